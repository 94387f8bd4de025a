//! `[loading] wall = "wetted"` through the scene: the small borehole rock of
//! `lsm_hydrofrac.rs` (b = 8 m, a = 1.5 m, radii 0.1–0.5 m, 449 disks) loaded dry on the
//! faces a fluid would wet breaks within 10 % of the same rock loaded by the rays
//! (measured 1.890 vs 1.852 MPa), as the
//! fluid-driven run of that test does (within 1 %: this hole is lined by small disks with
//! shallow notches, unlike the rock of `lsm_hydrofrac.toml`, see `lsm_wall_loads.rs`);
//! and the keys are checked.

use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Scene, Silent};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-lsmwet-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const ROCK: &str = r#"
[scene]
name = "wet"
dim = 2
model = "lsm"

[particles]
kind = "random"
disk = { center = [0.0, 0.0], radius = 8.0 }
hole = { center = [0.0, 0.0], radius = 1.5 }
radius = [0.1, 0.5]
packing_fraction = 0.8
seed = 1
density = 2600.0

[bonds]
youngs_modulus = 10.0e9
poisson_ratio = 0.2
tensile_strength = 5.0e6
cohesion = 10.0e6
friction_angle = 30.0
tolerance = 0.05

[lsm]
damping = "local"

[schedule]
end_time = 0.25
steps = 10

[[output.probe]]
name = "pressure"
field = "pressure"
"#;

fn parse(text: &str) -> Result<Scene, String> {
    Scene::parse(text, Path::new("wet.toml"), LawRegistry::default()).map_err(|e| e.to_string())
}

fn breakdown(name: &str, loading: &str) -> f64 {
    let out = tmp(name);
    parse(&format!(
        "{ROCK}[loading]\npressure_rate = 1.0e7\n{loading}"
    ))
    .unwrap()
    .run(&out, &mut Silent)
    .unwrap();
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    s["initiation_pressure"].as_f64().unwrap()
}

#[test]
fn the_wetted_wall_breaks_the_small_rock_where_the_fluid_does() {
    let rays = breakdown("rays", "");
    let wet = breakdown("wet", "wall = \"wetted\"\nwall_spacing = 0.05\n");
    eprintln!("first break: rays {rays:.4e} Pa, wetted {wet:.4e} Pa");
    assert!((wet / rays - 1.0).abs() < 0.1, "{wet} vs {rays}");
}

#[test]
fn wall_keys_are_checked() {
    let cases = [
        ("[loading]\nwall = \"wetted\"\n", "loading.wall"),
        (
            "[loading]\npressure_rate = 1.0e7\nwall_spacing = 0.05\n",
            "loading.wall_spacing",
        ),
        (
            "[loading]\npressure_rate = 1.0e7\nwall = \"wetted\"\nwall_spacing = -1.0\n",
            "loading.wall_spacing",
        ),
        // the flooded crack needs the dry pressure wall
        ("[loading]\nflood_cracks = true\n", "loading.flood_cracks"),
        // the extent of the wall crack needs a pressurised hole
        (
            "[[output.probe]]\nname = \"e\"\nfield = \"crack_extent\"\n",
            "field = \"crack_extent\" needs a pressurised hole",
        ),
        // the line of the key, the key and the words it accepts
        (
            "[loading]\npressure_rate = 1.0e7\nwall = \"wet\"\n",
            "loading.wall = \"wet\": expected one of \"rays\", \"wetted\"",
        ),
    ];
    for (loading, key) in cases {
        let e = parse(&format!("{ROCK}{loading}")).unwrap_err();
        assert!(e.contains(key), "{key}: {e}");
    }
}

/// `[loading] crack_across_pores` joins the cracks of a hole: without one it is refused,
/// naming the key and its line.
#[test]
fn crack_across_pores_needs_a_hole() {
    let rock = ROCK.replace("hole = { center = [0.0, 0.0], radius = 1.5 }\n", "");
    assert_ne!(rock, ROCK);
    let text = format!("{rock}[loading]\ncrack_across_pores = true\n");
    let line = text.lines().count();
    let e = parse(&text).unwrap_err();
    assert!(
        e.contains("loading.crack_across_pores") && e.contains("needs a hole"),
        "{e}"
    );
    assert!(e.contains(&format!(":{line}")), "{e}");
}
