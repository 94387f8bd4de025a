//! The mechanics solve of the split schemes: `K x = g + Cᵀ (p − p₀)` by sparse Cholesky.

use std::sync::Arc;

use crate::solve::DirectSolver;

use super::{BiotError, BiotResult, BiotSystem, CouplingStats};

/// The mechanics solve `K x = g + Cᵀ (p − p₀)` shared by the split schemes.
pub(super) struct MechSolver {
    solver: Option<DirectSolver>,
    /// The stiffness of the current factorization.
    factored: Option<Arc<[f64]>>,
    solves: usize,
    rhs: Vec<f64>,
    full: Vec<f64>,
    /// The stiffness to factorize again before the next solve (a resumed run).
    resume: Option<Vec<f64>>,
    /// Factorizations that only rebuilt the factors of a resumed run (not counted).
    rebuilt: usize,
}

impl MechSolver {
    pub(super) fn new() -> Self {
        Self {
            solver: None,
            factored: None,
            solves: 0,
            rhs: Vec::new(),
            full: Vec::new(),
            resume: None,
            rebuilt: 0,
        }
    }

    /// The stiffness of the current factors (empty before the first).
    pub(super) fn memory(&self) -> Vec<f64> {
        self.factored.as_ref().map_or_else(Vec::new, |k| k.to_vec())
    }

    /// Factorize `stiffness` again before the next solve (see [`super::SchemeMemory`]).
    pub(super) fn resume(&mut self, stiffness: Vec<f64>) {
        self.resume = (!stiffness.is_empty()).then_some(stiffness);
    }

    /// Displacement in equilibrium with the loads at `t` and the pressure `p`.
    pub(super) fn solve<const D: usize>(
        &mut self,
        sys: &BiotSystem<'_, D>,
        t: f64,
        p: &[f64],
        u_out: &mut Vec<f64>,
    ) -> BiotResult<()> {
        let pat = sys.mech.pattern;
        if self.solver.is_none() {
            self.solver = Some(DirectSolver::new(pat)?);
        }
        let solver = self
            .solver
            .as_mut()
            .ok_or_else(|| BiotError::Solver("mechanics solver missing".into()))?;
        if let Some(k) = self.resume.take() {
            solver.factorize(pat, &k)?;
            self.rebuilt += 1;
            self.factored = Some(Arc::from(k));
        }
        let same = match &self.factored {
            Some(k) => Arc::ptr_eq(k, &sys.k_values) || **k == *sys.k_values,
            None => false,
        };
        if !same {
            self.factored = None;
            solver.factorize(pat, &sys.k_values)?;
        }
        self.factored = Some(sys.k_values.clone());
        self.rhs.resize(pat.num_equations(), 0.0);
        sys.mechanics_base(t, u_out, &mut self.full, &mut self.rhs)?;
        sys.add_pore_pressure_equations(p, &mut self.rhs);
        solver.solve_in_place(&mut self.rhs)?;
        self.solves += 1;
        sys.mech.dofs.scatter(&self.rhs, u_out);
        Ok(())
    }

    pub(super) fn stats(&self) -> CouplingStats {
        CouplingStats {
            linear: "cholesky",
            numeric_factorizations: self
                .solver
                .as_ref()
                .map_or(0, |s| s.numeric_factorizations() - self.rebuilt),
            symbolic_factorizations: self
                .solver
                .as_ref()
                .map_or(0, |s| s.symbolic_factorizations()),
            factor_nnz: self.solver.as_ref().map_or(0, |s| s.factor_nnz()),
            solves: self.solves,
            low_rank_updates: 0,
        }
    }
}
