//! Single-precision numeric `LDLᵀ` factors on the symbolic analysis of an [`Ldlt`]: a
//! preconditioner for an outer iteration in double precision (mixed precision).
//!
//! The same supernodal factorization as [`Ldlt::factorize`] (faer's, generic over the
//! scalar), with the matrix rounded to `f32`: `P A Pᵀ + ΔA = L̃ D̃ L̃ᵀ` with
//! `‖ΔA‖ ≲ c(n) ε₃₂ ‖|L̃| |D̃| |L̃ᵀ|‖`, `ε₃₂ = 2⁻²⁴ ≈ 6·10⁻⁸` (Higham, *Accuracy and
//! Stability of Numerical Algorithms*, §10.4, for a symmetric positive definite `A`). As
//! a preconditioner `M = L̃ D̃ L̃ᵀ`, `‖I − A M⁻¹‖ ≲ c κ(A) ε₃₂`: a Krylov method (or
//! iterative refinement) in double precision, with the residual computed from the matrix
//! in double, reaches a double-precision solution in a few more iterations, while the
//! factorization moves half the bytes and works on twice the vector lanes.
//!
//! A solve rounds the right-hand side to `f32` after scaling it to unit maximum (so
//! that a small residual does not underflow), permutes it, sweeps the supernodes of the
//! `f32` factors and scales back into `f64`. Supernode `s` holds the columns
//! `start..start + w` of `L̃` as one dense column-major block of `m = w + r` rows (the unit
//! lower triangle, `D̃` on its diagonal, over the rows `R_s` below); on a buffer of its
//! `m` rows, the forward sweep `L̃ y = P b` is one `axpy` per column (`y_below −= L̃_col y_j`,
//! the rows below `R_s` added into `y[R_s]` after), the backward sweep
//! `L̃ᵀ x = D̃⁻¹ y` one dot product per column, last to first
//! (`x_j = y_j / d_j − L̃_colᵀ x_below`, `x[R_s]` gathered first): every stored entry is
//! read once per sweep, in `f32` lanes (`pulp` picks AVX2 or plain code at run time).
//!
//! [`TrailingFactor`] reads the block of the unknowns eliminated last from the factors
//! (of either precision), for a solver that corrects them between the two halves of a
//! solve ([`LdltSingle::forward_in_place`], [`LdltSingle::backward_in_place`]).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{MatMut, Par, Side};
use pulp::Simd;

use crate::ldlt::{Ldlt, LdltError};

/// `f32` numeric factors of the pattern analysed by an [`Ldlt`] (which it owns, and gives
/// back by [`LdltSingle::into_analysis`] for a factorization in double precision).
pub struct LdltSingle {
    analysis: Ldlt,
    /// `L̃` with `D̃` on its diagonal, in faer's supernodal storage.
    values: Vec<f32>,
    /// The right-hand side in `f32`, in the elimination order.
    work: Vec<f32>,
    /// The rows of the widest supernode.
    buf: Vec<f32>,
    /// Scratch of the numeric factorization and of the solve.
    mem: Option<MemBuffer>,
    par: Par,
    factored: bool,
}

impl LdltSingle {
    /// Factors to come on the symbolic analysis of `analysis` (its own numeric factors, if
    /// any, are not used).
    pub fn new(analysis: Ldlt) -> Self {
        Self {
            analysis,
            values: Vec::new(),
            work: Vec::new(),
            buf: Vec::new(),
            mem: None,
            par: Par::Seq,
            factored: false,
        }
    }

    /// The symbolic analysis.
    pub fn analysis(&self) -> &Ldlt {
        &self.analysis
    }

    /// Give back the symbolic analysis (e.g. for [`Ldlt::factorize`] in double precision
    /// when the single-precision factorization failed).
    pub fn into_analysis(self) -> Ldlt {
        self.analysis
    }

    /// Use `par` for the numeric factorization.
    pub fn set_parallelism(&mut self, par: Par) {
        self.par = par;
        self.mem = None;
    }

    /// Stored entries of `L̃` (with `D̃` on its diagonal).
    pub fn factor_nnz(&self) -> usize {
        self.analysis.factor_nnz()
    }

    /// The elimination order (see [`Ldlt::permutation`]).
    pub fn permutation(&self) -> Option<&[usize]> {
        self.analysis.permutation()
    }

    /// Whether the last numeric factorization succeeded.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    fn symbolic(&self) -> &SymbolicCholesky<usize> {
        self.analysis.symbolic()
    }

    /// Allocate the factor and the scratch of the numeric factorization now and touch
    /// their pages, so that the first [`Self::factorize`] finds them ready: on another
    /// thread while the matrix is assembled, this takes the page faults of the fresh
    /// memory (tens of MB) off the factorization.
    ///
    /// Errors: the scratch cannot be allocated.
    pub fn reserve(&mut self) -> Result<(), LdltError> {
        let symbolic = self.analysis.symbolic();
        let n = symbolic.nrows();
        let len = symbolic.len_val();
        if self.values.len() != len {
            // Zeroed memory from the allocator (fresh pages, not yet mapped), then one
            // write per 4 KiB page: the page faults without a pass of zeros over it all.
            self.values = vec![0.0; len];
            for v in self.values.iter_mut().step_by(1024) {
                *v = std::hint::black_box(0.0);
            }
        }
        self.work.resize(n, 0.0);
        if self.mem.is_none() {
            let req = symbolic
                .factorize_numeric_ldlt_scratch::<f32>(self.par, Default::default())
                .or(symbolic.solve_in_place_scratch::<f32>(1, Par::Seq));
            let mut mem = MemBuffer::try_new(req).map_err(|_| LdltError("out of memory".into()))?;
            for b in mem.iter_mut().step_by(4096) {
                b.write(0);
            }
            self.mem = Some(mem);
        }
        Ok(())
    }

    /// Numeric factorization in `f32` of the matrix with the upper-triangle `values`
    /// (double precision, rounded here) of the analysed pattern (`col_ptr`, `row_idx`).
    /// The pattern may hold the whole symmetric matrix: only its upper triangle is read
    /// (faer's `Side::Upper`).
    ///
    /// Errors: lengths; a value outside the range of `f32`; a zero, non-finite or — with
    /// `positive` — non-positive pivot (for a matrix known to be positive definite, the
    /// sign that single precision is not enough for it).
    pub fn factorize(
        &mut self,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
        positive: bool,
    ) -> Result<(), LdltError> {
        let n = self.analysis.symbolic().nrows();
        self.factorize_signed(col_ptr, row_idx, values, positive.then_some(n))
    }

    /// [`Self::factorize`] of a matrix with known inertia: with `Some(p)`, the first `p`
    /// pivots (in the elimination order) must be positive and the others negative — the
    /// bordered matrix `[[P, Z], [Zᵀ, 0]]` of a positive definite `P` and a `Z` of full
    /// column rank, the border last, has `p = n(P)`.
    pub fn factorize_signed(
        &mut self,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
        positive: Option<usize>,
    ) -> Result<(), LdltError> {
        self.factored = false;
        let symbolic = self.analysis.symbolic();
        let n = symbolic.nrows();
        if col_ptr.len() != n + 1 || values.len() != row_idx.len() {
            return Err(LdltError(format!(
                "matrix of {} columns and {} values for {} row indices, want {n} columns",
                col_ptr.len().saturating_sub(1),
                values.len(),
                row_idx.len()
            )));
        }
        let mut a = Vec::with_capacity(values.len());
        for &v in values {
            let s = v as f32;
            if !s.is_finite() {
                return Err(LdltError(format!("value {v:e} outside single precision")));
            }
            a.push(s);
        }
        let sym = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let mat = SparseColMatRef::new(sym, &a[..]);
        self.values.resize(symbolic.len_val(), 0.0);
        self.work.resize(n, 0.0);
        let mem = match self.mem.take() {
            Some(m) => m,
            None => {
                let req = symbolic
                    .factorize_numeric_ldlt_scratch::<f32>(self.par, Default::default())
                    .or(symbolic.solve_in_place_scratch::<f32>(1, Par::Seq));
                MemBuffer::try_new(req).map_err(|_| LdltError("out of memory".into()))?
            }
        };
        let mem = self.mem.insert(mem);
        symbolic
            .factorize_numeric_ldlt(
                &mut self.values,
                mat,
                Side::Upper,
                Default::default(),
                self.par,
                MemStack::new(mem),
                Default::default(),
            )
            .map_err(|e| LdltError(format!("{e:?}")))?;
        drop(a);
        if let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() {
            let (begin, end, vptr) = (
                sn.supernode_begin(),
                sn.supernode_end(),
                sn.col_ptr_for_val(),
            );
            let mut tallest = 0;
            for s in 0..sn.n_supernodes() {
                let w = end[s] - begin[s];
                let m = (vptr[s + 1] - vptr[s]) / w.max(1);
                tallest = tallest.max(m);
                let block = &self.values[vptr[s]..vptr[s + 1]];
                for j in 0..w {
                    let d = block[j * m + j];
                    let sign_ok = positive.is_none_or(|p| (d > 0.0) == (begin[s] + j < p));
                    if !(d.is_finite() && d != 0.0 && sign_ok) {
                        return Err(LdltError(format!(
                            "pivot {d:e} of column {} in single precision",
                            begin[s] + j
                        )));
                    }
                }
            }
            self.buf.resize(tallest, 0.0);
        }
        self.factored = true;
        Ok(())
    }

    /// `rhs ← M⁻¹ rhs` with `M = Pᵀ L̃ D̃ L̃ᵀ P` (see the module documentation).
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LdltError> {
        self.forward_in_place(rhs)?;
        self.backward_in_place(rhs)
    }

    /// `rhs ← L̃⁻¹ P rhs` (on return in the elimination order): the first half of
    /// [`LdltSingle::solve_in_place`].
    pub fn forward_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LdltError> {
        self.sweep(rhs, true)
    }

    /// `rhs ← Pᵀ L̃⁻ᵀ D̃⁻¹ rhs` (`rhs` in the elimination order on entry, as
    /// [`LdltSingle::forward_in_place`] left it): the second half.
    pub fn backward_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LdltError> {
        self.sweep(rhs, false)
    }

    /// The forward sweep (with the permutation in) or the backward one (with the
    /// permutation out) in `f32` on `rhs` scaled to unit maximum.
    fn sweep(&mut self, rhs: &mut [f64], forward: bool) -> Result<(), LdltError> {
        let n = self.symbolic().nrows();
        if !self.factored {
            return Err(LdltError("solve before a successful factorization".into()));
        }
        if rhs.len() != n {
            return Err(LdltError(format!(
                "right-hand side of length {}, want {n}",
                rhs.len()
            )));
        }
        let scale = rhs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if scale == 0.0 || !scale.is_finite() {
            // Zero stays zero; a non-finite right-hand side gives a non-finite solution.
            rhs.iter_mut().for_each(|v| *v *= 0.0);
            return Ok(());
        }
        let symbolic = self.analysis.symbolic();
        let perm = symbolic.perm().map(|p| p.arrays());
        match perm {
            Some((fwd, _)) if forward => {
                for (w, &i) in self.work.iter_mut().zip(fwd) {
                    *w = (rhs[i] / scale) as f32;
                }
            }
            _ => {
                for (w, &r) in self.work.iter_mut().zip(rhs.iter()) {
                    *w = (r / scale) as f32;
                }
            }
        }
        let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else {
            return Err(LdltError(
                "single-precision solve of a simplicial factor".into(),
            ));
        };
        pulp::Arch::new().dispatch(Sweeps {
            sn,
            values: &self.values,
            x: &mut self.work,
            buf: &mut self.buf,
            forward,
        });
        match perm {
            Some((_, inv)) if !forward => {
                for (r, &k) in rhs.iter_mut().zip(inv) {
                    *r = f64::from(self.work[k]) * scale;
                }
            }
            _ => {
                for (r, &w) in rhs.iter_mut().zip(self.work.iter()) {
                    *r = f64::from(w) * scale;
                }
            }
        }
        Ok(())
    }

    /// The last `k` columns of the factors, in double precision (see [`TrailingFactor`]).
    pub fn trailing_factor(&self, k: usize) -> Result<TrailingFactor, LdltError> {
        if !self.factored {
            return Err(LdltError(
                "trailing factor before a successful factorization".into(),
            ));
        }
        TrailingFactor::from_supernodal(self.symbolic(), &self.values, k)
    }
}

/// The trailing `k × k` block `L₂₂`, `D₂` of the factors `P A Pᵀ = L D Lᵀ` (the unknowns
/// eliminated last), dense and in double precision. With `A` split as
/// `[[A₁₁, A₁₂], [A₂₁, A₂₂]]` in the elimination order, `L₂₂ D₂ L₂₂ᵀ` is the Schur
/// complement `A₂₂ − A₂₁ A₁₁⁻¹ A₁₂`; a right-hand side non-zero only on the last `k`
/// unknowns has `L⁻¹ b = [0; L₂₂⁻¹ b₂]`, and the last `k` entries of
/// `L⁻ᵀ D⁻¹ f` are `L₂₂⁻ᵀ D₂⁻¹ f₂`: a solver that corrects those unknowns between the
/// two halves of a solve needs only this block.
#[derive(Clone, Debug)]
pub struct TrailingFactor {
    k: usize,
    /// `L₂₂`, column-major, unit diagonal.
    l: Vec<f64>,
    d: Vec<f64>,
}

impl TrailingFactor {
    /// Read from supernodal factors `values` (any precision) of `symbolic`.
    pub(crate) fn from_supernodal<T: Copy + Into<f64>>(
        symbolic: &SymbolicCholesky<usize>,
        values: &[T],
        k: usize,
    ) -> Result<Self, LdltError> {
        let n = symbolic.nrows();
        if k > n {
            return Err(LdltError(format!("trailing block of {k} of {n} unknowns")));
        }
        let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else {
            return Err(LdltError("trailing block of a simplicial factor".into()));
        };
        let first = n - k;
        let mut l = vec![0.0; k * k];
        let mut d = vec![0.0; k];
        let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
        let (rptr, vptr, rows) = (sn.col_ptr_for_row_idx(), sn.col_ptr_for_val(), sn.row_idx());
        for s in 0..sn.n_supernodes() {
            let (start, w) = (begin[s], end[s] - begin[s]);
            if start + w <= first {
                continue;
            }
            let block = &values[vptr[s]..vptr[s + 1]];
            let m = block.len() / w.max(1);
            let below = &rows[rptr[s]..rptr[s] + (m - w)];
            for j in (first.max(start) - start)..w {
                let cj = start + j - first;
                let dst = &mut l[cj * k..(cj + 1) * k];
                d[cj] = block[j * m + j].into();
                dst[cj] = 1.0;
                for i in j + 1..w {
                    dst[start + i - first] = block[j * m + i].into();
                }
                for (t, &row) in below.iter().enumerate() {
                    dst[row - first] = block[j * m + w + t].into();
                }
            }
        }
        Ok(Self { k, l, d })
    }

    /// The size `k`.
    pub fn len(&self) -> usize {
        self.k
    }

    /// Whether `k = 0`.
    pub fn is_empty(&self) -> bool {
        self.k == 0
    }

    /// `v ← L₂₂⁻¹ v` (`k` values).
    pub fn forward(&self, v: &mut [f64]) {
        let k = self.k;
        for j in 0..k {
            let vj = v[j];
            if vj != 0.0 {
                for (x, &c) in v[j + 1..]
                    .iter_mut()
                    .zip(&self.l[j * k + j + 1..(j + 1) * k])
                {
                    *x -= c * vj;
                }
            }
        }
    }

    /// `v ← D₂ L₂₂ᵀ v` (`k` values).
    pub fn upper_product(&self, v: &mut [f64]) {
        let k = self.k;
        for j in 0..k {
            let s: f64 = v[j + 1..]
                .iter()
                .zip(&self.l[j * k + j + 1..(j + 1) * k])
                .map(|(x, c)| x * c)
                .sum();
            v[j] = self.d[j] * (v[j] + s);
        }
    }

    /// `v ← L₂₂⁻ᵀ D₂⁻¹ v` (`k` values).
    pub fn backward(&self, v: &mut [f64]) {
        let k = self.k;
        for j in (0..k).rev() {
            let s: f64 = v[j + 1..]
                .iter()
                .zip(&self.l[j * k + j + 1..(j + 1) * k])
                .map(|(x, c)| x * c)
                .sum();
            v[j] = v[j] / self.d[j] - s;
        }
    }

    /// The Schur complement `L₂₂ D₂ L₂₂ᵀ`, dense column-major `k × k` (its lower triangle
    /// by faer's triangular product, mirrored).
    pub fn schur_complement(&self, par: Par) -> Vec<f64> {
        let k = self.k;
        let mut out = vec![0.0; k * k];
        self.schur_complement_into(MatMut::from_column_major_slice_mut(&mut out, k, k), par);
        out
    }

    /// [`Self::schur_complement`] into `out` (`k × k`, any strides), without allocating
    /// it.
    ///
    /// # Panics
    /// When `out` is not `k × k`.
    pub fn schur_complement_into(&self, mut out: MatMut<'_, f64>, par: Par) {
        use faer::linalg::matmul::triangular::{BlockStructure, matmul};
        let k = self.k;
        assert!(
            out.nrows() == k && out.ncols() == k,
            "Schur complement of {k} unknowns into a {} × {} matrix",
            out.nrows(),
            out.ncols()
        );
        let l = faer::MatRef::from_column_major_slice(&self.l, k, k);
        let mut ld = l.to_owned();
        for (j, &dj) in self.d.iter().enumerate() {
            for v in ld.col_mut(j).iter_mut() {
                *v *= dj;
            }
        }
        matmul(
            out.as_mut(),
            BlockStructure::TriangularLower,
            faer::Accum::Replace,
            ld.as_ref(),
            BlockStructure::TriangularLower,
            l.transpose(),
            BlockStructure::TriangularUpper,
            1.0,
            par,
        );
        for j in 0..k {
            for i in j + 1..k {
                out[(j, i)] = out[(i, j)];
            }
        }
    }
}

/// The forward or backward sweep of [`LdltSingle::solve_in_place`] on `x` (in the
/// elimination order), compiled for the instruction set `pulp` dispatches to.
struct Sweeps<'a> {
    sn: &'a SymbolicSupernodalCholesky<usize>,
    values: &'a [f32],
    x: &'a mut [f32],
    buf: &'a mut [f32],
    /// The forward sweep, else the backward one.
    forward: bool,
}

impl pulp::WithSimd for Sweeps<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Self {
            sn,
            values,
            x,
            buf,
            forward,
        } = self;
        let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
        let (rptr, vptr, rows) = (sn.col_ptr_for_row_idx(), sn.col_ptr_for_val(), sn.row_idx());
        let ns = sn.n_supernodes();
        let node = |s: usize| {
            let (start, w) = (begin[s], end[s] - begin[s]);
            let block = &values[vptr[s]..vptr[s + 1]];
            let m = block.len() / w.max(1);
            (start, w, m, block, &rows[rptr[s]..rptr[s] + (m - w)])
        };
        // L̃ y = x.
        for s in (0..ns).filter(|_| forward) {
            let (start, w, m, block, below) = node(s);
            let b = &mut buf[..m];
            b[..w].copy_from_slice(&x[start..start + w]);
            b[w..].fill(0.0);
            for j in 0..w {
                let yj = b[j];
                if yj != 0.0 {
                    axpy(
                        simd,
                        &mut b[j + 1..],
                        &block[j * m + j + 1..(j + 1) * m],
                        -yj,
                    );
                }
            }
            x[start..start + w].copy_from_slice(&b[..w]);
            for (&row, &v) in below.iter().zip(&b[w..]) {
                x[row] += v;
            }
        }
        // L̃ᵀ x = D̃⁻¹ y.
        for s in (0..ns).rev().filter(|_| !forward) {
            let (start, w, m, block, below) = node(s);
            let b = &mut buf[..m];
            for (t, &row) in below.iter().enumerate() {
                b[w + t] = x[row];
            }
            for j in (0..w).rev() {
                let col = &block[j * m..(j + 1) * m];
                b[j] = x[start + j] / col[j] - dot(simd, &col[j + 1..], &b[j + 1..]);
            }
            x[start..start + w].copy_from_slice(&b[..w]);
        }
    }
}

/// `t += a c` (`c` as long as `t`).
#[inline(always)]
fn axpy<S: Simd>(simd: S, t: &mut [f32], c: &[f32], a: f32) {
    let (th, tt) = S::as_mut_simd_f32s(t);
    let (ch, ct) = S::as_simd_f32s(c);
    let av = simd.splat_f32s(a);
    for (t, &c) in th.iter_mut().zip(ch) {
        *t = simd.mul_add_e_f32s(c, av, *t);
    }
    for (t, &c) in tt.iter_mut().zip(ct) {
        *t += a * c;
    }
}

/// `aᵀ b` (`a` as long as `b`).
#[inline(always)]
fn dot<S: Simd>(simd: S, a: &[f32], b: &[f32]) -> f32 {
    let (ah, at) = S::as_simd_f32s(a);
    let (bh, bt) = S::as_simd_f32s(b);
    let mut acc = simd.splat_f32s(0.0);
    for (&x, &y) in ah.iter().zip(bh) {
        acc = simd.mul_add_e_f32s(x, y, acc);
    }
    let mut sum = simd.reduce_sum_f32s(acc);
    for (&x, &y) in at.iter().zip(bt) {
        sum += x * y;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Upper triangle (CSC) of a symmetric positive definite matrix on a `k × k` grid: a
    /// 9-point stencil with varying weights and diagonal (condition number ~ 10³).
    fn spd(k: usize) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = k * k;
        let mut col_ptr = vec![0];
        let (mut row_idx, mut vals) = (Vec::new(), Vec::new());
        for j in 0..n {
            let (jx, jy) = (j % k, j / k);
            for i in 0..=j {
                let (ix, iy) = (i % k, i / k);
                let (dx, dy) = (ix.abs_diff(jx), iy.abs_diff(jy));
                if i == j {
                    row_idx.push(i);
                    vals.push(9.0 + 0.5 * ((j * 7) % 5) as f64);
                } else if dx <= 1 && dy <= 1 {
                    row_idx.push(i);
                    vals.push(-1.0 - 0.1 * ((i + j) % 3) as f64 / (dx + dy) as f64);
                }
            }
            col_ptr.push(row_idx.len());
        }
        (n, col_ptr, row_idx, vals)
    }

    fn max_abs(v: &[f64]) -> f64 {
        v.iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    /// Both triangles of the matrix from its upper triangle (CSC, sorted rows).
    fn mirrored(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        vals: &[f64],
    ) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for j in 0..n {
            for q in col_ptr[j]..col_ptr[j + 1] {
                let i = row_idx[q];
                cols[j].push((i, vals[q]));
                if i != j {
                    cols[i].push((j, vals[q]));
                }
            }
        }
        let (mut cp, mut ri, mut va) = (vec![0], Vec::new(), Vec::new());
        for mut c in cols {
            c.sort_by_key(|e| e.0);
            ri.extend(c.iter().map(|e| e.0));
            va.extend(c.iter().map(|e| e.1));
            cp.push(ri.len());
        }
        (cp, ri, va)
    }

    /// The whole symmetric matrix in place of its upper triangle (only the upper triangle
    /// is read), memory reserved before the factorization, and the Schur complement
    /// written into a given matrix: bitwise the same results.
    #[test]
    fn whole_matrix_reserve_and_schur_into_change_nothing() {
        let (n, col_ptr, row_idx, vals) = spd(10);
        let (fc, fr, fv) = mirrored(n, &col_ptr, &row_idx, &vals);
        assert!(fr.len() > row_idx.len());
        let b: Vec<f64> = (0..n).map(|i| ((i * 5) % 7) as f64 - 3.0).collect();
        let mut upper = LdltSingle::new(Ldlt::analyse(n, &col_ptr, &row_idx, None).unwrap());
        upper.factorize(&col_ptr, &row_idx, &vals, true).unwrap();
        let mut whole = LdltSingle::new(Ldlt::analyse(n, &fc, &fr, None).unwrap());
        whole.reserve().unwrap();
        whole.factorize(&fc, &fr, &fv, true).unwrap();
        assert_eq!(whole.permutation(), upper.permutation());
        let (mut x, mut y) = (b.clone(), b.clone());
        upper.solve_in_place(&mut x).unwrap();
        whole.solve_in_place(&mut y).unwrap();
        assert_eq!(x, y);
        let m = 9;
        let t = whole.trailing_factor(m).unwrap();
        let s = t.schur_complement(Par::Seq);
        let mut into = faer::Mat::<f64>::zeros(m, m);
        t.schur_complement_into(into.as_mut(), Par::Seq);
        for j in 0..m {
            for i in 0..m {
                assert_eq!(into[(i, j)], s[j * m + i]);
                assert_eq!(into[(i, j)], into[(j, i)]);
            }
        }
        let mut double = Ldlt::analyse(n, &fc, &fr, None).unwrap();
        double.factorize(&fc, &fr, &fv).unwrap();
        let mut z = b.clone();
        double.solve_in_place(&mut z).unwrap();
        let mut w = b.clone();
        let mut reference = Ldlt::analyse(n, &col_ptr, &row_idx, None).unwrap();
        reference.factorize(&col_ptr, &row_idx, &vals).unwrap();
        reference.solve_in_place(&mut w).unwrap();
        assert_eq!(z, w);
    }

    /// The single-precision solve is the double-precision one to `f32` accuracy (10⁻⁵ of
    /// the solution's largest entry at condition number ~10³), for AMD and a given order.
    #[test]
    fn single_solve_matches_the_double_one() {
        let (n, col_ptr, row_idx, vals) = spd(14);
        let reversed: Vec<usize> = (0..n).rev().collect();
        for perm in [None, Some(reversed.as_slice())] {
            let mut double = Ldlt::analyse(n, &col_ptr, &row_idx, perm).unwrap();
            double.factorize(&col_ptr, &row_idx, &vals).unwrap();
            let analysis = Ldlt::analyse(n, &col_ptr, &row_idx, perm).unwrap();
            let mut single = LdltSingle::new(analysis);
            assert!(single.solve_in_place(&mut vec![1.0; n]).is_err());
            single.factorize(&col_ptr, &row_idx, &vals, true).unwrap();
            assert_eq!(single.factor_nnz(), double.factor_nnz());
            // Tiny and large right-hand sides: the scaling keeps both in range.
            for scale in [1e-30, 1.0, 1e30] {
                let b: Vec<f64> = (0..n).map(|i| scale * (1.0 + (i % 7) as f64)).collect();
                let (mut x64, mut x32) = (b.clone(), b.clone());
                double.solve_in_place(&mut x64).unwrap();
                single.solve_in_place(&mut x32).unwrap();
                let d = x64
                    .iter()
                    .zip(&x32)
                    .fold(0.0f64, |m, (a, c)| m.max((a - c).abs()));
                assert!(d <= 1e-5 * max_abs(&x64), "scale {scale:e}: {d:e}");
                assert!(d > 0.0, "the single solve is not rounded to f32");
            }
            let mut zero = vec![0.0; n];
            single.solve_in_place(&mut zero).unwrap();
            assert!(zero.iter().all(|&v| v == 0.0));
        }
    }

    /// The trailing block of either factor: `L₂₂ D₂ L₂₂ᵀ` inverts the trailing block of
    /// `A⁻¹` (`A⁻¹ [0; S x₂]` is `x₂` on the last `m` unknowns), and between the two
    /// halves of a solve `L₂₂⁻ᵀ D₂⁻¹ f₂` is the tail of the solution and `L₂₂⁻¹` the
    /// forward sweep of a right-hand side on the tail alone.
    #[test]
    fn trailing_factor_gives_the_schur_complement_and_the_tail() {
        let (n, col_ptr, row_idx, vals) = spd(12);
        let mut double = Ldlt::analyse(n, &col_ptr, &row_idx, None).unwrap();
        double.factorize(&col_ptr, &row_idx, &vals).unwrap();
        let mut single = LdltSingle::new(Ldlt::analyse(n, &col_ptr, &row_idx, None).unwrap());
        single.factorize(&col_ptr, &row_idx, &vals, true).unwrap();
        let order = double.permutation().unwrap().to_vec();
        for m in [1, 7, n / 3, n] {
            let tail = &order[n - m..];
            let xt: Vec<f64> = (0..m).map(|i| 1.0 + ((i * 37) % 11) as f64).collect();
            for (tol, t) in [
                (1e-10, double.trailing_factor(m).unwrap()),
                (1e-4, single.trailing_factor(m).unwrap()),
            ] {
                assert_eq!(t.len(), m);
                let s = t.schur_complement(Par::Seq);
                let mut rhs = vec![0.0; n];
                for (i, &e) in tail.iter().enumerate() {
                    rhs[e] = (0..m).map(|j| s[j * m + i] * xt[j]).sum();
                }
                double.solve_in_place(&mut rhs).unwrap();
                for (i, &e) in tail.iter().enumerate() {
                    let d = (rhs[e] - xt[i]).abs() / 11.0;
                    assert!(d < tol, "m {m}: {d:e}");
                }
            }
            // Two halves of the double solve with the tail from the trailing block.
            let t = double.trailing_factor(m).unwrap();
            let b: Vec<f64> = (0..n).map(|i| ((i * 13) % 9) as f64 - 4.0).collect();
            let mut x = b.clone();
            double.solve_in_place(&mut x).unwrap();
            let mut f = b.clone();
            double.forward_solve_in_place(&mut f).unwrap();
            let mut ft = f[n - m..].to_vec();
            t.backward(&mut ft);
            for (i, &e) in tail.iter().enumerate() {
                assert!((ft[i] - x[e]).abs() < 1e-10 * max_abs(&x), "m {m}");
            }
            double.backward_solve_in_place(&mut f).unwrap();
            assert!(
                f.iter()
                    .zip(&x)
                    .all(|(a, c)| (a - c).abs() < 1e-12 * max_abs(&x))
            );
            let mut on_tail = vec![0.0; n];
            for (i, &e) in tail.iter().enumerate() {
                on_tail[e] = xt[i];
            }
            double.forward_solve_in_place(&mut on_tail).unwrap();
            let mut yt = xt.clone();
            t.forward(&mut yt);
            assert!(on_tail[..n - m].iter().all(|&v| v == 0.0));
            for (a, c) in on_tail[n - m..].iter().zip(&yt) {
                assert!((a - c).abs() < 1e-12 * max_abs(&yt), "m {m}");
            }
        }
        assert!(single.trailing_factor(n + 1).is_err());
    }

    /// An indefinite matrix is refused when asked to be positive; a value beyond the range
    /// of `f32` always.
    #[test]
    fn non_positive_pivot_and_overflow_are_errors() {
        let (n, col_ptr, row_idx, mut vals) = spd(6);
        let analysis = || Ldlt::analyse(n, &col_ptr, &row_idx, None).unwrap();
        let mut single = LdltSingle::new(analysis());
        let last = vals.len() - 1;
        vals[last] = -50.0;
        let e = single
            .factorize(&col_ptr, &row_idx, &vals, true)
            .unwrap_err();
        assert!(e.0.contains("pivot"), "{e}");
        assert!(!single.is_factored());
        single.factorize(&col_ptr, &row_idx, &vals, false).unwrap();
        vals[0] = 1e300;
        let e = single
            .factorize(&col_ptr, &row_idx, &vals, false)
            .unwrap_err();
        assert!(e.0.contains("single precision"), "{e}");
        let e = single
            .factorize(&col_ptr[..n], &row_idx, &vals, false)
            .unwrap_err();
        assert!(e.0.contains("columns"), "{e}");
    }
}
