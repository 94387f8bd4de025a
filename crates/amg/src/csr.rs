//! Compressed sparse row matrices, the symmetric matrix built from an upper triangle, and
//! the parallel vector kernels.
//!
//! # Storage
//!
//! [`CsrMatrix`] stores row `i` in `row_ptr[i]..row_ptr[i+1]` with 32-bit column indices
//! sorted within the row (12 bytes per entry instead of 16 moves less memory in the
//! bandwidth-bound products). [`SymCsr`] expands a symmetric matrix given by its upper
//! triangle in compressed sparse *column* form — the layout of the reduced stiffness in
//! porofrac and of faer's symmetric solvers — into the full matrix once: entry `(r, c)`,
//! `r ≤ c`, of the upper triangle lands in rows `r` and `c`; new values on the same
//! pattern (time steps, fracture updates) are a parallel gather (see [`SymCsr`]).
//!
//! Rows with the same columns (the components of a node, the coarse equations of an
//! aggregate) are stored as column runs shared by the group and multiplied together: each
//! piece of `x` is read once for the whole group. Values are `f64` or `f32`
//! ([`Precision`]); products always accumulate in `f64`.
//!
//! # Determinism
//!
//! Products are computed row by row, each row by one thread in a fixed order; reductions
//! (dot products) sum fixed-size blocks in parallel and add the block sums in order. The
//! results are therefore bitwise independent of the number of threads.

use rayon::prelude::*;

use crate::error::{AmgError, Result, check_finite};

/// Storage precision of a matrix's values.
///
/// A preconditioner only has to be a fixed symmetric positive definite operator close to
/// `A⁻¹`: storing the finest matrix of a hierarchy in single precision (rounding each entry
/// to a relative 6e-8) halves the bytes its products read — most of a V-cycle's cost — and
/// its memory, while the Krylov method keeps multiplying by the exact double-precision
/// matrix (see [`crate::Amg::solve_upper`]). Products always accumulate in `f64`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    /// `f64` values.
    #[default]
    Double,
    /// `f32` values, read as `f64`.
    Single,
}

/// A stored value type: `f64`, or `f32` read as `f64`.
pub(crate) trait Value: Copy + Default + PartialEq + Send + Sync + 'static {
    fn get(self) -> f64;
    fn from_f64(v: f64) -> Self;
}

impl Value for f64 {
    #[inline(always)]
    fn get(self) -> f64 {
        self
    }
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v
    }
}

impl Value for f32 {
    #[inline(always)]
    fn get(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v as f32
    }
}

/// The values of a matrix in their storage precision.
#[derive(Clone, Debug)]
enum Values {
    Double(Vec<f64>),
    Single(Vec<f32>),
}

impl Default for Values {
    fn default() -> Self {
        Values::Double(Vec::new())
    }
}

/// Evaluate `$body` with `$v` bound to the value slice of either precision (`$body` must
/// compile for both).
macro_rules! with_values {
    ($vals:expr, $v:ident => $body:expr) => {
        match $vals {
            Values::Double($v) => $body,
            Values::Single($v) => $body,
        }
    };
}

/// Rows per parallel task in matrix kernels.
pub(crate) const ROWS_PER_TASK: usize = 512;
/// Entries per parallel task in vector kernels.
pub(crate) const VEC_BLOCK: usize = 4096;

/// A sparse matrix in compressed sparse row form with sorted 32-bit column indices.
#[derive(Clone, Debug, Default)]
pub struct CsrMatrix {
    nrows: usize,
    ncols: usize,
    row_ptr: Vec<usize>,
    col: Vec<u32>,
    val: Values,
    runs: Option<Runs>,
}

/// The column pattern as runs of consecutive columns, shared by groups of consecutive
/// rows with the same pattern (the components of a node, the coarse equations of an
/// aggregate). Products then read one `(start, length)` pair per run instead of one index
/// per entry, and contiguous pieces of `x`.
#[derive(Clone, Debug, Default)]
struct Runs {
    /// Group of each row.
    row_group: Vec<u32>,
    /// Runs of group `g`: `ptr[g]..ptr[g+1]`.
    ptr: Vec<usize>,
    start: Vec<u32>,
    len: Vec<u32>,
}

/// Heap bytes of a vector's capacity.
pub(crate) fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}

impl CsrMatrix {
    /// Heap bytes held (indices, values, run tables).
    pub(crate) fn bytes(&self) -> usize {
        vec_bytes(&self.row_ptr)
            + vec_bytes(&self.col)
            + with_values!(&self.val, v => vec_bytes(v))
            + self.runs.as_ref().map_or(0, |r| {
                vec_bytes(&r.row_group)
                    + vec_bytes(&r.ptr)
                    + vec_bytes(&r.start)
                    + vec_bytes(&r.len)
            })
    }

    /// Assemble from raw parts (internal: callers guarantee consistency).
    pub(crate) fn from_parts(
        nrows: usize,
        ncols: usize,
        row_ptr: Vec<usize>,
        col: Vec<u32>,
        val: Vec<f64>,
    ) -> Self {
        debug_assert_eq!(row_ptr.len(), nrows + 1);
        debug_assert_eq!(col.len(), val.len());
        debug_assert_eq!(row_ptr[nrows], col.len());
        Self {
            nrows,
            ncols,
            row_ptr,
            col,
            val: Values::Double(val),
            runs: None,
        }
    }

    /// Store the pattern as column runs of row groups (see [`Runs`]) instead of column
    /// indices when that reads less memory: at least three entries per run on average.
    /// The column indices are then dropped (rows are read through
    /// [`Self::for_each_in_row`] and [`Self::for_each_col`]).
    pub(crate) fn compress_runs(&mut self) {
        if self.runs.is_some() {
            return;
        }
        let runs = self.runs_of();
        if 3 * runs.start.len() <= self.nnz() {
            self.runs = Some(runs);
            self.col = Vec::new();
        }
    }

    /// The run table, computed in parallel over blocks of rows whose bounds never split a
    /// group (so the table is the one a single pass gives).
    fn runs_of(&self) -> Runs {
        const ROWS_PER_PART: usize = 1 << 16;
        let n = self.nrows;
        let cols_of = |i: usize| &self.col[self.row_ptr[i]..self.row_ptr[i + 1]];
        let mut bounds = vec![0];
        let mut b = ROWS_PER_PART;
        while b < n {
            while b < n && cols_of(b) == cols_of(b - 1) {
                b += 1;
            }
            if b < n {
                bounds.push(b);
            }
            b += ROWS_PER_PART;
        }
        bounds.push(n);
        let parts: Vec<Runs> = bounds
            .par_windows(2)
            .map(|w| {
                let mut runs = Runs {
                    row_group: Vec::with_capacity(w[1] - w[0]),
                    ptr: vec![0],
                    start: Vec::new(),
                    len: Vec::new(),
                };
                let mut prev: Option<usize> = None;
                for i in w[0]..w[1] {
                    let cols = cols_of(i);
                    if let Some(p) = prev
                        && cols_of(p) == cols
                    {
                        runs.row_group.push((runs.ptr.len() - 2) as u32);
                        continue;
                    }
                    prev = Some(i);
                    let mut k = 0;
                    while k < cols.len() {
                        let s = cols[k];
                        let mut e = k + 1;
                        while e < cols.len() && cols[e] == cols[e - 1] + 1 {
                            e += 1;
                        }
                        runs.start.push(s);
                        runs.len.push((e - k) as u32);
                        k = e;
                    }
                    runs.ptr.push(runs.start.len());
                    runs.row_group.push((runs.ptr.len() - 2) as u32);
                }
                runs
            })
            .collect();
        let total = |f: fn(&Runs) -> usize| parts.iter().map(f).sum::<usize>();
        let mut runs = Runs {
            row_group: Vec::with_capacity(n),
            ptr: Vec::with_capacity(total(|r| r.ptr.len() - 1) + 1),
            start: Vec::with_capacity(total(|r| r.start.len())),
            len: Vec::with_capacity(total(|r| r.len.len())),
        };
        runs.ptr.push(0);
        for part in parts {
            let (groups, at) = ((runs.ptr.len() - 1) as u32, runs.start.len());
            runs.row_group
                .extend(part.row_group.iter().map(|g| g + groups));
            runs.ptr.extend(part.ptr[1..].iter().map(|p| p + at));
            runs.start.extend(part.start);
            runs.len.extend(part.len);
        }
        runs
    }

    /// Number of rows.
    pub fn nrows(&self) -> usize {
        self.nrows
    }
    /// Number of columns.
    pub fn ncols(&self) -> usize {
        self.ncols
    }
    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_ptr[self.nrows]
    }
    /// Precision of the stored values.
    pub fn precision(&self) -> Precision {
        match self.val {
            Values::Double(_) => Precision::Double,
            Values::Single(_) => Precision::Single,
        }
    }
    /// Store the values in double precision (a no-op if they are).
    pub(crate) fn store_double(&mut self) {
        if let Values::Single(v) = &self.val {
            self.val = Values::Double(v.iter().map(|x| x.get()).collect());
        }
    }
    /// Row offsets (length `nrows + 1`).
    pub fn row_ptr(&self) -> &[usize] {
        &self.row_ptr
    }
    /// Column index of every stored entry, sorted within each row (built from the column
    /// runs when the matrix stores those).
    pub fn col_idx(&self) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.nnz());
        for i in 0..self.nrows {
            self.for_each_col(i, |j| out.push(j));
        }
        out
    }
    /// Value of every stored entry of a matrix stored in double precision (empty for one
    /// in single precision: the matrices whose values are read this way — prolongators,
    /// coarse levels — are always double).
    pub(crate) fn values(&self) -> &[f64] {
        match &self.val {
            Values::Double(v) => v,
            Values::Single(_) => {
                debug_assert!(false, "values() of a single-precision matrix");
                &[]
            }
        }
    }
    pub(crate) fn values_mut(&mut self) -> &mut [f64] {
        match &mut self.val {
            Values::Double(v) => v,
            Values::Single(_) => {
                debug_assert!(false, "values_mut() of a single-precision matrix");
                &mut []
            }
        }
    }
    /// The stored value at position `p` (of all entries, rows in order).
    #[inline]
    pub(crate) fn value_at(&self, p: usize) -> f64 {
        with_values!(&self.val, v => v[p].get())
    }

    /// `f(column, value)` for the entries of row `i`, columns increasing.
    #[inline]
    pub fn for_each_in_row(&self, i: usize, f: impl FnMut(u32, f64)) {
        with_values!(&self.val, v => self.for_each_in_row_of(v, i, f))
    }

    #[inline(always)]
    fn for_each_in_row_of<T: Value>(&self, val: &[T], i: usize, mut f: impl FnMut(u32, f64)) {
        let (p0, p1) = (self.row_ptr[i], self.row_ptr[i + 1]);
        prefetch_ahead(val, p0);
        match &self.runs {
            Some(r) => {
                let g = r.row_group[i] as usize;
                let mut p = p0;
                for k in r.ptr[g]..r.ptr[g + 1] {
                    let c = r.start[k];
                    for (t, &v) in val[p..p + r.len[k] as usize].iter().enumerate() {
                        f(c + t as u32, v.get());
                    }
                    p += r.len[k] as usize;
                }
            }
            None => {
                for (&c, &v) in self.col[p0..p1].iter().zip(&val[p0..p1]) {
                    f(c, v.get());
                }
            }
        }
    }

    /// `f(column, [a_{i0+q, column}; M])` over the entries of the `M` rows `i0..i0 + M`,
    /// which must be rows of one group ([`Self::row_group`]; any row for `M = 1`): they
    /// share their columns, which are read once for all of them.
    #[inline]
    pub(crate) fn for_each_in_group<const M: usize>(
        &self,
        i0: usize,
        mut f: impl FnMut(u32, [f64; M]),
    ) {
        if M == 1 && self.runs.is_none() {
            self.for_each_in_row(i0, |j, v| f(j, [v; M]));
            return;
        }
        with_values!(&self.val, v => self.for_each_in_group_of::<M, _>(v, i0, f))
    }

    #[inline(always)]
    fn for_each_in_group_of<const M: usize, T: Value>(
        &self,
        val: &[T],
        i0: usize,
        mut f: impl FnMut(u32, [f64; M]),
    ) {
        let Some(r) = &self.runs else {
            debug_assert!(false, "for_each_in_group on a matrix without row groups");
            return;
        };
        let base = self.row_ptr[i0];
        let len = self.row_ptr[i0 + 1] - base;
        prefetch_ahead(val, base);
        let rows: [&[T]; M] = std::array::from_fn(|q| &val[base + q * len..base + (q + 1) * len]);
        let g = r.row_group[i0] as usize;
        let mut p = 0;
        for k in r.ptr[g]..r.ptr[g + 1] {
            let c = r.start[k];
            for t in 0..r.len[k] as usize {
                f(c + t as u32, std::array::from_fn(|q| rows[q][p + t].get()));
            }
            p += r.len[k] as usize;
        }
    }

    /// Number of rows from `i` on (at most `max`, all before `end`) in the group of row
    /// `i`; 1 for a matrix with column indices.
    #[inline]
    pub(crate) fn group_run(&self, i: usize, end: usize, max: usize) -> usize {
        let Some(r) = &self.runs else {
            return 1;
        };
        let g = r.row_group[i];
        let mut m = 1;
        while m < max && i + m < end && r.row_group[i + m] == g {
            m += 1;
        }
        m
    }

    /// For a matrix stored as runs: the group of row `i` (`None` for a matrix with column
    /// indices).
    #[inline]
    pub(crate) fn row_group(&self, i: usize) -> Option<u32> {
        self.runs.as_ref().map(|r| r.row_group[i])
    }

    /// For a matrix stored as runs: the runs `(first column, length)` of row `i`'s
    /// columns, in order (`None` for a matrix with column indices).
    #[inline]
    pub(crate) fn row_runs(&self, i: usize) -> Option<impl Iterator<Item = (usize, usize)> + '_> {
        let r = self.runs.as_ref()?;
        let g = r.row_group[i] as usize;
        let k = r.ptr[g]..r.ptr[g + 1];
        let runs = r.start[k.clone()].iter().zip(&r.len[k]);
        Some(runs.map(|(&s, &l)| (s as usize, l as usize)))
    }

    /// `f(column)` for the first `m` entries of row `i` (columns increasing).
    #[inline]
    pub(crate) fn for_each_col_prefix(&self, i: usize, m: usize, mut f: impl FnMut(u32)) {
        match &self.runs {
            Some(r) => {
                let g = r.row_group[i] as usize;
                let mut left = m;
                for k in r.ptr[g]..r.ptr[g + 1] {
                    if left == 0 {
                        break;
                    }
                    let l = (r.len[k] as usize).min(left);
                    (r.start[k]..r.start[k] + l as u32).for_each(&mut f);
                    left -= l;
                }
            }
            None => {
                let p0 = self.row_ptr[i];
                self.col[p0..p0 + m].iter().for_each(|&c| f(c));
            }
        }
    }

    /// `f(column)` for the entries of row `i`, increasing.
    #[inline]
    pub fn for_each_col(&self, i: usize, mut f: impl FnMut(u32)) {
        match &self.runs {
            Some(r) => {
                let g = r.row_group[i] as usize;
                for k in r.ptr[g]..r.ptr[g + 1] {
                    (r.start[k]..r.start[k] + r.len[k]).for_each(&mut f);
                }
            }
            None => self.col[self.row_ptr[i]..self.row_ptr[i + 1]]
                .iter()
                .for_each(|&c| f(c)),
        }
    }

    /// Position within row `i` of column `c`, if stored.
    #[inline]
    pub(crate) fn find_in_row(&self, i: usize, c: u32) -> Option<usize> {
        match &self.runs {
            Some(r) => {
                let g = r.row_group[i] as usize;
                let mut at = 0;
                for k in r.ptr[g]..r.ptr[g + 1] {
                    let (s, l) = (r.start[k], r.len[k]);
                    if c < s {
                        return None;
                    }
                    if c < s + l {
                        return Some(at + (c - s) as usize);
                    }
                    at += l as usize;
                }
                None
            }
            None => self.col[self.row_ptr[i]..self.row_ptr[i + 1]]
                .binary_search(&c)
                .ok(),
        }
    }

    /// `(A x)_i` of a matrix stored with column indices (those stored as runs are
    /// multiplied by row groups, [`Self::rows_times`]), with four partial sums (the
    /// products are independent, so they need not wait for each other's additions).
    #[inline]
    fn row_dot<T: Value>(&self, val: &[T], i: usize, x: &[f64]) -> f64 {
        let mut acc = [0.0f64; 4];
        let r = self.row_ptr[i]..self.row_ptr[i + 1];
        let (cols, vals) = (&self.col[r.clone()], &val[r]);
        let mut vc = vals.chunks_exact(4);
        let mut cc = cols.chunks_exact(4);
        for (v, c) in (&mut vc).zip(&mut cc) {
            for t in 0..4 {
                acc[t] += v[t].get() * x[c[t] as usize];
            }
        }
        for (v, &c) in vc.remainder().iter().zip(cc.remainder()) {
            acc[0] += v.get() * x[c as usize];
        }
        (acc[0] + acc[1]) + (acc[2] + acc[3])
    }

    /// `f(i, (A x)_i)` for the rows `rows`, in order. Rows of a group (same columns,
    /// consecutive) are computed together: each piece of `x` is read once for all of them.
    #[inline]
    pub(crate) fn rows_times(
        &self,
        rows: std::ops::Range<usize>,
        x: &[f64],
        f: impl FnMut(usize, f64),
    ) {
        with_values!(&self.val, v => self.rows_times_of(v, rows, x, f))
    }

    #[inline(always)]
    fn rows_times_of<T: Value>(
        &self,
        val: &[T],
        rows: std::ops::Range<usize>,
        x: &[f64],
        mut f: impl FnMut(usize, f64),
    ) {
        let Some(r) = &self.runs else {
            for i in rows {
                f(i, self.row_dot(val, i, x));
            }
            return;
        };
        let mut i = rows.start;
        while i < rows.end {
            let g = r.row_group[i];
            let mut m = 1;
            while i + m < rows.end && m < 6 && r.row_group[i + m] == g {
                m += 1;
            }
            let runs = r.ptr[g as usize]..r.ptr[g as usize + 1];
            match m {
                1 => group_dot::<1, T>(self, val, r, runs, i, x, &mut f),
                2 => group_dot::<2, T>(self, val, r, runs, i, x, &mut f),
                3 => group_dot::<3, T>(self, val, r, runs, i, x, &mut f),
                4 => group_dot::<4, T>(self, val, r, runs, i, x, &mut f),
                5 => group_dot::<5, T>(self, val, r, runs, i, x, &mut f),
                _ => group_dot::<6, T>(self, val, r, runs, i, x, &mut f),
            }
            i += m;
        }
    }

    /// The diagonal (0 where no entry is stored).
    pub fn diagonal(&self) -> Vec<f64> {
        let mut d = zeros(self.nrows);
        par_rows(&mut d, |i, di| {
            if let Some(k) = self.find_in_row(i, i as u32) {
                *di = self.value_at(self.row_ptr[i] + k);
            }
        });
        d
    }

    /// `y = A x` (in parallel).
    pub fn mul(&self, x: &[f64], y: &mut [f64]) -> Result<()> {
        if x.len() != self.ncols || y.len() != self.nrows {
            return Err(AmgError::Input(format!(
                "product of a {}×{} matrix with a vector of length {} into one of length {}",
                self.nrows,
                self.ncols,
                x.len(),
                y.len()
            )));
        }
        self.spmv(x, y);
        Ok(())
    }

    /// `y = A x` without size checks.
    pub(crate) fn spmv(&self, x: &[f64], y: &mut [f64]) {
        self.par_products(x, y, |_, ax, yi| *yi = ax);
    }

    /// `f(i, (A x)_i, &mut y[i])` for every row, in parallel blocks of rows.
    pub(crate) fn par_products<F>(&self, x: &[f64], y: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64) + Sync + Send,
    {
        y.par_chunks_mut(ROWS_PER_TASK)
            .enumerate()
            .for_each(|(b, ys)| {
                let base = b * ROWS_PER_TASK;
                self.rows_times(base..base + ys.len(), x, |i, ax| {
                    f(i, ax, &mut ys[i - base])
                });
            });
    }

    /// `Σ_i f(i, (A x)_i, &mut y[i])` over every row, in parallel blocks of rows: a
    /// product and a reduction in one pass. The block sums are added in block order, so
    /// the result does not depend on the number of threads.
    pub(crate) fn par_products_sum<F>(&self, x: &[f64], y: &mut [f64], f: F) -> f64
    where
        F: Fn(usize, f64, &mut f64) -> f64 + Sync + Send,
    {
        par_block_sums(y, |base, ys| {
            let mut sum = 0.0;
            self.rows_times(base..base + ys.len(), x, |i, ax| {
                sum += f(i, ax, &mut ys[i - base]);
            });
            sum
        })
    }

    /// `f(i, (A x)_i, &mut y[i], &mut z[i])` for every row, in parallel blocks.
    pub(crate) fn par_products2<F>(&self, x: &[f64], y: &mut [f64], z: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64, &mut f64) + Sync + Send,
    {
        y.par_chunks_mut(ROWS_PER_TASK)
            .zip(z.par_chunks_mut(ROWS_PER_TASK))
            .enumerate()
            .for_each(|(b, (ys, zs))| {
                let base = b * ROWS_PER_TASK;
                self.rows_times(base..base + ys.len(), x, |i, ax| {
                    let k = i - base;
                    f(i, ax, &mut ys[k], &mut zs[k])
                });
            });
    }

    /// `f(i, (A x)_i, &mut y[i], &mut z[i], &mut w[i])` for every row, in parallel blocks.
    pub(crate) fn par_products3<F>(
        &self,
        x: &[f64],
        y: &mut [f64],
        z: &mut [f64],
        w: &mut [f64],
        f: F,
    ) where
        F: Fn(usize, f64, &mut f64, &mut f64, &mut f64) + Sync + Send,
    {
        y.par_chunks_mut(ROWS_PER_TASK)
            .zip(z.par_chunks_mut(ROWS_PER_TASK))
            .zip(w.par_chunks_mut(ROWS_PER_TASK))
            .enumerate()
            .for_each(|(b, ((ys, zs), ws))| {
                let base = b * ROWS_PER_TASK;
                self.rows_times(base..base + ys.len(), x, |i, ax| {
                    let k = i - base;
                    f(i, ax, &mut ys[k], &mut zs[k], &mut ws[k])
                });
            });
    }

    /// For a matrix in single precision laid out as [`SymCsr`] with the column offsets
    /// `col_ptr`: its upper triangle into `out` (column `i` is the first `col_ptr[i+1] −
    /// col_ptr[i]` entries of row `i`), in parallel; false (and `out` untouched) for one
    /// in double precision.
    pub(crate) fn upper_single(&self, col_ptr: &[usize], out: &mut Vec<f32>) -> bool {
        let Values::Single(v) = &self.val else {
            return false;
        };
        let n = self.nrows;
        out.resize(col_ptr[n], 0.0);
        let bounds = block_bounds(n, ROWS_PER_TASK * 8);
        let parts = split_by_items(out, &bounds, |i| col_ptr[i]);
        parts.into_par_iter().for_each(|(first, part)| {
            let mut at = 0;
            let mut i = first;
            while at < part.len() {
                let len = col_ptr[i + 1] - col_ptr[i];
                let p0 = self.row_ptr[i];
                part[at..at + len].copy_from_slice(&v[p0..p0 + len]);
                at += len;
                i += 1;
            }
        });
        true
    }

    /// The transpose, and for each of its entries the position of the same entry in `self`.
    #[cfg(test)]
    pub(crate) fn transpose_with_map(&self) -> (CsrMatrix, Vec<usize>) {
        let cols = self.col_idx();
        let mut count = vec![0usize; self.ncols + 1];
        for &c in &cols {
            count[c as usize + 1] += 1;
        }
        for j in 0..self.ncols {
            count[j + 1] += count[j];
        }
        let row_ptr = count.clone();
        let mut next = count;
        let nnz = self.nnz();
        let mut col = vec![0u32; nnz];
        let mut map = vec![0usize; nnz];
        for i in 0..self.nrows {
            for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                let j = cols[k] as usize;
                col[next[j]] = i as u32;
                map[next[j]] = k;
                next[j] += 1;
            }
        }
        let mut t = CsrMatrix::from_parts(self.ncols, self.nrows, row_ptr, col, vec![0.0; nnz]);
        t.gather_from(self.values(), &map);
        (t, map)
    }

    /// `val[k] = src[map[k]]` for every stored entry (in parallel).
    #[cfg(test)]
    pub(crate) fn gather_from(&mut self, src: &[f64], map: &[usize]) {
        self.values_mut()
            .par_chunks_mut(VEC_BLOCK)
            .zip(map.par_chunks(VEC_BLOCK))
            .for_each(|(v, m)| {
                for (vk, &mk) in v.iter_mut().zip(m) {
                    *vk = src[mk];
                }
            });
    }
}

/// `(A x)_i` for the `M` rows `i0..i0 + M` of one group (same column runs `runs`), passed
/// to `f`; each row sums in two lanes (even and odd positions).
#[inline(always)]
fn group_dot<const M: usize, T: Value>(
    a: &CsrMatrix,
    val: &[T],
    r: &Runs,
    runs: std::ops::Range<usize>,
    i0: usize,
    x: &[f64],
    f: &mut impl FnMut(usize, f64),
) {
    let base = a.row_ptr[i0];
    let len = a.row_ptr[i0 + 1] - base;
    prefetch_ahead(val, base);
    let vals: [&[T]; M] = std::array::from_fn(|q| &val[base + q * len..base + (q + 1) * len]);
    let mut acc = [[0.0f64; 2]; M];
    let mut p = 0;
    for k in runs {
        let c = r.start[k] as usize;
        let l = r.len[k] as usize;
        let xs = &x[c..c + l];
        for q in 0..M {
            let v = &vals[q][p..p + l];
            let mut t = 0;
            while t + 1 < l {
                acc[q][0] += v[t].get() * xs[t];
                acc[q][1] += v[t + 1].get() * xs[t + 1];
                t += 2;
            }
            if t < l {
                acc[q][0] += v[t].get() * xs[t];
            }
        }
        p += l;
    }
    for q in 0..M {
        f(i0 + q, acc[q][0] + acc[q][1]);
    }
}

/// How far ahead of the current position the row kernels ask the cache for values.
const PREFETCH_BYTES: usize = 2048;

/// Hint the cache to load the line [`PREFETCH_BYTES`] after `v[at]`; nothing when that is
/// past the end or off x86-64.
///
/// The row kernels ([`group_dot`], [`CsrMatrix::for_each_in_row`], the upper-triangle
/// product of [`crate::upper`]) read the values in order, but do enough work per value
/// (conversion, column runs, two rows at once) that the hardware prefetcher alone leaves
/// a thread waiting on memory: at E2 n = 1000 the single-precision product took 18.4 ms
/// on one thread and 9.7–10.0 ms on two. Asking for the line 2 kB ahead, once per row
/// group, took it to 8.1–8.3 ms, the upper-triangle product from 12.5–13.0 to 12.2 ms and
/// the strength pass from 0.13–0.16 s to 0.10–0.11 s (docs/BENCHMARKS.md).
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn prefetch_ahead<T>(v: &[T], at: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some(p) = v.get(at + PREFETCH_BYTES / std::mem::size_of::<T>().max(1)) {
        // SAFETY: `_mm_prefetch` (SSE, part of the x86-64 baseline) only hints the cache;
        // it never faults and its load is not visible to the program. The address is that
        // of an element of `v`.
        unsafe {
            std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
                (p as *const T).cast::<i8>(),
            )
        };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (v, at);
}

/// Run `f(i, &mut y[i])` for every row, in parallel blocks of rows.
#[inline]
pub(crate) fn par_rows<F>(y: &mut [f64], f: F)
where
    F: Fn(usize, &mut f64) + Sync + Send,
{
    y.par_chunks_mut(ROWS_PER_TASK)
        .enumerate()
        .for_each(|(b, ys)| {
            let base = b * ROWS_PER_TASK;
            for (k, yi) in ys.iter_mut().enumerate() {
                f(base + k, yi);
            }
        });
}

/// `Σ_i f(i, &mut y[i])` over every row, in parallel blocks of rows; the block sums are
/// added in block order (independent of the number of threads).
pub(crate) fn par_rows_sum<F>(y: &mut [f64], f: F) -> f64
where
    F: Fn(usize, &mut f64) -> f64 + Sync + Send,
{
    par_block_sums(y, |base, ys| {
        let mut sum = 0.0;
        for (k, yi) in ys.iter_mut().enumerate() {
            sum += f(base + k, yi);
        }
        sum
    })
}

/// `Σ_b g(first row of b, y[b])` over the blocks `b` of [`ROWS_PER_TASK`] rows of `y`, in
/// parallel; the block sums are added in block order, so the result does not depend on
/// the number of threads.
fn par_block_sums<G>(y: &mut [f64], g: G) -> f64
where
    G: Fn(usize, &mut [f64]) -> f64 + Sync + Send,
{
    let parts: Vec<f64> = y
        .par_chunks_mut(ROWS_PER_TASK)
        .enumerate()
        .map(|(b, ys)| g(b * ROWS_PER_TASK, ys))
        .collect();
    parts.iter().sum()
}

/// A symmetric matrix given by its upper triangle in compressed sparse column form,
/// expanded once to a full [`CsrMatrix`].
///
/// No map from the full entries to the upper-triangle values is stored: the lower part
/// and diagonal of full row `i` (its first entries) are column `i` of the upper triangle,
/// starting at `col_ptr[i]`, and an entry `(i, c)` with `c > i` is the entry of row `i` in
/// column `c`, that is at the rank of `i` in full row `c`'s lower part (a binary search
/// of a few indices). Only the column offsets are kept.
#[derive(Clone, Debug)]
pub struct SymCsr {
    full: CsrMatrix,
    /// Column offsets of the upper triangle (length `n + 1`).
    col_ptr: Vec<usize>,
}

impl SymCsr {
    /// Build from the upper triangle (`row ≤ column`) in CSC form: column `c` holds rows
    /// `row_idx[col_ptr[c]..col_ptr[c+1]]`, strictly increasing, with `values` alongside.
    ///
    /// Errors: inconsistent lengths, a row index below the diagonal or out of range,
    /// unsorted or repeated rows, more than `u32::MAX − 1` equations or entries, non-finite
    /// values.
    pub fn from_upper_csc(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
    ) -> Result<Self> {
        Self::from_upper_csc_in(Precision::Double, n, col_ptr, row_idx, values)
    }

    /// [`Self::from_upper_csc`] with the full matrix's values stored in `precision`.
    pub fn from_upper_csc_in(
        precision: Precision,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
    ) -> Result<Self> {
        validate_upper_csc(n, col_ptr, row_idx, values)?;
        // Full row i = column i of the upper triangle (columns r ≤ i, diagonal last) followed
        // by the columns c > i whose upper column holds row i — a transpose. One pass counts
        // the entries of each row and the last column holding it; the rows are then written
        // in parallel, values with their columns ([`UpperCsc::expand_rows`]).
        let mut upper_count = vec![0u32; n];
        let mut last_col: Vec<u32> = (0..n as u32).collect();
        for c in 0..n {
            for &r in &row_idx[col_ptr[c]..col_ptr[c + 1]] {
                if r != c {
                    upper_count[r] += 1;
                    last_col[r] = c as u32;
                }
            }
        }
        let mut row_ptr = Vec::with_capacity(n + 1);
        row_ptr.push(0usize);
        for i in 0..n {
            row_ptr.push(row_ptr[i] + col_ptr[i + 1] - col_ptr[i] + upper_count[i] as usize);
        }
        drop(upper_count);
        let nnz = row_ptr[n];
        let mut col = vec![0u32; nnz];
        let mut val = match precision {
            Precision::Double => Values::Double(zeros_of(nnz)),
            Precision::Single => Values::Single(zeros_of(nnz)),
        };
        let upper = UpperCsc {
            col_ptr,
            row_idx,
            values,
        };
        with_values!(&mut val, v => upper.expand_rows(&row_ptr, &last_col, &mut col, v));
        let mut full = CsrMatrix::from_parts(n, n, row_ptr, col, Vec::new());
        full.val = val;
        full.compress_runs();
        Ok(Self {
            full,
            col_ptr: col_ptr.to_vec(),
        })
    }

    /// Number of equations.
    pub fn n(&self) -> usize {
        self.full.nrows
    }
    /// Number of upper-triangle entries this matrix was built from.
    pub fn upper_nnz(&self) -> usize {
        self.col_ptr[self.n()]
    }
    /// The full matrix.
    pub fn matrix(&self) -> &CsrMatrix {
        &self.full
    }

    /// New upper-triangle values on the same pattern. Errors: wrong length, non-finite.
    pub fn set_values(&mut self, values: &[f64]) -> Result<()> {
        check_upper_values(values, self.upper_nnz())?;
        self.fill(values);
        Ok(())
    }

    fn fill(&mut self, values: &[f64]) {
        fill_from_upper(&mut self.full, &self.col_ptr, values);
    }

    /// `y = A x` (in parallel).
    pub fn mul(&self, x: &[f64], y: &mut [f64]) -> Result<()> {
        self.full.mul(x, y)
    }

    pub(crate) fn into_parts(self) -> (CsrMatrix, Vec<usize>) {
        (self.full, self.col_ptr)
    }
}

/// The upper triangle in CSC form, as given to [`SymCsr::from_upper_csc`].
struct UpperCsc<'a> {
    col_ptr: &'a [usize],
    row_idx: &'a [usize],
    values: &'a [f64],
}

impl UpperCsc<'_> {
    /// Column indices and values of the full rows laid out by `row_ptr`. The rows are
    /// split into parts, one task each; every task scans the columns from its first row to
    /// the last column holding one of its rows (`last_col`; a band for equations numbered
    /// by node), keeping the entries of its own rows: each row comes out sorted and each
    /// task writes only its own slices.
    fn expand_rows<T: Value>(
        &self,
        row_ptr: &[usize],
        last_col: &[u32],
        col: &mut [u32],
        val: &mut [T],
    ) {
        let (col_ptr, row_idx, values) = (self.col_ptr, self.row_idx, self.values);
        let n = row_ptr.len() - 1;
        let parts = (4 * rayon::current_num_threads()).clamp(1, n.max(1));
        let bounds: Vec<usize> = (0..=parts).map(|k| n * k / parts).collect();
        let row_start = |i: usize| row_ptr[i];
        let slices: Vec<_> = split_by_items(col, &bounds, row_start)
            .into_iter()
            .zip(split_by_items(val, &bounds, row_start))
            .collect();
        slices
            .into_par_iter()
            .enumerate()
            .for_each(|(k, ((_, col), (_, val)))| {
                let rows = bounds[k]..bounds[k + 1];
                let base = row_ptr[rows.start];
                // Lower part and diagonal (column i of the upper triangle), and the write
                // cursor of each row's upper part.
                let mut next = Vec::with_capacity(rows.len());
                for i in rows.clone() {
                    let at = row_ptr[i] - base;
                    let span = col_ptr[i]..col_ptr[i + 1];
                    for (q, &r) in row_idx[span.clone()].iter().enumerate() {
                        col[at + q] = r as u32;
                        val[at + q] = T::from_f64(values[span.start + q]);
                    }
                    next.push(at + span.len());
                }
                let end = rows
                    .clone()
                    .map(|r| last_col[r] as usize + 1)
                    .max()
                    .unwrap_or(0);
                for c in rows.start..end {
                    for p in col_ptr[c]..col_ptr[c + 1] {
                        let r = row_idx[p];
                        if r != c && rows.contains(&r) {
                            let at = &mut next[r - rows.start];
                            col[*at] = c as u32;
                            val[*at] = T::from_f64(values[p]);
                            *at += 1;
                        }
                    }
                }
            });
    }
}

/// `v` cut into the slices of the consecutive item ranges `bounds[k]..bounds[k + 1]`, item
/// `i` starting at `offset(i)` (counted from `offset(bounds[0])`), each with the first item
/// of its range: the parts of a parallel pass that writes only its own slice.
pub(crate) fn split_by_items<'a, T>(
    mut v: &'a mut [T],
    bounds: &[usize],
    offset: impl Fn(usize) -> usize,
) -> Vec<(usize, &'a mut [T])> {
    let mut out = Vec::with_capacity(bounds.len().saturating_sub(1));
    for w in bounds.windows(2) {
        let (head, tail) = std::mem::take(&mut v).split_at_mut(offset(w[1]) - offset(w[0]));
        out.push((w[0], head));
        v = tail;
    }
    out
}

/// `0, size, 2·size, …, n`: the bounds of consecutive blocks of at most `size` items.
pub(crate) fn block_bounds(n: usize, size: usize) -> Vec<usize> {
    (0..n).step_by(size).chain(std::iter::once(n)).collect()
}

/// Error unless `values` has `upper_nnz` finite entries.
pub(crate) fn check_upper_values(values: &[f64], upper_nnz: usize) -> Result<()> {
    if values.len() != upper_nnz {
        return Err(AmgError::Input(format!(
            "{} values for a pattern of {upper_nnz} entries",
            values.len(),
        )));
    }
    check_finite(values, "matrix value")
}

/// Position in the upper-triangle values of every entry of full row `i` (see [`SymCsr`]),
/// passed to `f(k, position)` with `k` the entry's index within the row.
#[inline]
fn upper_positions(full: &CsrMatrix, col_ptr: &[usize], i: usize, mut f: impl FnMut(usize, usize)) {
    let m = col_ptr[i + 1] - col_ptr[i];
    let mut k = 0;
    full.for_each_col(i, |c| {
        let c = c as usize;
        if k < m {
            f(k, col_ptr[i] + k);
        } else {
            // Invariant: the pattern is symmetric, so row i is in (the lower part of) row c.
            let t = full.find_in_row(c, i as u32).unwrap_or(0);
            f(k, col_ptr[c] + t);
        }
        k += 1;
    });
}

/// Set the values of the full matrix `full` from the upper-triangle `values` laid out by
/// `col_ptr` (in parallel over rows).
/// Values are rounded to the matrix's storage precision.
pub(crate) fn fill_from_upper(full: &mut CsrMatrix, col_ptr: &[usize], values: &[f64]) {
    let mut val = std::mem::take(&mut full.val);
    with_values!(&mut val, v => fill_rows(full, v, col_ptr, values));
    full.val = val;
}

fn fill_rows<T: Value>(f: &CsrMatrix, val: &mut [T], col_ptr: &[usize], values: &[f64]) {
    let row_ptr = &f.row_ptr;
    let n = f.nrows;
    let slices = split_by_items(val, &block_bounds(n, ROWS_PER_TASK), |i| row_ptr[i]);
    slices.into_par_iter().for_each(|(start, out)| {
        let base = row_ptr[start];
        for i in start..(start + ROWS_PER_TASK).min(n) {
            let at = row_ptr[i] - base;
            upper_positions(f, col_ptr, i, |k, p| out[at + k] = T::from_f64(values[p]));
        }
    });
}

/// Whether the full matrix `full` holds the upper-triangle `values` laid out by `col_ptr`,
/// rounded to its storage precision (exactly so for double precision; in parallel over
/// rows).
pub(crate) fn equals_upper(full: &CsrMatrix, col_ptr: &[usize], values: &[f64]) -> bool {
    if values.len() != col_ptr[full.nrows] {
        return false;
    }
    with_values!(&full.val, val => (0..full.nrows)
    .into_par_iter()
    .with_min_len(ROWS_PER_TASK)
    .all(|i| {
        let vals = &val[full.row_ptr[i]..full.row_ptr[i + 1]];
        let mut same = true;
        upper_positions(full, col_ptr, i, |k, p| {
            same &= vals[k] == Value::from_f64(values[p])
        });
        same
    }))
}

/// Check the upper-triangle CSC arrays.
fn validate_upper_csc(
    n: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
    values: &[f64],
) -> Result<()> {
    if n >= u32::MAX as usize {
        return Err(AmgError::Input(format!(
            "{n} equations exceed the 32-bit indices"
        )));
    }
    if col_ptr.len() != n + 1 {
        return Err(AmgError::Input(format!(
            "column offsets of length {} for {n} columns (want {})",
            col_ptr.len(),
            n + 1
        )));
    }
    if col_ptr[0] != 0 || col_ptr[n] != row_idx.len() || row_idx.len() != values.len() {
        return Err(AmgError::Input(format!(
            "column offsets run from {} to {}, with {} row indices and {} values",
            col_ptr[0],
            col_ptr[n],
            row_idx.len(),
            values.len()
        )));
    }
    if 2 * row_idx.len() >= u32::MAX as usize {
        return Err(AmgError::Input(format!(
            "{} entries exceed the 32-bit indices",
            row_idx.len()
        )));
    }
    for c in 0..n {
        if col_ptr[c] > col_ptr[c + 1] {
            return Err(AmgError::Input(format!(
                "column offsets decrease at column {c}"
            )));
        }
        let rows = &row_idx[col_ptr[c]..col_ptr[c + 1]];
        for (k, &r) in rows.iter().enumerate() {
            if r > c {
                return Err(AmgError::Input(format!(
                    "entry ({r}, {c}) is below the diagonal: give the upper triangle"
                )));
            }
            if k > 0 && rows[k - 1] >= r {
                return Err(AmgError::Input(format!(
                    "rows of column {c} are not strictly increasing"
                )));
            }
        }
    }
    check_finite(values, "matrix value")
}

/// Deterministic parallel dot product `aᵀ b`.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let parts: Vec<f64> = a
        .par_chunks(VEC_BLOCK)
        .zip(b.par_chunks(VEC_BLOCK))
        .map(|(x, y)| block_dot(x, y))
        .collect();
    parts.iter().sum()
}

/// A vector of `n` zeros, written here in the calling thread.
///
/// `vec![0.0; n]` maps fresh zero pages that are faulted in where they are first
/// written; inside a parallel kernel that writes a new output those page faults come
/// from several threads at once and contend. Large outputs of parallel kernels are
/// allocated with this function instead, which takes the faults here, in one thread.
pub(crate) fn zeros(n: usize) -> Vec<f64> {
    zeros_of(n)
}

/// [`zeros`] of either value type.
fn zeros_of<T: Value>(n: usize) -> Vec<T> {
    // Zero floats come from the allocator's zeroed pages: no serial pass writing them.
    vec![T::default(); n]
}

/// Dot product of two short slices with four partial sums.
#[inline]
fn block_dot(x: &[f64], y: &[f64]) -> f64 {
    let mut s = [0.0f64; 4];
    let mut xc = x.chunks_exact(4);
    let mut yc = y.chunks_exact(4);
    for (xa, ya) in (&mut xc).zip(&mut yc) {
        for k in 0..4 {
            s[k] += xa[k] * ya[k];
        }
    }
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for (a, b) in xc.remainder().iter().zip(yc.remainder()) {
        t += a * b;
    }
    t
}

/// Euclidean norm.
pub(crate) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// `Σ_i f(i, &mut a[i], &mut b[i])` in parallel blocks; the block sums are added in block
/// order (independent of the number of threads).
pub(crate) fn par_zip2_sum<F>(a: &mut [f64], b: &mut [f64], f: F) -> f64
where
    F: Fn(usize, &mut f64, &mut f64) -> f64 + Sync + Send,
{
    let parts: Vec<f64> = a
        .par_chunks_mut(ROWS_PER_TASK)
        .zip(b.par_chunks_mut(ROWS_PER_TASK))
        .enumerate()
        .map(|(blk, (xa, xb))| {
            let base = blk * ROWS_PER_TASK;
            let mut sum = 0.0;
            for (k, (ai, bi)) in xa.iter_mut().zip(xb.iter_mut()).enumerate() {
                sum += f(base + k, ai, bi);
            }
            sum
        })
        .collect();
    parts.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The upper triangle of [[4, 1, 0], [1, 5, 2], [0, 2, 6]].
    fn small() -> SymCsr {
        SymCsr::from_upper_csc(
            3,
            &[0, 1, 3, 5],
            &[0, 0, 1, 1, 2],
            &[4.0, 1.0, 5.0, 2.0, 6.0],
        )
        .unwrap()
    }

    #[test]
    fn run_table_over_many_parts_keeps_every_row_and_group() {
        // Nodes of 3 equations coupled at node distances 0, 1 and 7: 150 000 rows, the
        // parallel parts of 65 536 rows would cut node groups without the bound shift.
        let (nodes, k) = (50_000, 3);
        let (mut cp, mut ri, mut v) = (vec![0], vec![], vec![]);
        for c in 0..nodes * k {
            let node = c / k;
            for d in [7, 1, 0] {
                if d <= node {
                    for r in (node - d) * k..((node - d) * k + k).min(c + 1) {
                        ri.push(r);
                        v.push(if r == c { 20.0 } else { -1.0 });
                    }
                }
            }
            cp.push(ri.len());
        }
        let a = SymCsr::from_upper_csc(nodes * k, &cp, &ri, &v).unwrap();
        let m = a.matrix();
        assert!(m.runs.is_some());
        let rows: Vec<Vec<u32>> = (0..m.nrows())
            .map(|i| {
                let mut c = vec![];
                m.for_each_col(i, |j| c.push(j));
                c
            })
            .collect();
        for (i, cols) in rows.iter().enumerate() {
            let node = i / k;
            let mut want = vec![];
            for nb in [
                node.wrapping_sub(7),
                node.wrapping_sub(1),
                node,
                node + 1,
                node + 7,
            ] {
                if nb < nodes {
                    want.extend((nb * k) as u32..(nb * k + k) as u32);
                }
            }
            assert_eq!(cols, &want, "row {i}");
            if i > 0 {
                let same_group = m.row_group(i).unwrap() == m.row_group(i - 1).unwrap();
                assert_eq!(same_group, rows[i - 1] == *cols, "row {i}");
            }
        }
    }

    #[test]
    fn expands_the_upper_triangle() {
        let a = small();
        let m = a.matrix();
        assert_eq!(m.row_ptr(), &[0, 2, 5, 7]);
        assert_eq!(m.col_idx(), vec![0, 1, 0, 1, 2, 1, 2]);
        assert_eq!(m.values(), &[4.0, 1.0, 1.0, 5.0, 2.0, 2.0, 6.0]);
        let mut y = vec![0.0; 3];
        a.mul(&[1.0, 2.0, 3.0], &mut y).unwrap();
        assert_eq!(y, vec![6.0, 17.0, 22.0]);
        // The same with the pattern stored as runs.
        let mut m = m.clone();
        m.runs = Some(m.runs_of());
        assert_eq!(m.runs.as_ref().map(|r| r.start.len()), Some(3));
        m.mul(&[1.0, 2.0, 3.0], &mut y).unwrap();
        assert_eq!(y, vec![6.0, 17.0, 22.0]);
        assert_eq!(m.diagonal(), vec![4.0, 5.0, 6.0]);
    }

    #[test]
    fn expansion_of_an_irregular_band_matches_the_dense_matrix() {
        // Upper entries (r, c) at distances 0, 1, 3 and 17, some left out; values from the
        // position so that every entry differs.
        let n = 60;
        let (mut col_ptr, mut rows, mut vals) = (vec![0], vec![], vec![]);
        for c in 0..n {
            for d in [17, 3, 1, 0] {
                if d <= c && (d == 0 || (c * 7 + d) % 5 != 1) {
                    rows.push(c - d);
                    vals.push(1.0 + (rows.len() as f64).sqrt());
                }
            }
            col_ptr.push(rows.len());
        }
        let mut dense = vec![vec![0.0; n]; n];
        for c in 0..n {
            for p in col_ptr[c]..col_ptr[c + 1] {
                dense[rows[p]][c] = vals[p];
                dense[c][rows[p]] = vals[p];
            }
        }
        let mut a = SymCsr::from_upper_csc(n, &col_ptr, &rows, &vals).unwrap();
        let check = |a: &SymCsr, dense: &[Vec<f64>]| {
            let m = a.matrix();
            for (i, row) in dense.iter().enumerate() {
                let mut got: Vec<(usize, f64)> = Vec::new();
                m.for_each_in_row(i, |j, x| got.push((j as usize, x)));
                assert!(got.windows(2).all(|w| w[0].0 < w[1].0), "row {i} sorted");
                let want: Vec<(usize, f64)> = row
                    .iter()
                    .enumerate()
                    .filter(|(_, x)| **x != 0.0)
                    .map(|(j, &x)| (j, x))
                    .collect();
                assert_eq!(got, want, "row {i}");
            }
        };
        check(&a, &dense);
        assert!(equals_upper(a.matrix(), &col_ptr, &vals));
        // New values: the expansion follows, and the old ones no longer match.
        let new: Vec<f64> = vals.iter().map(|v| 2.0 * v + 1.0).collect();
        a.set_values(&new).unwrap();
        for row in dense.iter_mut() {
            for x in row.iter_mut().filter(|x| **x != 0.0) {
                *x = 2.0 * *x + 1.0;
            }
        }
        check(&a, &dense);
        assert!(equals_upper(a.matrix(), &col_ptr, &new));
        assert!(!equals_upper(a.matrix(), &col_ptr, &vals));
        let mut one_off = new.clone();
        one_off[rows.len() / 2] += 1e-12;
        assert!(!equals_upper(a.matrix(), &col_ptr, &one_off));
    }

    #[test]
    fn group_products_match_row_by_row_products() {
        // Nodes of 1–7 equations coupled to nodes k ± 1 and k ± 5: the rows of a node form
        // one group (sizes 1–7; 7 is computed as 6 + 1), and the 512-row blocks of the
        // parallel kernels cut groups.
        let sizes: Vec<usize> = (0..900).map(|k| 1 + k % 7).collect();
        let first: Vec<usize> = sizes
            .iter()
            .scan(0, |s, &m| {
                *s += m;
                Some(*s - m)
            })
            .collect();
        let n: usize = sizes.iter().sum();
        let node: Vec<usize> = (0..sizes.len())
            .flat_map(|k| std::iter::repeat_n(k, sizes[k]))
            .collect();
        let (mut col_ptr, mut rows, mut vals) = (vec![0], vec![], vec![]);
        for c in 0..n {
            let kc = node[c];
            for kr in kc.saturating_sub(5)..=kc {
                if kr + 5 == kc || kr + 1 >= kc {
                    for r in first[kr]..(first[kr] + sizes[kr]).min(c + 1) {
                        rows.push(r);
                        vals.push(if r == c {
                            40.0
                        } else {
                            1.0 / (1.0 + (r + 2 * c) as f64)
                        });
                    }
                }
            }
            col_ptr.push(rows.len());
        }
        let a = SymCsr::from_upper_csc(n, &col_ptr, &rows, &vals).unwrap();
        assert!(a.matrix().runs.is_some(), "stored as runs");
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut y = vec![0.0; n];
        a.mul(&x, &mut y).unwrap();
        let mut plain = a.matrix().clone();
        plain.runs = None;
        plain.col = a.matrix().col_idx();
        for i in 0..n {
            let want = plain.row_dot(plain.values(), i, &x);
            assert!(
                (y[i] - want).abs() <= 1e-14 * want.abs().max(1.0),
                "row {i}: {} vs {want}",
                y[i]
            );
        }
    }

    #[test]
    fn new_values_on_the_same_pattern() {
        let mut a = small();
        a.set_values(&[1.0, 2.0, 3.0, 4.0, 5.0]).unwrap();
        assert_eq!(a.matrix().values(), &[1.0, 2.0, 2.0, 3.0, 4.0, 4.0, 5.0]);
        assert!(matches!(a.set_values(&[1.0; 4]), Err(AmgError::Input(_))));
        assert_eq!(
            a.set_values(&[1.0, f64::NAN, 3.0, 4.0, 5.0]),
            Err(AmgError::NotFinite {
                what: "matrix value",
                index: 1
            })
        );
    }

    #[test]
    fn rejects_bad_patterns() {
        // Lower-triangle entry.
        assert!(SymCsr::from_upper_csc(2, &[0, 2, 3], &[0, 1, 1], &[1.0; 3]).is_err());
        // Unsorted rows.
        assert!(SymCsr::from_upper_csc(2, &[0, 1, 3], &[0, 1, 0], &[1.0; 3]).is_err());
        // Offsets inconsistent.
        assert!(SymCsr::from_upper_csc(2, &[0, 1, 4], &[0, 0, 1], &[1.0; 3]).is_err());
        assert!(SymCsr::from_upper_csc(2, &[0, 1], &[0], &[1.0]).is_err());
    }

    #[test]
    fn transpose_and_dot() {
        let m = CsrMatrix::from_parts(2, 3, vec![0, 2, 3], vec![0, 2, 1], vec![1.0, 2.0, 3.0]);
        let (t, map) = m.transpose_with_map();
        assert_eq!(t.row_ptr(), &[0, 1, 2, 3]);
        assert_eq!(t.col_idx(), vec![0, 1, 0]);
        assert_eq!(t.values(), &[1.0, 3.0, 2.0]);
        assert_eq!(map, vec![0, 2, 1]);
        let a: Vec<f64> = (0..10_000).map(|i| i as f64).collect();
        let s: f64 = (0..10_000).map(|i| (i * i) as f64).sum();
        assert_eq!(dot(&a, &a), s);
    }
}
