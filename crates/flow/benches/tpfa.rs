//! TPFA assembly + solve on 2D Cartesian grids of 1e4, 1e5 and 1e6 cells.
//!
//! `assemble_solve`: transmissibilities, model (pattern, BCs), symbolic and numeric sparse
//! Cholesky and one steady solve — everything but the grid. `step_reused`: one implicit
//! Euler step with the factorization reused (the cost of every later step).

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock};
use porofrac_grid::generate::cartesian;
use porofrac_grid::{Grid, Point};

fn problem(grid: &Grid<2>) -> FlowProblem<2> {
    let n = grid.num_cells();
    FlowProblem::new(
        Rock::new(
            vec![0.2; n],
            Permeability::uniform(n, 1e-13).expect("valid"),
        ),
        Fluid::water(),
    )
    .pressure_bc(grid.boundary("xmin").expect("side"), 2e7)
    .pressure_bc(grid.boundary("xmax").expect("side"), 1e7)
}

fn bench(c: &mut Criterion) {
    for (side, samples) in [(100usize, 20usize), (316, 10), (1000, 10)] {
        let grid = cartesian::<2>(
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 1.0),
            [side, side],
        )
        .expect("grid");
        let prob = problem(&grid);
        let cells = grid.num_cells();
        let mut g = c.benchmark_group("tpfa");
        g.sample_size(samples)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(3));
        g.bench_with_input(
            BenchmarkId::new("assemble_solve", cells),
            &grid,
            |b, grid| {
                b.iter(|| {
                    let mut m = FlowModel::new(grid, &prob).expect("model");
                    black_box(m.solve_steady(0.0).expect("solve").pressure[0])
                })
            },
        );
        let mut model = FlowModel::new(&grid, &prob).expect("model");
        let p0 = vec![1.5e7; cells];
        model.step(&p0, 3600.0, 0.0).expect("step");
        g.bench_with_input(BenchmarkId::new("step_reused", cells), &p0, |b, p0| {
            b.iter(|| black_box(model.step(p0, 3600.0, 0.0).expect("step").pressure[0]))
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
