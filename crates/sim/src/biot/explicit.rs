//! The explicit-pressure update of Nilsen et al. (2017) §2.5: the volumetric coupling only
//! in fractured cells, the flow implicit in the fluxes.

use super::{
    BiotCoupling, BiotResult, BiotState, BiotStep, BiotSystem, CouplingStats, FlowSolver,
    MechSolver, SchemeMemory, check_len, check_state, check_step,
};

/// The explicit-pressure coupling of Nilsen et al. (2017) §2.5: the volumetric term only in
/// fractured cells, no feedback iteration (see the module docs).
pub struct ExplicitPressure {
    /// `fractured[K]`: whether cell `K` carries the volumetric coupling term.
    pub fractured: Vec<bool>,
    flow: FlowSolver,
    mech: MechSolver,
}

impl ExplicitPressure {
    /// The scheme with the given fractured-cell flags (one per cell).
    pub fn new(fractured: Vec<bool>) -> Self {
        Self {
            fractured,
            flow: FlowSolver::new(),
            mech: MechSolver::new(),
        }
    }

    /// What the linear algebra did: the flow and mechanics factorizations and solves
    /// together (see [`CouplingStats`]).
    pub fn stats(&self) -> CouplingStats {
        self.flow.stats().add(self.mech.stats())
    }

    /// The flow and mechanics matrices of the current factors (see [`SchemeMemory`]).
    pub fn memory(&self) -> SchemeMemory {
        SchemeMemory::of_split(&self.flow, &self.mech)
    }

    /// Go on from `memory`: the factors are computed again before the next solve.
    pub fn resume(&mut self, memory: SchemeMemory) {
        memory.resume_split(&mut self.flow, &mut self.mech);
    }

    /// The pressure at `t + dt` from the displacements `u_new = u^{n+1}`, `u_old = uⁿ`
    /// (nodal, `D · nodes`) and the pressure `p_old = pⁿ`: solves
    /// `(M + Δt A)(p^{n+1} − pⁿ) = Δt (b(t + Δt) − A pⁿ) − Σ_{K fractured} α_K ΔV_K(u^{n+1} − uⁿ) e_K`.
    /// Volume changes of cells not flagged fractured are ignored. Errors: lengths, a
    /// negative `dt`, or a singular flow matrix (`dt = 0` with a cell without storage).
    pub fn update_pressure<const D: usize>(
        &mut self,
        sys: &BiotSystem<'_, D>,
        u_new: &[f64],
        u_old: &[f64],
        p_old: &[f64],
        t: f64,
        dt: f64,
    ) -> BiotResult<Vec<f64>> {
        check_step(dt, t)?;
        let dt = self.flow.step_for(dt, t);
        let nc = sys.num_cells();
        check_len("fractured flags", self.fractured.len(), nc)?;
        check_len("old pressure", p_old.len(), nc)?;
        let mut rhs = vec![0.0; nc];
        sys.flow_residual(p_old, t + dt, dt, &mut rhs)?;
        let mut a = vec![0.0; nc];
        let mut b = vec![0.0; nc];
        sys.alpha_volume_change(u_new, &mut a)?;
        sys.alpha_volume_change(u_old, &mut b)?;
        for c in 0..nc {
            if self.fractured[c] {
                rhs[c] -= a[c] - b[c];
            }
        }
        self.flow.factorize(sys.flow, sys.flow.accumulation(), dt)?;
        self.flow.solve(&mut rhs)?;
        Ok(p_old.iter().zip(&rhs).map(|(p, d)| p + d).collect())
    }
}

impl<const D: usize> BiotCoupling<D> for ExplicitPressure {
    fn name(&self) -> &str {
        "explicit-pressure"
    }

    /// Staggered step: the mechanics in equilibrium with the loads at `t + dt` and the
    /// old pressure, then [`ExplicitPressure::update_pressure`].
    fn step(
        &mut self,
        sys: &BiotSystem<'_, D>,
        state: &BiotState,
        t: f64,
        dt: f64,
    ) -> BiotResult<BiotStep> {
        check_step(dt, t)?;
        check_state(sys, state)?;
        let mut u = Vec::new();
        self.mech.solve(sys, t + dt, &state.pressure, &mut u)?;
        let p = self.update_pressure(sys, &u, &state.displacement, &state.pressure, t, dt)?;
        Ok(BiotStep {
            state: BiotState {
                displacement: u,
                pressure: p,
            },
            iterations: 1,
            residual: 0.0,
        })
    }
}
