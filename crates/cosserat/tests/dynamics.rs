//! Dynamics (Marazzato (2021) eqs. 30–31, and energy conservation of average-acceleration
//! Newmark):
//!
//! * a free body (no Dirichlet condition, no load) under Newmark average acceleration
//!   conserves `½VᵀMV + ½UᵀKU` to 1e-10 relative over 200 steps (2D and 3D);
//! * explicit leapfrog at the computed stable step stays bounded (energy within 2 % of its
//!   initial value over 400 steps), and 1.1 × the estimated limit `2/ω_max` blows up,
//!   which shows the estimate is close to the true limit;
//! * a zero micro-inertia is refused for dynamics;
//! * the beam of Marazzato (2021) §4.2.1 in dynamic flexion: the first period of the tip
//!   deflection after a one-step tip impulse lies between the Euler–Bernoulli periods of the
//!   Cosserat bound (`D = EI + (M + Mc)a²`, 31.0 µs) and of the Cauchy beam (`D = EI`,
//!   48.9 µs), and a coarser mesh is stiffer (shorter period).

mod common;

use common::sample;
use porofrac_cosserat::dynamics::EXPLICIT_SAFETY;
use porofrac_cosserat::{
    BodyLoads, Condition, Cosserat, Dynamics, Field, Integrator, Material, Options, constant,
};
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

/// The tip deflection history of the beam of Marazzato (2021) §4.2.1 (1 mm × 40 µm × 40 µm,
/// `nx × 2 × 2` cubes of 6 tetrahedra, clamped at x = 0, a y-traction `p0 = E·1e-6` on the tip face
/// during the first step, Newmark over `T = 200 L √(ρ/E)`), and the times at which it
/// changes sign (linear interpolation between steps).
fn beam_sign_changes(nx: usize, steps: usize) -> Vec<f64> {
    let (lx, a) = (1e-3, 4e-5);
    let g = simplices(Point::<3>::zeros(), Point::<3>::new(lx, a, a), [nx, 2, 2]).unwrap();
    let (k, shear) = (16.67e9, 10e9);
    let nu = (3.0 * k - 2.0 * shear) / (2.0 * (3.0 * k + shear));
    let young = 9.0 * k * shear / (3.0 * k + shear);
    // Rattez et al.: Gc = 5 GPa, L = 1 N, M = Mc = 2.5 N, ρ = 2500, j = (2/5)ℓ², ℓ = 10 µm.
    let m = Material::with_couple_moduli(shear, nu, 5e9, [1.0, 2.5, 2.5])
        .unwrap()
        .with_inertia(2500.0, 0.4 * 1e-10)
        .unwrap();
    let dt = 200.0 * lx * (2500.0 / young).sqrt() / steps as f64;
    let p0 = young * 1e-6;
    let clamp =
        Condition::new(g.boundary("xmin").unwrap()).clamp((0..6).map(|_| constant(0.0)).collect());
    let impulse: Field<3> = std::sync::Arc::new(move |_, t| if t <= 1.5 * dt { p0 } else { 0.0 });
    let tip = Condition::new(g.boundary("xmax").unwrap()).load(1, impulse);
    let model = Cosserat::new(g, m, Options::default(), &[clamp, tip], BodyLoads::none()).unwrap();
    let n = model.equations();
    let grid = model.grid();
    let tip_cells: Vec<usize> = (0..grid.num_cells())
        .filter(|&c| grid.cell_centroid(c)[0] > lx * (1.0 - 1.0 / nx as f64))
        .collect();
    let mut d = Dynamics::new(
        &model,
        Integrator::Newmark,
        dt,
        0.0,
        vec![0.0; n],
        vec![0.0; n],
    )
    .unwrap();
    let (mut t0, mut y0) = (0.0, 0.0);
    let mut changes = Vec::new();
    for _ in 0..steps {
        d.step(&model).unwrap();
        let y = tip_cells.iter().map(|&c| d.u[6 * c + 1]).sum::<f64>() / tip_cells.len() as f64;
        if y0 != 0.0 && (y > 0.0) != (y0 > 0.0) {
            changes.push(t0 + (d.t - t0) * y0 / (y0 - y));
        }
        (t0, y0) = (d.t, y);
    }
    changes
}

#[test]
fn beam_in_flexion_oscillates_between_the_euler_bernoulli_bounds() {
    // Clamped square beam, side a, length L: f1 = 1.8751²/(2π) √(D/(ρ a² L⁴)).
    let (lx, a, rho): (f64, f64, f64) = (1e-3, 4e-5, 2500.0);
    let young = 9.0 * 16.67e9 * 10e9 / (3.0 * 16.67e9 + 10e9);
    let ei = young * a.powi(4) / 12.0;
    let period = |d: f64| {
        2.0 * std::f64::consts::PI / 1.8751f64.powi(2) * (rho * a * a * lx.powi(4) / d).sqrt()
    };
    let (cosserat, cauchy) = (period(ei + (2.5 + 2.5) * a * a), period(ei));
    assert!((cosserat - 31.0e-6).abs() < 0.1e-6 && (cauchy - 48.9e-6).abs() < 0.1e-6);
    // The first period ends at the second sign change of the tip deflection.
    let fine = beam_sign_changes(160, 500);
    let coarse = beam_sign_changes(40, 500);
    assert!(fine.len() >= 2 && coarse.len() >= 2, "{fine:?} {coarse:?}");
    assert!(
        fine[1] > cosserat && fine[1] < cauchy,
        "period {:.3e} s outside [{cosserat:.3e}, {cauchy:.3e}]",
        fine[1]
    );
    assert!(
        coarse[1] < fine[1],
        "coarse {:.3e} ≥ fine {:.3e}",
        coarse[1],
        fine[1]
    );
}
