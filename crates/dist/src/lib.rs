//! porofrac-dist: distributed sparse linear algebra on MPI — the linear-elasticity solve
//! of the continuum model on many processes.
//!
//! # The problem
//!
//! `A x = b` with `A` symmetric positive definite (the reduced stiffness of linear
//! elasticity, a Laplacian), its rows distributed over `P` processes. Process `r` owns the
//! contiguous global rows `s_r..s_{r+1}` and their entries; vectors are distributed the
//! same way.
//!
//! # The pieces
//!
//! 1. [`partition`]: recursive coordinate bisection of the grid's nodes into `P` parts,
//!    balanced to one node — the rows a process owns are the equations of its nodes,
//!    numbered part by part. (Without MPI: this module is all the crate offers.)
//! 2. `matrix` (feature `mpi`): the distributed CSR matrix split into the block of
//!    owned columns and the block of ghost columns, a ghost-exchange plan built once, the
//!    product `y = A x` with the exchange overlapped, the transpose product, and dot
//!    products by all-reduce.
//! 3. `amg` (feature `mpi`): smoothed-aggregation AMG whose aggregates stay inside a
//!    process (built by `porofrac-amg` on the owned block), with the smoothed prolongator
//!    `P = (I − ωD⁻¹A)T` and the Galerkin product `PᵀAP` across processes, the coarsest
//!    level gathered to every process and factorized by sparse Cholesky, and the V-cycle.
//! 4. `pcg` (feature `mpi`): CG preconditioned by the V-cycle, reporting its iterations
//!    and residual.
//!
//! # Cost per CG iteration
//!
//! On each level one product costs the local `nnz` flops plus one message to each
//! neighbour process (its ghost values, `8 · n_ghost` bytes received); a V-cycle with
//! Chebyshev degree `ν` does `2ν + 1` products per level, one restriction (a reverse
//! exchange) and one prolongation; a CG iteration adds one product and three all-reduces.
//! The coarsest level costs an all-gather of its right-hand side and a redundant direct
//! solve on each process.
//!
//! # Agreement with the serial solve
//!
//! On one process the hierarchy is the serial one of `porofrac-amg` up to round-off (the
//! owned block is the whole matrix, the aggregation is the same). On `P` processes the
//! aggregates are cut at process borders, a slightly weaker coarse space; the solution
//! agrees with the serial one to the solver tolerance, and the iteration count grows
//! little (tested: at most 20 % from one to four processes).

pub mod partition;

#[cfg(feature = "mpi")]
pub mod amg;
#[cfg(feature = "mpi")]
pub mod error;
#[cfg(feature = "mpi")]
pub mod matrix;
#[cfg(feature = "mpi")]
pub mod pcg;

#[cfg(feature = "mpi")]
pub use amg::{DistAmg, DistLevelInfo};
#[cfg(feature = "mpi")]
pub use error::{DistError, Result};
#[cfg(feature = "mpi")]
pub use matrix::{Comm, DistCsr, Exchange, Layout};
pub use partition::recursive_bisection;
#[cfg(feature = "mpi")]
pub use pcg::DistCgStats;
#[cfg(feature = "mpi")]
pub use porofrac_amg::{AmgOptions, NearNullSpace};
