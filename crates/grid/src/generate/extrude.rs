//! Extrusion of a 2D grid along z: triangles become three tetrahedra per layer (simplices
//! for MDEM), every other polygon becomes a prism (a polyhedron for VEM).
//!
//! With layers `z_0 < … < z_L`, 2D node `i` at layer `k` is 3D node `k · n₂ + i`. A
//! triangle with 2D nodes `a < b < c` (sorted by index) and their copies `a', b', c'` one
//! layer up is split into the tetrahedra
//!
//! ```text
//!   (a, b, c, a'),  (b, c, a', b'),  (c, a', b', c')
//! ```
//!
//! which cuts each side quad `(p, q, q', p')` with `p < q` along the diagonal `p'–q`, from
//! the top copy of the smaller index to the bottom copy of the larger one. The diagonal
//! depends only on the edge, so neighbouring prisms agree, and a polygon prism next to a
//! triangle splits that side quad the same way (two triangular faces); its other side
//! faces stay quadrilaterals. Hanging nodes of the 2D grid become vertical lines of
//! hanging nodes on the polygon prisms' faces. Cell tags carry over: every 3D cell made
//! from 2D cell `c` has the tags of `c`.
//!
//! Cells are numbered layer by layer (bottom first); within a layer in the order of the
//! 2D cells, a triangle giving its three tetrahedra in the order above.

use std::collections::HashSet;

use crate::builder::CellFaceLoops;
use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::point::Point;

/// Extrude `grid` over the z levels `levels` (strictly increasing, at least two).
///
/// Errors: fewer than two levels, levels not finite or not increasing, or a 3D grid that
/// fails validation (which a valid 2D grid cannot produce).
pub fn extrude(grid: &Grid<2>, levels: &[f64]) -> Result<Grid<3>> {
    if levels.len() < 2 {
        return Err(GridError::Input(format!(
            "extrusion needs at least two z levels, got {}",
            levels.len()
        )));
    }
    if let Some(k) = (1..levels.len()).find(|&k| {
        !(levels[k - 1].is_finite() && levels[k].is_finite() && levels[k] > levels[k - 1])
    }) {
        return Err(GridError::Input(format!(
            "extrusion levels must be finite and increasing: z[{}] = {}, z[{k}] = {}",
            k - 1,
            levels[k - 1],
            levels[k]
        )));
    }
    let n2 = grid.num_nodes();
    let layers = levels.len() - 1;
    let mut nodes = Vec::with_capacity(n2 * levels.len());
    for &z in levels {
        nodes.extend(grid.nodes().iter().map(|p| Point::<3>::new(p[0], p[1], z)));
    }
    let is_triangle = |c: usize| grid.cell_nodes(c).len() == 3;
    let edge = |p: usize, q: usize| (p.min(q), p.max(q));
    let triangle_edges: HashSet<(usize, usize)> = (0..grid.num_cells())
        .filter(|&c| is_triangle(c))
        .flat_map(|c| {
            let v = grid.cell_nodes(c);
            [edge(v[0], v[1]), edge(v[1], v[2]), edge(v[2], v[0])]
        })
        .collect();

    let mut cells = CellFaceLoops::new();
    // 3D cells made from each 2D cell, for the tags.
    let mut from_2d: Vec<Vec<usize>> = vec![Vec::new(); grid.num_cells()];
    let mut count = 0;
    for k in 0..layers {
        let (lo, hi) = (k * n2, (k + 1) * n2);
        for c in 0..grid.num_cells() {
            let v = grid.cell_nodes(c);
            if v.len() == 3 {
                let mut s = [v[0], v[1], v[2]];
                s.sort_unstable();
                let [a, b, c3] = s;
                for tet in [
                    [lo + a, lo + b, lo + c3, hi + a],
                    [lo + b, lo + c3, hi + a, hi + b],
                    [lo + c3, hi + a, hi + b, hi + c3],
                ] {
                    push_tet(&mut cells, &nodes, tet);
                    from_2d[c].push(count);
                    count += 1;
                }
            } else {
                push_prism(&mut cells, grid, c, lo, hi, |p, q| {
                    triangle_edges.contains(&edge(p, q))
                });
                from_2d[c].push(count);
                count += 1;
            }
        }
    }
    let mut out = Grid::from_cell_faces(nodes, &cells)?;
    for (name, members) in grid.cell_tags() {
        let mut m: Vec<usize> = members
            .iter()
            .flat_map(|&c| from_2d[c].iter().copied())
            .collect();
        m.sort_unstable();
        out.set_cell_tag(name.clone(), m)?;
    }
    Ok(out)
}

/// A tetrahedron with its four outward faces (reordered to positive volume).
fn push_tet(cells: &mut CellFaceLoops, nodes: &[Point<3>], mut t: [usize; 4]) {
    let x = |i: usize| nodes[t[i]];
    let vol = (x(1) - x(0)).cross(&(x(2) - x(0))).dot(&(x(3) - x(0)));
    if vol < 0.0 {
        t.swap(1, 2);
    }
    for f in [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]] {
        cells.push_face(&[t[f[0]], t[f[1]], t[f[2]]]);
    }
    cells.finish_cell();
}

/// The prism of 2D cell `c` between the node offsets `lo` and `hi`; side quads on edges
/// where `split(p, q)` are cut like the tetrahedra's (module docs).
fn push_prism(
    cells: &mut CellFaceLoops,
    grid: &Grid<2>,
    c: usize,
    lo: usize,
    hi: usize,
    split: impl Fn(usize, usize) -> bool,
) {
    let v = grid.cell_nodes(c);
    let m = v.len();
    // Counter-clockwise order (positive signed area).
    let area2: f64 = (0..m)
        .map(|i| {
            let (p, q) = (grid.node(v[i]), grid.node(v[(i + 1) % m]));
            p[0] * q[1] - q[0] * p[1]
        })
        .sum();
    let ccw: Vec<usize> = if area2 > 0.0 {
        v.to_vec()
    } else {
        v.iter().rev().copied().collect()
    };
    let bottom: Vec<usize> = ccw.iter().rev().map(|&i| lo + i).collect();
    cells.push_face(&bottom);
    let top: Vec<usize> = ccw.iter().map(|&i| hi + i).collect();
    cells.push_face(&top);
    for i in 0..m {
        let (p, q) = (ccw[i], ccw[(i + 1) % m]);
        if split(p, q) {
            if p < q {
                // Diagonal p'–q.
                cells.push_face(&[lo + p, lo + q, hi + p]);
                cells.push_face(&[lo + q, hi + q, hi + p]);
            } else {
                // Diagonal q'–p.
                cells.push_face(&[lo + p, lo + q, hi + q]);
                cells.push_face(&[lo + p, hi + q, hi + p]);
            }
        } else {
            cells.push_face(&[lo + p, lo + q, hi + q, hi + p]);
        }
    }
    cells.finish_cell();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{CompositeSpec, Diagonals, composite};

    /// The extruded composite grid is valid (closure, orientation, shared faces matched)
    /// and its volumes add up to the box; tags carry over layer by layer.
    #[test]
    fn extruded_composite_fills_the_box() {
        let mut spec = CompositeSpec::new(
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(6.0, 6.0),
            [6, 6],
            Point::<2>::new(3.0, 3.0),
            1.0,
            3,
            0.3,
        );
        spec.diagonals = Diagonals::Alternating;
        spec.perturb = 0.2;
        spec.seed = 5;
        let g2 = composite(&spec).unwrap();
        let levels = [0.0, 0.4, 1.0];
        let g3 = extrude(&g2, &levels).unwrap();
        let tris = (0..g2.num_cells())
            .filter(|&c| g2.cell_nodes(c).len() == 3)
            .count();
        let polys = g2.num_cells() - tris;
        assert_eq!(g3.num_cells(), 2 * (3 * tris + polys));
        assert_eq!(g3.num_nodes(), 3 * g2.num_nodes());
        let vol: f64 = g3.cell_volumes().iter().sum();
        assert!((vol - 36.0).abs() < 1e-10 * 36.0, "{vol}");
        // Per 2D cell: the 3D cells of each layer have the 2D area times the layer height.
        let refined = &g3.cell_tags()["refined"];
        assert_eq!(refined.len(), 2 * 3 * tris);
        assert!(refined.iter().all(|&c| g3.cell_nodes(c).len() == 4));
        let well = &g3.cell_tags()["well"];
        assert_eq!(well.len(), 2 * 3 * g2.cell_tags()["well"].len());
        for &c in well {
            let x = g3.cell_centroid(c);
            assert!((x[0] - 3.0).hypot(x[1] - 3.0) < 0.3 + 0.5);
        }
    }

    #[test]
    fn bad_levels_are_errors() {
        let spec = CompositeSpec::new(
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(3.0, 3.0),
            [3, 3],
            Point::<2>::new(1.5, 1.5),
            0.5,
            2,
            0.4,
        );
        let g2 = composite(&spec).unwrap();
        assert!(extrude(&g2, &[0.0]).is_err());
        assert!(extrude(&g2, &[0.0, 0.0]).is_err());
        assert!(extrude(&g2, &[0.0, f64::NAN]).is_err());
        assert!(extrude(&g2, &[1.0, 0.5]).is_err());
    }
}
