//! NLGS speed on a dense pile of 10 000 disks: contact updates (local solves) per second.
//!
//! The pile is a seeded random packing (radii 0.4–0.6 m, packing fraction 0.8) in a
//! 100 m wide box with a floor and two side walls, settled under gravity for 20 steps.
//! Each measured iteration is one time step of h = 1e-3 s with exactly 100 sweeps
//! (min = max = 100); criterion reports elements per second = contacts × 100 / time.
//! Three variants: the sequential sweep in sorted order, and the coloured and the
//! slab-partitioned parallel sweeps in rayon's default pool (one thread per core).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use porofrac_nscd::{ContactLaw, Nscd, Ordering, RigidBody, SolverParams};
use porofrac_particles::{Disks, RandomPacking};

fn pile(ordering: Ordering) -> Nscd {
    let (w, h) = (100.0, 99.5);
    let p = RandomPacking::new([0.0, 0.0], [w, h], 0.4, 0.6, 0.8, 1)
        .generate()
        .unwrap();
    let d = Disks::new(&p.centres, &p.radii, 2800.0).unwrap();
    let walls = vec![
        RigidBody::segment([-1.0, 0.0], [w + 1.0, 0.0]),
        RigidBody::segment([0.0, 2.0 * h], [0.0, 0.0]),
        RigidBody::segment([w, 0.0], [w, 2.0 * h]),
    ];
    let params = SolverParams {
        min_sweeps: 100,
        max_sweeps: 100,
        tolerance: 1e-30,
        ordering,
        ..SolverParams::default()
    };
    let mut s = Nscd::new(d, walls, ContactLaw::frictional(0.4), params, [0.0, -9.81]).unwrap();
    for _ in 0..20 {
        s.step(1e-3).unwrap();
    }
    s
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("nlgs");
    g.sample_size(10);
    for (name, ordering) in [
        ("sorted, 1 thread", Ordering::Sorted),
        ("coloured, rayon pool", Ordering::Coloured),
        ("slabs, rayon pool", Ordering::Slabs),
    ] {
        let mut s = pile(ordering);
        let contacts = s.step(1e-3).unwrap().contacts;
        g.throughput(Throughput::Elements(100 * contacts as u64));
        g.bench_function(
            format!("pile 1e4 disks, {contacts} contacts, 100 sweeps, {name}"),
            |b| b.iter(|| s.step(1e-3).unwrap()),
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
