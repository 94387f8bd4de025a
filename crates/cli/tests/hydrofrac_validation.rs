//! The crack flow from the opening through the command (`[physics] crack_flow`).
//!
//! Checks:
//! * `crack_flow = "fixed"` written out gives the seed's scene (`scenes/hydrofrac_seed.toml`)
//!   the same failures and probes, to the last digit, as the scene without the key: the
//!   default keeps every existing result.
//! * `crack_flow` without fracturing flow, `crack_flow = "cubic-law"` together with
//!   `fracture_permeability`, and an unknown value are refused by `check`, naming the key
//!   and its line.
//! * `crack_flow = "cubic-law"` on the seed's scene runs, and its crack (on the
//!   transmissivity floor of the seed, 1e-13 m³, then its own opening) keeps the seed's
//!   orientation: one crack along y through the well (every fractured cell farther than
//!   two cells from the well wall within one cell size, √2/12 m, of the line x = 15 m).

mod common;

use common::{porofrac, root, run_ok, tmp_dir};

fn seed() -> String {
    std::fs::read_to_string(root().join("scenes/hydrofrac_seed.toml")).unwrap()
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

/// `text` written as `<name>.toml` in a fresh directory: its path.
fn write(name: &str, text: &str) -> std::path::PathBuf {
    let dir = tmp_dir(name);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// `porofrac check` on `text`: exit status and stderr.
fn check_text(name: &str, text: &str) -> (i32, String) {
    let path = write(name, text);
    let (code, _, err) = porofrac(&["check", path.to_str().unwrap()]);
    (code, err)
}

/// The seed with `extra` added to `[physics]` after `fluid_lag`.
fn with_physics(extra: &str) -> String {
    let base = seed();
    let anchor = "fluid_lag = false";
    assert!(base.contains(anchor));
    base.replacen(anchor, &format!("{extra}\n{anchor}"), 1)
}

#[test]
fn crack_flow_fixed_is_the_default_to_the_last_digit() {
    let out_a = tmp_dir("cf_default").join("out");
    let out_b = tmp_dir("cf_fixed").join("out");
    run_ok(&write("cf_default", &seed()), &out_a);
    run_ok(
        &write("cf_fixed", &with_physics("crack_flow = \"fixed\"")),
        &out_b,
    );
    for file in ["fracture.csv", "probes.csv"] {
        let a = std::fs::read_to_string(out_a.join(file)).unwrap();
        let b = std::fs::read_to_string(out_b.join(file)).unwrap();
        assert!(a.lines().count() > 10, "{file}: {a}");
        assert_eq!(a, b, "{file} differs");
    }
}

#[test]
fn crack_flow_keys_out_of_place_are_refused_naming_the_key_and_line() {
    // Without fracture and flow (the patch test is static elasticity).
    let base = std::fs::read_to_string(root().join("scenes/patch_test.toml")).unwrap();
    let text = format!("{base}\n[physics]\ncrack_flow = \"cubic-law\"\n");
    let line = line_of(&text, "crack_flow");
    let (code, err) = check_text("cf_no_flow", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(":{line}:")) && err.contains("physics.crack_flow"),
        "{err}"
    );
    assert!(
        err.contains("needs fracture = true and flow = true"),
        "{err}"
    );

    // With a fixed fracture permeability.
    let text = with_physics("crack_flow = \"cubic-law\"\nfracture_permeability = 1e-12");
    let line = line_of(&text, "fracture_permeability");
    let (code, err) = check_text("cf_with_k", &text);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(":{line}:")) && err.contains("physics.fracture_permeability"),
        "{err}"
    );
    assert!(err.contains("cubic-law"), "{err}");

    // An unknown value.
    let text = with_physics("crack_flow = \"quadratic\"");
    let line = line_of(&text, "crack_flow");
    let (code, err) = check_text("cf_unknown", &text);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(&format!(":{line}:")), "{err}");
    assert!(
        err.contains("crack_flow") && err.contains("cubic-law"),
        "{err}"
    );
}

#[test]
fn the_seed_with_the_cubic_law_grows_one_crack_along_y() {
    let out = tmp_dir("cf_cubic").join("out");
    run_ok(
        &write("cf_cubic", &with_physics("crack_flow = \"cubic-law\"")),
        &out,
    );
    // cell, x, y, time, mode (a word): the coordinates.
    let text = std::fs::read_to_string(out.join("fracture.csv")).unwrap();
    assert!(text.starts_with("cell,x [m],y [m],"), "{text}");
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .skip(1)
                .take(2)
                .map(|v| v.parse().unwrap())
                .collect()
        })
        .collect();
    let (ix, iy) = (0, 1);
    let cell = 2f64.sqrt() / 12.0;
    let far: Vec<&Vec<f64>> = rows
        .iter()
        .filter(|r| ((r[ix] - 15.0).powi(2) + (r[iy] - 15.0).powi(2)).sqrt() > 0.25 + 2.0 * cell)
        .collect();
    assert!(far.len() >= 20, "{} cells away from the wall", far.len());
    for r in &far {
        assert!(
            (r[ix] - 15.0).abs() <= cell,
            "cell at ({}, {})",
            r[ix],
            r[iy]
        );
    }
}
