//! Fracture toughness of the packing recipe of the borehole scenes (radii 0.1–1 m
//! uniform, scaled by `--rmax`; packing fraction 0.8, E = 10 GPa, ν = 0.2 by the hexagonal
//! closed form, bond σ_t = 5 MPa, c = 10 MPa, φ = 30°, no bending spring, bond tolerance
//! 0.05, contacts μ = 0.6, local damping 0.7): a notch of half-length c cut through the
//! centre of a disk of radius `--radius` (default 4 c_max + 4 r_max), the pressure ramped
//! on its faces and in the crack that grows from it ([`porofrac_lsm::toughness`]), failure
//! when that crack has grown by `--growth` (default 2 r_max) beyond the notch tip;
//! `K_Ic = p_c √(π c)`.
//!
//! `cargo run --release -p porofrac-lsm --example notch_toughness -- C... [--seeds N]
//! [--rmax R] [--rate PA_PER_S] [--radius M] [--growth M] [--radical]` (default c = 3 6,
//! 3 seeds, r_max 1 m, 2.5 MPa/s; `--radical`: flooded bonds load their power-diagram
//! face, [`porofrac_lsm::FaceWidths`], instead of the bond width; `--pores`: the crack is traced
//! through the faces of the bond network, [`porofrac_lsm::CrackExtent::across_pores`]). One row per (c, seed); the mean and sd of K_Ic per c.

use porofrac_lsm::CrackFaces;
use porofrac_lsm::calibrate::scene_rock;
use porofrac_lsm::toughness::{NotchRamp, griffith_toughness, pressurised_notch};
use porofrac_particles::{Disks, RandomPacking, Region};

fn main() {
    let mut cs = Vec::new();
    let (mut seeds, mut r1, mut rate) = (3u64, 1.0, 2.5e6);
    let (mut radius, mut growth): (Option<f64>, Option<f64>) = (None, None);
    let mut faces = CrackFaces::BondWidth;
    let mut pores = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut num = |name: &str| -> f64 {
            args.next()
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("{name} needs a number"))
        };
        match a.as_str() {
            "--seeds" => seeds = num("--seeds") as u64,
            "--rmax" => r1 = num("--rmax"),
            "--rate" => rate = num("--rate"),
            "--radius" => radius = Some(num("--radius")),
            "--growth" => growth = Some(num("--growth")),
            "--radical" => faces = CrackFaces::Radical,
            "--pores" => pores = true,
            _ => cs.push(a.parse::<f64>().expect("a notch half-length (m)")),
        }
    }
    if cs.is_empty() {
        cs = vec![3.0, 6.0];
    }
    let cmax = cs.iter().copied().fold(0.0, f64::max);
    let radius = radius.unwrap_or(4.0 * cmax + 4.0 * r1);
    let growth = growth.unwrap_or(2.0 * r1);
    let spec = scene_rock(0.2).expect("springs");
    let ramp = NotchRamp {
        rate,
        alpha: 0.7,
        dt_fraction: 0.5,
        growth,
        max_pressure: 100e6,
        faces,
        across_pores: pores,
    };
    println!(
        "# disk radius {radius} m, r_max {r1} m, growth {growth} m, rate {:.3} MPa/s, faces {faces:?}, across pores {pores}",
        rate / 1e6
    );
    println!(
        "c_m\tseed\tdisks\tcut\tcut_extent_m\tface_load/2c\tfirst_MPa\tfailure_MPa\tK_MPa_sqrt_m\tbroken\ttensile\tseconds"
    );
    for &c in &cs {
        let mut ks = Vec::new();
        for seed in 1..=seeds {
            let t0 = std::time::Instant::now();
            let p = RandomPacking::new([-radius; 2], [radius; 2], 0.1 * r1, r1, 0.8, seed)
                .generate_in(
                    &Region::Disk {
                        centre: [0.0; 2],
                        radius,
                    },
                    &[],
                )
                .expect("packing");
            let disks = Disks::new(&p.centres, &p.radii, 2600.0).expect("disks");
            let n = disks.len();
            let t = pressurised_notch(disks, spec, [0.0; 2], c, &ramp).expect("notch test");
            let k = griffith_toughness(t.failure, c);
            ks.push(k);
            println!(
                "{c}\t{seed}\t{n}\t{}\t{:.3}\t{:.3}\t{:.3}\t{:.3}\t{:.3}\t{}\t{}\t{:.1}",
                t.cut,
                t.cut_extent,
                t.face_load / (2.0 * c),
                t.first_break / 1e6,
                t.failure / 1e6,
                k / 1e6,
                t.broken,
                t.tensile,
                t0.elapsed().as_secs_f64()
            );
        }
        let m = ks.iter().sum::<f64>() / ks.len() as f64;
        let sd =
            (ks.iter().map(|k| (k - m).powi(2)).sum::<f64>() / (ks.len().max(2) - 1) as f64).sqrt();
        println!("# c = {c} m: K_Ic {:.3} ± {:.3} MPa√m", m / 1e6, sd / 1e6);
    }
}
