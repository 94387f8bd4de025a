//! porofrac scenes as a library: read a scene file into a validated, typed [`Scene`],
//! compose its model and run it, writing the outputs of docs/SCENE.md (summary, probes,
//! lines, fracture log, VTK, plots). The `porofrac` command is a thin layer over this
//! crate (arguments, progress, exit codes); a Rust program gets the same outputs with
//!
//! ```no_run
//! use porofrac_scene::{Scene, Silent};
//!
//! let scene = Scene::load("scenes/patch_test.toml".as_ref())?;
//! let summary = scene.run("out/patch_test".as_ref(), &mut Silent)?;
//! println!("{} in {:.2} s", summary.sizes_text, summary.wall_seconds.total);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Shape
//!
//! The crate is a registry of models. [`common`] holds what every model shares: the
//! loaded scene, its errors with the lines of the parser's spans ([`common::loaded`]),
//! the shared sections ([`common::sections`]), the [`model::Model`] trait and the loop
//! that drives it ([`driver`]: `probes.csv`, `lines/`, VTK, `summary.json`, progress and
//! interruption), outputs, plots, limits, expressions and cell laws
//! ([`laws::LawRegistry`], to which a user adds their own), and what two models share
//! (particles, the lattice, the grid builder). Each model is one folder ([`continuum`],
//! [`cosserat`], [`lbm`], [`lsm`], [`nscd`]) holding its own sections, checks, build and
//! [`model::Model`] implementation, importing [`common`] only; it exposes one
//! [`model::ModelKind`] value, and [`MODELS`] lists them. `[scene] model` (default
//! `"continuum"`) is looked up there; the file is parsed once, and a section of one model
//! in another model's scene is refused by name from the sections each model declares.
//! `docs/ADDING_A_MODEL.md` shows how a model is added.
//!
//! # Hostile input
//!
//! A scene is refused with an error naming the key before anything big is allocated:
//! expressions nest at most [`expr::MAX_NESTING`] deep, and the number of steps, cells
//! and unknowns a scene asks for is bounded by what the machine has ([`limits`]).

pub mod common;
pub mod continuum;
pub mod cosserat;
pub mod lbm;
pub mod lsm;
pub mod nscd;

use std::path::{Path, PathBuf};

pub use common::driver::{Observer, SetupReport, Silent, StepReport, Stop};
pub use common::laws::{self, LawRegistry};
pub use common::loaded::SceneError;
pub use common::model::RunError;
pub use common::output::Summary;
pub use common::plan::Plan;
pub use common::{driver, expr, limits, model, output};

use common::loaded::{self as check, LoadedScene};
use common::model::ModelKind;

/// The models of the registry: `[scene] model` is looked up here. A new model is one
/// folder (its sections, checks, build and [`model::Model`]) and one line here.
pub static MODELS: &[&'static dyn ModelKind] = &[
    &continuum::KIND,
    &nscd::KIND,
    &lbm::KIND,
    &cosserat::KIND,
    &lsm::KIND,
];

/// A scene file read and validated: every key known, every value checked, every
/// expression compiled once.
#[derive(Clone, Debug)]
pub struct Scene {
    loaded: LoadedScene,
    laws: LawRegistry,
}

impl Scene {
    /// Read, parse and validate a scene file with the built-in laws.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        Self::load_with(path, LawRegistry::default())
    }

    /// Read, parse and validate a scene file whose regions may use the laws of `laws`
    /// (the built-in ones and the user's, [`LawRegistry::register`]).
    pub fn load_with(path: &Path, laws: LawRegistry) -> Result<Self, SceneError> {
        let loaded = check::load(path, MODELS)?;
        check::check(&loaded, &laws, MODELS)?;
        Ok(Self { loaded, laws })
    }

    /// Read, parse and validate a scene file with `--set KEY=VALUE` overrides applied to
    /// the parsed document before the typed read ([`common::overrides`]): every check
    /// applies to them, an error in one names `--set KEY`, and `summary.json` records
    /// them under `overrides`.
    pub fn load_with_overrides(
        path: &Path,
        laws: LawRegistry,
        overrides: &[common::overrides::Override],
    ) -> Result<Self, SceneError> {
        let loaded = check::load_with(path, MODELS, overrides)?;
        check::check(&loaded, &laws, MODELS)?;
        Ok(Self { loaded, laws })
    }

    /// Parse and validate scene text; `path` names it in errors and anchors relative
    /// paths (mesh files).
    pub fn parse(text: &str, path: &Path, laws: LawRegistry) -> Result<Self, SceneError> {
        let loaded = check::parse(text, path, MODELS)?;
        check::check(&loaded, &laws, MODELS)?;
        Ok(Self { loaded, laws })
    }

    /// Parse and validate scene text with `--set` overrides applied to the parsed
    /// document ([`Scene::load_with_overrides`] for text; `path` names it in errors and
    /// anchors relative paths).
    pub fn parse_with_overrides(
        text: &str,
        path: &Path,
        laws: LawRegistry,
        overrides: &[common::overrides::Override],
    ) -> Result<Self, SceneError> {
        let loaded = check::parse_with(text, path, MODELS, overrides)?;
        check::check(&loaded, &laws, MODELS)?;
        Ok(Self { loaded, laws })
    }

    /// The typed content of the file.
    pub fn file(&self) -> &common::sections::SceneFile {
        &self.loaded.scene
    }

    /// Where the scene came from.
    pub fn path(&self) -> &Path {
        &self.loaded.path
    }

    /// The scene name (`[scene] name`).
    pub fn name(&self) -> &str {
        &self.loaded.scene.scene.name
    }

    /// The default output directory, `out/<name>`.
    pub fn default_out(&self) -> PathBuf {
        PathBuf::from("out").join(self.name())
    }

    /// Everything a run does before its first step, and nothing written: the files the
    /// scene names read (meshes, decks and their includes), the grid built, boundaries,
    /// tags, selections, probes and lines located, the sections the model needs, rigid
    /// body modes, the lattice's Mach number and relaxation time, packings and
    /// calibrations. The same build as [`Scene::run`], so a scene `check` passes is one
    /// `run` starts stepping, and one it refuses fails with the error `run` gives. The
    /// [`Plan`] says what a run would compute and write, with estimates of its memory
    /// and time. A long build (a packing) reports progress to `observer` and stops
    /// with [`RunError::Interrupted`] when it asks.
    pub fn check(&self, observer: &mut dyn Observer) -> Result<Plan, RunError> {
        common::model::check(&self.loaded, &self.laws, observer)
    }

    /// Run the scene and write its outputs into `out`.
    ///
    /// A run that fails still writes `summary.json` with `"status": "failed: <error>"`;
    /// an interrupted run ([`Observer::stop_requested`]) ends after the current step with
    /// complete files and `"status": "interrupted at t = …"` ([`Summary::interrupted`]).
    /// The run locks `out` while it writes (a second run into it is refused) and first
    /// removes what an earlier run wrote there under porofrac's names
    /// ([`output::OutputLock`], [`output::remove_earlier_outputs`]).
    pub fn run(&self, out: &Path, observer: &mut dyn Observer) -> Result<Summary, RunError> {
        let start = std::time::Instant::now();
        let lock = output::OutputLock::acquire(out)?;
        if let Some(pid) = lock.taken_over() {
            eprintln!(
                "note: {}: took over the lock of process {pid}, which no longer runs",
                out.join(output::LOCK_FILE).display()
            );
        }
        output::remove_earlier_outputs(out, self.name())?;
        let result = common::model::run(&self.loaded, &self.laws, Some(out), observer);
        if let Err(e) = &result {
            output::write_failed_summary(&self.loaded, out, &e.to_string(), start);
        }
        drop(lock);
        result
    }

    /// Run the scene on the MPI ranks of `world` (`mpirun -n P porofrac run`), writing
    /// the outputs of [`Scene::run`] into `out`: rank 0 locks `out`, removes what an
    /// earlier run wrote there and writes `summary.json`; every rank returns the same
    /// result (an error on one rank ends the run on all of them, with that error). A
    /// model without a distributed path refuses with an error naming `[scene] model`.
    /// Collective: every rank of `world` calls it.
    #[cfg(feature = "mpi")]
    pub fn run_distributed(
        &self,
        out: &Path,
        world: &mpi::topology::SimpleCommunicator,
        observer: &mut dyn Observer,
    ) -> Result<Summary, RunError> {
        common::distributed::run(&self.loaded, &self.laws, out, world, observer)
    }

    /// Run the scene and keep its results in memory, writing nothing: the observer gets
    /// the probe values of every sampled step ([`Observer::sampled`]) and the lines and
    /// the model's state ([`common::snapshot::Snapshot`]) of every written step
    /// ([`Observer::written`]) when it [`Observer::records`]. The numbers are those of
    /// [`Scene::run`]; `[output] checkpoint_every`, plots and VTK files are left out. An
    /// interrupted run ends as [`Scene::run`] describes.
    pub fn run_in_memory(&self, observer: &mut dyn Observer) -> Result<Summary, RunError> {
        common::model::run(&self.loaded, &self.laws, None, observer)
    }

    /// Continue the run whose checkpoint is in `out` (`<out>/checkpoint/state.bin`,
    /// [`common::checkpoint`]): the model is built again, its state and the files written
    /// so far are restored, and the run goes on from the step after the checkpoint, to
    /// the same results as a run never stopped. The scene must be the one the checkpoint
    /// was written from (same model, same file content), else the run is refused before
    /// anything is built; nothing in `out` is removed first.
    pub fn resume(&self, out: &Path, observer: &mut dyn Observer) -> Result<Summary, RunError> {
        let start = std::time::Instant::now();
        let (model, hash) = common::checkpoint::read_header(out)?;
        common::checkpoint::check_matches(&self.loaded, out, &model, hash)?;
        let lock = output::OutputLock::acquire(out)?;
        let mut loaded = self.loaded.clone();
        loaded.resume = true;
        let result = common::model::run(&loaded, &self.laws, Some(out), observer);
        if let Err(e) = &result {
            output::write_failed_summary(&self.loaded, out, &e.to_string(), start);
        }
        drop(lock);
        result
    }

    /// The scene stored in the checkpoint of `out`, parsed as from its original path
    /// (which anchors relative paths such as mesh files) with the `--set` overrides the
    /// run was started with, and the built-in laws.
    pub fn from_checkpoint(out: &Path) -> Result<Self, RunError> {
        Self::from_checkpoint_with(out, LawRegistry::default())
    }

    /// [`Scene::from_checkpoint`] with the laws of `laws`.
    pub fn from_checkpoint_with(out: &Path, laws: LawRegistry) -> Result<Self, RunError> {
        let c = common::checkpoint::Checkpoint::read(out)?;
        let text = c.state.str("scene/text")?;
        let path = PathBuf::from(c.state.str("scene/path")?);
        let overrides = common::checkpoint::stored_overrides(&c.state)?;
        let loaded = check::parse_with(text, &path, MODELS, &overrides)?;
        check::check(&loaded, &laws, MODELS)?;
        Ok(Self { loaded, laws })
    }
}
