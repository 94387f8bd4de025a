//! GMRES with the multigrid preconditioner, with the `LDLᵀ` preconditioner, and the
//! `LDLᵀ` + Schur complement solve against the sparse LU:
//!
//! * the plate with a hole (level 2, 1,280 triangles, N = 0.5, r/ℓ = 1.063): each solution
//!   at GMRES tolerance 1e-12 equals the LU's to 1e-9 of its largest entry, the stress
//!   concentration factor to 1e-9 relative, in fewer than 150 iterations (the multigrid),
//!   60 (the `LDLᵀ` preconditioner), 2 (the Schur complement solve with double-precision
//!   factors, exact up to rounding) and 6 (with single-precision factors, whose error of
//!   about `κ ε₃₂` GMRES removes);
//! * the Newmark matrix of the same plate (a step load held for 10 steps) and of a 3D
//!   clamped box of tetrahedra under a body force: every step converges and the states
//!   equal the LU's to 1e-8 of their largest entry (GMRES with the multigrid and the Schur
//!   complement solve; the latter with double-precision factors is exact up to rounding,
//!   which on the strongly graded level-1 plate leaves a relative residual above 1e-12
//!   that at most 3 iterations per step remove, with single-precision ones at most 6);
//! * the error path: too few iterations is [`CosseratError::NotConverged`] with the
//!   residual reached, never a NaN.

mod common;

use porofrac_cosserat::{
    BodyLoads, Condition, Cosserat, CosseratError, Dynamics, FactorPrecision, GmresOptions,
    Integrator, LinearOptions, LinearSolver, Material, Options, constant, mesh, strain_index,
};
use porofrac_grid::Point;
use porofrac_grid::generate::{perturb, simplices};

fn plate(level: usize) -> Cosserat<2> {
    let (r, n) = (0.216, 0.5f64);
    let grid =
        mesh::plate_with_hole(16.2, r, 16 * level, 10 * level, 0.1 * r / level as f64).unwrap();
    let a = n * n / (1.0 - n * n);
    let m = Material::with_length(1e3, 0.3, a * 1e3, r / 1.063)
        .unwrap()
        .with_inertia(1e-3, 1e-4)
        .unwrap();
    let left = Condition::new(grid.boundary("xmin").unwrap())
        .fix(0, constant(0.0))
        .fix(2, constant(0.0));
    let bottom = Condition::new(grid.boundary("ymin").unwrap())
        .fix(1, constant(0.0))
        .fix(2, constant(0.0));
    let top = Condition::new(grid.boundary("ymax").unwrap()).load(1, constant(1.0));
    Cosserat::new(
        grid,
        m,
        Options::default(),
        &[left, bottom, top],
        BodyLoads::none(),
    )
    .unwrap()
}

fn options(solver: LinearSolver, tolerance: f64) -> LinearOptions {
    options_in(solver, tolerance, FactorPrecision::default())
}

fn options_in(solver: LinearSolver, tolerance: f64, precision: FactorPrecision) -> LinearOptions {
    LinearOptions {
        solver,
        gmres: GmresOptions {
            tolerance,
            factor_precision: precision,
            ..GmresOptions::default()
        },
    }
}

use FactorPrecision::{Double, Single};

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

fn scf(model: &Cosserat<2>, w: &[f64]) -> f64 {
    (0..model.grid().num_cells())
        .map(|c| model.cell_stress(c, w)[strain_index(2, 1, 1)])
        .fold(f64::MIN, f64::max)
}

#[test]
fn plate_with_hole_gmres_equals_lu() {
    let model = plate(2);
    let (lu, _, used) = model
        .solve_static_with(0.0, &options(LinearSolver::Lu, 1e-12))
        .unwrap();
    assert_eq!(used, LinearSolver::Lu);
    for (solver, precision, max_its) in [
        (LinearSolver::GmresAmg, Single, 150),
        (LinearSolver::GmresLdlt, Single, 60),
        (LinearSolver::GmresLdlt, Double, 60),
        (LinearSolver::LdltSchur, Double, 2),
        (LinearSolver::LdltSchur, Single, 6),
    ] {
        let name = format!("{} {precision:?}", solver.name());
        let (gm, stats, used) = model
            .solve_static_with(0.0, &options_in(solver, 1e-12, precision))
            .unwrap();
        assert_eq!(used, solver);
        if solver != LinearSolver::GmresAmg {
            assert_eq!(stats.factor_precision, Some(precision));
        }
        assert!(stats.max_residual <= 1e-12, "{stats:?}");
        assert!(stats.iterations <= max_its, "{name} {stats:?}");
        let d = max_diff(&lu, &gm) / max_abs(&lu);
        assert!(d < 1e-9, "{name}: relative difference {d:.2e} ({stats:?})");
        let (s_lu, s_gm) = (scf(&model, &lu), scf(&model, &gm));
        assert!(
            ((s_gm - s_lu) / s_lu).abs() < 1e-9,
            "{name}: SCF {s_gm} against {s_lu}"
        );
    }
}

/// The model's boundary difference `Z B Zᵀ` is the system minus the preconditioning
/// matrix, entry by entry (to rounding), and has two columns per fixed component of a
/// boundary facet.
#[test]
fn boundary_difference_is_system_minus_preconditioner() {
    let model = plate(2);
    let (k, p) = (model.system_values(), model.preconditioner_values());
    let e = model.boundary_difference();
    let pat = model.pattern();
    let n = pat.equations();
    // Fixed: u_x and φ on the facets of x = 0, u_y and φ on those of y = 0.
    let facets = |name| model.grid().boundary(name).unwrap().len();
    assert_eq!(e.blocks.len(), 2 * (facets("xmin") + facets("ymin")));
    assert_eq!(e.columns.len(), 2 * e.blocks.len());
    let mut zbz = std::collections::HashMap::<(usize, usize), f64>::new();
    for (b, pair) in e.blocks.iter().zip(e.columns.chunks(2)) {
        for (a, za) in pair.iter().enumerate() {
            for (c, zc) in pair.iter().enumerate() {
                for &(i, vi) in za {
                    for &(j, vj) in zc {
                        *zbz.entry((i, j)).or_default() += b[a + 2 * c] * vi * vj;
                    }
                }
            }
        }
    }
    let mut scale = 0.0f64;
    let mut worst = 0.0f64;
    for j in 0..n {
        for q in pat.col_ptr[j]..pat.col_ptr[j + 1] {
            let d = k[q] - p[q];
            scale = scale.max(d.abs());
            let z = zbz.remove(&(pat.row_idx[q], j)).unwrap_or(0.0);
            worst = worst.max((d - z).abs());
        }
    }
    assert!(scale > 0.0);
    assert!(
        worst <= 1e-12 * scale,
        "|K − P − Z B Zᵀ| = {worst:e} of {scale:e}"
    );
    // Nothing outside the pattern.
    assert!(zbz.values().all(|v| v.abs() <= 1e-12 * scale));
}

/// Both forms of the Schur complement solve — the bordered matrix of the model's boundary
/// difference and the unknowns `T` ordered last, found from the values alone — give the
/// LU's solution; with double-precision factors each is exact up to rounding (one
/// iteration).
#[test]
fn bordered_and_trailing_schur_solves_equal_lu() {
    use porofrac_cosserat::linear::{Linear, SchurAnalysis, SystemRef};
    let model = plate(2);
    let (lu, _, _) = model
        .solve_static_with(0.0, &options(LinearSolver::Lu, 1e-12))
        .unwrap();
    let (values, pre, centres) = (
        model.system_values(),
        model.preconditioner_values(),
        model.centres(),
    );
    let sys = SystemRef {
        pattern: model.pattern(),
        values: &values,
        preconditioner: &pre,
        centres: &centres,
        dim: 2,
    };
    let mut rhs = vec![0.0; model.equations()];
    model.rhs(0.0, &mut rhs);
    let difference = model.boundary_difference();
    let mut entries = Vec::new();
    for bordered in [true, false] {
        for precision in [Double, Single] {
            let name = if bordered { "bordered" } else { "T last" };
            // The single-precision analysis with its factor's memory reserved, as the
            // model prepares it.
            let analysis = bordered.then(|| {
                SchurAnalysis::bordered(model.pattern(), &difference, precision == Single).unwrap()
            });
            if let Some(a) = &analysis {
                assert!(a.is_bordered());
                assert_eq!(a.dense_len(), difference.columns.len());
            }
            let opts = options_in(LinearSolver::LdltSchur, 1e-12, precision);
            let mut lin = Linear::with_analysis(sys, &opts, analysis).unwrap();
            let mut x = rhs.clone();
            lin.solve(&mut x, None).unwrap();
            let st = lin.stats();
            entries.push(st.factor_entries);
            let max_its = if precision == Double { 1 } else { 6 };
            assert!(st.max_iterations <= max_its, "{name} {precision:?}: {st:?}");
            assert!(st.max_residual <= 1e-12, "{name} {precision:?}: {st:?}");
            let d = max_diff(&lu, &x) / max_abs(&lu);
            assert!(
                d < 1e-9,
                "{name} {precision:?}: relative difference {d:.2e}"
            );
        }
    }
    // The bordered form was used (no fallback): fewer entries in its factors and dense
    // blocks than with `T` last.
    assert!(
        entries[0] < entries[2] && entries[1] < entries[3],
        "{entries:?}"
    );
}

/// `auto`: the Schur complement solve for a static 2D plate, the LU for a small 3D box.
#[test]
fn auto_takes_the_schur_solve_for_a_static_plate() {
    assert_eq!(LinearSolver::Auto.resolve(8_640), LinearSolver::LdltSchur);
    assert_eq!(LinearSolver::Auto.resolve(311_040), LinearSolver::GmresAmg);
    assert_eq!(LinearSolver::Auto.resolve_newmark(8_640), LinearSolver::Lu);
    let (_, _, used) = plate(1)
        .solve_static_with(0.0, &options(LinearSolver::Auto, 1e-10))
        .unwrap();
    assert_eq!(used, LinearSolver::LdltSchur);
    let (_, _, used) = clamped_box()
        .solve_static_with(0.0, &options(LinearSolver::Auto, 1e-10))
        .unwrap();
    assert_eq!(used, LinearSolver::Lu);
}

/// A clamped perturbed box of tetrahedra under gravity.
fn clamped_box() -> Cosserat<3> {
    let g = perturb(
        &simplices(
            Point::<3>::zeros(),
            Point::<3>::new(1.0, 0.6, 0.5),
            [4, 3, 2],
        )
        .unwrap(),
        0.2,
        6,
    )
    .unwrap();
    let m = Material::with_couple_moduli(1000.0, 0.25, 300.0, [1.0, 2.0, 0.5])
        .unwrap()
        .with_inertia(2.0, 0.02)
        .unwrap();
    let clamp = Condition::new(g.boundary("xmin").unwrap()).clamp(vec![constant(0.0); 6]);
    let body = BodyLoads::none().with(2, constant(-9.81));
    Cosserat::new(g, m, Options::default(), &[clamp], body).unwrap()
}

/// Newmark states with the LU and with `solver` after `steps` steps.
fn newmark_pair<const D: usize>(
    model: &Cosserat<D>,
    dt: f64,
    steps: usize,
    other: LinearSolver,
    precision: FactorPrecision,
) -> (Vec<f64>, Vec<f64>, usize) {
    let n = model.equations();
    let mut states = Vec::new();
    let mut iterations = 0;
    for solver in [LinearSolver::Lu, other] {
        let mut d = Dynamics::with_solver(
            model,
            Integrator::Newmark,
            dt,
            0.0,
            vec![0.0; n],
            vec![0.0; n],
            &options_in(solver, 1e-12, precision),
        )
        .unwrap();
        assert_eq!(d.solver().unwrap().solver(), solver);
        for _ in 0..steps {
            d.step(model).unwrap();
        }
        let st = d.solver_stats();
        assert_eq!(st.solves, steps);
        if solver != LinearSolver::Lu {
            assert!(st.max_residual <= 1e-12, "{st:?}");
            iterations = st.max_iterations;
        }
        states.push(d.u);
    }
    let g = states.pop().unwrap();
    (states.pop().unwrap(), g, iterations)
}

#[test]
fn newmark_gmres_equals_lu_in_2d_and_3d() {
    // The plate: a step load; dt about a tenth of the time a shear wave takes to cross it.
    let model = plate(1);
    for (solver, precision, max_its) in [
        (LinearSolver::GmresAmg, Single, 100),
        (LinearSolver::LdltSchur, Double, 3),
        (LinearSolver::LdltSchur, Single, 6),
    ] {
        let name = format!("{} {precision:?}", solver.name());
        let (lu, gm, its) = newmark_pair(&model, 0.05, 10, solver, precision);
        let d = max_diff(&lu, &gm) / max_abs(&lu);
        assert!(max_abs(&lu) > 0.0);
        assert!(
            d < 1e-8,
            "2D {name}: relative difference {d:.2e} (max iterations {its})"
        );
        assert!(its <= max_its, "2D {name}: {its} iterations");
    }

    // 3D: a clamped perturbed box of tetrahedra under gravity.
    let model = clamped_box();
    for (solver, precision, max_its) in [
        (LinearSolver::GmresAmg, Single, 100),
        (LinearSolver::LdltSchur, Double, 3),
        (LinearSolver::LdltSchur, Single, 6),
    ] {
        let name = format!("{} {precision:?}", solver.name());
        let (lu, gm, its) = newmark_pair(&model, 5e-3, 10, solver, precision);
        let d = max_diff(&lu, &gm) / max_abs(&lu);
        assert!(max_abs(&lu) > 0.0);
        assert!(
            d < 1e-8,
            "3D {name}: relative difference {d:.2e} (max iterations {its})"
        );
        assert!(its <= max_its, "3D {name}: {its} iterations");
    }
}

#[test]
fn too_few_iterations_is_an_error_with_the_residual() {
    let model = plate(1);
    let mut o = options(LinearSolver::GmresAmg, 1e-12);
    o.gmres.max_iterations = 3;
    let e = model.solve_static_with(0.0, &o).unwrap_err();
    match e {
        CosseratError::NotConverged {
            iterations,
            residual,
            tolerance,
        } => {
            assert_eq!(iterations, 3);
            assert!(residual.is_finite() && residual > tolerance, "{residual}");
        }
        e => panic!("unexpected error {e}"),
    }
}

/// The parallel assembly is deterministic: one and two threads give bitwise the same
/// matrices; and the solve whose symbolic analysis was prepared beside the assembly (the
/// first set-up of the model) gives bitwise the solution of one analysed afresh (the
/// second).
#[test]
fn parallel_assembly_and_prepared_analysis_are_deterministic() {
    let pool = |t| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
    };
    let one = pool(1).install(|| plate(1));
    let two = pool(2).install(|| plate(1));
    assert_eq!(one.symmetric_values(), two.symmetric_values());
    assert_eq!(one.nitsche_values(), two.nitsche_values());
    assert!(one.symmetric_values().iter().any(|&v| v != 0.0));
    let opts = options(LinearSolver::LdltSchur, 1e-12);
    let (v, p) = (two.system_values(), two.preconditioner_values());
    let solve = |model: &Cosserat<2>| {
        let mut lin = model.linear(v.clone(), p.clone(), &opts).unwrap();
        let mut x = vec![0.0; model.equations()];
        model.rhs(0.0, &mut x);
        lin.solve(&mut x, None).unwrap();
        x
    };
    let prepared = solve(&two);
    let fresh = solve(&two);
    assert_eq!(prepared, fresh);
    assert!(prepared.iter().any(|&x| x != 0.0));
}

/// The numeric `LDLᵀ` factorisation gives bitwise the same solution on one thread as on
/// two, in single and in double precision, on the plate of 5,120 triangles (15,360
/// unknowns, large enough for faer to split its supernodal work): so choosing its thread
/// count by size ([`porofrac_cosserat::linear::FACTOR_PARALLEL_MULTIPLY_ADDS`]) leaves
/// the solutions of the plate unchanged.
#[test]
fn factorisation_on_one_and_two_threads_is_bitwise_the_same() {
    use porofrac_sparse::{Ldlt, LdltSingle, Par};
    let model = plate(4);
    let (p, values) = (model.pattern(), model.preconditioner_values());
    let n = p.equations();
    assert!(n >= 15_000, "{n} unknowns");
    let mut rhs = vec![0.0; n];
    model.rhs(0.0, &mut rhs);
    let solve = |par: Par, single: bool| {
        let analysis = Ldlt::analyse(n, &p.col_ptr, &p.row_idx, None).unwrap();
        let mut x = rhs.clone();
        if single {
            let mut f = LdltSingle::new(analysis);
            f.set_parallelism(par);
            f.factorize(&p.col_ptr, &p.row_idx, &values, true).unwrap();
            f.solve_in_place(&mut x).unwrap();
        } else {
            let mut f = analysis;
            f.set_parallelism(par);
            f.factorize(&p.col_ptr, &p.row_idx, &values).unwrap();
            f.solve_in_place(&mut x).unwrap();
        }
        x
    };
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for single in [true, false] {
        let seq = solve(Par::Seq, single);
        let par = two.install(|| solve(Par::rayon(2), single));
        assert!(seq.iter().all(|v| v.is_finite()) && max_abs(&seq) > 0.0);
        assert_eq!(seq, par, "single precision: {single}");
    }
}
