//! Checkpoints of the continuum model ([`crate::common::checkpoint`]): what later steps
//! read, saved after a step and put back into a model built anew from the same scene.
//!
//! - the state: nodal displacements, cell stresses, pressures, the failed cells with the
//!   log of their failures (cell, time, mode) and the rows of `fracture.csv` written;
//! - the crack tracking: the recorded cracks (normal and point of every failed cell), which
//!   decide where a crack may grow;
//! - the coupled driver: the Biot state and the memory of the coupling scheme
//!   ([`porofrac_sim::SchemeMemory`]: the matrices of its factors, the step they were
//!   built for, the columns of a low-rank update and its last forward sweep), from which
//!   the factors are computed again, so that the resumed steps take the same arithmetic
//!   as the run never stopped;
//! - the solver counts of `summary.json`.
//!
//! Not checkpointed (refused with `[output] checkpoint_every`, [`supported`]): static
//! mechanics solved by CG-AMG, whose preconditioner is built once and then only updated,
//! so a rebuilt one would start the iterations from another hierarchy.

use porofrac_frac::{Failure, FailureMode, FailureState};
use porofrac_grid::Point;
use porofrac_law::Tensor;
use porofrac_sim::{BiotState, SchemeMemory, StaticSolver};

use crate::common::checkpoint::State;
use crate::common::model::RunError;

use super::{Driver, Stepper};

/// Whether the run of `s` can write and resume from checkpoints (see the module docs).
pub(super) fn supported<const D: usize>(s: &Stepper<'_, D>) -> bool {
    !matches!(
        &s.driver,
        Driver::Static {
            solver: StaticSolver::CgAmg(_),
            ..
        }
    )
}

fn bad(what: String) -> RunError {
    RunError::Checkpoint(what)
}

/// Save the state of `s` (see the module docs).
pub(super) fn save<const D: usize>(s: &Stepper<'_, D>, state: &mut State) {
    state.put_f64("continuum/u", s.u.as_slice());
    state.put_f64(
        "continuum/stress",
        s.stress
            .iter()
            .flat_map(|t| t.iter().copied())
            .collect::<Vec<_>>(),
    );
    if let Some(p) = &s.pressure {
        state.put_f64("continuum/pressure", p.as_slice());
    }
    save_failures(state, &s.failures);
    let tracking = match &s.driver {
        Driver::Static { resolution, .. } => resolution.tracking(),
        Driver::Coupled { frac, .. } => frac.resolution().tracking(),
    };
    if let Some(t) = tracking {
        let cells = t.recorded();
        let mut normals = Vec::with_capacity(D * cells.len());
        let mut points = Vec::with_capacity(D * cells.len());
        for &c in cells {
            normals.extend(t.normal(c).unwrap_or_else(Point::<D>::zeros).iter());
            points.extend(t.point(c).unwrap_or_else(Point::<D>::zeros).iter());
        }
        state.put_u64(
            "continuum/tracking/cells",
            cells.iter().map(|&c| c as u64).collect::<Vec<_>>(),
        );
        state.put_f64("continuum/tracking/normals", normals);
        state.put_f64("continuum/tracking/points", points);
    }
    if let Some(csv) = &s.fracture_csv {
        state.put_str("continuum/fracture_csv", csv.text());
    }
    state.put_u64(
        "continuum/counts",
        vec![
            s.logged as u64,
            s.done as u64,
            u64::from(s.stress_stale),
            s.stats.iterations as u64,
            s.stats.factorizations as u64,
            s.stats.low_rank_updates as u64,
        ],
    );
    state.put_f64("continuum/residual", vec![s.stats.max_relative_residual]);
    if let Driver::Coupled { frac, state: biot } = &s.driver {
        if let Some(b) = biot {
            state.put_f64("continuum/biot/u", b.displacement.as_slice());
            state.put_f64("continuum/biot/p", b.pressure.as_slice());
        }
        save_memory(state, &frac.scheme_memory());
        if frac.cavitation_pressure().is_some() {
            state.put_f64("continuum/void", frac.void().to_vec());
        }
        if let Some(fronts) = frac.tip_fronts() {
            state.put_f64("continuum/tip_fronts", fronts.to_vec());
        }
    }
}

fn save_failures(state: &mut State, f: &FailureState) {
    let log = f.log();
    state.put_u64(
        "continuum/failures/cells",
        log.iter().map(|f| f.cell as u64).collect::<Vec<_>>(),
    );
    state.put_f64(
        "continuum/failures/times",
        log.iter().map(|f| f.time).collect::<Vec<_>>(),
    );
    state.put_u8(
        "continuum/failures/modes",
        log.iter()
            .map(|f| match f.mode {
                FailureMode::Tensile => 0,
                FailureMode::Shear => 1,
            })
            .collect::<Vec<_>>(),
    );
}

fn save_memory(state: &mut State, m: &SchemeMemory) {
    state.put_f64("continuum/scheme/factored", m.factored.as_slice());
    state.put_f64("continuum/scheme/current", m.current.as_slice());
    state.put_f64("continuum/scheme/stiffness", m.stiffness.as_slice());
    state.put_f64(
        "continuum/scheme/numbers",
        vec![m.dt.unwrap_or(f64::NAN), m.scale, m.residual],
    );
    state.put_u64(
        "continuum/scheme/columns",
        m.columns.iter().map(|&c| c as u64).collect::<Vec<_>>(),
    );
    state.put_u64("continuum/scheme/updates", vec![m.updates as u64]);
    if let Some((b, f)) = &m.forward {
        state.put_f64("continuum/scheme/forward_rhs", b.as_slice());
        state.put_f64("continuum/scheme/forward", f.as_slice());
    }
}

/// Indices of a saved array, each below `n`.
fn indices(state: &State, name: &str, n: usize) -> Result<Vec<usize>, RunError> {
    state
        .u64s(name)?
        .iter()
        .map(|&c| {
            usize::try_from(c)
                .ok()
                .filter(|&c| c < n)
                .ok_or_else(|| bad(format!("array `{name}` holds {c}, out of range 0..{n}")))
        })
        .collect()
}

fn points<const D: usize>(values: &[f64]) -> Vec<Point<D>> {
    values
        .chunks_exact(D)
        .map(Point::<D>::from_column_slice)
        .collect()
}

/// Put back the state [`save`] saved into `s`, just built from the same scene.
pub(super) fn restore<const D: usize>(
    s: &mut Stepper<'_, D>,
    state: &State,
) -> Result<(), RunError> {
    let grid = s.body.grid;
    let (nc, nn) = (grid.num_cells(), grid.num_nodes());
    s.u = state.f64s_len("continuum/u", D * nn)?.to_vec();
    s.stress = state
        .f64s_len("continuum/stress", D * D * nc)?
        .chunks_exact(D * D)
        .map(Tensor::<D>::from_column_slice)
        .collect();
    if s.pressure.is_some() {
        s.pressure = Some(state.f64s_len("continuum/pressure", nc)?.to_vec());
    }
    // The failures.
    let cells = indices(state, "continuum/failures/cells", nc)?;
    let times = state.f64s_len("continuum/failures/times", cells.len())?;
    let modes = state.u8s("continuum/failures/modes")?;
    if modes.len() != cells.len() {
        return Err(bad(format!(
            "array `continuum/failures/modes` has {} values, want {}",
            modes.len(),
            cells.len()
        )));
    }
    let log = cells
        .iter()
        .zip(times)
        .zip(modes)
        .map(|((&cell, &time), &m)| {
            let mode = match m {
                0 => FailureMode::Tensile,
                1 => FailureMode::Shear,
                m => return Err(bad(format!("failure mode {m} is not 0 or 1"))),
            };
            Ok(Failure { cell, time, mode })
        })
        .collect::<Result<Vec<_>, _>>()?;
    s.failures = FailureState::from_log(nc, log).map_err(bad)?;
    // The crack tracking.
    let tracking = match &mut s.driver {
        Driver::Static { resolution, .. } => resolution.tracking_mut(),
        Driver::Coupled { frac, .. } => frac.resolution_mut().tracking_mut(),
    };
    if let Some(t) = tracking {
        let cells = indices(state, "continuum/tracking/cells", nc)?;
        let normals = points::<D>(state.f64s_len("continuum/tracking/normals", D * cells.len())?);
        let pts = points::<D>(state.f64s_len("continuum/tracking/points", D * cells.len())?);
        t.restore(&cells, &normals, &pts).map_err(bad)?;
    }
    if let Some(csv) = s.fracture_csv.as_mut() {
        csv.restore(state.str("continuum/fracture_csv")?.to_string());
    }
    let c = state.u64s_len("continuum/counts", 6)?;
    let count = |i: usize| usize::try_from(c[i]).map_err(|_| bad("count out of range".into()));
    s.logged = count(0)?.min(s.failures.count());
    s.done = count(1)?.min(s.times.len().saturating_sub(1));
    s.stress_stale = c[2] != 0;
    s.stats.iterations = count(3)?;
    s.stats.factorizations = count(4)?;
    s.stats.low_rank_updates = count(5)?;
    s.stats.max_relative_residual = state.f64("continuum/residual")?;
    // Factorizations from here on add to the saved count.
    s.count_base = s.stats.factorizations;
    if let Driver::Coupled { frac, state: biot } = &mut s.driver {
        if state.f64s("continuum/void").is_ok() {
            frac.resume_void(state.f64s_len("continuum/void", nc)?)
                .map_err(|e| bad(e.to_string()))?;
        }
        if let Ok(fronts) = state.f64s("continuum/tip_fronts") {
            frac.resume_tip_fronts(fronts)
                .map_err(|e| bad(e.to_string()))?;
        }
        if state.f64s("continuum/biot/u").is_ok() {
            *biot = Some(BiotState {
                displacement: state.f64s_len("continuum/biot/u", D * nn)?.to_vec(),
                pressure: state.f64s_len("continuum/biot/p", nc)?.to_vec(),
            });
        }
        let n = state.f64s_len("continuum/scheme/numbers", 3)?;
        let forward = if state.f64s("continuum/scheme/forward").is_ok() {
            Some((
                state.f64s("continuum/scheme/forward_rhs")?.to_vec(),
                state.f64s("continuum/scheme/forward")?.to_vec(),
            ))
        } else {
            None
        };
        let memory = SchemeMemory {
            factored: state.f64s("continuum/scheme/factored")?.to_vec(),
            current: state.f64s("continuum/scheme/current")?.to_vec(),
            stiffness: state.f64s("continuum/scheme/stiffness")?.to_vec(),
            dt: (!n[0].is_nan()).then_some(n[0]),
            scale: n[1],
            columns: indices(state, "continuum/scheme/columns", usize::MAX)?,
            forward,
            residual: n[2],
            updates: usize::try_from(state.u64("continuum/scheme/updates")?)
                .map_err(|_| bad("count out of range".into()))?,
        };
        frac.resume(s.failures.clone(), memory)
            .map_err(|e| bad(format!("the coupled state: {e}")))?;
    }
    Ok(())
}
