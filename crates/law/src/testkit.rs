//! A test kit for cell laws: the invariants every [`CellLaw`] must satisfy.
//!
//! Usable from any crate's tests (no test framework dependency): each check returns
//! `Ok(worst relative discrepancy)` or a [`KitFailure`] naming the check, the
//! discrepancy, the tolerance and where it occurred. [`check_all`] runs everything on
//! deterministic pseudo-random displacements.
//!
//! | check | property | tolerance |
//! |---|---|---|
//! | [`check_forces_gradient`] | `F = −∇E`, central differences of the energy | `fd_tol` |
//! | [`check_stiffness_jacobian`] | `K = −∂F/∂u` (the Hessian of `E`), central differences of the forces | `fd_tol` |
//! | [`check_stiffness_symmetric`] | `K = Kᵀ` | `exact_tol` |
//! | [`check_rigid_body_motions`] | translations and linearized rotations `u = W (x − x̄)`, `W = −Wᵀ`, give zero force and energy | `exact_tol` |
//! | [`check_linear_field`] | `u = A x + b`: `E = |K| · ½ ε : C : ε` and `σ = C : ε` with `ε = sym(A)` | `exact_tol` |
//!
//! A law that returns an error where a check evaluates it fails that check, with an
//! infinite discrepancy and the law's error as the location.
//!
//! Discrepancies are relative: `max |a − b| / max |b|` over the compared entries, with the
//! stiffness checks scaled by `max |K|` and the rigid-body ones by `max |K| · max |u|`
//! (forces) and `max |K| · max |u|²` (energy). The finite-difference step is
//! `fd_step · diam(K)` with `diam` the largest node distance; for a linear law central
//! differences of a quadratic energy are exact, so the error is round-off,
//! `≈ 1e-16 · amplitude / fd_step`.

use nalgebra::DMatrix;
use porofrac_grid::Point;

use crate::stiffness::Stiffness;
use crate::{CellGeometry, CellLaw, LawError, Scratch, Tensor};

/// Parameters of the checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KitOptions {
    /// Finite-difference step relative to the cell diameter.
    pub fd_step: f64,
    /// Tolerance of the finite-difference checks (relative).
    pub fd_tol: f64,
    /// Tolerance of the exact checks: symmetry, rigid-body motions, linear fields.
    pub exact_tol: f64,
    /// Size of the sampled displacements relative to the cell diameter.
    pub amplitude: f64,
    /// Seed of the deterministic displacement sampler.
    pub seed: u64,
}

impl Default for KitOptions {
    /// `fd_step = 1e-6`, `fd_tol = 1e-6`, `exact_tol = 1e-10`, `amplitude = 1e-3`, `seed = 1`.
    fn default() -> Self {
        Self {
            fd_step: 1e-6,
            fd_tol: 1e-6,
            exact_tol: 1e-10,
            amplitude: 1e-3,
            seed: 1,
        }
    }
}

/// A failed check.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{check}: relative discrepancy {error:.3e} exceeds tolerance {tol:.1e} ({location})")]
pub struct KitFailure {
    /// Name of the check.
    pub check: &'static str,
    /// The worst relative discrepancy.
    pub error: f64,
    /// The tolerance it was compared with.
    pub tol: f64,
    /// Where the worst discrepancy occurred (dof, motion, quantity).
    pub location: String,
}

/// The worst relative discrepancies of a passed [`check_all`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct KitReport {
    /// [`check_forces_gradient`].
    pub forces_gradient: f64,
    /// [`check_stiffness_jacobian`].
    pub stiffness_jacobian: f64,
    /// [`check_stiffness_symmetric`].
    pub symmetry: f64,
    /// [`check_rigid_body_motions`].
    pub rigid_body: f64,
    /// [`check_linear_field`] energy, if a material was given.
    pub linear_energy: Option<f64>,
    /// [`check_linear_field`] stress, if a material was given.
    pub linear_stress: Option<f64>,
}

fn verdict(
    check: &'static str,
    error: f64,
    tol: f64,
    location: impl FnOnce() -> String,
) -> Result<f64, KitFailure> {
    // `!(error <= tol)` also rejects NaN.
    if error <= tol {
        Ok(error)
    } else {
        Err(KitFailure {
            check,
            error,
            tol,
            location: location(),
        })
    }
}

/// A law that fails to evaluate fails the check it was called in.
fn law_failed(check: &'static str, tol: f64) -> impl FnOnce(LawError) -> KitFailure {
    move |e| KitFailure {
        check,
        error: f64::INFINITY,
        tol,
        location: format!("the law failed: {e}"),
    }
}

fn rel(diff: f64, scale: f64) -> f64 {
    if diff == 0.0 {
        0.0
    } else if scale > 0.0 {
        diff / scale
    } else {
        f64::INFINITY
    }
}

fn vertex_mean<const D: usize>(cell: &CellGeometry<'_, D>) -> Point<D> {
    cell.coords.iter().sum::<Point<D>>() / cell.coords.len().max(1) as f64
}

/// The largest distance between two nodes of the cell.
pub fn cell_diameter<const D: usize>(cell: &CellGeometry<'_, D>) -> f64 {
    let mut d: f64 = 0.0;
    for (i, a) in cell.coords.iter().enumerate() {
        for b in &cell.coords[i + 1..] {
            d = d.max((a - b).norm());
        }
    }
    d
}

/// A deterministic pseudo-random generator (SplitMix64), uniform in `[−1, 1)`.
#[derive(Clone, Debug)]
pub struct Sampler(u64);

impl Sampler {
    /// A sampler with the given seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    /// The next number in `[−1, 1)`.
    pub fn next_sym(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// Fill `out` (length `D·n`) with pseudo-random nodal displacements of size
/// `amplitude · diam(K)`.
pub fn sample_displacement<const D: usize>(
    cell: &CellGeometry<'_, D>,
    amplitude: f64,
    seed: u64,
    out: &mut [f64],
) {
    let s = amplitude * cell_diameter(cell);
    let mut r = Sampler::new(seed);
    out.iter_mut().for_each(|v| *v = s * r.next_sym());
}

/// Fill `out` (length `D·n`) with the nodal values of the linear field `u = A x + b`.
pub fn linear_field<const D: usize>(
    cell: &CellGeometry<'_, D>,
    grad: &Tensor<D>,
    shift: &Point<D>,
    out: &mut [f64],
) {
    for (i, x) in cell.coords.iter().enumerate() {
        let u = grad * x + shift;
        out[D * i..D * i + D].copy_from_slice(u.as_slice());
    }
}

fn fd_step<const D: usize>(cell: &CellGeometry<'_, D>, opts: &KitOptions) -> f64 {
    opts.fd_step * cell_diameter(cell)
}

/// `F = −∇E`: compare the law's forces at `u` with central differences of its energy.
pub fn check_forces_gradient<const D: usize, L: CellLaw<D> + ?Sized>(
    law: &L,
    cell: &CellGeometry<'_, D>,
    u: &[f64],
    opts: &KitOptions,
    scratch: &mut Scratch,
) -> Result<f64, KitFailure> {
    let n = u.len();
    let h = fd_step(cell, opts);
    let failed = || law_failed("forces = -grad energy", opts.fd_tol);
    let mut f = vec![0.0; n];
    law.forces(cell, u, &mut f, scratch).map_err(failed())?;
    let mut w = u.to_vec();
    let (mut worst, mut at, mut scale) = (0.0_f64, 0, 0.0_f64);
    for j in 0..n {
        w[j] = u[j] + h;
        let ep = law.energy(cell, &w, scratch).map_err(failed())?;
        w[j] = u[j] - h;
        let em = law.energy(cell, &w, scratch).map_err(failed())?;
        w[j] = u[j];
        let fd = -(ep - em) / (2.0 * h);
        scale = scale.max(fd.abs()).max(f[j].abs());
        let d = (fd - f[j]).abs();
        if d > worst {
            worst = d;
            at = j;
        }
    }
    verdict(
        "forces = -grad energy",
        rel(worst, scale),
        opts.fd_tol,
        || format!("dof {at}"),
    )
}

/// `K = −∂F/∂u`: compare the law's stiffness at `u` with central differences of its
/// forces.
pub fn check_stiffness_jacobian<const D: usize, L: CellLaw<D> + ?Sized>(
    law: &L,
    cell: &CellGeometry<'_, D>,
    u: &[f64],
    opts: &KitOptions,
    scratch: &mut Scratch,
) -> Result<f64, KitFailure> {
    let n = u.len();
    let h = fd_step(cell, opts);
    let failed = || law_failed("stiffness = -d forces/du", opts.fd_tol);
    let mut k = DMatrix::zeros(n, n);
    law.stiffness(cell, u, &mut k, scratch).map_err(failed())?;
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let mut w = u.to_vec();
    let (mut worst, mut at) = (0.0_f64, (0, 0));
    for j in 0..n {
        w[j] = u[j] + h;
        law.forces(cell, &w, &mut fp, scratch).map_err(failed())?;
        w[j] = u[j] - h;
        law.forces(cell, &w, &mut fm, scratch).map_err(failed())?;
        w[j] = u[j];
        for i in 0..n {
            let fd = -(fp[i] - fm[i]) / (2.0 * h);
            let d = (fd - k[(i, j)]).abs();
            if d > worst {
                worst = d;
                at = (i, j);
            }
        }
    }
    verdict(
        "stiffness = -d forces/du",
        rel(worst, k.amax()),
        opts.fd_tol,
        || format!("entry {at:?}"),
    )
}

/// `K = Kᵀ` at `u`.
pub fn check_stiffness_symmetric<const D: usize, L: CellLaw<D> + ?Sized>(
    law: &L,
    cell: &CellGeometry<'_, D>,
    u: &[f64],
    opts: &KitOptions,
    scratch: &mut Scratch,
) -> Result<f64, KitFailure> {
    let n = u.len();
    let mut k = DMatrix::zeros(n, n);
    law.stiffness(cell, u, &mut k, scratch)
        .map_err(law_failed("stiffness symmetric", opts.exact_tol))?;
    let (mut worst, mut at) = (0.0_f64, (0, 0));
    for i in 0..n {
        for j in i + 1..n {
            let d = (k[(i, j)] - k[(j, i)]).abs();
            if d > worst {
                worst = d;
                at = (i, j);
            }
        }
    }
    verdict(
        "stiffness symmetric",
        rel(worst, k.amax()),
        opts.exact_tol,
        || format!("entry {at:?}"),
    )
}

/// The rigid-body motions of a cell: `D` translations and `D(D−1)/2` linearized
/// rotations `u = W (x − x̄)` (`W` a unit skew matrix, `x̄` the vertex average), each of
/// size `amplitude · diam(K)`. Calls `f(name, u)` for each.
pub fn for_each_rigid_motion<const D: usize>(
    cell: &CellGeometry<'_, D>,
    amplitude: f64,
    mut f: impl FnMut(String, &[f64]),
) {
    let n = cell.coords.len();
    let s = amplitude * cell_diameter(cell);
    let xbar = vertex_mean(cell);
    let mut u = vec![0.0; D * n];
    for a in 0..D {
        let mut t = Point::<D>::zeros();
        t[a] = s;
        linear_field(cell, &Tensor::<D>::zeros(), &t, &mut u);
        f(format!("translation {a}"), &u);
    }
    let diam = cell_diameter(cell).max(f64::MIN_POSITIVE);
    for a in 0..D {
        for b in a + 1..D {
            let mut w = Tensor::<D>::zeros();
            w[(a, b)] = s / diam;
            w[(b, a)] = -s / diam;
            linear_field(cell, &w, &(-(w * xbar)), &mut u);
            f(format!("rotation ({a},{b})"), &u);
        }
    }
}

/// Rigid-body motions (see [`for_each_rigid_motion`]) give zero forces and zero energy,
/// relative to `max |K| · max |u|` and `max |K| · max |u|²` (`K` at `u = 0`).
pub fn check_rigid_body_motions<const D: usize, L: CellLaw<D> + ?Sized>(
    law: &L,
    cell: &CellGeometry<'_, D>,
    opts: &KitOptions,
    scratch: &mut Scratch,
) -> Result<f64, KitFailure> {
    let n = D * cell.coords.len();
    let failed = || law_failed("rigid-body motions", opts.exact_tol);
    let mut k = DMatrix::zeros(n, n);
    law.stiffness(cell, &vec![0.0; n], &mut k, scratch)
        .map_err(failed())?;
    let kmax = k.amax();
    let mut f = vec![0.0; n];
    let (mut worst, mut at) = (0.0_f64, String::new());
    let mut error = None;
    for_each_rigid_motion(cell, opts.amplitude, |name, u| {
        if error.is_some() {
            return;
        }
        let umax = u.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let energy = law
            .forces(cell, u, &mut f, scratch)
            .and_then(|()| law.energy(cell, u, scratch));
        let energy = match energy {
            Ok(e) => e,
            Err(e) => {
                error = Some(e);
                return;
            }
        };
        let fmax = f.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let ef = rel(fmax, kmax * umax);
        let ee = rel(energy.abs(), kmax * umax * umax);
        if ef > worst {
            worst = ef;
            at = format!("{name}: forces");
        }
        if ee > worst {
            worst = ee;
            at = format!("{name}: energy");
        }
    });
    if let Some(e) = error {
        return Err(failed()(e));
    }
    verdict("rigid-body motions", worst, opts.exact_tol, || at)
}

/// For `u = A x + b`: the energy equals `|K| · ½ ε : C : ε` and the stress equals
/// `C : ε` with `ε = sym(A)` and `C` = `material`. Returns the two relative
/// discrepancies `(energy, stress)`.
pub fn check_linear_field<const D: usize, L: CellLaw<D> + ?Sized>(
    law: &L,
    cell: &CellGeometry<'_, D>,
    material: &Stiffness<D>,
    grad: &Tensor<D>,
    shift: &Point<D>,
    opts: &KitOptions,
    scratch: &mut Scratch,
) -> Result<(f64, f64), KitFailure> {
    let mut u = vec![0.0; D * cell.coords.len()];
    linear_field(cell, grad, shift, &mut u);
    let eps = (grad + grad.transpose()) * 0.5;
    let e_exact = cell.volume * material.energy_density(&eps);
    let e = law
        .energy(cell, &u, scratch)
        .map_err(law_failed("linear field energy", opts.exact_tol))?;
    let ee = verdict(
        "linear field energy",
        rel((e - e_exact).abs(), e_exact.abs()),
        opts.exact_tol,
        || format!("energy {e:e}, expected {e_exact:e}"),
    )?;
    let s_exact = material.stress(&eps);
    let s = law
        .stress(cell, &u, scratch)
        .map_err(law_failed("linear field stress", opts.exact_tol))?;
    let es = verdict(
        "linear field stress",
        rel((s - s_exact).amax(), s_exact.amax()),
        opts.exact_tol,
        || format!("stress {s:?}, expected {s_exact:?}"),
    )?;
    Ok((ee, es))
}

/// Run every check on deterministic pseudo-random data (seeded by `opts.seed`): the
/// derivative and symmetry checks at a sampled displacement, the rigid-body motions, and,
/// if `material` is given, [`check_linear_field`] for a sampled gradient `A` (with both a
/// symmetric and a skew part) and shift `b`.
pub fn check_all<const D: usize, L: CellLaw<D> + ?Sized>(
    law: &L,
    cell: &CellGeometry<'_, D>,
    material: Option<&Stiffness<D>>,
    opts: &KitOptions,
) -> Result<KitReport, KitFailure> {
    let mut scratch = Scratch::default();
    let mut u = vec![0.0; D * cell.coords.len()];
    sample_displacement(cell, opts.amplitude, opts.seed, &mut u);
    let mut report = KitReport {
        forces_gradient: check_forces_gradient(law, cell, &u, opts, &mut scratch)?,
        stiffness_jacobian: check_stiffness_jacobian(law, cell, &u, opts, &mut scratch)?,
        symmetry: check_stiffness_symmetric(law, cell, &u, opts, &mut scratch)?,
        rigid_body: check_rigid_body_motions(law, cell, opts, &mut scratch)?,
        ..KitReport::default()
    };
    if let Some(m) = material {
        let mut r = Sampler::new(opts.seed ^ 0x5EED);
        let grad = Tensor::<D>::from_fn(|_, _| opts.amplitude * r.next_sym());
        let shift = Point::<D>::from_fn(|_, _| opts.amplitude * cell_diameter(cell) * r.next_sym());
        let (e, s) = check_linear_field(law, cell, m, &grad, &shift, opts, &mut scratch)?;
        report.linear_energy = Some(e);
        report.linear_stress = Some(s);
    }
    Ok(report)
}
