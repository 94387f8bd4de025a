//! Bond updates per second of the lattice solid step on 2D disks: a bonded random
//! packing (radii 0.2–0.5 m, packing fraction 0.8) stepped at half the stable time step.
//! One "bond update" is one bond's force evaluation inside a full step (integration,
//! contacts and gathering included in the time).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use porofrac_lsm::{BondLaw, LatticeSolid, LsmSpec};
use porofrac_particles::{Disks, RandomPacking};

fn solid(side: f64) -> LatticeSolid {
    let p = RandomPacking::new([0.0, 0.0], [side, side], 0.2, 0.5, 0.8, 1)
        .generate()
        .unwrap();
    let d = Disks::new(&p.centres, &p.radii, 2600.0).unwrap();
    let mut spec = LsmSpec::new(BondLaw::elastic(6e9, 3e9, 1e7));
    spec.bond_tolerance = 0.05;
    LatticeSolid::new(d, spec).unwrap()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("lsm_step");
    for side in [40.0, 120.0] {
        let mut s = solid(side);
        let dt = 0.5 * s.stable_dt();
        let steps = 20;
        g.throughput(Throughput::Elements((s.bonds().len() * steps) as u64));
        g.bench_function(
            format!("{}_disks_{}_bonds", s.disks().len(), s.bonds().len()),
            |b| {
                b.iter(|| {
                    for _ in 0..steps {
                        s.step(dt, &[]).unwrap();
                    }
                })
            },
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
