//! The direct solve on the coarsest level: sparse Cholesky `P A Pᵀ = L Lᵀ` (faer, AMD
//! ordering). The symbolic factorization is computed once; new values on the same pattern
//! only refactorize numerically.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use crate::csr::CsrMatrix;
use crate::error::{AmgError, Result};

/// Sparse Cholesky factorization of a symmetric matrix stored in full CSR form.
#[derive(Debug)]
pub(crate) struct CoarseSolver {
    n: usize,
    level: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Position in the CSR values of every upper-triangle entry.
    src: Vec<usize>,
    upper: Vec<f64>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
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
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_cholesky(
            sym,
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| AmgError::Input(format!("coarse symbolic Cholesky: {e:?}")))?;
        let nnz = row_idx.len();
        Ok(Self {
            n,
            level,
            col_ptr,
            row_idx,
            src,
            upper: vec![0.0; nnz],
            symbolic,
            l_values: Vec::new(),
        })
    }

    /// Entries of the factor `L`.
    pub(crate) fn factor_nnz(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Numeric factorization of `a` (the matrix given to [`Self::new`], new values).
    pub(crate) fn factorize(&mut self, a: &CsrMatrix) -> Result<()> {
        let vals = a.values();
        for (u, &s) in self.upper.iter_mut().zip(&self.src) {
            *u = vals[s];
        }
        let sym = SymbolicSparseColMatRef::new_checked(
            self.n,
            self.n,
            &self.col_ptr,
            None,
            &self.row_idx,
        );
        let mat = SparseColMatRef::new(sym, &self.upper);
        self.l_values.resize(self.symbolic.len_val(), 0.0);
        let req = self
            .symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default());
        let mut mem = MemBuffer::try_new(req)
            .map_err(|_| AmgError::Input("out of memory in the coarse factorization".into()))?;
        let res = self.symbolic.factorize_numeric_llt(
            &mut self.l_values,
            mat,
            Side::Upper,
            Default::default(),
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        );
        match res {
            Ok(_) => Ok(()),
            Err(faer::linalg::solvers::LltError::NonPositivePivot { index }) => {
                // faer 0.24 counts the failing pivot from 1 in the simplicial factorization
                // and from 0 in the supernodal one.
                let k = match self.symbolic.raw() {
                    SymbolicCholeskyRaw::Simplicial(_) => index.saturating_sub(1),
                    SymbolicCholeskyRaw::Supernodal(_) => index,
                }
                .min(self.n.saturating_sub(1));
                let equation = match self.symbolic.perm() {
                    Some(p) => p.arrays().0[k],
                    None => k,
                };
                Err(AmgError::CoarseNotPositiveDefinite {
                    level: self.level,
                    size: self.n,
                    equation,
                })
            }
        }
    }

    /// Solve in place (`rhs` holds `b` on entry and `x` on return).
    pub(crate) fn solve(&self, rhs: &mut [f64], mem: &mut MemBuffer) {
        let llt = LltRef::<'_, usize, f64>::new(&self.symbolic, &self.l_values);
        let n = self.n;
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(mem),
        );
    }

    /// Scratch buffer for [`Self::solve`].
    pub(crate) fn solve_buffer(&self) -> Result<MemBuffer> {
        MemBuffer::try_new(self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq))
            .map_err(|_| AmgError::Input("out of memory for the coarse solve".into()))
    }
}
