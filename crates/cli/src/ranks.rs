//! The ranks of `mpirun -n P porofrac run scene.toml`.
//!
//! Built with the `mpi` feature, a `porofrac run` started by an MPI launcher (mpirun,
//! mpiexec, srun: the launcher's environment says how many copies it started) initializes
//! MPI: on one rank it runs the scene as without the launcher, on more it runs the scene's
//! distributed path (`Scene::run_distributed`), with progress and messages from rank 0
//! only. Started without a launcher it runs as a plain `porofrac run` and MPI is not
//! initialized.
//!
//! Built without the feature but started by a launcher with more than one copy, it
//! refuses to run, so that P copies never race on one output folder.

use std::sync::atomic::{AtomicBool, Ordering};

use porofrac_scene::{Observer, RunError, Scene, Summary};
#[cfg(feature = "mpi")]
use porofrac_scene::{SetupReport, StepReport, Stop};

/// Set on the ranks other than 0: they print nothing (rank 0 prints for all).
static QUIET: AtomicBool = AtomicBool::new(false);

/// Whether this process is a rank other than 0 of a distributed run, which prints nothing.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// How many copies an MPI launcher started (the launcher's environment: Open MPI's
/// `OMPI_COMM_WORLD_SIZE`, MPICH's and Slurm's `PMI_SIZE`); `None` without a launcher.
fn launched_size() -> Option<usize> {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"]
        .iter()
        .find_map(|v| std::env::var(v).ok()?.trim().parse().ok())
}

/// The ranks this run has (one without a launcher); holds MPI initialized until dropped.
pub struct Ranks {
    #[cfg(feature = "mpi")]
    universe: Option<mpi::environment::Universe>,
}

impl Ranks {
    /// Initialize MPI when a launcher started this process (see the module docs); refuse
    /// a launch on more than one rank when built without MPI.
    pub fn start() -> Result<Self, String> {
        let launched = launched_size();
        #[cfg(feature = "mpi")]
        {
            use mpi::traits::Communicator;
            if launched.is_none() {
                return Ok(Self { universe: None });
            }
            let universe = mpi::initialize().ok_or("MPI could not be initialized")?;
            if universe.world().rank() != 0 {
                QUIET.store(true, Ordering::Relaxed);
            }
            Ok(Self {
                universe: Some(universe),
            })
        }
        #[cfg(not(feature = "mpi"))]
        {
            if launched.is_some_and(|n| n > 1) {
                return Err("this porofrac was built without MPI: build it with \
                            `--features mpi` (scripts/install-mpi installs MPI)"
                    .into());
            }
            Ok(Self {})
        }
    }

    /// The number of ranks (1 without a launcher or without MPI).
    pub fn size(&self) -> usize {
        #[cfg(feature = "mpi")]
        {
            use mpi::traits::Communicator;
            self.universe
                .as_ref()
                .map_or(1, |u| u.world().size() as usize)
        }
        #[cfg(not(feature = "mpi"))]
        1
    }

    /// Run `scene` on all the ranks ([`Ranks::size`] > 1), writing into `out`; rank 0
    /// reports to `observer`, the others only share its stop request.
    pub fn run(
        &self,
        scene: &Scene,
        out: &std::path::Path,
        observer: &mut dyn Observer,
    ) -> Result<Summary, RunError> {
        #[cfg(feature = "mpi")]
        if let Some(universe) = &self.universe {
            let world = universe.world();
            return if quiet() {
                scene.run_distributed(out, &world, &mut Quiet(observer))
            } else {
                scene.run_distributed(out, &world, observer)
            };
        }
        scene.run(out, observer)
    }
}

/// The observer of the ranks other than 0: no progress, the stop request of the inner one.
#[cfg(feature = "mpi")]
struct Quiet<'a>(&'a mut dyn Observer);

#[cfg(feature = "mpi")]
impl Observer for Quiet<'_> {
    fn step(&mut self, _: &StepReport) {}

    fn setup(&mut self, _: &SetupReport<'_>) {}

    fn stop_requested(&self) -> bool {
        self.0.stop_requested()
    }

    fn stop_handle(&self) -> Stop {
        self.0.stop_handle()
    }
}
