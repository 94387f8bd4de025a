//! The error type of the VTK writers.

use std::path::PathBuf;

/// What can go wrong when writing a VTK file.
#[derive(Debug, thiserror::Error)]
pub enum VtkError {
    /// Inconsistent input: an array of the wrong length, offsets that do not fit the
    /// connectivity, a non-finite time step, …
    #[error("{0}")]
    Input(String),
    /// A file could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The target file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}
