//! Shared helpers of the integration tests.
#![allow(dead_code)]

use porofrac_cosserat::{Condition, Field, components};
use porofrac_grid::{Grid, Point};
use std::sync::Arc;

/// One condition fixing every component on every boundary face to `exact(x)[k]`.
pub fn clamp_all<const D: usize>(
    grid: &Grid<D>,
    exact: impl Fn(&Point<D>) -> Vec<f64> + Send + Sync + Clone + 'static,
) -> Condition<D> {
    let faces = grid.boundary_faces();
    let fields: Vec<Field<D>> = (0..components(D))
        .map(|k| {
            let e = exact.clone();
            Arc::new(move |x: &Point<D>, _t: f64| e(x)[k]) as Field<D>
        })
        .collect();
    Condition::new(faces).clamp(fields)
}

/// Sample `exact` at the barycentres (cell-major).
pub fn sample<const D: usize>(grid: &Grid<D>, exact: impl Fn(&Point<D>) -> Vec<f64>) -> Vec<f64> {
    let mut out = Vec::new();
    for c in 0..grid.num_cells() {
        out.extend(exact(grid.cell_centroid(c)));
    }
    out
}

/// The static solution by the sparse LU, after checking that GMRES with the multigrid
/// preconditioner, GMRES with the `LDLᵀ` preconditioner and the `LDLᵀ` + Schur complement
/// solve (the last two with single- and double-precision factors; each with GMRES at
/// tolerance 1e-12) converge on the same system and give the same solution to 1e-8 of its
/// largest entry.
pub fn solve_checked<const D: usize>(model: &porofrac_cosserat::Cosserat<D>) -> Vec<f64> {
    use porofrac_cosserat::{FactorPrecision, GmresOptions, LinearOptions, LinearSolver};
    let opts = |solver, factor_precision| LinearOptions {
        solver,
        gmres: GmresOptions {
            tolerance: 1e-12,
            factor_precision,
            ..GmresOptions::default()
        },
    };
    let (lu, _, _) = model
        .solve_static_with(0.0, &opts(LinearSolver::Lu, FactorPrecision::Double))
        .unwrap();
    let scale = lu.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
    for (solver, precision) in [
        (LinearSolver::GmresAmg, FactorPrecision::Single),
        (LinearSolver::GmresLdlt, FactorPrecision::Single),
        (LinearSolver::GmresLdlt, FactorPrecision::Double),
        (LinearSolver::LdltSchur, FactorPrecision::Single),
        (LinearSolver::LdltSchur, FactorPrecision::Double),
    ] {
        let (gm, stats, used) = model
            .solve_static_with(0.0, &opts(solver, precision))
            .unwrap();
        assert_eq!(used, solver);
        let d = lu
            .iter()
            .zip(&gm)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            d <= 1e-8 * scale && stats.max_residual <= 1e-12,
            "{} {precision:?} against LU: {d:.2e} of {scale:.2e}, {stats:?}",
            solver.name()
        );
    }
    lu
}
