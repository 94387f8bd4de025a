//! The fixed-stress split: flow with the stabilisation `α²/K_dr`, then mechanics,
//! iterated within each step.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use super::{
    BiotCoupling, BiotError, BiotResult, BiotState, BiotStep, BiotSystem, CouplingStats,
    FlowSolver, MechSolver, SchemeMemory, check_state, check_step, inf_norm,
};

/// The fixed-stress split (see the module docs): flow with the stabilisation
/// `α²/K_dr`, then mechanics, iterated to convergence within each step.
pub struct FixedStress {
    /// Relative pressure change `‖δp^{k+1} − δp^k‖∞ / max(‖p − p₀‖∞, ‖δp‖∞)` at which
    /// the iteration stops (it also stops when the change is below the rounding level
    /// `16 ε ‖p‖∞`). The displacement is solved exactly for each pressure iterate, so its
    /// change is a bounded image of the pressure change.
    pub tolerance: f64,
    /// Iterations allowed per step.
    pub max_iterations: usize,
    flow: FlowSolver,
    mech: MechSolver,
    interrupt: Option<Arc<AtomicBool>>,
}

impl FixedStress {
    /// A fixed-stress scheme with the given tolerance and iteration limit.
    pub fn new(tolerance: f64, max_iterations: usize) -> Self {
        Self {
            tolerance,
            max_iterations,
            flow: FlowSolver::new(),
            mech: MechSolver::new(),
            interrupt: None,
        }
    }

    /// Poll `flag` before every iteration after the first: when it is set, the step ends
    /// with [`BiotError::Interrupted`] (Ctrl-C during a long step).
    pub fn set_interrupt(&mut self, flag: Option<Arc<AtomicBool>>) {
        self.interrupt = flag;
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
}

impl<const D: usize> BiotCoupling<D> for FixedStress {
    fn name(&self) -> &str {
        "fixed-stress"
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
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(BiotError::Input(format!(
                "fixed-stress tolerance must be > 0, got {}",
                self.tolerance
            )));
        }
        let kdr = sys.drained_bulk.as_ref().ok_or_else(|| {
            BiotError::Input(
                "fixed-stress needs the drained bulk modulus (BiotSystem::with_drained_bulk_modulus)"
                    .into(),
            )
        })?;
        let dt = self.flow.step_for(dt, t);
        let nc = sys.num_cells();
        let t1 = t + dt;
        let vols = sys.mech.grid.cell_volumes();
        let alpha = &sys.ops.alpha;
        let beta: Vec<f64> = (0..nc)
            .map(|c| alpha[c] * alpha[c] / kdr[c] * vols[c])
            .collect();
        let diag: Vec<f64> = sys
            .flow
            .accumulation()
            .iter()
            .zip(&beta)
            .map(|(m, b)| m + b)
            .collect();
        self.flow.factorize(sys.flow, &diag, dt)?;
        let mut r0 = vec![0.0; nc];
        sys.flow_residual(&state.pressure, t1, dt, &mut r0)?;
        let mut cvo = vec![0.0; nc];
        sys.alpha_volume_change(&state.displacement, &mut cvo)?;
        let mut u_k = state.displacement.clone();
        let mut dp_k = vec![0.0; nc];
        let mut cv = vec![0.0; nc];
        let mut rhs = vec![0.0; nc];
        let mut p = vec![0.0; nc];
        let mut u_new = Vec::new();
        let mut change = f64::INFINITY;
        for it in 1..=self.max_iterations.max(1) {
            if it > 1
                && self
                    .interrupt
                    .as_ref()
                    .is_some_and(|f| f.load(Ordering::Relaxed))
            {
                return Err(BiotError::Interrupted);
            }
            sys.alpha_volume_change(&u_k, &mut cv)?;
            for c in 0..nc {
                rhs[c] = r0[c] - (cv[c] - cvo[c]) + beta[c] * dp_k[c];
            }
            self.flow.solve(&mut rhs)?;
            for c in 0..nc {
                p[c] = state.pressure[c] + rhs[c];
            }
            self.mech.solve(sys, t1, &p, &mut u_new)?;
            let dpc = rhs
                .iter()
                .zip(&dp_k)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let pref = p
                .iter()
                .zip(&sys.ops.p0)
                .fold(inf_norm(&rhs), |m, (a, b)| m.max((a - b).abs()));
            // The mechanics is solved exactly for the new pressure, so the displacement
            // change is a bounded linear image of the pressure change: the pressure change
            // alone measures convergence. Rounding floor: 16 ε |p|.
            let floor = 16.0 * f64::EPSILON * inf_norm(&p);
            change = dpc / pref.max(f64::MIN_POSITIVE);
            // The first iterate starts from the old displacement, which ignores the new
            // loads: at least two iterations.
            let converged = it >= 2 && (change <= self.tolerance || dpc <= floor);
            dp_k.copy_from_slice(&rhs);
            std::mem::swap(&mut u_k, &mut u_new);
            if converged {
                return Ok(BiotStep {
                    state: BiotState {
                        displacement: u_k,
                        pressure: p,
                    },
                    iterations: it,
                    residual: change,
                });
            }
        }
        Err(BiotError::NoConvergence {
            iterations: self.max_iterations,
            change,
        })
    }
}
