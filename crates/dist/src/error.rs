//! Errors of the distributed solve.

use thiserror::Error;

/// What went wrong in a distributed setup or solve. Every process that detects the error
/// returns it; collective checks make all processes agree where the error could differ.
#[derive(Debug, Error)]
pub enum DistError {
    /// Inconsistent input (lengths, indices, options), with what was wrong.
    #[error("distributed solve: {0}")]
    Input(String),
    /// The local aggregation or the coarsest factorization of `porofrac-amg` failed.
    #[error("distributed AMG: {0}")]
    Amg(#[from] porofrac_amg::AmgError),
    /// CG stopped at the iteration limit above the tolerance.
    #[error(
        "CG did not converge in {iterations} iterations: relative residual {relative_residual:.3e} above {tolerance:.1e}"
    )]
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// `‖b − A x‖ / ‖b‖` at the end.
        relative_residual: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// A non-positive diagonal or curvature: the matrix or preconditioner is not SPD.
    #[error("distributed solve: {0} (the matrix is not symmetric positive definite)")]
    NotPositiveDefinite(String),
}

/// Result of the distributed solve.
pub type Result<T> = std::result::Result<T, DistError>;
