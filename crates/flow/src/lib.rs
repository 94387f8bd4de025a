//! Two-point flux (TPFA) finite-volume single-phase flow of a slightly compressible fluid on
//! any polygonal (D = 2) or polyhedral (D = 3) [`porofrac_grid::Grid`].
//!
//! # Model
//!
//! Mass conservation with Darcy's law (the flow part of Nilsen et al. (2017) eq. 28b, without the
//! volumetric coupling term that a Biot model adds):
//!
//! ```text
//!   S ∂p/∂t + ∇·u = q,     u = −(K/μ) ∇p,     S = φ c_f + (α − φ)/K_s,
//! ```
//!
//! `K` the permeability tensor (m²), `μ` the viscosity, `φ` porosity, `c_f` the fluid
//! compressibility, `α` the Biot–Willis coefficient and `K_s` the grain bulk modulus
//! (`K_s = ∞` by default, so `S = φ c_f`).
//!
//! # Discretization
//!
//! Cell-centred finite volumes with two-point fluxes ([`trans`]): the flux from cell `K` to
//! its neighbour `L` across face `f` is `T_f (p_K − p_L)/μ` with `T_f` the harmonic average
//! of the half-transmissibilities `t_{K,f} = A_f (K n_f)·(c_f − x_K)/|c_f − x_K|²`.
//! Time is discretized by implicit Euler (Nilsen et al. (2017) eq. 29):
//!
//! ```text
//!   |K| S_K (p_K^{n+1} − p_K^n)/Δt + Σ_f F_{K,f}(p^{n+1}) = Q_K ,
//! ```
//!
//! assembled as `(M/Δt + A) p^{n+1} = M/Δt p^n + b(t^{n+1})` ([`model`]), with `M` the
//! accumulation diagonal, `A` the symmetric flux matrix (with Dirichlet and well terms)
//! and `b` the forcing; all three are public so that a Biot coupling (Nilsen et al. (2017) eq. 30)
//! can add its blocks. The system is symmetric positive definite and solved by sparse Cholesky
//! (`porofrac_sparse::Cholesky`) with the symbolic factorization reused across steps.
//!
//! Sources ([`problem::Source`]) are total rates or pore volumes per hour spread over a set
//! of cells in proportion to their volumes; wells ([`problem::Well`], [`well`]) use
//! Peaceman's well index and are controlled by bottom-hole pressure or rate; boundary
//! faces take a pressure or an outward Darcy flux that may depend on position and time
//! ([`problem::ScalarField`]); other boundary faces are no-flow.
//!
//! # Example
//!
//! ```
//! use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock};
//! use porofrac_grid::{Point, generate::cartesian};
//!
//! let grid = cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 0.1), [10, 1])?;
//! let n = grid.num_cells();
//! let rock = Rock::new(vec![0.2; n], Permeability::uniform(n, 1e-12)?);
//! let problem = FlowProblem::new(rock, Fluid { viscosity: 1e-3, compressibility: 0.0 })
//!     .pressure_bc(grid.boundary("xmin")?, 2e5)
//!     .pressure_bc(grid.boundary("xmax")?, 1e5);
//! let mut model = FlowModel::new(&grid, &problem)?;
//! let r = model.solve_steady(0.0)?;
//! // Darcy: u = k Δp / (μ L) = 1e-12 · 1e5 / 1e-3 = 1e-4 m/s through a face of length 0.1.
//! let q_out = r.face_flux[grid.boundary("xmax")?[0]];
//! assert!((q_out - 1e-5).abs() < 1e-17);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod error;
pub mod model;
pub mod perm;
pub mod problem;
pub mod trans;
pub mod well;

pub use error::{FlowError, Result};
pub use model::{FlowLinearSolver, FlowModel, StepResult};
pub use perm::{Permeability, Tensor};
pub use problem::{
    BoundaryCondition, BoundaryKind, FieldFn, FlowProblem, Fluid, Rock, ScalarField, Source,
    SourceRate, Well, WellControl,
};
pub use trans::Transmissibilities;
pub use well::peaceman_well_index;
