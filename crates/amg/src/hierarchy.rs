//! The multigrid hierarchy: setup, numeric rebuild and the V-cycle.
//!
//! # Setup
//!
//! From level `ℓ` (matrix `A_ℓ`, nodes, near-null space `B_ℓ`):
//!
//! 1. strength graph and aggregates of the nodes ([`crate::aggregate`]);
//! 2. tentative prolongator `T_ℓ` and the coarse near-null space by local QR;
//! 3. `ρ̂ ≈ ρ(D⁻¹A_ℓ)` by Lanczos, `ω = (4/3)/ρ̂` and `P_ℓ = (I − ω D⁻¹ A_ℓ) T_ℓ`
//!    ([`crate::product`]). Smoothing damps the energy of the coarse basis functions: on
//!    an eigenvector of `D⁻¹A` with eigenvalue `λ ∈ [0, ρ]` the energy of `(I − ωD⁻¹A) v`
//!    relative to `‖v‖_D²` is `λ (1 − ωλ)²`, and `ω = 4/(3ρ)` minimises its maximum over
//!    `[0, ρ]` (the maxima at `λ = 1/(3ω)` and `λ = ρ` are then both `ρ/9`);
//! 4. `A_{ℓ+1} = P_ℓᵀ A_ℓ P_ℓ`, exactly symmetric.
//!
//! It stops when a level has at most `max_coarse` equations, at `max_levels`, or when an
//! aggregation no longer reduces the size by the factor `min_coarsening`; the last level is
//! factorized by sparse Cholesky ([`crate::coarse`]).
//!
//! # Rebuild
//!
//! For new values on the same pattern (a time step, a fracture changing some cells'
//! stiffness) [`Amg::update_values`] keeps the aggregates, the tentative prolongators,
//! every sparsity pattern and the symbolic coarse factorization, and recomputes `ρ̂`, `P_ℓ`,
//! `A_{ℓ+1}` and the coarse factor numerically.
//!
//! # Precision
//!
//! The finest matrix is stored in the precision of the [`SymCsr`] it is built from
//! ([`crate::Precision`]); the coarse levels, the prolongators and the coarsest factor are
//! always double. In single precision every setup pass over the finest matrix and every
//! smoother product reads 4 instead of 8 bytes per value; the hierarchy is then the exact
//! one of the rounded matrix `Ã` (`|ã_ij − a_ij| ≤ 2⁻²⁴ |a_ij|`), a fixed symmetric
//! preconditioner, and CG multiplies by the caller's double-precision upper triangle
//! ([`Amg::solve_upper`], [`crate::upper`]), so the solution and its residual are those of
//! `A`. The iterations stay within a few of the double-precision hierarchy's (tested on
//! E2, E3 and at ν = 0.499). With long rows ([`UPPER_MIN_ENTRIES_PER_ROW`]) the finest
//! level's smoother and spectral estimate multiply by a single-precision copy of the upper
//! triangle instead of the full rows: the same `f32` values, half the bytes.
//!
//! # V-cycle
//!
//! `z = M r` with, on each level, `ν` Chebyshev steps before and after the coarse
//! correction (the same polynomial, so `M` is symmetric; see [`crate::smoother`]):
//!
//! ```text
//!   x_ℓ = S_ℓ(0; b_ℓ),  b_{ℓ+1} = P_ℓᵀ (b_ℓ − A_ℓ x_ℓ),  x_ℓ ← x_ℓ + P_ℓ x_{ℓ+1},
//!   x_ℓ ← S_ℓ(x_ℓ; b_ℓ),  and  x_L = A_L⁻¹ b_L  on the coarsest level.
//! ```

use faer::dyn_stack::MemBuffer;

use crate::aggregate::{Blocks, Tentative, aggregate, strength, tentative};
use crate::coarse::CoarseSolver;
use crate::csr::{
    CsrMatrix, SymCsr, check_upper_values, dot, equals_upper, fill_from_upper, par_rows, vec_bytes,
    zeros,
};
use crate::error::{AmgError, Result, check_finite};
use crate::nullspace::NearNullSpace;
use crate::product::{
    Blocked, Galerkin, numeric_galerkin, restrict, smooth_prolongator, symbolic_galerkin,
    symbolic_prolongator,
};
use crate::smoother::{Chebyshev, SmoothWork, spectral_radius};
use crate::upper::{UpperProduct, UpperSingle};

/// Parameters of the setup and the cycle. The defaults suit 2D and 3D elasticity with
/// rigid-body modes and scalar diffusion with the constant.
#[derive(Clone, Debug, PartialEq)]
pub struct AmgOptions {
    /// Strength threshold θ ≥ 0 (see [`crate::aggregate`]); 0 keeps every connection.
    pub strength_threshold: f64,
    /// A level with at most this many equations is solved directly.
    pub max_coarse: usize,
    /// Maximum number of levels (at least 1).
    pub max_levels: usize,
    /// Stop coarsening when a coarse level would keep more than this fraction of the
    /// equations (in `(0, 1)`).
    pub min_coarsening: f64,
    /// Chebyshev degree `ν ≥ 1` of the pre- and post-smoother.
    pub smoother_degree: usize,
    /// Upper end of the Chebyshev interval as a multiple of the estimate `ρ̂` (≥ 1).
    pub chebyshev_upper: f64,
    /// Ratio `β/α > 1` of the Chebyshev interval.
    pub chebyshev_ratio: f64,
    /// Lanczos steps of the `ρ(D⁻¹A)` estimate (at least 2).
    pub lanczos_steps: usize,
    /// Prolongator damping `ω ρ̂` (4/3 classically; 0 gives unsmoothed aggregation).
    pub prolongation_damping: f64,
    /// CG stops with [`AmgError::Stagnation`] after this many iterations without a new
    /// smallest residual.
    pub stagnation_window: usize,
    /// The finest `aggressive_levels` levels aggregate on the distance-two strength graph
    /// (see [`crate::aggregate`]); 0 = never.
    pub aggressive_levels: usize,
}

impl Default for AmgOptions {
    fn default() -> Self {
        Self {
            strength_threshold: 0.0,
            max_coarse: 1000,
            max_levels: 12,
            min_coarsening: 0.8,
            smoother_degree: 2,
            chebyshev_upper: 1.1,
            chebyshev_ratio: 30.0,
            lanczos_steps: 10,
            prolongation_damping: 4.0 / 3.0,
            stagnation_window: 50,
            aggressive_levels: 0,
        }
    }
}

impl AmgOptions {
    fn validate(&self) -> Result<()> {
        let bad = |what: &str| Err(AmgError::Input(format!("option {what}")));
        if !(self.strength_threshold >= 0.0 && self.strength_threshold.is_finite()) {
            return bad("strength_threshold must be finite and ≥ 0");
        }
        if self.max_levels == 0 {
            return bad("max_levels must be ≥ 1");
        }
        if !(self.min_coarsening > 0.0 && self.min_coarsening < 1.0) {
            return bad("min_coarsening must be in (0, 1)");
        }
        if self.smoother_degree == 0 {
            return bad("smoother_degree must be ≥ 1");
        }
        if !(self.chebyshev_upper >= 1.0 && self.chebyshev_upper.is_finite()) {
            return bad("chebyshev_upper must be finite and ≥ 1");
        }
        if !(self.chebyshev_ratio > 1.0 && self.chebyshev_ratio.is_finite()) {
            return bad("chebyshev_ratio must be finite and > 1");
        }
        if self.lanczos_steps < 2 {
            return bad("lanczos_steps must be ≥ 2");
        }
        if !(self.prolongation_damping >= 0.0 && self.prolongation_damping < 2.0) {
            return bad("prolongation_damping must be in [0, 2)");
        }
        if self.stagnation_window == 0 {
            return bad("stagnation_window must be ≥ 1");
        }
        Ok(())
    }
}

/// Transfer from a level to the next.
#[derive(Debug)]
struct Transfer {
    /// Tentative prolongator (fixed after the setup).
    t: Blocked,
    /// Smoothed prolongator.
    p: Blocked,
    /// Block pattern of the next level's matrix.
    galerkin: Galerkin,
    /// Coarse equations `off[a]..off[a+1]` of aggregate `a`.
    off: Vec<usize>,
}

/// One level of the hierarchy.
#[derive(Debug)]
struct Level {
    a: CsrMatrix,
    dinv: Vec<f64>,
    rho: f64,
    smoother: Chebyshev,
    transfer: Option<Transfer>,
}

impl Level {
    /// A level; its smoother is set by the numeric setup (none on the coarsest level).
    fn new(a: CsrMatrix, dinv: Vec<f64>, transfer: Option<Transfer>) -> Self {
        Self {
            a,
            dinv,
            rho: 0.0,
            smoother: Chebyshev::default(),
            transfer,
        }
    }
}

/// Work vectors of one level.
#[derive(Debug, Default)]
struct Work {
    b: Vec<f64>,
    x: Vec<f64>,
    r: Vec<f64>,
    d: Vec<f64>,
    dn: Vec<f64>,
}

/// Size and cost figures of one level.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelInfo {
    /// Equations.
    pub rows: usize,
    /// Stored entries of the (full) matrix.
    pub nnz: usize,
    /// Estimated `ρ(D⁻¹A)` (0 on the coarsest level).
    pub rho: f64,
}

/// Heap memory of a hierarchy by part, in bytes (see [`Amg::memory`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AmgMemory {
    /// The matrices of all levels (full CSR with run tables).
    pub matrices: usize,
    /// The column offsets that locate the finest matrix's entries in the caller's
    /// upper-triangle values.
    pub fine_map: usize,
    /// Tentative prolongators.
    pub tentative: usize,
    /// Smoothed prolongators.
    pub prolongators: usize,
    /// The Galerkin patterns, kept for numeric rebuilds.
    pub products: usize,
    /// Inverse diagonals, work vectors and CG vectors.
    pub vectors: usize,
}

impl AmgMemory {
    /// Sum of all parts.
    pub fn total(&self) -> usize {
        self.matrices
            + self.fine_map
            + self.tentative
            + self.prolongators
            + self.products
            + self.vectors
    }
}

/// A smoothed-aggregation multigrid hierarchy for a symmetric positive definite matrix,
/// usable as a preconditioner ([`Self::apply`]) or solver ([`Self::solve`]).
pub struct Amg {
    levels: Vec<Level>,
    coarse: CoarseSolver,
    coarse_mem: MemBuffer,
    work: Vec<Work>,
    /// Column offsets of the caller's upper triangle (see [`SymCsr`]).
    fine_col_ptr: Vec<usize>,
    pub(crate) options: AmgOptions,
    pub(crate) cg: [Vec<f64>; 4],
    /// Partition of the product with the caller's upper triangle (built by the
    /// first [`Amg::solve_upper`]).
    upper: Option<UpperProduct>,
    /// The finest matrix's upper triangle in single precision for its smoother and
    /// spectral estimate (see [`UPPER_MIN_ENTRIES_PER_ROW`]).
    fine_upper: Option<UpperSingle>,
    /// False after a failed [`Amg::update_values`].
    valid: bool,
}

impl std::fmt::Debug for Amg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Amg")
            .field("levels", &self.level_info())
            .field("coarse_factor_nnz", &self.coarse.factor_nnz())
            .field("options", &self.options)
            .finish()
    }
}

/// The finest operator with the caller's double-precision values ([`Amg::operator`]).
pub struct FineOperator<'a> {
    amg: &'a Amg,
    values: &'a [f64],
}

impl FineOperator<'_> {
    /// `y = A x`; returns `xᵀ A x`. Errors: wrong lengths.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) -> Result<f64> {
        let n = self.amg.n();
        if x.len() != n || y.len() != n {
            return Err(AmgError::Input(format!(
                "product with vectors of length {} and {}, want {n}",
                x.len(),
                y.len()
            )));
        }
        Ok(self.amg.fine_product(Some(self.values), x, y))
    }
}

/// A finest matrix stored in single precision with at least this many entries per row on
/// average (3D elasticity: about 43) is smoothed through its upper triangle, kept in
/// single precision next to the full rows ([`crate::upper`]): half the bytes of the full
/// rows per product, for a kernel that gathers along a column and scatters along a row.
/// With shorter rows (2D elasticity: about 14) the kernel's work per byte outweighs the saving: on a grid of
/// 2 M equations with 14 entries per row the double-precision upper product took 29 ms
/// against 16 ms for the full single-precision one, on 0.19 M equations with 43 per row
/// 5.2 ms against 5.0 ms for the same bytes (docs/BENCHMARKS.md).
pub const UPPER_MIN_ENTRIES_PER_ROW: usize = 24;

/// `1/a_ii`, or an error naming a non-positive diagonal.
fn inverse_diagonal(a: &CsrMatrix, level: usize) -> Result<Vec<f64>> {
    let d = a.diagonal();
    if let Some((equation, &value)) = d.iter().enumerate().find(|(_, v)| v.is_nan() || **v <= 0.0) {
        return Err(AmgError::NonPositiveDiagonal {
            level,
            equation,
            value,
        });
    }
    let mut dinv = zeros(d.len());
    par_rows(&mut dinv, |i, v| *v = 1.0 / d[i]);
    Ok(dinv)
}

impl Amg {
    /// Build the hierarchy for `matrix`. `node_of_equation[e]` is the node (any id) whose
    /// component equation `e` is — equations of one node are aggregated together; use
    /// `0..n` for scalar problems — and `near_null` the near-null space (rigid-body modes,
    /// constants).
    ///
    /// Errors: inconsistent lengths or options, a non-positive diagonal, a coarsest
    /// operator that is not positive definite.
    pub fn new(
        matrix: SymCsr,
        node_of_equation: &[usize],
        near_null: &NearNullSpace,
        options: &AmgOptions,
    ) -> Result<Self> {
        if node_of_equation.len() != matrix.n() {
            return Err(AmgError::Input(format!(
                "{} equations and {} node ids",
                matrix.n(),
                node_of_equation.len()
            )));
        }
        let blocks = Blocks::from_ids(node_of_equation)?;
        Self::build(matrix, blocks, near_null.clone(), options)
    }

    /// [`Self::new`] with the nodes and the near-null space owned: each level's are
    /// dropped as soon as the next level's exist.
    fn build(
        matrix: SymCsr,
        mut blocks: Blocks,
        mut null: NearNullSpace,
        options: &AmgOptions,
    ) -> Result<Self> {
        options.validate()?;
        let n = matrix.n();
        if n == 0 {
            return Err(AmgError::Input("empty matrix".into()));
        }
        if null.len() != n {
            return Err(AmgError::Input(format!(
                "{n} equations and near-null vectors of length {}",
                null.len()
            )));
        }
        let (a0, fine_col_ptr) = matrix.into_parts();
        let fine_upper = if a0.nnz() >= UPPER_MIN_ENTRIES_PER_ROW * n {
            UpperSingle::new(&a0, &fine_col_ptr)
        } else {
            None
        };
        let mut levels: Vec<Level> = Vec::new();
        let mut a = a0;
        loop {
            let l = levels.len();
            if l > 0 {
                a.compress_runs();
            }
            let dinv = inverse_diagonal(&a, l)?;
            if a.nrows() <= options.max_coarse || l + 1 >= options.max_levels {
                // The coarsest level is factorized in double precision.
                a.store_double();
                levels.push(Level::new(a, dinv, None));
                break;
            }
            let s = strength(&a, &blocks, options.strength_threshold);
            let (agg, num_agg) = aggregate(&s, l < options.aggressive_levels);
            drop(s);
            let Tentative {
                p: t,
                eq_agg,
                coarse_null,
                coarse_blocks,
            } = tentative(&blocks, &agg, num_agg, &null)?;
            drop(agg);
            // This level's nodes and near-null space are done with.
            null = coarse_null;
            blocks = coarse_blocks;
            let nc = t.ncols();
            if nc == 0 || nc as f64 > options.min_coarsening * a.nrows() as f64 {
                a.store_double();
                levels.push(Level::new(a, dinv, None));
                break;
            }
            let off = blocks.ptr.clone();
            let p = symbolic_prolongator(&a, &eq_agg, &off)?;
            drop(eq_agg);
            let transfer = Transfer {
                t,
                p,
                galerkin: Galerkin::default(),
                off,
            };
            let mut level = Level::new(a, dinv, Some(transfer));
            let op = fine_upper.as_ref().filter(|_| l == 0);
            if !smooth_level(&mut level, op, &fine_col_ptr, options) {
                return Err(internal());
            }
            let tr = level.transfer.as_mut().ok_or_else(internal)?;
            let (galerkin, mut ac) = symbolic_galerkin(&level.a, &tr.p, &tr.off);
            numeric_galerkin(&galerkin, &level.a, &tr.p, &tr.off, &mut ac);
            tr.galerkin = galerkin;
            levels.push(level);
            a = ac;
        }
        let nl = levels.len();
        let last = levels.last().ok_or_else(internal)?;
        let mut coarse = CoarseSolver::new(&last.a, nl - 1)?;
        coarse.factorize(&last.a)?;
        let coarse_mem = coarse.solve_buffer()?;
        let work = levels
            .iter()
            .enumerate()
            .map(|(l, lev)| {
                let n = lev.a.nrows();
                let (nb, ns) = match (l, lev.transfer.is_some()) {
                    (0, true) => (0, n),
                    (0, false) => (0, 0),
                    (_, true) => (n, n),
                    (_, false) => (n, 0),
                };
                Work {
                    b: zeros(nb),
                    x: zeros(nb),
                    r: zeros(ns),
                    d: zeros(ns),
                    dn: zeros(ns),
                }
            })
            .collect();
        Ok(Self {
            levels,
            coarse,
            coarse_mem,
            work,
            fine_col_ptr,
            options: options.clone(),
            cg: Default::default(),
            upper: fine_upper.as_ref().map(UpperSingle::partition),
            fine_upper,
            valid: true,
        })
    }

    /// Build for linear elasticity in `dim` dimensions: the near-null space is the
    /// rigid-body modes at the node coordinates `coords` (`dim` per node) and `dofs[e] =
    /// (node, component)` of every equation (see [`NearNullSpace::rigid_body_modes`]).
    pub fn elasticity(
        matrix: SymCsr,
        coords: &[f64],
        dim: usize,
        dofs: &[(usize, usize)],
        options: &AmgOptions,
    ) -> Result<Self> {
        if dofs.len() != matrix.n() {
            return Err(AmgError::Input(format!(
                "{} equations and {} (node, component) pairs",
                matrix.n(),
                dofs.len()
            )));
        }
        let null = NearNullSpace::rigid_body_modes(coords, dim, dofs)?;
        let nodes: Vec<usize> = dofs.iter().map(|&(node, _)| node).collect();
        let blocks = Blocks::from_ids(&nodes)?;
        drop(nodes);
        Self::build(matrix, blocks, null, options)
    }

    /// Build for a scalar problem: one equation per node, the constant as near-null space.
    pub fn scalar(matrix: SymCsr, options: &AmgOptions) -> Result<Self> {
        let n = matrix.n();
        let null = NearNullSpace::constant(n.max(1))?;
        let nodes: Vec<usize> = (0..n).collect();
        let blocks = Blocks::from_ids(&nodes)?;
        drop(nodes);
        Self::build(matrix, blocks, null, options)
    }

    /// Recompute the hierarchy numerically for new upper-triangle `values` on the pattern
    /// the hierarchy was built with, keeping the aggregates and all patterns.
    ///
    /// Errors: wrong length, non-finite values, a non-positive diagonal, a coarsest
    /// operator that is not positive definite. After an error on the values (not on the
    /// length) the hierarchy refuses to solve until an update succeeds.
    pub fn update_values(&mut self, values: &[f64]) -> Result<()> {
        check_upper_values(values, self.fine_col_ptr[self.n()])?;
        self.valid = false;
        fill_from_upper(&mut self.levels[0].a, &self.fine_col_ptr, values);
        if let Some(u) = self.fine_upper.as_mut() {
            u.refresh(&self.levels[0].a, &self.fine_col_ptr);
        }
        let nl = self.levels.len();
        for l in 0..nl {
            let (lo, hi) = self.levels.split_at_mut(l + 1);
            let level = &mut lo[l];
            level.dinv = inverse_diagonal(&level.a, l)?;
            let op = self.fine_upper.as_ref().filter(|_| l == 0);
            if !smooth_level(level, op, &self.fine_col_ptr, &self.options) {
                break;
            }
            let tr = level.transfer.as_ref().ok_or_else(internal)?;
            numeric_galerkin(&tr.galerkin, &level.a, &tr.p, &tr.off, &mut hi[0].a);
        }
        let last = &self.levels[nl - 1];
        self.coarse.factorize(&last.a)?;
        self.valid = true;
        Ok(())
    }

    /// Whether the finest matrix holds these upper-triangle `values` (those of the build
    /// or of the last [`Self::update_values`]) rounded to its storage precision: exactly
    /// for a double-precision matrix; in single precision, changes below the rounding of
    /// an `f32` leave the preconditioner as it is (a solve with [`Self::solve_upper`] still
    /// multiplies by the given values).
    pub fn has_values(&self, values: &[f64]) -> bool {
        equals_upper(&self.levels[0].a, &self.fine_col_ptr, values)
    }

    /// Number of equations.
    pub fn n(&self) -> usize {
        self.levels[0].a.nrows()
    }

    /// The matrix of the finest level (full CSR).
    pub fn matrix(&self) -> &CsrMatrix {
        &self.levels[0].a
    }

    /// Size and spectral estimate of every level, finest first.
    pub fn level_info(&self) -> Vec<LevelInfo> {
        self.levels
            .iter()
            .map(|l| LevelInfo {
                rows: l.a.nrows(),
                nnz: l.a.nnz(),
                rho: l.rho,
            })
            .collect()
    }

    /// Heap memory held, by part (capacities of the stored arrays; the coarsest level's
    /// Cholesky factor is not counted).
    pub fn memory(&self) -> AmgMemory {
        let mut m = AmgMemory {
            matrices: self.fine_upper.as_ref().map_or(0, UpperSingle::bytes),
            fine_map: vec_bytes(&self.fine_col_ptr),
            vectors: self.cg.iter().map(vec_bytes).sum::<usize>(),
            ..AmgMemory::default()
        };
        for level in &self.levels {
            m.matrices += level.a.bytes();
            m.vectors += vec_bytes(&level.dinv);
            if let Some(tr) = &level.transfer {
                m.tentative += tr.t.bytes();
                m.prolongators += tr.p.bytes() + vec_bytes(&tr.off);
                m.products += tr.galerkin.bytes();
            }
        }
        for w in &self.work {
            m.vectors += [&w.b, &w.x, &w.r, &w.d, &w.dn]
                .into_iter()
                .map(vec_bytes)
                .sum::<usize>();
        }
        m
    }

    /// Operator complexity: stored entries of all levels over those of the finest.
    pub fn operator_complexity(&self) -> f64 {
        let total: usize = self.levels.iter().map(|l| l.a.nnz()).sum();
        total as f64 / self.levels[0].a.nnz().max(1) as f64
    }

    /// Entries of the coarsest level's Cholesky factor.
    pub fn coarse_factor_nnz(&self) -> usize {
        self.coarse.factor_nnz()
    }

    /// The options the hierarchy was built with.
    pub fn options(&self) -> &AmgOptions {
        &self.options
    }

    /// Error if a failed [`Self::update_values`] left the hierarchy unusable.
    pub(crate) fn check_valid(&self) -> Result<()> {
        if self.valid {
            Ok(())
        } else {
            Err(AmgError::Input(
                "the last update_values failed: update the hierarchy again before use".into(),
            ))
        }
    }

    /// Make ready the product with the caller's double-precision upper triangle
    /// ([`Self::fine_product`]): the partition of the upper-triangle kernel.
    pub(crate) fn prepare_operator(&mut self, upper: Option<&[f64]>) {
        if upper.is_some() && self.upper.is_none() {
            self.upper = Some(UpperProduct::new(&self.levels[0].a, &self.fine_col_ptr));
        }
    }

    /// `y = A x` with the finest matrix as stored (`upper = None`) or with the caller's
    /// double-precision upper triangle `upper` on the finest pattern, as made ready by
    /// [`Self::prepare_operator`]; returns `xᵀ y` (summed in the same pass).
    pub(crate) fn fine_product(&self, upper: Option<&[f64]>, x: &[f64], y: &mut [f64]) -> f64 {
        let a = &self.levels[0].a;
        let times = |i: usize, ax: f64, yi: &mut f64| {
            *yi = ax;
            ax * x[i]
        };
        match upper {
            None => a.par_products_sum(x, y, times),
            Some(values) => {
                let part = self
                    .upper
                    .unwrap_or_else(|| UpperProduct::new(a, &self.fine_col_ptr));
                part.apply(a, &self.fine_col_ptr, values, x, y)
            }
        }
    }

    /// The operator [`Self::solve_upper`] multiplies by for the upper-triangle `values`.
    ///
    /// Errors: `values` of the wrong length or not finite, a hierarchy left unusable by a
    /// failed [`Self::update_values`].
    pub fn operator<'a>(&'a mut self, values: &'a [f64]) -> Result<FineOperator<'a>> {
        self.check_valid()?;
        check_upper_values(values, self.upper_nnz())?;
        self.prepare_operator(Some(values));
        Ok(FineOperator { amg: self, values })
    }

    /// Number of upper-triangle entries of the finest matrix.
    pub(crate) fn upper_nnz(&self) -> usize {
        self.fine_col_ptr[self.n()]
    }

    /// One V-cycle: `z = M r`. Errors: wrong lengths, non-finite `r`, a hierarchy left
    /// unusable by a failed [`Self::update_values`].
    pub fn apply(&mut self, r: &[f64], z: &mut [f64]) -> Result<()> {
        self.check_valid()?;
        let n = self.n();
        if r.len() != n || z.len() != n {
            return Err(AmgError::Input(format!(
                "V-cycle on vectors of length {} and {}, want {n}",
                r.len(),
                z.len()
            )));
        }
        check_finite(r, "right-hand side")?;
        self.vcycle(r, z);
        Ok(())
    }

    /// One V-cycle without checks; returns `rhsᵀ out` (summed in the finest
    /// post-smoother's last pass).
    pub(crate) fn vcycle(&mut self, rhs: &[f64], out: &mut [f64]) -> f64 {
        let nl = self.levels.len();
        if nl == 1 {
            out.copy_from_slice(rhs);
            self.coarse.solve(out, &mut self.coarse_mem);
            return dot(rhs, out);
        }
        // Down: pre-smooth and restrict the residual.
        for l in 0..nl - 1 {
            let lev = &self.levels[l];
            let Some(tr) = lev.transfer.as_ref() else {
                break;
            };
            let (lo, hi) = self.work.split_at_mut(l + 1);
            let w = &mut lo[l];
            let (b, x): (&[f64], &mut [f64]) = if l == 0 {
                (rhs, &mut *out)
            } else {
                (&w.b, &mut w.x)
            };
            let sw = SmoothWork {
                r: &mut w.r,
                d: &mut w.d,
                dn: &mut w.dn,
            };
            match self.fine_upper.as_ref().filter(|_| l == 0) {
                Some(u) => {
                    let op = u.op(&lev.a, &self.fine_col_ptr);
                    lev.smoother.smooth(&op, &lev.dinv, b, x, true, true, sw)
                }
                None => lev.smoother.smooth(&lev.a, &lev.dinv, b, x, true, true, sw),
            };
            restrict(&tr.galerkin, &tr.p, &tr.off, &w.r, &mut hi[0].b);
        }
        // Coarsest level.
        {
            let w = &mut self.work[nl - 1];
            w.x.copy_from_slice(&w.b);
            self.coarse.solve(&mut w.x, &mut self.coarse_mem);
        }
        // Up: prolongate the correction and post-smooth.
        let mut rhs_out = None;
        for l in (0..nl - 1).rev() {
            let lev = &self.levels[l];
            let Some(tr) = lev.transfer.as_ref() else {
                continue;
            };
            let (lo, hi) = self.work.split_at_mut(l + 1);
            let w = &mut lo[l];
            let (b, x): (&[f64], &mut [f64]) = if l == 0 {
                (rhs, &mut *out)
            } else {
                (&w.b, &mut w.x)
            };
            tr.p.mul_add(&tr.off, &hi[0].x, x);
            let sw = SmoothWork {
                r: &mut w.r,
                d: &mut w.d,
                dn: &mut w.dn,
            };
            rhs_out = match self.fine_upper.as_ref().filter(|_| l == 0) {
                Some(u) => {
                    let op = u.op(&lev.a, &self.fine_col_ptr);
                    lev.smoother.smooth(&op, &lev.dinv, b, x, false, false, sw)
                }
                None => lev
                    .smoother
                    .smooth(&lev.a, &lev.dinv, b, x, false, false, sw),
            };
        }
        rhs_out.unwrap_or_else(|| dot(rhs, out))
    }
}

fn internal() -> AmgError {
    AmgError::Input("internal inconsistency of the multigrid hierarchy".into())
}

/// Numeric part of a level with a transfer: `ρ̂`, the smoother interval and `P`, the
/// products of the estimate through `upper` where given (the finest level's upper
/// triangle, with the column offsets `col_ptr`). Returns false on the coarsest level.
fn smooth_level(
    level: &mut Level,
    upper: Option<&UpperSingle>,
    col_ptr: &[usize],
    options: &AmgOptions,
) -> bool {
    if level.transfer.is_none() {
        return false;
    }
    let steps = options.lanczos_steps;
    let rho = match upper {
        Some(u) => spectral_radius(&level.a, &u.op(&level.a, col_ptr), &level.dinv, steps),
        None => spectral_radius(&level.a, &level.a, &level.dinv, steps),
    };
    level.rho = rho;
    let hi = options.chebyshev_upper * rho;
    level.smoother = Chebyshev {
        lo: hi / options.chebyshev_ratio,
        hi,
        degree: options.smoother_degree,
    };
    let omega = options.prolongation_damping / rho;
    let Some(tr) = level.transfer.as_mut() else {
        return false;
    };
    smooth_prolongator(&level.a, &level.dinv, omega, &tr.t, &tr.off, &mut tr.p);
    true
}
