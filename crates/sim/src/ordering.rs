//! Geometric nested-dissection ordering of the equations for the sparse Cholesky factor.
//!
//! Minimum-degree orderings (AMD) leave large fill on 3D grids. Nested dissection splits
//! the nodes at the median of the longest axis of their bounding box, takes as separator
//! the nodes of one half that share a cell with the other half, orders both halves
//! recursively and numbers the separator last (George 1973). Below a leaf size the nodes
//! keep their order. Each node's equations stay together. On grids with a geometric
//! embedding (every grid here) this is a good, cheap nested dissection without a graph
//! partitioner.

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

/// Nested dissection of a symmetric sparsity pattern with a position for each unknown.
///
/// `col_ptr`, `row_idx`: the pattern's upper triangle (CSC); `pos[i]`: where unknown `i`
/// sits, `None` for unknowns coupled to many others (e.g. a platen shared by a whole
/// boundary), which are ordered last. The positioned unknowns are split at the median of
/// the longest axis of their bounding box; the separator is the unknowns of the lower
/// half adjacent (in the pattern) to the upper half; both halves are ordered
/// recursively, the separator after them (George 1973). Parts of at most `leaf`
/// unknowns keep their order. Returns `perm`, `perm[k]` the unknown eliminated `k`-th.
pub fn pattern_dissection<const D: usize>(
    pos: &[Option<Point<D>>],
    col_ptr: &[usize],
    row_idx: &[usize],
    leaf: usize,
) -> Vec<usize> {
    let n = pos.len();
    let placed = |i: usize| i < n && pos[i].is_some();
    let mut deg = vec![0usize; n + 1];
    for j in 0..n.min(col_ptr.len().saturating_sub(1)) {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if i != j && placed(i) && placed(j) {
                deg[i + 1] += 1;
                deg[j + 1] += 1;
            }
        }
    }
    for i in 0..n {
        deg[i + 1] += deg[i];
    }
    let mut fill = deg.clone();
    let mut adj = vec![0usize; deg[n]];
    for j in 0..n.min(col_ptr.len().saturating_sub(1)) {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if i != j && placed(i) && placed(j) {
                adj[fill[i]] = j;
                fill[i] += 1;
                adj[fill[j]] = i;
                fill[j] += 1;
            }
        }
    }
    let points: Vec<Point<D>> = pos
        .iter()
        .map(|p| p.unwrap_or_else(Point::<D>::zeros))
        .collect();
    let mut ctx = PatternDissection {
        points: &points,
        ptr: deg,
        adj,
        label: vec![0u32; n],
        next_label: 1,
        leaf: leaf.max(1),
        order: Vec::with_capacity(n),
    };
    let mut items: Vec<usize> = (0..n).filter(|&i| placed(i)).collect();
    ctx.dissect(&mut items);
    let mut order = ctx.order;
    order.extend((0..n).filter(|&i| !placed(i)));
    order
}

struct PatternDissection<'p, const D: usize> {
    points: &'p [Point<D>],
    ptr: Vec<usize>,
    adj: Vec<usize>,
    label: Vec<u32>,
    next_label: u32,
    leaf: usize,
    order: Vec<usize>,
}

impl<const D: usize> PatternDissection<'_, D> {
    fn dissect(&mut self, items: &mut [usize]) {
        if items.len() <= self.leaf {
            self.order.extend_from_slice(items);
            return;
        }
        let pts = self.points;
        let mut lo = [f64::INFINITY; D];
        let mut hi = [f64::NEG_INFINITY; D];
        for &v in items.iter() {
            for a in 0..D {
                lo[a] = lo[a].min(pts[v][a]);
                hi[a] = hi[a].max(pts[v][a]);
            }
        }
        let axis = (0..D)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap_or(0);
        // Split at the median coordinate, unknowns at the same coordinate on the same side
        // (a grid line of nodes is not cut in two).
        let half = items.len() / 2;
        items.select_nth_unstable_by(half, |&p, &q| pts[p][axis].total_cmp(&pts[q][axis]));
        let pivot = pts[items[half]][axis];
        let below = |v: &usize| pts[*v][axis] < pivot;
        let mut mid = partition_in_place(items, below);
        if mid == 0 {
            mid = partition_in_place(items, |v: &usize| pts[*v][axis] <= pivot);
        }
        if mid == 0 || mid == items.len() {
            self.order.extend_from_slice(items);
            return;
        }
        let (left_label, right_label) = (self.next_label, self.next_label + 1);
        self.next_label += 2;
        for &v in &items[..mid] {
            self.label[v] = left_label;
        }
        for &v in &items[mid..] {
            self.label[v] = right_label;
        }
        // The separator: the unknowns of the lower half adjacent to the upper one.
        let (left, right) = items.split_at(mid);
        let (mut a, mut sep) = (Vec::with_capacity(left.len()), Vec::new());
        for &v in left {
            let touches = self.adj[self.ptr[v]..self.ptr[v + 1]]
                .iter()
                .any(|&q| self.label[q] == right_label);
            if touches { sep.push(v) } else { a.push(v) }
        }
        let mut b = right.to_vec();
        if a.is_empty() || b.is_empty() {
            let mut rest = if a.is_empty() { b } else { a };
            self.dissect(&mut rest);
            self.order.extend_from_slice(&sep);
            return;
        }
        self.dissect(&mut a);
        self.dissect(&mut b);
        self.order.extend_from_slice(&sep);
    }
}

/// Reorder `items` so that those satisfying `pred` come first; returns their count.
fn partition_in_place(items: &mut [usize], pred: impl Fn(&usize) -> bool) -> usize {
    let mut k = 0;
    for i in 0..items.len() {
        if pred(&items[i]) {
            items.swap(i, k);
            k += 1;
        }
    }
    k
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
