//! Superconvergent patch recovery (Zienkiewicz & Zhu 1992) of nodal stresses.
//!
//! Cell stresses of first-order methods are constant per cell and oscillate near a
//! fracture tip (Nilsen et al. (2017) §3, Fig. 5). For each node `n`, every stress component is
//! fitted by least squares with a linear polynomial `a + b·(x − x_n)` to the cell values
//! sampled at the centroids of the cells around the node (its *patch*), and the recovered
//! nodal value is `a`. Where the patch has fewer than `D + 1` cells or its centroids are
//! degenerate (boundary and corner nodes), the patch grows by one ring of neighbouring
//! cells until the fit is well posed. The fit reproduces any linear stress field exactly.
//!
//! The fit is linear in the cell values: [`StressRecovery`] keeps every node's weights
//! (computed once per grid) so that a recovery is one weighted sum per node.
//!
//! [`cell_average`] turns the nodal field back into cell values (the mean over the
//! cell's nodes), which a failure criterion can use instead of the raw cell stress.

use nalgebra::{DMatrix, DVector};
use porofrac_grid::Grid;
use porofrac_law::Tensor;
use rayon::prelude::*;

/// Cells around each node (node → cells), built once per grid.
#[derive(Clone, Debug)]
pub struct NodeCells {
    pos: Vec<usize>,
    cells: Vec<usize>,
}

impl NodeCells {
    /// Build the node → cells map of a grid.
    pub fn new<const D: usize>(grid: &Grid<D>) -> Self {
        let mut count = vec![0usize; grid.num_nodes() + 1];
        for c in 0..grid.num_cells() {
            for &n in grid.cell_nodes(c) {
                count[n + 1] += 1;
            }
        }
        for i in 0..grid.num_nodes() {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut cells = vec![0; count[grid.num_nodes()]];
        for c in 0..grid.num_cells() {
            for &n in grid.cell_nodes(c) {
                cells[fill[n]] = c;
                fill[n] += 1;
            }
        }
        Self { pos: count, cells }
    }
    /// The cells around node `n`.
    pub fn of(&self, n: usize) -> &[usize] {
        &self.cells[self.pos[n]..self.pos[n + 1]]
    }
}

/// Recover nodal stresses from cell stresses (one tensor per node); see
/// [`StressRecovery`] for repeated recoveries on the same grid.
pub fn recover_nodal<const D: usize>(
    grid: &Grid<D>,
    adjacency: &NodeCells,
    cell_stress: &[Tensor<D>],
) -> Vec<Tensor<D>> {
    StressRecovery::new(grid, adjacency).nodal(cell_stress)
}

/// The recovery as a linear operator: the fit's nodal value is `a = e₀ᵀ (PᵀP)⁻¹ Pᵀ σ`
/// for the patch's design matrix `P` (rows `[1, (x_c − x_n)/h]`), so every node keeps
/// the weights `w = P (PᵀP)⁻¹ e₀` of its patch cells and a recovery is
/// `σ_n = Σ_c w_c σ_c` — the least-squares fits, their degeneracy checks and the growth of
/// the patches are done once per grid instead of once per stress field.
#[derive(Clone, Debug)]
pub struct StressRecovery {
    ptr: Vec<usize>,
    cells: Vec<usize>,
    weights: Vec<f64>,
}

impl StressRecovery {
    /// The weights of every node of `grid` (cells around nodes from `adjacency`).
    pub fn new<const D: usize>(grid: &Grid<D>, adjacency: &NodeCells) -> Self {
        let per_node: Vec<Vec<(usize, f64)>> = (0..grid.num_nodes())
            .into_par_iter()
            .map_init(Vec::new, |patch: &mut Vec<usize>, n| {
                node_weights(grid, adjacency, n, patch)
            })
            .collect();
        let mut ptr = Vec::with_capacity(per_node.len() + 1);
        ptr.push(0);
        let total = per_node.iter().map(Vec::len).sum();
        let (mut cells, mut weights) = (Vec::with_capacity(total), Vec::with_capacity(total));
        for w in &per_node {
            for &(c, x) in w {
                cells.push(c);
                weights.push(x);
            }
            ptr.push(cells.len());
        }
        Self {
            ptr,
            cells,
            weights,
        }
    }

    /// The recovered nodal stresses of the cell stresses `cell_stress`.
    pub fn nodal<const D: usize>(&self, cell_stress: &[Tensor<D>]) -> Vec<Tensor<D>> {
        (0..self.ptr.len() - 1)
            .into_par_iter()
            .map(|n| {
                let k = self.ptr[n]..self.ptr[n + 1];
                self.cells[k.clone()]
                    .iter()
                    .zip(&self.weights[k])
                    .fold(Tensor::<D>::zeros(), |acc, (&c, &w)| {
                        acc + cell_stress[c] * w
                    })
            })
            .collect()
    }
}

/// The recovery weights of node `n`: the patch cells and `w = P (PᵀP)⁻¹ e₀` of the
/// first well-posed patch (the node's cells, grown by up to three rings), or the plain
/// average of the node's cells on a grid too small for a linear fit.
fn node_weights<const D: usize>(
    grid: &Grid<D>,
    adjacency: &NodeCells,
    n: usize,
    patch: &mut Vec<usize>,
) -> Vec<(usize, f64)> {
    patch.clear();
    patch.extend_from_slice(adjacency.of(n));
    let xn = *grid.node(n);
    for _ring in 0..3 {
        if patch.len() > D {
            // Normal equations of the linear fit in coordinates scaled by the patch size.
            let h = patch
                .iter()
                .map(|&c| (grid.cell_centroid(c) - xn).norm())
                .fold(0.0f64, f64::max)
                .max(f64::MIN_POSITIVE);
            let m = patch.len();
            let p = DMatrix::<f64>::from_fn(m, D + 1, |i, j| {
                if j == 0 {
                    1.0
                } else {
                    (grid.cell_centroid(patch[i])[j - 1] - xn[j - 1]) / h
                }
            });
            let a = p.transpose() * &p;
            if let Some(chol) = a.clone().cholesky() {
                // Reject nearly degenerate patches (collinear centroids).
                let eig = a.symmetric_eigenvalues();
                if eig.min() > 1e-10 * eig.max() {
                    let y = chol.solve(&DVector::<f64>::from_fn(D + 1, |i, _| {
                        if i == 0 { 1.0 } else { 0.0 }
                    }));
                    let w = &p * y;
                    return patch.iter().copied().zip(w.iter().copied()).collect();
                }
            }
        }
        // Grow the patch by one ring: the cells around the nodes of the patch.
        let mut grown: Vec<usize> = patch.clone();
        for &c in patch.iter() {
            for &q in grid.cell_nodes(c) {
                grown.extend_from_slice(adjacency.of(q));
            }
        }
        grown.sort_unstable();
        grown.dedup();
        *patch = grown;
    }
    // A grid too small for a linear fit: the plain average of the patch.
    let cells = adjacency.of(n);
    let w = 1.0 / cells.len().max(1) as f64;
    cells.iter().map(|&c| (c, w)).collect()
}

/// Cell values of a nodal stress field: the mean over each cell's nodes.
pub fn cell_average<const D: usize>(grid: &Grid<D>, nodal: &[Tensor<D>]) -> Vec<Tensor<D>> {
    (0..grid.num_cells())
        .into_par_iter()
        .map(|c| {
            let nodes = grid.cell_nodes(c);
            nodes.iter().map(|&n| nodal[n]).sum::<Tensor<D>>() / nodes.len() as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use porofrac_grid::Point;
    use porofrac_grid::generate::{CompositeSpec, composite, perturb, simplices};

    fn linear_field<const D: usize>(x: &Point<D>) -> Tensor<D> {
        Tensor::<D>::from_fn(|i, j| {
            let k = (i + j) as f64;
            1.0 + k + (2.0 - k) * x[0] + 0.5 * (k + 1.0) * x[1] - 0.25 * k * x[D - 1]
        })
    }

    fn check_exact<const D: usize>(g: &Grid<D>) {
        let stress: Vec<Tensor<D>> = g.cell_centroids().iter().map(linear_field).collect();
        let adj = NodeCells::new(g);
        let nodal = recover_nodal(g, &adj, &stress);
        for (n, s) in nodal.iter().enumerate() {
            let exact = linear_field(g.node(n));
            assert!(
                (s - exact).amax() < 1e-11 * exact.amax().max(1.0),
                "node {n}: {s} vs {exact}"
            );
        }
    }

    #[test]
    fn linear_stress_is_recovered_exactly_on_mixed_grids() {
        let g = simplices(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 1.0), [8, 4]).unwrap();
        check_exact(&perturb(&g, 0.25, 7).unwrap());
        let spec = CompositeSpec::new(
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(10.0, 10.0),
            [10, 10],
            Point::<2>::new(5.0, 5.0),
            1.5,
            4,
            0.3,
        );
        check_exact(&composite(&spec).unwrap());
        let g = simplices(
            Point::<3>::new(0.0, 0.0, 0.0),
            Point::<3>::new(1.0, 1.0, 1.0),
            [3, 3, 3],
        )
        .unwrap();
        check_exact(&g);
    }

    #[test]
    fn recovered_field_is_smoother_than_cell_values() {
        // A quadratic field: the recovered nodal values are closer to the exact nodal
        // values than the cell values are to the exact values at the nodes.
        let g = simplices(
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 1.0),
            [16, 16],
        )
        .unwrap();
        let f = |x: &Point<2>| Tensor::<2>::from_fn(|_, _| x[0] * x[0] + x[0] * x[1]);
        let stress: Vec<Tensor<2>> = g.cell_centroids().iter().map(f).collect();
        let adj = NodeCells::new(&g);
        let nodal = recover_nodal(&g, &adj, &stress);
        let mut err_rec: f64 = 0.0;
        let mut err_cell: f64 = 0.0;
        for n in 0..g.num_nodes() {
            let exact = f(g.node(n))[(0, 0)];
            err_rec = err_rec.max((nodal[n][(0, 0)] - exact).abs());
            for &c in adj.of(n) {
                err_cell = err_cell.max((stress[c][(0, 0)] - exact).abs());
            }
        }
        assert!(
            err_rec < 0.2 * err_cell,
            "recovered {err_rec:e}, cell {err_cell:e}"
        );
        let avg = cell_average(&g, &nodal);
        assert_eq!(avg.len(), g.num_cells());
    }
}
