//! porofrac-sim: the continuum model composed — mechanics assembly, boundary conditions,
//! the static and explicit solves, Biot coupling with the flow, fracturing.
//!
//! sim composes the continuum crates and adds only what needs them together: the cell
//! laws of `porofrac-law` (implemented by `porofrac-vem`, `porofrac-mdem`), the TPFA flow
//! of `porofrac-flow`, the failure criteria of `porofrac-frac`, and the solvers of
//! `porofrac-sparse` (sparse Cholesky, `LDLᵀ`, low-rank updates, orderings) and
//! `porofrac-amg` (CG with algebraic multigrid). It knows no particles or lattices: the
//! particle–fluid coupling is `porofrac-particle-fluid`, the Cosserat model
//! `porofrac-cosserat`. How the process manages its heap is the binary's business
//! (`porofrac-cli`), not this library's.
//!
//! The pieces, in the order a static solve uses them:
//!
//! 1. [`bc`]: displacement conditions, rigid platens, tractions, body force and gravity,
//!    with values that may depend on position and time ([`ScalarField`]).
//! 2. [`dofs::DofMap`]: dof → equation map; prescribed dofs are eliminated, platen nodes
//!    share equations; conflicting conditions and free rigid-body modes are errors.
//! 3. [`pattern::Pattern`]: the sparsity pattern of the reduced stiffness (upper triangle,
//!    CSC: a [`porofrac_sparse::UpperPattern`]), built once, with per-cell scatter maps
//!    for a parallel, race-free fill.
//! 4. [`assembly`]: reduced stiffness and internal forces from the cell laws
//!    ([`porofrac_law::CellLaw`], chosen per cell by a [`LawMap`]), and the nodal loads.
//! 5. [`solve`]: sparse Cholesky with the symbolic factorization reused
//!    ([`DirectSolver`], on [`porofrac_sparse::Cholesky`]), [`solve_static`], cell
//!    stresses and reaction forces; [`linear`]: the choice of linear solver
//!    ([`LinearSolver`]: Cholesky, CG with algebraic multigrid, or automatic by size);
//!    [`ordering`]: nested-dissection orderings of a grid's equations.
//!
//! Then the time-dependent and coupled models: [`explicit`] (damped explicit dynamics),
//! [`biot`] (poroelasticity: monolithic, fixed-stress and explicit-pressure couplings;
//! the monolithic one on [`porofrac_sparse::Ldlt`] with low-rank updates of its
//! factors), [`fracturing`] (failure, law switches, fracture permeability). [`norms`]
//! measures errors of nodal fields against exact ones.
//!
//! State that changes (displacements, time) is passed explicitly; the types above are
//! built once per grid and set of conditions.
//!
//! With the cargo feature `fixtures`, `standard` adds the manufactured solutions E2 and
//! E3 used by the tests, benchmarks and examples.
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
pub mod cavitation;
pub mod crack_flow;
pub mod dofs;
pub mod error;
pub mod explicit;
pub mod field;
pub mod fracturing;
pub mod laws;
pub mod linear;
pub mod norms;
pub mod ordering;
pub mod pattern;
mod quadrature;
pub mod solve;
#[cfg(feature = "fixtures")]
pub mod standard;
mod stress_cache;
pub mod tip_asymptote;
pub mod tip_distance;
pub mod tip_opening;

pub use assembly::{assemble, nodal_loads, nodal_loads_of_cells};
pub use bc::{Displacement, Gravity, Loads, Platen, Traction};
pub use biot::{
    BiotCoupling, BiotError, BiotState, BiotStep, BiotSystem, CouplingStats, ExplicitPressure,
    FixedStress, Linearization, Monolithic, SchemeMemory, drained_bulk_modulus,
};
pub use dofs::DofMap;
pub use error::{Result, SimError};
pub use explicit::{ExplicitOptions, ExplicitSolution, ExplicitState, solve_explicit};
pub use field::{FieldFn, ScalarField, VectorField, VectorFn};
pub use fracturing::{
    Body, FailureResolution, FractureError, FractureFlow, FractureLaws, FracturePermeability,
    FractureSettings, FractureStep, Fracturing, ResolutionError, Resolved, Scheme, StressMeasure,
    TipRule,
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
