//! A rigid body's own friction coefficient μ_b ([`RigidBody::with_friction`]) against
//! closed forms, with the contact law's μ set far from it so that using the wrong one
//! fails (each test states its reference and tolerance):
//!
//! * a block (a disk that cannot rotate) pushed at constant speed along a base of its own
//!   μ_b by a frictionless driven wall: the wall pushes with μ_b m g and the base holds
//!   it with (−μ_b m g, m g) (solver tolerance), the block moves at the wall's speed;
//! * a disk on an incline of its own μ_b rolls with a = (2/3) g sin α when tan α ≤ 3μ_b
//!   and slips with a = g(sin α − μ_b cos α) otherwise (to 1e-10);
//! * a negative or non-finite μ_b is refused, naming the body and the friction.

use porofrac_nscd::{ContactLaw, Nscd, RigidBody, SolverParams};
use porofrac_particles::Disks;

const G: f64 = 9.81;

fn params() -> SolverParams {
    SolverParams {
        theta: 0.5,
        tolerance: 1e-13,
        min_sweeps: 1,
        ..SolverParams::default()
    }
}

/// A block of radius r = 0.5 m on a flat base (μ_b = 0.25) with the contact law's μ =
/// 0.9, pushed from the left at 0.1 m/s by a wall of μ = 0: at steady sliding the wall
/// exerts (μ_b m g, 0) on the block and the base (−μ_b m g, m g), to 1e-9 m g.
#[test]
fn block_pushed_along_a_base_needs_its_own_mu_times_the_weight() {
    let (r, mu_base, speed) = (0.5, 0.25, 0.1);
    let mut d = Disks::new(&[[0.0, r]], &[r], 2000.0).unwrap();
    d.inertia[0] = f64::INFINITY;
    let weight = d.mass[0] * G;
    let base = RigidBody::segment([-10.0, 0.0], [10.0, 0.0]).with_friction(mu_base);
    let pusher = RigidBody::segment([-r, 0.1], [-r, 2.0])
        .moving([speed, 0.0])
        .with_friction(0.0);
    let mut s = Nscd::new(
        d,
        vec![base, pusher],
        ContactLaw::frictional(0.9),
        params(),
        [0.0, -G],
    )
    .unwrap();
    for _ in 0..200 {
        s.step(1e-3).unwrap();
    }
    let [bx, by, _] = s.body_reaction(0);
    let [px, py, _] = s.body_reaction(1);
    assert!(
        (px - mu_base * weight).abs() < 1e-9 * weight,
        "wall push {px}, μ_b m g {}",
        mu_base * weight
    );
    assert!(py.abs() < 1e-9 * weight, "wall shear {py}");
    assert!(
        (bx + mu_base * weight).abs() < 1e-9 * weight,
        "base shear {bx}"
    );
    assert!((by - weight).abs() < 1e-9 * weight, "base normal {by}");
    assert!(
        (s.disks.v[0][0] - speed).abs() < 1e-9 * speed,
        "block speed {}",
        s.disks.v[0][0]
    );
}

/// A disk of radius 0.5 m on an incline of tan α = 0.5 whose own μ_b is 0.1 (3μ_b < tan α:
/// slips) or 0.2 (3μ_b > tan α: rolls), the contact law's μ being 0.9 (it would roll in
/// both): after 0.2 s its velocity along the slope is a t with the closed-form a, to
/// 1e-10 relative.
#[test]
fn disk_on_an_incline_rolls_or_slips_by_the_base_mu() {
    let (r, h, steps) = (0.5, 1e-3, 200);
    let alpha = 0.5f64.atan();
    let e = [alpha.cos(), -alpha.sin()];
    let up = [alpha.sin(), alpha.cos()];
    for (mu_base, rolls) in [(0.1, false), (0.2, true)] {
        let base = RigidBody::segment([-100.0 * e[0], -100.0 * e[1]], [100.0 * e[0], 100.0 * e[1]])
            .with_friction(mu_base);
        let d = Disks::new(&[[r * up[0], r * up[1]]], &[r], 2000.0).unwrap();
        let mut s = Nscd::new(
            d,
            vec![base],
            ContactLaw::frictional(0.9),
            params(),
            [0.0, -G],
        )
        .unwrap();
        for _ in 0..steps {
            s.step(h).unwrap();
        }
        let t = h * steps as f64;
        let a = if rolls {
            2.0 / 3.0 * G * alpha.sin()
        } else {
            G * (alpha.sin() - mu_base * alpha.cos())
        };
        let v = s.disks.v[0];
        let along = v[0] * e[0] + v[1] * e[1];
        assert!(
            (along - a * t).abs() <= 1e-10 * a * t,
            "μ_b = {mu_base}: v = {along}, expected {}",
            a * t
        );
        let slip = along + s.disks.omega[0] * r;
        if rolls {
            assert!(slip.abs() < 1e-10, "μ_b = {mu_base}: slip velocity {slip}");
        } else {
            assert!(slip > 1e-2, "μ_b = {mu_base}: slip velocity {slip}");
        }
    }
}

/// A negative or non-finite μ_b is refused with the body's index and the word friction.
#[test]
fn bad_body_friction_is_refused() {
    for mu in [-0.1, f64::NAN, f64::INFINITY] {
        let d = Disks::new(&[[0.0, 1.0]], &[0.5], 1000.0).unwrap();
        let base = RigidBody::segment([-1.0, 0.0], [1.0, 0.0]).with_friction(mu);
        let e = Nscd::new(
            d,
            vec![base],
            ContactLaw::frictional(0.3),
            params(),
            [0.0; 2],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("friction") && e.contains('0'), "μ_b = {mu}: {e}");
    }
}
