//! The [`Grid`] type: flat topology arrays with offsets, and the geometry computed once.

use std::collections::BTreeMap;

use crate::error::{GridError, Result};
use crate::point::{Point, for_each_facet};

/// Marker for "no cell" on the outer side of a boundary face.
pub const NO_CELL: usize = usize::MAX;

/// A polygonal (D = 2) or polyhedral (D = 3) grid.
///
/// See the crate documentation for the data model. All arrays are flat with offset
/// arrays (`*_pos`, length `n + 1`), in the style of reservoir simulators.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid<const D: usize> {
    pub(crate) nodes: Vec<Point<D>>,
    // faces
    pub(crate) face_node_pos: Vec<usize>,
    pub(crate) face_nodes: Vec<usize>,
    pub(crate) face_cells: Vec<[usize; 2]>,
    pub(crate) face_area: Vec<f64>,
    pub(crate) face_normal: Vec<Point<D>>,
    pub(crate) face_centroid: Vec<Point<D>>,
    // cells
    pub(crate) cell_face_pos: Vec<usize>,
    pub(crate) cell_faces: Vec<usize>,
    pub(crate) cell_face_outward: Vec<bool>,
    pub(crate) cell_node_pos: Vec<usize>,
    pub(crate) cell_nodes: Vec<usize>,
    pub(crate) cell_volume: Vec<f64>,
    pub(crate) cell_centroid: Vec<Point<D>>,
    // tags
    pub(crate) cell_tags: BTreeMap<String, Vec<usize>>,
    pub(crate) face_tags: BTreeMap<String, Vec<usize>>,
    /// The faces with one cell, ascending (the topology never changes after building).
    pub(crate) boundary: Vec<usize>,
}

/// Names of the bounding-box sides, in the order `[x, y, z] × [min, max]`.
pub const SIDE_NAMES: [&str; 6] = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"];

impl<const D: usize> Grid<D> {
    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }
    /// Number of faces (edges in 2D).
    pub fn num_faces(&self) -> usize {
        self.face_cells.len()
    }
    /// Number of cells.
    pub fn num_cells(&self) -> usize {
        self.cell_face_pos.len() - 1
    }
    /// All node coordinates.
    pub fn nodes(&self) -> &[Point<D>] {
        &self.nodes
    }
    /// Coordinates of node `n`.
    pub fn node(&self, n: usize) -> &Point<D> {
        &self.nodes[n]
    }

    /// Nodes of face `f`, ordered so that the right-hand rule (3D) or a clockwise rotation
    /// of `b − a` (2D) gives the normal, which points from [`Self::face_cells`]`[0]` to `[1]`.
    pub fn face_nodes(&self, f: usize) -> &[usize] {
        &self.face_nodes[self.face_node_pos[f]..self.face_node_pos[f + 1]]
    }
    /// The two cells of face `f`: the normal points from the first to the second. The second
    /// is `None` on the boundary.
    pub fn face_cells(&self, f: usize) -> (usize, Option<usize>) {
        let [a, b] = self.face_cells[f];
        (a, (b != NO_CELL).then_some(b))
    }
    /// Whether face `f` lies on the boundary (has one cell).
    pub fn is_boundary_face(&self, f: usize) -> bool {
        self.face_cells[f][1] == NO_CELL
    }
    /// Area of face `f` (length in 2D): the norm of the sum of its facet area vectors.
    pub fn face_area(&self, f: usize) -> f64 {
        self.face_area[f]
    }
    /// Unit normal of face `f`, from its first cell to its second.
    pub fn face_normal(&self, f: usize) -> &Point<D> {
        &self.face_normal[f]
    }
    /// Centroid of face `f` (facet centroids weighted by facet area along the normal).
    pub fn face_centroid(&self, f: usize) -> &Point<D> {
        &self.face_centroid[f]
    }

    /// Faces of cell `c`.
    pub fn cell_faces(&self, c: usize) -> &[usize] {
        &self.cell_faces[self.cell_face_pos[c]..self.cell_face_pos[c + 1]]
    }
    /// For each face of [`Self::cell_faces`]: whether the face normal points out of `c`.
    pub fn cell_face_outward(&self, c: usize) -> &[bool] {
        &self.cell_face_outward[self.cell_face_pos[c]..self.cell_face_pos[c + 1]]
    }
    /// Nodes of cell `c`: counter-clockwise in 2D; in 3D in order of first appearance in
    /// the cell's faces.
    pub fn cell_nodes(&self, c: usize) -> &[usize] {
        &self.cell_nodes[self.cell_node_pos[c]..self.cell_node_pos[c + 1]]
    }
    /// Volume of cell `c` (area in 2D).
    pub fn cell_volume(&self, c: usize) -> f64 {
        self.cell_volume[c]
    }
    /// Centroid of cell `c`.
    pub fn cell_centroid(&self, c: usize) -> &Point<D> {
        &self.cell_centroid[c]
    }
    /// All cell volumes.
    pub fn cell_volumes(&self) -> &[f64] {
        &self.cell_volume
    }
    /// All cell centroids.
    pub fn cell_centroids(&self) -> &[Point<D>] {
        &self.cell_centroid
    }
    /// Largest number of nodes of any cell.
    pub fn max_cell_nodes(&self) -> usize {
        self.cell_node_pos
            .windows(2)
            .map(|w| w[1] - w[0])
            .max()
            .unwrap_or(0)
    }

    /// Nodes of `face` in the order that makes its normal point out of a cell for which
    /// `outward` (from [`Self::cell_face_outward`]) is the given flag.
    pub fn oriented_face_nodes(
        &self,
        face: usize,
        outward: bool,
    ) -> impl Iterator<Item = usize> + '_ {
        let nodes = self.face_nodes(face);
        let len = nodes.len();
        (0..len).map(move |k| {
            if outward {
                nodes[k]
            } else {
                nodes[len - 1 - k]
            }
        })
    }

    /// Boundary integrals of the nodal hat functions times the outward normal,
    /// `N_i = ∫_∂K φ_i n dS`, for the nodes of cell `c` in the order of
    /// [`Self::cell_nodes`], written to `out` (length = number of cell nodes).
    ///
    /// On each face φ is linear on the facets of the shared triangulation, with the value
    /// at a face point `x̄` equal to the average of the face's vertex values, so
    /// `Σ_i N_i ⊗ x_i = |K| I` holds exactly (the discrete divergence theorem behind the
    /// VEM consistency and the Biot `div_d`; Nilsen et al. (2017) eqs. 24–26).
    /// In 2D this is `N_i = ½ R(x_{i+1} − x_{i−1})`, R the clockwise rotation.
    ///
    /// On a simplex the face integrals have the closed form `N_i = |K| ∇λ_i` (λ the
    /// barycentric coordinates), computed from the node coordinates alone.
    pub fn cell_node_normals(&self, c: usize, out: &mut [Point<D>]) {
        let cn = self.cell_nodes(c);
        assert_eq!(out.len(), cn.len(), "cell_node_normals: output length");
        if cn.len() == D + 1 && self.simplex_node_normals(c, out) {
            return;
        }
        self.face_node_normals(c, out);
    }

    /// [`Self::cell_node_normals`] by the facets of the cell's faces (any cell).
    fn face_node_normals(&self, c: usize, out: &mut [Point<D>]) {
        let cn = self.cell_nodes(c);
        out.iter_mut().for_each(|q| *q = Point::<D>::zeros());
        const STACK: usize = 32;
        let mut pts = [Point::<D>::zeros(); STACK];
        let mut loc = [0usize; STACK];
        let mut heap: (Vec<Point<D>>, Vec<usize>) = (Vec::new(), Vec::new());
        for (&face, &out_flag) in self.cell_faces(c).iter().zip(self.cell_face_outward(c)) {
            let m = self.face_nodes(face).len();
            let (p, l): (&mut [Point<D>], &mut [usize]) = if m <= STACK {
                (&mut pts[..m], &mut loc[..m])
            } else {
                heap.0.resize(m, Point::<D>::zeros());
                heap.1.resize(m, 0);
                (&mut heap.0[..], &mut heap.1[..])
            };
            for (k, g) in self.oriented_face_nodes(face, out_flag).enumerate() {
                p[k] = self.nodes[g];
                // Invariant of a validated grid: every face node is a cell node.
                l[k] = cn
                    .iter()
                    .position(|&n| n == g)
                    .expect("face node belongs to its cell");
            }
            for_each_facet::<D>(p, |a, _centroid, corners| {
                if D == 2 {
                    // ∫_e φ n ds = |e| n / 2 for both ends of the edge.
                    out[l[0]] += a * 0.5;
                    out[l[1]] += a * 0.5;
                } else if corners[2] != usize::MAX {
                    for &k in &corners {
                        out[l[k]] += a / 3.0;
                    }
                } else {
                    // Triangle (x_k, x_k+1, x̄): each corner gets a/3; x̄ spreads its a/3
                    // evenly over the m face vertices.
                    out[l[corners[0]]] += a / 3.0;
                    out[l[corners[1]]] += a / 3.0;
                    let share = a / (3.0 * m as f64);
                    for &lk in l.iter() {
                        out[lk] += share;
                    }
                }
            });
        }
    }

    /// `N_i = |K| ∇λ_i` of simplex `c`: with the edge matrix `J = [x_1 − x_0, …, x_D − x_0]`,
    /// `∇λ_k` is row `k − 1` of `J⁻¹` for `k ≥ 1` and `∇λ_0 = −Σ_k ∇λ_k`, so
    /// `Σ_i N_i ⊗ x_i = |K| J⁻ᵀ Jᵀ = |K| I`. False (nothing written) for a singular `J`.
    fn simplex_node_normals(&self, c: usize, out: &mut [Point<D>]) -> bool {
        let cn = self.cell_nodes(c);
        let x0 = self.nodes[cn[0]];
        let j = nalgebra::SMatrix::<f64, D, D>::from_fn(|r, k| self.nodes[cn[k + 1]][r] - x0[r]);
        let Some(inv) = j.try_inverse() else {
            return false;
        };
        let vol = self.cell_volume(c);
        let mut sum = Point::<D>::zeros();
        for k in 0..D {
            let nk = inv.row(k).transpose() * vol;
            out[k + 1] = nk;
            sum += nk;
        }
        out[0] = -sum;
        true
    }

    /// Named cell tags (e.g. `well`, or the physical groups of an imported mesh).
    pub fn cell_tags(&self) -> &BTreeMap<String, Vec<usize>> {
        &self.cell_tags
    }
    /// Named face tags (boundary or interior faces).
    pub fn face_tags(&self) -> &BTreeMap<String, Vec<usize>> {
        &self.face_tags
    }
    /// Tag the given cells with `name` (replacing an existing tag of that name).
    pub fn set_cell_tag(&mut self, name: impl Into<String>, mut cells: Vec<usize>) -> Result<()> {
        cells.sort_unstable();
        cells.dedup();
        if let Some(&c) = cells.iter().find(|&&c| c >= self.num_cells()) {
            return Err(GridError::Input(format!(
                "cell tag lists cell {c}, grid has {}",
                self.num_cells()
            )));
        }
        self.cell_tags.insert(name.into(), cells);
        Ok(())
    }
    /// Tag the given faces with `name` (replacing an existing tag of that name).
    pub fn set_face_tag(&mut self, name: impl Into<String>, mut faces: Vec<usize>) -> Result<()> {
        faces.sort_unstable();
        faces.dedup();
        if let Some(&f) = faces.iter().find(|&&f| f >= self.num_faces()) {
            return Err(GridError::Input(format!(
                "face tag lists face {f}, grid has {}",
                self.num_faces()
            )));
        }
        self.face_tags.insert(name.into(), faces);
        Ok(())
    }

    /// Axis-aligned bounding box `(min, max)` of the nodes.
    pub fn bounding_box(&self) -> (Point<D>, Point<D>) {
        let mut lo = Point::<D>::repeat(f64::INFINITY);
        let mut hi = Point::<D>::repeat(f64::NEG_INFINITY);
        for p in &self.nodes {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        (lo, hi)
    }

    /// All boundary faces.
    pub fn boundary_faces(&self) -> Vec<usize> {
        self.boundary.clone()
    }

    /// Boundary faces on a named side of the bounding box (`xmin` … `zmax`) or carrying a
    /// face tag of that name.
    ///
    /// A boundary face lies on a side when all its nodes are within `1e-9` of the box size
    /// of that side's plane; this works for generated and imported grids alike.
    pub fn boundary(&self, name: &str) -> Result<Vec<usize>> {
        if let Some(k) = SIDE_NAMES[..2 * D].iter().position(|&s| s == name) {
            // The bounding box of the grid is that of its boundary nodes.
            let mut lo = Point::<D>::repeat(f64::INFINITY);
            let mut hi = Point::<D>::repeat(f64::NEG_INFINITY);
            for &f in &self.boundary {
                for &n in self.face_nodes(f) {
                    lo = lo.inf(&self.nodes[n]);
                    hi = hi.sup(&self.nodes[n]);
                }
            }
            let axis = k / 2;
            let plane = if k % 2 == 0 { lo[axis] } else { hi[axis] };
            let tol = 1e-9 * (hi - lo).amax().max(f64::MIN_POSITIVE);
            return Ok(self
                .boundary
                .iter()
                .copied()
                .filter(|&f| {
                    self.face_nodes(f)
                        .iter()
                        .all(|&n| (self.nodes[n][axis] - plane).abs() <= tol)
                })
                .collect());
        }
        if let Some(faces) = self.face_tags.get(name) {
            return Ok(faces.clone());
        }
        let mut known: Vec<&str> = SIDE_NAMES[..2 * D].to_vec();
        known.extend(self.face_tags.keys().map(String::as_str));
        Err(GridError::UnknownName {
            name: name.to_string(),
            known: known.join(", "),
        })
    }

    /// The nodes of a set of faces, sorted and without repetition.
    pub fn nodes_of_faces(&self, faces: &[usize]) -> Vec<usize> {
        let mut n: Vec<usize> = faces
            .iter()
            .flat_map(|&f| self.face_nodes(f).iter().copied())
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }
}

impl Grid<3> {
    /// Volume enclosed by the faces of cell `c`, each face split into triangles about its
    /// vertex average: `V = Σ ((a − o) × (b − o)) · (m − o) / 6` over the outward
    /// triangles `(m, a, b)`, about a node `o` of the cell (about the origin, map
    /// coordinates in the millions would cancel the digits). Independent of how the
    /// grid's own cell volumes are computed, it checks them and the faces' orientation.
    pub fn enclosed_volume(&self, c: usize) -> f64 {
        let o = *self.node(self.cell_nodes(c)[0]);
        let mut v = 0.0;
        for (&f, &out) in self.cell_faces(c).iter().zip(self.cell_face_outward(c)) {
            let nodes = self.face_nodes(f);
            let m = nodes.iter().map(|&n| self.node(n) - o).sum::<Point<3>>() / nodes.len() as f64;
            let mut s = 0.0;
            for k in 0..nodes.len() {
                let a = self.node(nodes[k]) - o;
                let b = self.node(nodes[(k + 1) % nodes.len()]) - o;
                s += a.cross(&b).dot(&m);
            }
            v += if out { s } else { -s } / 6.0;
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use crate::Point;
    use crate::generate::{perturb, simplices};

    /// The closed form on simplices agrees with the face integrals.
    #[test]
    fn simplex_node_normals_match_the_face_integrals() {
        fn check<const D: usize>(g: &crate::Grid<D>) {
            let (mut a, mut b) = (
                vec![Point::<D>::zeros(); D + 1],
                vec![Point::<D>::zeros(); D + 1],
            );
            for c in 0..g.num_cells() {
                assert!(g.simplex_node_normals(c, &mut a));
                g.face_node_normals(c, &mut b);
                let scale = b.iter().map(|v| v.norm()).sum::<f64>();
                for (x, y) in a.iter().zip(&b) {
                    assert!((x - y).norm() <= 1e-13 * scale, "cell {c}: {x} against {y}");
                }
            }
        }
        let g2 = simplices(Point::<2>::zeros(), Point::<2>::new(2.0, 1.0), [7, 5]).unwrap();
        check(&perturb(&g2, 0.3, 7).unwrap());
        let g3 = simplices(
            Point::<3>::zeros(),
            Point::<3>::new(1.0, 2.0, 0.5),
            [3, 4, 2],
        )
        .unwrap();
        check(&perturb(&g3, 0.3, 11).unwrap());
    }
}
