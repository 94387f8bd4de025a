//! Elastic stiffness tensors in Kelvin form.
//!
//! Hooke's law `σ = C : ε` becomes `σ_K = D ε_K` with `D_kl = B_k : C : B_l` (see
//! [`crate::kelvin`]); the energy density is `W = ½ ε : C : ε = ½ ε_K · D ε_K`.
//!
//! * Isotropic: `σ = 2μ ε + λ tr(ε) I`, so `D = 2μ I_K + λ 𝟙 𝟙ᵀ` with `𝟙` the
//!   indicator of the normal components (in Kelvin form the shear diagonal is `2μ`, not
//!   the Voigt `μ`). From Young's modulus and Poisson's ratio,
//!   `λ = Eν/((1+ν)(1−2ν))`, `μ = E/(2(1+ν))`.
//! * 2D defaults to plane strain (the 3D law restricted to `ε_i3 = 0`, same `λ`, `μ`).
//!   Plane stress (`σ_i3 = 0`) replaces `λ` by `λ* = 2λμ/(λ+2μ)`.
//! * Anisotropic: any symmetric positive-definite `K × K` Kelvin matrix.
//!
//! Every constructor validates its input (finite values, `E > 0`, `−1 < ν < ½`, `μ > 0`,
//! positive bulk modulus, symmetry, and positive definiteness by a Cholesky
//! factorization) and returns a [`LawError`] naming the parameter or entry.

use nalgebra::{DMatrix, DMatrixView};

use crate::Tensor;
use crate::error::{LawError, Result};
use crate::kelvin::{Kelvin, KelvinMatrix, from_kelvin, kelvin_len, pair, to_kelvin};

/// Relative tolerance of the symmetry check of a user-given Kelvin matrix.
pub const SYMMETRY_TOL: f64 = 1e-12;

/// A linear elastic stiffness in Kelvin form (the `K × K` matrix `D`, `K` = 3 or 6).
#[derive(Clone, Debug, PartialEq)]
pub struct Stiffness<const D: usize> {
    m: KelvinMatrix,
    lame: Option<(f64, f64)>,
}

fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(LawError::InvalidParameter {
            name,
            value,
            reason: "must be finite",
        })
    }
}

/// `(λ, μ)` from `(E, ν)`, validated.
fn lame_from_young(e: f64, nu: f64) -> Result<(f64, f64)> {
    finite("E", e)?;
    finite("nu", nu)?;
    if e <= 0.0 {
        return Err(LawError::InvalidParameter {
            name: "E",
            value: e,
            reason: "Young's modulus must be positive",
        });
    }
    if nu >= 0.5 || nu <= -1.0 {
        return Err(LawError::InvalidParameter {
            name: "nu",
            value: nu,
            reason: "Poisson's ratio must lie in (-1, 0.5)",
        });
    }
    Ok((
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        e / (2.0 * (1.0 + nu)),
    ))
}

/// Validate Lamé parameters for a 3D-consistent material (μ > 0, 3λ + 2μ > 0).
fn check_lame(lambda: f64, mu: f64) -> Result<()> {
    finite("lambda", lambda)?;
    finite("mu", mu)?;
    if mu <= 0.0 {
        return Err(LawError::InvalidParameter {
            name: "mu",
            value: mu,
            reason: "shear modulus must be positive",
        });
    }
    if 3.0 * lambda + 2.0 * mu <= 0.0 {
        return Err(LawError::InvalidParameter {
            name: "lambda",
            value: lambda,
            reason: "bulk modulus lambda + 2 mu / 3 must be positive",
        });
    }
    Ok(())
}

impl<const D: usize> Stiffness<D> {
    /// Number of Kelvin components, `D(D+1)/2`.
    pub const K: usize = kelvin_len(D);

    /// Isotropic stiffness from Young's modulus `e` and Poisson's ratio `nu`; in 2D,
    /// plane strain. Errors if `e ≤ 0`, `nu ∉ (−1, ½)` or a value is not finite.
    pub fn isotropic(e: f64, nu: f64) -> Result<Self> {
        let (lambda, mu) = lame_from_young(e, nu)?;
        Self::from_lame(lambda, mu)
    }

    /// Isotropic stiffness from the Lamé parameters; in 2D, plane strain. Errors if
    /// `mu ≤ 0`, the bulk modulus `λ + 2μ/3 ≤ 0`, or a value is not finite.
    pub fn from_lame(lambda: f64, mu: f64) -> Result<Self> {
        check_lame(lambda, mu)?;
        Self::lame_unchecked(lambda, mu)
    }

    fn lame_unchecked(lambda: f64, mu: f64) -> Result<Self> {
        let mut m = KelvinMatrix::zeros();
        for k in 0..Self::K {
            m[(k, k)] = 2.0 * mu;
            if k < D {
                for l in 0..D {
                    m[(k, l)] += lambda;
                }
            }
        }
        let s = Self {
            m,
            lame: Some((lambda, mu)),
        };
        s.check_positive_definite()?;
        Ok(s)
    }

    /// A general (anisotropic) stiffness from its `K × K` Kelvin matrix.
    ///
    /// Checks the shape, finiteness, symmetry (relative tolerance [`SYMMETRY_TOL`] of the
    /// largest entry; the matrix is then symmetrized exactly) and positive definiteness.
    pub fn from_kelvin(m: DMatrixView<'_, f64>) -> Result<Self> {
        const WHAT: &str = "Kelvin stiffness matrix";
        let k = Self::K;
        if m.nrows() != k || m.ncols() != k {
            return Err(LawError::WrongSize {
                what: WHAT,
                expected: k,
                rows: m.nrows(),
                cols: m.ncols(),
            });
        }
        let mut scale: f64 = 0.0;
        for i in 0..k {
            for j in 0..k {
                let v = m[(i, j)];
                if !v.is_finite() {
                    return Err(LawError::NonFinite {
                        what: WHAT,
                        row: i,
                        col: j,
                        value: v,
                    });
                }
                scale = scale.max(v.abs());
            }
        }
        let mut out = KelvinMatrix::zeros();
        for i in 0..k {
            for j in 0..k {
                let (upper, lower) = (m[(i, j)], m[(j, i)]);
                if (upper - lower).abs() > SYMMETRY_TOL * scale {
                    return Err(LawError::NotSymmetric {
                        what: WHAT,
                        row: i,
                        col: j,
                        upper,
                        lower,
                    });
                }
                out[(i, j)] = 0.5 * (upper + lower);
            }
        }
        let s = Self { m: out, lame: None };
        s.check_positive_definite()?;
        Ok(s)
    }

    /// Like [`Self::from_kelvin`], from a row-major slice of `K²` numbers.
    pub fn from_kelvin_rows(rows: &[f64]) -> Result<Self> {
        let k = Self::K;
        if rows.len() != k * k {
            return Err(LawError::WrongSize {
                what: "Kelvin stiffness matrix (row-major slice)",
                expected: k,
                rows: rows.len() / k.max(1),
                cols: k,
            });
        }
        let m = DMatrix::from_row_slice(k, k, rows);
        Self::from_kelvin(m.as_view())
    }

    fn check_positive_definite(&self) -> Result<()> {
        let k = Self::K;
        let block = DMatrix::from_fn(k, k, |i, j| self.m[(i, j)]);
        if block.iter().all(|v| v.is_finite()) && nalgebra::Cholesky::new(block).is_some() {
            Ok(())
        } else {
            Err(LawError::NotPositiveDefinite {
                what: "stiffness matrix",
            })
        }
    }

    /// The Kelvin matrix (6 × 6; only the leading `K × K` block is non-zero).
    #[inline]
    pub fn kelvin(&self) -> &KelvinMatrix {
        &self.m
    }

    /// The leading `K × K` Kelvin block as a dynamic matrix.
    pub fn to_dmatrix(&self) -> DMatrix<f64> {
        DMatrix::from_fn(Self::K, Self::K, |i, j| self.m[(i, j)])
    }

    /// The Lamé parameters `(λ, μ)` of an isotropic stiffness (for 2D plane stress, the
    /// effective `λ*`), `None` for a general anisotropic one.
    #[inline]
    pub fn lame(&self) -> Option<(f64, f64)> {
        self.lame
    }

    /// Component `C_abcd` of the fourth-order elasticity tensor
    /// (`C_abcd = Σ_kl D_kl (B_k)_ab (B_l)_cd`). Indices must be `< D`.
    pub fn component(&self, a: usize, b: usize, c: usize, d: usize) -> f64 {
        let mut s = 0.0;
        for k in 0..Self::K {
            let bk = basis_entry::<D>(k, a, b);
            if bk == 0.0 {
                continue;
            }
            for l in 0..Self::K {
                s += self.m[(k, l)] * bk * basis_entry::<D>(l, c, d);
            }
        }
        s
    }

    /// The full fourth-order tensor as a flat array, entry `C_abcd` at
    /// `((a·3 + b)·3 + c)·3 + d` (3 × 3 × 3 × 3 slots; unused ones zero in 2D).
    pub fn tensor4(&self) -> [f64; 81] {
        let mut t = [0.0; 81];
        for a in 0..D {
            for b in 0..D {
                for c in 0..D {
                    for d in 0..D {
                        t[((a * 3 + b) * 3 + c) * 3 + d] = self.component(a, b, c, d);
                    }
                }
            }
        }
        t
    }

    /// Stress (Kelvin) of a Kelvin strain, `σ_K = D ε_K`.
    #[inline]
    pub fn stress_kelvin(&self, strain: &Kelvin) -> Kelvin {
        self.m * strain
    }

    /// Stress tensor of a strain tensor (the strain is symmetrized first).
    #[inline]
    pub fn stress(&self, strain: &Tensor<D>) -> Tensor<D> {
        from_kelvin::<D>(&self.stress_kelvin(&to_kelvin::<D>(strain)))
    }

    /// Energy density `½ ε : C : ε = ½ ε_K · D ε_K` of a strain tensor.
    #[inline]
    pub fn energy_density(&self, strain: &Tensor<D>) -> f64 {
        let e = to_kelvin::<D>(strain);
        0.5 * e.dot(&(self.m * e))
    }

    /// Largest eigenvalue of the Kelvin matrix (an upper bound on the modulus that
    /// enters stable explicit time steps; `λ + 2μ`-like for isotropic materials).
    pub fn max_eigenvalue(&self) -> f64 {
        self.to_dmatrix()
            .symmetric_eigenvalues()
            .iter()
            .fold(0.0_f64, |a, &b| a.max(b))
    }
}

impl Stiffness<2> {
    /// 2D plane-stress isotropic stiffness from `E` and `ν` (`λ* = 2λμ/(λ+2μ)`).
    pub fn isotropic_plane_stress(e: f64, nu: f64) -> Result<Self> {
        let (lambda, mu) = lame_from_young(e, nu)?;
        Self::from_lame_plane_stress(lambda, mu)
    }

    /// 2D plane-stress isotropic stiffness from the 3D Lamé parameters
    /// (`λ* = 2λμ/(λ+2μ)`, same `μ`).
    pub fn from_lame_plane_stress(lambda: f64, mu: f64) -> Result<Self> {
        check_lame(lambda, mu)?;
        Self::lame_unchecked(2.0 * lambda * mu / (lambda + 2.0 * mu), mu)
    }
}

/// Entry `(a, b)` of the Kelvin basis tensor `B_k`.
#[inline]
fn basis_entry<const D: usize>(k: usize, a: usize, b: usize) -> f64 {
    let (p, q) = pair::<D>(k);
    if p == q {
        if a == p && b == p { 1.0 } else { 0.0 }
    } else if (a == p && b == q) || (a == q && b == p) {
        std::f64::consts::FRAC_1_SQRT_2
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isotropic_3d_matches_lame_form() {
        let s = Stiffness::<3>::isotropic(1.0, 0.3).unwrap();
        let (l, m) = s.lame().unwrap();
        assert!((l - 0.3 / (1.3 * 0.4)).abs() < 1e-15);
        assert!((m - 1.0 / 2.6).abs() < 1e-15);
        let k = s.kelvin();
        assert!((k[(0, 0)] - (l + 2.0 * m)).abs() < 1e-15);
        assert!((k[(0, 2)] - l).abs() < 1e-15);
        assert!((k[(3, 3)] - 2.0 * m).abs() < 1e-15);
        assert_eq!(k[(3, 4)], 0.0);
        // σ = 2με + λ tr(ε) I on a general strain.
        let e = Tensor::<3>::new(1e-3, 2e-4, -3e-4, 2e-4, -5e-4, 7e-4, -3e-4, 7e-4, 4e-4);
        let expect = e * (2.0 * m) + Tensor::<3>::identity() * (l * e.trace());
        assert!((s.stress(&e) - expect).amax() < 1e-17);
        let w = 0.5 * e.component_mul(&expect).sum();
        assert!((s.energy_density(&e) - w).abs() < 1e-20);
        // C_1212 = μ, C_1122 = λ.
        assert!((s.component(0, 1, 0, 1) - m).abs() < 1e-15);
        assert!((s.component(0, 0, 1, 1) - l).abs() < 1e-15);
        assert!((s.max_eigenvalue() - (3.0 * l + 2.0 * m)).abs() < 1e-12);
    }

    #[test]
    fn plane_strain_and_plane_stress_2d() {
        let s = Stiffness::<2>::isotropic(1.0, 0.3).unwrap();
        let k = s.kelvin();
        // Plane strain: D11 = E(1−ν)/((1+ν)(1−2ν)), D12 = Eν/((1+ν)(1−2ν)), D33 = E/(1+ν).
        assert!((k[(0, 0)] - 0.7 / (1.3 * 0.4)).abs() < 1e-15);
        assert!((k[(0, 1)] - 0.3 / (1.3 * 0.4)).abs() < 1e-15);
        assert!((k[(2, 2)] - 1.0 / 1.3).abs() < 1e-15);
        assert_eq!(k[(3, 3)], 0.0);
        // Plane stress: D11 = E/(1−ν²), D12 = Eν/(1−ν²), D33 = E/(1+ν).
        let p = Stiffness::<2>::isotropic_plane_stress(1.0, 0.3).unwrap();
        let k = p.kelvin();
        assert!((k[(0, 0)] - 1.0 / 0.91).abs() < 1e-14);
        assert!((k[(0, 1)] - 0.3 / 0.91).abs() < 1e-14);
        assert!((k[(2, 2)] - 1.0 / 1.3).abs() < 1e-15);
    }

    #[test]
    fn invalid_parameters_are_named() {
        let cases: [(f64, f64, &str); 6] = [
            (1.0, 0.5, "nu"),
            (1.0, -1.0, "nu"),
            (0.0, 0.3, "E"),
            (-2.0, 0.3, "E"),
            (f64::NAN, 0.3, "E"),
            (1.0, f64::INFINITY, "nu"),
        ];
        for (e, nu, name) in cases {
            match Stiffness::<3>::isotropic(e, nu) {
                Err(LawError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
                other => panic!("({e}, {nu}) gave {other:?}"),
            }
        }
        assert!(matches!(
            Stiffness::<2>::from_lame(1.0, 0.0),
            Err(LawError::InvalidParameter { name: "mu", .. })
        ));
        assert!(matches!(
            Stiffness::<3>::from_lame(-1.0, 1.0),
            Err(LawError::InvalidParameter { name: "lambda", .. })
        ));
        let msg = Stiffness::<3>::isotropic(1.0, 0.7).unwrap_err().to_string();
        assert!(msg.contains("nu = 0.7"), "{msg}");
    }

    #[test]
    fn anisotropic_checks() {
        let ok = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let s = Stiffness::<2>::from_kelvin_rows(&ok).unwrap();
        assert_eq!(s.lame(), None);
        assert_eq!(s.kelvin()[(0, 2)], 0.5);
        let mut bad = ok;
        bad[1] = 1.1;
        assert!(matches!(
            Stiffness::<2>::from_kelvin_rows(&bad),
            Err(LawError::NotSymmetric { row: 0, col: 1, .. })
        ));
        // Symmetric but indefinite: eigenvalues of [[1,2],[2,1]] are 3, −1.
        let indef = [1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        assert!(matches!(
            Stiffness::<2>::from_kelvin_rows(&indef),
            Err(LawError::NotPositiveDefinite { .. })
        ));
        let mut nan = ok;
        nan[4] = f64::NAN;
        assert!(matches!(
            Stiffness::<2>::from_kelvin_rows(&nan),
            Err(LawError::NonFinite { row: 1, col: 1, .. })
        ));
        assert!(matches!(
            Stiffness::<3>::from_kelvin_rows(&ok),
            Err(LawError::WrongSize { expected: 6, .. })
        ));
        // The tensor form reproduces D ε for the anisotropic matrix.
        let e = nalgebra::Matrix2::new(1.0, 0.25, 0.25, -0.5);
        let sig = s.stress(&e);
        for a in 0..2 {
            for b in 0..2 {
                let mut v = 0.0;
                for c in 0..2 {
                    for d in 0..2 {
                        v += s.component(a, b, c, d) * e[(c, d)];
                    }
                }
                assert!((v - sig[(a, b)]).abs() < 1e-14);
            }
        }
    }
}
