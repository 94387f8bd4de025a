//! The fault-propagation experiment (Renouf et al. (2006) §5.3) through the library: the trends
//! reported there on the bundled reduced run (`scenes/nscd/fault_gamma0.toml`, the
//! 150 m × 15 m geometry scaled by 1/5) and on `fault_thick.toml` (scaled by 2/5) — those
//! that hold run, the others are kept ignored with the measured values (the five-packing
//! table is docs/nscd/fault_trends.md) — and the scene keys of the settling and of the
//! fault measures on a smaller sample ([`scene_text`]: geometry × `SCALE` of the paper's,
//! radii, density, μ and γ unchanged, the basement block at the paper's 0.325 m/s for the
//! run that gives the paper's slip over thickness, 13 m / 15 m, gravity settling first).

use std::path::Path;
use std::path::PathBuf;
use std::sync::OnceLock;

use porofrac_scene::{LawRegistry, Scene, Silent};

/// Geometry scale against the paper's 150 m × 15 m.
const SCALE: f64 = 0.15;
/// Steps of 0.01 s at 0.325 m/s: slip = 0.87 × thickness.
const STEPS: usize = 600;

fn scene_text(gamma: f64, seed: u64) -> String {
    let (l, h, tip) = (150.0 * SCALE, 15.0 * SCALE, 75.0 * SCALE);
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let v = [0.325 * c, 0.325 * s];
    let xb = tip - 2.0 / 30f64.to_radians().tan();
    let left = -0.1 * l - 2.0;
    let w1 = [85.0 * SCALE, 7.5 * SCALE, 6.0 * SCALE];
    let d_w = if gamma > 0.0 { 5e-3 } else { 0.0 };
    let end = STEPS as f64 * 0.01;
    let mut t = format!(
        r#"[scene]
name = "fault_g{gamma}_s{seed}"
dim = 2
model = "nscd"
[particles]
kind = "random"
region = [[0.0, 0.0], [{l}, {h}]]
radius = [0.13, 0.26]
packing_fraction = 0.8
seed = {seed}
density = 2800.0
[[wall]]
polygon = [[{left}, -2.0], [{xb}, -2.0], [{tip}, 0.0], [{left}, 0.0]]
velocity = [{v0}, {v1}]
[[wall]]
polygon = [[{xb}, -2.0], [{r}, -2.0], [{r}, 0.0], [{tip}, 0.0]]
[[wall]]
from = [0.0, {top}]
to = [0.0, 0.0]
velocity = [{v0}, {v1}]
[[wall]]
from = [{l}, 0.0]
to = [{l}, {top}]
[contact]
mu = 0.4
cohesion = {gamma}
d_w = {d_w}
[nscd]
settle_ratio = 1.0e-6
[nscd.fault]
tip = [{tip}, 0.0]
dip = 30.0
slip_rate = 0.325
window = [[{wx0}, -1.0], [{wx1}, {wy1}]]
velocity_window = {vw}
[schedule]
end_time = {end}
dt = 0.01
[output]
every = {every}
vtk = false
"#,
        v0 = v[0],
        v1 = v[1],
        r = l + 5.0,
        top = 3.0 * h,
        wx0 = tip - 0.2 * l,
        wx1 = tip + 0.4 * l,
        wy1 = 1.5 * h + 1.0,
        vw = 0.1 * end,
        every = STEPS / 40,
    );
    for f in ["p", "q"] {
        t += &format!(
            "[[output.probe]]\nname = \"{f}\"\nfield = \"{f}\"\ncell = {{ center = [{}, {}], radius = {} }}\n",
            w1[0], w1[1], w1[2]
        );
    }
    t
}

/// What a run gives: the probe rows (time, p, q) and `summary.json`.
struct Run {
    rows: Vec<[f64; 3]>,
    summary: serde_json::Value,
}

fn run_scene(scene: Scene, tag: &str) -> Run {
    let out =
        std::env::temp_dir().join(format!("porofrac-nscd-fault-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let summary = scene.run(&out, &mut Silent).unwrap();
    assert_eq!(summary.status, "ok");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let rows = std::fs::read_to_string(out.join("probes.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    std::fs::remove_dir_all(&out).unwrap();
    Run { rows, summary }
}

fn fault(r: &Run, key: &str) -> f64 {
    r.summary["fault"][key]
        .as_f64()
        .unwrap_or_else(|| panic!("fault.{key} in {}", r.summary["fault"]))
}

/// Mean of p over the fraction [a, b] of the run.
fn mean_p(r: &Run, a: f64, b: f64) -> f64 {
    let end = r.rows.last().unwrap()[0];
    let v: Vec<f64> = r
        .rows
        .iter()
        .filter(|x| x[0] >= a * end - 1e-9 && x[0] <= b * end + 1e-9)
        .map(|x| x[1])
        .collect();
    v.iter().sum::<f64>() / v.len() as f64
}

/// W1 (Renouf et al. (2006) Fig. 14, phase 1 then phase 2) without cohesion, on the bundled
/// reduced run (`fault_gamma0.toml`, 4 000 steps, under a minute on one core): the settling
/// meets K < 1e-6 ΔE_p; p rises fast — its mean over [T/8, T/4] is at least 1.3 × its
/// settled value — then stays on a plateau: the mean over [T/4, T] is within 25 % of the
/// phase-1 level. (On the smaller samples of [`scene_text`] packing seed 3 rises by only
/// 1.28×: the trend needs the reduced size.)
#[test]
fn w1_pressure_rises_fast_then_plateaus() {
    let r = &bundled_run("0");
    let st = &r.summary["settling"];
    let (k, e) = (
        st["kinetic_energy"].as_f64().unwrap(),
        st["potential_energy_released"].as_f64().unwrap(),
    );
    assert!(e > 0.0 && k < 1e-6 * e, "settling {st}");
    let p0 = r.rows[0][1];
    let rise = mean_p(r, 0.125, 0.25);
    let plateau = mean_p(r, 0.25, 1.0);
    assert!(p0 > 0.0 && rise >= 1.3 * p0, "p0 {p0}, phase 1 {rise}");
    assert!(
        (plateau - rise).abs() <= 0.25 * rise,
        "phase 1 {rise}, phase 2 {plateau}"
    );
}

fn bundled_run(gamma: &str) -> Run {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/nscd");
    let scene = Scene::load(&dir.join(format!("fault_gamma{gamma}.toml"))).unwrap();
    run_scene(scene, &format!("bundled-{gamma}"))
}

/// `scenes/nscd/fault_thick.toml` (the recommended geometry at 2/5 scale, 60 m × 6 m,
/// about 2 340 disks) with cohesion `gamma` (d_w = 5 mm when γ > 0).
fn thick_run(gamma: f64) -> Run {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/nscd/fault_thick.toml");
    let d_w = if gamma > 0.0 { 5e-3 } else { 0.0 };
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("cohesion = 0.0", &format!("cohesion = {gamma:e}"))
        .replace("d_w = 0.0", &format!("d_w = {d_w}"))
        .replace("plots = true", "plots = false\nvtk = false");
    let scene = Scene::parse(&text, &path, LawRegistry::default()).unwrap();
    run_scene(scene, &format!("thick-{gamma:e}"))
}

/// The trend of Renouf et al. (2006) §5.3.3 (Fig. 14), on the sample twice as thick
/// (`fault_thick.toml`, packing seed 1): in phase 2 ([T/4, T]) the W1 pressure at γ = 1e5
/// is 2 ± 0.5 times that at γ = 0 (paper Fig. 14: "about 2×"; measured 1.59, and 1.63 and
/// 1.67 with packing seeds 2 and 3, docs/BENCHMARKS.md), and the run-out at γ = 1e5 is
/// below that at γ = 0 (the paper's run-out shrinking with γ, between its ends: 2.67
/// against 3.66 m here, lower at γ = 1e5 in all five packings of docs/nscd/fault_trends.md),
/// and the fitted trishear zone narrows by at least 3° ("its area shrinks with γ", Fig. 13;
/// 27° → 15° here; 22 → 16, 22 → 19, 23 → 12, 26 → 17 with packing seeds 2 to 5).
/// And θ_l of §5.3.2 (Fig. 12a), read as the angle between the left and right limits of
/// the fault area drawn from the tip (`fault.area.opening_deg`), is above the fault dip
/// θ = 30° at γ = 0 and below it at γ = 1e5, as the paper reports: 33.8° and 14.5° here;
/// over five packings 35.0 ± 2.8° and 22.5 ± 5.8°, above 30° at γ = 0 in five of five,
/// below at γ = 1e5 in four of five (docs/nscd/fault_trends.md). Two runs of 4 000 steps,
/// about a minute and a half each on one core.
#[test]
fn strong_cohesion_doubles_w1_pressure_and_shortens_the_run_out() {
    let (free, cohesive) = std::thread::scope(|s| {
        let a = s.spawn(|| thick_run(0.0));
        let b = s.spawn(|| thick_run(1e5));
        (a.join().unwrap(), b.join().unwrap())
    });
    let ratio = mean_p(&cohesive, 0.25, 1.0) / mean_p(&free, 0.25, 1.0);
    assert!(
        (1.5..=2.5).contains(&ratio),
        "p(1e5)/p(0) in phase 2: {ratio}"
    );
    let (r0, r5) = (fault(&free, "run_out"), fault(&cohesive, "run_out"));
    assert!(r5 < r0, "run-out {r0} m at γ = 0, {r5} m at γ = 1e5");
    let apex = |r: &Run| {
        r.summary["fault"]["trishear"]["half_apex_deg"]
            .as_f64()
            .unwrap()
    };
    let (a0, a5) = (apex(&free), apex(&cohesive));
    assert!(
        a5 <= a0 - 3.0,
        "fitted trishear half apical angle {a0}° at γ = 0, {a5}° at γ = 1e5"
    );
    let (o0, o5) = (opening(&free), opening(&cohesive));
    assert!(
        o0 > 30.0 && o5 < 30.0,
        "θ_l (opening of the fault area) {o0}° at γ = 0, {o5}° at γ = 1e5"
    );
}

/// θ_l read as the angle between the limits of the fault area (`fault.area`).
fn opening(r: &Run) -> f64 {
    r.summary["fault"]["area"]["opening_deg"]
        .as_f64()
        .unwrap_or_else(|| panic!("fault.area in {}", r.summary["fault"]))
}

/// The 2/5-scale sample (`fault_thick.toml`, packing seed 1) at γ = 0, 1e3, 1e4, 1e5, run
/// once for the trend gates below (a minute and a half to four minutes each).
fn thick() -> &'static [Run] {
    static RUNS: OnceLock<Vec<Run>> = OnceLock::new();
    RUNS.get_or_init(|| [0.0, 1e3, 1e4, 1e5].iter().map(|&g| thick_run(g)).collect())
}

fn values(key: &str) -> Vec<f64> {
    thick().iter().map(|r| fault(r, key)).collect()
}

/// Renouf et al. (2006) §5.3.2 (Fig. 12a): θ_l decreases monotonically with γ, from
/// above θ to below it. Read as the angle between the limits of the fault area from the
/// tip (`fault.area.opening_deg`), it does between the ends of the γ range (tested in
/// `strong_cohesion_doubles_w1_pressure_and_shortens_the_run_out`) but not monotonically:
/// 33.8°, 34.8°, 38.8°, 14.5° on this packing; over five packings (docs/nscd/fault_trends.md)
/// 35.0 ± 2.8°, 37.6 ± 6.6°, 33.0 ± 4.4°, 22.5 ± 5.8° — flat within the packing scatter
/// up to γ = 1e4, then a fall at 1e5 in four packings of five; no packing is monotonic.
/// Read as the orientation of the fault area's axis (the ray of the half-slip contour,
/// `fault.area.axis_deg`), it does not fall: 29.9 ± 1.8°, 30.1 ± 3.5°, 31.9 ± 4.7°,
/// 33.8 ± 7.1°, the basement dip within the scatter at every γ (the band fit
/// `limit_angle_deg`, 29.9 ± 5.7° → 37.6 ± 5.0°, rises more: its free line through four
/// or five band boundaries follows the bend of the contour near the surface).
#[test]
#[ignore = "not monotonic over the four γ: a fall at γ = 1e5 only (docs/nscd/fault_trends.md)"]
fn limit_angle_decreases_with_cohesion() {
    let a: Vec<f64> = thick().iter().map(opening).collect();
    assert!(a.windows(2).all(|w| w[1] < w[0]), "{a:?}");
}

/// The run-out of Renouf et al. (2006) §5.3.2 shrinks as γ grows. On this packing 3.66,
/// 2.80, 1.21, 2.67 m: not monotonic. Over five packings (docs/nscd/fault_trends.md) the
/// means fall (2.44 ± 0.85, 2.02 ± 1.12, 1.27 ± 0.56, 1.18 ± 1.06 m) and γ = 1e5 is below
/// γ = 0 in all five (tested in
/// `strong_cohesion_doubles_w1_pressure_and_shortens_the_run_out`), but one packing of
/// five is monotonic over the four γ: the packing scatter is as large as the steps.
#[test]
#[ignore = "not robust: monotonic in one packing of five (docs/nscd/fault_trends.md)"]
fn run_out_shrinks_with_cohesion() {
    let r = values("run_out");
    assert!(r.windows(2).all(|w| w[1] < w[0]), "{r:?}");
}

/// After Renouf et al. (2006) §5.3.2 (the trishear zone matches best without cohesion):
/// the trishear L2 mismatch over the layer (`fault.trishear.layer.l2`: without the
/// uplifted hanging wall and the surface flow above the initial free surface) is
/// smallest at γ = 0. On this packing 0.185, 0.153, 0.143, 0.158: the largest at γ = 0.
/// Over five packings (docs/nscd/fault_trends.md) 0.178 ± 0.018, 0.160 ± 0.035,
/// 0.161 ± 0.028, 0.168 ± 0.039: flat within the scatter. Over the whole window
/// (`fault.trishear.l2`) the mismatch falls with γ (0.189 ± 0.054 → 0.142 ± 0.026)
/// because the surface flow of the cohesionless runs, above the layer, is not a trishear
/// motion.
#[test]
#[ignore = "does not hold: the mismatch is flat in γ (five packings, docs/nscd/fault_trends.md)"]
fn trishear_mismatch_smallest_without_cohesion() {
    let l2: Vec<f64> = thick()
        .iter()
        .map(|r| {
            r.summary["fault"]["trishear"]["layer"]["l2"]
                .as_f64()
                .unwrap()
        })
        .collect();
    assert!(l2[1..].iter().all(|&m| m > l2[0]), "{l2:?}");
}

fn error_of(text: &str) -> String {
    match Scene::parse(text, Path::new("fault.toml"), LawRegistry::default()) {
        Err(e) => e.to_string(),
        Ok(scene) => {
            let out = std::env::temp_dir()
                .join(format!("porofrac-nscd-fault-bad-{}", std::process::id()));
            let e = scene.run(&out, &mut Silent).unwrap_err().to_string();
            let _ = std::fs::remove_dir_all(&out);
            e
        }
    }
}

/// Bad settling and fault keys are refused with the key named; a settling cut short
/// names `settle_max_steps`.
#[test]
fn settling_and_fault_keys_are_checked() {
    let base = scene_text(0.0, 1);
    for (from, to, key) in [
        (
            "settle_ratio = 1.0e-6",
            "settle_ratio = -1.0",
            "nscd.settle_ratio",
        ),
        (
            "settle_ratio = 1.0e-6",
            "settle_ratio = 1.0e-6\nsettle_dt = 0.0",
            "nscd.settle_dt",
        ),
        ("dip = 30.0", "dip = 95.0", "nscd.fault.dip"),
        (
            "dip = 30.0",
            "dip = 30.0\nlimit_fraction = 0.7",
            "nscd.fault.limit_fraction",
        ),
        (
            "slip_rate = 0.325",
            "slip_rate = 0.0",
            "nscd.fault.slip_rate",
        ),
        (
            "window = [[",
            "window = [[100.0, 0.0], [",
            "nscd.fault.window",
        ),
        (
            "settle_ratio = 1.0e-6",
            "settle_ratio = 1.0e-6\nsettle_max_steps = 2",
            "nscd.settle_max_steps",
        ),
    ] {
        let e = error_of(&base.replacen(from, to, 1));
        assert!(e.contains(key), "{key}: {e}");
    }
}
