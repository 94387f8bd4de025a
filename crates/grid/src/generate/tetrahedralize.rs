//! Replace some cells of a 3D grid by tetrahedra that conform with the cells around them
//! (an MDEM zone inside a VEM far field of any polyhedra, e.g. a corner-point grid).
//!
//! 1. **Faces of the zone.** Every face of a zone cell that is not a triangle is split into
//!    triangles about a new node at its vertex average — the point the grid already
//!    triangulates it about, so the geometry does not change. A face shared with a cell
//!    outside the zone is split the same way in that cell: its polygon becomes the same
//!    triangles, and the two cells still share every face.
//! 2. **Cells of the zone.** Each zone cell becomes the tetrahedra joining its face
//!    triangles to a new node at its centroid (every corner-point or convex cell is star-
//!    shaped about it; a cell that is not is reported by the validation as an inverted
//!    tetrahedron).
//! 3. **Refinement** (`levels` times): every zone tetrahedron is split into eight by its
//!    edge midpoints (four corner tetrahedra and the inner octahedron cut into four along
//!    the diagonal from the midpoint of edge 0–2 to that of edge 1–3). A triangle of a cell outside the zone whose three edges were split
//!    becomes four triangles; any other face of such a cell gets the midpoints of its split
//!    edges as hanging nodes.
//!
//! Cell tags carry over to the children of a cell, face tags to the pieces of a face;
//! [`Tetrahedralized::parent`] gives every new cell its cell of the input grid.

use std::collections::{BTreeMap, HashMap};

use crate::builder::CellFaceLoops;
use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::point::Point;

/// A grid whose zone was replaced by tetrahedra, and where every cell came from.
#[derive(Clone, Debug)]
pub struct Tetrahedralized {
    /// The new grid; the zone's tetrahedra carry the cell tag `refined`.
    pub grid: Grid<3>,
    /// For every cell of `grid`, its cell in the input grid.
    pub parent: Vec<usize>,
}

/// The outward loops of the cells, with each loop's face of the input grid (`usize::MAX`
/// for faces inside a zone cell).
struct Loops {
    cells: Vec<Vec<(Vec<usize>, usize)>>,
}

/// Replace the cells `zone` of `grid` by conforming tetrahedra, refined `levels` times.
pub fn tetrahedralize(grid: &Grid<3>, zone: &[usize], levels: usize) -> Result<Tetrahedralized> {
    let n = grid.num_cells();
    let mut in_zone = vec![false; n];
    for &c in zone {
        if c >= n {
            return Err(GridError::Input(format!(
                "tetrahedralize: cell {c} is not in the grid ({n} cells)"
            )));
        }
        in_zone[c] = true;
    }
    if levels > 4 {
        return Err(GridError::Input(format!(
            "tetrahedralize: {levels} refinement levels multiply the zone by 8^{levels}; at most 4"
        )));
    }
    let mut nodes: Vec<Point<3>> = grid.nodes().to_vec();
    // Face centre nodes of the non-triangular faces of the zone.
    let mut centre_of_face = vec![usize::MAX; grid.num_faces()];
    for f in 0..grid.num_faces() {
        let (a, b) = grid.face_cells(f);
        let touches = in_zone[a] || b.is_some_and(|b| in_zone[b]);
        let fnodes = grid.face_nodes(f);
        if touches && fnodes.len() > 3 {
            let x = fnodes.iter().map(|&v| grid.node(v)).sum::<Point<3>>() / fnodes.len() as f64;
            centre_of_face[f] = nodes.len();
            nodes.push(x);
        }
    }
    // Every cell as outward loops; zone cells as tetrahedra (4 node ids, positive).
    let mut loops = Loops { cells: Vec::new() };
    let mut tets: Vec<([usize; 4], usize)> = Vec::new();
    let mut tet_parent: Vec<usize> = Vec::new();
    let mut parent = Vec::new();
    for c in 0..n {
        let mut cell_loops = Vec::new();
        let centre = if in_zone[c] {
            nodes.push(*grid.cell_centroid(c));
            nodes.len() - 1
        } else {
            usize::MAX
        };
        for (&f, &out) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
            let mut ring: Vec<usize> = grid.face_nodes(f).to_vec();
            if !out {
                ring.reverse();
            }
            let tris: Vec<Vec<usize>> = if centre_of_face[f] == usize::MAX {
                vec![ring]
            } else {
                let m = ring.len();
                (0..m)
                    .map(|k| vec![centre_of_face[f], ring[k], ring[(k + 1) % m]])
                    .collect()
            };
            for t in tris {
                if in_zone[c] {
                    // Outward base (a, b, c) with the apex inside: positive as (a, c, b, d).
                    tets.push(([t[0], t[2], t[1], centre], f));
                    tet_parent.push(c);
                } else {
                    cell_loops.push((t, f));
                }
            }
        }
        if !in_zone[c] {
            loops.cells.push(cell_loops);
            parent.push(c);
        }
    }
    let mut zone_tets: Vec<[usize; 4]> = tets.iter().map(|t| t.0).collect();
    // Faces of the zone's tetrahedra that lie on faces of the input grid: (sorted nodes)
    // → input face, so that pieces of tagged faces keep their tags.
    let mut source: HashMap<[usize; 3], usize> = HashMap::new();
    for (t, f) in &tets {
        let mut key = [t[0], t[1], t[2]];
        key.sort_unstable();
        source.insert(key, *f);
    }
    for _ in 0..levels {
        let mut midpoint: HashMap<(usize, usize), usize> = HashMap::new();
        let mut mid = |a: usize, b: usize, nodes: &mut Vec<Point<3>>| {
            let key = (a.min(b), a.max(b));
            *midpoint.entry(key).or_insert_with(|| {
                nodes.push((nodes[a] + nodes[b]) * 0.5);
                nodes.len() - 1
            })
        };
        let mut next = Vec::with_capacity(8 * zone_tets.len());
        let mut next_parent = Vec::with_capacity(8 * zone_tets.len());
        let mut next_source = HashMap::new();
        for (t, &p) in zone_tets.iter().zip(&tet_parent) {
            let mut m = |i: usize, j: usize, nodes: &mut Vec<Point<3>>| mid(t[i], t[j], nodes);
            let (m01, m02, m03) = (
                m(0, 1, &mut nodes),
                m(0, 2, &mut nodes),
                m(0, 3, &mut nodes),
            );
            let (m12, m13, m23) = (
                m(1, 2, &mut nodes),
                m(1, 3, &mut nodes),
                m(2, 3, &mut nodes),
            );
            let children = [
                [t[0], m01, m02, m03],
                [m01, t[1], m12, m13],
                [m02, m12, t[2], m23],
                [m03, m13, m23, t[3]],
                [m01, m02, m03, m13],
                [m01, m02, m12, m13],
                [m02, m03, m13, m23],
                [m02, m12, m13, m23],
            ];
            for mut ch in children {
                if signed_volume(&nodes, &ch) < 0.0 {
                    ch.swap(0, 1);
                }
                next.push(ch);
                next_parent.push(p);
            }
            // The four pieces of each face of `t` that lies on an input face.
            for (a, b, c) in [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)] {
                let mut key = [t[a], t[b], t[c]];
                key.sort_unstable();
                if let Some(&f) = source.get(&key) {
                    let (ab, ac, bc) = (
                        mid(t[a], t[b], &mut nodes),
                        mid(t[a], t[c], &mut nodes),
                        mid(t[b], t[c], &mut nodes),
                    );
                    for mut piece in [[t[a], ab, ac], [ab, t[b], bc], [ac, bc, t[c]], [ab, bc, ac]]
                    {
                        piece.sort_unstable();
                        next_source.insert(piece, f);
                    }
                }
            }
        }
        // Cells outside the zone: split triangles, hanging nodes on split edges.
        for cell in &mut loops.cells {
            let mut out = Vec::with_capacity(cell.len());
            for (ring, f) in cell.drain(..) {
                let m = ring.len();
                let mids: Vec<Option<usize>> = (0..m)
                    .map(|k| {
                        let (a, b) = (ring[k], ring[(k + 1) % m]);
                        midpoint.get(&(a.min(b), a.max(b))).copied()
                    })
                    .collect();
                if m == 3 && mids.iter().all(Option::is_some) {
                    let (ab, bc, ca) = (
                        mids[0].unwrap_or(0),
                        mids[1].unwrap_or(0),
                        mids[2].unwrap_or(0),
                    );
                    let (a, b, c) = (ring[0], ring[1], ring[2]);
                    for piece in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
                        out.push((piece.to_vec(), f));
                    }
                } else {
                    let mut r = Vec::with_capacity(2 * m);
                    for k in 0..m {
                        r.push(ring[k]);
                        if let Some(x) = mids[k] {
                            r.push(x);
                        }
                    }
                    out.push((r, f));
                }
            }
            *cell = out;
        }
        zone_tets = next;
        tet_parent = next_parent;
        source = next_source;
    }
    // Assemble: cells outside the zone, then the tetrahedra.
    let mut cfl = CellFaceLoops::new();
    let mut loop_source: Vec<usize> = Vec::new();
    for cell in &loops.cells {
        for (ring, f) in cell {
            cfl.push_face(ring);
            loop_source.push(*f);
        }
        cfl.finish_cell();
    }
    for t in &zone_tets {
        for face in [
            [t[0], t[2], t[1]],
            [t[0], t[1], t[3]],
            [t[0], t[3], t[2]],
            [t[1], t[2], t[3]],
        ] {
            cfl.push_face(&face);
            let mut key = face;
            key.sort_unstable();
            loop_source.push(source.get(&key).copied().unwrap_or(usize::MAX));
        }
        cfl.finish_cell();
    }
    parent.extend_from_slice(&tet_parent);
    let mut out = Grid::from_cell_faces(nodes, &cfl)?;
    // Tags: cells by parent, boundary faces by their input face.
    let first_tet = loops.cells.len();
    let mut cell_tags: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (name, cells) in grid.cell_tags() {
        let mut tagged = vec![false; n];
        for &c in cells {
            tagged[c] = true;
        }
        let children: Vec<usize> = (0..parent.len()).filter(|&c| tagged[parent[c]]).collect();
        cell_tags.insert(name.clone(), children);
    }
    cell_tags.insert(
        crate::generate::REFINED_TAG.to_string(),
        (first_tet..parent.len()).collect(),
    );
    for (name, cells) in cell_tags {
        out.set_cell_tag(name, cells)?;
    }
    let mut face_tag_of: HashMap<usize, Vec<&str>> = HashMap::new();
    for (name, faces) in grid.face_tags() {
        for &f in faces {
            face_tag_of.entry(f).or_default().push(name);
        }
    }
    let mut face_tags: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for c in 0..out.num_cells() {
        for (local, &f) in out.cell_faces(c).iter().enumerate() {
            let src = loop_source[cfl.cell_pos[c] + local];
            if out.is_boundary_face(f)
                && let Some(names) = face_tag_of.get(&src)
            {
                for name in names {
                    face_tags.entry(name.to_string()).or_default().push(f);
                }
            }
        }
    }
    for (name, faces) in face_tags {
        out.set_face_tag(name, faces)?;
    }
    Ok(Tetrahedralized { grid: out, parent })
}

/// Six times the signed volume of a tetrahedron.
fn signed_volume(nodes: &[Point<3>], t: &[usize; 4]) -> f64 {
    let (a, b, c, d) = (nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]);
    (b - a).cross(&(c - a)).dot(&(d - a))
}
