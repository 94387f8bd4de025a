//! VTK XML files for ParaView, meshio and VTK's own readers, and atomic file writes.
//!
//! One writer for every kind of output of porofrac: unstructured grids (`.vtu`,
//! [`UnstructuredGrid`]), particles and contact lines (`.vtp`, [`PolyData`]), lattices
//! (`.vti`, [`ImageData`]) and time series (`.pvd`, [`PvdWriter`]). Every file goes through
//! [`write_atomic`] (or its streaming form [`write_atomic_with`]): the bytes are written to
//! a temporary file in the target's directory, which is then renamed over the target, so a
//! reader (ParaView polling a running simulation, a killed run) sees the old file or the
//! new one, never a part of either.
//!
//! # The VTK XML format as written here
//!
//! A file is
//!
//! ```text
//! <?xml version="1.0"?>
//! <VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">
//!   <UnstructuredGrid>
//!     <FieldData> … </FieldData>                       (only if there are field arrays)
//!     <Piece NumberOfPoints="…" NumberOfCells="…">
//!       <PointData> … </PointData>
//!       <CellData> … </CellData>
//!       <Points> <DataArray Name="Points" NumberOfComponents="3" …/> </Points>
//!       <Cells> connectivity, offsets, types [, faces, faceoffsets] </Cells>
//!     </Piece>
//!   </UnstructuredGrid>
//!   <AppendedData encoding="raw"> _… </AppendedData>  (only with Encoding::Appended)
//! </VTKFile>
//! ```
//!
//! with two spaces of indentation per level. `PolyData` pieces carry `NumberOfVerts`,
//! `NumberOfLines`, `NumberOfStrips` (always 0) and `NumberOfPolys` and a
//! `<Verts>`/`<Lines>`/`<Polys>` section (`connectivity`, `offsets`) for each kind present;
//! `ImageData` carries `WholeExtent`, `Origin` and `Spacing` and its piece an `Extent`,
//! and has no points or cells (the lattice defines them). VTK's readers find the sections
//! of a piece by name, so their order is free; the order above is the one always written.
//!
//! **Points and cells.** Points have three coordinates (`z = 0` for plane data). A cell
//! is the slice `connectivity[offsets[c−1]..offsets[c]]` (`offsets` holds end positions,
//! `offsets[−1] = 0`). A `VTK_POLYHEDRON` (42) additionally has its faces in the `faces`
//! stream — per cell the number of faces, then per face its node count and nodes — and
//! `faceoffsets`, the end position of each cell's part of `faces` (−1 for a cell that is
//! not a polyhedron). This is the layout ParaView 5.x and meshio read.
//!
//! **Data arrays.** `<DataArray type="Float64|Int32|Int64|UInt8" Name="…">` with
//! `NumberOfComponents` when it is not 1 (VTK's default; meshio reads an explicit 1 as an
//! `n × 1` array), optional `ComponentName0`, `ComponentName1`, … (ParaView shows them in
//! its component menus), and `NumberOfTuples`. Components are interleaved per tuple. How
//! ParaView reads the component count: 1 scalar, 3 vector, 6 symmetric tensor in the order
//! `XX YY ZZ XY YZ XZ`, 9 full tensor row-major `XX XY XZ YX YY YZ ZX ZY ZZ`; other counts
//! are shown component by component. [`component_names`] holds the usual names, also for
//! plane tensors (3 symmetric, 4 full components), which ParaView has no special view for.
//!
//! **Encodings** ([`Encoding`]):
//!
//! * `format="ascii"`: numbers as text, floats in Rust's shortest round-trip form (reading
//!   the text back gives the same bits), twelve numbers (whole tuples) per line;
//! * `format="binary"` (the default): inline base64 (RFC 4648 with `=` padding, one
//!   stream per array) of an 8-byte little-endian unsigned byte count (`header_type="UInt64"`)
//!   followed by the little-endian values;
//! * `format="appended" offset="…"`: the same count-and-values blocks, raw (not encoded),
//!   back to back after the `_` marker of `<AppendedData encoding="raw">`; `offset` is the
//!   position of an array's block counted from the byte after `_`.
//!
//! No compression is written.
//!
//! **Collections.** A `.pvd` file lists the data sets of a time series:
//! `<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">` with one
//! `<DataSet timestep="t" group="" part="0" file="relative/path"/>` per step.
//!
//! **Parallel pieces.** A `.pvtu` file ([`write_pvtu`]) names the `.vtu` pieces of one
//! data set (one per process of a distributed run) and declares their arrays.
//!
//! Attribute values and names are XML-escaped (`& < > " '`).

mod array;
mod atomic;
mod doc;
mod error;
mod image;
mod pimage;
mod poly;
mod pvd;
mod pvtu;
mod unstructured;

pub use array::{Attributes, DataArray, Encoding, Values, component_names};
pub use atomic::{write_atomic, write_atomic_via, write_atomic_with};
pub use error::VtkError;
pub use image::ImageData;
pub use pimage::{ImagePiece, PImageData};
pub use poly::{CellArray, PolyData};
pub use pvd::PvdWriter;
pub use pvtu::{pvtu_text, write_pvtu};
pub use unstructured::{CellType, Polyhedra, UnstructuredGrid};
