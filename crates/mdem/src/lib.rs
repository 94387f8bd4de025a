//! MDEM and central-force DEM cell laws on simplices, and a DEM lattice with shear
//! springs and micro-rotations.
//!
//! # Edge extensions (Nilsen et al. 2017, §2.2, eq. 15)
//!
//! The paper: H. M. Nilsen, I. Larsen, X. Raynaud (2017), arXiv:1702.01552.
//!
//! On a simplex with `D + 1` nodes there are `K = D(D+1)/2` edges, exactly as many as
//! independent strain components (3 in 2D, 6 in 3D). Edge `k` joins nodes `a_k → b_k`
//! (order: [`edges`]); with length `l_k` and unit vector `t_k`, a linear displacement
//! `u(x) = ε x + rigid` lengthens it by
//!
//! ```text
//! U_k = t_k · (u_b − u_a) = l_k t_k · ε t_k = l_k Kelvin(t_k ⊗ t_k) · ε,
//! ```
//!
//! so `U = M ε` with row `k` of the `K × K` matrix `M` equal to `l_k Kelvin(t_k ⊗ t_k)`
//! (Kelvin notation: `[e11, e22, √2 e12]`, `[e11, e22, e33, √2 e23, √2 e13, √2 e12]`).
//! `M` is invertible exactly when the simplex is non-degenerate. Since the `D(D+1)`
//! nodal displacements of a simplex span exactly the linear fields, `U = R u` with
//! `R` the edge-projection operator (row `k`: `−t_k` at node `a_k`, `+t_k` at `b_k`).
//!
//! # MDEM (§2.2, eqs. 16–21)
//!
//! The energy `E = ½ Uᵀ 𝐊 U = ½ εᵀ Mᵀ 𝐊 M ε` equals the linear-elastic energy of the
//! cell, `|K| · ½ ε · D ε`, iff `Mᵀ 𝐊 M = |K| D`, i.e.
//!
//! ```text
//! 𝐊 = |K| (M⁻¹)ᵀ D M⁻¹          (eq. 21, with the volume factor |K|)
//! ```
//!
//! (the paper's eq. 19 writes the energy without the ½ and eq. 21 without `|K|`; both are
//! absorbed here so that `E` is the physical energy of the cell). Edge forces are
//! `F = 𝐊 U` (eq. 17, tension positive), nodal forces are the edge forces acting along
//! the edges, `f = −Rᵀ F` (restoring), the stress is `σ = (1/|K|) Mᵀ F = D ε`
//! (eq. 18) and the local stiffness is `Rᵀ 𝐊 R`, which equals the P1 finite-element
//! stiffness `|K| Bᵀ D B` and the VEM stiffness on the same simplex (§2.4, eq. 27).
//!
//! # Central-force DEM (§2.6, eqs. 32–33)
//!
//! [`DemLaw`] keeps only the diagonal `𝐊_d = diag(𝐊)`: each edge is an independent
//! spring. Its effective Cauchy stiffness `Mᵀ 𝐊_d M / |K|` differs from `D` unless `𝐊`
//! is diagonal; [`dem_stiffness_loss`] computes the difference
//! `T = C − 𝒦(𝒦⁻¹(C)_d)` of the paper's Figure 3. The post-failure variant acts only
//! on shortening edges (compression only).
//!
//! # DEM with shear springs and rotations (§2.1, eqs. 7–14)
//!
//! See [`lattice`].

mod dem;
mod error;
pub mod lattice;
mod mdem;
mod simplex;

pub use dem::{DemLaw, DemMode, EdgeState};
pub use error::MdemError;
pub use mdem::MdemLaw;
pub use simplex::{
    cauchy_from_edge_stiffness, dem_stiffness_loss, edge_matrix, edge_stiffness_from_cauchy, edges,
    kelvin_size, simplex_volume,
};
