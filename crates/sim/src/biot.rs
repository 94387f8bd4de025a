//! Biot poroelasticity: the coupling of the mechanics of this crate with the TPFA flow of
//! `porofrac-flow` (seed §2.5, eqs. 28–30).
//!
//! # Continuous model and sign convention
//!
//! Tension is positive. With `u` the displacement, `p` the pore pressure, `p₀` the initial
//! pore pressure (in equilibrium, it does not deform the rock: the coupling acts on
//! `p − p₀`), `σ'` the effective stress of the cell laws and α the Biot–Willis
//! coefficient, the total stress is `σ = σ' − α (p − p₀) I` and (seed eq. 28)
//!
//! ```text
//!   ∇·σ + f = 0,      ∂/∂t (S p + α ∇·u) − ∇·(k/μ ∇p) = q .
//! ```
//!
//! # Discrete operators
//!
//! The discrete divergence of seed eq. 30 is the exact volume change of the first-order
//! VEM projection: with `N_i = ∫_∂K φ_i n dS` ([`porofrac_grid::Grid::cell_node_normals`]),
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
//! # Time discretization (seed eqs. 29–30)
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
//! (tested to 1e-10).
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
//! low-rank update of the factors (Sherman–Morrison–Woodbury, `crate::lowrank`), every
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
//! # Explicit pressure update (seed §2.5)
//!
//! For explicit mechanics the seed keeps the volumetric term only in fractured cells and
//! updates the pressure otherwise without feedback. [`ExplicitPressure::update_pressure`]
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

use std::ops::Range;
use std::sync::Arc;

use rayon::prelude::*;

use faer::Par;
use porofrac_flow::{FlowError, FlowModel};
use porofrac_grid::Point;
use porofrac_law::Stiffness;
use porofrac_sparse::{Ldlt, LdltError, LowRank, UpperRows};

use crate::assembly::{ElementCache, assemble, assemble_with, cell_tangents, nodal_loads};
use crate::error::SimError;
use crate::solve::{DirectSolver, StaticProblem};

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
}

/// Result alias of the Biot module.
pub type BiotResult<T> = std::result::Result<T, BiotError>;

/// Drained bulk modulus `K_dr = (1/D²) Σ_{a,b < D} D_ab` of a stiffness (Kelvin form):
/// `λ + 2μ/D` for an isotropic material (`λ + μ` in 2D plane strain, `λ + 2μ/3` in 3D).
pub fn drained_bulk_modulus<const D: usize>(stiffness: &Stiffness<D>) -> f64 {
    let k = stiffness.kelvin();
    let mut s = 0.0;
    for a in 0..D {
        for b in 0..D {
            s += k[(a, b)];
        }
    }
    s / (D * D) as f64
}

/// The mechanics and flow of one poroelastic problem, with the coupling operators.
///
/// Built once per grid, conditions and materials; the couplings ([`Monolithic`],
/// [`FixedStress`], [`ExplicitPressure`]) take it by reference at every step. The
/// coupling data (α, `p₀`, the node normals) and the assembled stiffness are shared
/// (reference counted), so a system rebuilt for the same laws (e.g. by
/// [`crate::fracturing::Fracturing`] at every step) costs no assembly and the couplings
/// recognise its stiffness as the one they factorized without comparing values.
pub struct BiotSystem<'a, const D: usize> {
    mech: StaticProblem<'a, D>,
    flow: &'a FlowModel<D>,
    ops: Arc<Operators<D>>,
    drained_bulk: Option<Vec<f64>>,
    k_values: Arc<[f64]>,
    /// The kept stiffness of the linear cells (see [`ElementCache`]).
    elements: Option<Arc<ElementCache>>,
    /// The cells whose stiffness is not kept in `elements` (all without it).
    free_cells: Vec<usize>,
    /// Their stiffness matrices in `k_values` (concatenated in the order of
    /// `free_cells`), when `k_values` is this system's own assembly at a known point.
    free_tangents: Option<Vec<f64>>,
}

/// The coupling data of a grid: α and `p₀` per cell, and the node normals `N_i` of every
/// cell (cell `c` owns `normals[node_ptr[c]..node_ptr[c + 1]]`, in the order of its nodes).
///
/// `weights[D·k + a] = α_K N_{k,a}` and `dofs[D·k + a] = D·n_k + a` for the `k`-th entry of
/// `normals` (node `n_k` of its cell): the rows of the coupling `C` over all nodal dofs.
/// `free_eq[q]`, `free_w[q]` for `q` in `free_ptr[c]..free_ptr[c + 1]`: the equations of
/// the free dofs of cell `c` and their weights, the rows of the reduced coupling.
#[derive(Debug, PartialEq)]
pub(crate) struct Operators<const D: usize> {
    pub(crate) alpha: Vec<f64>,
    pub(crate) p0: Vec<f64>,
    pub(crate) node_ptr: Vec<usize>,
    pub(crate) normals: Vec<Point<D>>,
    pub(crate) weights: Vec<f64>,
    pub(crate) dofs: Vec<usize>,
    pub(crate) free_ptr: Vec<usize>,
    pub(crate) free_eq: Vec<usize>,
    pub(crate) free_w: Vec<f64>,
}

impl<'a, const D: usize> BiotSystem<'a, D> {
    /// Couple `mechanics` with `flow` through the Biot coefficient `alpha` (per cell, in
    /// [0, 1]; it should equal the `biot_alpha` of the flow's rock, which sets its
    /// storage) and the initial pressure `p0` (per cell).
    ///
    /// Errors: length mismatches, α out of range, a non-finite `p0`, a nonlinear cell
    /// law, free rigid-body modes, or an assembly error.
    pub fn new(
        mechanics: StaticProblem<'a, D>,
        flow: &'a FlowModel<D>,
        alpha: Vec<f64>,
        p0: Vec<f64>,
    ) -> BiotResult<Self> {
        let grid = mechanics.grid;
        let nc = grid.num_cells();
        if flow.num_cells() != nc {
            return Err(BiotError::Input(format!(
                "flow model has {} cells, grid has {nc}",
                flow.num_cells()
            )));
        }
        check_len("alpha", alpha.len(), nc)?;
        check_len("initial pressure", p0.len(), nc)?;
        if let Some(c) = alpha
            .iter()
            .position(|a| !(a.is_finite() && (0.0..=1.0).contains(a)))
        {
            return Err(BiotError::Input(format!(
                "cell {c}: Biot coefficient must be in [0, 1], got {}",
                alpha[c]
            )));
        }
        if let Some(c) = p0.iter().position(|p| !p.is_finite()) {
            return Err(BiotError::Input(format!(
                "cell {c}: initial pressure is {}",
                p0[c]
            )));
        }
        mechanics.dofs.check_rigid_modes(grid)?;
        let mut node_ptr = Vec::with_capacity(nc + 1);
        node_ptr.push(0);
        for c in 0..nc {
            node_ptr.push(node_ptr[c] + grid.cell_nodes(c).len());
        }
        let mut normals = vec![Point::<D>::zeros(); node_ptr[nc]];
        for c in 0..nc {
            grid.cell_node_normals(c, &mut normals[node_ptr[c]..node_ptr[c + 1]]);
        }
        let mut weights = Vec::with_capacity(D * normals.len());
        let mut cdofs = Vec::with_capacity(D * normals.len());
        let mut free_ptr = Vec::with_capacity(nc + 1);
        let (mut free_eq, mut free_w) = (Vec::new(), Vec::new());
        free_ptr.push(0);
        for c in 0..nc {
            let nn = &normals[node_ptr[c]..node_ptr[c + 1]];
            for (&n, ni) in grid.cell_nodes(c).iter().zip(nn) {
                for a in 0..D {
                    weights.push(alpha[c] * ni[a]);
                    cdofs.push(D * n + a);
                    if let Some(e) = mechanics.dofs.equation(n, a) {
                        free_eq.push(e);
                        free_w.push(alpha[c] * ni[a]);
                    }
                }
            }
            free_ptr.push(free_eq.len());
        }
        let ops = Arc::new(Operators {
            alpha,
            p0,
            node_ptr,
            normals,
            weights,
            dofs: cdofs,
            free_ptr,
            free_eq,
            free_w,
        });
        Self::from_parts(mechanics, flow, ops, None, None)
    }

    /// A system on coupling data `ops` already validated for this grid, flow model and
    /// conditions (by [`Self::new`]), with the stiffness `k_values` of `mechanics.laws`
    /// when it is known (`None`: assembled here at zero displacement), taking the
    /// stiffness of the linear cells from `elements` when given (here and in
    /// [`Self::linearize`]).
    ///
    /// Errors: a law that is not piecewise linear, or an assembly error.
    pub(crate) fn from_parts(
        mechanics: StaticProblem<'a, D>,
        flow: &'a FlowModel<D>,
        ops: Arc<Operators<D>>,
        k_values: Option<Arc<[f64]>>,
        elements: Option<Arc<ElementCache>>,
    ) -> BiotResult<Self> {
        if !mechanics.laws.all_piecewise_linear() {
            return Err(BiotError::Input(
                "the Biot coupling needs linear or piecewise-linear cell laws (the stiffness \
                 is a linearization, see BiotSystem::linearize)"
                    .into(),
            ));
        }
        let k_values = match k_values {
            Some(k) if k.len() == mechanics.pattern.nnz() => k,
            _ => {
                let mut k = vec![0.0; mechanics.pattern.nnz()];
                let u = vec![0.0; mechanics.dofs.num_dofs()];
                assemble_with(
                    mechanics.grid,
                    mechanics.laws,
                    mechanics.dofs,
                    mechanics.pattern,
                    &u,
                    Some(&mut k),
                    None,
                    elements.as_deref(),
                )?;
                Arc::from(k)
            }
        };
        let free_cells = (0..mechanics.grid.num_cells())
            .filter(|&c| {
                elements
                    .as_deref()
                    .is_none_or(|e| !e.keeps(c, mechanics.laws.law(c)))
            })
            .collect();
        Ok(Self {
            mech: mechanics,
            flow,
            ops,
            drained_bulk: None,
            k_values,
            elements,
            free_cells,
            free_tangents: None,
        })
    }

    /// The shared coupling data and stiffness (for [`Self::from_parts`]).
    pub(crate) fn parts(&self) -> (Arc<Operators<D>>, Arc<[f64]>) {
        (self.ops.clone(), self.k_values.clone())
    }

    /// Set the drained bulk modulus of every cell (Pa, > 0), needed by [`FixedStress`]
    /// (see [`drained_bulk_modulus`]).
    pub fn with_drained_bulk_modulus(mut self, k_dr: Vec<f64>) -> BiotResult<Self> {
        check_len("drained bulk modulus", k_dr.len(), self.num_cells())?;
        if let Some(c) = k_dr.iter().position(|k| !(k.is_finite() && *k > 0.0)) {
            return Err(BiotError::Input(format!(
                "cell {c}: drained bulk modulus must be finite and > 0, got {}",
                k_dr[c]
            )));
        }
        self.drained_bulk = Some(k_dr);
        Ok(self)
    }

    /// Number of cells (pressure unknowns).
    pub fn num_cells(&self) -> usize {
        self.ops.alpha.len()
    }
    /// The mechanics problem.
    pub fn mechanics(&self) -> &StaticProblem<'a, D> {
        &self.mech
    }
    /// The flow model.
    pub fn flow(&self) -> &FlowModel<D> {
        self.flow
    }
    /// Biot coefficient per cell.
    pub fn alpha(&self) -> &[f64] {
        &self.ops.alpha
    }
    /// Initial pressure per cell.
    pub fn initial_pressure(&self) -> &[f64] {
        &self.ops.p0
    }
    /// The reduced stiffness values (upper triangle of the mechanics [`crate::Pattern`]).
    pub fn stiffness_values(&self) -> &[f64] {
        &self.k_values
    }

    /// Re-linearize the mechanics at the displacement `u` (nodal, prescribed values
    /// filled in) and measure the mechanical equilibrium of `(u, p)` at time `t`.
    ///
    /// The stiffness used by the couplings becomes the tangent `K(u)` (values only, the
    /// pattern is reused). For piecewise-linear laws ([`porofrac_law::CellLaw::is_piecewise_linear`])
    /// `F(u) = −K(u) u`, so a coupled step solved with `K(u^k)` is the exact solution once
    /// the stiffness at the solution equals the one used (an *active-set* iteration). The
    /// returned [`Linearization`] says whether the stiffness changed and gives the relative
    /// residual `‖g(t) + Cᵀ(p − p₀) + Tᵀ F(u)‖ / (‖g(t) + Cᵀ(p − p₀)‖ + ‖Tᵀ F(u)‖)` of the
    /// nonlinear equilibrium (0 for a consistent active set up to rounding).
    pub fn linearize(&mut self, u: &[f64], p: &[f64], t: f64) -> BiotResult<Linearization> {
        check_len("displacement", u.len(), self.mech.dofs.num_dofs())?;
        check_len("pressure", p.len(), self.num_cells())?;
        let mut internal = vec![0.0; self.mech.dofs.num_equations()];
        let changed = self.assemble_tangent(u, Some(&mut internal))?;
        self.free_tangents = None;
        let residual = self.residual_of(&internal, p, t)?;
        Ok(Linearization { changed, residual })
    }

    /// The relative residual of the nonlinear equilibrium of `(u, p)` at time `t` that
    /// [`Self::linearize`] measures, without touching the stiffness.
    pub fn equilibrium_residual(&self, u: &[f64], p: &[f64], t: f64) -> BiotResult<f64> {
        check_len("displacement", u.len(), self.mech.dofs.num_dofs())?;
        check_len("pressure", p.len(), self.num_cells())?;
        let mut internal = vec![0.0; self.mech.dofs.num_equations()];
        self.assemble_at(u, None, Some(&mut internal))?;
        self.residual_of(&internal, p, t)
    }

    /// `‖g(t) + Cᵀ(p − p₀) + f‖ / (‖g(t) + Cᵀ(p − p₀)‖ + ‖f‖)` for the internal forces `f`.
    fn residual_of(&self, internal: &[f64], p: &[f64], t: f64) -> BiotResult<f64> {
        let StaticProblem {
            grid, dofs, loads, ..
        } = self.mech;
        let mut full = vec![0.0; dofs.num_dofs()];
        nodal_loads(grid, loads, t, &mut full)?;
        let mut external = vec![0.0; dofs.num_equations()];
        dofs.reduce_add(&full, &mut external);
        dofs.add_platen_forces(grid, t, &mut external);
        self.add_pore_pressure_equations(p, &mut external);
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let scale = norm(&external) + norm(internal);
        let r: Vec<f64> = external.iter().zip(internal).map(|(a, b)| a + b).collect();
        Ok(if scale > 0.0 { norm(&r) / scale } else { 0.0 })
    }

    /// Re-linearize the mechanics at `u` as [`Self::linearize`] does, without the
    /// internal forces and the equilibrium residual (the stiffness only, the same
    /// values). Returns whether the stiffness changed.
    ///
    /// The kept (linear) cells do not depend on `u`: when the stiffness of every other
    /// cell at `u` equals, to the last bit, the one in the last tangent this system
    /// assembled, so does the sum, and nothing is assembled.
    pub fn tangent_at(&mut self, u: &[f64]) -> BiotResult<bool> {
        check_len("displacement", u.len(), self.mech.dofs.num_dofs())?;
        let tangents = self.free_cell_tangents(u)?;
        if self.free_tangents.as_ref() == Some(&tangents) {
            return Ok(false);
        }
        let changed = self.assemble_tangent(u, None)?;
        self.free_tangents = Some(tangents);
        Ok(changed)
    }

    /// The stiffness `values` and internal `forces` at `u` (each when asked for), the
    /// linear cells' stiffness taken from the kept element matrices.
    fn assemble_at(
        &self,
        u: &[f64],
        values: Option<&mut [f64]>,
        forces: Option<&mut [f64]>,
    ) -> BiotResult<()> {
        let m = &self.mech;
        assemble_with(
            m.grid,
            m.laws,
            m.dofs,
            m.pattern,
            u,
            values,
            forces,
            self.elements.as_deref(),
        )?;
        Ok(())
    }

    /// The stiffness matrices at `u` of the cells not kept, concatenated.
    fn free_cell_tangents(&self, u: &[f64]) -> BiotResult<Vec<f64>> {
        let mut out = Vec::new();
        cell_tangents(
            self.mech.grid,
            self.mech.laws,
            &self.free_cells,
            u,
            &mut out,
        )?;
        Ok(out)
    }

    /// The tangent at `u` (and the internal forces into `internal` when given); adopts
    /// it when it differs from the current stiffness and says whether it did.
    fn assemble_tangent(&mut self, u: &[f64], internal: Option<&mut [f64]>) -> BiotResult<bool> {
        // Assembled in place in a new shared slice (one allocation, no copy into an `Arc`).
        let mut values: Arc<[f64]> = std::iter::repeat_n(0.0, self.mech.pattern.nnz()).collect();
        self.assemble_at(
            u,
            Some(Arc::get_mut(&mut values).expect("a new allocation is not shared")),
            internal,
        )?;
        let changed = values.len() != self.k_values.len()
            || values
                .par_chunks(COMPARE_CHUNK)
                .zip(self.k_values.par_chunks(COMPARE_CHUNK))
                .any(|(a, b)| a != b);
        if changed {
            self.k_values = values;
        }
        Ok(changed)
    }

    /// The state at rest: zero displacement everywhere (prescribed dofs included) and
    /// `p = p₀`. A first step from it applies the loads *and* the prescribed displacements
    /// at `t + Δt` as a jump (with `Δt = 0`: the undrained response to both).
    pub fn rest_state(&self) -> BiotState {
        BiotState {
            displacement: vec![0.0; self.mech.dofs.num_dofs()],
            pressure: self.ops.p0.clone(),
        }
    }

    /// The initial state of the design: `p = p₀` and the displacement in equilibrium with
    /// the loads at time `t` (the initial pressure exerts no force).
    pub fn initial_state(&self, t: f64) -> BiotResult<BiotState> {
        let mut solver = DirectSolver::new(self.mech.pattern)?;
        solver.factorize(self.mech.pattern, &self.k_values)?;
        let mut st = self.rest_state();
        let mut rhs = vec![0.0; self.mech.dofs.num_equations()];
        let mut uf = Vec::new();
        self.mechanics_base(t, &mut uf, &mut Vec::new(), &mut rhs)?;
        solver.solve_in_place(&mut rhs)?;
        st.displacement.copy_from_slice(&uf);
        self.mech.dofs.scatter(&rhs, &mut st.displacement);
        Ok(st)
    }

    /// Volume change of every cell, `ΔV_K = Σ_i N_i · u_i` (m³; m² in 2D), for the nodal
    /// displacement `u` (length `D · nodes`), written to `out` (one per cell). Exact for
    /// linear fields: `ΔV_K = |K| ∇·u`.
    pub fn volume_change(&self, u: &[f64], out: &mut [f64]) -> BiotResult<()> {
        check_len("displacement", u.len(), self.mech.dofs.num_dofs())?;
        check_len("volume change output", out.len(), self.num_cells())?;
        let grid = self.mech.grid;
        let ops = &*self.ops;
        for (c, o) in out.iter_mut().enumerate() {
            let nodes = grid.cell_nodes(c);
            let nn = &ops.normals[ops.node_ptr[c]..ops.node_ptr[c + 1]];
            let mut s = 0.0;
            for (&n, ni) in nodes.iter().zip(nn) {
                for a in 0..D {
                    s += ni[a] * u[D * n + a];
                }
            }
            *o = s;
        }
        Ok(())
    }

    /// The nodal pore-pressure force `f_i = Σ_{K ∋ i} α_K (p_K − p₀_K) N_i` (length
    /// `D · nodes`, overwritten): the transpose of the coupling `C` applied to `p − p₀`,
    /// to be added to the external forces of a mechanics solve (e.g. an explicit one).
    pub fn pore_pressure_forces(&self, p: &[f64], out: &mut [f64]) -> BiotResult<()> {
        check_len("pressure", p.len(), self.num_cells())?;
        check_len("force output", out.len(), self.mech.dofs.num_dofs())?;
        out.fill(0.0);
        let grid = self.mech.grid;
        let ops = &*self.ops;
        for c in 0..self.num_cells() {
            let q = ops.alpha[c] * (p[c] - ops.p0[c]);
            if q == 0.0 {
                continue;
            }
            let nn = &ops.normals[ops.node_ptr[c]..ops.node_ptr[c + 1]];
            for (&n, ni) in grid.cell_nodes(c).iter().zip(nn) {
                for a in 0..D {
                    out[D * n + a] += q * ni[a];
                }
            }
        }
        Ok(())
    }

    /// `out[e] += Σ α_K (p_K − p₀_K) N_{i,a}` over the free dofs `(i, a)` of equation
    /// `e`: the reduced `Cᵀ (p − p₀)`.
    fn add_pore_pressure_equations(&self, p: &[f64], out: &mut [f64]) {
        let ops = &*self.ops;
        for ((q, pc), p0) in ops.free_ptr.windows(2).zip(p).zip(&ops.p0) {
            let dp = pc - p0;
            if dp == 0.0 {
                continue;
            }
            for (&e, w) in ops.free_eq[q[0]..q[1]].iter().zip(&ops.free_w[q[0]..q[1]]) {
                out[e] += w * dp;
            }
        }
    }

    /// In one pass over the cells: `mech[e] += Σ α_K (p_K − p₀_K) N_{i,a}` (the reduced
    /// `Cᵀ (p − p₀)`, as [`Self::add_pore_pressure_equations`]) and
    /// `cells[K] = α_K ΔV_K(u)` (as [`Self::alpha_volume_change`]; `u` of length
    /// `D · nodes`, `cells` one per cell).
    fn coupling_terms(&self, p: &[f64], u: &[f64], mech: &mut [f64], cells: &mut [f64]) {
        let ops = &*self.ops;
        let cols = ops.free_ptr.windows(2).zip(ops.node_ptr.windows(2));
        for (((q, k), (pc, p0)), o) in cols.zip(p.iter().zip(&ops.p0)).zip(cells.iter_mut()) {
            let dp = pc - p0;
            if dp != 0.0 {
                for (&e, w) in ops.free_eq[q[0]..q[1]].iter().zip(&ops.free_w[q[0]..q[1]]) {
                    mech[e] += w * dp;
                }
            }
            let k = D * k[0]..D * k[1];
            let mut s = 0.0;
            for (w, &d) in ops.weights[k.clone()].iter().zip(&ops.dofs[k]) {
                s += w * u[d];
            }
            *o = s;
        }
    }

    /// The prescribed displacements at `t` (free entries zero) into `u_fixed`, and the
    /// reduced mechanical right-hand side without pore pressure,
    /// `g = Tᵀ (f_f − K_fp u_p) + F_platen`, into `rhs`; `full` is scratch. Returns
    /// whether a prescribed displacement is non-zero.
    fn mechanics_base(
        &self,
        t: f64,
        u_fixed: &mut Vec<f64>,
        full: &mut Vec<f64>,
        rhs: &mut [f64],
    ) -> BiotResult<bool> {
        let StaticProblem {
            grid,
            laws,
            dofs,
            pattern,
            loads,
        } = self.mech;
        u_fixed.clear();
        u_fixed.resize(dofs.num_dofs(), 0.0);
        dofs.set_prescribed(grid, t, u_fixed);
        full.clear();
        full.resize(dofs.num_dofs(), 0.0);
        nodal_loads(grid, loads, t, full)?;
        rhs.fill(0.0);
        dofs.reduce_add(full, rhs);
        dofs.add_platen_forces(grid, t, rhs);
        let moved = u_fixed.iter().any(|&v| v != 0.0);
        if moved {
            let mut vals = vec![0.0; pattern.nnz()];
            let mut forces = vec![0.0; dofs.num_equations()];
            assemble(grid, laws, dofs, pattern, u_fixed, &mut vals, &mut forces)?;
            rhs.iter_mut().zip(&forces).for_each(|(r, f)| *r += f);
        }
        Ok(moved)
    }

    /// `out = Δt (b(t) − A pⁿ)`, the flow residual at the old pressure.
    fn flow_residual(&self, p_old: &[f64], t: f64, dt: f64, out: &mut [f64]) -> BiotResult<()> {
        self.flow.forcing(t, out)?;
        let a = self.flow.flux_matrix();
        let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        for (q, pk) in cp.windows(2).zip(p_old) {
            for (&i, a) in ri[q[0]..q[1]].iter().zip(&v[q[0]..q[1]]) {
                out[i] -= a * pk;
            }
        }
        out.iter_mut().for_each(|x| *x *= dt);
        Ok(())
    }

    /// `out = α_K ΔV_K(u) = Σ_{i,a} α_K N_{i,a} u_{i,a}` for every cell.
    fn alpha_volume_change(&self, u: &[f64], out: &mut [f64]) -> BiotResult<()> {
        check_len("displacement", u.len(), self.mech.dofs.num_dofs())?;
        check_len("volume change output", out.len(), self.num_cells())?;
        let ops = &*self.ops;
        for (o, q) in out.iter_mut().zip(ops.node_ptr.windows(2)) {
            let k = D * q[0]..D * q[1];
            let mut s = 0.0;
            for (w, &d) in ops.weights[k.clone()].iter().zip(&ops.dofs[k]) {
                s += w * u[d];
            }
            *o = s;
        }
        Ok(())
    }

    /// The default pressure scale `s = mean diag(K) / mean |C_{K,e}|` (see module docs).
    pub fn default_pressure_scale(&self) -> f64 {
        let pat = self.mech.pattern;
        let (cp, ri) = (pat.col_ptr(), pat.row_idx());
        let (mut sk, mut nk) = (0.0, 0usize);
        for j in 0..pat.num_equations() {
            for q in cp[j]..cp[j + 1] {
                if ri[q] == j {
                    sk += self.k_values[q].abs();
                    nk += 1;
                }
            }
        }
        let (mut sc, mut ncpl) = (0.0, 0usize);
        let grid = self.mech.grid;
        let ops = &*self.ops;
        for c in 0..self.num_cells() {
            let nn = &ops.normals[ops.node_ptr[c]..ops.node_ptr[c + 1]];
            for (&n, ni) in grid.cell_nodes(c).iter().zip(nn) {
                for a in 0..D {
                    let w = (ops.alpha[c] * ni[a]).abs();
                    if w > 0.0 && self.mech.dofs.equation(n, a).is_some() {
                        sc += w;
                        ncpl += 1;
                    }
                }
            }
        }
        if nk == 0 || ncpl == 0 || sk == 0.0 {
            return 1.0;
        }
        (sk / nk as f64) / (sc / ncpl as f64)
    }
}

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
    /// Monolithic: relative residual of the linear solve; fixed-stress: the last relative
    /// change; explicit: 0.
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

// ---------------------------------------------------------------------------------------
// Monolithic

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

/// The fully implicit monolithic scheme (seed eq. 30): one symmetric quasi-definite
/// system per step, solved by a sparse `LDLᵀ` factorization (see the module docs for the
/// block form and the scaling).
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
            forward: None,
            max_rank: DEFAULT_MAX_RANK,
            updates: 0,
            factored: None,
            residual: 0.0,
            default_scale: None,
            base: None,
            work: MonolithicWork::default(),
        })
    }

    /// Use `par` for factorizing (default sequential; a solve sweeps two independent
    /// parts of the factor on two threads, see `crate::ldlt`).
    pub fn set_parallelism(&mut self, par: Par) {
        self.ldlt.set_parallelism(par);
    }
    /// Number of numeric factorizations done (a step with the same matrix reuses it).
    pub fn numeric_factorizations(&self) -> usize {
        self.ldlt.numeric_factorizations()
    }
    /// What the linear algebra did (see [`CouplingStats`]); one symbolic analysis.
    pub fn stats(&self) -> CouplingStats {
        CouplingStats {
            linear: "ldlt",
            numeric_factorizations: self.ldlt.numeric_factorizations(),
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
        if self.relative_residual(&work.z, &work.rhs) <= LOW_RANK_RESIDUAL {
            return Ok(());
        }
        self.refactorize().map_err(|e| LdltError(e.to_string()))?;
        work.z.clone_from(&work.rhs);
        self.ldlt.solve_in_place(&mut work.z)
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

    /// `‖A z − b‖ / ‖b‖` (`‖A z − b‖` for `b = 0`) with the current matrix.
    fn relative_residual(&self, z: &[f64], rhs: &[f64]) -> f64 {
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
/// factors (`crate::lowrank`) rather than factorized: each new unknown costs a forward
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

/// Stiffness values compared per rayon task when a linearization asks whether the
/// tangent changed.
const COMPARE_CHUNK: usize = 1 << 14;

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
            .map_err(|e| BiotError::Solver(e.0))
            .and_then(|()| self.finish(sys, state, &w, fresh));
        self.work = w;
        result
    }
}

impl Monolithic {
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
            if residual > 1e-8 {
                // The factors are unusable: the next step factorizes again.
                self.factored = None;
                return Err(BiotError::Solver(format!(
                    "coupled system numerically singular: relative residual {residual:.2e}"
                )));
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

// ---------------------------------------------------------------------------------------
// Flow-only SPD solves (fixed-stress and explicit updates)

/// Sparse `LDLᵀ` of `diag(d) + Δt A` on the flow pattern (symmetric positive definite:
/// every pivot must be positive), refactorized only when the matrix changes.
struct FlowSolver {
    ldlt: Option<Ldlt>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    vals: Vec<f64>,
    factored_vals: Vec<f64>,
    /// `Δt` of the current factorization.
    dt: Option<f64>,
}

impl FlowSolver {
    fn new() -> Self {
        Self {
            ldlt: None,
            col_ptr: Vec::new(),
            row_idx: Vec::new(),
            vals: Vec::new(),
            factored_vals: Vec::new(),
            dt: None,
        }
    }

    /// The step to take for a requested `dt` at `t` (see `snap_step`).
    fn step_for(&self, dt: f64, t: f64) -> f64 {
        snap_step(dt, t, self.dt)
    }

    fn factorize<const D: usize>(
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
        if let Some(l) = &self.ldlt
            && l.is_factored()
            && self.vals == self.factored_vals
        {
            return Ok(());
        }
        self.dt = None;
        let ldlt = match self.ldlt.as_mut() {
            Some(l) => l,
            None => {
                let pat = flow.pattern();
                self.col_ptr = pat.col_ptr().to_vec();
                self.row_idx = pat.row_idx().to_vec();
                let l = Ldlt::analyse(pat.ncols(), &self.col_ptr, &self.row_idx, None)
                    .map_err(|e| BiotError::Solver(format!("flow factorization: {}", e.0)))?;
                self.ldlt.insert(l)
            }
        };
        let failed = |why: String| {
            BiotError::Solver(format!(
                "flow factorization failed ({why}); a region lacks storage and a pressure anchor"
            ))
        };
        ldlt.factorize(&self.col_ptr, &self.row_idx, &self.vals)
            .map_err(|e| failed(e.0))?;
        if !ldlt.pivots_positive() {
            return Err(failed("a pivot is not positive".into()));
        }
        self.factored_vals.clone_from(&self.vals);
        self.dt = Some(dt);
        Ok(())
    }

    fn solve(&mut self, rhs: &mut [f64]) -> BiotResult<()> {
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

    fn stats(&self) -> CouplingStats {
        match &self.ldlt {
            Some(l) => CouplingStats {
                linear: "cholesky",
                numeric_factorizations: l.numeric_factorizations(),
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

/// The mechanics solve `K x = g + Cᵀ (p − p₀)` shared by the split schemes.
struct MechSolver {
    solver: Option<DirectSolver>,
    /// The stiffness of the current factorization.
    factored: Option<Arc<[f64]>>,
    solves: usize,
    rhs: Vec<f64>,
    full: Vec<f64>,
}

impl MechSolver {
    fn new() -> Self {
        Self {
            solver: None,
            factored: None,
            solves: 0,
            rhs: Vec::new(),
            full: Vec::new(),
        }
    }

    /// Displacement in equilibrium with the loads at `t` and the pressure `p`.
    fn solve<const D: usize>(
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

    fn stats(&self) -> CouplingStats {
        CouplingStats {
            linear: "cholesky",
            numeric_factorizations: self
                .solver
                .as_ref()
                .map_or(0, |s| s.numeric_factorizations()),
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

// ---------------------------------------------------------------------------------------
// Fixed stress

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
}

impl FixedStress {
    /// A fixed-stress scheme with the given tolerance and iteration limit.
    pub fn new(tolerance: f64, max_iterations: usize) -> Self {
        Self {
            tolerance,
            max_iterations,
            flow: FlowSolver::new(),
            mech: MechSolver::new(),
        }
    }

    /// What the linear algebra did: the flow and mechanics factorizations and solves
    /// together (see [`CouplingStats`]).
    pub fn stats(&self) -> CouplingStats {
        self.flow.stats().add(self.mech.stats())
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

// ---------------------------------------------------------------------------------------
// Explicit pressure update

/// The seed's explicit-pressure coupling (§2.5): the volumetric term only in fractured
/// cells, no feedback iteration (see the module docs).
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
