//! Calibration of random packings against the hexagonal-lattice closed form: the recipe
//! of `scenes/lsm/borehole_dry.toml` (springs set for E = 10 GPa, ν = 0.2 by the
//! hexagonal closed form, σ_t = 5 MPa, c = 10 MPa, φ = 30°, radii 0.1–1 m, packing
//! fraction 0.8, bond tolerance 0.05), measured as `[bonds] calibrate = true` measures it
//! (uniaxial compression of a box to ε = 1e-3 for E and ν, a Brazilian test of a disk
//! for σ_t), over five packings and two sample sizes (box side 20 and 40 r_max,
//! Brazilian disk radius 10 and 20 r_max; the first is what the scene measures, smaller
//! samples do not relax to a packing and give a meaningless Brazilian peak).
//!
//! The gate (E within ±20 % of the closed form, ν within ±0.1 of it, on every packing)
//! is missed: a random packing bonds each disk to about 4 neighbours, not 6, and relaxes
//! non-affinely, so its E is about half the hexagonal lattice's and its ν scatters far
//! above it. The test stays ignored with its numbers printed (run with `--ignored
//! --nocapture`; the table is in docs/models/lsm.md).

use porofrac_lsm::calibrate::{
    QuasiStatic, brazilian, hexagonal_moduli, hexagonal_springs, uniaxial,
};
use porofrac_lsm::{BondLaw, LsmSpec};
use porofrac_particles::packing::Region;
use porofrac_particles::{Disks, RandomPacking};

const RHO: f64 = 2600.0;
const R: [f64; 2] = [0.1, 1.0];

fn spec() -> LsmSpec {
    let (kn, ks) = hexagonal_springs(10.0e9, 0.2).unwrap();
    let phi = 30f64.to_radians();
    let mut s = LsmSpec::new(BondLaw {
        kn,
        ks,
        kb: 0.0,
        tensile: 5.0e6,
        cohesion: 10.0e6,
        friction_angle: phi,
    });
    s.bond_tolerance = 0.05;
    s
}

fn packing(region: &Region, seed: u64) -> Disks {
    let (lo, hi) = region.bounds();
    let p = RandomPacking::new(lo, hi, R[0], R[1], 0.8, seed)
        .generate_in(region, &[])
        .unwrap();
    Disks::new(&p.centres, &p.radii, RHO).unwrap()
}

/// Mean and standard deviation.
fn stats(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let s = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    (m, s)
}

#[test]
#[ignore = "misses the gate: a random packing's E is about half the hexagonal closed form, its ν scatters (numbers in docs/models/lsm.md)"]
fn random_packings_calibrate_like_the_hexagonal_closed_form() {
    let spec = spec();
    let (e_hex, nu_hex) = hexagonal_moduli(spec.bonds.kn, spec.bonds.ks);
    let c = (e_hex / RHO).sqrt();
    let mut misses = Vec::new();
    for size in [20.0, 40.0] {
        let (mut es, mut nus, mut sts) = (Vec::new(), Vec::new(), Vec::new());
        for seed in 1..=5u64 {
            let side = size * R[1];
            let boxed = packing(
                &Region::Box {
                    lo: [0.0; 2],
                    hi: [side; 2],
                },
                seed,
            );
            let q = QuasiStatic {
                speed: 2e-4 * c,
                ..QuasiStatic::new(1.0)
            };
            let u = match uniaxial(boxed, spec, 1e-3, &q) {
                Ok(u) => u,
                Err(e) => {
                    eprintln!("size {size:>4} r_max seed {seed}: uniaxial: {e}");
                    misses.push((size, seed, f64::NAN, f64::NAN));
                    continue;
                }
            };
            let rad = 0.5 * size * R[1];
            let disk = packing(
                &Region::Disk {
                    centre: [0.0; 2],
                    radius: rad,
                },
                seed,
            );
            let q = QuasiStatic {
                speed: 2e-5 * c,
                ..QuasiStatic::new(1.0)
            };
            let b = match brazilian(disk, spec, 2.0 * R[1], &q) {
                Ok(b) => b,
                Err(e) => {
                    eprintln!("size {size:>4} r_max seed {seed}: Brazilian: {e}");
                    misses.push((size, seed, u.e / e_hex, u.nu));
                    continue;
                }
            };
            eprintln!(
                "size {size:>4} r_max seed {seed}: E {:.3e} Pa ({:.3} of the closed form), \
                 ν {:.3} (closed form {nu_hex:.3}), σ_t {:.3e} Pa",
                u.e,
                u.e / e_hex,
                u.nu,
                b.tensile_strength
            );
            if (u.e / e_hex - 1.0).abs() > 0.2 || (u.nu - nu_hex).abs() > 0.1 {
                misses.push((size, seed, u.e / e_hex, u.nu));
            }
            es.push(u.e);
            nus.push(u.nu);
            sts.push(b.tensile_strength);
        }
        if es.len() < 2 {
            continue;
        }
        let (e, se) = stats(&es);
        let (nu, snu) = stats(&nus);
        let (st, sst) = stats(&sts);
        eprintln!(
            "size {size:>4} r_max: E {e:.3e} ± {se:.2e} Pa ({:.3} of {e_hex:.3e}), \
             ν {nu:.3} ± {snu:.3}, σ_t {st:.3e} ± {sst:.2e} Pa",
            e / e_hex
        );
    }
    assert!(
        misses.is_empty(),
        "packings off the closed form (size, seed, E/E_hex, ν): {misses:?}"
    );
}
