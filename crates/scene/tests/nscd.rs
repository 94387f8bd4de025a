//! Scenes of model "nscd" through the library: the bundled column runs and returns its
//! exact contact forces; bad input is refused with the key named.

use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Scene, Silent};

fn scene_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/nscd")
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-nscd-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The column of ten disks: each disk feels a net contact force m g upwards (probe fy
/// of the bottom disk), the floor carries 10 m g (largest normal force, and its reaction
/// probe), nothing moves; ten contacts at every step.
#[test]
fn column_scene_carries_its_weight() {
    let scene = Scene::load(&scene_dir().join("column.toml")).unwrap();
    let out = out_dir("column");
    let summary = scene.run(&out, &mut Silent).unwrap();
    assert_eq!(summary.status, "ok");
    let m = 1000.0 * std::f64::consts::PI * 0.25;
    let w = m * 9.81;
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["particles"], 10);
    assert_eq!(json["contacts"]["last"], 10);
    assert_eq!(json["contacts"]["max"], 10);
    assert_eq!(json["contacts"]["mean"], 10.0);
    assert_eq!(json["not_converged_steps"], 0);
    assert!(json["sweeps"]["max"].as_u64().unwrap() >= 1);
    assert!(json["contact_updates_per_second"].as_f64().unwrap() > 0.0);
    let nf = &json["field_extrema"]["normal_force"];
    assert!(
        (nf[1].as_f64().unwrap() - 10.0 * w).abs() < 1e-8 * 10.0 * w,
        "{nf}"
    );
    assert!(
        (nf[0].as_f64().unwrap() - w).abs() < 1e-8 * 10.0 * w,
        "{nf}"
    );
    let probes = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let last: Vec<f64> = probes
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(
        (last[1] - w).abs() < 1e-8 * w,
        "fy of the bottom disk {}",
        last[1]
    );
    assert!((last[2] - 9.5).abs() < 1e-9, "top disk at {}", last[2]);
    assert!(
        (last[4] - 10.0 * w).abs() < 1e-8 * 10.0 * w,
        "the floor's reaction {}, 10 m g = {}",
        last[4],
        10.0 * w
    );
    for f in [
        "vtk/particles_0005.vtp",
        "vtk/contacts_0005.vtp",
        "nscd_column.pvd",
        "nscd_column_contacts.pvd",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}

fn error_of(text: &str) -> String {
    let path = scene_dir().join("inline.toml");
    match Scene::parse(text, &path, LawRegistry::default()) {
        Err(e) => e.to_string(),
        Ok(scene) => scene
            .run(&out_dir("inline"), &mut Silent)
            .unwrap_err()
            .to_string(),
    }
}

const HEAD: &str =
    "[scene]\nname = \"t\"\ndim = 2\nmodel = \"nscd\"\n[schedule]\nend_time = 0.01\ndt = 0.001\n";

#[test]
fn bad_nscd_scenes_name_the_key() {
    let list = |centres: &str, radii: &str| {
        format!(
            "{HEAD}[particles]\nkind = \"list\"\ncentres = {centres}\nradii = {radii}\ndensity = 1000.0\n"
        )
    };
    let e = error_of(&list("[[0.0, 0.0]]", "[0.0]"));
    assert!(
        e.contains("particles.radii") && e.contains("positive radius"),
        "{e}"
    );
    let e = error_of(&list("[[0.0, 0.0], [0.1, 0.0]]", "[0.5, 0.5]"));
    assert!(
        e.contains("particles") && e.contains("alert distance"),
        "{e}"
    );
    let e = error_of(&format!(
        "{}[grid]\nkind = \"cartesian\"\n",
        list("[[0.0, 0.0]]", "[0.5]")
    ));
    assert!(e.contains("grid") && e.contains("\"continuum\""), "{e}");
    let e = error_of(&format!(
        "{}[nscd]\ntheta = 0.2\n",
        list("[[0.0, 0.0]]", "[0.5]")
    ));
    assert!(e.contains("nscd.theta"), "{e}");
    // Under 4e6 m/s² a disk falls 2 m in the first 1 ms step, more than its radius.
    let e = error_of(&format!(
        "{}[nscd]\ngravity = [0.0, -4.0e6]\n",
        list("[[0.0, 5.0]]", "[0.5]")
    ));
    assert!(
        e.contains("schedule.dt") && e.contains("more than its radius"),
        "{e}"
    );
    let e = error_of(&format!(
        "{}[[output.probe]]\nname = \"a\"\nfield = \"p\"\nparticle = 0\n",
        list("[[0.0, 0.0]]", "[0.5]")
    ));
    assert!(e.contains("output.probe[0].cell"), "{e}");
    let e = error_of(&format!(
        "{}[[output.probe]]\nname = \"a\"\nfield = \"vx\"\nparticle = 3\n",
        list("[[0.0, 0.0]]", "[0.5]")
    ));
    assert!(
        e.contains("output.probe[0].particle") && e.contains("1 particles"),
        "{e}"
    );
}

#[test]
fn continuum_scene_refuses_nscd_sections() {
    let text = "[scene]\nname = \"t\"\ndim = 2\n[grid]\nkind = \"cartesian\"\nextent = [[0.0, 0.0], [1.0, 1.0]]\ncells = [2, 2]\n[contact]\nmu = 0.3\n";
    let e = Scene::parse(text, Path::new("c.toml"), LawRegistry::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("contact") && e.contains("\"nscd\""), "{e}");
    let text = "[scene]\nname = \"t\"\ndim = 2\n";
    let e = Scene::parse(text, Path::new("c.toml"), LawRegistry::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("grid is missing"), "{e}");
}

/// Every bundled NSCD scene passes the checks (running them takes seconds each: see
/// docs/BENCHMARKS.md).
#[test]
fn bundled_nscd_scenes_check() {
    for name in ["column", "pile", "forced_fold", "fault"] {
        Scene::load(&scene_dir().join(format!("{name}.toml")))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}
