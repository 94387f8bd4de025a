//! Uniaxial calibration of random packings of the borehole scenes' recipe (radii 0.1–1 m
//! uniform, packing fraction 0.8, bond tolerance 0.05, σ_t = 5 MPa, c = 10 MPa, φ = 30°,
//! no bending spring, contacts μ = 0.6) with the springs of the hexagonal lattice set for
//! E = 10 GPa and a Poisson's ratio ν_set: E and ν of boxes of several sizes and seeds,
//! measured on the core (affine fit, the result of `calibrate::uniaxial`) and at the
//! boundary (platen travel, side disks), as `[bonds] calibrate = true` loads them
//! (ε_yy = 1e-4, platens at 2e-4 of the lattice wave speed, local damping 0.7).
//!
//! `cargo run --release -p porofrac-lsm --example calibration_study -- [SIDE ...]
//! [--seeds N] [--nu NU_SET]` (box sides in largest radii, default 20 30 40; 5 seeds;
//! ν_set 0.2). Prints one row per (side, seed) and the mean and standard deviation per
//! side.

use porofrac_lsm::calibrate::{QuasiStatic, hexagonal_moduli, scene_rock, uniaxial};
use porofrac_particles::{Disks, RandomPacking, Region};

fn stats(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let s = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    (m, s)
}

fn main() {
    let mut sides = Vec::new();
    let mut seeds = 5u64;
    let mut nu_set = 0.2;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seeds" => seeds = args.next().and_then(|v| v.parse().ok()).expect("--seeds N"),
            "--nu" => nu_set = args.next().and_then(|v| v.parse().ok()).expect("--nu NU"),
            _ => sides.push(a.parse::<f64>().expect("a box side (largest radii)")),
        }
    }
    if sides.is_empty() {
        sides = vec![20.0, 30.0, 40.0];
    }
    let (r0, r1, rho) = (0.1, 1.0, 2600.0);
    let spec = scene_rock(nu_set).expect("springs");
    let (kn, ks) = (spec.bonds.kn, spec.bonds.ks);
    let (e_hex, nu_hex) = hexagonal_moduli(kn, ks);
    let c = (e_hex / rho).sqrt();
    let q = QuasiStatic {
        speed: 2e-4 * c,
        ..QuasiStatic::new(1.0)
    };
    println!(
        "side_rmax\tseed\tdisks\tcore\tE/E_hex\tnu\tE_platens/E_hex\tnu_sides\tsteps\tbroken\tseconds"
    );
    for &side in &sides {
        let (mut es, mut nus) = (vec![], vec![]);
        for seed in 1..=seeds {
            let t0 = std::time::Instant::now();
            let l = side * r1;
            let p = RandomPacking::new([0.0; 2], [l; 2], r0, r1, 0.8, seed)
                .generate_in(
                    &Region::Box {
                        lo: [0.0; 2],
                        hi: [l; 2],
                    },
                    &[],
                )
                .expect("packing");
            let disks = Disks::new(&p.centres, &p.radii, rho).expect("disks");
            let n = disks.len();
            match uniaxial(disks, spec, 1e-4, &q) {
                Ok(u) => {
                    println!(
                        "{side}\t{seed}\t{n}\t{}\t{:.4}\t{:.4}\t{:.4}\t{:.4}\t{}\t{}\t{:.1}",
                        u.core,
                        u.e / e_hex,
                        u.nu,
                        u.e_platens / e_hex,
                        u.nu_sides,
                        u.steps,
                        u.broken,
                        t0.elapsed().as_secs_f64()
                    );
                    es.push(u.e / e_hex);
                    nus.push(u.nu);
                }
                Err(e) => println!("{side}\t{seed}\t{n}\t{e}"),
            }
        }
        let (e, se) = stats(&es);
        let (nu, snu) = stats(&nus);
        println!(
            "# side {side}: E/E_hex {e:.4} ± {se:.4}, ν {nu:.4} ± {snu:.4} (hexagonal ν {nu_hex:.3}, {} packings)",
            es.len()
        );
    }
}
