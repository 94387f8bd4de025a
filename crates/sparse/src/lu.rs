//! Sparse LU factorization with partial pivoting of a general square matrix, the
//! symbolic analysis done once per pattern and kept.
//!
//! `P A Q = L U` by faer (column ordering `Q` by COLAMD, row pivoting `P` chosen during
//! the numeric factorization). For matrices that are not symmetric (a non-symmetric
//! Nitsche term, say), where [`crate::Cholesky`] and [`crate::Ldlt`] do not apply.
//! [`Lu::analyse`] takes the pattern of the whole matrix; [`Lu::factorize`] computes
//! the numbers for any values on it; [`Lu::solve_in_place`] solves `A x = b`.

use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::LuError as FaerLuError;
use faer::sparse::linalg::solvers::{Lu as FaerLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut};

/// A failure of [`Lu`].
#[derive(Debug, Clone, Copy, thiserror::Error)]
pub enum LuError {
    /// faer's symbolic analysis failed (out of memory or an index overflow).
    #[error("symbolic LU: {0:?}")]
    Symbolic(faer::sparse::FaerError),
    /// The matrix is structurally singular: no pivot for column `index`.
    #[error("the matrix is structurally singular at equation {index}")]
    StructurallySingular {
        /// The column without a pivot.
        index: usize,
    },
    /// faer's numeric factorization failed otherwise (out of memory).
    #[error("numeric LU: {0:?}")]
    Numeric(faer::sparse::FaerError),
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

/// Sparse LU with the symbolic analysis kept (see the module docs).
pub struct Lu {
    symbolic: SymbolicLu<usize>,
    lu: Option<FaerLu<usize, f64>>,
    n: usize,
    numeric: usize,
}

impl std::fmt::Debug for Lu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lu")
            .field("n", &self.n)
            .field("numeric", &self.numeric)
            .finish()
    }
}

impl Lu {
    /// Symbolic analysis of the square pattern `pattern`.
    pub fn analyse(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<Self, LuError> {
        let n = pattern.ncols();
        if pattern.nrows() != n {
            return Err(LuError::Dimension {
                what: "rows of the pattern",
                got: pattern.nrows(),
                want: n,
            });
        }
        let symbolic = SymbolicLu::try_new(pattern).map_err(LuError::Symbolic)?;
        Ok(Self {
            symbolic,
            lu: None,
            n,
            numeric: 0,
        })
    }

    /// Unknowns.
    pub fn dim(&self) -> usize {
        self.n
    }
    /// Successful numeric factorizations.
    pub fn numeric_factorizations(&self) -> usize {
        self.numeric
    }
    /// Whether the last numeric factorization succeeded.
    pub fn is_factored(&self) -> bool {
        self.lu.is_some()
    }

    /// Numeric factorization of `matrix` (values on the analysed pattern), on faer's
    /// global parallelism.
    pub fn factorize(&mut self, matrix: SparseColMatRef<'_, usize, f64>) -> Result<(), LuError> {
        self.lu = None;
        if matrix.nrows() != self.n || matrix.ncols() != self.n {
            return Err(LuError::Dimension {
                what: "matrix",
                got: matrix.ncols(),
                want: self.n,
            });
        }
        let lu =
            FaerLu::try_new_with_symbolic(self.symbolic.clone(), matrix).map_err(|e| match e {
                FaerLuError::SymbolicSingular { index } => LuError::StructurallySingular { index },
                FaerLuError::Generic(e) => LuError::Numeric(e),
            })?;
        self.lu = Some(lu);
        self.numeric += 1;
        Ok(())
    }

    /// Solve `A x = b` in place (`rhs` holds `b` on entry and `x` on return), on faer's
    /// global parallelism.
    pub fn solve_in_place(&self, rhs: &mut [f64]) -> Result<(), LuError> {
        let lu = self.lu.as_ref().ok_or(LuError::NotFactored)?;
        if rhs.len() != self.n {
            return Err(LuError::Dimension {
                what: "right-hand side",
                got: rhs.len(),
                want: self.n,
            });
        }
        let n = self.n;
        lu.solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(rhs, n, 1));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-symmetric tridiagonal matrix: solved to round-off, refactorized with new
    /// values on the kept analysis.
    #[test]
    fn solves_a_non_symmetric_matrix() {
        let n: usize = 40;
        let (mut cp, mut ri) = (vec![0], Vec::new());
        for j in 0..n {
            for i in j.saturating_sub(1)..(j + 2).min(n) {
                ri.push(i);
            }
            cp.push(ri.len());
        }
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &cp, None, &ri);
        let mut lu = Lu::analyse(sym).unwrap();
        for d in [3.0, 5.0] {
            let mut vals = Vec::new();
            for j in 0..n {
                for &i in &ri[cp[j]..cp[j + 1]] {
                    vals.push(if i == j {
                        d
                    } else if i < j {
                        -1.0
                    } else {
                        0.5
                    });
                }
            }
            lu.factorize(SparseColMatRef::new(sym, &vals)).unwrap();
            let b: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
            let mut x = b.clone();
            lu.solve_in_place(&mut x).unwrap();
            let mut ax = vec![0.0; n];
            for j in 0..n {
                for q in cp[j]..cp[j + 1] {
                    ax[ri[q]] += vals[q] * x[j];
                }
            }
            let err = ax
                .iter()
                .zip(&b)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12 * n as f64, "{err}");
        }
        assert_eq!(lu.numeric_factorizations(), 2);
    }
}
