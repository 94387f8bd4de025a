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

    fn bond_pairs(&self) -> Vec<[usize; 2]> {
        self.bonds()
            .iter()
            .map(|b| [b.i as usize, b.j as usize])
            .collect()
    }

    fn broken_pairs(&self, from: usize, out: &mut Vec<[usize; 2]>) {
        if let Some(b) = self.broken().get(from..) {
            out.extend(b.iter().map(|b| [b.i, b.j]));
        }
    }
}
