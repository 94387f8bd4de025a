//! Lattice solid scenes with a fluid and heat (`[lbm]`, `[thermal]`) through the
//! `porofrac` binary: hot held grains in a channel cooled by fluid flowing through. Checks:
//! the heat books of `summary.json` balance (total now = start + side inflow) to 1e-10
//! relative, heat leaves the grains and their mean temperature in `heat.csv` falls from
//! 80 °C; the fluid block and the images are written. A grain below two lattice spacings
//! is an error naming `lbm.spacing`.

mod common;

use common::{read_csv, run_text, summary};

const SCENE: &str = r#"
[scene]
name = "lsm_heat_small"
dim = 2
model = "lsm"

[particles]
kind = "random"
region = [[0.005, 0.0], [0.025, 0.02]]
radius = [0.002, 0.003]
packing_fraction = 0.4
seed = 3
density = 2600.0

[bonds]
youngs_modulus = 1.0e5
poisson_ratio = 0.2
tolerance = 0.5

[lsm]
damping = "local"

[loading]
platens = { velocity = 1.0e-9, thickness = 0.01 }

[lbm]
extent = [[0.0, 0.0], [0.03, 0.02]]
spacing = 0.0005
density = 1000.0
viscosity = 1.0e-5
tau = 0.8

[[lbm.boundary]]
side = "xmin"
kind = "pressure"
pressure = 0.3

[[lbm.boundary]]
side = "xmax"
kind = "pressure"
pressure = 0.0

[thermal]
diffusivity = 1.0e-6
solid_diffusivity = 4.0e-6
initial = 20.0
particle_temperature = 80.0

[[thermal.boundary]]
side = "xmin"
temperature = 20.0

[[thermal.boundary]]
side = "xmax"
outflow = true

[schedule]
end_time = 1.0
steps = 4
"#;

#[test]
fn hot_grains_cool_in_flowing_fluid_and_the_heat_books_balance() {
    let (code, err, out) = run_text("lsm_heat_small", SCENE);
    assert_eq!(code, 0, "{err}");
    let s = summary(&out);
    let h = &s["heat"];
    let initial = h["initial"].as_f64().unwrap();
    let defect = h["defect"].as_f64().unwrap();
    assert!(defect.abs() < 1e-10 * initial, "{h}");
    assert!(h["particle_defect"].as_f64().unwrap().abs() < 1e-10 * initial);
    let extracted = h["extracted_from_particles"].as_f64().unwrap();
    assert!(
        extracted > 0.01 * h["particles_initial"].as_f64().unwrap(),
        "{h}"
    );
    assert_eq!(s["fluid"]["fluid_steps"].as_u64(), Some(400));
    let (header, rows) = read_csv(&out.join("heat.csv"));
    assert_eq!(header[0], "time [s]");
    assert_eq!(header[7], "mean_particle_temperature [°C]");
    assert_eq!(rows.len(), 5);
    assert!((rows[0][7] - 80.0).abs() < 1e-9);
    assert!(rows[4][7] < rows[0][7]);
    for png in [
        "fluid_speed.png",
        "fluid_pressure.png",
        "temperature.png",
        "particles_temperature.png",
    ] {
        assert!(out.join("plots").join(png).exists(), "{png}");
    }
}

#[test]
fn a_grain_below_two_lattice_spacings_names_the_spacing() {
    let text = SCENE.replace("spacing = 0.0005", "spacing = 0.0011");
    let (code, err, _) = run_text("lsm_fluid_coarse", &text);
    assert_eq!(code, 1);
    assert!(
        err.contains("lbm.spacing") && err.contains("below 2 lattice spacings"),
        "{err}"
    );
}
