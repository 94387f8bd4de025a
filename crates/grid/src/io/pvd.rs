//! ParaView `.pvd` collection (time series) writer: [`porofrac_vtk::PvdWriter`] with the
//! grid's error type.
//!
//! ```text
//! <VTKFile type="Collection" version="0.1" byte_order="LittleEndian">
//!   <Collection>
//!     <DataSet timestep="0.5" group="" part="0" file="out/step_0001.vtu"/>
//!   </Collection>
//! </VTKFile>
//! ```
//!
//! The whole file is rewritten atomically after every [`PvdWriter::add`], so a run that is
//! killed leaves a valid collection of the steps written so far.

use std::path::Path;

use crate::error::Result;
use crate::io::vtu_write::vtk_err;

/// Writes a `.pvd` time series, one `DataSet` per [`add`](Self::add).
#[derive(Clone, Debug)]
pub struct PvdWriter(porofrac_vtk::PvdWriter);

impl PvdWriter {
    /// Create the collection file at `path` (an empty collection is written at once).
    pub fn create(path: impl AsRef<Path>) -> Result<Self> {
        porofrac_vtk::PvdWriter::create(path)
            .map(Self)
            .map_err(vtk_err)
    }

    /// Create the collection file at `path` holding `entries` (time and relative data-set
    /// path, as [`PvdWriter::entries`] gave them: the steps of a run that is continued).
    pub fn with_entries(path: impl AsRef<Path>, entries: Vec<(f64, String)>) -> Result<Self> {
        porofrac_vtk::PvdWriter::with_entries(path, entries)
            .map(Self)
            .map_err(vtk_err)
    }

    /// Append a step at `time` whose data set is `file` (a path relative to the `.pvd`
    /// file's directory, written with `/` separators), and rewrite the collection.
    pub fn add(&mut self, time: f64, file: impl AsRef<Path>) -> Result<()> {
        self.0.add(time, file).map_err(vtk_err)
    }

    /// The collection file.
    pub fn path(&self) -> &Path {
        self.0.path()
    }

    /// The steps so far: time and relative data-set path.
    pub fn entries(&self) -> &[(f64, String)] {
        self.0.entries()
    }
}
