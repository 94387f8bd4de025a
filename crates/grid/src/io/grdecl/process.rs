//! Turning a deck's pillars and corner depths into a polyhedral grid (see the
//! [module docs](super)).

use std::collections::BTreeMap;

use rayon::prelude::*;

use crate::builder::CellFaceLoops;
use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::point::Point;

use super::deck::Deck;

/// Tolerance of the processing, relative to the depths of the deck (the largest depth of
/// its corners and pillar ends): depths closer than this on a pillar are one node, and a
/// cell thinner than this at all four pillars is pinched out. Map coordinates do not
/// count: with UTM coordinates (millions of metres) the tolerance would be millimetres,
/// as large as real differences of depth.
pub const RELATIVE_TOLERANCE: f64 = 1e-9;

/// A corner-point grid as a polyhedral grid, with each cell's place in the deck.
#[derive(Clone, Debug)]
pub struct CornerPointGrid {
    /// The grid: faces split where neighbouring columns do not match, outer faces tagged
    /// `imin` … `kmax`.
    pub grid: Grid<3>,
    /// `(i, j, k)` of every cell (0-based).
    pub ijk: Vec<[usize; 3]>,
    /// The deck index `i + nx (j + ny k)` of every cell (to pick its properties).
    pub deck_cell: Vec<usize>,
    /// Active deck cells left out because their thickness is zero.
    pub pinched: usize,
    /// Deck cells with `ACTNUM = 0`.
    pub inactive: usize,
}

impl CornerPointGrid {
    /// The interior faces of the fault `name`; see [`fault_faces`].
    pub fn fault_faces(&self, faults: &[super::deck::FaultSegment], name: &str) -> Vec<usize> {
        fault_faces(&self.grid, &self.ijk, faults, name)
    }
}

/// The interior faces of the fault `name` of a grid whose cells have the deck indices
/// `ijk` (several cells may share one, e.g. the tetrahedra of an MDEM zone): for each of
/// its `FAULTS` segments, the faces between the segment's cells and the cells across
/// its side (the neighbouring column, or a deeper or shallower cell of the column).
/// Empty if the deck has no such fault.
pub fn fault_faces(
    grid: &Grid<3>,
    ijk: &[[usize; 3]],
    faults: &[super::deck::FaultSegment],
    name: &str,
) -> Vec<usize> {
    use super::deck::FaultFace::*;
    let segments: Vec<_> = faults.iter().filter(|s| s.name == name).collect();
    let inside = |c: [usize; 3], r: &[[usize; 2]; 3]| {
        (0..3).all(|a| (r[a][0]..=r[a][1]).contains(&(c[a] + 1)))
    };
    // Whether `b` lies across face `face` of `a`.
    let across = |a: [usize; 3], b: [usize; 3], face: super::deck::FaultFace| {
        let (di, dj) = (b[0] as isize - a[0] as isize, b[1] as isize - a[1] as isize);
        match face {
            XPlus => di == 1 && dj == 0,
            XMinus => di == -1 && dj == 0,
            YPlus => di == 0 && dj == 1,
            YMinus => di == 0 && dj == -1,
            ZPlus => di == 0 && dj == 0 && b[2] > a[2],
            ZMinus => di == 0 && dj == 0 && b[2] < a[2],
        }
    };
    (0..grid.num_faces())
        .filter(|&f| {
            let (a, Some(b)) = grid.face_cells(f) else {
                return false;
            };
            let (a, b) = (ijk[a], ijk[b]);
            segments.iter().any(|s| {
                (inside(a, &s.ijk) && across(a, b, s.face))
                    || (inside(b, &s.ijk) && across(b, a, s.face))
            })
        })
        .collect()
}

/// Names of the six ijk sides, tagged on the boundary faces that face them.
pub const IJK_SIDES: [&str; 6] = ["imin", "imax", "jmin", "jmax", "kmin", "kmax"];

/// An element of a column's stack along a pillar pair: a cell, or the gap between two
/// cells (or above the first, below the last). `top` and `bot` are the depths at the
/// pair's two pillars (`s = 0`, `s = 1`); along the pair they vary linearly in `s`.
#[derive(Clone, Copy, Debug)]
struct Elem {
    cell: Option<usize>,
    top: [f64; 2],
    bot: [f64; 2],
}

/// Depth of a line given at `s = 0` and `s = 1`, at `s`.
fn at(line: [f64; 2], s: f64) -> f64 {
    line[0] + (line[1] - line[0]) * s
}

/// Where two lines cross in `0 < s < 1`.
fn crossing(f: [f64; 2], g: [f64; 2]) -> Option<f64> {
    let den = (f[1] - f[0]) - (g[1] - g[0]);
    if den == 0.0 {
        return None;
    }
    let s = (g[0] - f[0]) / den;
    (s > 0.0 && s < 1.0).then_some(s)
}

/// A depth far above or below any cell (the ends of a column's stack).
const FAR: f64 = 1e30;

/// A sub-face: the overlap of two stack elements on a pillar pair.
struct SubFace {
    pair: usize,
    /// The cell on the side of lower `i` (or `j`) and the one on the other side.
    cells: [Option<usize>; 2],
    /// Vertices `verts[start..end]`.
    start: usize,
    end: usize,
}

/// A vertex of a sub-face on its pillar pair.
#[derive(Clone, Copy, Debug)]
struct Vertex {
    s: f64,
    z: f64,
    node: usize,
}

struct Builder<'a> {
    deck: &'a Deck,
    nx: usize,
    ny: usize,
    tol: f64,
    nodes: Vec<Point<3>>,
    /// Per pillar: its nodes as `(depth, node)` sorted by depth.
    pillar_pos: Vec<usize>,
    pillar_nodes: Vec<(f64, usize)>,
    /// Per pillar pair: the nodes inside the pair's surface (`0 < s < 1`).
    crossing_pos: Vec<usize>,
    crossings: Vec<Vertex>,
    subfaces: Vec<SubFace>,
    verts: Vec<Vertex>,
    /// Scratch: the polygon of an overlap in `(s, z)`.
    polygon: Vec<(f64, f64)>,
    /// Whether `i`, `j` and the depth make a right-handed frame (see
    /// [`right_handed`]).
    right_handed: bool,
}

/// Process a deck into a polyhedral grid.
pub fn corner_point_grid(deck: &Deck) -> Result<CornerPointGrid> {
    let [nx, ny, nz] = deck.dims;
    let n = nx * ny * nz;
    if deck.coord.len() != 6 * (nx + 1) * (ny + 1) || deck.zcorn.len() != 8 * n {
        return Err(GridError::Input(format!(
            "corner-point grid {nx} × {ny} × {nz}: COORD has {} values (needs {}), ZCORN {} \
             (needs {})",
            deck.coord.len(),
            6 * (nx + 1) * (ny + 1),
            deck.zcorn.len(),
            8 * n
        )));
    }
    // Depths only: map coordinates (UTM, millions of metres) would make the tolerance
    // millimetres, as large as real differences of depth.
    let scale = deck
        .coord
        .chunks(3)
        .map(|p| p[2])
        .chain(deck.zcorn.iter().copied())
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    let tol = RELATIVE_TOLERANCE * scale;
    let mut builder = Builder {
        deck,
        nx,
        ny,
        tol,
        nodes: Vec::new(),
        pillar_pos: Vec::new(),
        pillar_nodes: Vec::new(),
        crossing_pos: vec![0],
        crossings: Vec::new(),
        subfaces: Vec::new(),
        verts: Vec::new(),
        polygon: Vec::new(),
        right_handed: right_handed(deck)?,
    };
    let b = &mut builder;
    // --- Active cells (ACTNUM, not pinched), numbered in deck order. ---
    let mut cell_of = vec![usize::MAX; n];
    let mut ijk = Vec::new();
    let mut deck_cell = Vec::new();
    let (mut pinched, mut inactive) = (0, 0);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let d = i + nx * (j + ny * k);
                if deck.actnum.as_ref().is_some_and(|a| !a[d]) {
                    inactive += 1;
                    continue;
                }
                let mut thick = false;
                for c in 0..4 {
                    let (t, bt) = (b.z(i, j, k, c, 0), b.z(i, j, k, c, 1));
                    if bt < t - tol {
                        return Err(GridError::Input(format!(
                            "cell (i, j, k) = ({}, {}, {}) (1-based): the bottom is above the \
                             top at corner {} (ZCORN {} above {})",
                            i + 1,
                            j + 1,
                            k + 1,
                            c + 1,
                            bt,
                            t
                        )));
                    }
                    thick |= bt - t > tol;
                }
                if !thick {
                    pinched += 1;
                    continue;
                }
                cell_of[d] = ijk.len();
                ijk.push([i, j, k]);
                deck_cell.push(d);
            }
        }
    }
    if ijk.is_empty() {
        return Err(GridError::Input(
            "corner-point grid: no active cell of non-zero thickness".into(),
        ));
    }
    // --- Columns: their active cells from top to bottom, checked for overlaps. ---
    let mut column_pos = vec![0usize; nx * ny + 1];
    for &[i, j, _] in &ijk {
        column_pos[i + nx * j + 1] += 1;
    }
    for c in 0..nx * ny {
        column_pos[c + 1] += column_pos[c];
    }
    let mut column_cells = vec![0usize; ijk.len()];
    {
        let mut fill = column_pos.clone();
        for (c, &[i, j, _]) in ijk.iter().enumerate() {
            column_cells[fill[i + nx * j]] = c;
            fill[i + nx * j] += 1;
        }
    }
    for col in 0..nx * ny {
        for w in column_cells[column_pos[col]..column_pos[col + 1]].windows(2) {
            let ([i, j, k1], [_, _, k2]) = (ijk[w[0]], ijk[w[1]]);
            for c in 0..4 {
                if b.z(i, j, k2, c, 0) < b.z(i, j, k1, c, 1) - tol {
                    return Err(GridError::Input(format!(
                        "cells (i, j, k) = ({0}, {1}, {2}) and ({0}, {1}, {3}) (1-based) \
                         overlap at corner {4}: the top of the lower one is above the bottom \
                         of the upper one",
                        i + 1,
                        j + 1,
                        k1 + 1,
                        k2 + 1,
                        c + 1
                    )));
                }
            }
        }
    }
    // --- Pillar nodes: the corner depths of the active cells around each pillar. ---
    let mut depths: Vec<f64> = Vec::new();
    b.pillar_pos.push(0);
    for pj in 0..=ny {
        for pi in 0..=nx {
            depths.clear();
            for (ci, di) in [(pi.wrapping_sub(1), 1), (pi, 0)] {
                for (cj, dj) in [(pj.wrapping_sub(1), 1), (pj, 0)] {
                    if ci >= nx || cj >= ny {
                        continue;
                    }
                    let col = ci + nx * cj;
                    for &c in &column_cells[column_pos[col]..column_pos[col + 1]] {
                        let k = ijk[c][2];
                        depths.push(b.z(ci, cj, k, di + 2 * dj, 0));
                        depths.push(b.z(ci, cj, k, di + 2 * dj, 1));
                    }
                }
            }
            depths.sort_by(f64::total_cmp);
            let p = pi + (nx + 1) * pj;
            let mut last = f64::NEG_INFINITY;
            for &z in &depths {
                if z - last > tol {
                    let node = b.nodes.len();
                    b.nodes.push(b.pillar_point(p, z)?);
                    b.pillar_nodes.push((z, node));
                    last = z;
                }
            }
            b.pillar_pos.push(b.pillar_nodes.len());
        }
    }
    // --- Pillar pairs: overlaps of the two columns' stacks. ---
    let (mut minus, mut plus) = (Vec::new(), Vec::new());
    let num_pairs = (nx + 1) * ny + nx * (ny + 1);
    for pair in 0..num_pairs {
        let (p0, p1, cols) = b.pair_geometry(pair);
        for (side, stack) in [(0, &mut minus), (1, &mut plus)] {
            stack.clear();
            let mut above = [-FAR, -FAR];
            if let Some((ci, cj, corners)) = cols[side] {
                let col = ci + nx * cj;
                for &c in &column_cells[column_pos[col]..column_pos[col + 1]] {
                    let k = ijk[c][2];
                    let top = corners.map(|q| b.z(ci, cj, k, q, 0));
                    let bot = corners.map(|q| b.z(ci, cj, k, q, 1));
                    push_gap(stack, above, top, tol);
                    stack.push(Elem {
                        cell: Some(c),
                        top,
                        bot,
                    });
                    above = bot;
                }
            }
            push_gap(stack, above, [FAR, FAR], tol);
        }
        let mut start = 0;
        for m in &minus {
            while start < plus.len()
                && plus[start].bot[0] <= m.top[0] + tol
                && plus[start].bot[1] <= m.top[1] + tol
            {
                start += 1;
            }
            for q in &plus[start..] {
                if q.top[0] >= m.bot[0] - tol && q.top[1] >= m.bot[1] - tol {
                    break;
                }
                if m.cell.is_none() && q.cell.is_none() {
                    continue;
                }
                b.overlap(pair, [p0, p1], m, q)?;
            }
        }
        b.crossing_pos.push(b.crossings.len());
    }
    // --- Face loops, cell by cell. ---
    let num_cells = ijk.len();
    let mut sub_pos = vec![0usize; num_cells + 1];
    for sf in &b.subfaces {
        for c in sf.cells.iter().flatten() {
            sub_pos[c + 1] += 1;
        }
    }
    for c in 0..num_cells {
        sub_pos[c + 1] += sub_pos[c];
    }
    let mut sub_of_cell = vec![(0usize, 0usize); sub_pos[num_cells]];
    {
        let mut fill = sub_pos.clone();
        for (f, sf) in b.subfaces.iter().enumerate() {
            for (side, c) in sf.cells.iter().enumerate() {
                if let Some(c) = *c {
                    sub_of_cell[fill[c]] = (f, side);
                    fill[c] += 1;
                }
            }
        }
    }
    // Chunks of cells in parallel, joined in order.
    const CHUNK: usize = 4096;
    let b = &b;
    let parts: Vec<(CellFaceLoops, Vec<u8>)> = (0..num_cells.div_ceil(CHUNK))
        .into_par_iter()
        .map(|ch| {
            let mut loops = CellFaceLoops::new();
            let mut loop_side: Vec<u8> = Vec::new();
            let mut face = Vec::new();
            let mut scratch = Vec::new();
            for c in ch * CHUNK..((ch + 1) * CHUNK).min(num_cells) {
                let [i, j, k] = ijk[c];
                for bottom in [0, 1] {
                    b.horizontal_loop(i, j, k, bottom, &mut face)?;
                    // The loop's normal is `(P(i+1) − P(i)) × (P(j+1) − P(j))`: down (out of
                    // the bottom) in a right-handed deck.
                    let outward = (bottom == 1) == b.right_handed;
                    let added = b.emit(&mut loops, &mut face, outward, &mut scratch);
                    loop_side.extend(std::iter::repeat_n(4 + bottom as u8, added));
                }
                for &(f, side) in &sub_of_cell[sub_pos[c]..sub_pos[c + 1]] {
                    let sf = &b.subfaces[f];
                    b.sub_face_loop(sf, &mut face);
                    // The loop runs along the top from `s = 0` to `s = 1`, then back along the
                    // bottom: its normal is (pillar to pillar) × down, towards `i + 1` on an
                    // i-pair of a right-handed deck and towards `j − 1` on a j-pair. The two
                    // cells of a sub-face see it in opposite orientations.
                    let ipair = sf.pair < (nx + 1) * ny;
                    let outward = (ipair == b.right_handed) == (side == 0);
                    let added = b.emit(&mut loops, &mut face, outward, &mut scratch);
                    // The side this face looks at: the pair's direction, + for the minus
                    // cell.
                    let dir = if sf.pair < (nx + 1) * ny { 0 } else { 2 };
                    loop_side.extend(std::iter::repeat_n(dir + u8::from(side == 0), added));
                }
                loops.finish_cell();
            }
            Ok((loops, loop_side))
        })
        .collect::<Result<_>>()?;
    let mut loops = CellFaceLoops::new();
    let mut loop_side = Vec::new();
    for (part, sides) in &parts {
        loops.append(part);
        loop_side.extend_from_slice(sides);
    }
    drop(parts);
    let nodes = std::mem::take(&mut builder.nodes);
    // A cell the grid refuses (inverted, degenerate, not closed) is named by its deck
    // (i, j, k).
    let mut grid = Grid::from_cell_faces(nodes, &loops).map_err(|e| match e {
        GridError::Cell { cell, what } if cell < ijk.len() => {
            let [i, j, k] = ijk[cell];
            GridError::Input(format!(
                "cell (i, j, k) = ({}, {}, {}) (1-based): {what}",
                i + 1,
                j + 1,
                k + 1
            ))
        }
        e => e,
    })?;
    let mut tags: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for c in 0..num_cells {
        let faces = grid.cell_faces(c);
        for (local, &f) in faces.iter().enumerate() {
            if grid.is_boundary_face(f) {
                let side = loop_side[loops.cell_pos[c] + local];
                tags.entry(IJK_SIDES[side as usize]).or_default().push(f);
            }
        }
    }
    for (name, faces) in tags {
        grid.set_face_tag(name, faces)?;
    }
    Ok(CornerPointGrid {
        grid,
        ijk,
        deck_cell,
        pinched,
        inactive,
    })
}

/// Whether the deck's `i`, `j` and depth axes make a right-handed frame (`GDORIENT …
/// DOWN RIGHT`, say) or a left-handed one (`… DOWN LEFT`): the sign of `(a × b) · z`
/// summed over the columns, `a` and `b` the columns' edges from pillar `(i, j)` to `(i +
/// 1, j)` and to `(i, j + 1)` (tops and bottoms of the pillars, seen from above). Face loops are
/// oriented from it, for every cell alike.
fn right_handed(deck: &Deck) -> Result<bool> {
    let [nx, ny, _] = deck.dims;
    let point = |i: usize, j: usize, end: usize| {
        let p = 6 * (i + (nx + 1) * j) + 3 * end;
        [deck.coord[p], deck.coord[p + 1]]
    };
    let mut sum = 0.0;
    for end in [0, 1] {
        for j in 0..ny {
            for i in 0..nx {
                let o = point(i, j, end);
                let (a, b) = (point(i + 1, j, end), point(i, j + 1, end));
                sum += (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
            }
        }
    }
    if sum == 0.0 || !sum.is_finite() {
        return Err(GridError::Input(
            "corner-point grid: the columns have no area seen from above (COORD's pillars \
             do not span the map)"
                .into(),
        ));
    }
    Ok(sum > 0.0)
}

/// Push the gap between `above` and `below` onto a stack unless it is thinner than `tol`.
fn push_gap(stack: &mut Vec<Elem>, above: [f64; 2], below: [f64; 2], tol: f64) {
    if below[0] - above[0] > tol || below[1] - above[1] > tol {
        stack.push(Elem {
            cell: None,
            top: above,
            bot: below,
        });
    }
}

/// Columns of a pillar pair's side: `(i, j, [corner at s = 0, corner at s = 1])`.
type PairSide = Option<(usize, usize, [usize; 2])>;

impl Builder<'_> {
    /// Depth of corner `c` (0..4: `di + 2 dj`) of cell `(i, j, k)`, top (`dk = 0`) or
    /// bottom (`dk = 1`).
    fn z(&self, i: usize, j: usize, k: usize, c: usize, dk: usize) -> f64 {
        let (di, dj) = (c % 2, c / 2);
        let (nx, ny) = (self.nx, self.ny);
        self.deck.zcorn[(2 * k + dk) * 4 * nx * ny + (2 * j + dj) * 2 * nx + 2 * i + di]
    }

    /// The point of pillar `p` at depth `z` (on the line through its two COORD points).
    fn pillar_point(&self, p: usize, z: f64) -> Result<Point<3>> {
        let c = &self.deck.coord[6 * p..6 * p + 6];
        let (top, bot) = (
            Point::<3>::new(c[0], c[1], c[2]),
            Point::<3>::new(c[3], c[4], c[5]),
        );
        let dz = bot[2] - top[2];
        if dz.abs() <= self.tol {
            if (bot - top).norm() > self.tol {
                return Err(GridError::Input(format!(
                    "pillar {} (i, j) = ({}, {}) (1-based) of COORD is horizontal: its top and \
                     bottom points have the same depth",
                    p + 1,
                    p % (self.nx + 1) + 1,
                    p / (self.nx + 1) + 1
                )));
            }
            return Ok(Point::<3>::new(top[0], top[1], z));
        }
        Ok(top + (bot - top) * ((z - top[2]) / dz))
    }

    /// The pillars of a pair (at `s = 0` and `s = 1`) and the columns on its two sides.
    fn pair_geometry(&self, pair: usize) -> (usize, usize, [PairSide; 2]) {
        let (nx, ny) = (self.nx, self.ny);
        let pillar = |i: usize, j: usize| i + (nx + 1) * j;
        if pair < (nx + 1) * ny {
            // Between columns i − 1 and i, pillars (i, j) and (i, j + 1).
            let (i, j) = (pair % (nx + 1), pair / (nx + 1));
            let minus = (i > 0).then(|| (i - 1, j, [1, 3]));
            let plus = (i < nx).then_some((i, j, [0, 2]));
            (pillar(i, j), pillar(i, j + 1), [minus, plus])
        } else {
            // Between columns j − 1 and j, pillars (i, j) and (i + 1, j).
            let q = pair - (nx + 1) * ny;
            let (i, j) = (q % nx, q / nx);
            let minus = (j > 0).then(|| (i, j - 1, [2, 3]));
            let plus = (j < ny).then_some((i, j, [0, 1]));
            (pillar(i, j), pillar(i + 1, j), [minus, plus])
        }
    }

    /// The pair holding the edge of column `(i, j)` on its side `side` (0: j-min, 1:
    /// i-max, 2: j-max, 3: i-min), and whether the edge runs from `s = 1` to `s = 0` when
    /// the top face is traversed `(i,j) → (i+1,j) → (i+1,j+1) → (i,j+1)`.
    fn column_edge(&self, i: usize, j: usize, side: usize) -> (usize, bool) {
        let (nx, ny) = (self.nx, self.ny);
        let ipair = |i: usize, j: usize| i + (nx + 1) * j;
        let jpair = |i: usize, j: usize| (nx + 1) * ny + i + nx * j;
        match side {
            0 => (jpair(i, j), false),
            1 => (ipair(i + 1, j), false),
            2 => (jpair(i, j + 1), true),
            _ => (ipair(i, j), true),
        }
    }

    /// Node of pillar `p` at depth `z`.
    fn pillar_node(&self, p: usize, z: f64) -> Result<usize> {
        let list = &self.pillar_nodes[self.pillar_pos[p]..self.pillar_pos[p + 1]];
        let k = list.partition_point(|&(d, _)| d < z - self.tol);
        match list.get(k) {
            Some(&(d, node)) if (d - z).abs() <= self.tol => Ok(node),
            _ => Err(GridError::Input(format!(
                "corner-point processing: no node at depth {z} on pillar {}",
                p + 1
            ))),
        }
    }

    /// The overlap of stack elements `m` (minus side) and `q` (plus side) on pair `pair`:
    /// the region `max(top) ≤ z ≤ min(bot)`, a convex polygon in `(s, z)`, recorded as a
    /// sub-face if it is thicker than the tolerance.
    fn overlap(&mut self, pair: usize, pillars: [usize; 2], m: &Elem, q: &Elem) -> Result<()> {
        let mut cand = [0.0f64; 8];
        let mut nc = 0;
        for s in [Some(0.0), Some(1.0)]
            .into_iter()
            .chain([
                crossing(m.top, q.top),
                crossing(m.bot, q.bot),
                crossing(m.top, q.bot),
                crossing(q.top, m.bot),
                crossing(m.top, m.bot),
                crossing(q.top, q.bot),
            ])
            .flatten()
        {
            cand[nc] = s;
            nc += 1;
        }
        let cand = &mut cand[..nc];
        cand.sort_by(f64::total_cmp);
        let upper = |s: f64| at(m.top, s).max(at(q.top, s));
        let lower = |s: f64| at(m.bot, s).min(at(q.bot, s));
        let tol = self.tol;
        let mut feasible = [0.0f64; 8];
        let mut nf = 0;
        for &s in cand.iter() {
            if lower(s) - upper(s) >= -tol {
                feasible[nf] = s;
                nf += 1;
            }
        }
        let feasible = &feasible[..nf];
        let thickest = feasible
            .iter()
            .map(|&s| lower(s) - upper(s))
            .fold(f64::NEG_INFINITY, f64::max);
        if feasible.len() < 2 || thickest <= tol {
            return Ok(());
        }
        // Top chain left to right, bottom chain right to left.
        let poly = &mut self.polygon;
        poly.clear();
        poly.extend(feasible.iter().map(|&s| (s, upper(s))));
        for &s in feasible.iter().rev() {
            if lower(s) - upper(s) > tol {
                poly.push((s, lower(s)));
            }
        }
        // Drop vertices inside an edge (not on a pillar, on the line of their neighbours),
        // in order, each once. A vertex is dropped only if it and the vertices dropped
        // next to it all lie on the new edge: dropping one after the other, each against
        // its neighbours of the moment, could bend the edge away from a node that other
        // faces have on it (found again on the edge by `nodes_on_segment`).
        let n = poly.len();
        let mut keep = [true; 16];
        let mut kept = n;
        let on_edge = |a: (f64, f64), v: (f64, f64), w: (f64, f64)| {
            let between = (a.0 < v.0 && v.0 < w.0) || (w.0 < v.0 && v.0 < a.0);
            between && (at([a.1, w.1], (v.0 - a.0) / (w.0 - a.0)) - v.1).abs() <= tol
        };
        for k in 0..n {
            if kept <= 3 {
                break;
            }
            let prev = (1..n)
                .map(|d| (k + n - d) % n)
                .find(|&p| keep[p])
                .unwrap_or(k);
            let next = (1..n).map(|d| (k + d) % n).find(|&q| keep[q]).unwrap_or(k);
            let (a, w) = (poly[prev], poly[next]);
            let mut between = (1..n).map(|d| (prev + d) % n).take_while(|&x| x != next);
            if between.all(|x| on_edge(a, poly[x], w)) {
                keep[k] = false;
                kept -= 1;
            }
        }
        let mut flags = keep.iter();
        poly.retain(|_| flags.next().copied().unwrap_or(true));
        let start = self.verts.len();
        let poly = std::mem::take(&mut self.polygon);
        for &(s, z) in &poly {
            let node = if s == 0.0 {
                self.pillar_node(pillars[0], z)?
            } else if s == 1.0 {
                self.pillar_node(pillars[1], z)?
            } else {
                self.crossing_node(pair, pillars, s, z)?
            };
            if self.verts[start..].last().map(|v| v.node) != Some(node) {
                self.verts.push(Vertex { s, z, node });
            }
        }
        self.polygon = poly;
        if self.verts.len() > start + 1
            && self.verts[start].node == self.verts[self.verts.len() - 1].node
        {
            self.verts.pop();
        }
        if self.verts.len() - start < 3 {
            self.verts.truncate(start);
            return Ok(());
        }
        self.subfaces.push(SubFace {
            pair,
            cells: [m.cell, q.cell],
            start,
            end: self.verts.len(),
        });
        Ok(())
    }

    /// The node at `(s, z)` inside pair `pair` (the pair being processed), made once.
    fn crossing_node(&mut self, pair: usize, pillars: [usize; 2], s: f64, z: f64) -> Result<usize> {
        let from = self.crossing_pos[pair];
        let s_tol = RELATIVE_TOLERANCE;
        if let Some(v) = self.crossings[from..]
            .iter()
            .find(|v| (v.s - s).abs() <= s_tol && (v.z - z).abs() <= self.tol)
        {
            return Ok(v.node);
        }
        let x =
            self.pillar_point(pillars[0], z)? * (1.0 - s) + self.pillar_point(pillars[1], z)? * s;
        let node = self.nodes.len();
        self.nodes.push(x);
        self.crossings.push(Vertex { s, z, node });
        Ok(node)
    }

    /// Nodes of pair `pair` strictly inside the segment from `a` to `b` (`0 < s < 1`), in
    /// order from `a` to `b`.
    fn nodes_on_segment(&self, pair: usize, a: (f64, f64), b: (f64, f64), out: &mut Vec<usize>) {
        let list = &self.crossings[self.crossing_pos[pair]..self.crossing_pos[pair + 1]];
        let before = out.len();
        let (lo, hi) = (a.0.min(b.0), a.0.max(b.0));
        for v in list {
            if v.s > lo + RELATIVE_TOLERANCE
                && v.s < hi - RELATIVE_TOLERANCE
                && (at([a.1, b.1], (v.s - a.0) / (b.0 - a.0)) - v.z).abs() <= self.tol
            {
                out.push(v.node);
            }
        }
        // Sort the new nodes by their distance from `a` along s.
        let key = |n: usize| {
            list.iter()
                .find(|v| v.node == n)
                .map_or(0.0, |v| (v.s - a.0).abs())
        };
        out[before..].sort_by(|&x, &y| key(x).total_cmp(&key(y)));
    }

    /// The loop of a sub-face with every node on its edges: nodes of the pillars between
    /// two vertices on one pillar, nodes of the pair on its other edges.
    fn sub_face_loop(&self, sf: &SubFace, out: &mut Vec<usize>) {
        out.clear();
        let verts = &self.verts[sf.start..sf.end];
        let (p0, p1, _) = self.pair_geometry(sf.pair);
        for (k, v) in verts.iter().enumerate() {
            let w = verts[(k + 1) % verts.len()];
            out.push(v.node);
            if v.s == w.s && (v.s == 0.0 || v.s == 1.0) {
                let p = if v.s == 0.0 { p0 } else { p1 };
                let list = &self.pillar_nodes[self.pillar_pos[p]..self.pillar_pos[p + 1]];
                let (lo, hi) = (v.z.min(w.z), v.z.max(w.z));
                let from = list.partition_point(|&(d, _)| d <= lo + self.tol);
                let to = list.partition_point(|&(d, _)| d < hi - self.tol);
                let inner = list[from..to.max(from)].iter().map(|&(_, n)| n);
                if w.z > v.z {
                    out.extend(inner);
                } else {
                    let from = out.len();
                    out.extend(inner);
                    out[from..].reverse();
                }
            } else {
                self.nodes_on_segment(sf.pair, (v.s, v.z), (w.s, w.z), out);
            }
        }
    }

    /// The top (`bottom = 0`) or bottom face loop of cell `(i, j, k)`, corners in the order
    /// `(i,j) (i+1,j) (i+1,j+1) (i,j+1)` with the nodes of the pairs on its edges.
    fn horizontal_loop(
        &self,
        i: usize,
        j: usize,
        k: usize,
        bottom: usize,
        out: &mut Vec<usize>,
    ) -> Result<()> {
        out.clear();
        let corner_order = [0, 1, 3, 2];
        let pillar = |c: usize| (i + c % 2) + (self.nx + 1) * (j + c / 2);
        for side in 0..4 {
            let (c0, c1) = (corner_order[side], corner_order[(side + 1) % 4]);
            let (z0, z1) = (self.z(i, j, k, c0, bottom), self.z(i, j, k, c1, bottom));
            out.push(self.pillar_node(pillar(c0), z0)?);
            let (pair, reversed) = self.column_edge(i, j, side);
            let (a, b) = if reversed {
                ((1.0, z0), (0.0, z1))
            } else {
                ((0.0, z0), (1.0, z1))
            };
            self.nodes_on_segment(pair, a, b, out);
        }
        Ok(())
    }

    /// Append a face loop, reversed unless it is `outward` already, without repeated
    /// nodes; returns the number of loops added (see [`simple_loops`]: a loop that passes
    /// twice through a node, where the corners of a pinched cell meet, is split there, and
    /// loops of fewer than three nodes are dropped). The orientation is known from how
    /// the loop was made, never guessed from the geometry, which a thin or partly pinched
    /// cell makes unreliable.
    fn emit(
        &self,
        loops: &mut CellFaceLoops,
        face: &mut Vec<usize>,
        outward: bool,
        scratch: &mut Vec<usize>,
    ) -> usize {
        face.dedup();
        while face.len() > 1 && face.first() == face.last() {
            face.pop();
        }
        if face.len() < 3 {
            return 0;
        }
        if !outward {
            face.reverse();
        }
        simple_loops(face, scratch, |l| loops.push_face(l))
    }
}

/// Split a closed loop of nodes into loops that each visit a node once, and pass those
/// of at least three nodes to `push` (returns how many). A loop through a node twice
/// (`a b c a d`: the corners of a pinched cell meeting on a face) is two loops joined at
/// that node (`a b c` and `a d`); the loops keep the edges of the original in their
/// direction, so the cell stays closed, and a loop of two nodes (an edge walked there and
/// back) has no area. The split starts at the smallest node, so the two cells of a face,
/// which see the loop reversed, split it into the same loops.
fn simple_loops(face: &[usize], stack: &mut Vec<usize>, mut push: impl FnMut(&[usize])) -> usize {
    let m = face.len();
    let first = (0..m).min_by_key(|&k| face[k]).unwrap_or(0);
    let mut added = 0;
    stack.clear();
    for k in 0..m {
        let n = face[(first + k) % m];
        if let Some(p) = stack.iter().position(|&x| x == n) {
            if stack.len() - p >= 3 {
                push(&stack[p..]);
                added += 1;
            }
            stack.truncate(p + 1);
        } else {
            stack.push(n);
        }
    }
    if stack.len() >= 3 {
        push(stack);
        added += 1;
    }
    added
}

#[cfg(test)]
mod tests {
    use super::simple_loops;

    fn split(face: &[usize]) -> Vec<Vec<usize>> {
        let mut out = Vec::new();
        let n = simple_loops(face, &mut Vec::new(), |l| out.push(l.to_vec()));
        assert_eq!(n, out.len());
        out
    }

    /// Directed edges of loops, sorted.
    fn edges(loops: &[Vec<usize>]) -> Vec<(usize, usize)> {
        let mut e: Vec<_> = loops
            .iter()
            .flat_map(|l| (0..l.len()).map(move |k| (l[k], l[(k + 1) % l.len()])))
            .collect();
        e.sort_unstable();
        e
    }

    #[test]
    fn a_loop_through_a_node_twice_splits_there_keeping_its_edges() {
        // a b c a d: the loop a b c, and the edge a d walked there and back (dropped).
        assert_eq!(split(&[1, 2, 3, 1, 4]), vec![vec![1, 2, 3]]);
        // Two triangles joined at node 5, from any starting node and either way round:
        // the same two loops, reversed when the loop is.
        let face = [5, 7, 8, 5, 9, 6];
        let loops = split(&face);
        assert_eq!(loops, vec![vec![5, 7, 8], vec![5, 9, 6]]);
        let mut kept_edges = edges(&loops);
        let mut all_edges = edges(&[face.to_vec()]);
        kept_edges.sort_unstable();
        all_edges.sort_unstable();
        assert_eq!(kept_edges, all_edges);
        // Canonical loops: each rotated to start at its smallest node, sorted.
        let canon = |mut ls: Vec<Vec<usize>>| {
            for l in &mut ls {
                let m = (0..l.len()).min_by_key(|&k| l[k]).unwrap();
                l.rotate_left(m);
            }
            ls.sort();
            ls
        };
        for shift in 0..face.len() {
            let mut rotated = face.to_vec();
            rotated.rotate_left(shift);
            assert_eq!(
                canon(split(&rotated)),
                canon(loops.clone()),
                "shift {shift}"
            );
            let reversed: Vec<usize> = rotated.iter().rev().copied().collect();
            let back: Vec<Vec<usize>> = split(&reversed)
                .into_iter()
                .map(|l| l.into_iter().rev().collect())
                .collect();
            assert_eq!(canon(back), canon(loops.clone()), "reversed, shift {shift}");
        }
        // A simple loop is kept whole.
        assert_eq!(split(&[3, 1, 2, 4]), vec![vec![1, 2, 4, 3]]);
    }
}
