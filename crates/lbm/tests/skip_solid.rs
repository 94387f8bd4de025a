//! A step that skips stretches of solid nodes (`crate::runs`: every solid node, or the
//! stretches longer than a gap) computes the fluid bit for bit as one that visits every
//! node, with moving obstacles:
//!
//! * every population of every fluid node, the owner of every node, the force, torque and
//!   node exchange of every obstacle, the mass and the injected mass are equal to the bit
//!   after every step, for obstacles the lattice moves (crossing a periodic side, rotating
//!   boxes, a packed cluster whose rows are cut into short runs) and obstacles a caller
//!   places (as coupled particles are), with a mass source, inlet and outlet, TRT with a
//!   body force, in `f64` and `f32` storage;
//! * the solid nodes' storage is never read: filling it with NaN between steps changes
//!   none of these bits.

use porofrac_lbm::kernel::{Grid, Layout};
use porofrac_lbm::{
    Collision, Lattice, LatticeConfig, Obstacle, ObstacleMotion, Precision, Shape, Side, SideKind,
};

fn disk(center: [f64; 2], radius: f64, velocity: [f64; 2], omega: f64) -> Obstacle {
    Obstacle {
        shape: Shape::Circle { center, radius },
        velocity,
        angular_velocity: omega,
    }
}

/// Everything of `a` and `b` that a caller can read is equal to the bit.
fn assert_same(a: &Lattice, b: &Lattice, step: usize) {
    let (nx, ny) = a.size();
    for j in 0..ny {
        for i in 0..nx {
            assert_eq!(a.owner(i, j), b.owner(i, j), "step {step}, node ({i}, {j})");
            if a.is_solid(i, j) {
                continue;
            }
            for q in 0..9 {
                let (x, y) = (a.population(i, j, q), b.population(i, j, q));
                assert_eq!(
                    x.to_bits(),
                    y.to_bits(),
                    "step {step}, node ({i}, {j}), q {q}: {x} vs {y}"
                );
            }
        }
    }
    for k in 0..a.obstacles().len() {
        for (x, y) in [
            (a.force(k), b.force(k)),
            (a.node_exchange(k), b.node_exchange(k)),
        ] {
            assert_eq!(
                x.map(f64::to_bits),
                y.map(f64::to_bits),
                "step {step}, obstacle {k}"
            );
        }
    }
    assert_eq!(a.mass().to_bits(), b.mass().to_bits(), "step {step}");
    assert_eq!(a.injected_mass().to_bits(), b.injected_mass().to_bits());
}

/// Fill every population of every solid node with NaN.
fn poison_solid(l: &mut Lattice) {
    let (nx, ny) = l.size();
    let g = Grid { nx, ny };
    let mut s = l.raw_state();
    let layout = if s.swapped {
        Layout::Swapped
    } else {
        Layout::Natural
    };
    for j in 0..ny {
        for i in 0..nx {
            if l.is_solid(i, j) {
                let n = g.node(i as isize, j as isize);
                for q in 0..9 {
                    s.populations[g.loc(layout, n, q)] = f64::NAN;
                }
            }
        }
    }
    l.restore_raw_state(s).unwrap();
}

/// Step `runs` (solid stretches of `gap` nodes or more skipped, solid storage poisoned
/// every 37 steps), `clean` (the same, not poisoned) and `every` (every node) together and compare them after every step;
/// `between` moves the obstacles before a step (placed by the caller). Returns the
/// nodes the skipping lattice visited in its last step and its fluid nodes then.
fn run(
    every: Lattice,
    gap: usize,
    steps: usize,
    mut between: impl FnMut(&mut Lattice, usize),
) -> (usize, usize) {
    let mut every = every;
    every.set_skip_solid(None);
    let mut runs = every.clone();
    runs.set_skip_solid(Some(gap));
    let mut clean = runs.clone();
    let mut visited = (0, 0);
    for n in 0..steps {
        if n % 37 == 5 {
            poison_solid(&mut runs);
        }
        for l in [&mut every, &mut runs, &mut clean] {
            between(l, n);
        }
        let fluid = clean.fluid_nodes();
        for l in [&mut every, &mut runs, &mut clean] {
            l.step().unwrap();
        }
        visited = (clean.visited_nodes(), fluid);
        assert_eq!(every.visited_nodes(), every.size().0 * every.size().1);
        assert_same(&runs, &every, n);
        assert_same(&clean, &every, n);
    }
    visited
}

/// A periodic channel with a body force, disks and boxes the lattice moves, and a packed
/// cluster of disks.
fn moving_lattice(precision: Precision) -> Lattice {
    let mut cfg = LatticeConfig::periodic(96, 56, 0.7);
    cfg.periodic = [true, false];
    cfg.accel = [2e-6, 0.0];
    cfg.collision = Collision::trt();
    let mut l = Lattice::new(cfg).unwrap();
    l.set_precision(precision);
    l.init(|p| (1.0, [0.02 * (p[1] / 56.0), 0.0]));
    for ob in [
        disk([90.3, 20.2], 6.3, [0.11, 0.03], 0.0),
        disk([30.1, 31.7], 5.1, [-0.07, 0.05], 0.01),
        Obstacle {
            shape: Shape::Box {
                center: [60.0, 12.0],
                half: [7.0, 3.0],
                angle: 0.2,
            },
            velocity: [0.02, 0.01],
            angular_velocity: 0.004,
        },
    ] {
        l.add_obstacle(ob).unwrap();
    }
    // a packed cluster: rows cut into short runs, stepped whole
    for a in 0..5 {
        for b in 0..3 {
            let c = [8.0 + 3.1 * a as f64, 38.0 + 3.3 * b as f64];
            l.add_obstacle(disk(c, 1.45, [0.0, -0.004], 0.0)).unwrap();
        }
    }
    l
}

#[test]
fn lattice_moved_obstacles_give_the_same_fluid_bits() {
    for precision in [Precision::Double, Precision::Single] {
        // every solid node skipped
        let (visited, fluid) = run(moving_lattice(precision), 1, 240, |_, _| {});
        assert_eq!(visited, fluid);
        // solid stretches of 1 to 3 nodes stepped with the mask, longer ones skipped
        let (visited, fluid) = run(moving_lattice(precision), 4, 240, |_, _| {});
        assert!(visited > fluid && visited < 96 * 56, "{visited} vs {fluid}");
    }
}

#[test]
fn placed_obstacles_with_a_source_inlet_and_outlet_give_the_same_fluid_bits() {
    let mut cfg = LatticeConfig::periodic(80, 48, 0.8);
    cfg.periodic = [false, false];
    cfg.sides = [
        SideKind::Velocity,
        SideKind::Pressure { density: 1.0 },
        SideKind::Wall,
        SideKind::Wall,
    ];
    let mut l = Lattice::new(cfg).unwrap();
    l.set_side_velocity(Side::XMin, |p| [0.03 * p[1] * (48.0 - p[1]) / 576.0, 0.0]);
    let centres = [[25.0, 20.0], [45.0, 28.0], [60.0, 16.0], [36.0, 13.0]];
    for (k, c) in centres.iter().enumerate() {
        l.add_obstacle(disk(*c, 4.0 + k as f64, [0.0, 0.0], 0.0))
            .unwrap();
    }
    l.set_obstacle_motion_mode(ObstacleMotion::External);
    let s = l
        .add_source(&[(10, 24), (11, 24), (10, 25), (11, 25)])
        .unwrap();
    l.set_source_rate(s, 2e-4).unwrap();
    // the disks oscillate and turn as coupled particles would, placed before every step
    let (visited, fluid) = run(l, 1, 300, |l, n| {
        let t = n as f64;
        for (k, c) in centres.iter().enumerate() {
            let w = 0.05 + 0.01 * k as f64;
            let a = 2.5;
            let x = [c[0] + a * (w * t).sin(), c[1] + a * (0.7 * w * t).cos()];
            let v = [a * w * (w * t).cos(), -0.7 * a * w * (0.7 * w * t).sin()];
            l.place_obstacle(k, x, 0.0, v, 0.01 * (w * t).cos());
        }
        l.update_obstacles().unwrap();
    });
    assert_eq!(visited, fluid);
}
