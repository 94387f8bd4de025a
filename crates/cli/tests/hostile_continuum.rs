//! Continuum and Cosserat scenes whose numbers make a run overflow, sample nowhere or
//! never settle, through the `porofrac` binary.
//!
//! Checks:
//! * a probe `at` (or a line end) with `inf`, or outside the grid's box, is refused by
//!   `check`, naming `output.probe[i].at` and its line (patch test, Cosserat shear layer);
//! * a modulus of 1e300 (continuum Young's modulus, Cosserat shear modulus) and a
//!   viscosity of `inf` are refused by `check`, naming the key and its line;
//! * loads that overflow the solution (a traction of 1e300·1e300, a body force of
//!   1e300 in the Cosserat Lamb scene) end the run with status 1 and an error that names
//!   the load keys with their lines, and no NaN or inf in any output file;
//! * Ctrl-C while the failures of the first state of a hydraulic-fracture scene are
//!   being settled (the load exceeds the strength everywhere) ends the run with status
//!   130 and `"status": "interrupted at t = 0"`.

mod common;

use std::path::Path;

use common::{porofrac, root, run_text, send_ctrl_c, spawn_run, summary, tmp_dir};

fn scene(name: &str) -> String {
    std::fs::read_to_string(root().join("scenes").join(name)).unwrap()
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

/// `porofrac check` on `text` written as `<name>.toml`: exit status and stderr.
fn check_text(name: &str, text: &str) -> (i32, String) {
    let dir = tmp_dir(name);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let (code, _, err) = porofrac(&["check", path.to_str().unwrap()]);
    (code, err)
}

/// Every number of every CSV file and of `summary.json` under `out` is finite (and
/// `summary.json` holds no `null`).
fn no_non_finite(out: &Path) {
    let Ok(rd) = std::fs::read_dir(out) else {
        return;
    };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            no_non_finite(&p);
            continue;
        }
        let name = p.to_string_lossy().into_owned();
        if name.ends_with(".csv") {
            let text = std::fs::read_to_string(&p).unwrap();
            for v in text.lines().skip(1).flat_map(|l| l.split(',')) {
                if let Ok(x) = v.trim().parse::<f64>() {
                    assert!(x.is_finite(), "{name}: {v}");
                }
            }
        } else if name.ends_with("summary.json") {
            let text = std::fs::read_to_string(&p).unwrap();
            assert!(!text.contains("null"), "{name}: {text}");
        }
    }
}

#[test]
fn probes_at_infinity_or_outside_the_grid_are_refused_by_check() {
    let base = scene("patch_test.toml");
    let line = line_of(&base, "at = [0.5, 0.5]");
    let text = base.replacen("at = [0.5, 0.5]", "at = [inf, 0.5]", 1);
    let (code, err) = check_text("cont_probe_inf", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(":{line}:")) && err.contains("output.probe[0].at"),
        "{err}"
    );
    assert!(err.contains("finite"), "{err}");
    let text = base.replacen("at = [0.5, 0.5]", "at = [0.5, 7.0]", 1);
    let (code, err) = check_text("cont_probe_out", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(":{line}:")) && err.contains("outside the grid"),
        "{err}"
    );

    let base = scene("cosserat_shear_layer.toml");
    let line = line_of(&base, "at = [0.0, 0.5e-3]");
    let text = base.replacen("at = [0.0, 0.5e-3]", "at = [-inf, 0.5e-3]", 1);
    let (code, err) = check_text("cont_cosserat_probe_inf", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(":{line}:")) && err.contains("output.probe[0].at"),
        "{err}"
    );
}

#[test]
fn moduli_and_viscosities_out_of_range_are_refused_by_check() {
    let base = scene("hybrid_uniaxial.toml");
    let line = line_of(&base, "youngs_modulus = 1.0e9");
    let text = base.replacen("youngs_modulus = 1.0e9", "youngs_modulus = 1e300", 1);
    let (code, err) = check_text("cont_e_huge", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(":{line}:")) && err.contains("youngs_modulus = 1e300"),
        "{err}"
    );
    assert!(err.contains("1e15"), "{err}");

    let base = scene("cosserat_plate_hole.toml");
    let needle = "cosserat_shear_modulus = ";
    let line = line_of(&base, needle);
    let old = base.lines().nth(line - 1).unwrap().to_string();
    let text = base.replacen(&old, "cosserat_shear_modulus = 1e300", 1);
    let (code, err) = check_text("cont_gc_huge", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(":{line}:")) && err.contains("cosserat_shear_modulus"),
        "{err}"
    );

    let base = scene("mandel.toml");
    let line = line_of(&base, "viscosity = ");
    let old = base.lines().nth(line - 1).unwrap().to_string();
    let text = base.replacen(&old, "viscosity = inf", 1);
    let (code, err) = check_text("cont_mu_inf", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(":{line}:")) && err.contains("fluid.viscosity"),
        "{err}"
    );
}

#[test]
fn overflowing_loads_end_the_run_naming_the_load_keys() {
    let base = scene("hybrid_uniaxial.toml");
    let line = line_of(&base, "traction = [0.0, \"-1e7");
    let text = base.replacen("-1e7*", "-1e300*1e300*", 1);
    let (code, err, out) = run_text("cont_traction_overflow", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("overflowed") && err.contains(&format!("bc[2].traction (line {line})")),
        "{err}"
    );
    assert!(err.contains("material.rock.youngs_modulus"), "{err}");
    no_non_finite(&out);

    let base = scene("cantilever.toml");
    let line = line_of(&base, "traction = [0.0, \"1.5 - 6*y^2\"]");
    let text = base.replacen("\"1.5 - 6*y^2\"", "1e300", 1);
    let (code, err, out) = run_text("cont_cantilever_overflow", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("overflowed") && err.contains(&format!("traction (line {line})")),
        "{err}"
    );
    no_non_finite(&out);

    let base = scene("cosserat_lamb.toml");
    let line = line_of(&base, "body_force = ");
    let text = base.replacen("-1.0e6 *", "-1.0e300 *", 1);
    let (code, err, out) = run_text("cont_lamb_overflow", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("overflowed") && err.contains(&format!("loads.body_force (line {line})")),
        "{err}"
    );
    no_non_finite(&out);
}

#[test]
fn ctrl_c_while_the_first_failures_settle_ends_the_run_as_interrupted() {
    // Without the displacement condition on `xmin` the load fails most of the grid at
    // t = 0 and the settling of the failures takes many solves.
    let base = scene("hydrofrac_seed.toml");
    let mut lines: Vec<&str> = base.lines().collect();
    let i = lines
        .iter()
        .position(|l| l.contains("boundary = \"xmin\""))
        .unwrap();
    assert!(lines[i + 1].starts_with("displacement"), "{}", lines[i + 1]);
    lines.remove(i + 1);
    let text = lines.join("\n");
    let dir = tmp_dir("cont_settle_interrupt");
    let path = dir.join("settle.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    let mut child = spawn_run(&path, &out);
    // The first state takes seconds to settle; the request lands inside it.
    std::thread::sleep(std::time::Duration::from_millis(1500));
    send_ctrl_c(&child);
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert_eq!(summary(&out)["status"], "interrupted at t = 0");
}
