//! Simplex edge geometry: the edge map `M` (Nilsen et al. (2017) eq. 15) and the maps between the
//! MDEM edge stiffness `𝐊` and the Cauchy stiffness `C` (eqs. 20–21).
//!
//! The hot-path core ([`Frame`]) is fixed-size and allocation-free: `K = D(D+1)/2` is a
//! second const parameter chosen by a `match` on `D` in the laws, so no trait bounds on
//! `D` leak into user code. The public functions of this module allocate and are meant
//! for analysis (Figure 3, tests).

use nalgebra::{DMatrix, SMatrix, SVector};
use porofrac_grid::Point;

use crate::MdemError;

const EDGES_2D: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];
const EDGES_3D: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
const KELVIN_2D: [(usize, usize); 3] = [(0, 0), (1, 1), (0, 1)];
const KELVIN_3D: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)];

/// Relative volume below which a simplex counts as degenerate:
/// `|K| ≤ DEGENERATE · l_max^D`.
pub(crate) const DEGENERATE: f64 = 1e-12;

/// The edges `(a_k, b_k)` of a simplex in dimension `dim`, in the order used for the
/// rows of `M` and the entries of `U`, `F`, `𝐊`: 2D `(0,1), (0,2), (1,2)`;
/// 3D `(0,1), (0,2), (0,3), (1,2), (1,3), (2,3)`. Empty for other dimensions.
pub fn edges(dim: usize) -> &'static [(usize, usize)] {
    match dim {
        2 => &EDGES_2D,
        3 => &EDGES_3D,
        _ => &[],
    }
}

/// Number of Kelvin components (= number of simplex edges): 3 in 2D, 6 in 3D, and
/// `dim(dim+1)/2` in general.
pub const fn kelvin_size(dim: usize) -> usize {
    dim * (dim + 1) / 2
}

/// Tensor index pairs of the Kelvin components for `k` components (3 or 6).
pub(crate) fn kelvin_pairs(k: usize) -> &'static [(usize, usize)] {
    if k == 3 { &KELVIN_2D } else { &KELVIN_3D }
}

/// Kelvin vector of the symmetric tensor `t ⊗ t`.
fn kelvin_outer<const D: usize, const K: usize>(t: &SVector<f64, D>) -> SVector<f64, K> {
    let pairs = kelvin_pairs(K);
    SVector::<f64, K>::from_fn(|k, _| {
        let (i, j) = pairs[k];
        if i == j {
            t[i] * t[i]
        } else {
            std::f64::consts::SQRT_2 * t[i] * t[j]
        }
    })
}

/// Symmetric tensor from a Kelvin vector.
pub(crate) fn tensor_from_kelvin<const D: usize, const K: usize>(
    s: &SVector<f64, K>,
) -> SMatrix<f64, D, D> {
    let mut t = SMatrix::<f64, D, D>::zeros();
    for (k, &(i, j)) in kelvin_pairs(K).iter().enumerate() {
        if i == j {
            t[(i, i)] = s[k];
        } else {
            let v = s[k] / std::f64::consts::SQRT_2;
            t[(i, j)] = v;
            t[(j, i)] = v;
        }
    }
    t
}

/// Signed volume of a simplex (D = 2 or 3) and its longest edge.
fn signed_volume<const D: usize>(c: &[Point<D>]) -> f64 {
    let e = |i: usize, a: usize| c[i][a] - c[0][a];
    if D == 2 {
        0.5 * (e(1, 0) * e(2, 1) - e(1, 1) * e(2, 0))
    } else {
        let (a, b, d) = (1, 2, 3);
        (e(a, 0) * (e(b, 1) * e(d, 2) - e(b, 2) * e(d, 1))
            - e(a, 1) * (e(b, 0) * e(d, 2) - e(b, 2) * e(d, 0))
            + e(a, 2) * (e(b, 0) * e(d, 1) - e(b, 1) * e(d, 0)))
            / 6.0
    }
}

/// Inverse by Gauss–Jordan elimination with partial pivoting; `None` if singular
/// relative to the largest entry.
pub(crate) fn invert<const K: usize>(m: &SMatrix<f64, K, K>) -> Option<SMatrix<f64, K, K>> {
    let mut a = *m;
    let mut inv = SMatrix::<f64, K, K>::identity();
    let scale = a.amax();
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    for col in 0..K {
        let mut p = col;
        for r in col + 1..K {
            if a[(r, col)].abs() > a[(p, col)].abs() {
                p = r;
            }
        }
        let piv = a[(p, col)];
        if piv.abs() <= 1e-14 * scale {
            return None;
        }
        a.swap_rows(col, p);
        inv.swap_rows(col, p);
        let r = 1.0 / piv;
        for j in 0..K {
            a[(col, j)] *= r;
            inv[(col, j)] *= r;
        }
        for i in 0..K {
            if i != col {
                let f = a[(i, col)];
                if f != 0.0 {
                    for j in 0..K {
                        a[(i, j)] -= f * a[(col, j)];
                        inv[(i, j)] -= f * inv[(col, j)];
                    }
                }
            }
        }
    }
    Some(inv)
}

/// Edge geometry of one simplex, fixed size (`K` edges in `D` dimensions).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame<const D: usize, const K: usize> {
    /// Unit edge vectors `t_k`.
    pub t: [SVector<f64, D>; K],
    /// The edge map `M` (row `k` = `l_k Kelvin(t_k ⊗ t_k)`).
    pub m: SMatrix<f64, K, K>,
    /// `M⁻¹`.
    pub minv: SMatrix<f64, K, K>,
    /// Volume `|K|` (positive).
    pub volume: f64,
}

impl<const D: usize, const K: usize> Frame<D, K> {
    /// Build the frame; `coords` must hold `D + 1` points and `K = D(D+1)/2`.
    pub fn new(coords: &[Point<D>]) -> Result<Self, MdemError> {
        debug_assert_eq!(K, kelvin_size(D));
        if coords.len() != D + 1 {
            return Err(MdemError::NotASimplex {
                got: coords.len(),
                expected: D + 1,
            });
        }
        let mut t = [SVector::<f64, D>::zeros(); K];
        let mut m = SMatrix::<f64, K, K>::zeros();
        let mut lmax = 0.0_f64;
        for (k, &(a, b)) in edges(D).iter().enumerate() {
            let dx = coords[b] - coords[a];
            let l = dx.norm();
            lmax = lmax.max(l);
            if !(l.is_finite() && l > 0.0) {
                return Err(MdemError::Degenerate {
                    volume: 0.0,
                    scale: l,
                });
            }
            t[k] = dx / l;
            m.set_row(k, &(kelvin_outer::<D, K>(&t[k]) * l).transpose());
        }
        let volume = signed_volume(coords).abs();
        let bad = MdemError::Degenerate {
            volume,
            scale: lmax,
        };
        if volume.is_nan() || volume <= DEGENERATE * lmax.powi(D as i32) {
            return Err(bad);
        }
        let minv = invert(&m).ok_or(bad)?;
        Ok(Self { t, m, minv, volume })
    }

    /// Edge elongations `U = R u`.
    #[inline]
    pub fn elongations(&self, u: &[f64]) -> SVector<f64, K> {
        let mut du = SVector::<f64, K>::zeros();
        for (k, &(a, b)) in edges(D).iter().enumerate() {
            let mut s = 0.0;
            for c in 0..D {
                s += self.t[k][c] * (u[D * b + c] - u[D * a + c]);
            }
            du[k] = s;
        }
        du
    }

    /// MDEM edge stiffness `𝐊 = |K| M⁻ᵀ D M⁻¹`, symmetrised.
    #[inline]
    pub fn edge_stiffness(&self, d: &SMatrix<f64, K, K>) -> SMatrix<f64, K, K> {
        let k = self.minv.transpose() * d * self.minv * self.volume;
        (k + k.transpose()) * 0.5
    }

    /// Nodal forces `f = −Rᵀ F` for edge forces `F`.
    #[inline]
    pub fn nodal_forces(&self, f_edge: &SVector<f64, K>, out: &mut [f64]) {
        out.fill(0.0);
        for (k, &(a, b)) in edges(D).iter().enumerate() {
            for c in 0..D {
                let v = f_edge[k] * self.t[k][c];
                out[D * a + c] += v;
                out[D * b + c] -= v;
            }
        }
    }

    /// Local stiffness `Rᵀ 𝐊 R` written into `out` (`D(D+1)` square, already sized).
    ///
    /// With `A_p = Σ_k s_pk t_k e_kᵀ` (`D × K`; `s_pk = −1` if node `p` is the start of
    /// edge `k`, `+1` if its end), block `(p, q)` is `A_p 𝐊 A_qᵀ`. `G_p = A_p 𝐊` is
    /// formed once per node; each entry of `out` is written once.
    #[inline]
    pub fn nodal_stiffness(&self, kmat: &SMatrix<f64, K, K>, out: &mut DMatrix<f64>) {
        let e = edges(D);
        // G_p = A_p 𝐊 for the D + 1 ≤ 4 nodes.
        let mut g = [SMatrix::<f64, D, K>::zeros(); 4];
        for (k, &(a, b)) in e.iter().enumerate() {
            for l in 0..K {
                let c = kmat[(k, l)];
                for x in 0..D {
                    let v = c * self.t[k][x];
                    g[b][(x, l)] += v;
                    g[a][(x, l)] -= v;
                }
            }
        }
        for p in 0..=D {
            for q in p..=D {
                // block = G_p A_qᵀ = Σ_{l ∋ q} s_ql G_p[:, l] t_lᵀ.
                let mut blk = SMatrix::<f64, D, D>::zeros();
                for (l, &(a, b)) in e.iter().enumerate() {
                    let s = if b == q {
                        1.0
                    } else if a == q {
                        -1.0
                    } else {
                        continue;
                    };
                    for x in 0..D {
                        let v = s * g[p][(x, l)];
                        for y in 0..D {
                            blk[(x, y)] += v * self.t[l][y];
                        }
                    }
                }
                for x in 0..D {
                    for y in 0..D {
                        out[(D * p + x, D * q + y)] = blk[(x, y)];
                        out[(D * q + y, D * p + x)] = blk[(x, y)];
                    }
                }
            }
        }
    }
}

fn check_dim<const D: usize>() -> Result<usize, MdemError> {
    match D {
        2 | 3 => Ok(kelvin_size(D)),
        _ => Err(MdemError::UnsupportedDimension(D)),
    }
}

fn check_square(m: &DMatrix<f64>, k: usize) -> Result<(), MdemError> {
    if m.nrows() != k || m.ncols() != k {
        return Err(MdemError::MaterialShape {
            rows: m.nrows(),
            cols: m.ncols(),
            expected: k,
        });
    }
    Ok(())
}

fn to_fixed<const K: usize>(m: &DMatrix<f64>) -> SMatrix<f64, K, K> {
    SMatrix::<f64, K, K>::from_fn(|i, j| m[(i, j)])
}

fn to_dyn<const K: usize>(m: &SMatrix<f64, K, K>) -> DMatrix<f64> {
    DMatrix::from_fn(K, K, |i, j| m[(i, j)])
}

/// Dispatch a body on the Kelvin size of `D`, binding it to the const `K`.
macro_rules! with_k {
    ($d:ident, |$k:ident| $body:expr) => {
        match $d {
            2 => {
                const $k: usize = 3;
                $body
            }
            3 => {
                const $k: usize = 6;
                $body
            }
            _ => Err(MdemError::UnsupportedDimension($d)),
        }
    };
}
pub(crate) use with_k;

/// Volume (area in 2D) of a simplex; an error if it is not a non-degenerate simplex.
pub fn simplex_volume<const D: usize>(coords: &[Point<D>]) -> Result<f64, MdemError> {
    check_dim::<D>()?;
    with_k!(D, |K| Frame::<D, K>::new(coords).map(|f| f.volume))
}

/// The edge map `M` (`K × K`, Nilsen et al. (2017) eq. 15): `U = M ε` for the edges in
/// [`edges`] order.
pub fn edge_matrix<const D: usize>(coords: &[Point<D>]) -> Result<DMatrix<f64>, MdemError> {
    check_dim::<D>()?;
    with_k!(D, |K| Frame::<D, K>::new(coords).map(|f| to_dyn(&f.m)))
}

/// `𝒦⁻¹(C)`: the MDEM edge stiffness `𝐊 = |K| M⁻ᵀ C M⁻¹` of a simplex for the Kelvin
/// Cauchy stiffness `c` (Nilsen et al. (2017) eq. 21 with the volume factor).
pub fn edge_stiffness_from_cauchy<const D: usize>(
    coords: &[Point<D>],
    c: &DMatrix<f64>,
) -> Result<DMatrix<f64>, MdemError> {
    let k = check_dim::<D>()?;
    check_square(c, k)?;
    with_k!(D, |K| {
        let f = Frame::<D, K>::new(coords)?;
        Ok(to_dyn(&f.edge_stiffness(&to_fixed::<K>(c))))
    })
}

/// `𝒦(𝐊)`: the Cauchy stiffness `C = Mᵀ 𝐊 M / |K|` (Kelvin) that an edge stiffness
/// `𝐊` represents on a simplex (Nilsen et al. (2017) eq. 20 with the volume factor).
pub fn cauchy_from_edge_stiffness<const D: usize>(
    coords: &[Point<D>],
    kmat: &DMatrix<f64>,
) -> Result<DMatrix<f64>, MdemError> {
    let k = check_dim::<D>()?;
    check_square(kmat, k)?;
    with_k!(D, |K| {
        let f = Frame::<D, K>::new(coords)?;
        let c = f.m.transpose() * to_fixed::<K>(kmat) * f.m / f.volume;
        Ok(to_dyn(&c))
    })
}

/// The stiffness lost by keeping only the diagonal of the MDEM edge stiffness (seed
/// §3, Figure 3): `T = C − 𝒦(diag 𝒦⁻¹(C))`, in Kelvin form.
pub fn dem_stiffness_loss<const D: usize>(
    coords: &[Point<D>],
    c: &DMatrix<f64>,
) -> Result<DMatrix<f64>, MdemError> {
    let kmat = edge_stiffness_from_cauchy(coords, c)?;
    let kd = DMatrix::from_diagonal(&kmat.diagonal());
    Ok(c - cauchy_from_edge_stiffness(coords, &kd)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_of_random_matrix() {
        let m = SMatrix::<f64, 4, 4>::from_fn(|i, j| {
            ((i * 7 + j * 3) % 5) as f64 + (i == j) as u8 as f64 * 3.0
        });
        let inv = invert(&m).unwrap();
        let err = (m * inv - SMatrix::<f64, 4, 4>::identity()).amax();
        assert!(err < 1e-14, "{err}");
        assert!(invert(&SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 4.0)).is_none());
    }

    #[test]
    fn edge_map_of_right_triangle() {
        // Edges (0,1) along x (l=1), (0,2) along y (l=1), (1,2) along (-1,1)/√2 (l=√2).
        let c = [
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 0.0),
            Point::<2>::new(0.0, 1.0),
        ];
        let m = edge_matrix(&c).unwrap();
        let s2 = std::f64::consts::SQRT_2;
        let expect = DMatrix::from_row_slice(
            3,
            3,
            &[
                1.0,
                0.0,
                0.0,
                0.0,
                1.0,
                0.0,
                s2 * 0.5,
                s2 * 0.5,
                -s2 * s2 * 0.5,
            ],
        );
        assert!((m - expect).amax() < 1e-15);
        assert!((simplex_volume(&c).unwrap() - 0.5).abs() < 1e-15);
    }

    #[test]
    fn degenerate_and_non_simplex_are_errors() {
        let c = [
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 0.0),
            Point::<2>::new(2.0, 0.0),
        ];
        assert!(matches!(edge_matrix(&c), Err(MdemError::Degenerate { .. })));
        let c = [Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 0.0)];
        assert_eq!(
            edge_matrix(&c),
            Err(MdemError::NotASimplex {
                got: 2,
                expected: 3
            })
        );
        let c = [
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(0.0, 1.0),
        ];
        assert!(matches!(edge_matrix(&c), Err(MdemError::Degenerate { .. })));
    }
}
