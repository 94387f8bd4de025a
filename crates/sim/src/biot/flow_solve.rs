//! The flow solve of the split schemes: sparse `LDLᵀ` of `diag(d) + Δt A`.

use porofrac_flow::FlowModel;

use porofrac_sparse::Ldlt;

use super::{BiotError, BiotResult, CouplingStats, snap_step};

/// Sparse `LDLᵀ` of `diag(d) + Δt A` on the flow pattern (symmetric positive definite:
/// every pivot must be positive), refactorized only when the matrix changes.
pub(super) struct FlowSolver {
    ldlt: Option<Ldlt>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    vals: Vec<f64>,
    factored_vals: Vec<f64>,
    /// `Δt` of the current factorization.
    dt: Option<f64>,
    /// The matrix to factorize again before the next solve (a resumed run).
    resume: Option<Vec<f64>>,
    /// Factorizations that only rebuilt the factors of a resumed run (not counted).
    rebuilt: usize,
}

impl FlowSolver {
    pub(super) fn new() -> Self {
        Self {
            ldlt: None,
            col_ptr: Vec::new(),
            row_idx: Vec::new(),
            vals: Vec::new(),
            factored_vals: Vec::new(),
            dt: None,
            resume: None,
            rebuilt: 0,
        }
    }

    /// The matrix of the current factors and its `Δt` (empty and `None` before the first).
    pub(super) fn memory(&self) -> (Vec<f64>, Option<f64>) {
        match &self.ldlt {
            Some(l) if l.is_factored() => (self.factored_vals.clone(), self.dt),
            _ => (Vec::new(), None),
        }
    }

    /// Factorize `factored` again before the next solve, with `dt` its step (see
    /// [`super::SchemeMemory`]).
    pub(super) fn resume(&mut self, factored: Vec<f64>, dt: Option<f64>) {
        self.dt = dt;
        self.resume = (!factored.is_empty()).then_some(factored);
    }

    /// The step to take for a requested `dt` at `t` (see `snap_step`).
    pub(super) fn step_for(&self, dt: f64, t: f64) -> f64 {
        snap_step(dt, t, self.dt)
    }

    pub(super) fn factorize<const D: usize>(
        &mut self,
        flow: &FlowModel<D>,
        diag: &[f64],
        dt: f64,
    ) -> BiotResult<()> {
        let a = flow.flux_matrix();
        self.vals.clear();
        self.vals.extend(a.val().iter().map(|v| v * dt));
        for (c, &p) in flow.diagonal_positions().iter().enumerate() {
            self.vals[p] += diag[c];
        }
        let failed = |why: String| {
            BiotError::Solver(format!(
                "flow factorization failed ({why}); a region lacks storage and a pressure anchor"
            ))
        };
        if let Some(old) = self.resume.take() {
            let ldlt = Self::analysed(&mut self.ldlt, &mut self.col_ptr, &mut self.row_idx, flow)?;
            if old.len() != self.row_idx.len() {
                return Err(BiotError::Input(format!(
                    "resumed flow matrix of {} entries, the pattern has {}",
                    old.len(),
                    self.row_idx.len()
                )));
            }
            ldlt.factorize(&self.col_ptr, &self.row_idx, &old)
                .map_err(|e| failed(e.0))?;
            self.rebuilt += 1;
            self.factored_vals = old;
        }
        if let Some(l) = &self.ldlt
            && l.is_factored()
            && self.vals == self.factored_vals
        {
            return Ok(());
        }
        self.dt = None;
        let ldlt = Self::analysed(&mut self.ldlt, &mut self.col_ptr, &mut self.row_idx, flow)?;
        ldlt.factorize(&self.col_ptr, &self.row_idx, &self.vals)
            .map_err(|e| failed(e.0))?;
        if !ldlt.pivots_positive() {
            return Err(failed("a pivot is not positive".into()));
        }
        self.factored_vals.clone_from(&self.vals);
        self.dt = Some(dt);
        Ok(())
    }

    /// The solver, analysed on the flow pattern at its first use.
    fn analysed<'s, const D: usize>(
        ldlt: &'s mut Option<Ldlt>,
        col_ptr: &mut Vec<usize>,
        row_idx: &mut Vec<usize>,
        flow: &FlowModel<D>,
    ) -> BiotResult<&'s mut Ldlt> {
        match ldlt {
            Some(l) => Ok(l),
            None => {
                let pat = flow.pattern();
                *col_ptr = pat.col_ptr().to_vec();
                *row_idx = pat.row_idx().to_vec();
                let l = Ldlt::analyse(pat.ncols(), col_ptr, row_idx, None)
                    .map_err(|e| BiotError::Solver(format!("flow factorization: {}", e.0)))?;
                Ok(ldlt.insert(l))
            }
        }
    }

    pub(super) fn solve(&mut self, rhs: &mut [f64]) -> BiotResult<()> {
        let ldlt = self
            .ldlt
            .as_mut()
            .ok_or_else(|| BiotError::Solver("flow solve before factorization".into()))?;
        ldlt.solve_in_place(rhs)
            .map_err(|e| BiotError::Solver(e.0))?;
        if let Some(c) = rhs.iter().position(|v| !v.is_finite()) {
            return Err(BiotError::Solver(format!(
                "non-finite pressure in cell {c}"
            )));
        }
        Ok(())
    }

    pub(super) fn stats(&self) -> CouplingStats {
        match &self.ldlt {
            Some(l) => CouplingStats {
                linear: "cholesky",
                numeric_factorizations: l.numeric_factorizations() - self.rebuilt,
                symbolic_factorizations: 1,
                factor_nnz: l.factor_nnz(),
                solves: l.solves(),
                low_rank_updates: 0,
            },
            None => CouplingStats {
                linear: "cholesky",
                ..CouplingStats::default()
            },
        }
    }
}
