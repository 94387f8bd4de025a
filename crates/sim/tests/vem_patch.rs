//! Patch test with the VEM law on perturbed Cartesian grids (quadrilaterals, hexahedra
//! with non-planar faces): `u = A x + b` prescribed on the boundary is reproduced at every
//! interior node to 1e-10 relative, and every cell stress equals the exact constant stress
//! to 1e-10 relative.

mod common;

use common::{perturb, rel};
use nalgebra::SMatrix;
use porofrac_grid::{Point, generate};
use porofrac_law::stiffness::Stiffness;
use porofrac_sim::*;
use porofrac_vem::VemLaw;

fn vem_patch<const D: usize>(n: usize) {
    let (e, nu) = (3.0e9, 0.22);
    let grid = perturb(
        &generate::cartesian::<D>(Point::<D>::zeros(), Point::<D>::repeat(1.0), [n; D]).unwrap(),
        1.0 / n as f64,
        0.2,
    );
    let law = VemLaw::<D>::new(Stiffness::<D>::isotropic(e, nu).unwrap());
    let a = SMatrix::<f64, D, D>::from_fn(|i, j| 1e-3 * (0.4 + i as f64 - 0.9 * j as f64));
    let b = Point::<D>::from_fn(|i, _| 1e-3 * (1.0 - i as f64));
    let exact = move |x: &[f64], c: usize| b[c] + (0..D).map(|j| a[(c, j)] * x[j]).sum::<f64>();
    let bc = Displacement {
        name: "boundary".into(),
        faces: grid.boundary_faces(),
        components: std::array::from_fn(|c| Some(ScalarField::from_fn(move |x, _| exact(x, c)))),
    };
    let dofs = DofMap::new(&grid, &[bc], &[]).unwrap();
    let pattern = Pattern::new(&grid, &dofs).unwrap();
    let laws = LawMap::uniform(&grid, &law).unwrap();
    let mut solver = DirectSolver::new(&pattern).unwrap();
    let loads = Loads::default();
    let problem = StaticProblem {
        grid: &grid,
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
    assert!(
        worst < 1e-10,
        "{D}D VEM patch test: displacement error {worst:.2e}"
    );
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let eps = (a + a.transpose()) * 0.5;
    let sig = eps * (2.0 * mu) + SMatrix::<f64, D, D>::identity() * (lambda * eps.trace());
    let s = cell_stresses(&grid, &laws, &u).unwrap();
    let worst_s = s
        .iter()
        .map(|t| (t - sig).amax() / sig.amax())
        .fold(0.0, f64::max);
    assert!(
        worst_s < 1e-10,
        "{D}D VEM patch test: stress error {worst_s:.2e}"
    );
    eprintln!("{D}D VEM patch test: displacement {worst:.2e}, stress {worst_s:.2e}");
}

#[test]
fn vem_patch_2d() {
    vem_patch::<2>(6);
}

#[test]
fn vem_patch_3d() {
    vem_patch::<3>(3);
}
