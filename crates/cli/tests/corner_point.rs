//! Corner-point decks through scene files (`scenes/corner_point/`).
//!
//! Checks:
//! * the bundled injection scene runs on the faulted deck: 480 deck cells less 2 inactive
//!   and 40 pinched; the VTK files carry `ijk` and `volume`; pressure falls away from the
//!   injector;
//! * mass balance on the faulted deck with the rock properties of the deck (PORO × NTG,
//!   PERM × NTG): a rate well injects `q t` into the closed block, and the stored volume
//!   `c_f Σ φ_c V_c Δp_c`, summed over one probe per cell, equals it to 1e-9 relative,
//!   with `φ_c V_c` known independently from the deck's construction (every cell a
//!   20 × 20 × 5 m³ planar hexahedron, NTG 0.9, PORO 0.1 in layer 3 and 0.2 elsewhere);
//! * a sealed fault (`FAULTS` + `MULTFLT 0`, added to the same deck): nothing crosses it,
//!   the cells east of it keep their initial pressure exactly, and the west side stores
//!   all that was injected (1e-9 relative); a multiplier of a fault the deck does not
//!   define is an error naming it;
//! * an MDEM zone around a vertical well (`mdem_zone = { around = … }`, `refine = 0`):
//!   the 25 cells within 25 m of the axis become 24 tetrahedra each (6 faces × 4
//!   triangles), and the patch test passes through the command on the hybrid grid: the
//!   affine displacement prescribed on all outer faces (imin … kmax) gives the exact
//!   constant stress in every cell, VEM and MDEM (field extrema within 1e-8 of the
//!   largest stress);
//! * a deck declaring 1e9 cells and a ZCORN of 8e9 repeated values is refused at its
//!   `DIMENS`, naming the memory, before anything is allocated;
//! * the bounding-box side `zmin`, which touches no face of the dipping top, is an error
//!   that points to the ijk sides; `select = { ijk = … }` on a generated grid is an error;
//! * a negative `PORO` of an active cell in a flow scene is an error naming `PORO`, the
//!   deck file and line, and the cell's 1-based `(i, j, k)`.

mod common;

use common::{porofrac, root, summary, tmp_dir};

fn run(name: &str, text: &str) -> (i32, String, std::path::PathBuf) {
    common::run_text(name, text)
}

fn deck() -> String {
    root()
        .join("scenes/corner_point/faulted.grdecl")
        .to_string_lossy()
        .into_owned()
}

#[test]
fn the_bundled_injection_scene_runs_on_the_faulted_deck() {
    let dir = tmp_dir("cp_injection");
    let out = dir.join("out");
    let scene = root().join("scenes/corner_point/injection.toml");
    let (code, _, err) = porofrac(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let s = summary(&out);
    assert_eq!(s["cells"], 480 - 2 - 40);
    let vtk = std::fs::read_to_string(out.join("vtk/step_0004.vtu"))
        .or_else(|_| std::fs::read_to_string(out.join("vtk/step_0001.vtu")))
        .unwrap();
    assert!(vtk.contains("Name=\"ijk\"") && vtk.contains("Name=\"volume\""));
    let probes = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let last: Vec<f64> = probes
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(
        last[1] > last[2] && last[2] > 1e7,
        "p_well {} > p_far {} > p0",
        last[1],
        last[2]
    );
}

fn balance_scene(probes: &str, boundary: &str) -> String {
    balance_scene_on(&deck(), probes, boundary)
}

fn balance_scene_on(deck_path: &str, probes: &str, boundary: &str) -> String {
    format!(
        r#"
[scene]
name = "cp_balance"
dim = 3

[grid]
kind = "file"
path = "{}"

[[region]]
name = "all"
select = {{ all = true }}
law = "vem"
material = "rock"

[material.rock]
youngs_modulus = 1.0e10
poisson_ratio = 0.25

[fluid]
viscosity = 1.0e-3
compressibility = 4.5e-10

[[bc]]
boundary = "{boundary}"
displacement = [0.0, 0.0, 0.0]

[[well]]
name = "injector"
at = [90.0, 90.0, 1016.0]
radius = 0.1
rate = 0.001

[physics]
flow = true
coupling = "none"

[schedule]
end_time = 864000.0
dt = 86400.0

[output]
vtk = false
plots = false
{probes}
"#,
        deck_path
    )
}

/// One pressure probe at the centroid of every cell.
fn cell_probes(g: &porofrac_grid::Grid<3>) -> String {
    let mut probes = String::new();
    for c in 0..g.num_cells() {
        let x = g.cell_centroid(c);
        probes += &format!(
            "[[output.probe]]\nname = \"p{c}\"\nfield = \"pressure\"\nat = [{}, {}, {}]\n",
            x[0], x[1], x[2]
        );
    }
    probes
}

/// The last row of `probes.csv`.
fn last_probes(out: &std::path::Path) -> Vec<f64> {
    let text = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    text.lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect()
}

#[test]
fn a_rate_well_fills_the_faulted_block_by_its_deck_pore_volume() {
    let (_, cp) = porofrac_grid::io::read_grdecl(deck()).unwrap();
    let g = &cp.grid;
    let probes = cell_probes(g);
    let (code, err, out) = run("cp_balance", &balance_scene(&probes, "kmax"));
    assert_eq!(code, 0, "{err}");
    let last = last_probes(&out);
    assert_eq!(last[0], 864000.0);
    let stored: f64 = (0..g.num_cells())
        .map(|c| {
            let poro = if cp.ijk[c][2] == 2 { 0.1 } else { 0.2 };
            4.5e-10 * poro * 0.9 * 2000.0 * last[1 + c]
        })
        .sum();
    let injected = 0.001 * 864000.0;
    assert!(
        (stored - injected).abs() <= 1e-9 * injected,
        "stored {stored} m³ against {injected} m³ injected"
    );
    let (lo, hi) = last[1..]
        .iter()
        .fold((f64::MAX, 0.0f64), |(a, b), &p| (a.min(p), b.max(p)));
    assert!(
        hi > 1.01 * lo,
        "the deck's permeability leaves a pressure gradient"
    );
}

#[test]
fn a_sealed_fault_lets_nothing_through() {
    let dir = tmp_dir("cp_sealed_deck");
    let sealed = dir.join("sealed.grdecl");
    let text = std::fs::read_to_string(deck()).unwrap()
        + "FAULTS\n 'F1' 5 5 1 8 1 6 'X' /\n/\nMULTFLT\n 'F1' 0.0 /\n/\n";
    std::fs::write(&sealed, text).unwrap();
    let (_, cp) = porofrac_grid::io::read_grdecl(&sealed).unwrap();
    let g = &cp.grid;
    let (code, err, out) = run(
        "cp_sealed",
        &balance_scene_on(sealed.to_str().unwrap(), &cell_probes(g), "kmax"),
    );
    assert_eq!(code, 0, "{err}");
    let last = last_probes(&out);
    let mut west = 0.0;
    for c in 0..g.num_cells() {
        let p = last[1 + c];
        if cp.ijk[c][0] >= 5 {
            assert_eq!(p, 0.0, "cell {:?} east of the sealed fault", cp.ijk[c]);
        } else {
            let poro = if cp.ijk[c][2] == 2 { 0.1 } else { 0.2 };
            west += 4.5e-10 * poro * 0.9 * 2000.0 * p;
        }
    }
    let injected = 0.001 * 864000.0;
    assert!(
        (west - injected).abs() <= 1e-9 * injected,
        "west stores {west} m³ of {injected}"
    );

    let bad = dir.join("bad.grdecl");
    let text = std::fs::read_to_string(deck()).unwrap() + "MULTFLT\n 'F9' 0.0 /\n/\n";
    std::fs::write(&bad, text).unwrap();
    let (code, err, _) = run(
        "cp_badfault",
        &balance_scene_on(bad.to_str().unwrap(), "", "kmax"),
    );
    assert_eq!(code, 1);
    assert!(err.contains("no fault named 'F9'"), "{err}");
}

#[test]
fn an_mdem_zone_around_a_well_replaces_its_cells_by_tetrahedra() {
    let mut bcs = String::new();
    for side in ["imin", "imax", "jmin", "jmax", "kmin", "kmax"] {
        bcs += &format!(
            "[[bc]]\nboundary = \"{side}\"\ndisplacement = [\"1e-4*(x + 0.5*y)\", \
             \"1e-4*(-0.3*y + 0.2*z)\", \"1e-4*(0.1*x - 0.4*z)\"]\n"
        );
    }
    let text = format!(
        r#"
[scene]
name = "cp_zone"
dim = 3
[grid]
kind = "file"
path = "{}"
mdem_zone = {{ around = {{ path = [[50.0, 90.0, 990.0], [50.0, 90.0, 1050.0]], radius = 25.0 }} }}
refine = 0
well_path = [[50.0, 90.0, 990.0], [50.0, 90.0, 1050.0]]
well_radius = 8.0
[[region]]
name = "rock"
select = {{ all = true }}
law = "vem"
material = "rock"
[[region]]
name = "zone"
select = {{ tag = "refined" }}
law = "mdem"
[material.rock]
youngs_modulus = 1.0e10
poisson_ratio = 0.25
{bcs}
[output]
plots = false
"#,
        deck()
    );
    let (code, err, out) = run("cp_zone", &text);
    assert_eq!(code, 0, "{err}");
    let s = summary(&out);
    assert_eq!(s["cells"], 438 - 25 + 25 * 24);
    // u = 1e-4 (x + 0.5 y, −0.3 y + 0.2 z, 0.1 x − 0.4 z); λ = μ = 4e9 Pa.
    let exact = [
        ("sxx", 9.2e5),
        ("syy", -1.2e5),
        ("szz", -2.0e5),
        ("sxy", 2.0e5),
        ("syz", 8.0e4),
        ("sxz", 4.0e4),
    ];
    for (field, want) in exact {
        for v in s["field_extrema"][field].as_array().unwrap() {
            let v = v.as_f64().unwrap();
            assert!((v - want).abs() <= 1e-8 * 9.2e5, "{field} {v} vs {want}");
        }
    }
}

#[test]
fn corner_point_mistakes_are_named() {
    let (code, err, _) = run("cp_zmin", &balance_scene("", "zmin"));
    assert_eq!(code, 1);
    assert!(
        err.contains("bc[0].boundary = \"zmin\"") && err.contains("kmin (top)"),
        "{err}"
    );
    let generated = r#"
[scene]
name = "ijk"
dim = 3
[grid]
kind = "cartesian"
extent = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
cells = [2, 2, 2]
[[region]]
name = "all"
select = { ijk = [[1, 2], [1, 2], [1, 1]] }
law = "vem"
material = "rock"
[material.rock]
youngs_modulus = 1.0e9
poisson_ratio = 0.25
[[bc]]
boundary = "zmin"
displacement = [0.0, 0.0, 0.0]
"#;
    let dir = tmp_dir("cp_huge_deck");
    let huge = dir.join("huge.grdecl");
    std::fs::write(
        &huge,
        "DIMENS\n 1000 1000 1000 /\nZCORN\n 8000000000*1.0 /\n",
    )
    .unwrap();
    let (code, err, _) = run(
        "cp_huge",
        &balance_scene_on(huge.to_str().unwrap(), "", "kmax"),
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("DIMENS") && err.contains("kB per deck cell") && err.contains("GB"),
        "{err}"
    );
    let (code, err, _) = run("cp_ijk", generated);
    assert_eq!(code, 1);
    assert!(
        err.contains("region[0].select") && err.contains("corner-point deck"),
        "{err}"
    );
}

#[test]
fn a_bad_deck_porosity_names_keyword_file_line_and_cell() {
    let dir = tmp_dir("cp_bad_poro_deck");
    let path = dir.join("bad_poro.grdecl");
    let mut text = std::fs::read_to_string(deck()).unwrap();
    let line = text.lines().count() + 1;
    text.push_str("PORO\n 5*0.2 -0.45 474*0.2 /\n");
    std::fs::write(&path, text).unwrap();
    let (code, err, _) = run(
        "cp_bad_poro",
        &balance_scene_on(path.to_str().unwrap(), "", "kmax"),
    );
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!("bad_poro.grdecl:{line}: PORO of cell (i, j, k) = (6, 1, 1) is -0.45; porosity must be in (0, 1]")),
        "{err}"
    );
}
