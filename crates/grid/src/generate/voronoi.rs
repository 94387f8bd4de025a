//! Voronoi (PEBI) grids in 2D, clipped to a box.
//!
//! `n` generating seeds are drawn uniformly in the box by a `ChaCha8Rng` seeded with
//! `seed`. The cell of seed `s_i` is
//!
//! ```text
//!   K_i = { x in box : |x − s_i| ≤ |x − s_j| for all j }
//!       = box ∩ ⋂_j { x : (x − (s_i + s_j)/2) · (s_j − s_i) ≤ 0 },
//! ```
//!
//! computed by clipping the box with the bisector half-planes of the neighbours in order
//! of bucket rings around `s_i`; a ring at bucket distance `r` holds no seed closer than
//! `r b` (`b` the bucket width), and a seed `s_j` can cut the cell only if
//! `|s_j − s_i| < 2 R` with `R` the largest distance from `s_i` to a vertex of the
//! current cell, so the search stops once `r b ≥ 2 R`.
//!
//! Optional Lloyd iterations move every seed to the area centroid of its cell and
//! recompute the cells (a few make the cells rounder and the edges less disparate).
//!
//! **Shared nodes.** Every line bounding a clipped cell is either the bisector with a
//! neighbour `j` or a box side, so each cell vertex is labelled by the three "generators"
//! it is equidistant to or lies on: `{i, j, k}` (an interior Voronoi vertex), `{i, j,
//! side}` (on a box side) or `{i, side, side}` (a box corner). Cells sharing a vertex
//! produce the same label, so vertices are identified by their labels, never by
//! comparing coordinates; the node takes the coordinates computed by the lowest-numbered
//! cell. Near-degenerate seed configurations (four seeds almost on one circle) give
//! Voronoi edges much shorter than the cell size: vertices joined by an edge shorter than
//! `1e-10 h` (`h = √(box area / n)`) are merged into one node (a vertex on the box
//! boundary wins, so the boundary stays exact), and repeated nodes are dropped from the
//! polygons. Vertices on a box side lie exactly on it.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::error::{GridError, Result, cell_err};
use crate::grid::Grid;
use crate::point::Point;

/// Default number of Lloyd iterations of [`voronoi`] in the scene files.
pub const DEFAULT_LLOYD: usize = 3;

type P2 = Point<2>;

/// A vertex of a clipped cell and the line its outgoing edge lies on.
#[derive(Clone, Copy, Debug)]
struct Vert {
    p: P2,
    line: u32,
}

/// Seeds sorted into a uniform bucket grid.
struct Buckets {
    lo: P2,
    width: [f64; 2],
    count: [usize; 2],
    pos: Vec<usize>,
    items: Vec<u32>,
}

impl Buckets {
    fn new(lo: P2, hi: P2, seeds: &[P2]) -> Self {
        let n = seeds.len();
        let ext = hi - lo;
        // About two seeds per bucket.
        let b = (ext[0] * ext[1] * 2.0 / n as f64).sqrt();
        let count = [
            ((ext[0] / b).ceil() as usize).clamp(1, 1 << 15),
            ((ext[1] / b).ceil() as usize).clamp(1, 1 << 15),
        ];
        let width = [ext[0] / count[0] as f64, ext[1] / count[1] as f64];
        let mut this = Self {
            lo,
            width,
            count,
            pos: vec![0; count[0] * count[1] + 1],
            items: vec![0; n],
        };
        let ids: Vec<usize> = seeds.iter().map(|s| this.bucket_of(s)).collect();
        for &b in &ids {
            this.pos[b + 1] += 1;
        }
        for k in 0..count[0] * count[1] {
            this.pos[k + 1] += this.pos[k];
        }
        let mut fill = this.pos.clone();
        for (i, &b) in ids.iter().enumerate() {
            this.items[fill[b]] = i as u32;
            fill[b] += 1;
        }
        this
    }
    fn cell_xy(&self, s: &P2) -> [usize; 2] {
        let f = |a: usize| {
            let t = ((s[a] - self.lo[a]) / self.width[a]).floor();
            (t.max(0.0) as usize).min(self.count[a] - 1)
        };
        [f(0), f(1)]
    }
    fn bucket_of(&self, s: &P2) -> usize {
        let [x, y] = self.cell_xy(s);
        y * self.count[0] + x
    }
    fn bucket(&self, x: usize, y: usize) -> &[u32] {
        let b = y * self.count[0] + x;
        &self.items[self.pos[b]..self.pos[b + 1]]
    }
}

/// Clip `poly` by the half-plane of points closer to `si` than to `sj` (line id `j`).
fn clip(poly: &mut Vec<Vert>, tmp: &mut Vec<Vert>, si: P2, sj: P2, j: u32) {
    let u = sj - si;
    let m = (si + sj) * 0.5;
    let f = |p: &P2| (p - m).dot(&u);
    if poly.iter().all(|v| f(&v.p) <= 0.0) {
        return;
    }
    tmp.clear();
    let len = poly.len();
    for k in 0..len {
        let a = poly[k];
        let b = poly[(k + 1) % len];
        let (fa, fb) = (f(&a.p), f(&b.p));
        if fa <= 0.0 {
            tmp.push(a);
        }
        if (fa <= 0.0) != (fb <= 0.0) {
            let t = fa / (fa - fb);
            let p = a.p + (b.p - a.p) * t;
            let line = if fa <= 0.0 { j } else { a.line };
            tmp.push(Vert { p, line });
        }
    }
    std::mem::swap(poly, tmp);
}

/// The clipped Voronoi cell of seed `i`, left in `poly` (counter-clockwise).
fn cell_polygon(
    i: usize,
    seeds: &[P2],
    lo: P2,
    hi: P2,
    buckets: &Buckets,
    poly: &mut Vec<Vert>,
    tmp: &mut Vec<Vert>,
) -> Result<()> {
    let n = seeds.len() as u32;
    poly.clear();
    // Outgoing edges: bottom (ymin), right (xmax), top (ymax), left (xmin).
    poly.extend_from_slice(&[
        Vert { p: lo, line: n + 2 },
        Vert {
            p: P2::new(hi[0], lo[1]),
            line: n + 1,
        },
        Vert { p: hi, line: n + 3 },
        Vert {
            p: P2::new(lo[0], hi[1]),
            line: n,
        },
    ]);
    let si = seeds[i];
    let radius2 = |poly: &[Vert]| {
        poly.iter()
            .map(|v| (v.p - si).norm_squared())
            .fold(0.0, f64::max)
    };
    let mut r2 = radius2(poly);
    let [cx, cy] = buckets.cell_xy(&si);
    let bmin = buckets.width[0].min(buckets.width[1]);
    let max_ring = buckets.count[0].max(buckets.count[1]);
    for ring in 0..=max_ring {
        let (x0, x1) = (
            cx.saturating_sub(ring),
            (cx + ring).min(buckets.count[0] - 1),
        );
        let (y0, y1) = (
            cy.saturating_sub(ring),
            (cy + ring).min(buckets.count[1] - 1),
        );
        for y in y0..=y1 {
            let edge_row = y + ring == cy || y == cy + ring;
            let mut x = x0;
            while x <= x1 {
                if edge_row || x + ring == cx || x == cx + ring {
                    for &j in buckets.bucket(x, y) {
                        let j = j as usize;
                        if j == i {
                            continue;
                        }
                        let d2 = (seeds[j] - si).norm_squared();
                        if d2 == 0.0 {
                            return Err(GridError::Input(format!(
                                "voronoi: seeds {i} and {j} coincide"
                            )));
                        }
                        if d2 < 4.0 * r2 {
                            clip(poly, tmp, si, seeds[j], j as u32);
                            if poly.len() < 3 {
                                return Err(cell_err(i, "voronoi cell clipped away"));
                            }
                            r2 = radius2(poly);
                        }
                    }
                    x += 1;
                } else {
                    // Interior of the ring was done before: jump to its right column.
                    x = (cx + ring).max(x + 1);
                }
            }
        }
        let reach = ring as f64 * bmin;
        if reach * reach >= 4.0 * r2 {
            break;
        }
    }
    Ok(())
}

fn polygon_centroid(poly: &[Vert]) -> P2 {
    let m = poly.len();
    let o = poly[0].p;
    let mut a = 0.0;
    let mut c = P2::zeros();
    for k in 1..m - 1 {
        let (p, q) = (poly[k].p - o, poly[k + 1].p - o);
        let w = p[0] * q[1] - p[1] * q[0];
        a += w;
        c += (p + q) * w;
    }
    o + c / (3.0 * a)
}

/// Check the box and count; the box extent.
fn check_input(lo: P2, hi: P2, n: usize) -> Result<()> {
    if n == 0 || n >= (u32::MAX - 8) as usize {
        return Err(GridError::Input(format!(
            "voronoi: cell count must be in 1..{}, got {n}",
            u32::MAX - 8
        )));
    }
    for a in 0..2 {
        if !(lo[a].is_finite() && hi[a].is_finite() && hi[a] > lo[a]) {
            return Err(GridError::Input(format!(
                "voronoi: extent must have min < max on every axis, got axis {a}: [{}, {}]",
                lo[a], hi[a]
            )));
        }
    }
    Ok(())
}

const CHUNK: usize = 512;

/// Cells of a chunk: vertex counts, vertex labels and coordinates.
type ChunkCells = (Vec<usize>, Vec<[u32; 3]>, Vec<P2>);

/// A 2D Voronoi grid of exactly `n` cells on the box `[lo, hi]` (see the module docs),
/// with `lloyd` Lloyd iterations ([`DEFAULT_LLOYD`] is a good choice). The same `seed`
/// gives the same grid.
///
/// Errors: `n = 0`, an empty or non-finite box, or (practically impossible with random
/// seeds) a degenerate configuration the builder rejects.
pub fn voronoi(lo: P2, hi: P2, n: usize, seed: u64, lloyd: usize) -> Result<Grid<2>> {
    check_input(lo, hi, n)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let ext = hi - lo;
    let mut seeds: Vec<P2> = (0..n)
        .map(|_| {
            P2::from_fn(|a, _| {
                let t = 1e-9 + (1.0 - 2e-9) * rng.random::<f64>();
                lo[a] + ext[a] * t
            })
        })
        .collect();

    for _ in 0..lloyd {
        let buckets = Buckets::new(lo, hi, &seeds);
        let seeds_ref = &seeds;
        seeds = (0..n)
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(poly, tmp), i| {
                    cell_polygon(i, seeds_ref, lo, hi, &buckets, poly, tmp)?;
                    Ok(polygon_centroid(poly))
                },
            )
            .collect::<Result<_>>()?;
    }

    // Final cells as labelled vertex lists, chunk by chunk.
    let buckets = Buckets::new(lo, hi, &seeds);
    let nu = n as u32;
    let chunks: Vec<ChunkCells> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|ch| {
            let (mut poly, mut tmp) = (Vec::new(), Vec::new());
            let mut counts = Vec::with_capacity(CHUNK);
            let mut keys = Vec::with_capacity(CHUNK * 7);
            let mut xy = Vec::with_capacity(CHUNK * 7);
            for i in ch * CHUNK..((ch + 1) * CHUNK).min(n) {
                cell_polygon(i, &seeds, lo, hi, &buckets, &mut poly, &mut tmp)?;
                let m = poly.len();
                counts.push(m);
                for k in 0..m {
                    let prev = poly[(k + m - 1) % m].line;
                    let mut key = [i as u32, prev, poly[k].line];
                    key.sort_unstable();
                    keys.push(key);
                    xy.push(poly[k].p);
                }
            }
            Ok((counts, keys, xy))
        })
        .collect::<Result<_>>()?;
    let total: usize = chunks.iter().map(|c| c.1.len()).sum();
    let mut cell_pos = Vec::with_capacity(n + 1);
    cell_pos.push(0);
    let mut keys = Vec::with_capacity(total);
    let mut xy = Vec::with_capacity(total);
    for (counts, k, p) in chunks {
        for c in counts {
            cell_pos.push(cell_pos.last().copied().unwrap_or(0) + c);
        }
        keys.extend_from_slice(&k);
        xy.extend_from_slice(&p);
    }

    // Vertex ids by label: sort occurrences by (label, occurrence).
    let mut order: Vec<u32> = (0..total as u32).collect();
    order.par_sort_unstable_by_key(|&o| (keys[o as usize], o));
    let mut vid = vec![0u32; total];
    let mut vert_xy: Vec<P2> = Vec::new();
    let mut vert_rank: Vec<u8> = Vec::new();
    for (k, &o) in order.iter().enumerate() {
        let o = o as usize;
        if k == 0 || keys[order[k - 1] as usize] != keys[o] {
            vert_xy.push(xy[o]);
            vert_rank.push(keys[o].iter().filter(|&&g| g >= nu).count() as u8);
        }
        vid[o] = (vert_xy.len() - 1) as u32;
    }
    drop(order);

    // Merge the ends of edges shorter than 1e-10 h (boundary vertices win).
    let h = (ext[0] * ext[1] / n as f64).sqrt();
    let tol2 = (1e-10 * h).powi(2);
    let mut parent: Vec<u32> = (0..vert_xy.len() as u32).collect();
    fn find(parent: &mut [u32], mut a: u32) -> u32 {
        while parent[a as usize] != a {
            let g = parent[parent[a as usize] as usize];
            parent[a as usize] = g;
            a = g;
        }
        a
    }
    for c in 0..n {
        let (s, e) = (cell_pos[c], cell_pos[c + 1]);
        for k in s..e {
            let k1 = if k + 1 == e { s } else { k + 1 };
            if (xy[k] - xy[k1]).norm_squared() < tol2 {
                let (ra, rb) = (find(&mut parent, vid[k]), find(&mut parent, vid[k1]));
                if ra != rb {
                    let a_wins = (vert_rank[ra as usize], std::cmp::Reverse(ra))
                        > (vert_rank[rb as usize], std::cmp::Reverse(rb));
                    let (w, l) = if a_wins { (ra, rb) } else { (rb, ra) };
                    parent[l as usize] = w;
                }
            }
        }
    }
    // Node numbering: roots in vertex order.
    let mut node_of = vec![u32::MAX; vert_xy.len()];
    let mut nodes = Vec::with_capacity(vert_xy.len());
    for v in 0..vert_xy.len() as u32 {
        if find(&mut parent, v) == v {
            node_of[v as usize] = nodes.len() as u32;
            nodes.push(vert_xy[v as usize]);
        }
    }
    let mut poly_pos = Vec::with_capacity(n + 1);
    poly_pos.push(0);
    let mut poly_nodes: Vec<usize> = Vec::with_capacity(total);
    for c in 0..n {
        let start = poly_nodes.len();
        for k in cell_pos[c]..cell_pos[c + 1] {
            let node = node_of[find(&mut parent, vid[k]) as usize] as usize;
            if poly_nodes.len() > start && poly_nodes[poly_nodes.len() - 1] == node {
                continue;
            }
            poly_nodes.push(node);
        }
        while poly_nodes.len() > start + 1 && poly_nodes[poly_nodes.len() - 1] == poly_nodes[start]
        {
            poly_nodes.pop();
        }
        if poly_nodes.len() - start < 3 {
            return Err(cell_err(c, "voronoi cell collapsed to fewer than 3 nodes"));
        }
        poly_pos.push(poly_nodes.len());
    }
    Grid::from_polygons(nodes, &poly_pos, &poly_nodes)
}
