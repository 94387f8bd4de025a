//! The D2Q9 velocity set, described once (Mora et al. (2015) eq. 3).
//!
//! Directions: 0 rest; 1–4 the axes `(1,0) (0,1) (-1,0) (0,-1)`; 5–8 the diagonals
//! `(1,1) (-1,1) (-1,-1) (1,-1)`. Weights `4/9`, `1/9`, `1/36`; sound speed
//! `c_s² = 1/3` in lattice units. The equilibrium is
//! `f_i^eq = w_i ρ [1 + 3 c_i·u + 9/2 (c_i·u)² − 3/2 u·u]`.

/// Number of discrete velocities.
pub const Q: usize = 9;

/// Lattice velocities `c_i` (lattice units).
pub const C: [[i32; 2]; Q] = [
    [0, 0],
    [1, 0],
    [0, 1],
    [-1, 0],
    [0, -1],
    [1, 1],
    [-1, 1],
    [-1, -1],
    [1, -1],
];

/// Weights `w_i`.
pub const W: [f64; Q] = [
    4.0 / 9.0,
    1.0 / 9.0,
    1.0 / 9.0,
    1.0 / 9.0,
    1.0 / 9.0,
    1.0 / 36.0,
    1.0 / 36.0,
    1.0 / 36.0,
    1.0 / 36.0,
];

/// The opposite direction `ī` with `c_ī = −c_i`.
pub const OPP: [usize; Q] = [0, 3, 4, 1, 2, 7, 8, 5, 6];

/// Squared sound speed `c_s² = 1/3`.
pub const CS2: f64 = 1.0 / 3.0;

/// `c_i` as floating point.
#[inline(always)]
pub fn cf(i: usize) -> [f64; 2] {
    [C[i][0] as f64, C[i][1] as f64]
}

/// The equilibrium `f_i^eq(ρ, u)` of one direction.
#[inline(always)]
pub fn feq(i: usize, rho: f64, u: [f64; 2]) -> f64 {
    let c = cf(i);
    let cu = c[0] * u[0] + c[1] * u[1];
    W[i] * rho * (1.0 + 3.0 * cu + 4.5 * cu * cu - 1.5 * (u[0] * u[0] + u[1] * u[1]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moments_of_the_velocity_set() {
        let s: f64 = W.iter().sum();
        assert!((s - 1.0).abs() < 1e-15);
        for a in 0..2 {
            let m1: f64 = (0..Q).map(|i| W[i] * C[i][a] as f64).sum();
            assert!(m1.abs() < 1e-15);
            for b in 0..2 {
                let m2: f64 = (0..Q).map(|i| W[i] * (C[i][a] * C[i][b]) as f64).sum();
                let want = if a == b { CS2 } else { 0.0 };
                assert!((m2 - want).abs() < 1e-15);
            }
        }
        for i in 0..Q {
            assert_eq!(C[OPP[i]], [-C[i][0], -C[i][1]]);
        }
    }
}
