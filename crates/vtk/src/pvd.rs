//! ParaView `.pvd` collection (time series) writer.
//!
//! ```text
//! <?xml version="1.0"?>
//! <VTKFile type="Collection" version="0.1" byte_order="LittleEndian">
//!   <Collection>
//!     <DataSet timestep="0.5" group="" part="0" file="out/step_0001.vtu"/>
//!   </Collection>
//! </VTKFile>
//! ```
//!
//! The whole file is rewritten atomically after every [`PvdWriter::add`], so a run that is
//! killed leaves a valid collection of the steps written so far. Time steps are written in
//! shortest round-trip form.

use std::path::{Path, PathBuf};

use crate::atomic::write_atomic;
use crate::doc::escape;
use crate::error::VtkError;

/// Writes a `.pvd` time series, one `DataSet` per [`add`](Self::add).
#[derive(Clone, Debug)]
pub struct PvdWriter {
    path: PathBuf,
    entries: Vec<(f64, String)>,
}

impl PvdWriter {
    /// Create the collection file at `path` (an empty collection is written at once).
    pub fn create(path: impl AsRef<Path>) -> Result<Self, VtkError> {
        let w = Self {
            path: path.as_ref().to_path_buf(),
            entries: Vec::new(),
        };
        w.flush()?;
        Ok(w)
    }

    /// Create the collection file at `path` holding `entries` (time and relative data-set
    /// path, as [`PvdWriter::entries`] gave them: the steps of a run that is continued).
    pub fn with_entries(
        path: impl AsRef<Path>,
        entries: Vec<(f64, String)>,
    ) -> Result<Self, VtkError> {
        if let Some((t, _)) = entries.iter().find(|(t, _)| !t.is_finite()) {
            return Err(VtkError::Input(format!("pvd: time {t} is not finite")));
        }
        let w = Self {
            path: path.as_ref().to_path_buf(),
            entries,
        };
        w.flush()?;
        Ok(w)
    }

    /// Append a step at `time` whose data set is `file` (a path relative to the `.pvd`
    /// file's directory, written with `/` separators), and rewrite the collection.
    pub fn add(&mut self, time: f64, file: impl AsRef<Path>) -> Result<(), VtkError> {
        if !time.is_finite() {
            return Err(VtkError::Input(format!("pvd: time {time} is not finite")));
        }
        let file = file.as_ref();
        if file.is_absolute() {
            return Err(VtkError::Input(format!(
                "pvd: data set path {} must be relative to the .pvd file",
                file.display()
            )));
        }
        let rel: Vec<String> = file
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        self.entries.push((time, rel.join("/")));
        self.flush()
    }

    /// The collection file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The steps so far: time and relative data-set path.
    pub fn entries(&self) -> &[(f64, String)] {
        &self.entries
    }

    /// The collection's text.
    pub fn to_text(&self) -> String {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
             byte_order=\"LittleEndian\">\n  <Collection>\n",
        );
        for (t, f) in &self.entries {
            s.push_str(&format!(
                "    <DataSet timestep=\"{t:?}\" group=\"\" part=\"0\" file=\""
            ));
            escape(f, &mut s);
            s.push_str("\"/>\n");
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        s
    }

    fn flush(&self) -> Result<(), VtkError> {
        write_atomic(&self.path, self.to_text().as_bytes())
    }
}
