//! Mesh import and export: Gmsh 4.1 `.msh`, ASCII or binary (read), VTK XML `.vtu` (read
//! ASCII, base64, appended and zlib-compressed data; write through [`porofrac_vtk`]) and
//! ParaView `.pvd` time series (write).
//!
//! # Cells and face orientation
//!
//! The grid stores every cell as a set of *outward* face loops ([`crate::CellFaceLoops`]).
//! Gmsh and VTK store standard cells as node lists in a reference order; each shape has a
//! fixed table that turns the node list into outward loops:
//!
//! | shape | Gmsh / VTK type | outward faces (local node numbers) |
//! |---|---|---|
//! | triangle | 2 / 5 | polygon `0 1 2` (counter-clockwise) |
//! | quadrilateral | 3 / 9 | polygon `0 1 2 3` |
//! | tetrahedron | 4 / 10 | `0 2 1`, `0 1 3`, `0 3 2`, `1 2 3` |
//! | hexahedron | 5 / 12 | `0 3 2 1`, `4 5 6 7`, `0 1 5 4`, `1 2 6 5`, `2 3 7 6`, `0 4 7 3` |
//! | prism / wedge | 6 / 13 | `0 2 1`, `3 4 5`, `0 1 4 3`, `1 2 5 4`, `0 3 5 2` |
//! | pyramid | 7 / 14 | `0 3 2 1`, `0 1 4`, `1 2 4`, `2 3 4`, `3 0 4` |
//!
//! A tetrahedron is positively oriented when `(x₁ − x₀) × (x₂ − x₀) · (x₃ − x₀) > 0`;
//! a hexahedron, prism or pyramid when its first face (`0 1 2 …`) turns counter-clockwise
//! seen from the opposite face or apex. Gmsh and VTK agree on all these orders (VTK's wedge
//! has its parametric corners `(0,0,0), (1,0,0), (0,1,0)` at the bottom like Gmsh's prism;
//! VTK's own quality filter gives a negative volume for the mirrored order).
//! Elements are **never reoriented**:
//! an element with negative signed volume
//! `|K| = (1/D) Σ_facets a_f · (c_f − x̄)` (the divergence theorem over the outward loops,
//! the same facet split as the grid) is reported as an inverted cell, naming the file, the
//! cell (= element order among the cells) and the element's tag and line.
//!
//! # Nodes
//!
//! Nodes that no cell uses (geometry points, nodes of boundary-only elements) are dropped
//! and the rest renumbered compactly in file order. A 2D mesh must lie in a plane
//! `z = const`.
//!
//! # Reading Gmsh files
//!
//! [`read_msh`](crate::io::read_msh) reads MSH 4.1 files, ASCII (`$MeshFormat` line
//! `4.1 0 8`) or binary (`4.1 1 8`). Sections read: `$MeshFormat`, `$PhysicalNames`,
//! `$Entities` (entity → physical groups), `$Nodes` and `$Elements` (entity blocks).
//! Other sections (`$Periodic`, `$NodeData`, …) are skipped; `$PartitionedEntities` and
//! `$Parametrizations` are refused.
//!
//! * Cells are the elements of dimension `D`: triangles (2) and quadrangles (3) in 2D;
//!   tetrahedra (4), hexahedra (5), prisms (6) and pyramids (7) in 3D, in file order.
//! * A physical group of dimension `D` becomes a cell tag, named by `$PhysicalNames` or
//!   `physical_<tag>`. A physical group of dimension `D − 1` (lines in 2D, triangles and
//!   quadrangles in 3D) becomes a face tag: each of its elements is matched to the grid
//!   face with the same node set.
//! * Points (15), and lines (1) in 3D, are accepted and ignored. Any other element type
//!   (second order, …) is an error naming the line and the type.
//!
//! A binary file differs from an ASCII one only in the data of `$Entities`, `$Nodes` and
//! `$Elements`: section headers, `$End…` lines, `$MeshFormat` and `$PhysicalNames` stay
//! text. The line `4.1 1 8` is followed by the integer 1 in 4 binary bytes and a newline;
//! it gives the byte order of every binary number (Gmsh writes the machine's; both orders
//! are read). The binary data hold the numbers of the ASCII lines in the same order, back
//! to back, as `int` (4-byte signed), `size_t` (8-byte unsigned: data size 8) and `double`
//! (8-byte IEEE), and end with a newline before `$End…`:
//!
//! | section | binary data |
//! |---|---|
//! | `$Entities` | `numPoints numCurves numSurfaces numVolumes` (`size_t`); per point `tag` (`int`), `x y z` (`double`), `numPhysicalTags` (`size_t`), the physical tags (`int`); per curve, surface and volume `tag` (`int`), `minX minY minZ maxX maxY maxZ` (`double`), `numPhysicalTags` (`size_t`), the physical tags (`int`), `numBoundingEntities` (`size_t`), the bounding entity tags (`int`) |
//! | `$Nodes` | `numEntityBlocks numNodes minNodeTag maxNodeTag` (`size_t`); per block `entityDim entityTag parametric` (`int`) and `numNodesInBlock` (`size_t`), the block's node tags (`size_t`), then per node `x y z`, and `entityDim` parametric coordinates if `parametric` is 1 (`double`) |
//! | `$Elements` | `numEntityBlocks numElements minElementTag maxElementTag` (`size_t`); per block `entityDim entityTag elementType` (`int`) and `numElementsInBlock` (`size_t`), then per element its tag and its node tags (`size_t`) |
//!
//! Physical groups become tags exactly as in an ASCII file, and a mesh saved both ways
//! gives the same grid bit for bit. Every count (entities, blocks, nodes, elements,
//! physical tags) is checked against the bytes left in the file before anything is
//! allocated for it. Errors in ASCII data give the line; errors in binary data give the
//! line of the section header, the section and the byte offset
//! (`mesh.msh:21: $Nodes (binary data, byte 3247): …`). Cells and nodes read from binary
//! data are named by their Gmsh tag only.
//!
//! # Reading VTK files
//!
//! [`read_vtu`](crate::io::read_vtu) reads `VTK_TRIANGLE` (5), `VTK_QUAD` (9) and `VTK_POLYGON` (7) cells in 2D,
//! `VTK_TETRA` (10), `VTK_HEXAHEDRON` (12), `VTK_WEDGE` (13), `VTK_PYRAMID` (14) and
//! `VTK_POLYHEDRON` (42) cells in 3D, from one `<Piece>`. Cell tags come from the
//! `tag:<name>` cell-data arrays, or, if there are none, from an integer `tag` array as
//! `tag_<value>`; face tags from `facetag:<name>` field data.
//!
//! Data arrays may be stored in any of the ways VTK writes them, which covers ParaView's
//! default save (appended raw data compressed with zlib):
//!
//! * `format="ascii"`: numbers as text;
//! * `format="binary"`: a binary block (below) encoded inline as base64. VTK encodes the
//!   header and the data as one base64 stream, or, when compressed, as two streams back to
//!   back; both are read;
//! * `format="appended"` with `offset="…"`: the binary block lies in the file's
//!   `<AppendedData encoding="raw">` (the bytes after its `_` marker; `offset` counts
//!   bytes from the one after `_`) or `<AppendedData encoding="base64">` (`offset` counts
//!   base64 characters after `_`, and each array is its own base64 text).
//!
//! A binary block is made of integers of the file's `header_type` (`UInt32`, the
//! default, or `UInt64`) followed by data, all in the file's `byte_order`
//! (`LittleEndian` or `BigEndian`):
//!
//! * without compression: one integer, the number of data bytes, then the data;
//! * with `compressor="vtkZLibDataCompressor"`: the header
//!   `[nblocks, block_size, last_block_size, csize_0, …, csize_{nblocks−1}]`, then the
//!   `nblocks` zlib streams of `csize_k` bytes each, back to back. The data was cut into
//!   blocks of `block_size` bytes before compression; the last block has
//!   `last_block_size` bytes, or `block_size` when `last_block_size` is 0. An empty array
//!   has `nblocks = 0`.
//!
//! Other compressors (`vtkLZ4DataCompressor`, `vtkLZMADataCompressor`) are refused.
//! Every size in a header is checked against the bytes actually present before a buffer
//! is allocated: a size or block count larger than the data, an offset past the appended
//! data, a block that cannot inflate to its declared size (zlib inflates at most
//! 1032-fold), a corrupt zlib stream, or an array whose size disagrees with
//! `NumberOfPoints` / `NumberOfCells` is a [`GridError::Parse`] naming the file, the line
//! of the `<DataArray>`, the array, where its data is, and what is wrong. A file that ends
//! inside `<AppendedData>` is read up to the first array it cuts, and the error says the
//! file looks cut short.
//!
//! # Errors
//!
//! A missing or unreadable file is [`GridError::Io`] with its path; a malformed file is
//! [`GridError::Parse`] with the 1-based line (and, as above, the array or section); a well-formed file whose grid is invalid
//! (degenerate or inverted cells, non-matching faces) is [`GridError::InFile`] wrapping the
//! grid error, whose cell index is the cell's position among the file's cells.

mod base64;
mod gmsh;
pub mod grdecl;
mod pvd;
mod vtu;
mod vtu_write;
mod xml;

pub use gmsh::{parse_msh, parse_msh_bytes, read_msh};
pub use grdecl::{read_grdecl, read_grdecl_with};
pub use pvd::PvdWriter;
pub use vtu::read_vtu;
pub use vtu_write::{Encoding, Field, kelvin_to_vtk_sym, write_vtu, write_vtu_with};

use std::fs;
use std::path::Path;

use crate::builder::CellFaceLoops;
use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::point::{Point, for_each_facet};

/// First-order element shapes shared by Gmsh and VTK.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Shape {
    Triangle,
    Quad,
    Tetra,
    Hexa,
    /// Gmsh prism and VTK wedge: `0 1 2` counter-clockwise seen from `3 4 5`.
    Prism,
    Pyramid,
}

impl Shape {
    pub(crate) fn num_nodes(self) -> usize {
        match self {
            Shape::Triangle => 3,
            Shape::Quad | Shape::Tetra => 4,
            Shape::Pyramid => 5,
            Shape::Prism => 6,
            Shape::Hexa => 8,
        }
    }
    pub(crate) fn dim(self) -> usize {
        match self {
            Shape::Triangle | Shape::Quad => 2,
            _ => 3,
        }
    }
    pub(crate) fn name(self) -> &'static str {
        match self {
            Shape::Triangle => "triangle",
            Shape::Quad => "quadrilateral",
            Shape::Tetra => "tetrahedron",
            Shape::Hexa => "hexahedron",
            Shape::Prism => "prism",
            Shape::Pyramid => "pyramid",
        }
    }
    /// Outward face loops in local node numbers (3D shapes only).
    fn faces(self) -> &'static [&'static [usize]] {
        match self {
            Shape::Triangle | Shape::Quad => &[],
            Shape::Tetra => &[&[0, 2, 1], &[0, 1, 3], &[0, 3, 2], &[1, 2, 3]],
            Shape::Hexa => &[
                &[0, 3, 2, 1],
                &[4, 5, 6, 7],
                &[0, 1, 5, 4],
                &[1, 2, 6, 5],
                &[2, 3, 7, 6],
                &[0, 4, 7, 3],
            ],
            Shape::Prism => &[
                &[0, 2, 1],
                &[3, 4, 5],
                &[0, 1, 4, 3],
                &[1, 2, 5, 4],
                &[0, 3, 5, 2],
            ],
            Shape::Pyramid => &[
                &[0, 3, 2, 1],
                &[0, 1, 4],
                &[1, 2, 4],
                &[2, 3, 4],
                &[3, 0, 4],
            ],
        }
    }
    /// Append the cell with global node numbers `v` (in the shape's reference order).
    pub(crate) fn push(self, loops: &mut CellFaceLoops, v: &[usize]) {
        debug_assert_eq!(v.len(), self.num_nodes());
        if self.dim() == 2 {
            loops.push_polygon(v);
            return;
        }
        let mut buf = [0usize; 4];
        for f in self.faces() {
            for (k, &l) in f.iter().enumerate() {
                buf[k] = v[l];
            }
            loops.push_face(&buf[..f.len()]);
        }
        loops.finish_cell();
    }
}

/// Where a cell came from, for error messages.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Origin {
    /// 1-based line of the element (Gmsh) or of the cell arrays (VTK); 0 in binary data.
    pub line: usize,
    /// Element tag (Gmsh) or cell index (VTK).
    pub tag: u64,
    /// Whether the cell is a standard shape (orientation check applies).
    pub standard: bool,
}

/// A mesh as read from a file, before validation.
pub(crate) struct RawMesh<const D: usize> {
    /// All nodes in file order.
    pub nodes: Vec<Point<D>>,
    /// File label (Gmsh tag or VTK point index) and line of each node (0 in binary data).
    pub node_label: Vec<(u64, usize)>,
    /// Cells as outward loops in `nodes` numbering.
    pub loops: CellFaceLoops,
    /// One per cell.
    pub origin: Vec<Origin>,
    /// `"Gmsh element"` or `"VTK cell"`.
    pub what_cell: &'static str,
    /// `"Gmsh node"` or `"VTK point"`.
    pub what_node: &'static str,
}

/// The validated grid and the map from file node index to grid node (`usize::MAX` if the
/// node was dropped).
pub(crate) struct Built<const D: usize> {
    pub grid: Grid<D>,
    pub node_map: Vec<usize>,
}

impl<const D: usize> RawMesh<D> {
    /// Drop unused nodes, build and validate the grid; errors are wrapped in
    /// [`GridError::InFile`] and name the element.
    pub(crate) fn build(mut self, path: &Path) -> Result<Built<D>> {
        let in_file = |e: GridError| GridError::InFile {
            path: path.to_path_buf(),
            source: Box::new(e),
        };
        if self.loops.num_cells() == 0 {
            return Err(in_file(GridError::Input(format!(
                "the file has no {D}D cells"
            ))));
        }
        let mut node_map = vec![usize::MAX; self.nodes.len()];
        for &n in &self.loops.loop_nodes {
            node_map[n] = 0;
        }
        let mut kept = Vec::with_capacity(self.nodes.len());
        let mut labels = Vec::with_capacity(self.nodes.len());
        for (n, m) in node_map.iter_mut().enumerate() {
            if *m == 0 {
                *m = kept.len();
                kept.push(self.nodes[n]);
                labels.push(self.node_label[n]);
            }
        }
        for n in &mut self.loops.loop_nodes {
            *n = node_map[*n];
        }
        match Grid::from_cell_faces(kept, &self.loops) {
            Ok(grid) => match overlapping_cell(&grid) {
                Some((c, times)) => Err(in_file(GridError::Cell {
                    cell: c,
                    what: format!(
                        "overlaps other cells: next to its boundary side the mesh covers the \
                         plane {times} times, not once ({}), the {} cell of the file; the \
                         connectivity folds the mesh over itself",
                        self.describe(c),
                        ordinal(c + 1)
                    ),
                })),
                None => Ok(Built { grid, node_map }),
            },
            Err(e) => {
                // Prefer the precise diagnosis of an inverted standard element.
                let nodes: Vec<Point<D>> = compact_nodes(&self.nodes, &node_map, labels.len());
                for c in 0..self.loops.num_cells() {
                    if !self.origin[c].standard {
                        continue;
                    }
                    let (vol, size) = signed_volume(&nodes, &self.loops, c);
                    if vol < -1e-13 * size.powi(D as i32) {
                        return Err(in_file(GridError::Cell {
                            cell: c,
                            what: format!(
                                "inverted element: signed volume {vol:e} < 0 ({}), the {} cell \
                                 of the file; elements are not reoriented, fix the node order in \
                                 the mesh",
                                self.describe(c),
                                ordinal(c + 1)
                            ),
                        }));
                    }
                }
                Err(in_file(match e {
                    GridError::Cell { cell, what } if cell < self.origin.len() => GridError::Cell {
                        cell,
                        what: format!("{what} ({})", self.describe(cell)),
                    },
                    GridError::Node { node, what } if node < labels.len() => GridError::Node {
                        node,
                        what: format!(
                            "{what} ({} {}{})",
                            self.what_node,
                            labels[node].0,
                            at_line(labels[node].1)
                        ),
                    },
                    other => other,
                }))
            }
        }
    }

    fn describe(&self, c: usize) -> String {
        let o = self.origin[c];
        format!("{} {}{}", self.what_cell, o.tag, at_line(o.line))
    }
}

/// `1st`, `2nd`, `3rd`, `4th`, … (`11th`, `12th`, `13th`).
fn ordinal(n: usize) -> String {
    let suffix = match (n % 10, n % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

/// In 2D, a cell of a mesh that overlaps itself, and how many times the plane is covered
/// next to one of its boundary sides; `None` in 3D or when the cells do not overlap.
///
/// Every cell is positively oriented and every interior side is shared by two cells that
/// traverse it in opposite directions (the grid checks both), so the number of cells
/// covering a point equals the winding number about it of the boundary sides, each
/// traversed as its cell traverses it. Crossing a boundary side inwards raises that number
/// by one; where cells overlap it is 2 or more, and such a region is bounded by boundary
/// sides. So the mesh overlaps itself if and only if, just inside some boundary side (at
/// its midpoint moved into its cell by a thousandth of its length), the winding number
/// is not 1. The winding number is counted along a ray in +x through the boundary sides
/// that share its horizontal strip (`√B` strips for `B` boundary sides). The cell
/// reported is the first (lowest index) whose boundary side fails.
fn overlapping_cell<const D: usize>(grid: &Grid<D>) -> Option<(usize, i64)> {
    if D != 2 {
        return None;
    }
    // Boundary sides, each with its cell on the left.
    let mut sides: Vec<([f64; 2], [f64; 2], usize)> = Vec::new();
    for f in 0..grid.num_faces() {
        if !grid.is_boundary_face(f) {
            continue;
        }
        let l = grid.face_nodes(f);
        let (c, _) = grid.face_cells(f);
        // The normal points out of the cell: the cell is on the left of a → b when the
        // normal is on the right, (dy, −dx).
        let (a, b, n) = (grid.node(l[0]), grid.node(l[1]), grid.face_normal(f));
        let right = n[0] * (b[1] - a[1]) - n[1] * (b[0] - a[0]);
        let (a, b) = ([a[0], a[1]], [b[0], b[1]]);
        sides.push(if right >= 0.0 { (a, b, c) } else { (b, a, c) });
    }
    if sides.is_empty() {
        return None;
    }
    let (lo, hi) = sides
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s.0[1]).min(s.1[1]), hi.max(s.0[1]).max(s.1[1]))
        });
    let strips = (sides.len() as f64).sqrt().ceil().max(1.0) as usize;
    let height = (hi - lo).max(f64::MIN_POSITIVE);
    let strip_of = |y: f64| (((y - lo) / height * strips as f64) as usize).min(strips - 1);
    let mut in_strip: Vec<Vec<u32>> = vec![Vec::new(); strips];
    for (i, s) in sides.iter().enumerate() {
        let (y0, y1) = (s.0[1].min(s.1[1]), s.0[1].max(s.1[1]));
        for strip in &mut in_strip[strip_of(y0)..=strip_of(y1)] {
            strip.push(i as u32);
        }
    }
    let winding = |q: [f64; 2]| -> i64 {
        let mut w = 0;
        for &i in &in_strip[strip_of(q[1])] {
            let (a, b, _) = sides[i as usize];
            let up = a[1] <= q[1] && q[1] < b[1];
            let down = b[1] <= q[1] && q[1] < a[1];
            if up || down {
                let x = a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > q[0] {
                    w += if up { 1 } else { -1 };
                }
            }
        }
        w
    };
    let mut worst: Option<(usize, i64)> = None;
    for &(a, b, c) in &sides {
        if worst.is_some_and(|(w, _)| w <= c) {
            continue;
        }
        // A thousandth of the side's length to its left, into its cell.
        let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        let q = [m[0] - 1e-3 * (b[1] - a[1]), m[1] + 1e-3 * (b[0] - a[0])];
        let w = winding(q);
        if w != 1 {
            worst = Some((c, w));
        }
    }
    worst
}

/// `", line N"`, or nothing for line 0 (binary data has no lines).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(", line {line}")
    }
}

fn compact_nodes<const D: usize>(
    all: &[Point<D>],
    node_map: &[usize],
    kept: usize,
) -> Vec<Point<D>> {
    let mut out = vec![Point::<D>::zeros(); kept];
    for (n, &m) in node_map.iter().enumerate() {
        if m != usize::MAX {
            out[m] = all[n];
        }
    }
    out
}

/// Signed volume of cell `c` from its loops, and its bounding-box size.
fn signed_volume<const D: usize>(
    nodes: &[Point<D>],
    loops: &CellFaceLoops,
    c: usize,
) -> (f64, f64) {
    let ls = loops.cell_pos[c]..loops.cell_pos[c + 1];
    let all = &loops.loop_nodes[loops.loop_pos[ls.start]..loops.loop_pos[ls.end]];
    let xc = all.iter().map(|&n| nodes[n]).sum::<Point<D>>() / all.len() as f64;
    let mut lo = Point::<D>::repeat(f64::INFINITY);
    let mut hi = Point::<D>::repeat(f64::NEG_INFINITY);
    for &n in all {
        lo = lo.inf(&nodes[n]);
        hi = hi.sup(&nodes[n]);
    }
    let mut vol = 0.0;
    // Only called on the error path: a plain buffer is fine.
    let mut pts: Vec<Point<D>> = Vec::new();
    for k in ls {
        let l = &loops.loop_nodes[loops.loop_pos[k]..loops.loop_pos[k + 1]];
        pts.clear();
        pts.extend(l.iter().map(|&n| nodes[n]));
        for_each_facet::<D>(&pts, |a, ct, _| vol += a.dot(&(ct - xc)) / D as f64);
    }
    (vol, (hi - lo).amax())
}

/// Largest mesh file read (bytes).
pub const MAX_MESH_FILE_BYTES: u64 = 8 << 30;

/// Read a whole mesh file, mapping failures to [`GridError::Io`] with the path. Only a
/// regular file is read (not a directory, a device such as `/dev/zero` or a pipe), of at
/// most [`MAX_MESH_FILE_BYTES`] bytes: no more than that plus one byte is ever read, and
/// a buffer that cannot be allocated is an error, not an abort.
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read as _;
    let io = |source| GridError::Io {
        path: path.to_path_buf(),
        source,
    };
    let refuse = |what: String| io(std::io::Error::new(std::io::ErrorKind::InvalidInput, what));
    let meta = fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(refuse(
            "not a regular file (a directory, device or pipe); a mesh must be one".into(),
        ));
    }
    let too_big = |n: u64| {
        refuse(format!(
            "the file has {n} bytes or more, more than the {MAX_MESH_FILE_BYTES} a mesh file \
             may have"
        ))
    };
    if meta.len() > MAX_MESH_FILE_BYTES {
        return Err(too_big(meta.len()));
    }
    let mut bytes = Vec::new();
    bytes.try_reserve_exact(meta.len() as usize).map_err(|_| {
        refuse(format!(
            "cannot allocate {} bytes to read the file: not enough memory",
            meta.len()
        ))
    })?;
    fs::File::open(path)
        .map_err(io)?
        .take(MAX_MESH_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_MESH_FILE_BYTES {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Write an ASCII `.vtu` of triangles and quadrilaterals (by their node count).
    fn vtu(dir: &Path, name: &str, pts: &[[f64; 2]], cells: &[&[usize]]) -> std::path::PathBuf {
        let p: Vec<String> = pts.iter().map(|q| format!("{} {} 0", q[0], q[1])).collect();
        let conn: Vec<String> = cells
            .iter()
            .flat_map(|c| c.iter())
            .map(|n| n.to_string())
            .collect();
        let mut off = 0;
        let offsets: Vec<String> = cells
            .iter()
            .map(|c| {
                off += c.len();
                off.to_string()
            })
            .collect();
        let types: Vec<&str> = cells
            .iter()
            .map(|c| if c.len() == 3 { "5" } else { "9" })
            .collect();
        let text = format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" \
             byte_order=\"LittleEndian\">\n<UnstructuredGrid><Piece NumberOfPoints=\"{}\" \
             NumberOfCells=\"{}\">\n<Points><DataArray type=\"Float64\" \
             NumberOfComponents=\"3\" format=\"ascii\">{}</DataArray></Points>\n<Cells>\
             <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">{}</DataArray>\n\
             <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">{}</DataArray>\n\
             <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">{}</DataArray></Cells>\n\
             </Piece></UnstructuredGrid></VTKFile>\n",
            pts.len(),
            cells.len(),
            p.join(" "),
            conn.join(" "),
            offsets.join(" "),
            types.join(" ")
        );
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    fn dir(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("porofrac_io_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// Overlapping cells whose orientations are all consistent are refused naming the
    /// first cell next to the overlap (1-based in the message) and the covering count;
    /// valid meshes, with a hole too, pass; an inverted cell is named 1-based.
    #[test]
    fn overlapping_and_inverted_cells_are_refused() {
        let d = dir("overlap");
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        // A triangle lying inside the square, with its own nodes (its base on y = 0.2).
        let mut pts = sq.to_vec();
        pts.extend([[0.2, 0.2], [0.6, 0.2], [0.2, 0.6]]);
        let p = vtu(&d, "over.vtu", &pts, &[&[0, 1, 2], &[0, 2, 3], &[4, 5, 6]]);
        let e = read_vtu::<2>(&p).unwrap_err().to_string();
        assert!(
            e.contains("cell 2: overlaps other cells")
                && e.contains("covers the plane 2 times")
                && e.contains("the 3rd cell of the file"),
            "{e}"
        );
        // The same triangle listed first: it is the first bad cell.
        let p = vtu(&d, "over2.vtu", &pts, &[&[4, 5, 6], &[0, 1, 2], &[0, 2, 3]]);
        let e = read_vtu::<2>(&p).unwrap_err().to_string();
        assert!(
            e.contains("cell 0: overlaps other cells") && e.contains("the 1st cell"),
            "{e}"
        );
        // Two squares overlapping in a corner, on nodes of their own: the first one's
        // right side runs inside the second.
        let mut pts = sq.to_vec();
        pts.extend(sq.map(|[x, y]| [x + 0.3, y + 0.4]));
        let p = vtu(&d, "two.vtu", &pts, &[&[0, 1, 2, 3], &[4, 5, 6, 7]]);
        let e = read_vtu::<2>(&p).unwrap_err().to_string();
        assert!(
            e.contains("cell 0: overlaps") && e.contains("covers the plane 2 times"),
            "{e}"
        );
        // Valid: the square in two triangles; a 3 × 3 block of squares without its centre.
        let p = vtu(&d, "ok.vtu", &sq, &[&[0, 1, 2], &[0, 2, 3]]);
        let g = read_vtu::<2>(&p).unwrap();
        assert!((g.cell_volumes().iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let pts: Vec<[f64; 2]> = (0..16).map(|k| [(k % 4) as f64, (k / 4) as f64]).collect();
        let quads: Vec<[usize; 4]> = (0..9)
            .filter(|&k| k != 4)
            .map(|k| {
                let (i, j) = (k % 3, k / 3);
                let n = j * 4 + i;
                [n, n + 1, n + 5, n + 4]
            })
            .collect();
        let refs: Vec<&[usize]> = quads.iter().map(|q| &q[..]).collect();
        let p = vtu(&d, "hole.vtu", &pts, &refs);
        let g = read_vtu::<2>(&p).unwrap();
        assert!((g.cell_volumes().iter().sum::<f64>() - 8.0).abs() < 1e-12);
        // Inverted: the second cell, named 1-based too.
        let p = vtu(&d, "inv.vtu", &sq, &[&[0, 1, 2], &[0, 3, 2]]);
        let e = read_vtu::<2>(&p).unwrap_err().to_string();
        assert!(
            e.contains("inverted element") && e.contains("the 2nd cell of the file"),
            "{e}"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn ordinals() {
        let v: Vec<String> = [1, 2, 3, 4, 11, 12, 13, 21, 22, 101, 111]
            .map(ordinal)
            .to_vec();
        assert_eq!(
            v,
            [
                "1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd", "101st",
                "111th"
            ]
        );
    }

    /// Devices and folders are not read; a regular file is read whole.
    #[test]
    fn only_regular_files_are_read() {
        for p in ["/dev/zero", "/"] {
            if Path::new(p).exists() {
                let e = read_file(Path::new(p)).unwrap_err().to_string();
                assert!(e.contains("not a regular file"), "{e}");
            }
        }
        let d = dir("read");
        std::fs::write(d.join("a.msh"), b"abc").unwrap();
        assert_eq!(read_file(&d.join("a.msh")).unwrap(), b"abc");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
