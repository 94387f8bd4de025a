//! The pattern of a symmetric matrix stored as its upper triangle in compressed sparse
//! column (CSC) form: column `j` holds the rows `i ≤ j` of its stored entries,
//! `row_idx[col_ptr[j]..col_ptr[j + 1]]`, increasing. The values of a matrix on the
//! pattern are one array alongside `row_idx`; the entry `(i, j)` stands for `(j, i)` too.

use faer::sparse::SymbolicSparseColMatRef;

/// Upper-triangle CSC pattern of a symmetric `n × n` matrix (see the module docs).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct UpperPattern {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl UpperPattern {
    /// The pattern with column offsets `col_ptr` (length `n + 1`) and row indices
    /// `row_idx`.
    ///
    /// # Panics
    /// When the arrays do not form a valid upper-triangle pattern: wrong lengths,
    /// decreasing offsets, rows out of range, below the diagonal, unsorted or repeated
    /// (the invariants faer's factorizations rely on).
    pub fn new(n: usize, col_ptr: Vec<usize>, row_idx: Vec<usize>) -> Self {
        assert_eq!(
            col_ptr.len(),
            n + 1,
            "column offsets of an {n} × {n} pattern"
        );
        assert_eq!(col_ptr[n], row_idx.len(), "last column offset = entries");
        for j in 0..n {
            assert!(col_ptr[j] <= col_ptr[j + 1], "column offsets increase");
            let rows = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            assert!(
                rows.windows(2).all(|w| w[0] < w[1]) && rows.last().is_none_or(|&r| r <= j),
                "rows of column {j} increase and lie on or above the diagonal"
            );
        }
        Self {
            n,
            col_ptr,
            row_idx,
        }
    }

    /// Rows and columns.
    pub fn dim(&self) -> usize {
        self.n
    }
    /// Stored entries (upper triangle with the diagonal).
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
    /// Column offsets (length `n + 1`).
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }
    /// Row index of each stored entry, increasing within each column.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }
    /// The pattern as faer's symbolic matrix (the upper triangle: `faer::Side::Upper`).
    pub fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }

    /// `y += A x` for the symmetric matrix with these upper-triangle `values`, column by
    /// column (`y_i += a_ij x_j` and, off the diagonal, `y_j += a_ij x_i`).
    pub fn mul_add(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        for c in 0..self.n {
            for p in self.col_ptr[c]..self.col_ptr[c + 1] {
                let r = self.row_idx[p];
                y[r] += values[p] * x[c];
                if r != c {
                    y[c] += values[p] * x[r];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_uses_both_triangles() {
        // [[2, 1, 0], [1, 3, 4], [0, 4, 5]]
        let p = UpperPattern::new(3, vec![0, 1, 3, 5], vec![0, 0, 1, 1, 2]);
        let mut y = vec![1.0; 3];
        p.mul_add(&[2.0, 1.0, 3.0, 4.0, 5.0], &[1.0, 2.0, 3.0], &mut y);
        assert_eq!(y, vec![1.0 + 4.0, 1.0 + 1.0 + 6.0 + 12.0, 1.0 + 8.0 + 15.0]);
        assert_eq!((p.dim(), p.nnz()), (3, 5));
    }

    #[test]
    #[should_panic(expected = "on or above the diagonal")]
    fn rows_below_the_diagonal_are_refused() {
        UpperPattern::new(2, vec![0, 1, 2], vec![0, 0]).symbolic();
        UpperPattern::new(2, vec![0, 2, 3], vec![0, 1, 1]);
    }
}
