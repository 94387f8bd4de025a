//! Fracture toughness of a bonded packing, and what it means for the breakdown of a
//! pressurised hole.
//!
//! **The measurement** ([`pressurised_notch`]): a straight notch of half-length `c` is cut
//! through the middle of a sample ([`crate::LatticeSolid::cut`]) and a pressure `p`,
//! ramped at a fixed rate, is put on its faces the way [`crate::CrackExtent::flood_loads`]
//! puts the hole pressure in a flooded crack (`±p w n` on the two disks of every broken
//! bond connected to the notch, `w = 2 min(R_i, R_j)`), so the crack that grows from the
//! notch tips stays flooded. A line crack of half-length `c` with the pressure `p` on its
//! faces in an infinite plate has the stress intensity (Griffith, Sneddon)
//!
//! `K_I = p √(π c)`,
//!
//! which grows with `c`: at the toughness `K_Ic` the crack runs. The notch *fails* when
//! the crack connected to it reaches `c + growth` from its centre; the apparent
//! toughness is `K_Ic = p_c √(π c)` ([`griffith_toughness`]). A sample of radius R > 4c
//! is taken as infinite (the strip's width factor `√sec(πc/2R)` is below 1.04 there).
//! LEFM holds when `p_c √c` does not depend on `c`; a material with a strength and a
//! toughness does this only for notches long against its characteristic length
//!
//! `ℓ = (K_Ic/σ_t)²/π` ([`characteristic_length`]);
//!
//! shorter notches fail near the strength (`p_c → σ_t` as `c → 0`).
//!
//! **The hole** (Lamé, a thick-walled cylinder of radii a < b, pressure p inside): the
//! hoop stress is `σ_θθ(r) = p a²/(b² − a²) (1 + b²/r²)` ([`hoop_stress`]), `σ_t` at the
//! wall at the strength estimate `p_b = σ_t (b² − a²)/(b² + a²)`. A material with a
//! toughness breaks the hole later, the more so the smaller the hole against ℓ. The two
//! classical criteria of the notched-strength literature (Whitney & Nuismer 1974; used for
//! boreholes by Ito & Hayashi 1991 and, as the size effect of breakdown, by Haimson & Zhao
//! 1991) ask for σ_t not at the wall but
//!
//! * at the distance `d₀ = ℓ/2` from it (*point stress*,
//!   [`point_stress_breakdown`]: `p = σ_t (b² − a²)/(a² + a²b²/(a + d₀)²)`), or
//! * as the mean of σ_θθ over `d₀ = 2ℓ` from it (*average stress*,
//!   [`average_stress_breakdown`]: `p = σ_t (b² − a²)/(a² + a b²/(a + d₀))`);
//!
//! both distances are those at which the criterion reproduces `K_Ic` for a Griffith crack
//! in tension. Both tend to `p_b` as `a/ℓ → ∞`; for `b ≫ a` they read
//! `p ≈ p_b (1 + d₀/a)²` (point) and `p ≈ p_b (1 + d₀/a)` (average). Neither puts the
//! pressure in the crack: a flaw at the wall whose faces carry `p` as well breaks at
//! `σ_θθ(a) + p = σ_t`, `p = σ_t (b² − a²)/(2b²)` for a large hole (about half of `p_b`),
//! which is the limit of the flooded borehole scenes (docs/models/lsm.md).

use crate::bond::BrokenBond;
use crate::crack::{CrackExtent, CrackFaces, FaceWidths};
use crate::law::Damping;
use crate::{LatticeSolid, LsmError, LsmSpec};
use porofrac_particles::Disks;

/// How [`pressurised_notch`] loads its notch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NotchRamp {
    /// Pressure rate on the notch faces (Pa/s).
    pub rate: f64,
    /// Local damping α.
    pub alpha: f64,
    /// Time step as a fraction of the stable one.
    pub dt_fraction: f64,
    /// Growth beyond the notch tip that counts as failure (m).
    pub growth: f64,
    /// The pressure at which the test gives up (Pa).
    pub max_pressure: f64,
    /// The crack-face length of a flooded bond.
    pub faces: CrackFaces,
    /// Trace the crack through the pores it opens, the faces of the bond network
    /// ([`CrackExtent::across_pores`]).
    pub across_pores: bool,
}

/// What [`pressurised_notch`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct NotchTest {
    /// Half-length of the cut (m).
    pub half_length: f64,
    /// Bonds cut.
    pub cut: usize,
    /// Extent of the cut crack from the notch centre: its farthest cut bond (m).
    pub cut_extent: f64,
    /// The opening force per unit pressure of the flooded cut bonds,
    /// `Σ ℓ_k |n_k · ŷ|` (m, `ℓ_k` the face length of `ramp.faces`): a fluid on the faces
    /// of the notch would push them apart with `p · 2c`, so `face_load / 2c` is the share
    /// of the notch pressure that the flooded loads carry.
    pub face_load: f64,
    /// Pressure at the first broken bond (Pa).
    pub first_break: f64,
    /// Pressure at which the crack connected to the notch reached
    /// `half_length + growth` from the centre (Pa).
    pub failure: f64,
    /// Bonds broken by the load by then.
    pub broken: usize,
    /// Of them tensile.
    pub tensile: usize,
    /// Steps taken.
    pub steps: usize,
}

/// Cut a notch from `centre − (c, 0)` to `centre + (c, 0)` in `disks` bonded by `spec`
/// (its damping replaced by local damping `ramp.alpha`), ramp the pressure on its faces
/// and on the faces of the crack that grows from it, and stop when that crack reaches
/// `c + ramp.growth` from the centre (module docs). Errors when the notch cuts no bond,
/// on bad settings, or when the pressure passes `ramp.max_pressure` first.
pub fn pressurised_notch(
    disks: Disks,
    mut spec: LsmSpec,
    centre: [f64; 2],
    half_length: f64,
    ramp: &NotchRamp,
) -> Result<NotchTest, LsmError> {
    let c = half_length;
    if !(c.is_finite() && c > 0.0) {
        return Err(LsmError::bad("half_length", c, "must be positive"));
    }
    if !(ramp.rate.is_finite() && ramp.rate > 0.0) {
        return Err(LsmError::bad("rate", ramp.rate, "must be positive"));
    }
    if !(ramp.dt_fraction > 0.0 && ramp.dt_fraction <= 1.0) {
        return Err(LsmError::bad(
            "dt_fraction",
            ramp.dt_fraction,
            "must be in (0, 1]",
        ));
    }
    if !(ramp.growth.is_finite() && ramp.growth > 0.0) {
        return Err(LsmError::bad("growth", ramp.growth, "must be positive"));
    }
    if !(ramp.max_pressure.is_finite() && ramp.max_pressure > 0.0) {
        return Err(LsmError::bad(
            "max_pressure",
            ramp.max_pressure,
            "must be positive",
        ));
    }
    spec.damping = Damping::Local { alpha: ramp.alpha };
    let mut solid = LatticeSolid::new(disks, spec)?;
    let cut: Vec<BrokenBond> = solid.cut([centre[0] - c, centre[1]], [centre[0] + c, centre[1]])?;
    if cut.is_empty() {
        return Err(LsmError::Calibration(format!(
            "a notch of half-length {c} m cuts no bond"
        )));
    }
    let faces = match ramp.faces {
        CrackFaces::BondWidth => None,
        CrackFaces::Radical => Some(FaceWidths::radical(solid.disks(), solid.bonds())),
    };
    let width = |b: &BrokenBond| match &faces {
        Some(f) => f.get(b.i, b.j).unwrap_or(0.0),
        None => 2.0 * solid.disks().r[b.i].min(solid.disks().r[b.j]),
    };
    let n = solid.disks().len();
    let lining: Vec<usize> = cut.iter().flat_map(|b| [b.i, b.j]).collect();
    let mut crack = CrackExtent::new(n, &lining, centre)?;
    if ramp.across_pores {
        crack = crack.across_pores(solid.disks(), solid.bonds())?;
    }
    let mut cut_extent: f64 = 0.0;
    for b in &cut {
        cut_extent = cut_extent.max(crack.add(b.i, b.j, [b.x, b.y])?);
    }
    let face_load = cut
        .iter()
        .map(|b| {
            let (xi, xj) = (solid.disks().x[b.i], solid.disks().x[b.j]);
            let e = [xj[0] - xi[0], xj[1] - xi[1]];
            width(b) * (e[1] / e[0].hypot(e[1])).abs()
        })
        .sum();
    let dt = ramp.dt_fraction * solid.stable_dt();
    let mut loads = vec![[0.0; 3]; n];
    let mut seen = 0;
    let mut first_break = None;
    let mut steps = 0;
    loop {
        steps += 1;
        let p = ramp.rate * steps as f64 * dt;
        if p > ramp.max_pressure {
            return Err(LsmError::Calibration(format!(
                "the notch of half-length {c} m did not grow by {} m up to {:.4e} Pa",
                ramp.growth, ramp.max_pressure
            )));
        }
        loads.iter_mut().for_each(|l| *l = [0.0; 3]);
        match &faces {
            Some(f) => {
                crack.flood_loads_on_faces(solid.disks(), &cut, p, f, &mut loads)?;
                crack.flood_loads_on_faces(solid.disks(), solid.broken(), p, f, &mut loads)?;
            }
            None => {
                crack.flood_loads(solid.disks(), &cut, p, &mut loads)?;
                crack.flood_loads(solid.disks(), solid.broken(), p, &mut loads)?;
            }
        }
        solid.step(dt, &loads)?;
        let broken = solid.broken();
        if broken.len() > seen && first_break.is_none() {
            first_break = Some(p);
        }
        let mut extent = 0.0;
        for b in &broken[seen..] {
            extent = crack.add(b.i, b.j, [b.x, b.y])?;
        }
        seen = broken.len();
        if extent >= c + ramp.growth {
            return Ok(NotchTest {
                half_length: c,
                cut: cut.len(),
                cut_extent,
                face_load,
                first_break: first_break.unwrap_or(p),
                failure: p,
                broken: broken.len(),
                tensile: broken
                    .iter()
                    .filter(|b| b.mode == crate::BreakMode::Tensile)
                    .count(),
                steps,
            });
        }
    }
}

/// The toughness of a pressurised line crack of half-length `c` (m) that runs at the
/// pressure `p` (Pa) in an infinite plate: `K_Ic = p √(π c)` (Pa·√m).
pub fn griffith_toughness(p: f64, c: f64) -> f64 {
    p * (std::f64::consts::PI * c).sqrt()
}

/// The characteristic length `ℓ = (K_Ic/σ_t)²/π` (m) of a material of toughness `k_ic`
/// (Pa·√m) and tensile strength `sigma_t` (Pa).
pub fn characteristic_length(k_ic: f64, sigma_t: f64) -> f64 {
    (k_ic / sigma_t).powi(2) / std::f64::consts::PI
}

/// The hoop stress (Pa) at radius `r` of a thick-walled cylinder of radii `a < b` (m)
/// under the inner pressure `p` (Pa): `p a²/(b² − a²) (1 + b²/r²)` (Lamé).
pub fn hoop_stress(p: f64, a: f64, b: f64, r: f64) -> f64 {
    p * a * a / (b * b - a * a) * (1.0 + b * b / (r * r))
}

/// The strength estimate of breakdown `σ_t (b² − a²)/(b² + a²)` (Pa): the hoop stress at
/// the wall reaches `sigma_t`.
pub fn strength_breakdown(sigma_t: f64, a: f64, b: f64) -> f64 {
    sigma_t * (b * b - a * a) / (b * b + a * a)
}

/// Point-stress breakdown (Pa): the hoop stress reaches `sigma_t` at the distance `d0`
/// (m) from the wall, `σ_t (b² − a²)/(a² + a² b²/(a + d₀)²)`; `d0 = ℓ/2` reproduces
/// the toughness (module docs).
pub fn point_stress_breakdown(sigma_t: f64, a: f64, b: f64, d0: f64) -> f64 {
    let r = a + d0;
    sigma_t * (b * b - a * a) / (a * a + a * a * b * b / (r * r))
}

/// Average-stress breakdown (Pa): the mean hoop stress over `d0` (m) from the wall
/// reaches `sigma_t`, `σ_t (b² − a²)/(a² + a b²/(a + d₀))`; `d0 = 2ℓ` reproduces the
/// toughness (module docs).
pub fn average_stress_breakdown(sigma_t: f64, a: f64, b: f64, d0: f64) -> f64 {
    sigma_t * (b * b - a * a) / (a * a + a * b * b / (a + d0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The criteria against the Lamé stress they are built on: at the point-stress
    /// pressure the hoop stress at a + d₀ is σ_t; at the average-stress pressure the
    /// trapezoidal mean over [a, a + d₀] is σ_t; both are p_b at d₀ = 0.
    #[test]
    fn criteria_match_the_lame_stress() {
        let (st, a, b, d) = (3.44e6, 3.0, 22.0, 1.3);
        let p = point_stress_breakdown(st, a, b, d);
        assert!((hoop_stress(p, a, b, a + d) / st - 1.0).abs() < 1e-14);
        let p = average_stress_breakdown(st, a, b, d);
        let m = 200_000;
        let h = d / m as f64;
        let mean = (0..m)
            .map(|k| hoop_stress(p, a, b, a + (k as f64 + 0.5) * h))
            .sum::<f64>()
            / m as f64;
        assert!((mean / st - 1.0).abs() < 1e-9, "{mean}");
        let pb = strength_breakdown(st, a, b);
        assert!((hoop_stress(pb, a, b, a) / st - 1.0).abs() < 1e-14);
        assert_eq!(point_stress_breakdown(st, a, b, 0.0), pb);
        assert!((average_stress_breakdown(st, a, b, 0.0) / pb - 1.0).abs() < 1e-15);
        // Large holes: both tend to p_b.
        let big = 1e4;
        let pb = strength_breakdown(st, big, 7.3 * big);
        assert!(point_stress_breakdown(st, big, 7.3 * big, 1.0) / pb - 1.0 < 2.1e-4);
        assert!(average_stress_breakdown(st, big, 7.3 * big, 1.0) / pb - 1.0 < 1.1e-4);
    }

    /// A saw cut between two rows of a hexagonal lattice breaks the two bonds per
    /// spacing that cross it, and only those; a cut of no length is refused.
    #[test]
    fn a_cut_breaks_the_bonds_it_crosses() {
        use crate::law::BondLaw;
        let d = 1.0;
        let h = d * 3f64.sqrt() / 2.0;
        let mut centres = Vec::new();
        for row in 0..6 {
            for col in 0..10 {
                let x = col as f64 * d + if row % 2 == 1 { 0.5 * d } else { 0.0 };
                centres.push([x, row as f64 * h]);
            }
        }
        let n = centres.len();
        let disks = Disks::new(&centres, &vec![0.5 * d; n], 2600.0).unwrap();
        let mut s =
            LatticeSolid::new(disks, LsmSpec::new(BondLaw::elastic(1e9, 1e9, 0.0))).unwrap();
        let intact = s.intact_bonds();
        let y = 2.5 * h;
        let cut = s.cut([2.2, y], [7.2, y]).unwrap();
        // bonds whose midpoints lie at x = 2.25, 2.75, ..., 6.75 between rows 2 and 3
        assert_eq!(cut.len(), 10);
        assert_eq!(s.intact_bonds(), intact - 10);
        assert!(s.broken().is_empty());
        for b in &cut {
            let (yi, yj) = (centres[b.i][1], centres[b.j][1]);
            assert!((yi - y) * (yj - y) < 0.0 && b.x > 2.2 && b.x < 7.2, "{b:?}");
        }
        // cutting again breaks nothing more
        assert!(s.cut([2.2, y], [7.2, y]).unwrap().is_empty());
        let e = s.cut([1.0, 1.0], [1.0, 1.0]).unwrap_err();
        assert!(e.to_string().starts_with("to = 0"), "{e}");
    }

    /// ℓ of a Griffith crack: the crack of half-length ℓ runs at p = σ_t.
    #[test]
    fn characteristic_length_is_the_crack_that_runs_at_the_strength() {
        let (st, k) = (3.44e6, 4.1e6);
        let l = characteristic_length(k, st);
        assert!((griffith_toughness(st, l) / k - 1.0).abs() < 1e-15);
    }
}
