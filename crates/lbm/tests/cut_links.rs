//! The obstacle rules of the cut links (`crate::boundary`) as a caller can check them, the
//! reference for any change to how they load and store their populations (an order of
//! their own, a pass fused into the kernel):
//!
//! * after every step, every unknown `L(x_f, ᾱ)` of every cut link and every body's force
//!   and torque are those of the rule evaluated from the populations it read (what crossed
//!   into the body is left in its solid node; neither `L(x_f, α)` nor `L(x_f2, ᾱ)` is an
//!   unknown): interpolated bounce-back of a moving wall, plain bounce-back where `x_f2`
//!   is solid, the mass correction per body, standard and Galilean-invariant momentum
//!   exchange, while the bodies are placed, moved and their links rebuilt;
//! * the same bodies added in the opposite order give every fluid population, force and
//!   torque to the bit, in `f64` and `f32` storage (each body's rule depends on its own
//!   links only, whatever order the bodies are visited in).

use porofrac_lbm::d2q9::{C, OPP, W, cf};
use porofrac_lbm::{
    Lattice, LatticeConfig, MomentumExchange, Obstacle, ObstacleMotion, Precision, Shape,
};

fn disk(center: [f64; 2], radius: f64, velocity: [f64; 2], omega: f64) -> Obstacle {
    Obstacle {
        shape: Shape::Circle { center, radius },
        velocity,
        angular_velocity: omega,
    }
}

/// Disks in a periodic box, kept two nodes from its sides (no periodic copy writes into a
/// cut link's node), some one node apart (their links have no `x_f2`).
const DISKS: [([f64; 2], f64); 7] = [
    ([14.3, 12.1], 5.2),
    ([25.9, 12.6], 5.0),
    ([40.2, 30.4], 7.3),
    ([20.7, 31.0], 3.4),
    ([28.4, 31.2], 3.6),
    ([52.0, 12.5], 4.1),
    ([52.4, 37.9], 2.3),
];

/// The rule of `crate::boundary` for every cut link of obstacle `k`, from the populations
/// the last step's rules read (what crossed into the body is left in its solid node, and
/// neither `L(x_f, α)` nor `L(x_f2, ᾱ)` is an unknown): the unknowns in link order and the
/// force and torque.
fn rule(l: &Lattice, k: usize, gi: bool) -> (Vec<f64>, [f64; 3]) {
    let ob = &l.obstacles()[k];
    let c = ob.shape.center();
    let (nx, ny) = l.size();
    let mut backs = Vec::new();
    let mut intos = Vec::new();
    let mut walls = Vec::new();
    let (mut gained, mut weights) = (0.0, 0.0);
    for (i, j, a, d) in l.cut_links_of(k) {
        let ca = cf(a);
        let p = [i as f64 + 0.5, j as f64 + 0.5];
        let xw = [p[0] + d * ca[0], p[1] + d * ca[1]];
        let uw = ob.velocity_at(xw);
        let wall = 6.0 * W[a] * (ca[0] * uw[0] + ca[1] * uw[1]);
        let (bi, bj) = (i as isize + C[a][0] as isize, j as isize + C[a][1] as isize);
        let into = l.population(bi as usize, bj as usize, a);
        let (fi, fj) = (i as isize - C[a][0] as isize, j as isize - C[a][1] as isize);
        let f2_fluid = fi >= 0
            && fj >= 0
            && (fi as usize) < nx
            && (fj as usize) < ny
            && !l.is_solid(fi as usize, fj as usize);
        let back = if f2_fluid {
            ((1.0 - d) * l.population(i, j, a)
                + d * into
                + d * l.population(fi as usize, fj as usize, OPP[a])
                - wall)
                / (1.0 + d)
        } else {
            into - wall
        };
        gained += back - into;
        weights += W[a];
        backs.push(back);
        intos.push(into);
        walls.push((a, uw, xw));
    }
    let per_weight = gained / weights;
    let mut f = [0.0; 3];
    for ((back, &into), &(a, uw, xw)) in backs.iter_mut().zip(&intos).zip(&walls) {
        *back -= per_weight * W[a];
        let ca = cf(a);
        let amb = 2.0 * W[a];
        let df = if gi {
            [
                (ca[0] - uw[0]) * into - (-ca[0] - uw[0]) * *back - amb * ca[0],
                (ca[1] - uw[1]) * into - (-ca[1] - uw[1]) * *back - amb * ca[1],
            ]
        } else {
            [ca[0] * (into + *back - amb), ca[1] * (into + *back - amb)]
        };
        let r = [xw[0] - c[0], xw[1] - c[1]];
        f[0] += df[0];
        f[1] += df[1];
        f[2] += r[0] * df[1] - r[1] * df[0];
    }
    (backs, f)
}

#[test]
fn every_unknown_and_force_is_the_rule_of_its_body() {
    for exchange in [
        MomentumExchange::Standard,
        MomentumExchange::GalileanInvariant,
    ] {
        let mut cfg = LatticeConfig::periodic(64, 48, 0.7);
        cfg.momentum_exchange = exchange;
        let mut l = Lattice::new(cfg).unwrap();
        l.init(|p| {
            let y = p[1] / 48.0;
            (
                1.0 + 0.01 * y,
                [0.03 * y * (1.0 - y), 0.004 * (p[0] / 9.0).sin()],
            )
        });
        for (c, r) in DISKS {
            l.add_obstacle(disk(c, r, [0.0, 0.0], 0.0)).unwrap();
        }
        l.set_obstacle_motion_mode(ObstacleMotion::External);
        let mut checked = 0;
        for n in 0..60 {
            // placed as coupled particles are: moving walls, nodes covered and uncovered,
            // links rebuilt
            let t = n as f64;
            for (k, (c, _)) in DISKS.iter().enumerate() {
                let w = 0.07 + 0.013 * k as f64;
                let x = [c[0] + 0.8 * (w * t).sin(), c[1] + 0.6 * (w * t).cos()];
                let v = [0.8 * w * (w * t).cos(), -0.6 * w * (w * t).sin()];
                l.place_obstacle(k, x, 0.0, v, 0.02 * (w * t).cos());
            }
            l.update_obstacles().unwrap();
            l.step().unwrap();
            for k in 0..DISKS.len() {
                let (backs, force) = rule(&l, k, exchange == MomentumExchange::GalileanInvariant);
                for ((i, j, a, _), back) in l.cut_links_of(k).zip(&backs) {
                    let got = l.population(i, j, OPP[a]);
                    // the same operations in the same order: equal to round-off
                    assert!(
                        (got - back).abs() <= 1e-14,
                        "step {n}, body {k}, link ({i}, {j}, {a}): {got} vs {back}"
                    );
                    checked += 1;
                }
                let got = l.force(k);
                for d in 0..3 {
                    assert!(
                        (got[d] - force[d]).abs() <= 1e-13,
                        "step {n}, body {k}, component {d}: {got:?} vs {force:?}"
                    );
                }
            }
        }
        // about 7 bodies of 25-50 links, 60 steps
        assert!(checked > 10_000, "{checked} links checked");
    }
}

/// The disks moving together (they keep their gaps), turning at their own rates.
fn lattice(precision: Precision, reversed: bool) -> Lattice {
    let mut l = Lattice::new(LatticeConfig::periodic(64, 48, 0.8)).unwrap();
    l.set_precision(precision);
    l.init(|p| (1.0, [0.02 * (p[1] / 48.0), 0.0]));
    let mut order: Vec<usize> = (0..DISKS.len()).collect();
    if reversed {
        order.reverse();
    }
    for k in order {
        let (c, r) = DISKS[k];
        l.add_obstacle(disk(c, r, [0.031, -0.017], 0.002 * k as f64))
            .unwrap();
    }
    l
}

#[test]
fn bodies_in_either_order_give_the_same_bits() {
    for precision in [Precision::Double, Precision::Single] {
        let mut a = lattice(precision, false);
        let mut b = lattice(precision, true);
        let n = DISKS.len();
        let (nx, ny) = a.size();
        for step in 0..150 {
            a.step().unwrap();
            b.step().unwrap();
            for k in 0..n {
                assert_eq!(
                    a.force(k).map(f64::to_bits),
                    b.force(n - 1 - k).map(f64::to_bits),
                    "{precision:?}, step {step}, body {k}"
                );
            }
            for j in 0..ny {
                for i in 0..nx {
                    assert_eq!(a.is_solid(i, j), b.is_solid(i, j));
                    if a.is_solid(i, j) {
                        continue;
                    }
                    for q in 0..9 {
                        assert_eq!(
                            a.population(i, j, q).to_bits(),
                            b.population(i, j, q).to_bits(),
                            "{precision:?}, step {step}, node ({i}, {j}), q {q}"
                        );
                    }
                }
            }
        }
        // the disks crossed nodes: links were rebuilt along the way
        let moved = a.obstacles()[0].shape.center()[0] - DISKS[0].0[0];
        assert!(moved > 4.0, "moved {moved}");
    }
}
