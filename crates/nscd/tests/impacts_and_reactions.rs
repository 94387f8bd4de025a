//! Newton's impact law, the overlaps of the θ-scheme and the reactions of rigid bodies,
//! against closed forms (each test states its reference and tolerance):
//!
//! * a ball dropped on a floor with restitution e = ½ leaves at e times its arrival
//!   speed (to round-off) and rises to e² times its drop height (to the O(h v) of the
//!   time discretisation);
//! * a head-on impact of two disks with e = ½ conserves momentum and reverses the
//!   relative velocity scaled by e (to round-off);
//! * a disk arriving on a floor at speed v with the gap-aware inelastic law (e = 0)
//!   stays overlapping it by at most h(1 − θ)v, a bound that is reached, and not at all
//!   with θ = 1;
//! * the floor under a resting column of n disks carries n·m·g, and its moment about
//!   the floor's centre is the weight times the lever arm (solver tolerance);
//! * a block driven at constant speed over a fixed bed under a normal load N needs the
//!   horizontal force μ·N (solver tolerance).

use porofrac_nscd::{Axis, ContactLaw, Nscd, RigidBody, SolverParams};
use porofrac_particles::Disks;

const G: f64 = 9.81;

fn params(theta: f64) -> SolverParams {
    SolverParams {
        theta,
        tolerance: 1e-13,
        min_sweeps: 1,
        ..SolverParams::default()
    }
}

/// A ball of radius r dropped from rest with its lowest point H above a floor, e = ½:
/// the rebound speed is e times the arrival speed exactly, the arrival speed is
/// √(2gH) within g·h, and the highest point after the bounce is e²H above the floor
/// within 4 √(2gH) h (the overlap of the impact step and the sampling of the apex).
#[test]
fn ball_bounces_to_e_squared_of_its_height() {
    let (r, height, e, h) = (0.1, 1.0, 0.5, 1e-4);
    let d = Disks::new(&[[0.0, r + height]], &[r], 2500.0).unwrap();
    let floor = RigidBody::segment([-5.0, 0.0], [5.0, 0.0]);
    let law = ContactLaw::frictional(0.3).with_restitution(e);
    let mut s = Nscd::new(d, vec![floor], law, params(0.5), [0.0, -G]).unwrap();
    let mut arrival = None;
    let mut rebound = None;
    let mut apex = f64::NEG_INFINITY;
    for _ in 0..12_000 {
        let before = s.disks.v[0][1];
        s.step(h).unwrap();
        let after = s.disks.v[0][1];
        if arrival.is_none() && !s.contacts().is_empty() && s.contacts()[0].p[0] > 0.0 {
            arrival = Some(before);
            rebound = Some(after);
        } else if rebound.is_some() && after > 0.0 {
            apex = apex.max(s.disks.x[0][1] - r);
        }
        if rebound.is_some() && after < 0.0 && s.disks.x[0][1] - r > 0.5 * e * e * height {
            break;
        }
    }
    let (arrival, rebound) = (arrival.unwrap(), rebound.unwrap());
    let v0 = (2.0 * G * height).sqrt();
    assert!(
        (arrival + v0).abs() <= G * h,
        "arrival {arrival}, expected {}",
        -v0
    );
    assert!(
        (rebound + e * arrival).abs() <= 1e-12 * v0,
        "rebound {rebound}, expected {}",
        -e * arrival
    );
    assert!(
        (apex - e * e * height).abs() <= 4.0 * v0 * h,
        "apex {apex}, expected {}",
        e * e * height
    );
    assert_eq!(s.disks.omega[0], 0.0, "a normal impact spins nothing");
}

/// Two equal disks meeting head-on at v₁ = 2, v₂ = −1 m/s with e = ½, no gravity:
/// momentum m(v₁ + v₂) is conserved and the relative velocity after is −e times the
/// one before, v₁' = 0.5 − 0.75 = −0.25, v₂' = 1.25 (to 1e-12).
#[test]
fn head_on_impact_reverses_the_relative_velocity_by_e() {
    let e = 0.5;
    let mut d = Disks::new(&[[0.0, 0.0], [1.0005, 0.0]], &[0.5, 0.5], 1000.0).unwrap();
    d.v[0] = [2.0, 0.0];
    d.v[1] = [-1.0, 0.0];
    let law = ContactLaw::frictional(0.0).with_restitution(e);
    let mut s = Nscd::new(d, vec![], law, params(0.5), [0.0, 0.0]).unwrap();
    let h = 1e-3;
    for _ in 0..10 {
        s.step(h).unwrap();
    }
    let (v1, v2) = (s.disks.v[0][0], s.disks.v[1][0]);
    assert!((v1 + v2 - 1.0).abs() < 1e-12, "momentum {}", v1 + v2);
    assert!(
        (v1 + 0.25).abs() < 1e-12 && (v2 - 1.25).abs() < 1e-12,
        "{v1} {v2}"
    );
}

/// A disk moving at v = 1 m/s onto a floor, no gravity, e = 0, starting at gaps spread
/// over one step's travel: the overlap it keeps at rest is ≤ h(1 − θ)v for θ = ½ (to
/// 1e-12 relative) and at least 0.95 of it for some start, and 0 (to 1e-12 h v) for
/// θ = 1.
#[test]
fn inelastic_landing_overlap_is_at_most_h_one_minus_theta_v() {
    let (r, v, h) = (0.1, 1.0, 1e-2);
    for theta in [0.5, 1.0] {
        let bound = h * (1.0 - theta) * v;
        let mut largest = 0.0f64;
        for k in 0..50 {
            let gap = 3.0 * h * v + h * v * k as f64 / 50.0;
            let mut d = Disks::new(&[[0.0, r + gap]], &[r], 2500.0).unwrap();
            d.v[0] = [0.0, -v];
            let floor = RigidBody::segment([-5.0, 0.0], [5.0, 0.0]);
            let p = SolverParams {
                alert: Some(0.05),
                ..params(theta)
            };
            let mut s = Nscd::new(d, vec![floor], ContactLaw::default(), p, [0.0; 2]).unwrap();
            for _ in 0..10 {
                s.step(h).unwrap();
            }
            assert!(s.disks.v[0][1].abs() < 1e-12, "at rest: {:?}", s.disks.v[0]);
            let overlap = r - s.disks.x[0][1];
            assert!(
                overlap <= bound * (1.0 + 1e-12) + 1e-15,
                "θ = {theta}: overlap {overlap} > h(1 − θ)v = {bound}"
            );
            largest = largest.max(overlap);
        }
        if theta == 0.5 {
            assert!(
                largest >= 0.95 * bound,
                "largest overlap {largest} of {bound}"
            );
        } else {
            assert!(largest <= 1e-12 * h * v, "θ = 1: overlap {largest}");
        }
    }
}

/// A column of n = 10 equal disks at rest on a floor segment whose centre is a = 0.3 m
/// to the left of the column: the floor's reaction is (0, n m g) and its moment about
/// the floor's centre is a·n m g (to 1e-9 relative).
#[test]
fn floor_carries_the_column() {
    let (n, r) = (10, 0.05);
    let a = 0.3;
    let centres: Vec<[f64; 2]> = (0..n).map(|k| [a, r + 2.0 * r * k as f64]).collect();
    let d = Disks::new(&centres, &vec![r; n], 2000.0).unwrap();
    let weight = d.mass.iter().sum::<f64>() * G;
    let floor = RigidBody::segment([-1.0, 0.0], [1.0, 0.0]);
    let mut s = Nscd::new(
        d,
        vec![floor],
        ContactLaw::frictional(0.3),
        params(0.5),
        [0.0, -G],
    )
    .unwrap();
    for _ in 0..20 {
        s.step(1e-3).unwrap();
    }
    let [fx, fy, torque] = s.body_reaction(0);
    assert!(fx.abs() < 1e-9 * weight, "fx {fx}");
    assert!(
        (fy - weight).abs() < 1e-9 * weight,
        "fy {fy}, n m g {weight}"
    );
    assert!(
        (torque - a * weight).abs() < 1e-9 * a * weight,
        "τ {torque}"
    );
    assert_eq!(s.body_reaction(1), [0.0; 3], "no body 1");
}

/// A square block (1 m, mass 10 kg/m) over a bed of 8 fixed disks (infinite mass),
/// pressed down by N = 5e3 N/m and driven at 0.1 m/s to the right, μ = 0.4: once
/// sliding, the block exerts (μN, −N) on the bed (to 1e-9 relative).
#[test]
fn block_pushed_over_a_bed_needs_mu_n() {
    let (mu, load, r) = (0.4, 5.0e3, 0.1);
    let centres: Vec<[f64; 2]> = (0..8).map(|k| [0.2 * k as f64, 0.0]).collect();
    let mut d = Disks::new(&centres, &[r; 8], 2000.0).unwrap();
    for k in 0..8 {
        d.mass[k] = f64::INFINITY;
        d.inertia[k] = f64::INFINITY;
    }
    let block = RigidBody::polygon(vec![[0.2, r], [1.2, r], [1.2, r + 1.0], [0.2, r + 1.0]])
        .with_axes([Axis::Prescribed(0.1), Axis::Loaded(-load)], 10.0);
    let mut s = Nscd::new(
        d,
        vec![block],
        ContactLaw::frictional(mu),
        params(0.5),
        [0.0, -G],
    )
    .unwrap();
    for _ in 0..50 {
        s.step(1e-3).unwrap();
    }
    let [fx, fy, _] = s.body_reaction(0);
    assert!(
        (fx - mu * load).abs() < 1e-9 * load,
        "fx {fx}, μN {}",
        mu * load
    );
    assert!((fy + load).abs() < 1e-9 * load, "fy {fy}, −N {}", -load);
}

/// Restitution outside [0, 1], or with cohesion, is refused with its name.
#[test]
fn bad_restitution_is_refused() {
    let d = || Disks::new(&[[0.0, 1.0]], &[0.5], 1000.0).unwrap();
    for law in [
        ContactLaw::frictional(0.1).with_restitution(1.5),
        ContactLaw::frictional(0.1).with_restitution(f64::NAN),
        ContactLaw::frictional(0.1)
            .with_cohesion(1e3, 1e-3)
            .with_restitution(0.5),
    ] {
        let e = Nscd::new(d(), vec![], law, SolverParams::default(), [0.0; 2]).unwrap_err();
        assert!(e.to_string().starts_with("restitution"), "{e}");
    }
}

/// The same ball (e = ½, θ = ½) through three bounces: every rebound speed is e times
/// the arrival speed before it (to 1e-12, the impact step's velocity is exact), every
/// arrival speed is the rebound speed before it (free flight is exact with θ = ½: the
/// ball leaves and comes back through the same predicted contact, to g·h), so the
/// apexes go as H e², H e⁴, H e⁶, each within 4 v₀ h (the impact step's overlap and the
/// sampling of the apex).
#[test]
fn bounce_heights_go_as_powers_of_e_squared() {
    let (r, height, e, h) = (0.1, 1.0, 0.5, 1e-4);
    let d = Disks::new(&[[0.0, r + height]], &[r], 2500.0).unwrap();
    let floor = RigidBody::segment([-5.0, 0.0], [5.0, 0.0]);
    let law = ContactLaw::frictional(0.3).with_restitution(e);
    let mut s = Nscd::new(d, vec![floor], law, params(0.5), [0.0, -G]).unwrap();
    let v0 = (2.0 * G * height).sqrt();
    // (arrival, rebound, apex) of each bounce.
    let mut bounces: Vec<(f64, f64, f64)> = Vec::new();
    let mut rising = false;
    for _ in 0..30_000 {
        let before = s.disks.v[0][1];
        s.step(h).unwrap();
        let after = s.disks.v[0][1];
        let y = s.disks.x[0][1] - r;
        if before < 0.0 && after > 0.0 {
            bounces.push((before, after, f64::NEG_INFINITY));
            rising = true;
        } else if rising {
            let b = bounces.last_mut().unwrap();
            b.2 = b.2.max(y);
            if after < 0.0 {
                rising = false;
                if bounces.len() == 3 {
                    break;
                }
            }
        }
    }
    assert_eq!(bounces.len(), 3, "{bounces:?}");
    let mut speed = v0;
    for (k, &(arrival, rebound, apex)) in bounces.iter().enumerate() {
        assert!(
            (arrival + speed).abs() <= G * h,
            "bounce {k}: arrival {arrival}, expected {}",
            -speed
        );
        assert!(
            (rebound + e * arrival).abs() <= 1e-12 * v0,
            "bounce {k}: rebound {rebound} after {arrival}"
        );
        let want = height * e.powi(2 * (k as i32 + 1));
        assert!(
            (apex - want).abs() <= 4.0 * v0 * h,
            "bounce {k}: apex {apex}, H e^{} = {want}",
            2 * (k + 1)
        );
        speed = rebound;
    }
}

/// Two equal disks closing head-on at 3 m/s (1.5 m/s each), no gravity, e = 0,
/// h = 1 ms, from start gaps spread over one step's travel: they stop, and the overlap
/// they keep is ≤ h(1 − θ)v_n = 1.5 mm for θ = ½ (to 1e-12 relative) and reaches 0.95
/// of it for some start; 0 for θ = 1.
#[test]
fn head_on_overlap_is_at_most_h_one_minus_theta_v() {
    let (r, v, h) = (0.1, 3.0, 1e-3);
    for theta in [0.5, 1.0] {
        let bound = h * (1.0 - theta) * v;
        let mut largest = 0.0f64;
        for k in 0..50 {
            let gap = 2.0 * h * v + h * v * k as f64 / 50.0;
            let mut d = Disks::new(&[[0.0, 0.0], [2.0 * r + gap, 0.0]], &[r, r], 2500.0).unwrap();
            d.v[0] = [0.5 * v, 0.0];
            d.v[1] = [-0.5 * v, 0.0];
            let p = SolverParams {
                alert: Some(0.05),
                ..params(theta)
            };
            let mut s = Nscd::new(d, vec![], ContactLaw::default(), p, [0.0; 2]).unwrap();
            for _ in 0..10 {
                s.step(h).unwrap();
            }
            assert!(
                s.disks.v[0][0].abs() < 1e-12 && s.disks.v[1][0].abs() < 1e-12,
                "at rest: {:?}",
                s.disks.v
            );
            let overlap = 2.0 * r - (s.disks.x[1][0] - s.disks.x[0][0]);
            assert!(
                overlap <= bound * (1.0 + 1e-12) + 1e-15,
                "θ = {theta}: overlap {overlap} > h(1 − θ)v_n = {bound}"
            );
            largest = largest.max(overlap);
        }
        if theta == 0.5 {
            assert!(largest >= 0.95 * bound, "largest {largest} of {bound}");
        } else {
            assert!(largest <= 1e-12 * h * v, "θ = 1: overlap {largest}");
        }
    }
}
