//! The particle side of the coupling: a small trait any particle model implements, and
//! free rigid disks under gravity for tests and simple suspensions.

use porofrac_particles::Disks;

/// A particle model the fluid can carry: it exposes its disks, the largest time step it is
/// stable with, and advances by a step under external loads.
///
/// `external[i] = [fx, fy, torque]` is the load on disk `i` per metre of thickness (N/m,
/// N), held constant over the step; the model adds it to its own forces.
pub trait ParticleSolver {
    /// What can go wrong in a step.
    type Error: std::error::Error + Send + Sync + 'static;
    /// The disks (SI: m, m/s, rad/s, kg/m).
    fn disks(&self) -> &Disks;
    /// Largest stable time step (s); `f64::INFINITY` if any step is stable.
    fn stable_dt(&self) -> f64;
    /// Advance by `dt` (s) under `external` (one entry per disk).
    fn advance(&mut self, dt: f64, external: &[[f64; 3]]) -> Result<(), Self::Error>;
    /// The bonded pairs of disks at the start (intact or not), for the pores of the crack
    /// network ([`crate::bond_cracks`]); none for a model without bonds.
    fn bond_pairs(&self) -> Vec<[usize; 2]> {
        Vec::new()
    }
    /// Append to `out` the pairs of the bonds broken so far, in the order they broke,
    /// from the `from`-th on (a model's broken bonds never heal); none without bonds.
    fn broken_pairs(&self, from: usize, out: &mut Vec<[usize; 2]>) {
        let _ = (from, out);
    }
}

/// A rigid disk's state stopped being finite.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[error("rigid disk {particle}: the state is not finite after a step (load too large?)")]
pub struct RigidDiskError {
    /// The disk.
    pub particle: usize,
}

/// Free rigid disks (no contacts) under gravity with buoyancy, integrated by symplectic
/// Euler: `v ← v + Δt (F + (m − ρ_f A) g)/m`, `x ← x + Δt v`, `ω ← ω + Δt T/I`,
/// `θ ← θ + Δt ω`. A disk of infinite mass or inertia does not translate or rotate.
#[derive(Clone, Debug)]
pub struct RigidDisks {
    /// The disks.
    pub disks: Disks,
    /// Gravity (m/s²).
    pub gravity: [f64; 2],
    /// Density of the displaced fluid (kg/m³) for the buoyancy `−ρ_f A g`.
    pub fluid_density: f64,
}

impl RigidDisks {
    /// Disks without gravity.
    pub fn new(disks: Disks) -> Self {
        RigidDisks {
            disks,
            gravity: [0.0, 0.0],
            fluid_density: 0.0,
        }
    }

    /// The buoyancy-corrected weight `(m − ρ_f A) g` of disk `i` (N/m).
    pub fn net_weight(&self, i: usize) -> [f64; 2] {
        let m = self.disks.mass[i] - self.fluid_density * self.disks.area(i);
        [m * self.gravity[0], m * self.gravity[1]]
    }
}

impl ParticleSolver for RigidDisks {
    type Error = RigidDiskError;

    fn disks(&self) -> &Disks {
        &self.disks
    }

    fn stable_dt(&self) -> f64 {
        f64::INFINITY
    }

    fn advance(&mut self, dt: f64, external: &[[f64; 3]]) -> Result<(), RigidDiskError> {
        for i in 0..self.disks.len() {
            let e = external.get(i).copied().unwrap_or([0.0; 3]);
            let w = self.net_weight(i);
            let d = &mut self.disks;
            if d.mass[i].is_finite() {
                for a in 0..2 {
                    d.v[i][a] += dt * (e[a] + w[a]) / d.mass[i];
                    d.x[i][a] += dt * d.v[i][a];
                }
            }
            if d.inertia[i].is_finite() {
                d.omega[i] += dt * e[2] / d.inertia[i];
                d.angle[i] += dt * d.omega[i];
            }
            let ok = d.x[i].iter().chain(&d.v[i]).all(|v| v.is_finite()) && d.omega[i].is_finite();
            if !ok {
                return Err(RigidDiskError { particle: i });
            }
        }
        Ok(())
    }
}
