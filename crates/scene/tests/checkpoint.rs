//! Checkpoint and resume: a run stopped after a step (as by Ctrl-C) and resumed, or
//! resumed from a periodic checkpoint, writes the same files as a run never stopped —
//! bit for bit: probes, lines, VTK files and series, the model's own tables, and the
//! numbers of `summary.json` other than times and memory. A checkpoint of another scene
//! is refused. Also: every series of a step carries the driver's time of that step.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Observer, Scene, Silent, StepReport};

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-ckpt-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Asks to stop once step `after` is reported (the driver stops after the next one).
struct StopAfter {
    after: usize,
    stop: bool,
}

impl Observer for StopAfter {
    fn step(&mut self, r: &StepReport) {
        if r.step >= self.after {
            self.stop = true;
        }
    }
    fn stop_requested(&self) -> bool {
        self.stop
    }
}

/// Every file under `dir` (relative path → bytes), but the checkpoint and temporary files.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let rel = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
            if p.is_dir() {
                if rel != "checkpoint" {
                    stack.push(p);
                }
            } else if !rel.starts_with(".tmp") && !rel.contains("/.tmp") {
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// `summary.json` without the keys that measure time or memory.
fn summary_numbers(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    fn strip(v: &mut serde_json::Value) {
        if let serde_json::Value::Object(m) = v {
            m.retain(|k, _| {
                !(k.contains("seconds")
                    || k.contains("per_second")
                    || k.contains("memory")
                    || k == "mlups")
            });
            m.values_mut().for_each(strip);
        }
    }
    strip(&mut v);
    v
}

/// Files of `a` and `b` are the same (PNG plots aside, which draw the same numbers but
/// are not compared byte for byte), and so are the summaries' numbers.
fn assert_same_outputs(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    let names = |f: &BTreeMap<String, Vec<u8>>| -> Vec<String> {
        f.keys()
            .filter(|k| !k.ends_with(".png") && *k != "summary.json")
            .cloned()
            .collect()
    };
    assert_eq!(names(&fa), names(&fb), "file lists differ");
    for name in names(&fa) {
        assert!(
            fa[&name] == fb[&name],
            "{name} differs between the straight and the resumed run"
        );
    }
    assert_eq!(summary_numbers(a), summary_numbers(b));
}

/// Run `text` straight into one folder; into another stopped after step `k` then resumed
/// (with the scene given, and once more from the checkpoint's copy); and from a periodic
/// checkpoint (`checkpoint_every`): every output must be identical.
fn check_resume(name: &str, text: &str, k: usize, every: usize) {
    let dir = out_dir(name);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let scene = Scene::load(&path).unwrap();
    let straight = dir.join("straight");
    let s = scene.run(&straight, &mut Silent).unwrap();
    assert_eq!(s.status, "ok");

    // Stopped (as by Ctrl-C) after step k + 1, then resumed with the scene named.
    let stopped = dir.join("stopped");
    let s = scene
        .run(
            &stopped,
            &mut StopAfter {
                after: k,
                stop: false,
            },
        )
        .unwrap();
    assert!(s.interrupted(), "{}", s.status);
    assert!(stopped.join("checkpoint/state.bin").is_file());
    let s = scene.resume(&stopped, &mut Silent).unwrap();
    assert_eq!(s.status, "ok");
    assert_same_outputs(&straight, &stopped);

    // The same, resumed from the copy of the scene the checkpoint holds.
    let copy = dir.join("copy");
    scene
        .run(
            &copy,
            &mut StopAfter {
                after: k,
                stop: false,
            },
        )
        .unwrap();
    let from_ckpt = Scene::from_checkpoint(&copy).unwrap();
    assert_eq!(from_ckpt.path(), path.as_path());
    from_ckpt.resume(&copy, &mut Silent).unwrap();
    assert_same_outputs(&straight, &copy);

    // Periodic checkpoints: the finished run's folder keeps its last one (before the
    // end); resuming from it recomputes the tail to the same files.
    let periodic_text = text.replace(
        "[output]\n",
        &format!("[output]\ncheckpoint_every = {every}\n"),
    );
    assert_ne!(periodic_text, text, "the scene needs an [output] section");
    let ppath = dir.join(format!("{name}_periodic.toml"));
    std::fs::write(&ppath, &periodic_text).unwrap();
    let periodic = Scene::load(&ppath).unwrap();
    let a = dir.join("periodic_straight");
    periodic.run(&a, &mut Silent).unwrap();
    let b = dir.join("periodic_resumed");
    periodic.run(&b, &mut Silent).unwrap();
    periodic.resume(&b, &mut Silent).unwrap();
    assert_same_outputs(&a, &b);
    assert_same_outputs(&straight, &a);

    // A checkpoint is refused for another scene content, naming the checkpoint file.
    let other = Scene::parse(
        &text.replace("[output]\n", "[output]\nevery = 1000\n"),
        &path,
        LawRegistry::default(),
    );
    if let Ok(other) = other {
        let e = other.resume(&stopped, &mut Silent).unwrap_err().to_string();
        assert!(
            e.contains("checkpoint/state.bin") && e.contains("another scene file"),
            "{e}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A small fault-propagation run: moving basement block and wall, cohesion, a loaded
/// lid on free axes, random NLGS ordering, tracked cells, a line, VTK series, the
/// fault measures in `summary.json`.
const NSCD: &str = r#"
[scene]
name = "ckpt_nscd"
dim = 2
model = "nscd"

[particles]
kind = "random"
region = [[0.0, 0.0], [6.0, 1.5]]
radius = [0.1, 0.15]
packing_fraction = 0.75
seed = 1
density = 2800.0

[[wall]]
name = "hanging_wall_block"
polygon = [[-1.0, -1.0], [1.268, -1.0], [3.0, 0.0], [-1.0, 0.0]]
velocity = [0.281458, 0.1625]

[[wall]]
name = "footwall_block"
polygon = [[1.268, -1.0], [7.0, -1.0], [7.0, 0.0], [3.0, 0.0]]

[[wall]]
name = "left"
from = [0.0, 5.0]
to = [0.0, 0.0]
velocity = [0.281458, 0.1625]

[[wall]]
name = "right"
from = [6.0, 0.0]
to = [6.0, 5.0]

[[wall]]
name = "lid"
from = [7.0, 1.7]
to = [-1.0, 1.7]
velocity = [0.0, "free"]
force = [0.0, -2.0e3]
mass = 50.0

[contact]
mu = 0.4
cohesion = 1.0e3
d_w = 5.0e-3

[nscd]
min_sweeps = 20
max_sweeps = 200
ordering = "random"
ordering_seed = 7

[nscd.fault]
tip = [3.0, 0.0]
dip = 30.0
slip_rate = 0.325
window = [[0.0, 0.0], [6.0, 3.0]]
velocity_window = 0.05

[schedule]
end_time = 0.12
dt = 0.01

[output]
every = 2
plots = false

[[output.probe]]
name = "p"
field = "p"
cell = { center = [3.0, 0.8], radius = 0.6 }

[[output.probe]]
name = "vy5"
field = "vy"
particle = 5

[[output.line]]
name = "vx_mid"
field = "vx"
from = [0.2, 0.7]
to = [5.8, 0.7]
points = 9
"#;

#[test]
fn nscd_resumes_bit_identical() {
    check_resume("nscd", NSCD, 4, 3);
}

/// `timestep` values of a `.pvd` file.
fn pvd_times(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    text.split("timestep=\"")
        .skip(1)
        .map(|r| r.split('"').next().unwrap().to_string())
        .collect()
}

/// The particle and the contact series of an NSCD run hold the very same times, which are
/// the times of `probes.csv`.
#[test]
fn nscd_series_share_their_times() {
    let dir = out_dir("nscd_times");
    std::fs::create_dir_all(&dir).unwrap();
    // 0.1 is not a multiple of dt in binary: accumulated t += dt drifts from i dt.
    let text = NSCD
        .replace("end_time = 0.12", "end_time = 0.3")
        .replace("every = 2", "every = 10");
    let path = dir.join("t.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    Scene::load(&path).unwrap().run(&out, &mut Silent).unwrap();
    let a = pvd_times(&out.join("ckpt_nscd.pvd"));
    let b = pvd_times(&out.join("ckpt_nscd_contacts.pvd"));
    assert_eq!(a.len(), 4);
    assert_eq!(a, b);
    let probes = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let csv: Vec<String> = probes
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().to_string())
        .collect();
    let parsed = |v: &[String]| {
        v.iter()
            .map(|t| t.parse::<f64>().unwrap())
            .collect::<Vec<_>>()
    };
    // probes.csv has a row at every step; the written steps are every 10th.
    let written: Vec<f64> = parsed(&csv).into_iter().step_by(10).collect();
    assert_eq!(parsed(&a), written);
    assert_eq!(parsed(&a)[1], 10.0 * 0.01);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A small Brazilian test of bonded disks (platens, breakage, tracked cell).
const LSM: &str = r#"
[scene]
name = "ckpt_lsm"
dim = 2
model = "lsm"

[particles]
kind = "random"
disk = { center = [0.0, 0.0], radius = 3.0 }
radius = [0.2, 0.4]
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

[contacts]
friction = 0.6

[lsm]
damping = "local"
damping_coefficient = 0.7

[loading]
platens = { velocity = 4.0, thickness = 0.6 }

[schedule]
end_time = 0.012
steps = 12

[output]
every = 2
plots = false

[[output.probe]]
name = "platen_force"
field = "platen_force"

[[output.probe]]
name = "broken"
field = "broken"

[[output.probe]]
name = "p_centre"
field = "p"
cell = { center = [0.0, 0.0], radius = 1.5 }

[[output.line]]
name = "vy_mid"
field = "vy"
from = [-2.5, 0.0]
to = [2.5, 0.0]
points = 7
"#;

/// The particle and the contact series of an LSM run hold the very same times, which are
/// the times of `probes.csv` (the particles advance by many sub-steps per output step).
#[test]
fn lsm_series_share_their_times() {
    let dir = out_dir("lsm_times");
    std::fs::create_dir_all(&dir).unwrap();
    let text = LSM
        .replace("end_time = 0.012", "end_time = 0.3")
        .replace("steps = 12", "steps = 30")
        .replace("every = 2", "every = 10");
    let path = dir.join("t.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    Scene::load(&path).unwrap().run(&out, &mut Silent).unwrap();
    let a = pvd_times(&out.join("ckpt_lsm.pvd"));
    let b = pvd_times(&out.join("ckpt_lsm_contacts.pvd"));
    assert_eq!(a.len(), 4);
    assert_eq!(a, b);
    let probes = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let csv: Vec<f64> = probes
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    let pvd: Vec<f64> = a.iter().map(|t| t.parse().unwrap()).collect();
    // probes.csv has a row at every step; the written steps are every 10th.
    let written: Vec<f64> = csv.into_iter().step_by(10).collect();
    assert_eq!(pvd, written);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn lsm_resumes_bit_identical() {
    check_resume("lsm", LSM, 5, 4);
}

/// A channel with a fixed cylinder, a ramped inlet, an outlet, and heat from a hot
/// cylinder wall side.
const LBM: &str = r#"
[scene]
name = "ckpt_lbm"
model = "lbm"
dim = 2

[lbm]
extent = [[0.0, 0.0], [0.44, 0.082]]
spacing = 0.002
density = 1.0
viscosity = 1.0e-3
tau = 0.56
collision = "trt"

[[lbm.boundary]]
side = "xmin"
kind = "velocity"
velocity = ["4 * 0.3 * y * (0.082 - y) / 0.082^2 * min(t / 0.5, 1)", 0.0]

[[lbm.boundary]]
side = "xmax"
kind = "pressure"
pressure = 0.0

[[obstacle]]
name = "cylinder"
shape = { circle = { center = [0.05, 0.04], radius = 0.01 } }

[thermal]
diffusivity = 1.0e-3
initial = "20.0"

[[thermal.boundary]]
side = "ymin"
temperature = 80.0

[[thermal.boundary]]
side = "xmax"
outflow = true

[schedule]
end_time = 0.048
dt = 0.004

[output]
every = 2
plots = false

[[output.probe]]
name = "drag"
field = "fx"
obstacle = "cylinder"

[[output.probe]]
name = "p_front"
field = "pressure"
at = [0.03, 0.04]

[[output.probe]]
name = "t_back"
field = "temperature"
at = [0.08, 0.02]

[[output.line]]
name = "vx_across"
field = "vx"
from = [0.2, 0.002]
to = [0.2, 0.08]
points = 9
"#;

#[test]
fn lbm_resumes_bit_identical() {
    check_resume("lbm", LBM, 5, 4);
}

/// A small Lamb problem (explicit Cosserat dynamics under a Ricker body force).
const COSSERAT_EXPLICIT: &str = r#"
[scene]
name = "ckpt_cosserat"
dim = 2
model = "cosserat"

[grid]
kind = "triangles"
diagonals = "crossed"
extent = [[-100.0, 0.0], [100.0, 100.0]]
cells = [10, 5]

[[region]]
name = "ground"
select = { all = true }
law = "cosserat-dem"
material = "rock"

[material.rock]
youngs_modulus = 18.8e9
poisson_ratio = 0.25
cosserat_shear_modulus = 7.52e9
characteristic_length = 5.0
density = 2200.0
micro_inertia = 4.1666667

[loads]
body_force = [0.0, "-1.0e6 * exp(-(x^2 + (y - 90)^2) / 625) * (1 - 2 * (pi * 145 * (t - 0.01))^2) * exp(-(pi * 145 * (t - 0.01))^2)"]

[schedule]
end_time = 0.012
steps = 12

[solver]
time_integration = "explicit"

[output]
every = 2
plots = false

[[output.probe]]
name = "receiver_uy"
field = "uy"
at = [-30.0, 99.0]

[[output.probe]]
name = "work"
field = "work"
at = [0.0, 50.0]

[[output.line]]
name = "uy_top"
field = "uy"
from = [-90.0, 99.0]
to = [90.0, 99.0]
points = 7
"#;

#[test]
fn cosserat_resumes_bit_identical() {
    check_resume("cosserat_explicit", COSSERAT_EXPLICIT, 5, 4);
    let newmark = COSSERAT_EXPLICIT.replace(
        "time_integration = \"explicit\"",
        "time_integration = \"newmark\"\nlinear = \"gmres-amg\"",
    );
    check_resume("cosserat_newmark", &newmark, 5, 4);
}

/// The hydraulic fracture of `scenes/hydrofrac_seed.toml` on a coarser grid for ten
/// minutes, every step written: monolithic coupling with low-rank updates of its factors,
/// recovered stresses, crack tracking and tip toughness, `fracture.csv`.
fn hydrofrac_small() -> String {
    let text = include_str!("../../../scenes/hydrofrac_seed.toml");
    let mut out = text.to_string();
    for (from, to) in [
        ("cells = [30, 30]", "cells = [10, 10]"),
        ("refine = 12 ", "refine = 6 "),
        ("end_time = 2400.0", "end_time = 600.0"),
        (
            "[output]\nevery = 10\n",
            "[output]\nevery = 1\nplots = false\n",
        ),
    ] {
        assert!(out.contains(from), "{from}");
        out = out.replace(from, to);
    }
    out
}

/// Rows of `fracture.csv` (failed cells) of an output folder.
fn fracture_rows(dir: &Path) -> usize {
    std::fs::read_to_string(dir.join("fracture.csv"))
        .unwrap()
        .lines()
        .count()
        - 1
}

#[test]
fn continuum_hydrofrac_resumes_bit_identical() {
    let text = hydrofrac_small();
    // Cells fail before and after the step the run stops at.
    let dir = out_dir("hydrofrac_rows");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("h.toml");
    for (end, at_least) in [("end_time = 180.0", 1), ("end_time = 600.0", 2)] {
        std::fs::write(&path, text.replace("end_time = 600.0", end)).unwrap();
        let out = dir.join(end);
        Scene::load(&path).unwrap().run(&out, &mut Silent).unwrap();
        assert!(
            fracture_rows(&out) >= at_least,
            "{end}: {}",
            fracture_rows(&out)
        );
        let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
        assert!(summary.contains("\"low_rank_updates\": "), "{summary}");
        assert!(!summary.contains("\"low_rank_updates\": 0,"), "{summary}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
    check_resume("continuum_hydrofrac", &text, 3, 4);
    // The split schemes carry their flow and mechanics factors.
    // (The explicit-pressure update opens cells without settling after four minutes on
    // this grid: three minutes, a cell failed by then.)
    let split = text
        .replace(
            "coupling = \"monolithic\"",
            "coupling = \"explicit-pressure\"",
        )
        .replace("end_time = 600.0", "end_time = 180.0");
    check_resume("continuum_hydrofrac_split", &split, 1, 2);
}

/// Terzaghi's consolidation (`scenes/terzaghi.toml`) for a few steps with a time step
/// that is not a binary fraction: poroelasticity without fracture, the monolithic factors
/// reused from step to step.
#[test]
fn continuum_terzaghi_resumes_bit_identical() {
    let mut text = include_str!("../../../scenes/terzaghi.toml").to_string();
    for (from, to) in [
        ("end_time = 86400.0\ndt = 216.0", "end_time = 2.1\ndt = 0.3"),
        (
            "[output]\nevery = 100\n",
            "[output]\nevery = 2\nplots = false\n",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, to);
    }
    check_resume("continuum_terzaghi", &text, 2, 3);
    let fixed = text.replace("coupling = \"monolithic\"", "coupling = \"fixed-stress\"");
    check_resume("continuum_terzaghi_fixed_stress", &fixed, 2, 3);
}

/// Static mechanics with failing cells and flow on the fixed skeleton
/// (`coupling = "none"`), and static mechanics solved by damped explicit relaxation.
#[test]
fn continuum_static_resumes_bit_identical() {
    let text = include_str!("../../../scenes/tension_band.toml").replace(
        "[[output.probe]]\nname = \"syy_top\"",
        "[output]\nplots = false\n\n[[output.probe]]\nname = \"syy_top\"",
    );
    // The band fails at t = 5 s: stopped after it, and before it (periodic checkpoints).
    check_resume("continuum_tension_band", &text, 5, 2);
    // Damped explicit relaxation from the previous step's displacements.
    let explicit = text
        .replace(
            "poisson_ratio = 0.25\n",
            "poisson_ratio = 0.25\ndensity = 2500.0\n",
        )
        .replace(
            "[physics]\n",
            "[solver]\nmechanics = \"explicit\"\n\n[physics]\n",
        );
    assert!(explicit.contains("mechanics = \"explicit\""));
    check_resume("continuum_tension_band_explicit", &explicit, 5, 2);
    let amg = text.replace(
        "[physics]\n",
        "[solver]\nlinear = \"cg-amg\"\n\n[physics]\n",
    );
    assert_ne!(amg, text);
    // CG-AMG keeps its hierarchy from the first matrix: a rebuilt one would iterate
    // otherwise, so such scenes are refused checkpoints.
    let amg = amg.replace(
        "[output]\nplots = false\n",
        "[output]\nplots = false\ncheckpoint_every = 2\n",
    );
    let dir = out_dir("continuum_amg");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("amg.toml");
    std::fs::write(&path, &amg).unwrap();
    let e = Scene::load(&path)
        .unwrap()
        .run(&dir.join("out"), &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("output.checkpoint_every") && e.contains("cannot write or resume"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
    let text = include_str!("../../../scenes/flow_column.toml")
        .replace("end_time = 30.0", "end_time = 2.0")
        .replace(
            "[output]\nevery = 40\n",
            "[output]\nevery = 2\nplots = false\n",
        );
    check_resume("continuum_flow_column", &text, 3, 3);
}
