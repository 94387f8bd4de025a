//! The continuum's distributed linear elasticity through the command: the standard
//! problems E2 and E3 (scenes/bench/e2.toml, e3.toml) at a small n, run by
//! `mpirun -n P porofrac run` on 1, 2 and 4 ranks (oversubscribed), against the serial
//! run of the same scene with CG-AMG.
//!
//! Checks, for every rank count:
//! - the L2 error against the manufactured solution agrees with the serial one to
//!   `1e-6` relative, and the extrema of every displacement component to `1e-6` of the
//!   largest displacement: both runs solve to the relative residual `1e-10`, so the
//!   solutions differ by at most the condition number times that (about `10⁻⁷` of the
//!   solution at these sizes);
//! - on 2 and 4 ranks the summary is the distributed one (`distributed.ranks = P`) and
//!   the CG iterations on 4 ranks are at most 1.2 times those on 1 (the serial run's when
//!   one rank runs the serial path);
//! - a scene the distributed path does not model (a material that can fail) is refused
//!   on 2 ranks with an error naming the key.
#![cfg(feature = "mpi")]

use std::path::{Path, PathBuf};
use std::process::Command;

fn exe() -> &'static str {
    env!("CARGO_BIN_EXE_porofrac")
}

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenes/bench/{name}.toml"))
}

fn out_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "porofrac-mpi-elasticity-{}-{tag}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Run `porofrac run` (under `mpirun -n ranks` when given) and read its summary.
fn run(name: &str, cells: &str, ranks: Option<usize>, extra: &[&str]) -> serde_json::Value {
    let out = out_dir(&format!(
        "{name}-{}",
        ranks.map_or("serial".into(), |p| p.to_string())
    ));
    let mut cmd = match ranks {
        Some(p) => {
            let mut c = Command::new("mpirun");
            c.args([
                "--oversubscribe",
                "--allow-run-as-root",
                "-n",
                &p.to_string(),
                exe(),
            ]);
            c
        }
        None => Command::new(exe()),
    };
    cmd.arg("run")
        .arg(scene(name))
        .arg("--out")
        .arg(&out)
        .args(["--set", &format!("grid.cells={cells}")])
        .args([
            "--set",
            "solver.linear=\"cg-amg\"",
            "--set",
            "solver.tolerance=1e-10",
        ])
        .args(extra)
        .env("RAYON_NUM_THREADS", "1");
    let o = cmd
        .output()
        .expect("mpirun (OpenMPI or MPICH) on the PATH: scripts/install-mpi");
    assert!(
        o.status.success(),
        "{name} on {ranks:?} ranks failed:\n{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    let _ = std::fs::remove_dir_all(&out);
    serde_json::from_str(&text).expect("summary.json is JSON")
}

fn l2(s: &serde_json::Value) -> f64 {
    s["errors"]["l2_displacement"]
        .as_f64()
        .expect("errors.l2_displacement")
}

fn iterations(s: &serde_json::Value) -> u64 {
    s["solver"]["iterations"]
        .as_u64()
        .expect("solver.iterations")
}

fn agree(name: &str, cells: &str, dim: usize) {
    let serial = run(name, cells, None, &[]);
    let umax = ["ux", "uy", "uz"][..dim]
        .iter()
        .flat_map(|c| serial["field_extrema"][c].as_array().unwrap().iter())
        .map(|v| v.as_f64().unwrap().abs())
        .fold(0.0, f64::max);
    let mut its = Vec::new();
    for p in [1, 2, 4] {
        let d = run(name, cells, Some(p), &[]);
        let rel = (l2(&d) - l2(&serial)).abs() / l2(&serial);
        assert!(
            rel <= 1e-6,
            "{name} on {p} ranks: L2 errors {} and {} (serial)",
            l2(&d),
            l2(&serial)
        );
        for c in &["ux", "uy", "uz"][..dim] {
            for k in 0..2 {
                let (a, b) = (
                    d["field_extrema"][c][k].as_f64().unwrap(),
                    serial["field_extrema"][c][k].as_f64().unwrap(),
                );
                assert!(
                    (a - b).abs() <= 1e-6 * umax,
                    "{name} on {p} ranks: {c}[{k}] {a} against {b}"
                );
            }
        }
        if p > 1 {
            assert_eq!(
                d["distributed"]["ranks"].as_u64(),
                Some(p as u64),
                "{name}: not the distributed path"
            );
        }
        eprintln!(
            "{name} {cells} on {p} ranks: {} iterations (serial {}), L2 {:.6e} (serial {:.6e})",
            iterations(&d),
            iterations(&serial),
            l2(&d),
            l2(&serial)
        );
        its.push(iterations(&d));
    }
    assert!(
        its[2] as f64 <= 1.2 * its[0] as f64,
        "{name}: iterations on 1, 2, 4 ranks {its:?} grow by more than 20 %"
    );
}

#[test]
fn e2_on_1_2_4_ranks_agrees_with_the_serial_run() {
    agree("e2", "[48, 48]", 2);
}

#[test]
fn e3_on_1_2_4_ranks_agrees_with_the_serial_run() {
    agree("e3", "[10, 10, 10]", 3);
}

#[test]
fn a_material_that_can_fail_is_refused_by_key() {
    let out = out_dir("refused");
    let o = Command::new("mpirun")
        .args([
            "--oversubscribe",
            "--allow-run-as-root",
            "-n",
            "2",
            exe(),
            "run",
        ])
        .arg(scene("e2"))
        .arg("--out")
        .arg(&out)
        .args([
            "--set",
            "grid.cells=[8, 8]",
            "--set",
            "material.unit.tensile_strength=1e6",
        ])
        .output()
        .expect("mpirun on the PATH");
    let _ = std::fs::remove_dir_all(&out);
    assert!(!o.status.success());
    // mpirun forwards the ranks' output on either stream.
    let err = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        err.contains("material.unit.tensile_strength makes the material fail")
            && err.contains("run this scene without mpirun"),
        "{err}"
    );
}
