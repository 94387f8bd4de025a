//! `ImageData` (`.vti`): a regular lattice of points, `x` fastest.
//!
//! Point `(i, j, k)` lies at `origin + (i, j, k) · spacing`; point data hold
//! `n_x · n_y · n_z` tuples in the order `i + n_x (j + n_y k)`, cell data
//! `max(n_x − 1, 1) · max(n_y − 1, 1) · max(n_z − 1, 1)` (a flat axis of one point has one
//! layer of cells). `WholeExtent` and the piece's `Extent` are `0 n_x−1 0 n_y−1 0 n_z−1`.

use std::io;
use std::path::Path;

use crate::array::{Attributes, DataArray, Encoding};
use crate::doc::{Doc, to_bytes, to_file};
use crate::error::VtkError;

/// A lattice with its data, borrowed from the caller.
#[derive(Clone, Copy, Debug)]
pub struct ImageData<'a> {
    /// Points per axis (≥ 1 each; a plane lattice has `n_z = 1`).
    pub size: [usize; 3],
    /// Position of point `(0, 0, 0)`.
    pub origin: [f64; 3],
    /// Distance between neighbouring points along each axis.
    pub spacing: [f64; 3],
    /// Arrays of any length attached to the whole data set.
    pub field_data: &'a [DataArray<'a>],
    /// One tuple per point.
    pub point_data: Attributes<'a>,
    /// One tuple per cell.
    pub cell_data: Attributes<'a>,
}

impl ImageData<'_> {
    fn num_points(&self) -> usize {
        self.size.iter().product()
    }

    fn num_cells(&self) -> usize {
        self.size
            .iter()
            .map(|&n| n.saturating_sub(1).max(1))
            .product()
    }

    /// Check the lattice and the sizes of all arrays.
    pub fn check(&self) -> Result<(), VtkError> {
        if self.size.contains(&0) {
            return Err(VtkError::Input(format!(
                "image data: lattice size {:?} has an empty axis",
                self.size
            )));
        }
        self.point_data
            .check(self.num_points(), "point data")
            .map_err(VtkError::Input)?;
        self.cell_data
            .check(self.num_cells(), "cell data")
            .map_err(VtkError::Input)
    }

    fn emit(&self, w: &mut dyn io::Write, enc: Encoding) -> io::Result<()> {
        let [nx, ny, nz] = self.size;
        let extent = format!("0 {} 0 {} 0 {}", nx - 1, ny - 1, nz - 1);
        self.emit_extents(w, enc, &extent, &extent)
    }

    /// The document with a `WholeExtent` and a piece `Extent` of their own (the same for
    /// a whole image; a piece of a parallel set names the whole and its own part).
    pub(crate) fn emit_extents(
        &self,
        w: &mut dyn io::Write,
        enc: Encoding,
        whole: &str,
        extent: &str,
    ) -> io::Result<()> {
        const KIND: &str = "ImageData";
        let [ox, oy, oz] = self.origin;
        let [sx, sy, sz] = self.spacing;
        let origin = format!("{ox:?} {oy:?} {oz:?}");
        let spacing = format!("{sx:?} {sy:?} {sz:?}");
        let mut doc = Doc::start(
            w,
            enc,
            KIND,
            &[
                ("WholeExtent", whole),
                ("Origin", &origin),
                ("Spacing", &spacing),
            ],
        )?;
        if !self.field_data.is_empty() {
            doc.section("FieldData", &[], self.field_data)?;
        }
        doc.open("Piece", &[("Extent", extent)])?;
        doc.attributes("PointData", &self.point_data)?;
        doc.attributes("CellData", &self.cell_data)?;
        doc.close("Piece")?;
        doc.finish(KIND)
    }

    /// The file's bytes.
    pub fn to_bytes(&self, enc: Encoding) -> Result<Vec<u8>, VtkError> {
        self.check()?;
        Ok(to_bytes(|w| self.emit(w, enc)))
    }

    /// Write the file atomically (streamed, as [`crate::UnstructuredGrid::write`]).
    pub fn write(&self, path: impl AsRef<Path>, enc: Encoding) -> Result<(), VtkError> {
        self.check()?;
        to_file(path.as_ref(), |w| self.emit(w, enc))
    }
}
