//! VTK XML UnstructuredGrid (`.vtu`) writer and reader.
//!
//! # Writing
//!
//! * 2D cells are `VTK_POLYGON` (7) with the counter-clockwise [`Grid::cell_nodes`] and
//!   points at `z = 0`. 3D cells are `VTK_POLYHEDRON` (42) with the `faces` / `faceoffsets`
//!   arrays (the layout ParaView 5.x and meshio read): per cell the number of faces, then
//!   for each face its node count and nodes, in the cell's outward order. A face seen from
//!   its second cell is written reversed and rotated so that reading the file back gives
//!   the same cell node order, hence the identical grid (`read(write(g)) == g`).
//! * Tags. For every cell tag an `Int32` cell-data array `tag:<name>` holding 1 on the
//!   tagged cells and 0 elsewhere (names are exact, tags may overlap), and one plain `tag`
//!   array: the 1-based position (in name order) of the last tag holding the cell, 0 for
//!   none (for colouring in ParaView). Face tags, which VTK cannot attach to polyhedron
//!   faces, go to the grid's `FieldData` as `Int64` arrays `facetag:<name>` of face
//!   indices; the reader rebuilds the same face numbering, so they round-trip exactly.
//!   The names `tag` and `tag:…` are reserved in cell data.
//! * Data: [`Field`] scalars, vectors (3 components, z = 0 in 2D), symmetric tensors
//!   (written as 9 components, row-major, which ParaView shows as a tensor) and `Int32`
//!   arrays. [`Encoding::Base64`] (default; inline binary, `header_type="UInt64"`,
//!   little-endian, no compression) or [`Encoding::Ascii`] (floats in Rust's shortest
//!   round-trip form, so both encodings are bit-exact).
//! * The file is written atomically (temporary file in the same directory, then rename).
//!
//! # Reading
//!
//! `VTK_TRIANGLE` (5), `VTK_QUAD` (9), `VTK_POLYGON` (7) in 2D (all points at one `z`);
//! `VTK_TETRA` (10), `VTK_HEXAHEDRON` (12), `VTK_WEDGE` (13), `VTK_PYRAMID` (14),
//! `VTK_POLYHEDRON` (42) in 3D. ASCII or inline base64 data (`UInt32`/`UInt64` headers,
//! either byte order); compressed or appended data are refused. Cell tags come from the
//! `tag:<name>` arrays, or, if there are none, from an integer `tag` array as
//! `tag_<value>`; face tags from `facetag:<name>` field data.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use crate::builder::CellFaceLoops;
use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::io::xml::{self, Element, LineIndex};
use crate::io::{Origin, RawMesh, Shape, base64, read_file, write_atomic, xml_escape};
use crate::point::{Point, assert_dim};

/// A data array to write, borrowed from the caller. Lengths must equal the number of
/// points (point data) or cells (cell data).
#[derive(Clone, Copy, Debug)]
pub enum Field<'a, const D: usize> {
    /// One value per entity.
    Scalars(&'a [f64]),
    /// One vector per entity, written with 3 components (z = 0 in 2D).
    Vectors(&'a [Point<D>]),
    /// One symmetric tensor per entity as `[xx, yy, zz, xy, yz, xz]` (plain components,
    /// not Kelvin-scaled; see [`kelvin_to_vtk_sym`]), written as 9 components row-major.
    SymTensors(&'a [[f64; 6]]),
    /// One integer per entity (`Int32`).
    Ints(&'a [i32]),
}

impl<const D: usize> Field<'_, D> {
    fn len(&self) -> usize {
        match self {
            Field::Scalars(v) => v.len(),
            Field::Vectors(v) => v.len(),
            Field::SymTensors(v) => v.len(),
            Field::Ints(v) => v.len(),
        }
    }
}

/// Convert a Kelvin vector (2D `[a11, a22, √2 a12]`, 3D
/// `[a11, a22, a33, √2 a23, √2 a13, √2 a12]`) to VTK's symmetric order
/// `[xx, yy, zz, xy, yz, xz]`. Returns `None` for any other length.
pub fn kelvin_to_vtk_sym(k: &[f64]) -> Option<[f64; 6]> {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    match k.len() {
        3 => Some([k[0], k[1], 0.0, k[2] * s, 0.0, 0.0]),
        6 => Some([k[0], k[1], k[2], k[5] * s, k[3] * s, k[4] * s]),
        _ => None,
    }
}

/// How data arrays are encoded in the file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// Text; floats in shortest round-trip form.
    Ascii,
    /// Inline base64 of little-endian binary with a `UInt64` byte-count header.
    #[default]
    Base64,
}

trait Scalar: Copy {
    const VTK: &'static str;
    const SIZE: usize;
    fn put_le(self, out: &mut Vec<u8>);
    fn put_text(self, out: &mut String);
}

macro_rules! scalar {
    ($t:ty, $name:literal, $fmt:literal) => {
        impl Scalar for $t {
            const VTK: &'static str = $name;
            const SIZE: usize = std::mem::size_of::<$t>();
            fn put_le(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            fn put_text(self, out: &mut String) {
                let _ = write!(out, $fmt, self);
            }
        }
    };
}
scalar!(f64, "Float64", "{:?}");
scalar!(i32, "Int32", "{}");
scalar!(i64, "Int64", "{}");
scalar!(u8, "UInt8", "{}");

fn data_array<T: Scalar>(
    out: &mut String,
    enc: Encoding,
    indent: &str,
    name: &str,
    ncomp: usize,
    values: &[T],
    bytes: &mut Vec<u8>,
) {
    let _ = write!(out, "{indent}<DataArray type=\"{}\" Name=\"", T::VTK);
    xml_escape(name, out);
    out.push('"');
    // One component is VTK's default; meshio reads an explicit 1 as an n × 1 array.
    if ncomp != 1 {
        let _ = write!(out, " NumberOfComponents=\"{ncomp}\"");
    }
    if ncomp > 0 && values.len() % ncomp == 0 {
        let _ = write!(out, " NumberOfTuples=\"{}\"", values.len() / ncomp);
    }
    match enc {
        Encoding::Ascii => {
            out.push_str(" format=\"ascii\">\n");
            let per_line = (12 / ncomp.max(1)).max(1) * ncomp.max(1);
            for (k, chunk) in values.chunks(per_line).enumerate() {
                let _ = k;
                out.push_str(indent);
                out.push_str("  ");
                for (i, &v) in chunk.iter().enumerate() {
                    if i > 0 {
                        out.push(' ');
                    }
                    v.put_text(out);
                }
                out.push('\n');
            }
        }
        Encoding::Base64 => {
            out.push_str(" format=\"binary\">\n");
            bytes.clear();
            bytes.extend_from_slice(&((values.len() * T::SIZE) as u64).to_le_bytes());
            for &v in values {
                v.put_le(bytes);
            }
            out.push_str(indent);
            out.push_str("  ");
            base64::encode_into(bytes, out);
            out.push('\n');
        }
    }
    let _ = writeln!(out, "{indent}</DataArray>");
}

fn write_field<const D: usize>(
    out: &mut String,
    enc: Encoding,
    name: &str,
    field: &Field<'_, D>,
    bytes: &mut Vec<u8>,
) {
    const IND: &str = "        ";
    match field {
        Field::Scalars(v) => data_array(out, enc, IND, name, 1, v, bytes),
        Field::Ints(v) => data_array(out, enc, IND, name, 1, v, bytes),
        Field::Vectors(v) => {
            let flat: Vec<f64> = v
                .iter()
                .flat_map(|p| (0..3).map(move |a| if a < D { p[a] } else { 0.0 }))
                .collect();
            data_array(out, enc, IND, name, 3, &flat, bytes);
        }
        Field::SymTensors(v) => {
            let flat: Vec<f64> = v
                .iter()
                .flat_map(|t| {
                    let [xx, yy, zz, xy, yz, xz] = *t;
                    [xx, xy, xz, xy, yy, yz, xz, yz, zz]
                })
                .collect();
            data_array(out, enc, IND, name, 9, &flat, bytes);
        }
    }
}

/// Write `grid` with point and cell data to a `.vtu` file (inline base64 binary; see the
/// module docs for the layout and the tag arrays).
pub fn write_vtu<const D: usize>(
    path: impl AsRef<Path>,
    grid: &Grid<D>,
    point_data: &[(&str, Field<'_, D>)],
    cell_data: &[(&str, Field<'_, D>)],
) -> Result<()> {
    write_vtu_with(path, grid, point_data, cell_data, Encoding::Base64)
}

/// [`write_vtu`] with a chosen data [`Encoding`].
pub fn write_vtu_with<const D: usize>(
    path: impl AsRef<Path>,
    grid: &Grid<D>,
    point_data: &[(&str, Field<'_, D>)],
    cell_data: &[(&str, Field<'_, D>)],
    enc: Encoding,
) -> Result<()> {
    const { assert_dim::<D>() };
    let text = vtu_text(grid, point_data, cell_data, enc)?;
    write_atomic(path.as_ref(), text.as_bytes())
}

fn check_fields<const D: usize>(
    fields: &[(&str, Field<'_, D>)],
    n: usize,
    what: &str,
    reserve_tags: bool,
) -> Result<()> {
    for (k, (name, f)) in fields.iter().enumerate() {
        if name.is_empty() {
            return Err(GridError::Input(format!(
                "{what} array {k} has an empty name"
            )));
        }
        if fields[..k].iter().any(|(m, _)| m == name) {
            return Err(GridError::Input(format!(
                "{what} array `{name}` given twice"
            )));
        }
        if reserve_tags && (*name == "tag" || name.starts_with("tag:")) {
            return Err(GridError::Input(format!(
                "{what} array name `{name}` is reserved for cell tags"
            )));
        }
        if f.len() != n {
            return Err(GridError::Input(format!(
                "{what} array `{name}` has {} values, expected {n}",
                f.len()
            )));
        }
    }
    Ok(())
}

fn vtu_text<const D: usize>(
    grid: &Grid<D>,
    point_data: &[(&str, Field<'_, D>)],
    cell_data: &[(&str, Field<'_, D>)],
    enc: Encoding,
) -> Result<String> {
    check_fields(point_data, grid.num_nodes(), "point data", false)?;
    check_fields(cell_data, grid.num_cells(), "cell data", true)?;
    let nc = grid.num_cells();
    let mut out = String::new();
    let mut bytes = Vec::new();
    out.push_str(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
         byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n",
    );
    let edge_order = if D == 2 { edge_order(grid) } else { None };
    if !grid.face_tags().is_empty() || edge_order.is_some() {
        out.push_str("    <FieldData>\n");
        for (name, faces) in grid.face_tags() {
            let v: Vec<i64> = faces.iter().map(|&f| f as i64).collect();
            data_array(
                &mut out,
                enc,
                "      ",
                &format!("facetag:{name}"),
                1,
                &v,
                &mut bytes,
            );
        }
        if let Some(v) = &edge_order {
            data_array(&mut out, enc, "      ", EDGE_ORDER, 1, v, &mut bytes);
        }
        out.push_str("    </FieldData>\n");
    }
    let _ = writeln!(
        out,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{nc}\">",
        grid.num_nodes()
    );
    out.push_str("      <PointData>\n");
    for (name, f) in point_data {
        write_field(&mut out, enc, name, f, &mut bytes);
    }
    out.push_str("      </PointData>\n      <CellData>\n");
    if !grid.cell_tags().is_empty() {
        let mut plain = vec![0i32; nc];
        let mut one = vec![0i32; nc];
        let mut per_tag = Vec::new();
        for (k, (name, cells)) in grid.cell_tags().iter().enumerate() {
            one.iter_mut().for_each(|x| *x = 0);
            for &c in cells {
                one[c] = 1;
                plain[c] = k as i32 + 1;
            }
            per_tag.push((format!("tag:{name}"), one.clone()));
        }
        write_field(&mut out, enc, "tag", &Field::<D>::Ints(&plain), &mut bytes);
        for (name, v) in &per_tag {
            write_field(&mut out, enc, name, &Field::<D>::Ints(v), &mut bytes);
        }
    }
    for (name, f) in cell_data {
        write_field(&mut out, enc, name, f, &mut bytes);
    }
    out.push_str("      </CellData>\n      <Points>\n");
    let pts: Vec<f64> = grid
        .nodes()
        .iter()
        .flat_map(|p| (0..3).map(move |a| if a < D { p[a] } else { 0.0 }))
        .collect();
    data_array(&mut out, enc, "        ", "Points", 3, &pts, &mut bytes);
    drop(pts);
    out.push_str("      </Points>\n      <Cells>\n");
    let mut conn: Vec<i64> = Vec::with_capacity(grid.cell_nodes.len());
    let mut offsets: Vec<i64> = Vec::with_capacity(nc);
    for c in 0..nc {
        conn.extend(grid.cell_nodes(c).iter().map(|&n| n as i64));
        offsets.push(conn.len() as i64);
    }
    const IND: &str = "        ";
    data_array(&mut out, enc, IND, "connectivity", 1, &conn, &mut bytes);
    data_array(&mut out, enc, IND, "offsets", 1, &offsets, &mut bytes);
    let types = vec![if D == 2 { 7u8 } else { 42u8 }; nc];
    data_array(&mut out, enc, IND, "types", 1, &types, &mut bytes);
    if D == 3 {
        let (faces, faceoffsets) = polyhedron_faces(grid);
        data_array(&mut out, enc, IND, "faces", 1, &faces, &mut bytes);
        data_array(
            &mut out,
            enc,
            IND,
            "faceoffsets",
            1,
            &faceoffsets,
            &mut bytes,
        );
    }
    out.push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    Ok(out)
}

/// Name of the 2D field-data array that keeps the order of each cell's faces.
const EDGE_ORDER: &str = "porofrac:edge_order";

/// In 2D, the position along the polygon ([`Grid::cell_nodes`]) of each of a cell's faces
/// in [`Grid::cell_faces`] order, for all cells; `None` when every cell lists its faces
/// along the polygon (then the polygon alone restores the grid).
fn edge_order<const D: usize>(grid: &Grid<D>) -> Option<Vec<i64>> {
    let mut out = Vec::with_capacity(grid.cell_faces.len());
    let mut trivial = true;
    for c in 0..grid.num_cells() {
        let cn = grid.cell_nodes(c);
        for (k, (&f, &o)) in grid
            .cell_faces(c)
            .iter()
            .zip(grid.cell_face_outward(c))
            .enumerate()
        {
            let start = grid.oriented_face_nodes(f, o).next().unwrap_or(usize::MAX);
            let pos = cn.iter().position(|&n| n == start).unwrap_or(k);
            trivial &= pos == k;
            out.push(pos as i64);
        }
    }
    (!trivial).then_some(out)
}

/// The `faces` stream and `faceoffsets` (end positions) of all cells as polyhedra.
///
/// Outward faces are written as stored; a face seen from its second cell is reversed and
/// rotated so that the order of first appearance of the nodes equals
/// [`Grid::cell_nodes`] (a loop rotation that does this exists because the grid was built
/// from such loops).
fn polyhedron_faces<const D: usize>(grid: &Grid<D>) -> (Vec<i64>, Vec<i64>) {
    let mut faces = Vec::with_capacity(grid.face_nodes.len() * 2 + grid.cell_faces.len());
    let mut offsets = Vec::with_capacity(grid.num_cells());
    let mut buf: Vec<usize> = Vec::new();
    for c in 0..grid.num_cells() {
        let target = grid.cell_nodes(c);
        let mut seen = 0;
        faces.push(grid.cell_faces(c).len() as i64);
        for (&f, &outw) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
            buf.clear();
            buf.extend(grid.oriented_face_nodes(f, outw));
            let m = buf.len();
            let fits = |r: usize| {
                let mut k = seen;
                for j in 0..m {
                    let n = buf[(r + j) % m];
                    if !target[..seen].contains(&n) {
                        if target.get(k) != Some(&n) {
                            return None;
                        }
                        k += 1;
                    }
                }
                Some(k)
            };
            let (rot, next) = if outw {
                (0, fits(0))
            } else {
                (0..m)
                    .find_map(|r| fits(r).map(|k| (r, Some(k))))
                    .unwrap_or((0, None))
            };
            // `next` is always Some for a grid built from loops; fall back gracefully.
            seen = next.unwrap_or(seen);
            faces.push(m as i64);
            faces.extend((0..m).map(|j| buf[(rot + j) % m] as i64));
        }
        offsets.push(faces.len() as i64);
    }
    (faces, offsets)
}

// ---------------------------------------------------------------------------- reading

struct Ctx<'a> {
    path: &'a Path,
    lines: LineIndex,
    big_endian: bool,
    header64: bool,
}

impl Ctx<'_> {
    fn err(&self, offset: usize, what: impl Into<String>) -> GridError {
        GridError::Parse {
            path: self.path.to_path_buf(),
            line: self.lines.line(offset),
            what: what.into(),
        }
    }

    /// Decode a DataArray as f64 (`want_int`: refuse float types) with `ncomp`
    /// components and `tuples` tuples (if given).
    fn array(
        &self,
        el: &Element<'_>,
        ncomp: usize,
        tuples: Option<usize>,
        want_int: bool,
    ) -> Result<Vec<f64>> {
        let name = el.attr("Name").unwrap_or("(unnamed)");
        let ty = el
            .attr("type")
            .ok_or_else(|| self.err(el.offset, format!("DataArray `{name}` has no type")))?;
        let (size, is_float, signed) = match ty {
            "Float32" => (4, true, true),
            "Float64" => (8, true, true),
            "Int8" => (1, false, true),
            "UInt8" => (1, false, false),
            "Int16" => (2, false, true),
            "UInt16" => (2, false, false),
            "Int32" => (4, false, true),
            "UInt32" => (4, false, false),
            "Int64" => (8, false, true),
            "UInt64" => (8, false, false),
            _ => {
                return Err(self.err(
                    el.offset,
                    format!("DataArray `{name}`: unsupported type `{ty}`"),
                ));
            }
        };
        if want_int && is_float {
            return Err(self.err(
                el.offset,
                format!("DataArray `{name}` must be an integer array, found {ty}"),
            ));
        }
        let nc: usize = match el.attr("NumberOfComponents") {
            None => 1,
            Some(s) => s.trim().parse().map_err(|_| {
                self.err(
                    el.offset,
                    format!("DataArray `{name}`: bad NumberOfComponents `{s}`"),
                )
            })?,
        };
        if nc != ncomp {
            return Err(self.err(
                el.offset,
                format!("DataArray `{name}` has {nc} components, expected {ncomp}"),
            ));
        }
        let format = el.attr("format").unwrap_or("ascii");
        let values: Vec<f64> = match format {
            "ascii" => {
                let mut v = Vec::new();
                for tok in el.text.split_ascii_whitespace() {
                    let off = el.text_offset + (tok.as_ptr() as usize - el.text.as_ptr() as usize);
                    let x: f64 = if is_float {
                        tok.parse().ok()
                    } else {
                        tok.parse::<i64>().ok().map(|i| i as f64)
                    }
                    .ok_or_else(|| {
                        self.err(off, format!("DataArray `{name}`: bad {ty} value `{tok}`"))
                    })?;
                    v.push(x);
                }
                v
            }
            "binary" => {
                let raw = base64::decode(el.text.as_bytes())
                    .map_err(|w| self.err(el.text_offset, format!("DataArray `{name}`: {w}")))?;
                let hs = if self.header64 { 8 } else { 4 };
                if raw.len() < hs {
                    return Err(
                        self.err(el.offset, format!("DataArray `{name}`: no binary header"))
                    );
                }
                let count = self.uint(&raw[..hs]) as usize;
                let data = &raw[hs..];
                if count > data.len() || count % size != 0 {
                    return Err(self.err(
                        el.offset,
                        format!(
                            "DataArray `{name}`: header says {count} bytes, {} present \
                             (values of {size} bytes)",
                            data.len()
                        ),
                    ));
                }
                data[..count]
                    .chunks_exact(size)
                    .map(|b| self.decode(b, is_float, signed))
                    .collect()
            }
            "appended" => {
                return Err(self.err(
                    el.offset,
                    format!("DataArray `{name}`: appended data is not supported (write inline ascii or binary)"),
                ));
            }
            _ => {
                return Err(self.err(
                    el.offset,
                    format!("DataArray `{name}`: unknown format `{format}`"),
                ));
            }
        };
        if values.len() % ncomp != 0 {
            return Err(self.err(
                el.offset,
                format!(
                    "DataArray `{name}`: {} values is not a multiple of {ncomp}",
                    values.len()
                ),
            ));
        }
        if let Some(t) = tuples
            && values.len() != t * ncomp
        {
            return Err(self.err(
                el.offset,
                format!(
                    "DataArray `{name}` has {} tuples, expected {t}",
                    values.len() / ncomp
                ),
            ));
        }
        if let Some(bad) = values.iter().position(|x| !x.is_finite()) {
            return Err(self.err(
                el.offset,
                format!("DataArray `{name}`: value {bad} is not finite"),
            ));
        }
        Ok(values)
    }

    fn uint(&self, b: &[u8]) -> u64 {
        let mut x = 0u64;
        for k in 0..b.len() {
            let byte = if self.big_endian {
                b[k]
            } else {
                b[b.len() - 1 - k]
            };
            x = (x << 8) | u64::from(byte);
        }
        x
    }

    fn decode(&self, b: &[u8], is_float: bool, signed: bool) -> f64 {
        let u = self.uint(b);
        if is_float {
            if b.len() == 4 {
                f64::from(f32::from_bits(u as u32))
            } else {
                f64::from_bits(u)
            }
        } else if signed {
            let shift = 64 - 8 * b.len() as u32;
            (((u << shift) as i64) >> shift) as f64
        } else {
            u as f64
        }
    }

    fn ints(&self, el: &Element<'_>, tuples: Option<usize>) -> Result<Vec<i64>> {
        Ok(self
            .array(el, 1, tuples, true)?
            .into_iter()
            .map(|x| x as i64)
            .collect())
    }
}

fn named<'e, 'a>(parent: &'e Element<'a>, name: &str) -> Option<&'e Element<'a>> {
    parent
        .children_named("DataArray")
        .find(|d| d.attr("Name") == Some(name))
}

/// Read a `.vtu` file as a `D`-dimensional grid (see the module docs).
pub fn read_vtu<const D: usize>(path: impl AsRef<Path>) -> Result<Grid<D>> {
    const { assert_dim::<D>() };
    let path = path.as_ref();
    let bytes = read_file(path)?;
    let text = match std::str::from_utf8(&bytes) {
        Ok(t) => t,
        Err(e) => {
            let line = bytes[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1;
            return Err(GridError::Parse {
                path: path.to_path_buf(),
                line,
                what: "not UTF-8 text (raw appended binary data is not supported)".into(),
            });
        }
    };
    parse_vtu(text, path)
}

fn parse_vtu<const D: usize>(text: &str, path: &Path) -> Result<Grid<D>> {
    let mut cx = Ctx {
        path,
        lines: LineIndex::new(text),
        big_endian: false,
        header64: false,
    };
    let root = xml::parse(text).map_err(|e| cx.err(e.offset, format!("XML: {}", e.what)))?;
    if root.name != "VTKFile" || root.attr("type") != Some("UnstructuredGrid") {
        return Err(cx.err(
            root.offset,
            "not a VTK UnstructuredGrid file (<VTKFile type=\"UnstructuredGrid\">)",
        ));
    }
    if let Some(c) = root.attr("compressor")
        && !c.is_empty()
    {
        return Err(cx.err(
            root.offset,
            format!("compressed data ({c}) is not supported"),
        ));
    }
    cx.big_endian = match root.attr("byte_order").unwrap_or("LittleEndian") {
        "LittleEndian" => false,
        "BigEndian" => true,
        o => return Err(cx.err(root.offset, format!("unknown byte_order `{o}`"))),
    };
    cx.header64 = match root.attr("header_type").unwrap_or("UInt32") {
        "UInt32" => false,
        "UInt64" => true,
        o => return Err(cx.err(root.offset, format!("unsupported header_type `{o}`"))),
    };
    if let Some(a) = root.child("AppendedData") {
        return Err(cx.err(
            a.offset,
            "appended data is not supported (write inline ascii or binary)",
        ));
    }
    let ug = root
        .child("UnstructuredGrid")
        .ok_or_else(|| cx.err(root.offset, "no <UnstructuredGrid> element"))?;
    let mut pieces = ug.children_named("Piece");
    let piece = pieces
        .next()
        .ok_or_else(|| cx.err(ug.offset, "no <Piece> element"))?;
    if let Some(p) = pieces.next() {
        return Err(cx.err(p.offset, "more than one <Piece> is not supported"));
    }
    let count = |attr: &str| -> Result<usize> {
        piece
            .attr(attr)
            .and_then(|s| s.trim().parse().ok())
            .ok_or_else(|| cx.err(piece.offset, format!("<Piece> needs a valid {attr}")))
    };
    let np = count("NumberOfPoints")?;
    let nc = count("NumberOfCells")?;

    // Points.
    let pts_el = piece
        .child("Points")
        .and_then(|p| p.child("DataArray"))
        .ok_or_else(|| cx.err(piece.offset, "no <Points><DataArray>"))?;
    let xyz = cx.array(pts_el, 3, Some(np), false)?;
    if D == 2
        && let Some(k) = (1..np).find(|&k| xyz[3 * k + 2] != xyz[2])
    {
        return Err(cx.err(
            pts_el.offset,
            format!(
                "point {k} has z = {} but point 0 has z = {}: a 2D grid must lie in a plane z = const",
                xyz[3 * k + 2],
                xyz[2]
            ),
        ));
    }
    let nodes: Vec<Point<D>> = (0..np)
        .map(|k| Point::<D>::from_fn(|a, _| xyz[3 * k + a]))
        .collect();
    drop(xyz);

    // Cells.
    let cells_el = piece
        .child("Cells")
        .ok_or_else(|| cx.err(piece.offset, "no <Cells> element"))?;
    let get = |name: &str| {
        named(cells_el, name)
            .ok_or_else(|| cx.err(cells_el.offset, format!("<Cells> has no `{name}` array")))
    };
    let conn_el = get("connectivity")?;
    let types_el = get("types")?;
    let offs_el = get("offsets")?;
    let conn = cx.ints(conn_el, None)?;
    let offsets = cx.ints(offs_el, Some(nc))?;
    let types = cx.ints(types_el, Some(nc))?;
    let poly = if types.contains(&42) {
        let fe = get("faces")?;
        let fo = get("faceoffsets")?;
        Some((cx.ints(fe, None)?, cx.ints(fo, Some(nc))?, fe.offset))
    } else {
        None
    };
    // Optional 2D face order (see `edge_order`).
    let mut order: Option<(Vec<i64>, usize)> = None;
    if D == 2
        && let Some(el) = [ug.child("FieldData"), piece.child("FieldData")]
            .into_iter()
            .flatten()
            .find_map(|fd| named(fd, EDGE_ORDER))
    {
        order = Some((cx.ints(el, None)?, el.offset));
    }
    let mut order_pos = 0usize;
    let mut loops = CellFaceLoops::new();
    let mut origin = Vec::with_capacity(nc);
    let mut start = 0usize;
    let mut face_start = 0usize;
    let mut v: Vec<usize> = Vec::with_capacity(8);
    let point = |id: i64, c: usize, off: usize| -> Result<usize> {
        if id < 0 || id as usize >= np {
            Err(cx.err(
                off,
                format!("cell {c}: point {id} does not exist ({np} points)"),
            ))
        } else {
            Ok(id as usize)
        }
    };
    for c in 0..nc {
        let end = offsets[c];
        if end < start as i64 || end as usize > conn.len() {
            return Err(cx.err(
                offs_el.offset,
                format!(
                    "cell {c}: offset {end} is out of order or past the connectivity ({} ids)",
                    conn.len()
                ),
            ));
        }
        let end = end as usize;
        v.clear();
        for &id in &conn[start..end] {
            v.push(point(id, c, conn_el.offset)?);
        }
        start = end;
        let t = types[c];
        let shape = match (D, t) {
            (2, 5) => Some(Shape::Triangle),
            (2, 9) => Some(Shape::Quad),
            (2, 7) => None,
            (3, 10) => Some(Shape::Tetra),
            (3, 12) => Some(Shape::Hexa),
            (3, 13) => Some(Shape::Prism),
            (3, 14) => Some(Shape::Pyramid),
            (3, 42) => None,
            _ => {
                return Err(cx.err(
                    types_el.offset,
                    format!("cell {c}: VTK cell type {t} is not supported in a {D}D grid"),
                ));
            }
        };
        if let Some(s) = shape {
            if v.len() != s.num_nodes() {
                return Err(cx.err(
                    conn_el.offset,
                    format!(
                        "cell {c}: a {} needs {} points, got {}",
                        s.name(),
                        s.num_nodes(),
                        v.len()
                    ),
                ));
            }
            s.push(&mut loops, &v);
        } else if D == 2 {
            if v.len() < 3 {
                return Err(cx.err(
                    conn_el.offset,
                    format!("cell {c}: a polygon needs at least 3 points"),
                ));
            }
            match &order {
                None => loops.push_polygon(&v),
                Some((ord, off)) => {
                    let m = v.len();
                    let chunk = ord.get(order_pos..order_pos + m).ok_or_else(|| {
                        cx.err(*off, format!("{EDGE_ORDER}: too short for cell {c}"))
                    })?;
                    let mut hit = [false; 64];
                    for &p in chunk {
                        let ok = p >= 0 && (p as usize) < m && (m > 64 || !hit[p as usize]);
                        if !ok {
                            return Err(cx.err(
                                *off,
                                format!(
                                    "{EDGE_ORDER}: cell {c} is not a permutation of its {m} edges"
                                ),
                            ));
                        }
                        if m <= 64 {
                            hit[p as usize] = true;
                        }
                        let p = p as usize;
                        loops.push_face(&[v[p], v[(p + 1) % m]]);
                    }
                    loops.finish_cell();
                    order_pos += m;
                }
            }
        } else {
            let Some((faces, fo, foff)) = &poly else {
                return Err(cx.err(cells_el.offset, "polyhedra without a faces array"));
            };
            let fend = fo[c];
            let bad = |w: String| cx.err(*foff, format!("cell {c}: {w}"));
            if fend < face_start as i64 || fend as usize > faces.len() {
                return Err(bad(format!(
                    "faceoffset {fend} is out of order or past the faces array"
                )));
            }
            let fend = fend as usize;
            let stream = &faces[face_start..fend];
            let nfaces = *stream
                .first()
                .ok_or_else(|| bad("empty face list".into()))?;
            let mut k = 1usize;
            for _ in 0..nfaces.max(0) {
                let m = *stream
                    .get(k)
                    .ok_or_else(|| bad("face list shorter than declared".into()))?;
                if m < 3 || m as usize > stream.len() - k - 1 {
                    return Err(bad(format!("bad face size {m}")));
                }
                v.clear();
                for &id in &stream[k + 1..k + 1 + m as usize] {
                    v.push(point(id, c, *foff)?);
                }
                loops.push_face(&v);
                k += 1 + m as usize;
            }
            if k != stream.len() {
                return Err(bad(format!(
                    "face list has {} extra values",
                    stream.len() - k
                )));
            }
            loops.finish_cell();
            face_start = fend;
        }
        if poly.is_some() && shape.is_some() && poly.as_ref().is_some_and(|p| p.1[c] >= 0) {
            return Err(cx.err(
                cells_el.offset,
                format!("cell {c}: faceoffset must be -1 for a non-polyhedral cell"),
            ));
        }
        origin.push(Origin {
            line: cx.lines.line(types_el.offset),
            tag: c as u64,
            standard: shape.is_some() || D == 2,
        });
    }
    if let Some((ord, off)) = &order
        && order_pos != ord.len()
    {
        return Err(cx.err(
            *off,
            format!(
                "{EDGE_ORDER} has {} values, the polygons have {order_pos} edges",
                ord.len()
            ),
        ));
    }
    let raw = RawMesh::<D> {
        nodes,
        node_label: (0..np)
            .map(|k| (k as u64, cx.lines.line(pts_el.offset)))
            .collect(),
        loops,
        origin,
        what_cell: "VTK cell",
        what_node: "VTK point",
    };
    let built = raw.build(path)?;
    let mut grid = built.grid;
    let in_file = |e: GridError| GridError::InFile {
        path: path.to_path_buf(),
        source: Box::new(e),
    };

    // Tags.
    let mut cell_tags: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    if let Some(cd) = piece.child("CellData") {
        let mut have_named = false;
        for el in cd.children_named("DataArray") {
            if let Some(name) = el.attr("Name").and_then(|n| n.strip_prefix("tag:")) {
                have_named = true;
                let vals = cx.ints(el, Some(nc))?;
                let cells = (0..nc).filter(|&c| vals[c] != 0).collect();
                cell_tags.insert(name.to_string(), cells);
            }
        }
        if !have_named && let Some(el) = named(cd, "tag") {
            let vals = cx.ints(el, Some(nc))?;
            for (c, &t) in vals.iter().enumerate() {
                cell_tags.entry(format!("tag_{t}")).or_default().push(c);
            }
        }
    }
    for (name, cells) in cell_tags {
        grid.set_cell_tag(name, cells).map_err(in_file)?;
    }
    for fd in [ug.child("FieldData"), piece.child("FieldData")]
        .into_iter()
        .flatten()
    {
        for el in fd.children_named("DataArray") {
            if let Some(name) = el.attr("Name").and_then(|n| n.strip_prefix("facetag:")) {
                let vals = cx.ints(el, None)?;
                if let Some(&f) = vals
                    .iter()
                    .find(|&&f| f < 0 || f as usize >= grid.num_faces())
                {
                    return Err(cx.err(
                        el.offset,
                        format!(
                            "face tag `{name}` lists face {f}; the grid has {} faces",
                            grid.num_faces()
                        ),
                    ));
                }
                grid.set_face_tag(name, vals.iter().map(|&f| f as usize).collect())
                    .map_err(in_file)?;
            }
        }
    }
    Ok(grid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::cartesian;

    /// Field arrays are written with the right layout in both encodings.
    #[test]
    fn field_layout() {
        let g =
            cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 1.0), [2, 1]).unwrap();
        let s = [0.1, -2.5e-300];
        let vecs = [Point::<2>::new(1.0, 2.0), Point::<2>::new(3.0, 4.0)];
        let t = [[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]; 2];
        let ints = [7, -8];
        let cd = [
            ("s", Field::Scalars(&s)),
            ("v", Field::Vectors(&vecs)),
            ("t", Field::SymTensors(&t)),
            ("i", Field::Ints(&ints)),
        ];
        for enc in [Encoding::Ascii, Encoding::Base64] {
            let text = vtu_text(&g, &[], &cd, enc).unwrap();
            let cx = Ctx {
                path: Path::new("x.vtu"),
                lines: LineIndex::new(&text),
                big_endian: false,
                header64: true,
            };
            let root = xml::parse(&text).ok().unwrap();
            let cdel = root
                .child("UnstructuredGrid")
                .and_then(|u| u.child("Piece"))
                .and_then(|p| p.child("CellData"))
                .unwrap();
            let get = |n: &str, nc: usize| {
                cx.array(named(cdel, n).unwrap(), nc, Some(2), false)
                    .unwrap()
            };
            assert_eq!(get("s", 1), s.to_vec());
            assert_eq!(get("v", 3), vec![1.0, 2.0, 0.0, 3.0, 4.0, 0.0]);
            // xx yy zz xy yz xz → row-major [xx xy xz; xy yy yz; xz yz zz]
            assert_eq!(
                &get("t", 9)[..9],
                &[1.0, 4.0, 6.0, 4.0, 2.0, 5.0, 6.0, 5.0, 3.0]
            );
            assert_eq!(get("i", 1), vec![7.0, -8.0]);
        }
        // Bad lengths and reserved names are errors.
        assert!(vtu_text(&g, &[("p", Field::Scalars(&s))], &[], Encoding::Ascii).is_err());
        assert!(vtu_text(&g, &[], &[("tag", Field::Ints(&ints))], Encoding::Ascii).is_err());
    }

    /// VTK's own variant: a UInt32 header encoded as a separate base64 stream, big-endian.
    #[test]
    fn separate_header_big_endian() {
        let vals = [1.5f64, -2.0, 3.25e-7];
        let mut data = Vec::new();
        for v in vals {
            data.extend_from_slice(&v.to_be_bytes());
        }
        let mut text = String::new();
        base64::encode_into(&(data.len() as u32).to_be_bytes(), &mut text);
        text.push('\n');
        base64::encode_into(&data, &mut text);
        let doc =
            format!("<DataArray type=\"Float64\" Name=\"x\" format=\"binary\">{text}</DataArray>");
        let el = xml::parse(&doc).ok().unwrap();
        let cx = Ctx {
            path: Path::new("x.vtu"),
            lines: LineIndex::new(&doc),
            big_endian: true,
            header64: false,
        };
        assert_eq!(cx.array(&el, 1, Some(3), false).unwrap(), vals.to_vec());
        // A header claiming more bytes than present is an error.
        let mut h = String::new();
        base64::encode_into(&99u32.to_be_bytes(), &mut h);
        let doc = doc.replacen(&text[..8], &h, 1);
        let el = xml::parse(&doc).ok().unwrap();
        assert!(cx.array(&el, 1, None, false).is_err());
    }

    #[test]
    fn kelvin_conversion() {
        let r = std::f64::consts::SQRT_2;
        let k2 = kelvin_to_vtk_sym(&[1.0, 2.0, 3.0 * r]).unwrap();
        for (a, b) in k2.iter().zip([1.0, 2.0, 0.0, 3.0, 0.0, 0.0]) {
            assert!((a - b).abs() <= 1e-15 * 3.0, "{a} vs {b}");
        }
        let k = kelvin_to_vtk_sym(&[1.0, 2.0, 3.0, 4.0 * r, 5.0 * r, 6.0 * r]).unwrap();
        for (a, b) in k.iter().zip([1.0, 2.0, 3.0, 6.0, 4.0, 5.0]) {
            assert!((a - b).abs() <= 1e-15 * b, "{a} vs {b}");
        }
        assert_eq!(kelvin_to_vtk_sym(&[1.0]), None);
    }
}
