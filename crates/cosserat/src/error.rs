//! The error type of the crate.

use porofrac_grid::GridError;
use thiserror::Error;

/// Errors of the Cosserat discretisation, its assembly and its solvers.
#[derive(Debug, Error)]
pub enum CosseratError {
    /// A material parameter is out of range; `name` is the parameter.
    #[error("material parameter {name} = {value}: {reason}")]
    Material {
        /// Parameter name (`shear_modulus`, `characteristic_length`, ...).
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A cell of the grid is not a simplex (triangle in 2D, tetrahedron in 3D).
    #[error("cell {cell} has {faces} faces and {nodes} nodes: the Cosserat DEM needs simplices")]
    NotSimplex {
        /// The cell.
        cell: usize,
        /// Its face count.
        faces: usize,
        /// Its node count.
        nodes: usize,
    },
    /// No admissible set of `D + 1` cells reconstructs the value at a facet (eq. 10).
    #[error(
        "facet {face} (centroid {centroid}): no {need} cells with non-degenerate barycentres \
         give barycentric weights below {limit} in a pool of {pool} cells"
    )]
    NoStencil {
        /// The facet (face index of the grid).
        face: usize,
        /// Its centroid, formatted.
        centroid: String,
        /// Cells a stencil needs (`D + 1`).
        need: usize,
        /// Largest admissible weight.
        limit: f64,
        /// Pool size tried last.
        pool: usize,
    },
    /// A boundary condition is inconsistent; `what` says which.
    #[error("boundary condition {index}: {what}")]
    Condition {
        /// Position of the condition in the list given.
        index: usize,
        /// What is wrong.
        what: String,
    },
    /// A function argument is out of range; `what` names it.
    #[error("{what}")]
    Input {
        /// Argument and problem.
        what: String,
    },
    /// GMRES did not reach its tolerance.
    #[error(
        "GMRES reached a relative residual of {residual:.3e} in {iterations} iterations, \
         not the tolerance {tolerance:.1e} (a harder system than the multigrid \
         preconditioner handles: use the LU)"
    )]
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// True relative residual reached.
        residual: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// The sparse LU failed or produced a non-finite solution.
    #[error("linear solve: {0}")]
    Solve(String),
    /// The grid could not be built.
    #[error("grid: {0}")]
    Grid(#[from] GridError),
    /// A stop was requested (the flag of [`crate::linear::Linear::set_interrupt`]) during
    /// an iterative solve.
    #[error("interrupted")]
    Interrupted,
}

/// Result with [`CosseratError`].
pub type Result<T> = std::result::Result<T, CosseratError>;
