//! Errors of the flow crate.

use porofrac_grid::GridError;

/// Everything that can go wrong when setting up or solving a flow problem.
///
/// Every variant names *what* is wrong and *where*: a cell, a face, a boundary condition,
/// a source or a well.
#[derive(Debug, thiserror::Error)]
pub enum FlowError {
    /// A rock property of a cell is invalid (permeability not SPD, porosity outside (0, 1], …).
    #[error("cell {cell}: {what}")]
    Cell {
        /// Index of the offending cell.
        cell: usize,
        /// What is wrong with it.
        what: String,
    },
    /// A face-related problem (a boundary condition on an interior face, a face listed twice, …).
    #[error("face {face}: {what}")]
    Face {
        /// Index of the offending face.
        face: usize,
        /// What is wrong with it.
        what: String,
    },
    /// A rock property that is not per cell is invalid (e.g. the grain bulk modulus).
    #[error("rock {property}: {what}")]
    Rock {
        /// Which property.
        property: &'static str,
        /// What is wrong with it.
        what: String,
    },
    /// A fluid property is invalid.
    #[error("fluid {property}: {what}")]
    Fluid {
        /// `viscosity` or `compressibility`.
        property: &'static str,
        /// What is wrong with it.
        what: String,
    },
    /// A boundary condition is invalid.
    #[error("boundary condition #{index} ({kind}): {what}")]
    Boundary {
        /// Position of the condition in [`crate::FlowProblem::boundary_conditions`].
        index: usize,
        /// `pressure` or `flux`.
        kind: &'static str,
        /// What is wrong with it.
        what: String,
    },
    /// A source term is invalid.
    #[error("source `{name}`: {what}")]
    Source {
        /// The source's name.
        name: String,
        /// What is wrong with it.
        what: String,
    },
    /// A well is invalid.
    #[error("well `{name}`: {what}")]
    Well {
        /// The well's name.
        name: String,
        /// What is wrong with it.
        what: String,
    },
    /// An input array has the wrong length.
    #[error("{what} has length {got}, expected {expected}")]
    Length {
        /// Which array.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length the grid requires.
        expected: usize,
    },
    /// The linear system is singular (e.g. a connected region with zero storage and neither a
    /// pressure boundary condition nor a pressure-controlled well).
    #[error("singular flow system: {0}")]
    Singular(String),
    /// An invalid time or time step.
    #[error("time stepping: {0}")]
    Time(String),
    /// The sparse Cholesky factorization or solve failed.
    #[error("linear solver: {0}")]
    Solver(String),
    /// An error from the grid crate (e.g. an unknown boundary name).
    #[error(transparent)]
    Grid(#[from] GridError),
}

/// Result alias of this crate.
pub type Result<T, E = FlowError> = std::result::Result<T, E>;

pub(crate) fn cell_err(cell: usize, what: impl Into<String>) -> FlowError {
    FlowError::Cell {
        cell,
        what: what.into(),
    }
}
