//! The error type of the crate.

use porofrac_grid::GridError;
use porofrac_law::LawError;

/// Everything that can go wrong when setting up or solving a mechanics problem.
///
/// Every variant names where the problem is: a node and component, a cell, a face, an
/// equation mapped back to its node, or the rigid-body modes left free.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// An error from the grid (e.g. an unknown boundary name).
    #[error(transparent)]
    Grid(#[from] GridError),
    /// Two boundary conditions prescribe different things for one node and component.
    #[error(
        "node {node} at {position}: component {component} has conflicting conditions: {first} and {second}"
    )]
    Conflict {
        /// The node.
        node: usize,
        /// Its coordinates, formatted.
        position: String,
        /// `x`, `y` or `z`.
        component: &'static str,
        /// The first condition (kind, boundary, value).
        first: String,
        /// The second condition.
        second: String,
    },
    /// The displacement and platen conditions leave rigid-body modes unconstrained, so the
    /// stiffness matrix is singular.
    #[error(
        "the boundary conditions leave rigid-body motion free ({}): add displacement conditions that remove {}",
        modes.join(", "),
        if modes.len() == 1 { "it" } else { "them" }
    )]
    Singular {
        /// The free modes, e.g. `"translation x"`, `"rotation about z"`, or a combination.
        modes: Vec<String>,
    },
    /// A part of the grid joined to the rest by no node (an island of cells, say between
    /// inactive cells of a deck) is left free by the conditions: its stiffness is
    /// singular, and an iterative solver would not converge.
    #[error(
        "{cells} of the grid's {total} cells ({cell} among them) form a part joined to the rest by no node, and the boundary conditions leave it free ({}): constrain that part, or leave its cells out of the grid",
        modes.join(", ")
    )]
    FloatingPart {
        /// Number of cells of the part.
        cells: usize,
        /// Number of cells of the grid.
        total: usize,
        /// One cell of the part, as the message names it (`cell 12 at (x, y, z)`; a caller
        /// may name it in its own terms, e.g. by a deck's `(i, j, k)`).
        cell: String,
        /// Index of that cell in the grid.
        cell_index: usize,
        /// The free modes of the part.
        modes: Vec<String>,
    },
    /// The Cholesky factorization met a non-positive pivot.
    #[error(
        "the stiffness matrix is not positive definite at equation {equation} ({location}): \
         a part of the grid may be unconstrained, or a cell law is unstable"
    )]
    NotPositiveDefinite {
        /// The reduced equation (in the unpermuted numbering).
        equation: usize,
        /// The node and component, or the platen, of that equation.
        location: String,
    },
    /// The solution has a non-finite entry.
    #[error("the solution is not finite at {location}")]
    NotFinite {
        /// The node and component, or the platen.
        location: String,
    },
    /// A cell law returned something unusable (wrong size, NaN) for a cell.
    #[error("cell {cell} (law `{law}`): {what}")]
    Cell {
        /// The cell.
        cell: usize,
        /// The law's name.
        law: String,
        /// What is wrong.
        what: String,
    },
    /// A cell law failed to evaluate a cell (a degenerate cell, a node count it does not
    /// support, a slice of the wrong length).
    #[error("cell {cell} (law `{law}`): {source}")]
    Law {
        /// The cell.
        cell: usize,
        /// The law's name.
        law: String,
        /// What the law reported.
        #[source]
        source: LawError,
    },
    /// A boundary condition refers to a face that cannot carry it.
    #[error("{condition}: face {face} {what}")]
    Face {
        /// The condition (kind and boundary name).
        condition: String,
        /// The face.
        face: usize,
        /// What is wrong.
        what: String,
    },
    /// Invalid arguments (lengths, indices).
    #[error("invalid input: {0}")]
    Input(String),
    /// An error inside the sparse linear algebra (e.g. out of memory).
    #[error("sparse linear algebra: {0}")]
    LinearAlgebra(String),
    /// An iterative linear solve failed: iteration limit, stagnation or breakdown (the
    /// message names the iterations and the relative residual reached), or its setup.
    #[error("iterative linear solver: {0}")]
    Iterative(String),
    /// A nonlinear static solve did not converge.
    #[error(
        "static solve did not converge in {iterations} iterations (relative residual {residual:.3e})"
    )]
    NoConvergence {
        /// Iterations done.
        iterations: usize,
        /// The last relative residual.
        residual: f64,
    },
}

/// Result alias of this crate.
pub type Result<T, E = SimError> = std::result::Result<T, E>;

/// Names of the axes, for messages.
pub(crate) const AXES: [&str; 3] = ["x", "y", "z"];

pub(crate) fn fmt_point(p: &[f64]) -> String {
    let parts: Vec<String> = p.iter().map(|v| format!("{v}")).collect();
    format!("({})", parts.join(", "))
}
