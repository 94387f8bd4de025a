//! Building a [`Grid`] from cells given as oriented face loops, with validation.
//!
//! A cell is a list of faces, each an *outward-oriented* node loop: a pair `[a, b]` in 2D
//! (the polygon's edge traversed counter-clockwise), a polygon of ≥ 3 nodes in 3D
//! (right-hand rule gives the outward normal). Faces shared by two cells are recognised by
//! their node sets and must appear with opposite orientations.

use std::collections::BTreeMap;

use rayon::prelude::*;

use crate::error::{GridError, Result, cell_err};
use crate::grid::{Grid, NO_CELL};
use crate::point::{Point, assert_dim, for_each_facet};

/// Cells as outward face loops in flat arrays.
///
/// Cell `c` owns loops `cell_pos[c]..cell_pos[c+1]`; loop `k` has nodes
/// `loop_nodes[loop_pos[k]..loop_pos[k+1]]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellFaceLoops {
    /// Offsets into the loops, one per cell plus one.
    pub cell_pos: Vec<usize>,
    /// Offsets into `loop_nodes`, one per loop plus one.
    pub loop_pos: Vec<usize>,
    /// Node indices of all loops.
    pub loop_nodes: Vec<usize>,
}

impl CellFaceLoops {
    /// An empty list.
    pub fn new() -> Self {
        Self {
            cell_pos: vec![0],
            loop_pos: vec![0],
            loop_nodes: Vec::new(),
        }
    }
    /// Append one face loop to the cell under construction.
    pub fn push_face(&mut self, nodes: &[usize]) {
        self.loop_nodes.extend_from_slice(nodes);
        self.loop_pos.push(self.loop_nodes.len());
    }
    /// Close the cell under construction (its faces are those pushed since the last call).
    pub fn finish_cell(&mut self) {
        self.cell_pos.push(self.loop_pos.len() - 1);
    }
    /// Append a 2D polygon given by its nodes in counter-clockwise order.
    pub fn push_polygon(&mut self, nodes: &[usize]) {
        let m = nodes.len();
        for k in 0..m {
            self.push_face(&[nodes[k], nodes[(k + 1) % m]]);
        }
        self.finish_cell();
    }
    /// Number of cells.
    pub fn num_cells(&self) -> usize {
        self.cell_pos.len().saturating_sub(1)
    }
    /// Append the cells of `other` after these (node indices unchanged).
    pub fn append(&mut self, other: &CellFaceLoops) {
        let (loops, nodes) = (self.loop_pos.len() - 1, self.loop_nodes.len());
        self.loop_nodes.extend_from_slice(&other.loop_nodes);
        self.loop_pos
            .extend(other.loop_pos.iter().skip(1).map(|&p| p + nodes));
        self.cell_pos
            .extend(other.cell_pos.iter().skip(1).map(|&p| p + loops));
    }
    fn face_loop(&self, k: usize) -> &[usize] {
        &self.loop_nodes[self.loop_pos[k]..self.loop_pos[k + 1]]
    }
}

/// Relative tolerance below which a face area or cell volume counts as degenerate.
const DEGENERATE: f64 = 1e-13;

impl<const D: usize> Grid<D> {
    /// Build and validate a grid from node coordinates and cells given as outward face loops.
    ///
    /// Checks: finite coordinates; loop sizes (2 nodes in 2D, ≥ 3 in 3D); node indices in
    /// range; each cell's boundary closed (every directed edge matched by its reverse);
    /// faces shared by at most two cells, with opposite orientations; no unused and no
    /// coincident nodes; positive face areas and cell volumes; in 2D, no self-intersecting
    /// polygon. The first failure is returned, naming the cell, face or node.
    pub fn from_cell_faces(nodes: Vec<Point<D>>, cells: &CellFaceLoops) -> Result<Self> {
        const { assert_dim::<D>() };
        check_structure::<D>(&nodes, cells)?;
        let num_cells = cells.num_cells();
        let num_loops = cells.loop_pos.len() - 1;

        // --- Match face occurrences by their node sets. ---
        // Bucket the loops by their smallest node (a counting sort: linear, and local for
        // grids numbered with some locality), then compare the few loops of each bucket.
        let min_node = |k: usize| cells.face_loop(k).iter().copied().min().unwrap_or(0);
        let mut bucket_pos = vec![0usize; nodes.len() + 1];
        for k in 0..num_loops {
            bucket_pos[min_node(k) + 1] += 1;
        }
        for n in 0..nodes.len() {
            bucket_pos[n + 1] += bucket_pos[n];
        }
        let mut bucket_items = vec![0usize; num_loops];
        {
            let mut fill = bucket_pos.clone();
            for k in 0..num_loops {
                let m = min_node(k);
                bucket_items[fill[m]] = k;
                fill[m] += 1;
            }
        }
        const NODE_CHUNK: usize = 4096;
        let pairs: Vec<Vec<(usize, usize)>> = (0..nodes.len().div_ceil(NODE_CHUNK))
            .into_par_iter()
            .map(|ch| {
                let mut out = Vec::new();
                let mut matched = Vec::new();
                for n in ch * NODE_CHUNK..((ch + 1) * NODE_CHUNK).min(nodes.len()) {
                    let bucket = &bucket_items[bucket_pos[n]..bucket_pos[n + 1]];
                    match_bucket(cells, bucket, &mut matched, &mut out)?;
                }
                Ok(out)
            })
            .collect::<Result<_>>()?;
        drop(bucket_items);
        drop(bucket_pos);
        // rep[k] = the first occurrence (smallest loop index) with the same node set as k.
        let mut rep: Vec<usize> = (0..num_loops).collect();
        let mut partner: Vec<usize> = vec![usize::MAX; num_loops];
        for &(first, second) in pairs.iter().flatten() {
            partner[first] = second;
            rep[second] = first;
        }
        drop(pairs);
        let loop_cell = loop_owner(cells);

        // --- Number faces in order of first occurrence. ---
        let mut face_of_loop = vec![usize::MAX; num_loops];
        let mut face_node_pos = vec![0];
        let mut face_nodes = Vec::with_capacity(cells.loop_nodes.len() / 2 + 1);
        let mut face_cells: Vec<[usize; 2]> = Vec::with_capacity(num_loops / 2 + 1);
        for k in 0..num_loops {
            if rep[k] == k {
                face_of_loop[k] = face_cells.len();
                face_nodes.extend_from_slice(cells.face_loop(k));
                face_node_pos.push(face_nodes.len());
                let other = if partner[k] == usize::MAX {
                    NO_CELL
                } else {
                    loop_cell[partner[k]]
                };
                if other == loop_cell[k] {
                    return Err(cell_err(
                        loop_cell[k],
                        "the same face appears twice in the cell",
                    ));
                }
                face_cells.push([loop_cell[k], other]);
            } else {
                face_of_loop[k] = face_of_loop[rep[k]];
            }
        }
        let cell_faces = face_of_loop;
        let cell_face_outward: Vec<bool> = (0..num_loops).map(|k| rep[k] == k).collect();

        // --- Cell nodes (in chunks of cells: no per-cell allocation). ---
        const CELL_CHUNK: usize = 2048;
        let chunks: Vec<(Vec<usize>, Vec<usize>)> = (0..num_cells.div_ceil(CELL_CHUNK))
            .into_par_iter()
            .map(|ch| {
                let range = ch * CELL_CHUNK..((ch + 1) * CELL_CHUNK).min(num_cells);
                let mut counts = Vec::with_capacity(range.len());
                let mut list = Vec::with_capacity(range.len() * (D + 1));
                for c in range {
                    let before = list.len();
                    cell_node_list::<D>(cells, c, &mut list)?;
                    counts.push(list.len() - before);
                }
                Ok((counts, list))
            })
            .collect::<Result<_>>()?;
        let mut cell_node_pos = Vec::with_capacity(num_cells + 1);
        cell_node_pos.push(0);
        let mut cell_nodes = Vec::with_capacity(chunks.iter().map(|c| c.1.len()).sum());
        for (counts, list) in &chunks {
            for &k in counts {
                cell_node_pos.push(cell_node_pos[cell_node_pos.len() - 1] + k);
            }
            cell_nodes.extend_from_slice(list);
        }
        drop(chunks);

        let boundary = (0..face_cells.len())
            .filter(|&f| face_cells[f][1] == NO_CELL)
            .collect();
        let mut grid = Grid {
            nodes,
            face_node_pos,
            face_nodes,
            face_cells,
            face_area: Vec::new(),
            face_normal: Vec::new(),
            face_centroid: Vec::new(),
            cell_face_pos: cells.cell_pos.clone(),
            cell_faces,
            cell_face_outward,
            cell_node_pos,
            cell_nodes,
            cell_volume: Vec::new(),
            cell_centroid: Vec::new(),
            cell_tags: BTreeMap::new(),
            face_tags: BTreeMap::new(),
            boundary,
        };
        check_nodes_used_and_distinct(&grid)?;
        grid.compute_geometry()?;
        Ok(grid)
    }

    /// Compute face and cell geometry; fails on degenerate faces and cells.
    pub(crate) fn compute_geometry(&mut self) -> Result<()> {
        // Indexed parallel writes into preallocated arrays (a fallible `collect` would go
        // through linked lists of vectors).
        let nf = self.num_faces();
        let mut area = vec![0.0; nf];
        let mut normal = vec![Point::<D>::zeros(); nf];
        let mut centroid = vec![Point::<D>::zeros(); nf];
        area.par_iter_mut()
            .zip(normal.par_iter_mut())
            .zip(centroid.par_iter_mut())
            .enumerate()
            .try_for_each(|(f, ((a, n), c))| {
                (*a, *n, *c) = self.face_geometry(f)?;
                Ok::<(), GridError>(())
            })?;
        self.face_area = area;
        self.face_normal = normal;
        self.face_centroid = centroid;
        let nc = self.num_cells();
        let mut volume = vec![0.0; nc];
        let mut centroid = vec![Point::<D>::zeros(); nc];
        volume
            .par_iter_mut()
            .zip(centroid.par_iter_mut())
            .enumerate()
            .try_for_each(|(c, (v, x))| {
                (*v, *x) = self.cell_geometry(c)?;
                Ok::<(), GridError>(())
            })?;
        self.cell_volume = volume;
        self.cell_centroid = centroid;
        if D == 2 {
            (0..self.num_cells())
                .into_par_iter()
                .try_for_each(|c| check_simple_polygon(self, c))?;
        }
        Ok(())
    }

    fn face_geometry(&self, f: usize) -> Result<(f64, Point<D>, Point<D>)> {
        let mut pts = [Point::<D>::zeros(); 16];
        let nodes = self.face_nodes(f);
        let heap: Vec<Point<D>>;
        let p: &[Point<D>] = if nodes.len() <= 16 {
            for (k, &n) in nodes.iter().enumerate() {
                pts[k] = self.nodes[n];
            }
            &pts[..nodes.len()]
        } else {
            heap = nodes.iter().map(|&n| self.nodes[n]).collect();
            &heap
        };
        let mut area_vec = Point::<D>::zeros();
        let mut facets = [(Point::<D>::zeros(), Point::<D>::zeros()); 16];
        let mut nf = 0;
        let mut big = Vec::new();
        for_each_facet::<D>(p, |a, c, _| {
            area_vec += a;
            if nf < 16 {
                facets[nf] = (a, c);
            } else {
                big.push((a, c));
            }
            nf += 1;
        });
        let area = area_vec.norm();
        let size = face_size(p);
        if area.is_nan() || area <= DEGENERATE * size.powi(D as i32 - 1) {
            return Err(GridError::Face {
                face: f,
                nodes: nodes.to_vec(),
                what: format!("degenerate face (area {area:e})"),
            });
        }
        let normal = area_vec / area;
        let mut w_sum = 0.0;
        let mut centroid = Point::<D>::zeros();
        for (a, c) in facets[..nf.min(16)].iter().chain(big.iter()) {
            let w = a.dot(&normal);
            w_sum += w;
            centroid += c * w;
        }
        Ok((area, normal, centroid / w_sum))
    }

    fn cell_geometry(&self, c: usize) -> Result<(f64, Point<D>)> {
        let cn = self.cell_nodes(c);
        let xc = cn.iter().map(|&n| self.nodes[n]).sum::<Point<D>>() / cn.len() as f64;
        let mut vol = 0.0;
        let mut moment = Point::<D>::zeros();
        const STACK: usize = 16;
        let mut stack = [Point::<D>::zeros(); STACK];
        let mut heap: Vec<Point<D>> = Vec::new();
        for (&face, &out) in self.cell_faces(c).iter().zip(self.cell_face_outward(c)) {
            let m = self.face_nodes(face).len();
            let pts: &mut [Point<D>] = if m <= STACK {
                &mut stack[..m]
            } else {
                heap.resize(m, Point::<D>::zeros());
                &mut heap[..]
            };
            for (p, n) in pts.iter_mut().zip(self.oriented_face_nodes(face, out)) {
                *p = self.nodes[n];
            }
            for_each_facet::<D>(pts, |a, ct, _| {
                let v = a.dot(&(ct - xc)) / D as f64;
                vol += v;
                moment += (xc + ct * D as f64) * (v / (D as f64 + 1.0));
            });
        }
        let (lo, hi) = cn.iter().fold(
            (
                Point::<D>::repeat(f64::INFINITY),
                Point::<D>::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), &n| (lo.inf(&self.nodes[n]), hi.sup(&self.nodes[n])),
        );
        let size = (hi - lo).amax();
        if !vol.is_finite() || vol <= DEGENERATE * size.powi(D as i32) {
            let what = if vol < -DEGENERATE * size.powi(D as i32) {
                format!("inverted cell (signed volume {vol:e}; faces oriented inward?)")
            } else {
                format!("degenerate cell (volume {vol:e})")
            };
            return Err(cell_err(c, what));
        }
        Ok((vol, moment / vol))
    }
}

impl Grid<2> {
    /// Build a 2D grid from polygons given by their nodes in counter-clockwise order
    /// (`cell_nodes[cell_pos[c]..cell_pos[c+1]]`). Hanging nodes are simply extra polygon
    /// vertices. Validation as in [`Grid::from_cell_faces`].
    pub fn from_polygons(
        nodes: Vec<Point<2>>,
        cell_pos: &[usize],
        cell_nodes: &[usize],
    ) -> Result<Self> {
        if cell_pos.first() != Some(&0) || cell_pos.last() != Some(&cell_nodes.len()) {
            return Err(GridError::Input(
                "polygon offsets must start at 0 and end at the node count".into(),
            ));
        }
        let mut loops = CellFaceLoops::new();
        loops.loop_nodes.reserve(2 * cell_nodes.len());
        for (c, w) in cell_pos.windows(2).enumerate() {
            if w[1] < w[0] + 3 {
                return Err(cell_err(
                    c,
                    format!(
                        "a polygon needs at least 3 nodes, got {}",
                        w[1].saturating_sub(w[0])
                    ),
                ));
            }
            loops.push_polygon(&cell_nodes[w[0]..w[1]]);
        }
        Self::from_cell_faces(nodes, &loops)
    }
}

fn face_size<const D: usize>(p: &[Point<D>]) -> f64 {
    let mut s: f64 = 0.0;
    for a in p {
        s = s.max((a - p[0]).amax());
    }
    s
}

/// Whether two loops (each without repeated nodes) have the same node set.
fn same_node_set(a: &[usize], b: &[usize]) -> bool {
    a.len() == b.len() && a.iter().all(|n| b.contains(n))
}

/// Pair up the loops of one bucket (loops sharing their smallest node, in increasing
/// loop order) that have equal node sets; pairs `(first, second)` go to `out`.
fn match_bucket(
    cells: &CellFaceLoops,
    bucket: &[usize],
    matched: &mut Vec<bool>,
    out: &mut Vec<(usize, usize)>,
) -> Result<()> {
    if bucket.len() < 2 {
        return Ok(());
    }
    matched.clear();
    matched.resize(bucket.len(), false);
    for x in 0..bucket.len() {
        if matched[x] {
            continue;
        }
        let a = bucket[x];
        let la = cells.face_loop(a);
        let mut found = false;
        for y in x + 1..bucket.len() {
            let b = bucket[y];
            let lb = cells.face_loop(b);
            if matched[y] || !same_node_set(la, lb) {
                continue;
            }
            if found {
                return Err(GridError::Face {
                    face: a,
                    nodes: la.to_vec(),
                    what: "shared by more than two cells".into(),
                });
            }
            if !is_reversed(la, lb) {
                return Err(GridError::Face {
                    face: a,
                    nodes: la.to_vec(),
                    what:
                        "its two cells give it the same orientation (inconsistent or inverted cell)"
                            .into(),
                });
            }
            found = true;
            matched[y] = true;
            out.push((a, b));
        }
    }
    Ok(())
}

/// Whether loop `b` is loop `a` traversed backwards (up to a cyclic shift).
fn is_reversed(a: &[usize], b: &[usize]) -> bool {
    let m = a.len();
    if m == 2 {
        // A 2D face is a directed segment: a cyclic shift of [b, a] is [a, b] itself.
        return b[0] == a[1] && b[1] == a[0];
    }
    let Some(p) = b.iter().position(|&n| n == a[0]) else {
        return false;
    };
    (0..m).all(|k| b[(p + m - k) % m] == a[k])
}

fn loop_owner(cells: &CellFaceLoops) -> Vec<usize> {
    let mut owner = vec![0; cells.loop_pos.len() - 1];
    for (c, w) in cells.cell_pos.windows(2).enumerate() {
        owner[w[0]..w[1]].iter_mut().for_each(|o| *o = c);
    }
    owner
}

fn check_structure<const D: usize>(nodes: &[Point<D>], cells: &CellFaceLoops) -> Result<()> {
    if let Some(n) = nodes.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
        return Err(GridError::Node {
            node: n,
            what: format!("non-finite coordinate {:?}", nodes[n].as_slice()),
        });
    }
    let offsets_ok = |pos: &[usize], len: usize| {
        pos.first() == Some(&0) && pos.last() == Some(&len) && pos.windows(2).all(|w| w[0] <= w[1])
    };
    if !offsets_ok(&cells.loop_pos, cells.loop_nodes.len())
        || !offsets_ok(&cells.cell_pos, cells.loop_pos.len() - 1)
    {
        return Err(GridError::Input(
            "cell/face offsets are not monotone or do not match the arrays".into(),
        ));
    }
    if cells.num_cells() == 0 {
        return Err(GridError::Input("the grid has no cells".into()));
    }
    let scratch = || (Vec::new(), Vec::new(), Vec::new());
    (0..cells.num_cells()).into_par_iter().try_for_each_init(scratch, |(edges, starts, ends): &mut (Vec<(usize, usize)>, Vec<usize>, Vec<usize>), c| {
        let loops = cells.cell_pos[c]..cells.cell_pos[c + 1];
        if loops.len() < D + 1 {
            return Err(cell_err(c, format!("{} faces; a {D}D cell needs at least {}", loops.len(), D + 1)));
        }
        for k in loops.clone() {
            let l = cells.face_loop(k);
            if (D == 2 && l.len() != 2) || (D == 3 && l.len() < 3) {
                return Err(cell_err(c, format!("face {:?} has {} nodes", l, l.len())));
            }
            if let Some(&n) = l.iter().find(|&&n| n >= nodes.len()) {
                return Err(cell_err(c, format!("node {n} does not exist ({} nodes)", nodes.len())));
            }
            for i in 0..l.len() {
                if l[i + 1..].contains(&l[i]) {
                    return Err(cell_err(c, format!("face {l:?} repeats node {}", l[i])));
                }
            }
        }
        // Closed boundary: each directed edge (a, b) of the face loops has a reverse (b, a).
        edges.clear();
        for k in loops {
            let l = cells.face_loop(k);
            let m = l.len();
            let count = if D == 2 { 1 } else { m };
            for i in 0..count {
                edges.push((l[i], l[(i + 1) % m]));
            }
        }
        if D == 2 {
            // Edges (a, b): every node is the start of exactly one edge and the end of one.
            starts.clear();
            starts.extend(edges.iter().map(|e| e.0));
            ends.clear();
            ends.extend(edges.iter().map(|e| e.1));
            starts.sort_unstable();
            ends.sort_unstable();
            if starts != ends || starts.windows(2).any(|w| w[0] == w[1]) {
                return Err(cell_err(c, "polygon boundary is not one closed loop of distinct nodes"));
            }
        } else {
            edges.sort_unstable();
            if edges.windows(2).any(|w| w[0] == w[1]) {
                return Err(cell_err(c, "two faces traverse an edge in the same direction (inconsistent face orientation)"));
            }
            for &(a, b) in edges.iter() {
                if edges.binary_search(&(b, a)).is_err() {
                    return Err(cell_err(c, format!("not closed: edge {a}-{b} belongs to only one face")));
                }
            }
        }
        Ok(())
    })
}

/// Append the cell's node list to `out`: in 2D the polygon in loop order (chained), in
/// 3D the nodes in order of first appearance in the cell's faces.
fn cell_node_list<const D: usize>(
    cells: &CellFaceLoops,
    c: usize,
    out: &mut Vec<usize>,
) -> Result<()> {
    let loops = cells.cell_pos[c]..cells.cell_pos[c + 1];
    let start = out.len();
    if D == 2 {
        let m = loops.len();
        let edge = |k: usize| {
            let l = cells.face_loop(loops.start + k);
            (l[0], l[1])
        };
        let mut cur = edge(0).0;
        // Start the search at the edge after the last one used (the common case of a
        // polygon given in order makes this linear).
        let mut at = 0;
        for _ in 0..m {
            out.push(cur);
            let next = (0..m)
                .map(|s| (at + s) % m)
                .find(|&k| edge(k).0 == cur)
                .ok_or_else(|| cell_err(c, "polygon boundary is not closed"))?;
            cur = edge(next).1;
            at = next + 1;
        }
        if cur != out[start] {
            return Err(cell_err(c, "polygon boundary is more than one loop"));
        }
    } else {
        for k in loops {
            for &n in cells.face_loop(k) {
                if !out[start..].contains(&n) {
                    out.push(n);
                }
            }
        }
    }
    Ok(())
}

fn check_nodes_used_and_distinct<const D: usize>(g: &Grid<D>) -> Result<()> {
    let mut used = vec![false; g.nodes.len()];
    for &n in &g.cell_nodes {
        used[n] = true;
    }
    if let Some(n) = used.iter().position(|u| !u) {
        return Err(GridError::Node {
            node: n,
            what: "not used by any cell".into(),
        });
    }
    // Sort (coordinate keys, node) records: equal coordinates become neighbours. The key
    // is a total order on finite floats (sign-flipped bits) with −0 mapped to +0.
    let key = |x: f64| {
        let b = (x + 0.0).to_bits();
        if b >> 63 == 1 { !b } else { b | (1 << 63) }
    };
    let mut order: Vec<([u64; D], usize)> = g
        .nodes
        .par_iter()
        .enumerate()
        .map(|(n, p)| (std::array::from_fn(|a| key(p[a])), n))
        .collect();
    order.par_sort_unstable();
    for w in order.windows(2) {
        if w[0].0 == w[1].0 {
            let (a, b) = (w[0].1, w[1].1);
            return Err(GridError::Node {
                node: a.max(b),
                what: format!("coincides with node {}", a.min(b)),
            });
        }
    }
    Ok(())
}

/// A 2D polygon must not cross itself: no two non-adjacent edges intersect.
fn check_simple_polygon<const D: usize>(g: &Grid<D>, c: usize) -> Result<()> {
    let cn = g.cell_nodes(c);
    let m = cn.len();
    if m <= 3 {
        return Ok(());
    }
    let p = |i: usize| {
        let x = &g.nodes[cn[i % m]];
        [x[0], x[1]]
    };
    let orient = |a: [f64; 2], b: [f64; 2], q: [f64; 2]| {
        (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0])
    };
    for i in 0..m {
        for j in i + 2..m {
            if i == 0 && j == m - 1 {
                continue;
            }
            let (a, b, c2, d) = (p(i), p(i + 1), p(j), p(j + 1));
            let d1 = orient(a, b, c2);
            let d2 = orient(a, b, d);
            let d3 = orient(c2, d, a);
            let d4 = orient(c2, d, b);
            if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
                return Err(cell_err(
                    c,
                    format!(
                        "self-intersecting polygon: edges {}-{} and {}-{} cross",
                        cn[i],
                        cn[(i + 1) % m],
                        cn[j],
                        cn[(j + 1) % m]
                    ),
                ));
            }
        }
    }
    Ok(())
}

// Keep generic bound checks in one place.
#[allow(dead_code)]
fn _assert_send_sync() {
    fn f<T: Send + Sync>() {}
    f::<Grid<2>>();
    f::<Grid<3>>();
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64) -> Point<2> {
        Point::<2>::new(x, y)
    }

    #[test]
    fn shared_faces_are_matched_and_checked() {
        // Two triangles sharing the edge 0–1: 5 faces, one interior.
        let nodes = vec![p(0.0, 0.0), p(1.0, 0.0), p(0.5, 1.0), p(0.5, -1.0)];
        let g = Grid::from_polygons(nodes.clone(), &[0, 3, 6], &[0, 1, 2, 1, 0, 3]).unwrap();
        assert_eq!(g.num_faces(), 5);
        assert_eq!(g.boundary_faces().len(), 4);
        assert_eq!(g.face_cells(0), (0, Some(1)));
        // Same orientation on the shared edge (the second triangle clockwise).
        let e = Grid::from_polygons(nodes.clone(), &[0, 3, 6], &[0, 1, 2, 0, 1, 3]);
        assert!(
            matches!(&e, Err(GridError::Face { what, .. }) if what.contains("same orientation")),
            "{e:?}"
        );
        // Two triangles without a shared edge but with coincident nodes 1 and 4.
        let mut dup = nodes.clone();
        dup.push(p(1.0, 0.0));
        let e = Grid::from_polygons(dup, &[0, 3, 6], &[0, 1, 2, 4, 0, 3]);
        assert!(
            matches!(&e, Err(GridError::Node { node: 4, what }) if what.contains("coincides with node 1")),
            "{e:?}"
        );
        // Three cells on one edge.
        let mut nodes3 = nodes;
        nodes3.push(p(0.5, 2.0));
        let e = Grid::from_polygons(nodes3, &[0, 3, 6, 9], &[0, 1, 2, 1, 0, 3, 0, 1, 4]);
        assert!(
            matches!(&e, Err(GridError::Face { what, .. }) if what.contains("more than two")),
            "{e:?}"
        );
    }
}
