//! The coupled poroelastic system: the mechanics, the flow and the coupling operators
//! (volume change, pore-pressure forces) shared by every scheme.

use std::sync::Arc;

use rayon::prelude::*;

use porofrac_flow::FlowModel;
use porofrac_grid::{Grid, Point};
use porofrac_law::Stiffness;

use crate::assembly::{ElementCache, assemble, assemble_with, cell_tangents, nodal_loads};
use crate::dofs::DofMap;
use crate::solve::{DirectSolver, StaticProblem};

use super::{BiotError, BiotResult, BiotState, Linearization, check_len};

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
///
/// [`Monolithic`]: super::Monolithic
/// [`FixedStress`]: super::FixedStress
/// [`ExplicitPressure`]: super::ExplicitPressure
pub struct BiotSystem<'a, const D: usize> {
    pub(super) mech: StaticProblem<'a, D>,
    pub(super) flow: &'a FlowModel<D>,
    pub(super) ops: Arc<Operators<D>>,
    pub(super) drained_bulk: Option<Vec<f64>>,
    pub(super) k_values: Arc<[f64]>,
    /// The kept stiffness of the linear cells (see [`ElementCache`]).
    pub(super) elements: Option<Arc<ElementCache>>,
    /// The cells whose stiffness is not kept in `elements` (all without it).
    pub(super) free_cells: Vec<usize>,
    /// Their stiffness matrices in `k_values` (concatenated in the order of
    /// `free_cells`), when `k_values` is this system's own assembly at a known point.
    pub(super) free_tangents: Option<Vec<f64>>,
    /// The void created in every cell over a step, as a fluid source rate (m³/s per cell;
    /// m²/s in 2D) added to the flow forcing ([`Self::set_void_source`]).
    pub(super) void_source: Option<Vec<f64>>,
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

impl<const D: usize> Operators<D> {
    /// The same coupling data with the Biot coefficient `alpha` (one per cell, in [0, 1]):
    /// the weights `α_K N_i` of every cell recomputed from the kept node normals, the
    /// free dofs those of `dofs` (the map the data was built with).
    pub(crate) fn with_alpha(&self, grid: &Grid<D>, dofs: &DofMap<D>, alpha: Vec<f64>) -> Self {
        let mut weights = Vec::with_capacity(self.weights.len());
        let (mut free_eq, mut free_w) = (
            Vec::with_capacity(self.free_eq.len()),
            Vec::with_capacity(self.free_w.len()),
        );
        let mut free_ptr = Vec::with_capacity(self.free_ptr.len());
        free_ptr.push(0);
        for (c, &a_c) in alpha.iter().enumerate() {
            let nn = &self.normals[self.node_ptr[c]..self.node_ptr[c + 1]];
            for (&n, ni) in grid.cell_nodes(c).iter().zip(nn) {
                for a in 0..D {
                    weights.push(a_c * ni[a]);
                    if let Some(e) = dofs.equation(n, a) {
                        free_eq.push(e);
                        free_w.push(a_c * ni[a]);
                    }
                }
            }
            free_ptr.push(free_eq.len());
        }
        Self {
            alpha,
            p0: self.p0.clone(),
            node_ptr: self.node_ptr.clone(),
            normals: self.normals.clone(),
            weights,
            dofs: self.dofs.clone(),
            free_ptr,
            free_eq,
            free_w,
        }
    }
}

/// Stiffness values compared per rayon task when a linearization asks whether the
/// tangent changed.
const COMPARE_CHUNK: usize = 1 << 14;

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
                    .is_none_or(|e| !e.keeps(c, mechanics.laws.law_index(c)))
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
            void_source: None,
        })
    }

    /// The shared coupling data and stiffness (for [`Self::from_parts`]).
    pub(crate) fn parts(&self) -> (Arc<Operators<D>>, Arc<[f64]>) {
        (self.ops.clone(), self.k_values.clone())
    }

    /// Set the drained bulk modulus of every cell (Pa, > 0), needed by [`FixedStress`]
    /// (see [`drained_bulk_modulus`]).
    ///
    /// [`FixedStress`]: super::FixedStress
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

    /// Add the rate `q` (m³/s per cell; m²/s in 2D; one per cell) to the flow forcing of
    /// every step: the volume `q Δt` a step opens in a cell without fluid to fill it (a
    /// cavitation void, [`crate::cavitation`]) counts as a source of that volume in the
    /// cell's mass balance `M Δp + α ΔV + Δt A p = Δt (b + q)`. `None` (the default):
    /// no such term, the forcing as it was.
    ///
    /// Errors: a length other than the number of cells, a non-finite rate.
    pub fn set_void_source(&mut self, q: Option<Vec<f64>>) -> BiotResult<()> {
        if let Some(q) = &q {
            check_len("void source", q.len(), self.num_cells())?;
            if let Some(c) = q.iter().position(|v| !v.is_finite()) {
                return Err(BiotError::Input(format!(
                    "cell {c}: void source must be finite, got {}",
                    q[c]
                )));
            }
        }
        self.void_source = q;
        Ok(())
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
    pub(super) fn residual_of(&self, internal: &[f64], p: &[f64], t: f64) -> BiotResult<f64> {
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
    pub(super) fn assemble_at(
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
    pub(super) fn free_cell_tangents(&self, u: &[f64]) -> BiotResult<Vec<f64>> {
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
    pub(super) fn assemble_tangent(
        &mut self,
        u: &[f64],
        internal: Option<&mut [f64]>,
    ) -> BiotResult<bool> {
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
    pub(super) fn add_pore_pressure_equations(&self, p: &[f64], out: &mut [f64]) {
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
    pub(super) fn coupling_terms(&self, p: &[f64], u: &[f64], mech: &mut [f64], cells: &mut [f64]) {
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
    pub(super) fn mechanics_base(
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
    pub(super) fn flow_residual(
        &self,
        p_old: &[f64],
        t: f64,
        dt: f64,
        out: &mut [f64],
    ) -> BiotResult<()> {
        self.flow.forcing(t, out)?;
        if let Some(q) = &self.void_source {
            out.iter_mut().zip(q).for_each(|(o, q)| *o += q);
        }
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
    pub(super) fn alpha_volume_change(&self, u: &[f64], out: &mut [f64]) -> BiotResult<()> {
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
