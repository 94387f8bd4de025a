//! `porofrac check` does everything `run` does before its first step and writes nothing.
//!
//! - A table of scenes that `run` refuses before stepping, one per kind of refusal
//!   (files, sections, boundaries, tags, probes and lines located in the built grid,
//!   rigid-body modes, lattice limits, packings, contact dynamics without disks, a
//!   Cosserat mesh without reconstruction stencils): `check` fails with exit status 1
//!   and exactly the error line of `run`, writes nothing, and `run` writes no step (no
//!   `probes.csv`, no VTK file; its `summary.json`, when there is one, says `failed`).
//! - Every bundled scene under `scenes/` passes `check`, and its report states the
//!   sizes, steps and files of the scene and the estimates.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{porofrac_in, root};

/// A fresh directory of the test's own.
fn fresh_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("porofrac-check-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The `error: …` line of a command's stderr (progress lines apart).
fn error_line(err: &str) -> String {
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(errors.len(), 1, "one error line expected:\n{err}");
    errors[0].to_string()
}

/// Every file under `dir`, relative to it, sorted.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push(p.strip_prefix(base).unwrap().to_path_buf());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// A bundled scene's text with each `(from, to)` replaced; every `from` must occur, so
/// a drifted scene fails the test instead of passing it unchanged.
fn edited(scene: &str, edits: &[(&str, &str)]) -> String {
    let mut text = std::fs::read_to_string(root().join("scenes").join(scene)).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{scene}: `{from}` not found");
        text = text.replacen(from, to, 1);
    }
    text
}

/// A scene that `run` refuses before its first step.
struct Refused {
    /// Name of the case (and of its scene file).
    name: &'static str,
    /// The scene text.
    scene: String,
    /// Other files next to the scene (a deck).
    files: Vec<(&'static str, String)>,
    /// Text the error must contain (what the refusal is about, in the user's words).
    says: &'static str,
}

fn refused_scenes() -> Vec<Refused> {
    let patch = "patch_test.toml";
    let mut no_bc = std::fs::read_to_string(root().join("scenes").join(patch)).unwrap();
    let (a, b) = (
        no_bc.find("# u = A x").unwrap(),
        no_bc.find("[[output.probe]]").unwrap(),
    );
    no_bc.replace_range(a..b, "");
    let faulted =
        std::fs::read_to_string(root().join("scenes/corner_point/faulted.grdecl")).unwrap();
    let deck = faulted.replacen("METRIC\n", "METRIC\nINCLUDE\n 'missing.inc' /\n", 1);
    assert!(deck.contains("INCLUDE"));
    let injection = "corner_point/injection.toml";
    let line = "\n[[output.line]]\nname = \"down\"\nfield = \"pressure\"\n\
                from = [90.0, 90.0, 1016.0]\nto = [90.0, 90.0, 3016.0]\npoints = 5\n";
    vec![
        Refused {
            name: "missing_mesh",
            scene: edited(
                patch,
                &[(
                    "kind = \"cartesian\"",
                    "kind = \"file\"\npath = \"nowhere.msh\"",
                )],
            ),
            files: vec![],
            says: "grid.path = \"nowhere.msh\": nowhere.msh: No such file",
        },
        Refused {
            name: "missing_include",
            scene: edited(
                injection,
                &[(
                    "path = \"faulted.grdecl\"",
                    "path = \"with_include.grdecl\"",
                )],
            ),
            files: vec![("with_include.grdecl", deck)],
            says: "INCLUDE 'missing.inc': no such file",
        },
        Refused {
            name: "flow_without_fluid",
            scene: edited(
                patch,
                &[(
                    "[[output.probe]]",
                    "[physics]\nflow = true\n\n[[output.probe]]",
                )],
            ),
            files: vec![],
            says: "physics.flow = true needs a [fluid] section",
        },
        Refused {
            name: "unknown_boundary",
            scene: edited(patch, &[("boundary = \"xmin\"", "boundary = \"left\"")]),
            files: vec![],
            says: "bc[0].boundary = \"left\": unknown boundary or tag `left`",
        },
        Refused {
            name: "undefined_tag",
            scene: edited(
                patch,
                &[("select = { all = true }", "select = { tag = \"nope\" }")],
            ),
            files: vec![],
            says: "region[0].select = { tag = \"nope\" }: the grid has no such cell tag",
        },
        Refused {
            name: "probe_outside_the_deck",
            scene: edited(
                injection,
                &[("at = [190.0, 150.0, 1030.0]", "at = [190.0, 150.0, 5030.0]")],
            ),
            files: vec![("faulted.grdecl", faulted.clone())],
            says: "output.probe[1].at = [190.0, 150.0, 5030.0] is outside the grid",
        },
        Refused {
            name: "line_outside_the_deck",
            scene: edited(injection, &[]) + line,
            files: vec![("faulted.grdecl", faulted.clone())],
            says: "of the line is outside the grid",
        },
        Refused {
            name: "rigid_modes",
            scene: no_bc,
            files: vec![],
            says: "leave rigid-body motion free (translation x, translation y, rotation about z)",
        },
        Refused {
            name: "lbm_tau",
            scene: edited("lbm/taylor_green.toml", &[("tau = 0.8 ", "tau = 0.5001 ")]),
            files: vec![],
            says: "lbm.tau = 0.5001 must be above 0.505",
        },
        Refused {
            name: "lbm_mach",
            scene: edited(
                "lbm/taylor_green.toml",
                &[("1e-3 * cos", "1e2 * cos"), ("-1e-3 * sin", "-1e2 * sin")],
            ),
            files: vec![],
            says: "on this lattice (limit 0.3)",
        },
        Refused {
            name: "lsm_packing",
            scene: edited(
                "lsm/brazilian.toml",
                &[("radius = 22.0 }", "radius = 1.05 }")],
            ),
            files: vec![],
            says: "particles.kind generates no particle",
        },
        Refused {
            name: "nscd_no_disks",
            scene: {
                let text = edited("nscd/column.toml", &[]);
                let (a, b) = (
                    text.find("centres = ").unwrap(),
                    text.find("density = ").unwrap(),
                );
                let mut t = text.clone();
                t.replace_range(a..b, "centres = []\nradii = []\n");
                t
            },
            files: vec![],
            says: "particles.kind generates no particle",
        },
        Refused {
            name: "cosserat_stencil",
            scene: edited(
                "cosserat_shear_layer.toml",
                &[
                    ("diagonals = \"crossed\"\n", ""),
                    ("cells = [10, 50]", "cells = [1, 1]"),
                ],
            ),
            files: vec![],
            says: "no 3 cells with non-degenerate barycentres",
        },
    ]
}

/// Each refusal of `run` before its first step is `check`'s too, word for word, with
/// exit status 1 and nothing written; `run` writes no step of it.
#[test]
fn check_refuses_what_run_refuses_before_stepping_with_the_same_error() {
    for case in refused_scenes() {
        let dir = fresh_dir(case.name);
        let file = format!("{}.toml", case.name);
        std::fs::write(dir.join(&file), &case.scene).unwrap();
        for (name, text) in &case.files {
            std::fs::write(dir.join(name), text).unwrap();
        }
        let before = files_under(&dir);

        let (code, out, err) = porofrac_in(&dir, &["check", &file]);
        assert_eq!(code, 1, "{}: check passed:\n{out}{err}", case.name);
        assert!(!out.contains(": ok"), "{}: {out}", case.name);
        let checked = error_line(&err);
        assert!(
            checked.contains(&format!("{file}:")) || checked.contains("rigid-body"),
            "{}: the error names the file: {checked}",
            case.name
        );
        assert!(checked.contains(case.says), "{}: {checked}", case.name);
        assert_eq!(
            files_under(&dir),
            before,
            "{}: check wrote files",
            case.name
        );

        let (code, _, err) = porofrac_in(&dir, &["run", &file, "--out", "out"]);
        assert_eq!(code, 1, "{}: run did not refuse it", case.name);
        assert_eq!(error_line(&err), checked, "{}", case.name);
        let out = dir.join("out");
        assert!(
            !out.join("probes.csv").exists(),
            "{}: a step was written",
            case.name
        );
        assert!(
            !out.join("vtk").exists(),
            "{}: a VTK step was written",
            case.name
        );
        if out.join("summary.json").exists() {
            let s: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                    .unwrap();
            assert!(
                s["status"].as_str().unwrap().starts_with("failed"),
                "{}: {s}",
                case.name
            );
            assert_eq!(s["steps"], 0, "{}", case.name);
        }
    }
}

/// Bundled scenes whose build takes long: the settled deposits of the paper-size
/// contact dynamics scenes (`check` settles them as `run` does: 14 532 disks, about a
/// minute on two cores, and 39 742 disks, about three minutes), and the 2 347-disk
/// `fault_thick` (about 8 s). They are checked by the ignored test below.
const SLOW: &[&str] = &[
    "nscd/fault_paper.toml",
    "nscd/forced_fold_paper.toml",
    "nscd/fault_thick.toml",
];

fn bundled_scenes() -> Vec<PathBuf> {
    fn under(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                under(&path, out);
            } else if path.extension().is_some_and(|e| e == "toml") {
                out.push(path);
            }
        }
    }
    let mut scenes = Vec::new();
    under(&root().join("scenes"), &mut scenes);
    scenes.sort();
    scenes
}

/// Check `scene` in a fresh directory: it passes, reports its sizes and estimates, and
/// writes nothing.
fn passes_check(scene: &Path) {
    let name = scene
        .strip_prefix(root().join("scenes"))
        .unwrap()
        .to_string_lossy()
        .replace(['/', '.'], "_");
    let dir = fresh_dir(&format!("bundled-{name}"));
    let (code, out, err) = porofrac_in(&dir, &["check", scene.to_str().unwrap()]);
    assert_eq!(code, 0, "{}: {err}", scene.display());
    let first = out.lines().next().unwrap_or("");
    assert!(
        first.starts_with(&format!("{}: ok (", scene.display())),
        "{}: {out}",
        scene.display()
    );
    for needle in [
        "  model ",
        "  steps: ",
        "estimated peak memory: ",
        "estimated run time: ",
    ] {
        assert!(
            out.contains(needle),
            "{}: no `{needle}`:\n{out}",
            scene.display()
        );
    }
    assert!(
        files_under(&dir).is_empty(),
        "{}: check wrote files",
        scene.display()
    );
}

/// Every bundled scene passes `check` (they are all valid), the slow builds of [`SLOW`]
/// apart.
#[test]
fn every_bundled_scene_passes_the_full_check() {
    let scenes = bundled_scenes();
    assert!(scenes.len() >= 30, "{} scenes found", scenes.len());
    let mut checked = 0;
    for scene in &scenes {
        if SLOW.iter().any(|s| scene.ends_with(s)) {
            continue;
        }
        passes_check(scene);
        checked += 1;
    }
    assert_eq!(checked + SLOW.len(), scenes.len());
}

/// The bundled scenes of [`SLOW`] pass `check` too (minutes: run with `--ignored`).
#[test]
#[ignore = "builds paper-size deposits (minutes)"]
fn slow_bundled_scenes_pass_the_full_check() {
    for scene in SLOW {
        passes_check(&root().join("scenes").join(scene));
    }
}

/// The report of a known scene: sizes, steps, written files, and estimates that follow
/// from its counts (`patch_test`: an 8 × 8 grid of quadrilaterals, 98 free unknowns, no
/// schedule, one VTK file, two probes, one line).
#[test]
fn the_report_states_the_sizes_steps_and_files() {
    let dir = fresh_dir("report");
    let scene = root().join("scenes/patch_test.toml");
    let (code, out, err) = porofrac_in(&dir, &["check", scene.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("model continuum (2D): 64 cells, 81 nodes, 98 unknowns"),
        "{out}"
    );
    assert!(
        out.contains("steps: 0; written: 1 (1 VTK files, 1 lines); probes.csv: 1 rows of 2 probes"),
        "{out}"
    );
    // terzaghi: 400 steps written every 100th (0, 100, …, 400), probes at every step.
    let scene = root().join("scenes/terzaghi.toml");
    let (code, out, err) = porofrac_in(&dir, &["check", scene.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("steps: 400; written: 5 (5 VTK files"), "{out}");
    assert!(out.contains("probes.csv: 401 rows of"), "{out}");
    // A lattice solid scene counts particles and bonds.
    let scene = root().join("scenes/lsm/brazilian.toml");
    let (code, out, err) = porofrac_in(&dir, &["check", scene.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("model lsm (2D): 1008 particles, 1956 bonds"),
        "{out}"
    );
}

/// Ctrl-C while `check` builds a long packing (6.5 M disks, as in the run's own test)
/// stops it at the next poll: exit status 130, and nothing written.
#[test]
fn ctrl_c_stops_a_long_build_of_check() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let dir = fresh_dir("ctrlc");
    let text = edited(
        "nscd/pile.toml",
        &[(
            "region = [[0.0, 0.0], [100.0, 99.5]]",
            "region = [[0.0, 0.0], [2530.0, 2530.0]]",
        )],
    );
    std::fs::write(dir.join("big.toml"), text).unwrap();
    let before = files_under(&dir);
    let mut child = Command::new(env!("CARGO_BIN_EXE_porofrac"))
        .current_dir(&dir)
        .args(["check", "big.toml"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = Vec::new();
    loop {
        let Some(Ok(l)) = lines.next() else {
            panic!("the check ended before packing: {seen:?}");
        };
        if l.contains("packing: placing disks") {
            break;
        }
        seen.push(l);
    }
    common::send_ctrl_c(&child);
    let rest: Vec<String> = lines.map_while(Result::ok).collect();
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{rest:?}");
    assert!(
        rest.iter().any(|l| l == "big.toml: check interrupted"),
        "{rest:?}"
    );
    assert!(!String::from_utf8_lossy(&out.stdout).contains(": ok"));
    assert_eq!(files_under(&dir), before);
}
