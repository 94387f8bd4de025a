//! `porofrac keys`, the generated docs/SCENE.md and docs/summary.schema.json, `--set`,
//! and the summaries of short bundled scenes of every model against the schema.

mod common;

use common::{porofrac, read_csv, root, summary, tmp_dir};

/// The text of a generated file, or a failure saying the command that regenerates it.
fn fresh(file: &str, args: &[&str], command: &str) {
    let (code, generated, err) = porofrac(args);
    assert_eq!(code, 0, "{err}");
    let path = root().join(file);
    let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        on_disk == generated,
        "{file} is stale: regenerate it with `cargo run --release -p porofrac-cli -- {}` \
         (the command `{command}`)",
        args.join(" ") + " > " + file
    );
}

#[test]
fn the_key_reference_is_generated() {
    fresh(
        "docs/SCENE.md",
        &["keys", "--markdown"],
        porofrac_scene::common::keys::MARKDOWN_COMMAND,
    );
}

#[test]
fn the_summary_schema_is_generated() {
    fresh(
        "docs/summary.schema.json",
        &["keys", "--summary-schema"],
        porofrac_scene::common::keys::SUMMARY_SCHEMA_COMMAND,
    );
}

#[test]
fn keys_lists_a_model_and_a_section() {
    let (code, out, _) = porofrac(&["keys", "continuum", "grid"]);
    assert_eq!(code, 0);
    assert!(
        out.starts_with("[grid]  (models: continuum, cosserat)\n"),
        "{out}"
    );
    assert!(out.contains("\n  cells "), "{out}");
    assert!(!out.contains("[[bc]]"), "{out}");
    // A model sees its sections and the shared ones it reads, not the others'.
    let (_, nscd, _) = porofrac(&["keys", "nscd"]);
    assert!(
        nscd.contains("[nscd]") && nscd.contains("[particles]"),
        "{nscd}"
    );
    assert!(
        !nscd.contains("[grid]") && !nscd.contains("[bonds]"),
        "{nscd}"
    );
    // One word that is not a model is a section, of every model.
    let (_, bc, _) = porofrac(&["keys", "bc"]);
    assert!(bc.starts_with("[[bc]]"), "{bc}");
    assert!(bc.contains("(model cosserat)"), "{bc}");
    let (code, _, err) = porofrac(&["keys", "nscd", "grid"]);
    assert_eq!(code, 2);
    assert!(
        err.starts_with("error: no section `grid` in model \"nscd\""),
        "{err}"
    );
}

#[test]
fn set_overrides_keys_and_is_recorded() {
    let scene = root().join("scenes/patch_test.toml");
    let scene = scene.to_str().unwrap();
    let dir = tmp_dir("keys-set");
    let (a, b) = (dir.join("a"), dir.join("b"));
    let (code, _, err) = porofrac(&["run", scene, "--out", a.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = porofrac(&[
        "run",
        scene,
        "--out",
        b.to_str().unwrap(),
        "--set",
        "material.rock.youngs_modulus=2e9",
        "--set",
        "output.plots=false",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        summary(&b)["overrides"],
        serde_json::json!({"material.rock.youngs_modulus": 2e9, "output.plots": false})
    );
    assert!(summary(&a).get("overrides").is_none());
    // The patch test's stress is linear in E: twice E, twice σxx.
    let (head, rows_a) = read_csv(&a.join("probes.csv"));
    let (_, rows_b) = read_csv(&b.join("probes.csv"));
    let col = head.iter().position(|h| h == "sxx_center [Pa]").unwrap();
    let (sa, sb) = (rows_a[0][col], rows_b[0][col]);
    assert!(sa.abs() > 0.0);
    assert!((sb / sa - 2.0).abs() < 1e-9, "{sa} {sb}");
    // An error in an override names the option, not a line.
    let (code, _, err) = porofrac(&["check", scene, "--set", "grid.cells=many"]);
    assert_eq!(code, 1);
    assert_eq!(
        err.trim_end(),
        "error: patch_test.toml: --set grid.cells: grid.cells = \"many\": expected a number \
         of cells per axis, e.g. [40, 20] (voronoi: one number)"
    );
    let (code, _, err) = porofrac(&["check", scene, "--set", "material.rock.youngs_modulus"]);
    assert_eq!(code, 1);
    assert_eq!(
        err.trim_end(),
        "error: --set material.rock.youngs_modulus: expected KEY=VALUE, e.g. --set \
         material.rock.youngs_modulus=2e10"
    );
}

#[test]
fn summaries_of_short_bundled_scenes_match_the_schema() {
    let dir = tmp_dir("keys-summaries");
    for (scene, set) in [
        ("patch_test", vec![]),
        ("cantilever", vec![]),
        ("flow_column", vec![]),
        ("cosserat_shear_layer", vec![]),
        ("lbm/taylor_green", vec![]),
        ("nscd/column", vec![]),
        (
            "lsm/brazilian",
            vec!["schedule.end_time=0.2", "schedule.steps=20"],
        ),
    ] {
        let out = dir.join(scene.replace('/', "_"));
        let path = root().join(format!("scenes/{scene}.toml"));
        let mut args = vec![
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        for s in &set {
            args.extend(["--set", s]);
        }
        let (code, _, err) = porofrac(&args);
        assert_eq!(code, 0, "{scene}: {err}");
        // `summary` validates against docs/summary.schema.json.
        let s = summary(&out);
        assert_eq!(s["status"], "ok", "{scene}");
    }
    // The keys of model nscd are described, not merely allowed: a contact count that is
    // a number instead of `{ last, mean, max }` is refused, for model nscd only.
    let mut s = summary(&dir.join("nscd_column"));
    let schema = common::schema::summary_schema();
    s["contacts"] = serde_json::json!(10);
    assert!(common::schema::validate(&schema, &s).is_err());
    s["model"] = serde_json::json!("lsm");
    assert!(common::schema::validate(&schema, &s).is_ok());
}
