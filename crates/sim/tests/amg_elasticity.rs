//! Linear elasticity assembled by porofrac-sim: CG-AMG against the sparse Cholesky
//! solution, iteration counts, eliminated dofs, numeric rebuild, and a deficient
//! near-null space.

mod elasticity_systems;

use elasticity_systems::{System, build, e2, e3, rel_diff};
use porofrac_amg::{
    Amg, AmgError, AmgOptions, NearNullSpace, Precision, SymCsr, UPPER_MIN_ENTRIES_PER_ROW,
};
use porofrac_grid::{Point, generate};
use porofrac_law::Stiffness;
use porofrac_mdem::MdemLaw;
use porofrac_sim::{Displacement, Loads, Platen, ScalarField};
use porofrac_vem::VemLaw;

/// Solve with CG-AMG (rigid-body modes) from zero; returns (iterations, levels, x).
fn amg_solve<const D: usize>(
    sys: &System<D>,
    options: &AmgOptions,
    tol: f64,
) -> (usize, usize, Vec<f64>) {
    let mut amg = Amg::elasticity(sys.sym(), &sys.coords, D, &sys.eq_dofs, options).unwrap();
    let mut x = vec![0.0; sys.n()];
    let s = amg.solve(&mut x, &sys.rhs, tol, 300).unwrap();
    assert!(s.relative_residual <= tol);
    (s.iterations, amg.level_info().len(), x)
}

fn opts(max_coarse: usize) -> AmgOptions {
    AmgOptions {
        max_coarse,
        ..AmgOptions::default()
    }
}

/// E2 (2D plane strain, triangles): the CG-AMG solution equals the Cholesky solution, and
/// the iteration count is nearly independent of the mesh size (h and h/2).
#[test]
fn e2_matches_cholesky_with_bounded_iterations() {
    let mut its = Vec::new();
    for n in [40, 80, 160] {
        let sys = e2(n);
        let (it, levels, x) = amg_solve(&sys, &opts(200), 1e-11);
        let chol = sys.cholesky();
        let d = rel_diff(&x, &chol);
        println!(
            "E2 n = {n}: {} equations, {levels} levels, {it} iterations, difference {d:.2e}",
            sys.n()
        );
        // κ(A) ~ 1e4–1e5 here: a residual of 1e-11 bounds the error by ~1e-6 in the
        // worst case and ~1e-9 in practice.
        assert!(d < 1e-7, "difference {d:e}");
        assert!(levels >= 3);
        its.push(it);
    }
    // Observed 21, 22, 26 (the last with one more level): nearly independent of h. Allow
    // 30 % between successive sizes and 32 (observed + 25 %) overall.
    for w in its.windows(2) {
        let (a, b) = (w[0] as f64, w[1] as f64);
        assert!((b - a).abs() <= 0.3 * a, "iterations {its:?}");
    }
    assert!(its.iter().all(|&k| k <= 32), "iterations {its:?}");
}

/// E3 (3D, tetrahedra): same checks at n = 8 and 16.
#[test]
fn e3_matches_cholesky_with_bounded_iterations() {
    let mut its = Vec::new();
    for n in [8, 16] {
        let sys = e3(n);
        let (it, levels, x) = amg_solve(&sys, &opts(200), 1e-11);
        let chol = sys.cholesky();
        let d = rel_diff(&x, &chol);
        println!(
            "E3 n = {n}: {} equations, {levels} levels, {it} iterations, difference {d:.2e}",
            sys.n()
        );
        assert!(d < 1e-7, "difference {d:e}");
        assert!(levels >= 2);
        its.push(it);
    }
    // Observed 18 and 19: allow 30 % between h and h/2 and 24 (observed + 25 %) overall.
    let (a, b) = (its[0] as f64, its[1] as f64);
    assert!((b - a).abs() <= 0.3 * a, "iterations {its:?}");
    assert!(its.iter().all(|&k| k <= 24), "iterations {its:?}");
}

/// A cantilever with partially prescribed dofs: clamped at x = 0, a roller (only uy = 0)
/// at y = 0, MDEM law, gravity-like body force. Nodes with 0, 1 or 2 equations.
#[test]
fn rollers_and_clamps_with_mdem() {
    let grid = generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::new(4.0, 1.0), [160, 40])
        .unwrap();
    let clamp = Displacement {
        name: "xmin".into(),
        faces: grid.boundary("xmin").unwrap(),
        components: [Some(ScalarField::Const(0.0)), Some(ScalarField::Const(0.0))],
    };
    let roller = Displacement {
        name: "ymin".into(),
        faces: grid.boundary("ymin").unwrap(),
        components: [None, Some(ScalarField::Const(0.0))],
    };
    let loads = Loads {
        body_force: Some([ScalarField::Const(0.1), ScalarField::Const(-1.0)].into()),
        ..Loads::default()
    };
    let law = MdemLaw::new(&Stiffness::<2>::isotropic(1.0, 0.25).unwrap()).unwrap();
    let sys = build(grid, &[clamp, roller], &[], &loads, &law);
    let per_node = {
        let mut c = vec![0usize; sys.grid.num_nodes()];
        for &(n, _) in &sys.eq_dofs {
            c[n] += 1;
        }
        c
    };
    assert!(per_node.contains(&0) && per_node.contains(&1) && per_node.contains(&2));
    let (it, _, x) = amg_solve(&sys, &opts(200), 1e-11);
    let d = rel_diff(&x, &sys.cholesky());
    println!(
        "cantilever: {} equations, {it} iterations, difference {d:.2e}",
        sys.n()
    );
    assert!(d < 1e-7, "difference {d:e}");
    // Observed 25: a long body held at one end converges a little more slowly than E2;
    // allow 25 % more.
    assert!(it <= 32, "{it} iterations");
}

/// A rigid platen (all top nodes share one vertical equation) on a block clamped at the
/// bottom: the platen equation couples a whole row of nodes; CG-AMG still converges.
#[test]
fn platen_equation() {
    let grid =
        generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::repeat(1.0), [60, 60]).unwrap();
    let bottom = Displacement {
        name: "ymin".into(),
        faces: grid.boundary("ymin").unwrap(),
        components: [Some(ScalarField::Const(0.0)), Some(ScalarField::Const(0.0))],
    };
    let platen = Platen {
        name: "ymax".into(),
        faces: grid.boundary("ymax").unwrap(),
        force: [None, Some(ScalarField::Const(-1.0))],
    };
    let law = VemLaw::new(Stiffness::<2>::isotropic(1.0, 0.3).unwrap());
    let sys = build(grid, &[bottom], &[platen], &Loads::default(), &law);
    let (it, _, x) = amg_solve(&sys, &opts(200), 1e-11);
    let d = rel_diff(&x, &sys.cholesky());
    println!(
        "platen: {} equations, {it} iterations, difference {d:.2e}",
        sys.n()
    );
    assert!(d < 1e-7, "difference {d:e}");
    // Observed 27; allow 25 % more.
    assert!(it <= 34, "{it} iterations");
}

/// New values on the same pattern (another material): the rebuilt hierarchy solves the
/// new system as well as one built from scratch and matches Cholesky; rebuilding with the
/// original values reproduces the original solve bitwise.
#[test]
fn numeric_rebuild() {
    let mut sys = e2(60);
    let original = sys.values.clone();
    let rhs0 = sys.rhs.clone();
    let options = opts(200);
    let mut amg = Amg::elasticity(sys.sym(), &sys.coords, 2, &sys.eq_dofs, &options).unwrap();
    let mut x0 = vec![0.0; sys.n()];
    let s0 = amg.solve(&mut x0, &rhs0, 1e-11, 200).unwrap();
    let law = VemLaw::new(Stiffness::<2>::isotropic(3.0, 0.45).unwrap());
    sys.reassemble(&law);
    amg.update_values(&sys.values).unwrap();
    let mut x1 = vec![0.0; sys.n()];
    let s1 = amg.solve(&mut x1, &sys.rhs, 1e-11, 200).unwrap();
    let d = rel_diff(&x1, &sys.cholesky());
    let mut fresh = Amg::elasticity(sys.sym(), &sys.coords, 2, &sys.eq_dofs, &options).unwrap();
    let mut x2 = vec![0.0; sys.n()];
    let s2 = fresh.solve(&mut x2, &sys.rhs, 1e-11, 200).unwrap();
    println!("rebuild: ν = 0.3 {s0:?}; ν = 0.45 rebuilt {s1:?}, fresh {s2:?}, difference {d:.2e}");
    assert!(d < 1e-7, "difference {d:e}");
    // ν = 0.45 is nearer incompressibility and takes more iterations (observed 33 both).
    assert!(s1.iterations <= s2.iterations + 2, "{s1:?} vs {s2:?}");
    amg.update_values(&original).unwrap();
    let mut x3 = vec![0.0; sys.n()];
    let s3 = amg.solve(&mut x3, &rhs0, 1e-11, 200).unwrap();
    assert_eq!(s3, s0);
    assert!(x3.iter().zip(&x0).all(|(a, b)| a.to_bits() == b.to_bits()));
    // Wrong length or non-finite values are errors, not panics.
    assert!(amg.update_values(&original[1..]).is_err());
    let mut bad = original.clone();
    bad[5] = f64::NAN;
    assert!(amg.update_values(&bad).is_err());
}

/// Translations only (no rotations) is a deficient near-null space for elasticity: CG
/// still converges to the same solution, in clearly more iterations.
#[test]
fn translations_only_converge_more_slowly() {
    let sys = e2(80);
    let options = opts(200);
    let (it_rigid, _, x_rigid) = amg_solve(&sys, &options, 1e-10);
    let rigid = NearNullSpace::rigid_body_modes(&sys.coords, 2, &sys.eq_dofs).unwrap();
    let mut data = Vec::new();
    for k in 0..2 {
        data.extend_from_slice(rigid.vector(k));
    }
    let translations = NearNullSpace::from_vectors(sys.n(), data).unwrap();
    let mut amg = Amg::new(sys.sym(), &sys.nodes(), &translations, &options).unwrap();
    let mut x = vec![0.0; sys.n()];
    let s = amg.solve(&mut x, &sys.rhs, 1e-10, 300).unwrap();
    println!(
        "E2 n = 80: rigid modes {it_rigid} iterations, translations only {}",
        s.iterations
    );
    // Observed 21 and 27.
    assert!(
        s.iterations >= it_rigid + 3,
        "{} vs {it_rigid}",
        s.iterations
    );
    assert!(rel_diff(&x, &x_rigid) < 1e-7);
}

/// 3D elasticity gives bitwise the same hierarchy and solution with one thread and two,
/// with the finest matrix in double precision and in single precision (whose smoother
/// and spectral estimate multiply by its upper triangle: 3D rows are long enough).
#[test]
fn elasticity_does_not_depend_on_the_thread_count() {
    let sys = e3(10);
    let run = |threads: usize, precision: Precision| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let sym = SymCsr::from_upper_csc_in(
                    precision,
                    sys.n(),
                    sys.pattern.col_ptr(),
                    sys.pattern.row_idx(),
                    &sys.values,
                )
                .unwrap();
                let mut amg =
                    Amg::elasticity(sym, &sys.coords, 3, &sys.eq_dofs, &opts(100)).unwrap();
                let mut x = vec![0.0; sys.n()];
                let s = amg
                    .solve_upper(&sys.values, &mut x, &sys.rhs, 1e-10, 100)
                    .unwrap();
                (amg.level_info(), s, x)
            })
    };
    assert!(2 * sys.pattern.nnz() - sys.n() >= UPPER_MIN_ENTRIES_PER_ROW * sys.n());
    for precision in [Precision::Double, Precision::Single] {
        let (l1, s1, x1) = run(1, precision);
        let (l2, s2, x2) = run(2, precision);
        assert!(l1.len() >= 2);
        assert_eq!(l1, l2);
        assert_eq!(s1, s2);
        assert!(x1.iter().zip(&x2).all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}

/// Aggressive coarsening (aggregation on the distance-two strength graph on the finest
/// level): the same solution as Cholesky with a much smaller hierarchy — operator
/// complexity below 1.25 against 1.4–1.5 (observed 1.12 / 1.11 / 1.03 against 1.44) —
/// and iterations still nearly independent of h (observed 28, 32 on E2 n = 80, 160 and 24
/// on E3 n = 16; allowed: 40 and 30 % between h and h/2).
#[test]
fn aggressive_coarsening_keeps_the_solution_with_a_smaller_hierarchy() {
    let aggressive = AmgOptions {
        aggressive_levels: 1,
        ..opts(200)
    };
    let mut its = Vec::new();
    for n in [80, 160] {
        let sys = e2(n);
        let mut amg =
            Amg::elasticity(sys.sym(), &sys.coords, 2, &sys.eq_dofs, &aggressive).unwrap();
        let plain = Amg::elasticity(sys.sym(), &sys.coords, 2, &sys.eq_dofs, &opts(200)).unwrap();
        let mut x = vec![0.0; sys.n()];
        let s = amg.solve(&mut x, &sys.rhs, 1e-11, 300).unwrap();
        let d = rel_diff(&x, &sys.cholesky());
        let (oc, oc_plain) = (amg.operator_complexity(), plain.operator_complexity());
        println!(
            "E2 n = {n}: {} iterations, operator complexity {oc:.3} (plain {oc_plain:.3}), difference {d:.2e}",
            s.iterations
        );
        assert!(d < 1e-7, "difference {d:e}");
        assert!(oc < 1.25 && oc_plain > 1.35, "{oc} vs {oc_plain}");
        its.push(s.iterations);
    }
    let sys = e3(16);
    let mut amg = Amg::elasticity(sys.sym(), &sys.coords, 3, &sys.eq_dofs, &aggressive).unwrap();
    let mut x = vec![0.0; sys.n()];
    let s = amg.solve(&mut x, &sys.rhs, 1e-11, 300).unwrap();
    let d = rel_diff(&x, &sys.cholesky());
    println!(
        "E3 n = 16: {} iterations, operator complexity {:.3}, difference {d:.2e}",
        s.iterations,
        amg.operator_complexity()
    );
    assert!(d < 1e-7, "difference {d:e}");
    assert!(amg.operator_complexity() < 1.25);
    its.push(s.iterations);
    assert!(its.iter().all(|&k| k <= 40), "iterations {its:?}");
    assert!(
        (its[1] as f64 - its[0] as f64).abs() <= 0.3 * its[0] as f64,
        "{its:?}"
    );
}

/// The strength threshold θ = 0.08 (porofrac-sim's 2D default) drops weak couplings on
/// the coarse levels: fewer CG iterations than θ = 0 on E2 (observed 22 against 26 at
/// n = 160; 16 against 26 at n = 1000 in docs/BENCHMARKS.md), the same solution.
#[test]
fn strength_threshold_cuts_iterations_in_2d() {
    let sys = e2(160);
    let theta = AmgOptions {
        strength_threshold: 0.08,
        ..opts(200)
    };
    let (it0, _, x0) = amg_solve(&sys, &opts(200), 1e-11);
    let (it1, _, x1) = amg_solve(&sys, &theta, 1e-11);
    println!("E2 n = 160: θ = 0: {it0} iterations, θ = 0.08: {it1}");
    assert!(rel_diff(&x0, &x1) < 1e-7);
    assert!(it1 < it0, "θ = 0.08: {it1} iterations, θ = 0: {it0}");
}

/// The finest matrix stored in single precision: CG multiplies by the double-precision
/// values ([`Amg::solve_upper`]), so the solution matches Cholesky as closely as with a
/// double-precision hierarchy, in about as many iterations; [`Amg::solve`] refuses such a
/// hierarchy; numeric updates and [`Amg::has_values`] work on the rounded values.
#[test]
fn single_precision_finest_matrix() {
    fn check<const D: usize>(sys: &System<D>, tol: f64, max_iter: usize) {
        let options = opts(200);
        let mut double =
            Amg::elasticity(sys.sym(), &sys.coords, D, &sys.eq_dofs, &options).unwrap();
        let mut x = vec![0.0; sys.n()];
        let it_double = double
            .solve(&mut x, &sys.rhs, tol, max_iter)
            .unwrap()
            .iterations;
        // A double-precision hierarchy with the upper triangle as operator: the same
        // solve up to the summation order of the products.
        let mut y = vec![0.0; sys.n()];
        let s_upper = double
            .solve_upper(&sys.values, &mut y, &sys.rhs, tol, max_iter)
            .unwrap();
        assert!(s_upper.iterations.abs_diff(it_double) <= 1);
        assert!(rel_diff(&y, &x) < 1e2 * tol, "{:e}", rel_diff(&y, &x));
        let chol = sys.cholesky();
        let single = SymCsr::from_upper_csc_in(
            Precision::Single,
            sys.n(),
            sys.pattern.col_ptr(),
            sys.pattern.row_idx(),
            &sys.values,
        )
        .unwrap();
        let mut amg = Amg::elasticity(single, &sys.coords, D, &sys.eq_dofs, &options).unwrap();
        assert_eq!(amg.matrix().precision(), Precision::Single);
        assert!(amg.level_info().len() >= 2);
        x.fill(0.0);
        assert!(matches!(
            amg.solve(&mut x, &sys.rhs, tol, max_iter),
            Err(AmgError::Input(_))
        ));
        let s = amg
            .solve_upper(&sys.values, &mut x, &sys.rhs, tol, max_iter)
            .unwrap();
        let d = rel_diff(&x, &chol);
        println!(
            "E{D}: {} equations, {} iterations in single precision, {it_double} in double, difference {d:.2e}",
            sys.n(),
            s.iterations
        );
        assert!(s.relative_residual <= tol);
        assert!(d < 1e4 * tol, "difference {d:e}");
        assert!(
            s.iterations as f64 <= 1.1 * it_double as f64 + 3.0,
            "{} vs {it_double}",
            s.iterations
        );
        // Values rounded to f32 compare equal; a change the rounding keeps is not seen.
        assert!(amg.has_values(&sys.values));
        let mut nudged = sys.values.clone();
        nudged[0] *= 1.0 + 1e-12;
        assert!(amg.has_values(&nudged));
        nudged[0] *= 1.0 + 1e-3;
        assert!(!amg.has_values(&nudged));
        // Twice the matrix: half the solution.
        let doubled: Vec<f64> = sys.values.iter().map(|v| 2.0 * v).collect();
        amg.update_values(&doubled).unwrap();
        assert!(amg.has_values(&doubled));
        let mut y = vec![0.0; sys.n()];
        amg.solve_upper(&doubled, &mut y, &sys.rhs, tol, max_iter)
            .unwrap();
        let half: Vec<f64> = chol.iter().map(|v| 0.5 * v).collect();
        assert!(rel_diff(&y, &half) < 1e4 * tol);
        // Wrong length and non-finite values are refused.
        assert!(
            amg.solve_upper(&doubled[1..], &mut y, &sys.rhs, 1e-11, 300)
                .is_err()
        );
        let mut bad = doubled.clone();
        bad[3] = f64::NAN;
        assert!(amg.solve_upper(&bad, &mut y, &sys.rhs, 1e-11, 300).is_err());
    }
    check(&e2(80), 1e-11, 300);
    check(&e3(12), 1e-11, 300);
    // Near incompressibility (ν = 0.499: the bulk modulus 500 times the shear modulus)
    // makes A much worse conditioned, so rounding it to f32 perturbs its smallest
    // eigenvalues the most; the preconditioner built from the rounded matrix still works.
    let mut sys = e2(80);
    sys.reassemble(&VemLaw::new(Stiffness::<2>::isotropic(1.0, 0.499).unwrap()));
    check(&sys, 1e-8, 3000);
}
