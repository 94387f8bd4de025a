//! Helpers of the scene tests: run the `porofrac` binary, read what it writes.

#![allow(dead_code)]

pub mod schema;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh directory for one test, under the build's own scratch directory (so runs
/// replace their previous outputs instead of piling up in the system's temporary
/// directory).
pub fn tmp_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("porofrac-cli-test-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run the binary: exit status, stdout, stderr.
pub fn porofrac(args: &[&str]) -> (i32, String, String) {
    porofrac_in(Path::new("."), args)
}

/// Run the binary in `dir`: exit status, stdout, stderr.
pub fn porofrac_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_porofrac"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Run `porofrac run <scene> --out <out>`, require success (exit status 0) and return
/// its stderr.
pub fn run_ok(scene: &Path, out: &Path) -> String {
    let (code, _, err) = porofrac(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{}: {err}", scene.display());
    err
}

/// Write `text` as the scene `<name>.toml` in a fresh directory and run it into `out/`
/// there: exit status, stderr and the output directory.
pub fn run_text(name: &str, text: &str) -> (i32, String, PathBuf) {
    let dir = tmp_dir(name);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    let (code, _, err) = porofrac(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    (code, err, out)
}

/// Header and numeric rows of a CSV file.
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// `|a − b| ≤ tol · scale`.
pub fn close(a: f64, b: f64, scale: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * scale
}

/// The parsed `summary.json` of an output directory.
pub fn summary(out: &Path) -> serde_json::Value {
    let v =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    // Every summary a test reads matches the published schema.
    if let Err(e) = schema::validate(&schema::summary_schema(), &v) {
        panic!(
            "{}: not valid against docs/summary.schema.json: {e}",
            out.display()
        );
    }
    v
}

/// Starts `porofrac run SCENE --out OUT` in the background, its stderr discarded.
pub fn spawn_run(scene: &Path, out: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_porofrac"))
        .args([
            "run",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

/// Sends Ctrl-C (SIGINT) to a running child; asserts the signal was delivered.
pub fn send_ctrl_c(child: &Child) {
    let pid = child.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-INT", &pid])
            .status()
            .unwrap()
            .success()
    );
}

/// `mpirun -n ranks --oversubscribe porofrac args…`: exit status and stderr. Open MPI
/// is allowed to run as root (CI containers) and ends the job after 300 s.
pub fn mpirun(ranks: usize, args: &[&str]) -> (i32, String) {
    let o = Command::new("mpirun")
        .args(["--oversubscribe", "--timeout", "300", "-n"])
        .arg(ranks.to_string())
        .arg(env!("CARGO_BIN_EXE_porofrac"))
        .args(args)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .expect("mpirun (scripts/install-mpi installs it)");
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}
