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
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
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
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Plane {
    /// Plane strain (`ε_zz = 0`), the default.
    #[default]
    Strain,
    /// Plane stress (`σ_zz = 0`): `λ* = 2λμ/(λ + 2μ)`.
    Stress,
}

/// `[grid] kind`.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
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
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
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
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum InitialMechanics {
    /// Solve the mechanics at t = 0 before the schedule starts.
    #[default]
    Equilibrium,
    /// Start from rest: the loads switch on at t = 0+.
    Zero,
}

/// `[physics] coupling`.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
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
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum FailureStress {
    /// The cell law's stress.
    #[default]
    Cell,
    /// The cell average of the patch-recovered nodal stress.
    Recovered,
}

/// `[solver] mechanics`.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum MechanicsSolver {
    /// A static solve at every output time.
    #[default]
    Direct,
    /// Damped dynamic relaxation.
    Explicit,
}

/// `[solver] linear`.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
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
#[derive(Clone, Debug, Deserialize)]
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
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSection {
    /// Output goes to `out/<name>/` unless `--out` is given.
    pub name: String,
    /// 2 or 3.
    pub dim: i64,
    /// 2D only: plane strain (default) or plane stress.
    pub plane: Option<Plane>,
    /// The model: `"continuum"` (default); see docs/SCENE.md for the others.
    pub model: Option<String>,
}

/// `[grid]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSection {
    /// The generator or reader.
    pub kind: GridKind,
    /// Min and max corner.
    pub extent: Option<[Vec<f64>; 2]>,
    /// Cells per axis (one number for voronoi).
    pub cells: Option<CellCount>,
    /// Seed of random generators.
    pub seed: Option<u64>,
    /// Interior node jitter, fraction of the local cell size.
    pub perturb: Option<f64>,
    /// Mesh file for `kind = "file"`, relative to the scene file: `.vtu` (any VTK encoding:
    /// ASCII, base64, appended, zlib) or else Gmsh 4.1 `.msh` (ASCII or binary).
    pub path: Option<String>,
    /// Composite: centre of the refined zone.
    pub center: Option<Vec<f64>>,
    /// Composite: half-width of the refined zone (m).
    pub zone_half_width: Option<f64>,
    /// Composite: subdivisions per coarse cell in the zone.
    pub refine: Option<i64>,
    /// Composite: radius of the tagged well cells (m).
    pub well_radius: Option<f64>,
    /// Composite: name of the well tag (default `well`).
    pub well_tag: Option<String>,
    /// Round well: edge length on the well wall (m; default half the zone's spacing).
    pub well_size: Option<f64>,
    /// Composite: split of the fine squares.
    pub diagonals: Option<DiagonalsChoice>,
    /// Voronoi: Lloyd iterations.
    pub lloyd: Option<i64>,
    /// 3D files and decks: cells replaced by conforming tetrahedra (an MDEM zone), refined
    /// `refine` times; tagged `refined`.
    pub mdem_zone: Option<Select>,
    /// With `mdem_zone`: the well trajectory (points); zone cells whose centroid is
    /// within `well_radius` of it are tagged `well` (or `well_tag`).
    pub well_path: Option<Vec<Vec<f64>>>,
}

/// `cells = [nx, ny(, nz)]` or, for Voronoi, one number.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum CellCount {
    /// One number.
    One(i64),
    /// Per axis.
    PerAxis(Vec<i64>),
}

/// `[[region]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// Name (for `[[source]] region = ...`).
    pub name: String,
    /// Which cells (by centroid).
    pub select: Select,
    /// `vem | mdem | dem`.
    pub law: Option<String>,
    /// Name of a `[material.<name>]`.
    pub material: Option<String>,
}

/// A cell selection.
#[derive(Clone, Debug, Deserialize, PartialEq)]
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
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PathBall {
    /// The polyline's points.
    pub path: Vec<Vec<f64>>,
    /// Distance (m).
    pub radius: f64,
}

/// Centre and radius.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Ball {
    /// Centre.
    pub center: Vec<f64>,
    /// Radius (m).
    pub radius: f64,
}

/// Scalar or per-axis permeability.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum Permeability {
    /// Isotropic (m²).
    Scalar(f64),
    /// `[kx, ky(, kz)]` (m²).
    Diagonal(Vec<f64>),
}

/// `[material.<name>]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// E (Pa). Required by the continuum model; `model = "cosserat"` accepts
    /// `shear_modulus` instead (absent: NaN, refused by the checks).
    #[serde(default = "missing")]
    pub youngs_modulus: f64,
    /// ν.
    pub poisson_ratio: f64,
    /// ρ (kg/m³).
    pub density: Option<f64>,
    /// Biot α.
    pub biot_alpha: Option<f64>,
    /// φ.
    pub porosity: Option<f64>,
    /// k (m²).
    pub permeability: Option<Permeability>,
    /// K_s (Pa).
    pub solid_bulk_modulus: Option<f64>,
    /// Tensile strength (Pa).
    pub tensile_strength: Option<f64>,
    /// Fracture toughness `K_Ic` (Pa·√m): a crack-tip cell fails in tension only when its
    /// stress intensity reaches it too.
    pub fracture_toughness: Option<f64>,
    /// Mohr–Coulomb cohesion (Pa).
    pub cohesion: Option<f64>,
    /// Mohr–Coulomb friction angle (degrees).
    pub friction_angle: Option<f64>,
    /// `model = "cosserat"`: G (Pa).
    pub shear_modulus: Option<f64>,
    /// `model = "cosserat"`: Gc (Pa).
    pub cosserat_shear_modulus: Option<f64>,
    /// `model = "cosserat"`: ℓ (m).
    pub characteristic_length: Option<f64>,
    /// `model = "cosserat"`, 3D: `[L, M, Mc]` (N).
    pub couple_moduli: Option<Vec<f64>>,
    /// `model = "cosserat"`: j (m²).
    pub micro_inertia: Option<f64>,
}

fn missing() -> f64 {
    f64::NAN
}

/// `[fluid]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fluid {
    /// μ (Pa s).
    pub viscosity: f64,
    /// c_f (1/Pa).
    pub compressibility: f64,
}

/// `[[bc]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bc {
    /// A side `xmin … zmax` or a face tag.
    pub boundary: String,
    /// Per component: number, expression or `"free"`.
    pub displacement: Option<Vec<Component>>,
    /// Traction (Pa) per component.
    pub traction: Option<Vec<NumOrExpr>>,
    /// Flow Dirichlet pressure (Pa).
    pub pressure: Option<NumOrExpr>,
    /// Outward Darcy flux (m/s).
    pub flux: Option<NumOrExpr>,
    /// Rigid platen.
    pub platen: Option<Platen>,
    /// `model = "cosserat"`: micro-rotation (2D one value, 3D three; or `"free"`).
    pub rotation: Option<crate::common::rotation_keys::PerRotation>,
    /// `model = "cosserat"`: couple traction (N/m).
    pub couple_traction: Option<crate::common::rotation_keys::PerRotation>,
}

/// `platen = { force = [...] }`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Platen {
    /// Total force per component (N; per metre in 2D), or `"free"`.
    pub force: Vec<Component>,
}

/// `[loads]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Loads {
    /// Gravity (m/s²), uses the material density.
    pub gravity: Option<Vec<f64>>,
    /// Body force (N/m³) per component.
    pub body_force: Option<Vec<NumOrExpr>>,
    /// `model = "cosserat"`: body couple (N/m²).
    pub body_couple: Option<crate::common::rotation_keys::PerRotation>,
}

/// `[[source]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Source {
    /// Name of a `[[region]]`.
    pub region: String,
    /// m³/s over the region.
    pub rate: Option<f64>,
    /// The region's pore volume per hour.
    pub pore_volumes_per_hour: Option<f64>,
}

/// `[[well]]`: a Peaceman well in one cell, controlled by rate or bottom-hole pressure.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WellSection {
    /// Name (for messages).
    pub name: String,
    /// The point the well passes through (its cell is the well's cell).
    pub at: Option<Vec<f64>>,
    /// Or the index of the well's cell.
    pub cell: Option<i64>,
    /// Wellbore radius (m).
    pub radius: f64,
    /// Skin factor (default 0).
    pub skin: Option<f64>,
    /// Volumetric rate (m³/s; 2D: per metre), positive for injection.
    pub rate: Option<f64>,
    /// Or the bottom-hole pressure (Pa).
    pub bottom_hole_pressure: Option<f64>,
}

/// `[initial]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Initial {
    /// Initial pressure (Pa).
    pub pressure: Option<NumOrExpr>,
    /// Equilibrium (default) or rest at t = 0.
    pub mechanics: Option<InitialMechanics>,
}

/// `[schedule]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Schedule {
    /// End time (s).
    pub end_time: f64,
    /// Step (s).
    pub dt: Option<f64>,
    /// Or a number of steps.
    pub steps: Option<i64>,
}

/// `[physics]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Physics {
    /// Solve flow.
    pub flow: Option<bool>,
    /// The poroelastic coupling.
    pub coupling: Option<CouplingChoice>,
    /// Check failure criteria.
    pub fracture: Option<bool>,
    /// Stress the failure criteria see: the cell law's stress (default) or the
    /// patch-recovered nodal stress averaged over the cell.
    pub failure_stress: Option<FailureStress>,
    /// Isotropic permeability (m²) of failed cells with flow (default 1e-12).
    pub fracture_permeability: Option<f64>,
    /// Or the crack transmissivity (m³): a failed cell takes `T / (2 r_c)`.
    pub fracture_transmissivity: Option<f64>,
    /// `false`: no fluid lag, the intact cells bordering a crack take its permeability
    /// (default `true`: they keep the rock's).
    pub fluid_lag: Option<bool>,
    /// Residual stiffness ratio of open edges of failed cells (default 1e-6).
    pub open_edge_stiffness: Option<f64>,
    /// Crack tracking angle in degrees (absent: no tracking).
    pub crack_tracking: Option<f64>,
    /// Crack tracking: no new crack within this distance (m) of a failed cell (default 0).
    pub crack_exclusion: Option<f64>,
}

/// `[solver]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Solver {
    /// Static solves or damped dynamic relaxation.
    pub mechanics: Option<MechanicsSolver>,
    /// The linear solver.
    pub linear: Option<LinearChoice>,
    /// Relative residual / unbalanced-force ratio.
    pub tolerance: Option<f64>,
    /// Threads (0: default).
    pub threads: Option<i64>,
    /// `model = "cosserat"`: η of the interior penalty.
    pub penalty: Option<f64>,
    /// `model = "cosserat"`: time integrator with a `[schedule]`.
    pub time_integration: Option<crate::common::rotation_keys::TimeIntegration>,
}

/// `[output]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Write VTK files.
    #[serde(default = "yes")]
    pub vtk: bool,
    /// Write PNG plots.
    #[serde(default = "yes")]
    pub plots: bool,
    /// Write every n-th step (VTK, lines).
    #[serde(default = "one")]
    pub every: i64,
    /// Sample the probes into `probes.csv` every n-th step (and at every written step),
    /// independently of `every`; default 1: every step.
    #[serde(default = "one")]
    pub probe_every: i64,
    /// `[[output.probe]]`.
    #[serde(default)]
    pub probe: Vec<Probe>,
    /// `[[output.line]]`.
    #[serde(default)]
    pub line: Vec<Line>,
    /// An exact displacement (numbers or expressions in x, y, z, t): `summary.json` then
    /// reports the L2 error of the last written displacement against it.
    pub exact_displacement: Option<Vec<NumOrExpr>>,
}

impl Default for Output {
    fn default() -> Self {
        Self {
            vtk: true,
            plots: true,
            every: 1,
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
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Probe {
    /// Column name.
    pub name: String,
    /// Field name.
    pub field: String,
    /// Position (grid and lattice models).
    #[serde(default)]
    pub at: Vec<f64>,
    /// Particle index (particle models).
    pub particle: Option<i64>,
    /// Tracked cell (particle models).
    pub cell: Option<Ball>,
    /// Lattice Boltzmann: the obstacle whose force or torque is probed (instead of `at`).
    pub obstacle: Option<String>,
}

/// `[[output.line]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Line {
    /// File name (`lines/<name>.csv`).
    pub name: String,
    /// Field name.
    pub field: String,
    /// Start point.
    pub from: Vec<f64>,
    /// End point.
    pub to: Vec<f64>,
    /// Number of sample points.
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
