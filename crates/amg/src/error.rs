//! Errors of the multigrid setup and the conjugate-gradient solve.

use thiserror::Error;

/// Everything that can go wrong in this crate. No routine panics on bad input or
/// returns a silent NaN: it returns one of these.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AmgError {
    /// Inconsistent sizes, indices out of range, unsorted patterns, bad options.
    #[error("invalid input: {0}")]
    Input(String),
    /// A NaN or infinite number in an input.
    #[error("non-finite {what} at index {index}")]
    NotFinite {
        /// Which input (matrix values, right-hand side, initial guess, near-null space…).
        what: &'static str,
        /// Position of the first non-finite entry.
        index: usize,
    },
    /// A diagonal entry that is zero, negative or missing: the matrix cannot be
    /// symmetric positive definite.
    #[error("diagonal entry {value:e} of equation {equation} on level {level} is not positive")]
    NonPositiveDiagonal {
        /// Multigrid level (0 = the given matrix).
        level: usize,
        /// Equation on that level.
        equation: usize,
        /// The offending diagonal value (0 when the entry is missing).
        value: f64,
    },
    /// The Cholesky factorization of the coarsest operator met a non-positive pivot: the
    /// matrix is not positive definite (or is singular on the near-null space).
    #[error(
        "coarsest operator ({size} equations, level {level}) is not positive definite at equation {equation}"
    )]
    CoarseNotPositiveDefinite {
        /// Coarsest level.
        level: usize,
        /// Its number of equations.
        size: usize,
        /// Failing equation of the coarse operator.
        equation: usize,
    },
    /// `pᵀAp ≤ 0` or `rᵀMr ≤ 0` in CG: the matrix or the preconditioner is not positive
    /// definite.
    #[error(
        "CG breakdown at iteration {iteration}: {what} (matrix or preconditioner not positive definite)"
    )]
    Breakdown {
        /// Iteration at which it happened.
        iteration: usize,
        /// The failing quantity, with its value.
        what: String,
    },
    /// The iteration limit was reached above the tolerance.
    #[error(
        "CG did not converge in {iterations} iterations: relative residual {residual:.3e} > tolerance {tolerance:.3e}"
    )]
    NoConvergence {
        /// Iterations done.
        iterations: usize,
        /// Relative residual `‖b − A x‖ / ‖b‖` reached.
        residual: f64,
        /// Requested tolerance.
        tolerance: f64,
    },
    /// The residual stopped decreasing before reaching the tolerance (loss of accuracy or
    /// a tolerance below what the conditioning allows).
    #[error(
        "CG stagnated after {iterations} iterations: relative residual {residual:.3e} > tolerance {tolerance:.3e}"
    )]
    Stagnation {
        /// Iterations done.
        iterations: usize,
        /// Relative residual `‖b − A x‖ / ‖b‖` of the `x` left behind.
        residual: f64,
        /// Requested tolerance.
        tolerance: f64,
    },
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, AmgError>;

/// Error if any entry of `v` is not finite.
pub(crate) fn check_finite(v: &[f64], what: &'static str) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(AmgError::NotFinite { what, index }),
        None => Ok(()),
    }
}
