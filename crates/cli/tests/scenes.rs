//! The bundled scenes and the error contract, through the user's path: the `porofrac`
//! binary, its exit status and the files it writes.
//!
//! Checks and references:
//! * `scenes/patch_test.toml`: an affine displacement on the boundary of a perturbed
//!   grid; probes and the line output equal the affine field and its constant stress
//!   (plane strain, E = 1e9, ν = 0.3) to 1e-10 relative.
//! * `scenes/hybrid_uniaxial.toml`: MDEM near the well, VEM with hanging nodes outside,
//!   ramped uniaxial traction; probes equal the closed-form plane-strain solution
//!   `uy = −p y (1 − ν²)/E`, `ux = p x ν (1 + ν)/E`, `σyy = −p`, `σxx = 0` at every
//!   written time, p = 1e7 min(t/60, 1), to 1e-9 relative.
//! * Errors: invalid values, unknown keys, bad expressions, missing references,
//!   singular systems and missing mesh files exit with status 1 and one line naming the
//!   file, line and key; command-line misuse exits with status 2.

mod common;

use common::{close, porofrac, read_csv, root, run_ok, tmp_dir};

/// Plane strain, E = 1e9, ν = 0.3.
fn lame() -> (f64, f64) {
    let (e, nu) = (1e9, 0.3);
    (
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        e / (2.0 * (1.0 + nu)),
    )
}

#[test]
fn patch_test_scene_reproduces_the_affine_field() {
    let out = tmp_dir("patch");
    let scene = root().join("scenes/patch_test.toml");
    run_ok(&scene, &out);
    let u = |x: f64, y: f64| (1e-4 + 1e-3 * x + 2e-4 * y, -2e-4 - 5e-4 * x + 3e-4 * y);
    let (l, m) = lame();
    let sxx = (l + 2.0 * m) * 1e-3 + l * 3e-4;
    let (header, rows) = read_csv(&out.join("probes.csv"));
    assert_eq!(header, ["time [s]", "ux_center [m]", "sxx_center [Pa]"]);
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0][0], 0.0);
    assert!(
        close(rows[0][1], u(0.5, 0.5).0, 1e-3, 1e-10),
        "{}",
        rows[0][1]
    );
    assert!(
        close(rows[0][2], sxx, sxx, 1e-10),
        "{} vs {sxx}",
        rows[0][2]
    );
    let (header, rows) = read_csv(&out.join("lines/diagonal.csv"));
    assert_eq!(header, ["time [s]", "s [m]", "x [m]", "y [m]", "uy [m]"]);
    assert_eq!(rows.len(), 11);
    for r in &rows {
        assert!(close(r[4], u(r[2], r[3]).1, 1e-3, 1e-10), "{r:?}");
        assert!(close(r[1], (r[2] * r[2] + r[3] * r[3]).sqrt(), 1.0, 1e-14));
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "ok");
    assert_eq!(summary["cells"], 64);
    assert_eq!(summary["nodes"], 81);
    assert_eq!(summary["dofs"], 2 * 49);
    assert_eq!(summary["steps"], 0);
    assert_eq!(summary["fractured_cells"], 0);
    for phase in [
        "total", "grid", "assembly", "solve", "flow", "stepping", "output",
    ] {
        assert!(summary["wall_seconds"][phase].as_f64().unwrap() >= 0.0);
    }
    assert!(summary["peak_memory_bytes"].as_u64().unwrap() > 0);
    assert!(out.join("vtk/step_0000.vtu").is_file());
    let pvd = std::fs::read_to_string(out.join("patch_test.pvd")).unwrap();
    assert!(pvd.contains("vtk/step_0000.vtu"));
    let vtu = std::fs::read_to_string(out.join("vtk/step_0000.vtu")).unwrap();
    assert!(vtu.contains("Name=\"displacement\""));
    for plot in ["ux.png", "syy.png", "smin.png", "line_diagonal.png"] {
        assert!(out.join("plots").join(plot).is_file(), "{plot}");
    }
    // One output time: no time series to draw (the values are in probes.csv).
    assert!(!out.join("plots/probes.png").exists());
    let (header, rows) = read_csv(&out.join("fracture.csv"));
    assert_eq!(header, ["cell", "x [m]", "y [m]", "time [s]", "mode"]);
    assert!(rows.is_empty());
    // The grid read back from the written .vtu is the grid the run used.
    let g: porofrac_grid::Grid<2> =
        porofrac_grid::io::read_vtu(out.join("vtk/step_0000.vtu")).unwrap();
    assert_eq!(g.num_cells(), 64);
}

#[test]
fn hybrid_scene_matches_the_uniaxial_solution_at_every_time() {
    let out = tmp_dir("hybrid");
    let scene = root().join("scenes/hybrid_uniaxial.toml");
    run_ok(&scene, &out);
    let (e, nu) = (1e9, 0.3);
    let (header, rows) = read_csv(&out.join("probes.csv"));
    assert_eq!(
        header,
        [
            "time [s]",
            "uy_top [m]",
            "ux_right [m]",
            "syy_well [Pa]",
            "sxx_far [Pa]"
        ]
    );
    let times: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(times, [0.0, 30.0, 60.0, 90.0, 120.0]);
    for r in &rows {
        let p = 1e7 * (r[0] / 60.0).min(1.0);
        assert!(
            close(r[1], -p * 30.0 * (1.0 - nu * nu) / e, 0.3, 1e-9),
            "{r:?}"
        );
        assert!(
            close(r[2], p * 30.0 * nu * (1.0 + nu) / e, 0.3, 1e-9),
            "{r:?}"
        );
        assert!(close(r[3], -p, 1e7, 1e-9), "{r:?}");
        assert!(close(r[4], 0.0, 1e7, 1e-9), "{r:?}");
    }
    let (_, line) = read_csv(&out.join("lines/vertical.csv"));
    assert_eq!(line.len(), 5 * 31);
    for r in &line {
        let p = 1e7 * (r[0] / 60.0).min(1.0);
        assert!(
            close(r[4], -p * r[3] * (1.0 - nu * nu) / e, 0.3, 1e-9),
            "{r:?}"
        );
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["steps"], 4);
    // All laws are linear: one symbolic and one numeric factorization for all steps.
    assert_eq!(summary["solver"]["symbolic_factorizations"], 1);
}

/// Write `text` as `<name>.toml` in a fresh directory and run `porofrac check` on it.
fn check_text(name: &str, text: &str) -> (i32, String) {
    let dir = tmp_dir(name);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let (code, _, err) = porofrac(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
    ]);
    (code, err)
}

fn patch_text() -> String {
    std::fs::read_to_string(root().join("scenes/patch_test.toml")).unwrap()
}

/// The 1-based line of the first line containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn invalid_values_name_file_line_and_key() {
    let text = patch_text().replace("poisson_ratio = 0.3", "poisson_ratio = 0.5");
    let (code, err) = check_text("nu", &text);
    assert_eq!(code, 1);
    let line = line_of(&text, "poisson_ratio");
    assert_eq!(
        err.trim(),
        format!("error: nu.toml:{line}: material.rock.poisson_ratio = 0.5 must be < 0.5")
    );

    let text = patch_text().replace("youngs_modulus = 1.0e9", "youngs_modulus = -1.0");
    let (code, err) = check_text("e", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!(
            "e.toml:{}: material.rock.youngs_modulus = -1 must be in 1e-3 … 1e15 Pa",
            line_of(&text, "youngs")
        )),
        "{err}"
    );
}

#[test]
fn unknown_keys_and_types_are_errors() {
    let text = patch_text().replace("poisson_ratio = 0.3", "poisson = 0.3");
    let (code, err) = check_text("unknown", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!("unknown.toml:{}:", line_of(&text, "poisson = "))),
        "{err}"
    );
    assert!(
        err.contains("unknown key `poisson` in [material.rock]; did you mean `poisson_ratio`?"),
        "{err}"
    );
    let text = patch_text().replace("cells = [8, 8]", "cells = \"many\"");
    let (code, err) = check_text("types", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!("types.toml:{}:", line_of(&text, "cells = "))),
        "{err}"
    );
}

#[test]
fn bad_expressions_and_references_are_errors() {
    let text = patch_text().replacen("3e-4*y\"]", "3e-4*yy\"]", 1);
    let (code, err) = check_text("expr", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!(
            "expr.toml:{}: bc[0].displacement",
            line_of(&text, "yy")
        )),
        "{err}"
    );
    assert!(err.contains("unknown name `yy`"), "{err}");

    let text = patch_text().replace("material = \"rock\"", "material = \"granite\"");
    let (code, err) = check_text("refs", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!(
            "refs.toml:{}: region[0].material = \"granite\" is not a defined material",
            line_of(&text, "granite")
        )),
        "{err}"
    );

    let text = patch_text().replace("boundary = \"ymax\"", "boundary = \"top\"");
    let (code, err) = check_text("side", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!(
            "side.toml:{}: bc[3].boundary = \"top\"",
            line_of(&text, "\"top\"")
        )),
        "{err}"
    );
}

#[test]
fn singular_systems_name_the_free_rigid_modes() {
    let mut text = patch_text();
    let start = text.find("[[bc]]").unwrap();
    let end = text.find("[[output.probe]]").unwrap();
    text.replace_range(
        start..end,
        "[[bc]]\nboundary = \"ymin\"\ndisplacement = [\"free\", 0.0]\n\n",
    );
    let (code, err) = check_text("singular", &text);
    assert_eq!(code, 1);
    assert!(err.contains("translation x"), "{err}");
    assert!(!err.contains("rotation"), "{err}");
}

#[test]
fn missing_mesh_file_and_misuse() {
    let text = patch_text().replace(
        "kind = \"cartesian\"",
        "kind = \"file\"\npath = \"nowhere.msh\"",
    );
    let (code, err) = check_text("mesh", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains("grid.path = ") && err.contains("nowhere.msh"),
        "{err}"
    );

    let (code, _, _) = porofrac(&["frobnicate"]);
    assert_eq!(code, 2);
    let (code, _, _) = porofrac(&["run"]);
    assert_eq!(code, 2);
    let (code, _, err) = porofrac(&["run", "/nonexistent/scene.toml"]);
    assert_eq!(code, 1);
    assert!(err.contains("scene.toml"), "{err}");
    let (code, out, _) = porofrac(&[
        "check",
        root().join("scenes/hybrid_uniaxial.toml").to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    assert!(out.contains("ok"));
}

/// `scenes/tension_band.toml`: σyy = E/(1 − ν²)·1e-4·t until the weak band fails at the
/// first step with σyy > 5e5 Pa (t = 5 s); all 20 band triangles fail then, in tension,
/// and the plate carries no stress afterwards (|σyy| < 1e-6 of the pre-failure value).
#[test]
fn tension_band_fails_at_the_predicted_time() {
    let out = tmp_dir("band");
    let scene = root().join("scenes/tension_band.toml");
    run_ok(&scene, &out);
    let e_prime = 1e9 / (1.0 - 0.25f64 * 0.25);
    let (_, rows) = read_csv(&out.join("probes.csv"));
    assert_eq!(rows.len(), 9);
    for r in &rows {
        let t = r[0];
        if t < 5.0 {
            assert!(close(r[1], e_prime * 1e-4 * t, 1e5, 1e-10), "{r:?}");
            assert_eq!(r[2], 0.0);
        } else {
            assert!(r[1].abs() < 1e-6 * 5e5, "{r:?}");
            assert_eq!(r[2], 1.0);
        }
    }
    let text = std::fs::read_to_string(out.join("fracture.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "cell,x [m],y [m],time [s],mode");
    assert_eq!(lines.len(), 21);
    for l in &lines[1..] {
        let f: Vec<&str> = l.split(',').collect();
        let y: f64 = f[2].parse().unwrap();
        assert!((0.4..=0.5).contains(&y), "{l}");
        assert_eq!((f[3], f[4]), ("5", "tensile"));
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["fractured_cells"], 20);
}

/// `scenes/flow_column.toml`: pressure diffusion on a fixed skeleton (coupling "none"),
/// drained top, closed bottom. Every sampled cell pressure at t = 10, 20, 30 s matches the
/// Fourier series within 0.5 % of p0 (implicit Euler with Δt = 0.25 s, 100 cells).
#[test]
fn flow_column_matches_the_fourier_series() {
    let out = tmp_dir("flow");
    let scene = root().join("scenes/flow_column.toml");
    run_ok(&scene, &out);
    let (p0, h, c) = (1e7, 10.0, 1e-13 / (1e-3 * 0.3 * 1e-9));
    let exact = |y: f64, t: f64| -> f64 {
        (0..200)
            .map(|m| {
                let k = (2 * m + 1) as f64 * std::f64::consts::PI;
                4.0 / k * (k * (h - y) / (2.0 * h)).sin() * (-k * k * c * t / (4.0 * h * h)).exp()
            })
            .sum::<f64>()
            * p0
    };
    let (_, rows) = read_csv(&out.join("lines/pressure.csv"));
    let mut worst: f64 = 0.0;
    for r in rows.iter().filter(|r| r[0] > 0.0) {
        worst = worst.max((r[4] - exact(r[3], r[0])).abs() / p0);
    }
    assert_eq!(rows.len(), 4 * 100);
    assert!(worst < 5e-3, "worst {worst:e}");
    let (_, probes) = read_csv(&out.join("probes.csv"));
    assert_eq!(probes[0][1], p0);
    let vtu = std::fs::read_to_string(out.join("vtk/step_0003.vtu")).unwrap();
    assert!(vtu.contains("Name=\"pressure\""));
}

/// The patch test solved by damped explicit dynamics (`solver.mechanics = "explicit"`,
/// Cundall damping, density scaling) reaches the affine solution to 1e-6 relative.
#[test]
fn explicit_mechanics_reaches_the_static_solution() {
    let text = patch_text().replace(
        "poisson_ratio = 0.3",
        "poisson_ratio = 0.3\ndensity = 2500.0",
    ) + "\n[solver]\nmechanics = \"explicit\"\ntolerance = 1e-10\n";
    let dir = tmp_dir("explicit");
    let path = dir.join("explicit.toml");
    std::fs::write(&path, &text).unwrap();
    let out = dir.join("out");
    run_ok(&path, &out);
    let (l, m) = lame();
    let sxx = (l + 2.0 * m) * 1e-3 + l * 3e-4;
    let (_, rows) = read_csv(&out.join("probes.csv"));
    assert!(close(rows[0][1], 7e-4, 7e-4, 1e-6), "{}", rows[0][1]);
    assert!(close(rows[0][2], sxx, sxx, 1e-6), "{}", rows[0][2]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["solver"]["linear"], "explicit");
    assert!(summary["solver"]["iterations"].as_u64().unwrap() > 0);
    // Without a density the explicit solver is refused with the key named.
    let text = patch_text() + "\n[solver]\nmechanics = \"explicit\"\n";
    let (code, err) = check_text("nodensity", &text);
    assert_eq!(code, 1);
    assert!(err.contains("material.rock.density is required"), "{err}");
}

/// `scenes/terzaghi.toml`: coupled (monolithic) Terzaghi consolidation through the scene
/// path. At every written time (T = c_v t/H² ≈ 0.25, 0.5, 0.75, 1.0) the pressure along the
/// column is within 1 % of the undrained pressure p_i of the series solution, and the top
/// settlement within 1 % of the closed form s0 + (s∞ − s0)·U(T).
#[test]
fn terzaghi_scene_matches_the_series_solution() {
    let out = tmp_dir("terzaghi");
    let scene = root().join("scenes/terzaghi.toml");
    run_ok(&scene, &out);
    let (e, nu, h, sigma0) = (1e9, 0.25, 10.0, 1e6);
    let m = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let s = 0.3 * 1e-10;
    let p_i = sigma0 / (1.0 + s * m);
    let cv = (1e-15 / 1e-3) / (s + 1.0 / m);
    let series = |f: &dyn Fn(f64) -> f64| {
        (0..200)
            .map(|k| f((2 * k + 1) as f64 * std::f64::consts::PI))
            .sum::<f64>()
    };
    let (_, rows) = read_csv(&out.join("lines/pressure.csv"));
    let mut worst: f64 = 0.0;
    for r in rows.iter().filter(|r| r[0] > 0.0) {
        let (t, y) = (r[0], r[3]);
        let exact = 1e7
            + p_i
                * series(&|k| {
                    4.0 / k
                        * (k * (h - y) / (2.0 * h)).sin()
                        * (-k * k * cv * t / (4.0 * h * h)).exp()
                });
        worst = worst.max((r[4] - exact).abs() / p_i);
    }
    assert_eq!(rows.len(), 5 * 50);
    assert!(worst < 1e-2, "pressure error {worst:e} of p_i");
    let (s_inf, s0) = (sigma0 * h / m, sigma0 * h / (m + 1.0 / s));
    // Probes are sampled at every step (400 of 216 s); the settlement is checked at the
    // written times, those of the line.
    let (_, probes) = read_csv(&out.join("probes.csv"));
    assert_eq!(probes.len(), 401);
    let written: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let at_written: Vec<&Vec<f64>> = probes
        .iter()
        .filter(|r| r[0] > 0.0 && written.contains(&r[0]))
        .collect();
    assert_eq!(at_written.len(), 4);
    for r in at_written {
        let tt = cv * r[0] / (h * h);
        let u = 1.0 - series(&|k| 8.0 / (k * k) * (-k * k * tt / 4.0).exp());
        let exact = -(s0 + (s_inf - s0) * u);
        assert!(
            (r[2] - exact).abs() < 1e-2 * exact.abs(),
            "t = {}: {} vs {exact}",
            r[0],
            r[2]
        );
    }
}

/// `scenes/cantilever.toml`: Timoshenko–Goodier cantilever, plane stress, VEM on
/// 128 × 16 squares: the tip deflection is within 1 % of the exact 2.07, and the
/// deflection line within 1 % of the exact `uy(x, 0)` at every sample.
#[test]
fn cantilever_scene_tip_deflection_within_one_percent() {
    let out = tmp_dir("cantilever");
    let scene = root().join("scenes/cantilever.toml");
    run_ok(&scene, &out);
    let (_, rows) = read_csv(&out.join("probes.csv"));
    let tip = rows[0][1];
    assert!((tip - 2.07).abs() < 0.01 * 2.07, "tip {tip}");
    let (_, line) = read_csv(&out.join("lines/deflection.csv"));
    for r in &line {
        let x = r[2];
        let exact = 0.002 * (5.5 * x / 4.0 + (24.0 - x) * x * x);
        assert!((r[4] - exact).abs() <= 0.01 * 2.07, "{r:?} vs {exact}");
    }
}

/// A 3D scene (tetrahedra, nested-dissection ordering): uniaxial traction with rollers
/// gives `uz = −p z/E`, `ux = ν p x/E` at every probe to 1e-9 relative.
#[test]
fn three_d_uniaxial_scene() {
    let text = r#"
[scene]
name = "cube"
dim = 3
[grid]
kind = "tetrahedra"
extent = [[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]
cells = [4, 5, 6]
seed = 2
perturb = 0.2
[[region]]
name = "rock"
select = { all = true }
law = "mdem"
material = "rock"
[material.rock]
youngs_modulus = 2.0e9
poisson_ratio = 0.2
[[bc]]
boundary = "xmin"
displacement = [0.0, "free", "free"]
[[bc]]
boundary = "ymin"
displacement = ["free", 0.0, "free"]
[[bc]]
boundary = "zmin"
displacement = ["free", "free", 0.0]
[[bc]]
boundary = "zmax"
traction = [0.0, 0.0, -4.0e6]
[output]
plots = false
[[output.probe]]
name = "uz"
field = "uz"
at = [0.3, 1.1, 3.0]
[[output.probe]]
name = "ux"
field = "ux"
at = [1.0, 0.7, 1.3]
[[output.probe]]
name = "szz"
field = "szz"
at = [0.5, 0.5, 0.5]
"#;
    let dir = tmp_dir("cube");
    let path = dir.join("cube.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    run_ok(&path, &out);
    let (p, e, nu) = (4e6, 2e9, 0.2);
    let (_, rows) = read_csv(&out.join("probes.csv"));
    assert!(close(rows[0][1], -p * 3.0 / e, 6e-3, 1e-9), "{:?}", rows[0]);
    assert!(
        close(rows[0][2], nu * p * 1.0 / e, 6e-3, 1e-9),
        "{:?}",
        rows[0]
    );
    assert!(close(rows[0][3], -p, p, 1e-9), "{:?}", rows[0]);
}

/// `scenes/manufactured_e2.toml` through the scene path at n = 20, 40 and 80: the largest
/// error of ux at the grid nodes on the diagonal falls with a fitted order 2 ± 0.2, and is
/// below 2 % of max |ux| = 0.01 at n = 40.
#[test]
fn manufactured_scene_converges_at_second_order() {
    let base = std::fs::read_to_string(root().join("scenes/manufactured_e2.toml")).unwrap();
    let mut errors = Vec::new();
    for n in [20usize, 40, 80] {
        let text = base
            .replace("cells = [40, 40]", &format!("cells = [{n}, {n}]"))
            .replace("points = 41", &format!("points = {}", n + 1));
        let dir = tmp_dir(&format!("mms{n}"));
        let path = dir.join("mms.toml");
        std::fs::write(&path, text).unwrap();
        let out = dir.join("out");
        let (code, _, err) = porofrac(&[
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        let (_, rows) = read_csv(&out.join("lines/diagonal_ux.csv"));
        let worst = rows
            .iter()
            .map(|r| {
                (r[4]
                    - (std::f64::consts::PI * r[2]).sin() * (std::f64::consts::PI * r[3]).sin()
                        / 100.0)
                    .abs()
            })
            .fold(0.0f64, f64::max);
        errors.push(worst);
    }
    let order1 = (errors[0] / errors[1]).log2();
    let order2 = (errors[1] / errors[2]).log2();
    assert!(errors[1] < 2e-2 * 0.01, "{errors:?}");
    assert!(
        (order1 - 2.0).abs() < 0.2 && (order2 - 2.0).abs() < 0.2,
        "{errors:?} orders {order1} {order2}"
    );
}

/// The rigid platen with the Biot coupling: Terzaghi's column loaded through a platen
/// carrying the total force σ0·width instead of the traction gives the same pressures and
/// settlements (the exact solution has a uniform top displacement) to 1e-8 relative.
#[test]
fn platen_with_coupling_matches_the_traction_load() {
    let base = std::fs::read_to_string(root().join("scenes/terzaghi.toml")).unwrap();
    let platen = base.replace(
        "traction = [0.0, -1.0e6]",
        "platen = { force = [\"free\", -1.0e6] }\n[[bc]]\nboundary = \"ymax\"",
    );
    assert_ne!(platen, base);
    let mut results = Vec::new();
    for (name, text) in [("traction", &base), ("platen", &platen)] {
        let dir = tmp_dir(&format!("platen-{name}"));
        let path = dir.join("terzaghi.toml");
        std::fs::write(&path, text).unwrap();
        let out = dir.join("out");
        let (code, _, err) = porofrac(&[
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{name}: {err}");
        results.push(read_csv(&out.join("probes.csv")).1);
    }
    assert_eq!(results[0].len(), results[1].len());
    for (a, b) in results[0].iter().zip(&results[1]) {
        assert!(close(a[1], b[1], 1e7, 1e-8), "{a:?} vs {b:?}");
        assert!(close(a[2], b[2], 1e-2, 1e-8), "{a:?} vs {b:?}");
    }
}

/// `[solver] threads = 1` runs the scene in a one-thread pool; the assembly is bitwise
/// independent of the thread count, so the outputs equal the default run's exactly.
#[test]
fn thread_count_does_not_change_the_result() {
    let dir = tmp_dir("threads");
    let text = std::fs::read_to_string(root().join("scenes/patch_test.toml")).unwrap();
    assert!(!text.contains("[solver]"));
    let one = dir.join("one.toml");
    std::fs::write(&one, format!("{text}\n[solver]\nthreads = 1\n")).unwrap();
    run_ok(&root().join("scenes/patch_test.toml"), &dir.join("default"));
    run_ok(&one, &dir.join("one"));
    let read = |d: &str| std::fs::read_to_string(dir.join(d).join("probes.csv")).unwrap();
    assert_eq!(read("default"), read("one"));
    let (code, err) = check_text("threads.toml", &format!("{text}\n[solver]\nthreads = -1\n"));
    assert_eq!(code, 1);
    assert!(err.contains("solver.threads"), "{err}");
}

/// Flow on a fixed skeleton with `linear = "cg-amg"`: the pressure systems are solved by
/// CG with a scalar AMG preconditioner to 1e-12; every probe equals the Cholesky run's to
/// 1e-9 of the initial pressure.
#[test]
fn flow_with_cg_amg_matches_cholesky() {
    let dir = tmp_dir("flow-amg");
    let text = std::fs::read_to_string(root().join("scenes/flow_column.toml")).unwrap();
    assert!(!text.contains("[solver]"));
    let amg = dir.join("amg.toml");
    std::fs::write(
        &amg,
        format!("{text}\n[solver]\nlinear = \"cg-amg\"\ntolerance = 1.0e-12\n"),
    )
    .unwrap();
    run_ok(&root().join("scenes/flow_column.toml"), &dir.join("direct"));
    run_ok(&amg, &dir.join("amg"));
    let (h1, direct) = read_csv(&dir.join("direct/probes.csv"));
    let (h2, cg) = read_csv(&dir.join("amg/probes.csv"));
    assert_eq!(h1, h2);
    assert_eq!(direct.len(), cg.len());
    let p0 = direct[0][1].abs().max(1.0);
    for (a, b) in direct.iter().zip(&cg) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-9 * p0, "{a:?} vs {b:?}");
        }
    }
}

#[test]
fn fracture_toughness_transmissivity_and_lag_keys_are_checked() {
    // The scene of Nilsen et al. (2017) §3 with fluid lag: a fixed fracture permeability,
    // no toughness.
    let seed =
        std::fs::read_to_string(root().join("scenes/hydrofrac_seed_fluid_lag.toml")).unwrap();
    // A toughness needs a tensile strength.
    let text = seed.replace("tensile_strength = 2.0e5", "fracture_toughness = 1.0e5");
    let (code, err) = check_text("toughness_alone", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!(
            "toughness_alone.toml:{}: material.rock.fracture_toughness needs tensile_strength",
            line_of(&text, "fracture_toughness")
        )),
        "{err}"
    );
    let text = seed.replace(
        "tensile_strength = 2.0e5",
        "tensile_strength = 2.0e5\nfracture_toughness = -1.0",
    );
    let (code, err) = check_text("toughness_negative", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains("material.rock.fracture_toughness = -1 must be > 0"),
        "{err}"
    );
    // One of fracture_permeability and fracture_transmissivity.
    let text = seed.replace(
        "fracture_permeability = 1.0e-12",
        "fracture_permeability = 1.0e-12\nfracture_transmissivity = 1.0e-13",
    );
    let (code, err) = check_text("both_permeabilities", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!(
            "both_permeabilities.toml:{}: physics.fracture_transmissivity and \
             fracture_permeability both set",
            line_of(&text, "fracture_transmissivity")
        )),
        "{err}"
    );
    // No fluid lag is a property of a fracturing flow.
    let text = seed.replace("fracture = true", "fracture = false").replace(
        "crack_tracking = 45.0",
        "fluid_lag = false\ncrack_tracking = 45.0",
    );
    let (code, err) = check_text("lag_without_fracture", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains(&format!(
            "lag_without_fracture.toml:{}: physics.fluid_lag needs fracture = true and flow = true",
            line_of(&text, "fluid_lag = false")
        )),
        "{err}"
    );
    let text = seed.replace(
        "fracture_permeability = 1.0e-12",
        "fracture_transmissivity = 0.0",
    );
    let (code, err) = check_text("transmissivity_zero", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains("physics.fracture_transmissivity = 0 must be > 0"),
        "{err}"
    );
}
