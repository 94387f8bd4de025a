//! The temperature lattice against closed forms and balances.
//!
//! * A sine mode `T = 1 + A sin(kx)` in fluid at rest decays as `exp(−χ k² t)`: `χ` within
//!   1 %; advected by a uniform flow, the same decay (the mode moves with the flow).
//! * A step `T = 1` for `x < L/2`, 0 beyond (periodic, two steps) against
//!   `½ erfc((x − x0)/(2√(χ t)))` summed over the images: within 1 % of the jump.
//! * Heat balance with a heated disk of another diffusivity in a flow, periodic sides:
//!   `Σ T` constant to 1e-12 relative per step; with a flux side and adiabatic sides
//!   `Σ T` grows by exactly `q nx` per step (1e-8 relative per step).
//! * Steady conduction between two fixed temperatures: the linear profile to 1e-10.

use porofrac_lbm::{Lattice, LatticeConfig, Obstacle, Shape, SideKind, Thermal, ThermalSide};
use std::f64::consts::PI;

fn erfc(x: f64) -> f64 {
    // Abramowitz & Stegun 7.1.26 is too coarse (1.5e-7 is fine for 1 % but keep it simple
    // and accurate): continued integration of exp(−t²) by Simpson's rule.
    if x < 0.0 {
        return 2.0 - erfc(-x);
    }
    let upper = x + 10.0;
    let n = 20_000;
    let h = (upper - x) / n as f64;
    let f = |t: f64| (-t * t).exp();
    let mut s = f(x) + f(upper);
    for k in 1..n {
        s += f(x + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0 * 2.0 / PI.sqrt()
}

fn amplitude(th: &Thermal, nx: usize, k: f64) -> f64 {
    let mut s = 0.0;
    for i in 0..nx {
        s += (th.temperature(i, 1) - 1.0) * (k * (i as f64 + 0.5)).sin();
    }
    2.0 * s / nx as f64
}

#[test]
fn sine_mode_decays_with_the_diffusivity() {
    let nx = 64;
    let tau_g = 0.8;
    let chi = (tau_g - 0.5) / 3.0;
    let k = 2.0 * PI / nx as f64;
    for ux in [0.0, 0.05] {
        let mut lat = Lattice::new(LatticeConfig::periodic(nx, 4, 0.8)).unwrap();
        lat.init(|_| (1.0, [ux, 0.0]));
        let mut th = Thermal::new(&lat, tau_g, tau_g, [ThermalSide::Adiabatic; 4], |p| {
            1.0 + 0.1 * (k * p[0]).sin()
        })
        .unwrap();
        let steps = 1280; // the mode travels exactly once around at u = 0.05
        let a0 = amplitude(&th, nx, k);
        for _ in 0..steps {
            th.step(&lat);
            lat.step().unwrap();
        }
        let a1 = amplitude(&th, nx, k);
        let measured = (a0 / a1).ln() / (k * k * steps as f64);
        assert!(
            (measured / chi - 1.0).abs() < 0.01,
            "u = {ux}: χ = {measured} vs {chi}"
        );
    }
}

#[test]
fn step_diffuses_like_erfc() {
    let nx = 200;
    let tau_g = 1.0;
    let chi = (tau_g - 0.5) / 3.0;
    let lat = Lattice::new(LatticeConfig::periodic(nx, 2, 0.8)).unwrap();
    let l = nx as f64;
    let mut th = Thermal::new(&lat, tau_g, tau_g, [ThermalSide::Adiabatic; 4], |p| {
        if p[0] < l / 2.0 { 1.0 } else { 0.0 }
    })
    .unwrap();
    let steps = 600;
    for _ in 0..steps {
        th.step(&lat);
    }
    let t = steps as f64;
    let s = 2.0 * (chi * t).sqrt();
    let mut worst: f64 = 0.0;
    for i in 0..nx {
        let x = i as f64 + 0.5;
        // rises at 0 (and L), falls at L/2: a periodic sum of the two fronts
        let mut exact = 0.0;
        for m in -2..=2 {
            let sh = m as f64 * l;
            exact += 0.5 * erfc((x - l / 2.0 - sh) / s) - 0.5 * erfc((x - sh) / s);
        }
        worst = worst.max((th.temperature(i, 0) - exact).abs());
    }
    assert!(worst < 0.01, "largest deviation {worst} of a unit jump");
}

#[test]
fn heat_is_conserved_and_flux_sides_add_exactly_their_flux() {
    let (nx, ny) = (48, 32);
    let mut cfg = LatticeConfig::periodic(nx, ny, 0.7);
    cfg.accel = [1e-5, 0.0];
    let mut lat = Lattice::new(cfg).unwrap();
    lat.add_obstacle(Obstacle {
        shape: Shape::Circle {
            center: [20.3, 15.8],
            radius: 6.1,
        },
        velocity: [0.0, 0.0],
        angular_velocity: 0.0,
    })
    .unwrap();
    let mut th = Thermal::new(&lat, 0.9, 1.7, [ThermalSide::Adiabatic; 4], |p| {
        if ((p[0] - 20.3).powi(2) + (p[1] - 15.8).powi(2)).sqrt() < 6.1 {
            2.0
        } else {
            1.0
        }
    })
    .unwrap();
    let total0 = th.total();
    for _ in 0..300 {
        let before = th.total();
        th.step(&lat);
        lat.step().unwrap();
        assert!((th.total() / before - 1.0).abs() < 1e-12);
    }
    assert!((th.total() / total0 - 1.0).abs() < 1e-11);

    // channel with walls; heat flux q through ymin, ymax adiabatic
    let mut cfg = LatticeConfig::periodic(nx, ny, 0.8);
    cfg.periodic = [true, false];
    cfg.sides = [SideKind::Wall; 4];
    let lat = Lattice::new(cfg).unwrap();
    let q = 1e-4;
    let sides = [
        ThermalSide::Adiabatic,
        ThermalSide::Adiabatic,
        ThermalSide::Flux(q),
        ThermalSide::Adiabatic,
    ];
    let mut th = Thermal::new(&lat, 0.8, 0.8, sides, |_| 1.0).unwrap();
    for _ in 0..200 {
        let before = th.total();
        th.step(&lat);
        let gained = th.total() - before;
        assert!(
            (gained / (q * nx as f64) - 1.0).abs() < 1e-8,
            "gained {gained}"
        );
    }
}

#[test]
fn conduction_between_fixed_temperatures_is_linear() {
    let (nx, ny) = (4, 20);
    let mut cfg = LatticeConfig::periodic(nx, ny, 0.8);
    cfg.periodic = [true, false];
    let lat = Lattice::new(cfg).unwrap();
    let sides = [
        ThermalSide::Adiabatic,
        ThermalSide::Adiabatic,
        ThermalSide::Temperature(10.0),
        ThermalSide::Temperature(30.0),
    ];
    let mut th = Thermal::new(&lat, 0.9, 0.9, sides, |_| 20.0).unwrap();
    for _ in 0..20_000 {
        th.step(&lat);
    }
    for j in 0..ny {
        let y = j as f64 + 0.5;
        let exact = 10.0 + 20.0 * y / ny as f64;
        assert!(
            (th.temperature(1, j) - exact).abs() < 1e-10,
            "y = {y}: {} vs {exact}",
            th.temperature(1, j)
        );
    }
}

#[test]
fn an_outflow_side_lets_advected_heat_leave_and_the_sides_book_it() {
    // Channel: velocity inlet at xmin (cold, T = 0), pressure outlet at xmax (outflow),
    // walls at ymin and ymax; the fluid starts hot (T = 1) and is flushed.
    let (nx, ny) = (60, 12);
    let mut cfg = LatticeConfig::periodic(nx, ny, 0.8);
    cfg.periodic = [false, false];
    cfg.sides = [
        SideKind::Velocity,
        SideKind::Pressure { density: 1.0 },
        SideKind::Wall,
        SideKind::Wall,
    ];
    let u_in = 0.05;
    let mut lat = Lattice::new(cfg).unwrap();
    lat.set_side_velocity(porofrac_lbm::Side::XMin, |_| [u_in, 0.0]);
    lat.init(|_| (1.0, [u_in, 0.0]));
    let sides = [
        ThermalSide::Temperature(0.0),
        ThermalSide::Outflow,
        ThermalSide::Adiabatic,
        ThermalSide::Adiabatic,
    ];
    let mut th = Thermal::new(&lat, 0.6, 0.6, sides, |_| 1.0).unwrap();
    let total0 = th.total();
    let mut worst: f64 = 0.0;
    // three flow-through times
    let steps = (3.0 * nx as f64 / u_in) as usize;
    for _ in 0..steps {
        let (before, sides_before) = (th.total(), th.side_heat());
        th.step(&lat);
        lat.step().unwrap();
        let booked: f64 = (0..4).map(|s| th.side_heat()[s] - sides_before[s]).sum();
        worst = worst.max((th.total() - before - booked).abs() / total0);
    }
    assert!(worst < 1e-13, "per-step defect {worst:e}");
    let mean = th.total() / (nx * ny) as f64;
    // the heat left through the outlet (and a little through the inlet by diffusion)
    assert!(mean < 0.02, "mean temperature after flushing {mean}");
    assert!(th.side_heat()[1] < -0.5 * total0, "{:?}", th.side_heat());
}
