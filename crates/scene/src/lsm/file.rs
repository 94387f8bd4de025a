//! The sections of a lattice solid scene (`[scene] model = "lsm"`), parsed strictly
//! like the rest of the file ([`crate::common::sections`]). `[particles]` is shared with the other
//! particle model ([`crate::common::particles`]).

use serde::Deserialize;

/// `[bonds]`: springs from `youngs_modulus` and `poisson_ratio` (hexagonal lattice
/// closed form, [`porofrac_lsm`]) or `kn`, `ks` directly; strengths; calibration.
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BondsSection {
    /// 2D Young's modulus E (Pa), with `poisson_ratio`.
    #[schemars(extend("unit" = "Pa"))]
    pub youngs_modulus: Option<f64>,
    /// Poisson's ratio ν ≤ 1/3.
    pub poisson_ratio: Option<f64>,
    /// Normal stiffness k_n (N/m²), instead of E and ν.
    #[schemars(extend("unit" = "N/m²"))]
    pub kn: Option<f64>,
    /// Shear stiffness k_s (N/m², default 0 with `kn`).
    #[schemars(extend("unit" = "N/m²"))]
    pub ks: Option<f64>,
    /// Bending stiffness k_b (N·m/m per rad, default 0).
    #[schemars(extend("unit" = "N·m/m per rad"))]
    pub kb: Option<f64>,
    /// Tensile strength σ_t (Pa): tension cut-off (default unbreakable).
    #[schemars(extend("unit" = "Pa"))]
    pub tensile_strength: Option<f64>,
    /// Cohesion c (Pa, default σ_t tan φ).
    #[schemars(extend("unit" = "Pa"))]
    pub cohesion: Option<f64>,
    /// Friction angle φ of the bond strength (degrees, default 30).
    #[schemars(extend("unit" = "degrees"))]
    pub friction_angle: Option<f64>,
    /// Disks closer than (R_i + R_j)(1 + tolerance) are bonded (default 0.05).
    pub tolerance: Option<f64>,
    /// Measure E, ν (uniaxial compression) and σ_t (Brazilian test) of the packing
    /// before the run, into `summary.json` `calibration` (default false).
    #[serde(default)]
    pub calibrate: bool,
}

/// `[contacts] normal`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum NormalChoice {
    /// `F = k_n δ`.
    #[default]
    Linear,
    /// Hertz, from `modulus` and `poisson_ratio`.
    Hertz,
}

/// `[contacts]`: unbonded and broken-bond contacts.
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactsSection {
    /// Coulomb friction μ (default 0.6).
    pub friction: Option<f64>,
    /// Normal law (default linear).
    #[serde(default)]
    pub normal: NormalChoice,
    /// Linear normal stiffness (N/m², default the bonds' k_n).
    #[schemars(extend("unit" = "N/m²"))]
    pub kn: Option<f64>,
    /// Tangential stiffness (N/m², default the bonds' k_s).
    #[schemars(extend("unit" = "N/m²"))]
    pub ks: Option<f64>,
    /// Hertz: grain Young's modulus (Pa).
    #[schemars(extend("unit" = "Pa"))]
    pub modulus: Option<f64>,
    /// Hertz: grain Poisson's ratio.
    pub poisson_ratio: Option<f64>,
}

/// `[lsm] damping`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum DampingChoice {
    /// None.
    #[default]
    None,
    /// Local (Cundall), α = `damping_coefficient` (default 0.7).
    Local,
    /// Viscous, rate = `damping_coefficient` (1/s, required).
    Viscous,
}

/// `[lsm]`: time stepping.
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LsmSection {
    /// Time step (s); default `dt_fraction` × the stable one. Above the stable one is an
    /// error.
    #[schemars(extend("unit" = "s"))]
    pub dt: Option<f64>,
    /// Time step as a fraction of the stable one (default 0.5).
    pub dt_fraction: Option<f64>,
    /// Damping (default none).
    #[serde(default)]
    pub damping: DampingChoice,
    /// α (local) or rate (viscous).
    pub damping_coefficient: Option<f64>,
    /// Gravity (m/s², default `[0, 0]`).
    #[schemars(extend("unit" = "m/s²"))]
    pub gravity: Option<[f64; 2]>,
    /// With `[lbm]`: the fluid sees every disk enlarged by the bond tolerance, so the
    /// gap of a bonded pair holds no fluid (default false).
    pub seal_bonds: Option<bool>,
}

/// `[loading] platens`: the particles within `thickness` of the top and of the bottom
/// of the sample move towards each other at `velocity`, until they stop (at
/// `stop_displacement` or `stop_time`) and then hold their place, or until their force
/// reaches `hold_force`, which a servo then holds.
#[derive(Clone, Copy, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlatensSpec {
    /// Speed of each platen (m/s).
    #[schemars(extend("unit" = "m/s"))]
    pub velocity: f64,
    /// Thickness of the platen layers (m).
    #[schemars(extend("unit" = "m"))]
    pub thickness: f64,
    /// Each platen stops when it has moved this far (m) and holds its place from then on
    /// (a displacement-controlled test held at a strain; default: never stops). The
    /// sub-step that reaches it moves the platen by what is left, so the platen stops
    /// exactly there.
    #[schemars(extend("unit" = "m"))]
    pub stop_displacement: Option<f64>,
    /// Or the platens stop at this time (s) and hold their place, having moved
    /// `velocity × stop_time`.
    #[schemars(extend("unit" = "s"))]
    pub stop_time: Option<f64>,
    /// Or the platens approach at `velocity` until the platen force (the `platen_force`
    /// probe: the mean of the two platens' loads, N/m, compressive positive) reaches
    /// this value, and a servo then holds it: each sub-step of `dt` both platens move
    /// at `(hold_force − F) / (k_est · 10 dt)`, at most `velocity` either way, with
    /// `k_est` the stiffness of the bonds and contacts touching the platens (stable
    /// for any sample; see docs/models/lsm.md). Not with a stop key nor with `[lbm]`.
    #[schemars(extend("unit" = "N/m"))]
    pub hold_force: Option<f64>,
}

impl PlatensSpec {
    /// How far each platen moves before it stops (m; infinite when it never stops).
    pub fn travel(&self) -> f64 {
        match (self.stop_displacement, self.stop_time) {
            (Some(d), _) => d,
            (None, Some(t)) => self.velocity * t,
            (None, None) => f64::INFINITY,
        }
    }
}

/// `[loading] wall`: which faces of the lining particles the hole pressure loads.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum WallChoice {
    /// The faces seen from the hole centre.
    #[default]
    Rays,
    /// The faces a fluid filling the hole wets (notches and connected pockets), bonded
    /// gaps sealed ([`porofrac_lsm::WallFaces::Wetted`]).
    Wetted,
}

/// `[loading]`.
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LoadingSection {
    /// Platens (a Brazilian or compression test).
    pub platens: Option<PlatensSpec>,
    /// Pressure on the wall of `[particles] hole` rising at this rate (Pa/s).
    #[schemars(extend("unit" = "Pa/s"))]
    pub pressure_rate: Option<f64>,
    /// Largest pressure, then held (Pa, default no limit).
    #[schemars(extend("unit" = "Pa"))]
    pub pressure_max: Option<f64>,
    /// Faces the pressure loads (default `"rays"`).
    #[serde(default)]
    pub wall: WallChoice,
    /// `wall = "wetted"`: raster spacing (m, default half the smallest radius, the
    /// lattice spacing a fluid would need).
    #[schemars(extend("unit" = "m"))]
    pub wall_spacing: Option<f64>,
    /// The hole pressure also acts in the broken bonds of the crack connected to the
    /// hole wall, `p · 2 min(R_i, R_j)` pushing their disks apart (a crack the fluid
    /// follows without lag, [`porofrac_lsm::CrackExtent::flood_loads`]; default false).
    #[serde(default)]
    pub flood_cracks: bool,
    /// The crack connected to the hole wall is traced through the pores it opens: the
    /// pores are the faces of the bond network (disk centres joined by bonds), a broken
    /// bond opens the two faces it separates, and the crack is the set of broken bonds
    /// reachable from the pore that holds the hole through opened faces; two broken
    /// bonds that share a disk but no face are not joined. For the breakdown event and
    /// for `flood_cracks` ([`porofrac_lsm::CrackExtent::across_pores`]; default false:
    /// broken bonds that share a disk are joined, the lining disks to the hole).
    #[serde(default)]
    pub crack_across_pores: bool,
}

/// The sections of model `lsm` read by the model itself (`[particles]` is shared with
/// model `nscd`, `[lbm]` and `[thermal]` with model `lbm`).
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
pub struct LsmSections {
    /// `[bonds]`.
    pub bonds: Option<BondsSection>,
    /// `[contacts]`.
    pub contacts: Option<ContactsSection>,
    /// `[lsm]`.
    pub lsm: Option<LsmSection>,
    /// `[loading]`.
    pub loading: Option<LoadingSection>,
    /// `[injection]` (with `[lbm]`).
    pub injection: Option<super::fluid::InjectionSection>,
}
