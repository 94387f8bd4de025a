//! The scene file: typed TOML sections of docs/SCENE.md, and the locations of keys for error
//! messages.
//!
//! Parsing is strict: unknown keys, wrong types and choices that are not one of the
//! listed words are errors that name the file, line and key; values are checked in
//! [`crate::common::loaded`]. Every choice is an enum here, so nothing downstream compares
//! strings.

use std::collections::BTreeMap;

use serde::Deserialize;

/// A number, or a string expression in x, y, z (m) and t (s).
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(untagged)]
#[schemars(extend("expected" = "a number or an expression in x, y, z, t, e.g. 1e6 or \"1e6*min(t/60, 1)\""))]
pub enum NumOrExpr {
    /// A constant.
    Num(f64),
    /// An expression (see [`crate::common::expr`]).
    Expr(String),
}

impl NumOrExpr {
    /// The value as a field of position and time (expressions compiled once; a constant
    /// expression becomes a constant). Checked scenes only: an expression that does not
    /// parse here would have been refused by [`crate::common::loaded`], and gives NaN.
    pub fn to_field(&self) -> porofrac_grid::ScalarField {
        use porofrac_grid::ScalarField;
        match self {
            Self::Num(x) => ScalarField::Const(*x),
            Self::Expr(s) => match crate::common::expr::Expr::parse(s) {
                Ok(e) => match e.as_constant() {
                    Some(c) => ScalarField::Const(c),
                    None => ScalarField::from_fn(move |x, t| e.eval(x, t)),
                },
                Err(_) => ScalarField::Const(f64::NAN),
            },
        }
    }

    /// A component that may be `"free"`: `None` for free, else [`NumOrExpr::to_field`].
    pub fn to_component(&self) -> Option<porofrac_grid::ScalarField> {
        match self {
            Self::Expr(s) if s == "free" => None,
            v => Some(v.to_field()),
        }
    }
}

/// The components of a vector given as numbers or expressions (body force, exact
/// displacement) as one field: the expressions are compiled together
/// ([`crate::common::expr::Program`]), so subexpressions the components share are evaluated once.
pub fn vector_field<const D: usize>(values: &[NumOrExpr]) -> porofrac_sim::VectorField<D> {
    use crate::common::expr::{Expr, Program};
    use porofrac_sim::VectorField;
    if values
        .iter()
        .all(|v| matches!(v.to_field(), porofrac_grid::ScalarField::Const(_)))
    {
        return VectorField::Components(std::array::from_fn(|a| values[a].to_field()));
    }
    let exprs: Vec<Expr> = values
        .iter()
        .map(|v| match v {
            NumOrExpr::Num(x) => Expr::constant(*x),
            NumOrExpr::Expr(s) => Expr::parse(s).unwrap_or_else(|_| Expr::constant(f64::NAN)),
        })
        .collect();
    let program = Program::new(&exprs.iter().collect::<Vec<_>>());
    VectorField::from_batch_fn(move |xs, t, out| program.eval_points(xs, t, out.as_flattened_mut()))
}

/// One component of a displacement condition: a number, an expression, or `"free"`.
pub type Component = NumOrExpr;

/// `[scene] plane`: the 2D idealization.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Plane {
    /// Plane strain (`ε_zz = 0`), the default.
    #[default]
    Strain,
    /// Plane stress (`σ_zz = 0`): `λ* = 2λμ/(λ + 2μ)`.
    Stress,
}

/// `[grid] kind`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum GridKind {
    /// Axis-aligned boxes.
    #[default]
    Cartesian,
    /// Boxes split into two triangles (2D).
    Triangles,
    /// Boxes split into six tetrahedra (3D).
    Tetrahedra,
    /// A centroidal Voronoi grid (2D).
    Voronoi,
    /// A Gmsh or VTK file.
    File,
    /// A far field with a refined simplex zone around a well.
    Composite,
    /// A far field with a zone of graded triangles around a round well.
    RoundWell,
}

impl GridKind {
    /// The word of the scene file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Cartesian => "cartesian",
            Self::Triangles => "triangles",
            Self::Tetrahedra => "tetrahedra",
            Self::Voronoi => "voronoi",
            Self::File => "file",
            Self::Composite => "composite",
            Self::RoundWell => "round-well",
        }
    }
}

/// `[grid] diagonals` of composite grids.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum DiagonalsChoice {
    /// All fine squares split along the same diagonal.
    #[default]
    Structured,
    /// A checkerboard of diagonals.
    Alternating,
    /// Each square cut into 4 triangles by its centre (`model = "cosserat"`).
    Crossed,
}

/// `[initial] mechanics`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum InitialMechanics {
    /// Solve the mechanics at t = 0 before the schedule starts.
    #[default]
    Equilibrium,
    /// Start from rest: the loads switch on at t = 0+.
    Zero,
}

/// `[physics] coupling`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum CouplingChoice {
    /// Fully implicit (Nilsen et al. (2017) eq. 30).
    #[default]
    Monolithic,
    /// Fixed-stress split.
    FixedStress,
    /// The explicit-pressure update of Nilsen et al. (2017) §2.5.
    ExplicitPressure,
    /// Flow on a fixed skeleton.
    None,
}

/// `[physics] failure_stress`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum FailureStress {
    /// The cell law's stress.
    #[default]
    Cell,
    /// The cell average of the patch-recovered nodal stress.
    Recovered,
}

/// `[physics] crack_flow`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum CrackFlow {
    /// One permeability for every failed cell, whatever its opening
    /// (`fracture_permeability` or `fracture_transmissivity`).
    #[default]
    Fixed,
    /// The cubic law `w³/12μ` from the crack's own opening `w`, measured in every failed
    /// cell from the displacements at the start of each step; `fracture_transmissivity`
    /// is the floor of a closed crack.
    #[serde(alias = "cubic_law")]
    CubicLaw,
}

/// `[physics] tip_rule`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum TipRuleChoice {
    /// The tip cell's own stress: `σ₁ √(2π r_c) > K_Ic` and `σ₁ > σ_t`.
    #[default]
    Stress,
    /// The opening behind the tip (displacement correlation,
    /// `K_I = E′ w / (4 √(2/π) √r)`): the tip cell fails when `K_I > K_Ic`.
    Opening,
    /// The opening behind the tip read with the tip asymptote of a fluid-driven crack
    /// (toughness `√r`, viscosity `r^{2/3}` at the front's speed): the tip cell fails when
    /// the front lies beyond the tip.
    Asymptote,
}

/// `[solver] mechanics`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum MechanicsSolver {
    /// A static solve at every output time.
    #[default]
    Direct,
    /// Damped dynamic relaxation.
    Explicit,
}

/// `[solver] linear`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum LinearChoice {
    /// By dimension and size (measured in docs/BENCHMARKS.md).
    #[default]
    Auto,
    /// Sparse Cholesky.
    Cholesky,
    /// CG preconditioned by smoothed-aggregation AMG.
    CgAmg,
    /// Sparse LU with partial pivoting (model `cosserat`).
    Lu,
    /// Restarted GMRES preconditioned by smoothed-aggregation AMG (model `cosserat`).
    GmresAmg,
}

/// The top-level sections of [`SceneFile`]: those every model may read, and those two
/// models share. Every other top-level section belongs to one model, which reads it
/// ([`crate::common::model::ModelKind::sections_of`]).
pub const SHARED_SECTIONS: [&str; 17] = [
    "scene",
    "grid",
    "region",
    "material",
    "fluid",
    "bc",
    "loads",
    "source",
    "well",
    "initial",
    "schedule",
    "physics",
    "solver",
    "output",
    "particles",
    "lbm",
    "thermal",
];

/// The sections of a scene file that every model may read or two models share
/// ([`SHARED_SECTIONS`]).
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// `[scene]`.
    pub scene: SceneSection,
    /// `[grid]` (required by the continuum model, [`crate::common::loaded`]; other models have
    /// none).
    #[serde(default)]
    pub grid: GridSection,
    /// `[[region]]`: later regions override earlier ones.
    #[serde(default)]
    pub region: Vec<Region>,
    /// `[material.<name>]`.
    #[serde(default)]
    pub material: BTreeMap<String, Material>,
    /// `[fluid]`.
    pub fluid: Option<Fluid>,
    /// `[[bc]]`.
    #[serde(default)]
    pub bc: Vec<Bc>,
    /// `[loads]`.
    pub loads: Option<Loads>,
    /// `[[source]]`.
    #[serde(default)]
    pub source: Vec<Source>,
    /// `[[well]]`: Peaceman wells.
    #[serde(default)]
    pub well: Vec<WellSection>,
    /// `[initial]`.
    pub initial: Option<Initial>,
    /// `[schedule]`: absent means one static solve.
    pub schedule: Option<Schedule>,
    /// `[physics]`.
    #[serde(default)]
    pub physics: Physics,
    /// `[solver]`.
    #[serde(default)]
    pub solver: Solver,
    /// `[output]`.
    #[serde(default)]
    pub output: Output,
    /// `[particles]` (models `nscd` and `lsm`).
    pub particles: Option<crate::common::particles::ParticlesSection>,
    /// `[lbm]` (lattice Boltzmann model).
    pub lbm: Option<crate::common::lattice::sections::LbmSection>,
    /// `[thermal]` (lattice Boltzmann model).
    pub thermal: Option<crate::common::lattice::sections::ThermalSection>,
}

/// `[scene]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSection {
    /// Output goes to `out/<name>/` unless `--out` is given.
    pub name: String,
    /// 2 or 3 (the particle and lattice models: 2 only).
    pub dim: i64,
    /// 2D only: plane strain (default) or plane stress.
    pub plane: Option<Plane>,
    /// The model (default `"continuum"`): `"continuum"`, `"cosserat"`, `"nscd"`, `"lsm"`
    /// or `"lbm"` (docs/models/).
    pub model: Option<String>,
}

/// `[grid]`.
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GridSection {
    /// The generator or reader.
    pub kind: GridKind,
    /// Min and max corner (default the unit box).
    #[schemars(extend("unit" = "m"))]
    pub extent: Option<[Vec<f64>; 2]>,
    /// Cells per axis; `voronoi`: one number (exactly that many cells). With `dim = 3`,
    /// `composite` and `round-well` extrude the 2D grid over `cells[2]` layers.
    pub cells: Option<CellCount>,
    /// Seed of random generators: voronoi, perturb (default 0).
    pub seed: Option<u64>,
    /// Interior nodes move by up to this fraction of their shortest edge, < 0.5; boundary
    /// nodes stay (default 0).
    pub perturb: Option<f64>,
    /// `file`: the mesh, relative to the scene file: `.vtu` (any VTK XML encoding: ASCII,
    /// base64, appended, zlib), `.grdecl`/`.data` (an Eclipse corner-point deck, 3D), else
    /// Gmsh 4.1 `.msh` (ASCII or binary).
    pub path: Option<String>,
    /// Composite, round-well: centre of the refined zone (3D: x, y of the vertical well).
    #[schemars(extend("unit" = "m"))]
    pub center: Option<Vec<f64>>,
    /// Composite, round-well: half-width of the square zone, snapped to whole coarse cells.
    #[schemars(extend("unit" = "m"))]
    pub zone_half_width: Option<f64>,
    /// Composite: fine squares per coarse edge (each split in 2 triangles); round-well:
    /// interface nodes per coarse edge (triangle size `h / refine`); file or deck with
    /// `mdem_zone`: refinement levels 0–3.
    pub refine: Option<i64>,
    /// Cells whose centroid is within it get the tag `well` (or `well_tag`); round-well:
    /// radius of the circular well.
    #[schemars(extend("unit" = "m"))]
    pub well_radius: Option<f64>,
    /// Name of the tag of the well cells (default `"well"`).
    pub well_tag: Option<String>,
    /// Round well: edge length on the well wall; the well has `n = max(32, 4⌈2πR / (4
    /// well_size)⌉)` nodes (default half the zone's triangle size).
    #[schemars(extend("unit" = "m"))]
    pub well_size: Option<f64>,
    /// Composite: the split of the fine squares; Cosserat triangles: `"crossed"` (default
    /// `"structured"`).
    pub diagonals: Option<DiagonalsChoice>,
    /// Voronoi: Lloyd iterations (default 3).
    pub lloyd: Option<i64>,
    /// 3D file or deck: cells replaced by conforming tetrahedra (an MDEM zone, tagged
    /// `refined`), refined `refine` times.
    pub mdem_zone: Option<Select>,
    /// With `mdem_zone`: the well trajectory (points); zone cells whose centroid is within
    /// `well_radius` of it are tagged `well` (or `well_tag`).
    #[schemars(extend("unit" = "m"))]
    pub well_path: Option<Vec<Vec<f64>>>,
}

/// `cells = [nx, ny(, nz)]` or, for Voronoi, one number.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(untagged)]
#[schemars(extend("expected" = "a number of cells per axis, e.g. [40, 20] (voronoi: one number)"))]
pub enum CellCount {
    /// One number.
    One(i64),
    /// Per axis.
    PerAxis(Vec<i64>),
}

/// `[[region]]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// Name (for `[[source]] region`).
    pub name: String,
    /// Which cells, by centroid. Later regions override earlier ones for the cells they
    /// select; the first region must give both `law` and `material`, later ones may give
    /// one of them.
    pub select: Select,
    /// `"vem"`, `"mdem"`, `"dem"` or a registered law; model `cosserat`: `"cosserat-dem"`.
    pub law: Option<String>,
    /// Name of a `[material.<name>]`.
    pub material: Option<String>,
}

/// A cell selection.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Select {
    /// `{ all = true }`.
    All(bool),
    /// `{ box = [[x0, y0], [x1, y1]] }`.
    Box([Vec<f64>; 2]),
    /// `{ circle = { center = [x, y], radius = r } }`.
    Circle(Ball),
    /// `{ sphere = { center = [x, y, z], radius = r } }`.
    Sphere(Ball),
    /// `{ tag = "name" }`.
    Tag(String),
    /// `{ ijk = [[i0, i1], [j0, j1], [k0, k1]] }`: cells of a corner-point deck by their
    /// 1-based indices, ranges inclusive (Eclipse's `BOX`).
    Ijk([[u64; 2]; 3]),
    /// `{ around = { path = [[x, y, z], …], radius = r } }`: cells whose centroid lies
    /// within `r` of a polyline (a well trajectory).
    Around(PathBall),
}

/// A polyline and a distance.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PathBall {
    /// The polyline's points.
    #[schemars(extend("unit" = "m"))]
    pub path: Vec<Vec<f64>>,
    /// Distance (m).
    #[schemars(extend("unit" = "m"))]
    pub radius: f64,
}

/// Centre and radius.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Ball {
    /// Centre.
    #[schemars(extend("unit" = "m"))]
    pub center: Vec<f64>,
    /// Radius (m).
    #[schemars(extend("unit" = "m"))]
    pub radius: f64,
}

/// Scalar or per-axis permeability.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(untagged)]
#[schemars(extend("expected" = "a permeability or one per axis, e.g. 1e-15 or [1e-15, 1e-16]"))]
pub enum Permeability {
    /// Isotropic (m²).
    Scalar(f64),
    /// `[kx, ky(, kz)]` (m²).
    Diagonal(Vec<f64>),
}

/// `[material.<name>]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// E (required by the continuum model; `model = "cosserat"` accepts `shear_modulus`
    /// instead).
    #[serde(default = "missing")]
    #[schemars(extend("unit" = "Pa"))]
    pub youngs_modulus: f64,
    /// ν in (−1, 0.5).
    pub poisson_ratio: f64,
    /// ρ; needed by explicit mechanics and `[loads] gravity`.
    #[schemars(extend("unit" = "kg/m³"))]
    pub density: Option<f64>,
    /// Biot α in [0, 1] (default 1).
    pub biot_alpha: Option<f64>,
    /// φ in (0, 1]; required with flow (default on a corner-point deck: `PORO × NTG ×
    /// MULTPV`).
    pub porosity: Option<f64>,
    /// Isotropic k or `[kx, ky(, kz)]`; required with flow (default on a corner-point deck:
    /// `[PERMX·NTG, PERMY·NTG, PERMZ]`).
    #[schemars(extend("unit" = "m²"))]
    pub permeability: Option<Permeability>,
    /// K_s of the grains, the same for all materials (default incompressible grains).
    #[schemars(extend("unit" = "Pa"))]
    pub solid_bulk_modulus: Option<f64>,
    /// σ_t of the tensile criterion (Nilsen et al. eq. 31; default never fails in tension).
    #[schemars(extend("unit" = "Pa"))]
    pub tensile_strength: Option<f64>,
    /// K_Ic: a crack-tip cell fails in tension only when also `σ₁ √(2π r_c) ≥ K_Ic` (needs
    /// `tensile_strength`).
    #[schemars(extend("unit" = "Pa·√m"))]
    pub fracture_toughness: Option<f64>,
    /// Mohr–Coulomb cohesion (with `friction_angle`).
    #[schemars(extend("unit" = "Pa"))]
    pub cohesion: Option<f64>,
    /// Mohr–Coulomb friction angle in [0, 90).
    #[schemars(extend("unit" = "degrees"))]
    pub friction_angle: Option<f64>,
    /// Cosserat: G (instead of E).
    #[schemars(extend("unit" = "Pa", "models" = ["cosserat"]))]
    pub shear_modulus: Option<f64>,
    /// Cosserat: Gc ≥ 0 (0 is classical elasticity).
    #[schemars(extend("unit" = "Pa", "models" = ["cosserat"]))]
    pub cosserat_shear_modulus: Option<f64>,
    /// Cosserat: ℓ (2D: `m_3j = 4Gℓ² ∂_jφ`; 3D: `L = 0, M = Mc = 2Gℓ²`).
    #[schemars(extend("unit" = "m", "models" = ["cosserat"]))]
    pub characteristic_length: Option<f64>,
    /// Cosserat 3D: `[L, M, Mc]`, instead of `characteristic_length`.
    #[schemars(extend("unit" = "N", "models" = ["cosserat"]))]
    pub couple_moduli: Option<Vec<f64>>,
    /// Cosserat dynamics: j.
    #[schemars(extend("unit" = "m²", "models" = ["cosserat"]))]
    pub micro_inertia: Option<f64>,
}

fn missing() -> f64 {
    f64::NAN
}

/// `[fluid]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Fluid {
    /// μ (`[fluid]` is required with flow).
    #[schemars(extend("unit" = "Pa·s"))]
    pub viscosity: f64,
    /// c_f.
    #[schemars(extend("unit" = "1/Pa"))]
    pub compressibility: f64,
}

/// `[[bc]]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Bc {
    /// A side `xmin xmax ymin ymax zmin zmax` (of the bounding box; `zmin zmax` in 3D only)
    /// or a face tag.
    pub boundary: String,
    /// Prescribed displacement per component; `"free"` leaves a component (which may then
    /// carry `traction`).
    #[schemars(extend("unit" = "m"))]
    pub displacement: Option<Vec<Component>>,
    /// Traction on the boundary faces, per component.
    #[schemars(extend("unit" = "Pa"))]
    pub traction: Option<Vec<NumOrExpr>>,
    /// Flow: Dirichlet pressure. A boundary with neither `pressure` nor `flux` is no-flow.
    #[schemars(extend("unit" = "Pa"))]
    pub pressure: Option<NumOrExpr>,
    /// Flow: outward Darcy flux (Neumann); not with `pressure`.
    #[schemars(extend("unit" = "m/s"))]
    pub flux: Option<NumOrExpr>,
    /// A rigid platen: the boundary's nodes share one displacement per loaded component,
    /// the total force applied to it; not with `displacement` or `traction`.
    pub platen: Option<Platen>,
    /// Cosserat: micro-rotation (2D one value, 3D three; or `"free"`), imposed by Nitsche
    /// terms; a component may not be both prescribed and loaded.
    #[schemars(extend("unit" = "rad", "models" = ["cosserat"]))]
    pub rotation: Option<crate::common::rotation_keys::PerRotation>,
    /// Cosserat: couple traction (2D one value, 3D three).
    #[schemars(extend("unit" = "N/m", "models" = ["cosserat"]))]
    pub couple_traction: Option<crate::common::rotation_keys::PerRotation>,
}

/// `platen = { force = [...] }`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Platen {
    /// Total force per component (2D: per metre), or `"free"`.
    #[schemars(extend("unit" = "N"))]
    pub force: Vec<Component>,
}

/// `[loads]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Loads {
    /// Body force ρ g with the material density.
    #[schemars(extend("unit" = "m/s²"))]
    pub gravity: Option<Vec<f64>>,
    /// Body force per component (manufactured solutions use it).
    #[schemars(extend("unit" = "N/m³"))]
    pub body_force: Option<Vec<NumOrExpr>>,
    /// Cosserat: body couple (2D one value, 3D three).
    #[schemars(extend("unit" = "N/m²", "models" = ["cosserat"]))]
    pub body_couple: Option<crate::common::rotation_keys::PerRotation>,
}

/// `[[source]]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Source {
    /// Name of a `[[region]]`: fluid is injected (positive) or produced in its cells.
    pub region: String,
    /// Total rate over the region (2D: per metre).
    #[schemars(extend("unit" = "m³/s"))]
    pub rate: Option<f64>,
    /// Or the region's pore volume per hour; exactly one of `rate` and
    /// `pore_volumes_per_hour`.
    #[schemars(extend("unit" = "1/h"))]
    pub pore_volumes_per_hour: Option<f64>,
}

/// `[[well]]`: a Peaceman well in one cell, controlled by rate or bottom-hole pressure.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WellSection {
    /// Name (for messages).
    pub name: String,
    /// The well's cell is the one containing this point; or
    #[schemars(extend("unit" = "m"))]
    pub at: Option<Vec<f64>>,
    /// the cell index; exactly one of `at` and `cell`.
    pub cell: Option<i64>,
    /// Wellbore radius (m).
    #[schemars(extend("unit" = "m"))]
    pub radius: f64,
    /// Skin factor (default 0).
    pub skin: Option<f64>,
    /// Injection (positive) rate (2D: per metre); or
    #[schemars(extend("unit" = "m³/s"))]
    pub rate: Option<f64>,
    /// the bottom-hole pressure; exactly one of `rate` and `bottom_hole_pressure`.
    #[schemars(extend("unit" = "Pa"))]
    pub bottom_hole_pressure: Option<f64>,
}

/// `[initial]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Initial {
    /// Initial pore pressure p₀; the coupling acts on `p − p₀` (default 0).
    #[schemars(extend("unit" = "Pa"))]
    pub pressure: Option<NumOrExpr>,
    /// `"equilibrium"`: the loads act on the skeleton at t = 0 with p = p₀; `"zero"`: start
    /// from rest, loads on at t = 0+ (default `"equilibrium"`).
    pub mechanics: Option<InitialMechanics>,
}

/// `[schedule]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Schedule {
    /// End of the run. Without `[schedule]` a continuum or Cosserat scene is one static
    /// solve at t = 0; a schedule has at most 1e7 steps.
    #[schemars(extend("unit" = "s"))]
    pub end_time: f64,
    /// Step; exactly one of `dt` and `steps`.
    #[schemars(extend("unit" = "s"))]
    pub dt: Option<f64>,
    /// Number of steps, instead of `dt`.
    pub steps: Option<i64>,
}

/// `[physics]`.
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Physics {
    /// Solve TPFA flow (default `false`).
    pub flow: Option<bool>,
    /// The poroelastic coupling (default `"monolithic"`).
    pub coupling: Option<CouplingChoice>,
    /// Check failure criteria after every solve (default `false`). Within a step the most
    /// critical violating cells (within 1 % of the largest utilization) fail and the step
    /// is solved again until none fails.
    pub fracture: Option<bool>,
    /// Stress the failure criteria see (default `"cell"`).
    pub failure_stress: Option<FailureStress>,
    /// Isotropic permeability of failed cells with flow (default 1e-12).
    #[schemars(extend("unit" = "m²"))]
    pub fracture_permeability: Option<f64>,
    /// Instead: a failed cell takes `T / (2 r_c)` (`r_c`: radius of the disk or ball of the
    /// cell's size).
    #[schemars(extend("unit" = "m³"))]
    pub fracture_transmissivity: Option<f64>,
    /// `false`: no fluid lag, the intact cells bordering a crack take its permeability
    /// (default `true`: they keep the rock's).
    pub fluid_lag: Option<bool>,
    /// The crack's flow (default `"fixed"`): `"cubic-law"` gives a failed cell of aperture
    /// `w` (the displacement jump across it, docs/models/continuum.md) and thickness
    /// `h_n` across the opening the permeability `max(w³/12, T_min) / h_n`, so the crack
    /// conducts `w³/12μ` per unit height; `T_min` is `fracture_transmissivity` (default
    /// 1e-13 m³, a residual aperture of 0.11 mm). Needs fracture = true and flow = true.
    pub crack_flow: Option<CrackFlow>,
    /// Residual stiffness ratio of open edges of failed cells, in [0, 1) (default 1e-6).
    pub open_edge_stiffness: Option<f64>,
    /// A crack continues along its line, kinking at most this angle, in (0, 90] (default no
    /// tracking).
    #[schemars(extend("unit" = "degrees"))]
    pub crack_tracking: Option<f64>,
    /// With tracking: no new crack within this distance of a failed cell (default 0).
    #[schemars(extend("unit" = "m"))]
    pub crack_exclusion: Option<f64>,
    /// How a crack tip grows against `fracture_toughness` (default `"stress"`). `"stress"`:
    /// the tip cell's stress, `σ₁ √(2π r_c) > K_Ic` and `σ₁ > σ_t`. `"opening"`: the jump
    /// `w` of the displacement across the band of failed cells on the line of nodes one
    /// cell behind the tip, at the distance `r` from it, gives
    /// `K_I = E′ w / (4 √(2/π) √r)` with `E′ = E/(1 − ν²)` (plane stress: `E`); an intact
    /// cell next to a crack tip fails when `K_I > K_Ic`, whatever its tensile strength
    /// (which still governs cells away from tips). Meant for cracks along a row of split
    /// rectangles (a predefined path; docs/hydrofrac/validation.md, "KGD"). `"asymptote"`:
    /// the same opening `w` read with the tip asymptote of a fluid-driven crack moving at
    /// the speed `V`, `w³ = (K′/E′)³ r^{3/2} + 18√3 (μ′V/E′) r²` (`K′ = 4√(2/π) K_Ic`,
    /// `μ′ = 12 μ` of `[fluid] viscosity`), gives the front's distance `r` and, with its
    /// position at the start of the step, its speed; the tip cell fails when the front
    /// lies beyond the tip (the same as `"opening"` for a crack at rest; it converges for
    /// viscous cracks, where `"opening"` does not;
    /// docs/hydrofrac/validation.md, "KGD, viscosity-dominated"). Both need
    /// fracture = true, flow = true and failure_stress = "cell".
    pub tip_rule: Option<TipRuleChoice>,
    /// With tip_rule = "opening": read the opening at this distance behind the tip instead
    /// of one cell behind it, on a crack through any cells (a zig-zag band of triangles;
    /// the crack's line fitted through the failed cells' centroids, the opening fitted on
    /// the nodes of the band's two faces; docs/hydrofrac/validation.md, "A tip rule at a
    /// fixed distance"). A cell beside a crack is held. A crack shorter than this distance
    /// (a wing of a few cells at a wall) is read at a quarter of its length (at least one
    /// cell) with Sneddon's factor; one shorter than two cells fails by its tensile
    /// strength ("Short wings read at a quarter of their length"). Needs crack_tracking (every cell around a tip is read as
    /// ahead of it; tracking picks the one the crack enters). Default none: one cell
    /// behind the tip.
    #[schemars(extend("unit" = "m"))]
    pub tip_sample_distance: Option<f64>,
    /// The pore pressure of a cell never falls below this absolute pressure (the fluid's
    /// vapour pressure; default none: unbounded suction). A cell that opens faster than
    /// fluid reaches it (a crack tip ahead of the fluid) stays at it, and the volume it
    /// opens is a void that the fluid fills first when it arrives (docs/models/continuum.md,
    /// "Cavitation"). Needs flow = true.
    #[schemars(extend("unit" = "Pa"))]
    pub cavitation_pressure: Option<f64>,
}

/// `[solver]`.
#[derive(Clone, Debug, Default, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Solver {
    /// Continuum: a static solve at every step time, or damped dynamic relaxation (needs
    /// `density`) (default `"direct"`).
    pub mechanics: Option<MechanicsSolver>,
    /// The linear solver (default `"auto"`; docs/SCENE-GUIDE.md, `[solver]`, says what
    /// `"auto"` picks per model and size).
    pub linear: Option<LinearChoice>,
    /// Relative residual of iterative solves; unbalanced-force ratio of explicit relaxation
    /// (default 1e-8 for CG, 1e-10 for GMRES).
    pub tolerance: Option<f64>,
    /// 0: one thread per core; n in 1..=1024: a pool of n threads (default 0).
    pub threads: Option<i64>,
    /// Cosserat: η of the interior penalty (default 1).
    #[schemars(extend("models" = ["cosserat"]))]
    pub penalty: Option<f64>,
    /// Cosserat: how the cells of each facet value are chosen (default
    /// `"smallest-boundary-weight"`).
    #[schemars(extend("models" = ["cosserat"]))]
    pub stencil: Option<crate::common::rotation_keys::Stencil>,
    /// Cosserat with a `[schedule]` (default `"newmark"`).
    #[schemars(extend("models" = ["cosserat"]))]
    pub time_integration: Option<crate::common::rotation_keys::TimeIntegration>,
}

/// `[output]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Write VTK files under `vtk/` and `<name>.pvd`.
    #[serde(default = "yes")]
    pub vtk: bool,
    /// Write PNG plots under `plots/`.
    #[serde(default = "yes")]
    pub plots: bool,
    /// Write every n-th step (VTK, lines).
    #[serde(default = "one")]
    pub every: i64,
    /// Sample the probes into `probes.csv` every n-th step (and at every written step),
    /// independently of `every`; default 1: every step.
    #[serde(default = "one")]
    pub probe_every: i64,
    /// Write a checkpoint (`checkpoint/state.bin`, the state of the run for
    /// `porofrac run --resume`) every n-th step; 0 (default): none, but a run stopped by
    /// Ctrl-C between steps still writes one.
    #[serde(default)]
    pub checkpoint_every: u64,
    /// `[[output.probe]]`: one column of `probes.csv` (`time [s],<name [unit]>…`, one row
    /// per sampled step, the first at t = 0).
    #[serde(default)]
    pub probe: Vec<Probe>,
    /// `[[output.line]]`: a field sampled along a segment at every written step:
    /// `lines/<name>.csv` with `time [s],s [m],x [m],y [m][,z [m]],<field> [<unit>]`.
    #[serde(default)]
    pub line: Vec<Line>,
    /// Continuum: `summary.json` `errors.l2_displacement`, the L2 error of the last
    /// displacement (its P1 interpolant, degree-5 quadrature per cell; triangles or
    /// tetrahedra) against this displacement (numbers or expressions in x, y, z, t).
    #[schemars(extend("unit" = "m"))]
    pub exact_displacement: Option<Vec<NumOrExpr>>,
}

impl Default for Output {
    fn default() -> Self {
        Self {
            vtk: true,
            plots: true,
            every: 1,
            checkpoint_every: 0,
            probe_every: 1,
            probe: Vec::new(),
            line: Vec::new(),
            exact_displacement: None,
        }
    }
}

fn yes() -> bool {
    true
}
fn one() -> i64 {
    1
}

/// `[[output.probe]]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Probe {
    /// Column name.
    pub name: String,
    /// A field of the model (docs/SCENE-GUIDE.md lists them per model).
    pub field: String,
    /// Grid and lattice models: the point; fluid probes of `lsm` with `[lbm]`.
    #[serde(default)]
    #[schemars(extend("unit" = "m"))]
    pub at: Vec<f64>,
    /// Particle models: the particle's index.
    pub particle: Option<i64>,
    /// Particle models: a tracked cell (the particles whose centre is inside at t = 0).
    pub cell: Option<Ball>,
    /// Lattice Boltzmann: the obstacle whose force or torque is probed (instead of `at`).
    pub obstacle: Option<String>,
    /// The `[[wall]]` (by `name`) whose reaction `fx fy torque` is probed: the force
    /// it exerts on the disks (N/m) and its moment about the wall's centroid (N·m/m).
    /// Model lsm: `"top"` or `"bottom"` (a platen's force on the rest of the sample and
    /// its moment about the platen's mean centre), `"hole"` (the hole pressure's force on
    /// the lining and its moment about the hole centre).
    #[schemars(extend("models" = ["nscd", "lsm"]))]
    pub wall: Option<String>,
}

/// `[[output.line]]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Line {
    /// File name (`lines/<name>.csv`).
    pub name: String,
    /// A field of the model.
    pub field: String,
    /// Start point.
    #[schemars(extend("unit" = "m"))]
    pub from: Vec<f64>,
    /// End point.
    #[schemars(extend("unit" = "m"))]
    pub to: Vec<f64>,
    /// Number of sample points (at most 1e6).
    pub points: i64,
}

/// One step of a key path: a table key or an index into an array of tables.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum KeyPart {
    /// A key.
    Key(String),
    /// An index into an array of tables (`[[bc]]` number k, from 0).
    Index(usize),
}

/// Render a key path the way users write it: `material.rock.poisson_ratio`, `bc[2].traction`.
pub fn key_text(path: &[KeyPart]) -> String {
    let mut s = String::new();
    for p in path {
        match p {
            KeyPart::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                // A key is user text too: a long one is shortened like any echo.
                s.push_str(&crate::common::loaded::echo(k));
            }
            KeyPart::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// The 1-based line of a byte offset.
pub fn line_of_offset(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())]
        .bytes()
        .filter(|&b| b == b'\n')
        .count()
        + 1
}
