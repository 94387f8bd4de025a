//! Simplex meshes the Cosserat experiments use that the grid crate does not generate.
//!
//! * [`crossed`]: each square of an `nx × ny` lattice cut into 4 triangles by its centre
//!   (the "crossed" meshes of SEEDS 001.4 E1 and E3).
//! * [`locate`]: the simplex containing a point.

use porofrac_grid::{CellFaceLoops, Grid, GridError, Point};

use crate::error::Result;

/// A crossed triangle mesh of `[lo, hi]` with `n[0] × n[1]` squares, 4 triangles each.
///
/// Errors: a zero count or an empty box (from the grid builder, or named here).
pub fn crossed(lo: Point<2>, hi: Point<2>, n: [usize; 2]) -> Result<Grid<2>> {
    if n[0] == 0 || n[1] == 0 || !(hi[0] > lo[0] && hi[1] > lo[1]) {
        return Err(GridError::Input(format!(
            "crossed mesh: need n > 0 and hi > lo, got n = {n:?}, lo = {lo:?}, hi = {hi:?}"
        ))
        .into());
    }
    let (nx, ny) = (n[0], n[1]);
    let dx = (hi[0] - lo[0]) / nx as f64;
    let dy = (hi[1] - lo[1]) / ny as f64;
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1) + nx * ny);
    for j in 0..=ny {
        for i in 0..=nx {
            nodes.push(Point::<2>::new(
                lo[0] + i as f64 * dx,
                lo[1] + j as f64 * dy,
            ));
        }
    }
    let corner = |i: usize, j: usize| j * (nx + 1) + i;
    let centre0 = nodes.len();
    for j in 0..ny {
        for i in 0..nx {
            nodes.push(Point::<2>::new(
                lo[0] + (i as f64 + 0.5) * dx,
                lo[1] + (j as f64 + 0.5) * dy,
            ));
        }
    }
    let mut loops = CellFaceLoops::new();
    for j in 0..ny {
        for i in 0..nx {
            let c = centre0 + j * nx + i;
            let q = [
                corner(i, j),
                corner(i + 1, j),
                corner(i + 1, j + 1),
                corner(i, j + 1),
            ];
            for k in 0..4 {
                loops.push_polygon(&[q[k], q[(k + 1) % 4], c]);
            }
        }
    }
    Ok(Grid::from_cell_faces(nodes, &loops)?)
}

/// The first simplex (lowest id) whose closure contains `x` (tolerance `1e-10` in the
/// barycentric coordinates), or `None`. A linear scan: meant for probes, not hot loops.
pub fn locate<const D: usize>(grid: &Grid<D>, x: &Point<D>) -> Option<usize> {
    (0..grid.num_cells()).find(|&c| {
        let nodes = grid.cell_nodes(c);
        if nodes.len() != D + 1 {
            return false;
        }
        let x0 = grid.node(nodes[0]);
        let mut e = nalgebra::DMatrix::<f64>::zeros(D, D);
        for k in 0..D {
            let col = grid.node(nodes[k + 1]) - x0;
            for i in 0..D {
                e[(i, k)] = col[i];
            }
        }
        let r = nalgebra::DVector::from_iterator(D, (x - x0).iter().copied());
        match e.lu().solve(&r) {
            Some(l) => {
                let s: f64 = l.iter().sum();
                l.iter().all(|&v| v >= -1e-10) && s <= 1.0 + 1e-10
            }
            None => false,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossed_mesh_counts_and_area() {
        let g = crossed(Point::<2>::new(-0.12, -0.06), Point::<2>::new(0.12, 0.06), [5, 3]).unwrap();
        assert_eq!(g.num_cells(), 60);
        let area: f64 = g.cell_volumes().iter().sum();
        assert!((area - 0.24 * 0.12).abs() < 1e-15);
        assert_eq!(g.boundary("ymin").unwrap().len(), 5);
        assert!(crossed(Point::<2>::zeros(), Point::<2>::new(1.0, 1.0), [0, 2]).is_err());
    }
}
