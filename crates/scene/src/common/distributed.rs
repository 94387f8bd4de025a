//! Runs on MPI ranks (cargo feature `mpi`): the part of a distributed run every model
//! shares. `mpirun -n P porofrac run scene.toml` starts P copies of the program; each
//! reads the same scene, and [`crate::Scene::run_distributed`] hands the model's
//! distributed path ([`ModelKind::run_distributed`]) the communicator of all of them.
//!
//! Rank 0 owns the output folder: it takes its lock ([`OutputLock`]), removes what an
//! earlier run wrote there, and writes `summary.json` (with `"status": "failed: …"` when
//! the run fails). The model's path writes what each rank holds (its piece of a parallel
//! VTK file) and leaves the shared tables to rank 0.
//!
//! **Every rank ends the same way.** A rank that fails tells the others at the next point
//! where all of them meet ([`agree`]): each one then returns the error of the lowest
//! failing rank, so no rank waits forever on a rank that has stopped, and the command's
//! exit status is the same on all of them.
//!
//! [`ModelKind::run_distributed`]: crate::common::model::ModelKind::run_distributed

use std::path::Path;

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

use crate::common::driver::Observer;
use crate::common::laws::LawRegistry;
use crate::common::loaded::{LoadedScene, k};
use crate::common::model::RunError;
use crate::common::output::{self, OutputLock, Summary};

/// What the distributed path of model `model` refuses when it has none: the error of
/// [`ModelKind::run_distributed`]'s default, naming `[scene] model`.
///
/// [`ModelKind::run_distributed`]: crate::common::model::ModelKind::run_distributed
pub fn no_distributed_path(ls: &LoadedScene) -> RunError {
    let model = ls.model();
    ls.error(
        &k(&["scene", "model"]),
        format!(
            "= \"{model}\": model \"{model}\" has no distributed path: run it without mpirun \
             (or with -n 1)"
        ),
    )
    .into()
}

/// Make every rank end the same way: when `result` is an error on some rank, every rank
/// returns the error of the lowest failing rank (its own error there, the text of it
/// elsewhere; an interruption stays [`RunError::Interrupted`]). Collective: every rank of
/// `world` calls it at the same point.
pub fn agree<T>(world: &SimpleCommunicator, result: Result<T, RunError>) -> Result<T, RunError> {
    let rank = world.rank();
    let size = world.size();
    let mine = if result.is_err() { rank } else { size };
    let mut first = size;
    world.all_reduce_into(&mine, &mut first, SystemOperation::min());
    if first == size {
        return result;
    }
    let (interrupted, mut text) = match &result {
        Err(e) if rank == first => (
            matches!(e, RunError::Interrupted),
            e.to_string().into_bytes(),
        ),
        _ => (false, Vec::new()),
    };
    let root = world.process_at_rank(first);
    let mut head = [u64::from(interrupted), text.len() as u64];
    root.broadcast_into(&mut head[..]);
    text.resize(head[1] as usize, 0);
    root.broadcast_into(&mut text[..]);
    match result {
        Err(e) if rank == first => Err(e),
        _ if head[0] == 1 => Err(RunError::Interrupted),
        _ => Err(RunError::Distributed(
            String::from_utf8_lossy(&text).into_owned(),
        )),
    }
}

/// Whether any rank asks to stop (Ctrl-C reaches the ranks at different moments): the
/// same answer on every rank. Collective.
pub fn any(world: &SimpleCommunicator, flag: bool) -> bool {
    let mine = u8::from(flag);
    let mut all = 0u8;
    world.all_reduce_into(&mine, &mut all, SystemOperation::max());
    all == 1
}

/// Run a validated scene on the ranks of `world` with its model's distributed path,
/// writing its outputs into `out` (see the module docs). Collective.
pub(crate) fn run(
    ls: &LoadedScene,
    laws: &LawRegistry,
    out: &Path,
    world: &SimpleCommunicator,
    observer: &mut dyn Observer,
) -> Result<Summary, RunError> {
    let start = std::time::Instant::now();
    let root = world.rank() == 0;
    let lock = if root {
        OutputLock::acquire(out)
            .map_err(RunError::from)
            .and_then(|lock| {
                if let Some(pid) = lock.taken_over() {
                    eprintln!(
                        "note: {}: took over the lock of process {pid}, which no longer runs",
                        out.join(output::LOCK_FILE).display()
                    );
                }
                output::remove_earlier_outputs(out, &ls.scene.scene.name)?;
                Ok(Some(lock))
            })
    } else {
        Ok(None)
    };
    // Nothing is written into `out` before rank 0 has cleared it.
    let lock = agree(world, lock)?;
    let result = match ls.kind() {
        Some(kind) => kind.run_distributed(ls, laws, out, world, observer),
        None => Err(ls
            .error(
                &k(&["scene", "model"]),
                format!(
                    "= \"{}\" is not available in this version of porofrac",
                    ls.model()
                ),
            )
            .into()),
    };
    let result = agree(world, result);
    let written = match (&result, root) {
        (Ok(summary), true) => summary.write(out).map_err(RunError::from),
        (Err(e), true) => {
            output::write_failed_summary(ls, out, &e.to_string(), start);
            Ok(())
        }
        _ => Ok(()),
    };
    let written = agree(world, written);
    drop(lock);
    written.and(result)
}
