//! Calibration: spring stiffnesses from E and ν on a hexagonal lattice (closed form of
//! the crate docs), and quasi-static tests that measure a packing's macroscopic
//! properties.
//!
//! * [`uniaxial`]: a rectangular sample between two frictionless platens (the bottom
//!   and top layers of particles, vertical velocity prescribed, lateral motion and
//!   rotation free) is shortened to a small strain ε_yy and held until at rest; then
//!   `E = σ_yy/ε_yy` and `ν = −ε_xx/ε_yy` with `σ_yy` the platen reaction over the
//!   sample width (the centre spacing of the side particles plus their mean radius on
//!   each side) and ε the homogeneous strain of the sample's core: the least-squares
//!   affine fit `u ≈ u₀ + ε x` (plus a rotation) of the displacements of the disks
//!   farther than [`CORE_MARGIN`] largest radii from every side and platen, held by at
//!   least two intact bonds and part of the sample's bonded network (its largest cluster
//!   of disks joined by intact bonds: a small cluster loose in a pore drifts freely),
//!   fitted a second time without the disks more than three median distances off the
//!   first fit (without a bending spring a disk held by a chain of bonds can roll on its
//!   neighbours at no cost and wander off the field). The strains at the boundary are not used: the platen
//!   layers and the free sides are bonded to fewer neighbours than the core and their
//!   disks relax out of the affine field, so the platen travel over-counts ε_yy (E
//!   reads low) and the mean displacement of the few side disks of the middle half
//!   scatters ν from packing to packing (0.24–0.62 for springs of the hexagonal
//!   lattice's ν = 0.2 on the recipe of `scenes/lsm/borehole_dry.toml`). Those boundary
//!   measures are kept in [`Uniaxial::e_platens`] and [`Uniaxial::nu_sides`]. The test
//!   holds the strain until the kinetic energy of that network is below 1e-10 of the
//!   bond energy (a rattler, which local damping does not stop, is left out),
//!   or until E holds steady to 1e-4 (relative) and ν to 1e-3 over 5000 steps.
//! * [`brazilian`]: a disk sample of radius R squeezed between two caps of particles
//!   moving towards each other; the peak load F (N/m) gives the splitting tensile
//!   strength `σ_t = 2F/(πD) = F/(πR)` (plane elasticity of a diametrically loaded disk).
//!
//! Both use local damping and a constant platen speed; the speed should be far below
//! the wave speed (a few 1e-3 of `√(E/ρ)` keeps the sample near equilibrium).

use crate::{BondLaw, ContactLaw, LatticeSolid, LsmError, LsmSpec, Motion};
use porofrac_particles::Disks;

/// The rock of the bundled borehole scenes (`scenes/lsm/borehole_*.toml`,
/// `scenes/lsm_hydrofrac.toml`) as a spec: springs of the hexagonal lattice for
/// E = 10 GPa and Poisson's ratio `nu` (0.2 in the scenes), no bending spring, a tensile
/// strength of 5 MPa, a cohesion of 10 MPa and a friction angle of 30°, bonds between
/// disks within 5 % of their radii, frictional contacts (μ = 0.6) as stiff as the bonds;
/// damping and the step left at [`LsmSpec::new`]'s. The studies of that rock outside a
/// scene (calibration, size effect, toughness, wall loads) start from it.
///
/// Errors: `nu` outside the hexagonal lattice's range ([`hexagonal_springs`]).
pub fn scene_rock(nu: f64) -> Result<LsmSpec, LsmError> {
    let (kn, ks) = hexagonal_springs(10e9, nu)?;
    let law = BondLaw {
        kn,
        ks,
        kb: 0.0,
        tensile: 5e6,
        cohesion: 10e6,
        friction_angle: 30f64.to_radians(),
    };
    let mut spec = LsmSpec::new(law);
    spec.bond_tolerance = 0.05;
    spec.contacts = ContactLaw {
        friction: 0.6,
        ..ContactLaw::like_bonds(&law)
    };
    Ok(spec)
}

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

/// Distance from the sides and platens (in largest radii) beyond which the disks of a
/// uniaxial sample form its core, whose affine fit gives the strain (module docs).
pub const CORE_MARGIN: f64 = 3.0;

/// Result of [`uniaxial`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uniaxial {
    /// Young's modulus (Pa): platen stress over the core's ε_yy.
    pub e: f64,
    /// Poisson's ratio: −ε_xx/ε_yy of the core.
    pub nu: f64,
    /// Young's modulus with ε_yy from the platens' travel (Pa; the boundary measure).
    pub e_platens: f64,
    /// Poisson's ratio with ε_xx from the mean displacement of the side disks of the
    /// middle half of the height (the boundary measure).
    pub nu_sides: f64,
    /// Disks of the core.
    pub core: usize,
    /// Steps taken.
    pub steps: usize,
    /// Bonds broken by the test: E and ν are elastic moduli only when none broke.
    pub broken: usize,
}

/// Which of `n` disks belong to the largest cluster joined by the intact `bonds`.
fn largest_cluster(n: usize, bonds: &[crate::Bond]) -> Vec<bool> {
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut parent: Vec<usize> = (0..n).collect();
    for b in bonds.iter().filter(|b| b.intact) {
        let (ri, rj) = (
            root(&mut parent, b.i as usize),
            root(&mut parent, b.j as usize),
        );
        if ri != rj {
            parent[ri.max(rj)] = ri.min(rj);
        }
    }
    let mut size = vec![0usize; n];
    for i in 0..n {
        size[root(&mut parent, i)] += 1;
    }
    let biggest = (0..n)
        .max_by_key(|&i| (size[i], std::cmp::Reverse(i)))
        .unwrap_or(0);
    (0..n).map(|i| root(&mut parent, i) == biggest).collect()
}

/// An affine displacement field `u(x) = ū + G (x − x̄)`, `G[c][k] = ∂u_c/∂x_k`.
struct Affine {
    g: [[f64; 2]; 2],
    xm: [f64; 2],
    um: [f64; 2],
}

impl Affine {
    /// Distance of disk i's displacement from the field.
    fn residual(&self, x0: &[f64; 2], x: &[f64; 2]) -> f64 {
        let dx = [x0[0] - self.xm[0], x0[1] - self.xm[1]];
        let r =
            [0, 1].map(|c| x[c] - x0[c] - self.um[c] - self.g[c][0] * dx[0] - self.g[c][1] * dx[1]);
        r[0].hypot(r[1])
    }
}

/// The strain gradient G of the core's displacements: the least-squares affine fit
/// ([`affine_fit`]), then again without the disks whose distance from it exceeds
/// [`OUTLIER`] times the median distance (a disk of a loose chain turning about a single
/// bond moves off the field without straining the sample).
fn core_fit(x0: &[[f64; 2]], x: &[[f64; 2]], set: &[usize]) -> Option<[[f64; 2]; 2]> {
    let first = affine_fit(x0, x, set)?;
    let mut r: Vec<f64> = set.iter().map(|&i| first.residual(&x0[i], &x[i])).collect();
    let mut sorted = r.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let kept: Vec<usize> = set
        .iter()
        .zip(r.drain(..))
        .filter(|&(_, d)| d <= OUTLIER * median)
        .map(|(&i, _)| i)
        .collect();
    affine_fit(x0, x, &kept).map(|f| f.g)
}

/// Distance from the affine fit, in median distances, beyond which a core disk is left
/// out of the strain ([`core_fit`]).
const OUTLIER: f64 = 3.0;

/// Least-squares affine fit `u ≈ ū + G (x − x̄)` of the displacements `u = x − x₀` of the
/// disks `set`, or `None` for a degenerate set.
fn affine_fit(x0: &[[f64; 2]], x: &[[f64; 2]], set: &[usize]) -> Option<Affine> {
    let n = set.len() as f64;
    let mut xm = [0.0; 2];
    let mut um = [0.0; 2];
    for &i in set {
        for k in 0..2 {
            xm[k] += x0[i][k] / n;
            um[k] += (x[i][k] - x0[i][k]) / n;
        }
    }
    // Normal equations: M g_c = b_c with M = Σ dx dxᵀ, b_c = Σ du_c dx.
    let mut m = [[0.0; 2]; 2];
    let mut b = [[0.0; 2]; 2];
    for &i in set {
        let dx = [x0[i][0] - xm[0], x0[i][1] - xm[1]];
        let du = [x[i][0] - x0[i][0] - um[0], x[i][1] - x0[i][1] - um[1]];
        for p in 0..2 {
            for q in 0..2 {
                m[p][q] += dx[p] * dx[q];
                b[p][q] += du[p] * dx[q];
            }
        }
    }
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let scale = m[0][0] * m[1][1];
    if set.len() < 3 || det.is_nan() || det <= 1e-12 * scale {
        return None;
    }
    let inv = [
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ];
    let mut g = [[0.0; 2]; 2];
    for c in 0..2 {
        for k in 0..2 {
            g[c][k] = b[c][0] * inv[0][k] + b[c][1] * inv[1][k];
        }
    }
    Some(Affine { g, xm, um })
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

/// Uniaxial compression of a rectangular sample to the strain `strain` (module docs). The
/// moduli are elastic only if no bond broke ([`Uniaxial::broken`]): the strain must stay
/// below the bonds' strength (1e-4 for the rock of the bundled scenes, whose bonds break
/// from about 1e-3).
pub fn uniaxial(
    disks: Disks,
    spec: LsmSpec,
    strain: f64,
    q: &QuasiStatic,
) -> Result<Uniaxial, LsmError> {
    uniaxial_polled(disks, spec, strain, q, &mut |_| false)
}

/// Steps over which E and ν of a uniaxial sample's core must hold steady for
/// the sample to count as at rest when its kinetic energy does not vanish (a loose chain
/// of disks turning at no cost).
const STEADY_STEPS: usize = 5000;

/// How steady over [`STEADY_STEPS`]: E relative, ν absolute to ten times this.
const STEADY: f64 = 1e-4;

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
    let x0 = s.disks().x.clone();
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
    // The sample is the largest cluster of disks joined by intact bonds: a rattler or a
    // small bonded cluster loose in a pore carries no load, and local damping (a force
    // against the velocity, proportional to the net force) does not stop one drifting.
    let mut bonds_of = vec![0usize; n];
    for b in s.bonds().iter().filter(|b| b.intact) {
        bonds_of[b.i as usize] += 1;
        bonds_of[b.j as usize] += 1;
    }
    let network = largest_cluster(n, s.bonds());
    let bonded_kinetic = |s: &LatticeSolid| {
        let d = s.disks();
        (0..n)
            .filter(|&i| network[i] && d.mass[i].is_finite())
            .map(|i| {
                let v = d.v[i];
                0.5 * d.mass[i] * (v[0] * v[0] + v[1] * v[1])
                    + 0.5 * d.inertia[i] * d.omega[i] * d.omega[i]
            })
            .sum::<f64>()
    };
    let margin = CORE_MARGIN * rmax;
    let core: Vec<usize> = (0..n)
        .filter(|&i| {
            let x = x0[i];
            network[i]
                && bonds_of[i] >= 2
                && x[0] > lo[0] + margin
                && x[0] < hi[0] - margin
                && x[1] > lo[1] + margin
                && x[1] < hi[1] - margin
        })
        .collect();
    // The width carried: centre spacing of the sides plus one mean radius each side.
    let mean_r = |s: &LatticeSolid, set: &[usize]| {
        set.iter().map(|&i| s.disks().r[i]).sum::<f64>() / set.len() as f64
    };
    let width = width0 + mean_r(&s, &left) + mean_r(&s, &right);
    let measure = |s: &LatticeSolid| -> Result<Uniaxial, LsmError> {
        let eyy = (mean_y(s, &top) - mean_y(s, &bottom) - gap0) / gap0;
        let exx = (mean_x(s, &right) - mean_x(s, &left) - width0) / width0;
        let load: f64 = top.iter().map(|&i| s.forces()[i][1]).sum::<f64>()
            - bottom.iter().map(|&i| s.forces()[i][1]).sum::<f64>();
        let syy = -0.5 * load / width;
        let g = core_fit(&x0, &s.disks().x, &core).ok_or_else(|| {
            LsmError::Calibration(format!(
                "uniaxial: the sample's core ({} disks farther than {CORE_MARGIN} largest \
                 radii from its sides) is too small for a strain",
                core.len()
            ))
        })?;
        Ok(Uniaxial {
            e: syy / g[1][1],
            nu: -g[0][0] / g[1][1],
            e_platens: syy / eyy,
            nu_sides: -exx / eyy,
            core: core.len(),
            steps: 0,
            broken: 0,
        })
    };
    // At rest: the kinetic energy of the bonded disks below 1e-10 of the bond energy,
    // or E of the core steady to 1e-4 and ν to 1e-3 over `STEADY_STEPS` (a slow creep of a few
    // loose disks that never comes to rest does not move the core).
    let mut last = measure(&s)?;
    let mut since = 0;
    loop {
        polled(0)?;
        for _ in 0..200 {
            s.step(dt, &[])?;
        }
        steps += 200;
        since += 200;
        if bonded_kinetic(&s) < 1e-10 * s.bond_energy() {
            break;
        }
        if since >= STEADY_STEPS {
            let now = measure(&s)?;
            if (now.e - last.e).abs() < STEADY * now.e.abs()
                && (now.nu - last.nu).abs() < 10.0 * STEADY
            {
                break;
            }
            last = now;
            since = 0;
        }
        if steps > q.max_steps {
            return Err(LsmError::Calibration(format!(
                "uniaxial: not at rest after {steps} steps"
            )));
        }
    }
    Ok(Uniaxial {
        steps,
        broken: s.broken().len(),
        ..measure(&s)?
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

/// Springs calibrated on a packing recipe by [`packing_springs`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PackingSprings {
    /// Normal stiffness (N/m²).
    pub kn: f64,
    /// Shear stiffness (N/m²).
    pub ks: f64,
    /// The Poisson's ratio of the hexagonal lattice with these springs (the parameter
    /// iterated on).
    pub nu_lattice: f64,
    /// E (Pa) and ν measured at the last iteration, before E was rescaled.
    pub measured: (f64, f64),
    /// Measurements made.
    pub evaluations: usize,
}

/// Springs `(k_n, k_s)` for which a packing recipe has the Young's modulus `e` and the
/// Poisson's ratio `nu`, calibrated on the packing itself: a random packing bonds each
/// disk to fewer neighbours than the hexagonal lattice and relaxes non-affinely, so the
/// closed form of [`hexagonal_springs`] gives it about half the E and a higher ν
/// (docs/models/lsm.md, "Calibration").
///
/// `measure(k_n, k_s)` returns the recipe's `(E, ν)` with those springs (for example the
/// mean of [`uniaxial`] over a few packings). With linear springs at small strain ν
/// depends on `k_s/k_n` only and E scales with `k_n` at a fixed ratio, so the springs are
/// [`hexagonal_springs`]`(E_set, ν_set)` with `ν_set` found by the secant method until
/// the measured ν is within `tol` of `nu` (at most 8 measurements), then `E_set` scaled
/// by `e/E` measured. A target out of reach of `ν_set ∈ (−0.9, 1/3]` is an error.
pub fn packing_springs(
    e: f64,
    nu: f64,
    tol: f64,
    measure: &mut dyn FnMut(f64, f64) -> Result<(f64, f64), LsmError>,
) -> Result<PackingSprings, LsmError> {
    hexagonal_springs(e, nu)?;
    if !(tol > 0.0 && tol.is_finite()) {
        return Err(LsmError::bad("tol", tol, "must be positive"));
    }
    let (lo, hi) = (-0.9, 1.0 / 3.0);
    let mut run = |nu_set: f64, evaluations: &mut usize| -> Result<(f64, f64), LsmError> {
        let (kn, ks) = hexagonal_springs(e, nu_set)?;
        *evaluations += 1;
        let (em, num) = measure(kn, ks)?;
        if !(em.is_finite() && em > 0.0 && num.is_finite()) {
            return Err(LsmError::Calibration(format!(
                "packing springs: the measurement gave E = {em:e}, ν = {num}"
            )));
        }
        Ok((em, num))
    };
    let mut evaluations = 0;
    let mut a = nu;
    let mut fa = run(a, &mut evaluations)?;
    let mut b = (nu - (fa.1 - nu)).clamp(lo, hi);
    let mut fb = if (fa.1 - nu).abs() <= tol {
        return finish(e, a, fa, evaluations);
    } else {
        run(b, &mut evaluations)?
    };
    while (fb.1 - nu).abs() > tol {
        if evaluations >= 8 {
            return Err(LsmError::Calibration(format!(
                "packing springs: ν = {:.4} after {evaluations} measurements, not within \
                 {tol} of {nu}",
                fb.1
            )));
        }
        let slope = (fb.1 - fa.1) / (b - a);
        if slope.is_nan() || slope.abs() <= 1e-9 {
            return Err(LsmError::Calibration(
                "packing springs: ν does not change with k_s/k_n".into(),
            ));
        }
        let next = (b - (fb.1 - nu) / slope).clamp(lo, hi);
        if next == b {
            return Err(LsmError::Calibration(format!(
                "packing springs: ν = {nu} is out of reach of the packing (ν = {:.4} at the \
                 bound k_s/k_n of ν_lattice = {b:.3})",
                fb.1
            )));
        }
        (a, fa) = (b, fb);
        b = next;
        fb = run(b, &mut evaluations)?;
    }
    finish(e, b, fb, evaluations)
}

fn finish(
    e: f64,
    nu_set: f64,
    measured: (f64, f64),
    evaluations: usize,
) -> Result<PackingSprings, LsmError> {
    let (kn, ks) = hexagonal_springs(e * e / measured.0, nu_set)?;
    Ok(PackingSprings {
        kn,
        ks,
        nu_lattice: nu_set,
        measured,
        evaluations,
    })
}
