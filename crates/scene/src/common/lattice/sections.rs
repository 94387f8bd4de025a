//! The typed sections of a lattice Boltzmann scene: `[lbm]`, `[[lbm.boundary]]`,
//! `[[obstacle]]` and `[thermal]` (see the README, "Lattice Boltzmann fluid").

use serde::Deserialize;

use crate::common::sections::NumOrExpr;

/// `[lbm]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LbmSection {
    /// Min and max corner (m).
    #[schemars(extend("unit" = "m"))]
    pub extent: [Vec<f64>; 2],
    /// Lattice spacing Δx (m).
    #[schemars(extend("unit" = "m"))]
    pub spacing: f64,
    /// Fluid density (kg/m³).
    #[schemars(extend("unit" = "kg/m³"))]
    pub density: f64,
    /// Kinematic viscosity (m²/s).
    #[schemars(extend("unit" = "m²/s"))]
    pub viscosity: f64,
    /// Relaxation time; with spacing and viscosity it fixes Δt.
    pub tau: f64,
    /// Collision operator.
    #[serde(default)]
    pub collision: CollisionChoice,
    /// TRT magic parameter (default 3/16).
    pub magic: Option<f64>,
    /// Floating-point type of the populations: "double" (default) or "single" (`f32`
    /// storage of `f − w`, collision and boundaries in `f64`: half the memory and the bytes
    /// a step moves; the cost on Poiseuille and Couette flow is a relative L2 error of
    /// 1e-6 to 1e-5, see docs/BENCHMARKS.md). The temperature lattice stays `f64`.
    #[serde(default)]
    pub precision: PrecisionChoice,
    /// Axes that wrap around.
    #[serde(default)]
    pub periodic: Vec<AxisChoice>,
    /// Body acceleration on the fluid (m/s²).
    #[schemars(extend("unit" = "m/s²"))]
    pub body_force: Option<Vec<f64>>,
    /// Initial velocity (m/s), numbers or expressions in x, y (default at rest).
    #[schemars(extend("unit" = "m/s"))]
    pub initial_velocity: Option<Vec<NumOrExpr>>,
    /// How the force on obstacles is summed from the cut links.
    #[serde(default)]
    pub momentum_exchange: ExchangeChoice,
    /// `[[lbm.boundary]]`: the sides that are not periodic.
    #[serde(default)]
    pub boundary: Vec<LbmBoundary>,
}

/// `[lbm] collision`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum CollisionChoice {
    /// Single relaxation time.
    #[default]
    Bgk,
    /// Two relaxation times.
    Trt,
}

/// `[lbm] precision`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum PrecisionChoice {
    /// `f64` populations.
    #[default]
    Double,
    /// `f32` populations (zero-centred: `f − w` is stored; collision in `f64`).
    Single,
}

/// An axis.
#[derive(Clone, Copy, Debug, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum AxisChoice {
    /// x.
    X,
    /// y.
    Y,
}

/// `[lbm] momentum_exchange`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum ExchangeChoice {
    /// `c_α [f̃_α + f_ᾱ]` (Mora et al. (2015) eq. 8).
    #[default]
    Standard,
    /// With relative velocities `c − u_w` (Wen et al. 2014).
    GalileanInvariant,
}

/// A side of the box.
#[derive(Clone, Copy, Debug, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum SideChoice {
    /// x = min.
    Xmin,
    /// x = max.
    Xmax,
    /// y = min.
    Ymin,
    /// y = max.
    Ymax,
}

impl SideChoice {
    /// The word of the scene file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Xmin => "xmin",
            Self::Xmax => "xmax",
            Self::Ymin => "ymin",
            Self::Ymax => "ymax",
        }
    }
}

/// `[[lbm.boundary]] kind`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum BoundaryKindChoice {
    /// No-slip wall halfway between nodes (moving with `velocity`).
    #[default]
    Wall,
    /// Velocity inlet.
    Velocity,
    /// Pressure outlet.
    Pressure,
}

/// `[[lbm.boundary]]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LbmBoundary {
    /// Which side.
    pub side: SideChoice,
    /// What it is.
    #[serde(default)]
    pub kind: BoundaryKindChoice,
    /// Wall or inlet velocity (m/s), numbers or expressions in x, y, t.
    #[schemars(extend("unit" = "m/s"))]
    pub velocity: Option<Vec<NumOrExpr>>,
    /// Outlet gauge pressure (Pa).
    #[schemars(extend("unit" = "Pa"))]
    pub pressure: Option<f64>,
}

/// `[[obstacle]]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSection {
    /// Name (for obstacle probes).
    pub name: String,
    /// Shape and position (m). It may overhang a side that is not periodic (clipped to the
    /// lattice: the force is that on the part inside) and lie across a periodic one; it may
    /// not overlap another obstacle.
    pub shape: ShapeChoice,
    /// Prescribed velocity of the centre (m/s), numbers or expressions in t.
    #[schemars(extend("unit" = "m/s"))]
    pub velocity: Option<Vec<NumOrExpr>>,
    /// Prescribed angular velocity (rad/s), number or expression in t.
    #[schemars(extend("unit" = "rad/s"))]
    pub angular_velocity: Option<NumOrExpr>,
}

/// `shape = { circle = {...} }` or `{ box = [[x0, y0], [x1, y1]] }`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum ShapeChoice {
    /// A disk.
    Circle(CircleShape),
    /// An axis-aligned rectangle.
    Box([Vec<f64>; 2]),
}

/// Centre and radius of a disk.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CircleShape {
    /// Centre (m).
    #[schemars(extend("unit" = "m"))]
    pub center: Vec<f64>,
    /// Radius (m).
    #[schemars(extend("unit" = "m"))]
    pub radius: f64,
}

/// `[thermal]` (parsed so that its keys are known; not available in this version).
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ThermalSection {
    /// Diffusivity in the fluid (m²/s).
    #[schemars(extend("unit" = "m²/s"))]
    pub diffusivity: f64,
    /// Diffusivity inside obstacles (m²/s).
    #[schemars(extend("unit" = "m²/s"))]
    pub solid_diffusivity: Option<f64>,
    /// Initial temperature.
    #[schemars(extend("unit" = "°C"))]
    pub initial: Option<NumOrExpr>,
    /// `[[thermal.boundary]]`.
    #[serde(default)]
    pub boundary: Vec<ThermalBoundary>,
    /// Initial temperature of the particles (model `lsm`; default `initial` at their
    /// centres).
    #[schemars(extend("unit" = "°C", "models" = ["lsm"]))]
    pub particle_temperature: Option<f64>,
    /// Heat capacity per volume ρ c_p of fluid and particles (grains), J/(m³·K), for the
    /// heat books (default 4.18e6).
    #[schemars(extend("unit" = "J/(m³·K)", "models" = ["lsm", "lbm"]))]
    pub heat_capacity: Option<f64>,
    /// Keep the heat books of every lattice step: `heat_books.csv` (one row per step:
    /// the fluid's stored heat before and after, conduction in, advection in and out
    /// through the sides, what the solid nodes gave, the defect) and summary `heat_books`
    /// (model `lbm`, serial runs; default false).
    #[schemars(extend("models" = ["lbm"]))]
    pub books: Option<bool>,
}

/// `[[thermal.boundary]]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ThermalBoundary {
    /// Which side.
    pub side: SideChoice,
    /// Fixed temperature.
    #[schemars(extend("unit" = "°C"))]
    pub temperature: Option<f64>,
    /// Fixed flux.
    #[schemars(extend("unit" = "K·m/s"))]
    pub flux: Option<f64>,
    /// Zero-gradient outflow (advected heat leaves, nothing is reflected).
    #[serde(default)]
    pub outflow: bool,
}
