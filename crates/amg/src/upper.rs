//! The product with a symmetric matrix given by its upper triangle in double precision: the
//! Krylov method's operator when the hierarchy stores its finest matrix in single precision
//! ([`crate::csr::Precision`]), so that no second full copy of the matrix is kept.
//!
//! # Kernel
//!
//! Column `i` of the upper triangle `U` holds the entries `u_ri`, `r ≤ i`; they are row `i`
//! of the lower triangle, so the first entries of full row `i` have exactly these columns
//! (the hierarchy's pattern gives them, the caller's array the values). With `A = U + Uᵀ −
//! diag U`:
//!
//! ```text
//!   y_i = Σ_{r ≤ i} u_ri x_r  +  Σ_{c > i} u_ic x_c,
//! ```
//!
//! the first sum a gather along column `i`, the second the scatter `y_r += u_ri x_i` of the
//! later columns `i > r`. The rows are cut into parts of a fixed size, chosen so that the
//! scatter of a part reaches back into the previous part at most; the even parts are
//! computed in parallel, then the odd ones, each writing its own rows and those of the
//! part before it (disjoint within a phase). The parts and the order of the sums depend on
//! the matrix only, not on the number of threads, so neither do the results. For
//! equations numbered by node the scatter reaches back a band and the smallest part size
//! serves; a matrix with couplings across the numbering ends up with larger parts, down to
//! one computed by one thread. The rows of a node (a group with the same columns, see
//! [`crate::csr`]) are computed together: each piece of `x` is read and each piece of `y`
//! updated once for all of them.
//!
//! Traffic: one read of the `8 B` upper values (about half the full matrix) and of the
//! pattern's run tables, instead of `8 B` for every entry of the full matrix.
//!
//! The kernel is generic over the stored precision: `UpperSingle` keeps the upper
//! triangle of a hierarchy's single-precision finest matrix as `f32` (`4 B` per upper
//! entry against `4 B` per full entry for the full rows), and `UpperOp` runs the
//! smoother's and the spectral estimate's fused row updates (`RowProducts`) on its
//! products.

use rayon::prelude::*;

use std::sync::Mutex;

use crate::csr::{
    CsrMatrix, ROWS_PER_TASK, Value, par_rows, par_rows_sum, par_zip2_sum, prefetch_ahead,
};

/// Rows per part at least.
const MIN_PART: usize = 4096;

/// The partition of the upper-triangle product for one pattern.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct UpperProduct {
    /// Rows per part (the last part may be shorter).
    part: usize,
}

impl UpperProduct {
    /// The partition for the full pattern `full` and the upper triangle's column offsets
    /// `col_ptr` (column `i` holds the first `col_ptr[i+1] − col_ptr[i]` entries of row `i`):
    /// the smallest part size from [`MIN_PART`] on (growing fourfold) whose parts scatter
    /// into the previous part at most.
    pub(crate) fn new(full: &CsrMatrix, col_ptr: &[usize]) -> Self {
        let n = full.nrows();
        let first: Vec<usize> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut c0 = i;
                if col_ptr[i + 1] > col_ptr[i] {
                    full.for_each_col_prefix(i, 1, |c| c0 = c0.min(c as usize));
                }
                c0
            })
            .collect();
        let mut part = MIN_PART.min(n.max(1));
        while part < n {
            let reaches_back_one = (1..n.div_ceil(part)).all(|k| {
                let rows = k * part..((k + 1) * part).min(n);
                first[rows].iter().all(|&c| c >= (k - 1) * part)
            });
            if reaches_back_one {
                break;
            }
            part = (4 * part).min(n);
        }
        Self { part }
    }

    /// `y = A x` for the symmetric `A` with upper triangle `upper` (values in the layout of
    /// `col_ptr`) on the pattern `full` (see the module docs); returns `xᵀ A x`.
    ///
    /// `xᵀ A x` comes from the gathers alone: with `g_i = Σ_{r ≤ i} u_ri x_r` (the sum
    /// along column `i`, diagonal included), `xᵀ A x = Σ_i x_i (2 g_i − u_ii x_i)`. Each
    /// part sums its rows; the part sums are added in part order, so the result does not
    /// depend on the number of threads either.
    pub(crate) fn apply<T: Value>(
        &self,
        full: &CsrMatrix,
        col_ptr: &[usize],
        upper: &[T],
        x: &[f64],
        y: &mut [f64],
    ) -> f64 {
        let n = full.nrows();
        let part = self.part.max(1);
        let parts = n.div_ceil(part);
        y.par_chunks_mut(part).for_each(|c| c.fill(0.0));
        let mut energy = vec![0.0; parts];
        for phase in 0..2 {
            // Part `k` writes rows `(k − 1)·part..(k + 1)·part`.
            let mut jobs = Vec::with_capacity(parts / 2 + 1);
            let (mut rest, mut at) = (&mut y[..], 0);
            for k in (phase..parts).step_by(2) {
                let base = k.saturating_sub(1) * part;
                let end = ((k + 1) * part).min(n);
                let (_, tail) = rest.split_at_mut(base - at);
                let (mine, tail) = tail.split_at_mut(end - base);
                jobs.push((
                    k * part..end,
                    Part {
                        base,
                        y: mine,
                        energy: 0.0,
                    },
                ));
                (rest, at) = (tail, end);
            }
            let sums: Vec<f64> = jobs
                .into_par_iter()
                .map(|(rows, mut p)| {
                    let mut i = rows.start;
                    while i < rows.end {
                        let Some(g) = full.row_group(i) else {
                            p.row(full, col_ptr, upper, x, i);
                            i += 1;
                            continue;
                        };
                        let mut m = 1;
                        while i + m < rows.end && m < 3 && full.row_group(i + m) == Some(g) {
                            m += 1;
                        }
                        match m {
                            1 => p.group::<1, T>(full, col_ptr, upper, x, i),
                            2 => p.group::<2, T>(full, col_ptr, upper, x, i),
                            _ => p.group::<3, T>(full, col_ptr, upper, x, i),
                        }
                        i += m;
                    }
                    p.energy
                })
                .collect();
            for (k, e) in (phase..parts).step_by(2).zip(sums) {
                energy[k] = e;
            }
        }
        energy.iter().sum()
    }
}

/// The rows `base..base + y.len()` a part writes: its own and those of the part before.
struct Part<'a> {
    base: usize,
    y: &'a mut [f64],
    /// `Σ x_i (2 g_i − u_ii x_i)` over the part's rows so far.
    energy: f64,
}

impl Part<'_> {
    /// Gather and scatter of one row with column indices, entry by entry.
    fn row<T: Value>(
        &mut self,
        full: &CsrMatrix,
        col_ptr: &[usize],
        upper: &[T],
        x: &[f64],
        i: usize,
    ) {
        let vals = &upper[col_ptr[i]..col_ptr[i + 1]];
        let xi = x[i];
        let mut acc = 0.0;
        let mut diag = 0.0;
        let mut q = 0;
        full.for_each_col_prefix(i, vals.len(), |c| {
            let c = c as usize;
            let v = vals[q].get();
            acc += v * x[c];
            q += 1;
            if c < i {
                self.y[c - self.base] += v * xi;
            } else if c == i {
                diag = v;
            }
        });
        self.y[i - self.base] += acc;
        self.energy += xi * (2.0 * acc - diag * xi);
    }

    /// Gather and scatter of the `M` rows `i..i + M` of one group (same runs of columns).
    /// Columns before `i` are in every row's prefix: each piece of `x` is read and each
    /// piece of `y` updated once for all `M` rows. The few columns from `i` on (the
    /// node's own block) follow row by row.
    #[inline(always)]
    fn group<const M: usize, T: Value>(
        &mut self,
        full: &CsrMatrix,
        col_ptr: &[usize],
        upper: &[T],
        x: &[f64],
        i: usize,
    ) {
        prefetch_ahead(upper, col_ptr[i]);
        let vals: [&[T]; M] = std::array::from_fn(|r| &upper[col_ptr[i + r]..col_ptr[i + r + 1]]);
        let xr: [f64; M] = std::array::from_fn(|r| x[i + r]);
        let mut acc = [0.0; M];
        let mut q = 0;
        let mut tail = [0usize; M];
        let mut ntail = 0;
        let longest = vals.iter().map(|v| v.len()).max().unwrap_or(0);
        if let Some(runs) = full.row_runs(i) {
            for (s, l) in runs {
                // Columns before `i`.
                let e = (s + l).min(i);
                if s < e {
                    let v: [&[T]; M] = std::array::from_fn(|r| &vals[r][q..q + e - s]);
                    let y = &mut self.y[s - self.base..e - self.base];
                    joint(&v, &x[s..e], &xr, &mut acc, y);
                    q += e - s;
                }
                // Columns from `i` on (at most `M` in the prefixes).
                for c in e.max(s)..s + l {
                    if q + ntail >= longest || ntail == M {
                        break;
                    }
                    tail[ntail] = c;
                    ntail += 1;
                }
                if q + ntail >= longest {
                    break;
                }
            }
        }
        for r in 0..M {
            let row = i + r;
            let mut diag = 0.0;
            for (t, &c) in tail[..ntail].iter().enumerate() {
                let Some(v) = vals[r].get(q + t).map(|v| v.get()) else {
                    break;
                };
                acc[r] += v * x[c];
                if c < row {
                    self.y[c - self.base] += v * xr[r];
                } else if c == row {
                    diag = v;
                }
            }
            self.y[row - self.base] += acc[r];
            self.energy += xr[r] * (2.0 * acc[r] - diag * xr[r]);
        }
    }
}

/// `acc_r += v_r · xs` and `y += Σ_r v_r x_r` over one piece of columns.
#[inline(always)]
fn joint<const M: usize, T: Value>(
    v: &[&[T]; M],
    xs: &[f64],
    xr: &[f64; M],
    acc: &mut [f64; M],
    y: &mut [f64],
) {
    for (t, (xc, yc)) in xs.iter().zip(y.iter_mut()).enumerate() {
        let mut s = 0.0;
        for r in 0..M {
            let u = v[r][t].get();
            acc[r] += u * xc;
            s += u * xr[r];
        }
        *yc += s;
    }
}

/// The products of a smoother or of the spectral estimate: `f(i, (A x)_i, …)` for every
/// row, with the entries of any number of output vectors at row `i`. [`CsrMatrix`] computes
/// `(A x)_i` row by row inside the pass; [`UpperOp`] computes `A x` first.
pub(crate) trait RowProducts: Sync {
    /// `f(i, (A x)_i, &mut y[i])` for every row.
    fn products<F>(&self, x: &[f64], y: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64) + Sync + Send;
    /// `Σ_i f(i, (A x)_i, &mut y[i])`, summed by blocks of rows in a fixed order.
    fn products_sum<F>(&self, x: &[f64], y: &mut [f64], f: F) -> f64
    where
        F: Fn(usize, f64, &mut f64) -> f64 + Sync + Send;
    /// `f(i, (A x)_i, &mut y[i], &mut z[i])` for every row.
    fn products2<F>(&self, x: &[f64], y: &mut [f64], z: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64, &mut f64) + Sync + Send;
    /// `f(i, (A x)_i, &mut y[i], &mut z[i], &mut w[i])` for every row.
    fn products3<F>(&self, x: &[f64], y: &mut [f64], z: &mut [f64], w: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64, &mut f64, &mut f64) + Sync + Send;
}

impl RowProducts for CsrMatrix {
    fn products<F>(&self, x: &[f64], y: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64) + Sync + Send,
    {
        self.par_products(x, y, f)
    }
    fn products_sum<F>(&self, x: &[f64], y: &mut [f64], f: F) -> f64
    where
        F: Fn(usize, f64, &mut f64) -> f64 + Sync + Send,
    {
        self.par_products_sum(x, y, f)
    }
    fn products2<F>(&self, x: &[f64], y: &mut [f64], z: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64, &mut f64) + Sync + Send,
    {
        self.par_products2(x, y, z, f)
    }
    fn products3<F>(&self, x: &[f64], y: &mut [f64], z: &mut [f64], w: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64, &mut f64, &mut f64) + Sync + Send,
    {
        self.par_products3(x, y, z, w, f)
    }
}

/// The upper triangle of a symmetric matrix in single precision, kept next to its full
/// single-precision rows: the products of the finest level's smoother and spectral
/// estimate then read 4 bytes per entry of the upper triangle, about half of the full
/// matrix's values (see [`crate::hierarchy`] for when the hierarchy uses it).
#[derive(Debug)]
pub(crate) struct UpperSingle {
    part: UpperProduct,
    vals: Vec<f32>,
    /// `A x` of the last product.
    ax: Mutex<Vec<f64>>,
}

impl UpperSingle {
    /// The upper triangle of `full` (a matrix stored in single precision, laid out as
    /// [`crate::SymCsr`] with the column offsets `col_ptr`); `None` for one in double
    /// precision.
    pub(crate) fn new(full: &CsrMatrix, col_ptr: &[usize]) -> Option<Self> {
        let mut vals = Vec::new();
        if !full.upper_single(col_ptr, &mut vals) {
            return None;
        }
        Some(Self {
            part: UpperProduct::new(full, col_ptr),
            vals,
            ax: Mutex::new(Vec::new()),
        })
    }

    /// Copy the values of `full` again (after new values on the same pattern).
    pub(crate) fn refresh(&mut self, full: &CsrMatrix, col_ptr: &[usize]) {
        full.upper_single(col_ptr, &mut self.vals);
    }

    /// The partition of the product.
    pub(crate) fn partition(&self) -> UpperProduct {
        self.part
    }

    /// Heap bytes held.
    pub(crate) fn bytes(&self) -> usize {
        crate::csr::vec_bytes(&self.vals)
            + self.ax.lock().map_or(0, |ax| crate::csr::vec_bytes(&ax))
    }

    /// The operator on the pattern of `full`.
    pub(crate) fn op<'a>(&'a self, full: &'a CsrMatrix, col_ptr: &'a [usize]) -> UpperOp<'a> {
        UpperOp {
            upper: self,
            full,
            col_ptr,
        }
    }
}

/// [`UpperSingle`] on its pattern: `A x` by [`UpperProduct::apply`] into a buffer, then
/// the rows' functions in parallel blocks (the same blocks as [`CsrMatrix`]'s passes).
pub(crate) struct UpperOp<'a> {
    upper: &'a UpperSingle,
    full: &'a CsrMatrix,
    col_ptr: &'a [usize],
}

impl UpperOp<'_> {
    /// `g(ax)` with `ax = A x`.
    fn with_product<R>(&self, x: &[f64], g: impl FnOnce(&[f64]) -> R) -> R {
        let mut ax = self.upper.ax.lock().unwrap_or_else(|e| e.into_inner());
        ax.resize(self.full.nrows(), 0.0);
        let _ = self
            .upper
            .part
            .apply(self.full, self.col_ptr, &self.upper.vals, x, &mut ax);
        g(&ax)
    }
}

impl RowProducts for UpperOp<'_> {
    fn products<F>(&self, x: &[f64], y: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64) + Sync + Send,
    {
        self.with_product(x, |ax| par_rows(y, |i, yi| f(i, ax[i], yi)))
    }
    fn products_sum<F>(&self, x: &[f64], y: &mut [f64], f: F) -> f64
    where
        F: Fn(usize, f64, &mut f64) -> f64 + Sync + Send,
    {
        self.with_product(x, |ax| par_rows_sum(y, |i, yi| f(i, ax[i], yi)))
    }
    fn products2<F>(&self, x: &[f64], y: &mut [f64], z: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64, &mut f64) + Sync + Send,
    {
        self.with_product(x, |ax| {
            par_zip2_sum(y, z, |i, yi, zi| {
                f(i, ax[i], yi, zi);
                0.0
            });
        })
    }
    fn products3<F>(&self, x: &[f64], y: &mut [f64], z: &mut [f64], w: &mut [f64], f: F)
    where
        F: Fn(usize, f64, &mut f64, &mut f64, &mut f64) + Sync + Send,
    {
        self.with_product(x, |ax| {
            y.par_chunks_mut(ROWS_PER_TASK)
                .zip(z.par_chunks_mut(ROWS_PER_TASK))
                .zip(w.par_chunks_mut(ROWS_PER_TASK))
                .enumerate()
                .for_each(|(b, ((ys, zs), ws))| {
                    let base = b * ROWS_PER_TASK;
                    for k in 0..ys.len() {
                        f(base + k, ax[base + k], &mut ys[k], &mut zs[k], &mut ws[k]);
                    }
                });
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csr::SymCsr;

    /// Upper triangle of a symmetric matrix with couplings at distances `dists` (some left
    /// out), values from the position.
    fn band(n: usize, dists: &[usize]) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let (mut col_ptr, mut rows, mut vals) = (vec![0], vec![], vec![]);
        for c in 0..n {
            let mut here: Vec<usize> = dists
                .iter()
                .filter(|&&d| d <= c && (d == 0 || (c * 7 + d) % 5 != 1))
                .map(|&d| c - d)
                .collect();
            here.sort_unstable();
            here.dedup();
            for r in here {
                rows.push(r);
                vals.push(entry(r, c, 50.0));
            }
            col_ptr.push(rows.len());
        }
        (col_ptr, rows, vals)
    }

    /// Entry `(r, c)` of the test matrices: `diag` on the diagonal, 1–3.3 off it.
    fn entry(r: usize, c: usize, diag: f64) -> f64 {
        if r == c {
            diag
        } else {
            1.0 + ((r * 31 + c) % 17) as f64 / 7.0
        }
    }

    /// The band of `band` on `nodes` nodes with a dense `k × k` block per coupling (the
    /// equations of a node share their columns: the products go by groups).
    fn node_band(nodes: usize, k: usize, dists: &[usize]) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let (ncp, nrows, _) = band(nodes, dists);
        let (mut col_ptr, mut rows, mut vals) = (vec![0], vec![], vec![]);
        for c in 0..nodes * k {
            let node = c / k;
            for &rn in &nrows[ncp[node]..ncp[node + 1]] {
                for r in rn * k..(rn * k + k).min(c + 1) {
                    rows.push(r);
                    vals.push(entry(r, c, 80.0));
                }
            }
            col_ptr.push(rows.len());
        }
        (col_ptr, rows, vals)
    }

    fn check(n: usize, dists: &[usize]) -> UpperProduct {
        check_matrix(n, band(n, dists))
    }

    fn check_matrix(
        n: usize,
        (col_ptr, rows, vals): (Vec<usize>, Vec<usize>, Vec<f64>),
    ) -> UpperProduct {
        let a = SymCsr::from_upper_csc(n, &col_ptr, &rows, &vals).unwrap();
        let x: Vec<f64> = (0..n).map(|i| (0.1 * i as f64).cos()).collect();
        let mut want = vec![0.0; n];
        a.mul(&x, &mut want).unwrap();
        let up = UpperProduct::new(a.matrix(), &col_ptr);
        let mut y = vec![f64::NAN; n];
        let energy = up.apply(a.matrix(), &col_ptr, &vals, &x, &mut y);
        let want_energy: f64 = x.iter().zip(&want).map(|(a, b)| a * b).sum();
        assert!(
            (energy - want_energy).abs() <= 1e-12 * want_energy.abs(),
            "xᵀAx {energy} vs {want_energy}"
        );
        for i in 0..n {
            assert!(
                (y[i] - want[i]).abs() <= 1e-13 * want[i].abs().max(1.0),
                "row {i}: {} vs {}",
                y[i],
                want[i]
            );
        }
        // A second product reuses the buffers; one thread gives the same bits.
        let mut y2 = vec![0.0; n];
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let energy2 = pool.install(|| up.apply(a.matrix(), &col_ptr, &vals, &x, &mut y2));
        assert!(y.iter().zip(&y2).all(|(a, b)| a.to_bits() == b.to_bits()));
        assert_eq!(energy.to_bits(), energy2.to_bits());
        up
    }

    /// The upper triangle in single precision gives the products of the full
    /// single-precision rows, in all four forms, to the rounding of the different order of
    /// the sums (the values are the same `f32`s), and the same bits on one thread and two.
    #[test]
    fn single_upper_products_match_the_full_rows() {
        use crate::csr::Precision;
        let nodes = 6000;
        let (col_ptr, rows, vals) = node_band(nodes, 3, &[0, 1, 2, 30, 31]);
        let n = 3 * nodes;
        let a = SymCsr::from_upper_csc_in(Precision::Single, n, &col_ptr, &rows, &vals).unwrap();
        let full = a.matrix();
        let upper = UpperSingle::new(full, &col_ptr).unwrap();
        assert!(
            UpperSingle::new(
                SymCsr::from_upper_csc(n, &col_ptr, &rows, &vals)
                    .unwrap()
                    .matrix(),
                &col_ptr
            )
            .is_none()
        );
        let op = upper.op(full, &col_ptr);
        let x: Vec<f64> = (0..n).map(|i| (0.1 * i as f64).cos()).collect();
        let w: Vec<f64> = (0..n).map(|i| 1.0 + (0.3 * i as f64).sin()).collect();
        let close = |u: &[f64], v: &[f64]| {
            u.iter()
                .zip(v)
                .all(|(p, q)| (p - q).abs() <= 1e-13 * q.abs().max(1.0))
        };
        // Every form through one operator; the outputs of all four.
        let forms = |p: &dyn Fn(&mut [Vec<f64>; 5]) -> f64| {
            let mut out: [Vec<f64>; 5] = std::array::from_fn(|_| vec![0.0; n]);
            let s = p(&mut out);
            (out, s)
        };
        let via_full = forms(&|o: &mut [Vec<f64>; 5]| {
            let [y0, y1, y2, y3, y4] = o;
            full.par_products(&x, y0, |i, ax, y| *y = ax * w[i]);
            full.par_products2(&x, y1, y2, |_, ax, y, z| (*y, *z) = (ax, 2.0 * ax));
            full.par_products3(&x, y3, y4, y2, |_, ax, y, z, v| {
                (*y, *z, *v) = (ax - 1.0, ax + 1.0, *v + ax)
            });
            full.par_products_sum(&x, y1, |i, ax, y| {
                *y += ax;
                ax * x[i]
            })
        });
        let via_upper = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    forms(&|o: &mut [Vec<f64>; 5]| {
                        let [y0, y1, y2, y3, y4] = o;
                        op.products(&x, y0, |i, ax, y| *y = ax * w[i]);
                        op.products2(&x, y1, y2, |_, ax, y, z| (*y, *z) = (ax, 2.0 * ax));
                        op.products3(&x, y3, y4, y2, |_, ax, y, z, v| {
                            (*y, *z, *v) = (ax - 1.0, ax + 1.0, *v + ax)
                        });
                        op.products_sum(&x, y1, |i, ax, y| {
                            *y += ax;
                            ax * x[i]
                        })
                    })
                })
        };
        let (want, want_sum) = via_full;
        let (got, sum) = via_upper(2);
        for (g, w) in got.iter().zip(&want) {
            assert!(close(g, w));
        }
        assert!((sum - want_sum).abs() <= 1e-12 * want_sum.abs());
        let (got1, sum1) = via_upper(1);
        assert_eq!(sum.to_bits(), sum1.to_bits());
        for (g, h) in got.iter().zip(&got1) {
            assert!(g.iter().zip(h).all(|(p, q)| p.to_bits() == q.to_bits()));
        }
        // New values on the same pattern: the copy follows them.
        let doubled: Vec<f64> = vals.iter().map(|v| 2.0 * v).collect();
        let mut a2 = a.clone();
        a2.set_values(&doubled).unwrap();
        let mut upper2 = UpperSingle::new(full, &col_ptr).unwrap();
        upper2.refresh(a2.matrix(), &col_ptr);
        let mut y = vec![0.0; n];
        upper2
            .op(a2.matrix(), &col_ptr)
            .products(&x, &mut y, |_, ax, y| *y = ax);
        let mut ax = vec![0.0; n];
        full.par_products(&x, &mut ax, |_, v, y| *y = v);
        let twice: Vec<f64> = ax.iter().map(|v| 2.0 * v).collect();
        assert!(close(&y, &twice));
    }

    #[test]
    fn matches_the_full_product_on_a_band() {
        // Many parts (odd and even), each scattering 40 rows back.
        let up = check(30_000, &[0, 1, 3, 40]);
        assert_eq!(up.part, MIN_PART);
    }

    #[test]
    fn matches_the_full_product_by_node_groups() {
        // Nodes of 1–4 equations (groups of up to 3 rows computed together, longer ones
        // split); groups of 3 straddle the parts of 4096 rows.
        for k in 1..=4 {
            let nodes = 12_000 / k;
            let (col_ptr, rows, vals) = node_band(nodes, k, &[0, 1, 2, 30]);
            let a = SymCsr::from_upper_csc(nodes * k, &col_ptr, &rows, &vals).unwrap();
            // One equation per node: short runs, stored with column indices.
            assert_eq!(a.matrix().row_group(0).is_some(), k > 1, "k = {k}");
            check_matrix(nodes * k, (col_ptr, rows, vals));
        }
    }

    #[test]
    fn far_couplings_use_larger_parts() {
        // Couplings across 9000 rows: parts of 4096 would scatter beyond the previous part.
        let up = check(20_000, &[0, 2, 9000]);
        assert_eq!(up.part, 4 * MIN_PART);
        // The last rows coupled to the first: one part.
        let up = check(9000, &[0, 1, 8999, 2500]);
        assert_eq!(up.part, 9000);
        // Two parts, the second scattering into the whole first.
        let up = check(5000, &[0, 1, 4999, 2500]);
        assert_eq!(up.part, MIN_PART);
    }
}
