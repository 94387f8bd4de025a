//! Hostile and inconsistent particle and lattice scenes (`nscd`, `lsm`, `lbm`) through
//! the `porofrac` binary: each is refused by `check` with exit status 1 and one line
//! naming the file, the 1-based line and the key; Ctrl-C during set-up or inside a long
//! step ends the run with status 130 and `"status": "interrupted at t = …"`.
//!
//! Checks:
//! * a listed particle at x = 1e20 (`particles.centres`), `[nscd] alert = 30` on the
//!   pile (`nscd.alert`, bounded by the largest radius);
//! * `[lsm] dt = 1e-300` (`lsm.dt`: more time steps than a run may take);
//! * `dt` together with `steps` (NSCD and LSM, the continuum's message);
//! * keys without effect: `packing_fraction` with `kind = "hexagonal"`, `settle_dt`
//!   without `settle_ratio`;
//! * NSCD `end_time = 1e-300` (shorter than one step; with `steps = 1`, a step too small
//!   to divide by);
//! * an LBM probe outside the lattice, output times between lattice steps (with the
//!   nearest valid values), `initial_velocity = "1/0"` and `body_force = 1e300` named by
//!   key;
//! * Ctrl-C while a 6.5 M-disk packing is generated, and inside one long LSM output
//!   step: status 130, the interrupted status, and (for the step) whole probe rows.

mod common;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use common::{porofrac, read_csv, root, send_ctrl_c, summary, tmp_dir};

fn scene(path: &str) -> String {
    std::fs::read_to_string(root().join("scenes").join(path)).unwrap()
}

/// Write `text` as `<name>.toml` in a fresh directory; the path.
fn write(name: &str, text: &str) -> PathBuf {
    let dir = tmp_dir(name);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// 1-based line of the first line containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

/// `porofrac check` on `text`: it must fail with status 1 and one line naming
/// `<file>:<line of needle>:` and `key`; returns the message.
fn refused(name: &str, text: &str, needle: &str, key: &str) -> String {
    let path = write(name, text);
    let (code, _, err) = porofrac(&["check", path.to_str().unwrap()]);
    assert_eq!(code, 1, "{name}: {err}");
    let at = format!("{name}.toml:{}:", line_of(text, needle));
    assert!(err.contains(&at), "{name}: expected {at} in {err}");
    assert!(err.contains(key), "{name}: expected {key} in {err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    err
}

#[test]
fn a_particle_far_away_is_refused_by_check() {
    let text = scene("nscd/column.toml").replacen("[[0.0, 0.5]", "[[1e20, 0.5]", 1);
    let err = refused("far_particle", &text, "centres =", "particles.centres [0]");
    assert!(err.contains("1e6 largest diameters"), "{err}");
    // A non-finite centre is refused too (TOML `inf`).
    let text = scene("nscd/column.toml").replacen("[[0.0, 0.5]", "[[inf, 0.5]", 1);
    refused("inf_particle", &text, "centres =", "particles.centres [0]");
}

#[test]
fn an_alert_distance_above_the_largest_radius_is_refused() {
    let text =
        scene("nscd/pile.toml").replace("max_sweeps = 100", "max_sweeps = 100\nalert = 30.0");
    let err = refused("alert", &text, "alert =", "nscd.alert");
    assert!(err.contains("largest particle radius 0.6"), "{err}");
}

#[test]
fn an_lsm_time_step_giving_too_many_steps_is_refused() {
    let text = scene("lsm/brazilian.toml").replace("[lsm]", "[lsm]\ndt = 1e-300");
    let err = refused("lsm_dt", &text, "dt = 1e-300", "lsm.dt");
    assert!(err.contains("more than the 10000000"), "{err}");
}

#[test]
fn dt_and_steps_together_are_refused_by_the_particle_models() {
    let text = scene("nscd/column.toml").replace("dt = 1.0e-3", "dt = 1.0e-3\nsteps = 5");
    let err = refused("nscd_dt_steps", &text, "[schedule]", "schedule");
    assert!(err.contains("needs exactly one of dt and steps"), "{err}");
    let text = scene("lsm/brazilian.toml").replace("steps = 150", "steps = 150\ndt = 0.01");
    let err = refused("lsm_dt_steps", &text, "[schedule]", "schedule");
    assert!(err.contains("needs exactly one of dt and steps"), "{err}");
}

#[test]
fn keys_without_effect_are_refused() {
    let text = scene("nscd/column.toml")
        .replace("kind = \"list\"", "kind = \"list\"\npacking_fraction = nan");
    let err = refused(
        "phi_list",
        &text,
        "packing_fraction",
        "particles.packing_fraction",
    );
    assert!(err.contains("has no effect with kind = \"list\""), "{err}");
    let text = scene("nscd/pile.toml")
        .replace("kind = \"random\"", "kind = \"hexagonal\"")
        .replace("radius = [0.4, 0.6]", "radius = 0.5")
        .replace("seed = 1\n", "");
    let err = refused(
        "phi_hex",
        &text,
        "packing_fraction",
        "particles.packing_fraction",
    );
    assert!(
        err.contains("has no effect with kind = \"hexagonal\""),
        "{err}"
    );
    let text =
        scene("nscd/pile.toml").replace("max_sweeps = 100", "max_sweeps = 100\nsettle_dt = 1e-3");
    let err = refused("settle_dt", &text, "settle_dt", "nscd.settle_dt");
    assert!(err.contains("without settle_ratio"), "{err}");
    let text = scene("lsm/brazilian.toml").replace("[lsm]", "[lsm]\ndt = 1e-6\ndt_fraction = 0.5");
    refused("dt_fraction", &text, "dt_fraction", "lsm.dt_fraction");
}

#[test]
fn end_times_below_one_step_are_refused() {
    let text = scene("nscd/column.toml").replace("end_time = 0.05", "end_time = 1e-300");
    let err = refused("end_short", &text, "end_time", "schedule.end_time");
    assert!(err.contains("shorter than one step"), "{err}");
    let text = scene("nscd/column.toml")
        .replace("end_time = 0.05", "end_time = 1e-300")
        .replace("dt = 1.0e-3", "steps = 1");
    let err = refused("end_tiny", &text, "end_time", "schedule.end_time");
    assert!(err.contains("step of 1e-300 s"), "{err}");
}

#[test]
fn lbm_probes_and_lines_outside_the_lattice_are_refused() {
    let text = scene("lbm/taylor_green.toml").replace(
        "at = [0.0001953125, 0.0251953125]",
        "at = [0.0001953125, 1.5]",
    );
    let err = refused("lbm_probe", &text, "at = [", "output.probe[0].at");
    assert!(err.contains("outside the lattice"), "{err}");
    let text = format!(
        "{}\n[[output.line]]\nname = \"cut\"\nfield = \"vx\"\nfrom = [0.0, 0.05]\nto = [0.3, 0.05]\npoints = 10\n",
        scene("lbm/taylor_green.toml")
    );
    refused("lbm_line", &text, "to = [0.3", "output.line[0].to");
}

#[test]
fn lbm_output_times_between_lattice_steps_are_refused_with_the_nearest_valid_ones() {
    // Δt = 0.0152587890625 s; 4 outputs over 1000 steps are valid, 3 are not.
    let text = scene("lbm/taylor_green.toml").replace("steps = 4", "steps = 3");
    let err = refused("lbm_every", &text, "steps = 3", "schedule.steps");
    assert!(err.contains("0.0152587890625 s"), "{err}");
    // 333 and 334 lattice steps.
    assert!(
        err.contains("5.08117675781") && err.contains("5.09643554688"),
        "{err}"
    );
    let text =
        scene("lbm/taylor_green.toml").replace("end_time = 15.2587890625", "end_time = 15.2");
    let err = refused("lbm_end", &text, "end_time = 15.2", "schedule.end_time");
    assert!(
        err.contains("use 15.1977539063 s or 15.2130126953 s"),
        "{err}"
    );
    let path = write("lbm_valid", &scene("lbm/taylor_green.toml"));
    let (code, _, err) = porofrac(&["check", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn lbm_inputs_that_diverge_name_their_key() {
    let text = scene("lbm/taylor_green.toml").replace(
        "initial_velocity = [\"1e-3",
        "initial_velocity = [\"1/0 + 1e-3",
    );
    let path = write("lbm_iv", &text);
    let (code, _, err) = porofrac(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        path.with_extension("out").to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    let at = format!("lbm_iv.toml:{}:", line_of(&text, "initial_velocity"));
    assert!(
        err.contains(&at) && err.contains("lbm.initial_velocity"),
        "{err}"
    );
    assert!(err.contains("not a finite velocity"), "{err}");
    let text = scene("lbm/taylor_green.toml").replace(
        "periodic = [\"x\", \"y\"]",
        "periodic = [\"x\", \"y\"]\nbody_force = [1e300, 0.0]",
    );
    let err = refused("lbm_body", &text, "body_force", "lbm.body_force");
    assert!(err.contains("Mach limit"), "{err}");
}

/// Start `porofrac run` on `path`, wait until a stderr line contains `cue`, send SIGINT:
/// exit status, the summary and the output directory.
fn interrupt_when(path: &Path, cue: &str) -> (i32, serde_json::Value, PathBuf) {
    let out = path.with_extension("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_porofrac"))
        .args([
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = Vec::new();
    loop {
        let Some(Ok(l)) = lines.next() else {
            panic!("the run ended before {cue:?}: {seen:?}");
        };
        if l.contains(cue) {
            break;
        }
        seen.push(l);
    }
    send_ctrl_c(&child);
    // Drain stderr so the child never blocks on a full pipe.
    for _ in lines {}
    let status = child.wait().unwrap();
    (status.code().unwrap_or(-1), summary(&out), out)
}

#[test]
fn ctrl_c_while_a_large_packing_is_generated_ends_the_run_as_interrupted() {
    // 6.5 M disks of radius 0.4–0.6 m: placing them alone takes seconds, relaxing them
    // minutes; the run reports its progress and stops at the first poll after SIGINT.
    let text = scene("nscd/pile.toml").replace(
        "region = [[0.0, 0.0], [100.0, 99.5]]",
        "region = [[0.0, 0.0], [2530.0, 2530.0]]",
    );
    let path = write("ctrlc_packing", &text);
    let (code, summary, _) = interrupt_when(&path, "packing: placing disks");
    assert_eq!(code, 130, "{summary}");
    assert_eq!(summary["status"], "interrupted at t = 0");
    assert_eq!(summary["steps"], 0);
}

#[test]
fn ctrl_c_inside_a_long_lsm_step_ends_the_run_as_interrupted() {
    // Two output steps of 1000 s each: millions of sub-steps in the first one.
    let text = scene("lsm/brazilian.toml")
        .replace("end_time = 1.5", "end_time = 2000.0")
        .replace("steps = 150", "steps = 2")
        .replace("every = 10", "every = 1");
    let path = write("ctrlc_lsm", &text);
    // The first progress line comes after step 0 (the initial state) is written.
    let (code, summary, out) = interrupt_when(&path, "step 0/2 ");
    assert_eq!(code, 130, "{summary}");
    assert_eq!(summary["status"], "interrupted at t = 0");
    let (_, rows) = read_csv(&out.join("probes.csv"));
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0][0], 0.0);
}

#[test]
fn ctrl_c_inside_the_sweeps_of_an_nscd_step_ends_the_run_as_interrupted() {
    // 1e8 sweeps per step on the 10 000-disk pile: the first step would take hours.
    let text = scene("nscd/pile.toml")
        .replace("min_sweeps = 100", "min_sweeps = 100000000")
        .replace("max_sweeps = 100", "max_sweeps = 100000000")
        .replace("every = 40", "every = 1");
    let path = write("ctrlc_nscd", &text);
    let (code, summary, out) = interrupt_when(&path, "step 0/40 ");
    assert_eq!(code, 130, "{summary}");
    assert_eq!(summary["status"], "interrupted at t = 0");
    assert!(out.join("probes.csv").is_file());
}
