//! Fracture toughness of the borehole scenes' packing recipe (radii 0.1–1 m, packing
//! fraction 0.8, E = 10 GPa, ν = 0.2 by the hexagonal closed form, bond σ_t = 5 MPa,
//! c = 10 MPa, φ = 30°, no bending spring, bond tolerance 0.05, local damping 0.7) from a
//! pressurised notch ([`porofrac_lsm::toughness::pressurised_notch`]): notches of
//! half-length c = 3 and 6 m through the centre of a disk of radius 28 m, the pressure
//! ramped at 2.5 MPa/s on the notch faces and in the crack connected to them (traced
//! through the pores it opens, the faces of the bond network), failure when that crack has
//! grown 2 m beyond the tip.
//!
//! Checks (seeds 1–3):
//! * linear elastic fracture mechanics: the apparent toughness `K = p_c √(π c)` of the
//!   two lengths agrees to ±20 % in the mean (measured 16.34 and 15.18 MPa√m: seeds 1–3
//!   20.3, 10.6, 18.1 at c = 3 m and 9.5, 14.6, 21.5 at c = 6 m; the characteristic
//!   length `ℓ = (K/σ_t)²/π` is 6.7 m = 6.7 r_max with the recipe's σ_t = 3.44 MPa), so
//!   the longer notch fails at about `1/√2` of the shorter's pressure;
//! * the crack rule matters: with cracks joined through shared disks (the scenes'
//!   default) the c = 3 m notch of seed 1 needs more than 1.2 times the pressure
//!   (measured 8.97 against 6.62 MPa, 268 against 103 broken bonds): its crack is split
//!   at pores of four or more disks and the pressure stops there.

use porofrac_lsm::calibrate::scene_rock;
use porofrac_lsm::toughness::{NotchRamp, griffith_toughness, pressurised_notch};
use porofrac_lsm::{CrackFaces, LsmSpec};
use porofrac_particles::{Disks, RandomPacking, Region};

const RADIUS: f64 = 28.0;

fn spec() -> LsmSpec {
    scene_rock(0.2).unwrap()
}

fn disks(seed: u64) -> Disks {
    let p = RandomPacking::new([-RADIUS; 2], [RADIUS; 2], 0.1, 1.0, 0.8, seed)
        .generate_in(
            &Region::Disk {
                centre: [0.0; 2],
                radius: RADIUS,
            },
            &[],
        )
        .unwrap();
    Disks::new(&p.centres, &p.radii, 2600.0).unwrap()
}

fn failure(seed: u64, c: f64, across_pores: bool) -> f64 {
    let ramp = NotchRamp {
        rate: 2.5e6,
        alpha: 0.7,
        dt_fraction: 0.5,
        growth: 2.0,
        max_pressure: 20e6,
        faces: CrackFaces::BondWidth,
        across_pores,
    };
    let t = pressurised_notch(disks(seed), spec(), [0.0; 2], c, &ramp).unwrap();
    eprintln!(
        "seed {seed}, c = {c} m, across pores {across_pores}: {} bonds cut, first break \
         {:.3} MPa, failure {:.3} MPa, K {:.3} MPa√m, {} broken",
        t.cut,
        t.first_break / 1e6,
        t.failure / 1e6,
        griffith_toughness(t.failure, c) / 1e6,
        t.broken
    );
    assert!(t.first_break <= t.failure && t.tensile <= t.broken);
    t.failure
}

#[test]
fn a_pressurised_notch_gives_one_toughness_for_two_lengths() {
    let mean_k = |c: f64| {
        (1..=3u64)
            .map(|seed| griffith_toughness(failure(seed, c, true), c))
            .sum::<f64>()
            / 3.0
    };
    let (k3, k6) = (mean_k(3.0), mean_k(6.0));
    eprintln!(
        "K_Ic: {:.3} MPa√m (c = 3 m), {:.3} (c = 6 m)",
        k3 / 1e6,
        k6 / 1e6
    );
    assert!((k3 / k6 - 1.0).abs() < 0.2, "{k3} vs {k6}");
    // more than the strength alone gives a notch of a few grains (σ_t √(π r_max) =
    // 6.1 MPa√m for one largest radius), and ℓ below the disk's radius 28 m (K < 33 MPa√m)
    assert!(k3 > 3.44e6 * (std::f64::consts::PI * 1.0).sqrt(), "{k3}");
    assert!(k3 < 3.44e6 * (std::f64::consts::PI * RADIUS).sqrt(), "{k3}");
}

#[test]
fn a_crack_that_stops_at_pores_needs_more_pressure() {
    let joined = failure(1, 3.0, true);
    let split = failure(1, 3.0, false);
    assert!(split > 1.2 * joined, "{split} vs {joined}");
}
