//! Hostile and inconsistent scenes through the `porofrac` binary: every one is refused
//! with exit status 1 and one line naming the file, line and key, before anything big
//! is allocated, also under a 4 GB address-space limit; an interrupted run exits with
//! 130 and complete files.
//!
//! Checks:
//! * an expression nested 100 000 deep, TOML arrays nested 100 000 deep;
//! * `end_time = 1e12, dt = 1e-3` (1e15 steps), `cells = [100000000, 100000000]`
//!   (1e16 cells), `cells = [30000, 30000]` (9e8 cells: more memory than the 4 GB
//!   limit), a line of 1e12 points — the error names the key and, for memory, how
//!   much is needed against what the machine has;
//! * fields not available for the scene's dimension (`uz` in 2D) name the key;
//! * `szz` in plane strain equals `ν (σxx + σyy)`, in plane stress 0 (uniaxial
//!   compression, closed form, 1e-9 relative);
//! * Ctrl-C (SIGINT) during a run: exit status 130, `"status": "interrupted at t = …"`,
//!   `probes.csv` holds whole rows of the finished steps.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{read_csv, root, send_ctrl_c, spawn_run, summary, tmp_dir};

fn patch_text() -> String {
    std::fs::read_to_string(root().join("scenes/patch_test.toml")).unwrap()
}

/// Run `porofrac run` on `text` under an address-space limit of 4 GB (`ulimit -v`):
/// exit status and stderr.
fn run_limited(name: &str, text: &str) -> (i32, String, PathBuf) {
    let dir = tmp_dir(name);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    let cmd = format!(
        "ulimit -v 4000000; exec '{}' run '{}' --out '{}'",
        env!("CARGO_BIN_EXE_porofrac"),
        path.display(),
        out.display()
    );
    let o = Command::new("sh").arg("-c").arg(cmd).output().unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        out,
    )
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn deep_nesting_is_an_error_not_a_crash() {
    let deep = format!("{}x{}", "(".repeat(100_000), ")".repeat(100_000));
    let text = patch_text().replacen("3e-4*y\"]", &format!("3e-4*y + {deep}\"]"), 1);
    let (code, err, _) = run_limited("deep_expr", &text);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("bc[0].displacement"), "{err}");
    assert!(err.contains("nests more than 100 levels"), "{err}");

    let arrays = format!("deep = {}1{}\n", "[".repeat(100_000), "]".repeat(100_000));
    let text = format!("{arrays}{}", patch_text());
    let (code, err, _) = run_limited("deep_toml", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("deep_toml.toml:1:") && err.contains("nest"),
        "{err}"
    );
}

#[test]
fn absurd_sizes_are_refused_before_allocating() {
    let text = format!("{}\n[schedule]\nend_time = 1e12\ndt = 1e-3\n", patch_text());
    let (code, err, _) = run_limited("steps", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(
            "steps.toml:{}: schedule.dt",
            line_of(&text, "dt = 1e-3")
        )),
        "{err}"
    );
    assert!(err.contains("1.000e15 steps"), "{err}");

    let text = patch_text().replace("cells = [8, 8]", "cells = [100000000, 100000000]");
    let (code, err, _) = run_limited("count", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("grid.cells asks for 1.000e16 cells, more than"),
        "{err}"
    );

    let text = patch_text().replace("cells = [8, 8]", "cells = [30000, 30000]");
    let (code, err, _) = run_limited("cells", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(
            "cells.toml:{}: grid.cells",
            line_of(&text, "cells = [")
        )),
        "{err}"
    );
    assert!(
        err.contains("needs about") && err.contains("this machine has"),
        "{err}"
    );

    let text = format!("{}\n[solver]\nthreads = 1000000000\n", patch_text());
    let (code, err, _) = run_limited("threads", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("solver.threads = 1000000000 must be in 0..=1024"),
        "{err}"
    );

    let text = patch_text().replace("points = 11", "points = 1000000000000");
    let (code, err, _) = run_limited("points", &text);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("output.line[0].points"), "{err}");
}

#[test]
fn fields_not_in_the_scene_are_errors_naming_the_key() {
    let text = patch_text().replace("field = \"sxx\"", "field = \"uz\"");
    let (code, err, _) = run_limited("uz2d", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(
            "uz2d.toml:{}: output.probe[1].field = \"uz\" is not a field of a 2D scene",
            line_of(&text, "\"uz\"")
        )),
        "{err}"
    );
}

/// A 1 × 1 square under uniaxial compression σyy = −p (rollers on xmin and ymin): plane
/// strain gives σzz = ν (σxx + σyy) = −ν p, plane stress σzz = 0.
fn uniaxial(plane: &str) -> String {
    format!(
        r#"
[scene]
name = "uniaxial_{plane}"
dim = 2
plane = "{plane}"

[grid]
kind = "triangles"
extent = [[0.0, 0.0], [1.0, 1.0]]
cells = [4, 4]

[[region]]
name = "all"
select = {{ all = true }}
law = "mdem"
material = "rock"

[material.rock]
youngs_modulus = 1.0e9
poisson_ratio = 0.25

[[bc]]
boundary = "xmin"
displacement = [0.0, "free"]

[[bc]]
boundary = "ymin"
displacement = ["free", 0.0]

[[bc]]
boundary = "ymax"
traction = [0.0, -1.0e6]

[output]
vtk = false
plots = false

[[output.probe]]
name = "szz"
field = "szz"
at = [0.4, 0.6]

[[output.probe]]
name = "syy"
field = "syy"
at = [0.4, 0.6]
"#
    )
}

#[test]
fn szz_follows_the_plane_setting() {
    for (plane, want) in [("strain", -0.25e6), ("stress", 0.0)] {
        let (code, err, out) = run_limited(&format!("szz_{plane}"), &uniaxial(plane));
        assert_eq!(code, 0, "{err}");
        let (_, rows) = read_csv(&out.join("probes.csv"));
        assert!((rows[0][2] + 1e6).abs() <= 1e-9 * 1e6, "syy {}", rows[0][2]);
        assert!(
            (rows[0][1] - want).abs() <= 1e-9 * 1e6,
            "{plane}: szz {}",
            rows[0][1]
        );
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let szz = &summary["field_extrema"]["szz"];
        assert!(
            (szz[0].as_f64().unwrap() - want).abs() <= 1e-9 * 1e6,
            "{szz}"
        );
        assert!(
            (szz[1].as_f64().unwrap() - want).abs() <= 1e-9 * 1e6,
            "{szz}"
        );
    }
}

fn wait_for(path: &Path) {
    for _ in 0..600 {
        if path.is_file() {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    panic!("{} never appeared", path.display());
}

#[test]
fn ctrl_c_ends_with_status_130_and_complete_files() {
    // Flow on a fixed skeleton for many short steps: long enough to be interrupted.
    let text = std::fs::read_to_string(root().join("scenes/flow_column.toml"))
        .unwrap()
        .replace("[schedule]", "[schedule]\n# long run\n");
    let text = text
        .lines()
        .map(|l| {
            if l.trim_start().starts_with("dt =") || l.trim_start().starts_with("steps =") {
                "steps = 2000000".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let dir = tmp_dir("ctrlc");
    let path = dir.join("long.toml");
    std::fs::write(&path, &text).unwrap();
    let out = dir.join("out");
    let mut child = spawn_run(&path, &out);
    wait_for(&out.join("probes.csv"));
    std::thread::sleep(std::time::Duration::from_millis(700));
    send_ctrl_c(&child);
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    let summary = summary(&out);
    let status = summary["status"].as_str().unwrap();
    assert!(status.starts_with("interrupted at t = "), "{status}");
    let t: f64 = status["interrupted at t = ".len()..].parse().unwrap();
    let (_, rows) = read_csv(&out.join("probes.csv"));
    assert!(rows.len() >= 2);
    assert_eq!(rows.last().unwrap()[0], t);
    // The last finished step is written, whatever `every` says: t = steps · end_time / N.
    let steps = summary["steps"].as_u64().unwrap() as f64;
    assert!(
        (t - steps * 30.0 / 2.0e6).abs() <= 1e-9 * t,
        "{t} after {steps} steps"
    );
}
