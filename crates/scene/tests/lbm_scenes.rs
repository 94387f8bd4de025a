//! Lattice Boltzmann scenes (`model = "lbm"`) through the library.
//!
//! * Poiseuille flow between halfway walls driven by `body_force` with TRT: the probe on a
//!   node row gives `a/(2ν) y (H − y)` to 1e-6 (TRT with Λ = 3/16 is exact for it), and
//!   `summary.json` carries the `lattice` block, `mlups` and `field_extrema`; the `.vti`
//!   and `.pvd` files and the speed, vorticity and probe plots are written.
//! * A disk at rest in a closed box of fluid at rest: the obstacle probes `fx fy torque`
//!   are zero to round-off.
//! * Heat through the scene: conduction between a wall at 10 °C and one at 30 °C across
//!   the Poiseuille channel reaches the linear profile (1e-9), and `temperature` is in
//!   `field_extrema` and the `.vti`.
//! * Bad scenes are refused with the key: keys of the continuum model, `tau = 0.5`, an
//!   unknown precision, an obstacle entirely outside the extent, a wall faster than the Mach limit, a thermal diffusivity
//!   too small for the lattice, a thermal side without a condition, a field
//!   of another model, and `[lbm]` in a continuum scene.

use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Scene, Silent};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-lbm-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn parse(text: &str) -> Result<Scene, String> {
    Scene::parse(text, Path::new("t.toml"), LawRegistry::default()).map_err(|e| e.to_string())
}

const POISEUILLE: &str = r#"
[scene]
name = "poiseuille"
model = "lbm"
dim = 2

[lbm]
extent = [[0.0, 0.0], [0.004, 0.01]]
spacing = 1.0e-3
density = 1000.0
viscosity = 1.0e-6
tau = 0.8
collision = "trt"
periodic = ["x"]
body_force = [1.0e-5, 0.0]

[[lbm.boundary]]
side = "ymin"
kind = "wall"

[[lbm.boundary]]
side = "ymax"
kind = "wall"

[schedule]
end_time = 2000.0
steps = 4

[[output.probe]]
name = "u"
field = "vx"
at = [0.0015, 0.0035]

[[output.probe]]
name = "p"
field = "pressure"
at = [0.0015, 0.0035]
"#;

#[test]
fn poiseuille_scene_is_exact_and_writes_its_outputs() {
    let scene = parse(POISEUILLE).unwrap();
    let out = tmp("poiseuille");
    scene.run(&out, &mut Silent).unwrap();
    let csv = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let last: Vec<f64> = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let (a, nu, h, y) = (1.0e-5, 1.0e-6, 0.01, 0.0035);
    let exact = a / (2.0 * nu) * y * (h - y);
    assert!(
        (last[1] / exact - 1.0).abs() < 1e-6,
        "u = {} vs {exact}",
        last[1]
    );
    assert!(last[2].abs() < 1e-9, "pressure {}", last[2]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let lat = &summary["lattice"];
    assert_eq!(lat["nodes"], serde_json::json!([4, 10]));
    // Δt = (τ − ½)/3 Δx²/ν
    assert!((lat["time_step"].as_f64().unwrap() - 0.1).abs() < 1e-12);
    assert_eq!(lat["lattice_steps"].as_u64().unwrap(), 20000);
    assert!(lat["mach"].as_f64().unwrap() > 0.0 && lat["mach"].as_f64().unwrap() < 0.3);
    assert!(summary["mlups"].as_f64().unwrap() > 0.0);
    let vx = summary["field_extrema"]["vx"].as_array().unwrap();
    let umax = a * h * h / (8.0 * nu);
    // the largest node velocity is half a spacing off the centre
    let top = a / (2.0 * nu) * 0.0045 * (h - 0.0045);
    assert!((vx[1].as_f64().unwrap() / top - 1.0).abs() < 1e-6 && top < umax);
    let vti = std::fs::read(out.join("vtk/step_0004.vti")).unwrap();
    assert!(vti.len() > 40 * 6 * 8, "vti of {} bytes", vti.len());
    assert!(
        std::fs::read_to_string(out.join("poiseuille.pvd"))
            .unwrap()
            .contains("step_0004.vti")
    );
    for png in ["speed.png", "vorticity.png", "probes.png"] {
        assert!(
            std::fs::metadata(out.join("plots").join(png))
                .unwrap()
                .len()
                > 0,
            "{png}"
        );
    }
}

#[test]
fn disk_at_rest_feels_no_force_through_the_scene() {
    let text = r#"
[scene]
name = "disk"
model = "lbm"
dim = 2

[lbm]
extent = [[0.0, 0.0], [0.03, 0.02]]
spacing = 1.0e-3
density = 1000.0
viscosity = 1.0e-6
tau = 0.9

[[obstacle]]
name = "disk"
shape = { circle = { center = [0.0123, 0.0101], radius = 0.0042 } }

[[obstacle]]
name = "block"
shape = { box = [[0.02, 0.004], [0.0263, 0.0151]] }

[schedule]
end_time = 20.0
steps = 2

[output]
vtk = false
plots = false

[[output.probe]]
name = "fx"
field = "fx"
obstacle = "disk"

[[output.probe]]
name = "fy"
field = "fy"
obstacle = "block"

[[output.probe]]
name = "torque"
field = "torque"
obstacle = "disk"
"#;
    let out = tmp("disk");
    parse(text).unwrap().run(&out, &mut Silent).unwrap();
    let csv = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    for line in csv.lines().skip(1) {
        for v in line.split(',').skip(1) {
            let v: f64 = v.parse().unwrap();
            // force unit ρ Δx³/Δt² = 1000 · 1e-9 / 0.16 ≈ 6e-6 N/m: 1e-12 of it is round-off
            assert!(v.abs() < 1e-16, "{line}");
        }
    }
}

fn refused(text: &str, key: &str, words: &str) {
    match parse(text) {
        Ok(_) => panic!("accepted a scene with {key}"),
        Err(e) => {
            assert!(e.contains(key) && e.contains(words), "{e}");
            assert!(e.starts_with("t.toml:"), "{e}");
        }
    }
}

#[test]
fn bad_lbm_scenes_name_the_key() {
    refused(
        &POISEUILLE.replace("[schedule]", "[grid]\nkind = \"cartesian\"\n\n[schedule]"),
        "grid",
        "belongs to model \"continuum\"",
    );
    refused(
        &POISEUILLE.replace("tau = 0.8", "tau = 0.5"),
        "lbm.tau",
        "0.505",
    );
    refused(
        &POISEUILLE.replace(
            "collision = \"trt\"",
            "collision = \"trt\"\nprecision = \"half\"",
        ),
        "precision",
        "half",
    );
    let with_disk = format!(
        "{POISEUILLE}\n[[obstacle]]\nname = \"d\"\nshape = {{ circle = {{ center = [0.002, 0.0125], radius = 0.002 }} }}\n"
    );
    refused(
        &with_disk,
        "obstacle[0].shape",
        "entirely outside lbm.extent along y",
    );
    refused(
        &POISEUILLE.replace(
            "side = \"ymax\"\nkind = \"wall\"",
            "side = \"ymax\"\nkind = \"wall\"\nvelocity = [0.01, 0.0]",
        ),
        "lbm.boundary[1].velocity",
        "Mach",
    );
    refused(
        &format!("{POISEUILLE}\n[thermal]\ndiffusivity = 1e-9\n"),
        "thermal.diffusivity",
        "relaxation time",
    );
    refused(
        &format!(
            "{POISEUILLE}\n[thermal]\ndiffusivity = 1e-6\n[[thermal.boundary]]\nside = \"ymin\"\n"
        ),
        "thermal.boundary[0].side",
        "exactly one of temperature, flux and outflow = true",
    );
    refused(
        &format!("{POISEUILLE}\n[thermal]\ndiffusivity = 1e-6\nparticle_temperature = 80.0\n"),
        "thermal.particle_temperature",
        "belongs to model \"lsm\"",
    );
    refused(
        &POISEUILLE.replace("field = \"vx\"", "field = \"temperature\""),
        "output.probe[0].field",
        "needs [thermal]",
    );
    refused(
        &POISEUILLE.replace("field = \"vx\"", "field = \"ux\""),
        "output.probe[0].field",
        "not a field of model \"lbm\"",
    );
    refused(
        &POISEUILLE.replace("side = \"ymin\"", "side = \"xmin\""),
        "lbm.boundary[0].side",
        "periodic axis",
    );
    let continuum = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/patch_test.toml"
    ))
    .unwrap();
    refused(
        &format!(
            "{continuum}\n[lbm]\nextent = [[0.0, 0.0], [1.0, 1.0]]\nspacing = 0.1\ndensity = 1.0\nviscosity = 1.0\ntau = 0.8\n"
        ),
        "lbm",
        "belongs to model \"lbm\"",
    );
}

#[test]
fn conduction_through_the_scene() {
    let text = POISEUILLE.replace("body_force = [1.0e-5, 0.0]", "")
        + r#"
[thermal]
diffusivity = 1.0e-6
initial = "20 + 100 * x"

[[thermal.boundary]]
side = "ymin"
temperature = 10.0

[[thermal.boundary]]
side = "ymax"
temperature = 30.0

[[output.probe]]
name = "T"
field = "temperature"
at = [0.0015, 0.0035]
"#;
    let out = tmp("conduction");
    parse(&text).unwrap().run(&out, &mut Silent).unwrap();
    let csv = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let last: Vec<f64> = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let exact = 10.0 + 20.0 * 0.0035 / 0.01;
    assert!((last[3] - exact).abs() < 1e-9, "T = {} vs {exact}", last[3]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let t = summary["field_extrema"]["temperature"].as_array().unwrap();
    assert!(
        (t[0].as_f64().unwrap() - 11.0).abs() < 1e-9
            && (t[1].as_f64().unwrap() - 29.0).abs() < 1e-9
    );
    let vti = String::from_utf8_lossy(&std::fs::read(out.join("vtk/step_0004.vti")).unwrap())
        .into_owned();
    assert!(vti.contains("Name=\"temperature\""));
}
