//! Types of the scene keys of `model = "cosserat"` that live in the shared sections
//! (`[[bc]] rotation`, `couple_traction`, `[loads] body_couple`, `[solver]
//! time_integration`, `stencil`).

use serde::Deserialize;

use crate::common::sections::NumOrExpr;

/// One value per rotation component: a single value in 2D, three in 3D.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(untagged)]
#[schemars(extend("expected" = "one value in 2D or three in 3D, each a number, an expression or \"free\", e.g. 0 or [0, 0, \"free\"]"))]
pub enum PerRotation {
    /// One value (2D).
    One(NumOrExpr),
    /// Three values (3D).
    Many(Vec<NumOrExpr>),
}

impl PerRotation {
    /// The values in order.
    pub fn values(&self) -> Vec<&NumOrExpr> {
        match self {
            Self::One(v) => vec![v],
            Self::Many(v) => v.iter().collect(),
        }
    }
}

/// `[solver] stencil`: how the cells of each facet value are chosen (docs/models/cosserat.md,
/// "Which stencil").
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Stencil {
    /// Interior facets: the first subset of the two cells and their neighbours, nearest
    /// first, with all weights below 1; boundary facets in 2D: the subset with the
    /// smallest largest weight (3D: as `"first-interpolating"`).
    #[default]
    SmallestBoundaryWeight,
    /// The seed's rule: the first subset with all weights below 1 on every facet.
    FirstInterpolating,
    /// The paper's wider pool (graph distance 2) and the smallest largest weight on every
    /// facet.
    SmallestWeight,
}

/// `[solver] time_integration` with a `[schedule]`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum TimeIntegration {
    /// Newmark average acceleration (implicit).
    #[default]
    Newmark,
    /// Explicit leapfrog with sub-steps below the computed stable step.
    Explicit,
}
