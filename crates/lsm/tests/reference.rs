//! Checks of the lattice solid against closed forms:
//!
//! 1. a bonded pair oscillates with the period `2π√(μ/k_n)` (μ the reduced mass) and
//!    velocity Verlet keeps the energy within 1e-6 (relative) over 10⁴ periods;
//! 2. a strained hexagonal lattice has the E and ν of the closed form of the crate docs
//!    (E within 1 %, ν of the core within 2 % and of the side disks within 1 %);
//! 3. a single bond breaks in pure tension, pure shear and combined loading at the
//!    displacement predicted by the bond kinematics and the Mohr–Coulomb criterion with
//!    its tension cut-off, in the right mode;
//! 4. bad input is refused with an error naming it.

use porofrac_lsm::calibrate::{QuasiStatic, hexagonal_moduli, hexagonal_springs, uniaxial};
use porofrac_lsm::{BondLaw, BreakMode, LatticeSolid, LsmError, LsmSpec, Motion};
use porofrac_particles::Disks;
use porofrac_particles::packing::hexagonal;

fn pair(law: BondLaw) -> LatticeSolid {
    let d = Disks::new(&[[0.0, 0.0], [1.0, 0.0]], &[0.5, 0.5], 1.0).unwrap();
    LatticeSolid::new(d, LsmSpec::new(law)).unwrap()
}

#[test]
fn bonded_pair_period_and_energy() {
    let kn = 2.0;
    let mut s = pair(BondLaw::elastic(kn, 0.0, 0.0));
    let m = s.disks().mass[0];
    let mu = 0.5 * m;
    let period = 2.0 * std::f64::consts::PI * (mu / kn).sqrt();
    let per = 4000;
    let dt = period / per as f64;
    assert!(dt < s.stable_dt());
    // An opening impulse: velocities ∓0.005 after the first step.
    let mut ext = vec![[0.0; 3]; 2];
    ext[0] = [-0.005 * m / dt, 0.0, 0.0];
    ext[1] = [0.005 * m / dt, 0.0, 0.0];
    s.step(dt, &ext).unwrap();
    let e0 = s.disks().kinetic_energy() + s.bond_energy();
    assert!(e0 > 0.0);
    let mut worst: f64 = 0.0;
    let mut crossings = Vec::new();
    let mut prev = s.disks().x[1][0] - s.disks().x[0][0] - 1.0;
    let periods = 10_000;
    for _ in 0..periods * per {
        s.step(dt, &[]).unwrap();
        let e = s.disks().kinetic_energy() + s.bond_energy();
        worst = worst.max((e - e0).abs() / e0);
        let stretch = s.disks().x[1][0] - s.disks().x[0][0] - 1.0;
        if prev < 0.0 && stretch >= 0.0 {
            // Linear interpolation of the upward zero crossing.
            crossings.push(s.time() - dt * stretch / (stretch - prev));
        }
        prev = stretch;
    }
    assert!(worst < 1e-6, "relative energy error {worst:.3e}");
    let n = crossings.len();
    assert!(n >= periods - 1);
    let measured = (crossings[n - 1] - crossings[0]) / (n - 1) as f64;
    let rel = (measured - period).abs() / period;
    // Verlet's period error is (ωΔt)²/24 ≈ 1e-7 here.
    assert!(rel < 1e-6, "period {measured} vs {period}: {rel:.2e}");
}

#[test]
fn hexagonal_lattice_moduli() {
    let (kn, ks) = (1.0e9, 0.4e9);
    let (e, nu) = hexagonal_moduli(kn, ks);
    // The inverse formula round-trips.
    let (kn2, ks2) = hexagonal_springs(e, nu).unwrap();
    assert!((kn2 - kn).abs() < 1e-6 * kn && (ks2 - ks).abs() < 1e-6 * kn);
    let p = hexagonal([0.0, 0.0], [60.0, 40.0], 0.5).unwrap();
    let d = Disks::new(&p.centres, &p.radii, 2600.0).unwrap();
    let c = (e / 2600.0).sqrt();
    let q = QuasiStatic {
        speed: 2e-4 * c,
        ..QuasiStatic::new(1.0)
    };
    let m = uniaxial(d, LsmSpec::new(BondLaw::elastic(kn, ks, 0.0)), 1e-3, &q).unwrap();
    let (re, rn) = ((m.e - e) / e, (m.nu - nu) / nu);
    eprintln!(
        "uniaxial E {:.5e} vs {:.5e} ({re:+.3e}), nu {:.5} vs {:.5} ({rn:+.3e}); boundary E {:.5e}, nu {:.5}; {} steps",
        m.e, e, m.nu, nu, m.e_platens, m.nu_sides, m.steps
    );
    assert!(re.abs() < 0.01, "E {:.4e} vs {:.4e} ({re:+.3e})", m.e, e);
    // The core's ν (affine fit of the disks away from the sides and platens) is 1.4 %
    // below the closed form on this 60 × 40 m lattice of unit disks (0.17396 vs 0.17647;
    // the side disks' boundary measure 0.17600): 2 %.
    assert!(rn.abs() < 0.02, "nu {:.4} vs {:.4} ({rn:+.3e})", m.nu, nu);
    assert!(
        (m.nu_sides - nu).abs() < 0.01 * nu,
        "boundary nu {:.4} vs {nu:.4}",
        m.nu_sides
    );
}

/// The two disks of [`pair`], i fixed, j driven at speed v in the direction β; returns
/// the platen travel at breakage and the mode.
fn drive_to_break(law: BondLaw, beta: f64, v: f64, dt: f64) -> (f64, BreakMode) {
    let mut s = pair(law);
    s.set_motion(0, Motion::Fixed);
    s.set_motion(1, Motion::Velocity([v * beta.cos(), v * beta.sin()]));
    for _ in 0..1_000_000 {
        let r = s.step(dt, &[]).unwrap();
        if r.broken > 0 {
            let b = s.broken()[0];
            assert_eq!((b.i, b.j), (0, 1));
            return (v * s.time(), b.mode);
        }
    }
    panic!("no breakage");
}

/// The travel s at which the bond of [`pair`] breaks when j moves along (cos β, sin β)
/// from (1, 0): `d(s) = |(1 + s cos β, s sin β)|`, `dδ_s/ds = sin β / d` (the tangential
/// component of the path), integrated by the midpoint rule on a fine grid.
fn predicted(law: &BondLaw, beta: f64) -> (f64, BreakMode) {
    let (ft, fc, tphi) = (law.tensile, law.cohesion, law.friction_angle.tan());
    let ds = 1e-8;
    let (mut s, mut shear) = (0.0f64, 0.0f64);
    loop {
        let mid = s + 0.5 * ds;
        let d = ((1.0 + mid * beta.cos()).powi(2) + (mid * beta.sin()).powi(2)).sqrt();
        shear += beta.sin() / d * ds;
        s += ds;
        let d = ((1.0 + s * beta.cos()).powi(2) + (s * beta.sin()).powi(2)).sqrt();
        let fn_ = law.kn * (d - 1.0);
        if fn_ / ft > 1.0 {
            return (s, BreakMode::Tensile);
        }
        if (law.ks * shear).abs() > fc - fn_ * tphi {
            return (s, BreakMode::Shear);
        }
    }
}

#[test]
fn single_bond_breakage_tension_shear_combined() {
    // Unit width (radii 0.5): F_t = σ_t, F_c = c.
    let law = BondLaw {
        kn: 100.0,
        ks: 50.0,
        kb: 0.0,
        tensile: 1.0,
        cohesion: 0.8,
        friction_angle: 30f64.to_radians(),
    };
    let v = 1e-4;
    let dt = 0.5 * pair(law).stable_dt();
    let cases = [
        ("pure tension", 0.0, BreakMode::Tensile),
        ("pure shear", 90f64.to_radians(), BreakMode::Shear),
        ("shear with tension", 45f64.to_radians(), BreakMode::Shear),
        (
            "shear with compression",
            135f64.to_radians(),
            BreakMode::Shear,
        ),
    ];
    for (name, beta, mode) in cases {
        let (s_pred, m_pred) = predicted(&law, beta);
        assert_eq!(m_pred, mode, "{name}: the prediction's mode");
        let (s, m) = drive_to_break(law, beta, v, dt);
        assert_eq!(m, mode, "{name}");
        // Breakage is tested once per step: within one step of travel past the
        // prediction, plus 1e-5 relative for the shear increments taken along the
        // end-of-step tangent (first order in the bond rotation per step).
        let slack = 1e-5 * s_pred;
        assert!(
            s >= s_pred - slack && s <= s_pred + v * dt + slack,
            "{name}: broke at travel {s:.6e}, predicted {s_pred:.6e}"
        );
    }
    // Mohr–Coulomb: tension lowers the shear strength, compression raises it.
    let (s45, _) = predicted(&law, 45f64.to_radians());
    let (s90, _) = predicted(&law, 90f64.to_radians());
    let (s135, _) = predicted(&law, 135f64.to_radians());
    assert!(s45 < s90 && s90 < s135);
    // Pure tension: the cut-off F_t/k_n.
    let (s0, _) = predicted(&law, 0.0);
    assert!((s0 - law.tensile / law.kn).abs() < 1e-7);
}

#[test]
fn bad_input_is_refused_by_name() {
    let mut s = pair(BondLaw::elastic(1.0, 0.5, 0.0));
    match s.step(2.0 * s.stable_dt(), &[]) {
        Err(LsmError::TimeStep { .. }) => {}
        other => panic!("expected a time step error, got {other:?}"),
    }
    match s.step(0.5 * s.stable_dt(), &[[0.0; 3]]) {
        Err(LsmError::External {
            got: 1,
            expected: 2,
        }) => {}
        other => panic!("{other:?}"),
    }
    let d = Disks::new(&[[0.0, 0.0], [1.0, 0.0]], &[0.5, 0.5], 1.0).unwrap();
    let err =
        LatticeSolid::new(d.clone(), LsmSpec::new(BondLaw::elastic(-1.0, 0.0, 0.0))).unwrap_err();
    assert!(err.to_string().contains("bonds.kn"), "{err}");
    let d2 = Disks::new(&[[0.0, 0.0], [0.9, 0.0]], &[0.5, 0.5], 1.0).unwrap();
    let err = LatticeSolid::new(d2, LsmSpec::new(BondLaw::elastic(1.0, 0.0, 0.0))).unwrap_err();
    assert!(matches!(err, LsmError::Overlap { i: 0, j: 1, .. }), "{err}");
    assert!(
        hexagonal_springs(1.0, 0.4)
            .unwrap_err()
            .to_string()
            .contains("nu")
    );
}
