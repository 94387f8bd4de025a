//! The direct solver and the static solve.
//!
//! [`DirectSolver`] factorises the reduced stiffness `A = Tᵀ K_ff T` (symmetric positive
//! definite once the rigid modes are removed) by a sparse Cholesky factorization
//! `P A Pᵀ = L Lᵀ` ([`porofrac_sparse::Cholesky`], AMD ordering `P`). The symbolic part
//! (ordering, elimination tree, the pattern of `L`) depends only on the [`Pattern`] and
//! is computed once in [`DirectSolver::new`]; [`DirectSolver::factorize`] recomputes only
//! the numbers, so time steps and law switches reuse it.
//!
//! [`solve_static`] solves `Σ_K F_K(u) + f_ext = 0` for the free dofs with prescribed
//! values `u_p(t)`: Newton's method `A(u) Δx = f_ext + Tᵀ F(u)`, `u_f ← u_f + T Δx`, which
//! for linear laws is one step from `u = (0, u_p)`: `A x = Tᵀ (f_f − K_fp u_p) + F_platen`.
//! Before factorising it checks the rigid-body modes ([`DofMap::check_rigid_modes`]); after
//! solving it checks that the solution is finite and that the relative residual
//! `‖A Δx − r‖ / ‖r‖` is below `1e-8` (for CG-AMG: its tolerance), which catches
//! numerically singular systems (an unconstrained piece) that a Cholesky factorization
//! with tiny pivots may let through. The linear solver is any [`LinearSolve`]:
//! [`DirectSolver`], [`crate::linear::AmgSolver`] or the [`crate::linear::StaticSolver`]
//! chosen by a [`crate::linear::LinearSolver`].

use faer::Side;
use faer::sparse::SparseColMatRef;
use porofrac_grid::{Grid, Point};
use porofrac_law::Tensor;
use porofrac_sparse::{Cholesky, CholeskyError, PermutationError};
use rayon::prelude::*;

pub use faer::Par;

use crate::assembly::{Work, assemble, nodal_loads};
use crate::bc::Loads;
use crate::dofs::DofMap;
use crate::error::{Result, SimError};
use crate::laws::LawMap;
use crate::linear::LinearSolve;
use crate::pattern::Pattern;

/// Factors with at least this many entries are factorized on all threads by default.
pub const PARALLEL_MIN_FACTOR_NNZ: usize = 100_000_000;

/// The factorization's default parallelism for a factor of `factor_nnz` entries:
/// `Par::rayon(n)` with the `n` threads of the current rayon pool (the `[solver] threads`
/// of a scene) from [`PARALLEL_MIN_FACTOR_NNZ`] entries, sequential below or for one
/// thread.
///
/// Measured on the 2-core machine (`scripts/solver_benchmarks.sh`, docs/BENCHMARKS.md):
/// two threads factorize E3 n = 40 (nested dissection, 2.8e8 entries) in 17.6 s against
/// 30.6 s sequentially and E2 n = 1000 (AMD, 3.1e8) in 12.3 s against 17.0 s, but E2
/// n = 500 (5.3e7) in 2.03 s against 1.66 s; at E2 n = 300 (1.8e7) the criterion bench
/// found two threads slower too (850 against 511 ms).
pub fn default_parallelism(factor_nnz: usize) -> Par {
    match rayon::current_num_threads() {
        n if n > 1 && factor_nnz >= PARALLEL_MIN_FACTOR_NNZ => Par::rayon(n),
        _ => Par::Seq,
    }
}

/// Sparse Cholesky solver for the reduced stiffness, with the symbolic factorization
/// computed once per pattern and reused for every numeric factorization
/// ([`porofrac_sparse::Cholesky`] on the upper triangle of the [`Pattern`]).
#[derive(Debug)]
pub struct DirectSolver {
    cholesky: Cholesky,
    par: Par,
    symbolic_count: usize,
}

impl DirectSolver {
    /// Symbolic analysis (AMD ordering and the pattern of the factor) of `pattern`.
    ///
    /// The default parallelism is [`default_parallelism`] of the factor's size; change it
    /// with [`Self::set_parallelism`].
    pub fn new(pattern: &Pattern) -> Result<Self> {
        Self::analyse(pattern, None)
    }

    /// Symbolic analysis with a given fill-reducing ordering: `perm[k]` is the equation
    /// eliminated `k`-th (e.g. [`crate::ordering::nested_dissection`]).
    pub fn with_ordering(pattern: &Pattern, perm: &[usize]) -> Result<Self> {
        Self::analyse(pattern, Some(perm))
    }

    fn analyse(pattern: &Pattern, perm: Option<&[usize]>) -> Result<Self> {
        let n = pattern.num_equations();
        let cholesky =
            Cholesky::analyse(pattern.upper().symbolic(), Side::Upper, perm).map_err(|e| {
                match e {
                    CholeskyError::Ordering(PermutationError::Length { len, .. }) => {
                        SimError::Input(format!("ordering has {len} entries for {n} equations"))
                    }
                    CholeskyError::Ordering(PermutationError::Entry { index, value }) => {
                        SimError::Input(format!(
                            "ordering is not a permutation of the {n} equations (entry {index} = {value})"
                        ))
                    }
                    CholeskyError::Symbolic(e) => {
                        SimError::LinearAlgebra(format!("symbolic Cholesky: {e:?}"))
                    }
                    e => SimError::LinearAlgebra(format!("symbolic Cholesky: {e}")),
                }
            })?;
        Ok(Self {
            par: default_parallelism(cholesky.factor_nnz()),
            cholesky,
            symbolic_count: 1,
        })
    }

    /// Use `par` (e.g. `Par::Seq` or `Par::rayon(2)`) for factorizing and solving.
    pub fn set_parallelism(&mut self, par: Par) {
        self.par = par;
    }

    /// Number of symbolic factorizations done (1: it is never repeated).
    pub fn symbolic_factorizations(&self) -> usize {
        self.symbolic_count
    }
    /// Number of numeric factorizations done.
    pub fn numeric_factorizations(&self) -> usize {
        self.cholesky.numeric_factorizations()
    }
    /// Number of stored entries of the factor `L`.
    pub fn factor_nnz(&self) -> usize {
        self.cholesky.factor_nnz()
    }

    /// Numeric factorization of the matrix with the given upper-triangle `values` of the
    /// pattern this solver was built for.
    ///
    /// Error [`SimError::NotPositiveDefinite`] names the failing equation in the original
    /// numbering (its `location` says `equation e`; [`solve_static`] maps it to the node).
    pub fn factorize(&mut self, pattern: &Pattern, values: &[f64]) -> Result<()> {
        let (n, nnz) = (self.cholesky.dim(), self.cholesky.pattern_nnz());
        if pattern.num_equations() != n || pattern.nnz() != nnz || values.len() != nnz {
            return Err(SimError::Input(format!(
                "factorize: pattern of {} equations / {} entries and {} values, solver built for {} / {}",
                pattern.num_equations(),
                pattern.nnz(),
                values.len(),
                n,
                nnz
            )));
        }
        let mat = SparseColMatRef::new(pattern.upper().symbolic(), values);
        self.cholesky.factorize(mat, self.par).map_err(|e| match e {
            CholeskyError::NonPositivePivot { index, .. } => SimError::NotPositiveDefinite {
                equation: index,
                location: format!("equation {index}"),
            },
            _ => SimError::LinearAlgebra("out of memory".into()),
        })
    }

    /// Solve `A x = b` in place (`rhs` holds `b` on entry and `x` on return).
    pub fn solve_in_place(&self, rhs: &mut [f64]) -> Result<()> {
        self.cholesky
            .solve_in_place(rhs, self.par)
            .map_err(|e| match e {
                CholeskyError::NotFactored => {
                    SimError::Input("solve before a successful factorization".into())
                }
                CholeskyError::Dimension { got, want, .. } => {
                    SimError::Input(format!("right-hand side of length {got}, want {want}"))
                }
                _ => SimError::LinearAlgebra("out of memory".into()),
            })
    }
}

/// The immutable description of a static mechanics problem (all borrowed).
#[derive(Clone, Copy)]
pub struct StaticProblem<'a, const D: usize> {
    /// The grid.
    pub grid: &'a porofrac_grid::Grid<D>,
    /// The law of each cell.
    pub laws: &'a LawMap<'a, D>,
    /// Dofs and equations from the displacement and platen conditions.
    pub dofs: &'a DofMap<D>,
    /// The sparsity pattern built from `grid` and `dofs`.
    pub pattern: &'a Pattern,
    /// External loads.
    pub loads: &'a Loads<D>,
}

/// Options of [`solve_static`].
#[derive(Clone, Copy, Debug)]
pub struct StaticOptions {
    /// Newton iterations allowed for nonlinear laws (linear problems take one step).
    pub max_iterations: usize,
    /// Relative residual at which a nonlinear solve stops.
    pub tolerance: f64,
}

impl Default for StaticOptions {
    fn default() -> Self {
        Self {
            max_iterations: 30,
            tolerance: 1e-10,
        }
    }
}

/// The result of a static solve.
#[derive(Clone, Debug)]
pub struct StaticSolution<const D: usize> {
    /// Nodal displacements, node-major (`D` per node), prescribed values filled in.
    pub displacement: Vec<f64>,
    /// Linear solves done.
    pub iterations: usize,
    /// Relative residual of the last linear solve, `‖A Δx − r‖ / ‖r‖`.
    pub residual: f64,
    /// Iterations of an iterative linear solver, summed over the linear solves (0 for
    /// Cholesky).
    pub linear_iterations: usize,
}

impl<const D: usize> StaticSolution<D> {
    /// Displacement of node `n`.
    pub fn node(&self, n: usize) -> Point<D> {
        Point::<D>::from_column_slice(&self.displacement[D * n..D * n + D])
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Solve the static problem at time `t` with `solver` (built for `problem.pattern`).
///
/// Errors: [`SimError::Singular`] if rigid-body modes are free (checked first),
/// [`SimError::NotPositiveDefinite`] naming the node and component of a failing pivot,
/// [`SimError::NotFinite`] or an ill-conditioned residual, [`SimError::Iterative`] for an
/// iterative linear solve that does not converge, [`SimError::NoConvergence`] for a
/// nonlinear solve, and the assembly and load errors.
pub fn solve_static<const D: usize, S: LinearSolve + ?Sized>(
    problem: &StaticProblem<'_, D>,
    solver: &mut S,
    t: f64,
    options: &StaticOptions,
) -> Result<StaticSolution<D>> {
    let StaticProblem {
        grid,
        laws,
        dofs,
        pattern,
        loads,
    } = *problem;
    dofs.check_rigid_modes(grid)?;
    let neq = dofs.num_equations();
    let mut u = vec![0.0; dofs.num_dofs()];
    dofs.set_prescribed(grid, t, &mut u);
    let mut full = vec![0.0; dofs.num_dofs()];
    nodal_loads(grid, loads, t, &mut full)?;
    let mut fext = vec![0.0; neq];
    dofs.reduce_add(&full, &mut fext);
    dofs.add_platen_forces(grid, t, &mut fext);
    let mut values = vec![0.0; pattern.nnz()];
    let mut forces = vec![0.0; neq];
    let mut r = vec![0.0; neq];
    let mut ar = vec![0.0; neq];
    let linear = laws.all_linear();
    let mut reference = 0.0f64;
    let mut residual = 0.0;
    let mut linear_iterations = 0;
    for it in 1..=options.max_iterations.max(1) {
        assemble(grid, laws, dofs, pattern, &u, &mut values, &mut forces)?;
        r.iter_mut()
            .zip(fext.iter().zip(&forces))
            .for_each(|(ri, (a, b))| *ri = a + b);
        let rn = norm(&r);
        if it == 1 {
            reference = rn.max(f64::MIN_POSITIVE);
        } else if rn <= options.tolerance * reference {
            return Ok(StaticSolution {
                displacement: u,
                iterations: it - 1,
                residual,
                linear_iterations,
            });
        }
        let mut dx = vec![0.0; neq];
        let stats = solver
            .solve_system(pattern, &values, &r, &mut dx)
            .map_err(|e| match e {
                SimError::NotPositiveDefinite { equation, .. } => SimError::NotPositiveDefinite {
                    equation,
                    location: dofs.describe_equation(grid, equation),
                },
                e => e,
            })?;
        linear_iterations += stats.iterations;
        if let Some(e) = dx.iter().position(|v| !v.is_finite()) {
            return Err(SimError::NotFinite {
                location: dofs.describe_equation(grid, e),
            });
        }
        // The iterative solvers compute the true residual to stop (in parallel); the
        // direct ones leave it to this check.
        residual = match stats.relative_residual {
            Some(rel) => rel,
            None => {
                ar.fill(0.0);
                pattern.mul_add(&values, &dx, &mut ar);
                let err = ar
                    .iter()
                    .zip(&r)
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum::<f64>()
                    .sqrt();
                if rn > 0.0 { err / rn } else { err }
            }
        };
        if residual > solver.residual_limit() {
            let (e, _) = dx.iter().enumerate().fold((0, 0.0f64), |acc, (i, v)| {
                if v.abs() > acc.1 { (i, v.abs()) } else { acc }
            });
            return Err(SimError::NotPositiveDefinite {
                equation: e,
                location: format!(
                    "{}; numerically singular: relative residual {residual:.2e}, largest displacement there",
                    dofs.describe_equation(grid, e)
                ),
            });
        }
        dofs.scatter_add(&dx, &mut u);
        if linear {
            return Ok(StaticSolution {
                displacement: u,
                iterations: 1,
                residual,
                linear_iterations,
            });
        }
    }
    Err(SimError::NoConvergence {
        iterations: options.max_iterations,
        residual: {
            assemble(grid, laws, dofs, pattern, &u, &mut values, &mut forces)?;
            let rn: f64 = fext
                .iter()
                .zip(&forces)
                .map(|(a, b)| (a + b) * (a + b))
                .sum::<f64>()
                .sqrt();
            rn / reference
        },
    })
}

/// Stress of every cell for the nodal displacement `u` (via [`porofrac_law::CellLaw::stress`],
/// in parallel).
pub fn cell_stresses<const D: usize>(
    grid: &Grid<D>,
    laws: &LawMap<'_, D>,
    u: &[f64],
) -> Result<Vec<Tensor<D>>> {
    if u.len() != D * grid.num_nodes() {
        return Err(SimError::Input(format!(
            "displacement of length {}, want {}",
            u.len(),
            D * grid.num_nodes()
        )));
    }
    let mut out = vec![Tensor::<D>::zeros(); grid.num_cells()];
    out.par_iter_mut()
        .enumerate()
        .for_each_init(Work::<D>::default, |w, (c, s)| {
            w.gather(grid, c, u);
            let geo = w.geo.load(grid, c);
            *s = laws.law(c).stress(&geo, &w.u, &mut w.scratch);
        });
    Ok(out)
}

/// The force that holds the nodes of `faces` in place: `R = −Σ_{n ∈ nodes(faces)} F_n(u)`,
/// with `F` the restoring forces of the cells. At equilibrium it equals the support
/// reaction (or the applied load) on those nodes.
pub fn reaction<const D: usize>(
    grid: &Grid<D>,
    laws: &LawMap<'_, D>,
    u: &[f64],
    faces: &[usize],
) -> Result<Point<D>> {
    if u.len() != D * grid.num_nodes() {
        return Err(SimError::Input(format!(
            "displacement of length {}, want {}",
            u.len(),
            D * grid.num_nodes()
        )));
    }
    if let Some(&f) = faces.iter().find(|&&f| f >= grid.num_faces()) {
        return Err(SimError::Input(format!("reaction: face {f} out of range")));
    }
    let mut marked = vec![false; grid.num_nodes()];
    for n in grid.nodes_of_faces(faces) {
        marked[n] = true;
    }
    let sum = (0..grid.num_cells())
        .into_par_iter()
        .filter(|&c| grid.cell_nodes(c).iter().any(|&n| marked[n]))
        .try_fold(
            || (Work::<D>::default(), Point::<D>::zeros()),
            |(mut w, mut acc), c| {
                w.gather(grid, c, u);
                w.forces(grid, laws, c)?;
                for (i, &n) in grid.cell_nodes(c).iter().enumerate() {
                    if marked[n] {
                        for a in 0..D {
                            acc[a] -= w.f[D * i + a];
                        }
                    }
                }
                Ok::<_, SimError>((w, acc))
            },
        )
        .map(|r| r.map(|(_, acc)| acc))
        .try_reduce(Point::<D>::zeros, |a, b| Ok(a + b))?;
    Ok(sum)
}
