//! The direct solve on the coarsest level: sparse Cholesky `P A Pᵀ = L Lᵀ` (AMD ordering,
//! [`porofrac_sparse::Cholesky`]) of the upper triangle of the coarsest operator. The
//! symbolic factorization is computed once; new values on the same pattern only
//! refactorize numerically.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SparseColMatRef;
use faer::{Par, Side};
use porofrac_sparse::{Cholesky, CholeskyError, UpperPattern};

use crate::csr::CsrMatrix;
use crate::error::{AmgError, Result};

/// Sparse Cholesky factorization of a symmetric matrix stored in full CSR form.
#[derive(Debug)]
pub(crate) struct CoarseSolver {
    level: usize,
    /// The upper triangle's pattern.
    upper: UpperPattern,
    /// Position in the CSR values of every upper-triangle entry.
    src: Vec<usize>,
    values: Vec<f64>,
    cholesky: Cholesky,
}

impl CoarseSolver {
    /// Symbolic analysis of `a` (level `level` of the hierarchy, for messages).
    pub(crate) fn new(a: &CsrMatrix, level: usize) -> Result<Self> {
        let n = a.nrows();
        // Upper-triangle column j = the entries of row j with column ≤ j (symmetry).
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::new();
        let mut src = Vec::new();
        for j in 0..n {
            let mut k = 0;
            a.for_each_col(j, |i| {
                if i as usize <= j {
                    row_idx.push(i as usize);
                    src.push(a.row_ptr()[j] + k);
                }
                k += 1;
            });
            col_ptr.push(row_idx.len());
        }
        let upper = UpperPattern::new(n, col_ptr, row_idx);
        let cholesky =
            Cholesky::analyse(upper.symbolic(), Side::Upper, None).map_err(|e| match e {
                CholeskyError::Symbolic(e) => {
                    AmgError::Input(format!("coarse symbolic Cholesky: {e:?}"))
                }
                e => AmgError::Input(format!("coarse symbolic Cholesky: {e}")),
            })?;
        let nnz = upper.nnz();
        Ok(Self {
            level,
            upper,
            src,
            values: vec![0.0; nnz],
            cholesky,
        })
    }

    /// Entries of the factor `L`.
    pub(crate) fn factor_nnz(&self) -> usize {
        self.cholesky.factor_nnz()
    }

    /// Numeric factorization of `a` (the matrix given to [`Self::new`], new values).
    pub(crate) fn factorize(&mut self, a: &CsrMatrix) -> Result<()> {
        let vals = a.values();
        for (u, &s) in self.values.iter_mut().zip(&self.src) {
            *u = vals[s];
        }
        let mat = SparseColMatRef::new(self.upper.symbolic(), &self.values);
        self.cholesky.factorize(mat, Par::Seq).map_err(|e| match e {
            CholeskyError::NonPositivePivot { index, .. } => AmgError::CoarseNotPositiveDefinite {
                level: self.level,
                size: self.upper.dim(),
                equation: index,
            },
            _ => AmgError::Input("out of memory in the coarse factorization".into()),
        })
    }

    /// Solve in place (`rhs` holds `b` on entry and `x` on return).
    pub(crate) fn solve(&self, rhs: &mut [f64], mem: &mut MemBuffer) {
        // Invariant: the hierarchy solves only after a successful factorization, with a
        // vector of the coarse size and the buffer of `solve_buffer`.
        self.cholesky
            .solve_in_place_with(rhs, Par::Seq, MemStack::new(mem))
            .expect("coarse solve after a successful factorization");
    }

    /// Scratch buffer for [`Self::solve`].
    pub(crate) fn solve_buffer(&self) -> Result<MemBuffer> {
        MemBuffer::try_new(self.cholesky.solve_scratch(1, Par::Seq))
            .map_err(|_| AmgError::Input("out of memory for the coarse solve".into()))
    }
}
