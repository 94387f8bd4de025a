//! Sparse products of the setup, on aggregate blocks: the smoothed prolongator, the
//! restriction, and the Galerkin operator.
//!
//! # Column blocks
//!
//! Every coarse equation belongs to one aggregate, and aggregate `b` owns the consecutive
//! coarse equations `off[b]..off[b+1]` (`k_b ≤ m` of them, `m` the near-null dimension:
//! 3 in 2D, 6 in 3D elasticity, 1 for diffusion). A row of the tentative prolongator, of
//! the smoothed prolongator and of `A P` either holds all columns of an aggregate or none.
//! These matrices are therefore stored with, for every row, its list of aggregate *blocks*
//! (aggregate, position of the first value); the values of a block are contiguous. The
//! products then do their index work (markers, positions) once per block and the
//! arithmetic on short dense vectors: `k` times less bookkeeping than scalar sparse
//! products.
//!
//! All products run row by row with a dense accumulator over the aggregates (a marker or a
//! position per aggregate, per thread): no triplets, no hashing, no per-row allocation.
//! Rows are distributed over threads in fixed blocks and each row is summed in a fixed
//! order, so the results do not depend on the number of threads. The patterns are
//! computed once in the setup; a numeric rebuild for new matrix values scatters into them.
//!
//! # Precision
//!
//! The prolongators store their values in single precision (each computed in double and
//! rounded once, relative `2⁻²⁴`): the restriction and prolongation of every V-cycle read
//! half the bytes, and the hierarchy holds less. The rounded `P` is the prolongator: the
//! coarse operator is the exact (double-precision) Galerkin product `Pᵀ A P` with it, so
//! the coarse correction stays an `A`-orthogonal projection and the V-cycle symmetric;
//! only the near-null space is reproduced to single precision instead of exactly.
//!
//! # Prolongator smoothing
//!
//! `P = (I − ω D⁻¹ A) P_tent` row by row: `p_i = t_i − ω/a_ii Σ_j a_ij t_j`, with `t_j` the
//! single block of row `j` of `P_tent`. Row `i` of `P` has one block per aggregate that
//! contains a neighbour of `i`.
//!
//! # Galerkin operator
//!
//! `A_c = Pᵀ (A P)` without storing `W = A P`: the coarse block rows are split into
//! contiguous *parts*, and each part visits the fine rows `i` whose `P` row has a block
//! `p_{i,a}` of one of its aggregates, computes the row `w_i = (A P)_i` (blocks in the
//! order they are met, only the aggregates from the part's first one on) and adds
//!
//! ```text
//!   (A_c)_{a,b} += p_{i,a} w_{i,b}ᵀ        (k_a × k_b outer products)
//! ```
//!
//! to its block rows `a`. A fine row next to two parts is visited by both; the memory of
//! `W` (larger than `A` itself after aggressive coarsening) is never needed. The rows of a
//! node (a group of `A`: the same columns, hence the same blocks in `P` and `W`) are
//! computed together, with one pass over their columns and one set of block lookups; every
//! entry still receives its rows' terms in increasing row order, so grouping does not
//! change the bits.
//! Only the blocks `b ≥ a` are summed; the diagonal blocks are averaged with their
//! transposes and the blocks `b < a` are copied from the transposed blocks `(b, a)`. This
//! halves the arithmetic and makes `A_c` exactly symmetric, so the V-cycle is an exactly
//! symmetric operator.
//!
//! # Restriction
//!
//! `(Pᵀ r)_{off[a]..off[a+1]} = Σ_i r_i p_{i,a}`, on the parts of the Galerkin product:
//! each part runs over its fine rows and adds to its own aggregates, reading `P` row by
//! row. No transpose of `P` is stored.

use rayon::prelude::*;

use crate::csr::{
    CsrMatrix, ROWS_PER_TASK, block_bounds, par_rows, split_by_items, vec_bytes, zeros,
};
use crate::error::{AmgError, Result};

/// The marker of row (or aggregate) `i` in a dense accumulator. Markers start at zero
/// (fresh zero pages cost nothing until touched), so row `i` is marked `i + 1`.
#[inline]
fn stamp(i: usize) -> u32 {
    i as u32 + 1
}
/// Aggregates per parallel task in the Galerkin product.
const AGGS_PER_TASK: usize = 64;

/// A matrix with scalar rows and columns in aggregate blocks (see the module docs), with
/// 32-bit block tables: no scalar column indices are stored (block `b` covers the columns
/// `off[b]..off[b+1]` of the layout it was built with).
#[derive(Clone, Debug)]
pub(crate) struct Blocked {
    ncols: usize,
    /// Blocks of row `i`: `bptr[i]..bptr[i+1]`.
    bptr: Vec<u32>,
    /// Aggregate of each block.
    bagg: Vec<u32>,
    /// Position in `vals` of each block's first value, and the number of values last.
    bpos: Vec<u32>,
    /// Values in single precision (see the module docs).
    vals: Vec<f32>,
}

impl Blocked {
    /// Heap bytes held.
    pub(crate) fn bytes(&self) -> usize {
        vec_bytes(&self.bptr)
            + vec_bytes(&self.bagg)
            + vec_bytes(&self.bpos)
            + vec_bytes(&self.vals)
    }

    /// The matrix (values zero) whose row `i` holds the aggregates
    /// `bagg[bptr[i]..bptr[i+1]]` (increasing) with the column layout `off`. Errors: more
    /// blocks or values than 32-bit positions hold.
    pub(crate) fn from_blocks(
        nrows: usize,
        off: &[usize],
        bptr: &[usize],
        bagg: Vec<u32>,
    ) -> Result<Self> {
        let width = |b: u32| off[b as usize + 1] - off[b as usize];
        let len: usize = bagg.iter().map(|&b| width(b)).sum();
        if len >= u32::MAX as usize {
            return Err(AmgError::Input(format!(
                "{len} prolongator entries exceed the 32-bit positions"
            )));
        }
        let mut bpos = Vec::with_capacity(bagg.len() + 1);
        let mut at = 0u32;
        for &b in &bagg {
            bpos.push(at);
            at += width(b) as u32;
        }
        bpos.push(at);
        Ok(Self {
            ncols: *off.last().unwrap_or(&0),
            bptr: bptr[..=nrows].iter().map(|&q| q as u32).collect(),
            bagg,
            bpos,
            vals: vec![0.0; len],
        })
    }

    /// Number of rows.
    pub(crate) fn nrows(&self) -> usize {
        self.bptr.len() - 1
    }
    /// Number of (scalar) columns.
    pub(crate) fn ncols(&self) -> usize {
        self.ncols
    }

    /// Aggregates and value positions of the blocks of row `i`.
    #[inline]
    pub(crate) fn blocks(&self, i: usize) -> (&[u32], &[u32]) {
        let r = self.bptr[i] as usize..self.bptr[i + 1] as usize;
        (&self.bagg[r.clone()], &self.bpos[r])
    }

    /// The values of row `i` lie at `row_start(i)..row_start(i + 1)`.
    #[inline]
    pub(crate) fn row_start(&self, i: usize) -> usize {
        self.bpos[self.bptr[i] as usize] as usize
    }

    /// Number of blocks.
    pub(crate) fn num_blocks(&self) -> usize {
        self.bagg.len()
    }

    /// All values, row by row.
    pub(crate) fn values(&self) -> &[f32] {
        &self.vals
    }
    /// All values, mutable.
    pub(crate) fn values_mut(&mut self) -> &mut [f32] {
        &mut self.vals
    }

    /// `y += M x` for the column layout `off` (in parallel over rows).
    pub(crate) fn mul_add(&self, off: &[usize], x: &[f64], y: &mut [f64]) {
        par_rows(y, |i, yi| {
            let (bb, bp) = self.blocks(i);
            let mut sum = 0.0;
            for (&b, &s) in bb.iter().zip(bp) {
                let (c, k, s) = (
                    off[b as usize],
                    off[b as usize + 1] - off[b as usize],
                    s as usize,
                );
                sum += block_dot(&self.vals[s..s + k], &x[c..c + k]);
            }
            *yi += sum;
        });
    }

    /// The scalar CSR form for the column layout `off`.
    #[cfg(test)]
    pub(crate) fn to_csr(&self, off: &[usize]) -> CsrMatrix {
        let mut row_ptr = vec![0];
        let mut col = Vec::new();
        for i in 0..self.nrows() {
            for &b in self.blocks(i).0 {
                col.extend(off[b as usize] as u32..off[b as usize + 1] as u32);
            }
            row_ptr.push(col.len());
        }
        let vals = self.vals.iter().map(|&v| f64::from(v)).collect();
        CsrMatrix::from_parts(self.nrows(), self.ncols, row_ptr, col, vals)
    }
}

/// Per-row block lists computed in parallel blocks of rows and concatenated.
fn concat_block_lists(parts: Vec<(Vec<usize>, Vec<u32>)>, nrows: usize) -> (Vec<usize>, Vec<u32>) {
    let mut bptr = Vec::with_capacity(nrows + 1);
    bptr.push(0);
    let mut bagg = Vec::with_capacity(parts.iter().map(|p| p.1.len()).sum());
    for (counts, aggs) in parts {
        for c in counts {
            bptr.push(bptr.last().copied().unwrap_or(0) + c);
        }
        bagg.extend_from_slice(&aggs);
    }
    (bptr, bagg)
}

/// The pattern of `P = (I − ω D⁻¹A) P_tent`: row `i` has a block for every aggregate
/// `eq_agg[j]` of a column `j` of row `i` of `A` (aggregates of width zero excluded).
pub(crate) fn symbolic_prolongator(
    a: &CsrMatrix,
    eq_agg: &[u32],
    off: &[usize],
) -> Result<Blocked> {
    let n = a.nrows();
    let nagg = off.len() - 1;
    let parts: Vec<(Vec<usize>, Vec<u32>)> = (0..n.div_ceil(ROWS_PER_TASK))
        .into_par_iter()
        .map_init(
            || vec![0u32; nagg],
            |mark, blk| {
                let rows = blk * ROWS_PER_TASK..((blk + 1) * ROWS_PER_TASK).min(n);
                let mut counts = Vec::with_capacity(rows.len());
                let mut aggs = Vec::new();
                let mut last: Option<(u32, std::ops::Range<usize>)> = None;
                for i in rows {
                    let start = aggs.len();
                    // A row of the previous row's group has its columns, hence its blocks.
                    let group = a.row_group(i);
                    if let (Some(g), Some((lg, prev))) = (group, &last)
                        && g == *lg
                    {
                        aggs.extend_from_within(prev.clone());
                        counts.push(aggs.len() - start);
                        continue;
                    }
                    a.for_each_col(i, |j| {
                        let b = eq_agg[j as usize] as usize;
                        if mark[b] != stamp(i) && off[b + 1] > off[b] {
                            mark[b] = stamp(i);
                            aggs.push(b as u32);
                        }
                    });
                    aggs[start..].sort_unstable();
                    counts.push(aggs.len() - start);
                    last = group.map(|g| (g, start..aggs.len()));
                }
                (counts, aggs)
            },
        )
        .collect();
    let (bptr, bagg) = concat_block_lists(parts, n);
    Blocked::from_blocks(n, off, &bptr, bagg)
}

/// `y += s x` on short slices of equal length, unrolled for the common block widths
/// (6: 3D rigid modes, 3: 2D rigid modes).
#[inline]
fn axpy<X: Copy + Into<f64>>(y: &mut [f64], s: f64, x: &[X]) {
    match y.len() {
        6 => axpy_fixed::<6, X>(y, s, x),
        3 => axpy_fixed::<3, X>(y, s, x),
        _ => {
            for (yi, &xi) in y.iter_mut().zip(x) {
                *yi += s * xi.into();
            }
        }
    }
}

/// `v · x` on short slices of equal length, unrolled for the common block widths.
#[inline]
fn block_dot(v: &[f32], x: &[f64]) -> f64 {
    fn fixed<const K: usize>(v: &[f32], x: &[f64]) -> f64 {
        match (<&[f32; K]>::try_from(v), <&[f64; K]>::try_from(x)) {
            (Ok(v), Ok(x)) => (0..K).map(|t| f64::from(v[t]) * x[t]).sum(),
            _ => 0.0,
        }
    }
    match v.len() {
        6 => fixed::<6>(v, x),
        3 => fixed::<3>(v, x),
        _ => v.iter().zip(x).map(|(&v, x)| f64::from(v) * x).sum(),
    }
}

#[inline]
fn axpy_fixed<const K: usize, X: Copy + Into<f64>>(y: &mut [f64], s: f64, x: &[X]) {
    if let (Ok(y), Ok(x)) = (<&mut [f64; K]>::try_from(y), <&[X; K]>::try_from(x)) {
        for t in 0..K {
            y[t] += s * x[t].into();
        }
    }
}

/// Fill `p` (from [`symbolic_prolongator`]) with `T − ω D⁻¹ A T`; `dinv` holds `1/a_ii`.
pub(crate) fn smooth_prolongator(
    a: &CsrMatrix,
    dinv: &[f64],
    omega: f64,
    t: &Blocked,
    off: &[usize],
    p: &mut Blocked,
) {
    let nagg = off.len() - 1;
    let n = p.nrows();
    let Blocked {
        bptr,
        bagg,
        bpos,
        vals,
        ..
    } = p;
    let row_start = |i: usize| bpos[bptr[i] as usize] as usize;
    let tv = t.values();
    let blocks = split_by_items(vals, &block_bounds(n, ROWS_PER_TASK), row_start);
    blocks.into_par_iter().for_each_init(
        || (vec![0usize; nagg], Vec::new()),
        |(pos, acc), (start, vals)| {
            let base = row_start(start);
            for i in start..(start + ROWS_PER_TASK).min(n) {
                // The row is summed in double precision, then rounded.
                let row0 = row_start(i);
                for q in bptr[i] as usize..bptr[i + 1] as usize {
                    pos[bagg[q] as usize] = bpos[q] as usize - row0;
                }
                let row = row0 - base..row_start(i + 1) - base;
                acc.clear();
                acc.resize(row.len(), 0.0);
                a.for_each_in_row(i, |j, aij| {
                    let (tb, tp) = t.blocks(j as usize);
                    for (&b, &s) in tb.iter().zip(tp) {
                        let k = off[b as usize + 1] - off[b as usize];
                        let (d, s) = (pos[b as usize], s as usize);
                        axpy(&mut acc[d..d + k], aij, &tv[s..s + k]);
                    }
                });
                let scale = -omega * dinv[i];
                acc.iter_mut().for_each(|v| *v *= scale);
                let (tb, tp) = t.blocks(i);
                for (&b, &s) in tb.iter().zip(tp) {
                    let k = off[b as usize + 1] - off[b as usize];
                    let (d, s) = (pos[b as usize], s as usize);
                    axpy(&mut acc[d..d + k], 1.0, &tv[s..s + k]);
                }
                for (v, &x) in vals[row].iter_mut().zip(acc.iter()) {
                    *v = x as f32;
                }
            }
        },
    );
}

/// For every aggregate `a`, the rows `i` of `P` with a block of `a`, increasing:
/// `rows[ptr[a]..ptr[a+1]]` (the pattern of the block transpose).
fn rows_of_aggregates(p: &Blocked, nagg: usize) -> (Vec<usize>, Vec<u32>) {
    let mut ptr = vec![0usize; nagg + 1];
    for &b in &p.bagg {
        ptr[b as usize + 1] += 1;
    }
    for a in 0..nagg {
        ptr[a + 1] += ptr[a];
    }
    let mut next = ptr.clone();
    let mut rows = vec![0u32; p.num_blocks()];
    for i in 0..p.nrows() {
        for &b in p.blocks(i).0 {
            rows[next[b as usize]] = i as u32;
            next[b as usize] += 1;
        }
    }
    (ptr, rows)
}

/// `out = Pᵀ r`: every part of `g` sums `r_i p_{i,a}` into its aggregates `a`, over its
/// fine rows `i` increasing (so the result does not depend on the parts).
pub(crate) fn restrict(g: &Galerkin, p: &Blocked, off: &[usize], r: &[f64], out: &mut [f64]) {
    let pv = p.values();
    let parts = split_by_items(out, &g.part_aggs, |a| off[a]);
    parts.into_par_iter().enumerate().for_each(|(k, (_, out))| {
        let (lo, hi) = (g.part_aggs[k], g.part_aggs[k + 1]);
        let base = off[lo];
        out.fill(0.0);
        for &i in &g.rows[g.rptr[k]..g.rptr[k + 1]] {
            let ri = r[i as usize];
            let (pb, pp) = p.blocks(i as usize);
            for (&a, &s) in pb.iter().zip(pp) {
                let (a, s) = (a as usize, s as usize);
                if (lo..hi).contains(&a) {
                    let d = off[a] - base;
                    let ka = off[a + 1] - off[a];
                    axpy(&mut out[d..d + ka], ri, &pv[s..s + ka]);
                }
            }
        }
    });
}

/// The block pattern of `A_c`, with the offsets and mirrors the numeric product needs, and
/// the fine rows each part of the numeric product visits.
#[derive(Clone, Debug, Default)]
pub(crate) struct Galerkin {
    /// Blocks of block row `a`: `bptr[a]..bptr[a+1]`, aggregates increasing.
    bptr: Vec<usize>,
    bagg: Vec<u32>,
    /// Column offset of each block within its (scalar) rows.
    boff: Vec<usize>,
    /// Index of the mirror block `(b, a)` of each block `(a, b)`.
    mirror: Vec<usize>,
    /// Part `k` owns the block rows `part_aggs[k]..part_aggs[k+1]`.
    part_aggs: Vec<usize>,
    /// The fine rows of part `k` (increasing): `rows[rptr[k]..rptr[k+1]]`, those whose
    /// row of `P` has a block in the part's aggregates.
    rptr: Vec<usize>,
    rows: Vec<u32>,
}

impl Galerkin {
    /// Heap bytes held.
    pub(crate) fn bytes(&self) -> usize {
        vec_bytes(&self.bptr)
            + vec_bytes(&self.bagg)
            + vec_bytes(&self.boff)
            + vec_bytes(&self.mirror)
            + vec_bytes(&self.part_aggs)
            + vec_bytes(&self.rptr)
            + vec_bytes(&self.rows)
    }
}

/// Rows `i0..i0 + M` of `W = A P` restricted to the aggregates `≥ lo`, in blocks, for the
/// `M` rows of one group of `A` (same columns, hence the same blocks of `P` and of `W`; a
/// single row for `M = 1`): appends the aggregates to `aggs` and, per aggregate `b`, its
/// values row after row (`M · k_b` of them) to `vals`. The index work is done once for
/// all `M` rows, and each row's values are summed in column order, so grouping does not
/// change the bits. `slot[b]` is `u32::MAX` on entry for every `b` and is restored before
/// returning.
#[allow(clippy::too_many_arguments)]
#[inline]
fn w_rows<const M: usize>(
    a: &CsrMatrix,
    p: &Blocked,
    off: &[usize],
    i0: usize,
    lo: usize,
    slot: &mut [u32],
    aggs: &mut Vec<u32>,
    vals: &mut Vec<f64>,
) {
    let pv = p.values();
    aggs.clear();
    vals.clear();
    a.for_each_in_group::<M>(i0, |j, aij| {
        let (pb, pp) = p.blocks(j as usize);
        for (&b, &s) in pb.iter().zip(pp) {
            let (bu, s) = (b as usize, s as usize);
            if bu < lo {
                continue;
            }
            let k = off[bu + 1] - off[bu];
            let pjb = &pv[s..s + k];
            if slot[bu] == u32::MAX {
                slot[bu] = vals.len() as u32;
                aggs.push(b);
                for aq in aij {
                    vals.extend(pjb.iter().map(|&v| aq * f64::from(v)));
                }
            } else {
                let d = slot[bu] as usize;
                for (q, aq) in aij.into_iter().enumerate() {
                    axpy(&mut vals[d + q * k..d + (q + 1) * k], aq, pjb);
                }
            }
        }
    });
    for &b in aggs.iter() {
        slot[b as usize] = u32::MAX;
    }
}

/// The pattern of `A_c = Pᵀ A P` (block rows of the coarse aggregates), the parts of the
/// numeric product, and `A_c` with zero values.
pub(crate) fn symbolic_galerkin(
    a: &CsrMatrix,
    p: &Blocked,
    off: &[usize],
) -> (Galerkin, CsrMatrix) {
    let nagg = off.len() - 1;
    let (pt_ptr, pt_rows) = rows_of_aggregates(p, nagg);
    let rows_of = |ag: usize| &pt_rows[pt_ptr[ag]..pt_ptr[ag + 1]];
    // Block (a, b) is present when some row i has a block of a in P and a column j of A
    // whose row of P has a block of b.
    let lists: Vec<(Vec<usize>, Vec<u32>)> = (0..nagg.div_ceil(AGGS_PER_TASK))
        .into_par_iter()
        .map_init(
            || vec![0u32; nagg],
            |mark, blk| {
                let aggs = blk * AGGS_PER_TASK..((blk + 1) * AGGS_PER_TASK).min(nagg);
                let mut counts = Vec::with_capacity(aggs.len());
                let mut list = Vec::new();
                for ag in aggs {
                    let start = list.len();
                    if off[ag + 1] > off[ag] {
                        // Rows of one group (the components of a node) have the same
                        // columns, hence the same blocks: the first of them stands for all.
                        let mut last_group = None;
                        for &i in rows_of(ag) {
                            let group = a.row_group(i as usize);
                            if group.is_some() && group == last_group {
                                continue;
                            }
                            last_group = group;
                            a.for_each_col(i as usize, |j| {
                                for &b in p.blocks(j as usize).0 {
                                    if mark[b as usize] != stamp(ag) {
                                        mark[b as usize] = stamp(ag);
                                        list.push(b);
                                    }
                                }
                            });
                        }
                    }
                    list[start..].sort_unstable();
                    counts.push(list.len() - start);
                }
                (counts, list)
            },
        )
        .collect();
    let (bptr, bagg) = concat_block_lists(lists, nagg);
    let width = |b: u32| off[b as usize + 1] - off[b as usize];
    let mut boff = Vec::with_capacity(bagg.len());
    let mut row_len = vec![0usize; nagg];
    for ag in 0..nagg {
        let mut len = 0;
        for &b in &bagg[bptr[ag]..bptr[ag + 1]] {
            boff.push(len);
            len += width(b);
        }
        row_len[ag] = len;
    }
    let mirror: Vec<usize> = (0..nagg)
        .into_par_iter()
        .flat_map_iter(|ag| {
            let (bptr, bagg) = (&bptr, &bagg);
            bagg[bptr[ag]..bptr[ag + 1]].iter().map(move |&b| {
                let row = &bagg[bptr[b as usize]..bptr[b as usize + 1]];
                // The pattern is symmetric: (a, b) present ⇒ (b, a) present.
                bptr[b as usize] + row.binary_search(&(ag as u32)).unwrap_or(0)
            })
        })
        .collect();
    let nc = off[nagg];
    let mut row_ptr = Vec::with_capacity(nc + 1);
    row_ptr.push(0);
    for ag in 0..nagg {
        for _ in 0..width(ag as u32) {
            row_ptr.push(row_ptr.last().copied().unwrap_or(0) + row_len[ag]);
        }
    }
    let nnz = row_ptr[nc];
    let mut col = Vec::with_capacity(nnz);
    for ag in 0..nagg {
        for _ in 0..width(ag as u32) {
            for &b in &bagg[bptr[ag]..bptr[ag + 1]] {
                col.extend(off[b as usize] as u32..off[b as usize + 1] as u32);
            }
        }
    }
    // Parts: contiguous block rows with about equal numbers of values.
    // Few parts: a fine row next to two parts is visited by both.
    let num_parts = (2 * rayon::current_num_threads()).clamp(1, nagg.max(1));
    let mut part_aggs = vec![0usize];
    for k in 1..num_parts {
        let target = nnz * k / num_parts;
        let ag = (off.partition_point(|&o| row_ptr[o] < target))
            .saturating_sub(1)
            .min(nagg);
        if ag > *part_aggs.last().unwrap_or(&0) {
            part_aggs.push(ag);
        }
    }
    if nagg > *part_aggs.last().unwrap_or(&0) || part_aggs.len() == 1 {
        part_aggs.push(nagg);
    }
    let row_lists: Vec<Vec<u32>> = part_aggs
        .par_windows(2)
        .map(|w| {
            let mut rows: Vec<u32> = (w[0]..w[1])
                .flat_map(|ag| rows_of(ag).iter().copied())
                .collect();
            rows.sort_unstable();
            rows.dedup();
            rows
        })
        .collect();
    let mut rptr = Vec::with_capacity(row_lists.len() + 1);
    rptr.push(0);
    let mut rows = Vec::with_capacity(row_lists.iter().map(Vec::len).sum());
    for list in row_lists {
        rows.extend_from_slice(&list);
        rptr.push(rows.len());
    }
    let ac = CsrMatrix::from_parts(nc, nc, row_ptr, col, zeros(nnz));
    (
        Galerkin {
            bptr,
            bagg,
            boff,
            mirror,
            part_aggs,
            rptr,
            rows,
        },
        ac,
    )
}

/// The data a part of [`numeric_galerkin`] works on.
struct GalerkinRows<'a> {
    a: &'a CsrMatrix,
    p: &'a Blocked,
    off: &'a [usize],
    g: &'a Galerkin,
    row_ptr: &'a [usize],
    /// The part's aggregates.
    lo: usize,
    hi: usize,
    /// Position in `A_c`'s values of the part's first value.
    base: usize,
}

impl GalerkinRows<'_> {
    /// Add `p_{i,a} w_{i,b}ᵀ` (`b ≥ a`, `a` in the part) for the `M` rows `i0..i0 + M` of
    /// one group of `A` to the part's values `vals`. The rows have the same blocks in `P`
    /// and `W`; the block lookups are done once for all of them, and every entry still
    /// receives the rows' terms in increasing row order.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn add<const M: usize>(
        &self,
        i0: usize,
        slot: &mut [u32],
        pos: &mut [usize],
        waggs: &mut Vec<u32>,
        wvals: &mut Vec<f64>,
        vals: &mut [f64],
    ) {
        let Self {
            a,
            p,
            off,
            g,
            row_ptr,
            lo,
            hi,
            base,
        } = *self;
        let width = |b: usize| off[b + 1] - off[b];
        let pv = p.values();
        w_rows::<M>(a, p, off, i0, lo, slot, waggs, wvals);
        let blocks: [(&[u32], &[u32]); M] = std::array::from_fn(|q| p.blocks(i0 + q));
        for (bi, &ag) in blocks[0].0.iter().enumerate() {
            let ag = ag as usize;
            if ag < lo || ag >= hi {
                continue;
            }
            let ka = width(ag);
            let start = row_ptr[off[ag]] - base;
            let len = row_ptr[off[ag] + 1] - row_ptr[off[ag]];
            for q in g.bptr[ag]..g.bptr[ag + 1] {
                pos[g.bagg[q] as usize] = g.boff[q];
            }
            let block_row = &mut vals[start..start + ka * len];
            for (q, (_, bp)) in blocks.iter().enumerate() {
                let s = bp[bi] as usize;
                let pia = &pv[s..s + ka];
                let mut t = 0;
                for &b in waggs.iter() {
                    let b = b as usize;
                    let kb = width(b);
                    if b >= ag {
                        let wib = &wvals[t + q * kb..t + (q + 1) * kb];
                        let co = pos[b];
                        for (r, &x) in pia.iter().enumerate() {
                            let d = r * len + co;
                            axpy(&mut block_row[d..d + kb], f64::from(x), wib);
                        }
                    }
                    t += M * kb;
                }
            }
        }
    }
}

/// Fill `ac` (from [`symbolic_galerkin`]) with `Pᵀ A P`, exactly symmetric, without
/// storing `A P`: every part computes the rows `w_i = (A P)_i` of its fine rows (the
/// aggregates `≥` its first one) and adds `p_{i,a} w_{i,b}ᵀ` to its block rows `a`, for
/// `b ≥ a`. Each entry is summed by one part, over `i` increasing, so the result does not
/// depend on the number of parts or threads.
pub(crate) fn numeric_galerkin(
    g: &Galerkin,
    a: &CsrMatrix,
    p: &Blocked,
    off: &[usize],
    ac: &mut CsrMatrix,
) {
    let nagg = off.len() - 1;
    let width = |b: usize| off[b + 1] - off[b];
    let row_ptr = ac.row_ptr().to_vec();
    // Pass 1: blocks (a, b ≥ a); diagonal blocks symmetrized.
    let parts = split_by_items(ac.values_mut(), &g.part_aggs, |a| row_ptr[off[a]]);
    parts.into_par_iter().enumerate().for_each_init(
        || {
            (
                vec![u32::MAX; nagg],
                vec![0usize; nagg],
                Vec::new(),
                Vec::new(),
            )
        },
        |(slot, pos, waggs, wvals), (k, (_, vals))| {
            let (lo, hi) = (g.part_aggs[k], g.part_aggs[k + 1]);
            let base = row_ptr[off[lo]];
            vals.fill(0.0);
            let rows = &g.rows[g.rptr[k]..g.rptr[k + 1]];
            let mut t = 0;
            while t < rows.len() {
                let i = rows[t] as usize;
                // Rows of one group of `A` (consecutive in the part's list) go together.
                let mut m = a.group_run(i, a.nrows(), 3);
                m = (1..m)
                    .find(|&q| rows.get(t + q) != Some(&((i + q) as u32)))
                    .unwrap_or(m);
                let cx = GalerkinRows {
                    a,
                    p,
                    off,
                    g,
                    row_ptr: &row_ptr,
                    lo,
                    hi,
                    base,
                };
                match m {
                    1 => cx.add::<1>(i, slot, pos, waggs, wvals, vals),
                    2 => cx.add::<2>(i, slot, pos, waggs, wvals, vals),
                    _ => cx.add::<3>(i, slot, pos, waggs, wvals, vals),
                }
                t += m;
            }
            for ag in lo..hi {
                let ka = width(ag);
                if ka == 0 {
                    continue;
                }
                let start = row_ptr[off[ag]] - base;
                let len = row_ptr[off[ag] + 1] - row_ptr[off[ag]];
                let q = g.bptr[ag]
                    + g.bagg[g.bptr[ag]..g.bptr[ag + 1]].partition_point(|&b| (b as usize) < ag);
                let co = g.boff[q];
                let block_row = &mut vals[start..start + ka * len];
                for r in 0..ka {
                    for c in r + 1..ka {
                        let (u, l) = (r * len + co + c, c * len + co + r);
                        let v = 0.5 * (block_row[u] + block_row[l]);
                        block_row[u] = v;
                        block_row[l] = v;
                    }
                }
            }
        },
    );
    // Pass 2: blocks (a, b < a) from the transposed blocks (b, a).
    // A temporary copy of the upper blocks (freed at return: nothing kept between calls).
    let copy = ac.values().to_vec();
    let src = &copy[..];
    split_by_items(ac.values_mut(), &block_bounds(nagg, AGGS_PER_TASK), |a| {
        row_ptr[off[a]]
    })
    .into_par_iter()
    .for_each(|(a0, vals)| {
        let base = row_ptr[off[a0]];
        for ag in a0..(a0 + AGGS_PER_TASK).min(nagg) {
            let ka = width(ag);
            if ka == 0 {
                continue;
            }
            let start = row_ptr[off[ag]] - base;
            let len = row_ptr[off[ag] + 1] - row_ptr[off[ag]];
            for q in g.bptr[ag]..g.bptr[ag + 1] {
                let b = g.bagg[q] as usize;
                if b >= ag {
                    break;
                }
                let kb = width(b);
                let m = g.mirror[q];
                let sbase = row_ptr[off[b]] + g.boff[m];
                let slen = row_ptr[off[b] + 1] - row_ptr[off[b]];
                for r in 0..ka {
                    for c in 0..kb {
                        vals[start + r * len + g.boff[q] + c] = src[sbase + c * slen + r];
                    }
                }
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense(m: &CsrMatrix) -> Vec<Vec<f64>> {
        let mut d = vec![vec![0.0; m.ncols()]; m.nrows()];
        for i in 0..m.nrows() {
            m.for_each_in_row(i, |j, x| d[i][j as usize] += x);
        }
        d
    }

    fn from_dense(d: &[Vec<f64>]) -> CsrMatrix {
        let mut rp = vec![0];
        let mut c = vec![];
        let mut v = vec![];
        for row in d {
            for (j, &x) in row.iter().enumerate() {
                if x != 0.0 {
                    c.push(j as u32);
                    v.push(x);
                }
            }
            rp.push(c.len());
        }
        CsrMatrix::from_parts(d.len(), d[0].len(), rp, c, v)
    }

    fn matmul(a: &[Vec<f64>], b: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let mut c = vec![vec![0.0; b[0].len()]; a.len()];
        for i in 0..a.len() {
            for k in 0..b.len() {
                for j in 0..b[0].len() {
                    c[i][j] += a[i][k] * b[k][j];
                }
            }
        }
        c
    }

    fn transpose(a: &[Vec<f64>]) -> Vec<Vec<f64>> {
        (0..a[0].len())
            .map(|j| a.iter().map(|r| r[j]).collect())
            .collect()
    }

    #[test]
    fn node_groups_give_the_same_bits() {
        // Two equations per node on a chain of 12 nodes (each node coupled to its
        // neighbours: rows of a node share six consecutive columns), aggregates of three
        // nodes with three coarse equations each. The matrix stored as runs takes the
        // grouped paths; the same matrix with column indices the row-by-row ones.
        let (nodes, k) = (12, 2);
        let n = nodes * k;
        let mut a = vec![vec![0.0; n]; n];
        for i in 0..n {
            for j in 0..n {
                let (ni, nj) = (i / k, j / k);
                if ni.abs_diff(nj) <= 1 {
                    a[i][j] = if i == j {
                        6.0 + 0.1 * i as f64
                    } else {
                        -0.5 - 0.01 * ((i * 7 + j * 7) % 5) as f64
                    };
                }
            }
        }
        let plain = from_dense(&a);
        let mut grouped = from_dense(&a);
        grouped.compress_runs();
        assert!(grouped.row_group(0).is_some() && grouped.row_group(0) == grouped.row_group(1));
        let nagg = nodes / 3;
        let off: Vec<usize> = (0..=nagg).map(|b| 3 * b).collect();
        let eq_agg: Vec<u32> = (0..n).map(|i| (i / (3 * k)) as u32).collect();
        let bptr: Vec<usize> = (0..=n).collect();
        let mut t = Blocked::from_blocks(n, &off, &bptr, eq_agg.clone()).unwrap();
        for (q, v) in t.values_mut().iter_mut().enumerate() {
            *v = ((q * 13 % 7) as f32 - 3.0) / 4.0;
        }
        let dinv: Vec<f64> = (0..n).map(|i| 1.0 / a[i][i]).collect();
        let galerkin = |am: &CsrMatrix| {
            let mut p = symbolic_prolongator(am, &eq_agg, &off).unwrap();
            smooth_prolongator(am, &dinv, 0.5, &t, &off, &mut p);
            let (g, mut ac) = symbolic_galerkin(am, &p, &off);
            numeric_galerkin(&g, am, &p, &off, &mut ac);
            (dense(&p.to_csr(&off)), dense(&ac))
        };
        let (pd, want_bits) = galerkin(&plain);
        let (pg, got) = galerkin(&grouped);
        assert_eq!(pd, pg);
        let want = matmul(&transpose(&pd), &matmul(&a, &pd));
        for i in 0..off[nagg] {
            for j in 0..off[nagg] {
                assert_eq!(
                    got[i][j].to_bits(),
                    want_bits[i][j].to_bits(),
                    "Ac[{i}][{j}]"
                );
                assert!((got[i][j] - want[i][j]).abs() < 1e-13, "Ac[{i}][{j}]");
            }
        }
    }

    #[test]
    fn block_products_match_dense() {
        // A 6×6 SPD matrix (a 1D chain with a longer-range coupling), three aggregates
        // {0,1}, {2,3}, {4,5} of widths 2, 1, 2.
        let n = 6;
        let mut a = vec![vec![0.0; n]; n];
        for i in 0..n {
            a[i][i] = 4.0 + i as f64 * 0.1;
            if i + 1 < n {
                a[i][i + 1] = -1.0;
                a[i + 1][i] = -1.0;
            }
            if i + 2 < n {
                a[i][i + 2] = -0.3;
                a[i + 2][i] = -0.3;
            }
        }
        let off = vec![0, 2, 3, 5];
        let eq_agg: Vec<u32> = vec![0, 0, 1, 1, 2, 2];
        // Tentative: row i has the block of its aggregate.
        let bptr: Vec<usize> = (0..=n).collect();
        let mut t = Blocked::from_blocks(n, &off, &bptr, eq_agg.clone()).unwrap();
        let tvals = [0.6f32, 0.8, -0.8, 0.6, 0.7, 0.7, 1.0, 0.0, 0.0, 1.0];
        t.values_mut().copy_from_slice(&tvals);
        let am = from_dense(&a);
        let mut p = symbolic_prolongator(&am, &eq_agg, &off).unwrap();
        let dinv: Vec<f64> = (0..n).map(|i| 1.0 / a[i][i]).collect();
        let omega = 0.4;
        smooth_prolongator(&am, &dinv, omega, &t, &off, &mut p);
        let td = dense(&t.to_csr(&off));
        let at = matmul(&a, &td);
        let pd = dense(&p.to_csr(&off));
        for i in 0..n {
            for j in 0..5 {
                // Computed in double precision, stored rounded to single.
                let want = td[i][j] - omega * dinv[i] * at[i][j];
                assert_eq!(pd[i][j], want as f32 as f64, "P[{i}][{j}]");
            }
        }
        let (g, mut ac) = symbolic_galerkin(&am, &p, &off);
        numeric_galerkin(&g, &am, &p, &off, &mut ac);
        let want = matmul(&transpose(&pd), &matmul(&a, &pd));
        let got = dense(&ac);
        for i in 0..5 {
            for j in 0..5 {
                assert!((got[i][j] - want[i][j]).abs() < 1e-14, "Ac[{i}][{j}]");
                assert_eq!(got[i][j], got[j][i]);
            }
        }
        // Restriction.
        let r: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut rc = vec![0.0; 5];
        restrict(&g, &p, &off, &r, &mut rc);
        for j in 0..5 {
            let want: f64 = (0..n).map(|i| pd[i][j] * r[i]).sum();
            assert!((rc[j] - want).abs() < 1e-15);
        }
    }
}
