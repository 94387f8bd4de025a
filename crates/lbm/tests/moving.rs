//! Moving obstacles: the incremental update gives the geometry a fresh rasterisation
//! gives, fluid plus covered and uncovered nodes conserve momentum to round-off, and mass
//! sources add exactly their mass.

use porofrac_lbm::{Collision, Lattice, LatticeConfig, Obstacle, ObstacleMotion, Shape};

fn disk(center: [f64; 2], radius: f64, velocity: [f64; 2], omega: f64) -> Obstacle {
    Obstacle {
        shape: Shape::Circle { center, radius },
        velocity,
        angular_velocity: omega,
    }
}

/// Sorted cut links `(i, j, α, δ)` of every obstacle.
fn links(l: &Lattice) -> Vec<(usize, usize, usize, usize, f64)> {
    let mut v = Vec::new();
    for k in 0..l.obstacles().len() {
        v.extend(l.cut_links_of(k).map(|(i, j, a, d)| (k, i, j, a, d)));
    }
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v
}

#[test]
fn incremental_update_matches_a_fresh_rasterisation() {
    let cfg = LatticeConfig::periodic(48, 40, 0.8);
    let mut l = Lattice::new(cfg.clone()).unwrap();
    // three disks, two of them crossing periodic sides during the run, close enough to
    // change each other's links
    let bodies = [
        disk([10.3, 20.2], 4.3, [0.11, 0.03], 0.0),
        disk([20.1, 21.7], 3.1, [-0.07, 0.05], 0.01),
        disk([40.0, 5.5], 5.2, [0.13, -0.09], 0.0),
    ];
    for b in &bodies {
        l.add_obstacle(b.clone()).unwrap();
    }
    for _ in 0..180 {
        l.step().unwrap();
    }
    let mut fresh = Lattice::new(cfg).unwrap();
    for ob in l.obstacles() {
        fresh.add_obstacle(ob.clone()).unwrap();
    }
    for j in 0..40 {
        for i in 0..48 {
            assert_eq!(l.owner(i, j), fresh.owner(i, j), "node ({i}, {j})");
        }
    }
    let (a, b) = (links(&l), links(&fresh));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.0, x.1, x.2, x.3), (y.0, y.1, y.2, y.3));
        assert!((x.4 - y.4).abs() < 1e-12, "{x:?} vs {y:?}");
    }
    // the centres stay in the first period
    for ob in l.obstacles() {
        let c = ob.shape.center();
        assert!((0.0..48.0).contains(&c[0]) && (0.0..40.0).contains(&c[1]));
    }
}

#[test]
fn fluid_and_moving_bodies_exchange_momentum_exactly() {
    // Bodies driven at fixed velocities through a closed periodic box: per step the fluid
    // loses what the momentum exchange on cut links and the covered/uncovered nodes give
    // the bodies.
    for collision in [Collision::Bgk, Collision::trt()] {
        let mut cfg = LatticeConfig::periodic(40, 32, 0.7);
        cfg.collision = collision;
        let mut l = Lattice::new(cfg).unwrap();
        l.set_obstacle_motion_mode(ObstacleMotion::External);
        let mut b = [
            disk([12.2, 15.1], 4.4, [0.08, 0.02], 0.015),
            disk([30.4, 8.3], 3.3, [-0.05, 0.06], -0.02),
        ];
        for o in &b {
            l.add_obstacle(o.clone()).unwrap();
        }
        let mut worst: f64 = 0.0;
        let mut through_nodes: f64 = 0.0;
        for _ in 0..200 {
            let before = l.momentum();
            let mut gained = [0.0; 2];
            for (k, o) in b.iter_mut().enumerate() {
                let c = o.shape.center();
                let v = o.velocity;
                o.shape = Shape::Circle {
                    center: [c[0] + v[0], c[1] + v[1]],
                    radius: match o.shape {
                        Shape::Circle { radius, .. } => radius,
                        _ => unreachable!(),
                    },
                };
                l.place_obstacle(k, o.shape.center(), 0.0, v, o.angular_velocity);
            }
            l.update_obstacles().unwrap();
            for k in 0..2 {
                let e = l.node_exchange(k);
                through_nodes += e[0].abs() + e[1].abs();
                gained[0] += e[0];
                gained[1] += e[1];
            }
            l.step().unwrap();
            for k in 0..2 {
                let f = l.force(k);
                gained[0] += f[0];
                gained[1] += f[1];
            }
            let after = l.momentum();
            for a in 0..2 {
                worst = worst.max((after[a] - before[a] + gained[a]).abs());
            }
        }
        assert!(worst < 1e-12, "{collision:?}: momentum defect {worst:e}");
        // the covered and uncovered nodes carry far more than round-off: without them the
        // balance would fail
        assert!(through_nodes > 1e-2, "{through_nodes}");
    }
}

#[test]
fn a_source_adds_its_mass_and_no_momentum() {
    let mut l = Lattice::new(LatticeConfig::periodic(24, 24, 0.9)).unwrap();
    let s = l
        .add_source(&[(11, 11), (12, 11), (11, 12), (12, 12)])
        .unwrap();
    let m0 = l.mass();
    for n in 0..100 {
        l.set_source_rate(s, 1e-4 * (n as f64 / 50.0).min(1.0))
            .unwrap();
        l.step().unwrap();
    }
    let added = l.mass() - m0;
    assert!(added > 0.0);
    assert!((added - l.injected_mass()).abs() < 1e-12 * l.mass());
    let p = l.momentum();
    assert!(p[0].abs() < 1e-14 && p[1].abs() < 1e-14, "{p:?}");
    assert!(l.source_density(s) > 1.0);
    assert!(l.add_source(&[]).is_err());
    assert!(l.add_source(&[(24, 0)]).is_err());
    assert!(l.set_source_rate(s, f64::NAN).is_err());
}

#[test]
fn a_body_partly_covered_by_another_feels_no_ambient_pressure() {
    // A disk half buried in a box (a particle touching others in a rock): in fluid at
    // rest only gauge pressure loads it, so nothing; with absolute pressure c_s² ρ₀ on its
    // wetted half it would be pushed by about c_s² · 2R = 2.7 (lattice units).
    let mut l = Lattice::new(LatticeConfig::periodic(40, 40, 0.8)).unwrap();
    l.add_obstacle(Obstacle {
        shape: Shape::aligned_box([5.0, 5.0], [20.3, 35.0]),
        velocity: [0.0, 0.0],
        angular_velocity: 0.0,
    })
    .unwrap();
    let d = l
        .add_obstacle(disk([20.1, 19.7], 4.1, [0.0, 0.0], 0.0))
        .unwrap();
    for _ in 0..20 {
        l.step().unwrap();
    }
    let f = l.force(d);
    assert!(l.cut_links_of(d).count() > 10);
    assert!(f.iter().all(|v| v.abs() < 1e-12), "{f:?}");
}
