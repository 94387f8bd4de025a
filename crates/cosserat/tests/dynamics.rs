//! Dynamics (the seed's verification plan §3 and §5 test 4):
//!
//! * a free body (no Dirichlet condition, no load) under Newmark average acceleration
//!   conserves `½VᵀMV + ½UᵀKU` to 1e-10 relative over 200 steps (2D and 3D);
//! * explicit leapfrog at the computed stable step stays bounded (energy within 2 % of its
//!   initial value over 400 steps), and 1.1 × the estimated limit `2/ω_max` blows up,
//!   which shows the estimate is close to the true limit;
//! * a zero micro-inertia is refused for dynamics.

mod common;

use common::sample;
use porofrac_cosserat::dynamics::EXPLICIT_SAFETY;
use porofrac_cosserat::{BodyLoads, Cosserat, Dynamics, Integrator, Material, Options};
use porofrac_grid::Point;
use porofrac_grid::generate::{perturb, simplices};

fn free_2d() -> Cosserat<2> {
    let g = perturb(
        &simplices(Point::<2>::zeros(), Point::<2>::new(1.0, 0.6), [8, 5]).unwrap(),
        0.2,
        4,
    )
    .unwrap();
    let m = Material::with_length(1000.0, 0.25, 500.0, 0.1)
        .unwrap()
        .with_inertia(2.0, 0.01)
        .unwrap();
    Cosserat::new(g, m, Options::default(), &[], BodyLoads::none()).unwrap()
}

fn energy<const D: usize>(model: &Cosserat<D>, d: &Dynamics) -> f64 {
    d.kinetic() + model.energy(&d.u)
}

#[test]
fn newmark_conserves_energy_of_a_free_body() {
    let model = free_2d();
    let u0 = sample(model.grid(), |x| {
        vec![
            1e-3 * (3.0 * x[0] * x[1]).sin(),
            1e-3 * x[0] * x[0],
            1e-3 * x[1],
        ]
    });
    let v0 = sample(model.grid(), |x| vec![0.01 * x[1], -0.02 * x[0], 0.05]);
    let mut d = Dynamics::new(&model, Integrator::Newmark, 2e-3, 0.0, u0, v0).unwrap();
    let e0 = energy(&model, &d);
    for _ in 0..200 {
        d.step(&model).unwrap();
    }
    let e1 = energy(&model, &d);
    assert!((e1 - e0).abs() < 1e-10 * e0, "{e0} → {e1}");
    // The state did move (not a trivial pass).
    assert!(model.energy(&d.u) > 1e-3 * e0);

    // 3D: a perturbed box of tetrahedra.
    let g = perturb(
        &simplices(
            Point::<3>::zeros(),
            Point::<3>::new(1.0, 0.6, 0.5),
            [3, 2, 2],
        )
        .unwrap(),
        0.2,
        6,
    )
    .unwrap();
    let m = Material::with_couple_moduli(1000.0, 0.25, 300.0, [1.0, 2.0, 0.5])
        .unwrap()
        .with_inertia(2.0, 0.02)
        .unwrap();
    let model = Cosserat::new(g, m, Options::default(), &[], BodyLoads::none()).unwrap();
    let u0 = sample(model.grid(), |x| {
        vec![1e-3 * x[1] * x[2], 0.0, 1e-3 * x[0] * x[0], 0.0, 1e-3, 0.0]
    });
    let v0 = sample(model.grid(), |x| {
        vec![0.0, 0.01 * x[0], 0.0, 0.02, 0.0, 0.0]
    });
    let mut d = Dynamics::new(&model, Integrator::Newmark, 2e-3, 0.0, u0, v0).unwrap();
    let e0 = energy(&model, &d);
    for _ in 0..200 {
        d.step(&model).unwrap();
    }
    let e1 = energy(&model, &d);
    assert!((e1 - e0).abs() < 1e-10 * e0, "3D: {e0} → {e1}");
}

#[test]
fn explicit_stable_step_is_close_to_the_limit() {
    let model = free_2d();
    let dt = Dynamics::stable_step(&model);
    assert!(dt.is_finite() && dt > 0.0);
    let u0 = sample(model.grid(), |x| vec![1e-3 * x[0] * x[1], 0.0, 0.0]);
    let v0 = vec![0.0; u0.len()];
    let mut d = Dynamics::new(
        &model,
        Integrator::Explicit,
        dt,
        0.0,
        u0.clone(),
        v0.clone(),
    )
    .unwrap();
    let e0 = energy(&model, &d);
    let mut worst: f64 = 0.0;
    for _ in 0..400 {
        d.step(&model).unwrap();
        worst = worst.max((energy(&model, &d) - e0).abs() / e0);
    }
    assert!(worst < 0.02, "energy drift {worst}");
    // Beyond the limit: 1.1 × 2/ω_max.
    let over = 1.1 * dt / EXPLICIT_SAFETY;
    let mut d = Dynamics::new(&model, Integrator::Explicit, over, 0.0, u0, v0).unwrap();
    let mut grew = false;
    for _ in 0..400 {
        if d.step(&model).is_err() || energy(&model, &d) > 1e3 * e0 {
            grew = true;
            break;
        }
    }
    assert!(grew, "1.1 × the estimated limit stayed bounded");
}

#[test]
fn zero_micro_inertia_is_refused() {
    let g = simplices(Point::<2>::zeros(), Point::<2>::new(1.0, 1.0), [2, 2]).unwrap();
    let m = Material::with_length(1.0, 0.2, 1.0, 0.1)
        .unwrap()
        .with_inertia(1.0, 0.0)
        .unwrap();
    let model = Cosserat::new(g, m, Options::default(), &[], BodyLoads::none()).unwrap();
    let n = model.equations();
    let e = Dynamics::new(
        &model,
        Integrator::Newmark,
        0.1,
        0.0,
        vec![0.0; n],
        vec![0.0; n],
    )
    .unwrap_err();
    assert!(e.to_string().contains("micro_inertia"));
}
