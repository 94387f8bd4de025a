//! The trishear velocity field of a fault-propagation fold (Erslev 1991), in the linear
//! form of Zehnder & Allmendinger (2000), to compare with particle velocities.
//!
//! Tip coordinates: x′ along the fault direction e (the hanging wall moves along +e at
//! V₀), y′ along ẑ × e, origin at the fault tip. With φ_a the half apical angle of the
//! triangular zone II ahead of the tip (x′ > 0, |y′| ≤ x′ tan φ_a):
//!
//! * zone I (above: y′ > x′ tan φ_a, or x′ ≤ 0 and y′ > 0) moves rigidly: v′ = (V₀, 0);
//! * zone III (below) is fixed: v′ = 0;
//! * zone II: v′_x = (V₀/2)(y′/(x′ tan φ_a) + 1),
//!   v′_y = (V₀ tan φ_a / 4)((y′/(x′ tan φ_a))² − 1).
//!
//! The field is divergence-free in zone II and continuous across both of its sides.
//! [`Trishear::l2_mismatch`] compares particle velocities with it:
//! √(Σ|v_i − v(x_i)|² / Σ|v(x_i)|²) over the particles given.

/// A trishear zone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trishear {
    /// Fault tip (m).
    pub tip: [f64; 2],
    /// Angle of the fault direction e from +x (rad).
    pub dip: f64,
    /// Half apical angle φ_a of zone II (rad).
    pub half_apex: f64,
    /// Slip velocity V₀ of the hanging wall (m/s).
    pub v0: f64,
}

impl Trishear {
    /// The velocity at `p` (m/s), in the global frame.
    pub fn velocity(&self, p: [f64; 2]) -> [f64; 2] {
        let e = [self.dip.cos(), self.dip.sin()];
        let n = [-e[1], e[0]];
        let d = [p[0] - self.tip[0], p[1] - self.tip[1]];
        let (x, y) = (d[0] * e[0] + d[1] * e[1], d[0] * n[0] + d[1] * n[1]);
        let tan = self.half_apex.tan();
        let (vx, vy) = if x > 0.0 && y.abs() <= x * tan {
            let s = y / (x * tan);
            (
                0.5 * self.v0 * (s + 1.0),
                0.25 * self.v0 * tan * (s * s - 1.0),
            )
        } else if (x > 0.0 && y > x * tan) || (x <= 0.0 && y > 0.0) {
            (self.v0, 0.0)
        } else {
            (0.0, 0.0)
        };
        [vx * e[0] + vy * n[0], vx * e[1] + vy * n[1]]
    }

    /// Relative L2 mismatch of the velocities `v` at the points `x` against the field
    /// (0 without points or when the field vanishes at all of them and so do the `v`).
    pub fn l2_mismatch(&self, x: &[[f64; 2]], v: &[[f64; 2]]) -> f64 {
        let (mut num, mut den) = (0.0, 0.0);
        for (p, vi) in x.iter().zip(v) {
            let a = self.velocity(*p);
            num += (vi[0] - a[0]).powi(2) + (vi[1] - a[1]).powi(2);
            den += a[0] * a[0] + a[1] * a[1];
        }
        if den > 0.0 {
            (num / den).sqrt()
        } else if num > 0.0 {
            f64::INFINITY
        } else {
            0.0
        }
    }
}
