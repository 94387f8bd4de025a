//! The VEM patch test on corner-point grids: a faulted deck whose layers cross inside the
//! fault (nodes inside the fault surface, split sub-faces) on skewed, non-parallel pillars
//! (non-planar faces). `u = A x + b` prescribed on the boundary is reproduced at every
//! node and every cell stress is the exact constant stress, to 1e-9 relative.

mod common;

use common::rel;
use nalgebra::SMatrix;
use porofrac_grid::Point;
use porofrac_grid::io::grdecl::{Deck, corner_point_grid};
use porofrac_law::stiffness::Stiffness;
use porofrac_sim::*;
use porofrac_vem::VemLaw;

#[test]
fn vem_patch_test_on_a_faulted_corner_point_grid() {
    let (dx, dy, dz) = (10.0, 20.0, 2.0);
    let mut deck = Deck::on_vertical_pillars([3, 2, 3], [dx, dy], |[i, _], x, y, k| {
        100.0
            + k as f64 * dz
            + 0.05 * x
            + if i >= 2 {
                1.5 * dz * y / (2.0 * dy)
            } else {
                0.0
            }
    });
    // Skew the pillars, each differently: their bottom points move sideways.
    for (p, c) in deck.coord.chunks_mut(6).enumerate() {
        c[3] += 0.003 * ((p * 7) % 5) as f64;
        c[4] -= 0.002 * ((p * 3) % 4) as f64;
    }
    let cp = corner_point_grid(&deck).unwrap();
    let grid = &cp.grid;
    assert_eq!(grid.num_cells(), 18);
    assert!(grid.max_cell_nodes() > 8, "split faces add nodes to cells");
    let (e, nu) = (2.0e10, 0.25);
    let law = VemLaw::<3>::new(Stiffness::<3>::isotropic(e, nu).unwrap());
    let a = SMatrix::<f64, 3, 3>::from_fn(|i, j| 1e-4 * (0.4 + i as f64 - 0.9 * j as f64));
    let b = Point::<3>::new(1e-3, -2e-3, 5e-4);
    let exact = move |x: &[f64], c: usize| b[c] + (0..3).map(|j| a[(c, j)] * x[j]).sum::<f64>();
    let bc = Displacement {
        name: "boundary".into(),
        faces: grid.boundary_faces(),
        components: std::array::from_fn(|c| Some(ScalarField::from_fn(move |x, _| exact(x, c)))),
    };
    let dofs = DofMap::new(grid, &[bc], &[]).unwrap();
    assert!(dofs.num_equations() > 0, "interior nodes are free");
    let pattern = Pattern::new(grid, &dofs).unwrap();
    let laws = LawMap::uniform(grid, &law).unwrap();
    let mut solver = DirectSolver::new(&pattern).unwrap();
    let loads = Loads::default();
    let problem = StaticProblem {
        grid,
        laws: &laws,
        dofs: &dofs,
        pattern: &pattern,
        loads: &loads,
    };
    let u = solve_static(&problem, &mut solver, 0.0, &StaticOptions::default())
        .unwrap()
        .displacement;
    let scale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = (0..3 * grid.num_nodes())
        .map(|k| rel(u[k], exact(grid.node(k / 3).as_slice(), k % 3), scale))
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "displacement error {worst:.2e}");
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let eps = (a + a.transpose()) * 0.5;
    let sig = eps * (2.0 * mu) + SMatrix::<f64, 3, 3>::identity() * (lambda * eps.trace());
    let s = cell_stresses(grid, &laws, &u).unwrap();
    let worst_s = s
        .iter()
        .map(|t| (t - sig).amax() / sig.amax())
        .fold(0.0, f64::max);
    assert!(worst_s < 1e-9, "stress error {worst_s:.2e}");
    eprintln!("corner-point VEM patch test: displacement {worst:.2e}, stress {worst_s:.2e}");
}
