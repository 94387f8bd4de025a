//! The data of a flow problem: rock, fluid, boundary conditions, sources and wells.
//!
//! These are plain values; [`crate::FlowModel::new`] validates them against a grid and
//! returns an error naming the offending cell, face, condition, source or well.

use crate::perm::Permeability;

pub use porofrac_grid::field::{FieldFn, ScalarField};

/// Rock properties per cell.
///
/// Storage (specific storage coefficient, 1/Pa) of cell `K`:
/// `S_K = φ_K c_f + (α_K − φ_K) / K_s` (the storativity `S_c` of Nilsen et al. (2017) eq. 28b),
/// with the solid grain bulk modulus `K_s = ∞` by default, so `S_K = φ_K c_f`.
#[derive(Clone, Debug)]
pub struct Rock<const D: usize> {
    /// Porosity per cell, in (0, 1].
    pub porosity: Vec<f64>,
    /// Permeability per cell (m²).
    pub permeability: Permeability<D>,
    /// Biot–Willis coefficient α per cell, in [φ, 1] (default 1). It enters the flow model
    /// only through the storage term when `K_s` is finite.
    pub biot_alpha: Vec<f64>,
    /// Bulk modulus of the solid grains `K_s` (Pa), `f64::INFINITY` for incompressible grains.
    pub solid_bulk_modulus: f64,
}

impl<const D: usize> Rock<D> {
    /// Rock with the given porosity and permeability per cell, α = 1 and `K_s = ∞`.
    pub fn new(porosity: Vec<f64>, permeability: Permeability<D>) -> Self {
        let n = porosity.len();
        Self {
            porosity,
            permeability,
            biot_alpha: vec![1.0; n],
            solid_bulk_modulus: f64::INFINITY,
        }
    }
}

/// Fluid properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fluid {
    /// Dynamic viscosity μ (Pa·s), > 0.
    pub viscosity: f64,
    /// Fluid compressibility `c_f` (1/Pa), ≥ 0 (0: incompressible).
    pub compressibility: f64,
}

impl Fluid {
    /// Water at about 20 °C: μ = 1e-3 Pa·s, c_f = 4.4e-10 1/Pa.
    pub fn water() -> Self {
        Self {
            viscosity: 1e-3,
            compressibility: 4.4e-10,
        }
    }
}

/// The kind of a boundary condition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoundaryKind {
    /// Prescribed pressure (Dirichlet), Pa.
    Pressure,
    /// Prescribed outward Darcy flux `u·n` (Neumann), m/s; the volumetric outflow through a
    /// face is `u·n A_f`. Negative values inject.
    Flux,
}

impl BoundaryKind {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Self::Pressure => "pressure",
            Self::Flux => "flux",
        }
    }
}

/// A boundary condition on a set of boundary faces; faces without a condition are no-flow.
#[derive(Clone, Debug)]
pub struct BoundaryCondition {
    /// The boundary faces.
    pub faces: Vec<usize>,
    /// Pressure or flux.
    pub kind: BoundaryKind,
    /// The value, evaluated at the face centroid and at the end of the time step.
    pub value: ScalarField,
}

/// The rate of a volumetric source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SourceRate {
    /// A total rate (m³/s; m²/s per unit thickness in 2D), positive for injection.
    Total(f64),
    /// The cells' total pore volume `Σ φ_K |K|` per hour, positive for injection.
    PoreVolumesPerHour(f64),
}

/// A volumetric source on a set of cells, distributed in proportion to the cell volumes.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// A name for messages and results.
    pub name: String,
    /// The cells (non-empty).
    pub cells: Vec<usize>,
    /// The rate.
    pub rate: SourceRate,
}

/// How a well is controlled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WellControl {
    /// Bottom-hole pressure (Pa).
    Bhp(f64),
    /// Volumetric rate (m³/s; m²/s in 2D), positive for injection.
    Rate(f64),
}

/// A well in one cell with a Peaceman well index (see [`crate::well`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Well {
    /// A name for messages and results.
    pub name: String,
    /// The cell the well is in.
    pub cell: usize,
    /// Wellbore radius `r_w` (m), > 0.
    pub radius: f64,
    /// Skin factor `s` (dimensionless).
    pub skin: f64,
    /// Bottom-hole pressure or rate control.
    pub control: WellControl,
    /// A well index (m³) to use instead of Peaceman's.
    pub well_index: Option<f64>,
}

impl Well {
    /// A well without skin and with the Peaceman well index.
    pub fn new(name: impl Into<String>, cell: usize, radius: f64, control: WellControl) -> Self {
        Self {
            name: name.into(),
            cell,
            radius,
            skin: 0.0,
            control,
            well_index: None,
        }
    }
}

/// Everything a [`crate::FlowModel`] needs besides the grid.
#[derive(Clone, Debug)]
pub struct FlowProblem<const D: usize> {
    /// Rock properties.
    pub rock: Rock<D>,
    /// Fluid properties.
    pub fluid: Fluid,
    /// Boundary conditions; a face may appear in at most one.
    pub boundary_conditions: Vec<BoundaryCondition>,
    /// Volumetric sources.
    pub sources: Vec<Source>,
    /// Transmissibility multipliers of interior faces (faults): `(faces, m)`, applied in
    /// order; `m = 0` seals the faces.
    pub transmissibility_multipliers: Vec<(Vec<usize>, f64)>,
    /// Wells.
    pub wells: Vec<Well>,
}

impl<const D: usize> FlowProblem<D> {
    /// A problem with no-flow boundaries, no sources and no wells.
    pub fn new(rock: Rock<D>, fluid: Fluid) -> Self {
        Self {
            rock,
            fluid,
            boundary_conditions: Vec::new(),
            sources: Vec::new(),
            wells: Vec::new(),
            transmissibility_multipliers: Vec::new(),
        }
    }

    /// Multiply the transmissibility of the interior `faces` by `m ≥ 0` (a fault).
    pub fn transmissibility_multiplier(mut self, faces: Vec<usize>, m: f64) -> Self {
        self.transmissibility_multipliers.push((faces, m));
        self
    }

    /// Prescribe the pressure on `faces`.
    pub fn pressure_bc(mut self, faces: Vec<usize>, value: impl Into<ScalarField>) -> Self {
        self.boundary_conditions.push(BoundaryCondition {
            faces,
            kind: BoundaryKind::Pressure,
            value: value.into(),
        });
        self
    }

    /// Prescribe the outward Darcy flux `u·n` (m/s) on `faces`.
    pub fn flux_bc(mut self, faces: Vec<usize>, value: impl Into<ScalarField>) -> Self {
        self.boundary_conditions.push(BoundaryCondition {
            faces,
            kind: BoundaryKind::Flux,
            value: value.into(),
        });
        self
    }

    /// Add a source on `cells`.
    pub fn source(mut self, name: impl Into<String>, cells: Vec<usize>, rate: SourceRate) -> Self {
        self.sources.push(Source {
            name: name.into(),
            cells,
            rate,
        });
        self
    }

    /// Add a well.
    pub fn well(mut self, well: Well) -> Self {
        self.wells.push(well);
        self
    }
}
