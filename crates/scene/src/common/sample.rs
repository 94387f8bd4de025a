//! Sampling fields at points (probes and lines of docs/SCENE.md).
//!
//! A point is located in the cell that contains it; nodal fields are interpolated with
//! the same piecewise-linear hat functions the laws and loads use: each cell is split
//! into simplices formed by a face facet and the cell's vertex average, the value at a
//! face point is the average over the face's nodes and the value at the cell centre the
//! average over the cell's nodes. On triangles and tetrahedra this is exact linear
//! interpolation. Cell fields take the value of the containing cell.

use nalgebra::{DMatrix, DVector};
use porofrac_grid::point::for_each_facet;
use porofrac_grid::{Grid, Point};

/// Where a point lies: its cell and interpolation weights over the cell's nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct Location {
    /// The containing cell.
    pub cell: usize,
    /// `(node, weight)`; the weights sum to 1.
    pub weights: Vec<(usize, f64)>,
}

impl Location {
    /// Interpolate a nodal field with `stride` values per node at component `comp`.
    pub fn nodal(&self, values: &[f64], stride: usize, comp: usize) -> f64 {
        self.weights
            .iter()
            .map(|&(n, w)| w * values[stride * n + comp])
            .sum()
    }
}

/// Find the cell containing `x` and the interpolation weights, or `None` outside the grid.
pub fn locate<const D: usize>(grid: &Grid<D>, x: &Point<D>) -> Option<Location> {
    // Candidates by distance of the centroid; the containing cell is among the nearest.
    let mut order: Vec<(f64, usize)> = grid
        .cell_centroids()
        .iter()
        .enumerate()
        .map(|(c, xc)| ((xc - x).norm_squared(), c))
        .collect();
    let k = order.len().min(64);
    order.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
    order[..k].sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let mut best: Option<(f64, Location)> = None;
    for &(_, c) in &order[..k] {
        if let Some((outside, loc)) = weights_in_cell(grid, c, x) {
            if outside <= 1e-10 {
                return Some(loc);
            }
            if best.as_ref().is_none_or(|b| outside < b.0) {
                best = Some((outside, loc));
            }
        }
    }
    // Points on the boundary may miss by rounding only.
    best.filter(|b| b.0 <= 1e-8).map(|b| b.1)
}

/// Weights of `x` in cell `c`, with how far outside the best sub-simplex it is
/// (the most negative barycentric coordinate, negated; 0 inside).
fn weights_in_cell<const D: usize>(
    grid: &Grid<D>,
    c: usize,
    x: &Point<D>,
) -> Option<(f64, Location)> {
    let nodes = grid.cell_nodes(c);
    let n = nodes.len() as f64;
    let xc = nodes.iter().map(|&i| grid.node(i)).sum::<Point<D>>() / n;
    let mut best: Option<(f64, Vec<(usize, f64)>)> = None;
    let mut pts: Vec<Point<D>> = Vec::new();
    let mut ids: Vec<usize> = Vec::new();
    for (&f, &out) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
        ids.clear();
        ids.extend(grid.oriented_face_nodes(f, out));
        pts.clear();
        pts.extend(ids.iter().map(|&i| *grid.node(i)));
        let m = ids.len() as f64;
        for_each_facet::<D>(&pts, |_a, _centroid, corners| {
            // Simplex vertices: the facet corners and the cell centre.
            let mut verts = [Point::<D>::zeros(); 4];
            let mut vw: [Vec<(usize, f64)>; 4] = Default::default();
            for (j, &k) in corners.iter().take(D).enumerate() {
                if k == usize::MAX {
                    verts[j] = pts.iter().sum::<Point<D>>() / m;
                    vw[j] = ids.iter().map(|&i| (i, 1.0 / m)).collect();
                } else {
                    verts[j] = pts[k];
                    vw[j] = vec![(ids[k], 1.0)];
                }
            }
            verts[D] = xc;
            vw[D] = nodes.iter().map(|&i| (i, 1.0 / n)).collect();
            let Some(lambda) = barycentric::<D>(&verts[..=D], x) else {
                return;
            };
            let outside = -lambda
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min)
                .min(0.0);
            if best.as_ref().is_none_or(|b| outside < b.0) {
                let mut w: Vec<(usize, f64)> = Vec::new();
                for (j, l) in lambda.iter().enumerate() {
                    for &(node, s) in &vw[j] {
                        match w.iter_mut().find(|e| e.0 == node) {
                            Some(e) => e.1 += l * s,
                            None => w.push((node, l * s)),
                        }
                    }
                }
                best = Some((outside, w));
            }
        });
    }
    best.map(|(outside, weights)| (outside, Location { cell: c, weights }))
}

/// Barycentric coordinates of `x` in the simplex `v` (D + 1 vertices), None if degenerate.
fn barycentric<const D: usize>(v: &[Point<D>], x: &Point<D>) -> Option<Vec<f64>> {
    let a = DMatrix::<f64>::from_fn(D, D, |i, j| v[j][i] - v[D][i]);
    let rhs = DVector::<f64>::from_fn(D, |i, _| x[i] - v[D][i]);
    let l = a.lu().solve(&rhs)?;
    let mut out: Vec<f64> = l.iter().copied().collect();
    out.push(1.0 - l.sum());
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use porofrac_grid::generate::{cartesian, simplices};

    #[test]
    fn linear_field_is_interpolated_exactly() {
        let g = cartesian(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 1.0), [4, 3]).unwrap();
        let f: Vec<f64> = g
            .nodes()
            .iter()
            .map(|p| 1.0 + 2.0 * p[0] - 3.0 * p[1])
            .collect();
        for x in [
            Point::<2>::new(0.3, 0.7),
            Point::<2>::new(1.99, 0.01),
            Point::<2>::new(2.0, 1.0),
        ] {
            let loc = locate(&g, &x).unwrap();
            let v = loc.nodal(&f, 1, 0);
            assert!((v - (1.0 + 2.0 * x[0] - 3.0 * x[1])).abs() < 1e-12, "{v}");
            assert!(
                g.cell_centroid(loc.cell)
                    .iter()
                    .zip(x.iter())
                    .all(|(c, p)| (c - p).abs() <= 0.5)
            );
        }
        assert!(locate(&g, &Point::<2>::new(2.5, 0.5)).is_none());
        let g = simplices(
            Point::<3>::new(0.0, 0.0, 0.0),
            Point::<3>::new(1.0, 1.0, 1.0),
            [3, 3, 3],
        )
        .unwrap();
        let f: Vec<f64> = g
            .nodes()
            .iter()
            .map(|p| p[0] - 2.0 * p[1] + 0.5 * p[2])
            .collect();
        let x = Point::<3>::new(0.41, 0.27, 0.93);
        let v = locate(&g, &x).unwrap().nodal(&f, 1, 0);
        assert!((v - (x[0] - 2.0 * x[1] + 0.5 * x[2])).abs() < 1e-12);
    }
}
