//! The linear solvers of the Cosserat systems: the sparse LU of [`crate::pattern`], or
//! restarted GMRES ([`crate::krylov`]) preconditioned by one smoothed-aggregation V-cycle
//! ([`porofrac_amg`]).
//!
//! **Preconditioner.** The system is `K = S + N` with `S` the symmetric elastic + penalty
//! part (13), (17) and `N` the skew-symmetric penalty-free Nitsche part (18)–(20), so
//! `xᵀ K x = xᵀ S x`. `S` alone is singular (its kernel holds the rigid motions
//! `u = a + θ × x`, `φ = θ`, which the Nitsche terms control without a penalty); the
//! multigrid is built on the symmetric positive definite
//! `P = S + Σ_F (|F|/h_K) Q_kk(n) λ_F λ_Fᵀ` (a boundary penalty on every fixed component
//! `k` of a boundary facet, [`crate::Cosserat::preconditioner_values`]), plus the mass
//! term for the Newmark matrix. Aggregates hold the components of one cell; the near-null
//! space is the rigid motions of the Cosserat medium at the cell barycentres (translations
//! and `(θ × x, θ)`).
//!
//! **Choice.** [`LinearSolver::Auto`] takes the LU below [`AUTO_GMRES_EQUATIONS`]
//! equations and GMRES above (the Newmark matrix, solved at every step: below
//! [`AUTO_GMRES_EQUATIONS_NEWMARK`]) (measured in docs/BENCHMARKS.md: the LU's fill grows as
//! cells^1.4 on the plate meshes, GMRES with the V-cycle stays linear in memory).

use porofrac_amg::{Amg, AmgOptions, NearNullSpace, Precision, SymCsr};
use rayon::prelude::*;

use crate::error::{CosseratError, Result};
use crate::krylov::{GmresOptions, GmresStats, gmres};
use crate::pattern::{BlockPattern, SparseLu};

/// Equations from which [`LinearSolver::Auto`] takes GMRES with the V-cycle for a static
/// solve: `porofrac run scenes/cosserat_plate_hole.toml` (15,360 unknowns) took 4.6 s with
/// the LU and 2.8 s with GMRES, the shear layer (6,000) 1.0 s and 2.5 s.
pub const AUTO_GMRES_EQUATIONS: usize = 12_000;

/// Equations from which [`LinearSolver::Auto`] takes GMRES for the Newmark matrix, solved
/// at every step: the LU's one factorisation is then amortised over the steps (each a
/// pair of triangular solves against tens of V-cycles for GMRES), so it is kept up to the
/// size where its memory grows past a few GB (2.5 GB at 61,440 unknowns on the plate).
pub const AUTO_GMRES_EQUATIONS_NEWMARK: usize = 100_000;

/// Which linear solver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinearSolver {
    /// [`Self::Lu`] below [`AUTO_GMRES_EQUATIONS`] equations, [`Self::GmresAmg`] from there.
    #[default]
    Auto,
    /// Sparse LU with partial pivoting (faer).
    Lu,
    /// Restarted GMRES preconditioned by a smoothed-aggregation V-cycle.
    GmresAmg,
}

impl LinearSolver {
    /// The solver used for a static solve of `equations` unknowns (never [`Self::Auto`]).
    pub fn resolve(self, equations: usize) -> Self {
        self.resolve_from(equations, AUTO_GMRES_EQUATIONS)
    }

    /// The solver used for the Newmark matrix of `equations` unknowns.
    pub fn resolve_newmark(self, equations: usize) -> Self {
        self.resolve_from(equations, AUTO_GMRES_EQUATIONS_NEWMARK)
    }

    fn resolve_from(self, equations: usize, threshold: usize) -> Self {
        match self {
            Self::Auto if equations >= threshold => Self::GmresAmg,
            Self::Auto => Self::Lu,
            s => s,
        }
    }

    /// Short name: `"auto"`, `"lu"` or `"gmres-amg"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Lu => "lu",
            Self::GmresAmg => "gmres-amg",
        }
    }
}

/// Options of [`Linear`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinearOptions {
    /// The solver.
    pub solver: LinearSolver,
    /// GMRES parameters (used by [`LinearSolver::GmresAmg`]).
    pub gmres: GmresOptions,
}

/// The matrix of one system as the solvers need it: the values on the block pattern,
/// those of the preconditioning matrix, and the cell barycentres (`dim` per cell).
#[derive(Clone, Copy, Debug)]
pub struct SystemRef<'a> {
    /// The pattern.
    pub pattern: &'a BlockPattern,
    /// System values on the pattern.
    pub values: &'a [f64],
    /// Values of the symmetric positive definite preconditioning matrix on the pattern.
    pub preconditioner: &'a [f64],
    /// Cell barycentres, `dim` per cell.
    pub centres: &'a [f64],
    /// Space dimension (2 or 3).
    pub dim: usize,
}

/// Statistics of the solves done by a [`Linear`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinearStats {
    /// Solves done.
    pub solves: usize,
    /// GMRES iterations summed over the solves (0 for the LU).
    pub iterations: usize,
    /// Largest GMRES iteration count of one solve.
    pub max_iterations: usize,
    /// Largest true relative residual of a GMRES solve.
    pub max_residual: f64,
}

/// GMRES with the V-cycle: the system in row form (parallel products) and the hierarchy.
struct GmresAmg {
    row_ptr: Vec<usize>,
    col_idx: Vec<u32>,
    row_values: Vec<f64>,
    amg: Amg,
    options: GmresOptions,
}

enum Kind {
    Lu(Box<SparseLu>),
    Gmres(Box<GmresAmg>),
}

/// A factorised (LU) or preconditioned (GMRES) system, solved for any number of
/// right-hand sides.
pub struct Linear {
    kind: Kind,
    n: usize,
    stats: LinearStats,
}

impl std::fmt::Debug for Linear {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Linear")
            .field("solver", &self.solver().name())
            .field("n", &self.n)
            .field("stats", &self.stats)
            .finish()
    }
}

impl Linear {
    /// Factorise or set up the preconditioner for `sys` with the solver `options.solver`
    /// (resolved by size when [`LinearSolver::Auto`]).
    ///
    /// Errors: lengths, a structurally or numerically singular matrix (LU), a
    /// preconditioning matrix that is not positive definite (multigrid setup).
    pub fn new(sys: SystemRef<'_>, options: &LinearOptions) -> Result<Self> {
        let n = sys.pattern.equations();
        for (what, len) in [
            ("system values", sys.values.len()),
            ("preconditioner values", sys.preconditioner.len()),
        ] {
            if len != sys.pattern.nnz() {
                return Err(CosseratError::Input {
                    what: format!("{what}: {len} for a pattern of {}", sys.pattern.nnz()),
                });
            }
        }
        let kind = match options.solver.resolve(n) {
            LinearSolver::Lu | LinearSolver::Auto => {
                let mut lu = SparseLu::new(sys.pattern)?;
                lu.factorize(sys.pattern, sys.values)?;
                Kind::Lu(Box::new(lu))
            }
            LinearSolver::GmresAmg => Kind::Gmres(Box::new(GmresAmg::new(sys, options.gmres)?)),
        };
        Ok(Self {
            kind,
            n,
            stats: LinearStats::default(),
        })
    }

    /// The solver in use.
    pub fn solver(&self) -> LinearSolver {
        match self.kind {
            Kind::Lu(_) => LinearSolver::Lu,
            Kind::Gmres(_) => LinearSolver::GmresAmg,
        }
    }

    /// Statistics so far.
    pub fn stats(&self) -> LinearStats {
        self.stats
    }

    /// Solve with `rhs` replaced by the solution. GMRES starts from `guess` when given
    /// (the previous step's solution in dynamics), else from zero.
    ///
    /// Errors: lengths; a non-finite LU solution; GMRES that does not reach its tolerance
    /// (the message gives the residual and the iterations).
    pub fn solve(&mut self, rhs: &mut [f64], guess: Option<&[f64]>) -> Result<()> {
        if rhs.len() != self.n || guess.is_some_and(|g| g.len() != self.n) {
            return Err(CosseratError::Input {
                what: format!(
                    "right-hand side of length {} (guess {:?}), want {}",
                    rhs.len(),
                    guess.map(<[f64]>::len),
                    self.n
                ),
            });
        }
        match &mut self.kind {
            Kind::Lu(lu) => lu.solve_in_place(rhs)?,
            Kind::Gmres(g) => {
                let st = g.solve(rhs, guess)?;
                self.stats.iterations += st.iterations;
                self.stats.max_iterations = self.stats.max_iterations.max(st.iterations);
                self.stats.max_residual = self.stats.max_residual.max(st.residual);
            }
        }
        self.stats.solves += 1;
        Ok(())
    }
}

/// The rigid motions of a Cosserat medium at the cell barycentres: `dim` translations and
/// `(θ × x, θ)` for each rotation axis (one in 2D, three in 3D), coordinates centred and
/// scaled to unit size.
fn rigid_motions(centres: &[f64], dim: usize) -> Result<NearNullSpace> {
    let nc = centres.len() / dim;
    let ncomp = crate::material::components(dim);
    let n = nc * ncomp;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for c in centres.chunks(dim) {
        for j in 0..dim {
            lo[j] = lo[j].min(c[j]);
            hi[j] = hi[j].max(c[j]);
        }
    }
    let size = (0..dim)
        .map(|j| hi[j] - lo[j])
        .fold(0.0, f64::max)
        .max(1e-300);
    let rot = crate::material::rotations(dim);
    let mut data = vec![0.0; n * (dim + rot)];
    for (c, x) in centres.chunks(dim).enumerate() {
        let y = |j: usize| (x[j] - 0.5 * (lo[j] + hi[j])) / size;
        for a in 0..dim {
            data[a * n + c * ncomp + a] = 1.0;
        }
        for k in 0..rot {
            let v = &mut data[(dim + k) * n..(dim + k + 1) * n];
            // Axis e_z (2D) or e_k (3D): u = e × x, φ_k = 1.
            let axis = if dim == 2 { 2 } else { k };
            for i in 0..dim {
                let mut u = 0.0;
                for j in 0..dim {
                    u += crate::material::levi_civita(3, i, axis, j) * y(j);
                }
                v[c * ncomp + i] = u;
            }
            v[c * ncomp + dim + k] = 1.0;
        }
    }
    NearNullSpace::from_vectors(n, data).map_err(|e| CosseratError::Solve(format!("AMG: {e}")))
}

impl GmresAmg {
    fn new(sys: SystemRef<'_>, options: GmresOptions) -> Result<Self> {
        let p = sys.pattern;
        let n = p.equations();
        if p.nnz() > u32::MAX as usize || n > u32::MAX as usize {
            return Err(CosseratError::Input {
                what: format!("{} entries: too many for GMRES's 32-bit indices", p.nnz()),
            });
        }
        if sys.centres.len() * p.block != n * sys.dim {
            return Err(CosseratError::Input {
                what: format!(
                    "{} barycentre coordinates for {} cells in {}D",
                    sys.centres.len(),
                    n / p.block,
                    sys.dim
                ),
            });
        }
        // The pattern is structurally symmetric: row i of K has the indices of column i,
        // and walking the columns in order fills each row in increasing column order.
        let row_ptr = p.col_ptr.clone();
        let col_idx: Vec<u32> = p.row_idx.iter().map(|&r| r as u32).collect();
        let mut next = row_ptr[..n].to_vec();
        let mut row_values = vec![0.0; p.nnz()];
        for j in 0..n {
            for q in p.col_ptr[j]..p.col_ptr[j + 1] {
                let i = p.row_idx[q];
                row_values[next[i]] = sys.values[q];
                next[i] += 1;
            }
        }
        drop(next);
        // Upper triangle of the preconditioning matrix, by columns.
        let mut ucol = Vec::with_capacity(n + 1);
        let mut urow = Vec::with_capacity(p.nnz() / 2 + n);
        let mut uval = Vec::with_capacity(p.nnz() / 2 + n);
        ucol.push(0);
        for j in 0..n {
            for q in p.col_ptr[j]..p.col_ptr[j + 1] {
                let i = p.row_idx[q];
                if i > j {
                    break;
                }
                urow.push(i);
                uval.push(sys.preconditioner[q]);
            }
            ucol.push(urow.len());
        }
        let amg_err = |e: porofrac_amg::AmgError| {
            CosseratError::Solve(format!("multigrid preconditioner setup: {e}"))
        };
        // The hierarchy only preconditions: its finest matrix in single precision halves
        // the memory traffic of the smoother (same iteration counts measured).
        let sym = SymCsr::from_upper_csc_in(Precision::Single, n, &ucol, &urow, &uval)
            .map_err(amg_err)?;
        drop((ucol, urow, uval));
        let null = rigid_motions(sys.centres, sys.dim)?;
        let nodes: Vec<usize> = (0..n).map(|e| e / p.block).collect();
        let amg = Amg::new(sym, &nodes, &null, &amg_options()).map_err(amg_err)?;
        Ok(Self {
            row_ptr,
            col_idx,
            row_values,
            amg,
            options,
        })
    }

    fn solve(&mut self, rhs: &mut [f64], guess: Option<&[f64]>) -> Result<GmresStats> {
        let b = rhs.to_vec();
        match guess {
            Some(g) => rhs.copy_from_slice(g),
            None => rhs.fill(0.0),
        }
        let Self {
            row_ptr,
            col_idx,
            row_values,
            amg,
            options,
        } = self;
        let me = RowMatrix {
            row_ptr,
            col_idx,
            row_values,
        };
        gmres(
            |x, y| me.apply(x, y),
            |r, z| {
                amg.apply(r, z)
                    .map_err(|e| CosseratError::Solve(format!("multigrid V-cycle: {e}")))
            },
            &b,
            rhs,
            options,
        )
    }
}

/// Borrowed row form of the system.
struct RowMatrix<'a> {
    row_ptr: &'a [usize],
    col_idx: &'a [u32],
    row_values: &'a [f64],
}

impl RowMatrix<'_> {
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        let (rp, ci, v) = (self.row_ptr, self.col_idx, self.row_values);
        y.par_iter_mut()
            .enumerate()
            .with_min_len(256)
            .for_each(|(i, yi)| {
                let mut s = 0.0;
                for q in rp[i]..rp[i + 1] {
                    s += v[q] * x[ci[q] as usize];
                }
                *yi = s;
            });
    }
}

/// The multigrid options: the [`AmgOptions`] defaults with a strength threshold of 0.02
/// (fewer GMRES iterations than 0 on the plate meshes; larger thresholds coarsen too
/// slowly and make the setup dominate).
fn amg_options() -> AmgOptions {
    AmgOptions {
        strength_threshold: 0.02,
        ..AmgOptions::default()
    }
}
