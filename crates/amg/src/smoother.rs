//! The spectral-radius estimate and the Chebyshev smoother.
//!
//! # Estimating ρ(D⁻¹A)
//!
//! `D⁻¹A` is similar to the symmetric `S = D^{-1/2} A D^{-1/2}`, so its eigenvalues are
//! real and positive for SPD `A`. A few steps of the Lanczos process on `S` from a fixed
//! pseudo-random start vector give a tridiagonal `T_k` whose largest eigenvalue (a Ritz
//! value) approaches `λ_max(S)` from below much faster than the power method; ten or so
//! steps are usually within a percent or two. A Ritz value never exceeds `λ_max`; where
//! Lanczos fails (a non-finite or non-positive value) Gershgorin's bound
//! `max_i Σ_j |a_ij| / √(a_ii a_jj)` (an upper bound, exact for some matrices) stands in.
//!
//! # Chebyshev smoothing
//!
//! A polynomial smoother of degree `k` updates `x ← x + p(D⁻¹A) D⁻¹ (b − A x)`, so the
//! error is multiplied by `q(D⁻¹A)` with `q(λ) = 1 − λ p(λ)`, `q(0) = 1`. The Chebyshev
//! choice minimises `max |q|` over an interval `[α, β]`:
//!
//! ```text
//!   q(λ) = T_k((β + α − 2λ)/(β − α)) / T_k((β + α)/(β − α)),
//! ```
//!
//! with `T_k` the Chebyshev polynomial of the first kind. For smoothing, `[α, β]` covers
//! the upper part of the spectrum, `β = c_hi ρ̂` slightly above the estimate `ρ̂` (so the
//! whole spectrum lies below it) and `α = β / r` with a ratio `r` of 10–30: the
//! high-frequency error (large `λ`) is damped by `1/T_k((β+α)/(β−α))`, the smooth error
//! (small `λ`) is left to the coarse grid. The three-term recurrence (`θ = (β+α)/2`,
//! `δ = (β−α)/2`, `σ = θ/δ`):
//!
//! ```text
//!   r₀ = b − A x₀,  d₀ = D⁻¹ r₀ / θ,  x₁ = x₀ + d₀,  ρ₀ = 1/σ,
//!   r_j = r_{j−1} − A d_{j−1},  ρ_j = 1/(2σ − ρ_{j−1}),
//!   d_j = ρ_j ρ_{j−1} d_{j−1} + (2ρ_j/δ) D⁻¹ r_j,  x_{j+1} = x_j + d_j.
//! ```
//!
//! `q(D⁻¹A)` is self-adjoint in the `A` inner product, so using the same polynomial before
//! and after the coarse correction makes the V-cycle a symmetric operator; with `β` above
//! the spectrum `|q| < 1`, and the cycle is positive definite — a valid CG preconditioner.

use nalgebra::DMatrix;

use rayon::prelude::*;

use crate::csr::{CsrMatrix, par_rows, par_rows_sum, zeros};
use crate::upper::RowProducts;

/// A pseudo-random number in `[-0.5, 0.5)` from an index (splitmix64).
fn hash_unit(i: usize) -> f64 {
    let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

/// Gershgorin bound on `λ_max(D^{-1/2} A D^{-1/2})`; `s = √(1/a_ii)`.
fn gershgorin(a: &CsrMatrix, s: &[f64]) -> f64 {
    let mut rows = zeros(a.nrows());
    par_rows(&mut rows, |i, ri| {
        let mut sum = 0.0;
        a.for_each_in_row(i, |j, v| sum += v.abs() * s[j as usize]);
        *ri = s[i] * sum;
    });
    rows.par_iter().copied().reduce(|| 0.0, f64::max)
}

/// Estimate `ρ(D⁻¹A)` by `steps` Lanczos steps (Gershgorin's bound where Lanczos fails).
///
/// Lanczos on the symmetric `S A S` (`S = D^{-1/2}`) with vectors `v = S⁻¹ q` is Lanczos on
/// `D⁻¹A` in the `D` inner product `⟨x, y⟩_D = Σ a_ii x_i y_i`, which needs no `S` in the
/// loop: `w = D⁻¹A q_j − β_j q_{j−1}`, `α_j = ⟨w, q_j⟩_D`, `w ← w − α_j q_j`,
/// `β_{j+1} = ‖w‖_D`, `q_{j+1} = w / β_{j+1}`. Each step is two passes: the product with
/// `α_j` summed alongside, and the update with `‖w‖_D²` summed alongside. The division by
/// `β` is folded into the next step as a scale of the stored vector.
/// The products go through `op` (the matrix `a` itself or its upper triangle); Gershgorin's
/// bound reads `a`.
pub(crate) fn spectral_radius<P: RowProducts>(
    a: &CsrMatrix,
    op: &P,
    dinv: &[f64],
    steps: usize,
) -> f64 {
    let n = a.nrows();
    let s: Vec<f64> = dinv.par_iter().map(|d| d.sqrt()).collect();
    if n <= 1 {
        return gershgorin(a, &s);
    }
    // q₀ = S v₀ with v₀ a unit random vector (‖q₀‖_D = ‖v₀‖).
    let mut q = zeros(n);
    let v_norm2 = par_rows_sum(&mut q, |i, qi| {
        let v = hash_unit(i);
        *qi = s[i] * v;
        v * v
    });
    drop(s);
    let mut q_scale = 1.0 / v_norm2.sqrt();
    let mut q_prev = zeros(n);
    let mut prev_scale = 0.0;
    let mut w = zeros(n);
    let mut alpha = Vec::with_capacity(steps);
    let mut beta: Vec<f64> = Vec::with_capacity(steps);
    for j in 0..steps.min(n) {
        let bj = if j > 0 { beta[j - 1] } else { 0.0 };
        let (qs, ps) = (q_scale, bj * prev_scale);
        let (qq, qp): (&[f64], &[f64]) = (&q, &q_prev);
        let aj = op.products_sum(qq, &mut w, |i, aq, wi| {
            *wi = dinv[i] * aq * qs - ps * qp[i];
            *wi * qq[i] * qs / dinv[i]
        });
        alpha.push(aj);
        let bn = par_rows_sum(&mut w, |i, wi| {
            *wi -= aj * qs * qq[i];
            *wi * *wi / dinv[i]
        })
        .sqrt();
        if bn.is_nan() || bn <= 1e-12 * aj.abs() || j + 1 == steps.min(n) {
            break;
        }
        beta.push(bn);
        // q_{j−1} ← q_j, q_j ← w / β (stored unscaled), w ← the old q_{j−1}'s storage.
        std::mem::swap(&mut q_prev, &mut q);
        std::mem::swap(&mut q, &mut w);
        prev_scale = q_scale;
        q_scale = 1.0 / bn;
    }
    // A Ritz value never exceeds λ_max ≤ the Gershgorin bound, so the bound (a pass over
    // the matrix) is needed only where Lanczos failed.
    let ritz = largest_ritz_value(&alpha, &beta);
    if ritz.is_finite() && ritz > 0.0 {
        ritz
    } else {
        let s: Vec<f64> = dinv.par_iter().map(|d| d.sqrt()).collect();
        gershgorin(a, &s)
    }
}

/// A Chebyshev smoother on `D⁻¹A` over the interval `[lo, hi]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Chebyshev {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    pub(crate) degree: usize,
}

/// Work vectors of a smoothing sweep.
pub(crate) struct SmoothWork<'a> {
    pub(crate) r: &'a mut [f64],
    pub(crate) d: &'a mut Vec<f64>,
    pub(crate) dn: &'a mut Vec<f64>,
}

impl Chebyshev {
    /// `x ← x + p(D⁻¹A) D⁻¹ (b − A x)` (from `x = 0` when `x_zero`). With `residual`,
    /// `w.r` holds `b − A x` for the returned `x` and the result is `None`; without it the
    /// result is `Some(bᵀx)` for the returned `x`, summed in the last pass (the
    /// post-smoother of the finest level gives CG its `rᵀz` this way).
    ///
    /// Each update of `x` is folded into the pass of the next product, and `r₀ = b` is
    /// read from `b` when `x = 0`; a residual no later step needs is not stored, nor the
    /// last `d`. Degree 2 from `x = 0` with the residual (the pre-smoother) streams 12
    /// vectors besides the two products, from a given `x` without it (the post-smoother)
    /// 10 with `bᵀx` (11 and a separate dot product of 2 before).
    pub(crate) fn smooth<P: RowProducts>(
        &self,
        a: &P,
        dinv: &[f64],
        b: &[f64],
        x: &mut [f64],
        x_zero: bool,
        residual: bool,
        w: SmoothWork<'_>,
    ) -> Option<f64> {
        let SmoothWork { r, d, dn } = w;
        let theta = 0.5 * (self.hi + self.lo);
        let delta = 0.5 * (self.hi - self.lo);
        let sigma = theta / delta;
        // d₀ = D⁻¹ r₀ / θ; r holds r₀ unless x = 0 (then r₀ = b). x₁ = x₀ + d₀ is pending.
        if x_zero {
            par_rows(d, |i, di| *di = dinv[i] * b[i] / theta);
        } else {
            a.products2(x, r, d, |i, ax, ri, di| {
                *ri = b[i] - ax;
                *di = dinv[i] * *ri / theta;
            });
        }
        let r0 = |i: usize, r: f64| if x_zero { b[i] } else { r };
        if self.degree <= 1 {
            let dd: &[f64] = d;
            if residual {
                if x_zero {
                    x.copy_from_slice(dd);
                } else {
                    par_rows(x, |i, xi| *xi += dd[i]);
                }
                a.products(dd, r, |i, ad, ri| *ri = r0(i, *ri) - ad);
                return None;
            }
            if x_zero {
                x.copy_from_slice(dd);
                return Some(crate::csr::dot(b, x));
            }
            return Some(par_rows_sum(x, |i, xi| {
                *xi += dd[i];
                b[i] * *xi
            }));
        }
        let mut rho = 1.0 / sigma;
        let mut bx = None;
        for step in 1..self.degree {
            let rho_n = 1.0 / (2.0 * sigma - rho);
            let c1 = rho_n * rho;
            let c2 = 2.0 * rho_n / delta;
            let dd: &[f64] = d;
            let first = step == 1;
            // r_j = r_{j−1} − A d_{j−1}, d_j = c₁ d_{j−1} + c₂ D⁻¹ r_j, x_{j+1} = x_j + d_j
            // (x_j = x₀ + d₀ still pending on the first step, x₀ = 0 when x_zero).
            let new_x = |i: usize, xi: f64, dni: f64| {
                if first && x_zero {
                    dd[i] + dni
                } else if first {
                    xi + (dd[i] + dni)
                } else {
                    xi + dni
                }
            };
            if residual || step + 1 < self.degree {
                a.products3(dd, r, dn, x, |i, ad, ri, dni, xi| {
                    *ri = if first { r0(i, *ri) } else { *ri } - ad;
                    *dni = c1 * dd[i] + c2 * dinv[i] * *ri;
                    *xi = new_x(i, *xi, *dni);
                });
            } else {
                // The last step: neither r_j nor d_j is needed after it.
                let rr: &[f64] = r;
                bx = Some(a.products_sum(dd, x, |i, ad, xi| {
                    let r_prev = if first { r0(i, rr[i]) } else { rr[i] };
                    let dni = c1 * dd[i] + c2 * dinv[i] * (r_prev - ad);
                    *xi = new_x(i, *xi, dni);
                    b[i] * *xi
                }));
            }
            std::mem::swap(d, dn);
            rho = rho_n;
        }
        if residual {
            let dd: &[f64] = d;
            a.products(dd, r, |_, ad, ri| *ri -= ad);
        }
        bx
    }
}

/// The largest eigenvalue of the symmetric tridiagonal Lanczos matrix with diagonal
/// `alpha` and off-diagonal `beta` (`beta.len() ≥ alpha.len() − 1`): the largest Ritz
/// value, a lower bound of `λ_max` that Lanczos steps raise towards it. NaN when the
/// entries are not finite.
pub fn largest_ritz_value(alpha: &[f64], beta: &[f64]) -> f64 {
    let k = alpha.len();
    let t = DMatrix::<f64>::from_fn(k, k, |i, j| {
        if i == j {
            alpha[i]
        } else if i + 1 == j {
            beta[i]
        } else if j + 1 == i {
            beta[j]
        } else {
            0.0
        }
    });
    t.symmetric_eigenvalues().max()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csr::SymCsr;

    fn laplace_1d(n: usize) -> SymCsr {
        let mut cp = vec![0];
        let mut ri = vec![];
        let mut v = vec![];
        for c in 0..n {
            if c > 0 {
                ri.push(c - 1);
                v.push(-1.0);
            }
            ri.push(c);
            v.push(2.0);
            cp.push(ri.len());
        }
        SymCsr::from_upper_csc(n, &cp, &ri, &v).unwrap()
    }

    #[test]
    fn lanczos_estimate_of_the_1d_laplacian() {
        // D⁻¹A = A/2 has eigenvalues 1 − cos(kπ/(n+1)), the largest 1 + cos(π/(n+1)).
        let n = 200;
        let a = laplace_1d(n);
        let dinv = vec![0.5; n];
        let exact = 1.0 + (std::f64::consts::PI / (n as f64 + 1.0)).cos();
        let est = spectral_radius(a.matrix(), a.matrix(), &dinv, 12);
        assert!(est <= exact * (1.0 + 1e-12), "{est} > {exact}");
        // Gershgorin gives 2 (= 1 + 1, not attained); Lanczos lands within 2 %.
        assert!(est > 0.98 * exact, "{est} vs {exact}");
    }

    #[test]
    fn all_paths_give_the_same_sweep() {
        // From x = 0 (x_zero or an explicit zero), from a given x, with and without the
        // returned residual: the same polynomial, for degrees 1–4.
        let n = 300;
        let a = laplace_1d(n);
        let dinv = vec![0.5; n];
        let b: Vec<f64> = (0..n).map(|i| (0.37 * i as f64).sin()).collect();
        let x0: Vec<f64> = (0..n).map(|i| (0.11 * i as f64).cos()).collect();
        let run = |ch: &Chebyshev, x: &mut Vec<f64>, x_zero: bool, residual: bool| {
            let (mut r, mut d, mut dn) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            let w = SmoothWork {
                r: &mut r,
                d: &mut d,
                dn: &mut dn,
            };
            ch.smooth(a.matrix(), &dinv, &b, x, x_zero, residual, w);
            r
        };
        let close = |u: &[f64], v: &[f64]| u.iter().zip(v).all(|(p, q)| (p - q).abs() < 1e-13);
        for degree in 1..=4 {
            let ch = Chebyshev {
                lo: 0.2,
                hi: 2.1,
                degree,
            };
            // Reference: the explicit three-term recurrence of the module docs.
            let reference = |x: &mut Vec<f64>| {
                let (theta, delta) = (0.5 * (ch.hi + ch.lo), 0.5 * (ch.hi - ch.lo));
                let sigma = theta / delta;
                let mut ax = vec![0.0; n];
                a.mul(x, &mut ax).unwrap();
                let mut r: Vec<f64> = (0..n).map(|i| b[i] - ax[i]).collect();
                let mut d: Vec<f64> = (0..n).map(|i| dinv[i] * r[i] / theta).collect();
                let mut rho = 1.0 / sigma;
                for i in 0..n {
                    x[i] += d[i];
                }
                for _ in 1..degree {
                    let rho_n = 1.0 / (2.0 * sigma - rho);
                    a.mul(&d, &mut ax).unwrap();
                    for i in 0..n {
                        r[i] -= ax[i];
                        d[i] = rho_n * rho * d[i] + 2.0 * rho_n / delta * dinv[i] * r[i];
                        x[i] += d[i];
                    }
                    rho = rho_n;
                }
                a.mul(x, &mut ax).unwrap();
                (0..n).map(|i| b[i] - ax[i]).collect::<Vec<f64>>()
            };
            for (start, x_zero) in [
                (vec![0.0; n], true),
                (vec![0.0; n], false),
                (x0.clone(), false),
            ] {
                let mut want = start.clone();
                let want_r = reference(&mut want);
                let mut x = if x_zero {
                    vec![f64::NAN; n]
                } else {
                    start.clone()
                };
                let r = run(&ch, &mut x, x_zero, true);
                assert!(close(&x, &want), "degree {degree}, x_zero {x_zero}");
                assert!(
                    close(&r, &want_r),
                    "residual, degree {degree}, x_zero {x_zero}"
                );
                let mut x = if x_zero {
                    vec![f64::NAN; n]
                } else {
                    start.clone()
                };
                run(&ch, &mut x, x_zero, false);
                assert!(
                    close(&x, &want),
                    "no residual, degree {degree}, x_zero {x_zero}"
                );
            }
        }
    }

    #[test]
    fn chebyshev_polynomial_matches_the_closed_form() {
        // For A = diag(λ) (D = I) the error factor is q(λ) = T_k(z(λ)) / T_k(z(0)).
        let lam = [0.05, 0.3, 0.9, 1.7, 2.0];
        let n = lam.len();
        let cp: Vec<usize> = (0..=n).collect();
        let ri: Vec<usize> = (0..n).collect();
        let a = SymCsr::from_upper_csc(n, &cp, &ri, &lam).unwrap();
        let dinv = vec![1.0; n];
        for degree in 1..=4 {
            let ch = Chebyshev {
                lo: 0.1,
                hi: 2.0,
                degree,
            };
            // Solve A x = 0 from x₀ = 1: x becomes q(λ) · 1.
            let b = vec![0.0; n];
            let mut x = vec![1.0; n];
            let (mut r, mut d, mut dn) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            ch.smooth(
                a.matrix(),
                &dinv,
                &b,
                &mut x,
                false,
                true,
                SmoothWork {
                    r: &mut r,
                    d: &mut d,
                    dn: &mut dn,
                },
            );
            let cheb = |k: usize, z: f64| {
                if z.abs() <= 1.0 {
                    (k as f64 * z.acos()).cos()
                } else {
                    (k as f64 * z.abs().acosh()).cosh() * z.signum().powi(k as i32)
                }
            };
            let z = |l: f64| (2.0 + 0.1 - 2.0 * l) / (2.0 - 0.1);
            for i in 0..n {
                let q = cheb(degree, z(lam[i])) / cheb(degree, z(0.0));
                assert!((x[i] - q).abs() < 1e-13, "degree {degree}: {} vs {q}", x[i]);
                // The returned residual is b − A x.
                assert!((r[i] + lam[i] * x[i]).abs() < 1e-13);
            }
        }
    }
}
