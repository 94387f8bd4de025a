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
//! The viscosity scene (`scenes/kgd_viscosity.toml`, h = 0.125 m, 3 s) against the
//! viscosity vertex solution over t ≥ 8 s, with the pore pressure bounded by a cavitation
//! pressure 10 MPa below the rock's and a closed crack's transmissivity floor of 1e-18 m³:
//! the half-length and the inlet opening within the target of 10 % on average (measured
//! 2026-11-29: +9.2 % and +9.6 %, the opening +21 % at most), the time exponent of the
//! length within 0.60–0.70 (0.630; 2/3). docs/hydrofrac/validation.md has the refinement
//! study.
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

/// The viscosity scene's mean relative errors over t ≥ 8 s: half-length, inlet opening,
/// the largest |error| of the inlet opening, and the time exponent of the half-length;
/// `tag` names the run's folder (the tests run at the same time).
fn kgd_viscosity_errors(tag: &str) -> (f64, f64, f64, f64) {
    let (e, nu, mu, q0): (f64, f64, f64, f64) = (1.0e10, 0.25, 1.0e-3, 1.0e-5);
    let ep = e / (1.0 - nu * nu);
    let mup = 12.0 * mu;
    let h = 0.125;
    let (probes, failed) = run_kgd(
        include_str!("../../../../scenes/kgd_viscosity.toml"),
        "scenes/kgd_viscosity.toml",
        tag,
    );
    let (mut e_l, mut e_w, mut worst_w, mut m) = (0.0, 0.0, 0.0f64, 0.0);
    let mut logs = Vec::new();
    for row in &probes {
        let v: Vec<f64> = row.iter().map(|x| x.parse().unwrap()).collect();
        let t = v[0];
        if t < 8.0 {
            continue;
        }
        let l = failed.iter().filter(|&&tf| tf <= t + 1e-9).count() as f64 * h / 4.0;
        let lv = 0.6152 * (ep * q0.powi(3) * t.powi(4) / mup).powf(1.0 / 6.0);
        let wv = 1.1265 * (mup * q0.powi(3) * t * t / ep).powf(1.0 / 6.0);
        let ew = (v[2] - v[3]) / wv - 1.0;
        e_l += l / lv - 1.0;
        e_w += ew;
        logs.push((t.ln(), l.ln()));
        worst_w = worst_w.max(ew.abs());
        m += 1.0;
    }
    let (e_l, e_w) = (e_l / m, e_w / m);
    let exponent = log_slope(&logs);
    println!(
        "KGD viscosity, h = {h} m, t >= 8 s: l {e_l:+.4}, w {e_w:+.4} (largest {worst_w:.4}), \
         exponent of l {exponent:.4}"
    );
    assert_eq!(m, 41.0, "probes every 0.8 s from 8 s to 40 s");
    (e_l, e_w, worst_w, exponent)
}

/// The target of 10 % on the inlet opening, on average over t ≥ 8 s (2026-11-29,
/// h = 0.125 m: +9.6 %, +20.6 % at most, early; at h = 0.0625 m +23.7 %: the tip rule
/// reads the viscous `r^{2/3}` opening as `√r`, docs/hydrofrac/validation.md).
#[test]
fn kgd_viscosity_inlet_opening_follows_the_vertex_solution() {
    let (_, e_w, worst_w, _) = kgd_viscosity_errors("kgd_mu_w");
    assert!(
        e_w.abs() < 0.10,
        "inlet opening {e_w:+.4} on average (target ±10 %), {worst_w:.4} at most"
    );
}

/// The target of 10 % on the half-length (2026-11-29, h = 0.125 m: +9.2 % on average,
/// +14.7 % at 8 s, +6.5 % at 40 s) and its time exponent (0.630 against 2/3). Before the
/// cavitation bound and the lower transmissivity floor the crack was +27 % long: the
/// floor of 1e-15 m³ (a residual aperture of 23 microns against an inlet opening of 40)
/// conducted the fluid to the tip with little viscous drop.
#[test]
fn kgd_viscosity_half_length_follows_the_vertex_solution() {
    let (e_l, _, _, exponent) = kgd_viscosity_errors("kgd_mu_l");
    assert!(e_l.abs() < 0.10, "half-length {e_l:+.4} (target ±10 %)");
    assert!(
        (0.60..0.70).contains(&exponent),
        "time exponent of the half-length {exponent:.4} (2/3)"
    );
}
