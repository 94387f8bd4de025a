//! Probes and words of a run through the `porofrac` binary:
//!
//! * **Probes every step**: the flagship `scenes/hydrofrac_seed.toml` (40 steps of 60 s,
//!   VTK every 10th) writes one `probes.csv` row per output time (41), and the rows at
//!   the VTK steps are bit-identical (the same text) to a run that samples the probes
//!   only at the VTK steps, as porofrac did before `probe_every` (sampling only reads the
//!   state); its `fracture.csv` is the same file too.
//! * **`probe_every = 3`**: rows at the steps that are multiples of 3 and at every VTK
//!   step (0, 3, 6, 9, 10, 12, …, 39, 40: 17 rows), each the same text as the default
//!   run's row of that time; `probe_every = 0` is refused naming the key and its line.
//! * **Units in headers**: `time [s]`, `p_well [Pa]`.
//! * **Words**: the progress line counts `step k/N` with N the steps after the initial
//!   state, as `summary.json` `steps` does; a continuum run counts fractured cells, a
//!   lattice Boltzmann run speaks of lattice nodes and never of fractures, a contact
//!   dynamics run of disks and contacts, and neither writes `cells`, `nodes` or
//!   `fractured_cells` into `summary.json`.

mod common;

use std::path::{Path, PathBuf};

use common::{porofrac, read_csv, root, run_ok as run, summary, tmp_dir};

/// The flagship scene with `edits` applied, written into `dir`.
fn flagship(dir: &Path, edits: &[(&str, &str)]) -> PathBuf {
    let mut t = std::fs::read_to_string(root().join("scenes/hydrofrac_seed.toml")).unwrap();
    for (from, to) in edits {
        assert!(t.contains(from), "the scene no longer contains {from:?}");
        t = t.replacen(from, to, 1);
    }
    let path = dir.join("scene.toml");
    std::fs::write(&path, t).unwrap();
    path
}

/// The data lines of a CSV file, keyed by their time column's text.
fn rows_by_time(path: &Path) -> Vec<(String, String)> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| (l.split(',').next().unwrap().to_string(), l.to_string()))
        .collect()
}

#[test]
fn flagship_probes_every_step_and_every_third_step_match_the_written_steps_bit_for_bit() {
    let dir = tmp_dir("probes-flagship");
    let out = dir.join("default");
    let err = run(&flagship(&dir, &[]), &out);
    let (header, rows) = read_csv(&out.join("probes.csv"));
    assert_eq!(header, ["time [s]", "p_well [Pa]", "p_above [Pa]"]);
    let times: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let expected: Vec<f64> = (0..=40).map(|k| 60.0 * k as f64).collect();
    assert_eq!(times, expected, "one row per output time");
    // Steps: 40 after the initial state, in the summary and in the progress line.
    assert_eq!(summary(&out)["steps"], 40);
    assert!(err.contains("step 40/40: "), "{err}");
    assert!(!err.contains("step 41/"), "{err}");
    assert!(err.contains("fractured cells"), "{err}");
    assert!(
        err.contains("19500 cells, 10375 nodes, 20657 unknowns, 19500 pressure unknowns, 40 steps"),
        "{err}"
    );

    // Sampling only at the VTK steps (every 10th), as before `probe_every`.
    let sub = dir.join("vtk-steps");
    std::fs::create_dir_all(&sub).unwrap();
    let vtk_only = sub.join("out");
    run(
        &flagship(&sub, &[("every = 10", "every = 10\nprobe_every = 1000")]),
        &vtk_only,
    );
    let old = rows_by_time(&vtk_only.join("probes.csv"));
    let new = rows_by_time(&out.join("probes.csv"));
    assert_eq!(
        old.iter().map(|r| r.0.as_str()).collect::<Vec<_>>(),
        ["0", "600", "1200", "1800", "2400"]
    );
    for (t, line) in &old {
        let same = new.iter().find(|r| &r.0 == t).expect("the time is sampled");
        assert_eq!(&same.1, line, "t = {t}");
    }
    assert_eq!(
        std::fs::read_to_string(out.join("fracture.csv")).unwrap(),
        std::fs::read_to_string(vtk_only.join("fracture.csv")).unwrap()
    );

    // Every third step and every VTK step.
    let sub = dir.join("every-third");
    std::fs::create_dir_all(&sub).unwrap();
    let third = sub.join("out");
    run(
        &flagship(&sub, &[("every = 10", "every = 10\nprobe_every = 3")]),
        &third,
    );
    let rows3 = rows_by_time(&third.join("probes.csv"));
    let steps: Vec<usize> = (0..=40).filter(|k| k % 3 == 0 || k % 10 == 0).collect();
    assert_eq!(steps.len(), 17);
    assert_eq!(
        rows3.iter().map(|r| r.0.clone()).collect::<Vec<_>>(),
        steps
            .iter()
            .map(|k| (60 * k).to_string())
            .collect::<Vec<_>>()
    );
    for (t, line) in &rows3 {
        let same = new.iter().find(|r| &r.0 == t).unwrap();
        assert_eq!(&same.1, line, "t = {t}");
    }
}

#[test]
fn probe_every_below_one_is_refused_naming_the_key_and_its_line() {
    let dir = tmp_dir("probes-every-zero");
    let scene = flagship(&dir, &[("every = 10", "every = 10\nprobe_every = 0")]);
    let line = std::fs::read_to_string(&scene)
        .unwrap()
        .lines()
        .position(|l| l.starts_with("probe_every"))
        .unwrap()
        + 1;
    let (code, _, err) = porofrac(&["check", scene.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!("scene.toml:{line}:"))
            && err.contains("output.probe_every")
            && err.contains("= 0 must be ≥ 1"),
        "{err}"
    );
}

#[test]
fn lattice_and_contact_runs_speak_their_own_words() {
    let dir = tmp_dir("probes-words");
    let out = dir.join("lbm");
    let err = run(&root().join("scenes/lbm/taylor_green.toml"), &out);
    assert!(!err.contains("fractured"), "{err}");
    assert!(err.contains(" lattice nodes, "), "{err}");
    let s = summary(&out);
    for key in ["cells", "nodes", "dofs", "fractured_cells"] {
        assert!(s.get(key).is_none(), "{key} in {s}");
    }
    let steps = s["steps"].as_u64().unwrap();
    assert!(err.contains(&format!("step {steps}/{steps}: ")), "{err}");
    assert!(s["wall_seconds"]["stepping"].as_f64().unwrap() > 0.0);
    assert_eq!(s["wall_seconds"]["assembly"], 0.0);

    let out = dir.join("nscd");
    let err = run(&root().join("scenes/nscd/column.toml"), &out);
    assert!(!err.contains("fractured"), "{err}");
    assert!(
        err.contains(" disks, ") && err.contains(" contacts, "),
        "{err}"
    );
    let s = summary(&out);
    for key in ["cells", "nodes", "dofs", "fractured_cells"] {
        assert!(s.get(key).is_none(), "{key} in {s}");
    }
    let (header, _) = read_csv(&out.join("probes.csv"));
    assert_eq!(header[0], "time [s]");
}
