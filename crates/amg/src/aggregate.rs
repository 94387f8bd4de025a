//! Strength of connection between nodes, greedy aggregation and the tentative
//! prolongator.
//!
//! # Nodes and strength
//!
//! Equations are grouped into *nodes* (blocks): the `D` displacement components of a grid
//! node on the finest level — fewer where components are prescribed — and the coarse
//! equations of one aggregate on coarser levels. With `A_IJ` the block of rows of node
//! `I` and columns of node `J`, node `J` is a *strong* neighbour of `I ≠ J` when
//!
//! ```text
//!   ‖A_IJ‖_F > θ √(‖A_II‖_F ‖A_JJ‖_F),
//! ```
//!
//! the symmetric block version of the classical criterion (θ = 0 keeps every structural
//! neighbour with a nonzero block).
//!
//! # Aggregation (Vaněk, Mandel, Brezina 1996)
//!
//! 1. Visit the nodes in order; a node whose strong neighbours are all still free forms an
//!    aggregate with them (its *root neighbourhood*). Disjoint neighbourhoods give
//!    aggregates of diameter two that cover most of the grid.
//! 2. Every free node joins the pass-1 aggregate it is most strongly connected to.
//! 3. Nodes still free (no strong neighbour in any aggregate) form aggregates with their
//!    free strong neighbours.
//!
//! *Aggressive* coarsening runs the same passes on the distance-two graph `S²` (visited
//! through `S`, never formed): root neighbourhoods of radius two, about three times fewer
//! aggregates in 2D, a sparser prolongator and a cheaper Galerkin product, at the price of
//! a weaker coarse space (GAMG's "aggressive coarsening" on its finest level).
//!
//! # Tentative prolongator
//!
//! Let `B` (n × m) be the near-null space on this level and `B_a` its rows on the equations
//! of aggregate `a`. A thin QR factorization `B_a = Q_a R_a` (modified Gram–Schmidt with
//! one reorthogonalization; a column whose remainder is below `10⁻⁸` of its norm is
//! linearly dependent and dropped, so `Q_a` has `k_a ≤ m` orthonormal columns) gives
//!
//! ```text
//!   P_tent = blockdiag(Q_a),   B_coarse = [R_1; R_2; …],   P_tent B_coarse = B,
//! ```
//!
//! so the coarse space reproduces the near-null space exactly, `P_tentᵀ P_tent = I`, and the
//! coarse equations of aggregate `a` form the coarse node `a` with `k_a` equations.

use rayon::prelude::*;

use crate::csr::{CsrMatrix, ROWS_PER_TASK};
use crate::error::{AmgError, Result};
use crate::nullspace::NearNullSpace;
use crate::product::Blocked;

/// Relative size below which a Gram–Schmidt remainder counts as linearly dependent.
const RANK_TOL: f64 = 1e-8;
/// Marker of a free node.
const FREE: u32 = u32::MAX;

/// Equations grouped into nodes: `eqs[ptr[I]..ptr[I+1]]` are the equations of node `I`.
#[derive(Clone, Debug)]
pub(crate) struct Blocks {
    pub(crate) node_of: Vec<u32>,
    pub(crate) ptr: Vec<usize>,
    pub(crate) eqs: Vec<u32>,
}

impl Blocks {
    /// Group equations by the node ids `node_of_equation` (any ids; numbered in increasing
    /// order of id).
    pub(crate) fn from_ids(node_of_equation: &[usize]) -> Result<Self> {
        let n = node_of_equation.len();
        if n >= u32::MAX as usize {
            return Err(AmgError::Input(format!(
                "{n} equations exceed the 32-bit indices"
            )));
        }
        let mut order: Vec<(usize, u32)> = node_of_equation
            .iter()
            .enumerate()
            .map(|(e, &id)| (id, e as u32))
            .collect();
        // Equations numbered node by node come in order already.
        if !order.is_sorted() {
            order.par_sort_unstable();
        }
        let mut node_of = vec![0u32; n];
        let mut ptr = vec![0usize];
        let mut eqs = Vec::with_capacity(n);
        for (k, &(id, e)) in order.iter().enumerate() {
            if k > 0 && order[k - 1].0 != id {
                ptr.push(k);
            }
            node_of[e as usize] = (ptr.len() - 1) as u32;
            eqs.push(e);
        }
        ptr.push(n);
        if n == 0 {
            ptr.truncate(1);
        }
        Ok(Self { node_of, ptr, eqs })
    }

    /// Number of nodes.
    pub(crate) fn len(&self) -> usize {
        self.ptr.len() - 1
    }

    fn node(&self, i: usize) -> &[u32] {
        &self.eqs[self.ptr[i]..self.ptr[i + 1]]
    }
}

/// Node graph of strong connections: neighbours of `I` are `adj[ptr[I]..ptr[I+1]]` with
/// strengths `w` (block norms).
#[derive(Clone, Debug)]
pub(crate) struct Strength {
    ptr: Vec<usize>,
    adj: Vec<u32>,
    w: Vec<f64>,
}

/// Rows of a [`Strength`] graph built in consecutive parts: per part the neighbour
/// counts of its rows, their neighbours and their strengths.
type StrengthPart = (Vec<usize>, Vec<u32>, Vec<f64>);

impl Strength {
    /// The graph of `nn` nodes from its parts, in order.
    fn concat(nn: usize, parts: Vec<StrengthPart>) -> Self {
        let mut ptr = Vec::with_capacity(nn + 1);
        ptr.push(0);
        let (mut adj, mut w) = (Vec::new(), Vec::new());
        for (counts, a_part, w_part) in parts {
            for c in counts {
                ptr.push(ptr.last().copied().unwrap_or(0) + c);
            }
            adj.extend_from_slice(&a_part);
            w.extend_from_slice(&w_part);
        }
        Strength { ptr, adj, w }
    }

    fn nbrs(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.ptr[i]..self.ptr[i + 1];
        (&self.adj[r.clone()], &self.w[r])
    }
}

/// `f(j, Σ_q a_{i_q j}²)` over the columns `j` of the rows `i_q` of node `node`. When the
/// node's equations are consecutive rows of one group of `a` (the common case), their
/// shared columns are read once for all of them ([`CsrMatrix::for_each_in_group`]).
#[inline]
fn node_columns(a: &CsrMatrix, blocks: &Blocks, node: usize, mut f: impl FnMut(u32, f64)) {
    let eqs = blocks.node(node);
    let m = eqs.len();
    let i0 = eqs.first().map_or(0, |&e| e as usize);
    let consecutive = eqs.iter().enumerate().all(|(q, &e)| e as usize == i0 + q);
    if (2..=3).contains(&m) && consecutive && a.group_run(i0, a.nrows(), m) == m {
        match m {
            2 => a.for_each_in_group::<2>(i0, |j, v| f(j, v[0] * v[0] + v[1] * v[1])),
            _ => a.for_each_in_group::<3>(i0, |j, v| f(j, v[0] * v[0] + v[1] * v[1] + v[2] * v[2])),
        }
    } else {
        for &i in eqs {
            a.for_each_in_row(i as usize, |j, v| f(j, v * v));
        }
    }
}

/// The structural neighbours `J` of node `I` with `‖A_IJ‖_F²`, `J` increasing, appended to
/// `adj` and `w`; returns `‖A_II‖_F²`.
///
/// The entries `(J, a²)` of the node's rows are listed in the order they are read and
/// sorted by `J` with a stable sort (no sort at all when the equations are numbered node
/// by node, as the columns of a row then come with `J` non-decreasing), so each block
/// norm is summed in the order its entries were read: the same sums, bit for bit, as a
/// dense accumulator over all nodes, without one (whose `12 B` per node, touched at
/// random, cost more than the norms on large levels).
fn block_norms(
    a: &CsrMatrix,
    blocks: &Blocks,
    node: usize,
    entries: &mut Vec<(u32, f64)>,
    adj: &mut Vec<u32>,
    w: &mut Vec<f64>,
) -> f64 {
    entries.clear();
    node_columns(a, blocks, node, |j, v2| {
        entries.push((blocks.node_of[j as usize], v2))
    });
    if !entries.is_sorted_by_key(|e| e.0) {
        entries.sort_by_key(|e| e.0);
    }
    let mut diag = 0.0;
    let mut k = 0;
    while k < entries.len() {
        let nj = entries[k].0;
        let mut sum = 0.0;
        while k < entries.len() && entries[k].0 == nj {
            sum += entries[k].1;
            k += 1;
        }
        if nj as usize == node {
            diag = sum;
        } else {
            adj.push(nj);
            w.push(sum);
        }
    }
    diag
}

/// The strong-connection graph of the nodes of `a` with threshold `theta`.
///
/// One pass over the matrix lists every structural neighbour with its block norm and the
/// diagonal block norms (in parallel parts of [`ROWS_PER_TASK`] nodes); a second pass over
/// these lists, once all diagonal norms are known, keeps the strong ones.
pub(crate) fn strength(a: &CsrMatrix, blocks: &Blocks, theta: f64) -> Strength {
    let nn = blocks.len();
    let nparts = nn.div_ceil(ROWS_PER_TASK);
    let mut parts: Vec<(StrengthPart, Vec<f64>)> = (0..nparts)
        .into_par_iter()
        .map_init(Vec::new, |entries, b| {
            let range = b * ROWS_PER_TASK..((b + 1) * ROWS_PER_TASK).min(nn);
            let mut counts = Vec::with_capacity(range.len());
            let mut diag = Vec::with_capacity(range.len());
            let (mut adj, mut w) = (Vec::new(), Vec::new());
            for node in range {
                let before = adj.len();
                diag.push(block_norms(a, blocks, node, entries, &mut adj, &mut w).sqrt());
                counts.push(adj.len() - before);
            }
            ((counts, adj, w), diag)
        })
        .collect();
    let diag: Vec<f64> = parts.iter().flat_map(|(_, d)| d.iter().copied()).collect();
    parts
        .par_iter_mut()
        .enumerate()
        .for_each(|(b, ((counts, adj, w), _))| {
            let mut at = 0;
            let mut kept = 0;
            for (k, count) in counts.iter_mut().enumerate() {
                let node = b * ROWS_PER_TASK + k;
                let end = at + *count;
                let mut c = 0;
                for p in at..end {
                    let j = adj[p] as usize;
                    let s = w[p].sqrt();
                    if s > theta * (diag[node] * diag[j]).sqrt() {
                        adj[kept] = adj[p];
                        w[kept] = s;
                        kept += 1;
                        c += 1;
                    }
                }
                at = end;
                *count = c;
            }
            adj.truncate(kept);
            w.truncate(kept);
        });
    Strength::concat(nn, parts.into_iter().map(|(p, _)| p).collect())
}

impl Strength {
    /// Call `f(J, w)` for every neighbour `J ≠ I` of node `I` in `S` or, with
    /// `distance_two`, in `S²`: the strong neighbours and theirs, a neighbour at distance
    /// two with the strength of the weakest link on the path (a node reached on several
    /// paths is visited once per path). `S²` is never formed.
    #[inline]
    fn visit(&self, i: usize, distance_two: bool, mut f: impl FnMut(u32, f64)) {
        let (nb, wb) = self.nbrs(i);
        for (&j, &wj) in nb.iter().zip(wb) {
            f(j, wj);
            if distance_two {
                let (nb2, wb2) = self.nbrs(j as usize);
                for (&k, &wk) in nb2.iter().zip(wb2) {
                    if k as usize != i {
                        f(k, wj.min(wk));
                    }
                }
            }
        }
    }
}

/// Greedy aggregation in three passes (see the module docs) on the strength graph `s`, or
/// with `distance_two` on `S²` (aggressive coarsening). Returns the aggregate of every
/// node and the number of aggregates.
pub(crate) fn aggregate(s: &Strength, distance_two: bool) -> (Vec<u32>, usize) {
    let nn = s.ptr.len() - 1;
    let mut agg = vec![FREE; nn];
    let mut count = 0u32;
    // Pass 1: root neighbourhoods.
    for i in 0..nn {
        if agg[i] != FREE {
            continue;
        }
        let mut all_free = true;
        s.visit(i, distance_two, |j, _| all_free &= agg[j as usize] == FREE);
        if all_free {
            agg[i] = count;
            s.visit(i, distance_two, |j, _| agg[j as usize] = count);
            count += 1;
        }
    }
    // Pass 2: attach to the most strongly connected pass-1 aggregate (equal strengths: the
    // neighbour of the lowest number). Every node reads only the pass-1 result, so the
    // nodes are independent (in parallel, the same result).
    let first = agg.clone();
    agg.par_chunks_mut(ROWS_PER_TASK)
        .enumerate()
        .for_each(|(blk, part)| {
            for (k, slot) in part.iter_mut().enumerate() {
                if *slot != FREE {
                    continue;
                }
                let mut best: Option<(f64, u32, u32)> = None;
                s.visit(blk * ROWS_PER_TASK + k, distance_two, |j, w| {
                    let a = first[j as usize];
                    if a != FREE && best.is_none_or(|(bw, bj, _)| w > bw || (w == bw && j < bj)) {
                        best = Some((w, j, a));
                    }
                });
                if let Some((_, _, a)) = best {
                    *slot = a;
                }
            }
        });
    // Pass 3: the rest form aggregates with their free neighbours.
    for i in 0..nn {
        if agg[i] != FREE {
            continue;
        }
        agg[i] = count;
        s.visit(i, distance_two, |j, _| {
            if agg[j as usize] == FREE {
                agg[j as usize] = count;
            }
        });
        count += 1;
    }
    (agg, count as usize)
}

/// The tentative prolongator of an aggregation, with the coarse near-null space and the
/// coarse nodes.
pub(crate) struct Tentative {
    /// `P_tent` (fine equations × coarse equations), orthonormal columns, one block per
    /// row.
    pub(crate) p: Blocked,
    /// Aggregate of every fine equation.
    pub(crate) eq_agg: Vec<u32>,
    /// The near-null space on the coarse level.
    pub(crate) coarse_null: NearNullSpace,
    /// The coarse equations grouped by aggregate (`ptr` is the column layout `off`).
    pub(crate) coarse_blocks: Blocks,
}

/// QR of one aggregate's near-null rows: `(Q column-major r × k, R row-major k × m, k)`.
fn local_qr(b: &NearNullSpace, rows: &[u32]) -> (Vec<f64>, Vec<f64>, usize) {
    let r = rows.len();
    let m = b.num_vectors();
    let mut q: Vec<f64> = Vec::with_capacity(r * m);
    let mut k = 0;
    let mut v = vec![0.0; r];
    for col in 0..m {
        for (vi, &e) in v.iter_mut().zip(rows) {
            *vi = b.get(e as usize, col);
        }
        let norm0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm0 == 0.0 {
            continue;
        }
        for _ in 0..2 {
            for j in 0..k {
                let qj = &q[j * r..(j + 1) * r];
                let d: f64 = qj.iter().zip(&v).map(|(a, b)| a * b).sum();
                v.iter_mut().zip(qj).for_each(|(vi, qi)| *vi -= d * qi);
            }
        }
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm > RANK_TOL * norm0 {
            q.extend(v.iter().map(|x| x / norm));
            k += 1;
        }
    }
    // R = Qᵀ B_a.
    let mut rmat = vec![0.0; k * m];
    for j in 0..k {
        let qj = &q[j * r..(j + 1) * r];
        for col in 0..m {
            rmat[j * m + col] = qj
                .iter()
                .zip(rows)
                .map(|(qi, &e)| qi * b.get(e as usize, col))
                .sum();
        }
    }
    (q, rmat, k)
}

/// Build the tentative prolongator for aggregates `agg` (per node) of `blocks`.
pub(crate) fn tentative(
    blocks: &Blocks,
    agg: &[u32],
    num_agg: usize,
    b: &NearNullSpace,
) -> Result<Tentative> {
    let n = blocks.node_of.len();
    let m = b.num_vectors();
    // Aggregate → equations (nodes in increasing order, their equations in block order).
    let mut aptr = vec![0usize; num_agg + 1];
    for (node, &a) in agg.iter().enumerate() {
        aptr[a as usize + 1] += blocks.ptr[node + 1] - blocks.ptr[node];
    }
    for a in 0..num_agg {
        aptr[a + 1] += aptr[a];
    }
    let mut next = aptr.clone();
    let mut aeqs = vec![0u32; n];
    for (node, &a) in agg.iter().enumerate() {
        for &e in blocks.node(node) {
            aeqs[next[a as usize]] = e;
            next[a as usize] += 1;
        }
    }
    let qrs: Vec<(Vec<f64>, Vec<f64>, usize)> = (0..num_agg)
        .into_par_iter()
        .map(|a| local_qr(b, &aeqs[aptr[a]..aptr[a + 1]]))
        .collect();
    // Coarse numbering: aggregate a owns coarse equations off[a]..off[a] + k_a.
    let mut off = vec![0usize; num_agg + 1];
    for (a, (_, _, k)) in qrs.iter().enumerate() {
        off[a + 1] = off[a] + k;
    }
    let nc = off[num_agg];
    if nc >= u32::MAX as usize {
        return Err(AmgError::Input(format!(
            "{nc} coarse equations exceed the 32-bit indices"
        )));
    }
    // One block per row (none where the aggregate has no coarse equation).
    let eq_agg: Vec<u32> = blocks.node_of.iter().map(|&nd| agg[nd as usize]).collect();
    let mut bptr = Vec::with_capacity(n + 1);
    bptr.push(0);
    let mut bagg = Vec::with_capacity(n);
    for &a in &eq_agg {
        if off[a as usize + 1] > off[a as usize] {
            bagg.push(a);
        }
        bptr.push(bagg.len());
    }
    let mut p = Blocked::from_blocks(n, &off, &bptr, bagg)?;
    drop(bptr);
    let row_start: Vec<usize> = (0..n).map(|e| p.row_start(e)).collect();
    let vals = p.values_mut();
    let mut bdata = vec![0.0; nc * m];
    let mut node_of = vec![0u32; nc];
    for (a, (q, rmat, k)) in qrs.iter().enumerate() {
        let rows = &aeqs[aptr[a]..aptr[a + 1]];
        let r = rows.len();
        for (l, &e) in rows.iter().enumerate() {
            let p0 = row_start[e as usize];
            for j in 0..*k {
                vals[p0 + j] = q[j * r + l] as f32;
            }
        }
        for j in 0..*k {
            node_of[off[a] + j] = a as u32;
            for c in 0..m {
                bdata[c * nc + off[a] + j] = rmat[j * m + c];
            }
        }
    }
    let coarse_null = NearNullSpace::from_parts(nc, m, bdata);
    let coarse_blocks = Blocks {
        node_of,
        ptr: off,
        eqs: (0..nc as u32).collect(),
    };
    Ok(Tentative {
        p,
        eq_agg,
        coarse_null,
        coarse_blocks,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csr::SymCsr;

    /// 1D Laplacian [−1 2 −1] of size n, upper CSC.
    fn laplace_1d(n: usize) -> SymCsr {
        let mut cp = vec![0];
        let mut ri = vec![];
        let mut v = vec![];
        for c in 0..n {
            if c > 0 {
                ri.push(c - 1);
                v.push(-1.0);
            }
            ri.push(c);
            v.push(2.0);
            cp.push(ri.len());
        }
        SymCsr::from_upper_csc(n, &cp, &ri, &v).unwrap()
    }

    #[test]
    fn blocks_group_by_id() {
        let b = Blocks::from_ids(&[7, 3, 7, 3, 9]).unwrap();
        assert_eq!(b.len(), 3);
        assert_eq!(b.node_of, vec![1, 0, 1, 0, 2]);
        assert_eq!(b.node(0), &[1, 3]);
        assert_eq!(b.node(1), &[0, 2]);
        assert_eq!(b.node(2), &[4]);
    }

    #[test]
    fn aggregates_of_a_chain_are_triples() {
        let a = laplace_1d(9);
        let blocks = Blocks::from_ids(&(0..9).collect::<Vec<_>>()).unwrap();
        let s = strength(a.matrix(), &blocks, 0.0);
        let (agg, na) = aggregate(&s, false);
        // Pass 1 takes {0,1}, {2,3,4}, {5,6,7}; node 8 joins {5,6,7}.
        assert_eq!(na, 3);
        assert_eq!(agg, vec![0, 0, 1, 1, 1, 2, 2, 2, 2]);
    }

    #[test]
    fn distance_two_aggregates_a_chain_in_fives() {
        let a = laplace_1d(12);
        let blocks = Blocks::from_ids(&(0..12).collect::<Vec<_>>()).unwrap();
        let s = strength(a.matrix(), &blocks, 0.0);
        // Neighbours within distance two; a distance-two link is as strong as its weakest
        // step (every |a_ij| = 1 here).
        let nbrs = |i: usize| {
            let mut out = Vec::new();
            s.visit(i, true, |j, w| out.push((j, w)));
            out.sort_by_key(|x| x.0);
            out.dedup();
            out
        };
        assert_eq!(nbrs(0), vec![(1, 1.0), (2, 1.0)]);
        assert_eq!(nbrs(5), vec![(3, 1.0), (4, 1.0), (6, 1.0), (7, 1.0)]);
        let (agg, na) = aggregate(&s, true);
        // Pass 1: roots 0, 5 and 10 take {0, 1, 2}, {3, …, 7} and {8, …, 11}.
        assert_eq!(na, 3);
        assert_eq!(agg, vec![0, 0, 0, 1, 1, 1, 1, 1, 2, 2, 2, 2]);
    }

    #[test]
    fn distance_two_equals_aggregation_on_the_squared_graph() {
        // A 2D grid Laplacian with varying weights (ties and strict maxima), S² formed
        // explicitly (strongest path per neighbour, sorted) against the on-the-fly visit.
        let m = 23;
        let n = m * m;
        let (mut rp, mut cols, mut vals) = (vec![0usize], Vec::new(), Vec::new());
        for i in 0..n {
            let (x, y) = (i % m, i / m);
            let mut row = vec![(i, 4.0)];
            for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                if (0..m as i64).contains(&xx) && (0..m as i64).contains(&yy) {
                    let j = yy as usize * m + xx as usize;
                    let w = 1.0 + ((i.min(j) * 7 + i.max(j)) % 3) as f64;
                    row.push((j, -w));
                }
            }
            row.sort_by_key(|e| e.0);
            for (j, v) in row {
                cols.push(j as u32);
                vals.push(v);
            }
            rp.push(cols.len());
        }
        let a = CsrMatrix::from_parts(n, n, rp, cols, vals);
        let blocks = Blocks::from_ids(&(0..n).collect::<Vec<_>>()).unwrap();
        let s = strength(&a, &blocks, 0.0);
        let mut parts = Vec::new();
        let (mut counts, mut adj, mut w) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..n {
            let mut row: Vec<(u32, f64)> = Vec::new();
            s.visit(i, true, |j, wj| row.push((j, wj)));
            row.sort_unstable_by(|x, y| x.0.cmp(&y.0).then(y.1.total_cmp(&x.1)));
            row.dedup_by_key(|x| x.0);
            counts.push(row.len());
            adj.extend(row.iter().map(|x| x.0));
            w.extend(row.iter().map(|x| x.1));
        }
        parts.push((counts, adj, w));
        let s2 = Strength::concat(n, parts);
        let explicit = aggregate(&s2, false);
        let on_the_fly = aggregate(&s, true);
        assert_eq!(on_the_fly, explicit);
        assert!(
            explicit.1 > 1 && explicit.1 < n / 9,
            "{} aggregates",
            explicit.1
        );
    }

    #[test]
    fn strength_graph_is_the_block_criterion() {
        // Two equations per node on a 9 × 9 grid of nodes, couplings to the eight
        // neighbours of varying size (some below θ), and the nodes numbered in order (the
        // columns of a row come node by node) or scrambled (they do not). Against the
        // definition: J is kept when ‖A_IJ‖_F > θ √(‖A_II‖_F ‖A_JJ‖_F), with weight ‖A_IJ‖_F.
        let m = 9;
        let nn = m * m;
        let n = 2 * nn;
        let coupling = |i: usize, j: usize, p: usize, q: usize| {
            let (lo, hi) = (i.min(j), i.max(j));
            let k = (lo * 31 + hi * 17 + p * 5 + q * 3) % 11;
            if i == j {
                if p == q { 8.0 } else { 0.5 }
            } else {
                -(0.01 + 0.1 * k as f64)
            }
        };
        let (mut cp, mut ri, mut v) = (vec![0usize], Vec::new(), Vec::new());
        for c in 0..n {
            let (j, q) = (c / 2, c % 2);
            let (xj, yj) = ((j % m) as i64, (j / m) as i64);
            for r in 0..=c {
                let (i, p) = (r / 2, r % 2);
                let (xi, yi) = ((i % m) as i64, (i / m) as i64);
                if (xi - xj).abs() <= 1 && (yi - yj).abs() <= 1 {
                    ri.push(r);
                    v.push(coupling(i, j, p.min(q), p.max(q)));
                }
            }
            cp.push(ri.len());
        }
        let a = SymCsr::from_upper_csc(n, &cp, &ri, &v).unwrap();
        let dense = |r: usize, c: usize| {
            let (r, c) = (r.min(c), r.max(c));
            ri[cp[c]..cp[c + 1]]
                .iter()
                .position(|&x| x == r)
                .map_or(0.0, |k| v[cp[c] + k])
        };
        let theta = 0.1;
        for scrambled in [false, true] {
            // Node id of grid node g (a permutation when scrambled: 7 is prime to 81).
            let id = |g: usize| if scrambled { (7 * g) % nn } else { g };
            let ids: Vec<usize> = (0..n).map(|e| id(e / 2)).collect();
            let blocks = Blocks::from_ids(&ids).unwrap();
            let s = strength(a.matrix(), &blocks, theta);
            // Grid node of block node I: the node with id I.
            let grid_node = |big: usize| (0..nn).find(|&g| id(g) == big).unwrap();
            let norm = |bi: usize, bj: usize| {
                let (gi, gj) = (grid_node(bi), grid_node(bj));
                let mut s2 = 0.0;
                for p in 0..2 {
                    for q in 0..2 {
                        s2 += dense(2 * gi + p, 2 * gj + q).powi(2);
                    }
                }
                s2.sqrt()
            };
            let (mut kept, mut filtered) = (0, 0);
            for bi in 0..nn {
                let mut want = Vec::new();
                for bj in 0..nn {
                    let w = norm(bi, bj);
                    if bj != bi && w > 0.0 {
                        if w > theta * (norm(bi, bi) * norm(bj, bj)).sqrt() {
                            want.push((bj as u32, w));
                        } else {
                            filtered += 1;
                        }
                    }
                }
                let (adj, w) = s.nbrs(bi);
                kept += want.len();
                assert_eq!(adj.len(), want.len(), "node {bi}, scrambled {scrambled}");
                for ((&j, &wj), &(wj_id, ww)) in adj.iter().zip(w).zip(&want) {
                    assert_eq!(j, wj_id);
                    assert!((wj - ww).abs() <= 1e-14 * ww, "{wj} vs {ww}");
                }
            }
            assert!(kept > 0 && filtered > 0, "θ keeps {kept}, drops {filtered}");
        }
    }

    #[test]
    fn tentative_prolongator_reproduces_the_null_space() {
        // 2 vectors (constant and linear) on 9 equations, 3 aggregates.
        let n = 9;
        let mut data = vec![1.0; n];
        data.extend((0..n).map(|i| i as f64));
        let b = NearNullSpace::from_vectors(n, data).unwrap();
        let blocks = Blocks::from_ids(&(0..n).collect::<Vec<_>>()).unwrap();
        let agg = vec![0, 0, 1, 1, 1, 2, 2, 2, 2];
        let t = tentative(&blocks, &agg, 3, &b).unwrap();
        let p = &t.p.to_csr(&t.coarse_blocks.ptr);
        assert_eq!(p.ncols(), 6);
        // P Bc = B, to the single-precision rounding of P's entries (relative 2⁻²⁴ each,
        // at most 4 entries of size ≤ 1 times |Bc| ≤ 15 per row: below 4e-6).
        let tol = 4.0 * 15.0 * f32::EPSILON as f64;
        for k in 0..2 {
            let mut y = vec![0.0; n];
            p.mul(t.coarse_null.vector(k), &mut y).unwrap();
            for (yi, bi) in y.iter().zip(b.vector(k)) {
                assert!((yi - bi).abs() < tol, "{yi} vs {bi}");
            }
        }
        // Orthonormal columns: Pᵀ P = I.
        let (pt, _) = p.transpose_with_map();
        for i in 0..6 {
            for j in 0..6 {
                let mut ei = vec![0.0; 6];
                ei[j] = 1.0;
                let mut col = vec![0.0; n];
                p.mul(&ei, &mut col).unwrap();
                let mut out = vec![0.0; 6];
                pt.mul(&col, &mut out).unwrap();
                let want = if i == j { 1.0 } else { 0.0 };
                // Sums of at most 4 products of entries rounded to single precision.
                assert!((out[i] - want).abs() < 8.0 * f32::EPSILON as f64);
            }
        }
    }

    #[test]
    fn dependent_columns_are_dropped() {
        // A one-equation aggregate cannot hold two independent vectors.
        let b = NearNullSpace::from_vectors(2, vec![1.0, 1.0, 2.0, 3.0]).unwrap();
        let blocks = Blocks::from_ids(&[0, 1]).unwrap();
        let t = tentative(&blocks, &[0, 1], 2, &b).unwrap();
        assert_eq!(t.p.ncols(), 2);
        assert_eq!(t.coarse_blocks.ptr, vec![0, 1, 2]);
        assert_eq!(t.coarse_null.vector(1), &[2.0, 3.0]);
    }
}
