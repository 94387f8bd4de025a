//! Time integration (eqs. 30–31) with the diagonal DEM mass (15).
//!
//! `M = diag(ρ|K|, …, ρ j |K|, …)` (displacement, then rotation components of each cell).
//!
//! * [`Integrator::Newmark`] — average acceleration (β = ¼, γ = ½), eq. (31): per step
//!   `(M/(βΔt²) + K) U¹ = F¹ + M (U⁰/(βΔt²) + V⁰/(βΔt) + (1/(2β) − 1) A⁰)`, then
//!   `A¹ = (U¹ − U⁰ − ΔtV⁰)/(βΔt²) − (1−2β)/(2β) A⁰`, `V¹ = V⁰ + Δt((1−γ)A⁰ + γA¹)`.
//!   The effective matrix is factorised once (its pattern is the stiffness pattern). With a
//!   symmetric `K` (no Nitsche terms) and no load it conserves `½VᵀMV + ½UᵀKU` exactly.
//! * [`Integrator::Explicit`] — leapfrog (kick–drift–kick), `A = M⁻¹(F − K U)`, stable for
//!   `Δt < 2/ω_max`. [`Dynamics::stable_step`] estimates `ω_max² = λ_max(M⁻¹K)` by power
//!   iteration and returns `0.8 · 2/ω_max` (the 0.8 covers the estimate from below).
//!
//! The velocity damping (30) on Dirichlet facets is not implemented: the clamped beam of
//! Marazzato (2021) §4.2.1 (tests/dynamics.rs) stays stable without it under Newmark.

use crate::discrete::Cosserat;
use crate::error::{CosseratError, Result};
use crate::linear::{Linear, LinearOptions, LinearStats};
use crate::material::components;

/// Time integrator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Integrator {
    /// Newmark average acceleration (implicit, unconditionally stable).
    #[default]
    Newmark,
    /// Explicit leapfrog with a step below the stability limit.
    Explicit,
}

/// Safety factor on the estimated explicit stability limit.
pub const EXPLICIT_SAFETY: f64 = 0.8;

/// The state of a dynamic run: displacements/rotations, velocities, accelerations.
#[derive(Debug)]
pub struct Dynamics {
    integrator: Integrator,
    dt: f64,
    /// Current time.
    pub t: f64,
    /// Generalised displacements (cell-major, `n` per cell).
    pub u: Vec<f64>,
    /// Velocities.
    pub v: Vec<f64>,
    /// Accelerations.
    pub a: Vec<f64>,
    mass: Vec<f64>,
    system: Vec<f64>,
    solver: Option<Linear>,
    /// Work done by the external loads so far (trapezoidal in time).
    pub external_work: f64,
    f_prev: Vec<f64>,
    scratch: Vec<f64>,
    scratch2: Vec<f64>,
}

/// The lumped mass of every unknown (eq. 15).
pub fn lumped_mass<const D: usize>(model: &Cosserat<D>) -> Vec<f64> {
    let n = components(D);
    let m = model.material();
    let g = model.grid();
    let mut out = Vec::with_capacity(model.equations());
    for c in 0..g.num_cells() {
        let v = g.cell_volume(c) * m.density;
        for a in 0..n {
            out.push(if a < D { v } else { v * m.micro_inertia });
        }
    }
    out
}

impl Dynamics {
    /// The load vector of the last step's end, which the next step's external work
    /// uses (with `t`, `u`, `v`, `a` and `external_work`, the whole state a step carries
    /// to the next: a checkpoint saves them).
    pub fn previous_load(&self) -> &[f64] {
        &self.f_prev
    }

    /// Put back the load vector [`Dynamics::previous_load`] gave (`Err` with the two
    /// lengths when it does not fit).
    pub fn set_previous_load(&mut self, f: Vec<f64>) -> std::result::Result<(), (usize, usize)> {
        if f.len() != self.f_prev.len() {
            return Err((f.len(), self.f_prev.len()));
        }
        self.f_prev = f;
        Ok(())
    }

    /// Start at `t0` from `u0`, `v0` (the initial acceleration solves `M A = F − K U`).
    ///
    /// Errors: `dt ≤ 0`, a zero micro-inertia (the rotation mass vanishes), wrong lengths,
    /// or a failure of the linear solver (factorisation or multigrid setup).
    pub fn new<const D: usize>(
        model: &Cosserat<D>,
        integrator: Integrator,
        dt: f64,
        t0: f64,
        u0: Vec<f64>,
        v0: Vec<f64>,
    ) -> Result<Self> {
        Self::with_solver(model, integrator, dt, t0, u0, v0, &LinearOptions::default())
    }

    /// [`Self::new`] with the linear solver of the Newmark matrix `K + M/(β dt²)` chosen
    /// by `linear` (its preconditioner is built on `P + M/(β dt²)`, see [`crate::linear`];
    /// "auto" by [`crate::LinearSolver::resolve_newmark`]).
    pub fn with_solver<const D: usize>(
        model: &Cosserat<D>,
        integrator: Integrator,
        dt: f64,
        t0: f64,
        u0: Vec<f64>,
        v0: Vec<f64>,
        linear: &LinearOptions,
    ) -> Result<Self> {
        let neq = model.equations();
        if !(dt.is_finite() && dt > 0.0) {
            return Err(CosseratError::Input {
                what: format!("time step {dt} must be positive"),
            });
        }
        if model.material().micro_inertia <= 0.0 {
            return Err(CosseratError::Material {
                name: "micro_inertia",
                value: model.material().micro_inertia,
                reason: "must be positive for dynamics",
            });
        }
        if u0.len() != neq || v0.len() != neq {
            return Err(CosseratError::Input {
                what: format!(
                    "initial state of lengths {} / {}, want {neq}",
                    u0.len(),
                    v0.len()
                ),
            });
        }
        let mass = lumped_mass(model);
        let system = model.system_values();
        let mut f = vec![0.0; neq];
        model.rhs(t0, &mut f);
        let mut ku = vec![0.0; neq];
        model.pattern().mul(&system, &u0, &mut ku);
        let a: Vec<f64> = (0..neq).map(|i| (f[i] - ku[i]) / mass[i]).collect();
        let solver = match integrator {
            Integrator::Explicit => None,
            Integrator::Newmark => {
                let beta = 0.25;
                let mut eff = system.clone();
                let mut pre = model.preconditioner_values();
                for (i, p) in model.pattern().diagonal_positions().into_iter().enumerate() {
                    eff[p] += mass[i] / (beta * dt * dt);
                    pre[p] += mass[i] / (beta * dt * dt);
                }
                let linear = LinearOptions {
                    solver: linear.solver.resolve_newmark(neq),
                    ..*linear
                };
                Some(model.linear(eff, pre, &linear)?)
            }
        };
        // What the model prepared for a static solve is not needed here.
        model.release_prepared();
        Ok(Self {
            integrator,
            dt,
            t: t0,
            u: u0,
            v: v0,
            a,
            mass,
            system,
            solver,
            external_work: 0.0,
            f_prev: f,
            scratch: vec![0.0; neq],
            scratch2: ku,
        })
    }

    /// The Newmark solver and its statistics (`None` for the explicit integrator).
    pub fn solver(&self) -> Option<&Linear> {
        self.solver.as_ref()
    }

    /// Poll `flag` in the iterative Newmark solves ([`Linear::set_interrupt`]); the
    /// explicit integrator solves nothing (its caller polls between steps).
    pub fn set_interrupt(&mut self, flag: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>) {
        if let Some(l) = self.solver.as_mut() {
            l.set_interrupt(flag);
        }
    }

    /// The Newmark solver, to put back its statistics ([`Linear::restore_counts`]).
    pub fn solver_mut(&mut self) -> Option<&mut Linear> {
        self.solver.as_mut()
    }

    /// Statistics of the Newmark solves (default for the explicit integrator).
    pub fn solver_stats(&self) -> LinearStats {
        self.solver.as_ref().map(Linear::stats).unwrap_or_default()
    }

    /// The time step.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The lumped mass.
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }

    /// An estimate of the explicit stability limit `0.8 · 2/√λ_max(M⁻¹K)` (power iteration,
    /// 200 iterations from a deterministic start).
    pub fn stable_step<const D: usize>(model: &Cosserat<D>) -> f64 {
        let mass = lumped_mass(model);
        let system = model.system_values();
        let n = model.equations();
        let mut x: Vec<f64> = (0..n)
            .map(|i| 1.0 + ((i * 7919) % 13) as f64 / 13.0)
            .collect();
        let mut y = vec![0.0; n];
        let mut lambda = 0.0;
        for _ in 0..200 {
            let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
            x.iter_mut().for_each(|v| *v /= norm);
            model.pattern().mul(&system, &x, &mut y);
            for i in 0..n {
                y[i] /= mass[i];
            }
            lambda = y.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>();
            std::mem::swap(&mut x, &mut y);
        }
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let lambda = lambda.abs().max(norm);
        EXPLICIT_SAFETY * 2.0 / lambda.sqrt()
    }

    /// Advance one step.
    pub fn step<const D: usize>(&mut self, model: &Cosserat<D>) -> Result<()> {
        let n = self.u.len();
        let dt = self.dt;
        let t1 = self.t + dt;
        let mut f = std::mem::take(&mut self.scratch);
        model.rhs(t1, &mut f);
        let u_old = self.u.clone();
        match self.integrator {
            Integrator::Newmark => {
                let beta = 0.25;
                let gamma = 0.5;
                let mut rhs = f.clone();
                for i in 0..n {
                    rhs[i] += self.mass[i]
                        * (self.u[i] / (beta * dt * dt)
                            + self.v[i] / (beta * dt)
                            + (0.5 / beta - 1.0) * self.a[i]);
                }
                // Initial guess: the predictor u + dt v + (½ − β) dt² a.
                let guess: Vec<f64> = (0..n)
                    .map(|i| self.u[i] + dt * self.v[i] + (0.5 - beta) * dt * dt * self.a[i])
                    .collect();
                self.solver
                    .as_mut()
                    .expect("Newmark has a linear solver")
                    .solve(&mut rhs, Some(&guess))?;
                for i in 0..n {
                    let a1 = (rhs[i] - self.u[i] - dt * self.v[i]) / (beta * dt * dt)
                        - (1.0 - 2.0 * beta) / (2.0 * beta) * self.a[i];
                    self.v[i] += dt * ((1.0 - gamma) * self.a[i] + gamma * a1);
                    self.a[i] = a1;
                }
                self.u = rhs;
            }
            Integrator::Explicit => {
                for i in 0..n {
                    self.v[i] += 0.5 * dt * self.a[i];
                    self.u[i] += dt * self.v[i];
                }
                let ku = &mut self.scratch2;
                model.pattern().mul(&self.system, &self.u, ku);
                for i in 0..n {
                    self.a[i] = (f[i] - ku[i]) / self.mass[i];
                    self.v[i] += 0.5 * dt * self.a[i];
                }
            }
        }
        // External work: ∫ F·du with the trapezoidal rule.
        self.external_work += (0..n)
            .map(|i| 0.5 * (f[i] + self.f_prev[i]) * (self.u[i] - u_old[i]))
            .sum::<f64>();
        std::mem::swap(&mut self.f_prev, &mut f);
        self.scratch = f;
        self.t = t1;
        if let Some(i) = self.u.iter().position(|v| !v.is_finite()) {
            return Err(CosseratError::Solve(format!(
                "non-finite state at equation {i} at t = {t1}: unstable time step?"
            )));
        }
        Ok(())
    }

    /// Kinetic energy `½ VᵀMV`.
    pub fn kinetic(&self) -> f64 {
        0.5 * self
            .v
            .iter()
            .zip(&self.mass)
            .map(|(v, m)| m * v * v)
            .sum::<f64>()
    }
}
