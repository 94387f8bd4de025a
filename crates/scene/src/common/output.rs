//! Output files of a run (SCENE.md, "Outputs"): every file is written atomically
//! (a temporary file in the same directory, then a rename), so an interrupted run never
//! leaves a half-written file.

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
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct WallSeconds {
    /// Whole run.
    pub total: f64,
    /// Grid generation or import.
    pub grid: f64,
    /// Assembly of matrices and loads.
    pub assembly: f64,
    /// Linear solves of the mechanics.
    pub solve: f64,
    /// Flow solves.
    pub flow: f64,
    /// Writing output.
    pub output: f64,
}

/// Linear-solver statistics.
#[derive(Clone, Debug, Default, serde::Serialize)]
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
#[derive(Clone, Debug, serde::Serialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// The model (`[scene] model`).
    pub model: String,
    /// 2 or 3.
    pub dim: usize,
    /// Number of cells.
    pub cells: usize,
    /// Number of nodes.
    pub nodes: usize,
    /// Number of mechanical unknowns (equations after eliminating prescribed dofs).
    pub dofs: usize,
    /// Number of written steps after t = 0.
    pub steps: usize,
    /// `"ok"`, `"interrupted at t = …"` or the error text.
    pub status: String,
    /// The last finished time of an interrupted run.
    #[serde(skip)]
    pub interrupted_at: Option<f64>,
    /// Number of failed cells.
    pub fractured_cells: usize,
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

/// Write an error status into `summary.json` of a failed run (best effort: the run's own
/// error is what the caller reports).
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
        cells: 0,
        nodes: 0,
        dofs: 0,
        steps: 0,
        status: error.to_string(),
        interrupted_at: None,
        fractured_cells: 0,
        wall_seconds: WallSeconds {
            total: start.elapsed().as_secs_f64(),
            ..WallSeconds::default()
        },
        peak_memory_bytes: peak_memory_bytes(),
        solver: SolverStats::default(),
        field_extrema: Default::default(),
        errors: Default::default(),
        version: env!("CARGO_PKG_VERSION").into(),
        extra: serde_json::Map::new(),
    };
    let _ = summary.write(out);
}
