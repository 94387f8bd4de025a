//! A rigid disk launched through water at rest in a periodic box, with
//! `porofrac-particle-fluid` (and the lattice Boltzmann fluid and disks below it) alone.
//!
//! The disk is rasterised as a moving obstacle of the lattice every fluid step and
//! receives the momentum-exchange force and torque of the fluid; it slows down as the
//! fluid takes up its momentum. In a closed periodic box the momentum of fluid and disk
//! together is conserved: the example prints the disk's speed and the relative defect of
//! the total momentum as the run proceeds (round-off, ~1e-14).
//!
//! ```sh
//! cargo run --release -p porofrac-particle-fluid --example launched_disk
//! ```

use std::error::Error;

use porofrac_lbm::{Lattice, LatticeConfig, Units};
use porofrac_particle_fluid::{CouplingOptions, ParticleFluid, RigidDisks};
use porofrac_particles::Disks;

fn main() -> Result<(), Box<dyn Error>> {
    // 48 × 48 lattice of 0.1 mm spacing, water (ν = 1e-6 m²/s, ρ = 1000 kg/m³), τ = 0.8.
    let (n, tau, dx) = (48usize, 0.8, 1e-4);
    let units = Units::from_viscosity(dx, 1e-6, 1000.0, tau)?;
    let lattice = Lattice::new(LatticeConfig::periodic(n, n, tau))?;
    let mut disks = Disks::new(&[[24.3 * dx, 20.6 * dx]], &[5.3 * dx], 1500.0)?;
    disks.v[0] = [units.velocity_si(0.04), units.velocity_si(0.015)];
    let mass = disks.mass[0];
    let p0 = [mass * disks.v[0][0], mass * disks.v[0][1]];
    let scale = p0[0].hypot(p0[1]);
    let mut solver = RigidDisks::new(disks);
    let mut coupled = ParticleFluid::new(
        &solver,
        lattice,
        units,
        [0.0, 0.0],
        CouplingOptions::default(),
    )?;
    println!(
        "{:>6} {:>14} {:>18}",
        "step", "disk speed m/s", "momentum defect"
    );
    for step in 1..=600 {
        coupled.step(&mut solver)?;
        if step % 100 == 0 {
            let (fluid, owed) = (coupled.fluid_momentum(), coupled.pending_impulse());
            let v = solver.disks.v[0];
            let defect = (0..2)
                .map(|a| (fluid[a] + owed[a] + mass * v[a] - p0[a]).abs() / scale)
                .fold(0.0_f64, f64::max);
            println!("{step:>6} {:>14.4e} {defect:>18.2e}", v[0].hypot(v[1]));
        }
    }
    Ok(())
}
