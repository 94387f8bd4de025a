//! Collision operators: BGK (Mora et al. (2015) eqs. 1–2) and two-relaxation-time (TRT),
//! with the Guo forcing term.
//!
//! With `f^±_i = (f_i ± f_ī)/2` the symmetric and antisymmetric parts of a direction pair,
//! TRT relaxes them with two rates,
//! `f*_i = f_i − ω⁺ (f⁺_i − f^eq⁺_i) − ω⁻ (f⁻_i − f^eq⁻_i) + S_i`,
//! `ω⁺ = 1/τ` fixing the kinematic viscosity `ν = c_s² (τ − ½)` and `ω⁻` chosen from the
//! magic parameter `Λ = (1/ω⁺ − ½)(1/ω⁻ − ½)`; `Λ = 3/16` places halfway bounce-back walls
//! exactly for Poiseuille flow. BGK is `ω⁻ = ω⁺`.
//!
//! Guo forcing (Guo, Zheng & Shi 2002): the equilibrium uses `u = (Σ c_i f_i + F/2)/ρ`
//! and the source is `S_i = w_i [3 (c_i − u) + 9 (c_i·u) c_i]·F`, whose antisymmetric part
//! `3 w_i c_i·F` is weighted by `(1 − ω⁻/2)` and symmetric part by `(1 − ω⁺/2)`.

use crate::LbmError;
use crate::d2q9::W;

/// The collision operator.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Collision {
    /// Single relaxation time (Bhatnagar–Gross–Krook).
    #[default]
    Bgk,
    /// Two relaxation times with the magic parameter `Λ` (3/16 by [`Collision::trt`]).
    Trt {
        /// `Λ = (τ⁺ − ½)(τ⁻ − ½)`.
        magic: f64,
    },
}

impl Collision {
    /// TRT with the magic parameter 3/16.
    pub fn trt() -> Self {
        Collision::Trt { magic: 3.0 / 16.0 }
    }

    /// The two rates `(ω⁺, ω⁻)` for relaxation time `tau`.
    pub fn rates(self, tau: f64) -> Result<Rates, LbmError> {
        if !(tau.is_finite() && tau > crate::TAU_MIN) {
            return Err(LbmError::Tau(tau));
        }
        let plus = 1.0 / tau;
        let minus = match self {
            Collision::Bgk => plus,
            Collision::Trt { magic } => {
                if !(magic.is_finite() && magic > 0.0) {
                    return Err(LbmError::Magic(magic));
                }
                1.0 / (0.5 + magic / (tau - 0.5))
            }
        };
        Ok(Rates { plus, minus })
    }
}

/// Relaxation rates of the symmetric and antisymmetric parts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rates {
    /// `ω⁺ = 1/τ`.
    pub plus: f64,
    /// `ω⁻`.
    pub minus: f64,
}

/// The pairs `(i, ī)` with `i` in 1, 2, 5, 6.
const PAIRS: [(usize, usize, f64, f64, f64); 4] = [
    (1, 3, 1.0, 0.0, W[1]),
    (2, 4, 0.0, 1.0, W[2]),
    (5, 7, 1.0, 1.0, W[5]),
    (6, 8, -1.0, 1.0, W[6]),
];

/// Collide one node: `f` pre-collision populations, `accel` the body acceleration (lattice
/// units; force density `ρ a`), `on` 1 for fluid and 0 for solid nodes (a solid node keeps
/// its populations). Returns the post-collision populations.
#[inline(always)]
pub fn collide(f: [f64; 9], rates: Rates, accel: [f64; 2], on: f64) -> [f64; 9] {
    collide_with::<true>(f, rates, accel, on)
}

/// [`collide`], with the force terms compiled out when `FORCE` is false (then `accel` is
/// ignored).
#[inline(always)]
pub fn collide_with<const FORCE: bool>(
    f: [f64; 9],
    rates: Rates,
    accel: [f64; 2],
    on: f64,
) -> [f64; 9] {
    let rho = f[0] + f[1] + f[2] + f[3] + f[4] + f[5] + f[6] + f[7] + f[8];
    let jx = f[1] - f[3] + f[5] - f[6] - f[7] + f[8];
    let jy = f[2] - f[4] + f[5] + f[6] - f[7] - f[8];
    let (fx, fy) = if FORCE {
        (rho * accel[0] * on, rho * accel[1] * on)
    } else {
        (0.0, 0.0)
    };
    let inv = 1.0 / rho;
    let ux = (jx + 0.5 * fx) * inv;
    let uy = (jy + 0.5 * fy) * inv;
    let wp = rates.plus * on;
    let wm = rates.minus * on;
    let gp = 1.0 - 0.5 * wp;
    let gm = 1.0 - 0.5 * wm;
    let usq = 1.5 * (ux * ux + uy * uy);
    let uf = 3.0 * (ux * fx + uy * fy);
    let mut out = f;
    let feq0 = W[0] * rho * (1.0 - usq);
    out[0] = f[0] - wp * (f[0] - feq0);
    if FORCE {
        out[0] -= gp * W[0] * uf;
    }
    for (i, o, cx, cy, w) in PAIRS {
        let cu = cx * ux + cy * uy;
        let eq_s = w * rho * (1.0 + 4.5 * cu * cu - usq);
        let eq_a = 3.0 * w * rho * cu;
        let fs = 0.5 * (f[i] + f[o]);
        let fa = 0.5 * (f[i] - f[o]);
        let mut ds = -wp * (fs - eq_s);
        let mut da = -wm * (fa - eq_a);
        if FORCE {
            let cf = cx * fx + cy * fy;
            ds += gp * w * (9.0 * cu * cf - uf);
            da += gm * 3.0 * w * cf;
        }
        out[i] = f[i] + ds + da;
        out[o] = f[o] + ds - da;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::d2q9::{C, feq};

    #[test]
    fn collision_conserves_mass_and_adds_the_force() {
        let f = [0.45, 0.12, 0.1, 0.09, 0.11, 0.03, 0.02, 0.025, 0.031];
        for col in [Collision::Bgk, Collision::trt()] {
            let r = col.rates(0.9).unwrap();
            let a = [1e-3, -2e-3];
            let g = collide(f, r, a, 1.0);
            let rho: f64 = f.iter().sum();
            let rho2: f64 = g.iter().sum();
            assert!((rho - rho2).abs() < 1e-15);
            for d in 0..2 {
                let m: f64 = (0..9).map(|i| C[i][d] as f64 * (g[i] - f[i])).sum();
                assert!((m - rho * a[d]).abs() < 1e-15, "{m}");
            }
            assert_eq!(collide(f, r, a, 0.0), f);
        }
    }

    #[test]
    fn equilibrium_is_a_fixed_point() {
        let u = [0.05, -0.02];
        let f: [f64; 9] = std::array::from_fn(|i| feq(i, 1.02, u));
        let g = collide(f, Collision::trt().rates(0.7).unwrap(), [0.0, 0.0], 1.0);
        for i in 0..9 {
            assert!((f[i] - g[i]).abs() < 4.0 * f64::EPSILON);
        }
    }

    #[test]
    fn tau_at_or_below_one_half_is_refused() {
        assert!(Collision::Bgk.rates(0.5).is_err());
        assert!(Collision::Bgk.rates(f64::NAN).is_err());
        assert!(Collision::Trt { magic: 0.0 }.rates(0.8).is_err());
    }
}
