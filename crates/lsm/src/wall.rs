//! Pressure on the wall of a circular hole (a borehole), as forces on the particles
//! that line it.
//!
//! The hole of centre `c` and radius `a` is swept by `N = 3600` rays from `c`; each ray
//! of direction `e_k` hits a first disk (the nearest intersection). The pressure on the
//! arc `a Δφ` of the ray, `Δφ = 2π/N`, pushes that disk outwards: the disk receives
//! `p a Δφ Σ_k e_k` over its rays. The forces sum to the pressure integral
//! `∮ p n a dφ` over the wall (zero in total, the hoop load of the continuum on each
//! side), so the tangential stress at the wall is `σ_θθ(a) = p (b² + a²)/(b² − a²)` for a
//! disk of outer radius b (the closed-form breakdown check). The set is taken once, in the
//! reference configuration (small strains).
//!
//! **Wetted faces** ([`WallFaces::Wetted`]). A fluid filling the hole does not stop at the
//! faces seen from the centre: it enters every notch between the lining disks and every
//! pocket of the pore space reached through gaps wider than its resolution, and there it
//! pushes the disks sideways as well (wedging). This variant loads exactly those faces.
//! The plane is rasterised in square cells of side `h`; a cell is solid when its centre
//! lies within `s R_i` of a disk centre (`s ≥ 1` enlarges the disks as a fluid with sealed
//! bonds sees them, so the gap of a bonded pair holds no fluid); the cells connected to
//! the hole centre through cells that share a side or a corner (the reach of a D2Q9
//! lattice of spacing `h`) are wet. On the circle of radius `s R_i` of every disk,
//! `M = 720` points at angles `θ_m` each carry the arc `s R_i Δθ`; a point is wet when a
//! wet cell touches its cell and no other enlarged disk contains it (the raster decides
//! what is connected, the circles where the seals are), and the disk receives
//! `−p s R_i Δθ Σ_wet n_m` (`n_m` the outward normal): the pressure integral over its
//! wetted arc, which is `p` times the chord between the arc's ends, normal to it, and
//! has no moment about the centre. A disk wet all round receives nothing; a disk wet
//! on one half receives `p · 2 s R`. If the wet cells reach the edge of the raster (the
//! pore space of the hole leaks out of the packing) the wall is refused.

use crate::LsmError;
use porofrac_particles::Disks;

/// Rays per wall.
const RAYS: usize = 3600;

/// Which faces of the particles lining a hole the hole pressure loads (see the module
/// docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum WallFaces {
    /// The faces seen from the hole centre (3600 rays).
    #[default]
    Rays,
    /// The faces a fluid filling the hole wets, notches and connected pockets included.
    Wetted {
        /// Raster cell side `h` (m), e.g. the lattice spacing of the fluid.
        spacing: f64,
        /// Radius factor `s ≥ 1` of the disks as the fluid sees them (1 + bond tolerance
        /// for sealed bonds).
        seal: f64,
    },
}

/// Sample points per disk circle of the wetted faces.
const ARC_POINTS: usize = 720;
/// Raster cell of no disk, not (yet) reached from the hole.
const OPEN: u32 = u32::MAX;
/// Raster cell reached from the hole.
const WET: u32 = u32::MAX - 1;

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
    /// The wall of the hole of `centre` and `radius` in the configuration of `disks`,
    /// loading the faces seen from the centre ([`WallFaces::Rays`]).
    pub fn new(disks: &Disks, centre: [f64; 2], radius: f64) -> Result<Self, LsmError> {
        Self::with_faces(disks, centre, radius, WallFaces::Rays)
    }

    /// The wall of the hole of `centre` and `radius` loading `faces`.
    pub fn with_faces(
        disks: &Disks,
        centre: [f64; 2],
        radius: f64,
        faces: WallFaces,
    ) -> Result<Self, LsmError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(LsmError::bad("hole radius", radius, "must be positive"));
        }
        let load = match faces {
            WallFaces::Rays => ray_loads(disks, centre, radius)?,
            WallFaces::Wetted { spacing, seal } => wetted_loads(disks, centre, spacing, seal)?,
        };
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

/// Load per unit pressure of every disk on the faces seen from the centre.
fn ray_loads(disks: &Disks, centre: [f64; 2], radius: f64) -> Result<Vec<[f64; 2]>, LsmError> {
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
    Ok(load)
}

/// Load per unit pressure of every disk on its wetted faces (see the module docs).
fn wetted_loads(
    disks: &Disks,
    centre: [f64; 2],
    h: f64,
    seal: f64,
) -> Result<Vec<[f64; 2]>, LsmError> {
    if !(h.is_finite() && h > 0.0) {
        return Err(LsmError::bad("wall spacing", h, "must be positive"));
    }
    if !(seal.is_finite() && (1.0..=2.0).contains(&seal)) {
        return Err(LsmError::bad("wall seal", seal, "must be in [1, 2]"));
    }
    let n = disks.len();
    // The raster: the disks' bounding box and the centre, with two cells of margin.
    let (mut lo, mut hi) = (centre, centre);
    for i in 0..n {
        let r = seal * disks.r[i];
        for a in 0..2 {
            lo[a] = lo[a].min(disks.x[i][a] - r);
            hi[a] = hi[a].max(disks.x[i][a] + r);
        }
    }
    let cells = |a: usize| (((hi[a] - lo[a]) / h).ceil() as usize).saturating_add(4);
    let (nx, ny) = (cells(0), cells(1));
    if nx.saturating_mul(ny) > 1 << 28 {
        return Err(LsmError::bad(
            "wall spacing",
            h,
            "gives more than 2^28 raster cells",
        ));
    }
    let origin = [lo[0] - 2.0 * h, lo[1] - 2.0 * h];
    let cell_of = |p: [f64; 2]| -> Option<usize> {
        let (i, j) = ((p[0] - origin[0]) / h, (p[1] - origin[1]) / h);
        let inside = i >= 0.0 && j >= 0.0 && (i as usize) < nx && (j as usize) < ny;
        inside.then(|| j as usize * nx + i as usize)
    };
    // Per cell: the disk covering it, OPEN or WET.
    let mut state = vec![OPEN; nx * ny];
    for i in 0..n {
        let (c, r) = (disks.x[i], seal * disks.r[i]);
        let i0 = (((c[0] - r - origin[0]) / h).floor().max(0.0)) as usize;
        let i1 = (((c[0] + r - origin[0]) / h).ceil() as usize).min(nx - 1);
        let j0 = (((c[1] - r - origin[1]) / h).floor().max(0.0)) as usize;
        let j1 = (((c[1] + r - origin[1]) / h).ceil() as usize).min(ny - 1);
        for j in j0..=j1 {
            for k in i0..=i1 {
                let p = [
                    origin[0] + (k as f64 + 0.5) * h - c[0],
                    origin[1] + (j as f64 + 0.5) * h - c[1],
                ];
                if p[0] * p[0] + p[1] * p[1] <= r * r {
                    state[j * nx + k] = i as u32;
                }
            }
        }
    }
    let start = cell_of(centre).expect("the centre lies in the raster");
    if state[start] != OPEN {
        return Err(LsmError::bad(
            "hole centre x",
            centre[0],
            "lies inside a particle",
        ));
    }
    state[start] = WET;
    let mut stack = vec![start];
    while let Some(c) = stack.pop() {
        let (i, j) = (c % nx, c / nx);
        if i == 0 || j == 0 || i + 1 == nx || j + 1 == ny {
            return Err(LsmError::bad(
                "wall spacing",
                h,
                "the space connected to the hole reaches the outside of the packing",
            ));
        }
        for dj in [-1isize, 0, 1] {
            for di in [-1isize, 0, 1] {
                let m = ((j as isize + dj) as usize) * nx + (i as isize + di) as usize;
                if state[m] == OPEN {
                    state[m] = WET;
                    stack.push(m);
                }
            }
        }
    }
    // A surface point is wet when a wet cell touches its cell and no other (enlarged)
    // disk contains it: the raster decides what is connected, the circles where the
    // seals are.
    let dth = std::f64::consts::TAU / ARC_POINTS as f64;
    let wet_at = |i: usize, q: [f64; 2]| -> bool {
        let (ci, cj) = (
            ((q[0] - origin[0]) / h).floor() as isize,
            ((q[1] - origin[1]) / h).floor() as isize,
        );
        let mut wet = false;
        for dj in -2isize..=2 {
            for di in -2isize..=2 {
                let (a, b) = (ci + di, cj + dj);
                if a < 0 || b < 0 || a >= nx as isize || b >= ny as isize {
                    continue;
                }
                let o = state[b as usize * nx + a as usize];
                if o == WET {
                    wet |= di.abs() <= 1 && dj.abs() <= 1;
                } else if o != OPEN && o as usize != i {
                    let (x, r) = (disks.x[o as usize], seal * disks.r[o as usize]);
                    if (q[0] - x[0]).powi(2) + (q[1] - x[1]).powi(2) < r * r {
                        return false;
                    }
                }
            }
        }
        wet
    };
    let load = (0..n)
        .map(|i| {
            let (c, r) = (disks.x[i], seal * disks.r[i]);
            let mut l = [0.0; 2];
            for m in 0..ARC_POINTS {
                let th = (m as f64 + 0.5) * dth;
                let e = [th.cos(), th.sin()];
                if wet_at(i, [c[0] + r * e[0], c[1] + r * e[1]]) {
                    l[0] -= r * dth * e[0];
                    l[1] -= r * dth * e[1];
                }
            }
            l
        })
        .collect();
    Ok(load)
}
