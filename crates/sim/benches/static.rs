//! E2 of the standard problems (2D plane strain, manufactured solution, unit square split
//! into 2 n² triangles), with the P1 simplex law: assembly, numeric factorization + solve
//! (sequential and 2 threads), at n = 100 and 300.

use std::f64::consts::PI;

#[path = "../tests/common/mod.rs"]
#[allow(missing_docs)]
mod common;

use common::{P1Law, isotropic};
use criterion::{Criterion, criterion_group, criterion_main};
use porofrac_grid::{Point, generate};
use porofrac_law::CellLaw;
use porofrac_sim::*;

fn bench(c: &mut Criterion) {
    let law = P1Law {
        d: isotropic::<2>(1.0, 0.3),
    };
    for n in [100usize, 300] {
        let grid =
            generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::repeat(1.0), [n, n]).unwrap();
        let ux = |x: &[f64], _t: f64| (PI * x[0]).sin() * (PI * x[1]).sin() / 100.0;
        let uy = |x: &[f64], _t: f64| x[0] * x[0] * x[1] / 100.0;
        let bc = Displacement {
            name: "boundary".into(),
            faces: grid.boundary_faces(),
            components: [
                Some(ScalarField::from_fn(ux)),
                Some(ScalarField::from_fn(uy)),
            ],
        };
        let loads = Loads {
            body_force: Some(
                [
                    ScalarField::from_fn(|x, _| {
                        -x[0] / 52.0 + 9.0 * PI * PI * (PI * x[0]).sin() * (PI * x[1]).sin() / 520.0
                    }),
                    ScalarField::from_fn(|x, _| {
                        -x[1] / 130.0 - PI * PI * (PI * x[0]).cos() * (PI * x[1]).cos() / 104.0
                    }),
                ]
                .into(),
            ),
            ..Loads::default()
        };
        let dofs = DofMap::new(&grid, &[bc], &[]).unwrap();
        let pattern = Pattern::new(&grid, &dofs).unwrap();
        let laws = LawMap::uniform(&grid, &law as &dyn CellLaw<2>).unwrap();
        let mut u = vec![0.0; dofs.num_dofs()];
        dofs.set_prescribed(&grid, 0.0, &mut u);
        let mut values = vec![0.0; pattern.nnz()];
        let mut forces = vec![0.0; pattern.num_equations()];
        let mut full = vec![0.0; dofs.num_dofs()];
        eprintln!(
            "E2 n={n}: {} equations, {} stored entries, {} chunks, duplication {:.4}",
            pattern.num_equations(),
            pattern.nnz(),
            pattern.num_chunks(),
            pattern.duplication()
        );
        let mut g = c.benchmark_group(format!("E2_n{n}"));
        g.sample_size(10);
        g.bench_function("pattern", |b| {
            b.iter(|| Pattern::new(&grid, &dofs).unwrap())
        });
        g.bench_function("assemble_stiffness", |b| {
            b.iter(|| {
                assemble(&grid, &laws, &dofs, &pattern, &u, &mut values, &mut forces).unwrap()
            })
        });
        g.bench_function("nodal_loads", |b| {
            b.iter(|| nodal_loads(&grid, &loads, 0.0, &mut full).unwrap())
        });
        g.bench_function("symbolic", |b| {
            b.iter(|| DirectSolver::new(&pattern).unwrap())
        });
        for (name, par) in [
            ("factor_solve_seq", Par::Seq),
            ("factor_solve_rayon2", Par::rayon(2)),
        ] {
            let mut solver = DirectSolver::new(&pattern).unwrap();
            solver.set_parallelism(par);
            let mut rhs = forces.clone();
            g.bench_function(name, |b| {
                b.iter(|| {
                    solver.factorize(&pattern, &values).unwrap();
                    rhs.copy_from_slice(&forces);
                    solver.solve_in_place(&mut rhs).unwrap();
                })
            });
        }
        g.finish();
        // Error of the nodal interpolant, for the record.
        let mut solver = DirectSolver::new(&pattern).unwrap();
        let problem = StaticProblem {
            grid: &grid,
            laws: &laws,
            dofs: &dofs,
            pattern: &pattern,
            loads: &loads,
        };
        let sol = solve_static(&problem, &mut solver, 0.0, &StaticOptions::default()).unwrap();
        let err = (0..grid.num_nodes())
            .map(|k| {
                let x = grid.node(k);
                let e0 = sol.displacement[2 * k] - ux(x.as_slice(), 0.0);
                let e1 = sol.displacement[2 * k + 1] - uy(x.as_slice(), 0.0);
                e0.abs().max(e1.abs())
            })
            .fold(0.0, f64::max);
        eprintln!(
            "E2 n={n}: max nodal error {err:.3e}, factor nnz {}",
            solver.factor_nnz()
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
