//! Errors of the law crate.

/// Everything that can go wrong when building a material or checking a law.
///
/// Every variant names the offending parameter or matrix entry and its value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LawError {
    /// A scalar material parameter is out of its admissible range or not finite.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        /// Name of the parameter (`"E"`, `"nu"`, `"lambda"`, `"mu"`, ...).
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The admissible range or the violated condition.
        reason: &'static str,
    },
    /// A matrix has the wrong shape.
    #[error("{what}: expected a {expected}×{expected} matrix, got {rows}×{cols}")]
    WrongSize {
        /// What the matrix is.
        what: &'static str,
        /// Expected number of rows and columns.
        expected: usize,
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
    },
    /// A matrix entry is NaN or infinite.
    #[error("{what}: entry ({row}, {col}) = {value} is not finite")]
    NonFinite {
        /// What the matrix is.
        what: &'static str,
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// The entry.
        value: f64,
    },
    /// A matrix that must be symmetric is not.
    #[error("{what} is not symmetric: entry ({row}, {col}) = {upper} but ({col}, {row}) = {lower}")]
    NotSymmetric {
        /// What the matrix is.
        what: &'static str,
        /// Row of the upper entry.
        row: usize,
        /// Column of the upper entry.
        col: usize,
        /// Value at (row, col).
        upper: f64,
        /// Value at (col, row).
        lower: f64,
    },
    /// A matrix that must be positive definite is not (its Cholesky factorization fails).
    #[error("{what} is not positive definite (Cholesky factorization failed)")]
    NotPositiveDefinite {
        /// What the matrix is.
        what: &'static str,
    },
}

/// Result type of the law crate.
pub type Result<T> = std::result::Result<T, LawError>;
