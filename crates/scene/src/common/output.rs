//! Output files of a run (docs/SCENE.md, "Outputs"): every file is written atomically
//! (a temporary file in the same directory, then a rename), so an interrupted run never
//! leaves a half-written file.
//!
//! One run at a time writes into an output folder: [`OutputLock`] holds the lock file
//! `.porofrac.lock` (created with `create_new`, holding the process id) while the run
//! writes; a second run into the same folder is refused naming the first one's process
//! id, and a lock left by a process that no longer exists is taken over with a note.
//! Before a run writes, [`remove_earlier_outputs`] removes the files an earlier run wrote
//! into the folder under porofrac's own names (the VTK steps, `.pvd` series, tables,
//! plots, `summary.json` and leftover temporary files), so ParaView never shows steps of
//! an earlier run next to the new ones; nothing else in the folder is touched.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// An output error (file and cause).
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct OutputError {
    /// The file.
    pub path: PathBuf,
    /// The cause.
    pub source: std::io::Error,
}

/// Write `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let err = |source| OutputError {
        path: path.to_path_buf(),
        source,
    };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(err)?;
    }
    porofrac_vtk::write_atomic(path, bytes).map_err(|e| match e {
        porofrac_vtk::VtkError::Io { source, .. } => err(source),
        other => err(std::io::Error::other(other.to_string())),
    })
}

/// A CSV table kept in memory and rewritten atomically: when it is created, after a row
/// if the last rewrite is older than [`CsvTable::FLUSH_INTERVAL`], and when it is dropped
/// (the end of a run, an error or an interruption). The file on disk always holds whole
/// rows, and long runs do not rewrite it after every step.
#[derive(Debug)]
pub struct CsvTable {
    path: PathBuf,
    text: String,
    flushed: std::time::Instant,
    dirty: bool,
}

impl CsvTable {
    /// Longest time rows stay in memory only.
    pub const FLUSH_INTERVAL: std::time::Duration = std::time::Duration::from_millis(500);

    /// A table with a header line (not yet written: see [`CsvTable::flush`]).
    pub fn new(path: PathBuf, header: &[String]) -> Self {
        let mut text = header.join(",");
        text.push('\n');
        Self {
            path,
            text,
            flushed: std::time::Instant::now(),
            dirty: true,
        }
    }
    /// The text of the table so far (header and rows), for a checkpoint.
    pub fn text(&self) -> &str {
        &self.text
    }
    /// Replace the table's text by `text` (the header and rows of a checkpoint); the file
    /// is rewritten at the next flush.
    pub fn restore(&mut self, text: String) {
        self.text = text;
        self.dirty = true;
    }
    /// Append a row of numbers (shortest round-trip form).
    pub fn push(&mut self, row: &[f64]) -> Result<(), OutputError> {
        self.append(row);
        self.maybe_flush()
    }
    /// Append several rows of numbers.
    pub fn push_rows(&mut self, rows: &[Vec<f64>]) -> Result<(), OutputError> {
        for r in rows {
            self.append(r);
        }
        self.maybe_flush()
    }
    /// Append a row of already formatted cells.
    pub fn push_text(&mut self, row: &[String]) -> Result<(), OutputError> {
        let _ = writeln!(self.text, "{}", row.join(","));
        self.dirty = true;
        self.maybe_flush()
    }
    fn append(&mut self, row: &[f64]) {
        for (i, v) in row.iter().enumerate() {
            if i > 0 {
                self.text.push(',');
            }
            let _ = write!(self.text, "{v}");
        }
        self.text.push('\n');
        self.dirty = true;
    }
    fn maybe_flush(&mut self) -> Result<(), OutputError> {
        if self.flushed.elapsed() >= Self::FLUSH_INTERVAL {
            self.flush()?;
        }
        Ok(())
    }
    /// Write the file as it is now.
    pub fn flush(&mut self) -> Result<(), OutputError> {
        write_atomic(&self.path, self.text.as_bytes())?;
        self.flushed = std::time::Instant::now();
        self.dirty = false;
        Ok(())
    }
}

impl Drop for CsvTable {
    fn drop(&mut self) {
        if self.dirty {
            // Best effort: the error of a run that already failed wins.
            let _ = self.flush();
        }
    }
}

/// Wall time of the phases of a run (seconds; a phase that did not run is 0).
#[derive(Clone, Copy, Debug, Default, serde::Serialize, schemars::JsonSchema)]
pub struct WallSeconds {
    /// Whole run.
    pub total: f64,
    /// Grid generation or import.
    pub grid: f64,
    /// Assembly of matrices and loads.
    pub assembly: f64,
    /// Time stepping of the particle and lattice models (contact detection, integration,
    /// streaming and collision; the contact solver's sweeps are under `solve`).
    pub stepping: f64,
    /// Linear solves of the mechanics.
    pub solve: f64,
    /// Flow solves.
    pub flow: f64,
    /// Writing output.
    pub output: f64,
}

/// Linear-solver statistics.
#[derive(Clone, Debug, Default, serde::Serialize, schemars::JsonSchema)]
pub struct SolverStats {
    /// Linear solver used.
    pub linear: String,
    /// Number of numeric factorizations.
    pub factorizations: usize,
    /// Number of symbolic factorizations (analyses).
    pub symbolic_factorizations: usize,
    /// Nonzeros of the factor.
    pub factor_nnz: usize,
    /// Matrices solved by a low-rank update of the factors instead of a factorization.
    pub low_rank_updates: usize,
    /// Iterations of iterative solvers (total).
    pub iterations: usize,
    /// Largest relative residual ‖K u − f‖ / ‖f‖ over the solves.
    pub max_relative_residual: f64,
}

/// `summary.json`.
#[derive(Clone, Debug, serde::Serialize, schemars::JsonSchema)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// The model (`[scene] model`).
    pub model: String,
    /// 2 or 3.
    pub dim: usize,
    /// Number of grid cells (grid models only: continuum, Cosserat).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cells: Option<usize>,
    /// Number of grid nodes (grid models only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nodes: Option<usize>,
    /// Number of unknowns of the main system (equations after eliminating prescribed
    /// dofs; grid models only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dofs: Option<usize>,
    /// The model's sizes in its own words (`64 cells, 81 nodes, 98 unknowns`, `400
    /// particles, 1100 bonds`) for the end-of-run line; not written.
    #[serde(skip)]
    pub sizes_text: String,
    /// Number of steps computed after t = 0: the output times after the initial state
    /// (the progress line's `step 40/40`).
    pub steps: usize,
    /// `"ok"`, `"interrupted at t = …"` or the error text.
    pub status: String,
    /// The last finished time of an interrupted run.
    #[serde(skip)]
    pub interrupted_at: Option<f64>,
    /// Number of failed cells (continuum only; the particle models write their own
    /// counts, e.g. `broken_bonds`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fractured_cells: Option<usize>,
    /// Wall time per phase.
    pub wall_seconds: WallSeconds,
    /// Peak resident memory of the process (bytes; 0 where unknown).
    pub peak_memory_bytes: u64,
    /// Solver statistics.
    pub solver: SolverStats,
    /// `[min, max]` of every field at the last written step.
    pub field_extrema: std::collections::BTreeMap<String, [f64; 2]>,
    /// Error norms against `[output] exact_displacement` at the last step (absent
    /// without it).
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub errors: std::collections::BTreeMap<String, f64>,
    /// porofrac version.
    pub version: String,
    /// The `--set` overrides of the run: each key as written and its value (absent
    /// without them).
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub overrides: std::collections::BTreeMap<String, serde_json::Value>,
    /// Keys a model adds ([`crate::common::model::Model::summary_extras`]: the `lattice` block
    /// and `mlups` of the lattice Boltzmann model, the particle statistics of contact
    /// dynamics).
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl Summary {
    /// Whether the run was interrupted (its files hold the finished steps).
    pub fn interrupted(&self) -> bool {
        self.interrupted_at.is_some()
    }
    /// Write `summary.json` into `dir`.
    pub fn write(&self, dir: &Path) -> Result<(), OutputError> {
        let json = serde_json::to_string_pretty(self).expect("summary serializes");
        write_atomic(&dir.join("summary.json"), json.as_bytes())
    }
}

/// Peak resident set size of this process in bytes (Linux `VmHWM`; 0 elsewhere).
pub fn peak_memory_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|kb| kb.parse::<u64>().ok())
            })
        })
        .map_or(0, |kb| kb * 1024)
}

/// Write `"status": "failed: <error>"` into `summary.json` of a failed run (best effort:
/// the run's own error is what the caller reports; the write is atomic, so if it fails
/// too nothing half-written stays).
pub(crate) fn write_failed_summary(
    ls: &crate::common::loaded::LoadedScene,
    out: &Path,
    error: &str,
    start: std::time::Instant,
) {
    let summary = Summary {
        scene: ls.scene.scene.name.clone(),
        model: ls.model().to_string(),
        dim: ls.scene.scene.dim.clamp(0, 3) as usize,
        cells: None,
        nodes: None,
        dofs: None,
        sizes_text: String::new(),
        steps: 0,
        status: format!("failed: {error}"),
        interrupted_at: None,
        fractured_cells: None,
        wall_seconds: WallSeconds {
            total: start.elapsed().as_secs_f64(),
            ..WallSeconds::default()
        },
        peak_memory_bytes: peak_memory_bytes(),
        solver: SolverStats::default(),
        field_extrema: Default::default(),
        errors: Default::default(),
        version: env!("CARGO_PKG_VERSION").into(),
        overrides: ls.overrides(),
        extra: serde_json::Map::new(),
    };
    let _ = summary.write(out);
}

/// Name of the lock file of an output folder.
pub const LOCK_FILE: &str = ".porofrac.lock";

/// The lock of an output folder, held while a run writes into it (see the module docs);
/// dropping it removes the lock file.
#[derive(Debug)]
pub struct OutputLock {
    path: PathBuf,
    /// The process id of a dead process whose lock was taken over.
    taken_over: Option<u32>,
}

/// Whether process `pid` exists (`/proc/<pid>`); `None` where that cannot be known.
fn process_alive(pid: u32) -> Option<bool> {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return None;
    }
    Some(proc.join(pid.to_string()).exists())
}

impl OutputLock {
    /// Create `dir` if needed and lock it for this process. Errors (naming the lock file):
    /// a live process holds the lock (its id is given), or the lock file cannot be
    /// created or read.
    pub fn acquire(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(LOCK_FILE);
        let err = |source| OutputError {
            path: path.clone(),
            source,
        };
        std::fs::create_dir_all(dir).map_err(|source| OutputError {
            path: dir.to_path_buf(),
            source,
        })?;
        let mut taken_over = None;
        // Two attempts: the second after removing a stale lock.
        for _ in 0..2 {
            match Self::create(&path) {
                Ok(()) => return Ok(Self { path, taken_over }),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
                Err(e) => return Err(err(e)),
            }
            let text = match std::fs::read_to_string(&path) {
                Ok(t) => t,
                // Removed in between by its owner: try again.
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                Err(e) => return Err(err(e)),
            };
            let pid = text.trim().parse::<u32>().ok();
            match pid.map(|p| (p, process_alive(p))) {
                Some((p, Some(false))) if p != std::process::id() => {
                    let _ = std::fs::remove_file(&path);
                    taken_over = Some(p);
                }
                Some((p, _)) => {
                    return Err(err(std::io::Error::other(format!(
                        "another porofrac run (process {p}) is writing into this folder; wait \
                         for it to end, or use another --out (if process {p} is not a \
                         porofrac run, remove the lock file)"
                    ))));
                }
                None => {
                    return Err(err(std::io::Error::other(
                        "the folder is locked by a lock file that holds no process id; \
                         remove it if no run writes into this folder",
                    )));
                }
            }
        }
        Err(err(std::io::Error::other(
            "another porofrac run took the lock of this folder at the same moment",
        )))
    }

    fn create(path: &Path) -> std::io::Result<()> {
        use std::io::Write as _;
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)?;
        let written = writeln!(f, "{}", std::process::id());
        if let Err(e) = written {
            drop(f);
            let _ = std::fs::remove_file(path);
            return Err(e);
        }
        Ok(())
    }

    /// The process id of a run that ended without removing its lock, when this lock took
    /// it over.
    pub fn taken_over(&self) -> Option<u32> {
        self.taken_over
    }
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Whether `name` is `<prefix>` followed by at least four digits and `.<ext>`.
fn numbered(name: &str, prefix: &str, ext: &str) -> bool {
    name.strip_prefix(prefix)
        .and_then(|r| r.strip_suffix(ext))
        .and_then(|r| r.strip_suffix('.'))
        .is_some_and(|d| d.len() >= 4 && d.bytes().all(|b| b.is_ascii_digit()))
}

/// Whether `name` is a temporary file of an atomic write (`.tmp.<pid>.<n>.<name>`) of a
/// process that no longer runs.
fn stale_temporary(name: &str) -> bool {
    let Some(rest) = name.strip_prefix(".tmp.") else {
        return false;
    };
    let pid = rest.split('.').next().and_then(|p| p.parse::<u32>().ok());
    match pid {
        Some(p) if p == std::process::id() => false,
        Some(p) => process_alive(p) != Some(true),
        None => false,
    }
}

/// Remove from `dir` the files an earlier run wrote there under porofrac's own names: in
/// `vtk/` the numbered steps (`step_NNNN.vtu`, `step_NNNN.vti`, `particles_NNNN.vtp`,
/// `contacts_NNNN.vtp`); the series `<name>.pvd` and `<name>_contacts.pvd` for the scene
/// name `names` gives and the one the earlier `summary.json` records; the tables
/// (`probes.csv`, `fracture.csv`, `heat.csv`, `broken.csv`, `crack.csv`, `lines/*.csv`);
/// the checkpoint `checkpoint/state.bin`;
/// the pictures `plots/*.png` and `plots/fracture/*.png`; `summary.json`; and temporary
/// files of atomic writes left by processes that no longer run. Folders left empty are
/// removed. Nothing else is touched. Returns the number of files removed.
pub fn remove_earlier_outputs(dir: &Path, name: &str) -> Result<usize, OutputError> {
    let mut names = vec![name.to_string()];
    if let Ok(text) = std::fs::read_to_string(dir.join("summary.json"))
        && let Ok(v) = serde_json::from_str::<serde_json::Value>(&text)
        && let Some(earlier) = v.get("scene").and_then(|s| s.as_str())
        && !earlier.is_empty()
        && !earlier.contains(['/', '\\'])
        && earlier != name
    {
        names.push(earlier.to_string());
    }
    let top: Vec<String> = names
        .iter()
        .flat_map(|n| [format!("{n}.pvd"), format!("{n}_contacts.pvd")])
        .chain(
            [
                "probes.csv",
                "fracture.csv",
                "heat.csv",
                "broken.csv",
                "crack.csv",
                "summary.json",
            ]
            .map(String::from),
        )
        .collect();
    let mut removed = 0;
    let mut clean = |sub: &str, keep: &dyn Fn(&str) -> bool| -> Result<(), OutputError> {
        let d = if sub.is_empty() {
            dir.to_path_buf()
        } else {
            dir.join(sub)
        };
        let Ok(entries) = std::fs::read_dir(&d) else {
            return Ok(());
        };
        for e in entries.flatten() {
            let n = e.file_name();
            let Some(n) = n.to_str() else { continue };
            let is_file = e.file_type().is_ok_and(|t| t.is_file());
            if is_file && (keep(n) || stale_temporary(n)) {
                let p = e.path();
                std::fs::remove_file(&p).map_err(|source| OutputError { path: p, source })?;
                removed += 1;
            }
        }
        if !sub.is_empty() {
            // Only succeeds when empty: a folder holding the user's files stays.
            let _ = std::fs::remove_dir(&d);
        }
        Ok(())
    };
    clean("vtk", &|n| {
        numbered(n, "step_", "vtu")
            || numbered(n, "step_", "vti")
            || numbered(n, "particles_", "vtp")
            || numbered(n, "contacts_", "vtp")
    })?;
    clean("lines", &|n| n.ends_with(".csv"))?;
    clean("checkpoint", &|n| n == "state.bin")?;
    clean("plots/fracture", &|n| n.ends_with(".png"))?;
    clean("plots", &|n| n.ends_with(".png"))?;
    clean("", &|n| top.iter().any(|t| t == n))?;
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("porofrac_output_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A table whose file cannot be written (its target is a folder) returns the error
    /// naming the file, keeps no temporary file, and its drop neither panics nor writes.
    #[test]
    fn a_failed_table_write_leaves_no_temporary_file() {
        let d = dir("table");
        std::fs::create_dir_all(d.join("probes.csv/inside")).unwrap();
        let mut t = CsvTable::new(d.join("probes.csv"), &["time".to_string()]);
        let _ = t.push_text(&["1".to_string()]);
        let e = t.flush().unwrap_err();
        assert_eq!(e.path, d.join("probes.csv"));
        drop(t);
        let names: Vec<String> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["probes.csv"]);
        assert!(d.join("probes.csv").is_dir());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn numbered_names() {
        assert!(numbered("step_0012.vtu", "step_", "vtu"));
        assert!(numbered("step_12345.vtu", "step_", "vtu"));
        assert!(!numbered("step_012.vtu", "step_", "vtu"));
        assert!(!numbered("step_0012x.vtu", "step_", "vtu"));
        assert!(!numbered("mystep_0012.vtu", "step_", "vtu"));
        assert!(!numbered("step_0012.vtu.bak", "step_", "vtu"));
    }

    /// The earlier run's files go, under both scene names; the user's files stay, and so
    /// do folders that still hold them.
    #[test]
    fn earlier_outputs_are_removed_and_nothing_else() {
        let d = dir("earlier");
        for sub in ["vtk", "lines", "plots/fracture"] {
            std::fs::create_dir_all(d.join(sub)).unwrap();
        }
        let ours = [
            "vtk/step_0000.vtu",
            "vtk/step_0001.vtu",
            "vtk/particles_0003.vtp",
            "old.pvd",
            "old_contacts.pvd",
            "new.pvd",
            "probes.csv",
            "lines/mid.csv",
            "plots/probes.png",
            "plots/fracture/open.png",
            "summary.json",
            ".tmp.4294967294.0.probes.csv",
        ];
        let theirs = [
            "vtk/mine.vtu",
            "other.pvd",
            "notes.txt",
            "plots/sketch.svg",
            "lines/readme.txt",
        ];
        for f in ours.iter().chain(&theirs) {
            std::fs::write(d.join(f), b"x").unwrap();
        }
        std::fs::write(d.join("summary.json"), br#"{"scene": "old"}"#).unwrap();
        let live = format!(".tmp.{}.0.a.csv", std::process::id());
        std::fs::write(d.join(&live), b"x").unwrap();
        assert_eq!(remove_earlier_outputs(&d, "new").unwrap(), ours.len());
        for f in ours {
            assert!(!d.join(f).exists(), "{f}");
        }
        for f in theirs.iter().chain([&live.as_str()]) {
            assert!(d.join(f).is_file(), "{f}");
        }
        assert!(!d.join("plots/fracture").exists());
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A live lock (this process) is refused naming the pid; a stale one (a dead pid) is
    /// taken over; the lock file goes with the lock.
    #[test]
    fn lock_refuses_a_live_owner_and_takes_over_a_dead_one() {
        let d = dir("lock");
        let lock = OutputLock::acquire(&d).unwrap();
        assert_eq!(lock.taken_over(), None);
        let text = std::fs::read_to_string(d.join(LOCK_FILE)).unwrap();
        assert_eq!(text.trim(), std::process::id().to_string());
        let e = OutputLock::acquire(&d).unwrap_err().to_string();
        assert!(
            e.contains(&format!("process {}", std::process::id())) && e.contains(LOCK_FILE),
            "{e}"
        );
        drop(lock);
        assert!(!d.join(LOCK_FILE).exists());
        if process_alive(1) == Some(true) {
            // A pid above the kernel's maximum (4194304) never runs.
            std::fs::write(d.join(LOCK_FILE), "4294967294\n").unwrap();
            let lock = OutputLock::acquire(&d).unwrap();
            assert_eq!(lock.taken_over(), Some(4_294_967_294));
        }
        std::fs::write(d.join(LOCK_FILE), "garbage").unwrap();
        assert!(OutputLock::acquire(&d).is_err());
        std::fs::remove_dir_all(&d).unwrap();
    }
}
