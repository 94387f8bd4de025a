//! Sparse `LDLᵀ` factorization of a symmetric matrix given by its upper triangle, with a
//! triangular solve for one right-hand side at a time (on two threads where the
//! elimination tree splits, see `Split`).
//!
//! Public for the other solvers of the workspace: [`Ldlt::analyse`] (pattern and an
//! optional elimination order, e.g. from [`crate::ordering::pattern_dissection`]),
//! [`Ldlt::factorize`] (values), [`Ldlt::solve_in_place`]; [`Ldlt::factor_nnz`] for the
//! fill.
//!
//! # Factorization
//!
//! With a fill-reducing permutation `P` (AMD, or one given by the caller),
//!
//! ```text
//!   P A Pᵀ = L D Lᵀ ,      L unit lower triangular, D diagonal,
//! ```
//!
//! computed by faer's supernodal sparse Cholesky without pivoting. It exists for every
//! symmetric ordering of a *quasi-definite* matrix `[[H, Bᵀ], [B, −G]]` with `H`, `G`
//! positive definite (Vanderbei 1995), the block systems of a monolithic Biot solve,
//! and for every symmetric positive definite matrix (then `D > 0`). The symbolic analysis
//! (elimination tree, supernodes) is done once per pattern; a numeric factorization
//! reuses it.
//!
//! # Solve
//!
//! `A x = b` is `x = Pᵀ L⁻ᵀ D⁻¹ L⁻¹ P b`. A time-stepping scheme that keeps its matrix
//! solves once per step with the same factors, so the solve is written for that case
//! directly on faer's supernodal storage: supernode `s` holds the columns
//! `start..start + w` of `L` as one dense column-major block of `w + r` rows, the `w × w`
//! unit lower triangle (with `D` on its diagonal) on top of the `r × w` block of the rows
//! `R_s` below it. The forward substitution `L y = P b` is, supernode by supernode,
//!
//! ```text
//!   y_top ← L_top⁻¹ y_top ,      y[R_s] ← y[R_s] − L_bot y_top ,
//! ```
//!
//! on a dense buffer `[y_top | 0]` of the supernode's `w + r` rows: the columns go in
//! groups of four, each group solving its `4 × 4` unit triangle and then updating the
//! contiguous rows below it (the rest of the triangle and the rows `R_s`) with one
//! four-column `axpy`; the buffer's lower part is added into `y[R_s]` once. `z = D⁻¹ y`
//! uses the inverse diagonal stored at factorization. The backward substitution
//! `Lᵀ x = z` runs the supernodes in reverse on the buffer `[D⁻¹ z_top | x[R_s]]`
//! (gathered once): the groups of four, from the last, subtract four dot products with
//! the contiguous rows below them, then solve their `4 × 4` transposed triangle,
//! `x_top ← L_top⁻ᵀ (z_top − L_botᵀ x[R_s])`. Every
//! entry of `L` is read once per sweep, `2 · nnz(L)` multiply–adds per solve, with no
//! allocation and no dispatch per supernode. The sweeps are compiled for the widest
//! vector instructions the processor has (`pulp` picks AVX2 or plain code at run time);
//! dot products sum in vector lanes, so the last bits of a solution may differ between
//! processors, never between runs on one.
//!
//! Two subtrees of the elimination tree that are not ancestors of one another touch
//! disjoint columns, and each writes (forward) or reads (backward) outside itself only
//! the rows of its ancestors. When the tree has two sets of whole subtrees of comparable
//! factor entries (`Split`, found once per pattern), each sweep runs the two sets on two
//! threads, the second on its own copy of the vector (its forward updates of the
//! ancestors' rows added after the join), and the remaining supernodes — the separators
//! above them — alone. The split depends on the factor's structure only, so a solution
//! does not depend on the number of threads.

use std::ops::Range;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SparseColMatRef;
use faer::sparse::SymbolicSparseColMatRef;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LdltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    factorize_symbolic_cholesky,
};
use faer::sparse::linalg::{SupernodalThreshold, SymbolicSupernodalParams};
use faer::{Conj, MatMut, Par, Side};
use pulp::Simd;

use crate::ordering::symmetric_ordering;

/// Supernode amalgamation (faer's rule: merge a child into its parent when the merged
/// block has `n` columns and a fraction of explicit zeros below the bound for `n`).
const RELAX: Option<&[(usize, f64)]> = Some(&[(4, 1.0), (16, 0.8), (48, 0.1), (usize::MAX, 0.05)]);

/// A failure of the factorization (a message naming the cause).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LdltError(
    /// The message.
    pub String,
);

impl std::fmt::Display for LdltError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for LdltError {}

/// The symbolic analysis and numeric factors of one sparsity pattern.
pub struct Ldlt {
    n: usize,
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    /// `1/D` in the permuted order (supernodal factors).
    inv_diag: Vec<f64>,
    /// Permuted work vector.
    work: Vec<f64>,
    /// Dense buffer of the rows below a supernode.
    tmp: Vec<f64>,
    /// Every supernode, ascending (the sequential sweeps).
    all: Vec<usize>,
    /// Two independent sets of subtrees of the supernodes, swept on two threads (see
    /// [`Split`]).
    split: Option<Split>,
    /// The work vector and dense buffer of the second subtree.
    work_b: Vec<f64>,
    tmp_b: Vec<f64>,
    /// Scratch of faer's numeric factorization and of its simplicial solve.
    mem: Option<MemBuffer>,
    par: Par,
    factored: bool,
    numeric: usize,
    solves: usize,
}

impl Ldlt {
    /// Symbolic analysis of the `n × n` matrix whose upper triangle has the CSC pattern
    /// (`col_ptr`, `row_idx`); `perm` is the elimination order (`perm[k]` eliminated
    /// `k`-th), `None` for AMD.
    pub fn analyse(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        perm: Option<&[usize]>,
    ) -> Result<Self, LdltError> {
        let sym = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let mut inverse = Vec::new();
        let ordering =
            symmetric_ordering(perm, &mut inverse, n).map_err(|e| LdltError(e.to_string()))?;
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            supernodal_params: SymbolicSupernodalParams { relax: RELAX },
            ..Default::default()
        };
        let symbolic = factorize_symbolic_cholesky(sym, Side::Upper, ordering, params)
            .map_err(|e| LdltError(format!("symbolic LDLᵀ: {e:?}")))?;
        let all = match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => (0..sn.n_supernodes()).collect(),
            SymbolicCholeskyRaw::Simplicial(_) => Vec::new(),
        };
        let split = match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => Split::find(
                sn.supernode_begin(),
                sn.supernode_end(),
                sn.col_ptr_for_row_idx(),
                sn.col_ptr_for_val(),
                sn.row_idx(),
            ),
            SymbolicCholeskyRaw::Simplicial(_) => None,
        };
        let nb = if split.is_some() { n } else { 0 };
        Ok(Self {
            n,
            symbolic,
            values: Vec::new(),
            inv_diag: Vec::new(),
            work: vec![0.0; n],
            tmp: Vec::new(),
            all,
            split,
            work_b: vec![0.0; nb],
            tmp_b: Vec::new(),
            mem: None,
            par: Par::Seq,
            factored: false,
            numeric: 0,
            solves: 0,
        })
    }

    /// Use `par` for the numeric factorization.
    pub fn set_parallelism(&mut self, par: Par) {
        self.par = par;
        self.mem = None;
    }
    /// The elimination order of the factors: `perm[k]` is the unknown eliminated `k`-th
    /// (`None`: the identity).
    pub fn permutation(&self) -> Option<&[usize]> {
        self.symbolic.perm().map(|p| p.arrays().0)
    }
    /// Stored entries of `L` (with `D` on its diagonal).
    pub fn factor_nnz(&self) -> usize {
        self.symbolic.len_val()
    }
    /// Multiply–adds of one numeric factorization, `Σ_j c_j (c_j − 1) / 2` over the
    /// columns `j` of the supernodal `L` with `c_j` stored entries (explicit zeros of
    /// amalgamated supernodes included), the dense kernels' work.
    pub fn multiply_adds(&self) -> f64 {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => {
                let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
                let rptr = sn.col_ptr_for_row_idx();
                (0..sn.n_supernodes())
                    .map(|s| {
                        let w = end[s] - begin[s];
                        let r = rptr[s + 1] - rptr[s];
                        (0..w)
                            .map(|k| {
                                let c = (w - k + r) as f64;
                                c * (c - 1.0) / 2.0
                            })
                            .sum::<f64>()
                    })
                    .sum()
            }
            SymbolicCholeskyRaw::Simplicial(sm) => {
                let cp = sm.col_ptr();
                (0..self.n)
                    .map(|j| {
                        let c = (cp[j + 1] - cp[j]) as f64;
                        c * (c - 1.0) / 2.0
                    })
                    .sum()
            }
        }
    }
    /// Numeric factorizations done.
    pub fn numeric_factorizations(&self) -> usize {
        self.numeric
    }
    /// Solves done.
    pub fn solves(&self) -> usize {
        self.solves
    }
    /// Whether every pivot of `D` is positive (the matrix is positive definite).
    pub fn pivots_positive(&self) -> bool {
        self.inv_diag.iter().all(|&d| d > 0.0)
    }
    /// Whether the first `p` pivots of `D` (in the elimination order) are positive and
    /// the others negative (see [`crate::ldlt_single::LdltSingle::factorize_signed`]).
    pub fn pivots_signed(&self, p: usize) -> bool {
        let p = p.min(self.inv_diag.len());
        self.inv_diag[..p].iter().all(|&d| d > 0.0) && self.inv_diag[p..].iter().all(|&d| d < 0.0)
    }
    /// Whether the last numeric factorization succeeded.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Numeric factorization of the matrix with the upper-triangle `values` of the
    /// analysed pattern (`col_ptr`, `row_idx`).
    pub fn factorize(
        &mut self,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
    ) -> Result<(), LdltError> {
        self.factored = false;
        let n = self.n;
        let sym = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let mat = SparseColMatRef::new(sym, values);
        self.values.resize(self.symbolic.len_val(), 0.0);
        let mem = match self.mem.take() {
            Some(m) => m,
            None => {
                let req = self
                    .symbolic
                    .factorize_numeric_ldlt_scratch::<f64>(self.par, Default::default())
                    .or(self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
                MemBuffer::try_new(req).map_err(|_| LdltError("out of memory".into()))?
            }
        };
        let mem = self.mem.insert(mem);
        let res = self.symbolic.factorize_numeric_ldlt(
            &mut self.values,
            mat,
            Side::Upper,
            Default::default(),
            self.par,
            MemStack::new(mem),
            Default::default(),
        );
        self.numeric += 1;
        if let Err(e) = res {
            return Err(LdltError(format!("{e:?}")));
        }
        self.inv_diag.clear();
        if let SymbolicCholeskyRaw::Supernodal(sn) = self.symbolic.raw() {
            self.inv_diag.resize(n, 0.0);
            let (begin, end, vptr) = (
                sn.supernode_begin(),
                sn.supernode_end(),
                sn.col_ptr_for_val(),
            );
            let mut widest = 0;
            for s in 0..sn.n_supernodes() {
                let (start, w) = (begin[s], end[s] - begin[s]);
                let m = (vptr[s + 1] - vptr[s]) / w.max(1);
                widest = widest.max(m);
                let block = &self.values[vptr[s]..vptr[s + 1]];
                for j in 0..w {
                    let d = block[j * m + j];
                    if !(d.is_finite() && d != 0.0) {
                        return Err(LdltError(format!("zero or non-finite pivot {d:e}")));
                    }
                    self.inv_diag[start + j] = 1.0 / d;
                }
            }
            self.tmp.resize(widest, 0.0);
            self.tmp_b.resize(widest, 0.0);
        }
        self.factored = true;
        Ok(())
    }

    /// The Schur complement `A₂₂ − A₂₁ A₁₁⁻¹ A₁₂` of the first `n − k` unknowns of the
    /// elimination order on the last `k`, read from the factors (`L₂₂ D₂ L₂₂ᵀ`): dense,
    /// column-major `k × k`, row and column `j` standing for the unknown eliminated
    /// `(n − k + j)`-th.
    ///
    /// With the unknowns coupled by a non-symmetric correction `E` ordered last, it gives
    /// the exact Schur complement `S + E_22` of `A + E` for a dense LU.
    pub fn trailing_schur_complement(&self, k: usize) -> Result<Vec<f64>, LdltError> {
        Ok(self.trailing_factor(k)?.schur_complement(self.par))
    }

    /// Solve `A X = B` in place for the `k` columns of `B` stored column-major in `rhs`
    /// (`n · k` values): faer's supernodal solve, blocked over the columns, the two
    /// halves of the columns in parallel.
    pub fn solve_columns_in_place(&mut self, rhs: &mut [f64], k: usize) -> Result<(), LdltError> {
        if !self.factored {
            return Err(LdltError("solve before a successful factorization".into()));
        }
        if rhs.len() != self.n * k {
            return Err(LdltError(format!(
                "right-hand sides of length {}, want {} × {k}",
                rhs.len(),
                self.n
            )));
        }
        if k == 0 {
            return Ok(());
        }
        self.solves += k;
        let (symbolic, values, n) = (&self.symbolic, &self.values[..], self.n);
        let solve = |cols: &mut [f64], k: usize| -> Result<(), LdltError> {
            if k == 0 {
                return Ok(());
            }
            let mut mem = MemBuffer::try_new(symbolic.solve_in_place_scratch::<f64>(k, Par::Seq))
                .map_err(|_| LdltError("out of memory".into()))?;
            LdltRef::<'_, usize, f64>::new(symbolic, values).solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(cols, n, k),
                Par::Seq,
                MemStack::new(&mut mem),
            );
            Ok(())
        };
        // The columns are independent: two halves, on two threads when there are (always
        // split the same way, so the result does not depend on the thread count).
        let half = k / 2;
        let (a, b) = rhs.split_at_mut(n * half);
        let (ra, rb) = rayon::join(|| solve(a, half), || solve(b, k - half));
        ra.and(rb)
    }

    /// Solve `A x = b` in place (`rhs` holds `b` on entry, `x` on return).
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LdltError> {
        if !self.factored {
            return Err(LdltError("solve before a successful factorization".into()));
        }
        if rhs.len() != self.n {
            return Err(LdltError(format!(
                "right-hand side of length {}, want {}",
                rhs.len(),
                self.n
            )));
        }
        self.solves += 1;
        if let SymbolicCholeskyRaw::Simplicial(_) = self.symbolic.raw() {
            // Only for an empty matrix (supernodal is forced).
            let ldlt = LdltRef::<'_, usize, f64>::new(&self.symbolic, &self.values);
            let mem = match self.mem.as_mut() {
                Some(m) => m,
                None => self.mem.insert(
                    MemBuffer::try_new(self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq))
                        .map_err(|_| LdltError("out of memory".into()))?,
                ),
            };
            let n = self.n;
            ldlt.solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(rhs, n, 1),
                Par::Seq,
                MemStack::new(mem),
            );
            return Ok(());
        }
        self.permute_in(rhs);
        self.sweep_forward();
        self.sweep_backward();
        self.permute_out(rhs);
        Ok(())
    }
}

/// The symbolic analysis, for numeric factors in another precision
/// ([`crate::ldlt_single`]).
impl Ldlt {
    pub(crate) fn symbolic(&self) -> &SymbolicCholesky<usize> {
        &self.symbolic
    }
}

/// The two halves of a solve and the trailing block of the factors, public for a solver
/// that corrects the unknowns eliminated last between the halves (see
/// [`crate::ldlt_single::TrailingFactor`]).
impl Ldlt {
    /// `rhs ← L⁻¹ P rhs` (on return in the elimination order). Counts as a solve.
    pub fn forward_solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LdltError> {
        self.forward_in_place(rhs)
    }

    /// `rhs ← Pᵀ L⁻ᵀ D⁻¹ rhs` (`rhs` in the elimination order on entry, as
    /// [`Ldlt::forward_solve_in_place`] left it).
    pub fn backward_solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LdltError> {
        self.backward_in_place(rhs)
    }

    /// The last `k` columns of the factors, dense.
    pub fn trailing_factor(
        &self,
        k: usize,
    ) -> Result<crate::ldlt_single::TrailingFactor, LdltError> {
        if !self.factored {
            return Err(LdltError(
                "trailing factor before a successful factorization".into(),
            ));
        }
        crate::ldlt_single::TrailingFactor::from_supernodal(&self.symbolic, &self.values, k)
    }
}

/// The two halves of a solve, for a solver that changes the vector between them
/// (`crate::lowrank`): `f = L⁻¹ P b` and `x = Pᵀ L⁻ᵀ D⁻¹ f`, `f` in the elimination
/// order; and `L⁻¹ P e_u` for unit vectors, which is zero outside the supernodes on the
/// path from the supernode of `u` to its root (the rows of `L` below a supernode belong
/// to its ancestors), so only those are swept.
impl Ldlt {
    /// `rhs ← L⁻¹ P rhs` (on return in the elimination order). Counts as a solve.
    pub fn forward_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LdltError> {
        self.check_supernodal(rhs.len())?;
        self.solves += 1;
        self.permute_in(rhs);
        self.sweep_forward();
        rhs.copy_from_slice(&self.work);
        Ok(())
    }

    /// `rhs ← Pᵀ L⁻ᵀ D⁻¹ rhs` (`rhs` in the elimination order on entry, as
    /// [`Ldlt::forward_in_place`] left it).
    pub fn backward_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LdltError> {
        self.check_supernodal(rhs.len())?;
        self.work.copy_from_slice(rhs);
        self.sweep_backward();
        self.permute_out(rhs);
        Ok(())
    }

    /// `1/D` in the elimination order.
    pub fn inverse_diagonal(&self) -> &[f64] {
        &self.inv_diag
    }

    /// `L⁻¹ P e_u` for every unknown `u` of `units` into the columns of `out`
    /// (column-major `n × units.len()`, in the elimination order, overwritten), swept over
    /// the path of supernodes from `u`'s to its root only, the columns on two threads.
    /// `paths[c]` receives the column ranges of the path of column `c` (outside them the
    /// column is zero). Counts as `units.len()` solves.
    pub fn forward_units(
        &mut self,
        units: &[usize],
        out: &mut [f64],
        paths: &mut Vec<Vec<Range<usize>>>,
    ) -> Result<(), LdltError> {
        let n = self.n;
        self.check_supernodal(n)?;
        if out.len() != n * units.len() || units.iter().any(|&u| u >= n) {
            return Err(LdltError(format!(
                "{} unit columns into {} values for {n} unknowns",
                units.len(),
                out.len()
            )));
        }
        self.solves += units.len();
        let SymbolicCholeskyRaw::Supernodal(sn) = self.symbolic.raw() else {
            return Err(LdltError("unit solves of a simplicial factor".into()));
        };
        let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
        let f = Factor::of(sn, &self.values, &self.inv_diag);
        let ns = sn.n_supernodes();
        let mut sn_of_col = vec![0; n];
        for s in 0..ns {
            sn_of_col[begin[s]..end[s]].fill(s);
        }
        // Parent: the supernode of the first row below (a later one).
        let parent: Vec<Option<usize>> = (0..ns)
            .map(|s| {
                let (_, _, _, _, below) = f.supernode(s);
                below.iter().min().map(|&r| sn_of_col[r])
            })
            .collect();
        let position: Vec<usize> = match self.symbolic.perm() {
            Some(p) => units.iter().map(|&u| p.arrays().1[u]).collect(),
            None => units.to_vec(),
        };
        let sn_paths: Vec<Vec<usize>> = position
            .iter()
            .map(|&k| {
                let mut path = Vec::new();
                let mut s = Some(sn_of_col[k]);
                while let Some(q) = s {
                    path.push(q);
                    s = parent[q].filter(|&p| p > q);
                }
                path
            })
            .collect();
        let widest = self.tmp.len();
        let arch = pulp::Arch::new();
        use rayon::prelude::*;
        out.par_chunks_mut(n.max(1))
            .zip(position.par_iter().zip(sn_paths.par_iter()))
            .for_each_init(
                || vec![0.0; widest],
                |tmp, (col, (&k, path))| {
                    col.fill(0.0);
                    col[k] = 1.0;
                    arch.dispatch(Forward {
                        f: &f,
                        sns: path,
                        x: col,
                        tmp,
                    });
                },
            );
        paths.clear();
        for path in &sn_paths {
            let mut cols: Vec<Range<usize>> = Vec::with_capacity(path.len());
            for &q in path {
                match cols.last_mut() {
                    Some(r) if r.end == begin[q] => r.end = end[q],
                    _ => cols.push(begin[q]..end[q]),
                }
            }
            paths.push(cols);
        }
        Ok(())
    }

    /// The supernodes on the paths from the supernodes of the columns `positions` (in
    /// the elimination order) to their roots, ascending: a set closed under the parent,
    /// so a backward sweep over it ([`Ldlt::backward_partial`]) gives the solution at
    /// every column of its supernodes.
    pub fn path_union(&self, positions: &[usize]) -> Result<Vec<usize>, LdltError> {
        self.check_supernodal(self.n)?;
        let SymbolicCholeskyRaw::Supernodal(sn) = self.symbolic.raw() else {
            return Err(LdltError("paths of a simplicial factor".into()));
        };
        let (begin, end, rptr) = (
            sn.supernode_begin(),
            sn.supernode_end(),
            sn.col_ptr_for_row_idx(),
        );
        let ns = sn.n_supernodes();
        let rows = sn.row_idx();
        let mut sn_of_col = vec![0; self.n];
        for s in 0..ns {
            sn_of_col[begin[s]..end[s]].fill(s);
        }
        let mut on = vec![false; ns];
        for &k in positions {
            let mut s = sn_of_col[k];
            while !on[s] {
                on[s] = true;
                // Parent: the supernode of the first row below (a later one).
                let below = &rows[rptr[s]..rptr[s + 1]];
                match below.iter().min().map(|&r| sn_of_col[r]) {
                    Some(q) if q > s => s = q,
                    _ => break,
                }
            }
        }
        Ok((0..ns).filter(|&s| on[s]).collect())
    }

    /// `x ← L⁻ᵀ D⁻¹ x` over the supernodes `sns` only (ascending, closed under the
    /// parent: [`Ldlt::path_union`]), `x` in the elimination order: the columns of `sns`
    /// get the values of a full backward sweep, the others are left as they were.
    pub fn backward_partial(&mut self, sns: &[usize], x: &mut [f64]) -> Result<(), LdltError> {
        self.check_supernodal(x.len())?;
        self.sweep_over(sns, x, false)
    }

    /// `x ← L⁻¹ x` for `x` (in the elimination order) zero outside the columns
    /// `positions`: a forward sweep over their paths to the roots only
    /// ([`Ldlt::path_union`]; outside them the result is zero too).
    pub fn forward_sparse(&mut self, positions: &[usize], x: &mut [f64]) -> Result<(), LdltError> {
        let sns = self.path_union(positions)?;
        self.sweep_over(&sns, x, true)
    }

    /// `x ← L⁻¹ x` (`forward`) or `x ← L⁻ᵀ D⁻¹ x` over the supernodes `sns` only
    /// (ascending, closed under the parent), on the calling thread.
    fn sweep_over(&mut self, sns: &[usize], x: &mut [f64], forward: bool) -> Result<(), LdltError> {
        let SymbolicCholeskyRaw::Supernodal(sn) = self.symbolic.raw() else {
            return Err(LdltError("partial sweep of a simplicial factor".into()));
        };
        let f = Factor::of(sn, &self.values, &self.inv_diag);
        let (arch, tmp) = (pulp::Arch::new(), &mut self.tmp);
        if forward {
            arch.dispatch(Forward { f: &f, sns, x, tmp });
        } else {
            arch.dispatch(Backward { f: &f, sns, x, tmp });
        }
        Ok(())
    }

    /// The position of the original unknown `u` in the elimination order.
    pub fn position(&self, u: usize) -> usize {
        match self.symbolic.perm() {
            Some(p) => p.arrays().1[u],
            None => u,
        }
    }

    fn check_supernodal(&self, len: usize) -> Result<(), LdltError> {
        if !self.factored {
            return Err(LdltError("solve before a successful factorization".into()));
        }
        if len != self.n {
            return Err(LdltError(format!(
                "right-hand side of length {len}, want {}",
                self.n
            )));
        }
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(_) => Ok(()),
            SymbolicCholeskyRaw::Simplicial(_) => {
                Err(LdltError("split solve of a simplicial factor".into()))
            }
        }
    }

    /// `work ← P rhs`.
    fn permute_in(&mut self, rhs: &[f64]) {
        match self.symbolic.perm() {
            Some(p) => {
                for (xi, &i) in self.work.iter_mut().zip(p.arrays().0) {
                    *xi = rhs[i];
                }
            }
            None => self.work.copy_from_slice(rhs),
        }
    }

    /// `rhs ← Pᵀ work`.
    fn permute_out(&self, rhs: &mut [f64]) {
        match self.symbolic.perm() {
            Some(p) => {
                for (r, &i) in rhs.iter_mut().zip(p.arrays().1) {
                    *r = self.work[i];
                }
            }
            None => rhs.copy_from_slice(&self.work),
        }
    }

    /// `work ← L⁻¹ work` (supernodal factors), on two threads over the split.
    fn sweep_forward(&mut self) {
        self.sweep(true);
    }

    /// `work ← L⁻ᵀ D⁻¹ work` (supernodal factors), on two threads over the split.
    fn sweep_backward(&mut self) {
        self.sweep(false);
    }

    fn sweep(&mut self, forward_sweep: bool) {
        let SymbolicCholeskyRaw::Supernodal(sn) = self.symbolic.raw() else {
            return;
        };
        let f = Factor::of(sn, &self.values, &self.inv_diag);
        let ns = sn.n_supernodes();
        let x = &mut self.work;
        // The sweeps compiled for the widest vector instructions of this processor.
        let arch = pulp::Arch::new();
        let tmp = &mut self.tmp;
        let forward = |sns: &[usize], x: &mut [f64], tmp: &mut [f64]| {
            arch.dispatch(Forward { f: &f, sns, x, tmp })
        };
        let backward = |sns: &[usize], x: &mut [f64], tmp: &mut [f64]| {
            arch.dispatch(Backward { f: &f, sns, x, tmp })
        };
        match &self.split {
            None => {
                let all = &self.all[..ns];
                if forward_sweep {
                    forward(all, x, tmp);
                } else {
                    backward(all, x, tmp);
                }
            }
            Some(sp) if forward_sweep => {
                // Forward: the subtrees of a and b on two threads, b on its own vector
                // (its updates of the rows of the rest added after), then the rest.
                let (xb, tmp_b) = (&mut self.work_b, &mut self.tmp_b);
                xb.fill(0.0);
                for c in &sp.b_cols {
                    xb[c.clone()].copy_from_slice(&x[c.clone()]);
                }
                rayon::join(|| forward(&sp.a, x, tmp), || forward(&sp.b, xb, tmp_b));
                for c in &sp.b_cols {
                    x[c.clone()].copy_from_slice(&xb[c.clone()]);
                }
                for c in &sp.rest_cols {
                    for (xi, yi) in x[c.clone()].iter_mut().zip(&xb[c.clone()]) {
                        *xi += yi;
                    }
                }
                forward(&sp.rest, x, tmp);
            }
            Some(sp) => {
                // Backward: the rest in reverse, then a and b on two threads (each reads
                // the rest and writes only its own columns).
                let (xb, tmp_b) = (&mut self.work_b, &mut self.tmp_b);
                backward(&sp.rest, x, tmp);
                xb.copy_from_slice(x);
                rayon::join(|| backward(&sp.a, x, tmp), || backward(&sp.b, xb, tmp_b));
                for c in &sp.b_cols {
                    x[c.clone()].copy_from_slice(&xb[c.clone()]);
                }
            }
        }
    }
}

/// Two disjoint sets `a` and `b` of whole subtrees of the supernodal elimination tree
/// (supernodes ascending), no supernode of one an ancestor of one of the other: the
/// forward sweep of a subtree writes only its own columns and rows of its ancestors (in
/// `rest`), the backward sweep reads only its own columns and those of its ancestors, so
/// both sweeps run `a` and `b` on two threads, `rest` (the other supernodes, ascending)
/// after them (forward) or before them (backward); a parent follows its children, so
/// ascending order is an elimination order of every set. Chosen by opening the heaviest
/// subtree (by factor entries) of a frontier that starts at the roots until the frontier
/// splits into two bins of comparable weight (heaviest first into the lighter bin).
#[derive(Debug)]
struct Split {
    a: Vec<usize>,
    b: Vec<usize>,
    /// The columns of `b`.
    b_cols: Vec<Range<usize>>,
    rest: Vec<usize>,
    /// The columns of `rest`.
    rest_cols: Vec<Range<usize>>,
}

impl Split {
    /// The lighter bin must carry at least this fraction of the heavier's entries.
    const BALANCE: f64 = 0.8;
    /// Both bins together at least this fraction of all entries.
    const WORTH: f64 = 0.6;
    /// Subtrees opened at most.
    const OPENINGS: usize = 256;

    /// The split of the supernodes given by faer's supernodal structure (`begin`,
    /// `end`: columns; `rptr`, `rows`: rows below each diagonal block; `vptr`: entries),
    /// or `None` when the tree has no such split or is not postordered.
    fn find(
        begin: &[usize],
        end: &[usize],
        rptr: &[usize],
        vptr: &[usize],
        rows: &[usize],
    ) -> Option<Self> {
        let ns = begin.len();
        if ns < 4 {
            return None;
        }
        let n = end[ns - 1];
        let mut sn_of_col = vec![0; n];
        for s in 0..ns {
            sn_of_col[begin[s]..end[s]].fill(s);
        }
        // Parent: the supernode of the first row below the diagonal block.
        let mut parent = vec![usize::MAX; ns];
        for s in 0..ns {
            let w = end[s] - begin[s];
            let r = (vptr[s + 1] - vptr[s]) / w.max(1) - w;
            if r > 0 {
                let first = rows[rptr[s]..rptr[s] + r].iter().copied().min()?;
                let p = sn_of_col[first];
                if p <= s {
                    return None;
                }
                parent[s] = p;
            }
        }
        // Subtree weights (children before parents).
        let mut weight: Vec<usize> = (0..ns).map(|s| vptr[s + 1] - vptr[s]).collect();
        for s in 0..ns {
            if parent[s] != usize::MAX {
                weight[parent[s]] += weight[s];
            }
        }
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); ns];
        let mut frontier = Vec::new();
        for s in 0..ns {
            match parent[s] {
                usize::MAX => frontier.push(s),
                p => children[p].push(s),
            }
        }
        let total: usize = frontier.iter().map(|&r| weight[r]).sum();
        for _ in 0..Self::OPENINGS {
            frontier.sort_by_key(|&c| (std::cmp::Reverse(weight[c]), c));
            let (mut a, mut b) = (Vec::new(), Vec::new());
            let (mut wa, mut wb) = (0usize, 0usize);
            for &c in &frontier {
                if wa <= wb {
                    a.push(c);
                    wa += weight[c];
                } else {
                    b.push(c);
                    wb += weight[c];
                }
            }
            let (lo, hi) = (wa.min(wb) as f64, wa.max(wb) as f64);
            if lo >= Self::BALANCE * hi {
                if lo + hi < Self::WORTH * total as f64 {
                    return None;
                }
                // Bin of every supernode: 0 rest, 1 a, 2 b (subtrees by depth-first walks).
                let mut bin = vec![0u8; ns];
                let mut stack = Vec::new();
                for (set, tag) in [(&a, 1u8), (&b, 2u8)] {
                    stack.extend_from_slice(set);
                    while let Some(q) = stack.pop() {
                        bin[q] = tag;
                        stack.extend_from_slice(&children[q]);
                    }
                }
                let of = |tag: u8| (0..ns).filter(|&q| bin[q] == tag).collect::<Vec<_>>();
                let cols = |set: &[usize]| {
                    let mut out: Vec<Range<usize>> = Vec::new();
                    for &q in set {
                        match out.last_mut() {
                            Some(r) if r.end == begin[q] => r.end = end[q],
                            _ => out.push(begin[q]..end[q]),
                        }
                    }
                    out
                };
                let (a, b, rest) = (of(1), of(2), of(0));
                return Some(Self {
                    b_cols: cols(&b),
                    rest_cols: cols(&rest),
                    a,
                    b,
                    rest,
                });
            }
            // Open the heaviest subtree: its root joins the rest.
            let heavy = frontier[0];
            if children[heavy].is_empty() {
                return None;
            }
            frontier.swap_remove(0);
            frontier.extend_from_slice(&children[heavy]);
        }
        None
    }
}

/// [`Factor::forward`] compiled for the instruction set `pulp` dispatches to.
struct Forward<'a, 'f> {
    f: &'a Factor<'f>,
    sns: &'a [usize],
    x: &'a mut [f64],
    tmp: &'a mut [f64],
}

impl pulp::WithSimd for Forward<'_, '_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        self.f.forward(simd, self.sns, self.x, self.tmp);
    }
}

/// [`Factor::backward`] compiled for the instruction set `pulp` dispatches to.
struct Backward<'a, 'f> {
    f: &'a Factor<'f>,
    sns: &'a [usize],
    x: &'a mut [f64],
    tmp: &'a mut [f64],
}

impl pulp::WithSimd for Backward<'_, '_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        self.f.backward(simd, self.sns, self.x, self.tmp);
    }
}

/// A view of the supernodal factor.
struct Factor<'f> {
    begin: &'f [usize],
    end: &'f [usize],
    rptr: &'f [usize],
    vptr: &'f [usize],
    rows: &'f [usize],
    values: &'f [f64],
    inv_diag: &'f [f64],
}

impl<'f> Factor<'f> {
    /// The view of the supernodal structure `sn` with the values and `1/D` of its factors.
    fn of(
        sn: &'f faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky<usize>,
        values: &'f [f64],
        inv_diag: &'f [f64],
    ) -> Self {
        Factor {
            begin: sn.supernode_begin(),
            end: sn.supernode_end(),
            rptr: sn.col_ptr_for_row_idx(),
            vptr: sn.col_ptr_for_val(),
            rows: sn.row_idx(),
            values,
            inv_diag,
        }
    }

    /// Supernode `s`: its first column, width `w`, rows below `r`, and the block.
    #[inline(always)]
    fn supernode(&self, s: usize) -> (usize, usize, usize, &[f64], &[usize]) {
        let (start, w) = (self.begin[s], self.end[s] - self.begin[s]);
        let block = &self.values[self.vptr[s]..self.vptr[s + 1]];
        let r = block.len() / w.max(1) - w;
        (
            start,
            w,
            r,
            block,
            &self.rows[self.rptr[s]..self.rptr[s] + r],
        )
    }

    /// `y ← L⁻¹ y` over the supernodes `sns` (ascending, in the permuted order).
    #[inline(always)]
    fn forward<S: Simd>(&self, simd: S, sns: &[usize], x: &mut [f64], buf: &mut [f64]) {
        for &s in sns {
            let (start, w, r, block, below) = self.supernode(s);
            let m = w + r;
            // buf = [y_top | accumulated −L_bot y_top]; column j updates the contiguous
            // rows j + 1..m of buf.
            let buf = &mut buf[..m];
            buf[..w].copy_from_slice(&x[start..start + w]);
            buf[w..].fill(0.0);
            let col = |j: usize| &block[j * m..(j + 1) * m];
            let mut j = 0;
            while j + 4 <= w {
                let c = [col(j), col(j + 1), col(j + 2), col(j + 3)];
                // The unit lower triangle of the group, then the rows below it.
                for a in 0..3 {
                    for b in a + 1..4 {
                        buf[j + b] -= c[a][j + b] * buf[j + a];
                    }
                }
                let xs = [-buf[j], -buf[j + 1], -buf[j + 2], -buf[j + 3]];
                let lo = j + 4;
                axpy4(
                    simd,
                    &mut buf[lo..],
                    [&c[0][lo..], &c[1][lo..], &c[2][lo..], &c[3][lo..]],
                    xs,
                );
                j += 4;
            }
            while j < w {
                let xj = buf[j];
                axpy(simd, &mut buf[j + 1..], &col(j)[j + 1..], -xj);
                j += 1;
            }
            x[start..start + w].copy_from_slice(&buf[..w]);
            for (&i, t) in below.iter().zip(&buf[w..]) {
                x[i] += t;
            }
        }
    }

    /// `x ← L⁻ᵀ D⁻¹ x` over the supernodes `sns` (ascending), in reverse.
    #[inline(always)]
    fn backward<S: Simd>(&self, simd: S, sns: &[usize], x: &mut [f64], buf: &mut [f64]) {
        for &s in sns.iter().rev() {
            let (start, w, r, block, below) = self.supernode(s);
            let m = w + r;
            // buf = [D⁻¹ z_top | x[R_s]]; column j reads the contiguous rows j + 1..m.
            let buf = &mut buf[..m];
            for ((b, xi), d) in buf[..w]
                .iter_mut()
                .zip(&x[start..start + w])
                .zip(&self.inv_diag[start..start + w])
            {
                *b = xi * d;
            }
            for (b, &i) in buf[w..].iter_mut().zip(below) {
                *b = x[i];
            }
            let col = |j: usize| &block[j * m..(j + 1) * m];
            let first = w % 4;
            let mut j = w;
            while j >= first + 4 {
                j -= 4;
                let c = [col(j), col(j + 1), col(j + 2), col(j + 3)];
                let lo = j + 4;
                let acc = dot4(
                    simd,
                    &buf[lo..],
                    [&c[0][lo..], &c[1][lo..], &c[2][lo..], &c[3][lo..]],
                );
                for (a, v) in acc.iter().enumerate() {
                    buf[j + a] -= v;
                }
                // The unit upper triangle (Lᵀ) of the group.
                for a in (0..3).rev() {
                    for b in a + 1..4 {
                        buf[j + a] -= c[a][j + b] * buf[j + b];
                    }
                }
            }
            for j in (0..first).rev() {
                let v = dot(simd, &col(j)[j + 1..], &buf[j + 1..]);
                buf[j] -= v;
            }
            x[start..start + w].copy_from_slice(&buf[..w]);
        }
    }
}

/// `t += x c` (`c` at least as long as `t`).
#[inline(always)]
fn axpy<S: Simd>(simd: S, t: &mut [f64], c: &[f64], x: f64) {
    let n = t.len();
    let (th, tt) = S::as_mut_simd_f64s(t);
    let (ch, ct) = S::as_simd_f64s(&c[..n]);
    let xs = simd.splat_f64s(x);
    for (t, c) in th.iter_mut().zip(ch) {
        *t = simd.add_f64s(*t, simd.mul_f64s(*c, xs));
    }
    for (t, c) in tt.iter_mut().zip(ct) {
        *t += c * x;
    }
}

/// `t += Σ_k x_k c_k` for four columns `c_k` at least as long as `t`.
#[inline(always)]
fn axpy4<S: Simd>(simd: S, t: &mut [f64], c: [&[f64]; 4], x: [f64; 4]) {
    let n = t.len();
    let (th, tt) = S::as_mut_simd_f64s(t);
    let (c0, r0) = S::as_simd_f64s(&c[0][..n]);
    let (c1, r1) = S::as_simd_f64s(&c[1][..n]);
    let (c2, r2) = S::as_simd_f64s(&c[2][..n]);
    let (c3, r3) = S::as_simd_f64s(&c[3][..n]);
    let xs = x.map(|v| simd.splat_f64s(v));
    let h = th.len();
    let (c0, c1, c2, c3) = (&c0[..h], &c1[..h], &c2[..h], &c3[..h]);
    for i in 0..h {
        let a = simd.add_f64s(simd.mul_f64s(c0[i], xs[0]), simd.mul_f64s(c1[i], xs[1]));
        let b = simd.add_f64s(simd.mul_f64s(c2[i], xs[2]), simd.mul_f64s(c3[i], xs[3]));
        th[i] = simd.add_f64s(th[i], simd.add_f64s(a, b));
    }
    for (i, t) in tt.iter_mut().enumerate() {
        *t += (r0[i] * x[0] + r1[i] * x[1]) + (r2[i] * x[2] + r3[i] * x[3]);
    }
}

/// `[c_k · t]` for four columns `c_k` at least as long as `t`, summed in vector lanes.
#[inline(always)]
fn dot4<S: Simd>(simd: S, t: &[f64], c: [&[f64]; 4]) -> [f64; 4] {
    let n = t.len();
    let (th, tt) = S::as_simd_f64s(t);
    let (c0, r0) = S::as_simd_f64s(&c[0][..n]);
    let (c1, r1) = S::as_simd_f64s(&c[1][..n]);
    let (c2, r2) = S::as_simd_f64s(&c[2][..n]);
    let (c3, r3) = S::as_simd_f64s(&c[3][..n]);
    let h = th.len();
    let (c0, c1, c2, c3) = (&c0[..h], &c1[..h], &c2[..h], &c3[..h]);
    let zero = simd.splat_f64s(0.0);
    let mut a = [zero; 4];
    for i in 0..h {
        let x = th[i];
        a[0] = simd.add_f64s(a[0], simd.mul_f64s(c0[i], x));
        a[1] = simd.add_f64s(a[1], simd.mul_f64s(c1[i], x));
        a[2] = simd.add_f64s(a[2], simd.mul_f64s(c2[i], x));
        a[3] = simd.add_f64s(a[3], simd.mul_f64s(c3[i], x));
    }
    let mut out = a.map(|v| simd.reduce_sum_f64s(v));
    for (i, t) in tt.iter().enumerate() {
        out[0] += r0[i] * t;
        out[1] += r1[i] * t;
        out[2] += r2[i] * t;
        out[3] += r3[i] * t;
    }
    out
}

/// `a · b` over the length of `b` (`a` at least as long), summed in vector lanes.
#[inline(always)]
fn dot<S: Simd>(simd: S, a: &[f64], b: &[f64]) -> f64 {
    let n = b.len();
    let (ah, at) = S::as_simd_f64s(&a[..n]);
    let (bh, bt) = S::as_simd_f64s(b);
    let mut acc = simd.splat_f64s(0.0);
    for (x, y) in ah.iter().zip(bh) {
        acc = simd.add_f64s(acc, simd.mul_f64s(*x, *y));
    }
    let mut s = simd.reduce_sum_f64s(acc);
    for (x, y) in at.iter().zip(bt) {
        s += x * y;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Upper-triangle CSC of a quasi-definite block matrix: a `k × k` grid Laplacian-like
    /// block `H` (positive definite), a coupling `B` of `k` extra unknowns with `k` grid
    /// points each, and `−G` on them.
    fn quasi_definite(k: usize) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
        let nh = k * k;
        let n = nh + k;
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for i in 0..k {
            for j in 0..k {
                let a = i * k + j;
                cols[a].push((a, 4.0 + 0.1 * (a % 3) as f64));
                if j > 0 {
                    cols[a].push((a - 1, -1.0));
                }
                if i > 0 {
                    cols[a].push((a - k, -1.0));
                }
            }
        }
        for c in 0..k {
            let col = nh + c;
            for j in 0..k {
                cols[col].push((c * k + j, 0.3 + 0.01 * j as f64));
            }
            if c > 0 {
                cols[col].push((col - 1, 0.2));
            }
            cols[col].push((col, -1.0 - 0.05 * c as f64));
        }
        let mut col_ptr = vec![0];
        let (mut row_idx, mut vals) = (Vec::new(), Vec::new());
        for c in &mut cols {
            c.sort_by_key(|e| e.0);
            for &(r, v) in c.iter() {
                row_idx.push(r);
                vals.push(v);
            }
            col_ptr.push(row_idx.len());
        }
        (n, col_ptr, row_idx, vals)
    }

    fn residual(col_ptr: &[usize], row_idx: &[usize], vals: &[f64], x: &[f64], b: &[f64]) -> f64 {
        let n = b.len();
        let mut ax = vec![0.0; n];
        for j in 0..n {
            for q in col_ptr[j]..col_ptr[j + 1] {
                let (r, v) = (row_idx[q], vals[q]);
                ax[r] += v * x[j];
                if r != j {
                    ax[j] += v * x[r];
                }
            }
        }
        let e: f64 = ax.iter().zip(b).map(|(a, c)| (a - c).powi(2)).sum();
        let nb: f64 = b.iter().map(|c| c * c).sum();
        (e / nb).sqrt()
    }

    /// The solve against the matrix (relative residual below 1e-13) with AMD and with a
    /// given ordering, twice with the same factors, on a small matrix and on one whose
    /// supernodes are wide (every path of the sweeps).
    /// A dense matrix has one supernode: `Σ_(c=1..n) c (c − 1) / 2 = (n³ − n) / 6`
    /// multiply–adds.
    #[test]
    fn multiply_adds_of_a_dense_matrix() {
        let n = 10;
        let col_ptr: Vec<usize> = (0..=n).map(|j| j * (j + 1) / 2).collect();
        let row_idx: Vec<usize> = (0..n).flat_map(|j| 0..=j).collect();
        let f = Ldlt::analyse(n, &col_ptr, &row_idx, None).unwrap();
        // One supernode, its square block stored whole.
        assert_eq!(f.factor_nnz(), n * n);
        assert_eq!(f.multiply_adds(), ((n * n * n - n) / 6) as f64);
    }

    /// The quasi-definite matrix `[[H, Bᵀ], [B, −G]]` in its own order has `k²` positive
    /// pivots, then `k` negative ones.
    #[test]
    fn pivot_signs_of_a_quasi_definite_matrix() {
        let k = 6;
        let (n, col_ptr, row_idx, vals) = quasi_definite(k);
        let identity: Vec<usize> = (0..n).collect();
        let mut f = Ldlt::analyse(n, &col_ptr, &row_idx, Some(&identity)).unwrap();
        f.factorize(&col_ptr, &row_idx, &vals).unwrap();
        assert!(f.pivots_signed(k * k));
        assert!(!f.pivots_signed(k * k - 1) && !f.pivots_signed(k * k + 1));
        assert!(!f.pivots_positive());
        let mut single = crate::ldlt_single::LdltSingle::new(
            Ldlt::analyse(n, &col_ptr, &row_idx, Some(&identity)).unwrap(),
        );
        single
            .factorize_signed(&col_ptr, &row_idx, &vals, Some(k * k))
            .unwrap();
        for wrong in [Some(k * k - 1), Some(n)] {
            assert!(
                single
                    .factorize_signed(&col_ptr, &row_idx, &vals, wrong)
                    .is_err()
            );
        }
        assert!(single.factorize(&col_ptr, &row_idx, &vals, false).is_ok());
    }

    #[test]
    fn solve_matches_the_matrix() {
        for k in [12, 41] {
            solve_matches(k);
        }
    }

    fn solve_matches(k: usize) {
        let (n, col_ptr, row_idx, vals) = quasi_definite(k);
        let b: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
        let reversed: Vec<usize> = (0..n).rev().collect();
        for perm in [None, Some(reversed.as_slice())] {
            let mut f = Ldlt::analyse(n, &col_ptr, &row_idx, perm).unwrap();
            f.factorize(&col_ptr, &row_idx, &vals).unwrap();
            assert!(!f.pivots_positive(), "the matrix is indefinite");
            for _ in 0..2 {
                let mut x = b.clone();
                f.solve_in_place(&mut x).unwrap();
                let res = residual(&col_ptr, &row_idx, &vals, &x, &b);
                assert!(res < 1e-13, "{res}");
            }
            assert_eq!((f.numeric_factorizations(), f.solves()), (1, 2));
        }
    }

    /// The trailing Schur complement `S` on the last `m` unknowns of the elimination
    /// order: `A⁻¹ [0; S x_T]` restricted to those unknowns is `x_T` (to 1e-10 relative),
    /// with AMD and with a given order, for `m` inside one supernode and across several.
    #[test]
    fn trailing_schur_complement_inverts_the_trailing_block() {
        for k in [12, 41] {
            let (n, col_ptr, row_idx, vals) = quasi_definite(k);
            let reversed: Vec<usize> = (0..n).rev().collect();
            for perm in [None, Some(reversed.as_slice())] {
                let mut f = Ldlt::analyse(n, &col_ptr, &row_idx, perm).unwrap();
                f.factorize(&col_ptr, &row_idx, &vals).unwrap();
                let order: Vec<usize> = f
                    .permutation()
                    .map_or_else(|| (0..n).collect(), <[usize]>::to_vec);
                for m in [1, 5, n / 2, n] {
                    let s = f.trailing_schur_complement(m).unwrap();
                    let tail = &order[n - m..];
                    let xt: Vec<f64> = (0..m).map(|i| 1.0 + ((i * 37) % 11) as f64).collect();
                    let mut rhs = vec![0.0; n];
                    for (i, &e) in tail.iter().enumerate() {
                        rhs[e] = (0..m).map(|j| s[j * m + i] * xt[j]).sum();
                    }
                    f.solve_in_place(&mut rhs).unwrap();
                    let scale = xt.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                    for (i, &e) in tail.iter().enumerate() {
                        let d = (rhs[e] - xt[i]).abs() / scale;
                        assert!(d < 1e-10, "k {k} m {m}: {d:e}");
                    }
                }
                assert!(f.trailing_schur_complement(n + 1).is_err());
            }
        }
    }

    /// The lower triangle (CSC) of a shifted 5-point Laplacian on a `k × k` grid:
    /// `(n, col_ptr, row_idx, vals)`.
    fn grid_laplacian(k: usize) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = k * k;
        let mut col_ptr = vec![0];
        let (mut row_idx, mut vals) = (Vec::new(), Vec::new());
        for a in 0..n {
            let (i, j) = (a / k, a % k);
            if i > 0 {
                row_idx.push(a - k);
                vals.push(-1.0);
            }
            if j > 0 {
                row_idx.push(a - 1);
                vals.push(-1.0);
            }
            row_idx.push(a);
            vals.push(4.0 + 0.01 * (a % 7) as f64);
            col_ptr.push(row_idx.len());
        }
        (n, col_ptr, row_idx, vals)
    }

    /// On a 2D grid Laplacian (AMD: a nested-dissection-like tree) the sweeps split into
    /// two subtrees, and the split solve satisfies the matrix like the sequential one.
    #[test]
    fn split_solve_matches_the_sequential_one() {
        let (n, col_ptr, row_idx, vals) = grid_laplacian(60);
        let b: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
        let mut f = Ldlt::analyse(n, &col_ptr, &row_idx, None).unwrap();
        f.factorize(&col_ptr, &row_idx, &vals).unwrap();
        let sp = f.split.as_ref().expect("a split of the grid's tree");
        assert!(!sp.a.is_empty() && !sp.b.is_empty());
        let mut x = b.clone();
        f.solve_in_place(&mut x).unwrap();
        assert!(residual(&col_ptr, &row_idx, &vals, &x, &b) < 1e-13);
        let split = f.split.take();
        let mut y = b.clone();
        f.solve_in_place(&mut y).unwrap();
        assert!(residual(&col_ptr, &row_idx, &vals, &y, &b) < 1e-13);
        let d = x
            .iter()
            .zip(&y)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        let m = y.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(d <= 1e-13 * m, "split and sequential differ by {d:e}");
        // The same split twice gives the same bits.
        f.split = split;
        let mut z = b.clone();
        f.solve_in_place(&mut z).unwrap();
        assert_eq!(x, z);
    }

    /// The two halves of a solve give the solve, and the path-restricted forward sweeps
    /// of unit vectors give the full forward sweep, zero outside the path (a 2D grid
    /// Laplacian with a split, and the quasi-definite block matrix).
    #[test]
    fn forward_units_match_the_forward_sweep() {
        let (n, col_ptr, row_idx, vals) = grid_laplacian(40);
        let systems = [(n, col_ptr, row_idx, vals), quasi_definite(9)];
        for (n, col_ptr, row_idx, vals) in systems {
            let mut f = Ldlt::analyse(n, &col_ptr, &row_idx, None).unwrap();
            f.factorize(&col_ptr, &row_idx, &vals).unwrap();
            let b: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
            let mut x = b.clone();
            f.solve_in_place(&mut x).unwrap();
            let mut y = b.clone();
            f.forward_in_place(&mut y).unwrap();
            f.backward_in_place(&mut y).unwrap();
            assert_eq!(x, y);
            let units = [0, n / 3, n / 2, n - 1];
            let mut cols = vec![f64::NAN; n * units.len()];
            let mut paths = Vec::new();
            f.forward_units(&units, &mut cols, &mut paths).unwrap();
            assert_eq!(paths.len(), units.len());
            for (c, &u) in units.iter().enumerate() {
                let mut e = vec![0.0; n];
                e[u] = 1.0;
                f.forward_in_place(&mut e).unwrap();
                let col = &cols[c * n..(c + 1) * n];
                let on_path = |i: usize| paths[c].iter().any(|r| r.contains(&i));
                let d = (0..n).map(|i| (col[i] - e[i]).abs()).fold(0.0, f64::max);
                let m = e.iter().map(|v| v.abs()).fold(0.0, f64::max);
                assert!(d <= 1e-15 * m, "unit {u}: differs by {d:e}");
                assert!((0..n).all(|i| on_path(i) || e[i] == 0.0), "unit {u}");
                let covered: usize = paths[c].iter().map(|r| r.len()).sum();
                assert!(covered < n, "unit {u}: the path is the whole factor");
            }
            // A backward sweep over the paths of a few columns gives the full sweep's
            // values at every column of those paths, bit for bit.
            let mut z = b.clone();
            f.forward_in_place(&mut z).unwrap();
            let mut full = z.clone();
            f.backward_in_place(&mut full).unwrap();
            let targets: Vec<usize> = [1, n / 4, n - 2].iter().map(|&u| f.position(u)).collect();
            let sns = f.path_union(&targets).unwrap();
            let mut part = z.clone();
            f.backward_partial(&sns, &mut part).unwrap();
            for &u in &[1, n / 4, n - 2] {
                assert_eq!(part[f.position(u)], full[u], "unknown {u}");
            }
            // The forward sweep of a vector with a few nonzeros, over their paths only.
            let mut sparse = vec![0.0; n];
            let mut dense = vec![0.0; n];
            for (k, &u) in [2, n / 3, n - 4].iter().enumerate() {
                sparse[f.position(u)] = 1.5 + k as f64;
                dense[u] = 1.5 + k as f64;
            }
            f.forward_sparse(&targets, &mut vec![0.0; n]).unwrap();
            let positions: Vec<usize> = [2, n / 3, n - 4].iter().map(|&u| f.position(u)).collect();
            f.forward_sparse(&positions, &mut sparse).unwrap();
            f.forward_in_place(&mut dense).unwrap();
            let d = (0..n)
                .map(|i| (sparse[i] - dense[i]).abs())
                .fold(0.0, f64::max);
            assert!(d <= 1e-14, "sparse forward sweep differs by {d:e}");
        }
    }
}
