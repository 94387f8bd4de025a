//! The sections of an NSCD scene (`[scene] model = "nscd"`), parsed strictly like the
//! rest of the file ([`crate::common::sections`]).

use serde::Deserialize;

pub use crate::common::particles::{ParticleKind, ParticlesSection, RadiusSpec};

/// A velocity component of a wall: a number (m/s) or `"free"`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(untagged)]
#[schemars(extend("expected" = "a velocity or \"free\""))]
pub enum WallComponent {
    /// Prescribed velocity (m/s).
    Velocity(f64),
    /// `"free"`: moved by the contacts and `force`.
    Word(String),
}

/// `[[wall]]`: a rigid segment or convex polygon translating at a prescribed velocity,
/// or free along an axis under a force.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WallSection {
    /// Name, unique among the walls: messages and wall probes
    /// (`[[output.probe]] wall = NAME`) use it.
    pub name: Option<String>,
    /// Segment start (m).
    #[schemars(extend("unit" = "m"))]
    pub from: Option<[f64; 2]>,
    /// Segment end (m).
    #[schemars(extend("unit" = "m"))]
    pub to: Option<[f64; 2]>,
    /// Or a convex polygon, counter-clockwise (m).
    #[schemars(extend("unit" = "m"))]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// Velocity per component (m/s) or `"free"` (default `[0, 0]`).
    #[schemars(extend("unit" = "m/s"))]
    pub velocity: Option<[WallComponent; 2]>,
    /// Force along the free components (N per metre of thickness).
    #[schemars(extend("unit" = "N/m"))]
    pub force: Option<[f64; 2]>,
    /// Mass (kg per metre), needed with a free component.
    #[schemars(extend("unit" = "kg/m"))]
    pub mass: Option<f64>,
    /// Coulomb friction coefficient of the contacts of disks with this wall, static and
    /// dynamic (default `[contact] mu` and `mu_static`): a base of its own roughness.
    pub mu: Option<f64>,
}

/// `[contact]`: the law between disks, and between disks and walls.
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactSection {
    /// Coulomb friction coefficient (default 0).
    pub mu: Option<f64>,
    /// Static friction coefficient (default `mu`), used by contacts that stuck at the
    /// end of the previous step; `mu` is then the dynamic one.
    pub mu_static: Option<f64>,
    /// Cohesion γ (N per metre of thickness, default 0).
    #[schemars(extend("unit" = "N/m"))]
    pub cohesion: Option<f64>,
    /// Attraction distance d_w (m, default 0).
    #[schemars(extend("unit" = "m"))]
    pub d_w: Option<f64>,
    /// Normal restitution coefficient e in [0, 1] of Newton's impact law (default 0):
    /// a contact that closes at relative normal velocity v_n⁻ < 0 leaves at −e v_n⁻
    /// (Moreau–Jean with Newton's law as in Siconos and LMGC90's `RST_CLB`; a contact
    /// is then active only once its predicted gap is ≤ 0). 0 keeps the gap-aware
    /// inelastic law (LMGC90's `IQS_CLB`). Not with `cohesion`.
    pub restitution: Option<f64>,
}

/// `[nscd] ordering`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum OrderingChoice {
    /// Contacts sorted by candidate then antagonist, every sweep.
    #[default]
    Sorted,
    /// A new random permutation every sweep (seed `ordering_seed`).
    Random,
    /// Colour groups of independent contacts swept in parallel (the same result for
    /// any number of threads).
    Coloured,
    /// One slab of disks per thread swept in parallel, then the contacts between slabs
    /// (the same result for a given number of threads).
    Slabs,
}

/// `[nscd]`: time stepping and NLGS.
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NscdSection {
    /// θ in [0.5, 1] (default 0.5). With θ < 1 a contact that closes at speed v_n
    /// keeps an overlap of at most h(1 − θ)v_n afterwards (h the step): contacts are
    /// detected at the predicted configuration q + h(1 − θ)q̇ and the step's positions
    /// use (1 − θ) of the arrival velocity, so θ = ½ leaves up to h v_n / 2 (1.5 mm for
    /// a head-on impact closing at 3 m/s with h = 1 ms), θ = 1 none. Such overlaps are
    /// permanent (the law pushes nothing apart) but do not grow.
    pub theta: Option<f64>,
    /// W-weighted relative impulse change that ends the sweeps (default 1.666e-4).
    pub tolerance: Option<f64>,
    /// Fewest NLGS sweeps of a step with contacts, always done (default 100): the
    /// paper's "minimal number of iterations". Then the sweeps stop on `tolerance` or
    /// on a sweep that changes nothing.
    pub min_sweeps: Option<i64>,
    /// Most sweeps per step (default 10 000).
    pub max_sweeps: Option<i64>,
    /// Alert distance of the detection (m, default half the smallest radius).
    #[schemars(extend("unit" = "m"))]
    pub alert: Option<f64>,
    /// Order of the contacts in a sweep.
    pub ordering: Option<OrderingChoice>,
    /// Seed of the random ordering (default 1).
    pub ordering_seed: Option<u64>,
    /// Gravity (m/s², default `[0, -9.81]`).
    #[schemars(extend("unit" = "m/s²"))]
    pub gravity: Option<[f64; 2]>,
    /// Gravity settling before the loading: stop when the kinetic energy is below this
    /// fraction of the potential energy released (1e-6 is a typical
    /// value; the criterion is this project's choice). No settling when
    /// absent.
    pub settle_ratio: Option<f64>,
    /// Most settling steps (default 20 000); reaching it is an error.
    pub settle_max_steps: Option<i64>,
    /// Settling step (s, default the schedule's `dt`).
    #[schemars(extend("unit" = "s"))]
    pub settle_dt: Option<f64>,
    /// `[nscd.fault]`: measures of a fault-propagation experiment in `summary.json`.
    pub fault: Option<FaultSection>,
}

/// `[nscd.fault]`: the basement fault of a fault-propagation experiment (Renouf et al.
/// (2006) §5.3), for the measures written to `summary.json` at the end of the run
/// ([`porofrac_particles::fault`]): the limit angle θ_l, the run-out, and the trishear L2
/// mismatch of the particle velocities.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FaultSection {
    /// The fault tip at t = 0 (the moving block's upper corner, m).
    #[schemars(extend("unit" = "m"))]
    pub tip: [f64; 2],
    /// Dip of the fault (degrees, in (0, 90)); the hanging wall moves up along it.
    #[schemars(extend("unit" = "degrees"))]
    pub dip: f64,
    /// Slip rate of the hanging wall along the fault (m/s).
    #[schemars(extend("unit" = "m/s"))]
    pub slip_rate: f64,
    /// The particles measured: current centres in `[[x0, y0], [x1, y1]]` (m).
    #[schemars(extend("unit" = "m"))]
    pub window: [[f64; 2]; 2],
    /// Particle velocities are averaged over this last part of the run (s, default 1).
    #[schemars(extend("unit" = "s"))]
    pub velocity_window: Option<f64>,
    /// Half apical angle of the analytic trishear zone (degrees); default: fitted.
    #[schemars(extend("unit" = "degrees"))]
    pub half_apex: Option<f64>,
    /// Band height of the limit-angle measure (m, default 4 × the largest radius).
    #[schemars(extend("unit" = "m"))]
    pub band: Option<f64>,
    /// Fraction f of the slip that bounds the fault area (default 0.2): its left limit
    /// is the contour |u| = (1 − f) s (rigid motion with the hanging wall on its left),
    /// its right limit |u| = f s (undeformed on its right); in (0, 0.5).
    pub limit_fraction: Option<f64>,
}

/// The sections of model `nscd` read by the model itself: `[[wall]]`, `[contact]`,
/// `[nscd]` (`[particles]` is shared with model `lsm`).
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
pub struct NscdSections {
    /// `[[wall]]`: rigid bodies.
    #[serde(default)]
    pub wall: Vec<WallSection>,
    /// `[contact]`: the contact law.
    pub contact: Option<ContactSection>,
    /// `[nscd]`: the solver.
    pub nscd: Option<NscdSection>,
}
