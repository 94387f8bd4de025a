//! Property tests: for random SPD permeability tensors on Cartesian and simplex grids in 2D
//! and 3D, the flux matrix is symmetric, has non-positive off-diagonal entries (the
//! absolute-value rule keeps it an M-matrix) and annihilates constants when there is no
//! Dirichlet face (a uniform pressure drives no flow).

use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock, Tensor};
use porofrac_grid::generate::{cartesian, simplices};
use porofrac_grid::{Grid, Point};
use proptest::prelude::*;

fn check<const D: usize>(grid: &Grid<D>, entries: &[f64]) -> Result<(), TestCaseError> {
    let n = grid.num_cells();
    // K = L Lᵀ + 0.1 I from pseudo-random lower-triangular L, scaled to ~1e-13.
    let tensors: Vec<Tensor<D>> = (0..n)
        .map(|c| {
            let l = Tensor::<D>::from_fn(|i, j| {
                if j <= i {
                    entries[(c * D * D + i * D + j) % entries.len()]
                } else {
                    0.0
                }
            });
            (l * l.transpose() + Tensor::<D>::identity() * 0.1) * 1e-13
        })
        .collect();
    let perm = Permeability::from_tensors(tensors).unwrap();
    let problem = FlowProblem::new(
        Rock::new(vec![0.2; n], perm),
        Fluid {
            viscosity: 1e-3,
            compressibility: 1e-9,
        },
    );
    let model = FlowModel::new(grid, &problem).unwrap();
    let a = model.flux_matrix();
    let (sym, vals) = a.parts();
    let mut dense = vec![0.0; n * n];
    for c in 0..n {
        for k in sym.col_ptr()[c]..sym.col_ptr()[c + 1] {
            dense[sym.row_idx()[k] * n + c] = vals[k];
        }
    }
    let scale = vals.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..n {
        let mut row = 0.0;
        for j in 0..n {
            row += dense[i * n + j];
            prop_assert!((dense[i * n + j] - dense[j * n + i]).abs() <= 1e-14 * scale);
            if i != j {
                prop_assert!(dense[i * n + j] <= 0.0);
            }
        }
        prop_assert!(row.abs() <= 1e-13 * scale, "row {i} sums to {row:e}");
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn flux_matrix_invariants(
        entries in proptest::collection::vec(-1.0f64..1.0, 9..40),
        nx in 1usize..4, ny in 1usize..4, nz in 1usize..3, simplex in any::<bool>(),
    ) {
        let g2 = if simplex {
            simplices::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 2.0), [nx, ny])
        } else {
            cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 2.0), [nx, ny])
        }.unwrap();
        check(&g2, &entries)?;
        let lo = Point::<3>::new(0.0, 0.0, 0.0);
        let hi = Point::<3>::new(1.0, 2.0, 0.5);
        let g3 = if simplex {
            simplices::<3>(lo, hi, [nx, ny, nz])
        } else {
            cartesian::<3>(lo, hi, [nx, ny, nz])
        }.unwrap();
        check(&g3, &entries)?;
    }
}
