//! `[solver] linear` through the `porofrac` command.
//!
//! Checks:
//! * `scenes/manufactured_e2.toml` (2D, 40 × 40 squares in triangles) and a 3D E3 scene
//!   (10³ cubes in tetrahedra): `linear = "cg-amg"` with `tolerance = 1e-10` writes the
//!   same line samples as `"cholesky"` to 1e-7 of the largest value; `summary.json`
//!   names the solver, counts CG iterations (0 for Cholesky) and reports a residual
//!   ≤ 1e-10;
//! * `"auto"` on a small 2D scene is Cholesky;
//! * `"cg-amg"` with coupled flow stops with status 1 and a message naming
//!   `solver.linear`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "porofrac-linear-test-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Write `text` as a scene, run it, return (status, stderr, output dir).
fn run(name: &str, text: &str) -> (i32, String, PathBuf) {
    let dir = tmp_dir(name);
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_porofrac"))
        .args([
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        out,
    )
}

/// The `value` column of every line file (sorted by name) after the header.
fn line_values(out: &Path) -> Vec<f64> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(out.join("lines"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let mut v = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(f).unwrap();
        for l in text.lines().skip(1) {
            v.push(l.rsplit(',').next().unwrap().parse::<f64>().unwrap());
        }
    }
    v
}

/// `(linear, iterations, max_relative_residual)` of summary.json.
fn solver_summary(out: &Path) -> (String, u64, f64) {
    let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    let s = &j["solver"];
    (
        s["linear"].as_str().unwrap().to_string(),
        s["iterations"].as_u64().unwrap(),
        s["max_relative_residual"].as_f64().unwrap(),
    )
}

fn with_solver(base: &str, linear: &str) -> String {
    format!("{base}\n[solver]\nlinear = \"{linear}\"\ntolerance = 1e-10\n")
}

fn compare(name: &str, base: &str) {
    let (code, err, chol) = run(&format!("{name}-chol"), &with_solver(base, "cholesky"));
    assert_eq!(code, 0, "{err}");
    let (code, err, amg) = run(&format!("{name}-amg"), &with_solver(base, "cg-amg"));
    assert_eq!(code, 0, "{err}");
    let (a, b) = (line_values(&chol), line_values(&amg));
    assert_eq!(a.len(), b.len());
    assert!(!a.is_empty());
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0f64, f64::max)
        / scale;
    let (lin_c, it_c, res_c) = solver_summary(&chol);
    let (lin_a, it_a, res_a) = solver_summary(&amg);
    eprintln!(
        "{name}: cholesky residual {res_c:.2e}; cg-amg {it_a} iterations, residual {res_a:.2e}; \
         largest line difference {worst:.2e} of max |value|"
    );
    assert!(
        worst < 1e-7,
        "{name}: cg-amg differs from cholesky by {worst:.2e}"
    );
    assert_eq!((lin_c.as_str(), it_c), ("cholesky", 0));
    assert_eq!(lin_a, "cg-amg");
    assert!(it_a > 0 && it_a < 200, "{it_a} iterations");
    assert!(res_a <= 1e-10, "residual {res_a:e}");
}

#[test]
fn cg_amg_equals_cholesky_on_e2() {
    let base = std::fs::read_to_string(root().join("scenes/manufactured_e2.toml")).unwrap();
    compare("e2", &base);
}

const E3: &str = r#"
[scene]
name = "e3"
dim = 3
[grid]
kind = "tetrahedra"
extent = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
cells = [10, 10, 10]
[[region]]
name = "all"
select = { all = true }
law = "vem"
material = "unit"
[material.unit]
youngs_modulus = 1.0
poisson_ratio = 0.3
[[bc]]
boundary = "xmin"
displacement = ["sin(pi*x)*sin(pi*y)*sin(pi*z)/100", "x^2*y*z/100", "y*z*cos(pi*x)/100"]
[[bc]]
boundary = "xmax"
displacement = ["sin(pi*x)*sin(pi*y)*sin(pi*z)/100", "x^2*y*z/100", "y*z*cos(pi*x)/100"]
[[bc]]
boundary = "ymin"
displacement = ["sin(pi*x)*sin(pi*y)*sin(pi*z)/100", "x^2*y*z/100", "y*z*cos(pi*x)/100"]
[[bc]]
boundary = "ymax"
displacement = ["sin(pi*x)*sin(pi*y)*sin(pi*z)/100", "x^2*y*z/100", "y*z*cos(pi*x)/100"]
[[bc]]
boundary = "zmin"
displacement = ["sin(pi*x)*sin(pi*y)*sin(pi*z)/100", "x^2*y*z/100", "y*z*cos(pi*x)/100"]
[[bc]]
boundary = "zmax"
displacement = ["sin(pi*x)*sin(pi*y)*sin(pi*z)/100", "x^2*y*z/100", "y*z*cos(pi*x)/100"]
[loads]
body_force = [
  "-x*z/52 + pi*y*sin(pi*x)/104 + 11*pi^2*sin(pi*x)*sin(pi*y)*sin(pi*z)/520",
  "-y*z/130 - pi^2*sin(pi*z)*cos(pi*x)*cos(pi*y)/104 - cos(pi*x)/104",
  "-x^2/104 + pi^2*y*z*cos(pi*x)/260 - pi^2*sin(pi*y)*cos(pi*x)*cos(pi*z)/104",
]
[output]
plots = false
vtk = false
[[output.line]]
name = "diagonal_ux"
field = "ux"
from = [0.0, 0.0, 0.0]
to = [1.0, 1.0, 1.0]
points = 21
[[output.line]]
name = "diagonal_uy"
field = "uy"
from = [0.0, 0.0, 0.0]
to = [1.0, 1.0, 1.0]
points = 21
[[output.line]]
name = "diagonal_uz"
field = "uz"
from = [0.0, 0.0, 0.0]
to = [1.0, 1.0, 1.0]
points = 21
"#;

#[test]
fn cg_amg_equals_cholesky_on_e3() {
    compare("e3", E3);
}

#[test]
fn auto_is_cholesky_on_a_small_2d_scene() {
    let base = std::fs::read_to_string(root().join("scenes/manufactured_e2.toml")).unwrap();
    let text = format!("{base}\n[solver]\nlinear = \"auto\"\n");
    let (code, err, out) = run("auto", &text);
    assert_eq!(code, 0, "{err}");
    let (linear, iterations, _) = solver_summary(&out);
    assert_eq!((linear.as_str(), iterations), ("cholesky", 0));
}

#[test]
fn cg_amg_with_coupled_flow_is_a_scene_error() {
    let base = std::fs::read_to_string(root().join("scenes/terzaghi.toml")).unwrap();
    let text = format!("{base}\n[solver]\nlinear = \"cg-amg\"\n");
    let (code, err, _) = run("coupled", &text);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("solver.linear"), "{err}");
    assert!(err.contains("cg-amg"), "{err}");
}
