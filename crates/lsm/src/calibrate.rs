//! Calibration: spring stiffnesses from E and ν on a hexagonal lattice (closed form of
//! the crate docs), and quasi-static tests that measure a packing's macroscopic
//! properties.
//!
//! * [`uniaxial`]: a rectangular sample between two frictionless platens (the bottom
//!   and top layers of particles, vertical velocity prescribed, lateral motion and
//!   rotation free) is shortened to a small strain ε_yy and held until at rest; then
//!   `E = σ_yy/ε_yy` with `σ_yy` the platen reaction over the sample width (the centre
//!   spacing of the side particles plus their mean radius on each side), and
//!   `ν = −ε_xx/ε_yy` with ε_xx from the mean lateral displacement of the side particles
//!   of the middle half of the height.
//! * [`brazilian`]: a disk sample of radius R squeezed between two caps of particles
//!   moving towards each other; the peak load F (N/m) gives the splitting tensile
//!   strength `σ_t = 2F/(πD) = F/(πR)` (plane elasticity of a diametrically loaded disk).
//!
//! Both use local damping and a constant platen speed; the speed should be far below
//! the wave speed (a few 1e-3 of `√(E/ρ)` keeps the sample near equilibrium).

use crate::{LatticeSolid, LsmError, LsmSpec, Motion};
use porofrac_particles::Disks;

/// Spring stiffnesses `(k_n, k_s)` of a hexagonal lattice with the 2D Young's modulus
/// `e` (Pa) and Poisson's ratio `nu` (at most 1/3).
pub fn hexagonal_springs(e: f64, nu: f64) -> Result<(f64, f64), LsmError> {
    if !(e.is_finite() && e > 0.0) {
        return Err(LsmError::bad("E", e, "must be positive"));
    }
    if !(nu > -1.0 && nu <= 1.0 / 3.0) {
        return Err(LsmError::bad(
            "nu",
            nu,
            "must be in (-1, 1/3]: a lattice of non-negative springs has ν ≤ 1/3",
        ));
    }
    let kn = e / (3f64.sqrt() * (1.0 - nu));
    Ok((kn, kn * (1.0 - 3.0 * nu) / (1.0 + nu)))
}

/// Young's modulus and Poisson's ratio `(E, ν)` of a hexagonal lattice of springs.
pub fn hexagonal_moduli(kn: f64, ks: f64) -> (f64, f64) {
    (
        2.0 * 3f64.sqrt() * kn * (kn + ks) / (3.0 * kn + ks),
        (kn - ks) / (3.0 * kn + ks),
    )
}

/// Settings of a quasi-static platen test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuasiStatic {
    /// Platen speed (m/s), each platen.
    pub speed: f64,
    /// Local damping α.
    pub alpha: f64,
    /// Time step as a fraction of the stable one.
    pub dt_fraction: f64,
    /// Most steps.
    pub max_steps: usize,
}

impl QuasiStatic {
    /// Platens at `speed`, α = 0.7, Δt = 0.5 of the stable step, at most 10⁶ steps.
    pub fn new(speed: f64) -> Self {
        Self {
            speed,
            alpha: 0.7,
            dt_fraction: 0.5,
            max_steps: 1_000_000,
        }
    }

    fn check(&self) -> Result<(), LsmError> {
        if !(self.speed.is_finite() && self.speed > 0.0) {
            return Err(LsmError::bad("speed", self.speed, "must be positive"));
        }
        if !(self.dt_fraction > 0.0 && self.dt_fraction <= 1.0) {
            return Err(LsmError::bad(
                "dt_fraction",
                self.dt_fraction,
                "must be in (0, 1]",
            ));
        }
        Ok(())
    }
}

/// Result of [`uniaxial`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uniaxial {
    /// Young's modulus (Pa).
    pub e: f64,
    /// Poisson's ratio.
    pub nu: f64,
}

fn bounds(d: &Disks) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for (x, r) in d.x.iter().zip(&d.r) {
        for a in 0..2 {
            lo[a] = lo[a].min(x[a] - r);
            hi[a] = hi[a].max(x[a] + r);
        }
    }
    (lo, hi)
}

/// Uniaxial compression of a rectangular sample to the strain `strain` (module docs).
pub fn uniaxial(
    disks: Disks,
    spec: LsmSpec,
    strain: f64,
    q: &QuasiStatic,
) -> Result<Uniaxial, LsmError> {
    uniaxial_polled(disks, spec, strain, q, &mut |_| false)
}

/// Steps between two calls of the progress callback of the calibration tests.
const POLL_EVERY: usize = 100;

/// [`uniaxial`], calling `poll` every few steps with the steps taken and
/// [`QuasiStatic::max_steps`]: `true` stops the test with [`LsmError::Interrupted`].
pub fn uniaxial_polled(
    disks: Disks,
    spec: LsmSpec,
    strain: f64,
    q: &QuasiStatic,
    poll: &mut dyn FnMut(porofrac_particles::Progress) -> bool,
) -> Result<Uniaxial, LsmError> {
    q.check()?;
    let mut polled = |steps: usize| {
        if steps.is_multiple_of(POLL_EVERY)
            && poll(porofrac_particles::Progress::new(
                "uniaxial test, step",
                steps,
                q.max_steps,
            ))
        {
            Err(LsmError::Interrupted)
        } else {
            Ok(())
        }
    };
    if !(strain > 0.0 && strain < 0.05) {
        return Err(LsmError::bad("strain", strain, "must be in (0, 0.05)"));
    }
    let (lo, hi) = bounds(&disks);
    let rmax = disks.radius_range()[1];
    let mut spec = spec;
    spec.damping = crate::Damping::Local { alpha: q.alpha };
    let mut s = LatticeSolid::new(disks, spec)?;
    let n = s.disks().len();
    let layer = 1.01 * rmax;
    let (mut top, mut bottom, mut left, mut right) = (vec![], vec![], vec![], vec![]);
    let h = hi[1] - lo[1];
    for i in 0..n {
        let (x, r) = (s.disks().x[i], s.disks().r[i]);
        if x[1] + r > hi[1] - layer {
            top.push(i);
        } else if x[1] - r < lo[1] + layer {
            bottom.push(i);
        } else if (x[1] - 0.5 * (lo[1] + hi[1])).abs() < 0.25 * h {
            if x[0] - r < lo[0] + layer {
                left.push(i);
            } else if x[0] + r > hi[0] - layer {
                right.push(i);
            }
        }
    }
    if top.is_empty() || bottom.is_empty() || left.is_empty() || right.is_empty() {
        return Err(LsmError::Calibration(
            "the sample has no platen or side particles".into(),
        ));
    }
    let mean_y = |s: &LatticeSolid, set: &[usize]| {
        set.iter().map(|&i| s.disks().x[i][1]).sum::<f64>() / set.len() as f64
    };
    let mean_x = |s: &LatticeSolid, set: &[usize]| {
        set.iter().map(|&i| s.disks().x[i][0]).sum::<f64>() / set.len() as f64
    };
    let gap0 = mean_y(&s, &top) - mean_y(&s, &bottom);
    let width0 = mean_x(&s, &right) - mean_x(&s, &left);
    let dt = q.dt_fraction * s.stable_dt();
    let target = strain * gap0;
    let ramp_steps = (0.5 * target / (q.speed * dt)).ceil() as usize;
    for &i in &top {
        s.set_motion(
            i,
            Motion::Axis {
                axis: 1,
                velocity: -q.speed,
            },
        );
    }
    for &i in &bottom {
        s.set_motion(
            i,
            Motion::Axis {
                axis: 1,
                velocity: q.speed,
            },
        );
    }
    let mut steps = 0;
    for _ in 0..ramp_steps {
        polled(steps)?;
        s.step(dt, &[])?;
        steps += 1;
    }
    for &i in top.iter().chain(&bottom) {
        s.set_motion(
            i,
            Motion::Axis {
                axis: 1,
                velocity: 0.0,
            },
        );
    }
    // Hold until the kinetic energy is small against the stored energy.
    loop {
        polled(0)?;
        for _ in 0..200 {
            s.step(dt, &[])?;
        }
        steps += 200;
        if s.disks().kinetic_energy() < 1e-10 * s.bond_energy() {
            break;
        }
        if steps > q.max_steps {
            return Err(LsmError::Calibration(format!(
                "uniaxial: not at rest after {steps} steps"
            )));
        }
    }
    let eyy = (mean_y(&s, &top) - mean_y(&s, &bottom) - gap0) / gap0;
    let exx = (mean_x(&s, &right) - mean_x(&s, &left) - width0) / width0;
    let load: f64 = top.iter().map(|&i| s.forces()[i][1]).sum::<f64>()
        - bottom.iter().map(|&i| s.forces()[i][1]).sum::<f64>();
    // The width carried: centre spacing of the sides plus one mean radius each side.
    let mean_r =
        |set: &[usize]| set.iter().map(|&i| s.disks().r[i]).sum::<f64>() / set.len() as f64;
    let width = width0 + mean_r(&left) + mean_r(&right);
    let syy = -0.5 * load / width;
    Ok(Uniaxial {
        e: syy / eyy,
        nu: -exx / eyy,
    })
}

/// Result of [`brazilian`].
#[derive(Clone, Debug, PartialEq)]
pub struct Brazilian {
    /// Peak load (N/m).
    pub peak_force: f64,
    /// Splitting tensile strength `F/(πR)` (Pa).
    pub tensile_strength: f64,
    /// Sample radius R (m).
    pub radius: f64,
    /// Bonds broken at the end.
    pub broken: usize,
    /// Load history: (platen approach (m), load (N/m)).
    pub curve: Vec<(f64, f64)>,
}

/// Brazilian test of a disk-shaped sample (module docs). The caps are the particles
/// within `cap` (m) of the top and bottom of the sample. The test stops when the load
/// has fallen below half its peak, or at `q.max_steps`.
pub fn brazilian(
    disks: Disks,
    spec: LsmSpec,
    cap: f64,
    q: &QuasiStatic,
) -> Result<Brazilian, LsmError> {
    brazilian_polled(disks, spec, cap, q, &mut |_| false)
}

/// [`brazilian`], calling `poll` every few steps with the steps taken and
/// [`QuasiStatic::max_steps`]: `true` stops the test with [`LsmError::Interrupted`].
pub fn brazilian_polled(
    disks: Disks,
    spec: LsmSpec,
    cap: f64,
    q: &QuasiStatic,
    poll: &mut dyn FnMut(porofrac_particles::Progress) -> bool,
) -> Result<Brazilian, LsmError> {
    q.check()?;
    let (lo, hi) = bounds(&disks);
    let radius = 0.25 * (hi[0] - lo[0] + hi[1] - lo[1]);
    let mut spec = spec;
    spec.damping = crate::Damping::Local { alpha: q.alpha };
    let mut s = LatticeSolid::new(disks, spec)?;
    let n = s.disks().len();
    let (mut top, mut bottom) = (vec![], vec![]);
    for i in 0..n {
        let (x, r) = (s.disks().x[i], s.disks().r[i]);
        if x[1] + r > hi[1] - cap {
            top.push(i);
            s.set_motion(i, Motion::Velocity([0.0, -q.speed]));
        } else if x[1] - r < lo[1] + cap {
            bottom.push(i);
            s.set_motion(i, Motion::Velocity([0.0, q.speed]));
        }
    }
    if top.is_empty() || bottom.is_empty() {
        return Err(LsmError::Calibration("brazilian: no cap particles".into()));
    }
    let dt = q.dt_fraction * s.stable_dt();
    let mut peak: f64 = 0.0;
    let mut curve = Vec::new();
    let mut steps = 0;
    let every = 50;
    while steps < q.max_steps {
        if steps.is_multiple_of(POLL_EVERY)
            && poll(porofrac_particles::Progress::new(
                "Brazilian test, step",
                steps,
                q.max_steps,
            ))
        {
            return Err(LsmError::Interrupted);
        }
        s.step(dt, &[])?;
        steps += 1;
        let load = 0.5
            * (top.iter().map(|&i| s.forces()[i][1]).sum::<f64>()
                - bottom.iter().map(|&i| s.forces()[i][1]).sum::<f64>());
        peak = peak.max(load);
        if steps % every == 0 {
            curve.push((2.0 * q.speed * s.time(), load));
        }
        if peak > 0.0 && load < 0.5 * peak && !s.broken().is_empty() {
            break;
        }
    }
    if s.broken().is_empty() {
        return Err(LsmError::Calibration(format!(
            "brazilian: no bond broke in {steps} steps"
        )));
    }
    Ok(Brazilian {
        peak_force: peak,
        tensile_strength: peak / (std::f64::consts::PI * radius),
        radius,
        broken: s.broken().len(),
        curve,
    })
}
