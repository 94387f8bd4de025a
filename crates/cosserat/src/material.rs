//! Isotropic Cosserat law, eqs. (2)–(3) and (25)–(26), in one dimension-generic form.
//!
//! Unknowns are *generalised components* `a = 0 … n−1`, `n = D + R`: the displacement
//! `u_a` for `a < D` and the micro-rotation `φ_{a−D}` for `a ≥ D` (`R = 1` in 2D, where
//! the one rotation is `φ_3`; `R = 3` in 3D). The generalised strain stacks
//!
//! ```text
//!   e_ij = ∂_j u_i + ε_ijk φ_k          (eq. 1; 2D: e12 = ∂2u1 + φ, e21 = ∂1u2 − φ)
//!   κ_kj = ∂_j φ_k
//! ```
//!
//! in one vector `s` with `e_ij` at [`strain_index`]`(i, j)` and `κ_kj` at
//! `strain_index(D + k, j)`, so that the gradient of component `a` in direction `j` is
//! always entry `strain_index(a, j)`. The law `Σ = A s` is block diagonal:
//!
//! ```text
//!   σ = λ tr(e) I + (G + Gc) e + (G − Gc) eᵀ
//!   m = L tr(κ) I + (M + Mc) κ + (M − Mc) κᵀ      (3D)
//!   m_3j = (M + Mc) κ_3j = 4 G ℓ² ∂_j φ          (2D, eq. 26)
//! ```
//!
//! A characteristic length `ℓ` stands for `L = 0`, `M = Mc = 2 G ℓ²` (so that
//! `M + Mc = 4 G ℓ²` in 2D and 3D alike); in 3D the three couple moduli may be given
//! instead. Tractions are `(Σ n)_a = Σ_j Σ[strain_index(a, j)] n_j`, and the penalty
//! weight of a jump `w` across a facet of normal `n` is `(w ⊗ n) : A : (w ⊗ n) = wᵀ Q(n) w`
//! ([`Material::acoustic`]), e.g. `(λ + G − Gc)(w·n)² + (G + Gc)|w|²` for displacements.

use nalgebra::DMatrix;

use crate::error::{CosseratError, Result};

/// Number of rotation components in dimension `d`: 1 in 2D, 3 in 3D.
pub const fn rotations(d: usize) -> usize {
    if d == 2 { 1 } else { 3 }
}

/// Generalised components per cell (`D + R`): 3 in 2D, 6 in 3D.
pub const fn components(d: usize) -> usize {
    d + rotations(d)
}

/// Length of the generalised strain vector `s`: `D² + R·D` (6 in 2D, 18 in 3D).
pub const fn strain_len(d: usize) -> usize {
    components(d) * d
}

/// Position of `∂_j w_a` (plus the rotation coupling for `a < D`) in the strain vector.
#[inline]
pub const fn strain_index(d: usize, a: usize, j: usize) -> usize {
    a * d + j
}

/// The permutation symbol `ε_ijk` with `k` a *rotation* component: in 2D the only rotation
/// is about `z`, so `k = 0` stands for axis 2.
#[inline]
pub fn levi_civita(d: usize, i: usize, j: usize, k: usize) -> f64 {
    let k = if d == 2 { 2 } else { k };
    match (i, j, k) {
        (0, 1, 2) | (1, 2, 0) | (2, 0, 1) => 1.0,
        (1, 0, 2) | (2, 1, 0) | (0, 2, 1) => -1.0,
        _ => 0.0,
    }
}

/// Isotropic Cosserat moduli (Pa and N) with the inertia of the dynamics.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Lamé's first parameter λ (Pa).
    pub lambda: f64,
    /// Shear modulus G (Pa).
    pub shear: f64,
    /// Cosserat coupling modulus Gc (Pa); 0 decouples the rotation from the displacement.
    pub coupling: f64,
    /// Couple moduli `[L, M, Mc]` (N; only `M + Mc` matters in 2D).
    pub couple: [f64; 3],
    /// Density ρ (kg/m³).
    pub density: f64,
    /// Rotational inertia per unit mass j (m²).
    pub micro_inertia: f64,
}

fn check(name: &'static str, value: f64, positive: bool) -> Result<()> {
    if !value.is_finite() {
        return Err(CosseratError::Material {
            name,
            value,
            reason: "must be finite",
        });
    }
    if positive && value <= 0.0 {
        return Err(CosseratError::Material {
            name,
            value,
            reason: "must be positive",
        });
    }
    if value < 0.0 {
        return Err(CosseratError::Material {
            name,
            value,
            reason: "must not be negative",
        });
    }
    Ok(())
}

impl Material {
    /// A material from `G`, `ν`, `Gc` and the characteristic length `ℓ` (eqs. 25–26):
    /// `λ = 2Gν/(1−2ν)`, `L = 0`, `M = Mc = 2Gℓ²`. Density 1, micro-inertia `ℓ²`.
    ///
    /// Errors name the parameter: `G ≤ 0`, `ν ∉ (−1, ½)`, `Gc < 0`, `ℓ ≤ 0`.
    pub fn with_length(shear: f64, poisson: f64, coupling: f64, length: f64) -> Result<Self> {
        check("shear_modulus", shear, true)?;
        check("cosserat_shear_modulus", coupling, false)?;
        check("characteristic_length", length, true)?;
        if !(poisson > -1.0 && poisson < 0.5) {
            return Err(CosseratError::Material {
                name: "poisson_ratio",
                value: poisson,
                reason: "must lie in (-1, 0.5)",
            });
        }
        let m = 2.0 * shear * length * length;
        Ok(Self {
            lambda: 2.0 * shear * poisson / (1.0 - 2.0 * poisson),
            shear,
            coupling,
            couple: [0.0, m, m],
            density: 1.0,
            micro_inertia: length * length,
        })
    }

    /// A material from `G`, `ν`, `Gc` and the couple moduli `[L, M, Mc]` (3D).
    ///
    /// Errors name the parameter; `M > 0` is required, `L, Mc ≥ 0`.
    pub fn with_couple_moduli(
        shear: f64,
        poisson: f64,
        coupling: f64,
        couple: [f64; 3],
    ) -> Result<Self> {
        let mut m = Self::with_length(shear, poisson, coupling, 1.0)?;
        check("couple_moduli[0] (L)", couple[0], false)?;
        check("couple_moduli[1] (M)", couple[1], true)?;
        check("couple_moduli[2] (Mc)", couple[2], false)?;
        m.couple = couple;
        m.micro_inertia = 0.0;
        Ok(m)
    }

    /// Set the density ρ and the micro-inertia j (errors name them: ρ ≤ 0, j < 0).
    pub fn with_inertia(mut self, density: f64, micro_inertia: f64) -> Result<Self> {
        check("density", density, true)?;
        check("micro_inertia", micro_inertia, false)?;
        self.density = density;
        self.micro_inertia = micro_inertia;
        Ok(self)
    }

    /// Poisson's ratio `ν = λ / (2(λ + G))`.
    pub fn poisson(&self) -> f64 {
        self.lambda / (2.0 * (self.lambda + self.shear))
    }

    /// The block-diagonal law matrix `A` (size [`strain_len`]`(d)`), `Σ = A s`.
    pub fn law_matrix(&self, d: usize) -> DMatrix<f64> {
        let s = strain_len(d);
        let mut a = DMatrix::zeros(s, s);
        let (g, gc) = (self.shear, self.coupling);
        let [l, m, mc] = self.couple;
        // Stress block: indices (i, j) of e, 0 ≤ i, j < d.
        for i in 0..d {
            for j in 0..d {
                let r = strain_index(d, i, j);
                a[(r, r)] += g + gc;
                a[(r, strain_index(d, j, i))] += g - gc;
                if i == j {
                    for kk in 0..d {
                        a[(r, strain_index(d, kk, kk))] += self.lambda;
                    }
                }
            }
        }
        // Couple block: κ_kj at strain_index(d, d + k, j).
        let r_count = rotations(d);
        if r_count == 1 {
            for j in 0..d {
                let r = strain_index(d, d, j);
                a[(r, r)] = m + mc;
            }
        } else {
            for k in 0..3 {
                for j in 0..3 {
                    let r = strain_index(d, d + k, j);
                    a[(r, r)] += m + mc;
                    a[(r, strain_index(d, d + j, k))] += m - mc;
                    if k == j {
                        for kk in 0..3 {
                            a[(r, strain_index(d, d + kk, kk))] += l;
                        }
                    }
                }
            }
        }
        a
    }

    /// `Q(n)_{ab} = Σ_{jl} n_j A[(a,j),(b,l)] n_l`: the weight of a jump `w` across a facet
    /// of unit normal `n` in the interior penalty (17), `(w ⊗ n):A:(w ⊗ n) = wᵀ Q w`.
    pub fn acoustic(law: &DMatrix<f64>, d: usize, n: &[f64]) -> DMatrix<f64> {
        let c = components(d);
        DMatrix::from_fn(c, c, |a, b| {
            let mut q = 0.0;
            for j in 0..d {
                for l in 0..d {
                    q += n[j] * law[(strain_index(d, a, j), strain_index(d, b, l))] * n[l];
                }
            }
            q
        })
    }

    /// Wave speeds `(c_p, c_s)` of the Cauchy part, `√((λ+2G)/ρ)` and `√(G/ρ)`.
    pub fn wave_speeds(&self) -> (f64, f64) {
        (
            ((self.lambda + 2.0 * self.shear) / self.density).sqrt(),
            (self.shear / self.density).sqrt(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 2D law in the Providas–Kattis form (25): σ = G·[[2(1−ν)/(1−2ν), 2ν/(1−2ν), 0, 0],
    /// …, [0, 0, 1+a, 1−a], [0, 0, 1−a, 1+a]] on (e11, e22, e12, e21).
    #[test]
    fn two_d_law_matches_eq_25() {
        let (g, nu, gc) = (1000.0, 0.25, 500.0);
        let m = Material::with_length(g, nu, gc, 0.1).unwrap();
        let a = m.law_matrix(2);
        let idx = [
            strain_index(2, 0, 0),
            strain_index(2, 1, 1),
            strain_index(2, 0, 1),
            strain_index(2, 1, 0),
        ];
        let r = gc / g;
        let want = [
            [
                2.0 * (1.0 - nu) / (1.0 - 2.0 * nu),
                2.0 * nu / (1.0 - 2.0 * nu),
                0.0,
                0.0,
            ],
            [
                2.0 * nu / (1.0 - 2.0 * nu),
                2.0 * (1.0 - nu) / (1.0 - 2.0 * nu),
                0.0,
                0.0,
            ],
            [0.0, 0.0, 1.0 + r, 1.0 - r],
            [0.0, 0.0, 1.0 - r, 1.0 + r],
        ];
        for p in 0..4 {
            for q in 0..4 {
                assert!((a[(idx[p], idx[q])] - g * want[p][q]).abs() < 1e-9 * g);
            }
        }
        let s = strain_index(2, 2, 0);
        assert!((a[(s, s)] - 4.0 * g * 0.01).abs() < 1e-12);
    }

    /// `(w⊗n):C:(w⊗n) = (λ+G−Gc)(w·n)² + (G+Gc)|w|²` (the law-weighted interior penalty of
    /// Marazzato (2021) eq. 17).
    #[test]
    fn acoustic_tensor_closed_form() {
        let m = Material::with_couple_moduli(10.0, 0.3, 4.0, [1.0, 2.0, 0.5]).unwrap();
        let law = m.law_matrix(3);
        let n = [0.48, 0.6, 0.64];
        let q = Material::acoustic(&law, 3, &n);
        let w = [0.3, -1.2, 0.7];
        let wn: f64 = (0..3).map(|i| w[i] * n[i]).sum();
        let ww: f64 = w.iter().map(|x| x * x).sum();
        let mut got = 0.0;
        for a in 0..3 {
            for b in 0..3 {
                got += w[a] * q[(a, b)] * w[b];
            }
        }
        let want = (m.lambda + m.shear - m.coupling) * wn * wn + (m.shear + m.coupling) * ww;
        assert!((got - want).abs() < 1e-12 * want);
        // Rotation block: (L + M − Mc)(ψ·n)² + (M + Mc)|ψ|².
        let mut got = 0.0;
        for a in 0..3 {
            for b in 0..3 {
                got += w[a] * q[(3 + a, 3 + b)] * w[b];
            }
        }
        let want = (1.0 + 2.0 - 0.5) * wn * wn + 2.5 * ww;
        assert!((got - want).abs() < 1e-12 * want);
    }

    #[test]
    fn bad_parameters_name_the_key() {
        let e = Material::with_length(1.0, 0.3, -1.0, 0.1).unwrap_err();
        assert!(e.to_string().contains("cosserat_shear_modulus"));
        let e = Material::with_length(1.0, 0.3, 1.0, 0.0).unwrap_err();
        assert!(e.to_string().contains("characteristic_length"));
        let e = Material::with_length(1.0, 0.5, 1.0, 0.1).unwrap_err();
        assert!(e.to_string().contains("poisson_ratio"));
        let e = Material::with_length(-1.0, 0.3, 1.0, 0.1).unwrap_err();
        assert!(e.to_string().contains("shear_modulus"));
    }
}
