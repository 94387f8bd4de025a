//! The shape every model of a scene has, and the dispatch on `[scene] model`.
//!
//! A model turns its typed section of the scene into a state (*build*), advances that
//! state from one output time to the next (*step*), and answers what the shared outputs
//! ask of it (*fields*): the value of each probe and of each line point, the VTK file of
//! a written step, the extrema of its fields, its plots and its part of `summary.json`.
//! The loop of [`crate::common::driver`] does the rest the same way for every model.
//!
//! `run` and `check` share the build ([`ModelKind::build`]): a run hands the built model
//! to the loop, a check describes it ([`Purpose`], [`crate::common::plan`]) and writes
//! nothing, so a scene that `check` passes is one that `run` starts stepping.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use porofrac_grid::GridError;
use porofrac_sim::SimError;

use crate::common::driver::Observer;
use crate::common::laws::LawRegistry;
use crate::common::loaded::{LoadedScene, SceneError, k};
use crate::common::output::{OutputError, SolverStats, Summary, WallSeconds};
use crate::common::plan::Plan;
use crate::common::sections::KeyPart;

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
    /// A stop was requested inside a long phase (the build of a model, or a step); the
    /// run ends as interrupted ([`crate::common::driver`]), not as an error.
    #[error("interrupted")]
    Interrupted,
    /// A checkpoint could not be used or written ([`crate::common::checkpoint`]).
    #[error("checkpoint {0}")]
    Checkpoint(String),
    /// Another rank of a distributed run failed with this error (`mpirun -n P`, the
    /// `mpi` feature), or the ranks could not exchange what they hold.
    #[error("{0}")]
    Distributed(String),
}

/// What a step did, for progress and statistics.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepStats {
    /// Solver iterations of the step (linear iterations, coupled solves, relaxation steps).
    pub iterations: usize,
    /// What has failed so far, counted in the model's own terms ([`Sizes::failed`]:
    /// fractured cells, broken bonds, broken cohesive contacts; 0 where nothing fails).
    pub failed: usize,
}

/// Sizes of a model in its own terms, for the progress line and `summary.json`.
///
/// The grid models (continuum, Cosserat) fill `cells`, `nodes` and `dofs`, written to
/// `summary.json` under those keys; the particle and lattice models leave them `None`
/// (their counts are in their own `summary.json` keys: `particles`, `bonds`, `lattice`).
/// `counts` is what the end-of-run line shows, in the model's words.
#[derive(Clone, Debug, Default)]
pub struct Sizes {
    /// Grid cells (grid models).
    pub cells: Option<usize>,
    /// Grid nodes (models with nodal unknowns).
    pub nodes: Option<usize>,
    /// Unknowns of the main system (grid models).
    pub dofs: Option<usize>,
    /// The sizes the end-of-run line shows, in order, e.g. `[("cells", 64), ("nodes",
    /// 81), ("unknowns", 98)]` or `[("particles", 400), ("bonds", 1100)]`.
    pub counts: Vec<(&'static str, usize)>,
    /// What [`StepStats::failed`] and [`Model::failed`] count (`"fractured cells"`,
    /// `"broken bonds"`, `"broken cohesive contacts"`); `None` for a model in which
    /// nothing fails (the count is then neither shown nor written).
    pub failed: Option<&'static str>,
}

impl Sizes {
    /// `cells 64, nodes 81, unknowns 98` as `64 cells, 81 nodes, 98 unknowns`.
    pub fn counts_text(&self) -> String {
        self.counts
            .iter()
            .map(|(what, n)| format!("{n} {what}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
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
    /// End-of-run plots into `dir` (`plots/`), given the probe series at the times they
    /// were sampled (every `[output] probe_every` steps, the last time included).
    fn plots(&self, dir: &Path, written: &[f64], series: &[Vec<f64>]) -> Result<(), RunError>;
    /// Sizes for the progress line and `summary.json`, in the model's terms.
    fn sizes(&self) -> Sizes;
    /// What has failed so far, in the terms of [`Sizes::failed`] (0 where nothing fails).
    fn failed(&self) -> usize;
    /// The unit of field `field` (a probe's or a line's `field`) for CSV headers and plot
    /// axes: `"Pa"`, `"m"`, `"m/s"`; `"1"` for numbers without a unit (ratios, counts,
    /// flags). Every field a model accepts has one.
    fn unit(&self, field: &str) -> &'static str;
    /// Solver statistics of the run so far.
    fn solver_stats(&self) -> SolverStats;
    /// Error norms against the exact solution the scene gives, at the current state
    /// (e.g. `"l2_displacement"`); empty without one.
    fn errors(&self) -> Result<BTreeMap<String, f64>, RunError>;
    /// Wall time of the model's phases so far (assembly, solve, flow, its own output).
    fn wall_seconds(&self) -> WallSeconds;
    /// What [`Model::after_step`] does to the state, without writing any file: the step
    /// of a run kept in memory ([`crate::Scene::run_in_memory`]). Nothing by default (a
    /// model whose `after_step` only writes files).
    fn after_step_in_memory(&mut self) -> Result<(), RunError> {
        Ok(())
    }
    /// The state at the current step for a run kept in memory
    /// ([`crate::common::snapshot`]); `mesh`: include the grid (the first written step).
    /// `None` by default (a model that keeps nothing but probes and lines).
    fn snapshot(&self, mesh: bool) -> Option<crate::common::snapshot::Snapshot> {
        let _ = mesh;
        None
    }
    /// Whether probe number `probe` may be NaN in a valid state: a value undefined at
    /// the probe's place (a fluid probe inside a solid disk). No by default: a probe that
    /// is NaN or infinite ends the run ([`crate::common::driver`]); an infinite value
    /// always does.
    fn probe_may_be_undefined(&self, probe: usize) -> bool {
        let _ = probe;
        false
    }
    /// Keys of the model's own in `summary.json`, besides the shared ones (none by
    /// default).
    fn summary_extras(&self) -> serde_json::Map<String, serde_json::Value> {
        serde_json::Map::new()
    }
    /// The work of the whole schedule, for the run-time estimate of a check (the
    /// per-model throughput constants of [`crate::common::limits`]).
    fn work(&self) -> crate::common::limits::Work;
    /// The estimated peak memory of a run of the model, the program itself apart (bytes;
    /// the per-model estimates of [`crate::common::limits`]).
    fn peak_bytes(&self) -> f64;
    /// Whether the model writes checkpoints ([`Model::save_state`]); no by default, and
    /// then `[output] checkpoint_every` and `--resume` are refused for it.
    fn checkpoints(&self) -> bool {
        false
    }
    /// Put into `state` everything of the current state (after step `step`) that a later
    /// step, probe, line, field, file or the summary reads: positions, velocities,
    /// histories, contact memories and warm starts, damage and fracture state, the model's
    /// own output files' progress. Caches that change iterates are saved too, or reset so
    /// that a straight run and a resumed one compute the same. Names must not start with
    /// `driver/` or `scene/`.
    fn save_state(&self, state: &mut crate::common::checkpoint::State) -> Result<(), RunError> {
        let _ = state;
        Err(RunError::Checkpoint(
            "this model does not write checkpoints".into(),
        ))
    }
    /// Put back the state [`Model::save_state`] saved, into a model just built from the
    /// same scene whose outputs go to `out`; the next call is `step(step + 1)`.
    fn restore_state(
        &mut self,
        state: &crate::common::checkpoint::State,
        out: &Path,
    ) -> Result<(), RunError> {
        let _ = (state, out);
        Err(RunError::Checkpoint(
            "this model does not read checkpoints".into(),
        ))
    }
}

/// A model's own sections, read from the parsed file by [`ModelKind::sections_of`] and
/// reached with [`LoadedScene::own`].
pub trait OwnSections: std::any::Any + std::fmt::Debug + Send + Sync {}

impl<T: std::any::Any + std::fmt::Debug + Send + Sync> OwnSections for T {}

/// One model of the registry: its name, the top-level sections it declares, how it reads,
/// checks and runs a scene. Each model folder exposes one value of a type implementing it
/// (`KIND`); the crate's list of them is [`crate::MODELS`].
pub trait ModelKind: Sync {
    /// The name of `[scene] model`.
    fn name(&self) -> &'static str;
    /// The top-level sections that belong to this model: in a scene of another model
    /// (that does not [`ModelKind::reads`] them) each is refused with
    /// `belongs to model "<name>", not "<model>"`.
    fn sections(&self) -> &'static [&'static str];
    /// Sections of other models this model reads too (none by default).
    fn reads(&self) -> &'static [&'static str] {
        &[]
    }
    /// How a section of this model is named when another model refuses it (the section
    /// itself by default).
    fn refused_as(&self, section: &str) -> Vec<KeyPart> {
        vec![KeyPart::Key(section.to_string())]
    }
    /// Keys of other models the model refuses its own way, before the sections are
    /// refused by their declared owners (nothing by default).
    fn refuse(&self, ls: &LoadedScene) -> Result<(), SceneError> {
        let _ = ls;
        Ok(())
    }
    /// Read the model's own sections (types, unknown keys) from the top-level sections of
    /// the document that are not shared ones. Errors keep the parser's spans.
    fn sections_of(
        &self,
        doc: toml::Spanned<toml::de::DeTable<'_>>,
    ) -> Result<Arc<dyn OwnSections>, toml::de::Error> {
        let _ = doc;
        Ok(Arc::new(()))
    }
    /// The JSON Schema of the model's own sections (the type [`ModelKind::sections_of`]
    /// reads), for the key reference and the errors that name a key
    /// ([`crate::common::keys`]); `None` for a model without sections of its own.
    fn own_schema(&self) -> Option<schemars::Schema> {
        None
    }
    /// The schema of the keys the model adds to `summary.json`
    /// ([`Model::summary_extras`]) as `generator` makes it (a reference into its
    /// definitions), for [`crate::common::keys::summary_schema`]; `None` (by default):
    /// not published.
    fn summary_schema(
        &self,
        generator: &mut schemars::SchemaGenerator,
    ) -> Option<schemars::Schema> {
        let _ = generator;
        None
    }
    /// Check every value the model reads (after the checks every model shares).
    fn check(&self, ls: &LoadedScene, laws: &LawRegistry) -> Result<(), SceneError>;
    /// Build the model — everything a run does before its first step: files read, grid
    /// built, conditions, probes and lines located, packings and calibrations — and hand
    /// it to `purpose` ([`Purpose::finish`]): a run drives it through the schedule
    /// writing its outputs, a check describes it and writes nothing.
    fn build(
        &self,
        ls: &LoadedScene,
        laws: &LawRegistry,
        purpose: &Purpose<'_>,
        observer: &mut dyn Observer,
    ) -> Result<Built, RunError>;
    /// Run the scene on the ranks of `world` (`mpirun -n P porofrac run`, P > 1) and
    /// write its outputs into `out`: each rank builds and steps its part, and the files
    /// are those of a serial run (`summary.json` is written by the caller,
    /// [`crate::Scene::run_distributed`]). Collective: every rank calls it and returns
    /// what the others return. A model without a distributed path refuses (the default):
    /// `model "X" has no distributed path: run it without mpirun (or with -n 1)`.
    #[cfg(feature = "mpi")]
    fn run_distributed(
        &self,
        ls: &LoadedScene,
        laws: &LawRegistry,
        out: &Path,
        world: &mpi::topology::SimpleCommunicator,
        observer: &mut dyn Observer,
    ) -> Result<Summary, RunError> {
        let _ = (laws, out, world, observer);
        Err(crate::common::distributed::no_distributed_path(ls))
    }
}

/// What a model is built for: the one difference between `run` and `check`.
#[derive(Clone, Copy, Debug)]
pub enum Purpose<'a> {
    /// Drive the built model through its schedule and write the outputs into the folder.
    Run(&'a Path),
    /// Describe the built model ([`Plan`]); write nothing.
    Check,
    /// Drive the built model through its schedule and keep the results in memory for the
    /// observer ([`crate::Scene::run_in_memory`]); write nothing.
    Memory,
}

/// What a built model ended as.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
pub enum Built {
    /// The summary of the run.
    Ran(Summary),
    /// What a run would do.
    Checked(Plan),
}

impl Purpose<'_> {
    /// The output folder of a run (`None` for a check: a build writes nothing then).
    pub fn out(&self) -> Option<&Path> {
        match self {
            Purpose::Run(out) => Some(out),
            Purpose::Check | Purpose::Memory => None,
        }
    }

    /// Hand a built model on: drive it through the loop of [`crate::common::driver`] for
    /// a run, describe it ([`Plan::of`]) for a check. `start` is the start of the build
    /// and `grid_seconds` the time spent on the grid (or the whole build).
    pub fn finish(
        &self,
        ls: &LoadedScene,
        model: &mut dyn Model,
        observer: &mut dyn Observer,
        start: std::time::Instant,
        grid_seconds: f64,
        dim: usize,
    ) -> Result<Built, RunError> {
        match self {
            Purpose::Run(out) => crate::common::driver::drive(
                ls,
                model,
                Some(out),
                observer,
                start,
                grid_seconds,
                dim,
            )
            .map(Built::Ran),
            Purpose::Memory => {
                crate::common::driver::drive(ls, model, None, observer, start, grid_seconds, dim)
                    .map(Built::Ran)
            }
            Purpose::Check => Ok(Built::Checked(Plan::of(
                ls,
                model,
                dim,
                start.elapsed().as_secs_f64(),
            ))),
        }
    }
}

/// Read a model's own sections from the non-shared part of a document.
pub fn own_sections<T>(
    doc: toml::Spanned<toml::de::DeTable<'_>>,
) -> Result<Arc<dyn OwnSections>, toml::de::Error>
where
    T: OwnSections + for<'de> serde::Deserialize<'de>,
{
    let t: T = serde::Deserialize::deserialize(toml::de::Deserializer::from(doc))?;
    Ok(Arc::new(t))
}

/// Run a validated scene with its model, in the thread pool the scene asks for, and
/// write `summary.json` (nothing without `out`: a run kept in memory).
pub(crate) fn run(
    ls: &LoadedScene,
    laws: &LawRegistry,
    out: Option<&Path>,
    observer: &mut dyn Observer,
) -> Result<Summary, RunError> {
    let start = std::time::Instant::now();
    let purpose = match out {
        Some(out) => Purpose::Run(out),
        None => Purpose::Memory,
    };
    let summary = match in_pool(ls, laws, &purpose, observer) {
        Ok(Built::Ran(summary)) => summary,
        // Only a model that ignored its purpose gets here.
        Ok(Built::Checked(_)) => {
            return Err(ls
                .error(
                    &k(&["scene", "model"]),
                    format!(
                        "= \"{}\" checked the scene instead of running it",
                        ls.model()
                    ),
                )
                .into());
        }
        // Stopped while the model was built: nothing was stepped.
        Err(RunError::Interrupted) => {
            crate::common::driver::interrupted_in_setup(ls, start, ls.scene.scene.dim as usize)
        }
        Err(e) => return Err(e),
    };
    if let Some(out) = out {
        summary.write(out)?;
    }
    Ok(summary)
}

/// Build a validated scene's model as a run would, up to its first step, and describe
/// it; nothing is written. A stop request of `observer` during the build ends it with
/// [`RunError::Interrupted`].
pub(crate) fn check(
    ls: &LoadedScene,
    laws: &LawRegistry,
    observer: &mut dyn Observer,
) -> Result<Plan, RunError> {
    match in_pool(ls, laws, &Purpose::Check, observer)? {
        Built::Checked(plan) => Ok(plan),
        // Only a model that ignored its purpose gets here.
        Built::Ran(_) => Err(ls
            .error(
                &k(&["scene", "model"]),
                format!("= \"{}\" ran the scene instead of checking it", ls.model()),
            )
            .into()),
    }
}

/// Build the scene's model for `purpose` in the thread pool the scene asks for.
fn in_pool(
    ls: &LoadedScene,
    laws: &LawRegistry,
    purpose: &Purpose<'_>,
    observer: &mut dyn Observer,
) -> Result<Built, RunError> {
    // `[solver] threads`: 0 (default) keeps rayon's pool (one thread per core); n > 0 runs
    // the scene in a pool of n threads (the parallel assembly, AMG and flow kernels).
    match ls.scene.solver.threads {
        Some(n) if n > 0 => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .build()
                .map_err(|e| ls.error(&k(&["solver", "threads"]), format!("= {n}: {e}")))?;
            pool.install(|| build_model(ls, laws, purpose, observer))
        }
        _ => build_model(ls, laws, purpose, observer),
    }
}

fn build_model(
    ls: &LoadedScene,
    laws: &LawRegistry,
    purpose: &Purpose<'_>,
    observer: &mut dyn Observer,
) -> Result<Built, RunError> {
    let Some(kind) = ls.kind() else {
        return Err(ls
            .error(
                &k(&["scene", "model"]),
                format!(
                    "= \"{}\" is not available in this version of porofrac",
                    ls.model()
                ),
            )
            .into());
    };
    kind.build(ls, laws, purpose, observer)
}
