//! Preconditioned conjugate gradients with the V-cycle as preconditioner.
//!
//! For SPD `A` and SPD `M ≈ A⁻¹`, CG minimises the `A`-norm of the error over the Krylov
//! space `x₀ + span{M r₀, (M A) M r₀, …}`:
//!
//! ```text
//!   r₀ = b − A x₀,  z₀ = M r₀,  p₀ = z₀,
//!   α_k = (r_k·z_k) / (p_k·A p_k),  x_{k+1} = x_k + α_k p_k,  r_{k+1} = r_k − α_k A p_k,
//!   z_{k+1} = M r_{k+1},  β_k = (r_{k+1}·z_{k+1}) / (r_k·z_k),  p_{k+1} = z_{k+1} + β_k p_k,
//! ```
//!
//! and `‖e_k‖_A ≤ 2 ((√κ − 1)/(√κ + 1))^k ‖e₀‖_A` with `κ = κ(M A)`: a multigrid
//! preconditioner with a mesh-independent `κ` gives mesh-independent iteration counts.
//! Besides the V-cycle an iteration makes three passes over the vectors: the product
//! `A p_k` with `p_k·A p_k` summed in the same pass, the update of `r` with
//! `‖r_{k+1}‖²`, and the update of `p` with the update of `x` by the previous `p`
//! (`x_{k+1} = x_k + α_k p_k` waits for the pass that overwrites `p_k`). The dot product
//! `r·z` is summed in the last pass of the V-cycle.
//!
//! It stops when the recursively updated residual satisfies `‖r_k‖ ≤ tol ‖b‖`, then checks
//! the true residual `‖b − A x_k‖` (the recursion drifts from it by rounding); if that is
//! still above the tolerance, CG restarts from `x_k` with the true residual. It fails
//! loudly instead of returning a wrong answer: `p·Ap ≤ 0` or `r·z ≤ 0` is a
//! [`AmgError::Breakdown`] (the matrix or the preconditioner is not positive definite), no
//! new smallest residual within the stagnation window (or three restarts that do not reach
//! the tolerance) is [`AmgError::Stagnation`], and the iteration limit is
//! [`AmgError::NoConvergence`] with the residual reached.

use crate::csr::{Precision, check_upper_values, norm, par_rows, par_rows_sum, par_zip2_sum};
use crate::error::{AmgError, Result, check_finite};
use crate::hierarchy::Amg;

/// Statistics of a converged solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgStats {
    /// CG iterations (each one V-cycle and one product with `A`).
    pub iterations: usize,
    /// True relative residual `‖b − A x‖ / ‖b‖` of the returned solution.
    pub relative_residual: f64,
}

/// Restarts allowed when the true residual misses the tolerance.
const MAX_RESTARTS: usize = 3;

impl Amg {
    /// Solve `A x = b` by preconditioned CG to `‖b − A x‖ ≤ tol ‖b‖`, starting from the
    /// given `x` (use zeros without a better guess), in at most `max_iter` iterations.
    ///
    /// The operator is the finest matrix as stored; for one stored in single precision
    /// ([`Precision::Single`]) use [`Self::solve_upper`] with the exact values.
    ///
    /// Errors: wrong lengths, non-finite `b` or `x`, a tolerance that is not a positive
    /// finite number, a hierarchy left unusable by a failed [`Amg::update_values`], a
    /// finest matrix in single precision, and the failures described in the module docs.
    pub fn solve(
        &mut self,
        x: &mut [f64],
        b: &[f64],
        tol: f64,
        max_iter: usize,
    ) -> Result<CgStats> {
        if self.matrix().precision() == Precision::Single {
            return Err(AmgError::Input(
                "the finest matrix is stored in single precision: solve with solve_upper and \
                 the double-precision values"
                    .into(),
            ));
        }
        self.solve_with(None, x, b, tol, max_iter)
    }

    /// [`Self::solve`] with the operator given by its upper-triangle `values` in double
    /// precision, on the pattern the hierarchy was built with (the layout of
    /// [`crate::SymCsr::from_upper_csc`]); the hierarchy — possibly stored in single
    /// precision, possibly built for slightly different values — only preconditions.
    ///
    /// Errors: those of [`Self::solve`] except the precision, and `values` of the wrong
    /// length or not finite.
    pub fn solve_upper(
        &mut self,
        values: &[f64],
        x: &mut [f64],
        b: &[f64],
        tol: f64,
        max_iter: usize,
    ) -> Result<CgStats> {
        check_upper_values(values, self.upper_nnz())?;
        self.solve_with(Some(values), x, b, tol, max_iter)
    }

    fn solve_with(
        &mut self,
        upper: Option<&[f64]>,
        x: &mut [f64],
        b: &[f64],
        tol: f64,
        max_iter: usize,
    ) -> Result<CgStats> {
        self.check_valid()?;
        let n = self.n();
        if x.len() != n || b.len() != n {
            return Err(AmgError::Input(format!(
                "solve with x of length {} and b of length {}, want {n}",
                x.len(),
                b.len()
            )));
        }
        if !(tol > 0.0 && tol.is_finite()) {
            return Err(AmgError::Input(format!(
                "tolerance {tol} must be a positive finite number"
            )));
        }
        check_finite(b, "right-hand side")?;
        check_finite(x, "initial guess")?;
        self.prepare_operator(upper);
        let mut v = std::mem::take(&mut self.cg);
        for w in v.iter_mut() {
            w.resize(n, 0.0);
        }
        let result = self.pcg(upper, x, b, tol, max_iter, &mut v);
        self.cg = v;
        result
    }

    fn pcg(
        &mut self,
        upper: Option<&[f64]>,
        x: &mut [f64],
        b: &[f64],
        tol: f64,
        max_iter: usize,
        v: &mut [Vec<f64>; 4],
    ) -> Result<CgStats> {
        let [r, z, p, q] = v;
        let bnorm = norm(b);
        if bnorm == 0.0 {
            x.fill(0.0);
            return Ok(CgStats {
                iterations: 0,
                relative_residual: 0.0,
            });
        }
        let target = tol * bnorm;
        self.fine_residual(upper, b, x, r);
        let rn0 = norm(r);
        if rn0 <= target {
            return Ok(CgStats {
                iterations: 0,
                relative_residual: rn0 / bnorm,
            });
        }
        let mut rz = self.restart(r, z, p, 0)?;
        let mut best = rn0;
        let mut since_best = 0;
        let mut restarts = 0;
        for it in 1..=max_iter {
            let pq = self.fine_product(upper, p, q);
            if pq.is_nan() || pq <= 0.0 {
                return Err(AmgError::Breakdown {
                    iteration: it,
                    what: format!("pᵀAp = {pq:e}"),
                });
            }
            let alpha = rz / pq;
            // x += α p waits for the pass that updates p (or for the end).
            let rn = {
                let qq: &[f64] = q;
                par_rows_sum(r, |i, ri| {
                    *ri -= alpha * qq[i];
                    *ri * *ri
                })
            }
            .sqrt();
            if !rn.is_finite() {
                return Err(AmgError::Breakdown {
                    iteration: it,
                    what: format!("residual norm {rn}"),
                });
            }
            let converged = rn <= target;
            let stagnated = !converged && {
                if rn < best {
                    best = rn;
                    since_best = 0;
                } else {
                    since_best += 1;
                }
                since_best >= self.options.stagnation_window
            };
            if converged || stagnated {
                let pp: &[f64] = p;
                par_rows(x, |i, xi| *xi += alpha * pp[i]);
            }
            if converged {
                // Check the true residual.
                self.fine_residual(upper, b, x, q);
                let true_rn = norm(q);
                if true_rn <= target {
                    return Ok(CgStats {
                        iterations: it,
                        relative_residual: true_rn / bnorm,
                    });
                }
                restarts += 1;
                if restarts > MAX_RESTARTS {
                    return Err(AmgError::Stagnation {
                        iterations: it,
                        residual: true_rn / bnorm,
                        tolerance: tol,
                    });
                }
                r.copy_from_slice(q);
                rz = self.restart(r, z, p, it)?;
                continue;
            }
            if stagnated {
                self.fine_residual(upper, b, x, q);
                return Err(AmgError::Stagnation {
                    iterations: it,
                    residual: norm(q) / bnorm,
                    tolerance: tol,
                });
            }
            let rz_new = self.vcycle(r, z);
            if rz_new.is_nan() || rz_new <= 0.0 {
                return Err(AmgError::Breakdown {
                    iteration: it,
                    what: format!("rᵀMr = {rz_new:e}"),
                });
            }
            let beta = rz_new / rz;
            rz = rz_new;
            let zz: &[f64] = z;
            par_zip2_sum(x, p, |i, xi, pi| {
                *xi += alpha * *pi;
                *pi = zz[i] + beta * *pi;
                0.0
            });
        }
        self.fine_residual(upper, b, x, q);
        let true_rn = norm(q);
        Err(AmgError::NoConvergence {
            iterations: max_iter,
            residual: true_rn / bnorm,
            tolerance: tol,
        })
    }

    /// `r = b − A x` with the operator of [`Self::fine_product`] (`r = b` without a
    /// product when `x = 0`, the usual first guess).
    fn fine_residual(&self, upper: Option<&[f64]>, b: &[f64], x: &[f64], r: &mut [f64]) {
        if x.iter().all(|&v| v == 0.0) {
            r.copy_from_slice(b);
            return;
        }
        let _ = self.fine_product(upper, x, r);
        par_rows(r, |i, ri| *ri = b[i] - *ri);
    }

    /// `z = M r`, `p = z`; returns `rᵀz` (error if not positive).
    fn restart(&mut self, r: &[f64], z: &mut [f64], p: &mut [f64], it: usize) -> Result<f64> {
        let rz = self.vcycle(r, z);
        if rz.is_nan() || rz <= 0.0 {
            return Err(AmgError::Breakdown {
                iteration: it,
                what: format!("rᵀMr = {rz:e}"),
            });
        }
        p.copy_from_slice(z);
        Ok(rz)
    }
}
