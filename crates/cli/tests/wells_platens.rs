//! Peaceman wells and rigid platens from scene files, through the `porofrac` binary.
//!
//! Checks:
//! * a rate-controlled well injecting `q` into a closed, highly permeable square: the
//!   pressure equalizes (k = 1e-8 m²: the steady spread around the well is ~0.03 Pa) and
//!   rises by `q t / (φ c_f |Ω|)` (mass balance, exact for the
//!   implicit TPFA scheme once uniform; 1e-6 relative on the field extrema);
//! * a well outside the grid or without a control is an error naming the key;
//! * a top platen with `force = ["free", -F]` over rollers: uniaxial compression,
//!   `σyy = −F / width`, `σxx = 0` (1e-9 relative), and the platen's top moves as one.

mod common;

use common::read_csv;

fn run(name: &str, text: &str) -> (i32, String, std::path::PathBuf) {
    common::run_text(name, text)
}

fn well_scene(well: &str) -> String {
    format!(
        r#"
[scene]
name = "well"
dim = 2

[grid]
kind = "cartesian"
extent = [[0.0, 0.0], [1.0, 1.0]]
cells = [10, 10]

[[region]]
name = "all"
select = {{ all = true }}
law = "vem"
material = "rock"

[material.rock]
youngs_modulus = 1.0e9
poisson_ratio = 0.25
porosity = 0.2
permeability = 1.0e-8

[fluid]
viscosity = 1.0e-3
compressibility = 1.0e-9

[[bc]]
boundary = "xmin"
displacement = [0.0, 0.0]

[physics]
flow = true
coupling = "none"

{well}

[schedule]
end_time = 10.0
dt = 1.0

[output]
vtk = false
plots = false
"#
    )
}

#[test]
fn rate_well_fills_a_closed_square_by_mass_balance() {
    let (q, t, phi, cf) = (1e-6, 10.0, 0.2, 1e-9);
    let text = well_scene(
        "[[well]]\nname = \"injector\"\nat = [0.55, 0.45]\nradius = 0.05\nskin = 1.0\nrate = 1.0e-6",
    );
    let (code, err, out) = run("rate_well", &text);
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let want = q * t / (phi * cf * 1.0);
    for v in summary["field_extrema"]["pressure"].as_array().unwrap() {
        let p = v.as_f64().unwrap();
        assert!((p - want).abs() <= 1e-6 * want, "{p} vs {want}");
    }
}

#[test]
fn bad_wells_name_the_key() {
    let (code, err, _) = run(
        "well_outside",
        &well_scene("[[well]]\nname = \"w\"\nat = [2.0, 0.5]\nradius = 0.05\nrate = 1.0e-6"),
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("well[0].at = [2.0, 0.5] is outside the grid"),
        "{err}"
    );
    let (code, err, _) = run(
        "well_control",
        &well_scene("[[well]]\nname = \"w\"\ncell = 3\nradius = 0.05"),
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("well[0] needs exactly one of rate and bottom_hole_pressure"),
        "{err}"
    );
}

#[test]
fn free_platen_component_gives_uniaxial_compression() {
    let text = r#"
[scene]
name = "platen"
dim = 2

[grid]
kind = "cartesian"
extent = [[0.0, 0.0], [2.0, 1.0]]
cells = [6, 4]

[[region]]
name = "all"
select = { all = true }
law = "vem"
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
platen = { force = ["free", -2.0e6] }

[output]
vtk = false
plots = false

[[output.probe]]
name = "syy"
field = "syy"
at = [1.3, 0.4]

[[output.probe]]
name = "sxx"
field = "sxx"
at = [1.3, 0.4]

[[output.line]]
name = "top"
field = "uy"
from = [0.0, 1.0]
to = [2.0, 1.0]
points = 5
"#;
    let (code, err, out) = run("platen_free", text);
    assert_eq!(code, 0, "{err}");
    let (_, rows) = read_csv(&out.join("probes.csv"));
    assert!(
        (rows[0][1] + 1.0e6).abs() <= 1e-9 * 1e6,
        "syy {}",
        rows[0][1]
    );
    assert!(rows[0][2].abs() <= 1e-9 * 1e6, "sxx {}", rows[0][2]);
    let (_, top) = read_csv(&out.join("lines/top.csv"));
    // Plane strain: uy(top) = −σ (1 − ν²) h / E, the same at every point of the platen.
    let want = -1.0e6 * (1.0 - 0.0625) * 1.0 / 1.0e9;
    for r in &top {
        assert!((r[4] - want).abs() <= 1e-9 * want.abs(), "{r:?}");
    }
}
