//! Geometric nested-dissection orderings of the equations of a grid for the sparse factors.
//!
//! Minimum-degree orderings (AMD) leave large fill on 3D grids. Nested dissection splits
//! the nodes at the median of the longest axis of their bounding box, takes as separator
//! the nodes of one half that share a cell with the other half, orders both halves
//! recursively and numbers the separator last (George 1973). Below a leaf size the nodes
//! keep their order. Each node's equations stay together. On grids with a geometric
//! embedding (every grid here) this is a good, cheap nested dissection without a graph
//! partitioner.
//!
//! [`pattern_dissection`] places the unknowns of a bare pattern at grid points for
//! [`porofrac_sparse::ordering::pattern_dissection`], which splits by those positions and
//! the pattern alone.

use porofrac_grid::{Grid, Point};

use crate::dofs::DofMap;

/// Nodes per leaf of the dissection.
const LEAF: usize = 64;

/// The nested-dissection permutation of the equations: `perm[k]` is the equation
/// eliminated `k`-th. Every equation appears exactly once.
pub fn nested_dissection<const D: usize>(grid: &Grid<D>, dofs: &DofMap<D>) -> Vec<usize> {
    let order = node_dissection(grid);
    let mut seen = vec![false; dofs.num_equations()];
    let mut perm = Vec::with_capacity(dofs.num_equations());
    for &v in &order {
        for a in 0..D {
            if let Some(e) = dofs.equation(v, a)
                && !seen[e]
            {
                seen[e] = true;
                perm.push(e);
            }
        }
    }
    perm
}

/// The nested-dissection order of the grid's nodes: `order[k]` is the node eliminated
/// `k`-th (separators after the parts they separate). Every node appears exactly once.
pub fn node_dissection<const D: usize>(grid: &Grid<D>) -> Vec<usize> {
    let n = grid.num_nodes();
    // node → cells
    let mut pos = vec![0usize; n + 1];
    for c in 0..grid.num_cells() {
        for &v in grid.cell_nodes(c) {
            pos[v + 1] += 1;
        }
    }
    for i in 0..n {
        pos[i + 1] += pos[i];
    }
    let mut fill = pos.clone();
    let mut cells = vec![0usize; pos[n]];
    for c in 0..grid.num_cells() {
        for &v in grid.cell_nodes(c) {
            cells[fill[v]] = c;
            fill[v] += 1;
        }
    }
    let mut ctx = Dissection {
        grid,
        pos,
        cells,
        label: vec![0u32; n],
        next_label: 1,
        order: Vec::with_capacity(n),
    };
    let mut nodes: Vec<usize> = (0..n).collect();
    ctx.dissect(&mut nodes);
    ctx.order
}

/// [`porofrac_sparse::ordering::pattern_dissection`] with the unknowns placed at grid
/// points (`None` for unknowns coupled to many others, ordered last).
pub fn pattern_dissection<const D: usize>(
    pos: &[Option<Point<D>>],
    col_ptr: &[usize],
    row_idx: &[usize],
    leaf: usize,
) -> Vec<usize> {
    let pos: Vec<Option<[f64; D]>> = pos
        .iter()
        .map(|p| p.map(|x| std::array::from_fn(|a| x[a])))
        .collect();
    porofrac_sparse::ordering::pattern_dissection(&pos, col_ptr, row_idx, leaf)
}

struct Dissection<'g, const D: usize> {
    grid: &'g Grid<D>,
    pos: Vec<usize>,
    cells: Vec<usize>,
    label: Vec<u32>,
    next_label: u32,
    order: Vec<usize>,
}

impl<const D: usize> Dissection<'_, D> {
    fn dissect(&mut self, nodes: &mut [usize]) {
        if nodes.len() <= LEAF {
            self.order.extend_from_slice(nodes);
            return;
        }
        let grid = self.grid;
        let mut lo = [f64::INFINITY; D];
        let mut hi = [f64::NEG_INFINITY; D];
        for &v in nodes.iter() {
            let x = grid.node(v);
            for a in 0..D {
                lo[a] = lo[a].min(x[a]);
                hi[a] = hi[a].max(x[a]);
            }
        }
        let axis = (0..D)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap_or(0);
        let mid = nodes.len() / 2;
        nodes.select_nth_unstable_by(mid, |&p, &q| {
            grid.node(p)[axis].total_cmp(&grid.node(q)[axis])
        });
        let (left_label, right_label) = (self.next_label, self.next_label + 1);
        self.next_label += 2;
        for &v in &nodes[..mid] {
            self.label[v] = left_label;
        }
        for &v in &nodes[mid..] {
            self.label[v] = right_label;
        }
        // Separator: left nodes sharing a cell with a right node.
        let (left, right) = nodes.split_at_mut(mid);
        let mut inner: Vec<usize> = Vec::with_capacity(left.len());
        let mut sep: Vec<usize> = Vec::new();
        for &v in left.iter() {
            let touches = self.cells[self.pos[v]..self.pos[v + 1]].iter().any(|&c| {
                grid.cell_nodes(c)
                    .iter()
                    .any(|&q| self.label[q] == right_label)
            });
            if touches { sep.push(v) } else { inner.push(v) }
        }
        if inner.is_empty() {
            // No useful split (e.g. a single layer of nodes): keep the order.
            self.order.extend_from_slice(left);
            let mut right = right.to_vec();
            self.dissect(&mut right);
            return;
        }
        self.dissect(&mut inner);
        let mut right = right.to_vec();
        self.dissect(&mut right);
        self.order.extend_from_slice(&sep);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::Displacement;
    use crate::field::ScalarField;
    use porofrac_grid::Point;
    use porofrac_grid::generate::simplices;

    #[test]
    fn every_equation_once() {
        let g = simplices(
            Point::<3>::new(0.0, 0.0, 0.0),
            Point::<3>::new(1.0, 1.0, 1.0),
            [6, 5, 4],
        )
        .unwrap();
        let fixed = Displacement {
            name: "zmin".into(),
            faces: g.boundary("zmin").unwrap(),
            components: std::array::from_fn(|_| Some(ScalarField::Const(0.0))),
        };
        let dofs = DofMap::new(&g, &[fixed], &[]).unwrap();
        let mut perm = nested_dissection(&g, &dofs);
        assert_eq!(perm.len(), dofs.num_equations());
        perm.sort_unstable();
        assert!(perm.iter().enumerate().all(|(i, &e)| i == e));
    }
}
