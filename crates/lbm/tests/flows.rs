//! Flows with closed-form or published solutions, on small lattices.
//!
//! * AA streaming against the two-array push kernel: identical to round-off.
//! * Poiseuille between halfway walls (body force): TRT with `Λ = 3/16` and BGK at
//!   `τ = ½ + √3/4` (also `Λ = 3/16`) give the exact parabola; BGK elsewhere is the exact
//!   parabola plus a uniform slip that scales with `16Λ − 3` (Ginzburg & d'Humières 2003).
//! * Plane Couette between walls that lie between nodes (box obstacles, Mora et al. (2015)
//!   eq. 7): the linear profile to 1e-6.
//! * Taylor–Green decay: the kinematic viscosity within 1 %.
//! * A disk and a box at rest in fluid at rest: force and torque zero to 1e-12.
//! * Square array of cylinders (Stokes flow): `F/(μU)` against Sangani & Acrivos (1982),
//!   Table 1; momentum exchange against the body force in steady state.
//! * Galilean invariance: a disk moving through fluid at rest against fluid streaming past
//!   the disk at rest.

use porofrac_lbm::d2q9::{C, Q, feq};
use porofrac_lbm::kernel::{Grid, Physics, push_step_periodic};
use porofrac_lbm::{
    Collision, Lattice, LatticeConfig, MomentumExchange, Obstacle, Shape, SideKind,
};
use std::f64::consts::PI;

fn channel(ny: usize, tau: f64, collision: Collision, accel: f64) -> Lattice {
    let mut cfg = LatticeConfig::periodic(4, ny, tau);
    cfg.collision = collision;
    cfg.periodic = [true, false];
    cfg.sides = [SideKind::Wall; 4];
    cfg.accel = [accel, 0.0];
    Lattice::new(cfg).unwrap()
}

fn run_to_steady(l: &mut Lattice, probe: (usize, usize), tol: f64, max: usize) {
    let mut last = f64::MAX;
    for n in 0..max {
        l.step().unwrap();
        if n % 200 == 0 {
            let u = l.moments(probe.0, probe.1).1[0];
            if (u - last).abs() <= tol * u.abs().max(1e-30) {
                return;
            }
            last = u;
        }
    }
    panic!("no steady state in {max} steps");
}

#[test]
fn aa_matches_two_array_push() {
    let n = 24;
    let mut cfg = LatticeConfig::periodic(n, n, 0.7);
    cfg.accel = [1e-5, -2e-5];
    let init = |p: [f64; 2]| {
        let k = 2.0 * PI / n as f64;
        (
            1.0 + 0.01 * (k * p[0]).cos(),
            [0.05 * (k * p[1]).sin(), 0.02 * (k * p[0]).sin()],
        )
    };
    let mut lat = Lattice::new(cfg.clone()).unwrap();
    lat.init(init);
    let g = Grid { nx: n, ny: n };
    let mut src = vec![0.0; Q * g.np()];
    for j in 0..n {
        for i in 0..n {
            for q in 0..Q {
                src[q * g.np() + g.node(i as isize, j as isize)] = lat.population(i, j, q);
            }
        }
    }
    let mut dst = src.clone();
    let phys = Physics {
        rates: lat.rates(),
        accel: cfg.accel,
    };
    for _ in 0..7 {
        lat.step().unwrap();
        push_step_periodic(&src, &mut dst, g, phys);
        std::mem::swap(&mut src, &mut dst);
    }
    for j in 0..n {
        for i in 0..n {
            for q in 0..Q {
                let a = lat.population(i, j, q);
                let b = src[q * g.np() + g.node(i as isize, j as isize)];
                assert!((a - b).abs() < 1e-15, "({i},{j}) q={q}: {a} vs {b}");
            }
        }
    }
}

/// Largest deviation of the profile from `a/(2ν) y (H − y) + slip` and the mean slip.
fn poiseuille_error(l: &Lattice, accel: f64, nu: f64) -> (f64, f64) {
    let ny = l.size().1;
    let h = ny as f64;
    let mut dev = Vec::new();
    for j in 0..ny {
        let y = j as f64 + 0.5;
        let exact = accel / (2.0 * nu) * y * (h - y);
        dev.push(l.moments(1, j).1[0] - exact);
    }
    let slip = dev.iter().sum::<f64>() / ny as f64;
    let spread = dev.iter().map(|d| (d - slip).abs()).fold(0.0, f64::max);
    (slip, spread)
}

#[test]
fn poiseuille_trt_magic_is_exact_and_bgk_slips_with_lambda() {
    let ny = 16;
    let accel = 1e-6;
    // TRT, Λ = 3/16, at two relaxation times: the exact parabola.
    for tau in [0.6, 1.4] {
        let mut l = channel(ny, tau, Collision::trt(), accel);
        run_to_steady(&mut l, (1, ny / 2), 1e-12, 200_000);
        let nu = (tau - 0.5) / 3.0;
        let umax = accel / (8.0 * nu) * (ny * ny) as f64;
        let (slip, spread) = poiseuille_error(&l, accel, nu);
        assert!(
            slip.abs() < 1e-8 * umax && spread < 1e-8 * umax,
            "TRT tau={tau}: slip {slip}, spread {spread}"
        );
    }
    // BGK: Λ = (τ − ½)²; exact at Λ = 3/16, otherwise a uniform slip ∝ (16Λ − 3) a/ν.
    let mut ratios = Vec::new();
    for tau in [0.5 + 3f64.sqrt() / 4.0, 0.7, 1.0, 1.5] {
        let mut l = channel(ny, tau, Collision::Bgk, accel);
        run_to_steady(&mut l, (1, ny / 2), 1e-12, 200_000);
        let nu = (tau - 0.5) / 3.0;
        let umax = accel / (8.0 * nu) * (ny * ny) as f64;
        let (slip, spread) = poiseuille_error(&l, accel, nu);
        assert!(
            spread < 1e-8 * umax,
            "BGK tau={tau}: profile not a shifted parabola ({spread})"
        );
        let lambda = (tau - 0.5) * (tau - 0.5);
        let scale = (16.0 * lambda - 3.0) * accel / nu;
        if scale.abs() < 1e-12 {
            assert!(slip.abs() < 1e-8 * umax, "BGK at Λ = 3/16: slip {slip}");
        } else {
            ratios.push(slip / scale);
        }
    }
    // The same constant for every τ: u = a/(2ν) [y (H − y) + (16Λ − 3)/12], the TRT
    // bounce-back solution, i.e. slip = (16Λ − 3)/24 · a/ν.
    for r in &ratios {
        assert!(
            (r - 1.0 / 24.0).abs() < 1e-6,
            "slip/((16Λ−3)a/ν) = {r}, ratios {ratios:?}"
        );
    }
}

#[test]
fn couette_between_off_node_walls_is_linear() {
    let (nx, ny) = (4, 14);
    let u_top = 0.02;
    let (y0, y1) = (1.3, 12.6);
    for collision in [Collision::Bgk, Collision::trt()] {
        let mut cfg = LatticeConfig::periodic(nx, ny, 0.8);
        cfg.collision = collision;
        let mut l = Lattice::new(cfg).unwrap();
        let wide = 4.0 * nx as f64;
        l.add_obstacle(Obstacle {
            shape: Shape::aligned_box([-wide, 0.0], [wide, y0]),
            velocity: [0.0, 0.0],
            angular_velocity: 0.0,
        })
        .unwrap();
        l.add_obstacle(Obstacle {
            shape: Shape::aligned_box([-wide, y1], [wide, ny as f64]),
            velocity: [u_top, 0.0],
            angular_velocity: 0.0,
        })
        .unwrap();
        run_to_steady(&mut l, (1, ny / 2), 1e-12, 200_000);
        for j in 0..ny {
            let y = j as f64 + 0.5;
            if y <= y0 || y >= y1 {
                continue;
            }
            let exact = u_top * (y - y0) / (y1 - y0);
            let (_, u) = l.moments(2, j);
            assert!(
                (u[0] - exact).abs() < 1e-6 * u_top,
                "{collision:?} y={y}: {} vs {exact}",
                u[0]
            );
            assert!(u[1].abs() < 1e-12);
        }
    }
}

#[test]
fn taylor_green_decay_gives_the_viscosity() {
    let n = 48;
    let tau = 0.8;
    let nu = (tau - 0.5) / 3.0;
    let k = 2.0 * PI / n as f64;
    let u0 = 0.02;
    let mut l = Lattice::new(LatticeConfig::periodic(n, n, tau)).unwrap();
    l.init(|p| {
        let (x, y) = (k * p[0], k * p[1]);
        let pr = -0.25 * u0 * u0 * ((2.0 * x).cos() + (2.0 * y).cos());
        (
            1.0 + 3.0 * pr,
            [u0 * x.cos() * y.sin(), -u0 * x.sin() * y.cos()],
        )
    });
    let energy = |l: &Lattice| {
        let mut e = 0.0;
        for j in 0..n {
            for i in 0..n {
                let (_, u) = l.moments(i, j);
                e += u[0] * u[0] + u[1] * u[1];
            }
        }
        e
    };
    for _ in 0..50 {
        l.step().unwrap();
    }
    let e0 = energy(&l);
    let steps = 400;
    for _ in 0..steps {
        l.step().unwrap();
    }
    let e1 = energy(&l);
    // E ∝ exp(−4 ν k² t)
    let nu_measured = (e0 / e1).ln() / (4.0 * k * k * steps as f64);
    assert!(
        (nu_measured / nu - 1.0).abs() < 0.01,
        "ν = {nu_measured} vs {nu}"
    );
}

#[test]
fn bodies_at_rest_in_fluid_at_rest_feel_no_force() {
    for collision in [Collision::Bgk, Collision::trt()] {
        let mut cfg = LatticeConfig::periodic(40, 36, 0.9);
        cfg.collision = collision;
        let mut l = Lattice::new(cfg).unwrap();
        let disk = l
            .add_obstacle(Obstacle {
                shape: Shape::Circle {
                    center: [12.31, 17.77],
                    radius: 6.4,
                },
                velocity: [0.0, 0.0],
                angular_velocity: 0.0,
            })
            .unwrap();
        let bx = l
            .add_obstacle(Obstacle {
                shape: Shape::Box {
                    center: [29.1, 18.4],
                    half: [4.3, 7.7],
                    angle: 0.37,
                },
                velocity: [0.0, 0.0],
                angular_velocity: 0.0,
            })
            .unwrap();
        for _ in 0..100 {
            l.step().unwrap();
            for k in [disk, bx] {
                let f = l.force(k);
                assert!(
                    f.iter().all(|v| v.abs() < 1e-12),
                    "{collision:?} body {k}: {f:?}"
                );
            }
        }
    }
}

#[test]
fn sangani_acrivos_formula_matches_their_table() {
    // F/(4πμU) = 1/(−½ ln c − 0.738 + c − 0.887 c² + 2.038 c³), square array, against
    // Table 1 of Sangani & Acrivos (1982): c = 0.05 → 15.56, c = 0.1 → 24.83.
    for (c, table) in [(0.05, 15.56), (0.10, 24.83)] {
        let k = sangani_acrivos(c);
        assert!((k / table - 1.0).abs() < 2e-3, "c = {c}: {k} vs {table}");
    }
}

fn sangani_acrivos(c: f64) -> f64 {
    4.0 * PI / (-0.5 * c.ln() - 0.738 + c - 0.887 * c * c + 2.038 * c * c * c)
}

#[test]
fn drag_in_a_periodic_array_of_cylinders() {
    let n = 48;
    let c = 0.1;
    let radius = n as f64 * (c / PI).sqrt();
    let tau = 1.0;
    let nu = (tau - 0.5) / 3.0;
    let accel = 1e-6;
    let mut cfg = LatticeConfig::periodic(n, n, tau);
    cfg.collision = Collision::trt();
    cfg.accel = [accel, 0.0];
    let mut l = Lattice::new(cfg).unwrap();
    let disk = l
        .add_obstacle(Obstacle {
            shape: Shape::Circle {
                center: [n as f64 / 2.0, n as f64 / 2.0],
                radius,
            },
            velocity: [0.0, 0.0],
            angular_velocity: 0.0,
        })
        .unwrap();
    run_to_steady(&mut l, (0, 0), 1e-9, 400_000);
    let mut usum = 0.0;
    for j in 0..n {
        for i in 0..n {
            if !l.is_solid(i, j) {
                usum += l.moments(i, j).1[0];
            }
        }
    }
    let area = (n * n) as f64;
    let u_superficial = usum / area;
    // Steady state: the momentum exchange balances the body force on the fluid.
    let f = l.force(disk);
    let body = accel * l.mass();
    assert!(
        (f[0] / body - 1.0).abs() < 1e-5,
        "force {} vs body force {body}",
        f[0]
    );
    assert!(f[1].abs() < 1e-9 * body);
    // Sangani & Acrivos: F is the pressure-gradient force per cell, f·L² (see the docs).
    let k = accel * area / (nu * u_superficial);
    let reference = 24.83;
    assert!(
        (k / reference - 1.0).abs() < 0.02,
        "F/(μU) = {k} vs {reference}"
    );
}

#[test]
fn drag_is_galilean_invariant() {
    let (nx, ny) = (64, 40);
    let u = 0.04;
    let center = [20.3, 20.1];
    let radius = 5.2;
    let mut forces = Vec::new();
    for exchange in [
        MomentumExchange::Standard,
        MomentumExchange::GalileanInvariant,
    ] {
        let mut cfg = LatticeConfig::periodic(nx, ny, 0.8);
        cfg.collision = Collision::trt();
        cfg.momentum_exchange = exchange;
        // fluid streaming past a disk at rest
        let mut a = Lattice::new(cfg.clone()).unwrap();
        let da = a
            .add_obstacle(Obstacle {
                shape: Shape::Circle { center, radius },
                velocity: [0.0, 0.0],
                angular_velocity: 0.0,
            })
            .unwrap();
        a.init(|_| (1.0, [u, 0.0]));
        // a disk moving through fluid at rest
        let mut b = Lattice::new(cfg).unwrap();
        let db = b
            .add_obstacle(Obstacle {
                shape: Shape::Circle { center, radius },
                velocity: [-u, 0.0],
                angular_velocity: 0.0,
            })
            .unwrap();
        let (mut fa, mut fb) = (0.0, 0.0);
        let steps = 300;
        for s in 0..steps {
            a.step().unwrap();
            b.step().unwrap();
            if s >= steps - 100 {
                fa += a.force(da)[0];
                fb += b.force(db)[0];
            }
        }
        forces.push((fa / 100.0, fb / 100.0));
    }
    let (sa, sb) = forces[0];
    let (ga, gb) = forces[1];
    eprintln!("standard: rest {sa:.6e} moving {sb:.6e}; GI: rest {ga:.6e} moving {gb:.6e}");
    assert!((sb / sa - 1.0).abs() < 1e-3, "standard: {sa} vs {sb}");
    assert!(
        (gb / ga - 1.0).abs() < 1e-3,
        "Galilean invariant: {ga} vs {gb}"
    );
}

#[test]
fn bad_input_is_an_error() {
    assert!(Lattice::new(LatticeConfig::periodic(8, 8, 0.5)).is_err());
    let outside = Obstacle {
        shape: Shape::Circle {
            center: [1.0, 8.0],
            radius: 2.0,
        },
        velocity: [0.0, 0.0],
        angular_velocity: 0.0,
    };
    // Across a wall it is outside; across a periodic side it wraps.
    let mut walls = LatticeConfig::periodic(16, 16, 0.8);
    walls.periodic = [false, true];
    let mut w = Lattice::new(walls).unwrap();
    assert_eq!(
        w.add_obstacle(outside.clone()),
        Err(porofrac_lbm::LbmError::Outside { obstacle: 0 })
    );
    let mut l = Lattice::new(LatticeConfig::periodic(16, 16, 0.8)).unwrap();
    let wrapped = l.add_obstacle(outside).unwrap();
    assert!(l.is_solid(15, 8) && l.is_solid(0, 8) && !l.is_solid(3, 8));
    l.step().unwrap();
    // at rest in fluid at rest: no force, also across the periodic side
    assert!(l.force(wrapped)[0].abs() < 1e-12 && l.force(wrapped)[1].abs() < 1e-12);
    let k = l
        .add_obstacle(Obstacle {
            shape: Shape::Circle {
                center: [8.0, 8.0],
                radius: 2.0,
            },
            velocity: [1.2, 0.0],
            angular_velocity: 0.0,
        })
        .unwrap();
    assert!(l.step().is_err());
    l.set_obstacle_motion(k, [0.1, 0.0], 0.0);
    assert!(l.step().is_ok());
    let _ = (C, feq(0, 1.0, [0.0, 0.0]));
}
