//! Hostile input and hostile surroundings of scene files, outputs and the continuum and
//! Cosserat runs, through the `porofrac` binary. Every refusal exits with status 1 and
//! one line naming the file, the 1-based line and the key.
//!
//! Checks:
//! * a scene file, or a mesh file, that is a device (`/dev/zero`) or a named pipe is
//!   refused at once as "not a regular file"; a scene file above 16 MB is refused;
//! * two runs into one `--out`: the second is refused naming the first one's process id
//!   and the lock file; a lock of a process that no longer runs is taken over with a note;
//! * a rerun into a folder removes the earlier run's step files (4 steps, then 1: only
//!   `step_0000.vtu` and `step_0001.vtu` remain) and nothing of the user's;
//! * a run whose output cannot be written ends with `"status": "failed: …"` in
//!   `summary.json` and leaves no temporary file;
//! * a 200 kB expression is echoed as its first 60 characters and its length, on stderr
//!   and in `summary.json`;
//! * a Cosserat body force that is not finite names `loads.body_force` and its line;
//! * a 60³ corner-point deck with flow coupled to the mechanics (a direct solve whose
//!   factor needs about 36 GB) is refused under a 4 GB address-space limit, naming
//!   `grid`, the counts and the factor's share, before anything big is allocated;
//! * a `.vtu` whose triangles overlap (a triangle standing on the bottom side inside the
//!   square, so the run would be constrained and silent) is refused naming the first
//!   cell next to the overlap;
//! * `perturb = 0.3` (the maximum) on crossed Cosserat triangles of elongated squares
//!   runs for several seeds, and 0.31 is refused naming `grid.perturb`.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{porofrac, root, send_ctrl_c, spawn_run, tmp_dir};

fn scene(name: &str) -> String {
    std::fs::read_to_string(root().join("scenes").join(name)).unwrap()
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

/// `porofrac run <dir>/<name>.toml --out <out>` with `text`: exit status and stderr.
fn run_in(dir: &Path, name: &str, text: &str, out: &Path) -> (i32, String) {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let (code, _, err) = porofrac(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    (code, err)
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// Every file name under `dir`, recursively.
fn all_files(dir: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                v.extend(all_files(&p));
            } else {
                v.push(p);
            }
        }
    }
    v
}

#[test]
fn devices_pipes_and_huge_files_are_refused_before_reading() {
    let dir = tmp_dir("core_devices");
    let (code, _, err) = porofrac(&["check", "/dev/zero"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("zero") && err.contains("not a regular file"),
        "{err}"
    );
    // A named pipe nobody writes to: opening it would block.
    let fifo = dir.join("pipe.toml");
    if Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        let (code, _, err) = porofrac(&["check", fifo.to_str().unwrap()]);
        assert_eq!(code, 1, "{err}");
        assert!(err.contains("named pipe"), "{err}");
    }
    // 17 MB (a sparse file): refused from its size.
    let big = dir.join("big.toml");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(17 << 20)
        .unwrap();
    let (code, _, err) = porofrac(&["check", big.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("more than the 16777216"), "{err}");
    // A mesh file that is /dev/zero (through a link named like a mesh).
    let mesh = dir.join("zero.msh");
    std::os::unix::fs::symlink("/dev/zero", &mesh).unwrap();
    let text = scene("patch_test.toml");
    let grid_start = text.find("[grid]").unwrap();
    let grid_end = grid_start + text[grid_start..].find("\n[[").unwrap();
    let text = format!(
        "{}[grid]\nkind = \"file\"\npath = \"zero.msh\"\n{}",
        &text[..grid_start],
        &text[grid_end..]
    );
    let (code, err) = run_in(&dir, "mesh", &text, &dir.join("out"));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(
            "mesh.toml:{}: grid.path",
            line_of(&text, "path =")
        )) && err.contains("not a regular file"),
        "{err}"
    );
}

/// A flow scene of many short steps: long enough to be running when a second run starts.
fn long_scene() -> String {
    scene("flow_column.toml")
        .lines()
        .map(|l| {
            if l.trim_start().starts_with("dt =") || l.trim_start().starts_with("steps =") {
                "steps = 2000000".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn a_second_run_into_a_locked_folder_is_refused() {
    let dir = tmp_dir("core_lock");
    let out = dir.join("out");
    let path = dir.join("long.toml");
    std::fs::write(&path, long_scene()).unwrap();
    let mut first = spawn_run(&path, &out);
    let probes = out.join("probes.csv");
    for _ in 0..600 {
        if probes.is_file() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    assert!(probes.is_file(), "the first run never wrote");
    let (code, err) = run_in(&dir, "second", &scene("patch_test.toml"), &out);
    send_ctrl_c(&first);
    let status = first.wait().unwrap();
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!("process {}", first.id())) && err.contains(".porofrac.lock"),
        "{err}"
    );
    // The second run wrote nothing: the first one's files are its own.
    assert_eq!(status.code(), Some(130));
    assert!(!out.join("patch_test.pvd").exists());
    assert_eq!(
        summary(&out)["scene"],
        "flow_column",
        "the summary is the first run's"
    );
    assert!(!out.join(".porofrac.lock").exists());

    // A lock left by a process that no longer runs (a pid above the kernel's maximum).
    std::fs::write(out.join(".porofrac.lock"), "4294967294\n").unwrap();
    let (code, err) = run_in(&dir, "third", &scene("patch_test.toml"), &out);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("note:") && err.contains("process 4294967294"),
        "{err}"
    );
    assert!(!out.join(".porofrac.lock").exists());
    // The earlier run's series is gone, the new one is there.
    assert!(!out.join("flow_column.pvd").exists());
    assert!(out.join("patch_test.pvd").is_file());
    assert_eq!(summary(&out)["status"], "ok");
}

#[test]
fn a_rerun_removes_the_earlier_steps_and_nothing_else() {
    let dir = tmp_dir("core_rerun");
    let out = dir.join("out");
    let steps = |n: usize| {
        format!(
            "{}\n[schedule]\nend_time = 1.0\nsteps = {n}\n",
            scene("patch_test.toml")
        )
    };
    let (code, err) = run_in(&dir, "four", &steps(4), &out);
    assert_eq!(code, 0, "{err}");
    let names = |d: &Path| {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    assert_eq!(
        names(&out.join("vtk")),
        [
            "step_0000.vtu",
            "step_0001.vtu",
            "step_0002.vtu",
            "step_0003.vtu",
            "step_0004.vtu"
        ]
    );
    std::fs::write(out.join("vtk/mine.vtu"), "mine").unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let (code, err) = run_in(&dir, "one", &steps(1), &out);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        names(&out.join("vtk")),
        ["mine.vtu", "step_0000.vtu", "step_0001.vtu"]
    );
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
    let pvd = std::fs::read_to_string(out.join("patch_test.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 2, "{pvd}");
    assert_eq!(summary(&out)["steps"], 1);
}

#[test]
fn a_failed_write_leaves_a_failed_summary_and_no_temporary_file() {
    let dir = tmp_dir("core_failwrite");
    let out = dir.join("out");
    // The first step's VTK file cannot replace a folder of that name (also as root).
    std::fs::create_dir_all(out.join("vtk/step_0000.vtu")).unwrap();
    std::fs::write(out.join("vtk/step_0000.vtu/keep"), "x").unwrap();
    let (code, err) = run_in(&dir, "fail", &scene("patch_test.toml"), &out);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("step_0000.vtu"), "{err}");
    let status = summary(&out)["status"].as_str().unwrap().to_string();
    assert!(
        status.starts_with("failed: ") && status.contains("step_0000.vtu: Is a directory"),
        "{status}"
    );
    let leftovers: Vec<PathBuf> = all_files(&out)
        .into_iter()
        .filter(|p| p.to_string_lossy().contains(".tmp."))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    assert!(!out.join(".porofrac.lock").exists());
}

#[test]
fn long_user_text_is_echoed_bounded() {
    let dir = tmp_dir("core_echo");
    // A syntax error at the end of a 200 kB expression (refused by the check).
    let long = format!("x{}", " + x".repeat(50_000));
    let text = scene("patch_test.toml").replacen("3e-4*y\"]", &format!("{long} + )\"]"), 1);
    // The whole expression as written, between its quotes.
    let at = text.find(&long).unwrap();
    let open = text[..at].rfind('"').unwrap();
    let close = at + text[at..].find('"').unwrap();
    let n = text[open + 1..close].chars().count();
    assert!(n > 200_000);
    let (code, err) = run_in(&dir, "echo", &text, &dir.join("out"));
    assert_eq!(code, 1, "{err}");
    assert!(err.len() < 600, "{} bytes: {}", err.len(), &err[..600]);
    assert!(
        err.contains(&format!("… ({n} characters)")) && err.contains("bc[0].displacement"),
        "{err}"
    );
    // A run-time error echoing it: a Cosserat body force that is not finite.
    let text = scene("cosserat_shear_layer.toml").replace(
        "[solver]",
        &format!(
            "[loads]\nbody_force = [0.0, \"sqrt(x - 1){}\"]\n\n[solver]",
            " + x".repeat(50_000)
        ),
    );
    let out = dir.join("out2");
    let (code, err) = run_in(&dir, "echo2", &text, &out);
    assert_eq!(code, 1, "{err}");
    assert!(err.len() < 600, "{} bytes", err.len());
    let status = summary(&out)["status"].as_str().unwrap().to_string();
    assert!(
        status.len() < 600 && status.contains(" characters)"),
        "{status}"
    );
}

#[test]
fn a_cosserat_body_force_that_is_not_finite_names_its_key() {
    let dir = tmp_dir("core_body_force");
    for (expr, value) in [("1/(x - x)", "inf"), ("sqrt(x - 1)", "NaN")] {
        let text = scene("cosserat_shear_layer.toml").replace(
            "[solver]",
            &format!("[loads]\nbody_force = [0.0, \"{expr}\"]\n\n[solver]"),
        );
        let (code, err) = run_in(&dir, "bf", &text, &dir.join("out"));
        assert_eq!(code, 1, "{err}");
        let line = line_of(&text, "body_force");
        assert!(
            err.contains(&format!(
                "bf.toml:{line}: loads.body_force [1] = \"{expr}\" is"
            )) && err.contains(value),
            "{err}"
        );
        assert!(!err.contains("scene.model"), "{err}");
    }
}

#[test]
fn perturbed_crossed_cosserat_triangles_stay_valid_at_the_maximum() {
    let dir = tmp_dir("core_perturb");
    // The bundled scene's squares are 5:1 (a 1 × 1 mm box, cells = [10, 50]): the apex of
    // a crossed triangle lies dy/2 from its base, a tenth of the shortest incident edge.
    for seed in [0, 1, 2, 3] {
        let text = scene("cosserat_shear_layer.toml").replace(
            "cells = [10, 50]",
            &format!("cells = [10, 50]\nperturb = 0.3\nseed = {seed}"),
        );
        let (code, err) = run_in(&dir, "p", &text, &dir.join(format!("out{seed}")));
        assert_eq!(code, 0, "seed {seed}: {err}");
    }
    let text = scene("cosserat_shear_layer.toml")
        .replace("cells = [10, 50]", "cells = [10, 50]\nperturb = 0.31");
    let (code, err) = run_in(&dir, "p", &text, &dir.join("out"));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(
            "p.toml:{}: grid.perturb = 0.31 must be in [0, 0.3]",
            line_of(&text, "perturb")
        )),
        "{err}"
    );
}

#[test]
fn a_deck_whose_direct_solve_does_not_fit_is_refused_before_allocating() {
    use porofrac_grid::io::grdecl::Deck;
    let dir = tmp_dir("core_deck_memory");
    // The faulted deck of porofrac-grid/examples/grdecl_speed.rs, 60³ cells.
    let n = 60;
    let (dx, dz) = (10.0, 2.0);
    let deck = Deck::on_vertical_pillars([n, n, n], [dx, dx], |[i, _], x, _, k| {
        let throw = if i >= n / 2 { dz / 2.0 } else { 0.0 };
        1000.0 + (k - k / 10) as f64 * dz + 0.02 * x + throw
    });
    let mut w = std::io::BufWriter::new(std::fs::File::create(dir.join("d60.grdecl")).unwrap());
    deck.write_text(&mut w).unwrap();
    drop(w);
    let mut text = std::fs::read_to_string(root().join("scenes/corner_point/injection.toml"))
        .unwrap()
        .replace("faulted.grdecl", "d60.grdecl");
    for m in ["[material.sandstone]", "[material.shaly]"] {
        text = text.replace(m, &format!("{m}\nporosity = 0.2\npermeability = 1.0e-13"));
    }
    let path = dir.join("deck.toml");
    std::fs::write(&path, &text).unwrap();
    let cmd = format!(
        "ulimit -v 4000000; exec '{}' run '{}' --out '{}'",
        env!("CARGO_BIN_EXE_porofrac"),
        path.display(),
        dir.join("out").display()
    );
    let o = Command::new("sh").arg("-c").arg(cmd).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!(
            "deck.toml:{}: grid holds ",
            line_of(&text, "[grid]")
        )) && err.contains("the factor of the direct solve alone")
            && err.contains("this machine has 4.1 GB"),
        "{err}"
    );
    // The estimate, not the allocator, stopped it: far below the limit at the refusal.
    let summary = summary(&dir.join("out"));
    let peak = summary["peak_memory_bytes"].as_f64().unwrap();
    assert!(peak < 2.0e9, "{peak}");
}

#[test]
fn overlapping_mesh_cells_are_refused() {
    let dir = tmp_dir("core_overlap");
    let pts = "0 0 0 1 0 0 1 1 0 0 1 0 0.2 0 0 0.6 0 0 0.2 0.5 0";
    let vtu = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" \
         byte_order=\"LittleEndian\">\n<UnstructuredGrid><Piece NumberOfPoints=\"7\" \
         NumberOfCells=\"3\">\n<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" \
         format=\"ascii\">{pts}</DataArray></Points>\n<Cells><DataArray type=\"Int64\" \
         Name=\"connectivity\" format=\"ascii\">0 1 2 0 2 3 4 5 6</DataArray>\n<DataArray \
         type=\"Int64\" Name=\"offsets\" format=\"ascii\">3 6 9</DataArray>\n<DataArray \
         type=\"UInt8\" Name=\"types\" format=\"ascii\">5 5 5</DataArray></Cells>\n</Piece>\
         </UnstructuredGrid></VTKFile>\n"
    );
    std::fs::write(dir.join("over.vtu"), vtu).unwrap();
    let text = "[scene]\nname = \"over\"\ndim = 2\n[grid]\nkind = \"file\"\npath = \"over.vtu\"\n\
                [[region]]\nname = \"rock\"\nselect = { all = true }\nlaw = \"vem\"\n\
                material = \"rock\"\n[material.rock]\nyoungs_modulus = 1.0e9\n\
                poisson_ratio = 0.25\n[[bc]]\nboundary = \"ymin\"\ndisplacement = [0.0, 0.0]\n\
                [[bc]]\nboundary = \"ymax\"\ntraction = [0.0, -1.0e6]\n";
    let (code, err) = run_in(&dir, "over", text, &dir.join("out"));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("over.toml:6: grid.path")
            && err.contains("cell 0: overlaps other cells")
            && err.contains("the 1st cell of the file"),
        "{err}"
    );
}
