//! porofrac-amg: smoothed-aggregation algebraic multigrid (SA-AMG) and preconditioned
//! conjugate gradients for symmetric positive definite systems — the reduced elasticity
//! stiffness of porofrac, or any SPD matrix given by its upper triangle.
//!
//! A sparse Cholesky factorization of a 3D stiffness matrix fills in like `n^{4/3}` and
//! costs `n²` operations even with nested dissection; CG with a multigrid preconditioner
//! costs `O(n)` per iteration and needs a number of iterations that does not grow with the
//! mesh size. The method is smoothed aggregation (Vaněk, Mandel, Brezina 1996):
//!
//! 1. [`csr`]: the matrix, expanded once from its upper triangle (CSC, as
//!    `porofrac_sim::Pattern` stores it) to full CSR for parallel products.
//! 2. [`nullspace`]: the near-null space — rigid-body modes for elasticity (built from the
//!    node and component of every equation, so eliminated dofs need no special care),
//!    constants for diffusion.
//! 3. [`aggregate`]: block strength of connection, greedy aggregation of nodes, and the
//!    tentative prolongator from a QR factorization of the near-null space on each
//!    aggregate.
//! 4. [`product`]: the Jacobi-smoothed prolongator `P = (I − ω D⁻¹A) P_tent` and the
//!    Galerkin operator `Pᵀ A P`, row by row with dense accumulators, without storing
//!    `A P` or the transpose of `P`.
//! 5. [`smoother`]: the Lanczos estimate of `ρ(D⁻¹A)` and the Chebyshev smoother.
//! 6. [`hierarchy`]: levels until a coarse size, sparse Cholesky on the coarsest
//!    (`porofrac-sparse`), the V-cycle, and the numeric rebuild for new values on the
//!    same pattern.
//! 7. [`pcg`]: preconditioned CG that reports its iterations and residual and fails loudly;
//!    with a hierarchy stored in single precision ([`Precision`]) it multiplies by the
//!    caller's double-precision upper triangle ([`upper`]).
//! 8. [`local`]: one aggregation step with its tentative prolongator as plain arrays, for
//!    hierarchies built elsewhere (the distributed one of `porofrac-dist`).
//!
//! All parallel kernels (rayon) give bitwise the same results for any number of threads.
//! [`Amg::memory`] reports what a hierarchy holds, by part.
//!
//! ```
//! use porofrac_amg::{Amg, AmgOptions, SymCsr};
//! // 1D Laplacian [−1 2 −1] on 2000 points, upper triangle in CSC.
//! let n = 2000;
//! let (mut col_ptr, mut rows, mut vals) = (vec![0], vec![], vec![]);
//! for c in 0..n {
//!     if c > 0 {
//!         rows.push(c - 1);
//!         vals.push(-1.0);
//!     }
//!     rows.push(c);
//!     vals.push(2.0);
//!     col_ptr.push(rows.len());
//! }
//! let a = SymCsr::from_upper_csc(n, &col_ptr, &rows, &vals)?;
//! let mut amg = Amg::scalar(a, &AmgOptions::default())?;
//! let b = vec![1.0; n];
//! let mut x = vec![0.0; n];
//! let stats = amg.solve(&mut x, &b, 1e-10, 100)?;
//! assert!(stats.relative_residual <= 1e-10);
//! # Ok::<(), porofrac_amg::AmgError>(())
//! ```

pub mod aggregate;
pub mod coarse;
pub mod csr;
pub mod error;
pub mod hierarchy;
pub mod local;
pub mod nullspace;
pub mod pcg;
pub mod product;
pub mod smoother;
pub mod upper;

pub use csr::{CsrMatrix, Precision, SymCsr};
pub use error::{AmgError, Result};
pub use hierarchy::{
    Amg, AmgMemory, AmgOptions, FineOperator, LevelInfo, UPPER_MIN_ENTRIES_PER_ROW,
};
pub use local::{LocalAggregation, aggregate_tentative};
pub use nullspace::NearNullSpace;
pub use pcg::CgStats;
