//! `PolyData` (`.vtp`): points with vertex, line and polygon cells (particles as
//! vertices, contacts as lines).

use std::io;
use std::path::Path;

use crate::array::{Attributes, DataArray, Encoding};
use crate::doc::{Doc, num, to_bytes, to_file};
use crate::error::VtkError;
use crate::unstructured::check_offsets;

/// Cells of one kind: cell `c` is `connectivity[offsets[c−1]..offsets[c]]`.
#[derive(Clone, Copy, Debug, Default)]
pub struct CellArray<'a> {
    /// The points of all cells, back to back.
    pub connectivity: &'a [i64],
    /// End position of each cell in `connectivity`.
    pub offsets: &'a [i64],
}

impl CellArray<'_> {
    fn len(&self) -> usize {
        self.offsets.len()
    }
}

/// A poly data set, borrowed from the caller. Cell data holds one tuple per cell, the
/// vertices first, then the lines, then the polygons (VTK's order).
#[derive(Clone, Copy, Debug, Default)]
pub struct PolyData<'a> {
    /// Point coordinates, `x y z` per point.
    pub points: &'a [f64],
    /// Vertex cells (`<Verts>`).
    pub verts: CellArray<'a>,
    /// Line and polyline cells (`<Lines>`).
    pub lines: CellArray<'a>,
    /// Polygon cells (`<Polys>`).
    pub polys: CellArray<'a>,
    /// Arrays of any length attached to the whole data set.
    pub field_data: &'a [DataArray<'a>],
    /// One tuple per point.
    pub point_data: Attributes<'a>,
    /// One tuple per cell.
    pub cell_data: Attributes<'a>,
}

impl PolyData<'_> {
    fn kinds(&self) -> [(&'static str, &CellArray<'_>); 3] {
        [
            ("Verts", &self.verts),
            ("Lines", &self.lines),
            ("Polys", &self.polys),
        ]
    }

    /// Check the sizes of all arrays.
    pub fn check(&self) -> Result<(), VtkError> {
        if !self.points.len().is_multiple_of(3) {
            return Err(VtkError::Input(format!(
                "points: {} coordinates are not 3 per point",
                self.points.len()
            )));
        }
        let np = self.points.len() / 3;
        let mut nc = 0;
        for (what, cells) in self.kinds() {
            check_offsets(cells.offsets, cells.connectivity.len(), what)?;
            if let Some(&p) = cells
                .connectivity
                .iter()
                .find(|&&p| p < 0 || p as u64 >= np as u64)
            {
                return Err(VtkError::Input(format!("{what}: point {p} of {np} points")));
            }
            nc += cells.len();
        }
        self.point_data
            .check(np, "point data")
            .map_err(VtkError::Input)?;
        self.cell_data
            .check(nc, "cell data")
            .map_err(VtkError::Input)
    }

    fn emit(&self, w: &mut dyn io::Write, enc: Encoding) -> io::Result<()> {
        const KIND: &str = "PolyData";
        let mut doc = Doc::start(w, enc, KIND, &[])?;
        if !self.field_data.is_empty() {
            doc.section("FieldData", &[], self.field_data)?;
        }
        let np = num(self.points.len() / 3);
        let (nv, nl, npo) = (
            num(self.verts.len()),
            num(self.lines.len()),
            num(self.polys.len()),
        );
        doc.open(
            "Piece",
            &[
                ("NumberOfPoints", &np),
                ("NumberOfVerts", &nv),
                ("NumberOfLines", &nl),
                ("NumberOfStrips", "0"),
                ("NumberOfPolys", &npo),
            ],
        )?;
        doc.attributes("PointData", &self.point_data)?;
        doc.attributes("CellData", &self.cell_data)?;
        doc.section("Points", &[], &[DataArray::new("Points", 3, self.points)])?;
        for (what, cells) in self.kinds() {
            if cells.len() > 0 {
                doc.section(
                    what,
                    &[],
                    &[
                        DataArray::new("connectivity", 1, cells.connectivity),
                        DataArray::new("offsets", 1, cells.offsets),
                    ],
                )?;
            }
        }
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
