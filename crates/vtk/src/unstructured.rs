//! `UnstructuredGrid` (`.vtu`): points, cells of any VTK type (polyhedra with their face
//! streams), field, point and cell data.

use std::io;
use std::path::Path;

use crate::array::{Attributes, DataArray, Encoding};
use crate::doc::{Doc, num, to_bytes, to_file};
use crate::error::VtkError;

/// VTK linear cell types and their codes in the `types` array.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum CellType {
    /// A point (1).
    Vertex = 1,
    /// Several points (2).
    PolyVertex = 2,
    /// A segment (3).
    Line = 3,
    /// A chain of segments (4).
    PolyLine = 4,
    /// A triangle, counter-clockwise (5).
    Triangle = 5,
    /// A triangle strip (6).
    TriangleStrip = 6,
    /// A polygon, nodes in order around it (7).
    Polygon = 7,
    /// An axis-aligned rectangle, nodes in lexicographic order (8).
    Pixel = 8,
    /// A quadrilateral (9).
    Quad = 9,
    /// A tetrahedron (10).
    Tetra = 10,
    /// An axis-aligned box, nodes in lexicographic order (11).
    Voxel = 11,
    /// A hexahedron (12).
    Hexahedron = 12,
    /// A wedge (prism) (13).
    Wedge = 13,
    /// A pyramid (14).
    Pyramid = 14,
    /// A polyhedron given by its faces (42; see [`Polyhedra`]).
    Polyhedron = 42,
}

impl CellType {
    /// The VTK code.
    pub fn code(self) -> u8 {
        self as u8
    }
}

/// The faces of the polyhedral cells: per cell (in cell order) the number of faces, then
/// for each face its node count and nodes, all in `faces`; `faceoffsets[c]` is the end of
/// cell `c`'s part of `faces`, or −1 if cell `c` is not a polyhedron.
#[derive(Clone, Copy, Debug)]
pub struct Polyhedra<'a> {
    /// The face stream.
    pub faces: &'a [i64],
    /// One end position (or −1) per cell.
    pub faceoffsets: &'a [i64],
}

/// An unstructured grid, borrowed from the caller.
#[derive(Clone, Copy, Debug)]
pub struct UnstructuredGrid<'a> {
    /// Point coordinates, `x y z` per point.
    pub points: &'a [f64],
    /// The points of all cells, back to back.
    pub connectivity: &'a [i64],
    /// End position of each cell in `connectivity`.
    pub offsets: &'a [i64],
    /// Type of each cell.
    pub types: &'a [CellType],
    /// Faces of the polyhedra (required if a cell is a [`CellType::Polyhedron`]).
    pub polyhedra: Option<Polyhedra<'a>>,
    /// Arrays of any length attached to the whole grid (`<FieldData>`, written only if
    /// not empty).
    pub field_data: &'a [DataArray<'a>],
    /// One tuple per point.
    pub point_data: Attributes<'a>,
    /// One tuple per cell.
    pub cell_data: Attributes<'a>,
}

/// Check that `offsets` are non-decreasing ends within `len` entries.
pub(crate) fn check_offsets(offsets: &[i64], len: usize, what: &str) -> Result<(), VtkError> {
    let mut last = 0i64;
    for (c, &o) in offsets.iter().enumerate() {
        if o < last || o as u64 > len as u64 {
            return Err(VtkError::Input(format!(
                "{what}: offset {o} of cell {c} is out of order or past the {len} connectivity entries"
            )));
        }
        last = o;
    }
    if offsets.last().map_or(0, |&o| o as usize) != len {
        return Err(VtkError::Input(format!(
            "{what}: the offsets end at {last}, the connectivity has {len} entries"
        )));
    }
    Ok(())
}

impl UnstructuredGrid<'_> {
    fn num_points(&self) -> usize {
        self.points.len() / 3
    }

    /// Check the sizes of all arrays.
    pub fn check(&self) -> Result<(), VtkError> {
        let input = VtkError::Input;
        if !self.points.len().is_multiple_of(3) {
            return Err(input(format!(
                "points: {} coordinates are not 3 per point",
                self.points.len()
            )));
        }
        let (np, nc) = (self.num_points(), self.types.len());
        if self.offsets.len() != nc {
            return Err(input(format!(
                "cells: {} offsets for {nc} cell types",
                self.offsets.len()
            )));
        }
        check_offsets(self.offsets, self.connectivity.len(), "cells")?;
        if let Some(&p) = self
            .connectivity
            .iter()
            .find(|&&p| p < 0 || p as u64 >= np as u64)
        {
            return Err(input(format!("cells: point {p} of {np} points")));
        }
        match &self.polyhedra {
            Some(p) if p.faceoffsets.len() != nc => {
                return Err(input(format!(
                    "polyhedra: {} face offsets for {nc} cells",
                    p.faceoffsets.len()
                )));
            }
            None if self.types.contains(&CellType::Polyhedron) => {
                return Err(input("polyhedra: cells of type 42 without faces".into()));
            }
            _ => {}
        }
        self.point_data.check(np, "point data").map_err(input)?;
        self.cell_data.check(nc, "cell data").map_err(input)?;
        Ok(())
    }

    fn emit(&self, w: &mut dyn io::Write, enc: Encoding) -> io::Result<()> {
        const KIND: &str = "UnstructuredGrid";
        let mut doc = Doc::start(w, enc, KIND, &[])?;
        if !self.field_data.is_empty() {
            doc.section("FieldData", &[], self.field_data)?;
        }
        let (np, nc) = (num(self.num_points()), num(self.types.len()));
        doc.open("Piece", &[("NumberOfPoints", &np), ("NumberOfCells", &nc)])?;
        doc.attributes("PointData", &self.point_data)?;
        doc.attributes("CellData", &self.cell_data)?;
        doc.section("Points", &[], &[DataArray::new("Points", 3, self.points)])?;
        let types: Vec<u8> = self.types.iter().map(|t| t.code()).collect();
        let mut cells = vec![
            DataArray::new("connectivity", 1, self.connectivity),
            DataArray::new("offsets", 1, self.offsets),
            DataArray::new("types", 1, &types[..]),
        ];
        if let Some(p) = &self.polyhedra {
            cells.push(DataArray::new("faces", 1, p.faces));
            cells.push(DataArray::new("faceoffsets", 1, p.faceoffsets));
        }
        doc.section("Cells", &[], &cells)?;
        doc.close("Piece")?;
        doc.finish(KIND)
    }

    /// The file's bytes.
    pub fn to_bytes(&self, enc: Encoding) -> Result<Vec<u8>, VtkError> {
        self.check()?;
        Ok(to_bytes(|w| self.emit(w, enc)))
    }

    /// Write the file atomically (streamed: the binary encodings hold one array at a
    /// time in memory, except [`Encoding::Appended`], which holds all data until the
    /// end).
    pub fn write(&self, path: impl AsRef<Path>, enc: Encoding) -> Result<(), VtkError> {
        self.check()?;
        to_file(path.as_ref(), |w| self.emit(w, enc))
    }
}
