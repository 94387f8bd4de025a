//! Obstacles at the edges of the lattice and the storage precision.
//!
//! * A wall block that overhangs the top side (clipped to the lattice) is the same channel
//!   as the block cut at the side: the same numbers to round-off; the Poiseuille parabola of
//!   the channel it leaves, to the second-order error of the interpolated bounce-back
//!   (`2/H²` of the peak velocity; 2.9e-3 and 8.4e-4 measured at `H` = 20 and 20.3), and
//!   the force on it the wall shear `ρ a H L / 2` to 2e-3 (7.5e-4 measured at `H` = 20).
//!   With the wall at `H` = 20.3 the lattice carries the body force of 20 rows of nodes,
//!   not of `H`: the block takes the wall shear less `ρ a (H − 20) L`, to 2e-3 (2.2e-4
//!   measured); this is the momentum exchange of a wall between nodes, not the clipping.
//! * A disk carried across a periodic side: the force on it and the fluid's mass are those
//!   of the same disk carried through the middle of the lattice (the same run shifted by half
//!   a period), step by step, and the momentum of fluid plus disk is conserved at every
//!   step: `P(n+1) − P(n) = −(F + X)`, `F` the momentum exchange on the cut links and `X`
//!   the momentum of the nodes covered and uncovered ([`Lattice::node_exchange`]).
//! * Overlapping obstacles: the one added on top of another reports it
//!   ([`Lattice::contact`]), and a moving one reports the body it runs into.
//! * `f32` storage: one step stores the `f64` step rounded to `f32`; the accuracy cost on
//!   Poiseuille and plane Couette flow at two resolutions (relative L2 errors against the
//!   closed forms, single and double).

use porofrac_lbm::{
    Collision, Lattice, LatticeConfig, LbmError, Obstacle, ObstacleOverhang, Precision, Shape,
    SideKind,
};

fn channel(nx: usize, ny: usize, accel: f64) -> LatticeConfig {
    let mut cfg = LatticeConfig::periodic(nx, ny, 0.8);
    cfg.collision = Collision::trt();
    cfg.periodic = [true, false];
    cfg.sides = [SideKind::Wall; 4];
    cfg.accel = [accel, 0.0];
    cfg
}

fn still(shape: Shape) -> Obstacle {
    Obstacle {
        shape,
        velocity: [0.0, 0.0],
        angular_velocity: 0.0,
    }
}

#[test]
fn a_wall_block_overhanging_the_top_is_a_wall() {
    let (nx, ny, accel) = (4, 24, 1e-6);
    let nu = (0.8 - 0.5) / 3.0;
    for top in [20.0, 20.3] {
        let block = still(Shape::aligned_box([-3.0, top], [9.0, 40.0]));
        let inside = still(Shape::aligned_box([-3.0, top], [9.0, ny as f64]));
        let mut cut = Lattice::new(channel(nx, ny, accel)).unwrap();
        cut.add_obstacle(inside).unwrap();
        // refused by default: a coupled particle may not leave the lattice
        let mut l = Lattice::new(channel(nx, ny, accel)).unwrap();
        assert_eq!(
            l.add_obstacle(block.clone()),
            Err(LbmError::Outside { obstacle: 0 })
        );
        l.set_obstacle_overhang(ObstacleOverhang::Clipped);
        let k = l.add_obstacle(block).unwrap();
        let rows = 20;
        for j in 0..ny {
            let y = j as f64 + 0.5;
            assert_eq!(l.is_solid(0, j), y >= top, "row {j}");
        }
        assert_eq!(l.fluid_nodes(), nx * rows);
        let mut last = f64::MAX;
        for n in 0..400_000 {
            l.step().unwrap();
            cut.step().unwrap();
            if n % 500 == 0 {
                let u = l.moments(1, ny / 2).1[0];
                if (u - last).abs() <= 1e-13 * u.abs() {
                    break;
                }
                last = u;
            }
        }
        let umax = accel / (8.0 * nu) * top * top;
        let mut worst: f64 = 0.0;
        for j in 0..rows {
            let y = j as f64 + 0.5;
            let exact = accel / (2.0 * nu) * y * (top - y);
            worst = worst.max((l.moments(1, j).1[0] - exact).abs());
        }
        // the wall shear ρ a H L / 2, less the body force on the fluid between the last
        // row of nodes and the wall (H − 20 rows), which the lattice does not carry
        let shear = accel * top * nx as f64 / 2.0 - accel * (top - 20.0) * nx as f64;
        let f = l.force(k);
        eprintln!(
            "top {top}: profile error {:.3e} of u_max, force {:.6e} vs wall shear {shear:.6e}",
            worst / umax,
            f[0]
        );
        assert!(
            worst < 2.0 / (top * top) * umax,
            "top {top}: {worst:.3e} vs {umax:.3e}"
        );
        assert!(
            (f[0] / shear - 1.0).abs() < 2e-3,
            "top {top}: force {} vs shear {shear}",
            f[0]
        );
        for j in 0..ny {
            let (a, b) = (l.moments(1, j).1[0], cut.moments(1, j).1[0]);
            assert!((a - b).abs() <= 1e-15 * umax, "row {j}: {a} vs {b}");
        }
        let g = cut.force(0);
        // the torques differ: they are taken about the two blocks' centres
        assert!((0..2).all(|c| (f[c] - g[c]).abs() <= 1e-12 * f[0].abs()));
    }
}

/// Force on the disk, fluid mass and the momentum balance residual per step.
fn carried_disk(x0: f64, steps: usize) -> (Vec<[f64; 3]>, Vec<f64>, f64, f64) {
    let (nx, ny) = (48, 24);
    let mut l = Lattice::new(LatticeConfig::periodic(nx, ny, 0.8)).unwrap();
    let u = 0.04;
    let k = l
        .add_obstacle(Obstacle {
            shape: Shape::Circle {
                center: [x0, 11.7],
                radius: 4.3,
            },
            velocity: [u, 0.01],
            angular_velocity: 0.0,
        })
        .unwrap();
    // the fluid streams along with a shear, so the disk is loaded all the way
    l.init(|p| {
        (
            1.0,
            [
                0.5 * u * (1.0 + (p[1] / ny as f64 * std::f64::consts::TAU).sin()),
                0.0,
            ],
        )
    });
    let (mut forces, mut mass) = (Vec::new(), Vec::new());
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    let mut p0 = l.momentum();
    for _ in 0..steps {
        l.step().unwrap();
        let p1 = l.momentum();
        let (f, x) = (l.force(k), l.node_exchange(k));
        for a in 0..2 {
            worst = worst.max((p1[a] - p0[a] + f[a] + x[a]).abs());
            scale = scale.max(f[a].abs());
        }
        p0 = p1;
        forces.push(f);
        mass.push(l.mass());
    }
    (forces, mass, worst, scale)
}

#[test]
fn a_disk_carried_across_a_periodic_side_keeps_force_and_balances() {
    let steps = 450;
    // centre at 40.3: it reaches the side x = 48 after ~85 steps and is across after ~320
    let (fa, ma, wa, sa) = carried_disk(40.3, steps);
    let (fb, mb, wb, _) = carried_disk(16.3, steps);
    let mut df: f64 = 0.0;
    let mut fmax: f64 = 0.0;
    for (a, b) in fa.iter().zip(&fb) {
        for c in 0..3 {
            df = df.max((a[c] - b[c]).abs());
            fmax = fmax.max(a[c].abs());
        }
    }
    let dm = ma
        .iter()
        .zip(&mb)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "force gap {df:.3e} of {fmax:.3e}, mass gap {dm:.3e}, momentum residual {wa:.3e} / {wb:.3e} of {sa:.3e}"
    );
    assert!(fmax > 1e-4, "the disk is loaded: {fmax}");
    assert!(df < 1e-9 * fmax, "force across the side differs by {df}");
    assert!(dm < 1e-10 * ma[0], "mass across the side differs by {dm}");
    assert!(wa < 1e-12 && wb < 1e-12, "momentum balance {wa} {wb}");
}

#[test]
fn overlapping_obstacles_are_reported() {
    let mut l = Lattice::new(LatticeConfig::periodic(32, 32, 0.8)).unwrap();
    let disk = |c: [f64; 2], v: [f64; 2]| Obstacle {
        shape: Shape::Circle {
            center: c,
            radius: 4.0,
        },
        velocity: v,
        angular_velocity: 0.0,
    };
    let a = l.add_obstacle(disk([8.2, 8.1], [0.0, 0.0])).unwrap();
    let b = l.add_obstacle(disk([14.0, 8.1], [0.0, 0.0])).unwrap();
    assert_eq!((l.contact(a), l.contact(b)), (None, Some(a)));
    let c = l.add_obstacle(disk([8.2, 22.0], [0.0, 0.0])).unwrap();
    let d = l.add_obstacle(disk([20.0, 22.0], [-0.2, 0.0])).unwrap();
    assert_eq!((l.contact(c), l.contact(d)), (None, None));
    let mut met = None;
    for n in 0..40 {
        l.step().unwrap();
        if l.contact(d).is_some() {
            met = Some(n);
            break;
        }
    }
    // the gap of 3.8 closes after 19 steps of 0.2; a node both cover comes a little later
    assert_eq!(l.contact(d), Some(c), "after {met:?} steps");
    assert!(met.unwrap() >= 18, "met after {met:?} steps");
}

#[test]
fn single_precision_stores_the_double_step_rounded() {
    let mut cfg = LatticeConfig::periodic(24, 16, 0.7);
    cfg.accel = [1e-5, 0.0];
    let mut d = Lattice::new(cfg).unwrap();
    d.init(|p| {
        (
            1.0 + 0.01 * (p[0] * 0.3).sin(),
            [0.03 * (p[1] * 0.4).cos(), 0.01],
        )
    });
    let mut s = d.clone();
    // f64 storage again changes nothing, bit for bit
    let before: Vec<f64> = (0..9).map(|q| d.population(3, 5, q)).collect();
    d.set_precision(Precision::Double);
    assert_eq!(d.precision(), Precision::Double);
    assert!((0..9).all(|q| d.population(3, 5, q).to_bits() == before[q].to_bits()));
    s.set_precision(Precision::Single);
    assert_eq!(s.precision(), Precision::Single);
    assert_eq!(2 * s.population_bytes(), d.population_bytes());
    for _ in 0..3 {
        d.step().unwrap();
        s.step().unwrap();
    }
    let mut worst: f64 = 0.0;
    for j in 0..16 {
        for i in 0..24 {
            for q in 0..9 {
                worst = worst.max((d.population(i, j, q) - s.population(i, j, q)).abs());
            }
        }
    }
    // three roundings of f − w (|f − w| ≲ 0.05) to f32: a few 1e-9
    assert!(worst > 0.0 && worst < 2e-8, "single vs double {worst:.3e}");
}

/// Relative L2 error of the Poiseuille profile between halfway walls after `t` diffusive
/// times (TRT, Λ = 3/16: the exact parabola in double).
fn poiseuille_l2(ny: usize, precision: Precision) -> f64 {
    let nu = 0.1;
    let umax = 0.01;
    let h = ny as f64;
    let accel = 8.0 * nu * umax / (h * h);
    let mut l = Lattice::new(channel(4, ny, accel)).unwrap();
    l.set_precision(precision);
    let steps = (6.0 * h * h / nu) as usize;
    for _ in 0..steps {
        l.step().unwrap();
    }
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..ny {
        let y = j as f64 + 0.5;
        let exact = accel / (2.0 * nu) * y * (h - y);
        num += (l.moments(1, j).1[0] - exact).powi(2);
        den += exact * exact;
    }
    (num / den).sqrt()
}

/// Relative L2 error of plane Couette flow between walls between nodes (box obstacles,
/// the top one moving), after six diffusive times.
fn couette_l2(ny: usize, precision: Precision) -> f64 {
    let u_top = 0.02;
    let scale = ny as f64 / 14.0;
    let (y0, y1) = (1.3 * scale, 12.6 * scale);
    let mut l = Lattice::new(LatticeConfig::periodic(4, ny, 0.8)).unwrap();
    l.set_precision(precision);
    l.add_obstacle(still(Shape::aligned_box([-16.0, 0.0], [16.0, y0])))
        .unwrap();
    l.add_obstacle(Obstacle {
        shape: Shape::aligned_box([-16.0, y1], [16.0, ny as f64]),
        velocity: [u_top, 0.0],
        angular_velocity: 0.0,
    })
    .unwrap();
    let nu = 0.1;
    let steps = (6.0 * (y1 - y0).powi(2) / nu) as usize;
    for _ in 0..steps {
        l.step().unwrap();
    }
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..ny {
        let y = j as f64 + 0.5;
        if y <= y0 || y >= y1 {
            continue;
        }
        let exact = u_top * (y - y0) / (y1 - y0);
        num += (l.moments(2, j).1[0] - exact).powi(2);
        den += exact * exact;
    }
    (num / den).sqrt()
}

#[test]
fn the_accuracy_cost_of_single_precision() {
    for (name, f) in [
        ("Poiseuille", poiseuille_l2 as fn(usize, Precision) -> f64),
        ("Couette", couette_l2),
    ] {
        for ny in [14, 28] {
            let d = f(ny, Precision::Double);
            let s = f(ny, Precision::Single);
            eprintln!("{name} ny = {ny}: L2 double {d:.3e}, single {s:.3e}");
            // what f32 storage adds stays far below what a resolution step changes
            assert!(
                s < d + 1e-4,
                "{name} ny = {ny}: single {s:.3e}, double {d:.3e}"
            );
        }
    }
}
