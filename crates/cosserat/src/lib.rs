//! Variational discrete element method for Cosserat (micropolar) elasticity on simplices,
//! 2D and 3D, static and dynamic (Marazzato, arXiv 2101.08712; the equation numbers below
//! are the paper's).
//!
//! # Method
//!
//! Each cell `K` carries a displacement `u_K` and a micro-rotation `φ_K` (one component in
//! 2D, three in 3D) at its barycentre. One code path serves both dimensions (const `D`):
//!
//! 1. [`recon`]: facet values `w_F = Σ λ_K w_K` from `D + 1` cells (eqs. 8–10, with the pool
//!    rules and fallbacks of the paper), cell gradients by the discrete Stokes formula (11)
//!    and the cellwise P1 reconstruction (14). All are exact for affine fields.
//! 2. [`material`]: the isotropic law (2)–(3), (25)–(26) in one block-diagonal matrix on
//!    the generalised strain `(e, κ)`, `e = ∇u + ε·φ`, `κ = ∇φ` (eq. 1).
//! 3. [`discrete`]: the elastic form `Σ_K Σ_q w_q B_qᵀ A B_q` (13), the interior penalty
//!    weighted by the law (17), the penalty-free non-symmetric Nitsche terms (18)–(20) and
//!    the loads (21)–(22), assembled once into a block pattern ([`pattern`]) and solved by
//!    a sparse LU.
//! 4. [`dynamics`]: diagonal mass (15) `ρ|K|`, `ρ j |K|`; Newmark average acceleration
//!    (31) and explicit leapfrog with a computed stable step; energies.
//! 5. [`mod@reference`]: the closed forms used to verify it (the shear boundary layer and the
//!    stress concentration factor of a hole).
//!
//! Sign conventions: `σ_ij` is the `i`-component of the traction on a face of normal `j`
//! (`t = σ n`), tension positive; balance `∂_j σ_ij + f_i = 0`,
//! `∂_j m_kj − ε_kij σ_ij + c_k = 0`.

#![warn(missing_docs)]

pub mod conditions;
pub mod discrete;
pub mod dynamics;
pub mod error;
pub mod krylov;
pub mod linear;
pub mod material;
pub mod mesh;
pub mod pattern;
pub mod recon;
pub mod reference;

pub use conditions::{BodyLoads, Condition, Field, Slot, constant};
pub use discrete::{Cosserat, Options, StrainVariant};
pub use dynamics::{Dynamics, Integrator};
pub use error::{CosseratError, Result};
pub use krylov::{FactorPrecision, GmresOptions, GmresStats};
pub use linear::{Linear, LinearOptions, LinearSolver, LinearStats, SystemRef};
pub use material::{Material, components, rotations, strain_index, strain_len};
pub use pattern::{BlockPattern, SparseLu};
pub use recon::{Reconstruction, StencilRule};
