//! Solves with a matrix that differs from a factorized one in a few rows and columns
//! (Sherman–Morrison–Woodbury in capacitance form).
//!
//! A fracturing step changes the coupled matrix only where a cell switched law or
//! permeability: `A = A₀ + P Δ Pᵀ`, with `P` the columns of the identity of the set `T` of
//! unknowns in a changed entry (`m = |T|`) and `Δ` the symmetric `m × m` change. With the
//! factors of `A₀` and `G = Pᵀ A₀⁻¹ P`, `A x = b` is
//!
//! ```text
//!   (I + G Δ) y = Pᵀ z ,      x = z − (A₀⁻¹ P) Δ y ,      z = A₀⁻¹ b
//! ```
//!
//! (`y = Pᵀ x`; Hager 1989, *Updating the inverse of a matrix*). With the factors
//! `Π A₀ Πᵀ = L D Lᵀ` (`Π` the elimination order) and, for every changed unknown `u`,
//! the forward solve `v_u = L⁻¹ Π e_u`,
//!
//! ```text
//!   G_uw = v_uᵀ D⁻¹ v_w ,     f = L⁻¹ Π b ,     (Pᵀ z)_u = v_uᵀ D⁻¹ f ,
//!   x = Πᵀ L⁻ᵀ D⁻¹ (f − Σ_u (Δ y)_u v_u) ,
//! ```
//!
//! so a solve is one forward and one backward sweep (as a plain solve), one solve with
//! the `m × m` capacitance matrix `I + G Δ` (dense LU with partial pivoting, factorized
//! once per change) and `2m` short vector operations. `v_u` is zero outside the
//! supernodes on the path from the supernode of `u` to the root of the elimination tree
//! (the rows of `L` below a supernode are its ancestors'), so it costs a forward sweep
//! over that path only ([`Ldlt::forward_units`]) — on the 3D hydraulic-fracture scene a
//! small part of the factor — and every product with it runs over the path's columns.
//! The `v_u` and their products `G` are kept for every unknown met since the last
//! factorization, so a later change pays only for the unknowns new to it. The error of
//! an updated solve, that of the capacitance solve, leaves a residual on `T` only; it is
//! measured there from the solution at `T`'s neighbours (a backward sweep over their
//! paths) and corrected within the solve's own backward sweep
//! ([`LowRank::solve_corrected`]). (The earlier
//! form kept the whole columns `A₀⁻¹ P`, a forward *and* a backward sweep over the whole
//! factor per unknown.) The caller bounds `m` and factorizes `A` afresh beyond it, and
//! checks the residual of the result against `A` itself.

use std::ops::Range;

use faer::Mat;
use faer::linalg::solvers::{PartialPivLu, Solve};

use crate::ldlt::{Ldlt, LdltError};

/// Unknowns whose forward solves are computed in one call (on two threads).
const BATCH: usize = 32;

/// Corrections of an updated solve from its residual on the support, each checked on
/// the solution the final backward sweep gives there ([`LowRank::solve_corrected`]).
/// One: on the 3D hydraulic-fracture scene it takes the residual from 1e-11 … 1e-9 to the
/// rounding of the backward sweep itself, 1e-13 … 1e-11 relative (a third of the solves
/// then above the 1e-12 of the caller, who refines them); more corrections stay at that
/// level, each a partial sweep dearer (4: 158 instead of 232 refined solves of 701,
/// 1.6 s slower).
const SUPPORT_CORRECTIONS: usize = 1;

/// Marks an unknown without a slot.
const NONE: usize = usize::MAX;

/// The update of a factorized matrix `A₀` to a matrix of the same pattern differing in
/// few unknowns (see the module docs).
pub struct LowRank {
    /// Per unknown: its slot among the cached columns, or [`NONE`].
    slot: Vec<usize>,
    /// The unknown of every slot.
    cached: Vec<usize>,
    /// The forward solves `v_u = L⁻¹ Π e_u` of the cached unknowns, column-major
    /// `n × cached.len()` in the elimination order: `w[a · n + i] = (v_{cached[a]})_i`.
    w: Vec<f64>,
    /// The columns where `v` of every slot may be nonzero (its path to the root).
    paths: Vec<Vec<Range<usize>>>,
    /// `G` between the slots: `gram[a][b] = v_aᵀ D⁻¹ v_b` for `b ≤ a`.
    gram: Vec<Vec<f64>>,
    /// The unknowns `T` of the current change.
    support: Vec<usize>,
    /// Per unknown: its index in `support`, or [`NONE`].
    local: Vec<usize>,
    /// The entries `(i, j, Δ_ij)` of the change, indices into `support`, both triangles.
    delta: Vec<(usize, usize, f64)>,
    /// LU of `I + G Δ`; `None`: no change set up (solve with `A₀`).
    lu: Option<PartialPivLu<f64>>,
    /// `Δ y` over the support.
    t: Vec<f64>,
    /// The support and its neighbours in the matrix (original indices): the unknowns
    /// the residual on the support reads ([`LowRank::prepare_correction`]).
    near: Vec<usize>,
    /// The supernodes on the paths from those of `near` to the roots, ascending.
    near_sns: Vec<usize>,
    /// A copy of the swept vector for the partial backward sweep, and the solution at
    /// `near` in the original order (other entries stale).
    scratch: Vec<f64>,
    near_x: Vec<f64>,
}

/// Row access to a symmetric matrix kept as its upper triangle in CSC (`col_ptr`,
/// `row_idx`): per row `i`, the columns `j > i` and positions of its entries `(i, j)`.
/// With the column itself (the entries `(r, i)`, `r ≤ i`) this is the whole row `i`.
pub struct UpperRows {
    ptr: Vec<usize>,
    /// `(column, position in the CSC values)`, by row, columns ascending.
    entries: Vec<(usize, usize)>,
}

impl UpperRows {
    /// The row index of the upper triangle (`col_ptr`, `row_idx`).
    pub fn new(col_ptr: &[usize], row_idx: &[usize]) -> Self {
        let n = col_ptr.len().saturating_sub(1);
        let mut ptr = vec![0usize; n + 1];
        for j in 0..n {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                if i < j {
                    ptr[i + 1] += 1;
                }
            }
        }
        for i in 0..n {
            ptr[i + 1] += ptr[i];
        }
        let mut fill = ptr.clone();
        let mut entries = vec![(0, 0); ptr[n]];
        for j in 0..n {
            for q in col_ptr[j]..col_ptr[j + 1] {
                let i = row_idx[q];
                if i < j {
                    entries[fill[i]] = (j, q);
                    fill[i] += 1;
                }
            }
        }
        Self { ptr, entries }
    }

    /// Call `f(j, q)` for every entry `(i, j)` of row `i` of the symmetric matrix, `q`
    /// its position in the CSC values.
    #[inline]
    pub fn for_row(
        &self,
        i: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        mut f: impl FnMut(usize, usize),
    ) {
        for q in col_ptr[i]..col_ptr[i + 1] {
            f(row_idx[q], q);
        }
        for &(j, q) in &self.entries[self.ptr[i]..self.ptr[i + 1]] {
            f(j, q);
        }
    }
}

impl LowRank {
    /// No cached columns, no change, for `n` unknowns.
    pub fn new(n: usize) -> Self {
        Self {
            slot: vec![NONE; n],
            cached: Vec::new(),
            w: Vec::new(),
            paths: Vec::new(),
            gram: Vec::new(),
            support: Vec::new(),
            local: vec![NONE; n],
            delta: Vec::new(),
            lu: None,
            t: Vec::new(),
            near: Vec::new(),
            near_sns: Vec::new(),
            scratch: Vec::new(),
            near_x: Vec::new(),
        }
    }

    /// Forget the cached columns and the change (after a new factorization of `A₀`).
    pub fn clear(&mut self) {
        for &u in &self.cached {
            self.slot[u] = NONE;
        }
        self.cached.clear();
        self.w.clear();
        self.paths.clear();
        self.gram.clear();
        self.clear_change();
    }

    fn clear_change(&mut self) {
        for &u in &self.support {
            self.local[u] = NONE;
        }
        self.support.clear();
        self.delta.clear();
        self.lu = None;
        self.near.clear();
        self.near_sns.clear();
    }

    /// Whether a change is set up (solves go through the capacitance matrix).
    pub fn is_active(&self) -> bool {
        self.lu.is_some()
    }

    /// The unknowns whose columns of `A₀⁻¹` are cached, in the order they were computed.
    pub fn cached_columns(&self) -> &[usize] {
        &self.cached
    }

    /// Compute and cache the columns of `A₀⁻¹` of the unknowns `columns` (in this order;
    /// those cached already and repeats are skipped) with the factors `ldlt`, and set up
    /// no change: the cache of an earlier run with the same factors is the same, bit for
    /// bit, and so are the updates [`LowRank::prepare`] builds on it.
    pub fn cache_columns(&mut self, ldlt: &mut Ldlt, columns: &[usize]) -> Result<(), LdltError> {
        let n = self.slot.len();
        if let Some(&u) = columns.iter().find(|&&u| u >= n) {
            return Err(LdltError(format!(
                "cached column {u} of a matrix of {n} unknowns"
            )));
        }
        self.clear_change();
        let mut seen = vec![false; n];
        let new: Vec<usize> = columns
            .iter()
            .copied()
            .filter(|&u| self.slot[u] == NONE && !std::mem::replace(&mut seen[u], true))
            .collect();
        self.support = new;
        let done = self.extend_cache(ldlt);
        self.support.clear();
        done
    }

    /// Unknowns whose columns of `A₀⁻¹` are cached.
    #[cfg(test)]
    pub fn cached_len(&self) -> usize {
        self.cached.len()
    }

    /// Set up the change from the factorized upper triangle `base` to `values` (the same
    /// CSC pattern `col_ptr`, `row_idx`). Returns `false`, with nothing set up, when more
    /// than `max_rank` unknowns changed.
    pub fn prepare(
        &mut self,
        ldlt: &mut Ldlt,
        col_ptr: &[usize],
        row_idx: &[usize],
        base: &[f64],
        values: &[f64],
        max_rank: usize,
    ) -> Result<bool, LdltError> {
        self.clear_change();
        let n = self.slot.len();
        if col_ptr.len() != n + 1 || base.len() != values.len() || values.len() != row_idx.len() {
            return Err(LdltError("low-rank update of another pattern".into()));
        }
        for j in 0..n {
            for q in col_ptr[j]..col_ptr[j + 1] {
                let d = values[q] - base[q];
                if d == 0.0 {
                    continue;
                }
                let i = row_idx[q];
                for u in [i, j] {
                    if self.local[u] == NONE {
                        self.local[u] = self.support.len();
                        self.support.push(u);
                    }
                }
                if self.support.len() > max_rank {
                    self.clear_change();
                    return Ok(false);
                }
                let (a, b) = (self.local[i], self.local[j]);
                self.delta.push((a, b, d));
                if a != b {
                    self.delta.push((b, a, d));
                }
            }
        }
        self.extend_cache(ldlt)?;
        let m = self.support.len();
        let slots: Vec<usize> = self.support.iter().map(|&u| self.slot[u]).collect();
        let mut cap = Mat::<f64>::identity(m, m);
        for &(k, j, v) in &self.delta {
            for (i, &a) in slots.iter().enumerate() {
                let b = slots[k];
                cap[(i, j)] += v * self.gram[a.max(b)][a.min(b)];
            }
        }
        self.lu = Some(cap.partial_piv_lu());
        Ok(true)
    }

    /// Cache the forward solves of the support's unknowns not cached yet, and their
    /// products `G` with every cached one.
    fn extend_cache(&mut self, ldlt: &mut Ldlt) -> Result<(), LdltError> {
        let new: Vec<usize> = self
            .support
            .iter()
            .copied()
            .filter(|&u| self.slot[u] == NONE)
            .collect();
        self.cache_new(ldlt, &new)
    }

    /// Cache the forward solves of the unknowns `new` (none cached yet, no repeats) and
    /// their products `G` with every cached one.
    fn cache_new(&mut self, ldlt: &mut Ldlt, new: &[usize]) -> Result<(), LdltError> {
        let n = self.slot.len();
        let mut paths = Vec::new();
        for chunk in new.chunks(BATCH) {
            let old = self.w.len();
            self.w.resize(old + n * chunk.len(), 0.0);
            ldlt.forward_units(chunk, &mut self.w[old..], &mut paths)?;
            for (&u, path) in chunk.iter().zip(paths.drain(..)) {
                let a = self.cached.len();
                self.slot[u] = a;
                self.cached.push(u);
                self.paths.push(path);
                let inv_d = ldlt.inverse_diagonal();
                let va = &self.w[a * n..(a + 1) * n];
                let row = (0..=a)
                    .map(|b| {
                        let vb = &self.w[b * n..(b + 1) * n];
                        self.paths[a]
                            .iter()
                            .flat_map(|r| r.clone())
                            .map(|i| va[i] * inv_d[i] * vb[i])
                            .sum()
                    })
                    .collect();
                self.gram.push(row);
            }
        }
        Ok(())
    }

    /// Solve `A x = b` in place with the factors of `A₀` and the change set up by
    /// [`LowRank::prepare`] (plainly with `A₀` when none is).
    pub fn solve(&mut self, ldlt: &mut Ldlt, rhs: &mut [f64]) -> Result<(), LdltError> {
        if self.lu.is_none() {
            return ldlt.solve_in_place(rhs);
        }
        ldlt.forward_in_place(rhs)?;
        self.update_forwarded(ldlt, rhs)?;
        ldlt.backward_in_place(rhs)
    }

    /// Set up [`LowRank::solve_corrected`] for the change prepared last: the support's
    /// neighbours in the matrix (`rows` of the CSC upper triangle `col_ptr`, `row_idx`)
    /// and the paths of their supernodes.
    pub fn prepare_correction(
        &mut self,
        ldlt: &Ldlt,
        col_ptr: &[usize],
        row_idx: &[usize],
        rows: &UpperRows,
    ) -> Result<(), LdltError> {
        let n = self.slot.len();
        let mut seen = vec![false; n];
        self.near.clear();
        for &u in &self.support {
            rows.for_row(u, col_ptr, row_idx, |j, _| {
                if !seen[j] {
                    seen[j] = true;
                    self.near.push(j);
                }
            });
            if !seen[u] {
                seen[u] = true;
                self.near.push(u);
            }
        }
        let positions: Vec<usize> = self.near.iter().map(|&u| ldlt.position(u)).collect();
        self.near_sns = ldlt.path_union(&positions)?;
        Ok(())
    }

    /// Solve `A x = b` in place as [`LowRank::solve`], corrected once from the residual
    /// on the support before the backward sweep. The error of an updated solve is that
    /// of the capacitance solve, and its residual lies on the support `T`
    /// ([`LowRank::solve_on_support`]); with `f'` the forward-swept right-hand side after
    /// the update, the solution at the support's neighbours `N(T)` comes from a backward
    /// sweep of a copy of `f'` over their paths only (`x = Πᵀ L⁻ᵀ D⁻¹ f'` there), which
    /// gives the residual `ρ_u = b_u − (A x)_u` for `u ∈ T` (`residual(u, x)`, `x` read
    /// at `N(T)` only); then `(I + Δ G)ᵀ c = ρ` and one backward sweep of
    /// `f' + Σ_u c_u v_u` is the solution and its correction together (two sweeps
    /// over the factor instead of three). Needs [`LowRank::prepare_correction`] after
    /// the last [`LowRank::prepare`]. `rhs` holds the forward sweep `f = L⁻¹ Π b` on
    /// entry ([`Ldlt::forward_in_place`]: the same for every matrix solved with the same
    /// `b` and factors, so the caller may keep it) and the solution on return; without a
    /// change set up, the backward sweep alone (a solve with `A₀`).
    pub fn solve_corrected(
        &mut self,
        ldlt: &mut Ldlt,
        rhs: &mut [f64],
        target: f64,
        residual: impl Fn(usize, &[f64]) -> f64,
    ) -> Result<(), LdltError> {
        if self.lu.is_none() {
            return ldlt.backward_in_place(rhs);
        }
        if self.near.is_empty() && !self.support.is_empty() {
            return Err(LdltError("corrected solve without its set-up".into()));
        }
        self.update_forwarded(ldlt, rhs)?;
        let n = rhs.len();
        self.near_x.resize(n, 0.0);
        for _ in 0..SUPPORT_CORRECTIONS {
            // The solution at `near` exactly as the full sweep of `rhs` will give it.
            self.scratch.clear();
            self.scratch.extend_from_slice(rhs);
            ldlt.backward_partial(&self.near_sns, &mut self.scratch)?;
            for &u in &self.near {
                self.near_x[u] = self.scratch[ldlt.position(u)];
            }
            let mut c = Mat::<f64>::from_fn(self.support.len(), 1, |i, _| {
                residual(self.support[i], &self.near_x)
            });
            if c.norm_l2() <= target {
                break;
            }
            if let Some(lu) = &self.lu {
                lu.solve_transpose_in_place(c.as_mut());
            }
            for (i, &u) in self.support.iter().enumerate() {
                self.add_column(u, c[(i, 0)], rhs);
            }
        }
        ldlt.backward_in_place(rhs)
    }

    /// `f ← f − Σ_u (Δ y)_u v_u` for the forward sweep `f = L⁻¹ Π b` in `rhs`: the
    /// capacitance solve of an updated solve (a change must be set up).
    fn update_forwarded(&mut self, ldlt: &Ldlt, rhs: &mut [f64]) -> Result<(), LdltError> {
        let Some(lu) = &self.lu else {
            return Err(LdltError("updated solve without a change".into()));
        };
        // (Pᵀ z)_u = v_uᵀ D⁻¹ f.
        let n = rhs.len();
        let m = self.support.len();
        let inv_d = ldlt.inverse_diagonal();
        let mut y = Mat::<f64>::from_fn(m, 1, |i, _| {
            let a = self.slot[self.support[i]];
            let v = &self.w[a * n..(a + 1) * n];
            self.paths[a]
                .iter()
                .flat_map(|r| r.clone())
                .map(|k| v[k] * inv_d[k] * rhs[k])
                .sum()
        });
        lu.solve_in_place(y.as_mut());
        // f ← f − Σ_u (Δ y)_u v_u, then x = Πᵀ L⁻ᵀ D⁻¹ f.
        self.t.clear();
        self.t.resize(m, 0.0);
        for &(i, j, v) in &self.delta {
            self.t[i] += v * y[(j, 0)];
        }
        for (&u, &ti) in self.support.iter().zip(&self.t) {
            self.add_column(u, -ti, rhs);
        }
        Ok(())
    }
}

impl LowRank {
    /// The entries `(A⁻¹)_{uw}` of the inverse of the current matrix between the unknowns
    /// `units` (`k` of them; row-major `k × k`, `out[i k + j] = (A⁻¹)_{units[i] units[j]}`):
    /// `A = A₀` without a change set up, else `A₀ + P Δ Pᵀ` ([`LowRank::prepare`]), whose
    /// set-up is kept. With `G = Pᵀ A₀⁻¹ P` over the cached columns (those of `units` not
    /// cached yet are computed, a forward sweep over each one's path), the capacitance form
    /// of the module docs applied to `b = e_w` gives
    ///
    /// ```text
    ///   (A⁻¹)_{uw} = G_uw − G_uT Δ (I + G_TT Δ)⁻¹ G_Tw ,
    /// ```
    ///
    /// no sweep over the whole factor: the Schur complement of `A` on a few unknowns.
    /// Its rounding is that of the capacitance solve (an updated solve's, before the
    /// caller's refinement).
    pub fn inverse_entries(
        &mut self,
        ldlt: &mut Ldlt,
        units: &[usize],
    ) -> Result<Vec<f64>, LdltError> {
        let n = self.slot.len();
        if let Some(&u) = units.iter().find(|&&u| u >= n) {
            return Err(LdltError(format!(
                "inverse entry of unknown {u} of a matrix of {n} unknowns"
            )));
        }
        let mut seen = vec![false; n];
        let new: Vec<usize> = units
            .iter()
            .copied()
            .filter(|&u| self.slot[u] == NONE && !std::mem::replace(&mut seen[u], true))
            .collect();
        self.cache_new(ldlt, &new)?;
        let g = |a: usize, b: usize| self.gram[a.max(b)][a.min(b)];
        let k = units.len();
        let slots: Vec<usize> = units.iter().map(|&u| self.slot[u]).collect();
        let mut out = vec![0.0; k * k];
        for (i, &a) in slots.iter().enumerate() {
            for (j, &b) in slots.iter().enumerate() {
                out[i * k + j] = g(a, b);
            }
        }
        let Some(lu) = &self.lu else {
            return Ok(out);
        };
        let m = self.support.len();
        let support: Vec<usize> = self.support.iter().map(|&u| self.slot[u]).collect();
        let mut t = vec![0.0; m];
        for (j, &b) in slots.iter().enumerate() {
            // y = (I + G Δ)⁻¹ G_Tw, then Δ y.
            let mut y = Mat::<f64>::from_fn(m, 1, |i, _| g(support[i], b));
            lu.solve_in_place(y.as_mut());
            t.fill(0.0);
            for &(r, c, v) in &self.delta {
                t[r] += v * y[(c, 0)];
            }
            for (i, &a) in slots.iter().enumerate() {
                let s: f64 = support.iter().zip(&t).map(|(&s, ts)| g(a, s) * ts).sum();
                out[i * k + j] -= s;
            }
        }
        Ok(out)
    }

    /// `Σ_{u ∈ T} r_u²`: the part of the residual `r` on the support of the change.
    pub fn support_norm2(&self, r: &[f64]) -> f64 {
        self.support.iter().map(|&u| r[u] * r[u]).sum()
    }

    /// Solve `A x = r` in place for a right-hand side that is zero outside the support
    /// `T` of the change (only `r_T` is read): with `A⁻¹ P = A₀⁻¹ P (I + Δ G)⁻¹`
    /// (push-through of the capacitance form) and `A₀⁻¹ P c = Πᵀ L⁻ᵀ D⁻¹ Σ_u c_u v_u`,
    ///
    /// ```text
    ///   (I + Δ G) c = r_T ,      x = Πᵀ L⁻ᵀ D⁻¹ Σ_u c_u v_u ,
    /// ```
    ///
    /// a solve with the transposed capacitance matrix, `m` vector updates over the paths
    /// and one backward sweep (no forward sweep). The residual of an updated solve is
    /// of this kind: its error is that of `y` (the capacitance matrix is formed from `G`
    /// with rounding and can be ill-conditioned), `A (A₀⁻¹ P Δ δy) = P (I + Δ G) Δ δy`.
    /// Plainly with `A₀` when no change is set up.
    pub fn solve_on_support(&mut self, ldlt: &mut Ldlt, rhs: &mut [f64]) -> Result<(), LdltError> {
        let Some(lu) = &self.lu else {
            return ldlt.solve_in_place(rhs);
        };
        let mut c = Mat::<f64>::from_fn(self.support.len(), 1, |i, _| rhs[self.support[i]]);
        lu.solve_transpose_in_place(c.as_mut());
        rhs.fill(0.0);
        for (i, &u) in self.support.iter().enumerate() {
            self.add_column(u, c[(i, 0)], rhs);
        }
        ldlt.backward_in_place(rhs)
    }

    /// `rhs += α v_u` over the paths of `v_u` (the forward-swept column of the changed
    /// unknown `u`); nothing when `α = 0`.
    fn add_column(&self, u: usize, alpha: f64, rhs: &mut [f64]) {
        if alpha == 0.0 {
            return;
        }
        let n = rhs.len();
        let a = self.slot[u];
        let v = &self.w[a * n..(a + 1) * n];
        for r in &self.paths[a] {
            for (x, vi) in rhs[r.clone()].iter_mut().zip(&v[r.clone()]) {
                *x += alpha * vi;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Upper-triangle CSC of a quasi-definite matrix: a 2D 5-point Laplacian block
    /// (`nx × nx`, positive) and a negative diagonal block coupled to it.
    fn matrix(nx: usize) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
        let nu = nx * nx;
        let n = nu + nx;
        let mut col_ptr = vec![0];
        let mut rows = Vec::new();
        let mut vals = Vec::new();
        for j in 0..n {
            if j < nu {
                let (x, y) = (j % nx, j / nx);
                if y > 0 {
                    rows.push(j - nx);
                    vals.push(-1.0);
                }
                if x > 0 {
                    rows.push(j - 1);
                    vals.push(-1.0);
                }
                rows.push(j);
                vals.push(4.2);
            } else {
                let c = j - nu;
                rows.push(c * nx + c);
                vals.push(0.5);
                rows.push(j);
                vals.push(-2.0);
            }
            col_ptr.push(rows.len());
        }
        (n, col_ptr, rows, vals)
    }

    fn mul(n: usize, cp: &[usize], ri: &[usize], v: &[f64], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; n];
        for j in 0..n {
            for q in cp[j]..cp[j + 1] {
                let i = ri[q];
                y[i] += v[q] * x[j];
                if i != j {
                    y[j] += v[q] * x[i];
                }
            }
        }
        y
    }

    /// The updated solve satisfies the changed system to rounding, also after a second
    /// change that reuses cached columns and adds new ones, and when the change softens
    /// a block to almost nothing (a cell that fails).
    /// Columns cached again in the recorded order, on factors of the same matrix, give
    /// the same update bit for bit as the cache built change by change; bad columns are
    /// refused.
    #[test]
    fn cached_columns_rebuild_the_same_update() {
        let (n, cp, ri, base) = matrix(12);
        let b: Vec<f64> = (0..n).map(|i| ((i * 5 + 1) % 13) as f64 - 6.0).collect();
        let mut first = base.clone();
        for q in cp[40]..cp[41] {
            first[q] *= 0.5;
        }
        let mut second = first.clone();
        for q in cp[n - 3]..cp[n - 2] {
            second[q] *= 2.0;
        }
        let mut ldlt = Ldlt::analyse(n, &cp, &ri, None).unwrap();
        ldlt.factorize(&cp, &ri, &base).unwrap();
        let mut lr = LowRank::new(n);
        assert!(lr.prepare(&mut ldlt, &cp, &ri, &base, &first, 64).unwrap());
        assert!(lr.prepare(&mut ldlt, &cp, &ri, &base, &second, 64).unwrap());
        let mut x = b.clone();
        lr.solve(&mut ldlt, &mut x).unwrap();
        let columns = lr.cached_columns().to_vec();
        assert!(columns.len() > 2);

        let mut again = Ldlt::analyse(n, &cp, &ri, None).unwrap();
        again.factorize(&cp, &ri, &base).unwrap();
        let mut lr2 = LowRank::new(n);
        lr2.cache_columns(&mut again, &columns).unwrap();
        assert!(!lr2.is_active());
        assert_eq!(lr2.cached_columns(), columns.as_slice());
        assert!(
            lr2.prepare(&mut again, &cp, &ri, &base, &second, 64)
                .unwrap()
        );
        let mut y = b.clone();
        lr2.solve(&mut again, &mut y).unwrap();
        assert_eq!(x, y);
        assert!(lr2.cache_columns(&mut again, &[n]).is_err());
    }

    /// The inverse entries of the changed matrix between a few unknowns equal the
    /// entries of full solves with unit right-hand sides (to rounding), with and without
    /// a change set up, and the change stays set up.
    #[test]
    fn inverse_entries_are_those_of_unit_solves() {
        let (n, cp, ri, base) = matrix(12);
        let mut changed = base.clone();
        for q in cp[40]..cp[41] {
            changed[q] *= 1e-3;
        }
        for q in cp[n - 2]..cp[n - 1] {
            changed[q] *= 3.0;
        }
        let units = [n - 5, 40, 7, n - 1];
        for (values, update) in [(&base, false), (&changed, true)] {
            let mut ldlt = Ldlt::analyse(n, &cp, &ri, None).unwrap();
            ldlt.factorize(&cp, &ri, &base).unwrap();
            let mut lr = LowRank::new(n);
            if update {
                assert!(lr.prepare(&mut ldlt, &cp, &ri, &base, values, 64).unwrap());
            }
            let g = lr.inverse_entries(&mut ldlt, &units).unwrap();
            assert_eq!(lr.is_active(), update);
            let k = units.len();
            for (j, &w) in units.iter().enumerate() {
                let mut e = vec![0.0; n];
                e[w] = 1.0;
                let mut x = e.clone();
                lr.solve(&mut ldlt, &mut x).unwrap();
                // The solve is the inverse's column: its residual is at rounding.
                let r = mul(n, &cp, &ri, values, &x);
                let res = r
                    .iter()
                    .zip(&e)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(res < 1e-12, "residual {res}");
                for (i, &u) in units.iter().enumerate() {
                    let d = (g[i * k + j] - x[u]).abs();
                    assert!(
                        d <= 1e-12 * x[u].abs().max(1e-3),
                        "{u},{w}: {} vs {}",
                        g[i * k + j],
                        x[u]
                    );
                }
            }
        }
        let mut ldlt = Ldlt::analyse(n, &cp, &ri, None).unwrap();
        ldlt.factorize(&cp, &ri, &base).unwrap();
        assert!(LowRank::new(n).inverse_entries(&mut ldlt, &[n]).is_err());
    }

    #[test]
    fn update_solves_the_changed_matrix() {
        let (n, cp, ri, base) = matrix(12);
        let mut ldlt = Ldlt::analyse(n, &cp, &ri, None).unwrap();
        ldlt.factorize(&cp, &ri, &base).unwrap();
        let mut lr = LowRank::new(n);
        let b: Vec<f64> = (0..n).map(|i| ((i * 7 + 3) % 11) as f64 - 5.0).collect();
        let mut changed = base.clone();
        // Soften the couplings of unknowns 40..44 (both triangles are one stored entry).
        for j in 40..44 {
            for q in cp[j]..cp[j + 1] {
                changed[q] *= if ri[q] == j { 0.3 } else { 1e-6 };
            }
        }
        for round in 0..2 {
            if round == 1 {
                // A second change: more unknowns, some cached already.
                let j = n - 3;
                for q in cp[j]..cp[j + 1] {
                    changed[q] *= 2.5;
                }
            }
            assert!(
                lr.prepare(&mut ldlt, &cp, &ri, &base, &changed, 64)
                    .unwrap()
            );
            let mut x = b.clone();
            lr.solve(&mut ldlt, &mut x).unwrap();
            let ax = mul(n, &cp, &ri, &changed, &x);
            let err = ax
                .iter()
                .zip(&b)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12, "round {round}: residual {err:e}");
            // The same solve corrected from the residual on the support, read at the
            // support's neighbours from a backward sweep over their paths only.
            let rows = UpperRows::new(&cp, &ri);
            lr.prepare_correction(&ldlt, &cp, &ri, &rows).unwrap();
            assert!(lr.near.len() > lr.support.len());
            let mut xc = b.clone();
            ldlt.forward_in_place(&mut xc).unwrap();
            let residual = |u: usize, x: &[f64]| {
                let mut ax = 0.0;
                rows.for_row(u, &cp, &ri, |j, q| ax += changed[q] * x[j]);
                b[u] - ax
            };
            lr.solve_corrected(&mut ldlt, &mut xc, 1e-14, residual)
                .unwrap();
            let ax = mul(n, &cp, &ri, &changed, &xc);
            let err_c = ax
                .iter()
                .zip(&b)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err_c < 1e-12, "round {round}: corrected residual {err_c:e}");
            // The rows of the symmetric matrix: row u of A x from the row index.
            let ones = vec![1.0; n];
            let full = mul(n, &cp, &ri, &changed, &ones);
            for (u, f) in full.iter().enumerate() {
                let mut sum = 0.0;
                rows.for_row(u, &cp, &ri, |_, q| sum += changed[q]);
                assert!((sum - f).abs() < 1e-12, "row {u}: {sum} against {f}");
            }
            // A right-hand side on the changed unknowns only: one backward sweep.
            let mut r = vec![0.0; n];
            for (k, &u) in lr.support.iter().enumerate() {
                r[u] = b[u] + k as f64;
            }
            let mut x = r.clone();
            x[0] = 1e30; // not read
            lr.solve_on_support(&mut ldlt, &mut x).unwrap();
            let ax = mul(n, &cp, &ri, &changed, &x);
            let err = ax
                .iter()
                .zip(&r)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12, "round {round}: support residual {err:e}");
        }
        assert!(lr.cached_len() > 4);
        // Too many unknowns: nothing set up, a plain solve with A₀.
        assert!(!lr.prepare(&mut ldlt, &cp, &ri, &base, &changed, 3).unwrap());
        assert!(!lr.is_active());
        let mut x = b.clone();
        lr.solve(&mut ldlt, &mut x).unwrap();
        let ax = mul(n, &cp, &ri, &base, &x);
        let err = ax
            .iter()
            .zip(&b)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "plain residual {err:e}");
    }
}
