//! Explicit damped dynamics (dynamic relaxation), Nilsen et al. (2017) §2.7.
//!
//! Nilsen et al. (2017) solve the mechanics of MDEM, DEM and VEM cells as in DEM codes: by explicit
//! time integration of Newton's law with Cundall's local, non-viscous damping, letting
//! the system relax to its static state. Only the nodal forces of the cell laws
//! ([`porofrac_law::CellLaw::forces`]) are needed, so any mix of laws — including the
//! nonlinear compression-only DEM of Nilsen et al. (2017) eq. 33 — runs unchanged.
//!
//! # Equations
//!
//! In the reduced unknowns `x` of [`crate::dofs`] (free dofs, platen nodes sharing one
//! equation) with prescribed values `u_p(t)` filled in,
//!
//! ```text
//!   M ẍ = f(x, t) := Tᵀ f_ext(t) + F_platen(t) + Tᵀ F_int(u(x, t)),   F_int = Σ_K F_K(u)
//! ```
//!
//! # Lumped mass
//!
//! Each cell's mass `ρ_K |K|` is split equally among its `n_K` nodes:
//! `m_i = Σ_{K ∋ i} ρ_K |K| / n_K`. On triangles and tetrahedra this is exactly the
//! row-sum lumping of the consistent P1 mass matrix (`∫_K φ_i = |K| / (D + 1)`); on
//! polygons and polyhedra it is the natural choice for the virtual-element basis, whose
//! integrals are not computable (only their sum, `|K|`, is). The mass of an equation is
//! the sum of the masses of the dofs mapped to it (a platen carries all its nodes).
//!
//! # Time integration (central differences / leapfrog)
//!
//! With `v^{n−½}` the velocity at the half step and `f^n = f(x^n, t^n)`:
//!
//! ```text
//!   v̂^n      = v^{n−½} + (Δt/2) f^n / M                (synchronised velocity estimate)
//!   d^n      = −α |f^n| sign(v̂^n)                      (Cundall local damping, per dof)
//!   v^{n+½}  = v^{n−½} + Δt (f^n + d^n) / M
//!   x^{n+1}  = x^n + Δt v^{n+½}
//! ```
//!
//! For `α = 0` this is the leapfrog / velocity-Verlet scheme (second order, symplectic):
//! started with `v^{−½} = v⁰ − (Δt/2) f⁰/M`, the total energy oscillates boundedly. The
//! damping force always opposes the motion (its power `−α |f| |v̂|` is never positive);
//! it does not depend on the size of the velocity, so slow and fast parts of the grid are
//! damped alike (Nilsen et al. (2017) §2.7). Prescribed dofs follow their values at `t^{n+1}`.
//!
//! # Stable time step
//!
//! Central differences are stable for a linear system iff `Δt ≤ 2 / ω_max`,
//! `ω_max² = λ_max(M⁻¹ A)`, `A` the reduced stiffness. By Gershgorin's theorem applied to
//! the rows of `M⁻¹ A`,
//!
//! ```text
//!   λ_max ≤ max_e g_e / M_e,   g_e = Σ_K Σ_{local i → e} Σ_{local j free} |K_K(i, j)|
//! ```
//!
//! (the triangle inequality bounds the absolute row sum of the assembled `A` by the sum
//! of the local ones). The local damping, in the worst case (the highest mode, whose
//! velocity opposes its force every step), scales the force by `1 + α`, so the computed
//! step is
//!
//! ```text
//!   Δt = safety · 2 / √((1 + α) max_e g_e / M_e)         (default safety 0.9)
//! ```
//!
//! For a nonlinear law the local stiffness is evaluated at the current displacement and
//! at a small uniform contraction and expansion of the cell (which closes, respectively
//! opens, every compression-only spring), taking the larger row sum, so the bound holds
//! whichever springs close later. [`ExplicitOptions::time_step`] overrides the step (e.g.
//! for tests); [`ExplicitState::critical_time_step`] keeps the bound.
//!
//! # Density scaling
//!
//! For quasi-static runs the inertia is fictitious. With
//! [`ExplicitOptions::density_scaling`] `= Some(Δt*)` every equation gets the mass
//!
//! ```text
//!   M_e = (1 + α) g_e (Δt* / (2 · safety))²
//! ```
//!
//! so that every equation sits at the same local stability limit and the computed step
//! is exactly `Δt*`. The masses are then proportional to the (Gershgorin) stiffness, i.e.
//! the relaxation is preconditioned by the diagonal of `A`: small stiff cells no longer
//! set a tiny global time step and soft cells no longer relax on a time scale `√(ρ/E)`
//! times longer than their stiff neighbours. The result is the same static solution.
//!
//! # Convergence and divergence
//!
//! [`solve_explicit`] stops when the unbalanced-force ratio `‖f(x)‖ / f_ref` drops below
//! the tolerance, with `f_ref = ‖Tᵀ f_ext + F_platen‖`, or the initial unbalanced force
//! when there are no loads (a problem driven by prescribed displacements). More than
//! `max_steps` steps give [`SimError::NoConvergence`] with the reached ratio.
//!
//! Divergence is caught before any NaN appears: a non-finite nodal force names its cell,
//! node and component; and with fixed supports the kinetic energy can never exceed the
//! energy put in, `E_in = E_kin⁰ + E_strain⁰ + W_ext` (`W_ext = Σ f_ext · Δx`), so
//! `E_kin > divergence_factor · E_in` is reported as [`SimError::Cell`] naming the node
//! with the fastest motion and the most strained cell at that node. (With moving
//! prescribed values the supports do work that is not tracked, and only the finiteness
//! checks apply.)
//!
//! # Parallel force evaluation
//!
//! Nodal forces use the fill chunks of the [`crate::pattern::Pattern`]: each chunk owns a
//! contiguous range of equations, visits the cells touching it and adds only the entries
//! it owns, so the scatter is race-free without atomics, and deterministic (independent of
//! the thread count). Each chunk keeps its own buffers ([`porofrac_law::Scratch`], the
//! gathered displacements and forces) across steps, and the geometry of every cell (node
//! coordinates and `∫_∂K φ_i n`) is computed once, so a step allocates nothing per cell.
//! The price is that cells on a chunk boundary are evaluated twice
//! ([`crate::Pattern::duplication`]: 7 % at E2 n = 100, 2 % at n = 300 with 8 chunks). On
//! 2 threads a step takes about 2.9 ms (MDEM) / 1.9 ms (VEM) at n = 100 (20 k triangles)
//! and 22 ms / 15 ms at n = 300 (180 k triangles), see `benches/explicit.rs`.

use porofrac_grid::{Grid, Point};
use porofrac_law::CellGeometry;
use rayon::prelude::*;

use crate::assembly::{Work, cell_error, law_error, nodal_loads};
use crate::error::{AXES, Result, SimError, fmt_point};
use crate::laws::LawMap;
use crate::pattern::Pattern;
use crate::solve::StaticProblem;

/// Options of [`solve_explicit`] and [`ExplicitState`].
#[derive(Clone, Copy, Debug)]
pub struct ExplicitOptions {
    /// Cundall's local damping coefficient `α ∈ [0, 1)` (0: undamped, true dynamics).
    pub damping: f64,
    /// Safety factor `∈ (0, 1]` on the Gershgorin stability bound.
    pub safety: f64,
    /// Unbalanced-force ratio at which [`solve_explicit`] stops.
    pub tolerance: f64,
    /// Steps allowed in [`solve_explicit`].
    pub max_steps: usize,
    /// Density scaling for quasi-static runs: the target time step `Δt*` (s). See the
    /// module docs.
    pub density_scaling: Option<f64>,
    /// Use this time step instead of the computed one (s).
    pub time_step: Option<f64>,
    /// Kinetic energy above this multiple of the energy put in counts as divergence.
    pub divergence_factor: f64,
}

impl Default for ExplicitOptions {
    fn default() -> Self {
        Self {
            damping: 0.8,
            safety: 0.9,
            tolerance: 1e-8,
            max_steps: 1_000_000,
            density_scaling: None,
            time_step: None,
            divergence_factor: 100.0,
        }
    }
}

impl ExplicitOptions {
    fn check(&self) -> Result<()> {
        let bad = |what: String| Err(SimError::Input(format!("explicit options: {what}")));
        if !(0.0..1.0).contains(&self.damping) {
            return bad(format!("damping must be in [0, 1), got {}", self.damping));
        }
        if !(self.safety > 0.0 && self.safety <= 1.0) {
            return bad(format!("safety must be in (0, 1], got {}", self.safety));
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return bad(format!("tolerance must be > 0, got {}", self.tolerance));
        }
        for (name, v) in [
            ("density_scaling", self.density_scaling),
            ("time_step", self.time_step),
        ] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0)
            {
                return bad(format!("{name} must be a positive time step, got {v}"));
            }
        }
        if !(self.divergence_factor.is_finite() && self.divergence_factor >= 1.0) {
            return bad(format!(
                "divergence_factor must be ≥ 1, got {}",
                self.divergence_factor
            ));
        }
        Ok(())
    }
}

/// The result of [`solve_explicit`].
#[derive(Clone, Debug)]
pub struct ExplicitSolution<const D: usize> {
    /// Nodal displacements, node-major (`D` per node), prescribed values filled in.
    pub displacement: Vec<f64>,
    /// Time steps taken.
    pub steps: usize,
    /// The time step used (s).
    pub dt: f64,
    /// The final unbalanced-force ratio `‖f‖ / f_ref`.
    pub unbalanced_ratio: f64,
}

impl<const D: usize> ExplicitSolution<D> {
    /// Displacement of node `n`.
    pub fn node(&self, n: usize) -> Point<D> {
        Point::<D>::from_column_slice(&self.displacement[D * n..D * n + D])
    }
}

/// Node coordinates and `∫_∂K φ_i n` of every cell, computed once.
struct GeoCache<const D: usize> {
    start: Vec<usize>,
    coords: Vec<Point<D>>,
    normals: Vec<Point<D>>,
}

impl<const D: usize> GeoCache<D> {
    fn new(grid: &Grid<D>) -> Self {
        let nc = grid.num_cells();
        let mut start = Vec::with_capacity(nc + 1);
        start.push(0);
        for c in 0..nc {
            start.push(start[c] + grid.cell_nodes(c).len());
        }
        let total = start[nc];
        let mut coords = Vec::with_capacity(total);
        let mut normals = vec![Point::<D>::zeros(); total];
        for c in 0..nc {
            coords.extend(grid.cell_nodes(c).iter().map(|&n| *grid.node(n)));
            grid.cell_node_normals(c, &mut normals[start[c]..start[c + 1]]);
        }
        Self {
            start,
            coords,
            normals,
        }
    }

    #[inline]
    fn cell<'a>(&'a self, grid: &Grid<D>, c: usize) -> CellGeometry<'a, D> {
        let r = self.start[c]..self.start[c + 1];
        CellGeometry {
            coords: &self.coords[r.clone()],
            node_normals: &self.normals[r],
            volume: grid.cell_volume(c),
        }
    }
}

/// Evaluate a per-cell local vector (written by `f` into `w.f`, length `D · n`; `f`
/// returns `false` to skip the cell) and sum it into the owned equations of each fill
/// chunk of `pattern`, in parallel, race-free. `out` (length = equations) is overwritten.
fn scatter_cells<const D: usize, F>(
    grid: &Grid<D>,
    raw: &[usize],
    pattern: &Pattern,
    works: &mut [Work<D>],
    out: &mut [f64],
    f: F,
) -> Result<()>
where
    F: Fn(&mut Work<D>, usize) -> Result<bool> + Sync,
{
    let mut parts = Vec::with_capacity(pattern.chunks.len());
    let mut rest = out;
    for (ch, w) in pattern.chunks.iter().zip(works.iter_mut()) {
        let (o, r) = rest.split_at_mut(ch.cols.len());
        parts.push((ch, w, o));
        rest = r;
    }
    parts.into_par_iter().try_for_each(|(ch, w, o)| {
        o.fill(0.0);
        let (c0, clen) = (ch.cols.start, o.len());
        for &c in &pattern.chunk_cells[ch.cells.clone()] {
            if !f(w, c)? {
                continue;
            }
            let nodes = grid.cell_nodes(c);
            for (i, fi) in w.f.iter().enumerate() {
                let k = raw[D * nodes[i / D] + i % D].wrapping_sub(c0);
                if k < clen {
                    o[k] += fi;
                }
            }
        }
        Ok(())
    })
}

/// Reduced internal forces `Tᵀ F_int(u)` into `out` (see [`scatter_cells`]).
fn internal_forces<const D: usize>(
    grid: &Grid<D>,
    laws: &LawMap<'_, D>,
    raw: &[usize],
    pattern: &Pattern,
    geo: &GeoCache<D>,
    works: &mut [Work<D>],
    u: &[f64],
    out: &mut [f64],
) -> Result<()> {
    scatter_cells(grid, raw, pattern, works, out, |w, c| {
        let law = laws.law(c);
        w.gather(grid, c, u);
        if law.is_linear() && w.u.iter().all(|&x| x == 0.0) {
            return Ok(false);
        }
        w.f.clear();
        w.f.resize(w.u.len(), 0.0);
        law.forces(&geo.cell(grid, c), &w.u, &mut w.f, &mut w.scratch)
            .map_err(law_error(laws, c))?;
        // Divergence: finite laws give non-finite forces only from non-finite motion.
        if let Some(i) = w.f.iter().position(|v| !v.is_finite()) {
            let n = grid.cell_nodes(c)[i / D];
            return Err(cell_error(
                laws,
                c,
                format!(
                    "non-finite nodal force at node {n} at {}, component {}",
                    fmt_point(grid.node(n).as_slice()),
                    AXES[i % D]
                ),
            ));
        }
        Ok(true)
    })
}

/// Whether the external loads are independent of time (then they are evaluated once).
fn loads_constant<const D: usize>(loads: &crate::bc::Loads<D>) -> bool {
    let b = loads
        .body_force
        .as_ref()
        .is_none_or(|b| b.as_const().is_some());
    let t = loads
        .tractions
        .iter()
        .all(|tr| tr.traction.iter().all(|f| f.as_const().is_some()));
    b && t
}

/// A lower-level explicit stepper: the state `(x^n, v^{n−½}, f^n)` of the scheme in the
/// module docs, advanced by [`Self::step`].
///
/// With `damping = 0` it integrates the true (undamped) dynamics; loads and prescribed
/// values follow the time unless [`Self::set_time_frozen`] holds them (as
/// [`solve_explicit`] does).
pub struct ExplicitState<'a, const D: usize> {
    problem: StaticProblem<'a, D>,
    geo: GeoCache<D>,
    works: Vec<Work<D>>,
    mass: Vec<f64>,
    bound: Vec<f64>,
    damping: f64,
    divergence_factor: f64,
    dt: f64,
    dt_stable: f64,
    dt_critical: f64,
    t: f64,
    frozen: bool,
    loads_const: bool,
    steps: usize,
    x: Vec<f64>,
    v: Vec<f64>,
    f: Vec<f64>,
    fint: Vec<f64>,
    fext: Vec<f64>,
    fext_nodal_reduced: Vec<f64>,
    u: Vec<f64>,
    prescribed: Vec<f64>,
    moving_supports: bool,
    energy_in: f64,
    work_ext: f64,
    fnorm: f64,
}

impl<'a, const D: usize> ExplicitState<'a, D> {
    /// Set up the stepper at time `t0`: lumped masses from the per-cell `density`
    /// (kg/m³), the stable time step, and the initial state from the nodal displacement
    /// `u0` and velocity `v0` (length `D · nodes`, node-major; zero if `None`; prescribed
    /// entries are ignored, a platen equation takes the mean of its dofs).
    ///
    /// Errors: wrong lengths, a non-positive or non-finite density (naming the cell), bad
    /// options, a law failing on a cell or returning a wrong-sized stiffness, or
    /// non-finite forces (naming the cell), an
    /// equation without mass or stiffness (naming its node), and the load errors.
    pub fn new(
        problem: &StaticProblem<'a, D>,
        density: &[f64],
        t0: f64,
        options: &ExplicitOptions,
        u0: Option<&[f64]>,
        v0: Option<&[f64]>,
    ) -> Result<Self> {
        options.check()?;
        let StaticProblem {
            grid,
            laws,
            dofs,
            pattern,
            loads,
        } = *problem;
        let nc = grid.num_cells();
        let ndof = dofs.num_dofs();
        let neq = dofs.num_equations();
        if ndof != D * grid.num_nodes() || pattern.num_equations() != neq {
            return Err(SimError::Input(format!(
                "explicit: dof map ({ndof} dofs, {neq} equations) and pattern ({} equations) \
                 do not match the grid ({} nodes)",
                pattern.num_equations(),
                grid.num_nodes()
            )));
        }
        if density.len() != nc {
            return Err(SimError::Input(format!(
                "explicit: {} densities for {nc} cells",
                density.len()
            )));
        }
        if let Some(c) = density.iter().position(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(cell_error(
                laws,
                c,
                format!("density must be positive, got {}", density[c]),
            ));
        }
        for (name, v) in [("u0", u0), ("v0", v0)] {
            if let Some(v) = v {
                if v.len() != ndof {
                    return Err(SimError::Input(format!(
                        "explicit: {name} has length {}, want {ndof}",
                        v.len()
                    )));
                }
                if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                    return Err(SimError::Input(format!(
                        "explicit: {name} is not finite at node {}, component {}",
                        i / D,
                        AXES[i % D]
                    )));
                }
            }
        }
        let raw = dofs.raw();
        // Lumped masses: ρ_K |K| / n_K per node, summed into the equations.
        let mut node_mass = vec![0.0; grid.num_nodes()];
        for c in 0..nc {
            let nodes = grid.cell_nodes(c);
            let share = density[c] * grid.cell_volume(c) / nodes.len() as f64;
            for &n in nodes {
                node_mass[n] += share;
            }
        }
        let mut mass = vec![0.0; neq];
        for (d, &e) in raw.iter().enumerate() {
            if e != usize::MAX {
                mass[e] += node_mass[d / D];
            }
        }
        let geo = GeoCache::new(grid);
        let mut works: Vec<Work<D>> = (0..pattern.chunks.len()).map(|_| Work::default()).collect();
        let mut state_u = vec![0.0; ndof];
        if let Some(u0) = u0 {
            state_u.copy_from_slice(u0);
        }
        dofs.set_prescribed(grid, t0, &mut state_u);
        // Gershgorin row sums of the local stiffnesses.
        let mut bound = vec![0.0; neq];
        {
            let u = &state_u;
            let geo = &geo;
            scatter_cells(grid, raw, pattern, &mut works, &mut bound, |w, c| {
                let law = laws.law(c);
                let nodes = grid.cell_nodes(c);
                let m = D * nodes.len();
                w.f.clear();
                w.f.resize(m, 0.0);
                let g = geo.cell(grid, c);
                let trials = if law.is_linear() { 1 } else { 3 };
                for trial in 0..trials {
                    w.gather(grid, c, u);
                    if trial > 0 {
                        // Uniform contraction (trial 1) or expansion (trial 2) by 1e-6.
                        let s = if trial == 1 { -1e-6 } else { 1e-6 };
                        let xbar = g.coords.iter().sum::<Point<D>>() / g.coords.len() as f64;
                        for (i, x) in g.coords.iter().enumerate() {
                            for a in 0..D {
                                w.u[D * i + a] = s * (x[a] - xbar[a]);
                            }
                        }
                    }
                    law.stiffness(&g, &w.u, &mut w.k, &mut w.scratch)
                        .map_err(law_error(laws, c))?;
                    if w.k.nrows() != m || w.k.ncols() != m {
                        return Err(cell_error(
                            laws,
                            c,
                            format!(
                                "stiffness is {}×{}, expected {m}×{m}",
                                w.k.nrows(),
                                w.k.ncols()
                            ),
                        ));
                    }
                    for i in 0..m {
                        let mut s = 0.0;
                        for j in 0..m {
                            if raw[D * nodes[j / D] + j % D] != usize::MAX {
                                s += w.k[(i, j)].abs();
                            }
                        }
                        w.f[i] = w.f[i].max(s);
                    }
                }
                Ok(true)
            })?;
        }
        let amp = 1.0 + options.damping;
        let describe = |e: usize| dofs.describe_equation(grid, e);
        if let Some(target) = options.density_scaling {
            let s = (target / (2.0 * options.safety)).powi(2) * amp;
            for (m, &g) in mass.iter_mut().zip(&bound) {
                if g > 0.0 {
                    *m = g * s;
                }
            }
        }
        let mut lam = 0.0f64;
        for e in 0..neq {
            if mass[e].is_nan() || mass[e] <= 0.0 {
                return Err(SimError::Input(format!(
                    "explicit: {} has no mass (it belongs to no cell)",
                    describe(e)
                )));
            }
            lam = lam.max(bound[e] / mass[e]);
        }
        if !(lam > 0.0 && lam.is_finite()) {
            return Err(SimError::Input(format!(
                "explicit: no stiffness to bound the time step (Gershgorin bound {lam})"
            )));
        }
        let dt_critical = 2.0 / (amp * lam).sqrt();
        let dt_stable = options.safety * dt_critical;
        let dt = options.time_step.unwrap_or(dt_stable);
        let mut x = vec![0.0; neq];
        let mut v = vec![0.0; neq];
        let mut count = vec![0usize; neq];
        for (d, &e) in raw.iter().enumerate() {
            if e != usize::MAX {
                count[e] += 1;
                if let Some(u0) = u0 {
                    x[e] += u0[d];
                }
                if let Some(v0) = v0 {
                    v[e] += v0[d];
                }
            }
        }
        for e in 0..neq {
            let k = count[e].max(1) as f64;
            x[e] /= k;
            v[e] /= k;
        }
        dofs.scatter(&x, &mut state_u);
        let prescribed = dofs.prescribed_dofs().iter().map(|&d| state_u[d]).collect();
        let mut s = Self {
            problem: *problem,
            geo,
            works,
            mass,
            bound,
            damping: options.damping,
            divergence_factor: options.divergence_factor,
            dt,
            dt_stable,
            dt_critical,
            t: t0,
            frozen: false,
            loads_const: loads_constant(loads),
            steps: 0,
            x,
            v,
            f: vec![0.0; neq],
            fint: vec![0.0; neq],
            fext: vec![0.0; neq],
            fext_nodal_reduced: vec![0.0; neq],
            u: state_u,
            prescribed,
            moving_supports: false,
            energy_in: 0.0,
            work_ext: 0.0,
            fnorm: 0.0,
        };
        s.update_loads(true)?;
        s.evaluate_forces()?;
        // v^{−½} = v⁰ − (Δt/2) f⁰/M.
        for e in 0..neq {
            s.v[e] -= 0.5 * s.dt * s.f[e] / s.mass[e];
        }
        s.energy_in = s.kinetic_energy() + s.strain_energy()?;
        Ok(s)
    }

    /// Hold loads and prescribed values at the current time (`true`), as a quasi-static
    /// relaxation does, or let them follow the time (`false`, the default).
    pub fn set_time_frozen(&mut self, frozen: bool) {
        self.frozen = frozen;
    }

    /// Evaluate the external loads at the current time (the nodal part only when
    /// `all` or when they depend on time).
    fn update_loads(&mut self, all: bool) -> Result<()> {
        let StaticProblem {
            grid, dofs, loads, ..
        } = self.problem;
        if all || !self.loads_const {
            let mut full = vec![0.0; dofs.num_dofs()];
            nodal_loads(grid, loads, self.t, &mut full)?;
            self.fext_nodal_reduced.fill(0.0);
            dofs.reduce_add(&full, &mut self.fext_nodal_reduced);
        }
        self.fext.copy_from_slice(&self.fext_nodal_reduced);
        dofs.add_platen_forces(grid, self.t, &mut self.fext);
        Ok(())
    }

    /// `f = f_ext + Tᵀ F_int(u)` at the current `u`, and its norm.
    fn evaluate_forces(&mut self) -> Result<()> {
        let StaticProblem {
            grid,
            laws,
            dofs,
            pattern,
            ..
        } = self.problem;
        internal_forces(
            grid,
            laws,
            dofs.raw(),
            pattern,
            &self.geo,
            &mut self.works,
            &self.u,
            &mut self.fint,
        )
        .map_err(|e| match e {
            SimError::Cell { cell, law, what } => SimError::Cell {
                cell,
                law,
                what: format!(
                    "{what} at explicit step {} (t = {:.6e} s, Δt = {:.3e} s, stable Δt = {:.3e} s)",
                    self.steps, self.t, self.dt, self.dt_stable
                ),
            },
            e => e,
        })?;
        let mut s = 0.0;
        for ((f, a), b) in self.f.iter_mut().zip(&self.fext).zip(&self.fint) {
            *f = a + b;
            s += *f * *f;
        }
        self.fnorm = s.sqrt();
        Ok(())
    }

    /// Advance one time step (see the module docs).
    ///
    /// Errors: divergence (a non-finite force naming its cell, node and component, or a
    /// kinetic energy beyond the energy put in, naming the node and cell), load errors.
    pub fn step(&mut self) -> Result<()> {
        let (dt, alpha) = (self.dt, self.damping);
        let mut dw = 0.0;
        for e in 0..self.x.len() {
            let (f, m) = (self.f[e], self.mass[e]);
            let vhat = self.v[e] + 0.5 * dt * f / m;
            let d = if alpha > 0.0 && vhat != 0.0 {
                -alpha * f.abs() * vhat.signum()
            } else {
                0.0
            };
            self.v[e] += dt * (f + d) / m;
            let dx = dt * self.v[e];
            self.x[e] += dx;
            dw += self.fext[e] * dx;
        }
        self.work_ext += dw;
        self.steps += 1;
        self.t += dt;
        let StaticProblem { grid, dofs, .. } = self.problem;
        dofs.scatter(&self.x, &mut self.u);
        if !self.frozen {
            dofs.set_prescribed(grid, self.t, &mut self.u);
            for (p, &d) in self.prescribed.iter_mut().zip(dofs.prescribed_dofs()) {
                if *p != self.u[d] {
                    self.moving_supports = true;
                    *p = self.u[d];
                }
            }
            self.update_loads(false)?;
        }
        self.evaluate_forces()?;
        let ke = self.kinetic_energy();
        let budget = self.divergence_factor * (self.energy_in + self.work_ext).abs();
        if !ke.is_finite() || (!self.moving_supports && ke > budget) {
            return Err(self.divergence_error(ke));
        }
        Ok(())
    }

    /// The divergence error: the equation with the largest kinetic energy, and the cell
    /// at its node with the largest (or a non-finite) strain energy.
    fn divergence_error(&mut self, ke: f64) -> SimError {
        let put_in = (self.energy_in + self.work_ext).abs();
        let StaticProblem {
            grid, laws, dofs, ..
        } = self.problem;
        let mut worst = (0, -1.0f64);
        for e in 0..self.v.len() {
            let k = self.mass[e] * self.v[e] * self.v[e];
            if !k.is_finite() || k > worst.1 {
                worst = (e, if k.is_finite() { k } else { f64::INFINITY });
                if !k.is_finite() {
                    break;
                }
            }
        }
        let e = worst.0;
        let node = dofs.raw().iter().position(|&q| q == e).map_or(0, |d| d / D);
        let w = &mut self.works[0];
        let mut cell = (usize::MAX, -1.0f64);
        for c in 0..grid.num_cells() {
            if !grid.cell_nodes(c).contains(&node) {
                continue;
            }
            w.gather(grid, c, &self.u);
            let en = laws
                .law(c)
                .energy(&self.geo.cell(grid, c), &w.u, &mut w.scratch);
            // A cell whose law fails or gives a non-finite energy is the worst.
            let en = match en {
                Ok(en) if en.is_finite() => en,
                _ => f64::INFINITY,
            };
            if en > cell.1 {
                cell = (c, en);
            }
        }
        let what = format!(
            "explicit integration diverged at step {} (t = {:.6e} s): kinetic energy {ke:.3e} J \
             exceeds {} × the energy put in ({put_in:.3e} J); fastest motion at {}, \
             in this cell; time step {:.3e} s, computed stable step {:.3e} s",
            self.steps,
            self.t,
            self.divergence_factor,
            dofs.describe_equation(grid, e),
            self.dt,
            self.dt_stable
        );
        if cell.0 == usize::MAX {
            SimError::NotFinite { location: what }
        } else {
            cell_error(laws, cell.0, what)
        }
    }

    /// Current time (s).
    pub fn time(&self) -> f64 {
        self.t
    }
    /// The time step in use (s).
    pub fn time_step(&self) -> f64 {
        self.dt
    }
    /// The computed stable time step, `safety · critical` (s).
    pub fn stable_time_step(&self) -> f64 {
        self.dt_stable
    }
    /// The Gershgorin bound on the critical step, `2 / √((1 + α) max_e g_e / M_e)` (s).
    pub fn critical_time_step(&self) -> f64 {
        self.dt_critical
    }
    /// Steps taken.
    pub fn steps(&self) -> usize {
        self.steps
    }
    /// Nodal displacements (length `D · nodes`, prescribed values filled in).
    pub fn displacement(&self) -> &[f64] {
        &self.u
    }
    /// The lumped (possibly density-scaled) mass of each equation (kg, 2D: per metre).
    pub fn masses(&self) -> &[f64] {
        &self.mass
    }
    /// The Gershgorin row sum `g_e` of each equation (N/m).
    pub fn stiffness_bounds(&self) -> &[f64] {
        &self.bound
    }
    /// The unbalanced force `f = f_ext + Tᵀ F_int` at the current displacement, per equation.
    pub fn unbalanced_force(&self) -> &[f64] {
        &self.f
    }
    /// `‖f‖` of [`Self::unbalanced_force`].
    pub fn unbalanced_norm(&self) -> f64 {
        self.fnorm
    }
    /// The external load per equation at the current time (with platen forces).
    pub fn external_force(&self) -> &[f64] {
        &self.fext
    }
    /// The velocity of each equation at the current time, `v̂^n = v^{n−½} + (Δt/2) f^n / M`
    /// (exact for the undamped velocity-Verlet form of the scheme).
    pub fn velocity(&self) -> Vec<f64> {
        (0..self.v.len())
            .map(|e| self.v[e] + 0.5 * self.dt * self.f[e] / self.mass[e])
            .collect()
    }
    /// Kinetic energy `½ Σ_e M_e (v̂_e)²` at the current time (J; 2D: per metre).
    pub fn kinetic_energy(&self) -> f64 {
        let mut s = 0.0;
        for e in 0..self.v.len() {
            let v = self.v[e] + 0.5 * self.dt * self.f[e] / self.mass[e];
            s += self.mass[e] * v * v;
        }
        0.5 * s
    }
    /// Strain energy `Σ_K E_K(u)` at the current displacement (J; 2D: per metre).
    pub fn strain_energy(&self) -> Result<f64> {
        let StaticProblem { grid, laws, .. } = self.problem;
        let geo = &self.geo;
        let u = &self.u;
        let e: f64 = (0..grid.num_cells())
            .into_par_iter()
            .map_init(Work::<D>::default, |w, c| {
                w.gather(grid, c, u);
                laws.law(c)
                    .energy(&geo.cell(grid, c), &w.u, &mut w.scratch)
                    .map_err(law_error(laws, c))
            })
            .sum::<Result<f64>>()?;
        if !e.is_finite() {
            return Err(SimError::NotFinite {
                location: format!("the strain energy at explicit step {}", self.steps),
            });
        }
        Ok(e)
    }
    /// Potential of the current external loads, `−f_ext · x` (J): with constant loads,
    /// `kinetic + strain + load potential` is conserved by the undamped dynamics.
    pub fn load_potential(&self) -> f64 {
        -self
            .fext
            .iter()
            .zip(&self.x)
            .map(|(f, x)| f * x)
            .sum::<f64>()
    }
}

/// Relax the static problem at time `t` to equilibrium with damped explicit dynamics
/// (see the module docs), from the nodal displacement `u0` (zero if `None`).
///
/// Loads and prescribed values are held at time `t`. Errors:
/// [`SimError::Singular`] if rigid-body modes are free, [`SimError::NoConvergence`] with
/// the reached unbalanced-force ratio after `max_steps` steps, divergence (naming the cell),
/// and the errors of [`ExplicitState::new`].
pub fn solve_explicit<const D: usize>(
    problem: &StaticProblem<'_, D>,
    density: &[f64],
    t: f64,
    options: &ExplicitOptions,
    u0: Option<&[f64]>,
) -> Result<ExplicitSolution<D>> {
    problem.dofs.check_rigid_modes(problem.grid)?;
    let mut s = ExplicitState::new(problem, density, t, options, u0, None)?;
    s.set_time_frozen(true);
    let fext = s.external_force().iter().map(|f| f * f).sum::<f64>().sqrt();
    let reference = if fext > 0.0 {
        fext
    } else {
        s.unbalanced_norm()
    };
    let ratio = |s: &ExplicitState<'_, D>| {
        if reference > 0.0 {
            s.unbalanced_norm() / reference
        } else {
            0.0
        }
    };
    loop {
        let r = ratio(&s);
        if r <= options.tolerance {
            return Ok(ExplicitSolution {
                displacement: s.u,
                steps: s.steps,
                dt: s.dt,
                unbalanced_ratio: r,
            });
        }
        if s.steps >= options.max_steps {
            return Err(SimError::NoConvergence {
                iterations: s.steps,
                residual: r,
            });
        }
        s.step()?;
    }
}
