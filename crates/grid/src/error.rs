//! Errors of the grid crate.

use std::path::PathBuf;

/// Everything that can go wrong when building, generating, reading or writing a grid.
///
/// Every variant names *where* the problem is: a cell, a face, a node, or a file and line.
#[derive(Debug, thiserror::Error)]
pub enum GridError {
    /// A cell failed a geometric or topological check.
    #[error("cell {cell}: {what}")]
    Cell {
        /// Index of the offending cell.
        cell: usize,
        /// What is wrong with it.
        what: String,
    },
    /// A face failed a check (e.g. shared by more than two cells).
    #[error("face {face} (nodes {nodes:?}): {what}")]
    Face {
        /// Index of the face (or of the face occurrence before deduplication).
        face: usize,
        /// Its nodes.
        nodes: Vec<usize>,
        /// What is wrong with it.
        what: String,
    },
    /// A node failed a check (NaN coordinate, duplicate, unused).
    #[error("node {node}: {what}")]
    Node {
        /// Index of the node.
        node: usize,
        /// What is wrong with it.
        what: String,
    },
    /// Invalid arguments to a generator or builder.
    #[error("invalid grid input: {0}")]
    Input(String),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A mesh file is malformed.
    #[error("{}:{line}: {what}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0 if unknown).
        line: usize,
        /// What is wrong.
        what: String,
    },
    /// A mesh file parsed, but the grid it describes is invalid.
    #[error("{}: {source}", path.display())]
    InFile {
        /// The file.
        path: PathBuf,
        /// The grid error.
        source: Box<GridError>,
    },
    /// An unknown boundary or tag name.
    #[error("unknown boundary or tag `{name}` (known: {known})")]
    UnknownName {
        /// The name asked for.
        name: String,
        /// Comma-separated list of the known names.
        known: String,
    },
}

/// Result alias of this crate.
pub type Result<T, E = GridError> = std::result::Result<T, E>;

pub(crate) fn cell_err(cell: usize, what: impl Into<String>) -> GridError {
    GridError::Cell {
        cell,
        what: what.into(),
    }
}
