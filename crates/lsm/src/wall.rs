//! Pressure on the wall of a circular hole (a borehole), as forces on the particles
//! that line it.
//!
//! The hole of centre `c` and radius `a` is swept by `N = 3600` rays from `c`; each ray
//! of direction `e_k` hits a first disk (the nearest intersection). The pressure on the
//! arc `a Δφ` of the ray, `Δφ = 2π/N`, pushes that disk outwards: the disk receives
//! `p a Δφ Σ_k e_k` over its rays. The forces sum to the pressure integral
//! `∮ p n a dφ` over the wall (zero in total, the hoop load of the continuum on each
//! side), so the tangential stress at the wall is `σ_θθ(a) = p (b² + a²)/(b² − a²)` for a
//! disk of outer radius b (seed 002.8 item 7). The set is taken once, in the reference
//! configuration (small strains).

use crate::LsmError;
use porofrac_particles::Disks;

/// Rays per wall.
const RAYS: usize = 3600;

/// The particles lining a hole and the pressure on them.
#[derive(Clone, Debug, PartialEq)]
pub struct PressureWall {
    /// Centre of the hole (m).
    pub centre: [f64; 2],
    /// Radius of the hole (m).
    pub radius: f64,
    /// Each lining particle and its load per unit pressure `a Δφ Σ e_k` (m).
    pub members: Vec<(u32, [f64; 2])>,
    /// Pressure (Pa).
    pub pressure: f64,
}

impl PressureWall {
    /// The wall of the hole of `centre` and `radius` in the configuration of `disks`.
    pub fn new(disks: &Disks, centre: [f64; 2], radius: f64) -> Result<Self, LsmError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(LsmError::bad("hole radius", radius, "must be positive"));
        }
        let n = disks.len();
        let mut load = vec![[0.0f64; 2]; n];
        let dphi = std::f64::consts::TAU / RAYS as f64;
        // Candidates: disks whose near side is within the largest diameter of the hole.
        let rmax = disks.radius_range()[1];
        let near: Vec<usize> = (0..n)
            .filter(|&i| {
                let d = crate::bond::dist(disks.x[i], centre);
                d - disks.r[i] < radius + 2.0 * rmax
            })
            .collect();
        let mut hit_any = false;
        for k in 0..RAYS {
            let phi = (k as f64 + 0.5) * dphi;
            let e = [phi.cos(), phi.sin()];
            let mut best: Option<(f64, usize)> = None;
            for &i in &near {
                let q = [disks.x[i][0] - centre[0], disks.x[i][1] - centre[1]];
                let along = q[0] * e[0] + q[1] * e[1];
                let perp2 = q[0] * q[0] + q[1] * q[1] - along * along;
                let r2 = disks.r[i] * disks.r[i];
                if along > 0.0 && perp2 < r2 {
                    let s = along - (r2 - perp2).sqrt();
                    if best.is_none_or(|(b, _)| s < b) {
                        best = Some((s, i));
                    }
                }
            }
            if let Some((_, i)) = best {
                load[i][0] += radius * dphi * e[0];
                load[i][1] += radius * dphi * e[1];
                hit_any = true;
            }
        }
        if !hit_any {
            return Err(LsmError::bad(
                "hole radius",
                radius,
                "no particle lines the hole",
            ));
        }
        let members = load
            .iter()
            .enumerate()
            .filter(|(_, l)| l[0] != 0.0 || l[1] != 0.0)
            .map(|(i, l)| (i as u32, *l))
            .collect();
        Ok(Self {
            centre,
            radius,
            members,
            pressure: 0.0,
        })
    }
}
