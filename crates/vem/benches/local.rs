//! Local VEM stiffness per cell type with a reused `Scratch` and output matrix.
//!
//! Run: `cargo bench -p porofrac-vem --bench local -- --warm-up-time 1 --measurement-time 2`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::DMatrix;
use porofrac_grid::{Grid, Point};
use porofrac_law::{GeometryBuffer, Scratch, Stiffness};
use porofrac_vem::VemLaw;

#[path = "../tests/common/mod.rs"]
mod common;

fn bench_cell<const D: usize>(c: &mut Criterion, name: &str, grid: &Grid<D>, law: &VemLaw<D>) {
    let mut buf = GeometryBuffer::<D>::default();
    let cell = buf.load(grid, 0);
    let mut scratch = Scratch::default();
    let mut out = DMatrix::zeros(0, 0);
    c.bench_function(&format!("vem local stiffness {name}"), |b| {
        b.iter(|| {
            law.local_stiffness(black_box(&cell), &mut out, &mut scratch);
            black_box(out[(0, 0)])
        })
    });
}

fn local(c: &mut Criterion) {
    let law2 = VemLaw::new(Stiffness::<2>::isotropic(1.0, 0.3).unwrap());
    let law3 = VemLaw::new(Stiffness::<3>::isotropic(1.0, 0.3).unwrap());
    let tri = common::polygon(vec![
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(1.0, 0.1),
        Point::<2>::new(0.3, 0.9),
    ]);
    bench_cell(c, "triangle", &tri, &law2);
    let quad = common::polygon(vec![
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(1.0, 0.1),
        Point::<2>::new(1.1, 0.9),
        Point::<2>::new(-0.1, 1.0),
    ]);
    bench_cell(c, "quadrilateral", &quad, &law2);
    let hex2 = common::polygon(common::regular(6, 1.0, Point::<2>::zeros()));
    bench_cell(c, "hexagon", &hex2, &law2);
    let tet = common::tetrahedron([
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(1.0, 0.1, 0.0),
        Point::<3>::new(0.2, 1.0, 0.1),
        Point::<3>::new(0.1, 0.2, 1.0),
    ])
    .unwrap();
    bench_cell(c, "tetrahedron", &tet, &law3);
    let corners: Vec<Point<3>> = common::cube_corners()
        .into_iter()
        .enumerate()
        .map(|(k, x)| x + common::jitter(k, 0.1))
        .collect();
    bench_cell(c, "hexahedron", &common::hexahedron(corners), &law3);
    let poly = common::twelve_faces(|k| common::jitter(k, 0.05));
    bench_cell(c, "12-face polyhedron (18 nodes)", &poly, &law3);
}

criterion_group!(benches, local);
criterion_main!(benches);
