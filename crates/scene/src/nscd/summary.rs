//! The keys model `nscd` adds to `summary.json`, as types: the run writes them
//! ([`NscdSummary`]) and `porofrac keys --summary-schema` publishes their schema
//! ([`crate::common::model::ModelKind::summary_schema`]), so the two cannot drift apart.

use serde::Serialize;

/// The keys of `summary.json` that a run of model `nscd` adds to the common ones (all
/// of them once the model is built; none in the summary of a run that stopped before).
#[derive(Clone, Debug, Serialize, schemars::JsonSchema)]
pub struct NscdSummary {
    /// Number of disks.
    pub particles: usize,
    /// Contacts (disk pairs and disk–wall pairs within the alert distance, open or
    /// closed) per step, over the steps of the run.
    pub contacts: NscdContactCounts,
    /// NLGS sweeps per step, over the steps of the run.
    pub sweeps: NscdSweepCounts,
    /// Convergence measure e_k of the last sweep of the last step.
    pub final_residual: f64,
    /// Steps whose sweeps stopped at `max_sweeps` above the tolerance.
    pub not_converged_steps: usize,
    /// Local contact solves of the run (Σ over the steps of sweeps × contacts).
    pub contact_updates: u64,
    /// Local contact solves per second of NLGS wall time.
    pub contact_updates_per_second: f64,
    /// Wall time of the NLGS sweeps (s).
    pub nlgs_seconds: f64,
    /// The gravity settling before the loading (`null` without `[nscd] settle_ratio`).
    pub settling: Option<NscdSettling>,
    /// The measures of `[nscd.fault]` at the end of the run (`null` without it).
    pub fault: Option<serde_json::Value>,
}

/// Contact counts of a run of model `nscd`.
#[derive(Clone, Copy, Debug, Serialize, schemars::JsonSchema)]
pub struct NscdContactCounts {
    /// Contacts of the last step.
    pub last: usize,
    /// Mean over the steps of their contact counts (0 for a run without steps).
    pub mean: f64,
    /// Largest contact count of a step.
    pub max: usize,
}

/// Sweep counts of a run of model `nscd`. A step with contacts does at least
/// `[nscd] min_sweeps` sweeps; a step without contacts does none, so with such steps
/// the mean can be below `min_sweeps`.
#[derive(Clone, Copy, Debug, Serialize, schemars::JsonSchema)]
pub struct NscdSweepCounts {
    /// Mean over the steps of their sweeps (0 for a run without steps).
    pub mean: f64,
    /// Most sweeps of a step.
    pub max: usize,
    /// Sweeps of the run.
    pub total: usize,
}

/// The gravity settling of a run of model `nscd`.
#[derive(Clone, Copy, Debug, Serialize, schemars::JsonSchema)]
pub struct NscdSettling {
    /// Settling steps taken.
    pub steps: usize,
    /// Kinetic energy at the end of the settling (J per metre of thickness).
    pub kinetic_energy: f64,
    /// Potential energy released by the settling (J per metre of thickness).
    pub potential_energy_released: f64,
    /// NLGS sweeps of the settling.
    pub sweeps: usize,
    /// Wall time of the settling (s).
    pub seconds: f64,
}

impl NscdSummary {
    /// The keys as they go into `summary.json`.
    pub fn into_map(self) -> serde_json::Map<String, serde_json::Value> {
        match serde_json::to_value(self) {
            Ok(serde_json::Value::Object(m)) => m,
            _ => serde_json::Map::new(),
        }
    }
}
