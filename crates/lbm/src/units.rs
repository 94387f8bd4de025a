//! SI ↔ lattice units.
//!
//! With spacing `Δx`, kinematic viscosity `ν` and relaxation time `τ`, the lattice viscosity
//! is `ν* = c_s² (τ − ½)` (Mora et al. (2015) eqs. 1–2), so `Δt = ν* Δx²/ν`. Velocities scale with
//! `Δx/Δt`, accelerations with `Δx/Δt²`, the gauge pressure is
//! `p = c_s² (ρ* − 1) ρ (Δx/Δt)²`, forces per unit depth with `ρ Δx³/Δt²` and torques per
//! unit depth with `ρ Δx⁴/Δt²`.

use crate::LbmError;
use crate::d2q9::CS2;

/// The conversion between SI and lattice units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Units {
    /// Lattice spacing `Δx` (m).
    pub dx: f64,
    /// Time step `Δt` (s).
    pub dt: f64,
    /// Fluid density `ρ` (kg/m³) that lattice density 1 stands for.
    pub density: f64,
    /// Relaxation time `τ`.
    pub tau: f64,
}

impl Units {
    /// Units from spacing, kinematic viscosity, density and relaxation time.
    pub fn from_viscosity(
        dx: f64,
        viscosity: f64,
        density: f64,
        tau: f64,
    ) -> Result<Self, LbmError> {
        for (name, v) in [
            ("spacing", dx),
            ("viscosity", viscosity),
            ("density", density),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(LbmError::Value(name, v));
            }
        }
        if !(tau > crate::TAU_MIN && tau.is_finite()) {
            return Err(LbmError::Tau(tau));
        }
        let dt = CS2 * (tau - 0.5) * dx * dx / viscosity;
        Ok(Units {
            dx,
            dt,
            density,
            tau,
        })
    }
    /// Lattice velocity of `v` (m/s).
    pub fn velocity(&self, v: f64) -> f64 {
        v * self.dt / self.dx
    }
    /// SI velocity of lattice velocity `v`.
    pub fn velocity_si(&self, v: f64) -> f64 {
        v * self.dx / self.dt
    }
    /// Lattice acceleration of `a` (m/s²).
    pub fn acceleration(&self, a: f64) -> f64 {
        a * self.dt * self.dt / self.dx
    }
    /// Lattice length of `x` (m).
    pub fn length(&self, x: f64) -> f64 {
        x / self.dx
    }
    /// Lattice density of gauge pressure `p` (Pa).
    pub fn pressure_density(&self, p: f64) -> f64 {
        1.0 + p / (CS2 * self.density * (self.dx / self.dt).powi(2))
    }
    /// Gauge pressure (Pa) of lattice density `rho`.
    pub fn pressure_si(&self, rho: f64) -> f64 {
        CS2 * (rho - 1.0) * self.density * (self.dx / self.dt).powi(2)
    }
    /// Force per unit depth (N/m) of a lattice force.
    pub fn force_si(&self, f: f64) -> f64 {
        f * self.density * self.dx.powi(3) / (self.dt * self.dt)
    }
    /// Torque per unit depth (N) of a lattice torque.
    pub fn torque_si(&self, t: f64) -> f64 {
        t * self.density * self.dx.powi(4) / (self.dt * self.dt)
    }
    /// Mach number `|u*|/c_s` of an SI speed.
    pub fn mach(&self, speed: f64) -> f64 {
        self.velocity(speed) / CS2.sqrt()
    }
    /// Error if the SI speed `speed` of `what` gives a Mach number above
    /// [`crate::MAX_MACH`].
    pub fn check_mach(&self, what: &'static str, speed: f64) -> Result<(), LbmError> {
        let ma = self.mach(speed.abs());
        if ma.is_nan() || ma > crate::MAX_MACH {
            return Err(LbmError::Mach { what, mach: ma });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversion_round_trips() {
        let u = Units::from_viscosity(1e-3, 1e-6, 1000.0, 0.8).unwrap();
        assert!((u.dt - 0.1).abs() < 1e-12);
        assert!((u.velocity_si(u.velocity(0.3)) - 0.3).abs() < 1e-15);
        assert!((u.pressure_si(u.pressure_density(12.5)) - 12.5).abs() < 1e-9);
        assert!(Units::from_viscosity(1e-3, 1e-6, 1000.0, 0.5).is_err());
        assert!(u.check_mach("inlet", 1e-3).is_ok());
        assert!(u.check_mach("inlet", 1e-2 * 3.0).is_err());
    }
}
