//! The obstacles' rules applied inside the stream–collide sweep (each band of the parallel
//! sweep applies the rules of the bodies whose cut links lie in it, as soon as the rows
//! they read are final) give the bits of applying every rule after the sweep: every
//! population of every fluid node, every force and torque and the mass after every step,
//! for bodies moved by the lattice across band boundaries, next to a wall and a pressure
//! side (where the rules must wait for the sides'), in `f64` and `f32`, with both momentum
//! exchanges, with and without the mass correction, with the solid skipped or stepped, on
//! 1, 2 and 3 threads (other bands).

use porofrac_lbm::{
    Collision, Lattice, LatticeConfig, MomentumExchange, Obstacle, ObstacleMass, Precision, Shape,
    SideKind,
};

const NX: usize = 72;
const NY: usize = 240;

/// Disks on a jittered grid, radii 2.3–6.8, all moving up and turning, two of them next to
/// the bottom wall and one against the top side.
fn lattice(cfg: &LatticeConfig, precision: Precision, in_sweep: bool, skip: bool) -> Lattice {
    let mut l = Lattice::new(cfg.clone()).unwrap();
    l.set_precision(precision);
    l.set_rules_in_sweep(in_sweep);
    l.set_skip_solid(if skip { Some(4) } else { None });
    l.init(|p| {
        let x = p[0] / NX as f64;
        (
            1.0 + 0.002 * (7.0 * x).sin(),
            [0.01 * (p[1] / 30.0).cos(), 0.0],
        )
    });
    let mut k = 0usize;
    for row in 0..14 {
        for col in 0..4 {
            let jit = ((k * 37 + 11) % 17) as f64 / 17.0;
            let r = 2.3 + 4.5 * ((k * 53 + 7) % 19) as f64 / 19.0;
            let c = [
                9.0 + 18.0 * col as f64 + 2.0 * jit,
                4.5 + 16.5 * row as f64 + jit,
            ];
            let r = r.min(c[1] - 1.2).min(NY as f64 - c[1] - 1.2);
            l.add_obstacle(Obstacle {
                shape: Shape::Circle {
                    center: c,
                    radius: r,
                },
                velocity: [0.004 * (k as f64).sin(), 0.011 + 0.001 * (k % 3) as f64],
                angular_velocity: 0.003 * (k as f64).cos(),
            })
            .unwrap();
            k += 1;
        }
    }
    l
}

fn same_bits(a: &Lattice, b: &Lattice, what: &str) {
    let (nx, ny) = a.size();
    for k in 0..a.obstacles().len() {
        assert_eq!(
            a.force(k).map(f64::to_bits),
            b.force(k).map(f64::to_bits),
            "{what}, body {k}: {:?} vs {:?}",
            a.force(k),
            b.force(k)
        );
    }
    for j in 0..ny {
        for i in 0..nx {
            assert_eq!(
                a.is_solid(i, j),
                b.is_solid(i, j),
                "{what}, node ({i}, {j})"
            );
            if a.is_solid(i, j) {
                continue;
            }
            for q in 0..9 {
                assert_eq!(
                    a.population(i, j, q).to_bits(),
                    b.population(i, j, q).to_bits(),
                    "{what}, node ({i}, {j}), q {q}"
                );
            }
        }
    }
    assert_eq!(a.mass().to_bits(), b.mass().to_bits(), "{what}: mass");
}

fn compare(cfg: &LatticeConfig, precision: Precision, skip: bool, steps: usize) -> usize {
    let mut a = lattice(cfg, precision, true, skip);
    let mut b = lattice(cfg, precision, false, skip);
    let mut in_sweep = 0;
    for step in 0..steps {
        a.step().unwrap();
        b.step().unwrap();
        assert_eq!(b.obstacles_in_sweep(), 0);
        in_sweep += a.obstacles_in_sweep();
        same_bits(
            &a,
            &b,
            &format!("{cfg:?} {precision:?} skip {skip}, step {step}"),
        );
    }
    in_sweep
}

#[test]
fn rules_in_the_sweep_give_the_bits_of_rules_after_it() {
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut cfg = LatticeConfig::periodic(NX, NY, 0.8);
            cfg.periodic = [true, false];
            cfg.sides = [
                SideKind::Wall,
                SideKind::Wall,
                SideKind::Wall,
                SideKind::Pressure { density: 1.0 },
            ];
            let mut runs = 0;
            for (precision, exchange, mass, skip) in [
                (
                    Precision::Double,
                    MomentumExchange::Standard,
                    ObstacleMass::Conserved,
                    true,
                ),
                (
                    Precision::Single,
                    MomentumExchange::Standard,
                    ObstacleMass::Conserved,
                    true,
                ),
                (
                    Precision::Double,
                    MomentumExchange::GalileanInvariant,
                    ObstacleMass::Uncorrected,
                    false,
                ),
            ] {
                cfg.momentum_exchange = exchange;
                cfg.obstacle_mass = mass;
                cfg.collision = if skip {
                    Collision::Bgk
                } else {
                    Collision::Trt { magic: 0.25 }
                };
                cfg.accel = if skip { [0.0, 0.0] } else { [1e-6, -2e-6] };
                let steps = 40;
                let in_sweep = compare(&cfg, precision, skip, steps);
                // 56 bodies: most lie inside a band (bands of 60, 30 and 20 rows)
                let least = if threads == 3 { 5 } else { 15 };
                assert!(
                    in_sweep >= least * steps,
                    "{threads} threads: {in_sweep} bodies in the sweep over {steps} steps"
                );
                runs += 1;
            }
            assert_eq!(runs, 3);
        });
    }
}
