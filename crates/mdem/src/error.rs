//! The error type of the crate.

use thiserror::Error;

/// Errors of the MDEM/DEM laws and the lattice model.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MdemError {
    /// Only 2D and 3D are supported.
    #[error("MDEM/DEM laws support dimension 2 or 3, not {0}")]
    UnsupportedDimension(usize),
    /// The material stiffness matrix has the wrong shape.
    #[error("material stiffness must be {expected}×{expected} (Kelvin form), got {rows}×{cols}")]
    MaterialShape {
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
        /// Required size (3 in 2D, 6 in 3D).
        expected: usize,
    },
    /// The material stiffness matrix has a NaN or infinite entry.
    #[error("material stiffness entry ({i}, {j}) is not finite")]
    MaterialNotFinite {
        /// Row.
        i: usize,
        /// Column.
        j: usize,
    },
    /// The material stiffness matrix is not symmetric.
    #[error("material stiffness is not symmetric: D[{i}][{j}] = {a} but D[{j}][{i}] = {b}")]
    MaterialNotSymmetric {
        /// Row.
        i: usize,
        /// Column.
        j: usize,
        /// `D[i][j]`.
        a: f64,
        /// `D[j][i]`.
        b: f64,
    },
    /// The material stiffness matrix is not positive definite.
    #[error("material stiffness is not positive definite")]
    MaterialNotPositiveDefinite,
    /// The cell is not a simplex (`D + 1` nodes).
    #[error("cell has {got} nodes; MDEM/DEM laws need a simplex with {expected} nodes")]
    NotASimplex {
        /// Number of nodes given.
        got: usize,
        /// `D + 1`.
        expected: usize,
    },
    /// The simplex has (almost) zero volume; its edge map `M` is singular.
    #[error("degenerate simplex: volume {volume:e} for edge length scale {scale:e}")]
    Degenerate {
        /// Volume (area in 2D).
        volume: f64,
        /// Longest edge.
        scale: f64,
    },
    /// A slice has the wrong length.
    #[error("{what} has length {got}, expected {expected}")]
    Length {
        /// Which argument.
        what: &'static str,
        /// Length given.
        got: usize,
        /// Length required.
        expected: usize,
    },
    /// The residual open-edge stiffness ratio is outside [0, 1).
    #[error("open-edge stiffness ratio must be in [0, 1), got {0}")]
    OpenStiffness(f64),
    /// A lattice parameter is out of range.
    #[error("lattice parameter {what} = {value} is invalid ({why})")]
    LatticeParameter {
        /// Which parameter.
        what: &'static str,
        /// The value given.
        value: f64,
        /// The requirement.
        why: &'static str,
    },
}

/// A law evaluation's failure as the [`CellLaw`](porofrac_law::CellLaw) error: a cell that
/// is not a simplex, a degenerate simplex, a slice of the wrong length. (The material
/// and lattice variants arise when a law is built, not when it evaluates a cell; they
/// keep their message.)
impl From<MdemError> for porofrac_law::LawError {
    fn from(e: MdemError) -> Self {
        use porofrac_law::LawError;
        match e {
            MdemError::NotASimplex { got, expected } => LawError::UnsupportedNodeCount {
                nodes: got,
                expected,
            },
            MdemError::Degenerate { volume, scale } => LawError::DegenerateCell { volume, scale },
            MdemError::Length {
                what,
                got,
                expected,
            } => LawError::WrongLength {
                what,
                got,
                expected,
            },
            other => LawError::Evaluation(other.to_string()),
        }
    }
}
