//! Restarted GMRES with right preconditioning, for the non-symmetric Nitsche systems.
//!
//! GMRES(m) (Saad & Schultz 1986) builds an orthonormal basis `V` of the Krylov space of
//! `A M⁻¹` from `r₀ = b − A x₀` by the Arnoldi process (modified Gram–Schmidt, one
//! re-orthogonalisation pass), reduces the Hessenberg matrix `H` with Givens rotations and
//! minimises `‖β e₁ − H y‖`; with the right preconditioner the minimised residual is the
//! true one, `‖b − A x‖` with `x = x₀ + Z y`, where the preconditioned vectors
//! `z_k = M⁻¹ v_k` are kept (as flexible GMRES does, Saad 1993), so that the update costs
//! no further application of `M⁻¹` and a preconditioner that is linear only up to rounding
//! (factors in single precision) still gives the minimised residual. After `m` steps it
//! restarts from the updated `x`. The stop test is `‖b − A x‖ ≤ tol ‖b‖`, checked by a true residual at every
//! restart and at the end: a run that does not reach it is an error that states the
//! residual reached, never a silent result.

use rayon::prelude::*;

use crate::error::{CosseratError, Result};

/// Parameters of [`gmres`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GmresOptions {
    /// Relative residual `‖b − A x‖ / ‖b‖` to reach.
    pub tolerance: f64,
    /// Krylov vectors kept before a restart.
    pub restart: usize,
    /// Largest number of matrix–vector products.
    pub max_iterations: usize,
    /// Precision of the sparse `LDLᵀ` factors that precondition GMRES in
    /// [`crate::linear`] (`"gmres-ldlt"`, `"ldlt-schur"`; not used by [`gmres`] itself).
    pub factor_precision: FactorPrecision,
}

/// Precision of a preconditioner's sparse factors: GMRES multiplies by the matrix and
/// sums in double precision whatever the preconditioner's, so single-precision factors
/// (half the memory traffic, twice the vector lanes) cost a few more iterations, not
/// accuracy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FactorPrecision {
    /// `f32` factors, or `f64` when the single-precision factorization meets a
    /// non-positive pivot (the matrix is too ill-conditioned for it).
    #[default]
    Single,
    /// `f64` factors.
    Double,
}

impl Default for GmresOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            restart: 60,
            max_iterations: 3000,
            factor_precision: FactorPrecision::default(),
        }
    }
}

/// What a GMRES solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GmresStats {
    /// Arnoldi steps (products with `A` and applications of `M⁻¹`).
    pub iterations: usize,
    /// True relative residual `‖b − A x‖ / ‖b‖` of the returned `x`.
    pub residual: f64,
}

/// Rows per parallel chunk of the vector operations.
const CHUNK: usize = 4096;

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(x, y)| x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>())
        .sum()
}

/// `c = Vᵀ w`, `w −= V c` (one classical Gram–Schmidt pass over the basis `v`), both in
/// one parallel sweep over row chunks each.
fn project(v: &[Vec<f64>], w: &mut [f64], c: &mut Vec<f64>) {
    let k = v.len();
    let dots = (0..w.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|b| {
            let r = b * CHUNK..((b + 1) * CHUNK).min(w.len());
            let wr = &w[r.clone()];
            v.iter()
                .map(|vi| {
                    vi[r.clone()]
                        .iter()
                        .zip(wr)
                        .map(|(p, q)| p * q)
                        .sum::<f64>()
                })
                .collect::<Vec<f64>>()
        })
        .reduce(
            || vec![0.0; k],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    *x += y;
                }
                a
            },
        );
    c.clear();
    c.extend_from_slice(&dots);
    w.par_chunks_mut(CHUNK).enumerate().for_each(|(b, wr)| {
        let (off, len) = (b * CHUNK, wr.len());
        for (vi, ci) in v.iter().zip(c.iter()) {
            for (x, y) in wr.iter_mut().zip(&vi[off..off + len]) {
                *x -= ci * y;
            }
        }
    });
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Solve `A x = b` from the initial guess in `x`. `apply(v, out)` sets `out = A v`;
/// `precondition(r, z)` sets `z ≈ A⁻¹ r` (any fixed linear map; its errors are passed on).
///
/// Errors: lengths, non-finite `b`, bad options, [`CosseratError::NotConverged`] when the
/// tolerance is not reached within `max_iterations`, [`CosseratError::Solve`] on a
/// breakdown or a non-finite residual.
pub fn gmres(
    mut apply: impl FnMut(&[f64], &mut [f64]),
    mut precondition: impl FnMut(&[f64], &mut [f64]) -> Result<()>,
    b: &[f64],
    x: &mut [f64],
    options: &GmresOptions,
) -> Result<GmresStats> {
    let n = b.len();
    if x.len() != n {
        return Err(CosseratError::Input {
            what: format!("gmres: x of length {}, b of length {n}", x.len()),
        });
    }
    if !(options.tolerance > 0.0 && options.tolerance < 1.0) || options.restart == 0 {
        return Err(CosseratError::Input {
            what: format!(
                "gmres: tolerance {} must be in (0, 1) and restart {} ≥ 1",
                options.tolerance, options.restart
            ),
        });
    }
    if b.iter().any(|v| !v.is_finite()) || x.iter().any(|v| !v.is_finite()) {
        return Err(CosseratError::Solve(
            "gmres: non-finite right-hand side or initial guess".into(),
        ));
    }
    let bnorm = norm(b);
    if bnorm == 0.0 {
        x.fill(0.0);
        return Ok(GmresStats::default());
    }
    let m = options.restart;
    let mut v: Vec<Vec<f64>> = Vec::with_capacity(m + 1);
    let mut zs: Vec<Vec<f64>> = Vec::with_capacity(m);
    let mut h = vec![0.0; (m + 1) * m]; // column-major, column j has m + 1 rows
    let (mut cs, mut sn, mut g) = (vec![0.0; m], vec![0.0; m], vec![0.0; m + 1]);
    let mut r = vec![0.0; n];
    let mut w = vec![0.0; n];
    let mut c = Vec::with_capacity(m + 1);
    let mut iterations = 0;
    let residual = |x: &[f64], r: &mut [f64], apply: &mut dyn FnMut(&[f64], &mut [f64])| {
        apply(x, r);
        for (ri, bi) in r.iter_mut().zip(b) {
            *ri = bi - *ri;
        }
        norm(r)
    };
    // From a zero guess the residual is b (no product).
    let mut beta = if x.iter().all(|&xi| xi == 0.0) {
        r.copy_from_slice(b);
        bnorm
    } else {
        residual(x, &mut r, &mut apply)
    };
    loop {
        let rel = beta / bnorm;
        if !rel.is_finite() {
            return Err(CosseratError::Solve(format!(
                "gmres: non-finite residual after {iterations} iterations (a singular \
                 matrix or preconditioner?)"
            )));
        }
        if rel <= options.tolerance {
            return Ok(GmresStats {
                iterations,
                residual: rel,
            });
        }
        if iterations >= options.max_iterations {
            return Err(CosseratError::NotConverged {
                iterations,
                residual: rel,
                tolerance: options.tolerance,
            });
        }
        // One cycle of m Arnoldi steps.
        v.truncate(0);
        v.push(r.iter().map(|ri| ri / beta).collect());
        g.fill(0.0);
        g[0] = beta;
        let mut k = 0;
        while k < m && iterations < options.max_iterations {
            if zs.len() <= k {
                zs.push(vec![0.0; n]);
            }
            precondition(&v[k], &mut zs[k])?;
            apply(&zs[k], &mut w);
            iterations += 1;
            let hk = &mut h[k * (m + 1)..(k + 1) * (m + 1)];
            hk.fill(0.0);
            // Classical Gram–Schmidt, repeated once when the norm drops by more than
            // 1/√2 ("twice is enough").
            let mut before = norm(&w);
            let mut wn = before;
            for _pass in 0..2 {
                project(&v, &mut w, &mut c);
                for (hi, ci) in hk.iter_mut().zip(&c) {
                    *hi += ci;
                }
                wn = norm(&w);
                if wn > std::f64::consts::FRAC_1_SQRT_2 * before {
                    break;
                }
                before = wn;
            }
            hk[k + 1] = wn;
            for i in 0..k {
                let (a, bb) = (hk[i], hk[i + 1]);
                hk[i] = cs[i] * a + sn[i] * bb;
                hk[i + 1] = -sn[i] * a + cs[i] * bb;
            }
            let den = hk[k].hypot(hk[k + 1]);
            if den == 0.0 || !den.is_finite() {
                return Err(CosseratError::Solve(format!(
                    "gmres: breakdown at iteration {iterations} (singular preconditioned \
                     matrix?)"
                )));
            }
            cs[k] = hk[k] / den;
            sn[k] = hk[k + 1] / den;
            hk[k] = den;
            hk[k + 1] = 0.0;
            g[k + 1] = -sn[k] * g[k];
            g[k] *= cs[k];
            k += 1;
            let est = g[k].abs() / bnorm;
            if wn == 0.0 || est <= 0.5 * options.tolerance {
                break;
            }
            v.push(w.iter().map(|wi| wi / wn).collect());
        }
        // y = H⁻¹ g (upper triangular k × k), x += Z y.
        let mut y = g[..k].to_vec();
        for i in (0..k).rev() {
            let mut s = y[i];
            for j in i + 1..k {
                s -= h[j * (m + 1) + i] * y[j];
            }
            y[i] = s / h[i * (m + 1) + i];
        }
        for (zi, yi) in zs.iter().zip(&y) {
            for (xj, zj) in x.iter_mut().zip(zi) {
                *xj += yi * zj;
            }
        }
        beta = residual(x, &mut r, &mut apply);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-symmetric tridiagonal system with a known solution, unpreconditioned and
    /// with restarts shorter than the dimension.
    #[test]
    fn solves_convection_diffusion_to_tolerance() {
        let n = 200;
        let apply = |v: &[f64], out: &mut [f64]| {
            for i in 0..n {
                let l = if i > 0 { v[i - 1] } else { 0.0 };
                let r = if i + 1 < n { v[i + 1] } else { 0.0 };
                out[i] = 4.0 * v[i] - 1.5 * l - 0.5 * r;
            }
        };
        let exact: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).sin()).collect();
        let mut b = vec![0.0; n];
        apply(&exact, &mut b);
        let mut x = vec![0.0; n];
        let opts = GmresOptions {
            tolerance: 1e-12,
            restart: 10,
            max_iterations: 500,
            ..Default::default()
        };
        let st = gmres(
            apply,
            |r, z| {
                z.copy_from_slice(r);
                Ok(())
            },
            &b,
            &mut x,
            &opts,
        )
        .unwrap();
        assert!(st.residual <= 1e-12, "{st:?}");
        let err = x
            .iter()
            .zip(&exact)
            .map(|(a, e)| (a - e).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-10, "max error {err}");
    }

    /// Too few iterations is an error naming the residual, not a result.
    #[test]
    fn non_convergence_is_an_error() {
        let n = 100;
        let apply = |v: &[f64], out: &mut [f64]| {
            for i in 0..n {
                let l = if i > 0 { v[i - 1] } else { 0.0 };
                out[i] = 2.0 * v[i] - l + if i + 1 < n { -v[i + 1] } else { 0.0 };
            }
        };
        let b = vec![1.0; n];
        let mut x = vec![0.0; n];
        let opts = GmresOptions {
            tolerance: 1e-12,
            restart: 5,
            max_iterations: 10,
            ..Default::default()
        };
        let e = gmres(
            apply,
            |r, z| {
                z.copy_from_slice(r);
                Ok(())
            },
            &b,
            &mut x,
            &opts,
        )
        .unwrap_err();
        assert!(
            matches!(e, CosseratError::NotConverged { iterations: 10, residual, .. } if residual > 1e-12),
            "{e}"
        );
    }
}
