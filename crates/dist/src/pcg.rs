//! Conjugate gradients preconditioned by the distributed AMG.
//!
//! With `M` the V-cycle (symmetric positive definite), from `x₀`:
//!
//! ```text
//!   r₀ = b − A x₀,  z₀ = M r₀,  p₀ = z₀,
//!   α_k = (r_k, z_k) / (p_k, A p_k),  x_{k+1} = x_k + α_k p_k,  r_{k+1} = r_k − α_k A p_k,
//!   z_{k+1} = M r_{k+1},  β_k = (r_{k+1}, z_{k+1}) / (r_k, z_k),  p_{k+1} = z_{k+1} + β_k p_k,
//! ```
//!
//! until `‖r_k‖ ≤ tol ‖b‖`. Every dot product is a local sum followed by an all-reduce,
//! so all processes take the same decisions.

use std::time::Instant;

use crate::amg::DistAmg;
use crate::error::{DistError, Result};
use crate::matrix::{Comm, dot};

/// What a distributed CG solve did.
#[derive(Clone, Debug, PartialEq)]
pub struct DistCgStats {
    /// Iterations (preconditioner applications after the first).
    pub iterations: usize,
    /// `‖b − A x‖ / ‖b‖` of the recurrence at the end.
    pub relative_residual: f64,
    /// Wall time of the iterations in seconds.
    pub seconds: f64,
}

impl DistAmg {
    /// Solve `A x = b` (owned parts; `x` holds the start on entry) by CG with this
    /// hierarchy as preconditioner, to `‖r‖ ≤ tolerance ‖b‖` in at most `max_iterations`
    /// (collective).
    ///
    /// Errors: lengths that disagree, no convergence, a non-positive curvature.
    pub fn solve(
        &self,
        comm: &Comm,
        x: &mut [f64],
        b: &[f64],
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<DistCgStats> {
        let t0 = Instant::now();
        let a = self.matrix();
        let n = a.rows().local();
        if x.len() != n || b.len() != n {
            return Err(DistError::Input(format!(
                "CG on vectors of length {} and {}, want {n}",
                x.len(),
                b.len()
            )));
        }
        let bnorm = dot(comm, b, b).sqrt();
        if bnorm == 0.0 {
            x.fill(0.0);
            return Ok(DistCgStats {
                iterations: 0,
                relative_residual: 0.0,
                seconds: t0.elapsed().as_secs_f64(),
            });
        }
        let mut q = vec![0.0; n];
        a.mul(comm, x, &mut q);
        let mut r: Vec<f64> = b.iter().zip(&q).map(|(b, q)| b - q).collect();
        let mut rel = dot(comm, &r, &r).sqrt() / bnorm;
        if rel <= tolerance {
            return Ok(DistCgStats {
                iterations: 0,
                relative_residual: rel,
                seconds: t0.elapsed().as_secs_f64(),
            });
        }
        let mut z = vec![0.0; n];
        self.apply(comm, &r, &mut z)?;
        let mut p = z.clone();
        let mut rz = dot(comm, &r, &z);
        for it in 1..=max_iterations {
            a.mul(comm, &p, &mut q);
            let pq = dot(comm, &p, &q);
            if pq.is_nan() || pq <= 0.0 {
                return Err(DistError::NotPositiveDefinite(format!(
                    "curvature {pq:e} at CG iteration {it}"
                )));
            }
            let alpha = rz / pq;
            for i in 0..n {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
            }
            rel = dot(comm, &r, &r).sqrt() / bnorm;
            if rel <= tolerance {
                return Ok(DistCgStats {
                    iterations: it,
                    relative_residual: rel,
                    seconds: t0.elapsed().as_secs_f64(),
                });
            }
            self.apply(comm, &r, &mut z)?;
            let rz_new = dot(comm, &r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            for i in 0..n {
                p[i] = z[i] + beta * p[i];
            }
        }
        Err(DistError::NotConverged {
            iterations: max_iterations,
            relative_residual: rel,
            tolerance,
        })
    }
}
