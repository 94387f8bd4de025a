//! Fluid in the cracks narrower than the lattice in a lattice solid scene
//! (`[injection] crack_flow = true`): the borehole rock of `lsm_hydrofrac.rs` (b = 8 m,
//! a = 1.5 m, radii 0.1–0.5 m, Δx = 0.05 m), fluid injected into the hole, the broken bonds
//! carrying the fluid by the cubic law of a water-like crack fluid (ν = 1e-6 m²/s).
//!
//! Checks: every broken bond is a channel of the network (`summary.json`
//! `crack_flow.channels` = rows of `broken.csv`); the network's books balance (pores −
//! their initial content + what they gave the lattice = 0 to 1e-12 of the mass moved);
//! the wall crack carries the hole's pressure (the largest channel pressure within
//! [0.5, 1.05] of the injection pressure at the end); the first break is tensile and at
//! the wall (within three largest radii of it); the fluid share of the step time is
//! reported; the run goes on past the one-node pockets that the dilating rock stretched
//! through zero density (it used to stop at 0.36 s). Bad keys are errors naming the key.
//! The ±20 % breakdown acceptance is an ignored test with its numbers.

use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Scene, Silent};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-lsmcf-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const SCENE: &str = r#"
[scene]
name = "cf"
dim = 2
model = "lsm"

[particles]
kind = "random"
disk = { center = [0.0, 0.0], radius = 8.0 }
hole = { center = [0.0, 0.0], radius = 1.5 }
radius = [0.1, 0.5]
packing_fraction = 0.8
seed = 1
density = 2600.0

[bonds]
youngs_modulus = 10.0e9
poisson_ratio = 0.2
tensile_strength = 5.0e6
cohesion = 10.0e6
friction_angle = 30.0
tolerance = 0.05
calibrate = true

[[output.probe]]
name = "pressure"
field = "pressure"

[lsm]
damping = "local"
seal_bonds = true

[lbm]
extent = [[-8.5, -8.5], [8.5, 8.5]]
spacing = 0.05
density = 1000.0
viscosity = 0.76
tau = 0.6

[schedule]
end_time = 0.2
steps = 10

[injection]
pressure = 12.0e6
ramp_time = 0.5
"#;

const CRACK: &str = "crack_flow = true\ncrack_viscosity = 1.0e-6\n";

fn error_of(text: &str) -> String {
    match Scene::parse(text, Path::new("cf.toml"), LawRegistry::default()) {
        Err(e) => e.to_string(),
        Ok(scene) => scene.run(&tmp("bad"), &mut Silent).unwrap_err().to_string(),
    }
}

#[test]
fn bad_crack_flow_keys_are_named() {
    for (extra, want) in [
        (
            "crack_min_aperture = 1.0e-4\n",
            "applies with crack_flow = true only",
        ),
        (
            "crack_flow = true\ncrack_min_aperture = 0.0\n",
            "must be a positive number",
        ),
        (
            "crack_flow = true\ncrack_viscosity = -1.0\n",
            "must be a positive number",
        ),
        (
            "crack_flow = true\ncrack_min_aperture = 0.05\n",
            "is not below lbm.spacing",
        ),
    ] {
        let e = error_of(&format!("{SCENE}{extra}"));
        let key = extra.lines().last().unwrap().split(' ').next().unwrap();
        assert!(e.contains(want), "{extra}: {e}");
        assert!(e.contains(&format!("injection.{key}")), "{extra}: {e}");
        // the key's line in the file (1-based)
        let line = SCENE.lines().count() + extra.lines().count();
        assert!(e.contains(&format!("{line}")), "{extra}: {e}");
    }
}

/// Run the scene with `extra` in `[injection]`: its summary and the radii from the hole
/// centre and modes of `broken.csv`.
fn run(name: &str, extra: &str, end: f64) -> (serde_json::Value, Vec<(f64, String)>) {
    let out = tmp(name);
    let text =
        format!("{SCENE}{extra}").replace("end_time = 0.2\n", &format!("end_time = {end}\n"));
    let scene = Scene::parse(&text, Path::new("cf.toml"), LawRegistry::default()).unwrap();
    scene.run(&out, &mut Silent).unwrap();
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let rows = std::fs::read_to_string(out.join("broken.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let (x, y): (f64, f64) = (f[3].parse().unwrap(), f[4].parse().unwrap());
            (x.hypot(y), f[5].to_string())
        })
        .collect();
    let _ = std::fs::remove_dir_all(&out);
    (s, rows)
}

#[test]
fn broken_bonds_carry_the_hole_fluid_and_the_books_balance() {
    let (s, breaks) = run("run", CRACK, 0.2);
    let c = &s["crack_flow"];
    let f = &s["fluid"];
    eprintln!(
        "crack flow {c}; initiation {} Pa, p_b {} Pa, injection {} Pa; fluid share {}; first \
         breaks {:?}",
        s["initiation_pressure"],
        s["calibration"]["breakdown_estimate"],
        s["injection"]["pressure"],
        f["fluid_share"],
        &breaks[..breaks.len().min(5)]
    );
    assert!(breaks.len() >= 3, "{} breaks", breaks.len());
    assert_eq!(c["channels"].as_u64().unwrap() as usize, breaks.len());
    let moved = c["created_mass"].as_f64().unwrap().abs()
        + c["to_lattice_mass"].as_f64().unwrap().abs()
        + c["pore_mass"].as_f64().unwrap().abs();
    assert!(
        c["mass_defect"].as_f64().unwrap().abs() <= 1e-12 * moved.max(1e-300),
        "{c}"
    );
    let p = s["injection"]["pressure"].as_f64().unwrap();
    let p_crack = c["max_pressure"].as_f64().unwrap();
    assert!(
        (0.5..1.05).contains(&(p_crack / p)),
        "crack {p_crack} vs hole {p}"
    );
    let (a, r_max) = (1.5, 0.5);
    assert!(
        breaks[0].0 < a + 3.0 * r_max,
        "first break at {}",
        breaks[0].0
    );
    assert_eq!(breaks[0].1, "tensile");
    let share = f["fluid_share"].as_f64().unwrap();
    let (fs, ps) = (
        f["fluid_seconds"].as_f64().unwrap(),
        f["particle_seconds"].as_f64().unwrap(),
    );
    assert!((share - fs / (fs + ps)).abs() < 1e-12);
    assert!(c["seconds"].as_f64().unwrap() <= fs);
}

/// The rock dilates as it cracks: past its breakdown (0.27 s) disks move apart around
/// fluid nodes they enclose alone, and the moving-wall bounce-back drains such a node in
/// proportion to the walls' speed, not to its mass. The run used to stop at t = 0.36 s
/// with "the flow diverged" on a node at r = 7.25 m with eight solid neighbours, its
/// density falling by about 4e-4 per step through zero. The one-node pockets are now kept
/// at half the reference density or above (`crack_flow.pocket_steps`, `pocket_mass`): the
/// run reaches 0.4 s, and its breakdown is unchanged (6.485 MPa, as before).
#[test]
fn the_crack_flow_run_goes_past_the_pockets_that_stopped_it() {
    let (s, breaks) = run("pockets", CRACK, 0.4);
    let c = &s["crack_flow"];
    eprintln!(
        "status {}, breakdown {} Pa, crack flow {c}",
        s["status"], s["breakdown_pressure"]
    );
    assert_eq!(s["status"], "ok");
    assert!(c["pocket_steps"].as_u64().unwrap() > 0, "{c}");
    assert!(c["pocket_mass"].as_f64().unwrap() > 0.0, "{c}");
    assert_eq!(c["channels"].as_u64().unwrap() as usize, breaks.len());
    let p_bd = s["breakdown_pressure"].as_f64().unwrap();
    assert!((p_bd / 6.485e6 - 1.0).abs() < 1e-3, "{p_bd}");
}

/// The acceptance of the thick-walled cylinder estimate with the fluid in the cracks:
/// breakdown (the wall crack reaching 2a) within ±20 % of p_b, Brazilian-calibrated σ_t.
/// Measured on this packing (run to 0.3 s): 6.485 MPa against p_b = 3.144 MPa, 2.06 p_b
/// (1.48 p_b without the crack flow, `lsm_hydrofrac.rs`); the wall crack reaches 5.15 m
/// by 0.3 s. The bundled rock (`scenes/lsm_hydrofrac.toml`, b = 22 m) over five packings
/// (docs/BENCHMARKS.md): 1.396, 1.176, 1.350, 0.815, 0.714 p_b (1.09 ± 0.31, 2 of 5 within
/// ±20 %), initiation 0.45–0.52 p_b, tensile, at the wall in one packing only: the hole's
/// fluid fills pockets of the rock's open pore space 2.5 m behind the wall
/// (`porofrac-particle-fluid` test `reach`) and the bonds behind them break first. The same
/// packings loaded dry at the same ramp (24 MPa/s) with the pressure in the wall crack:
/// on the wetted faces 0.965, 1.220, 1.884, 0.759, 0.662 p_b (1.10 ± 0.49, 1 of 5), on the
/// faces seen from the centre 1.507, 1.684, 2.371, 0.892, 1.710 (1.63 ± 0.53, 1 of 5),
/// against 1.09 ± 0.10 (4 of 5) for the latter at 2.5 MPa/s: the fluid run misses as its
/// dry analogues do at its ramp, and a rock open to the hole breaks inside first.
#[test]
#[ignore = "misses: 2.06 p_b on this packing; the bundled rock 1.09 ± 0.31 p_b, 2 of 5 packings within ±20 %, initiation at the wall in 1 of 5"]
fn breakdown_with_crack_flow_is_within_twenty_percent_of_the_thick_cylinder_estimate() {
    let (s, _) = run("gate", CRACK, 0.3);
    let p_b = s["calibration"]["breakdown_estimate"].as_f64().unwrap();
    let p_bd = s["breakdown_pressure"].as_f64();
    eprintln!(
        "breakdown {p_bd:?} Pa, p_b {p_b} Pa, ratio {:?}; extent at the end {} m; {}",
        p_bd.map(|p| p / p_b),
        s["crack_extent"],
        s["crack_flow"]
    );
    let p_bd = p_bd.expect("breakdown reached");
    assert!((p_bd / p_b - 1.0).abs() < 0.2, "{p_bd} vs p_b {p_b}");
}
