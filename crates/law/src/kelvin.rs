//! Kelvin (Mandel) notation for symmetric tensors.
//!
//! A symmetric tensor `ε` is stored as a vector whose Euclidean inner product equals the
//! tensor double contraction, `ε : τ = ε_K · τ_K`:
//!
//! ```text
//!   2D:  ε_K = [ε11, ε22, √2 ε12]                         (K = 3)
//!   3D:  ε_K = [ε11, ε22, ε33, √2 ε23, √2 ε13, √2 ε12]    (K = 6)
//! ```
//!
//! Equivalently, `ε_K[k] = B_k : ε` for the Frobenius-orthonormal basis of symmetric
//! matrices `B_k = e_a ⊗ e_a` (normal components) and `B_k = (e_a ⊗ e_b + e_b ⊗ e_a)/√2`
//! (shear components, pairs `(a, b)` as listed by [`kelvin_pair`]). A fourth-order
//! elasticity tensor with the minor and major symmetries becomes the symmetric `K × K`
//! matrix `D_kl = B_k : C : B_l` (Nilsen et al. (2017) §2.3, after eq. 26), and `σ_K = D ε_K`.
//!
//! # Representation
//!
//! Stable Rust cannot name `SVector<f64, {D(D+1)/2}>` for a const generic `D`. Kelvin
//! vectors and matrices are therefore *fixed six-slot* nalgebra types, [`Kelvin`] =
//! `SVector<f64, 6>` and [`KelvinMatrix`] = `SMatrix<f64, 6, 6>`, of which only the first
//! [`kelvin_len`]`(D)` entries (rows and columns) are used; the rest are kept at zero.
//! This keeps everything on the stack, needs no trait bounds on `D` in user code (a
//! generic `impl<const D: usize>` works as is), and zero padding makes full 6-slot
//! products correct in 2D as well (`D ε`, `ε · D ε`); hot loops can still iterate over
//! `0..kelvin_len(D)` only, which the compiler sees as a constant.

use nalgebra::{SMatrix, SVector};
use porofrac_grid::Point;

use crate::Tensor;

/// The largest Kelvin length (3D).
pub const MAX_KELVIN: usize = 6;

/// A Kelvin vector; entries at and beyond [`kelvin_len`]`(D)` are zero.
pub type Kelvin = SVector<f64, MAX_KELVIN>;

/// A Kelvin matrix; only the leading [`kelvin_len`]`(D)` square block is used, the rest
/// is zero.
pub type KelvinMatrix = SMatrix<f64, MAX_KELVIN, MAX_KELVIN>;

/// Number of independent components of a symmetric `d × d` tensor: 3 in 2D, 6 in 3D.
pub const fn kelvin_len(d: usize) -> usize {
    d * (d + 1) / 2
}

/// The tensor index pair `(a, b)`, `a ≤ b`, of Kelvin component `k` in dimension `d`.
///
/// 2D: `(0,0), (1,1), (0,1)`; 3D: `(0,0), (1,1), (2,2), (1,2), (0,2), (0,1)`.
/// Returns `None` if `k ≥ kelvin_len(d)` or `d` is not 2 or 3.
pub const fn kelvin_pair(d: usize, k: usize) -> Option<(usize, usize)> {
    match (d, k) {
        (2, 0) | (3, 0) => Some((0, 0)),
        (2, 1) | (3, 1) => Some((1, 1)),
        (2, 2) => Some((0, 1)),
        (3, 2) => Some((2, 2)),
        (3, 3) => Some((1, 2)),
        (3, 4) => Some((0, 2)),
        (3, 5) => Some((0, 1)),
        _ => None,
    }
}

/// The Kelvin index of tensor component `(a, b)` (in either order) in dimension `d`.
///
/// Returns `None` if `a` or `b` is out of range or `d` is not 2 or 3.
pub const fn kelvin_index(d: usize, a: usize, b: usize) -> Option<usize> {
    if (d != 2 && d != 3) || a >= d || b >= d {
        return None;
    }
    if a == b {
        return Some(a);
    }
    if d == 2 {
        return Some(2);
    }
    // 3D shear: the component is 3 + the index of the missing axis.
    Some(3 + (3 - a - b))
}

/// The weight of Kelvin component `k`: `1` for normal components, `√2` for shear.
#[inline]
pub fn kelvin_weight(d: usize, k: usize) -> f64 {
    if k < d { 1.0 } else { std::f64::consts::SQRT_2 }
}

/// The Kelvin vector of a tensor. Off-diagonal entries are symmetrized first,
/// `√2 (t_ab + t_ba)/2`, so `to_kelvin(t) = to_kelvin(sym(t))`.
#[inline]
pub fn to_kelvin<const D: usize>(t: &Tensor<D>) -> Kelvin {
    let mut v = Kelvin::zeros();
    for k in 0..kelvin_len(D) {
        let (a, b) = pair::<D>(k);
        v[k] = if a == b {
            t[(a, a)]
        } else {
            std::f64::consts::FRAC_1_SQRT_2 * (t[(a, b)] + t[(b, a)])
        };
    }
    v
}

/// The symmetric tensor of a Kelvin vector (entries beyond [`kelvin_len`]`(D)` ignored).
#[inline]
pub fn from_kelvin<const D: usize>(v: &Kelvin) -> Tensor<D> {
    let mut t = Tensor::<D>::zeros();
    for k in 0..kelvin_len(D) {
        let (a, b) = pair::<D>(k);
        if a == b {
            t[(a, a)] = v[k];
        } else {
            let s = std::f64::consts::FRAC_1_SQRT_2 * v[k];
            t[(a, b)] = s;
            t[(b, a)] = s;
        }
    }
    t
}

/// The Kelvin vector of `sym(u ⊗ n) = (u nᵀ + n uᵀ)/2` without forming the tensor.
///
/// This is the strain contribution of one node in the VEM/P1 projection
/// `ε = (1/|K|) Σ_i sym(u_i ⊗ N_i)`.
#[inline]
pub fn kelvin_sym_outer<const D: usize>(u: &Point<D>, n: &Point<D>) -> Kelvin {
    let mut v = Kelvin::zeros();
    for k in 0..kelvin_len(D) {
        let (a, b) = pair::<D>(k);
        v[k] = if a == b {
            u[a] * n[a]
        } else {
            std::f64::consts::FRAC_1_SQRT_2 * (u[a] * n[b] + u[b] * n[a])
        };
    }
    v
}

/// The Frobenius-orthonormal basis tensor `B_k` of Kelvin component `k`.
#[inline]
pub fn kelvin_basis<const D: usize>(k: usize) -> Tensor<D> {
    let mut v = Kelvin::zeros();
    if k < kelvin_len(D) {
        v[k] = 1.0;
    }
    from_kelvin::<D>(&v)
}

/// `kelvin_pair` for a component known to be in range (D is 2 or 3 by construction of
/// the callers' loops).
#[inline(always)]
pub(crate) fn pair<const D: usize>(k: usize) -> (usize, usize) {
    kelvin_pair(D, k).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_and_indices_are_consistent() {
        assert_eq!(kelvin_len(2), 3);
        assert_eq!(kelvin_len(3), 6);
        for d in 2..=3 {
            for k in 0..kelvin_len(d) {
                let (a, b) = kelvin_pair(d, k).unwrap();
                assert_eq!(kelvin_index(d, a, b), Some(k));
                assert_eq!(kelvin_index(d, b, a), Some(k));
            }
            assert_eq!(kelvin_pair(d, kelvin_len(d)), None);
        }
        assert_eq!(kelvin_index(3, 1, 2), Some(3));
        assert_eq!(kelvin_index(3, 0, 2), Some(4));
        assert_eq!(kelvin_index(3, 0, 1), Some(5));
        assert_eq!(kelvin_index(2, 0, 2), None);
    }

    #[test]
    fn round_trip_and_inner_product_3d() {
        let t = Tensor::<3>::new(1.0, 2.0, 3.0, 2.0, 5.0, 6.0, 3.0, 6.0, 9.0);
        let s = Tensor::<3>::new(-1.0, 0.5, 0.25, 0.5, 4.0, -2.0, 0.25, -2.0, 7.0);
        let v = to_kelvin::<3>(&t);
        let r2 = std::f64::consts::SQRT_2;
        let expect = [1.0, 5.0, 9.0, r2 * 6.0, r2 * 3.0, r2 * 2.0];
        for k in 0..6 {
            assert!((v[k] - expect[k]).abs() < 1e-15);
        }
        assert!((from_kelvin::<3>(&v) - t).amax() < 1e-15);
        // ε : τ = ε_K · τ_K
        let dot = t.component_mul(&s).sum();
        assert!((dot - v.dot(&to_kelvin::<3>(&s))).abs() < 1e-13);
    }

    #[test]
    fn round_trip_2d_and_sym_outer() {
        let t = nalgebra::Matrix2::new(1.0, 3.0, -1.0, 2.0);
        let v = to_kelvin::<2>(&t);
        assert!((v[2] - std::f64::consts::SQRT_2).abs() < 1e-15);
        assert_eq!(v[3], 0.0);
        let sym = from_kelvin::<2>(&v);
        assert!((sym - (t + t.transpose()) * 0.5).amax() < 1e-15);
        let u = Point::<2>::new(0.3, -1.2);
        let n = Point::<2>::new(2.0, 0.7);
        let direct = to_kelvin::<2>(&(u * n.transpose()));
        assert!((kelvin_sym_outer::<2>(&u, &n) - direct).amax() < 1e-15);
        // Basis is orthonormal in the Frobenius product.
        for k in 0..3 {
            for l in 0..3 {
                let p = kelvin_basis::<2>(k)
                    .component_mul(&kelvin_basis::<2>(l))
                    .sum();
                assert!((p - if k == l { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
    }
}
