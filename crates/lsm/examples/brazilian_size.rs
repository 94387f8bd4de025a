//! Size effect of the Brazilian test on the packing recipe of the borehole scenes (radii
//! 0.1–1 m uniform, packing fraction 0.8, E = 10 GPa, ν = 0.2, bond σ_t = 5 MPa,
//! c = 10 MPa, φ = 30°, no bending spring, bond tolerance 0.05, contacts μ = 0.6): the
//! splitting strength `F/(πR)` of disks of radius R for several seeds, with the settings
//! of the scenes' calibration (caps one largest diameter thick, platens at 2e-5 of the
//! lattice wave speed, local damping 0.7).
//!
//! `cargo run --release -p porofrac-lsm --example brazilian_size -- [R ...] [--seeds N]
//! [--cap-fraction F]` (default R = 10 15 22, 3 seeds, caps 2 m thick; with F the caps are
//! F·R thick). Prints one row per (R, seed) and the mean per R.

use porofrac_lsm::Damping;
use porofrac_lsm::calibrate::{QuasiStatic, brazilian, hexagonal_moduli, scene_rock};
use porofrac_particles::{Disks, RandomPacking, Region};

fn main() {
    let mut sizes = Vec::new();
    let mut seeds = 3u64;
    let mut cap_fraction: Option<f64> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--cap-fraction" {
            cap_fraction = args.next().and_then(|v| v.parse().ok());
            assert!(cap_fraction.is_some(), "--cap-fraction F");
        } else if a == "--seeds" {
            seeds = args.next().and_then(|v| v.parse().ok()).expect("--seeds N");
        } else {
            sizes.push(a.parse::<f64>().expect("a radius (m)"));
        }
    }
    if sizes.is_empty() {
        sizes = vec![10.0, 15.0, 22.0];
    }
    let (r0, r1, rho) = (0.1, 1.0, 2600.0);
    let mut spec = scene_rock(0.2).expect("springs");
    let (kn, ks) = (spec.bonds.kn, spec.bonds.ks);
    spec.damping = Damping::Local { alpha: 0.7 };
    let c = (hexagonal_moduli(kn, ks).0 / rho).sqrt();
    let q = QuasiStatic {
        speed: 2e-5 * c,
        ..QuasiStatic::new(1.0)
    };
    println!("R_m\tseed\tdisks\tpeak_MN_per_m\tsigma_t_MPa\tbroken\tseconds");
    for &radius in &sizes {
        let mut sum = 0.0;
        for seed in 1..=seeds {
            let t0 = std::time::Instant::now();
            let p = RandomPacking::new([-radius; 2], [radius; 2], r0, r1, 0.8, seed)
                .generate_in(
                    &Region::Disk {
                        centre: [0.0; 2],
                        radius,
                    },
                    &[],
                )
                .expect("packing");
            let disks = Disks::new(&p.centres, &p.radii, rho).expect("disks");
            let n = disks.len();
            let cap = cap_fraction.map_or(2.0 * r1, |f| f * radius);
            let b = brazilian(disks, spec, cap, &q).expect("brazilian test");
            sum += b.tensile_strength;
            println!(
                "{radius}\t{seed}\t{n}\t{:.2}\t{:.3}\t{}\t{:.1}",
                b.peak_force / 1e6,
                b.tensile_strength / 1e6,
                b.broken,
                t0.elapsed().as_secs_f64()
            );
        }
        println!(
            "# R = {radius} m: mean sigma_t {:.3} MPa",
            sum / seeds as f64 / 1e6
        );
    }
}
