//! Lattice Boltzmann obstacles at the edges of the lattice, overlapping obstacles and
//! single-precision populations, through scene files.
//!
//! * A wall block overhanging the top of a Poiseuille channel (clipped to the lattice)
//!   gives the probes and the force of the same block cut at the side (to round-off), and
//!   the force is the wall shear `ρ a H L / 2` (per metre of depth) to 1 %.
//! * A disk at rest across the periodic side of the channel feels the force of the same
//!   disk in the middle (to 1e-9).
//! * Two obstacles that overlap are refused, naming both keys and the line of the first; a
//!   moving obstacle that runs into another stops the run with the same words.
//! * `precision = "single"`: the Poiseuille probe within 1e-5 of the double run's.

use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Scene, Silent};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-lbme-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn parse(text: &str) -> Result<Scene, String> {
    Scene::parse(text, Path::new("t.toml"), LawRegistry::default()).map_err(|e| e.to_string())
}

/// A channel 4 mm long (periodic) and 10 mm high, walls top and bottom, driven by a body
/// force; probes `u` (vx at mid-height of the lower part) and `fx` on obstacle "block".
const CHANNEL: &str = r#"
[scene]
name = "channel"
model = "lbm"
dim = 2

[lbm]
extent = [[0.0, 0.0], [0.004, 0.01]]
spacing = 1.0e-3
density = 1000.0
viscosity = 1.0e-6
tau = 0.8
collision = "trt"
periodic = ["x"]
body_force = [1.0e-5, 0.0]

[[lbm.boundary]]
side = "ymin"
kind = "wall"

[[lbm.boundary]]
side = "ymax"
kind = "wall"

[schedule]
end_time = 2000.0
steps = 2

[output]
vtk = false
plots = false

[[output.probe]]
name = "u"
field = "vx"
at = [0.0015, 0.0035]
"#;

/// The last row of `probes.csv` of a run of `text`.
fn last_probes(text: &str, name: &str) -> Vec<f64> {
    let out = tmp(name);
    parse(text).unwrap().run(&out, &mut Silent).unwrap();
    let csv = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    csv.lines()
        .last()
        .unwrap()
        .split(',')
        .skip(1)
        .map(|v| v.parse().unwrap())
        .collect()
}

fn with_block(block: &str) -> String {
    format!(
        "{CHANNEL}\n[[output.probe]]\nname = \"fx\"\nfield = \"fx\"\nobstacle = \"block\"\n\n\
         [[obstacle]]\nname = \"block\"\nshape = {{ box = {block} }}\n"
    )
}

#[test]
fn a_block_overhanging_the_top_is_the_block_cut_at_the_side() {
    let over = last_probes(&with_block("[[-0.002, 0.008], [0.007, 0.03]]"), "over");
    let cut = last_probes(&with_block("[[-0.002, 0.008], [0.007, 0.01]]"), "cut");
    // ρ a H L / 2 with H = 8 mm between the bottom wall and the block, L = 4 mm
    let shear = 1000.0 * 1.0e-5 * 0.008 * 0.004 / 2.0;
    eprintln!("overhanging {over:?}, cut {cut:?}, wall shear {shear:.6e} N/m");
    assert!(
        (over[0] - cut[0]).abs() <= 1e-12 * cut[0].abs(),
        "{over:?} {cut:?}"
    );
    assert!(
        (over[1] - cut[1]).abs() <= 1e-12 * cut[1].abs(),
        "{over:?} {cut:?}"
    );
    assert!(
        (over[1] / shear - 1.0).abs() < 1e-2,
        "{} vs {shear}",
        over[1]
    );
}

#[test]
fn a_disk_across_the_periodic_side_feels_the_force_of_one_in_the_middle() {
    let disk = |x: f64| {
        format!(
            "{CHANNEL}\n[[output.probe]]\nname = \"fx\"\nfield = \"fx\"\nobstacle = \"d\"\n\n\
             [[obstacle]]\nname = \"d\"\nshape = {{ circle = {{ center = [{x}, 0.0052], radius = 0.0017 }} }}\n"
        )
    };
    let across = last_probes(&disk(0.0003), "across");
    let middle = last_probes(&disk(0.0023), "middle");
    eprintln!("across {across:?}, middle {middle:?}");
    assert!(across[1] > 0.0);
    assert!((across[1] - middle[1]).abs() <= 1e-9 * middle[1].abs());
}

#[test]
fn overlapping_obstacles_are_refused_naming_both() {
    let text = format!(
        "{CHANNEL}\n[[obstacle]]\nname = \"a\"\nshape = {{ circle = {{ center = [0.002, 0.005], radius = 0.0015 }} }}\n\n\
         [[obstacle]]\nname = \"b\"\nshape = {{ box = [[0.003, 0.004], [0.0035, 0.006]] }}\n"
    );
    let e = parse(&text).unwrap_err();
    let line_a = text
        .lines()
        .position(|l| l.contains("radius = 0.0015"))
        .unwrap()
        + 1;
    let line_b = line_a + 4;
    assert!(e.starts_with(&format!("t.toml:{line_b}")), "{e}");
    assert!(
        e.contains("obstacle[1].shape")
            && e.contains(&format!(
                "overlaps obstacle[0].shape (\"a\", line {line_a})"
            )),
        "{e}"
    );
    // apart, or touching, is accepted; an image across the periodic side overlaps too
    assert!(
        parse(
            &text
                .replace("0.003, 0.004", "0.0035, 0.004")
                .replace("0.0035, 0.006", "0.0038, 0.006")
        )
        .is_ok()
    );
    let across = text
        .replace(
            "[[0.003, 0.004], [0.0035, 0.006]]",
            "[[0.0042, 0.004], [0.0045, 0.006]]",
        )
        .replace("center = [0.002, 0.005]", "center = [0.0005, 0.005]");
    let e = parse(&across).unwrap_err();
    assert!(e.contains("overlaps obstacle[0].shape"), "{e}");
}

#[test]
fn a_moving_obstacle_that_runs_into_another_stops_the_run() {
    let text = format!(
        "{CHANNEL}\n[[obstacle]]\nname = \"still\"\nshape = {{ circle = {{ center = [0.001, 0.005], radius = 0.0008 }} }}\n\n\
         [[obstacle]]\nname = \"mover\"\nshape = {{ circle = {{ center = [0.003, 0.005], radius = 0.0008 }} }}\n\
         velocity = [0.0, 0.0]\nangular_velocity = 0.0\n"
    )
    .replace("body_force = [1.0e-5, 0.0]", "body_force = [0.0, 0.0]");
    // at rest: the run ends normally
    let out = tmp("rest");
    parse(&text).unwrap().run(&out, &mut Silent).unwrap();
    // carried to the left at 1e-6 m/s: the gap of 0.4 mm closes after 400 s
    let moving = text.replace("velocity = [0.0, 0.0]", "velocity = [-1.0e-6, 0.0]");
    let out = tmp("moving");
    let e = parse(&moving)
        .unwrap()
        .run(&out, &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("obstacle[1].velocity")
            && e.contains("carries obstacle[1] (\"mover\") into obstacle[0] (\"still\""),
        "{e}"
    );
}

#[test]
fn single_precision_through_the_scene() {
    let double = last_probes(CHANNEL, "double");
    let single = last_probes(
        &CHANNEL.replace(
            "collision = \"trt\"",
            "collision = \"trt\"\nprecision = \"single\"",
        ),
        "single",
    );
    eprintln!("double {double:?}, single {single:?}");
    assert!(single[0] != double[0]);
    assert!((single[0] / double[0] - 1.0).abs() < 1e-5);
}
