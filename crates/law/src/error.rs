//! Errors of the law crate.

/// Everything that can go wrong when building a material, checking a law or evaluating
/// a cell law.
///
/// Every variant names the offending parameter, matrix entry or cell property and its
/// value. A law does not know the index of the cell it evaluates: the caller that does
/// (assembly, stress recovery) adds it to its own error.
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
    /// The law cannot evaluate a cell with this many nodes (e.g. MDEM and DEM need a
    /// simplex, `D + 1` nodes).
    #[error("cell has {nodes} nodes; the law needs {expected} nodes")]
    UnsupportedNodeCount {
        /// Nodes of the cell.
        nodes: usize,
        /// Nodes the law needs.
        expected: usize,
    },
    /// The cell is degenerate: (almost) zero or negative volume for its size.
    #[error("degenerate cell: volume {volume:e} for length scale {scale:e}")]
    DegenerateCell {
        /// Volume (area in 2D).
        volume: f64,
        /// The length the volume was compared with (e.g. the longest edge).
        scale: f64,
    },
    /// A slice or matrix passed to the law has the wrong length.
    #[error("{what} has length {got}, expected {expected}")]
    WrongLength {
        /// Which argument.
        what: &'static str,
        /// Length given.
        got: usize,
        /// Length required.
        expected: usize,
    },
    /// Any other failure of a law to evaluate a cell (for laws defined outside
    /// porofrac), with the law's own message.
    #[error("{0}")]
    Evaluation(String),
}

/// Result type of the law crate.
pub type Result<T> = std::result::Result<T, LawError>;
