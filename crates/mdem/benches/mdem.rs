//! MDEM forces and stiffness per triangle and per tetrahedron with a reused Scratch.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::DMatrix;
use porofrac_grid::Point;
use porofrac_law::{CellGeometry, CellLaw, Scratch, Stiffness};
use porofrac_mdem::MdemLaw;

fn bench_dim<const D: usize>(c: &mut Criterion, coords: Vec<Point<D>>, name: &str) {
    let law = MdemLaw::<D>::new(&Stiffness::<D>::isotropic(1e9, 0.3).unwrap()).unwrap();
    let normals = vec![Point::<D>::zeros(); D + 1];
    let cell = CellGeometry {
        coords: &coords,
        node_normals: &normals,
        volume: 1.0,
    };
    let n = D * (D + 1);
    let u: Vec<f64> = (0..n).map(|i| 1e-3 * ((i * 7 % 5) as f64 - 2.0)).collect();
    let mut f = vec![0.0; n];
    let mut k = DMatrix::zeros(n, n);
    let mut scratch = Scratch::default();
    c.bench_function(&format!("mdem forces {name}"), |b| {
        b.iter(|| {
            law.forces(black_box(&cell), black_box(&u), &mut f, &mut scratch)
                .unwrap()
        })
    });
    c.bench_function(&format!("mdem stiffness {name}"), |b| {
        b.iter(|| {
            law.stiffness(black_box(&cell), black_box(&u), &mut k, &mut scratch)
                .unwrap()
        })
    });
}

fn benches(c: &mut Criterion) {
    bench_dim::<2>(
        c,
        vec![
            Point::<2>::new(0.1, -0.2),
            Point::<2>::new(1.3, 0.1),
            Point::<2>::new(0.4, 0.9),
        ],
        "triangle",
    );
    bench_dim::<3>(
        c,
        vec![
            Point::<3>::new(0.0, 0.1, -0.1),
            Point::<3>::new(1.2, 0.0, 0.2),
            Point::<3>::new(0.3, 0.9, 0.0),
            Point::<3>::new(0.2, 0.3, 1.1),
        ],
        "tetrahedron",
    );
}

criterion_group!(mdem, benches);
criterion_main!(mdem);
