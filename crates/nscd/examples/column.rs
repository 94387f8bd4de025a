//! A column of rigid disks resting on a floor, by non-smooth contact dynamics with
//! `porofrac-nscd` (and the disk state of `porofrac-particles`) alone.
//!
//! `n` equal disks of mass `m` stand one on another on a rigid floor under gravity `g`.
//! At rest, the contact below the `k`-th disk from the top carries the weight of the `k`
//! disks above it, `k m g` (per metre of thickness). The example settles columns of 5, 10
//! and 20 disks for a few warm-started steps and prints the largest deviation of the
//! contact forces from `k m g`, with the sweeps of non-linear Gauss–Seidel the first (cold)
//! step took.
//!
//! ```sh
//! cargo run --release -p porofrac-nscd --example column
//! ```

use std::error::Error;

use porofrac_nscd::detect::Antagonist;
use porofrac_nscd::{ContactLaw, Nscd, RigidBody, SolverParams};
use porofrac_particles::Disks;

fn main() -> Result<(), Box<dyn Error>> {
    let g = 9.81;
    let r = 0.5;
    println!(
        "{:>6} {:>14} {:>26}",
        "disks", "first sweeps", "largest |f − k m g|/(n m g)"
    );
    for n in [5usize, 10, 20] {
        let centres: Vec<[f64; 2]> = (0..n).map(|k| [0.0, r + 2.0 * r * k as f64]).collect();
        let disks = Disks::new(&centres, &vec![r; n], 2500.0)?;
        let floor = RigidBody::segment([-10.0, 0.0], [10.0, 0.0]);
        let params = SolverParams {
            theta: 0.5,
            tolerance: 1e-10,
            min_sweeps: 1,
            max_sweeps: 1_000_000,
            ..SolverParams::default()
        };
        let mut nscd = Nscd::new(
            disks,
            vec![floor],
            ContactLaw::frictional(0.3),
            params,
            [0.0, -g],
        )?;
        let mut first_sweeps = 0;
        for step in 0..3 {
            let stats = nscd.step(1e-3)?;
            if step == 0 {
                first_sweeps = stats.sweeps;
            }
        }
        let m = nscd.disks.mass[0];
        let mut worst: f64 = 0.0;
        for c in nscd.contacts() {
            // The contact under disk i carries the n − i disks from i up.
            let below = match c.other {
                Antagonist::Disk(j) => (c.i as usize).max(j as usize),
                Antagonist::Body(_) => 0,
            };
            let exact = (n - below) as f64 * m * g;
            worst = worst.max((nscd.contact_force(c)[0] - exact).abs() / (n as f64 * m * g));
        }
        println!("{n:>6} {first_sweeps:>14} {worst:>26.2e}");
    }
    Ok(())
}
