//! The fully implicit monolithic scheme (Nilsen et al. (2017) eq. 30): the symmetric
//! quasi-definite block system, its `LDLᵀ` factorization and low-rank updates.
//!
//! # The residual of a solve, in the Jacobi-scaled system
//!
//! The pressure scale `s` (see [`super`]) brings the blocks of `A` to one size on
//! average, not row by row. A cell whose crack conducts by the cubic law has the
//! pressure row `−s² (M_K + Δt Σ_f T_f)` with `T_f ∝ w³/12μ`: the crack cell at a
//! well's wall, opened by centimetres, gives a diagonal 1e15 times that of the rock
//! around it (`Δt A_KK / M_K` = 1.7e15 at 39 minutes on the seed's fluid-lag scene
//! with the cubic law, docs/hydrofrac/validation.md). A
//! backward-stable solve `z` leaves a residual of about `ε |A| |z|` row by row, so the
//! relative residual `‖b − A z‖ / ‖b‖` has a floor set by that one row, whatever the
//! accuracy of the solution elsewhere, and can sit above the limit of a usable solve
//! ([`FRESH_RESIDUAL`]) while the solution is as good as the data.
//!
//! The solve is therefore judged in the symmetrically (Jacobi) scaled system
//!
//! ```text
//!   Â ŷ = b̂,    Â = D A D,   b̂ = D b,   z = D ŷ,   D = diag(|a_ii|)^{-1/2},
//! ```
//!
//! whose diagonal is `±1` (`+1` on the displacement rows of `K`, `−1` on the pressure
//! rows): every row counts relative to its own diagonal. The residual test is
//!
//! ```text
//!   ‖b̂ − Â ŷ‖ / ‖b̂‖ = ‖D (b − A z)‖ / ‖D b‖ ≤ FRESH_RESIDUAL .
//! ```
//!
//! The factors need not be computed from `Â`: a quasi-definite matrix is factorized
//! without pivoting and without regularisation, and the factors of `D A D` are those of
//! `A` rescaled, `Â = (D L D⁻¹)(D Λ D)(D L D⁻¹)ᵀ` — the very same floating-point numbers
//! times powers of two when `D` is rounded to powers of two, since each multiply–add of
//! the factorization and of the sweeps is then scaled exactly. The factorization of `A`
//! *is* the factorization of the scaled system; the scaling enters where it changes
//! something, the measure of the residual, and the solutions of the scenes are unchanged
//! bit for bit. The corrections keep aiming at the plain residual: the low-rank update
//! at its own target (a miss factorizes afresh), a fresh solve above the limit in it
//! corrected up to [`FRESH_REFINEMENTS`] times with the same factors (which lowers it
//! where it is an error of the solve and leaves it where it is the floor of one row).
//! Only the verdict on a fresh solve is the scaled residual.
//!
//! A singular system (a body held by no condition, a flow region without storage or
//! anchor) is still refused: the pivots of its null space are round-off, the scaled
//! solution `ŷ = D⁻¹ z` is then [`SINGULAR_GROWTH`] times the scaled data `D b` or more,
//! and the scaled residual is far above the limit; it is reported as numerically
//! singular. A refused solve whose scaled solution stays bounded is reported as an
//! inaccurate solve of a matrix whose diagonal spans the range it names, not as a
//! missing support.

use std::ops::Range;
use std::sync::Arc;

use faer::Par;
use porofrac_grid::Point;

use porofrac_sparse::{Ldlt, LdltError, LowRank, UpperRows};

use super::{
    BiotCoupling, BiotError, BiotResult, BiotState, BiotStep, BiotSystem, CouplingStats, Operators,
    SchemeMemory, check_state, check_step, snap_step,
};

/// The fully implicit monolithic scheme (Nilsen et al. (2017) eq. 30): one symmetric
/// quasi-definite system per step, solved by a sparse `LDLᵀ` factorization (see the module docs for
/// the block form and the scaling).
///
/// The block matrix depends on the stiffness, α and the node normals, the TPFA matrix,
/// the storage, `s` and `Δt`, not on the state: a step whose inputs are those of the last
/// factorization (same shared stiffness, or equal values; same flow values; the same
/// `Δt` up to the rounding of the step times, see `snap_step`) only builds the
/// right-hand side and back-solves with the stored factors. Its relative residual is
/// measured on the first solve with each factorization (a later solve with the same
/// factors is as accurate); [`BiotStep::residual`] reports that value.
pub struct Monolithic {
    scale: Option<f64>,
    s: f64,
    nm: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Per cell-local dof (aligned with the system's normals × D): block position or MAX.
    cpos: Vec<usize>,
    /// Per flow-pattern entry: block position (upper part) or MAX.
    fpos: Vec<usize>,
    ldlt: Ldlt,
    /// The current matrix (upper triangle).
    values: Vec<f64>,
    /// The matrix of the current factors (`values` differs from it by a low-rank change).
    factor_values: Vec<f64>,
    /// The update of the factors to `values`.
    low_rank: Box<LowRank>,
    /// Row access to the pattern (the residual of an updated solve on its support).
    rows: UpperRows,
    /// The position of each unknown's diagonal entry in `values`.
    diag: Vec<usize>,
    /// The forward sweep `L⁻¹ Π b` of the last updated solve: the factorization it was
    /// swept with (their count), `b` and the sweep.
    forward: Option<(usize, Vec<f64>, Vec<f64>)>,
    /// At most this many changed unknowns go through `low_rank`; beyond, a factorization.
    max_rank: usize,
    /// Matrices solved by a low-rank update.
    updates: usize,
    /// The inputs of the current matrix.
    factored: Option<FactorInputs>,
    /// Relative residual of the first solve with the current factorization.
    residual: f64,
    /// The default pressure scale and the stiffness it was computed from.
    default_scale: Option<(Arc<[f64]>, f64)>,
    /// The mechanical right-hand side of time-independent conditions and loads.
    base: Option<MechanicsBase>,
    work: MonolithicWork,
    /// The state to go on from at the next step (a resumed run, [`SchemeMemory`]).
    resume: Option<Box<SchemeMemory>>,
    /// Factorizations that only rebuilt the factors of a resumed run (not counted).
    rebuilt: usize,
}

/// `g`, the prescribed displacements and whether one is non-zero, for the conditions of
/// `dofs` and the loads of `loads` (addresses, compared only while `ops` is held) when
/// neither depends on time.
struct MechanicsBase {
    ops: Arc<ErasedOperators>,
    dofs: usize,
    loads: usize,
    g: Vec<f64>,
    uf: Vec<f64>,
    moved: bool,
}

/// What the block matrix of a [`Monolithic`] factorization was made of.
struct FactorInputs {
    k: Arc<[f64]>,
    ops: Arc<ErasedOperators>,
    s: f64,
    dt: f64,
    flux: Vec<f64>,
    accumulation: Vec<f64>,
}

/// The coupling data of a factorization, type-erased over `D` for comparison.
type ErasedOperators = dyn std::any::Any + Send + Sync;

/// Buffers reused by every step.
#[derive(Default)]
struct MonolithicWork {
    rhs: Vec<f64>,
    z: Vec<f64>,
    uf: Vec<f64>,
    full: Vec<f64>,
    flow: Vec<f64>,
    cv: Vec<f64>,
    cvo: Vec<f64>,
}

impl Monolithic {
    /// Build the block pattern and its symbolic `LDLᵀ` analysis (see `block_ordering`) for
    /// `system`. `scale` is the pressure scale `s` (Pa/m); `None` uses
    /// [`BiotSystem::default_pressure_scale`].
    pub fn new<const D: usize>(system: &BiotSystem<'_, D>, scale: Option<f64>) -> BiotResult<Self> {
        if let Some(s) = scale
            && !(s.is_finite() && s > 0.0)
        {
            return Err(BiotError::Input(format!(
                "pressure scale must be finite and > 0, got {s}"
            )));
        }
        let pat = system.mech.pattern;
        let grid = system.mech.grid;
        let dofs = system.mech.dofs;
        let ops = &*system.ops;
        let nm = pat.num_equations();
        let nc = system.num_cells();
        let fpat = system.flow.pattern();
        let (fcp, fri) = (fpat.col_ptr(), fpat.row_idx());
        let mut col_ptr = pat.col_ptr().to_vec();
        let mut row_idx = pat.row_idx().to_vec();
        let mut cpos = vec![usize::MAX; D * ops.normals.len()];
        let mut fpos = vec![usize::MAX; fri.len()];
        let mut eqs: Vec<usize> = Vec::new();
        for c in 0..nc {
            let start = row_idx.len();
            eqs.clear();
            for &n in grid.cell_nodes(c) {
                for a in 0..D {
                    if let Some(e) = dofs.equation(n, a) {
                        eqs.push(e);
                    }
                }
            }
            eqs.sort_unstable();
            eqs.dedup();
            row_idx.extend_from_slice(&eqs);
            for (i, &n) in grid.cell_nodes(c).iter().enumerate() {
                for a in 0..D {
                    if let Some(e) = dofs.equation(n, a) {
                        // Invariant: e was pushed above.
                        let k = eqs.binary_search(&e).unwrap_or(0);
                        cpos[D * (ops.node_ptr[c] + i) + a] = start + k;
                    }
                }
            }
            for q in fcp[c]..fcp[c + 1] {
                if fri[q] <= c {
                    fpos[q] = row_idx.len();
                    row_idx.push(nm + fri[q]);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let n = nm + nc;
        let ldlt = block_ordering(system, &col_ptr, &row_idx)?;
        let nnz = row_idx.len();
        let rows = UpperRows::new(&col_ptr, &row_idx);
        let diag = (0..n)
            .map(|j| {
                (col_ptr[j]..col_ptr[j + 1])
                    .find(|&q| row_idx[q] == j)
                    .ok_or_else(|| {
                        BiotError::Input(format!("coupled pattern without diagonal at {j}"))
                    })
            })
            .collect::<BiotResult<Vec<_>>>()?;
        Ok(Self {
            scale,
            s: 1.0,
            nm,
            col_ptr,
            row_idx,
            cpos,
            fpos,
            ldlt,
            values: vec![0.0; nnz],
            factor_values: Vec::new(),
            low_rank: Box::new(LowRank::new(n)),
            rows,
            diag,
            forward: None,
            max_rank: DEFAULT_MAX_RANK,
            updates: 0,
            factored: None,
            residual: 0.0,
            default_scale: None,
            base: None,
            work: MonolithicWork::default(),
            resume: None,
            rebuilt: 0,
        })
    }

    /// The matrices of the current factors and of the current step, the low-rank update
    /// on them and the step they were built for (see [`SchemeMemory`]).
    pub fn memory(&self) -> SchemeMemory {
        let factored = self.ldlt.is_factored() && !self.factor_values.is_empty();
        let count = self.ldlt.numeric_factorizations();
        SchemeMemory {
            factored: if factored {
                self.factor_values.clone()
            } else {
                Vec::new()
            },
            current: match &self.factored {
                Some(_) if factored => self.values.clone(),
                _ => Vec::new(),
            },
            dt: self.factored.as_ref().map(|f| f.dt),
            scale: self.s,
            columns: self.low_rank.cached_columns().to_vec(),
            forward: self
                .forward
                .as_ref()
                .filter(|(k, ..)| *k == count)
                .map(|(_, b, f)| (b.clone(), f.clone())),
            residual: self.residual,
            updates: self.updates,
            ..SchemeMemory::default()
        }
    }

    /// Go on from `memory` at the next step: the factors of its matrix are computed
    /// again and its low-rank update is set up anew on them.
    pub fn resume(&mut self, memory: SchemeMemory) {
        self.residual = memory.residual;
        self.updates = memory.updates;
        self.resume = Some(Box::new(memory));
    }

    /// Rebuild the state of [`Self::memory`] for the step of `sys` at `t` by `dt`.
    fn resume_with<const D: usize>(
        &mut self,
        sys: &BiotSystem<'_, D>,
        memory: SchemeMemory,
        t: f64,
        dt: f64,
    ) -> BiotResult<()> {
        if memory.factored.is_empty() {
            return Ok(());
        }
        let nnz = self.values.len();
        if memory.factored.len() != nnz
            || !(memory.current.is_empty() || memory.current.len() == nnz)
        {
            return Err(BiotError::Input(format!(
                "resumed coupled matrix of {} entries, the pattern has {nnz}",
                memory.factored.len()
            )));
        }
        let n = self.num_unknowns();
        if let Some((b, f)) = &memory.forward
            && (b.len() != n || f.len() != n)
        {
            return Err(BiotError::Input(format!(
                "resumed forward sweep of {} and {} values, the system has {n} unknowns",
                b.len(),
                f.len()
            )));
        }
        self.values.clone_from(&memory.factored);
        self.refactorize()?;
        self.rebuilt += 1;
        self.low_rank
            .cache_columns(&mut self.ldlt, &memory.columns)
            .map_err(|e| BiotError::Solver(e.0))?;
        self.s = memory.scale;
        let count = self.ldlt.numeric_factorizations();
        self.forward = memory.forward.map(|(b, f)| (count, b, f));
        let Some(fdt) = memory.dt else {
            return Ok(());
        };
        // The step's matrix is the one of the checkpoint: the run never stopped holds it
        // factorized (or updated) and does not build it again.
        self.fill(sys, snap_step(dt, t, Some(fdt)));
        if self.values != memory.current {
            return Ok(());
        }
        if self.values != self.factor_values {
            let updated = self
                .low_rank
                .prepare(
                    &mut self.ldlt,
                    &self.col_ptr,
                    &self.row_idx,
                    &self.factor_values,
                    &self.values,
                    self.max_rank,
                )
                .map_err(|e| BiotError::Solver(e.0))?;
            if !updated {
                return Err(BiotError::Input(
                    "resumed low-rank update exceeds the largest rank".into(),
                ));
            }
            self.low_rank
                .prepare_correction(&self.ldlt, &self.col_ptr, &self.row_idx, &self.rows)
                .map_err(|e| BiotError::Solver(e.0))?;
        }
        self.factored = Some(FactorInputs {
            k: sys.k_values.clone(),
            ops: sys.ops.clone(),
            s: self.s,
            dt: fdt,
            flux: sys.flow.flux_matrix().val().to_vec(),
            accumulation: sys.flow.accumulation().to_vec(),
        });
        Ok(())
    }

    /// Use `par` for factorizing (default sequential; a solve sweeps two independent
    /// parts of the factor on two threads, see `porofrac_sparse::Ldlt`).
    pub fn set_parallelism(&mut self, par: Par) {
        self.ldlt.set_parallelism(par);
    }
    /// Number of numeric factorizations done (a step with the same matrix reuses it).
    pub fn numeric_factorizations(&self) -> usize {
        self.ldlt.numeric_factorizations() - self.rebuilt
    }
    /// What the linear algebra did (see [`CouplingStats`]); one symbolic analysis.
    pub fn stats(&self) -> CouplingStats {
        CouplingStats {
            linear: "ldlt",
            numeric_factorizations: self.ldlt.numeric_factorizations() - self.rebuilt,
            symbolic_factorizations: 1,
            factor_nnz: self.ldlt.factor_nnz(),
            solves: self.ldlt.solves(),
            low_rank_updates: self.updates,
        }
    }
    /// Solve matrices that differ from the factorized one in at most `max_rank` unknowns
    /// by a low-rank update of the factors (0: factorize every new matrix).
    pub fn set_max_rank(&mut self, max_rank: usize) {
        self.max_rank = max_rank;
    }
    /// The pressure scale `s` of the last step.
    pub fn pressure_scale(&self) -> f64 {
        self.s
    }
    /// Number of unknowns of the block system (reduced displacements + cells).
    pub fn num_unknowns(&self) -> usize {
        self.col_ptr.len() - 1
    }

    /// The pressure scale for `sys`: the fixed one, or the default one, computed once per
    /// stiffness.
    fn scale_for<const D: usize>(&mut self, sys: &BiotSystem<'_, D>) -> f64 {
        if let Some(s) = self.scale {
            return s;
        }
        if let Some((k, s)) = &self.default_scale
            && Arc::ptr_eq(k, &sys.k_values)
        {
            return *s;
        }
        let s = sys.default_pressure_scale();
        self.default_scale = Some((sys.k_values.clone(), s));
        s
    }

    /// Whether the matrix for (`sys`, `s`, `dt`) is the one factorized. Shared data
    /// compare by pointer first, then by value (adopting the new pointers when equal).
    fn is_factored<const D: usize>(&mut self, sys: &BiotSystem<'_, D>, s: f64, dt: f64) -> bool {
        let Some(f) = self.factored.as_mut() else {
            return false;
        };
        if !self.ldlt.is_factored()
            || f.s != s
            || f.dt != dt
            || f.flux != sys.flow.flux_matrix().val()
            || f.accumulation != sys.flow.accumulation()
        {
            return false;
        }
        if !Arc::ptr_eq(&f.k, &sys.k_values) {
            if *f.k != *sys.k_values {
                return false;
            }
            f.k = sys.k_values.clone();
        }
        let same_ops = match f.ops.downcast_ref::<Operators<D>>() {
            Some(o) => std::ptr::eq(o, &*sys.ops) || *o == *sys.ops,
            None => false,
        };
        if same_ops {
            f.ops = sys.ops.clone();
        }
        same_ops
    }

    fn fill<const D: usize>(&mut self, sys: &BiotSystem<'_, D>, dt: f64) {
        let s = self.s;
        let ops = &*sys.ops;
        let mech_nnz = sys.k_values.len();
        self.values[..mech_nnz].copy_from_slice(&sys.k_values);
        self.values[mech_nnz..].fill(0.0);
        for c in 0..sys.num_cells() {
            let w = -s * ops.alpha[c];
            for i in ops.node_ptr[c]..ops.node_ptr[c + 1] {
                for a in 0..D {
                    let p = self.cpos[D * i + a];
                    if p != usize::MAX {
                        self.values[p] += w * ops.normals[i][a];
                    }
                }
            }
        }
        let a = sys.flow.flux_matrix();
        let av = a.val();
        for (q, &p) in self.fpos.iter().enumerate() {
            if p != usize::MAX {
                self.values[p] = -s * s * dt * av[q];
            }
        }
        let dpos = sys.flow.diagonal_positions();
        for (c, m) in sys.flow.accumulation().iter().enumerate() {
            self.values[self.fpos[dpos[c]]] -= s * s * m;
        }
    }

    /// `work.z ← L⁻¹ Π work.rhs`, from the sweep of the last updated solve when the
    /// factors are the same: every solve of a step has the same right-hand side except
    /// for the pressure rows of the cells whose transmissibilities a failure changed, so
    /// the new sweep is the old one plus the sweep of the difference, which runs over the
    /// paths of its few nonzeros in the elimination tree only (`Ldlt::forward_sparse`).
    fn forward_sweep(&mut self, work: &mut MonolithicWork) -> Result<(), LdltError> {
        let factors = self.ldlt.numeric_factorizations();
        let n = work.rhs.len();
        if let Some((k, b, f)) = self.forward.as_mut()
            && *k == factors
            && b.len() == n
        {
            let changed: Vec<usize> = (0..n).filter(|&i| b[i] != work.rhs[i]).collect();
            if changed.len() <= self.max_rank {
                if !changed.is_empty() {
                    let positions: Vec<usize> =
                        changed.iter().map(|&i| self.ldlt.position(i)).collect();
                    let mut d = vec![0.0; n];
                    for (&i, &p) in changed.iter().zip(&positions) {
                        d[p] = work.rhs[i] - b[i];
                    }
                    self.ldlt.forward_sparse(&positions, &mut d)?;
                    for (fi, di) in f.iter_mut().zip(&d) {
                        *fi += di;
                    }
                    b.clone_from(&work.rhs);
                }
                work.z.copy_from_slice(f);
                return Ok(());
            }
        }
        work.z.clone_from(&work.rhs);
        self.ldlt.forward_in_place(&mut work.z)?;
        let (mut b, mut f) = self
            .forward
            .take()
            .map(|(_, b, f)| (b, f))
            .unwrap_or_default();
        b.clone_from(&work.rhs);
        f.clone_from(&work.z);
        self.forward = Some((factors, b, f));
        Ok(())
    }

    /// Iterative refinement of a low-rank solve `work.z` of `work.rhs` (corrected once
    /// already by `LowRank::solve_corrected`): the updated
    /// solve loses digits as the change grows (the capacitance matrix pairs `G` with the
    /// large stiffness drop of a failed cell), so correct with the residual of the
    /// current matrix, `z += solve(b − A z)`, until it is at the level of a fresh
    /// factorization; when it does not get there, factorize. The loss is that of the
    /// capacitance solve, whose error `δy` leaves the residual `P (I + Δ G) Δ δy` on the
    /// changed unknowns only: when the residual elsewhere is below half the target, the
    /// correction is solved from those rows (`LowRank::solve_on_support`: one backward
    /// sweep instead of two; on the 3D hydraulic-fracture scene every correction, a
    /// first residual of 1e-11 to 1e-9 going to 1e-15 to 1e-14 in one step).
    fn refine_update(&mut self, work: &mut MonolithicWork) -> Result<(), LdltError> {
        let mut r = vec![0.0; work.z.len()];
        for _ in 0..LOW_RANK_REFINEMENTS {
            r.fill(0.0);
            self.sym_mul_add(&work.z, &mut r);
            let rn = work.rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
            for (ri, b) in r.iter_mut().zip(&work.rhs) {
                *ri = b - *ri;
            }
            let en = r.iter().map(|v| v * v).sum::<f64>().sqrt();
            if en <= LOW_RANK_RESIDUAL * rn {
                return Ok(());
            }
            let off = (en * en - self.low_rank.support_norm2(&r)).max(0.0).sqrt();
            if off <= 0.5 * LOW_RANK_RESIDUAL * rn {
                self.low_rank.solve_on_support(&mut self.ldlt, &mut r)?;
            } else {
                self.low_rank.solve(&mut self.ldlt, &mut r)?;
            }
            for (z, d) in work.z.iter_mut().zip(&r) {
                *z += d;
            }
        }
        if self.plain_relative_residual(&work.z, &work.rhs) <= LOW_RANK_RESIDUAL {
            return Ok(());
        }
        self.refactorize().map_err(|e| LdltError(e.to_string()))?;
        work.z.clone_from(&work.rhs);
        self.ldlt.solve_in_place(&mut work.z)
    }

    /// Iterative refinement of a step's first solve with new factors (fresh or updated)
    /// whose relative residual is above [`FRESH_RESIDUAL`], the limit of a usable solve:
    /// a matrix of widely spread scales (stiff rock beside a cell that has nearly lost
    /// its stiffness, pressures of tens of MPa at a held crack tip) can leave such a
    /// solve just above it, and a correction `z += solve(b − A z)` with the same factors
    /// brings it back to round-off, as direct solvers refine. The corrections aim at the
    /// plain residual `‖b − A z‖/‖b‖`: a solve at or below the limit in it is left as it
    /// is (no arithmetic changes), and where that residual has a floor set by one row
    /// far larger than the others (see the module docs) they leave it there; the verdict
    /// is the Jacobi-scaled residual of [`Self::finish`].
    fn refine_fresh(&mut self, work: &mut MonolithicWork) -> Result<(), LdltError> {
        let mut r = vec![0.0; work.z.len()];
        for _ in 0..FRESH_REFINEMENTS {
            if self.plain_relative_residual(&work.z, &work.rhs) <= FRESH_RESIDUAL {
                return Ok(());
            }
            r.fill(0.0);
            self.sym_mul_add(&work.z, &mut r);
            for (ri, b) in r.iter_mut().zip(&work.rhs) {
                *ri = b - *ri;
            }
            self.low_rank.solve(&mut self.ldlt, &mut r)?;
            for (z, d) in work.z.iter_mut().zip(&r) {
                *z += d;
            }
        }
        Ok(())
    }

    /// Factorize `values` (the current matrix) and drop the low-rank update.
    fn refactorize(&mut self) -> BiotResult<()> {
        self.low_rank.clear();
        self.factor_values.clear();
        self.ldlt
            .factorize(&self.col_ptr, &self.row_idx, &self.values)
            .map_err(|e| {
                BiotError::Solver(format!(
                    "LDLᵀ of the coupled system failed ({}); a flow region may lack \
                     storage and a pressure anchor",
                    e.0
                ))
            })?;
        self.factor_values.clone_from(&self.values);
        Ok(())
    }

    /// Why a first solve of relative residual `residual` (above [`FRESH_RESIDUAL`]) is
    /// refused: a singular system gives a scaled solution `y = D⁻¹ z` far larger than the
    /// scaled right-hand side `D b` (the pivots of its null space are round-off), named
    /// as such; otherwise the solve is only inaccurate, and the spread of the diagonal is
    /// named instead of a missing support.
    fn refusal(&self, residual: f64, z: &[f64], rhs: &[f64]) -> String {
        let (mut y, mut b) = ((0.0f64, 0), 0.0f64);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for (i, (&q, (zi, bi))) in self.diag.iter().zip(z.iter().zip(rhs)).enumerate() {
            let a = self.values[q].abs();
            let d2 = jacobi_weight2(self.values[q]);
            if (zi * zi / d2).sqrt() > y.0 {
                y = ((zi * zi / d2).sqrt(), i);
            }
            b = b.max((bi * bi * d2).sqrt());
            if a > 0.0 {
                lo = lo.min(a);
                hi = hi.max(a);
            }
        }
        let what = if y.1 < self.nm {
            format!("displacement unknown {}", y.1)
        } else {
            format!("the pressure of cell {}", y.1 - self.nm)
        };
        if y.0 > SINGULAR_GROWTH * b {
            format!(
                "coupled system numerically singular: relative residual {residual:.2e} \
                 (Jacobi-scaled), the scaled solution {:.1e} times the right-hand side, \
                 largest at {what}",
                y.0 / b
            )
        } else {
            format!(
                "coupled solve inaccurate: relative residual {residual:.2e} (Jacobi-scaled) \
                 above {FRESH_RESIDUAL:e} after {FRESH_REFINEMENTS} corrections; the \
                 diagonal of the coupled matrix spans {lo:.1e} to {hi:.1e}, the largest \
                 scaled change at {what}"
            )
        }
    }

    /// `‖A z − b‖ / ‖b‖` (`‖A z − b‖` for `b = 0`) with the current matrix.
    fn plain_relative_residual(&self, z: &[f64], rhs: &[f64]) -> f64 {
        let mut az = vec![0.0; z.len()];
        self.sym_mul_add(z, &mut az);
        let rn = rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
        let en = az
            .iter()
            .zip(rhs)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        if rn > 0.0 { en / rn } else { en }
    }

    /// The relative residual of `z` in the Jacobi-scaled system (see the module docs):
    /// `‖D (A z − b)‖ / ‖D b‖` (`‖D (A z − b)‖` for `b = 0`) with the current matrix and
    /// `D = diag(|A_ii|)^{-1/2}`.
    fn relative_residual(&self, z: &[f64], rhs: &[f64]) -> f64 {
        let mut az = vec![0.0; z.len()];
        self.sym_mul_add(z, &mut az);
        let (mut rn, mut en) = (0.0, 0.0);
        for ((&q, a), b) in self.diag.iter().zip(&az).zip(rhs) {
            let d2 = jacobi_weight2(self.values[q]);
            rn += d2 * b * b;
            en += d2 * (a - b) * (a - b);
        }
        let (rn, en) = (rn.sqrt(), en.sqrt());
        if rn > 0.0 { en / rn } else { en }
    }

    /// `y += A x` with the symmetric matrix stored as its upper triangle: the columns in
    /// two halves of equal entries on two threads, the second half's products summed
    /// into a vector of its own and added after (the same sums on any number of threads).
    fn sym_mul_add(&self, x: &[f64], y: &mut [f64]) {
        let n = self.num_unknowns();
        let part = |cols: Range<usize>, y: &mut [f64]| {
            for j in cols {
                for q in self.col_ptr[j]..self.col_ptr[j + 1] {
                    let (r, v) = (self.row_idx[q], self.values[q]);
                    y[r] += v * x[j];
                    if r != j {
                        y[j] += v * x[r];
                    }
                }
            }
        };
        let half = self
            .col_ptr
            .partition_point(|&p| p < self.col_ptr[n] / 2)
            .min(n);
        let mut second = vec![0.0; n];
        rayon::join(|| part(0..half, y), || part(half..n, &mut second));
        for (a, b) in y.iter_mut().zip(&second) {
            *a += b;
        }
    }
}

/// Changed unknowns up to which a new matrix is solved by a low-rank update of the
/// factors (`porofrac_sparse::LowRank`) rather than factorized: each new unknown costs a forward
/// sweep over its path of the elimination tree, every solve a plain one plus a dense
/// `m × m` solve and `2m` vector updates over the paths, and refinement steps as the
/// update grows. On the 3D hydraulic-fracture scene (40 min) 240 factorizes a few times
/// instead of 45 (bound 60) for the same answer (docs/BENCHMARKS.md); the answer once
/// depended on the bound only through the scale of the right-hand side after a
/// factorization, now that of the new factors.
const DEFAULT_MAX_RANK: usize = 240;

/// Relative residual a low-rank solve is refined to (that of a fresh factorization on
/// the hydraulic-fracture scenes, 1e-13 to 1e-12).
const LOW_RANK_RESIDUAL: f64 = 1e-12;

/// Refinement steps of a low-rank solve before the matrix is factorized instead.
const LOW_RANK_REFINEMENTS: usize = 3;

/// Largest relative residual of a step's first solve with new factors; above it the
/// solve is refined ([`Monolithic::refine_fresh`]) and, if still above, the system is
/// reported as numerically singular.
const FRESH_RESIDUAL: f64 = 1e-8;

/// The squared weight `D_ii² = 1/|a_ii|` of an unknown with diagonal entry `a_ii` in the
/// Jacobi scaling of the residual (1 for a zero diagonal).
fn jacobi_weight2(a: f64) -> f64 {
    if a != 0.0 { 1.0 / a.abs() } else { 1.0 }
}

/// A refused solve whose scaled solution `D⁻¹ z` exceeds the scaled right-hand side
/// `D b` (largest entries) this many times is reported as singular: the factors of a
/// system with a null space give it pivots of round-off size and a solution of the
/// order of `1/ε` times the data, while a nonsingular one stays bounded by the condition
/// of the scaled matrix (1 to 2e3 over the fresh solves of the seed's fluid-lag scene
/// with the cubic law on `refine = 17`, docs/hydrofrac/validation.md).
const SINGULAR_GROWTH: f64 = 1e10;

/// Corrections of a first solve above [`FRESH_RESIDUAL`] before it is reported.
const FRESH_REFINEMENTS: usize = 3;

/// Unknowns per leaf of the dissection of the block system.
const DISSECTION_LEAF: usize = 8;

/// The symbolic analysis of the block system in the elimination order of the two with
/// the fewer factor entries: the dissection of [`block_dissection`] or faer's
/// approximate minimum degree. The dissection wins on the Mandel grid (below); on the
/// hydraulic-fracture scenes minimum degree has fewer entries — 6.1 against 12.6
/// million on the 3D scene with `refine = 6`, 3.3 against 5.1 million on the bundled 2D
/// one (docs/BENCHMARKS.md) — and every sweep and factorization reads that many. The
/// second analysis costs a small part of one numeric factorization.
fn block_ordering<const D: usize>(
    sys: &BiotSystem<'_, D>,
    col_ptr: &[usize],
    row_idx: &[usize],
) -> BiotResult<Ldlt> {
    let n = col_ptr.len() - 1;
    let perm = block_dissection(sys, col_ptr, row_idx);
    let nd = Ldlt::analyse(n, col_ptr, row_idx, Some(&perm)).map_err(|e| BiotError::Solver(e.0))?;
    let amd = Ldlt::analyse(n, col_ptr, row_idx, None).map_err(|e| BiotError::Solver(e.0))?;
    Ok(if amd.factor_nnz() < nd.factor_nnz() {
        amd
    } else {
        nd
    })
}

/// The elimination order of the block system: [`crate::ordering::pattern_dissection`]
/// with each displacement equation at its node and each pressure at its cell centroid;
/// equations shared by several nodes (platens, coupled to a whole boundary) last. On
/// the 40 × 40 Mandel grid its factor has 9 % fewer entries than AMD's (379 556
/// against 419 351) and the solves take 17 % fewer instructions.
fn block_dissection<const D: usize>(
    sys: &BiotSystem<'_, D>,
    col_ptr: &[usize],
    row_idx: &[usize],
) -> Vec<usize> {
    let grid = sys.mech.grid;
    let dofs = sys.mech.dofs;
    let nm = dofs.num_equations();
    let mut owner = vec![None; nm];
    let mut shared = vec![false; nm];
    for v in 0..grid.num_nodes() {
        for a in 0..D {
            if let Some(e) = dofs.equation(v, a) {
                shared[e] |= owner[e].is_some();
                owner[e] = Some(v);
            }
        }
    }
    let mut pos: Vec<Option<Point<D>>> = owner
        .iter()
        .zip(&shared)
        .map(|(o, &sh)| o.filter(|_| !sh).map(|v| *grid.node(v)))
        .collect();
    pos.extend((0..sys.num_cells()).map(|c| Some(*grid.cell_centroid(c))));
    crate::ordering::pattern_dissection(&pos, col_ptr, row_idx, DISSECTION_LEAF)
}

impl<const D: usize> BiotCoupling<D> for Monolithic {
    fn name(&self) -> &str {
        "monolithic"
    }

    fn step(
        &mut self,
        sys: &BiotSystem<'_, D>,
        state: &BiotState,
        t: f64,
        dt: f64,
    ) -> BiotResult<BiotStep> {
        check_step(dt, t)?;
        check_state(sys, state)?;
        if self.num_unknowns() != sys.mech.pattern.num_equations() + sys.num_cells()
            || self.nm != sys.mech.pattern.num_equations()
            || self.cpos.len() != D * sys.ops.normals.len()
            || self.fpos.len() != sys.flow.pattern().row_idx().len()
        {
            return Err(BiotError::Input(
                "monolithic solver built for another system".into(),
            ));
        }
        if let Some(memory) = self.resume.take() {
            self.resume_with(sys, *memory, t, dt)?;
        }
        let dt = snap_step(dt, t, self.factored.as_ref().map(|f| f.dt));
        if dt == 0.0
            && let Some(c) = sys.flow.accumulation().iter().position(|&m| m <= 0.0)
        {
            return Err(BiotError::Input(format!(
                "an undrained step (Δt = 0) needs storage in every cell, cell {c} has none \
                 (the system would be a saddle point): use a small Δt > 0"
            )));
        }
        // With factors at hand the scale stays theirs, so that a change of a few cells
        // changes a few entries (the solution does not depend on the scale); the default
        // scale of a new stiffness is computed only for a new factorization.
        let s = if self.ldlt.is_factored() && !self.factor_values.is_empty() {
            self.s
        } else {
            self.scale_for(sys)
        };
        let fresh = !self.is_factored(sys, s, dt);
        if fresh {
            self.factored = None;
            let mut updated = false;
            if self.ldlt.is_factored() && !self.factor_values.is_empty() && self.max_rank > 0 {
                self.s = s;
                self.fill(sys, dt);
                updated = self
                    .low_rank
                    .prepare(
                        &mut self.ldlt,
                        &self.col_ptr,
                        &self.row_idx,
                        &self.factor_values,
                        &self.values,
                        self.max_rank,
                    )
                    .map_err(|e| BiotError::Solver(e.0))?;
                if updated {
                    self.low_rank
                        .prepare_correction(&self.ldlt, &self.col_ptr, &self.row_idx, &self.rows)
                        .map_err(|e| BiotError::Solver(e.0))?;
                }
            }
            if updated {
                self.updates += 1;
            } else {
                self.s = self.scale_for(sys);
                self.fill(sys, dt);
                self.refactorize()?;
            }
            self.factored = Some(FactorInputs {
                k: sys.k_values.clone(),
                ops: sys.ops.clone(),
                s: self.s,
                dt,
                flux: sys.flow.flux_matrix().val().to_vec(),
                accumulation: sys.flow.accumulation().to_vec(),
            });
        }
        // The scale of the matrix now factorized or updated: a new factorization takes
        // the scale of the new matrix, and the pressure rows of the right-hand side and
        // the pressure of the solution must use that very scale.
        let s = self.s;
        let (nm, nc) = (self.nm, sys.num_cells());
        let t1 = t + dt;
        let mut w = std::mem::take(&mut self.work);
        w.rhs.resize(nm + nc, 0.0);
        w.flow.resize(nc, 0.0);
        w.cv.resize(nc, 0.0);
        w.cvo.resize(nc, 0.0);
        let moved = self.mechanics_base(sys, t1, &mut w)?;
        sys.coupling_terms(
            &state.pressure,
            &state.displacement,
            &mut w.rhs[..nm],
            &mut w.cvo,
        );
        sys.flow_residual(&state.pressure, t1, dt, &mut w.flow)?;
        if moved {
            sys.alpha_volume_change(&w.uf, &mut w.cv)?;
            for c in 0..nc {
                w.rhs[nm + c] = s * (-w.flow[c] + w.cv[c] - w.cvo[c]);
            }
        } else {
            for ((r, f), v) in w.rhs[nm..].iter_mut().zip(&w.flow).zip(&w.cvo) {
                *r = s * (-f - v);
            }
        }
        w.z.clone_from(&w.rhs);
        let solved = if self.low_rank.is_active() {
            // f = L⁻¹ Π b: every solve of a step has the same right-hand side, so with the
            // same factors the forward sweep is the one of the step's first solve.
            let swept = self.forward_sweep(&mut w);
            // The residual row u of the current matrix at x (read at u's neighbours).
            let (cp, ri, values, rows, b) = (
                &self.col_ptr,
                &self.row_idx,
                &self.values,
                &self.rows,
                &w.rhs,
            );
            let residual = |u: usize, x: &[f64]| {
                let mut ax = 0.0;
                rows.for_row(u, cp, ri, |j, q| ax += values[q] * x[j]);
                b[u] - ax
            };
            // Half the target on the support leaves room for the residual elsewhere.
            let target = 0.5 * LOW_RANK_RESIDUAL * b.iter().map(|v| v * v).sum::<f64>().sqrt();
            swept
                .and_then(|()| {
                    self.low_rank
                        .solve_corrected(&mut self.ldlt, &mut w.z, target, residual)
                })
                .and_then(|()| self.refine_update(&mut w))
        } else {
            self.low_rank.solve(&mut self.ldlt, &mut w.z)
        };
        let result = solved
            .and_then(|()| {
                if fresh {
                    self.refine_fresh(&mut w)
                } else {
                    Ok(())
                }
            })
            .map_err(|e| BiotError::Solver(e.0))
            .and_then(|()| self.finish(sys, state, &w, fresh));
        self.work = w;
        result
    }
}

impl Monolithic {
    /// The pressure change at every cell of `cells` of a void source `volumes[d] / Δt`
    /// in cell `d` over the last step's matrix (row-major `k × k`, `out[i k + j]` at
    /// `cells[i]` for a source in `cells[j]`): the source enters the pressure row of `d`
    /// as `−s · volumes[d]`, and the pressure of `c` is `s` times its unknown, so the
    /// entry is `−s² volumes[d] (A⁻¹)_{cd}`, entries of the inverse of the block matrix
    /// from the factors and the low-rank update of the last step
    /// (`porofrac_sparse::LowRank::inverse_entries`): no solve over the whole factor.
    /// `None` when `sys` is not the system of the last step's matrix.
    pub fn pressure_responses<const D: usize>(
        &mut self,
        sys: &BiotSystem<'_, D>,
        cells: &[usize],
        volumes: &[f64],
    ) -> BiotResult<Option<Vec<f64>>> {
        let Some(dt) = self.factored.as_ref().map(|f| f.dt) else {
            return Ok(None);
        };
        if cells.iter().any(|&c| c >= sys.num_cells()) || volumes.len() != cells.len() {
            return Err(BiotError::Input(format!(
                "responses of {} cells with {} volumes in a system of {} cells",
                cells.len(),
                volumes.len(),
                sys.num_cells()
            )));
        }
        if !self.is_factored(sys, self.s, dt) {
            return Ok(None);
        }
        let units: Vec<usize> = cells.iter().map(|&c| self.nm + c).collect();
        let mut g = self
            .low_rank
            .inverse_entries(&mut self.ldlt, &units)
            .map_err(|e| BiotError::Solver(e.0))?;
        let k = cells.len();
        let s2 = self.s * self.s;
        for row in g.chunks_mut(k.max(1)) {
            for (v, vol) in row.iter_mut().zip(volumes) {
                *v *= -s2 * vol;
            }
        }
        Ok(Some(g))
    }

    /// The accuracy attained by the last step's solve in the pressure of each cell of
    /// `cells` (Pa): the size of the change one step of iterative refinement with the
    /// current factors makes there, `s |(A⁻¹ (b − A z))_{n_m + c}|`, the first-order
    /// estimate of the solve's error in that pressure (the residual `b − A z` of the
    /// solve read in working precision, with its floor `ε |A| |z|` in the rows of a
    /// crack opened by centimetres, see the module docs). The solution is not changed.
    /// `None` when `sys` is not the system of the last step's matrix or no step was
    /// solved with it.
    pub fn pressure_accuracy<const D: usize>(
        &mut self,
        sys: &BiotSystem<'_, D>,
        cells: &[usize],
    ) -> BiotResult<Option<Vec<f64>>> {
        let Some(dt) = self.factored.as_ref().map(|f| f.dt) else {
            return Ok(None);
        };
        let n = self.num_unknowns();
        if cells.iter().any(|&c| c >= sys.num_cells()) {
            return Err(BiotError::Input(format!(
                "pressure accuracy of cells beyond the system's {}",
                sys.num_cells()
            )));
        }
        if !self.is_factored(sys, self.s, dt) || self.work.z.len() != n || self.work.rhs.len() != n
        {
            return Ok(None);
        }
        let mut r = vec![0.0; n];
        self.sym_mul_add(&self.work.z, &mut r);
        for (ri, b) in r.iter_mut().zip(&self.work.rhs) {
            *ri = b - *ri;
        }
        self.low_rank
            .solve(&mut self.ldlt, &mut r)
            .map_err(|e| BiotError::Solver(e.0))?;
        Ok(Some(
            cells
                .iter()
                .map(|&c| self.s * r[self.nm + c].abs())
                .collect(),
        ))
    }

    /// The last step's solve from `state` corrected by one step of iterative refinement
    /// with the current factors, `z += A⁻¹ (b − A z)` (kept as the last solve: a
    /// [`Self::pressure_accuracy`] after it estimates the corrected one). `None` when
    /// `sys` is not the system of the last step's matrix or no step was solved with it.
    pub fn refine_last<const D: usize>(
        &mut self,
        sys: &BiotSystem<'_, D>,
        state: &BiotState,
    ) -> BiotResult<Option<BiotStep>> {
        let Some(dt) = self.factored.as_ref().map(|f| f.dt) else {
            return Ok(None);
        };
        let n = self.num_unknowns();
        if !self.is_factored(sys, self.s, dt) || self.work.z.len() != n || self.work.rhs.len() != n
        {
            return Ok(None);
        }
        let mut w = std::mem::take(&mut self.work);
        let mut r = vec![0.0; n];
        self.sym_mul_add(&w.z, &mut r);
        for (ri, b) in r.iter_mut().zip(&w.rhs) {
            *ri = b - *ri;
        }
        let solved = self.low_rank.solve(&mut self.ldlt, &mut r);
        if solved.is_ok() {
            for (z, d) in w.z.iter_mut().zip(&r) {
                *z += d;
            }
        }
        let out = solved
            .map_err(|e| BiotError::Solver(e.0))
            .and_then(|()| self.finish(sys, state, &w, false));
        self.work = w;
        out.map(Some)
    }

    /// The mechanical part of the right-hand side at `t` into `work.rhs` and the
    /// prescribed displacements into `work.uf` (see `BiotSystem::mechanics_base`), kept
    /// from the first step when the conditions and loads do not depend on time.
    fn mechanics_base<const D: usize>(
        &mut self,
        sys: &BiotSystem<'_, D>,
        t: f64,
        work: &mut MonolithicWork,
    ) -> BiotResult<bool> {
        let nm = self.nm;
        let dofs = std::ptr::from_ref(sys.mech.dofs) as usize;
        let loads = std::ptr::from_ref(sys.mech.loads) as usize;
        if let Some(b) = &self.base
            && b.dofs == dofs
            && b.loads == loads
            && b.ops
                .downcast_ref::<Operators<D>>()
                .is_some_and(|o| std::ptr::eq(o, &*sys.ops))
        {
            work.rhs[..nm].copy_from_slice(&b.g);
            work.uf.clone_from(&b.uf);
            return Ok(b.moved);
        }
        self.base = None;
        let moved = sys.mechanics_base(t, &mut work.uf, &mut work.full, &mut work.rhs[..nm])?;
        if sys.mech.dofs.is_time_independent() && sys.mech.loads.is_time_independent() {
            self.base = Some(MechanicsBase {
                ops: sys.ops.clone(),
                dofs,
                loads,
                g: work.rhs[..nm].to_vec(),
                uf: work.uf.clone(),
                moved,
            });
        }
        Ok(moved)
    }

    /// Check the solution `work.z` (finite; the residual after a fresh factorization) and
    /// build the new state.
    fn finish<const D: usize>(
        &mut self,
        sys: &BiotSystem<'_, D>,
        state: &BiotState,
        work: &MonolithicWork,
        fresh: bool,
    ) -> BiotResult<BiotStep> {
        let (z, rhs) = (&work.z, &work.rhs);
        if let Some(i) = z.iter().position(|v| !v.is_finite()) {
            return Err(BiotError::Solver(format!(
                "non-finite solution at unknown {i}"
            )));
        }
        if fresh {
            let residual = self.relative_residual(z, rhs);
            if residual > FRESH_RESIDUAL {
                // The factors are unusable: the next step factorizes again.
                self.factored = None;
                return Err(BiotError::Solver(self.refusal(residual, z, rhs)));
            }
            self.residual = residual;
        }
        let nm = self.nm;
        let mut u = work.uf.clone();
        sys.mech.dofs.scatter(&z[..nm], &mut u);
        let s = self.s;
        let p = state
            .pressure
            .iter()
            .zip(&z[nm..])
            .map(|(p, y)| p + s * y)
            .collect();
        Ok(BiotStep {
            state: BiotState {
                displacement: u,
                pressure: p,
            },
            iterations: 1,
            residual: self.residual,
        })
    }
}
