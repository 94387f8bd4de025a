//! The shape every model of a scene has, and the dispatch on `[scene] model`.
//!
//! A model turns its typed section of the scene into a state (*build*), advances that
//! state from one output time to the next (*step*), and answers what the shared outputs
//! ask of it (*fields*): the value of each probe and of each line point, the VTK file of
//! a written step, the extrema of its fields, its plots and its part of `summary.json`.
//! The loop of [`crate::common::driver`] does the rest the same way for every model.

use std::collections::BTreeMap;
use std::path::Path;

use porofrac_grid::GridError;
use porofrac_sim::SimError;

use crate::common::driver::Observer;
use crate::common::laws::LawRegistry;
use crate::common::loaded::{LoadedScene, SceneError, k};
use crate::common::output::{OutputError, SolverStats, Summary, WallSeconds};

/// Anything that ends a run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// A problem in the scene file.
    #[error("{0}")]
    Scene(#[from] SceneError),
    /// The grid could not be built or read.
    #[error("grid: {0}")]
    Grid(#[from] GridError),
    /// The mechanics failed (singular system, bad law composition, ...).
    #[error("{0}")]
    Sim(#[from] SimError),
    /// Writing output failed.
    #[error("output: {0}")]
    Output(#[from] OutputError),
    /// Failures did not settle within a step.
    #[error("fracture: {0}")]
    Fracture(String),
    /// The flow model could not be built or solved.
    #[error("flow: {0}")]
    Flow(String),
    /// The poroelastic coupling failed.
    #[error("coupling: {0}")]
    Biot(#[from] porofrac_sim::BiotError),
    /// A plot could not be drawn.
    #[error("plot: {0}")]
    Plot(#[from] crate::common::plots::PlotError),
    /// The coupled fracturing step failed.
    #[error("{0}")]
    Coupled(#[from] porofrac_sim::FractureError),
}

/// What a step did, for progress and statistics.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepStats {
    /// Solver iterations of the step (linear iterations, coupled solves, relaxation steps).
    pub iterations: usize,
    /// Cells (or bonds) failed so far.
    pub failed: usize,
}

/// Sizes of a model for `summary.json`.
#[derive(Clone, Debug, Default)]
pub struct Sizes {
    /// Cells (or particles, lattice nodes).
    pub cells: usize,
    /// Nodes.
    pub nodes: usize,
    /// Unknowns of the main system.
    pub dofs: usize,
}

/// A model built from a scene, stepping through its output times (see the module docs).
pub trait Model {
    /// The output times: `0` first, then the end of every step of the schedule.
    fn times(&self) -> &[f64];
    /// Compute the state at `times()[step]` from the state at the previous time (step 0:
    /// the initial state).
    fn step(&mut self, step: usize) -> Result<StepStats, RunError>;
    /// The value of every `[[output.probe]]` at the current state, in scene order.
    fn probes(&self, values: &mut Vec<f64>);
    /// The points of `[[output.line]]` number `line` at the current state: rows
    /// `s, x, y(, z), value`.
    fn line(&self, line: usize, rows: &mut Vec<Vec<f64>>);
    /// Files the model writes after every step (e.g. the fracture log); called after each
    /// step, written or not.
    fn after_step(&mut self, out: &Path) -> Result<(), RunError>;
    /// Write the current state as VTK file number `index` in `dir`; returns the file name.
    fn write_vtk(&self, dir: &Path, index: usize) -> Result<String, RunError>;
    /// `[min, max]` of every field of the model at the current state.
    fn field_extrema(&self) -> BTreeMap<String, [f64; 2]>;
    /// End-of-run plots into `dir` (`plots/`), given the probe series at the written times.
    fn plots(&self, dir: &Path, written: &[f64], series: &[Vec<f64>]) -> Result<(), RunError>;
    /// Sizes for `summary.json`.
    fn sizes(&self) -> Sizes;
    /// Failed cells (or broken bonds) so far.
    fn failed(&self) -> usize;
    /// Solver statistics of the run so far.
    fn solver_stats(&self) -> SolverStats;
    /// Error norms against the exact solution the scene gives, at the current state
    /// (e.g. `"l2_displacement"`); empty without one.
    fn errors(&self) -> Result<BTreeMap<String, f64>, RunError>;
    /// Wall time of the model's phases so far (assembly, solve, flow, its own output).
    fn wall_seconds(&self) -> WallSeconds;
    /// Keys of the model's own in `summary.json`, besides the shared ones (none by
    /// default).
    fn summary_extras(&self) -> serde_json::Map<String, serde_json::Value> {
        serde_json::Map::new()
    }
}

/// Run a validated scene: dispatch on `[scene] model`, in the thread pool the scene asks
/// for, and write `summary.json`.
pub(crate) fn run(
    ls: &LoadedScene,
    laws: &LawRegistry,
    out: &Path,
    observer: &mut dyn Observer,
) -> Result<Summary, RunError> {
    // `[solver] threads`: 0 (default) keeps rayon's pool (one thread per core); n > 0 runs
    // the scene in a pool of n threads (the parallel assembly, AMG and flow kernels).
    match ls.scene.solver.threads {
        Some(n) if n > 0 => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .build()
                .map_err(|e| ls.error(&k(&["solver", "threads"]), format!("= {n}: {e}")))?;
            pool.install(|| run_model(ls, laws, out, observer))
        }
        _ => run_model(ls, laws, out, observer),
    }
}

fn run_model(
    ls: &LoadedScene,
    laws: &LawRegistry,
    out: &Path,
    observer: &mut dyn Observer,
) -> Result<Summary, RunError> {
    let summary = match ls.model() {
        "continuum" => crate::continuum::run(ls, laws, out, observer)?,
        "nscd" => crate::nscd::run(ls, out, observer)?,
        "lbm" => crate::lbm::run(ls, out, observer)?,
        "cosserat" => crate::cosserat::run(ls, out, observer)?,
        "lsm" => crate::lsm::run(ls, out, observer)?,
        other => {
            return Err(ls
                .error(
                    &k(&["scene", "model"]),
                    format!("= \"{other}\" is not available in this version of porofrac"),
                )
                .into());
        }
    };
    summary.write(out)?;
    Ok(summary)
}
