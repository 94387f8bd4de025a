//! The KGD scene (`scenes/kgd_toughness.toml`) against the toughness vertex solution of
//! Detournay (2004), at half the bundled scene's resolution (h = 0.125 m, 17 cells per
//! half-length at 100 s; 5 s in release).
//!
//! Checks, over t ≥ 20 s (after the initial transient), against
//! `ℓ = 0.9324 (E′Q₀t/K′)^{2/3}`, `p = K_Ic/√(πℓ)`, `w(0) = 4pℓ/E′`:
//! - the mean relative error of the half-length `ℓ` (failed cells · h/4), the inlet net
//!   pressure and the inlet opening (the jump of `u_y` across the path at x = 50);
//! - the time exponent of `ℓ` (least squares on `log ℓ` against `log t`).
//!
//! The viscosity scene (`scenes/kgd_viscosity.toml`, h = 0.125 m, steps of 0.4 s, the tip
//! rule `"asymptote"`; 7 s) against the viscosity vertex solution over t ≥ 8 s, with the
//! pore pressure bounded by a cavitation pressure 10 MPa below the rock's and a closed
//! crack's transmissivity floor of 1e-18 m³: the half-length, the inlet opening and the
//! inlet net pressure within the target of 10 % on average and their time exponents
//! (2/3, 1/3, −1/3), and the errors of the length and the pressure falling from h = 0.25 m
//! (steps of 0.8 s) to the scene's. docs/hydrofrac/validation.md has the refinement study.
//!
//! The bounds are the values measured at this resolution (2026-11-28: `ℓ` +7.4 % on
//! average, 7.5 % in absolute value; `p` 6.9 %; `w` 3.8 %; exponent 0.630) rounded up by
//! about 5 %; the bundled scene (h = 0.0625 m) and the refinement study are in
//! docs/hydrofrac/validation.md.

use std::path::Path;

use crate::{LawRegistry, Scene, Silent};

const E: f64 = 1.0e10;
const NU: f64 = 0.25;
const K_IC: f64 = 1.0e6;
const Q0: f64 = 1.0e-5;

/// The vertex solution at `t`: half-length, net pressure, inlet opening.
fn vertex(t: f64) -> (f64, f64, f64) {
    let ep = E / (1.0 - NU * NU);
    let kp = 4.0 * (2.0 / std::f64::consts::PI).sqrt() * K_IC;
    let l = 0.9324 * (ep * Q0 * t / kp).powf(2.0 / 3.0);
    let p = K_IC / (std::f64::consts::PI * l).sqrt();
    (l, p, 4.0 * p * l / ep)
}

/// The columns of a CSV file with a header (the numbers of every row).
pub(super) fn csv(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

/// The least-squares slope of `(log t, log ℓ)` pairs: the time exponent of a length.
pub(super) fn log_slope(logs: &[(f64, f64)]) -> f64 {
    let m = logs.len() as f64;
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / m,
        logs.iter().map(|p| p.1).sum::<f64>() / m,
    );
    logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / logs.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>()
}

/// Run a KGD scene's text (named `path` in errors) in a temporary folder: its probe rows
/// and the failure time of every failed cell (`fracture.csv`).
fn run_kgd(text: &str, path: &str, tag: &str) -> (Vec<Vec<String>>, Vec<f64>) {
    let scene = Scene::parse(text, Path::new(path), LawRegistry::default()).unwrap();
    let out = std::env::temp_dir().join(format!("porofrac_{tag}_{}", std::process::id()));
    scene.run(&out, &mut Silent).unwrap();
    let probes = csv(&out.join("probes.csv"));
    let failed = csv(&out.join("fracture.csv"))
        .iter()
        .map(|r| r[3].parse().unwrap())
        .collect();
    std::fs::remove_dir_all(&out).ok();
    (probes, failed)
}

#[test]
fn kgd_toughness_follows_the_vertex_solution() {
    let text = include_str!("../../../../scenes/kgd_toughness.toml")
        .replace("refine = 32", "refine = 16")
        .replace(
            "[[46.001, 50.001], [53.999, 50.0615]]",
            "[[46.001, 50.001], [53.999, 50.124]]",
        )
        .replace(
            "[[49.9385, 50.001], [50.0615, 50.0615]]",
            "[[49.876, 50.001], [50.124, 50.124]]",
        )
        .replace("at = [50.0001, 50.03125]", "at = [50.0001, 50.0625]")
        .replace("at = [50.0, 50.0625]", "at = [50.0, 50.125]");
    assert!(text.contains("refine = 16") && text.contains("50.124]]"));
    let h = 0.125;
    let (probes, failed) = run_kgd(&text, "scenes/kgd_toughness.toml", "kgd");

    let (mut e_l, mut a_l, mut a_p, mut a_w) = (0.0, 0.0, 0.0, 0.0);
    let mut logs = Vec::new();
    for row in &probes {
        let v: Vec<f64> = row.iter().map(|x| x.parse().unwrap()).collect();
        let t = v[0];
        if t < 20.0 {
            continue;
        }
        let n = failed.iter().filter(|&&tf| tf <= t + 1e-9).count();
        let l = n as f64 * h / 4.0;
        let (lv, pv, wv) = vertex(t);
        e_l += l / lv - 1.0;
        a_l += (l / lv - 1.0).abs();
        a_p += (v[1] / pv - 1.0).abs();
        a_w += ((v[2] - v[3]) / wv - 1.0).abs();
        logs.push((t.ln(), l.ln()));
    }
    let m = logs.len() as f64;
    assert_eq!(logs.len(), 41, "probes every 2 s from 20 s to 100 s");
    let (e_l, a_l, a_p, a_w) = (e_l / m, a_l / m, a_p / m, a_w / m);
    let exponent = log_slope(&logs);
    println!(
        "KGD toughness, h = {h} m, t >= 20 s: l {e_l:+.4} (mean |.| {a_l:.4}), p {a_p:.4}, \
         w {a_w:.4}, exponent {exponent:.4}"
    );
    assert!(
        e_l > 0.0 && a_l < 0.079,
        "half-length: mean error {e_l:+.4}, |.| {a_l:.4}"
    );
    assert!(a_p < 0.073, "inlet net pressure: mean |error| {a_p:.4}");
    assert!(a_w < 0.040, "inlet opening: mean |error| {a_w:.4}");
    assert!(
        (0.61..0.65).contains(&exponent),
        "time exponent of the half-length {exponent:.4} (2/3 in the vertex solution)"
    );
}

/// The viscosity scene's errors over t ≥ 8 s against the viscosity vertex solution.
#[derive(Clone, Copy, Debug)]
struct ViscousErrors {
    /// Mean relative error of the half-length.
    l: f64,
    /// Mean relative error of the inlet opening.
    w: f64,
    /// Mean relative error of the inlet net pressure.
    p: f64,
    /// The largest |relative error| of the half-length, the opening and the pressure.
    worst: [f64; 3],
    /// Time exponents of the half-length (2/3), inlet opening (1/3) and pressure (−1/3).
    exponents: [f64; 3],
}

/// The inlet net pressure of the viscosity vertex, `Π_m0(0) (μ′E′²/t)^{1/3}`: `Π_m0(0)`
/// from the series of Adachi & Detournay (2002) at `ξ = 0` (computed in
/// docs/hydrofrac/kgd_viscosity_study.py).
const PI_M0_INLET: f64 = 0.5443;

/// Run `scenes/kgd_viscosity.toml` at `refine` (cells of `h = 2/refine` m along the path;
/// the scene's own is 16) with steps of `dt` (s) and measure its errors; `tag` names the
/// run's folder (the tests run at the same time).
fn kgd_viscosity_errors(refine: u32, dt: f64, tag: &str) -> ViscousErrors {
    let (e, nu, mu, q0): (f64, f64, f64, f64) = (1.0e10, 0.25, 1.0e-3, 1.0e-5);
    let ep = e / (1.0 - nu * nu);
    let mup = 12.0 * mu;
    let h = 2.0 / refine as f64;
    let at = |x: f64| format!("{}", (x * 1e6).round() / 1e6);
    let text = include_str!("../../../../scenes/kgd_viscosity.toml");
    assert!(text.contains("refine = 16") && text.contains("dt = 0.4"));
    let text = text
        .replace("refine = 16", &format!("refine = {refine}"))
        .replace("dt = 0.4", &format!("dt = {dt}"))
        .replace(
            "[[46.001, 50.001], [53.999, 50.124]]",
            &format!("[[46.001, 50.001], [53.999, {}]]", at(50.0 + h - 0.001)),
        )
        .replace(
            "[[49.876, 50.001], [50.124, 50.124]]",
            &format!(
                "[[{}, 50.001], [{}, {}]]",
                at(50.0 - h + 0.001),
                at(50.0 + h - 0.001),
                at(50.0 + h - 0.001)
            ),
        )
        .replace(
            "at = [50.0001, 50.0625]",
            &format!("at = [50.0001, {}]", at(50.0 + h / 2.0)),
        )
        .replace(
            "at = [50.0, 50.125]",
            &format!("at = [50.0, {}]", at(50.0 + h)),
        );
    let (probes, failed) = run_kgd(&text, "scenes/kgd_viscosity.toml", tag);
    let (mut sum, mut worst, mut m) = ([0.0; 3], [0.0f64; 3], 0.0);
    let mut logs = [Vec::new(), Vec::new(), Vec::new()];
    for row in &probes {
        let v: Vec<f64> = row.iter().map(|x| x.parse().unwrap()).collect();
        let t = v[0];
        if t < 8.0 - 1e-9 {
            continue;
        }
        let l = failed.iter().filter(|&&tf| tf <= t + 1e-9).count() as f64 * h / 4.0;
        let (w, p) = (v[2] - v[3], v[1] - 1.0e7);
        let lv = 0.6152 * (ep * q0.powi(3) * t.powi(4) / mup).powf(1.0 / 6.0);
        let wv = 1.1265 * (mup * q0.powi(3) * t * t / ep).powf(1.0 / 6.0);
        let pv = PI_M0_INLET * (mup * ep * ep / t).cbrt();
        for (k, (x, xv)) in [(l, lv), (w, wv), (p, pv)].into_iter().enumerate() {
            sum[k] += x / xv - 1.0;
            worst[k] = worst[k].max((x / xv - 1.0).abs());
            logs[k].push((t.ln(), x.ln()));
        }
        m += 1.0;
    }
    let errors = ViscousErrors {
        l: sum[0] / m,
        w: sum[1] / m,
        p: sum[2] / m,
        worst,
        exponents: [
            log_slope(&logs[0]),
            log_slope(&logs[1]),
            log_slope(&logs[2]),
        ],
    };
    println!("KGD viscosity, h = {h} m, dt = {dt} s, t >= 8 s ({m} probes): {errors:?}");
    assert_eq!(
        m,
        (32.0 / dt).round() + 1.0,
        "probes every step from 8 s to 40 s"
    );
    errors
}

/// The bundled viscosity scene (h = 0.125 m, steps of 0.4 s), run once for the tests.
fn bundled_viscosity() -> ViscousErrors {
    static RUN: std::sync::OnceLock<ViscousErrors> = std::sync::OnceLock::new();
    *RUN.get_or_init(|| kgd_viscosity_errors(16, 0.4, "kgd_mu"))
}

/// The bundled viscosity scene within the 10 % target, at the values measured
/// (2026-11-29, h = 0.125 m: ℓ +6.4 %, w +3.9 %, p +4.3 % on average; rounded up by about
/// 1 % of the vertex solution) and its time exponents (ℓ 0.660, w 0.319, p −0.357). With
/// the tip rule `"opening"` (the viscous `r^{2/3}` opening read as `√r`) the same grid and
/// step give ℓ +15.4 %, w +3.5 %, p +7.9 % (docs/hydrofrac/validation.md).
#[test]
fn kgd_viscosity_follows_the_vertex_solution() {
    let e = bundled_viscosity();
    assert!((0.0..0.075).contains(&e.l), "half-length {:+.4}", e.l);
    assert!(e.w.abs() < 0.05, "inlet opening {:+.4}", e.w);
    assert!(e.p.abs() < 0.055, "inlet net pressure {:+.4}", e.p);
    assert!(
        e.worst.iter().all(|&x| x < 0.15),
        "largest errors {:?}",
        e.worst
    );
    let [xl, xw, xp] = e.exponents;
    assert!(
        (0.64..0.69).contains(&xl),
        "time exponent of ℓ {xl:.4} (2/3)"
    );
    assert!(
        (0.30..0.37).contains(&xw),
        "time exponent of w {xw:.4} (1/3)"
    );
    assert!(
        (-0.39..-0.32).contains(&xp),
        "time exponent of p {xp:.4} (−1/3)"
    );
}

/// Refinement: from h = 0.25 m (steps of 0.8 s) to the bundled 0.125 m (0.4 s) the mean
/// errors of the half-length and the inlet net pressure fall (measured +9.1 % → +6.4 %,
/// +6.6 % → +4.3 %) and the opening stays within 10 % (+4.0 %, +3.9 %); at 0.0625 m
/// (0.2 s, docs/hydrofrac/validation.md) +4.5 %, +3.7 %, +3.2 %.
#[test]
fn kgd_viscosity_converges_under_refinement() {
    let coarse = kgd_viscosity_errors(8, 0.8, "kgd_mu_coarse");
    let fine = bundled_viscosity();
    for (name, c, f) in [("ℓ", coarse.l, fine.l), ("p", coarse.p, fine.p)] {
        assert!(
            f.abs() < c.abs() && c.abs() < 0.10,
            "{name}: {c:+.4} at h = 0.25 m, {f:+.4} at 0.125 m"
        );
    }
    assert!(
        coarse.w.abs() < 0.10 && fine.w.abs() < 0.10,
        "w: {coarse:?} {fine:?}"
    );
}

/// The rule `"asymptote"` reads the cell stress away from tips: with the recovered stress
/// the scene is refused, naming the key, the rule and the line.
#[test]
fn the_asymptote_tip_rule_refuses_the_recovered_stress() {
    let text = include_str!("../../../../scenes/kgd_viscosity.toml").replace(
        "\ntip_rule = \"asymptote\"\n",
        "\ntip_rule = \"asymptote\"\nfailure_stress = \"recovered\"\n",
    );
    assert!(text.contains("failure_stress"));
    let line = text
        .lines()
        .position(|l| l.starts_with("tip_rule"))
        .unwrap()
        + 1;
    let err = match Scene::parse(&text, Path::new("kgd.toml"), LawRegistry::default()) {
        Ok(_) => panic!("the scene was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("tip_rule")
            && err.contains("\"asymptote\"")
            && err.contains("recovered")
            && err.contains(&format!("kgd.toml:{line}")),
        "{err}"
    );
}

/// `tip_sample_distance` applies to the rule `"opening"` with crack tracking only and
/// must be a positive length: other uses are refused, naming the key.
#[test]
fn the_tip_sample_distance_is_refused_without_the_opening_rule_and_tracking_or_when_not_positive() {
    let parse = |text: &str| match Scene::parse(text, Path::new("kgd.toml"), LawRegistry::default())
    {
        Ok(_) => None,
        Err(e) => Some(e.to_string()),
    };
    let base = include_str!("../../../../scenes/kgd_viscosity.toml");
    let with_asymptote = base.replace(
        "\ntip_rule = \"asymptote\"\n",
        "\ntip_rule = \"asymptote\"\ntip_sample_distance = 0.05\n",
    );
    assert!(with_asymptote.contains("tip_sample_distance"));
    let err = parse(&with_asymptote).expect("refused with the rule \"asymptote\"");
    assert!(
        err.contains("tip_sample_distance") && err.contains("\"opening\""),
        "{err}"
    );
    let opening = include_str!("../../../../scenes/kgd_toughness.toml");
    for bad in ["0.0", "-0.1"] {
        let text = opening.replace(
            "\ntip_rule = \"opening\"\n",
            &format!("\ntip_rule = \"opening\"\ntip_sample_distance = {bad}\n"),
        );
        assert!(text.contains("tip_sample_distance"));
        let err = parse(&text).expect("a distance that is not positive is refused");
        assert!(err.contains("tip_sample_distance"), "{err}");
    }
    let untracked = opening.replace(
        "\ntip_rule = \"opening\"\n",
        "\ntip_rule = \"opening\"\ntip_sample_distance = 0.05\n",
    );
    let err = parse(&untracked).expect("refused without crack tracking");
    assert!(
        err.contains("tip_sample_distance") && err.contains("crack_tracking"),
        "{err}"
    );
    let good = opening.replace(
        "\ntip_rule = \"opening\"\n",
        "\ntip_rule = \"opening\"\ntip_sample_distance = 0.05\ncrack_tracking = 45.0\n",
    );
    assert_eq!(parse(&good), None);
}
