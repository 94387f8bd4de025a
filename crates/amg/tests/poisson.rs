//! Scalar problems: the 1D and 2D Poisson equations (null space = constants), error cases,
//! determinism across thread counts, and random diagonally dominant SPD matrices.

use porofrac_amg::{Amg, AmgError, AmgOptions, CgStats, NearNullSpace, SymCsr};
use proptest::prelude::*;

/// Upper triangle (CSC) of the 1D Dirichlet Laplacian `[−1 2 −1]` on `n` points.
fn laplace_1d(n: usize) -> SymCsr {
    let mut cp = vec![0];
    let mut ri = vec![];
    let mut v = vec![];
    for c in 0..n {
        if c > 0 {
            ri.push(c - 1);
            v.push(-1.0);
        }
        ri.push(c);
        v.push(2.0);
        cp.push(ri.len());
    }
    SymCsr::from_upper_csc(n, &cp, &ri, &v).unwrap()
}

/// Upper-triangle values of [`laplace_2d`].
fn laplace_values(m: usize) -> Vec<f64> {
    (0..m * m)
        .flat_map(|c| {
            let (i, j) = (c % m, c / m);
            let mut col = vec![];
            if j > 0 {
                col.push(-1.0);
            }
            if i > 0 {
                col.push(-1.0);
            }
            col.push(4.0);
            col
        })
        .collect()
}

/// Upper triangle (CSC) of the 5-point Dirichlet Laplacian on an `m × m` interior grid.
fn laplace_2d(m: usize) -> SymCsr {
    let n = m * m;
    let mut cp = vec![0];
    let mut ri = vec![];
    let mut v = vec![];
    for c in 0..n {
        let (i, j) = (c % m, c / m);
        if j > 0 {
            ri.push(c - m);
            v.push(-1.0);
        }
        if i > 0 {
            ri.push(c - 1);
            v.push(-1.0);
        }
        ri.push(c);
        v.push(4.0);
        cp.push(ri.len());
    }
    SymCsr::from_upper_csc(n, &cp, &ri, &v).unwrap()
}

/// A smooth-plus-rough exact solution, the matching `b = A x`, and the solve's stats and
/// relative error.
fn solve_known(a: SymCsr, options: &AmgOptions, tol: f64) -> (CgStats, f64, usize) {
    let n = a.n();
    let exact: Vec<f64> = (0..n)
        .map(|i| (i as f64 * 0.37).sin() + (i % 7) as f64 * 0.1)
        .collect();
    let mut b = vec![0.0; n];
    a.mul(&exact, &mut b).unwrap();
    let mut amg = Amg::scalar(a, options).unwrap();
    let levels = amg.level_info().len();
    let mut x = vec![0.0; n];
    let stats = amg.solve(&mut x, &b, tol, 200).unwrap();
    // Independent check of the reported residual.
    let mut ax = vec![0.0; n];
    amg.matrix().mul(&x, &mut ax).unwrap();
    let res = ax
        .iter()
        .zip(&b)
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt()
        / b.iter().map(|q| q * q).sum::<f64>().sqrt();
    assert!(res <= tol, "true residual {res:e} > {tol:e}");
    assert!((res - stats.relative_residual).abs() <= 1e-3 * tol);
    let err = x
        .iter()
        .zip(&exact)
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt()
        / exact.iter().map(|q| q * q).sum::<f64>().sqrt();
    (stats, err, levels)
}

fn small_coarse() -> AmgOptions {
    AmgOptions {
        max_coarse: 50,
        ..AmgOptions::default()
    }
}

/// Multigrid on the 1D Laplacian: iteration counts do not grow with `n` although the
/// condition number grows like `n²` (4× per doubling; unpreconditioned CG would need
/// about 2× the iterations per doubling).
#[test]
fn poisson_1d_iterations_independent_of_size() {
    let mut its = Vec::new();
    for n in [4_000, 8_000, 16_000] {
        let (stats, err, levels) = solve_known(laplace_1d(n), &small_coarse(), 1e-10);
        println!("1D n = {n}: {levels} levels, {stats:?}, error {err:.2e}");
        // κ(A) ≈ 4n²/π² ≤ 1.1e8: error ≤ κ · residual = 1.1e-2 in the worst case; the
        // smooth exact solution keeps it far smaller.
        assert!(err < 1e-4, "error {err:e}");
        assert!(levels >= 4);
        its.push(stats.iterations);
    }
    // Observed 15 at every size. Nearly h-independent: successive sizes may differ by at
    // most 30 %, and no size needs more than 20 (observed + 1/3).
    for w in its.windows(2) {
        let (a, b) = (w[0] as f64, w[1] as f64);
        assert!((b - a).abs() <= 0.3 * a, "iterations {its:?}");
    }
    assert!(its.iter().all(|&k| k <= 20), "iterations {its:?}");
}

/// The same for the 2D 5-point Laplacian at h and h/2 (and h/4).
#[test]
fn poisson_2d_iterations_independent_of_size() {
    let mut its = Vec::new();
    for m in [64, 128, 256] {
        let (stats, err, levels) = solve_known(laplace_2d(m), &small_coarse(), 1e-10);
        println!("2D m = {m}: {levels} levels, {stats:?}, error {err:.2e}");
        assert!(err < 1e-6, "error {err:e}");
        its.push(stats.iterations);
    }
    // Observed 16 at every size; same bounds as in 1D.
    for w in its.windows(2) {
        let (a, b) = (w[0] as f64, w[1] as f64);
        assert!((b - a).abs() <= 0.3 * a, "iterations {its:?}");
    }
    assert!(its.iter().all(|&k| k <= 20), "iterations {its:?}");
}

/// A small matrix is solved directly: one iteration, residual at rounding level.
#[test]
fn small_problem_is_one_direct_solve() {
    let (stats, err, levels) = solve_known(laplace_2d(10), &AmgOptions::default(), 1e-12);
    assert_eq!(levels, 1);
    assert_eq!(stats.iterations, 1);
    assert!(err < 1e-12);
}

/// The zero right-hand side gives zero; a converged initial guess takes no iteration.
#[test]
fn trivial_right_hand_sides() {
    let a = laplace_2d(40);
    let n = a.n();
    let mut amg = Amg::scalar(a, &small_coarse()).unwrap();
    let mut x = vec![1.0; n];
    let s = amg.solve(&mut x, &vec![0.0; n], 1e-8, 10).unwrap();
    assert_eq!(s.iterations, 0);
    assert!(x.iter().all(|&v| v == 0.0));
    let b = vec![1.0; n];
    let s = amg.solve(&mut x, &b, 1e-10, 100).unwrap();
    let again = amg.solve(&mut x, &b, 1e-10, 100).unwrap();
    assert!(s.iterations > 0);
    assert_eq!(again.iterations, 0);
}

/// Error cases: sizes, non-finite numbers, tolerance, iteration limit, options,
/// non-positive diagonal, indefinite matrix.
#[test]
fn errors_are_reported() {
    let a = laplace_2d(40);
    let n = a.n();
    let mut amg = Amg::scalar(a.clone(), &small_coarse()).unwrap();
    let b = vec![1.0; n];
    let mut x = vec![0.0; n];
    assert!(matches!(
        amg.solve(&mut x[..n - 1], &b, 1e-8, 10),
        Err(AmgError::Input(_))
    ));
    let mut bad = b.clone();
    bad[7] = f64::NAN;
    assert_eq!(
        amg.solve(&mut x, &bad, 1e-8, 10),
        Err(AmgError::NotFinite {
            what: "right-hand side",
            index: 7
        })
    );
    let mut xbad = x.clone();
    xbad[3] = f64::INFINITY;
    assert!(matches!(
        amg.solve(&mut xbad, &b, 1e-8, 10),
        Err(AmgError::NotFinite { index: 3, .. })
    ));
    for tol in [0.0, -1.0, f64::NAN] {
        assert!(matches!(
            amg.solve(&mut x, &b, tol, 10),
            Err(AmgError::Input(_))
        ));
    }
    // Too few iterations: an error naming the iterations and the residual reached.
    match amg.solve(&mut x, &b, 1e-14, 2) {
        Err(AmgError::NoConvergence {
            iterations,
            residual,
            tolerance,
        }) => {
            assert_eq!(iterations, 2);
            assert!(residual > 1e-14 && residual < 1.0);
            assert_eq!(tolerance, 1e-14);
        }
        other => panic!("{other:?}"),
    }
    // A tolerance below rounding: the residual stops decreasing, reported as stagnation
    // well before the iteration limit.
    x.fill(0.0);
    match amg.solve(&mut x, &b, 1e-19, 10_000) {
        Err(AmgError::Stagnation {
            iterations,
            residual,
            ..
        }) => {
            println!("stagnation after {iterations} iterations at {residual:e}");
            assert!(iterations < 200 && residual < 1e-13);
        }
        other => panic!("{other:?}"),
    }
    // Bad options and sizes.
    for o in [
        AmgOptions {
            smoother_degree: 0,
            ..AmgOptions::default()
        },
        AmgOptions {
            chebyshev_ratio: 1.0,
            ..AmgOptions::default()
        },
        AmgOptions {
            max_levels: 0,
            ..AmgOptions::default()
        },
        AmgOptions {
            prolongation_damping: f64::NAN,
            ..AmgOptions::default()
        },
    ] {
        assert!(matches!(
            Amg::scalar(a.clone(), &o),
            Err(AmgError::Input(_))
        ));
    }
    let null = NearNullSpace::constant(n - 1).unwrap();
    let nodes: Vec<usize> = (0..n).collect();
    assert!(matches!(
        Amg::new(a.clone(), &nodes, &null, &AmgOptions::default()),
        Err(AmgError::Input(_))
    ));
    // A negative diagonal entry.
    let neg = SymCsr::from_upper_csc(2, &[0, 1, 3], &[0, 0, 1], &[1.0, 0.5, -2.0]).unwrap();
    assert_eq!(
        Amg::scalar(neg, &AmgOptions::default()).unwrap_err(),
        AmgError::NonPositiveDiagonal {
            level: 0,
            equation: 1,
            value: -2.0
        }
    );
    // Positive diagonal but indefinite ([[1, 2], [2, 1]]): the direct coarse solve says so.
    let indef = SymCsr::from_upper_csc(2, &[0, 1, 3], &[0, 0, 1], &[1.0, 2.0, 1.0]).unwrap();
    assert!(matches!(
        Amg::scalar(indef, &AmgOptions::default()),
        Err(AmgError::CoarseNotPositiveDefinite { .. })
    ));
}

/// New values that make the matrix indefinite (the 2D Laplacian shifted by −0.5 I:
/// diagonal 3.5 > 0, eigenvalues down to −0.5) are caught by the numeric rebuild: a
/// Galerkin operator gets a negative diagonal (or the coarsest factorization fails). The
/// hierarchy then refuses to solve until an update succeeds.
#[test]
fn indefinite_update_fails_loudly() {
    let m = 40;
    let a = laplace_2d(m);
    let n = a.n();
    let shifted: Vec<f64> = laplace_values(m)
        .iter()
        .map(|&v| if v == 4.0 { 3.5 } else { v })
        .collect();
    let mut amg = Amg::scalar(a, &small_coarse()).unwrap();
    let r = amg.update_values(&shifted);
    println!("update with the shifted values: {r:?}");
    assert!(
        matches!(
            r,
            Err(AmgError::CoarseNotPositiveDefinite { .. } | AmgError::NonPositiveDiagonal { .. })
        ),
        "{r:?}"
    );
    let b = vec![1.0; n];
    let mut x = vec![0.0; n];
    assert!(matches!(
        amg.solve(&mut x, &b, 1e-8, 10),
        Err(AmgError::Input(_))
    ));
    amg.update_values(&laplace_values(m)).unwrap();
    amg.solve(&mut x, &b, 1e-8, 100).unwrap();
}

/// A matrix with a positive diagonal that is indefinite only in its oscillating modes
/// (`2 I + 1.5 (S + Sᵀ)`, eigenvalues `2 + 3 cos θ`). With unsmoothed aggregation on two
/// levels the coarse operator (`12 I + 1.5 (S + Sᵀ)` on aggregates of three) is positive
/// definite, so the setup succeeds; CG detects the indefiniteness instead of returning an
/// answer.
#[test]
fn indefinite_in_high_frequencies_breaks_cg() {
    let n = 3000;
    let (mut cp, mut ri, mut v) = (vec![0], vec![], vec![]);
    for c in 0..n {
        if c > 0 {
            ri.push(c - 1);
            v.push(1.5);
        }
        ri.push(c);
        v.push(2.0);
        cp.push(ri.len());
    }
    let a = SymCsr::from_upper_csc(n, &cp, &ri, &v).unwrap();
    let options = AmgOptions {
        max_levels: 2,
        prolongation_damping: 0.0,
        ..AmgOptions::default()
    };
    let mut amg = Amg::scalar(a, &options).unwrap();
    assert_eq!(amg.level_info().len(), 2);
    let b: Vec<f64> = (0..n)
        .map(|i| ((i * 7919) % 1000) as f64 / 1000.0 - 0.5)
        .collect();
    let mut x = vec![0.0; n];
    let e = amg.solve(&mut x, &b, 1e-10, 500).unwrap_err();
    println!("{e}");
    assert!(matches!(e, AmgError::Breakdown { .. }), "{e:?}");
}

/// Bitwise the same solution with one thread and with two.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let a = laplace_2d(150);
            let n = a.n();
            let mut amg = Amg::scalar(a, &small_coarse()).unwrap();
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).cos()).collect();
            let mut x = vec![0.0; n];
            let s = amg.solve(&mut x, &b, 1e-10, 100).unwrap();
            (s, x)
        })
    };
    let (s1, x1) = run(1);
    let (s2, x2) = run(2);
    assert_eq!(s1, s2);
    assert!(x1.iter().zip(&x2).all(|(a, b)| a.to_bits() == b.to_bits()));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// Random sparse symmetric matrices with a positive, strictly dominant diagonal are SPD;
    /// CG-AMG solves them to the requested residual.
    #[test]
    fn random_dominant_matrices(
        n in 60usize..400,
        seed in 0u64..1000,
        density in 1usize..6,
    ) {
        let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 33) as f64 / (1u64 << 31) as f64
        };
        // Columns: a few random rows above the diagonal, then the diagonal.
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        let mut rowsum = vec![0.0; n];
        for c in 1..n {
            let mut rows: Vec<usize> = (0..density).map(|_| (next() * c as f64) as usize).collect();
            rows.sort_unstable();
            rows.dedup();
            for r in rows {
                let v = -next();
                cols[c].push((r, v));
                rowsum[r] += v.abs();
                rowsum[c] += v.abs();
            }
        }
        let (mut cp, mut ri, mut vals) = (vec![0], vec![], vec![]);
        for c in 0..n {
            for &(r, v) in &cols[c] {
                ri.push(r);
                vals.push(v);
            }
            ri.push(c);
            vals.push(rowsum[c] + 0.1 + next());
            cp.push(ri.len());
        }
        let a = SymCsr::from_upper_csc(n, &cp, &ri, &vals).unwrap();
        let opts = AmgOptions { max_coarse: 20, ..AmgOptions::default() };
        let mut amg = Amg::scalar(a, &opts).unwrap();
        let b: Vec<f64> = (0..n).map(|_| next() - 0.5).collect();
        let mut x = vec![0.0; n];
        let s = amg.solve(&mut x, &b, 1e-10, 200).unwrap();
        prop_assert!(s.relative_residual <= 1e-10);
        prop_assert!(s.iterations <= 40, "{s:?}");
    }
}

/// CG's operator ([`Amg::operator`]) on a hierarchy stored in single precision multiplies
/// by the caller's double-precision values, not by the stored `f32` rounding: it matches
/// the double-precision matrix to rounding (1e-14 relative), while the stored rows miss by
/// about the `f32` rounding of values that are not representable in `f32`.
#[test]
fn cg_operator_multiplies_by_the_double_precision_values() {
    let m = 40;
    let n = m * m;
    let plain = laplace_2d(m);
    // Values 4 + 0.1·(1/3), −1 + 0.1·(1/7): not representable in f32.
    let values: Vec<f64> = laplace_values(m)
        .iter()
        .map(|&v| {
            if v > 0.0 {
                v + 0.1 / 3.0
            } else {
                v + 0.1 / 7.0
            }
        })
        .collect();
    let mut exact = plain.clone();
    exact.set_values(&values).unwrap();
    let mut cp = vec![0];
    let mut ri = vec![];
    for c in 0..n {
        plain.matrix().for_each_col(c, |r| {
            if (r as usize) <= c {
                ri.push(r as usize);
            }
        });
        cp.push(ri.len());
    }
    let single =
        SymCsr::from_upper_csc_in(porofrac_amg::Precision::Single, n, &cp, &ri, &values).unwrap();
    let mut amg = Amg::scalar(single, &small_coarse()).unwrap();
    let x: Vec<f64> = (0..n).map(|i| (0.37 * i as f64).sin()).collect();
    let mut want = vec![0.0; n];
    exact.mul(&x, &mut want).unwrap();
    let mut stored = vec![0.0; n];
    amg.matrix().mul(&x, &mut stored).unwrap();
    let mut got = vec![0.0; n];
    let op = amg.operator(&values).unwrap();
    let energy = op.apply(&x, &mut got).unwrap();
    let scale = want.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let miss = |y: &[f64]| {
        y.iter()
            .zip(&want)
            .fold(0.0f64, |a, (p, q)| a.max((p - q).abs()))
            / scale
    };
    assert!(miss(&got) <= 1e-14, "operator misses by {:e}", miss(&got));
    assert!(
        miss(&stored) >= 1e-9,
        "f32 rows miss by {:e}",
        miss(&stored)
    );
    let want_energy: f64 = x.iter().zip(&want).map(|(a, b)| a * b).sum();
    assert!((energy - want_energy).abs() <= 1e-13 * want_energy.abs());
    assert!(op.apply(&x[1..], &mut got).is_err());
}
