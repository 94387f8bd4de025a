//! Random packings: the Brazilian test reports a tensile strength, and a pressurised
//! borehole in a bonded disk (b = 10 m, a = 2 m, radii 0.2–0.5 m, dry: the pressure as
//! wall forces, ramped over 40 wave crossings) initiates fracture near
//! `p_b = σ_t (b² − a²)/(b² + a²)` (Lamé's thick cylinder with the tensile strength at the
//! hole), with the first crack at the borehole wall. σ_t is the material's: the mean of the
//! Brazilian tests of five packings of the same disk without its hole (caps one largest
//! diameter thick). Initiation is the pressure of the first broken bond; the pressure at
//! ten broken bonds (a crack a few grains long) is printed too.

use porofrac_lsm::calibrate::{QuasiStatic, brazilian, hexagonal_springs};
use porofrac_lsm::{BondLaw, Damping, LatticeSolid, LsmSpec};
use porofrac_particles::packing::{Hole, Region};
use porofrac_particles::{Disks, RandomPacking};

const RHO: f64 = 2600.0;
const E: f64 = 10e9;

fn law() -> BondLaw {
    let (kn, ks) = hexagonal_springs(E, 0.2).unwrap();
    BondLaw {
        kn,
        ks,
        kb: 0.05 * kn * 0.35f64.powi(2),
        tensile: 5e6,
        cohesion: 10e6,
        friction_angle: 30f64.to_radians(),
    }
}

fn sample(radius: f64, hole: Option<f64>, seed: u64) -> Disks {
    let spec = RandomPacking::new([-radius, -radius], [radius, radius], 0.2, 0.5, 0.8, seed);
    let holes: Vec<Hole> = hole
        .map(|a| Hole {
            centre: [0.0; 2],
            radius: a,
        })
        .into_iter()
        .collect();
    let p = spec
        .generate_in(
            &Region::Disk {
                centre: [0.0; 2],
                radius,
            },
            &holes,
        )
        .unwrap();
    Disks::new(&p.centres, &p.radii, RHO).unwrap()
}

fn spec() -> LsmSpec {
    let mut s = LsmSpec::new(law());
    s.bond_tolerance = 0.05;
    s
}

fn wave_speed() -> f64 {
    (E / RHO).sqrt()
}

/// σ_t of the Brazilian test of a disk of radius 10 m (the borehole sample without
/// its hole).
fn brazilian_strength(seed: u64) -> f64 {
    let q = QuasiStatic {
        speed: 2e-5 * wave_speed(),
        ..QuasiStatic::new(1.0)
    };
    let r = brazilian(sample(10.0, None, seed), spec(), 1.0, &q).unwrap();
    assert!(r.broken > 0 && r.peak_force > 0.0);
    r.tensile_strength
}

/// Breakdown of a disk of radius b = 10 m with a hole of radius a = 2 m under a slow
/// pressure ramp: the pressures at the first break and at the 10th, and the distance of
/// the first break from the hole centre.
fn borehole(seed: u64, p_scale: f64) -> (f64, f64, f64) {
    let (a, b) = (2.0, 10.0);
    let mut sp = spec();
    sp.damping = Damping::Local { alpha: 0.7 };
    let mut s = LatticeSolid::new(sample(b, Some(a), seed), sp).unwrap();
    let w = s.add_pressure_wall([0.0; 2], a).unwrap();
    let dt = 0.5 * s.stable_dt();
    // Reach p_scale in 40 wave crossings of the disk.
    let rate = p_scale / (40.0 * 2.0 * b / wave_speed());
    let mut first = None;
    for k in 1..2_000_000 {
        let p = rate * k as f64 * dt;
        s.set_wall_pressure(w, p).unwrap();
        s.step(dt, &[]).unwrap();
        let nb = s.broken().len();
        if nb > 0 && first.is_none() {
            let bb = s.broken()[0];
            first = Some((p, (bb.x * bb.x + bb.y * bb.y).sqrt()));
        }
        if nb >= 10 {
            let (p1, r1) = first.unwrap();
            return (p1, p, r1);
        }
    }
    panic!("no breakdown");
}

#[test]
fn borehole_breaks_down_near_the_thick_cylinder_estimate() {
    let (a, b): (f64, f64) = (2.0, 10.0);
    let factor = (b * b - a * a) / (b * b + a * a);
    // The material's tensile strength: the mean of the Brazilian tests of five packings.
    let strengths: Vec<f64> = (1..=5u64).map(brazilian_strength).collect();
    let st = strengths.iter().sum::<f64>() / 5.0;
    let pb = st * factor;
    eprintln!("Brazilian sigma_t {strengths:?}: mean {st:.4e} Pa, p_b {pb:.4e} Pa");
    let mut ratios = Vec::new();
    for seed in 1..=5u64 {
        let (p_first, p10, r_first) = borehole(seed, pb);
        eprintln!(
            "seed {seed}: first break at {p_first:.4e} Pa = {:.3} p_b (r = {r_first:.2} m), 10 breaks at {p10:.4e} Pa = {:.3} p_b",
            p_first / pb,
            p10 / pb
        );
        // Initiation (fracture should initiate near p_b): the first break.
        ratios.push(p_first / pb);
        // The first crack starts at the borehole wall (within two largest diameters).
        assert!(
            r_first < a + 2.0,
            "seed {seed}: first break at r = {r_first}"
        );
    }
    let mean = ratios.iter().sum::<f64>() / 5.0;
    eprintln!("initiation / p_b: {ratios:.3?}, mean {mean:.3}");
    for (k, r) in ratios.iter().enumerate() {
        assert!(
            (r - 1.0).abs() < 0.2,
            "packing {}: initiation at {r:.3} p_b",
            k + 1
        );
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut s = LatticeSolid::new(sample(30.0, Some(3.0), 11), spec()).unwrap();
            assert!(s.bonds().len() > 8192, "large enough for the parallel path");
            let w = s.add_pressure_wall([0.0; 2], 3.0).unwrap();
            s.set_wall_pressure(w, 2e7).unwrap();
            let dt = 0.5 * s.stable_dt();
            for _ in 0..300 {
                s.step(dt, &[]).unwrap();
            }
            (
                s.disks().x.clone(),
                s.disks().omega.clone(),
                s.broken().to_vec(),
            )
        })
    };
    let (a, b) = (run(1), run(2));
    assert!(!a.2.is_empty(), "some bonds broke");
    assert_eq!(a, b);
}
