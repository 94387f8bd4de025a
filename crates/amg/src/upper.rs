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
//! later columns `i > r`. The rows are cut into parts of a fixed size; a part gathers its
//! own rows and scatters into its own rows or, for rows before it, into a spill buffer
//! that is added after the parallel pass, in part order. The parts depend on the matrix
//! only, not on the number of threads, so neither do the results. For equations numbered
//! by node the scatter reaches back a band, and the spill buffers are small; the parts are
//! chosen as small as keeps all spill buffers below `n/2` entries (a matrix with couplings
//! across the whole numbering ends up with one part, computed by one thread).
//!
//! Traffic: one read of the `8 B` upper values (about half the full matrix) and of the
//! pattern's run tables, instead of `8 B` for every entry of the full matrix.

use rayon::prelude::*;

use crate::csr::{CsrMatrix, vec_bytes};

/// Rows per part at least.
const MIN_PART: usize = 4096;

/// The partition and spill buffers of the upper-triangle product for one pattern.
#[derive(Debug, Default)]
pub(crate) struct UpperProduct {
    /// Rows per part.
    part: usize,
    /// Lowest row that part `k`'s scatter reaches.
    lo: Vec<usize>,
    /// Spill buffer of all parts: part `k` holds rows `lo[k]..k·part`.
    spill: Vec<f64>,
}

impl UpperProduct {
    /// The partition for the full pattern `full` and the upper triangle's column offsets
    /// `col_ptr` (column `i` holds the first `col_ptr[i+1] − col_ptr[i]` entries of row `i`).
    pub(crate) fn new(full: &CsrMatrix, col_ptr: &[usize]) -> Self {
        let n = full.nrows();
        let first: Vec<usize> = (0..n)
            .map(|i| {
                let mut c0 = i;
                if col_ptr[i + 1] > col_ptr[i] {
                    full.for_each_col_prefix(i, 1, |c| c0 = c0.min(c as usize));
                }
                c0
            })
            .collect();
        let lows = |part: usize| -> Vec<usize> {
            (0..n.div_ceil(part))
                .map(|k| {
                    let rows = k * part..((k + 1) * part).min(n);
                    first[rows.clone()]
                        .iter()
                        .copied()
                        .min()
                        .unwrap_or(rows.start)
                })
                .collect()
        };
        let mut part = MIN_PART.min(n.max(1));
        let lo = loop {
            let lo = lows(part);
            let spill: usize = lo.iter().enumerate().map(|(k, &l)| k * part - l).sum();
            if 2 * spill <= n || part >= n {
                break lo;
            }
            part = (4 * part).min(n);
        };
        let total = lo.iter().enumerate().map(|(k, &l)| k * part - l).sum();
        Self {
            part,
            lo,
            spill: vec![0.0; total],
        }
    }

    /// Heap bytes held.
    pub(crate) fn bytes(&self) -> usize {
        vec_bytes(&self.lo) + vec_bytes(&self.spill)
    }

    /// `y = A x` for the symmetric `A` with upper triangle `upper` (values in the layout of
    /// `col_ptr`) on the pattern `full` (see the module docs).
    pub(crate) fn apply(
        &mut self,
        full: &CsrMatrix,
        col_ptr: &[usize],
        upper: &[f64],
        x: &[f64],
        y: &mut [f64],
    ) {
        let n = full.nrows();
        let part = self.part;
        let mut jobs = Vec::with_capacity(self.lo.len());
        let (mut ys, mut ss) = (&mut y[..], &mut self.spill[..]);
        for (k, &lo) in self.lo.iter().enumerate() {
            let start = k * part;
            let (yk, yt) = ys.split_at_mut(((k + 1) * part).min(n) - start);
            let (sk, st) = ss.split_at_mut(start - lo);
            jobs.push((start, lo, yk, sk));
            (ys, ss) = (yt, st);
        }
        jobs.into_par_iter().for_each(|(start, lo, yk, sk)| {
            yk.fill(0.0);
            sk.fill(0.0);
            for i in start..start + yk.len() {
                let p0 = col_ptr[i];
                let vals = &upper[p0..col_ptr[i + 1]];
                let xi = x[i];
                let mut acc = [0.0f64; 2];
                let mut q = 0;
                full.for_each_col_prefix(i, vals.len(), |c| {
                    let c = c as usize;
                    let v = vals[q];
                    acc[q & 1] += v * x[c];
                    q += 1;
                    if c < i {
                        if c >= start {
                            yk[c - start] += v * xi;
                        } else {
                            sk[c - lo] += v * xi;
                        }
                    }
                });
                yk[i - start] += acc[0] + acc[1];
            }
        });
        let mut at = 0;
        for (k, &lo) in self.lo.iter().enumerate() {
            let len = k * part - lo;
            for (yi, s) in y[lo..lo + len].iter_mut().zip(&self.spill[at..at + len]) {
                *yi += s;
            }
            at += len;
        }
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
                vals.push(if r == c {
                    50.0
                } else {
                    1.0 + ((r * 31 + c) % 17) as f64 / 7.0
                });
            }
            col_ptr.push(rows.len());
        }
        (col_ptr, rows, vals)
    }

    fn check(n: usize, dists: &[usize]) -> UpperProduct {
        let (col_ptr, rows, vals) = band(n, dists);
        let a = SymCsr::from_upper_csc(n, &col_ptr, &rows, &vals).unwrap();
        let x: Vec<f64> = (0..n).map(|i| (0.1 * i as f64).cos()).collect();
        let mut want = vec![0.0; n];
        a.mul(&x, &mut want).unwrap();
        let mut up = UpperProduct::new(a.matrix(), &col_ptr);
        let mut y = vec![f64::NAN; n];
        up.apply(a.matrix(), &col_ptr, &vals, &x, &mut y);
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
        pool.install(|| up.apply(a.matrix(), &col_ptr, &vals, &x, &mut y2));
        assert!(y.iter().zip(&y2).all(|(a, b)| a.to_bits() == b.to_bits()));
        up
    }

    #[test]
    fn matches_the_full_product_on_a_band() {
        // Many parts, each spilling a band of 40 rows back.
        let up = check(30_000, &[0, 1, 3, 40]);
        assert_eq!(up.part, MIN_PART);
        assert_eq!(up.lo.len(), 30_000usize.div_ceil(MIN_PART));
        // Each part but the first spills at most 40 rows back (fewer where the coupling at
        // distance 40 of its first rows is left out).
        let parts = up.lo.len() - 1;
        assert!(up.spill.len() <= 40 * parts && up.spill.len() >= 38 * parts);
    }

    #[test]
    fn far_couplings_use_larger_parts() {
        // Couplings across 9000 rows: parts of 4096 would spill more than n/2.
        let up = check(20_000, &[0, 2, 9000]);
        assert!(up.part > MIN_PART, "part {}", up.part);
        assert!(2 * up.spill.len() <= 20_000);
        // Across the whole numbering: one part, no spill.
        let up = check(5000, &[0, 1, 4999, 2500]);
        assert_eq!((up.lo.len(), up.spill.len()), (1, 0));
    }
}
