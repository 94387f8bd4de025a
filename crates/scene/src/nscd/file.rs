//! The sections of an NSCD scene (`[scene] model = "nscd"`), parsed strictly like the
//! rest of the file ([`crate::file`]).

use serde::Deserialize;

pub use crate::particles::{ParticleKind, ParticlesSection, RadiusSpec};

/// A velocity component of a wall: a number (m/s) or `"free"`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum WallComponent {
    /// Prescribed velocity (m/s).
    Velocity(f64),
    /// `"free"`: moved by the contacts and `force`.
    Word(String),
}

/// `[[wall]]`: a rigid segment or convex polygon translating at a prescribed velocity,
/// or free along an axis under a force.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallSection {
    /// Name (for messages).
    pub name: Option<String>,
    /// Segment start (m).
    pub from: Option<[f64; 2]>,
    /// Segment end (m).
    pub to: Option<[f64; 2]>,
    /// Or a convex polygon, counter-clockwise (m).
    pub polygon: Option<Vec<[f64; 2]>>,
    /// Velocity per component (m/s) or `"free"` (default `[0, 0]`).
    pub velocity: Option<[WallComponent; 2]>,
    /// Force along the free components (N per metre of thickness).
    pub force: Option<[f64; 2]>,
    /// Mass (kg per metre), needed with a free component.
    pub mass: Option<f64>,
}

/// `[contact]`: the law between disks, and between disks and walls.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSection {
    /// Coulomb friction coefficient (default 0).
    pub mu: Option<f64>,
    /// Static friction coefficient (default `mu`), used by contacts that stuck at the
    /// end of the previous step; `mu` is then the dynamic one.
    pub mu_static: Option<f64>,
    /// Cohesion γ (N per metre of thickness, default 0).
    pub cohesion: Option<f64>,
    /// Attraction distance d_w (m, default 0).
    pub d_w: Option<f64>,
}

/// `[nscd] ordering`.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
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
}

/// `[nscd]`: time stepping and NLGS.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NscdSection {
    /// θ in [0.5, 1] (default 0.5).
    pub theta: Option<f64>,
    /// W-weighted relative impulse change that ends the sweeps (default 1.666e-4).
    pub tolerance: Option<f64>,
    /// Fewest sweeps per step (default 100).
    pub min_sweeps: Option<i64>,
    /// Most sweeps per step (default 10 000).
    pub max_sweeps: Option<i64>,
    /// Alert distance of the detection (m, default half the smallest radius).
    pub alert: Option<f64>,
    /// Order of the contacts in a sweep.
    pub ordering: Option<OrderingChoice>,
    /// Seed of the random ordering (default 1).
    pub ordering_seed: Option<u64>,
    /// Gravity (m/s², default `[0, -9.81]`).
    pub gravity: Option<[f64; 2]>,
}
