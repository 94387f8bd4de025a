//! The choice of linear solver for the static mechanics solve.
//!
//! [`solve_static`](crate::solve_static) solves `A Δx = r` with the reduced stiffness `A`
//! (symmetric positive definite) once per Newton step, through the [`LinearSolve`] trait:
//!
//! * [`DirectSolver`]: sparse Cholesky, symbolic factorization reused; exact up to
//!   rounding, memory and time grow like the factor (`n log n` / `n^{3/2}` in 2D,
//!   `n^{4/3}` / `n²` in 3D with nested dissection).
//! * [`AmgSolver`]: conjugate gradients preconditioned by smoothed-aggregation multigrid
//!   ([`porofrac_amg`], rigid-body near-null space from the node coordinates), to a
//!   relative residual `‖A Δx − r‖ / ‖r‖ ≤ tolerance`; `O(n)` memory and time per
//!   iteration, iteration counts nearly independent of `n`. The hierarchy stores its
//!   finest matrix in single precision by default ([`AmgSolver::set_precision`]; CG
//!   multiplies by the double-precision values, [`porofrac_amg::Amg::solve_upper`]). It is
//!   built on the first solve; later solves with new values on the same pattern only redo
//!   its numeric part ([`porofrac_amg::Amg::update_values`]: aggregates, patterns and the
//!   symbolic coarse factorization are kept), and a solve with unchanged values (to the
//!   stored precision) reuses it as is.
//!   A solve that reaches the iteration limit, stagnates or breaks down is an error
//!   ([`SimError::Iterative`]) naming the iterations and the residual reached.
//! * [`StaticSolver`]: one of the two, chosen by [`LinearSolver`]; `Auto` picks by the
//!   measured crossover ([`LinearSolver::resolve`]).

use porofrac_amg::{Amg, AmgOptions, Precision, SymCsr};
use porofrac_grid::Grid;

use crate::dofs::DofMap;
use crate::error::{Result, SimError};
use crate::ordering::nested_dissection;
use crate::pattern::Pattern;
use crate::solve::DirectSolver;

/// Default relative residual of the iterative solver.
pub const DEFAULT_TOLERANCE: f64 = 1e-8;
/// Default iteration limit of the iterative solver.
pub const DEFAULT_MAX_ITERATIONS: usize = 500;
/// `Auto` uses CG-AMG in 3D from this many equations (E3 n = 20, 20 577 equations:
/// CG-AMG 0.16 s setup + solve against 0.76 s for nested-dissection Cholesky;
/// docs/BENCHMARKS.md, "Linear solvers: direct vs AMG-CG").
pub const AUTO_MIN_EQUATIONS_3D: usize = 10_000;
/// `Auto` uses CG-AMG in 2D from this many equations (E2 setup + solve: at 0.18 M
/// equations Cholesky and CG-AMG take about the same time, at 0.5 M CG-AMG 1.8 s against
/// 1.9 s for AMD Cholesky on two threads, at 2 M 7.6 s against 13.5 s with 0.7 GB less
/// memory; docs/BENCHMARKS.md). Below it the direct solver's exact answer costs no more.
pub const AUTO_MIN_EQUATIONS_2D: usize = 400_000;

/// Which linear solver the static mechanics uses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum LinearSolver {
    /// Sparse Cholesky (AMD in 2D, geometric nested dissection in 3D).
    Cholesky,
    /// CG preconditioned by smoothed-aggregation AMG, to the relative residual
    /// `tolerance`.
    CgAmg {
        /// Relative residual `‖A x − b‖ / ‖b‖` to reach.
        tolerance: f64,
    },
    /// [`Self::CgAmg`] with [`DEFAULT_TOLERANCE`] for 3D systems of at least
    /// [`AUTO_MIN_EQUATIONS_3D`] equations and 2D systems of at least
    /// [`AUTO_MIN_EQUATIONS_2D`], [`Self::Cholesky`] otherwise.
    #[default]
    Auto,
}

impl LinearSolver {
    /// The concrete choice for a `dim`-dimensional system of `equations` equations
    /// (`Auto` resolved; the others unchanged).
    pub fn resolve(self, dim: usize, equations: usize) -> Self {
        match self {
            Self::Auto => {
                let min = if dim >= 3 {
                    AUTO_MIN_EQUATIONS_3D
                } else {
                    AUTO_MIN_EQUATIONS_2D
                };
                if equations >= min {
                    Self::CgAmg {
                        tolerance: DEFAULT_TOLERANCE,
                    }
                } else {
                    Self::Cholesky
                }
            }
            other => other,
        }
    }

    /// Short name: `"cholesky"`, `"cg-amg"` or `"auto"`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Cholesky => "cholesky",
            Self::CgAmg { .. } => "cg-amg",
            Self::Auto => "auto",
        }
    }
}

/// Statistics of one linear solve.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinearStats {
    /// Iterations of an iterative solver (0 for a direct solve).
    pub iterations: usize,
    /// The true relative residual `‖b − A x‖ / ‖b‖` of the solution when the solver
    /// computed it (CG does, to stop); `None` when the caller has to.
    pub relative_residual: Option<f64>,
}

/// A solver of `A x = b` for the reduced stiffness `A`, given by its upper-triangle
/// `values` on `pattern`.
pub trait LinearSolve {
    /// Solve `A x = b` into `x` (its content on entry is ignored).
    ///
    /// Errors: [`SimError::NotPositiveDefinite`] (with `equation`; the caller names the
    /// node), [`SimError::Iterative`], [`SimError::Input`] for inconsistent sizes.
    fn solve_system(
        &mut self,
        pattern: &Pattern,
        values: &[f64],
        b: &[f64],
        x: &mut [f64],
    ) -> Result<LinearStats>;

    /// Largest relative residual `‖A x − b‖ / ‖b‖` a successful solve may leave; above
    /// it the caller reports a numerically singular system.
    fn residual_limit(&self) -> f64 {
        1e-8
    }
}

impl LinearSolve for DirectSolver {
    fn solve_system(
        &mut self,
        pattern: &Pattern,
        values: &[f64],
        b: &[f64],
        x: &mut [f64],
    ) -> Result<LinearStats> {
        self.factorize(pattern, values)?;
        x.copy_from_slice(b);
        self.solve_in_place(x)?;
        Ok(LinearStats::default())
    }
}

/// CG preconditioned by smoothed-aggregation AMG with rigid-body modes (see the module
/// docs).
pub struct AmgSolver {
    amg: Option<Amg>,
    /// The last numeric update failed: update even if the values did not change.
    failed_update: bool,
    coords: Vec<f64>,
    eq_dofs: Vec<(usize, usize)>,
    dim: usize,
    n: usize,
    nnz: usize,
    options: AmgOptions,
    precision: Precision,
    tolerance: f64,
    max_iterations: usize,
    setups: usize,
    updates: usize,
    last_iterations: usize,
    total_iterations: usize,
}

impl std::fmt::Debug for AmgSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AmgSolver")
            .field("amg", &self.amg)
            .field("n", &self.n)
            .field("tolerance", &self.tolerance)
            .field("max_iterations", &self.max_iterations)
            .field("setups", &self.setups)
            .field("updates", &self.updates)
            .field("total_iterations", &self.total_iterations)
            .finish()
    }
}

/// The multigrid options [`AmgSolver`] starts from in `dim` dimensions: the
/// [`AmgOptions`] defaults with aggressive coarsening on the finest level
/// (`aggressive_levels = 1`), the strength threshold θ = 0.08 in 2D, 0 in 3D, and the
/// prolongator damping `ω ρ̂ = 1.6` instead of 4/3.
///
/// Measured with `cargo run --release -p porofrac-sim --example solvers` (docs/BENCHMARKS.md):
/// on the standard problem E2 (P1 triangles, 2 M equations) θ = 0.08 drops weak couplings
/// on the coarse levels and cuts CG from 26 to 16 iterations; on E3 (tetrahedra) the same
/// θ stalls the coarsening (operator complexity 17 at n = 40), so 3D keeps every
/// connection. Aggregating the finest level on the distance-two strength graph costs 5–7
/// more iterations but builds a hierarchy with operator complexity 1.05–1.13 instead of
/// 1.42–1.53: in back-to-back pairs on the idle machine the total time drops (E2 n = 1000:
/// 8.1–9.9 s against 8.6–11.3 s; E3 n = 40: 2.0–2.1 s against 2.1–2.4 s; E3 n = 60: 7.4
/// against 8.2 s) and so does the peak memory (2.74 against 3.33 GB, 0.75 against 0.89 GB,
/// 2.55 against 3.04 GB).
///
/// The damping 4/3 minimises the largest energy of a smoothed basis function over the
/// spectrum (see `porofrac_amg`'s hierarchy docs); with the large aggregates of aggressive
/// coarsening a stronger step is better in practice: `ω ρ̂ = 1.6` took CG from 21–24 to
/// 20–22 iterations on E2 n = 100–1000 and from 14–22 to 14–21 on E3 n = 10–60, with the
/// same L2 errors to 4 digits (E2 n = 1000: 1.6207e-8 against 1.6184e-8, reference
/// 1.6230e-8). Larger values cost accuracy at the same residual: `ω ρ̂ = 1.7` needed 20
/// iterations at E2 n = 1000 but left the L2 error at 1.6285e-8.
pub fn elasticity_amg_options(dim: usize) -> AmgOptions {
    AmgOptions {
        strength_threshold: if dim == 2 { 0.08 } else { 0.0 },
        aggressive_levels: 1,
        prolongation_damping: 1.6,
        ..AmgOptions::default()
    }
}

impl AmgSolver {
    /// A solver for the equations of `dofs` on `pattern` (node coordinates from `grid`),
    /// to the relative residual `tolerance`, with the options of
    /// [`elasticity_amg_options`] and [`DEFAULT_MAX_ITERATIONS`]. The hierarchy is built
    /// on the first solve.
    pub fn new<const D: usize>(
        grid: &Grid<D>,
        dofs: &DofMap<D>,
        pattern: &Pattern,
        tolerance: f64,
    ) -> Result<Self> {
        if !(tolerance > 0.0 && tolerance < 1.0) {
            return Err(SimError::Input(format!(
                "CG-AMG tolerance {tolerance} must be in (0, 1)"
            )));
        }
        let n = dofs.num_equations();
        if pattern.num_equations() != n {
            return Err(SimError::Input(format!(
                "pattern of {} equations for a dof map of {n}",
                pattern.num_equations()
            )));
        }
        let coords: Vec<f64> = grid
            .nodes()
            .iter()
            .flat_map(|p| p.iter().copied())
            .collect();
        // (node, component) of every equation; a platen's shared equation takes its
        // first node.
        let mut eq_dofs = vec![(usize::MAX, 0); n];
        for node in 0..grid.num_nodes() {
            for a in 0..D {
                if let Some(e) = dofs.equation(node, a)
                    && eq_dofs[e].0 == usize::MAX
                {
                    eq_dofs[e] = (node, a);
                }
            }
        }
        Ok(Self {
            amg: None,
            failed_update: false,
            coords,
            eq_dofs,
            dim: D,
            n,
            nnz: pattern.nnz(),
            options: elasticity_amg_options(D),
            precision: Precision::Single,
            tolerance,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            setups: 0,
            updates: 0,
            last_iterations: 0,
            total_iterations: 0,
        })
    }

    /// Iteration limit of each solve (at least 1).
    pub fn set_max_iterations(&mut self, max_iterations: usize) {
        self.max_iterations = max_iterations.max(1);
    }
    /// Multigrid options (takes effect at the next full setup, i.e. before the first
    /// solve).
    pub fn set_options(&mut self, options: AmgOptions) {
        self.options = options;
    }
    /// Storage precision of the hierarchy's finest matrix (takes effect at the next full
    /// setup). The default, [`Precision::Single`], halves the bytes the V-cycle reads from
    /// the finest matrix and its memory; CG multiplies by the assembled double-precision
    /// values either way, so the solution and the reported residual do not change.
    pub fn set_precision(&mut self, precision: Precision) {
        self.precision = precision;
    }
    /// The relative residual each solve reaches.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }
    /// Full hierarchy setups done (1 after the first solve: never repeated).
    pub fn setups(&self) -> usize {
        self.setups
    }
    /// Numeric rebuilds for new values on the same pattern.
    pub fn updates(&self) -> usize {
        self.updates
    }
    /// CG iterations of the last solve.
    pub fn last_iterations(&self) -> usize {
        self.last_iterations
    }
    /// CG iterations of all solves.
    pub fn total_iterations(&self) -> usize {
        self.total_iterations
    }
    /// The hierarchy (after the first solve).
    pub fn hierarchy(&self) -> Option<&Amg> {
        self.amg.as_ref()
    }

    /// Build the hierarchy for the upper-triangle `values` on `pattern` (first call), or
    /// update it numerically if the values changed since the last call. [`LinearSolve::
    /// solve_system`] calls it; calling it first separates the setup time from the solve.
    pub fn setup(&mut self, pattern: &Pattern, values: &[f64]) -> Result<()> {
        if pattern.nnz() != self.nnz || values.len() != self.nnz {
            return Err(SimError::Input(format!(
                "CG-AMG setup: pattern of {} entries and {} values, solver built for {}",
                pattern.nnz(),
                values.len(),
                self.nnz
            )));
        }
        let amg_err = |e: porofrac_amg::AmgError| SimError::Iterative(format!("AMG setup: {e}"));
        match self.amg.as_mut() {
            Some(amg) => {
                // The hierarchy's finest matrix holds the values it was last built or
                // updated with: compared in place, no copy kept.
                if self.failed_update || !amg.has_values(values) {
                    // The hierarchy refuses to solve after a failed update.
                    self.failed_update = true;
                    amg.update_values(values).map_err(amg_err)?;
                    self.failed_update = false;
                    self.updates += 1;
                }
            }
            None => {
                let sym = SymCsr::from_upper_csc_in(
                    self.precision,
                    self.n,
                    pattern.col_ptr(),
                    pattern.row_idx(),
                    values,
                )
                .map_err(amg_err)?;
                let amg =
                    Amg::elasticity(sym, &self.coords, self.dim, &self.eq_dofs, &self.options)
                        .map_err(amg_err)?;
                self.amg = Some(amg);
                // Only the first setup needs the node coordinates and equation dofs: later
                // setups update the hierarchy numerically.
                self.coords = Vec::new();
                self.eq_dofs = Vec::new();
                self.setups += 1;
            }
        }
        Ok(())
    }
}

impl LinearSolve for AmgSolver {
    fn solve_system(
        &mut self,
        pattern: &Pattern,
        values: &[f64],
        b: &[f64],
        x: &mut [f64],
    ) -> Result<LinearStats> {
        if pattern.num_equations() != self.n
            || pattern.nnz() != self.nnz
            || values.len() != self.nnz
            || b.len() != self.n
            || x.len() != self.n
        {
            return Err(SimError::Input(format!(
                "CG-AMG: pattern of {} equations / {} entries, {} values, vectors of {} and {}; solver built for {} / {}",
                pattern.num_equations(),
                pattern.nnz(),
                values.len(),
                b.len(),
                x.len(),
                self.n,
                self.nnz
            )));
        }
        if self.n == 0 {
            return Ok(LinearStats::default());
        }
        self.setup(pattern, values)?;
        let amg = self
            .amg
            .as_mut()
            .ok_or_else(|| SimError::Iterative("AMG hierarchy missing".into()))?;
        x.fill(0.0);
        let stats = amg
            .solve_upper(values, x, b, self.tolerance, self.max_iterations)
            .map_err(|e| SimError::Iterative(format!("CG-AMG: {e}")))?;
        self.last_iterations = stats.iterations;
        self.total_iterations += stats.iterations;
        Ok(LinearStats {
            iterations: stats.iterations,
            relative_residual: Some(stats.relative_residual),
        })
    }

    fn residual_limit(&self) -> f64 {
        // CG stops on its true residual and reports it (`LinearStats::relative_residual`).
        self.tolerance * (1.0 + 1e-6) + 1e-14
    }
}

/// The static mechanics solver chosen by a [`LinearSolver`].
// One per run: the size of the variants does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub enum StaticSolver {
    /// Sparse Cholesky.
    Direct(DirectSolver),
    /// CG-AMG.
    CgAmg(AmgSolver),
}

impl StaticSolver {
    /// The solver `choice` (with `Auto` resolved by [`LinearSolver::resolve`]) for the
    /// equations of `dofs` on `pattern`: Cholesky with nested dissection in 3D and AMD in
    /// 2D, or CG-AMG.
    pub fn new<const D: usize>(
        grid: &Grid<D>,
        dofs: &DofMap<D>,
        pattern: &Pattern,
        choice: LinearSolver,
    ) -> Result<Self> {
        match choice.resolve(D, dofs.num_equations()) {
            LinearSolver::CgAmg { tolerance } => {
                Ok(Self::CgAmg(AmgSolver::new(grid, dofs, pattern, tolerance)?))
            }
            _ => Ok(Self::Direct(if D == 3 {
                DirectSolver::with_ordering(pattern, &nested_dissection(grid, dofs))?
            } else {
                DirectSolver::new(pattern)?
            })),
        }
    }

    /// `"cholesky"` or `"cg-amg"`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Direct(_) => "cholesky",
            Self::CgAmg(_) => "cg-amg",
        }
    }
    /// Symbolic factorizations (Cholesky) or full hierarchy setups (CG-AMG).
    pub fn symbolic_factorizations(&self) -> usize {
        match self {
            Self::Direct(d) => d.symbolic_factorizations(),
            Self::CgAmg(a) => a.setups(),
        }
    }
    /// Numeric factorizations (Cholesky) or setups plus numeric rebuilds (CG-AMG).
    pub fn numeric_factorizations(&self) -> usize {
        match self {
            Self::Direct(d) => d.numeric_factorizations(),
            Self::CgAmg(a) => a.setups() + a.updates(),
        }
    }
    /// Entries of the Cholesky factor (for CG-AMG: of the coarsest level's factor).
    pub fn factor_nnz(&self) -> usize {
        match self {
            Self::Direct(d) => d.factor_nnz(),
            Self::CgAmg(a) => a.hierarchy().map_or(0, |h| h.coarse_factor_nnz()),
        }
    }
    /// CG iterations of all solves (0 for Cholesky).
    pub fn total_iterations(&self) -> usize {
        match self {
            Self::Direct(_) => 0,
            Self::CgAmg(a) => a.total_iterations(),
        }
    }
}

impl LinearSolve for StaticSolver {
    fn solve_system(
        &mut self,
        pattern: &Pattern,
        values: &[f64],
        b: &[f64],
        x: &mut [f64],
    ) -> Result<LinearStats> {
        match self {
            Self::Direct(d) => d.solve_system(pattern, values, b, x),
            Self::CgAmg(a) => a.solve_system(pattern, values, b, x),
        }
    }
    fn residual_limit(&self) -> f64 {
        match self {
            Self::Direct(d) => d.residual_limit(),
            Self::CgAmg(a) => a.residual_limit(),
        }
    }
}
