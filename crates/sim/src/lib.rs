//! porofrac-sim: mechanics assembly, boundary conditions and the static direct solve.
//!
//! The pieces, in the order a static solve uses them:
//!
//! 1. [`bc`]: displacement conditions, rigid platens, tractions, body force and gravity,
//!    with values that may depend on position and time ([`ScalarField`]).
//! 2. [`dofs::DofMap`]: dof → equation map; prescribed dofs are eliminated, platen nodes
//!    share equations; conflicting conditions and free rigid-body modes are errors.
//! 3. [`pattern::Pattern`]: the sparsity pattern of the reduced stiffness (upper triangle,
//!    CSC), built once, with per-cell scatter maps for a parallel, race-free fill.
//! 4. [`assembly`]: reduced stiffness and internal forces from the cell laws
//!    ([`porofrac_law::CellLaw`], chosen per cell by a [`LawMap`]), and the nodal loads.
//! 5. [`solve`]: sparse Cholesky with the symbolic factorization reused
//!    ([`DirectSolver`]), [`solve_static`], cell stresses and reaction forces;
//!    [`linear`]: the choice of linear solver ([`LinearSolver`]: Cholesky, CG with
//!    algebraic multigrid, or automatic by size).
//!
//! State that changes (displacements, time) is passed explicitly; the types above are
//! built once per grid and set of conditions.
//!
//! [`particle_fluid`] couples a particle model (any [`particle_fluid::ParticleSolver`]:
//! the lattice solid model, or free rigid disks) with the lattice Boltzmann fluid and heat
//! of `porofrac-lbm` (seed 002, §002.6): disks rasterised as moving obstacles every fluid
//! step, momentum-exchange loads in SI, particles sub-cycled, injection by a mass source,
//! heat books.
//!
//! ```no_run
//! # use porofrac_sim::*;
//! # fn run(grid: &porofrac_grid::Grid<2>, law: &dyn porofrac_law::CellLaw<2>) -> Result<()> {
//! let bottom = Displacement {
//!     name: "ymin".into(),
//!     faces: grid.boundary("ymin")?,
//!     components: [Some(0.0.into()), Some(0.0.into())],
//! };
//! let dofs = DofMap::new(grid, &[bottom], &[])?;
//! let pattern = Pattern::new(grid, &dofs)?;
//! let laws = LawMap::uniform(grid, law)?;
//! let loads = Loads::default();
//! let mut solver = DirectSolver::new(&pattern)?;
//! let problem = StaticProblem { grid, laws: &laws, dofs: &dofs, pattern: &pattern, loads: &loads };
//! let sol = solve_static(&problem, &mut solver, 0.0, &StaticOptions::default())?;
//! let stress = cell_stresses(grid, &laws, &sol.displacement)?;
//! # Ok(()) }
//! ```

pub mod assembly;
pub mod bc;
pub mod biot;
pub mod dofs;
pub mod error;
pub mod explicit;
pub mod field;
pub mod fracturing;
pub mod heap;
pub mod laws;
pub mod ldlt;
pub mod ldlt_single;
pub mod linear;
mod lowrank;
pub mod ordering;
pub mod particle_fluid;
pub mod pattern;
mod quadrature;
pub mod solve;
pub mod standard;
mod stress_cache;

pub use assembly::{assemble, nodal_loads};
pub use bc::{Displacement, Gravity, Loads, Platen, Traction};
pub use biot::{
    BiotCoupling, BiotError, BiotState, BiotStep, BiotSystem, CouplingStats, ExplicitPressure,
    FixedStress, Linearization, Monolithic, drained_bulk_modulus,
};
pub use dofs::DofMap;
pub use error::{Result, SimError};
pub use explicit::{ExplicitOptions, ExplicitSolution, ExplicitState, solve_explicit};
pub use field::{FieldFn, ScalarField, VectorField, VectorFn};
pub use fracturing::{
    Body, FailureResolution, FractureError, FractureFlow, FractureLaws, FracturePermeability,
    FractureSettings, FractureStep, Fracturing, ResolutionError, Resolved, Scheme, StressMeasure,
};
pub use laws::LawMap;
pub use linear::{
    AmgSolver, LinearSolve, LinearSolver, LinearStats, StaticSolver, elasticity_amg_options,
};
pub use pattern::Pattern;
pub use solve::{
    DirectSolver, PARALLEL_MIN_FACTOR_NNZ, Par, StaticOptions, StaticProblem, StaticSolution,
    cell_stresses, default_parallelism, reaction, solve_static,
};
