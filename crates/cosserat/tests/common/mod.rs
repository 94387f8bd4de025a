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
