//! Elasticity systems assembled by porofrac-sim for the tests, examples and benchmarks:
//! the standard problems E2 (2D plane strain, triangles) and E3 (3D, tetrahedra) with
//! their manufactured solutions, and the Cholesky reference solution.
#![allow(dead_code)]

use porofrac_amg::SymCsr;
use porofrac_grid::{Grid, Point, generate};
use porofrac_law::{CellLaw, Stiffness};
use porofrac_sim::ordering::nested_dissection;
use porofrac_sim::standard::{self, Manufactured};
use porofrac_sim::{
    DirectSolver, Displacement, DofMap, LawMap, Loads, Pattern, Platen, assemble, nodal_loads,
};
use porofrac_vem::VemLaw;

/// A reduced elasticity system `A x = b` with what the multigrid setup needs.
pub struct System<const D: usize> {
    pub grid: Grid<D>,
    pub dofs: DofMap<D>,
    pub pattern: Pattern,
    /// Upper-triangle values on `pattern`.
    pub values: Vec<f64>,
    pub rhs: Vec<f64>,
    /// Node coordinates, `D` per node.
    pub coords: Vec<f64>,
    /// `(node, component)` of every equation.
    pub eq_dofs: Vec<(usize, usize)>,
}

impl<const D: usize> System<D> {
    /// Number of equations.
    pub fn n(&self) -> usize {
        self.pattern.num_equations()
    }
    /// The matrix for the multigrid.
    pub fn sym(&self) -> SymCsr {
        SymCsr::from_upper_csc(
            self.n(),
            self.pattern.col_ptr(),
            self.pattern.row_idx(),
            &self.values,
        )
        .expect("valid pattern")
    }
    /// Node id of every equation.
    pub fn nodes(&self) -> Vec<usize> {
        self.eq_dofs.iter().map(|&(n, _)| n).collect()
    }
    /// The Cholesky solution of the system (nested dissection in 3D, AMD in 2D).
    pub fn cholesky(&self) -> Vec<f64> {
        let mut solver = if D == 3 {
            let perm = nested_dissection(&self.grid, &self.dofs);
            DirectSolver::with_ordering(&self.pattern, &perm).expect("ordering")
        } else {
            DirectSolver::new(&self.pattern).expect("symbolic")
        };
        solver
            .factorize(&self.pattern, &self.values)
            .expect("positive definite");
        let mut x = self.rhs.clone();
        solver.solve_in_place(&mut x).expect("solve");
        x
    }
    /// Reassemble with another law (same grid and conditions).
    pub fn reassemble(&mut self, law: &dyn CellLaw<D>) {
        let (values, rhs) = assemble_system(&self.grid, &self.dofs, &self.pattern, law, None);
        self.values = values;
        self.rhs = rhs;
    }
}

/// `(node, component)` of every equation (a shared platen equation: its first node).
pub fn equation_dofs<const D: usize>(grid: &Grid<D>, dofs: &DofMap<D>) -> Vec<(usize, usize)> {
    let mut out = vec![(usize::MAX, 0); dofs.num_equations()];
    for node in 0..grid.num_nodes() {
        for a in 0..D {
            if let Some(e) = dofs.equation(node, a)
                && out[e].0 == usize::MAX
            {
                out[e] = (node, a);
            }
        }
    }
    out
}

/// Stiffness values and right-hand side `Tᵀ(f − K u_p) + F_platen` at `t = 0`.
fn assemble_system<const D: usize>(
    grid: &Grid<D>,
    dofs: &DofMap<D>,
    pattern: &Pattern,
    law: &dyn CellLaw<D>,
    loads: Option<&Loads<D>>,
) -> (Vec<f64>, Vec<f64>) {
    let laws = LawMap::uniform(grid, law).expect("law map");
    let mut u = vec![0.0; dofs.num_dofs()];
    dofs.set_prescribed(grid, 0.0, &mut u);
    let mut values = vec![0.0; pattern.nnz()];
    let mut forces = vec![0.0; dofs.num_equations()];
    assemble(grid, &laws, dofs, pattern, &u, &mut values, &mut forces).expect("assembly");
    let mut full = vec![0.0; dofs.num_dofs()];
    let mut rhs = forces;
    if let Some(loads) = loads {
        nodal_loads(grid, loads, 0.0, &mut full).expect("loads");
        dofs.reduce_add(&full, &mut rhs);
    }
    dofs.add_platen_forces(grid, 0.0, &mut rhs);
    (values, rhs)
}

/// Assemble a system on `grid` with the given conditions, loads and law.
pub fn build<const D: usize>(
    grid: Grid<D>,
    displacements: &[Displacement<D>],
    platens: &[Platen<D>],
    loads: &Loads<D>,
    law: &dyn CellLaw<D>,
) -> System<D> {
    let dofs = DofMap::new(&grid, displacements, platens).expect("dof map");
    let pattern = Pattern::new(&grid, &dofs).expect("pattern");
    let (values, rhs) = assemble_system(&grid, &dofs, &pattern, law, Some(loads));
    let coords: Vec<f64> = grid
        .nodes()
        .iter()
        .flat_map(|p| p.iter().copied().collect::<Vec<_>>())
        .collect();
    let eq_dofs = equation_dofs(&grid, &dofs);
    System {
        grid,
        dofs,
        pattern,
        values,
        rhs,
        coords,
        eq_dofs,
    }
}

/// The standard problem on `grid` (Dirichlet on the whole boundary, the manufactured body
/// force), E = 1, ν = 0.3 (plane strain in 2D), P1 = VEM on simplices.
fn standard<const D: usize>(grid: Grid<D>, problem: &Manufactured<D>) -> System<D> {
    let bc = problem.boundary("boundary", grid.boundary_faces());
    let loads = Loads {
        body_force: Some(problem.body_force()),
        ..Loads::default()
    };
    let law = VemLaw::new(Stiffness::<D>::isotropic(1.0, 0.3).expect("material"));
    build(grid, &[bc], &[], &loads, &law)
}

/// E2: unit square, `n × n` squares split in two triangles (see
/// [`porofrac_sim::standard`]).
pub fn e2(n: usize) -> System<2> {
    let grid = generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::repeat(1.0), [n, n])
        .expect("grid");
    standard(grid, &standard::e2())
}

/// E3: unit cube, `n³` cubes split in six tetrahedra (see [`porofrac_sim::standard`]).
pub fn e3(n: usize) -> System<3> {
    let grid = generate::simplices::<3>(Point::<3>::zeros(), Point::<3>::repeat(1.0), [n, n, n])
        .expect("grid");
    standard(grid, &standard::e3())
}

/// `‖a − b‖ / ‖b‖`.
pub fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let n: f64 = b.iter().map(|y| y * y).sum();
    (d / n).sqrt()
}
