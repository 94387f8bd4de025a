//! `mpirun -n P porofrac run`: the launch path of distributed runs.
//!
//! Built without the `mpi` feature (the default build):
//! * a launch by an MPI launcher with more than one copy (its environment says so) is
//!   refused before anything is read or written, naming the feature and the install
//!   script; one copy runs as usual.
//!
//! Built with it (`cargo test -p porofrac-cli --features mpi --test mpi`, MPI installed
//! by `scripts/install-mpi`; `scripts/test-mpi` runs them):
//! * on 1 rank a scene runs the serial path: the same `probes.csv`, byte for byte, as
//!   without mpirun;
//! * on 2 and 4 ranks a model without a distributed path is refused by every rank with
//!   the error naming `[scene] model`, printed once (rank 0), a non-zero exit and
//!   `summary.json` saying `failed: …`;
//! * an error on rank 0 alone (its output folder cannot be made) ends every rank with a
//!   non-zero exit instead of leaving the others waiting (mpirun's own `--timeout` turns a
//!   hang into a failure of the test rather than a stuck test).

mod common;

use common::{porofrac, root, tmp_dir};

/// Built without MPI, launched as 2 copies: refused, nothing written.
#[cfg(not(feature = "mpi"))]
#[test]
fn without_the_feature_a_launch_on_several_ranks_is_refused() {
    use std::process::Command;
    let dir = tmp_dir("mpi-refused");
    let out = dir.join("out");
    for var in ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"] {
        let o = Command::new(env!("CARGO_BIN_EXE_porofrac"))
            .args(["run", "scenes/lbm/taylor_green.toml", "--out"])
            .arg(&out)
            .current_dir(root())
            .env(var, "2")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{var}: {err}");
        assert!(
            err.contains(
                "this porofrac was built without MPI: build it with `--features mpi` \
                 (scripts/install-mpi installs MPI)"
            ),
            "{var}: {err}"
        );
        assert!(
            !out.exists(),
            "{var}: the refused run wrote {}",
            out.display()
        );
    }
    // One copy is an ordinary run.
    let (code, _, err) = porofrac(&[
        "run",
        root()
            .join("scenes/lbm/taylor_green.toml")
            .to_str()
            .unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.join("probes.csv").is_file());
}

#[cfg(feature = "mpi")]
mod launched {
    use super::*;
    use std::path::Path;

    use common::mpirun;

    fn path(p: &Path) -> &str {
        p.to_str().unwrap()
    }

    #[test]
    fn one_rank_runs_the_serial_path() {
        let dir = tmp_dir("mpi-one-rank");
        let scene = root().join("scenes/lbm/taylor_green.toml");
        let (serial, mpi) = (dir.join("serial"), dir.join("mpi"));
        let (code, _, err) = porofrac(&["run", path(&scene), "--out", path(&serial)]);
        assert_eq!(code, 0, "{err}");
        let (code, err) = mpirun(1, &["run", path(&scene), "--out", path(&mpi)]);
        assert_eq!(code, 0, "{err}");
        let a = std::fs::read(serial.join("probes.csv")).unwrap();
        let b = std::fs::read(mpi.join("probes.csv")).unwrap();
        assert!(!a.is_empty());
        assert_eq!(a, b, "probes.csv differs between the serial run and -n 1");
    }

    #[test]
    fn a_model_without_a_distributed_path_is_refused_on_every_rank() {
        let scene = root().join("scenes/nscd/column.toml");
        for ranks in [2, 4] {
            let out = tmp_dir(&format!("mpi-refused-{ranks}"));
            let (code, err) = mpirun(ranks, &["run", path(&scene), "--out", path(&out)]);
            assert_ne!(code, 0, "-n {ranks}: {err}");
            let says = "model \"nscd\" has no distributed path: run it without mpirun \
                        (or with -n 1)";
            assert_eq!(err.matches(says).count(), 1, "-n {ranks}: {err}");
            assert!(err.contains("column.toml:"), "-n {ranks}: {err}");
            let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
            assert!(summary.contains("\"status\": \"failed: "), "{summary}");
        }
    }

    #[test]
    fn an_error_on_rank_0_alone_ends_every_rank() {
        let dir = tmp_dir("mpi-rank0-error");
        // The output folder is a file: rank 0 cannot lock it, the others wait on rank 0.
        let out = dir.join("taken");
        std::fs::write(&out, "not a folder").unwrap();
        let scene = root().join("scenes/nscd/column.toml");
        for ranks in [2, 4] {
            let (code, err) = mpirun(ranks, &["run", path(&scene), "--out", path(&out)]);
            assert_ne!(code, 0, "-n {ranks}: {err}");
            assert!(!err.contains("timeout"), "-n {ranks} hung: {err}");
            assert!(err.contains(path(&out)), "-n {ranks}: {err}");
        }
    }
}
