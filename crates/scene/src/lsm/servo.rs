//! The servo of `[loading] platens = { hold_force = F }`: platens that approach at their
//! speed until the platen force (the `platen_force` probe, N/m, compressive positive)
//! reaches `F`, then hold it.
//!
//! Each sub-step both platens move towards each other at
//!
//! ```text
//! v = clamp((F − F_now) / (k_est T), −velocity, velocity),   T = SERVO_STEPS · dt
//! ```
//!
//! with `k_est` the stiffness with which `F_now` answers a unit approach of the platens
//! before the rest of the sample moves: the sum, over the intact bonds and the touching
//! contacts between a platen disk and a disk outside that platen, of
//! `k_n n_y² + k_s n_x²` (`n` the unit vector between the centres; the Hertz contacts
//! take their tangent `dF_n/dδ` at the current force), halved because `F_now` is the
//! mean of the two platens (a link from one platen to the other counts twice, as the
//! two ends approach at `2v`).
//!
//! The servo is a dashpot of viscosity `k_est T` in series with the sample, pushed
//! with `F`: a passive element, so the held force cannot grow an oscillation in
//! continuous time, and the explicit update changes the force error by the factor
//! `1 − dt k / (k_est T) ∈ [1 − 1/SERVO_STEPS, 1]` for any link stiffness `k ≤ k_est`,
//! so it converges without overshoot sub-step by sub-step. Far from `F` the platens
//! move at `velocity`, as platens without a servo do.

use porofrac_lsm::{LatticeSolid, NormalLaw};

/// `T / dt`: the sub-steps over which the servo would close the force error if the
/// sample were as stiff as the links touching the platens.
pub const SERVO_STEPS: f64 = 10.0;

/// Which platen a disk belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    None,
    Top,
    Bottom,
}

/// A force-holding servo on the platens.
#[derive(Clone, Debug)]
pub struct Servo {
    /// Force to hold (N/m, compressive positive).
    pub force: f64,
    /// Largest speed of each platen (m/s).
    pub speed: f64,
    side: Vec<Side>,
}

impl Servo {
    /// A servo holding `force` with platens of at most `speed`, on `n` disks of which
    /// `top` and `bottom` are the platens.
    pub fn new(force: f64, speed: f64, n: usize, top: &[usize], bottom: &[usize]) -> Self {
        let mut side = vec![Side::None; n];
        for &i in top {
            side[i] = Side::Top;
        }
        for &i in bottom {
            side[i] = Side::Bottom;
        }
        Self { force, speed, side }
    }

    /// `k_est` (N/m per m of approach of each platen): see the module documentation.
    pub fn stiffness(&self, solid: &LatticeSolid) -> f64 {
        let x = &solid.disks().x;
        let r = &solid.disks().r;
        let spec = solid.spec();
        let link = |i: usize, j: usize, kn: f64, ks: f64| -> f64 {
            let weight = match (self.side[i], self.side[j]) {
                (Side::Top, Side::Bottom) | (Side::Bottom, Side::Top) => 2.0,
                (a, b) if a == b => 0.0,
                _ => 1.0,
            };
            if weight == 0.0 {
                return 0.0;
            }
            let d = [x[j][0] - x[i][0], x[j][1] - x[i][1]];
            let l2 = d[0] * d[0] + d[1] * d[1];
            if l2 == 0.0 {
                return weight * kn.max(ks);
            }
            weight * (kn * d[1] * d[1] + ks * d[0] * d[0]) / l2
        };
        let mut k = 0.0;
        let b = &spec.bonds;
        for bond in solid.bonds().iter().filter(|b| b.intact) {
            k += link(bond.i as usize, bond.j as usize, b.kn, b.ks);
        }
        let c = &spec.contacts;
        let (pairs, forces) = solid.contacts();
        for (p, f) in pairs.iter().zip(forces).filter(|(_, f)| f.fn_ > 0.0) {
            let (i, j) = (p.i as usize, p.j as usize);
            let kn = match c.normal {
                NormalLaw::Linear => c.kn,
                NormalLaw::Hertz { modulus, poisson } => {
                    // F = (4/3) E* √R* δ^{3/2}, so dF/dδ = 2 E* √R* √δ.
                    let e = modulus / (2.0 * (1.0 - poisson * poisson));
                    let rs = (r[i] * r[j] / (r[i] + r[j])).sqrt();
                    let delta = (0.75 * f.fn_ / (e * rs)).powf(2.0 / 3.0);
                    2.0 * e * rs * delta.sqrt()
                }
            };
            k += link(i, j, kn, c.ks);
        }
        0.5 * k
    }

    /// The approach speed of each platen over the next sub-step of `dt` (m/s, positive
    /// towards each other) when the platen force is `now` (N/m).
    pub fn velocity(&self, solid: &LatticeSolid, now: f64, dt: f64) -> f64 {
        let error = self.force - now;
        let k = self.stiffness(solid);
        let v = if k > 0.0 {
            error / (k * SERVO_STEPS * dt)
        } else {
            // Nothing touches the platens: approach (or retreat) at full speed.
            self.speed * error.signum()
        };
        v.clamp(-self.speed, self.speed)
    }
}
