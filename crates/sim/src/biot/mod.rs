//! Biot poroelasticity: the coupling of the mechanics of this crate with the TPFA flow of
//! `porofrac-flow` (H. M. Nilsen, I. Larsen, X. Raynaud (2017), arXiv:1702.01552, §2.5,
//! eqs. 28–30).
//!
//! # Continuous model and sign convention
//!
//! Tension is positive. With `u` the displacement, `p` the pore pressure, `p₀` the initial
//! pore pressure (in equilibrium, it does not deform the rock: the coupling acts on
//! `p − p₀`), `σ'` the effective stress of the cell laws and α the Biot–Willis
//! coefficient, the total stress is `σ = σ' − α (p − p₀) I` and (eq. 28 there)
//!
//! ```text
//!   ∇·σ + f = 0,      ∂/∂t (S p + α ∇·u) − ∇·(k/μ ∇p) = q .
//! ```
//!
//! # Discrete operators
//!
//! The discrete divergence of Nilsen et al. (2017) eq. 30 is the exact volume change of the
//! first-order VEM projection: with `N_i = ∫_∂K φ_i n dS`
//! ([`porofrac_grid::Grid::cell_node_normals`]),
//!
//! ```text
//!   ΔV_K(u) = Σ_{i ∈ K} N_i · u_i = |K| tr ε(Π u) = ∫_K ∇·(Π u) dx ,
//! ```
//!
//! exact for every linear field ([`BiotSystem::volume_change`]). The coupling matrix is
//! `C_{K,(i,a)} = α_K N_{i,a}` (cells × dofs), so `C u` is α times the volume change. The
//! weak form of `−α (p − p₀) I` in the momentum balance is `−∫ α (p − p₀) ∇·v`, i.e. with a
//! cell-wise constant pressure the nodal *pore-pressure force*
//!
//! ```text
//!   f_i = Σ_{K ∋ i} α_K (p_K − p₀_K) N_i = (Cᵀ (p − p₀))_i
//! ```
//!
//! ([`BiotSystem::pore_pressure_forces`]): the same `N_i` as the volume change, so the
//! mechanics sees exactly the transpose of the flow's coupling block.
//!
//! # Time discretization (Nilsen et al. 2017, eqs. 29–30)
//!
//! Implicit Euler from `(uⁿ, pⁿ)` at `t` to `t + Δt`, with `K` the reduced stiffness,
//! `M = diag(|K| S_K)` the accumulation, `A` the TPFA flux matrix and `b` the flow forcing
//! of [`porofrac_flow::FlowModel`] and `g` the mechanical load vector at `t + Δt`:
//!
//! ```text
//!   K u^{n+1} − Cᵀ (p^{n+1} − p₀)                          = g
//!   C (u^{n+1} − uⁿ) + M (p^{n+1} − pⁿ) + Δt A p^{n+1}   = Δt b .
//! ```
//!
//! The unknowns are the reduced displacements `x` and the pressure *increment*
//! `δp = p^{n+1} − pⁿ`; the flow rows are multiplied by `−1`, giving the symmetric
//! quasi-definite system
//!
//! ```text
//!   [  K        −Cᵀ       ] [x ]   [ g + Cᵀ (pⁿ − p₀)                        ]
//!   [ −C   −(M + Δt A)    ] [δp] = [ −Δt (b − A pⁿ) + C u_p^{n+1} − C uⁿ      ]
//! ```
//!
//! (`u_p` the prescribed displacements). `K` is positive definite and `M + Δt A` positive
//! definite as soon as every connected flow region has storage or a pressure anchor, so
//! the matrix is *quasi-definite* and has an `LDLᵀ` factorization for every symmetric
//! ordering (Vanderbei 1995): [`Monolithic`] uses a sparse `LDLᵀ` (faer's supernodal
//! factorization) with a nested-dissection or minimum-degree ordering of the block
//! system, whichever fills less, the symbolic analysis done once. `Δt = 0` is allowed and gives the
//! *undrained* response to an instantaneous load (no flux, `C δu + M δp = 0`); it needs
//! `S > 0` in every cell (with `S = 0` the block system is a saddle point without the
//! quasi-definite structure, and is rejected: take a small `Δt > 0` instead).
//!
//! **Scaling.** With `E ~ 1e9 Pa` and `p ~ 1e7 Pa` the blocks differ by many orders of
//! magnitude. The pressure unknown is scaled, `δp = s y`, and the flow rows multiplied by
//! `s`, which keeps the symmetry:
//! `[[K, −s Cᵀ], [−s C, −s² (M + Δt A)]]`. The default
//! `s = mean diag(K) / mean |C_{K,e}|` (units Pa/m) makes the coupling block as large as
//! the stiffness; `s` is a pure change of variables, so the solution does not depend on it
//! (tested to 1e-10). One `s` cannot level every row: a crack cell that conducts by the
//! cubic law has a pressure row far larger than the rock's, and [`Monolithic`] judges
//! its solves in the Jacobi-scaled system `D A D`, `D = diag(|a_ii|)^{-1/2}` (see
//! `monolithic.rs`: the factors of `A` are those of `D A D`, so only the residual test
//! changes).
//!
//! # What a step costs
//!
//! The block matrix depends on `K`, α, the node normals, `A`, `M`, `s` and `Δt`, none of
//! which changes for linear laws, no new failures and a fixed step. A step then builds
//! the right-hand side (`O(cells + equations)`: the prescribed displacements and loads
//! are kept when no condition depends on time) and back-solves with the stored factors,
//! `2 nnz(L)` multiply–adds; the matrix is filled and factorized again only when one of
//! its inputs changed. The inputs are recognised cheaply: the stiffness and the coupling
//! data are shared between the systems of one run ([`BiotSystem`] holds them reference
//! counted, so the same stiffness is the same allocation; otherwise values are
//! compared), the flow values are compared, and a `Δt` within the rounding of the step
//! times (`4 ε (|t| + |Δt|)`) of the factorized one is taken as equal, since the times of
//! a uniform schedule are rounded products `k Δt` whose differences wobble in the last
//! bits. [`Monolithic::stats`], [`FixedStress::stats`] and [`ExplicitPressure::stats`]
//! report the factorizations and solves done ([`CouplingStats`]).
//!
//! A matrix that differs from the factorized one in a few unknowns (a fracturing cell
//! switching law or permeability changes the rows of its nodes and of its and its
//! neighbours' pressures) is not factorized again: [`Monolithic`] solves it by a
//! low-rank update of the factors (Sherman–Morrison–Woodbury, `porofrac_sparse::LowRank`), every
//! such solve refined with the residual of the matrix itself to the relative residual
//! `1e-12` of a fresh factorization (else it factorizes; the residual of an updated
//! solve lies on the changed unknowns, so it is measured there from the solution at their
//! neighbours, a backward sweep over their paths of the elimination tree only, and the
//! correction joins the solve's own backward sweep, see `LowRank::solve_corrected`), and
//! keeps the pressure scale
//! of the factors meanwhile. Beyond `DEFAULT_MAX_RANK` changed unknowns it factorizes.
//!
//! # Fixed-stress split
//!
//! [`FixedStress`] iterates flow then mechanics (Kim, Tchelepi & Juanes 2011; Mikelić &
//! Wheeler 2013). Flow iteration `k + 1`, with the stabilisation `β_K = α_K² / K_dr,K`:
//!
//! ```text
//!   (M + β|K| + Δt A) δp^{k+1} = Δt (b − A pⁿ) − C (u^k − uⁿ) + β|K| δp^k ,
//! ```
//!
//! then the mechanics `K u^{k+1} = g + Cᵀ (pⁿ + δp^{k+1} − p₀)`, until both changes are
//! below a tolerance. At convergence this is the monolithic system. `K_dr` is the drained
//! bulk modulus of each cell's material: for an isotropic material
//! `K_dr = λ + 2μ/D`, i.e. `λ + μ` in 2D plane strain (the in-plane bulk modulus relating
//! the mean in-plane stress to the area change with `ε_zz = 0`) and `λ + 2μ/3` in 3D;
//! [`drained_bulk_modulus`] computes `(1/D²) Σ_{a,b ≤ D} D_ab` of the Kelvin matrix,
//! which is that value for isotropic materials and the Reuss-like mean-normal stiffness
//! for anisotropic ones.
//!
//! # Explicit pressure update (Nilsen et al. 2017, §2.5)
//!
//! For explicit mechanics Nilsen et al. (2017) keep the volumetric term only in fractured
//! cells and update the pressure otherwise without feedback. [`ExplicitPressure::update_pressure`]
//! takes `u^{n+1}`, `uⁿ`, `pⁿ` and the set `F` of fractured cells and solves
//!
//! ```text
//!   (M + Δt A) (p^{n+1} − pⁿ) = Δt (b − A pⁿ) − Σ_{K ∈ F} α_K (ΔV_K(u^{n+1}) − ΔV_K(uⁿ)) e_K ,
//! ```
//!
//! i.e. the flow is implicit in the fluxes (stable for any `Δt`, needed since fractured
//! cells take a high permeability) and explicit in the coupling. As a [`BiotCoupling`] it
//! is the staggered scheme: mechanics with `pⁿ`, then this update.
//!
//! # Restrictions
//!
//! The cell laws must be linear or piecewise linear (`F(u) = −K(u) u`, e.g. the
//! compression-only DEM of fractured cells): the couplings use the stiffness of the last
//! [`BiotSystem::linearize`] (at zero displacement after construction), and an active-set
//! loop around a step ([`crate::fracturing`]) makes it consistent. Prescribed non-zero
//! displacements act through the laws evaluated at the prescribed field alone, exact for
//! linear laws. The pressure `p` and `p₀` are cell values, one per grid cell, in the flow
//! model's cell order.
//!
//! # Files
//!
//! * `system.rs` — [`BiotSystem`]: the mechanics, the flow and the coupling operators.
//! * `monolithic.rs` — [`Monolithic`]: the fully implicit block system and its `LDLᵀ`.
//! * `fixed_stress.rs` — [`FixedStress`]: the fixed-stress split.
//! * `explicit.rs` — [`ExplicitPressure`]: the explicit-pressure update of Nilsen et al. (2017).
//! * `flow_solve.rs`, `mech_solve.rs` — the flow and mechanics solves of the split schemes.
//! * `memory.rs` — [`SchemeMemory`]: what a scheme carries from one step to the next, for
//!   checkpoints.

mod explicit;
mod fixed_stress;
mod flow_solve;
mod mech_solve;
mod memory;
mod monolithic;
mod system;

pub use explicit::ExplicitPressure;
pub use fixed_stress::FixedStress;
use flow_solve::FlowSolver;
use mech_solve::MechSolver;
pub use memory::SchemeMemory;
pub use monolithic::Monolithic;
pub(crate) use system::Operators;
pub use system::{BiotSystem, drained_bulk_modulus};

use porofrac_flow::FlowError;

use crate::error::SimError;

/// Errors of the Biot coupling.
#[derive(Debug, thiserror::Error)]
pub enum BiotError {
    /// An error of the mechanics (assembly, conditions, factorization).
    #[error("mechanics: {0}")]
    Mechanics(#[from] SimError),
    /// An error of the flow model (boundary values, lengths).
    #[error("flow: {0}")]
    Flow(#[from] FlowError),
    /// Invalid input: a length, a value out of range (naming what and where).
    #[error("invalid input: {0}")]
    Input(String),
    /// A linear system is singular or its solution is inaccurate.
    #[error("linear solve: {0}")]
    Solver(String),
    /// The fixed-stress iteration did not converge.
    #[error(
        "fixed-stress iteration did not converge in {iterations} iterations (last relative change {change:.3e})"
    )]
    NoConvergence {
        /// Iterations done.
        iterations: usize,
        /// The last relative change.
        change: f64,
    },
    /// A stop was requested (the flag given to the scheme's `set_interrupt`) between two
    /// iterations.
    #[error("interrupted")]
    Interrupted,
}

/// Result alias of the Biot module.
pub type BiotResult<T> = std::result::Result<T, BiotError>;

/// A step `Δt` within rounding of `previous` is taken as `previous`: the output times of
/// a uniform schedule are rounded products `k Δt`, so their differences wobble in the
/// last bits of `t` (e.g. `0.03 − 0.02 = 0.009999999999999998`), and a matrix holding
/// `Δt` would change, and be factorized again, at every step for nothing. The tolerance
/// `4 ε (|t| + |Δt|)` is the rounding of the times themselves.
fn snap_step(dt: f64, t: f64, previous: Option<f64>) -> f64 {
    match previous {
        Some(f) if (f - dt).abs() <= 4.0 * f64::EPSILON * (t.abs() + dt.abs()) => f,
        _ => dt,
    }
}

fn check_len(what: &str, got: usize, want: usize) -> BiotResult<()> {
    if got == want {
        Ok(())
    } else {
        Err(BiotError::Input(format!(
            "{what}: length {got}, want {want}"
        )))
    }
}

fn check_step(dt: f64, t: f64) -> BiotResult<()> {
    if !(dt.is_finite() && dt >= 0.0 && t.is_finite()) {
        return Err(BiotError::Input(format!(
            "time step must be finite and ≥ 0 and t finite, got Δt = {dt}, t = {t}"
        )));
    }
    Ok(())
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The outcome of [`BiotSystem::linearize`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linearization {
    /// Whether the stiffness at the new displacement differs from the previous one.
    pub changed: bool,
    /// Relative residual of the nonlinear mechanical equilibrium at the given state.
    pub residual: f64,
}

/// Displacement and pressure at one time.
#[derive(Clone, Debug, PartialEq)]
pub struct BiotState {
    /// Nodal displacements, node-major (`D` per node), prescribed values filled in.
    pub displacement: Vec<f64>,
    /// Cell pressures (Pa), absolute (the coupling acts on `p − p₀`).
    pub pressure: Vec<f64>,
}

/// The result of one coupled step.
#[derive(Clone, Debug)]
pub struct BiotStep {
    /// The state at the new time.
    pub state: BiotState,
    /// Iterations (1 for the monolithic and explicit schemes).
    pub iterations: usize,
    /// Monolithic: relative residual of the linear solve in the Jacobi-scaled system
    /// (`‖D (b − A z)‖/‖D b‖`, see [`Monolithic`]); fixed-stress: the last relative change;
    /// explicit: 0.
    pub residual: f64,
}

/// A scheme that advances a poroelastic state by one time step.
pub trait BiotCoupling<const D: usize> {
    /// A short name for output.
    fn name(&self) -> &str;
    /// Advance `state` (at time `t`) to `t + dt`; loads and boundary values are evaluated
    /// at `t + dt`. `dt = 0` gives the undrained response (no flow) where the scheme
    /// allows it.
    fn step(
        &mut self,
        system: &BiotSystem<'_, D>,
        state: &BiotState,
        t: f64,
        dt: f64,
    ) -> BiotResult<BiotStep>;
}

/// What the linear algebra of a coupling scheme did: which solver, how many numeric and
/// symbolic factorizations, the size of the factors and the number of solves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CouplingStats {
    /// The linear solver: `"ldlt"` (sparse `LDLᵀ` of the monolithic block system) or
    /// `"cholesky"` (sparse Cholesky of the flow and of the mechanics, split schemes).
    pub linear: &'static str,
    /// Numeric factorizations done.
    pub numeric_factorizations: usize,
    /// Symbolic analyses (orderings and factor patterns) done.
    pub symbolic_factorizations: usize,
    /// Stored entries of the current factors (summed over the factors of a split scheme).
    pub factor_nnz: usize,
    /// Triangular solves done (one per monolithic step; flow and mechanics solves of the
    /// split schemes).
    pub solves: usize,
    /// Matrices solved by a low-rank update of the current factors instead of a new
    /// factorization (monolithic scheme, see [`Monolithic`]).
    pub low_rank_updates: usize,
}

impl CouplingStats {
    fn add(self, o: CouplingStats) -> CouplingStats {
        CouplingStats {
            linear: self.linear,
            numeric_factorizations: self.numeric_factorizations + o.numeric_factorizations,
            symbolic_factorizations: self.symbolic_factorizations + o.symbolic_factorizations,
            factor_nnz: self.factor_nnz + o.factor_nnz,
            solves: self.solves + o.solves,
            low_rank_updates: self.low_rank_updates + o.low_rank_updates,
        }
    }
}

fn check_state<const D: usize>(sys: &BiotSystem<'_, D>, state: &BiotState) -> BiotResult<()> {
    check_len(
        "state displacement",
        state.displacement.len(),
        sys.mech.dofs.num_dofs(),
    )?;
    check_len("state pressure", state.pressure.len(), sys.num_cells())?;
    if let Some(c) = state.pressure.iter().position(|p| !p.is_finite()) {
        return Err(BiotError::Input(format!(
            "cell {c}: pressure is {}",
            state.pressure[c]
        )));
    }
    Ok(())
}
