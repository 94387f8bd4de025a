//! Fluid point probes of a lattice solid scene with `[lbm]` (`field = "fluid_pressure"`
//! or `"fluid_speed"` at `at = [x, y]`, bilinear between the fluid nodes).
//!
//! A ring of 12 bonded disks (R = 0.5 m, touching on a circle of radius 1.93 m, bonded
//! gaps sealed; E = 1e12 Pa: with 10 GPa its 1 mm expansion under the pressure squeezes
//! the closed box outside it to 2 % of the pressure) is filled by an injection at its centre, ramped to 2 MPa over 0.02 s and
//! held. Checks at 0.06 s: the probe at the centre reads the injection pressure (the mean
//! of the source nodes) within 1 % and so does a probe near the inner wall of the ring
//! (the fluid at rest carries one pressure); a probe outside the sealed ring reads below
//! 1 % of it (measured 0.22 %; a leaking ring would read the pressure itself); the speeds are below 1e-3 of the lattice's sound speed; a probe inside a
//! disk is empty (NaN). Bad probes name their key.

use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Scene, Silent};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-lsmprobe-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const RING: &str = r#"
[scene]
name = "ring"
dim = 2
model = "lsm"

[particles]
kind = "list"
centres = [[1.931852, 0.0], [1.673033, 0.965926], [0.965926, 1.673033], [0.0, 1.931852],
           [-0.965926, 1.673033], [-1.673033, 0.965926], [-1.931852, 0.0],
           [-1.673033, -0.965926], [-0.965926, -1.673033], [0.0, -1.931852],
           [0.965926, -1.673033], [1.673033, -0.965926]]
radii = [0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5]
density = 2600.0

[bonds]
youngs_modulus = 1.0e12
poisson_ratio = 0.2
tolerance = 0.05

[lsm]
damping = "local"
seal_bonds = true
"#;

const FLUID: &str = r#"
[lbm]
extent = [[-3.0, -3.0], [3.0, 3.0]]
spacing = 0.05
density = 1000.0
viscosity = 0.76
tau = 0.6

[injection]
center = [0.0, 0.0]
radius = 0.5
pressure = 2.0e6
ramp_time = 0.02

[schedule]
end_time = 0.06
steps = 6
"#;

const PROBES: &str = r#"
[[output.probe]]
name = "injection"
field = "pressure"

[[output.probe]]
name = "p_centre"
field = "fluid_pressure"
at = [0.0, 0.0]

[[output.probe]]
name = "p_wall"
field = "fluid_pressure"
at = [0.0, 1.3]

[[output.probe]]
name = "p_outside"
field = "fluid_pressure"
at = [2.7, 0.2]

[[output.probe]]
name = "p_in_disk"
field = "fluid_pressure"
at = [1.931852, 0.0]

[[output.probe]]
name = "speed_centre"
field = "fluid_speed"
at = [0.0, 0.0]

[[output.probe]]
name = "speed_wall"
field = "fluid_speed"
at = [0.0, 1.3]
"#;

fn parse(text: &str) -> Result<Scene, String> {
    Scene::parse(text, Path::new("ring.toml"), LawRegistry::default()).map_err(|e| e.to_string())
}

#[test]
fn fluid_probes_read_the_pressure_in_the_ring_and_none_outside() {
    let out = tmp("ring");
    let scene = parse(&format!("{RING}{FLUID}{PROBES}")).unwrap();
    scene.run(&out, &mut Silent).unwrap();
    let text = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let last: Vec<f64> = lines
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    // Columns by name: the header is `name [unit]`.
    let col = |n: &str| {
        last[head
            .iter()
            .position(|h| h.split(" [").next() == Some(n))
            .unwrap()]
    };
    let p = col("injection");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let u = s["fluid"]["spacing"].as_f64().unwrap() / s["fluid"]["time_step"].as_f64().unwrap();
    let sound = u / 3f64.sqrt();
    eprintln!(
        "t = {}: injection {p:.5e} Pa; centre {:.5e}, wall {:.5e}, outside {:.3e}, in a \
         disk {}; speeds {:.3e}, {:.3e} m/s (sound {sound:.3e} m/s)",
        col("time"),
        col("p_centre"),
        col("p_wall"),
        col("p_outside"),
        col("p_in_disk"),
        col("speed_centre"),
        col("speed_wall")
    );
    assert!(p > 1.9e6, "{p}");
    assert!((col("p_centre") / p - 1.0).abs() < 0.01);
    assert!((col("p_wall") / p - 1.0).abs() < 0.01);
    assert!(col("p_outside").abs() < 1e-2 * p);
    assert!(col("p_in_disk").is_nan());
    assert!(col("speed_centre") < 1e-3 * sound);
    assert!(col("speed_wall") < 1e-3 * sound);
}

#[test]
fn bad_fluid_probes_name_their_key() {
    let probe = |extra: &str| format!("[[output.probe]]\nname = \"q\"\n{extra}\n");
    let cases = [
        (
            format!(
                "{RING}[schedule]\nend_time = 0.01\nsteps = 1\n{}",
                probe("field = \"fluid_pressure\"\nat = [0.0, 0.0]")
            )
            .replace("seal_bonds = true\n", ""),
            "output.probe[0].field",
        ),
        (
            format!(
                "{RING}{FLUID}{}",
                probe("field = \"fluid_speed\"\nat = [9.0, 0.0]")
            ),
            "output.probe[0].at",
        ),
        (
            format!(
                "{RING}{FLUID}{}",
                probe("field = \"fluid_speed\"\nat = [0.0]")
            ),
            "output.probe[0].at",
        ),
        (
            format!(
                "{RING}{FLUID}{}",
                probe("field = \"fluid_pressure\"\nat = [0.0, 0.0]\nparticle = 1")
            ),
            "output.probe[0].particle",
        ),
        (
            format!(
                "{RING}{FLUID}{}",
                probe("field = \"pressure\"\nat = [0.0, 0.0]")
            ),
            "output.probe[0].at",
        ),
    ];
    for (text, key) in cases {
        let e = parse(&text).unwrap_err();
        assert!(e.contains(key), "{key}: {e}");
    }
}
