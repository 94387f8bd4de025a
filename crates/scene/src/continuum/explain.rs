//! What an error of the solvers means for the scene: a singular system, a solution that
//! is not finite or failures that do not settle are reported against the keys of the
//! scene that cause them (the boundary conditions, the loads, the materials), each with
//! its line; a stop request inside a step becomes [`RunError::Interrupted`].

use porofrac_sim::{BiotError, FractureError, SimError};

use crate::common::bounds::MAX_STRESS;
use crate::common::loaded::{LoadedScene, k, ki};
use crate::common::model::RunError;
use crate::common::sections::{KeyPart, key_text};

/// `key (line n)` for a key path of the scene.
fn at(ls: &LoadedScene, path: &[KeyPart]) -> String {
    format!("{} (line {})", key_text(path), ls.error(path, "").line)
}

/// The keys that load the body: the conditions and values of every `[[bc]]`, `[loads]`,
/// `initial.pressure`, sources and wells, each with its line.
pub(crate) fn load_keys(ls: &LoadedScene) -> Vec<String> {
    let s = &ls.scene;
    let mut keys = Vec::new();
    for (i, bc) in s.bc.iter().enumerate() {
        for (f, set) in [
            ("displacement", bc.displacement.is_some()),
            ("traction", bc.traction.is_some()),
            ("pressure", bc.pressure.is_some()),
            ("flux", bc.flux.is_some()),
        ] {
            if set {
                keys.push(at(ls, &ki("bc", i, &[f])));
            }
        }
        if bc.platen.is_some() {
            keys.push(at(ls, &ki("bc", i, &["platen", "force"])));
        }
    }
    if let Some(l) = &s.loads {
        if l.gravity.is_some() {
            keys.push(at(ls, &k(&["loads", "gravity"])));
        }
        if l.body_force.is_some() {
            keys.push(at(ls, &k(&["loads", "body_force"])));
        }
    }
    if s.initial.as_ref().is_some_and(|i| i.pressure.is_some()) {
        keys.push(at(ls, &k(&["initial", "pressure"])));
    }
    for i in 0..s.source.len() {
        keys.push(at(ls, &ki("source", i, &["rate"])));
    }
    for i in 0..s.well.len() {
        keys.push(at(ls, &ki("well", i, &[])));
    }
    keys
}

/// The moduli of every material, each with its line.
fn material_keys(ls: &LoadedScene) -> Vec<String> {
    ls.scene
        .material
        .keys()
        .map(|name| at(ls, &k(&["material", name, "youngs_modulus"])))
        .collect()
}

/// The `[[bc]]` keys that hold the body (displacements and platens), each with its line.
fn support_keys(ls: &LoadedScene) -> Vec<String> {
    let s = &ls.scene;
    let mut keys = Vec::new();
    for (i, bc) in s.bc.iter().enumerate() {
        if bc.displacement.is_some() {
            keys.push(at(ls, &ki("bc", i, &["displacement"])));
        }
        if bc.platen.is_some() {
            keys.push(at(ls, &ki("bc", i, &["platen"])));
        }
    }
    keys
}

fn list(keys: &[String]) -> String {
    if keys.is_empty() {
        "none in the scene".into()
    } else {
        keys.join(", ")
    }
}

/// What kind of failure a solver error is.
enum Kind {
    Interrupted,
    Singular,
    NotFinite,
    NotSettled { failed: usize },
    ActiveSet,
    Conditions,
    Other,
}

fn kind_of_sim(e: &SimError) -> Kind {
    match e {
        SimError::NotPositiveDefinite { .. } => Kind::Singular,
        SimError::Singular { .. } | SimError::Conflict { .. } => Kind::Conditions,
        SimError::NotFinite { .. } => Kind::NotFinite,
        SimError::LinearAlgebra(m) | SimError::Iterative(m) => kind_of_text(m),
        _ => Kind::Other,
    }
}

/// Errors of the sparse solvers reach here as text (`LDLᵀ …: ZeroPivot`).
fn kind_of_text(m: &str) -> Kind {
    let l = m.to_lowercase();
    if l.contains("pivot") || l.contains("positive definite") || l.contains("singular") {
        Kind::Singular
    } else if l.contains("not finite") || l.contains("non-finite") {
        Kind::NotFinite
    } else {
        Kind::Other
    }
}

fn kind_of_biot(e: &BiotError) -> Kind {
    match e {
        BiotError::Interrupted => Kind::Interrupted,
        BiotError::Mechanics(s) => kind_of_sim(s),
        BiotError::Solver(m) => kind_of_text(m),
        _ => kind_of_text(&e.to_string()),
    }
}

fn kind_of(e: &RunError) -> Kind {
    match e {
        RunError::Interrupted => Kind::Interrupted,
        RunError::Sim(s) => kind_of_sim(s),
        RunError::Biot(b) => kind_of_biot(b),
        RunError::Coupled(f) => match f {
            FractureError::Interrupted => Kind::Interrupted,
            FractureError::Biot(b) => kind_of_biot(b),
            FractureError::Mechanics(s) => kind_of_sim(s),
            FractureError::NotSettled { failed, .. } => Kind::NotSettled { failed: *failed },
            FractureError::ActiveSet { .. } => Kind::ActiveSet,
            _ => Kind::Other,
        },
        RunError::Fracture(m) if m.starts_with("failures did not settle") => {
            Kind::NotSettled { failed: 0 }
        }
        RunError::Flow(m) => kind_of_text(m),
        _ => Kind::Other,
    }
}

/// `e` in the user's terms (see the module docs); `cells` is the number of cells of the
/// grid (for failures that take most of it).
pub(crate) fn explain(ls: &LoadedScene, cells: usize, e: RunError) -> RunError {
    match kind_of(&e) {
        Kind::Interrupted => RunError::Interrupted,
        Kind::Singular => ls
            .error(
                &k(&["bc"]),
                format!(
                    "— the system has no unique solution ({e}): a part of the grid is not held \
                     by the displacement or platen conditions, or a material has (almost) no \
                     stiffness. Look at the conditions that hold the body: {}; and at the \
                     moduli: {}",
                    list(&support_keys(ls)),
                    list(&material_keys(ls))
                ),
            )
            .into(),
        Kind::NotFinite => overflow(ls, &e.to_string()),
        Kind::NotSettled { failed } if 2 * failed > cells && cells > 0 => ls
            .error(
                &k(&["bc"]),
                format!(
                    "— {e}: {failed} of {cells} cells failed, the loads exceed the strength of \
                     the rock almost everywhere. Look at the loads: {}; and at the strengths \
                     (tensile_strength, cohesion) of the materials",
                    list(&load_keys(ls))
                ),
            )
            .into(),
        Kind::Conditions => ls.error(&k(&["bc"]), format!("— {e}")).into(),
        Kind::ActiveSet => ls
            .error(
                &k(&["bc"]),
                format!(
                    "— {e}: the fractured cells open and close without settling, most often \
                     under loads far beyond the strength of the rock. Look at the loads: {}",
                    list(&load_keys(ls))
                ),
            )
            .into(),
        _ => e,
    }
}

/// The error of a state that is not finite: `what` says which value (the solver's
/// message, or the field and where); the loads and moduli of the scene are named.
pub(crate) fn overflow(ls: &LoadedScene, what: &str) -> RunError {
    ls.error(
        &k(&["bc"]),
        format!(
            "— the solution overflowed ({what}): the loads are too large for the moduli of the \
             scene (or an expression of a load is not finite somewhere). Look at the loads: \
             {}; and at the moduli: {}",
            list(&load_keys(ls)),
            list(&material_keys(ls))
        ),
    )
    .into()
}

/// `Err` naming the loads and moduli when a displacement or pressure of the state at `t`
/// is not finite, or a stress component is beyond [`MAX_STRESS`].
pub(crate) fn check_state<const D: usize>(
    ls: &LoadedScene,
    t: f64,
    u: &[f64],
    pressure: Option<&[f64]>,
    stress: &[porofrac_law::Tensor<D>],
) -> Result<(), RunError> {
    let axes = ["x", "y", "z"];
    if let Some(i) = u.iter().position(|v| !v.is_finite()) {
        let what = format!(
            "the displacement {} of node {} is {} at t = {t:e} s",
            axes[i % D],
            i / D,
            u[i]
        );
        return Err(overflow(ls, &what));
    }
    if let Some(p) = pressure
        && let Some(c) = p.iter().position(|v| !v.is_finite())
    {
        let what = format!("the pressure of cell {c} is {} at t = {t:e} s", p[c]);
        return Err(overflow(ls, &what));
    }
    if let Some(c) = stress
        .iter()
        .position(|s| s.iter().any(|v| !v.is_finite() || v.abs() > MAX_STRESS))
    {
        let v = stress[c].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let what = format!(
            "a stress component of cell {c} is {v:e} Pa at t = {t:e} s, beyond {MAX_STRESS:e} Pa \
             where its invariants overflow"
        );
        return Err(overflow(ls, &what));
    }
    Ok(())
}

/// An error of the boundary conditions (two conditions that prescribe different values
/// at a node, rigid-body motion left free) at the `[[bc]]` of the scene; others as they
/// are.
pub(crate) fn conditions(ls: &LoadedScene, e: SimError) -> RunError {
    match e {
        SimError::Conflict { .. } | SimError::Singular { .. } => {
            ls.error(&k(&["bc"]), format!("— {e}")).into()
        }
        e => e.into(),
    }
}
