//! Sparse Cholesky factorization of a symmetric positive definite matrix, the symbolic
//! analysis done once per pattern and kept.
//!
//! With a fill-reducing permutation `P` (AMD, or an elimination order of the caller),
//!
//! ```text
//!   P A Pᵀ = L Lᵀ ,      L lower triangular with a positive diagonal,
//! ```
//!
//! computed by faer's sparse Cholesky (simplicial or supernodal, faer's choice by the
//! flop count). [`Cholesky::analyse`] takes the pattern of one triangle of `A` (`Side`:
//! which one faer reads; the other may be stored or not) and computes the ordering, the
//! elimination tree and the pattern of `L`; [`Cholesky::factorize`] computes the numbers
//! for any values on that pattern, as often as they change; [`Cholesky::solve_in_place`]
//! solves `A x = b` by `x = Pᵀ L⁻ᵀ L⁻¹ P b`. Parallelism is an argument of every numeric
//! step; the caller may own the scratch memory (the `*_scratch` sizes and the `*_with`
//! variants) or let each call allocate it.
//!
//! A pivot that is not positive fails the factorization with
//! [`CholeskyError::NonPositivePivot`], which names the unknown in the caller's
//! numbering (faer counts the failing step from 1 in its simplicial factorization and
//! from 0 in its supernodal one; the step is mapped back through `P` here).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::LltError;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use crate::ordering::{PermutationError, symmetric_ordering};

/// A failure of [`Cholesky`].
#[derive(Debug, Clone, Copy, thiserror::Error)]
pub enum CholeskyError {
    /// The caller's elimination order is not a permutation of the unknowns.
    #[error(transparent)]
    Ordering(#[from] PermutationError),
    /// faer's symbolic analysis failed (out of memory or an index overflow).
    #[error("symbolic Cholesky: {0:?}")]
    Symbolic(faer::sparse::FaerError),
    /// Scratch or factor memory could not be allocated.
    #[error("out of memory")]
    OutOfMemory,
    /// The pivot of unknown `index` (the caller's numbering) is not positive: the matrix
    /// is not positive definite. `source` is faer's error, with its own step count.
    #[error("the pivot of unknown {index} is not positive")]
    NonPositivePivot {
        /// The unknown whose pivot failed.
        index: usize,
        /// faer's error.
        source: LltError,
    },
    /// A matrix or vector does not fit the analysed pattern.
    #[error("{what} of size {got}, the factorization was analysed for {want}")]
    Dimension {
        /// What did not fit.
        what: &'static str,
        /// Its size.
        got: usize,
        /// The size of the analysed pattern.
        want: usize,
    },
    /// A solve without a successful numeric factorization.
    #[error("solve before a successful factorization")]
    NotFactored,
}

/// Sparse Cholesky factorization with the symbolic analysis kept (see the module docs).
#[derive(Debug)]
pub struct Cholesky {
    symbolic: SymbolicCholesky<usize>,
    side: Side,
    n: usize,
    nnz: usize,
    values: Vec<f64>,
    factored: bool,
    numeric: usize,
}

impl Cholesky {
    /// Symbolic analysis of the `n × n` pattern `pattern`, of which faer reads the
    /// triangle `side`; `perm` is the elimination order (`perm[k]` the unknown eliminated
    /// `k`-th, checked by [`crate::ordering::inverse_permutation`]), `None` for AMD.
    pub fn analyse(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        side: Side,
        perm: Option<&[usize]>,
    ) -> Result<Self, CholeskyError> {
        let n = pattern.ncols();
        if pattern.nrows() != n {
            return Err(CholeskyError::Dimension {
                what: "rows of the pattern",
                got: pattern.nrows(),
                want: n,
            });
        }
        let mut inverse = Vec::new();
        let ordering = symmetric_ordering(perm, &mut inverse, n)?;
        let symbolic =
            factorize_symbolic_cholesky(pattern, side, ordering, CholeskySymbolicParams::default())
                .map_err(CholeskyError::Symbolic)?;
        Ok(Self {
            symbolic,
            side,
            n,
            nnz: pattern.compute_nnz(),
            values: Vec::new(),
            factored: false,
            numeric: 0,
        })
    }

    /// Unknowns.
    pub fn dim(&self) -> usize {
        self.n
    }
    /// Stored entries of the analysed pattern.
    pub fn pattern_nnz(&self) -> usize {
        self.nnz
    }
    /// Stored entries of the factor `L`.
    pub fn factor_nnz(&self) -> usize {
        self.symbolic.len_val()
    }
    /// The elimination order: `perm[k]` is the unknown eliminated `k`-th (`None`: the
    /// identity).
    pub fn permutation(&self) -> Option<&[usize]> {
        self.symbolic.perm().map(|p| p.arrays().0)
    }
    /// Whether the last numeric factorization succeeded.
    pub fn is_factored(&self) -> bool {
        self.factored
    }
    /// Numeric factorizations attempted.
    pub fn numeric_factorizations(&self) -> usize {
        self.numeric
    }

    /// Scratch memory of [`Self::factorize_with`] on `par`.
    pub fn factorize_scratch(&self, par: Par) -> StackReq {
        self.symbolic
            .factorize_numeric_llt_scratch::<f64>(par, Default::default())
    }

    /// Numeric factorization of `matrix` (values on the analysed pattern) on `par`, with
    /// scratch memory allocated for the call.
    pub fn factorize(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        par: Par,
    ) -> Result<(), CholeskyError> {
        self.factored = false;
        let mut mem = MemBuffer::try_new(self.factorize_scratch(par))
            .map_err(|_| CholeskyError::OutOfMemory)?;
        self.factorize_with(matrix, par, MemStack::new(&mut mem))
    }

    /// [`Self::factorize`] with the caller's scratch memory (at least
    /// [`Self::factorize_scratch`]).
    pub fn factorize_with(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        par: Par,
        stack: &mut MemStack,
    ) -> Result<(), CholeskyError> {
        self.factored = false;
        if matrix.nrows() != self.n || matrix.ncols() != self.n {
            return Err(CholeskyError::Dimension {
                what: "matrix",
                got: matrix.ncols(),
                want: self.n,
            });
        }
        self.values.resize(self.symbolic.len_val(), 0.0);
        let res = self.symbolic.factorize_numeric_llt(
            &mut self.values,
            matrix,
            self.side,
            Default::default(),
            par,
            stack,
            Default::default(),
        );
        self.numeric += 1;
        match res {
            Ok(_) => {
                self.factored = true;
                Ok(())
            }
            Err(source) => Err(self.pivot_error(source)),
        }
    }

    /// The error of a failed numeric factorization, the failing step mapped to the
    /// caller's numbering.
    fn pivot_error(&self, source: faer::linalg::cholesky::llt::factor::LltError) -> CholeskyError {
        let faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } = source;
        let step = match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(_) => index.saturating_sub(1),
            SymbolicCholeskyRaw::Supernodal(_) => index,
        }
        .min(self.n.saturating_sub(1));
        let index = match self.permutation() {
            Some(p) => p[step],
            None => step,
        };
        CholeskyError::NonPositivePivot {
            index,
            source: LltError::Numeric(source),
        }
    }

    /// Scratch memory of [`Self::solve_in_place_with`] for `nrhs` right-hand sides on
    /// `par`.
    pub fn solve_scratch(&self, nrhs: usize, par: Par) -> StackReq {
        self.symbolic.solve_in_place_scratch::<f64>(nrhs, par)
    }

    /// Solve `A x = b` in place (`rhs` holds `b` on entry and `x` on return) on `par`,
    /// with scratch memory allocated for the call.
    pub fn solve_in_place(&self, rhs: &mut [f64], par: Par) -> Result<(), CholeskyError> {
        let mut mem = MemBuffer::try_new(self.solve_scratch(1, par))
            .map_err(|_| CholeskyError::OutOfMemory)?;
        self.solve_in_place_with(rhs, par, MemStack::new(&mut mem))
    }

    /// [`Self::solve_in_place`] with the caller's scratch memory (at least
    /// [`Self::solve_scratch`] of one right-hand side).
    pub fn solve_in_place_with(
        &self,
        rhs: &mut [f64],
        par: Par,
        stack: &mut MemStack,
    ) -> Result<(), CholeskyError> {
        if !self.factored {
            return Err(CholeskyError::NotFactored);
        }
        if rhs.len() != self.n {
            return Err(CholeskyError::Dimension {
                what: "right-hand side",
                got: rhs.len(),
                want: self.n,
            });
        }
        let n = self.n;
        LltRef::<'_, usize, f64>::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            par,
            stack,
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The upper triangle of the `n × n` matrix `tridiag(-1, d, -1)`.
    fn tridiagonal(n: usize, d: f64) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            if j > 0 {
                row_idx.push(j - 1);
                values.push(-1.0);
            }
            row_idx.push(j);
            values.push(d);
            col_ptr.push(row_idx.len());
        }
        (col_ptr, row_idx, values)
    }

    fn residual(col_ptr: &[usize], row_idx: &[usize], values: &[f64], x: &[f64], b: &[f64]) -> f64 {
        let mut ax = vec![0.0; x.len()];
        for j in 0..x.len() {
            for q in col_ptr[j]..col_ptr[j + 1] {
                let i = row_idx[q];
                ax[i] += values[q] * x[j];
                if i != j {
                    ax[j] += values[q] * x[i];
                }
            }
        }
        ax.iter()
            .zip(b)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn solves_and_refactorizes_with_the_kept_analysis() {
        let n = 50;
        for perm in [None, Some((0..n).rev().collect::<Vec<_>>())] {
            let (cp, ri, mut vals) = tridiagonal(n, 2.5);
            let sym = SymbolicSparseColMatRef::new_checked(n, n, &cp, None, &ri);
            let mut chol = Cholesky::analyse(sym, Side::Upper, perm.as_deref()).unwrap();
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            for (round, d) in [2.5, 4.0].into_iter().enumerate() {
                for v in vals.iter_mut().filter(|v| **v > 0.0) {
                    *v = d;
                }
                chol.factorize(SparseColMatRef::new(sym, &vals), Par::Seq)
                    .unwrap();
                let mut x = b.clone();
                chol.solve_in_place(&mut x, Par::Seq).unwrap();
                assert!(residual(&cp, &ri, &vals, &x, &b) < 1e-12 * n as f64);
                assert_eq!(chol.numeric_factorizations(), round + 1);
            }
        }
    }

    /// The upper triangle of the dense `n × n` matrix with `d` on the diagonal and `-1`
    /// elsewhere.
    fn dense(n: usize, d: f64) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for i in 0..=j {
                row_idx.push(i);
                values.push(if i == j { d } else { -1.0 });
            }
            col_ptr.push(row_idx.len());
        }
        (col_ptr, row_idx, values)
    }

    /// A diagonally dominant matrix but for a negative diagonal entry at unknown 7: every
    /// pivot eliminated before 7 is positive and 7's is negative, whatever the order, so
    /// the error names 7 — for a tridiagonal matrix (faer's simplicial factorization)
    /// and a dense one (supernodal), with AMD and with a given order.
    #[test]
    fn a_failing_pivot_names_its_unknown() {
        for (cp, ri, mut vals) in [tridiagonal(20, 3.0), dense(150, 200.0)] {
            let n = cp.len() - 1;
            vals[cp[8] - 1] = -3.0;
            let sym = SymbolicSparseColMatRef::new_checked(n, n, &cp, None, &ri);
            let reversed: Vec<usize> = (0..n).rev().collect();
            for perm in [None, Some(&reversed[..])] {
                let mut chol = Cholesky::analyse(sym, Side::Upper, perm).unwrap();
                match chol.factorize(SparseColMatRef::new(sym, &vals), Par::Seq) {
                    Err(CholeskyError::NonPositivePivot { index, .. }) => {
                        assert_eq!(index, 7, "n = {n}, perm = {}", perm.is_some());
                    }
                    other => panic!("expected a pivot error, got {other:?}"),
                }
                assert!(!chol.is_factored());
                let mut x = vec![0.0; n];
                assert!(matches!(
                    chol.solve_in_place(&mut x, Par::Seq),
                    Err(CholeskyError::NotFactored)
                ));
            }
        }
    }

    #[test]
    fn a_bad_ordering_is_an_error() {
        let (cp, ri, _) = tridiagonal(3, 2.0);
        let sym = SymbolicSparseColMatRef::new_checked(3, 3, &cp, None, &ri);
        assert!(matches!(
            Cholesky::analyse(sym, Side::Upper, Some(&[0, 1, 1])),
            Err(CholeskyError::Ordering(PermutationError::Entry {
                index: 2,
                value: 1
            }))
        ));
    }
}
