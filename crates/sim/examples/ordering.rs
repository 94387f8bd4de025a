//! Fill and time of the sparse Cholesky factor with AMD and with geometric nested
//! dissection, on the E3 standard grid (n³ cubes, 6 tetrahedra each, all sides clamped).
//!
//! `cargo run --release -p porofrac-sim --example ordering -- 20 40`

use std::time::Instant;

use porofrac_grid::Point;
use porofrac_grid::generate::simplices;
use porofrac_law::Stiffness;
use porofrac_sim::ordering::nested_dissection;
use porofrac_sim::{DirectSolver, Displacement, DofMap, LawMap, Pattern, ScalarField, assemble};
use porofrac_vem::VemLaw;

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if sizes.is_empty() {
        vec![10, 20]
    } else {
        sizes
    };
    println!(
        "| n | equations | ordering | analysis | factor nnz | numeric factorization | solve |"
    );
    println!("|---|---|---|---|---|---|---|");
    for n in sizes {
        let g = simplices(
            Point::<3>::new(0.0, 0.0, 0.0),
            Point::<3>::new(1.0, 1.0, 1.0),
            [n, n, n],
        )
        .unwrap();
        let sides: Vec<usize> = g.boundary_faces();
        let clamp = Displacement {
            name: "boundary".into(),
            faces: sides,
            components: std::array::from_fn(|_| Some(ScalarField::Const(0.0))),
        };
        let dofs = DofMap::new(&g, &[clamp], &[]).unwrap();
        let pattern = Pattern::new(&g, &dofs).unwrap();
        let law = VemLaw::new(Stiffness::<3>::isotropic(1.0, 0.3).unwrap());
        let laws = LawMap::uniform(&g, &law).unwrap();
        let mut values = vec![0.0; pattern.nnz()];
        let mut forces = vec![0.0; dofs.num_equations()];
        let u = vec![0.0; dofs.num_dofs()];
        assemble(&g, &laws, &dofs, &pattern, &u, &mut values, &mut forces).unwrap();
        for name in ["amd", "nested dissection"] {
            let t0 = Instant::now();
            let mut solver = if name == "amd" {
                DirectSolver::new(&pattern).unwrap()
            } else {
                let perm = nested_dissection(&g, &dofs);
                DirectSolver::with_ordering(&pattern, &perm).unwrap()
            };
            let t_sym = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            solver.factorize(&pattern, &values).unwrap();
            let t_num = t1.elapsed().as_secs_f64();
            let mut rhs = vec![1.0; dofs.num_equations()];
            let t2 = Instant::now();
            solver.solve_in_place(&mut rhs).unwrap();
            let t_solve = t2.elapsed().as_secs_f64();
            println!(
                "| {n} | {} | {name} | {t_sym:.3} s | {:.3e} | {t_num:.3} s | {t_solve:.3} s |",
                dofs.num_equations(),
                solver.factor_nnz() as f64
            );
        }
    }
}
