//! porofrac-sparse: the sparse direct layer of porofrac, on faer.
//!
//! Every solver here takes a matrix by its compressed-column (CSC) pattern and values —
//! of a symmetric matrix usually its upper triangle — and splits the work as faer does:
//! a symbolic analysis (fill-reducing ordering, elimination tree, pattern of the
//! factors) computed once per pattern and kept, numeric factorizations for new values on
//! that pattern, and solves in place.
//!
//! - [`cholesky`]: [`Cholesky`], `P A Pᵀ = L Lᵀ` for symmetric positive definite
//!   matrices (the static mechanics, the pressure systems, the coarsest multigrid level).
//! - [`ldlt`]: [`Ldlt`], `P A Pᵀ = L D Lᵀ` for symmetric quasi-definite matrices (saddle
//!   point systems), with a solve written for one right-hand side per time step.
//! - [`ldlt_single`]: [`LdltSingle`], the same factors in single precision (a
//!   preconditioner), and [`TrailingFactor`], the last columns of the factors, dense:
//!   the Schur complement on the unknowns eliminated last.
//! - [`lowrank`]: [`LowRank`], solves with a matrix that differs from a factorized one
//!   in few unknowns (Sherman–Morrison–Woodbury), and [`UpperRows`], row access to an
//!   upper-triangle pattern.
//! - [`lu`]: [`Lu`], sparse LU with partial pivoting for non-symmetric matrices.
//! - [`pattern`]: [`UpperPattern`], the upper-triangle CSC pattern of a symmetric
//!   matrix, the form every symmetric factorization here reads.
//! - [`ordering`]: the check of an elimination order ([`ordering::inverse_permutation`])
//!   and a nested dissection of a pattern whose unknowns have positions.
//!
//! Parallelism is faer's [`Par`], passed to the numeric steps.

pub mod cholesky;
pub mod ldlt;
pub mod ldlt_single;
pub mod lowrank;
pub mod lu;
pub mod ordering;
pub mod pattern;

pub use cholesky::{Cholesky, CholeskyError};
pub use faer::Par;
pub use ldlt::{Ldlt, LdltError};
pub use ldlt_single::{LdltSingle, TrailingFactor};
pub use lowrank::{LowRank, UpperRows};
pub use lu::{Lu, LuError};
pub use ordering::{PermutationError, inverse_permutation};
pub use pattern::UpperPattern;
