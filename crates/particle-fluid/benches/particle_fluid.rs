//! The coupled particle–fluid step (`porofrac_particle_fluid`) with N moving disks on
//! a 512² periodic lattice: the whole step, the lattice step alone without disks, and the
//! rasterisation of N moving disks alone (placement, covered/uncovered nodes, `δ` of the
//! cut links). The split of the coupled step between fluid and particles is printed from
//! the model's own timers.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use porofrac_lbm::{Lattice, LatticeConfig, ObstacleMotion, Units};
use porofrac_particle_fluid::{CouplingOptions, ParticleFluid, RigidDisks};
use porofrac_particles::Disks;

const N_LATTICE: usize = 512;

/// N disks of radius 3–6 spacings on a jittered grid, moving at up to 0.01 spacings per
/// step (deterministic).
fn disks(n: usize, u: &Units) -> Disks {
    let per_row = (n as f64).sqrt().ceil() as usize;
    let cell = N_LATTICE as f64 / per_row as f64;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut c, mut r) = (Vec::new(), Vec::new());
    for k in 0..n {
        let radius = (3.0 + 3.0 * rnd()).min(0.5 * cell - 1.0);
        let room = 0.5 * cell - radius - 0.5;
        let x = ((k % per_row) as f64 + 0.5) * cell + room * (2.0 * rnd() - 1.0);
        let y = ((k / per_row) as f64 + 0.5) * cell + room * (2.0 * rnd() - 1.0);
        c.push([x * u.dx, y * u.dx]);
        r.push(radius * u.dx);
    }
    let mut d = Disks::new(&c, &r, 2500.0).expect("disks");
    for k in 0..n {
        d.v[k] = [
            u.velocity_si(0.01 * (2.0 * rnd() - 1.0)),
            u.velocity_si(0.01 * (2.0 * rnd() - 1.0)),
        ];
        d.omega[k] = 1e-3 * (2.0 * rnd() - 1.0) / u.dt;
    }
    d
}

fn bench(c: &mut Criterion) {
    let u = Units::from_viscosity(1e-4, 1e-6, 1000.0, 0.8).expect("units");
    let cfg = LatticeConfig::periodic(N_LATTICE, N_LATTICE, 0.8);
    let mut group = c.benchmark_group("particle_fluid_512");
    group.sample_size(10);
    let mut lat = Lattice::new(cfg.clone()).expect("lattice");
    group.bench_function("lattice_step_no_disks", |b| {
        b.iter(|| lat.step().expect("step"))
    });
    for n in [100usize, 1000] {
        let d = disks(n, &u);
        let mut solver = RigidDisks::new(d.clone());
        let mut sim = ParticleFluid::new(
            &solver,
            Lattice::new(cfg.clone()).expect("lattice"),
            u,
            [0.0, 0.0],
            CouplingOptions::default(),
        )
        .expect("coupling");
        group.bench_with_input(BenchmarkId::new("coupled_step", n), &n, |b, _| {
            b.iter(|| sim.step(&mut solver).expect("step"))
        });
        let s = sim.stats();
        eprintln!(
            "coupled_step/{n}: {} steps, fluid {:.1} %, particles {:.1} % ({} cut links)",
            s.steps,
            100.0 * s.fluid_seconds / (s.fluid_seconds + s.particle_seconds),
            100.0 * s.particle_seconds / (s.fluid_seconds + s.particle_seconds),
            sim.lattice().cut_links()
        );
        // rasterisation alone: every disk moved by a tenth of a spacing back and forth
        let mut lat = sim.lattice().clone();
        lat.set_obstacle_motion_mode(ObstacleMotion::External);
        let centres: Vec<[f64; 2]> = lat.obstacles().iter().map(|o| o.shape.center()).collect();
        let mut flip = 1.0;
        group.bench_with_input(BenchmarkId::new("rasterise", n), &n, |b, _| {
            b.iter(|| {
                flip = -flip;
                for (k, c) in centres.iter().enumerate() {
                    let x = [c[0] + 0.05 * flip, c[1] + 0.03 * flip];
                    lat.place_obstacle(k, x, 0.0, [0.01, 0.0], 0.0);
                }
                lat.update_obstacles().expect("update");
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
