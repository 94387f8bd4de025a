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
//! **Exact solve from the symmetric factor** ([`LinearSolver::LdltSchur`]). `K` and `P`
//! differ by the Nitsche terms and the boundary penalty alone, a matrix of low rank:
//! one rank-two term per fixed component `k` of a boundary facet,
//! `K − P = Σ c wᵀ − w cᵀ − γ p w wᵀ = Z B Zᵀ` ([`crate::Cosserat::boundary_difference`]:
//! `w` the facet value, `c` the Nitsche traction row, `B` block diagonal with `2 × 2`
//! blocks; 240 columns on the 2,880-triangle plate of 8,640 unknowns, growing as the
//! boundary, `√n` in 2D). The columns are scaled to unit length (`B` scaled to match). The
//! bordered symmetric matrix
//!
//! ```text
//!   A = [ P   Z ]  =  [ L₁₁  0  ] [ D₁  0  ] [ L₁₁  0  ]ᵀ ,     L₂₂ D₂ L₂₂ᵀ = −H ,   H = Zᵀ P⁻¹ Z ,
//!       [ Zᵀ  0 ]     [ L₂₁ L₂₂ ] [ 0   D₂ ] [ L₂₁ L₂₂ ]
//! ```
//!
//! is factorised by the sparse `LDLᵀ` of `porofrac-sparse` with the cells in approximate
//! minimum degree order (faer's AMD on the cell graph of `P`) and the `m` border unknowns
//! last, so the trailing block of the factors holds `−H` (`n` positive pivots, then `m`
//! negative ones). Woodbury's identity for `K = P + Z B Zᵀ` is then two sweeps and dense
//! work of order `m`: with `f = L⁻¹ Π [r; 0]` (the forward sweep, `Π` the elimination
//! order) the border part is `f₂ = −L₂₂⁻¹ Zᵀ P⁻¹ r`, so `u = L₂₂⁻ᵀ D₂⁻¹ f₂ = H⁻¹ Zᵀ P⁻¹ r`;
//! `y = B Zᵀ K⁻¹ r` solves `(I + B H) y = B H u`, i.e. `y = u − (I + B H)⁻¹ u`; and
//! `K⁻¹ r = P⁻¹ (r − Z y)` is the first block of the backward sweep of `f` whose border
//! part is replaced by `D₂ L₂₂ᵀ y = f₂ − D₂ L₂₂ᵀ (I + B H)⁻¹ u`:
//!
//! ```text
//!   u = L₂₂⁻ᵀ D₂⁻¹ f₂ ,   w = (I + B H)⁻¹ u  (dense LU) ,   f₂ ← f₂ − D₂ L₂₂ᵀ w ,   x = backward sweep .
//! ```
//!
//! `P` alone would need `T`, the 540 unknowns that `Z` touches, ordered last to give
//! `(P⁻¹)_TT` from its trailing block; in the bordered matrix the cells keep their
//! unconstrained order and only `Z`'s paths through the elimination tree fill: on the
//! plate 4.9·10⁸ multiply–adds at 8,640 unknowns against 7.8·10⁸ with `T` last
//! (2.96·10⁹ against 4.12·10⁹ at 24,000, 1.46·10¹⁰ against 2.28·10¹⁰ at 61,440), and a
//! dense block of order 240 instead of 540 ([`porofrac_sparse::Ldlt::multiply_adds`]).
//! The same identity without the low-rank form — for a [`SystemRef`] alone, or when the
//! bordered factorisation fails (a rank-deficient `Z`) — orders the unknowns `T` of the
//! rows and columns where `K` and `P` differ last in `P`'s factors: their trailing block is
//! the Schur complement `S_P = L_TT D_T L_TTᵀ`, `(P⁻¹)_TT = S_P⁻¹`, and
//!
//! ```text
//!   (S_P + E_TT) x_T = S_P (P⁻¹ b)_T ,      x = P⁻¹ (b − E x_T) ,
//! ```
//!
//! computed as `x_T = u_T − (S_P + E_TT)⁻¹ E_TT u_T`, `u_T = L_TT⁻ᵀ D_T⁻¹ f_T`, and the
//! backward sweep of `f − [0; L_TT⁻¹ E_TT x_T]` (no product with `S_P`, whose rounding
//! its condition number would amplify). Either is `K⁻¹` up to rounding; it is applied as
//! the preconditioner of GMRES, which checks the true residual (products with `K` by
//! columns, on a copy of its values: the few iterations do not pay for a row form). The
//! elimination order and the symbolic analysis depend only on the pattern and on `Z`:
//! [`crate::Cosserat::new`] computes them ([`SchurAnalysis`]) on a second thread while it
//! assembles the values, and allocates the factor there, so that the set-up is the
//! numeric factorisation alone. The dense part costs `O(m³)`, small against the sparse
//! factorisation up to 10⁵ unknowns in 2D. [`LinearSolver::GmresLdlt`] uses the `LDLᵀ` of
//! `P` (plain AMD) as an inexact preconditioner instead (40–43 iterations on the plate
//! from 8,640 to 61,440 unknowns).
//!
//! **Mixed precision** ([`FactorPrecision`], default single). The factors of `P` are
//! computed in `f32` ([`porofrac_sparse::ldlt_single`]: the same symbolic analysis, half the
//! bytes, twice the vector lanes; 1.5–1.7 times faster than `f64` from 61,440 unknowns on
//! the plate); the dense blocks, their LU and the sums of GMRES stay in `f64`. The solve above is then
//! `K⁻¹` up to an error of about `κ ε₃₂` that GMRES removes: with double-precision factors
//! one iteration reaches a relative residual of 1e-13 to 5e-13 on the plate meshes, with
//! single-precision ones 3 to 5 iterations reach 1e-13 to 9e-13 (GMRES keeps the
//! preconditioned vectors, so a preconditioner linear only up to rounding does not slow
//! it). A tolerance looser than [`REFINE_TOLERANCE`] is tightened to it (within
//! [`REFINE_ITERATIONS`] iterations), so that the solution equals the double-precision
//! direct solve's (stress concentration factor to 1e-11). A single-precision factorisation
//! that meets a pivot of the wrong sign (`P` too ill-conditioned for `f32`) is redone in
//! double.
//!
//! **Threads.** The numeric factorisation runs on one thread below
//! [`FACTOR_PARALLEL_MULTIPLY_ADDS`] and on all threads of the pool above: faer's parallel
//! supernodal kernels synchronise at spinning barriers, which on a machine busy with other
//! work made two threads twice as slow as one up to 61,440 unknowns on the plate, for a gain
//! of at most 8 % of the run on an idle machine. The solutions are bitwise the same either
//! way (on the plate: tests/gmres.rs and the runs of docs/BENCHMARKS.md).

//! **Choice.** [`LinearSolver::Auto`] takes, in 2D, [`LinearSolver::LdltSchur`] below
//! [`AUTO_GMRES_EQUATIONS`] equations (with a dense block of order at most
//! [`AUTO_SCHUR_UNKNOWNS`]) and GMRES with the V-cycle above (measured in docs/BENCHMARKS.md: the factor's
//! memory grows as `n^1.2` and its time as `n^1.4` on the plate; GMRES with the V-cycle
//! stays linear in memory); in 3D, where only the LU and GMRES were measured and `T` grows
//! as `n^(2/3)`, the LU below [`AUTO_GMRES_EQUATIONS_3D`] and GMRES above. The Newmark
//! matrix, solved at every step, keeps the LU below [`AUTO_GMRES_EQUATIONS_NEWMARK`].

use porofrac_amg::{Amg, AmgOptions, NearNullSpace, Precision, SymCsr};
use porofrac_sparse::{Ldlt, LdltError};
use porofrac_sparse::{LdltSingle, TrailingFactor};
use rayon::prelude::*;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::error::{CosseratError, Result};
use crate::krylov::{FactorPrecision, GmresOptions, GmresStats, gmres};
use crate::pattern::{BlockPattern, SparseLu};

/// Equations from which [`LinearSolver::Auto`] takes GMRES with the V-cycle for a static
/// solve (below: [`LinearSolver::LdltSchur`]). On the plate with a hole
/// (`plate_hole run` of crates/cosserat/examples, docs/BENCHMARKS.md) the factorisation
/// in single precision is faster up to 311,040 unknowns (8.0 s against 13.4 s at 138,240;
/// 21.4 s against 24.5 s at 311,040) but needs 1.9 times the memory of GMRES at 138,240
/// (1.3 GB) and about twice at 311,040 (3.1 GB): it is taken up to 150,000.
pub const AUTO_GMRES_EQUATIONS: usize = 150_000;

/// Equations from which [`LinearSolver::Auto`] takes GMRES with the V-cycle for a static
/// solve in 3D (below: the LU; the Schur complement solve is measured in 2D only).
pub const AUTO_GMRES_EQUATIONS_3D: usize = 12_000;

/// Largest order `m` of the dense block (the columns of the low-rank difference, or the
/// boundary unknowns `T`) for which [`LinearSolver::Auto`] takes
/// [`LinearSolver::LdltSchur`] (2D): its dense `m × m` blocks then take at most 134 MB
/// per copy and `O(m³)` work of a few seconds (on the plate, 640 columns at 61,440
/// unknowns, 960 at 138,240).
pub const AUTO_SCHUR_UNKNOWNS: usize = 4_096;

/// Equations from which [`LinearSolver::Auto`] takes GMRES for the Newmark matrix, solved
/// at every step: the LU's one factorisation is then amortised over the steps (each a
/// pair of triangular solves against tens of V-cycles for GMRES), so it is kept up to the
/// size where its memory grows past a few GB (2.5 GB at 61,440 unknowns on the plate).
pub const AUTO_GMRES_EQUATIONS_NEWMARK: usize = 100_000;

/// Relative residual to which GMRES refines the [`LinearSolver::LdltSchur`] solve with
/// single-precision factors when the requested tolerance is looser: the double-precision
/// direct solve reaches 1e-13 to 5e-13 on the plate from 8,640 to 61,440 unknowns, and a
/// solution refined only to 1e-10 differs from it by up to 1e-9 in the stress
/// concentration factor. At most [`REFINE_ITERATIONS`] iterations are spent on it; the
/// requested tolerance is then enough.
pub const REFINE_TOLERANCE: f64 = 1e-12;

/// Largest number of GMRES iterations of a refinement to [`REFINE_TOLERANCE`] (each two
/// sweeps of the single-precision factors; 3 to 5 on the plate).
pub const REFINE_ITERATIONS: usize = 12;

/// Which linear solver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinearSolver {
    /// In 2D [`Self::LdltSchur`] below [`AUTO_GMRES_EQUATIONS`] equations (and a dense
    /// block of order at most [`AUTO_SCHUR_UNKNOWNS`]), [`Self::GmresAmg`] otherwise; in 3D
    /// [`Self::Lu`] below [`AUTO_GMRES_EQUATIONS_3D`], [`Self::GmresAmg`] from there (the
    /// Newmark matrix: [`Self::Lu`] below [`AUTO_GMRES_EQUATIONS_NEWMARK`]).
    #[default]
    Auto,
    /// Sparse LU with partial pivoting (faer).
    Lu,
    /// Restarted GMRES preconditioned by a smoothed-aggregation V-cycle.
    GmresAmg,
    /// Restarted GMRES preconditioned by the sparse `LDLᵀ` factorisation of the
    /// preconditioning matrix.
    GmresLdlt,
    /// Direct: the sparse `LDLᵀ` of the preconditioning matrix bordered by the low-rank
    /// difference to the system (or with the unknowns where they differ ordered last),
    /// corrected exactly by a dense LU of the order of that rank; GMRES checks the
    /// residual (one iteration with double-precision factors, three or four with single).
    LdltSchur,
}

impl LinearSolver {
    /// The solver used for a static 2D solve of `equations` unknowns by size alone (never
    /// [`Self::Auto`]; [`Linear::new`] also applies the 3D rule and the bound on the
    /// boundary unknowns of [`Self::Auto`]).
    pub fn resolve(self, equations: usize) -> Self {
        self.resolve_from(equations, AUTO_GMRES_EQUATIONS, Self::LdltSchur)
    }

    /// The solver used for the Newmark matrix of `equations` unknowns.
    pub fn resolve_newmark(self, equations: usize) -> Self {
        self.resolve_from(equations, AUTO_GMRES_EQUATIONS_NEWMARK, Self::Lu)
    }

    fn resolve_from(self, equations: usize, threshold: usize, direct: Self) -> Self {
        match self {
            Self::Auto if equations >= threshold => Self::GmresAmg,
            Self::Auto => direct,
            s => s,
        }
    }

    /// Short name: `"auto"`, `"lu"`, `"gmres-amg"`, `"gmres-ldlt"` or `"ldlt-schur"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Lu => "lu",
            Self::GmresAmg => "gmres-amg",
            Self::GmresLdlt => "gmres-ldlt",
            Self::LdltSchur => "ldlt-schur",
        }
    }
}

/// Options of [`Linear`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinearOptions {
    /// The solver.
    pub solver: LinearSolver,
    /// GMRES parameters (used by every solver but [`LinearSolver::Lu`]).
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
    /// Stored entries of the `LDLᵀ` factor `L` ([`LinearSolver::GmresLdlt`]), plus the
    /// two dense blocks of order `m` (the trailing factor and the LU) of
    /// [`LinearSolver::LdltSchur`]; 0 for the others (faer does not report the LU's).
    pub factor_entries: usize,
    /// Precision of those `LDLᵀ` factors (`None` without them): the requested
    /// [`GmresOptions::factor_precision`], or double after a failed single-precision
    /// factorization.
    pub factor_precision: Option<FactorPrecision>,
}

/// The preconditioner of GMRES.
enum Precond {
    /// One V-cycle on the preconditioning matrix.
    Amg(Box<Amg>),
    /// The `LDLᵀ` factors of the preconditioning matrix.
    Ldlt(Box<Factor>),
    /// The exact inverse by the `LDLᵀ` and the dense Schur complement.
    Schur(Box<Schur>),
}

/// `K⁻¹` from the `LDLᵀ` factors of a symmetric matrix and a dense correction of the size
/// `k` of their trailing block (module documentation): the factors of the bordered
/// matrix `[[P, Z], [Zᵀ, 0]]` with the `k` border unknowns last and the LU of
/// `I + B H`, or those of `P` with the `k` unknowns `T` last and the LU of `S_P + E_TT`.
struct Schur {
    ldlt: Factor,
    /// The trailing block `L₂₂`, `D₂` of the factors.
    trail: TrailingFactor,
    /// LU of the dense correction.
    lu: DenseLu,
    form: SchurForm,
    /// Work vectors of length `k`.
    ut: Vec<f64>,
    xt: Vec<f64>,
    /// Work vector of the bordered matrix, `n + k` (empty with `T` last).
    z: Vec<f64>,
}

/// What the dense correction of [`Schur`] needs besides its LU.
enum SchurForm {
    /// `E = Z B Zᵀ` bordered.
    Bordered,
    /// `T` last: `E_TT` as `(row, column, value)` in the dense block's indices.
    Trailing { e: Vec<(u32, u32, f64)> },
}

/// Order from which the dense blocks of the Schur complement solve are computed on all
/// threads: faer's LU with partial pivoting of order 540 takes 2.5 ms on one thread and
/// 2.9 ms on two on this 2-core machine, of order 900 10.5 ms and 8.4 ms.
const DENSE_PARALLEL_ORDER: usize = 768;

/// The parallelism of the dense operations of order `k`.
fn dense_parallelism(k: usize) -> faer::Par {
    if k >= DENSE_PARALLEL_ORDER {
        faer::Par::rayon(0)
    } else {
        faer::Par::Seq
    }
}

/// Multiply–adds of the numeric `LDLᵀ` factorisation ([`Ldlt::multiply_adds`]) from which
/// it runs on all threads; below, on one. faer's parallel supernodal factorisation waits at
/// spinning barriers, so on a machine busy with other work two threads are slower than one
/// (the set-up of the solve on the plate, 2 cores at load 8, medians of 3 `plate_hole
/// run`: 0.19 against 0.08 s at 8,640 unknowns, 0.40 against 0.20 s at 24,000, 1.54
/// against 0.71 s at 61,440), while on an idle machine they saved at most 8 % of the run up
/// to 61,440 unknowns (1.46·10¹⁰ multiply–adds; docs/BENCHMARKS.md, "One thread for a small
/// factorisation"). Above this size the factorisation dominates the run and two threads pay
/// on an idle machine.
pub const FACTOR_PARALLEL_MULTIPLY_ADDS: f64 = 2.5e10;

/// The parallelism of the numeric factorisation analysed in `analysis`: one thread below
/// [`FACTOR_PARALLEL_MULTIPLY_ADDS`], all threads from it on.
fn factor_parallelism(analysis: &Ldlt) -> faer::Par {
    if analysis.multiply_adds() >= FACTOR_PARALLEL_MULTIPLY_ADDS {
        faer::Par::rayon(0)
    } else {
        faer::Par::Seq
    }
}

/// LU with partial pivoting of a dense square matrix, factorised in place (no copy of
/// the matrix beside its factors).
struct DenseLu {
    /// `L` (unit, strictly below the diagonal) and `U`.
    lu: faer::Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: faer::dyn_stack::MemBuffer,
}

impl DenseLu {
    fn new(mut a: faer::Mat<f64>) -> Self {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::linalg::lu::partial_pivoting::{factor, solve};
        let k = a.nrows();
        let (mut perm, mut perm_inv) = (vec![0usize; k], vec![0usize; k]);
        let par = dense_parallelism(k);
        let mut mem = MemBuffer::new(factor::lu_in_place_scratch::<usize, f64>(
            k,
            k,
            par,
            Default::default(),
        ));
        factor::lu_in_place(
            a.as_mut(),
            &mut perm,
            &mut perm_inv,
            par,
            MemStack::new(&mut mem),
            Default::default(),
        );
        let mem = MemBuffer::new(solve::solve_in_place_scratch::<usize, f64>(k, 1, par));
        Self {
            lu: a,
            perm,
            perm_inv,
            mem,
        }
    }

    /// `x ← A⁻¹ x`.
    fn solve_in_place(&mut self, x: &mut [f64]) {
        use faer::linalg::lu::partial_pivoting::solve;
        let k = x.len();
        let perm = faer::perm::PermRef::new_checked(&self.perm, &self.perm_inv, k);
        solve::solve_in_place(
            self.lu.as_ref(),
            self.lu.as_ref(),
            perm,
            faer::MatMut::from_column_major_slice_mut(x, k, 1),
            faer::Par::Seq,
            faer::dyn_stack::MemStack::new(&mut self.mem),
        );
    }
}

/// Numeric `LDLᵀ` factors of the preconditioning matrix, in double or single precision.
enum Factor {
    Double(Ldlt),
    Single(LdltSingle),
}

impl Factor {
    /// Factorise the upper triangle of `(col_ptr, row_idx, values)` (the whole matrix or
    /// its upper triangle: only that is read) of the symmetric positive
    /// definite matrix analysed in `analysis`, in `precision`; a single-precision
    /// factorization that fails (a non-positive pivot: too ill-conditioned for `f32`) is
    /// redone in double precision.
    fn new(
        analysis: Prepared,
        upper: (&[usize], &[usize], &[f64]),
        precision: FactorPrecision,
        positive: usize,
    ) -> std::result::Result<Self, LdltError> {
        let (c, r, v) = upper;
        let par = match &analysis {
            Prepared::Analysis(a) => factor_parallelism(a),
            Prepared::Single(s) => factor_parallelism(s.analysis()),
        };
        let mut ldlt = match (precision, analysis) {
            (FactorPrecision::Double, Prepared::Analysis(a)) => a,
            (FactorPrecision::Double, Prepared::Single(s)) => s.into_analysis(),
            (FactorPrecision::Single, analysis) => {
                let mut single = match analysis {
                    Prepared::Analysis(a) => {
                        let mut s = LdltSingle::new(a);
                        s.set_parallelism(par);
                        s
                    }
                    Prepared::Single(s) => s,
                };
                match single.factorize_signed(c, r, v, Some(positive)) {
                    Ok(()) => return Ok(Self::Single(single)),
                    Err(_) => single.into_analysis(),
                }
            }
        };
        ldlt.set_parallelism(par);
        ldlt.factorize(c, r, v)?;
        let size = c.len() - 1;
        if positive < size && !ldlt.pivots_signed(positive) {
            return Err(LdltError(format!(
                "the bordered matrix has not {positive} positive and {} negative pivots: \
                 the low-rank difference is not of full rank",
                size - positive
            )));
        }
        Ok(Self::Double(ldlt))
    }

    fn precision(&self) -> FactorPrecision {
        match self {
            Self::Double(_) => FactorPrecision::Double,
            Self::Single(_) => FactorPrecision::Single,
        }
    }

    fn analysis(&self) -> &Ldlt {
        match self {
            Self::Double(f) => f,
            Self::Single(f) => f.analysis(),
        }
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) -> std::result::Result<(), LdltError> {
        match self {
            Self::Double(f) => f.solve_in_place(rhs),
            Self::Single(f) => f.solve_in_place(rhs),
        }
    }

    /// `rhs ← L⁻¹ P rhs` (in the elimination order on return).
    fn forward(&mut self, rhs: &mut [f64]) -> std::result::Result<(), LdltError> {
        match self {
            Self::Double(f) => f.forward_solve_in_place(rhs),
            Self::Single(f) => f.forward_in_place(rhs),
        }
    }

    /// `rhs ← Pᵀ L⁻ᵀ D⁻¹ rhs` (in the elimination order on entry).
    fn backward(&mut self, rhs: &mut [f64]) -> std::result::Result<(), LdltError> {
        match self {
            Self::Double(f) => f.backward_solve_in_place(rhs),
            Self::Single(f) => f.backward_in_place(rhs),
        }
    }

    fn trailing_factor(&self, k: usize) -> std::result::Result<TrailingFactor, LdltError> {
        match self {
            Self::Double(f) => f.trailing_factor(k),
            Self::Single(f) => f.trailing_factor(k),
        }
    }
}

/// A matrix of low rank, `E = Σ_p Z_p B_p Z_pᵀ`: sparse columns `Z`, in pairs
/// `Z_p = [z_2p z_2p+1]`, and one `2 × 2` block `B_p` per pair.
#[derive(Clone, Debug, Default)]
pub struct LowRankDifference {
    /// The columns `z_i` as `(row, value)` lists.
    pub columns: Vec<Vec<(usize, f64)>>,
    /// `B_p`, column-major (`[b11, b21, b12, b22]`).
    pub blocks: Vec<[f64; 4]>,
}

/// The unknowns `T` of the rows and columns where the system differs from the
/// preconditioning matrix (marked `true`).
fn schur_unknowns(sys: SystemRef<'_>) -> Vec<bool> {
    let p = sys.pattern;
    let n = p.equations();
    let mut in_t = vec![false; n];
    for j in 0..n {
        for q in p.col_ptr[j]..p.col_ptr[j + 1] {
            if sys.values[q] != sys.preconditioner[q] {
                in_t[j] = true;
                in_t[p.row_idx[q]] = true;
            }
        }
    }
    in_t
}

/// The symbolic part of the [`LinearSolver::LdltSchur`] solve, which depends only on the
/// pattern and on where the system differs from the preconditioning matrix: the
/// elimination order (the cells in AMD order, then the border or `T`), the symbolic
/// analysis of the `LDLᵀ` in it, and for the bordered form the border columns.
/// [`crate::Cosserat::new`] prepares it while it assembles the values (on another thread);
/// [`Linear::new`] uses it when it fits the system.
pub struct SchurAnalysis {
    form: AnalysisForm,
    /// The analysis, or the single-precision factors with their memory reserved.
    analysis: Prepared,
}

/// The two forms of [`SchurAnalysis`].
enum AnalysisForm {
    /// The bordered matrix of a known low-rank difference.
    Bordered(Box<Border>),
    /// The unknowns `T` (marked `true`) eliminated last, `tail` in that order.
    Trailing { in_t: Vec<bool>, tail: Vec<usize> },
}

/// The bordered matrix `[[P, Z], [Zᵀ, 0]]` of a [`LowRankDifference`] `E = Z B Zᵀ`: its
/// upper triangle by columns (`P`'s, then the `k` border columns with their rows sorted
/// and a zero diagonal) and the values of the border columns, each scaled to unit length
/// (`B` scaled to match: `Z B Zᵀ` unchanged); the columns of `Z` that are zero are left out
/// (with their row and column of `B`).
struct Border {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// The values of the border columns, `row_idx[col_ptr[n]..]`.
    values: Vec<f64>,
    /// The blocks of `B` on the kept columns: `(first border column, size 1 or 2, values
    /// column-major)`.
    blocks: Vec<(usize, usize, [f64; 4])>,
}

/// The symbolic analysis of [`SchurAnalysis`], possibly inside single-precision factors
/// whose memory is already allocated ([`LdltSingle::reserve`]).
enum Prepared {
    Analysis(Ldlt),
    Single(LdltSingle),
}

impl std::fmt::Debug for SchurAnalysis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SchurAnalysis")
            .field("bordered", &self.is_bordered())
            .field("k", &self.dense_len())
            .finish()
    }
}

impl SchurAnalysis {
    /// The analysis of `pattern` with the unknowns marked in `in_t` eliminated last; with
    /// `reserve`, also the memory of single-precision factors (allocated and touched).
    pub fn new(pattern: &BlockPattern, in_t: Vec<bool>, reserve: bool) -> Result<Self> {
        let n = pattern.equations();
        if in_t.len() != n {
            return Err(CosseratError::Input {
                what: format!("{} unknown marks for {n} unknowns", in_t.len()),
            });
        }
        let b = pattern.block;
        let t_cell: Vec<bool> = (0..n / b)
            .map(|c| (0..b).any(|a| in_t[c * b + a]))
            .collect();
        let order = cell_amd_masked(pattern, &t_cell)?;
        let mut perm: Vec<usize> = order.iter().copied().filter(|&i| !in_t[i]).collect();
        let first = perm.len();
        perm.extend(order.iter().copied().filter(|&i| in_t[i]));
        // The whole pattern: the analysis reads its upper triangle.
        let tail = perm[first..].to_vec();
        let analysis = analyse_last(n, &pattern.col_ptr, &pattern.row_idx, perm, first, reserve)?;
        Ok(Self {
            form: AnalysisForm::Trailing { in_t, tail },
            analysis,
        })
    }

    /// The analysis of the bordered matrix of `pattern` and of the difference `e` between
    /// the system and the preconditioning matrix, the cells in AMD order and the border
    /// last; with `reserve`, also the memory of single-precision factors.
    ///
    /// Errors: `e` with a row outside the pattern, a non-finite value, or not two columns
    /// per block.
    pub fn bordered(pattern: &BlockPattern, e: &LowRankDifference, reserve: bool) -> Result<Self> {
        let n = pattern.equations();
        if e.columns.len() != 2 * e.blocks.len() {
            return Err(CosseratError::Input {
                what: format!(
                    "low-rank difference: {} columns for {} blocks of two",
                    e.columns.len(),
                    e.blocks.len()
                ),
            });
        }
        if let Some((i, &(r, v))) = e
            .columns
            .iter()
            .enumerate()
            .flat_map(|(i, c)| c.iter().map(move |x| (i, x)))
            .find(|(_, (r, v))| *r >= n || !v.is_finite())
        {
            return Err(CosseratError::Input {
                what: format!("low-rank difference: column {i} has value {v} in row {r} of {n}"),
            });
        }
        if e.blocks.iter().flatten().any(|v| !v.is_finite()) {
            return Err(CosseratError::Input {
                what: "low-rank difference: a non-finite coupling".into(),
            });
        }
        let mut col_ptr = Vec::with_capacity(n + e.columns.len() + 1);
        let mut row_idx = Vec::with_capacity(pattern.nnz() / 2 + n);
        col_ptr.push(0);
        for j in 0..n {
            let rows = &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]];
            row_idx.extend_from_slice(&rows[..rows.partition_point(|&r| r <= j)]);
            col_ptr.push(row_idx.len());
        }
        let mut values = Vec::new();
        let mut blocks = Vec::with_capacity(e.blocks.len());
        let mut column = Vec::new();
        let mut k = 0;
        for (p, blk) in e.blocks.iter().enumerate() {
            let kept: Vec<usize> = (0..2)
                .filter(|&a| e.columns[2 * p + a].iter().any(|&(_, v)| v != 0.0))
                .collect();
            // Columns of unit length (the coupling scaled to match): traction rows and
            // facet values differ by the moduli in size.
            let norm = |a: usize| {
                e.columns[2 * p + a]
                    .iter()
                    .map(|x| x.1 * x.1)
                    .sum::<f64>()
                    .sqrt()
            };
            let block = match kept[..] {
                [_, _] => {
                    let (s0, s1) = (norm(0), norm(1));
                    [
                        blk[0] * s0 * s0,
                        blk[1] * s1 * s0,
                        blk[2] * s0 * s1,
                        blk[3] * s1 * s1,
                    ]
                }
                [a] => [blk[3 * a] * norm(a) * norm(a), 0.0, 0.0, 0.0],
                _ => continue,
            };
            if block.iter().all(|&v| v == 0.0) {
                continue;
            }
            blocks.push((k, kept.len(), block));
            for &a in &kept {
                let scale = norm(a).recip();
                column.clear();
                column.extend(e.columns[2 * p + a].iter().map(|&(r, v)| (r, v * scale)));
                column.sort_unstable_by_key(|x| x.0);
                for &(r, v) in &column {
                    if row_idx.len() > col_ptr[n + k] && row_idx.last() == Some(&r) {
                        *values.last_mut().expect("a value per row") += v;
                    } else {
                        row_idx.push(r);
                        values.push(v);
                    }
                }
                row_idx.push(n + k);
                values.push(0.0);
                col_ptr.push(row_idx.len());
                k += 1;
            }
        }
        let order = cell_amd(pattern)?;
        let mut perm = order;
        perm.extend(n..n + k);
        let analysis = analyse_last(n + k, &col_ptr, &row_idx, perm, n, reserve)?;
        Ok(Self {
            form: AnalysisForm::Bordered(Box::new(Border {
                col_ptr,
                row_idx,
                values,
                blocks,
            })),
            analysis,
        })
    }

    /// The unknowns of the system it was made for.
    pub fn unknowns(&self) -> usize {
        match &self.form {
            AnalysisForm::Bordered(b) => {
                b.col_ptr.len() - 1 - b.blocks.iter().map(|x| x.1).sum::<usize>()
            }
            AnalysisForm::Trailing { in_t, .. } => in_t.len(),
        }
    }

    /// The unknowns `T` of the trailing form (marked `true`).
    fn trailing_unknowns(&self) -> Option<&[bool]> {
        match &self.form {
            AnalysisForm::Bordered(_) => None,
            AnalysisForm::Trailing { in_t, .. } => Some(in_t),
        }
    }

    /// Whether this is the bordered form.
    pub fn is_bordered(&self) -> bool {
        matches!(self.form, AnalysisForm::Bordered(_))
    }

    /// The order `k` of the dense correction (the border or `|T|`).
    pub fn dense_len(&self) -> usize {
        match &self.form {
            AnalysisForm::Bordered(b) => b.blocks.iter().map(|x| x.1).sum(),
            AnalysisForm::Trailing { tail, .. } => tail.len(),
        }
    }
}

/// The symbolic analysis of the matrix `(col_ptr, row_idx)` of `size` unknowns (its upper
/// triangle is read) in the order `perm`, checked to keep `perm[first..]` last; with
/// `reserve`, inside single-precision factors with their memory.
fn analyse_last(
    size: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
    perm: Vec<usize>,
    first: usize,
    reserve: bool,
) -> Result<Prepared> {
    let ldlt_err = |e| CosseratError::Solve(format!("LDLᵀ of the preconditioning matrix: {e}"));
    let analysis = Ldlt::analyse(size, col_ptr, row_idx, Some(&perm)).map_err(ldlt_err)?;
    if analysis
        .permutation()
        .is_some_and(|a| a[first..] != perm[first..])
    {
        return Err(CosseratError::Solve(
            "LDLᵀ: the boundary unknowns are not eliminated last".into(),
        ));
    }
    let prepared = if reserve {
        let par = factor_parallelism(&analysis);
        let mut single = LdltSingle::new(analysis);
        single.set_parallelism(par);
        single.reserve().map_err(ldlt_err)?;
        Prepared::Single(single)
    } else {
        Prepared::Analysis(analysis)
    };
    Ok(prepared)
}

impl Schur {
    /// Set up from the system, the whole preconditioning matrix (its upper triangle is
    /// read) and the symbolic analysis.
    fn new(
        sys: SystemRef<'_>,
        n: usize,
        full: (&[usize], &[usize], &[f64]),
        analysis: SchurAnalysis,
        precision: FactorPrecision,
    ) -> Result<Self> {
        let ldlt_err = |e| CosseratError::Solve(format!("LDLᵀ of the preconditioning matrix: {e}"));
        let SchurAnalysis { form, analysis } = analysis;
        let (ldlt, trail, form, dense) = match form {
            AnalysisForm::Bordered(border) => {
                let Border {
                    col_ptr,
                    row_idx,
                    values: border_values,
                    blocks,
                } = *border;
                // P's upper triangle (a prefix of each column of the whole pattern), then
                // the border.
                let mut values = Vec::with_capacity(row_idx.len());
                for j in 0..n {
                    let q = full.0[j];
                    values.extend_from_slice(&full.2[q..q + col_ptr[j + 1] - col_ptr[j]]);
                }
                values.extend_from_slice(&border_values);
                let ldlt = Factor::new(analysis, (&col_ptr, &row_idx, &values), precision, n)
                    .map_err(ldlt_err)?;
                drop(values);
                let trail = ldlt
                    .trailing_factor(col_ptr.len() - 1 - n)
                    .map_err(ldlt_err)?;
                let k = trail.len();
                // H = Zᵀ P⁻¹ Z = −L₂₂ D₂ L₂₂ᵀ, and I + B H row block by row block.
                let mut h = faer::Mat::<f64>::zeros(k, k);
                trail.schur_complement_into(h.as_mut(), dense_parallelism(k));
                for j in 0..k {
                    for v in h.col_mut(j).iter_mut() {
                        *v = -*v;
                    }
                }
                let mut m = faer::Mat::<f64>::identity(k, k);
                for &(c0, size, b) in &blocks {
                    for i in 0..size {
                        for a in 0..size {
                            let bia = b[i + size * a];
                            if bia != 0.0 {
                                for j in 0..k {
                                    m[(c0 + i, j)] += bia * h[(c0 + a, j)];
                                }
                            }
                        }
                    }
                }
                (ldlt, trail, SchurForm::Bordered, m)
            }
            AnalysisForm::Trailing { tail, .. } => {
                let p = sys.pattern;
                let k = tail.len();
                let ldlt = Factor::new(analysis, full, precision, n).map_err(ldlt_err)?;
                let trail = ldlt.trailing_factor(k).map_err(ldlt_err)?;
                let mut local = vec![u32::MAX; n];
                for (j, &i) in tail.iter().enumerate() {
                    local[i] = j as u32;
                }
                let mut e = Vec::new();
                for j in 0..n {
                    for q in p.col_ptr[j]..p.col_ptr[j + 1] {
                        let d = sys.values[q] - sys.preconditioner[q];
                        if d != 0.0 {
                            e.push((local[p.row_idx[q]], local[j], d));
                        }
                    }
                }
                let mut sa = faer::Mat::<f64>::zeros(k, k);
                trail.schur_complement_into(sa.as_mut(), dense_parallelism(k));
                for &(i, j, v) in &e {
                    sa[(i as usize, j as usize)] += v;
                }
                (ldlt, trail, SchurForm::Trailing { e }, sa)
            }
        };
        let k = trail.len();
        let lu = DenseLu::new(dense);
        if let Some(i) = (0..k).find(|&i| {
            let u = lu.lu[(i, i)];
            !(u.is_finite() && u != 0.0)
        }) {
            return Err(CosseratError::Solve(format!(
                "the Schur complement on the boundary unknowns is singular (pivot {i} of {k}): \
                 missing boundary conditions or zero moduli?"
            )));
        }
        let z = match form {
            SchurForm::Bordered => vec![0.0; n + k],
            SchurForm::Trailing { .. } => Vec::new(),
        };
        Ok(Self {
            ldlt,
            trail,
            lu,
            form,
            ut: vec![0.0; k],
            xt: vec![0.0; k],
            z,
        })
    }

    /// `z = K⁻¹ r` in one forward and one backward sweep of the factors, with dense
    /// operations of order `k` between them (module documentation).
    fn apply(&mut self, r: &[f64], z: &mut [f64]) -> Result<()> {
        let err = |e| CosseratError::Solve(format!("LDLᵀ solve: {e}"));
        let n = r.len();
        match &self.form {
            SchurForm::Bordered => {
                // f = L⁻¹ Π [r; 0]; u = L₂₂⁻ᵀ D₂⁻¹ f₂ = H⁻¹ Zᵀ P⁻¹ r; w = (I + B H)⁻¹ u;
                // f₂ += L₂₂⁻¹ H w; the backward sweep gives K⁻¹ r in its first n entries.
                let y = &mut self.z;
                y[..n].copy_from_slice(r);
                y[n..].fill(0.0);
                self.ldlt.forward(y).map_err(err)?;
                self.ut.copy_from_slice(&y[n..]);
                self.trail.backward(&mut self.ut);
                self.xt.copy_from_slice(&self.ut);
                self.lu.solve_in_place(&mut self.xt);
                // L₂₂⁻¹ H w = −D₂ L₂₂ᵀ w (no product with H: its rounding would be
                // amplified by L₂₂⁻¹).
                self.trail.upper_product(&mut self.xt);
                for (f, &c) in y[n..].iter_mut().zip(&self.xt) {
                    *f -= c;
                }
                self.ldlt.backward(y).map_err(err)?;
                z.copy_from_slice(&y[..n]);
                Ok(())
            }
            SchurForm::Trailing { e } => {
                // With f = L⁻¹ Π r (the forward sweep), u_T = L_TT⁻ᵀ D_T⁻¹ f_T is the T
                // part of P⁻¹ r (T is eliminated last); x_T = u_T − (S_P + E)⁻¹ E u_T; and
                // since E x_T is zero outside T, L⁻¹ Π (r − E x_T) = f − [0; L_TT⁻¹ E_TT x_T],
                // so z = P⁻¹ (r − E x_T) is the backward sweep of f corrected on T.
                let k = self.trail.len();
                let first = n - k;
                z.copy_from_slice(r);
                self.ldlt.forward(z).map_err(err)?;
                self.ut.copy_from_slice(&z[first..]);
                self.trail.backward(&mut self.ut);
                // No product with S_P: its rounding would be amplified by the condition
                // number of S_P.
                self.xt.fill(0.0);
                for &(i, j, v) in e {
                    self.xt[i as usize] += v * self.ut[j as usize];
                }
                self.lu.solve_in_place(&mut self.xt);
                for (x, &u) in self.xt.iter_mut().zip(&self.ut) {
                    *x = u - *x;
                }
                self.ut.fill(0.0);
                for &(i, j, v) in e {
                    self.ut[i as usize] += v * self.xt[j as usize];
                }
                self.trail.forward(&mut self.ut);
                for (f, &c) in z[first..].iter_mut().zip(&self.ut) {
                    *f -= c;
                }
                self.ldlt.backward(z).map_err(err)
            }
        }
    }
}

/// GMRES: the system in row form (parallel products) or in column form (a copy of the
/// system, sequential products), and the preconditioner.
struct Gmres {
    row_ptr: Vec<usize>,
    col_idx: Vec<u32>,
    row_values: Vec<f64>,
    /// The three arrays hold the columns (not the rows) of the system.
    by_columns: bool,
    pre: Precond,
    options: GmresOptions,
}

enum Kind {
    Lu(Box<SparseLu>),
    Gmres(Box<Gmres>),
}

/// A factorised (LU) or preconditioned (GMRES) system, solved for any number of
/// right-hand sides.
pub struct Linear {
    kind: Kind,
    n: usize,
    stats: LinearStats,
    interrupt: Option<Arc<AtomicBool>>,
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
        Self::with_analysis(sys, options, None)
    }

    /// [`Self::new`] with the symbolic analysis of the Schur complement solve prepared
    /// (used when that solve is chosen and the analysis is for its unknowns `T`).
    pub fn with_analysis(
        sys: SystemRef<'_>,
        options: &LinearOptions,
        prepared: Option<SchurAnalysis>,
    ) -> Result<Self> {
        Self::build(sys, options, prepared, true)
    }

    /// [`Self::with_analysis`] for the system values `values` and the preconditioning
    /// values `preconditioner` on `pattern`, taken by value: GMRES keeps `values` for its
    /// products instead of a copy.
    pub fn with_values(
        pattern: &BlockPattern,
        values: Vec<f64>,
        preconditioner: Vec<f64>,
        centres: &[f64],
        dim: usize,
        options: &LinearOptions,
        prepared: Option<SchurAnalysis>,
    ) -> Result<Self> {
        let sys = SystemRef {
            pattern,
            values: &values,
            preconditioner: &preconditioner,
            centres,
            dim,
        };
        let mut linear = Self::build(sys, options, prepared, false)?;
        drop(preconditioner);
        if let Kind::Gmres(g) = &mut linear.kind
            && g.by_columns
        {
            g.row_values = values;
        }
        Ok(linear)
    }

    /// The solver of [`Self::with_analysis`]; without `copy_values`, the products of a
    /// GMRES by columns are left without values (the caller moves them in).
    fn build(
        sys: SystemRef<'_>,
        options: &LinearOptions,
        prepared: Option<SchurAnalysis>,
        copy_values: bool,
    ) -> Result<Self> {
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
        let mut stats = LinearStats::default();
        // The unknowns where the system differs from the preconditioning matrix, when the
        // automatic choice looked at them (reused by the Schur complement solve).
        let mut in_t = None;
        let solver = match options.solver {
            // Measured on 2D plates only; in 3D the boundary unknowns grow as n^(2/3) and the
            // dense block with them, so 3D keeps the LU and GMRES, and a 2D system whose
            // dense block would be large takes GMRES.
            LinearSolver::Auto if sys.dim == 3 => {
                if n < AUTO_GMRES_EQUATIONS_3D {
                    LinearSolver::Lu
                } else {
                    LinearSolver::GmresAmg
                }
            }
            LinearSolver::Auto if n < AUTO_GMRES_EQUATIONS => {
                let dense = match &prepared {
                    Some(a) if a.is_bordered() && a.unknowns() == n => a.dense_len(),
                    _ => {
                        let t = schur_unknowns(sys);
                        let count = t.iter().filter(|&&t| t).count();
                        in_t = Some(t);
                        count
                    }
                };
                if dense > AUTO_SCHUR_UNKNOWNS {
                    LinearSolver::GmresAmg
                } else {
                    LinearSolver::LdltSchur
                }
            }
            s => s.resolve(n),
        };
        let kind = match solver {
            LinearSolver::Lu | LinearSolver::Auto => {
                let mut lu = SparseLu::new(sys.pattern)?;
                lu.factorize(sys.pattern, sys.values)?;
                Kind::Lu(Box::new(lu))
            }
            LinearSolver::GmresAmg => Kind::Gmres(Box::new(Gmres::new(
                sys,
                options.gmres,
                PrecondKind::Amg,
                copy_values,
            )?)),
            s @ (LinearSolver::GmresLdlt | LinearSolver::LdltSchur) => {
                let kind = if s == LinearSolver::GmresLdlt {
                    PrecondKind::Ldlt
                } else {
                    match prepared {
                        Some(a) if a.is_bordered() && a.unknowns() == n => {
                            PrecondKind::Schur(Box::new(a))
                        }
                        prepared => {
                            let in_t = in_t.take().unwrap_or_else(|| schur_unknowns(sys));
                            match prepared {
                                Some(a) if a.trailing_unknowns() == Some(&in_t[..]) => {
                                    PrecondKind::Schur(Box::new(a))
                                }
                                _ => PrecondKind::Schur(Box::new(SchurAnalysis::new(
                                    sys.pattern,
                                    in_t,
                                    false,
                                )?)),
                            }
                        }
                    }
                };
                let g = Gmres::new(sys, options.gmres, kind, copy_values)?;
                match &g.pre {
                    Precond::Ldlt(f) => {
                        stats.factor_entries = f.analysis().factor_nnz();
                        stats.factor_precision = Some(f.precision());
                    }
                    Precond::Schur(f) => {
                        let dense = match f.form {
                            SchurForm::Bordered => 2,
                            SchurForm::Trailing { .. } => 2,
                        };
                        stats.factor_entries =
                            f.ldlt.analysis().factor_nnz() + dense * f.trail.len().pow(2);
                        stats.factor_precision = Some(f.ldlt.precision());
                    }
                    Precond::Amg(_) => {}
                }
                Kind::Gmres(Box::new(g))
            }
        };
        Ok(Self {
            kind,
            n,
            stats,
            interrupt: None,
        })
    }

    /// Poll `flag` at every GMRES iteration: when it is set, [`Self::solve`] ends with
    /// [`CosseratError::Interrupted`] (Ctrl-C during a long solve). A direct solve is not
    /// iterative and does not poll.
    pub fn set_interrupt(&mut self, flag: Option<Arc<AtomicBool>>) {
        self.interrupt = flag;
    }

    /// The solver in use.
    pub fn solver(&self) -> LinearSolver {
        match &self.kind {
            Kind::Lu(_) => LinearSolver::Lu,
            Kind::Gmres(g) => match g.pre {
                Precond::Amg(_) => LinearSolver::GmresAmg,
                Precond::Ldlt(_) => LinearSolver::GmresLdlt,
                Precond::Schur(_) => LinearSolver::LdltSchur,
            },
        }
    }

    /// Statistics so far.
    pub fn stats(&self) -> LinearStats {
        self.stats
    }

    /// Put back the solve counts of [`Linear::stats`] (`solves`, `iterations`,
    /// `max_iterations`, `max_residual`) of a run that is continued; the factor's own
    /// figures stay this solver's.
    pub fn restore_counts(&mut self, s: &LinearStats) {
        self.stats.solves = s.solves;
        self.stats.iterations = s.iterations;
        self.stats.max_iterations = s.max_iterations;
        self.stats.max_residual = s.max_residual;
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
                let st = g.solve(rhs, guess, self.interrupt.as_deref())?;
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

/// Which preconditioner [`Gmres::new`] builds.
enum PrecondKind {
    Amg,
    Ldlt,
    /// With the analysis for the unknowns `T` ([`schur_unknowns`]).
    Schur(Box<SchurAnalysis>),
}

/// Approximate minimum degree order of the cell graph of `pattern` (faer's AMD), each
/// cell's components kept together: `perm[k]` is the equation eliminated `k`-th.
fn cell_amd(pattern: &BlockPattern) -> Result<Vec<usize>> {
    cell_amd_masked(pattern, &[])
}

/// [`cell_amd`] of the graph without the cells marked in `skip` (their edges dropped; the
/// marked cells are numbered after the others, in their order).
fn cell_amd_masked(pattern: &BlockPattern, skip: &[bool]) -> Result<Vec<usize>> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::amd;
    let nc = pattern.nbr_pos.len() - 1;
    let skipped = |c: usize| skip.get(c).copied().unwrap_or(false);
    let mut col_ptr = Vec::with_capacity(nc + 1);
    let mut row_idx = Vec::with_capacity(pattern.cells.len() / 2 + nc);
    col_ptr.push(0);
    for c in 0..nc {
        let nb = &pattern.cells[pattern.nbr_pos[c]..pattern.nbr_pos[c + 1]];
        if !skipped(c) {
            row_idx.extend(
                nb.iter()
                    .copied()
                    .take_while(|&r| r <= c)
                    .filter(|&r| !skipped(r)),
            );
        } else {
            row_idx.push(c);
        }
        col_ptr.push(row_idx.len());
    }
    let sym = faer::sparse::SymbolicSparseColMatRef::new_checked(nc, nc, &col_ptr, None, &row_idx);
    let (mut fwd, mut inv) = (vec![0usize; nc], vec![0usize; nc]);
    let mut mem = MemBuffer::try_new(amd::order_scratch::<usize>(nc, row_idx.len()))
        .map_err(|_| CosseratError::Solve("AMD ordering: out of memory".into()))?;
    amd::order(
        &mut fwd,
        &mut inv,
        sym,
        amd::Control::default(),
        MemStack::new(&mut mem),
    )
    .map_err(|e| CosseratError::Solve(format!("AMD ordering: {e:?}")))?;
    let b = pattern.block;
    Ok(fwd
        .iter()
        .filter(|&&c| !skipped(c))
        .chain((0..nc).filter(|&c| skipped(c)).collect::<Vec<_>>().iter())
        .flat_map(|&c| (0..b).map(move |a| c * b + a))
        .collect())
}

impl Gmres {
    fn new(
        sys: SystemRef<'_>,
        options: GmresOptions,
        kind: PrecondKind,
        copy_values: bool,
    ) -> Result<Self> {
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
        // The direct preconditioners take the whole preconditioning matrix: the LDLᵀ
        // reads its upper triangle only. Their solve needs few products with K, done by
        // columns on a copy (no transposition; or on the values moved in by the caller);
        // the multigrid's many are done by rows.
        let by_columns = !matches!(kind, PrecondKind::Amg);
        let product = || {
            if by_columns {
                let col_idx: Vec<u32> = p.row_idx.iter().map(|&r| r as u32).collect();
                let values = if copy_values {
                    sys.values.to_vec()
                } else {
                    Vec::new()
                };
                (p.col_ptr.clone(), col_idx, values)
            } else {
                row_form(p, sys.values)
            }
        };
        let preconditioner = || -> Result<Precond> {
            let full = (&p.col_ptr[..], &p.row_idx[..], sys.preconditioner);
            Ok(match kind {
                PrecondKind::Amg => {
                    let amg_err = |e: porofrac_amg::AmgError| {
                        CosseratError::Solve(format!("multigrid preconditioner setup: {e}"))
                    };
                    let (ucol, urow, uval) = upper_triangle(p, sys.preconditioner);
                    // The hierarchy only preconditions: its finest matrix in single
                    // precision halves the memory traffic of the smoother (same iteration
                    // counts measured).
                    let sym = SymCsr::from_upper_csc_in(Precision::Single, n, &ucol, &urow, &uval)
                        .map_err(amg_err)?;
                    drop((ucol, urow, uval));
                    let null = rigid_motions(sys.centres, sys.dim)?;
                    let nodes: Vec<usize> = (0..n).map(|e| e / p.block).collect();
                    Precond::Amg(Box::new(
                        Amg::new(sym, &nodes, &null, &amg_options()).map_err(amg_err)?,
                    ))
                }
                PrecondKind::Ldlt => {
                    let ldlt_err = |e| {
                        CosseratError::Solve(format!("LDLᵀ of the preconditioning matrix: {e}"))
                    };
                    let perm = cell_amd(p)?;
                    let analysis =
                        Ldlt::analyse(n, full.0, full.1, Some(&perm)).map_err(ldlt_err)?;
                    let f = Factor::new(
                        Prepared::Analysis(analysis),
                        full,
                        options.factor_precision,
                        n,
                    )
                    .map_err(ldlt_err)?;
                    Precond::Ldlt(Box::new(f))
                }
                PrecondKind::Schur(analysis) => {
                    let bordered = analysis.is_bordered();
                    let precision = options.factor_precision;
                    match Schur::new(sys, n, full, *analysis, precision) {
                        Ok(s) => Precond::Schur(Box::new(s)),
                        // A difference that does not match the system or is rank
                        // deficient: the form from the values themselves.
                        Err(_) if bordered => {
                            let t = SchurAnalysis::new(p, schur_unknowns(sys), false)?;
                            Precond::Schur(Box::new(Schur::new(sys, n, full, t, precision)?))
                        }
                        Err(e) => return Err(e),
                    }
                }
            })
        };
        let ((row_ptr, col_idx, row_values), pre) = rayon::join(product, preconditioner);
        let pre = pre?;
        Ok(Self {
            row_ptr,
            col_idx,
            row_values,
            by_columns,
            pre,
            options,
        })
    }

    fn solve(
        &mut self,
        rhs: &mut [f64],
        guess: Option<&[f64]>,
        interrupt: Option<&AtomicBool>,
    ) -> Result<GmresStats> {
        let b = rhs.to_vec();
        match guess {
            Some(g) => rhs.copy_from_slice(g),
            None => rhs.fill(0.0),
        }
        let Self {
            row_ptr,
            col_idx,
            row_values,
            by_columns,
            pre,
            options,
        } = self;
        let me = RowMatrix {
            row_ptr,
            col_idx,
            row_values,
            by_columns: *by_columns,
        };
        // A direct solve from single-precision factors: refined past a loose tolerance to
        // the accuracy of the double-precision one, within a few iterations.
        let refine = matches!(pre, Precond::Schur(f) if f.ldlt.precision() == FactorPrecision::Single)
            && options.tolerance > REFINE_TOLERANCE;
        let wanted = options.tolerance;
        let refined = GmresOptions {
            tolerance: REFINE_TOLERANCE,
            max_iterations: options.max_iterations.min(REFINE_ITERATIONS),
            ..*options
        };
        let result = gmres(
            |x, y| me.apply(x, y),
            |r, z| match pre {
                _ if interrupt.is_some_and(|f| f.load(Ordering::Relaxed)) => {
                    Err(CosseratError::Interrupted)
                }
                Precond::Amg(amg) => amg
                    .apply(r, z)
                    .map_err(|e| CosseratError::Solve(format!("multigrid V-cycle: {e}"))),
                Precond::Ldlt(f) => {
                    z.copy_from_slice(r);
                    f.solve_in_place(z)
                        .map_err(|e| CosseratError::Solve(format!("LDLᵀ solve: {e}")))
                }
                Precond::Schur(f) => f.apply(r, z),
            },
            &b,
            rhs,
            if refine { &refined } else { options },
        );
        match result {
            Err(CosseratError::NotConverged {
                iterations,
                residual,
                ..
            }) if refine && residual <= wanted => Ok(GmresStats {
                iterations,
                residual,
            }),
            r => r,
        }
    }
}

/// The row form of the system with `values` on the pattern: the pattern is structurally
/// symmetric, so row `i` has the indices of column `i`, and walking the columns in order
/// fills each row in increasing column order.
fn row_form(p: &BlockPattern, values: &[f64]) -> (Vec<usize>, Vec<u32>, Vec<f64>) {
    let n = p.equations();
    let row_ptr = p.col_ptr.clone();
    let col_idx: Vec<u32> = p.row_idx.iter().map(|&r| r as u32).collect();
    let mut next = row_ptr[..n].to_vec();
    let mut row_values = vec![0.0; p.nnz()];
    for j in 0..n {
        for q in p.col_ptr[j]..p.col_ptr[j + 1] {
            let i = p.row_idx[q];
            row_values[next[i]] = values[q];
            next[i] += 1;
        }
    }
    (row_ptr, col_idx, row_values)
}

/// The upper triangle of the matrix with `values` on the pattern, by columns.
fn upper_triangle(p: &BlockPattern, values: &[f64]) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    let n = p.equations();
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
            uval.push(values[q]);
        }
        ucol.push(urow.len());
    }
    (ucol, urow, uval)
}

/// Borrowed row (or column) form of the system.
struct RowMatrix<'a> {
    row_ptr: &'a [usize],
    col_idx: &'a [u32],
    row_values: &'a [f64],
    by_columns: bool,
}

impl RowMatrix<'_> {
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        let (rp, ci, v) = (self.row_ptr, self.col_idx, self.row_values);
        if self.by_columns {
            y.fill(0.0);
            for (j, &xj) in x.iter().enumerate() {
                for q in rp[j]..rp[j + 1] {
                    y[ci[q] as usize] += v[q] * xj;
                }
            }
            return;
        }
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
