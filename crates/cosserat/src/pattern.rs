//! The block sparsity pattern of the Cosserat system and the sparse LU on it.
//!
//! Unknown `(c, a)` (cell `c`, generalised component `a`) is equation `c·n + a`. Two cells
//! couple when they share an element (a cell's gradient stencil, or the union of the two
//! stencils of an interior facet), so the pattern is a block pattern with dense `n × n`
//! blocks, built once from the cell neighbour lists and stored in compressed sparse column
//! form with sorted rows. Every assembly writes into the same value array
//! ([`BlockPattern::position`]); the LU's symbolic analysis (ordering, elimination
//! structure) is done once per pattern and reused by every numeric factorisation
//! ([`porofrac_sparse::Lu`]).

use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use porofrac_sparse::{Lu, LuError};

use crate::error::{CosseratError, Result};

/// Block compressed-column pattern (see the module docs).
#[derive(Clone, Debug)]
pub struct BlockPattern {
    /// Components per cell (block size).
    pub block: usize,
    /// Offsets into `cells`, one per cell plus one.
    pub nbr_pos: Vec<usize>,
    /// Sorted coupled cells of each cell (its own included).
    pub cells: Vec<usize>,
    /// Column pointers of the scalar CSC pattern.
    pub col_ptr: Vec<usize>,
    /// Row indices of the scalar CSC pattern.
    pub row_idx: Vec<usize>,
}

impl BlockPattern {
    /// A pattern from sorted, duplicate-free, symmetric neighbour lists.
    pub fn new(neighbours: &[Vec<usize>], block: usize) -> Self {
        let mut nbr_pos = vec![0];
        let mut cells = Vec::new();
        for nb in neighbours {
            cells.extend_from_slice(nb);
            nbr_pos.push(cells.len());
        }
        let n = block;
        let mut col_ptr = Vec::with_capacity(neighbours.len() * n + 1);
        let mut row_idx = Vec::with_capacity(cells.len() * n * n);
        col_ptr.push(0);
        for nb in neighbours {
            for _b in 0..n {
                for &r in nb {
                    for a in 0..n {
                        row_idx.push(r * n + a);
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        Self {
            block,
            nbr_pos,
            cells,
            col_ptr,
            row_idx,
        }
    }

    /// Number of equations.
    pub fn equations(&self) -> usize {
        self.col_ptr.len() - 1
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Position in the value array of the block (row cell `r`, column cell `c`): the entry
    /// `(r·n + a, c·n + b)` is at `position + b·len·n + a` with `len` = [`Self::column_len`].
    /// `None` when the cells do not couple.
    #[inline]
    pub fn position(&self, r: usize, c: usize) -> Option<usize> {
        let nb = &self.cells[self.nbr_pos[c]..self.nbr_pos[c + 1]];
        let p = nb.binary_search(&r).ok()?;
        Some(self.nbr_pos[c] * self.block * self.block + p * self.block)
    }

    /// Scalar rows per column of cell `c` (`len · n`).
    #[inline]
    pub fn column_len(&self, c: usize) -> usize {
        (self.nbr_pos[c + 1] - self.nbr_pos[c]) * self.block
    }

    /// Add a dense local matrix (column-major, `m × m`, `m = cells.len()·n`) over the sorted
    /// local cell list into `values`.
    pub fn add_local(&self, values: &mut [f64], cells: &[usize], local: &[f64]) {
        let n = self.block;
        let m = cells.len() * n;
        for (cj, &c) in cells.iter().enumerate() {
            let stride = self.column_len(c);
            for (ri, &r) in cells.iter().enumerate() {
                let pos = self
                    .position(r, c)
                    .expect("local cells couple by construction");
                for b in 0..n {
                    let col = (cj * n + b) * m + ri * n;
                    let dst = pos + b * stride;
                    for a in 0..n {
                        values[dst + a] += local[col + a];
                    }
                }
            }
        }
    }

    /// [`Self::add_local`] restricted to the column cells in `columns`, into `chunk`: the
    /// values of those columns, which start at `offset` in the full value array. With a
    /// non-empty `q` (`n × n`, column-major) the local matrix is `local ⊗ q`, `local` then
    /// `cells.len()²` (column-major over the cells).
    pub fn add_local_columns(
        &self,
        chunk: &mut [f64],
        offset: usize,
        columns: std::ops::Range<usize>,
        cells: &[usize],
        local: &[f64],
        q: &[f64],
    ) {
        let n = self.block;
        let nl = cells.len();
        if !q.is_empty() {
            for (cj, &c) in cells.iter().enumerate() {
                if !columns.contains(&c) {
                    continue;
                }
                let stride = self.column_len(c);
                for (ri, pos) in self.column_positions(c, cells).enumerate() {
                    let mv = local[cj * nl + ri];
                    if mv == 0.0 {
                        continue;
                    }
                    let pos = pos - offset;
                    for b in 0..n {
                        let dst = &mut chunk[pos + b * stride..pos + b * stride + n];
                        for (d, &qv) in dst.iter_mut().zip(&q[b * n..(b + 1) * n]) {
                            *d += mv * qv;
                        }
                    }
                }
            }
            return;
        }
        let m = nl * n;
        for (cj, &c) in cells.iter().enumerate() {
            if !columns.contains(&c) {
                continue;
            }
            let stride = self.column_len(c);
            for (ri, pos) in self.column_positions(c, cells).enumerate() {
                let pos = pos - offset;
                for b in 0..n {
                    let col = (cj * n + b) * m + ri * n;
                    let dst = pos + b * stride;
                    for a in 0..n {
                        chunk[dst + a] += local[col + a];
                    }
                }
            }
        }
    }

    /// [`Self::position`] of the blocks (row cell `r`, column cell `c`) for the sorted
    /// row cells `rows`, by one walk along the column's cells.
    ///
    /// # Panics
    /// When a row cell does not couple with `c` (the local cells of an element always do).
    fn column_positions<'a>(
        &'a self,
        c: usize,
        rows: &'a [usize],
    ) -> impl Iterator<Item = usize> + 'a {
        let nb = &self.cells[self.nbr_pos[c]..self.nbr_pos[c + 1]];
        let base = self.nbr_pos[c] * self.block * self.block;
        let mut p = 0;
        rows.iter().map(move |&r| {
            while p < nb.len() && nb[p] < r {
                p += 1;
            }
            assert!(
                p < nb.len() && nb[p] == r,
                "local cells couple by construction"
            );
            base + p * self.block
        })
    }

    /// Positions of the diagonal entries, one per equation.
    pub fn diagonal_positions(&self) -> Vec<usize> {
        let n = self.block;
        let cells = self.nbr_pos.len() - 1;
        let mut d = Vec::with_capacity(cells * n);
        for c in 0..cells {
            let pos = self.position(c, c).expect("diagonal block present");
            for a in 0..n {
                d.push(pos + a * self.column_len(c) + a);
            }
        }
        d
    }

    /// `y = A x` for the matrix with these `values`.
    pub fn mul(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for j in 0..self.equations() {
            let xj = x[j];
            if xj == 0.0 {
                continue;
            }
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                y[self.row_idx[p]] += values[p] * xj;
            }
        }
    }

    /// `xᵀ A y`.
    pub fn form(&self, values: &[f64], x: &[f64], y: &[f64]) -> f64 {
        let mut s = 0.0;
        for j in 0..self.equations() {
            let mut col = 0.0;
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                col += values[p] * x[self.row_idx[p]];
            }
            s += col * y[j];
        }
        s
    }

    fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        let n = self.equations();
        SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx)
    }
}

/// Sparse LU with partial pivoting ([`porofrac_sparse::Lu`]) on a [`BlockPattern`], the
/// symbolic analysis shared by every factorisation of one pattern. Fits the non-symmetric
/// Nitsche matrix.
#[derive(Debug)]
pub struct SparseLu {
    lu: Lu,
}

fn lu_error(e: LuError) -> CosseratError {
    match e {
        LuError::StructurallySingular { index } => CosseratError::Solve(format!(
            "the matrix is structurally singular at equation {index}"
        )),
        LuError::Symbolic(e) | LuError::Numeric(e) => CosseratError::Solve(format!("{e:?}")),
        e => CosseratError::Solve(e.to_string()),
    }
}

impl SparseLu {
    /// Symbolic analysis of `pattern`.
    pub fn new(pattern: &BlockPattern) -> Result<Self> {
        Ok(Self {
            lu: Lu::analyse(pattern.symbolic()).map_err(lu_error)?,
        })
    }

    /// Numeric factorisation of the matrix with `values` on `pattern`.
    pub fn factorize(&mut self, pattern: &BlockPattern, values: &[f64]) -> Result<()> {
        if values.len() != pattern.nnz() || pattern.equations() != self.lu.dim() {
            return Err(CosseratError::Input {
                what: format!(
                    "factorize: {} values for a pattern of {} entries ({} equations, LU built for {})",
                    values.len(),
                    pattern.nnz(),
                    pattern.equations(),
                    self.lu.dim()
                ),
            });
        }
        let mat = SparseColMatRef::new(pattern.symbolic(), values);
        self.lu.factorize(mat).map_err(lu_error)
    }

    /// Solve in place; a non-finite result (a numerically singular matrix) is an error.
    pub fn solve_in_place(&self, rhs: &mut [f64]) -> Result<()> {
        if !self.lu.is_factored() {
            return Err(CosseratError::Solve("solve before factorisation".into()));
        }
        if rhs.len() != self.lu.dim() {
            return Err(CosseratError::Input {
                what: format!(
                    "right-hand side of length {}, want {}",
                    rhs.len(),
                    self.lu.dim()
                ),
            });
        }
        self.lu.solve_in_place(rhs).map_err(lu_error)?;
        if let Some(i) = rhs.iter().position(|v| !v.is_finite()) {
            return Err(CosseratError::Solve(format!(
                "non-finite solution at equation {i}: the system is singular (missing \
                 boundary conditions or zero moduli?)"
            )));
        }
        Ok(())
    }

    /// Numeric factorisations done so far.
    pub fn factorizations(&self) -> usize {
        self.lu.numeric_factorizations()
    }
}
