//! Grains from an image and the heat books through scenes of model `lbm`.
//!
//! * The bundled `scenes/lbm/sandstone_heat.toml` (Mora et al. (2015), Fig. 10, on a
//!   synthetic sandstone image): 700 lattice steps, `heat_books.csv` has one row per step
//!   whose terms balance the change of the fluid's stored heat to 1e-8 relative (the
//!   summary's worst step too), the grains give heat (`solids > 0`), cold fluid flows in
//!   at the inlet, and the temperature and speed pictures are written.
//! * Held grains (`grains.held = true`) stay at their temperature (within 0.5 %), where
//!   conjugate grains cool.
//! * Bad `[grains]` are refused with the key, the file and, for a bad PGM, its line: a
//!   missing file, a malformed value, a hostile size, a threshold out of 0–1, a pixel size
//!   that is not positive, an image off the lattice, a noisy image that would make
//!   20 000 obstacles or more, `held` without a temperature,
//!   `temperature` without `[thermal]`, and `thermal.books` in a lattice solid scene.

use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Scene, Silent};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-grains-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bundled() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/lbm/sandstone_heat.toml")
}

#[test]
fn bundled_sandstone_keeps_its_heat_books() {
    let scene = Scene::load(&bundled()).unwrap();
    let out = tmp("bundled");
    scene.run(&out, &mut Silent).unwrap();
    let csv = std::fs::read_to_string(out.join("heat_books.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 700);
    let mut solids = 0.0;
    for (n, r) in rows.iter().enumerate() {
        assert_eq!(r[0], (n + 1) as f64);
        // after − before = conduction in + advection in − advection out + solids
        let defect = (r[2] - r[1]) - (r[3] + r[4] - r[5] + r[6]);
        assert!(
            defect.abs() < 1e-8 * r[1].abs(),
            "step {}: defect {defect:e} of {:e}",
            n + 1,
            r[1]
        );
        assert!(r[8].abs() < 1e-8, "step {}: {}", n + 1, r[8]);
        if n > 0 {
            // no node changes sides: one step's after is the next step's before
            assert_eq!(r[1], rows[n - 1][2]);
        }
        solids += r[6];
    }
    assert!(solids > 0.0, "the hot grains gave {solids} J/m");
    // the inlet's advected heat: u T at 20 °C on 100 links of 0.1 mm, ρ c_p = 4.18e6, Δt =
    // 1 ms, so 0.1 c_s = 5.7735 mm/s gives 20 × 4.18e6 × 5.7735e-3 × 0.01 × 1e-3 J/m per
    // step, less where the inlet's corner nodes lag and the fluid compresses
    let full = 20.0 * 4.18e6 * 5.7735e-3 * 0.01 * 1e-3;
    let first = rows[0][4];
    assert!(
        first > 0.9 * full && first <= 1.0001 * full,
        "{first} of {full}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let b = &summary["heat_books"];
    assert_eq!(b["steps"].as_u64(), Some(700));
    assert!(b["max_relative_defect"].as_f64().unwrap() < 1e-8);
    assert!((b["solids"].as_f64().unwrap() / solids - 1.0).abs() < 1e-12);
    for png in ["speed.png", "temperature.png"] {
        assert!(
            std::fs::metadata(out.join("plots").join(png))
                .unwrap()
                .len()
                > 0
        );
    }
}

/// The bundled scene with its image by absolute path, changed by `edit`.
fn variant(edit: impl Fn(String) -> String) -> String {
    let text = std::fs::read_to_string(bundled()).unwrap();
    let img = bundled().with_file_name("sandstone.png");
    edit(text.replace(
        "image = \"sandstone.png\"",
        &format!("image = {:?}", img.to_str().unwrap()),
    ))
}

fn parse(text: &str, dir: &Path) -> Result<Scene, String> {
    Scene::parse(text, &dir.join("t.toml"), LawRegistry::default()).map_err(|e| e.to_string())
}

#[test]
fn held_grains_stay_at_their_temperature() {
    let text = variant(|t| {
        t.replace("temperature = 80.0", "temperature = 80.0\nheld = true")
            .replace("end_time = 0.7", "end_time = 0.1")
    });
    let out = tmp("held");
    parse(&text, &out).unwrap().run(&out, &mut Silent).unwrap();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    // the grains' nodes are reset to 80 °C every step and are the hottest nodes (what
    // arrives at a grain node may overshoot by the advective term 3 c·u of the fluid's
    // equilibrium: within 0.5 %), where conjugate grains cool below 79 °C in 100 steps
    let t = summary["field_extrema"]["temperature"].as_array().unwrap();
    let hottest = t[1].as_f64().unwrap();
    assert!((hottest - 80.0).abs() < 0.4, "{hottest}");
    let out2 = tmp("conjugate");
    let text = variant(|t| t.replace("end_time = 0.7", "end_time = 0.1"));
    parse(&text, &out2)
        .unwrap()
        .run(&out2, &mut Silent)
        .unwrap();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out2.join("summary.json")).unwrap()).unwrap();
    let cooled = summary["field_extrema"]["temperature"][1].as_f64().unwrap();
    assert!(cooled < 79.0, "{cooled}");
    assert!(
        summary["heat_books"]["max_relative_defect"]
            .as_f64()
            .unwrap()
            < 1e-8
    );
}

fn refused(text: &str, dir: &Path, key: &str, words: &str) {
    match parse(text, dir) {
        Ok(_) => panic!("accepted a scene with {key} ({words})"),
        Err(e) => {
            assert!(e.contains(key) && e.contains(words), "{e}");
            assert!(e.contains("t.toml:"), "{e}");
        }
    }
}

#[test]
fn bad_grains_name_the_key_the_file_and_the_line() {
    let dir = tmp("bad");
    let base = variant(|t| t);
    let with_image = |name: &str| {
        base.replace(
            &format!(
                "image = {:?}",
                bundled().with_file_name("sandstone.png").to_str().unwrap()
            ),
            &format!("image = {name:?}"),
        )
    };
    refused(
        &with_image("missing.pgm"),
        &dir,
        "grains.image",
        "missing.pgm",
    );
    std::fs::write(dir.join("bad.pgm"), "P2\n# rock\n3 2\n255\n1 2 3\n4 x 6\n").unwrap();
    refused(&with_image("bad.pgm"), &dir, "grains.image", "line 6");
    std::fs::write(dir.join("huge.pgm"), "P5 100000 100000 255\n").unwrap();
    refused(
        &with_image("huge.pgm"),
        &dir,
        "grains.image",
        "100000 × 100000",
    );
    // a checkerboard of single-node grains: 20 000 obstacles or more are refused
    let mut noise = b"P5 300 200 255\n".to_vec();
    noise.extend((0..300 * 200).map(|n| {
        if (n % 300 + n / 300) % 2 == 0 {
            255u8
        } else {
            0
        }
    }));
    std::fs::write(dir.join("noise.pgm"), noise).unwrap();
    refused(
        &with_image("noise.pgm")
            .replace("pixel_size = 1.0e-4", "pixel_size = 5.0e-5")
            .replace("spacing = 1.0e-4", "spacing = 5.0e-5"),
        &dir,
        "grains.image",
        "rectangles",
    );
    std::fs::write(dir.join("notes.txt"), "hello").unwrap();
    refused(&with_image("notes.txt"), &dir, "grains.image", "not a PGM");
    refused(
        &base.replace("threshold = 0.5", "threshold = 1.5"),
        &dir,
        "grains.threshold",
        "0–1",
    );
    refused(
        &base.replace("pixel_size = 1.0e-4", "pixel_size = -1.0"),
        &dir,
        "grains.pixel_size",
        "positive",
    );
    refused(
        &base.replace(
            "pixel_size = 1.0e-4",
            "pixel_size = 1.0e-4\norigin = [1.0, 1.0]",
        ),
        &dir,
        "grains.image",
        "no lattice node",
    );
    refused(
        &base.replace("temperature = 80.0", "held = true"),
        &dir,
        "grains.held",
        "temperature",
    );
    let no_heat = base[..base.find("[thermal]").unwrap()].to_string()
        + &base[base.find("[schedule]").unwrap()..];
    refused(&no_heat, &dir, "grains.temperature", "[thermal]");
}

#[test]
fn books_belong_to_the_lattice_boltzmann_model() {
    let dir = tmp("lsm");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/lsm_heat.toml"),
    )
    .unwrap()
    .replace(
        "heat_capacity = 4.18e6",
        "heat_capacity = 4.18e6\nbooks = true",
    );
    refused(&text, &dir, "thermal.books", "lbm");
}
