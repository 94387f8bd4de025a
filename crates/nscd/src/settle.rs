//! Sample preparation: gravity settling before the loading (M. Renouf, F. Dubois, P. Alart
//! (2006), Eur. J. Comput. Mech. 15(5), §5.1.1: "a state equilibrium is reached by a
//! stabilisation phase under gravity"; the paper gives no stopping criterion, the one here
//! is this project's choice).
//!
//! The bodies are held still (velocities zero along every axis) and the system is
//! stepped with step `h` until the kinetic energy
//! K = Σ ½ m|v|² + ½ I ω² falls below `ratio` × ΔE_p, where
//! ΔE_p = Σ m_i g·(x_i − x_i⁰) is the potential energy released since the start of the
//! settling (positive for a fall). After the settling the bodies get their motion back,
//! velocities of the disks are zeroed, the reference positions `x0` are reset to the
//! settled ones (so displacements count from the settled state) and the clock is reset to
//! 0.

use crate::{Axis, Nscd, NscdError};

/// Options of [`Nscd::settle`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SettleParams {
    /// Step (s).
    pub dt: f64,
    /// Stop once K < `ratio` × ΔE_p (this project's choice: 1e-6).
    pub ratio: f64,
    /// Most settling steps; reaching it is an error.
    pub max_steps: usize,
}

/// What a settling did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SettleStats {
    /// Steps taken.
    pub steps: usize,
    /// Final kinetic energy K (J per metre).
    pub kinetic: f64,
    /// Potential energy released ΔE_p (J per metre).
    pub released: f64,
    /// NLGS sweeps over all settling steps.
    pub sweeps: usize,
}

impl Nscd {
    /// Settle the disks under gravity with the bodies held still (module docs). Errors:
    /// [`NscdError::BadParameter`] for a non-positive `dt` or `ratio` or zero
    /// `max_steps`, [`NscdError::NotSettled`] when `max_steps` is reached, and any error
    /// of [`Nscd::step`].
    pub fn settle(&mut self, p: SettleParams) -> Result<SettleStats, NscdError> {
        self.settle_polled(p, &mut |_| false)
    }

    /// [`Nscd::settle`], calling `poll` before every step with the steps done and
    /// `max_steps`: `true` from `poll` stops the settling with
    /// [`NscdError::Interrupted`] (the bodies get their motion back as after any end).
    pub fn settle_polled(
        &mut self,
        p: SettleParams,
        poll: &mut dyn FnMut(porofrac_particles::Progress) -> bool,
    ) -> Result<SettleStats, NscdError> {
        let bad = |name, value, message| NscdError::BadParameter {
            name,
            value,
            message,
        };
        if !(p.dt.is_finite() && p.dt > 0.0) {
            return Err(bad("settle_dt", p.dt, "must be a positive number"));
        }
        if !(p.ratio.is_finite() && p.ratio > 0.0) {
            return Err(bad("settle_ratio", p.ratio, "must be a positive number"));
        }
        if p.max_steps == 0 {
            return Err(bad("settle_max_steps", 0.0, "must be at least 1"));
        }
        let kept: Vec<_> = self.bodies.iter().map(|b| (b.axes, b.velocity)).collect();
        for b in &mut self.bodies {
            b.axes = [Axis::Prescribed(0.0); 2];
            b.velocity = [0.0; 2];
        }
        let start = self.disks.x.clone();
        let released = |s: &Self| -> f64 {
            s.disks
                .x
                .iter()
                .zip(&start)
                .zip(&s.disks.mass)
                .filter(|(_, m)| m.is_finite())
                .map(|((x, x0), m)| {
                    m * (s.gravity[0] * (x[0] - x0[0]) + s.gravity[1] * (x[1] - x0[1]))
                })
                .sum()
        };
        let mut stats = SettleStats::default();
        let mut result = Err(NscdError::NotSettled {
            steps: p.max_steps,
            kinetic: 0.0,
            released: 0.0,
        });
        for k in 0..p.max_steps {
            if poll(porofrac_particles::Progress::new(
                "settling, step",
                k,
                p.max_steps,
            )) {
                result = Err(NscdError::Interrupted);
                break;
            }
            match self.step(p.dt) {
                Ok(st) => stats.sweeps += st.sweeps,
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
            stats.steps += 1;
            stats.kinetic = self.disks.kinetic_energy();
            stats.released = released(self);
            if stats.released > 0.0 && stats.kinetic < p.ratio * stats.released {
                result = Ok(stats);
                break;
            }
        }
        if let Err(NscdError::NotSettled {
            kinetic, released, ..
        }) = &mut result
        {
            *kinetic = stats.kinetic;
            *released = stats.released;
        }
        for (b, (axes, v)) in self.bodies.iter_mut().zip(kept) {
            b.axes = axes;
            b.velocity = v;
        }
        for i in 0..self.disks.len() {
            self.disks.v[i] = [0.0; 2];
            self.disks.omega[i] = 0.0;
        }
        self.disks.x0.clone_from(&self.disks.x);
        self.time = 0.0;
        result
    }
}
