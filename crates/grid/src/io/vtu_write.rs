//! VTK XML UnstructuredGrid (`.vtu`) writer: turns a grid into VTK points, cells and
//! data arrays and writes them with [`porofrac_vtk`].
//!
//! * 2D cells with 3 nodes are `VTK_TRIANGLE` (5), with 4 nodes `VTK_QUAD` (9), the
//!   others `VTK_POLYGON` (7); all with the counter-clockwise [`Grid::cell_nodes`] and
//!   points at `z = 0`. In 3D, a cell of 4 triangular faces is a `VTK_TETRA` (10) and a
//!   cell of 6 quadrilateral faces on 8 nodes, three faces at each node, a
//!   `VTK_HEXAHEDRON` (12), both with their nodes in VTK's order; the other 3D cells are
//!   `VTK_POLYHEDRON` (42) with the `faces` / `faceoffsets` arrays (the layout ParaView
//!   5.x and meshio read; `faceoffsets` is −1 for a cell of a standard type): per cell the
//!   number of faces, then for each face its node count and nodes, in the cell's outward
//!   order. A face seen from its second cell is written reversed and rotated so that
//!   reading the file back gives the same cell node order, hence the identical grid
//!   (`read(write(g)) == g`). meshio thus reads one block per cell type.
//! * In 3D, when a cell is written as a tetrahedron or hexahedron, the field-data arrays
//!   `porofrac:faces` / `porofrac:faceoffsets` (`Int64`) hold the face stream of *every*
//!   cell, so that reading the file back rebuilds the same face numbering and
//!   orientation; other readers ignore them.
//! * In 2D, when a cell does not list its faces in polygon order, the field-data array
//!   `porofrac:edge_order` (`Int64`) gives, per cell, the position along the polygon of
//!   each of its faces, so that the face numbering survives the round trip.
//! * Tags. For every cell tag an `Int32` cell-data array `tag:<name>` holding 1 on the
//!   tagged cells and 0 elsewhere (names are exact, tags may overlap), and one plain `tag`
//!   array: the 1-based position (in name order) of the last tag holding the cell, 0 for
//!   none (for colouring in ParaView). Face tags, which VTK cannot attach to polyhedron
//!   faces, go to the grid's `FieldData` as `Int64` arrays `facetag:<name>` of face
//!   indices; the reader rebuilds the same face numbering, so they round-trip exactly.
//!   The names `tag` and `tag:…` are reserved in cell data.
//! * Data: [`Field`] scalars, vectors (3 components, z = 0 in 2D), symmetric tensors
//!   (written as 9 components, row-major, which ParaView shows as a tensor), arrays of any
//!   number of components (full tensors, …) and `Int32` arrays. [`Encoding::Base64`]
//!   (default; inline binary, `header_type="UInt64"`, little-endian, no compression),
//!   [`Encoding::Ascii`] (floats in Rust's shortest round-trip form, so both encodings are
//!   bit-exact) or [`Encoding::Appended`] (raw binary in `<AppendedData>`).
//! * The file is written atomically ([`porofrac_vtk::write_atomic_with`]).

use std::path::Path;

use porofrac_vtk::{Attributes, CellType, DataArray, Polyhedra, UnstructuredGrid, VtkError};

pub use porofrac_vtk::Encoding;

use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::io::vtu::{EDGE_ORDER, FACE_OFFSETS, FACES};
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
    /// `components` values per entity, written as they are: a full tensor as 9
    /// components row-major `[xx, xy, xz, yx, yy, yz, zx, zy, zz]`, a 3D vector whose
    /// z matters in a 2D grid (a rotation `(0, 0, φ)`), ….
    Components {
        /// Values per entity (≥ 1).
        components: usize,
        /// `components` values per entity, entity after entity.
        values: &'a [f64],
    },
}

impl<const D: usize> Field<'_, D> {
    /// Number of entities (for [`Field::Components`], values / components).
    fn len(&self) -> usize {
        match self {
            Field::Scalars(v) => v.len(),
            Field::Vectors(v) => v.len(),
            Field::SymTensors(v) => v.len(),
            Field::Ints(v) => v.len(),
            Field::Components { components, values } => {
                if *components == 0 || !values.len().is_multiple_of(*components) {
                    usize::MAX
                } else {
                    values.len() / components
                }
            }
        }
    }

    /// The values as they are written: borrowed, or flattened into `flat`.
    fn values<'s>(&'s self, flat: &'s mut Vec<f64>) -> (usize, porofrac_vtk::Values<'s>) {
        match self {
            Field::Scalars(v) => (1, (*v).into()),
            Field::Ints(v) => (1, (*v).into()),
            Field::Components { components, values } => (*components, (*values).into()),
            Field::Vectors(v) => {
                flat.extend(
                    v.iter()
                        .flat_map(|p| (0..3).map(move |a| if a < D { p[a] } else { 0.0 })),
                );
                (3, flat.as_slice().into())
            }
            Field::SymTensors(v) => {
                flat.extend(v.iter().flat_map(|t| {
                    let [xx, yy, zz, xy, yz, xz] = *t;
                    [xx, xy, xz, xy, yy, yz, xz, yz, zz]
                }));
                (9, flat.as_slice().into())
            }
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
    with_vtk(grid, point_data, cell_data, |ug| {
        ug.write(path.as_ref(), enc)
    })
}

/// The bytes [`write_vtu_with`] writes (for tests of the layout).
#[cfg(test)]
pub(crate) fn vtu_bytes<const D: usize>(
    grid: &Grid<D>,
    point_data: &[(&str, Field<'_, D>)],
    cell_data: &[(&str, Field<'_, D>)],
    enc: Encoding,
) -> Result<Vec<u8>> {
    with_vtk(grid, point_data, cell_data, |ug| ug.to_bytes(enc))
}

pub(crate) fn vtk_err(e: VtkError) -> GridError {
    match e {
        VtkError::Input(what) => GridError::Input(what),
        VtkError::Io { path, source } => GridError::Io { path, source },
    }
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
        if let Field::Components { components, values } = f
            && (*components == 0 || !values.len().is_multiple_of(*components))
        {
            return Err(GridError::Input(format!(
                "{what} array `{name}` has {} values, not a multiple of its {components} components",
                values.len()
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

/// The fields as VTK data arrays; vectors and symmetric tensors are flattened into
/// `flat` (one vector per field).
fn data_arrays<'s, const D: usize>(
    fields: &'s [(&'s str, Field<'s, D>)],
    flat: &'s mut [Vec<f64>],
) -> Vec<DataArray<'s>> {
    fields
        .iter()
        .zip(flat.iter_mut())
        .map(|((name, f), flat)| {
            let (components, values) = f.values(flat);
            DataArray {
                name,
                components,
                values,
                component_names: &[],
            }
        })
        .collect()
}

/// The grid as a VTK unstructured grid with its tag arrays and the given data, handed to
/// `f`.
fn with_vtk<const D: usize, T>(
    grid: &Grid<D>,
    point_data: &[(&str, Field<'_, D>)],
    cell_data: &[(&str, Field<'_, D>)],
    f: impl FnOnce(&UnstructuredGrid<'_>) -> std::result::Result<T, VtkError>,
) -> Result<T> {
    check_fields(point_data, grid.num_nodes(), "point data", false)?;
    check_fields(cell_data, grid.num_cells(), "cell data", true)?;
    let nc = grid.num_cells();

    // Field data: face tags, then the 2D edge order.
    let face_tags: Vec<(String, Vec<i64>)> = grid
        .face_tags()
        .iter()
        .map(|(name, faces)| {
            (
                format!("facetag:{name}"),
                faces.iter().map(|&f| f as i64).collect(),
            )
        })
        .collect();
    let edge_order = if D == 2 { edge_order(grid) } else { None };
    let mut field: Vec<DataArray<'_>> = face_tags
        .iter()
        .map(|(name, v)| DataArray::new(name, 1, &v[..]))
        .collect();
    if let Some(v) = &edge_order {
        field.push(DataArray::new(EDGE_ORDER, 1, &v[..]));
    }

    // Cell tags: the plain `tag` array, then one `tag:<name>` array per tag.
    let mut tag_arrays: Vec<(String, Vec<i32>)> = Vec::new();
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
        tag_arrays.push(("tag".to_string(), plain));
        tag_arrays.extend(per_tag);
    }

    let mut point_flat = vec![Vec::new(); point_data.len()];
    let mut cell_flat = vec![Vec::new(); cell_data.len()];
    let points = data_arrays(point_data, &mut point_flat);
    let mut cells: Vec<DataArray<'_>> = tag_arrays
        .iter()
        .map(|(name, v)| DataArray::new(name, 1, &v[..]))
        .collect();
    cells.extend(data_arrays(cell_data, &mut cell_flat));

    let pts: Vec<f64> = grid
        .nodes()
        .iter()
        .flat_map(|p| (0..3).map(move |a| if a < D { p[a] } else { 0.0 }))
        .collect();
    let cells_vtk = vtk_cells(grid);
    if let Some((faces, offsets)) = &cells_vtk.all_faces {
        field.push(DataArray::new(FACES, 1, &faces[..]));
        field.push(DataArray::new(FACE_OFFSETS, 1, &offsets[..]));
    }
    let ug = UnstructuredGrid {
        points: &pts,
        connectivity: &cells_vtk.connectivity,
        offsets: &cells_vtk.offsets,
        types: &cells_vtk.types,
        polyhedra: cells_vtk
            .polyhedra
            .as_ref()
            .map(|(faces, faceoffsets)| Polyhedra { faces, faceoffsets }),
        field_data: &field,
        point_data: Attributes::new(&points),
        cell_data: Attributes::new(&cells),
    };
    f(&ug).map_err(vtk_err)
}

/// The cells of a grid in VTK terms (see the module docs).
struct VtkCells {
    types: Vec<CellType>,
    connectivity: Vec<i64>,
    offsets: Vec<i64>,
    /// `faces` / `faceoffsets` of the `<Cells>` element (3D with a polyhedron).
    polyhedra: Option<(Vec<i64>, Vec<i64>)>,
    /// The face stream of every cell, for [`FACES`] / [`FACE_OFFSETS`] (3D with a
    /// tetrahedron or hexahedron).
    all_faces: Option<(Vec<i64>, Vec<i64>)>,
}

/// Types, connectivity and polyhedron faces of every cell: triangles and quadrilaterals
/// in 2D (by node count; polygon order is a valid node order for both), tetrahedra and
/// hexahedra in 3D (by face structure, nodes in VTK's order), polygons and polyhedra for
/// the rest.
fn vtk_cells<const D: usize>(grid: &Grid<D>) -> VtkCells {
    let nc = grid.num_cells();
    let mut types = Vec::with_capacity(nc);
    let mut connectivity: Vec<i64> = Vec::with_capacity(grid.cell_nodes.len());
    let mut offsets: Vec<i64> = Vec::with_capacity(nc);
    if D == 2 {
        for c in 0..nc {
            let nodes = grid.cell_nodes(c);
            types.push(match nodes.len() {
                3 => CellType::Triangle,
                4 => CellType::Quad,
                _ => CellType::Polygon,
            });
            connectivity.extend(nodes.iter().map(|&n| n as i64));
            offsets.push(connectivity.len() as i64);
        }
        return VtkCells {
            types,
            connectivity,
            offsets,
            polyhedra: None,
            all_faces: None,
        };
    }
    let (faces, face_ends) = polyhedron_faces(grid);
    let mut poly_faces = Vec::new();
    let mut poly_offsets = Vec::with_capacity(nc);
    let mut any_poly = false;
    let mut start = 0usize;
    for c in 0..nc {
        let end = face_ends[c] as usize;
        let stream = &faces[start..end];
        let standard = standard_3d(grid, c, stream);
        match standard {
            Some((ty, nodes)) => {
                types.push(ty);
                connectivity.extend(nodes);
                poly_offsets.push(-1);
            }
            None => {
                types.push(CellType::Polyhedron);
                connectivity.extend(grid.cell_nodes(c).iter().map(|&n| n as i64));
                poly_faces.extend_from_slice(stream);
                poly_offsets.push(poly_faces.len() as i64);
                any_poly = true;
            }
        }
        offsets.push(connectivity.len() as i64);
        start = end;
    }
    let any_standard = types.iter().any(|&t| t != CellType::Polyhedron);
    VtkCells {
        types,
        connectivity,
        offsets,
        polyhedra: any_poly.then_some((poly_faces, poly_offsets)),
        all_faces: any_standard.then_some((faces, face_ends)),
    }
}

/// The face loops of a polyhedron's stream (`[n_faces, m, nodes…, m, nodes…]`).
fn stream_faces(stream: &[i64]) -> Vec<&[i64]> {
    let mut out = Vec::new();
    let mut k = 1;
    while k < stream.len() {
        let m = stream[k] as usize;
        out.push(&stream[k + 1..k + 1 + m]);
        k += 1 + m;
    }
    out
}

/// Cell `c` as a VTK tetrahedron (4 triangles on 4 nodes, nodes ordered so that the
/// first three, seen from the fourth, run counter-clockwise) or hexahedron (6
/// quadrilaterals on 8 nodes, each node on three of them: the bottom loop with its
/// normal pointing inside, then the node above each), given its outward face stream.
fn standard_3d<const D: usize>(
    grid: &Grid<D>,
    c: usize,
    stream: &[i64],
) -> Option<(CellType, Vec<i64>)> {
    let faces = stream_faces(stream);
    let nodes = grid.cell_nodes(c);
    let x = |n: i64| -> [f64; 3] {
        let p = grid.node(n as usize);
        std::array::from_fn(|a| if a < D { p[a] } else { 0.0 })
    };
    if nodes.len() == 4 && faces.len() == 4 && faces.iter().all(|f| f.len() == 3) {
        // The outward loop of the first face, reversed, points inside: towards the node
        // that is not on it.
        let f = faces[0];
        let apex = nodes.iter().map(|&n| n as i64).find(|n| !f.contains(n))?;
        let order = vec![f[0], f[2], f[1], apex];
        let [a, b, cc, d] = [0, 1, 2, 3].map(|i| x(order[i]));
        let u = sub(b, a);
        let v = sub(cc, a);
        let w = sub(d, a);
        let det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]);
        return (det > 0.0).then_some((CellType::Tetra, order));
    }
    if nodes.len() != 8 || faces.len() != 6 || faces.iter().any(|f| f.len() != 4) {
        return None;
    }
    let mut on = [0usize; 8];
    for f in &faces {
        for n in f.iter() {
            let i = nodes.iter().position(|&m| m as i64 == *n)?;
            on[i] += 1;
        }
    }
    if on.iter().any(|&k| k != 3) {
        return None;
    }
    let bottom: Vec<i64> = faces[0].iter().rev().copied().collect();
    // The node above bottom node `b`: its neighbour along an edge of some face, off the
    // bottom face.
    let above = |b: i64| -> Option<i64> {
        let mut found = None;
        for f in &faces {
            for k in 0..4 {
                let (p, q) = (f[k], f[(k + 1) % 4]);
                let other = if p == b {
                    q
                } else if q == b {
                    p
                } else {
                    continue;
                };
                if !bottom.contains(&other) {
                    match found {
                        None => found = Some(other),
                        Some(o) if o != other => return None,
                        _ => {}
                    }
                }
            }
        }
        found
    };
    let mut order = bottom.clone();
    for k in 0..4 {
        order.push(above(bottom[k])?);
    }
    let mut top = order[4..].to_vec();
    top.sort_unstable();
    top.dedup();
    if top.len() != 4 {
        return None;
    }
    Some((CellType::Hexahedron, order))
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

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

#[cfg(test)]
mod tests {
    use super::*;

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
