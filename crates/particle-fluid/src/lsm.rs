//! The lattice solid model as a particle model of the coupling.

use porofrac_lsm::{LatticeSolid, LsmError};
use porofrac_particles::Disks;

use crate::ParticleSolver;

/// Bonded disks carried by the fluid: one coupling sub-step is one velocity-Verlet step of
/// the lattice solid, with the fluid loads added to the bond and contact forces
/// (`external[i] = [fx, fy, torque]` per metre of thickness).
impl ParticleSolver for LatticeSolid {
    type Error = LsmError;

    fn disks(&self) -> &Disks {
        LatticeSolid::disks(self)
    }

    fn stable_dt(&self) -> f64 {
        LatticeSolid::stable_dt(self)
    }

    fn advance(&mut self, dt: f64, external: &[[f64; 3]]) -> Result<(), LsmError> {
        self.step(dt, external).map(|_| ())
    }
}
