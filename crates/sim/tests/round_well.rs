//! The patch test on the round-well grid: graded triangles (MDEM) around a circular well,
//! joined to the VEM far field by hanging nodes, in 2D and extruded to 3D (tetrahedra in
//! polygonal prisms). `u = A x + b` prescribed on the boundary is reproduced at every node
//! and every cell stress is the exact constant stress, to 1e-9 relative: the zone conforms
//! with the far field.

mod common;

use common::rel;
use nalgebra::SMatrix;
use porofrac_grid::generate::{RoundWellSpec, extrude, round_well};
use porofrac_grid::{Grid, Point};
use porofrac_law::CellLaw;
use porofrac_law::stiffness::Stiffness;
use porofrac_mdem::MdemLaw;
use porofrac_sim::*;
use porofrac_vem::VemLaw;

/// Largest relative displacement and stress errors of the patch test with MDEM on the
/// cells tagged `refined` and VEM on the others.
fn patch<const D: usize>(grid: &Grid<D>) -> (f64, f64) {
    let (e, nu) = (2.0e10, 0.25);
    let stiffness = Stiffness::<D>::isotropic(e, nu).unwrap();
    let vem = VemLaw::<D>::new(stiffness.clone());
    let mdem = MdemLaw::<D>::new(&stiffness).unwrap();
    let mut law_of_cell = vec![0; grid.num_cells()];
    for &c in &grid.cell_tags()["refined"] {
        law_of_cell[c] = 1;
    }
    let laws = LawMap::new(grid, vec![&vem as &dyn CellLaw<D>, &mdem], law_of_cell).unwrap();
    let a = SMatrix::<f64, D, D>::from_fn(|i, j| 1e-4 * (0.4 + i as f64 - 0.9 * j as f64));
    let b = Point::<D>::from_fn(|i, _| 1e-3 * (1.0 - 1.5 * i as f64));
    let exact = move |x: &[f64], c: usize| b[c] + (0..D).map(|j| a[(c, j)] * x[j]).sum::<f64>();
    let bc = Displacement {
        name: "boundary".into(),
        faces: grid.boundary_faces(),
        components: std::array::from_fn(|c| Some(ScalarField::from_fn(move |x, _| exact(x, c)))),
    };
    let dofs = DofMap::new(grid, &[bc], &[]).unwrap();
    let pattern = Pattern::new(grid, &dofs).unwrap();
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
    let worst = (0..D * grid.num_nodes())
        .map(|k| rel(u[k], exact(grid.node(k / D).as_slice(), k % D), scale))
        .fold(0.0, f64::max);
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let eps = (a + a.transpose()) * 0.5;
    let sig = eps * (2.0 * mu) + SMatrix::<f64, D, D>::identity() * (lambda * eps.trace());
    let s = cell_stresses(grid, &laws, &u).unwrap();
    let worst_s = s
        .iter()
        .map(|t| (t - sig).amax() / sig.amax())
        .fold(0.0, f64::max);
    (worst, worst_s)
}

fn small_well() -> Grid<2> {
    // 8 m × 8 m, 1 m cells, the zone 3 × 3 cells around (4.5, 4.5), a 0.4 m well.
    let spec = RoundWellSpec::new(
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(8.0, 8.0),
        [8, 8],
        Point::<2>::new(4.5, 4.5),
        1.5,
        4,
        0.4,
    );
    round_well(&spec).unwrap()
}

#[test]
fn round_well_zone_passes_the_patch_test_in_2d() {
    let g = small_well();
    let (du, ds) = patch(&g);
    eprintln!("round well 2D patch test: displacement {du:.2e}, stress {ds:.2e}");
    assert!(du < 1e-9, "displacement error {du:.2e}");
    assert!(ds < 1e-9, "stress error {ds:.2e}");
}

#[test]
fn extruded_round_well_zone_passes_the_patch_test_in_3d() {
    let g = extrude(&small_well(), &[0.0, 0.5, 1.0]).unwrap();
    let (du, ds) = patch(&g);
    eprintln!("round well 3D patch test: displacement {du:.2e}, stress {ds:.2e}");
    assert!(du < 1e-9, "displacement error {du:.2e}");
    assert!(ds < 1e-9, "stress error {ds:.2e}");
}
