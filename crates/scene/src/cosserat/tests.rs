//! Scenes of the Cosserat model run through the library, against closed forms, and the
//! errors of bad scenes (each naming its key).

use std::path::{Path, PathBuf};

use porofrac_cosserat::reference::{ShearLayer, hole_scf};

use crate::{LawRegistry, Scene, Silent};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-cosserat-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn read_csv(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// The bundled shear-layer scene: φ and u1 along x = 0 within 2 % of the closed form
/// (points where the reference is not ~0), τ within 1 %.
#[test]
fn shear_layer_scene_matches_the_closed_form() {
    let scene = Scene::load(&scenes_dir().join("cosserat_shear_layer.toml")).unwrap();
    let out = out_dir("shear");
    let summary = scene.run(&out, &mut Silent).unwrap();
    assert_eq!(summary.status, "ok");
    let exact = ShearLayer::new(1e-3, 1e10, 2e10, 100.0, [0.0, 0.0, 1e-5, 0.0]);
    let probes = read_csv(&out.join("probes.csv"));
    assert!(
        (probes[0][1] / exact.tau - 1.0).abs() < 0.01,
        "τ = {}",
        probes[0][1]
    );
    for (file, f, scale) in [
        ("phi", &(|x| exact.phi(x)) as &dyn Fn(f64) -> f64, 5.4e-3),
        ("u1", &(|x| exact.u1(x)) as &dyn Fn(f64) -> f64, 1e-5),
    ] {
        let rows = read_csv(&out.join("lines").join(format!("{file}.csv")));
        assert_eq!(rows.len(), 21);
        for r in &rows[1..20] {
            let (y, v) = (r[3], r[4]);
            let want = f(y);
            if want.abs() > 1e-3 * scale {
                assert!(
                    (v - want).abs() < 0.02 * want.abs(),
                    "{file}({y}) = {v}, want {want}"
                );
            }
        }
    }
    for f in [
        "vtk/step_0000.vtu",
        "plots/syy.png",
        "plots/phi.png",
        "summary.json",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let vtu = std::fs::read_to_string(out.join("vtk/step_0000.vtu")).unwrap();
    for name in ["displacement", "rotation", "stress", "couple_stress"] {
        assert!(vtu.contains(&format!("Name=\"{name}\"")), "{name}");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// The bundled plate-with-a-hole scene: the maximum cell σ_yy within 4 % of the analytic
/// SCF (N = 0.5, r/ℓ = 1.063: 2.5548) on its 5,120-triangle mesh.
#[test]
fn plate_hole_scene_scf() {
    let scene = Scene::load(&scenes_dir().join("cosserat_plate_hole.toml")).unwrap();
    let out = out_dir("plate");
    let summary = scene.run(&out, &mut Silent).unwrap();
    let scf = summary.field_extrema["syy"][1];
    let want = hole_scf(0.3, 0.5, 0.216, 0.216 / 1.063);
    assert!((scf - want).abs() < 0.04 * want, "SCF {scf} vs {want}");
    let _ = std::fs::remove_dir_all(&out);
}

const BASE: &str = r#"
[scene]
name = "t"
dim = 2
model = "cosserat"
[grid]
kind = "triangles"
extent = [[0.0, 0.0], [1.0, 1.0]]
cells = [4, 4]
[[region]]
name = "all"
select = { all = true }
law = "cosserat-dem"
material = "m"
[material.m]
shear_modulus = 1.0e3
poisson_ratio = 0.25
cosserat_shear_modulus = 500.0
characteristic_length = 0.1
[[bc]]
boundary = "ymin"
displacement = [0.0, 0.0]
rotation = 0.0
[[bc]]
boundary = "ymax"
traction = [0.0, 1.0]
"#;

fn error_of(text: &str) -> String {
    match Scene::parse(text, Path::new("t.toml"), LawRegistry::default()) {
        Ok(s) => match s.run(&out_dir("err"), &mut Silent) {
            Ok(_) => String::new(),
            Err(e) => e.to_string(),
        },
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_small_scene_runs_with_dynamics() {
    let text = format!(
        "{BASE}\n[schedule]\nend_time = 0.01\nsteps = 5\n[solver]\ntime_integration = \"explicit\"\n\
         [[output.probe]]\nname = \"k\"\nfield = \"kinetic\"\nat = [0.5, 0.5]\n"
    )
    .replace("characteristic_length = 0.1", "characteristic_length = 0.1\ndensity = 1.0\nmicro_inertia = 0.01");
    assert_eq!(error_of(&text), "");
}

#[test]
fn bad_scenes_name_their_key() {
    for (from, to, key) in [
        ("characteristic_length = 0.1", "", "characteristic_length"),
        (
            "shear_modulus = 1.0e3",
            "shear_modulus = -1.0",
            "shear_modulus",
        ),
        (
            "cosserat_shear_modulus = 500.0",
            "cosserat_shear_modulus = -5.0",
            "cosserat_shear_modulus",
        ),
        ("kind = \"triangles\"", "kind = \"cartesian\"", "grid.kind"),
        (
            "rotation = 0.0",
            "rotation = [0.0, 0.0, 0.0]",
            "bc[0].rotation",
        ),
        ("law = \"cosserat-dem\"", "law = \"vem\"", "region[0].law"),
        (
            "poisson_ratio = 0.25",
            "poisson_ratio = 0.25\npermeability = 1e-12",
            "permeability",
        ),
    ] {
        let text = BASE.replace(from, to);
        let e = error_of(&text);
        assert!(e.contains(key), "{key}: got `{e}`");
    }
    // A Cosserat key in a continuum scene names the key and the model.
    let cont = BASE
        .replace("model = \"cosserat\"", "model = \"continuum\"")
        .replace("law = \"cosserat-dem\"", "law = \"vem\"")
        .replace("shear_modulus = 1.0e3", "youngs_modulus = 1.0e3");
    let e = error_of(&cont);
    assert!(
        e.contains("cosserat_shear_modulus") && e.contains("cosserat"),
        "{e}"
    );
    // Dynamics without micro_inertia.
    let e = error_of(&format!("{BASE}\n[schedule]\nend_time = 1.0\nsteps = 2\n"));
    assert!(e.contains("density") || e.contains("micro_inertia"), "{e}");
}

/// `[solver] linear` and `tolerance`: the continuum model's solvers are refused naming the
/// key, a tolerance outside (0, 1) names its key, and GMRES with the multigrid runs,
/// reaching the tolerance asked for.
#[test]
fn linear_solver_keys() {
    let with = |extra: &str| format!("{BASE}\n[solver]\n{extra}\n");
    let e = error_of(&with("linear = \"cholesky\""));
    assert!(e.contains("solver.linear") && e.contains("cosserat"), "{e}");
    let e = error_of(&with("linear = \"gmres-amg\"\ntolerance = 2.0"));
    assert!(e.contains("solver.tolerance"), "{e}");
    let scene = Scene::parse(
        &with("linear = \"gmres-amg\"\ntolerance = 1e-11"),
        Path::new("t.toml"),
        LawRegistry::default(),
    )
    .unwrap();
    let s = scene.run(&out_dir("gmres"), &mut Silent).unwrap();
    assert_eq!(s.solver.linear, "gmres-amg");
    assert!(
        s.solver.iterations > 0 && s.solver.max_relative_residual <= 1e-11,
        "{:?}",
        s.solver
    );
}

/// `[solver] stencil`: the bundled plate-with-a-hole scene with the seed's rule is further
/// from the analytic SCF than with the default rule (5,120 O-grid triangles: measured
/// −1.06 % against −3.45 % of 2.5548); a misspelt rule names the key; the key in a
/// continuum scene names the key and the model.
#[test]
fn stencil_key() {
    let path = scenes_dir().join("cosserat_plate_hole.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let want = hole_scf(0.3, 0.5, 0.216, 0.216 / 1.063);
    let scf = |extra: &str| {
        let scene =
            Scene::parse(&format!("{text}\n{extra}"), &path, LawRegistry::default()).unwrap();
        let out = out_dir(&format!("stencil{}", extra.len()));
        let s = scene.run(&out, &mut Silent).unwrap();
        let _ = std::fs::remove_dir_all(&out);
        (s.field_extrema["syy"][1] - want) / want
    };
    let default = scf("");
    let seed = scf("[solver]\nstencil = \"first-interpolating\"");
    assert!(
        default.abs() < 0.015 && seed.abs() > 0.03,
        "default {default}, seed's rule {seed}"
    );
    let e = error_of(&format!("{BASE}\n[solver]\nstencil = \"nearest\"\n"));
    assert!(e.contains("solver.stencil"), "{e}");
    let cont = BASE
        .replace("model = \"cosserat\"", "model = \"continuum\"")
        .replace("law = \"cosserat-dem\"", "law = \"vem\"")
        .replace("shear_modulus = 1.0e3", "youngs_modulus = 1.0e3")
        .replace("cosserat_shear_modulus = 500.0\n", "")
        .replace("characteristic_length = 0.1\n", "")
        .replace("rotation = 0.0\n", "");
    let e = error_of(&format!(
        "{cont}\n[solver]\nstencil = \"smallest-weight\"\n"
    ));
    assert!(
        e.contains("solver.stencil") && e.contains("cosserat"),
        "{e}"
    );
}
