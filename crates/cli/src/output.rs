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
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    std::fs::write(&tmp, bytes).map_err(err)?;
    std::fs::rename(&tmp, path).map_err(err)
}

/// A CSV table kept in memory and rewritten atomically after every row.
#[derive(Clone, Debug)]
pub struct CsvTable {
    path: PathBuf,
    text: String,
}

impl CsvTable {
    /// A table with a header line.
    pub fn new(path: PathBuf, header: &[String]) -> Self {
        let mut text = header.join(",");
        text.push('\n');
        Self { path, text }
    }
    /// Append a row of numbers and rewrite the file.
    pub fn push(&mut self, row: &[f64]) -> Result<(), OutputError> {
        self.push_text(&row.iter().map(|v| format!("{v}")).collect::<Vec<_>>())
    }
    /// Append a row of already formatted cells and rewrite the file.
    pub fn push_text(&mut self, row: &[String]) -> Result<(), OutputError> {
        let _ = writeln!(self.text, "{}", row.join(","));
        self.flush()
    }
    /// Write the file as it is.
    pub fn flush(&self) -> Result<(), OutputError> {
        write_atomic(&self.path, self.text.as_bytes())
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
    /// `"ok"` or the error text.
    pub status: String,
    /// Number of failed cells.
    pub fractured_cells: usize,
    /// Wall time per phase.
    pub wall_seconds: WallSeconds,
    /// Peak resident memory of the process (bytes; 0 where unknown).
    pub peak_memory_bytes: u64,
    /// Solver statistics.
    pub solver: SolverStats,
    /// porofrac version.
    pub version: String,
}

impl Summary {
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
