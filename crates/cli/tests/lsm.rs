//! `porofrac run` on small lattice solid scenes: the outputs every particle scene must
//! offer, broken bonds logged by mode, and bad input refused with the key named.

mod common;

use common::{read_csv, run_text, summary};

const SCENE: &str = r#"
[scene]
name = "lsm_small"
dim = 2
model = "lsm"

[particles]
kind = "hexagonal"
disk = { center = [0.0, 0.0], radius = 6.0 }
hole = { center = [0.0, 0.0], radius = 1.5 }
radius = 0.5
density = 1000.0

[bonds]
youngs_modulus = 1.0e9
poisson_ratio = 0.2
tensile_strength = 1.0e6
cohesion = 2.0e6
friction_angle = 30.0

[lsm]
damping = "local"
damping_coefficient = 0.7

[loading]
pressure_rate = 2.5e7

[schedule]
end_time = 0.15
steps = 15

[output]
every = 5

[[output.probe]]
name = "pressure"
field = "pressure"

[[output.probe]]
name = "broken"
field = "broken"

[[output.probe]]
name = "x0"
field = "x"
particle = 0
"#;

#[test]
fn small_borehole_scene_runs_and_logs_broken_bonds() {
    let (code, err, out) = run_text("lsm_small", SCENE);
    assert_eq!(code, 0, "{err}");
    let s = summary(&out);
    let particles = s["particles"].as_u64().unwrap();
    let bonds = s["bonds"].as_u64().unwrap();
    let broken = s["broken_bonds"].as_u64().unwrap();
    assert!(
        particles > 50 && bonds > 2 * particles,
        "{particles} particles, {bonds} bonds"
    );
    assert!(broken > 0, "the pressure ramp breaks bonds");
    assert_eq!(
        broken,
        s["broken_tensile"].as_u64().unwrap() + s["broken_shear"].as_u64().unwrap()
    );
    assert!(s["bond_updates_per_second"].as_f64().unwrap() > 0.0);
    // The first break is at or above the pressure of a thick cylinder whose wall hoop
    // stress reaches the bond strength, within a factor of two (the lattice is coarse).
    let pb = s["initiation_pressure"].as_f64().unwrap();
    assert!(pb > 0.0 && pb < 2.5e7 * 0.15, "first break at {pb}");
    let text = std::fs::read_to_string(out.join("broken.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("time [s],i,j,x [m],y [m],mode"));
    assert_eq!(lines.clone().count() as u64, broken);
    assert!(lines.all(|l| l.ends_with(",tensile") || l.ends_with(",shear")));
    let (header, rows) = read_csv(&out.join("probes.csv"));
    assert_eq!(header, ["time [s]", "pressure [Pa]", "broken", "x0 [m]"]);
    // Probes at every step (16 output times), VTK every 5th.
    assert_eq!(rows.len(), 16);
    assert_eq!(rows[0][1], 0.0);
    assert!((rows.last().unwrap()[1] - 2.5e7 * 0.15).abs() < 1.0);
    for f in [
        "vtk/particles_0000.vtp",
        "vtk/contacts_0000.vtp",
        "plots/particles.png",
        "plots/breakage.png",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let vtp = std::fs::read_to_string(out.join("vtk/particles_0003.vtp")).unwrap();
    assert!(vtp.contains("Name=\"broken_bonds\"") && vtp.contains("Name=\"displacement\""));
}

#[test]
fn bad_lsm_input_names_the_key() {
    let cases = [
        (
            "[lsm]\ndamping = \"local\"\ndamping_coefficient = 0.7",
            "[lsm]\ndt = 1.0\n",
            "lsm.dt",
        ),
        (
            "poisson_ratio = 0.2\n",
            "poisson_ratio = 0.2\nkn = -1.0\n",
            "bonds.kn",
        ),
        (
            "youngs_modulus = 1.0e9\npoisson_ratio = 0.2\n",
            "kn = -1.0e9\n",
            "bonds.kn",
        ),
        (
            "friction_angle = 30.0\n",
            "friction_angle = 30.0\nstiffness = 1\n",
            "stiffness",
        ),
        ("[schedule]", "[contact]\nmu = 0.3\n\n[schedule]", "contact"),
        (
            "poisson_ratio = 0.2\n",
            "poisson_ratio = 0.4\n",
            "bonds.poisson_ratio",
        ),
    ];
    for (from, to, key) in cases {
        assert!(SCENE.contains(from), "{from}");
        let text = SCENE.replacen(from, to, 1);
        let (code, err, _) = run_text("lsm_bad", &text);
        assert_ne!(code, 0, "{to}");
        assert!(err.contains(key), "{to}: {err}");
    }
    // Overlapping particles.
    let listed = SCENE.replace(
        "kind = \"hexagonal\"\ndisk = { center = [0.0, 0.0], radius = 6.0 }\nhole = { center = [0.0, 0.0], radius = 1.5 }\nradius = 0.5\n",
        "kind = \"list\"\ncentres = [[0.0, 0.0], [0.5, 0.0]]\nradii = [0.5, 0.5]\n",
    );
    let listed = listed.replace("[loading]\npressure_rate = 2.5e7\n", "");
    let (code, err, _) = run_text("lsm_overlap", &listed);
    assert_ne!(code, 0);
    assert!(
        err.contains("particles") && err.contains("overlap"),
        "{err}"
    );
    // An lsm section in another model's scene.
    let (code, err, _) = run_text(
        "lsm_in_nscd",
        &SCENE.replace("model = \"lsm\"", "model = \"nscd\""),
    );
    assert_ne!(code, 0);
    assert!(err.contains("lsm"), "{err}");
}
