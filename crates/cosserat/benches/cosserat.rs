//! Assembly (reconstruction included) and linear solves of the Cosserat DEM on the plate
//! with a hole, O-grid levels 3 and 5 (2,880 and 8,000 triangles, 8,640 and 24,000
//! unknowns; r = 0.216 mm, r/ℓ = 1.063, N = 0.5), every solver: `cargo bench -p
//! porofrac-cosserat`.

#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use porofrac_cosserat::{
    BodyLoads, Condition, Cosserat, FactorPrecision, GmresOptions, LinearOptions, LinearSolver,
    Material, Options, constant, mesh,
};
use porofrac_grid::Grid;

fn grid(level: usize) -> Grid<2> {
    let r = 0.216;
    mesh::plate_with_hole(16.2, r, 16 * level, 10 * level, 0.1 * r / level as f64).unwrap()
}

fn model(grid: Grid<2>) -> Cosserat<2> {
    let n = 0.5f64;
    let a = n * n / (1.0 - n * n);
    let m = Material::with_length(1e3, 0.3, a * 1e3, 0.216 / 1.063).unwrap();
    let left = Condition::new(grid.boundary("xmin").unwrap())
        .fix(0, constant(0.0))
        .fix(2, constant(0.0));
    let bottom = Condition::new(grid.boundary("ymin").unwrap())
        .fix(1, constant(0.0))
        .fix(2, constant(0.0));
    let top = Condition::new(grid.boundary("ymax").unwrap()).load(1, constant(1.0));
    Cosserat::new(
        grid,
        m,
        Options::default(),
        &[left, bottom, top],
        BodyLoads::none(),
    )
    .unwrap()
}

fn bench(c: &mut Criterion) {
    for level in [3, 5] {
        let g = grid(level);
        let mut group = c.benchmark_group(format!("cosserat_plate_hole_level{level}"));
        group.sample_size(10);
        group.bench_function("assembly", |b| b.iter(|| model(g.clone())));
        let m = model(g);
        for (solver, precision, suffix) in [
            (LinearSolver::Lu, FactorPrecision::Single, ""),
            (LinearSolver::GmresAmg, FactorPrecision::Single, ""),
            (LinearSolver::GmresLdlt, FactorPrecision::Single, ""),
            (LinearSolver::LdltSchur, FactorPrecision::Single, ""),
            (LinearSolver::LdltSchur, FactorPrecision::Double, "_double"),
        ] {
            let options = LinearOptions {
                solver,
                gmres: GmresOptions {
                    factor_precision: precision,
                    ..GmresOptions::default()
                },
            };
            group.bench_function(format!("solve_{}{suffix}", solver.name()), |b| {
                b.iter(|| m.solve_static_with(0.0, &options).unwrap())
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
