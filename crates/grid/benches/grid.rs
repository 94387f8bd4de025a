//! Grid construction benchmarks: topology + geometry of large structured simplex grids
//! and a 2D Voronoi grid.
//!
//! `cargo bench -p porofrac-grid --bench grid`

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use porofrac_grid::Point;
use porofrac_grid::generate::{DEFAULT_LLOYD, simplices, voronoi};

fn build(c: &mut Criterion) {
    let mut group = c.benchmark_group("grid");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(10));
    group.bench_function("triangles_1000x1000 (2M cells)", |b| {
        b.iter(|| {
            simplices(
                Point::<2>::new(0.0, 0.0),
                Point::<2>::new(1.0, 1.0),
                [1000, 1000],
            )
            .expect("valid grid")
        })
    });
    group.bench_function("tetrahedra_60^3 (1.3M cells)", |b| {
        b.iter(|| {
            simplices(
                Point::<3>::new(0.0, 0.0, 0.0),
                Point::<3>::new(1.0, 1.0, 1.0),
                [60, 60, 60],
            )
            .expect("valid grid")
        })
    });
    group.bench_function("voronoi_1e5 (3 Lloyd iterations)", |b| {
        b.iter(|| {
            voronoi(
                Point::<2>::new(0.0, 0.0),
                Point::<2>::new(1.0, 1.0),
                100_000,
                1,
                DEFAULT_LLOYD,
            )
            .expect("valid grid")
        })
    });
    group.finish();
}

criterion_group!(benches, build);
criterion_main!(benches);
