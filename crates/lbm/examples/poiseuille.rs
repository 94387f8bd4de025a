//! Plane Poiseuille flow with `porofrac-lbm` alone: a channel between two halfway
//! bounce-back walls, periodic along x, driven by a uniform body acceleration `g`.
//!
//! The steady profile is the parabola `u(y) = g / (2ν) · y (H − y)` with the walls at
//! `y = 0` and `y = H` (half a spacing outside the first and last rows of nodes) and
//! `ν = (τ − ½)/3` in lattice units. The two-relaxation-time collision with the magic
//! parameter `Λ = 3/16` reproduces it to round-off on any lattice; the example prints the
//! largest deviation from it relative to the centre-line speed.
//!
//! ```sh
//! cargo run --release -p porofrac-lbm --example poiseuille
//! ```

use porofrac_lbm::{Collision, Lattice, LatticeConfig, LbmError, SideKind};

fn main() -> Result<(), LbmError> {
    let (nx, ny) = (4, 24);
    let (tau, accel) = (0.8, 1e-6);
    let mut config = LatticeConfig::periodic(nx, ny, tau);
    config.collision = Collision::trt();
    config.periodic = [true, false];
    config.sides = [SideKind::Wall; 4];
    config.accel = [accel, 0.0];
    let mut lattice = Lattice::new(config)?;

    // March to a steady state: stop when the centre-line speed changes by less than 1e-12
    // of itself over 500 steps.
    let mut last = f64::MAX;
    for step in 0..400_000 {
        lattice.step()?;
        if step % 500 == 0 {
            let u = lattice.moments(0, ny / 2).1[0];
            if (u - last).abs() <= 1e-12 * u.abs() {
                break;
            }
            last = u;
        }
    }

    let nu = (tau - 0.5) / 3.0;
    let h = ny as f64;
    let exact = |y: f64| accel / (2.0 * nu) * y * (h - y);
    let u_max = exact(h / 2.0);
    println!("{:>6} {:>14} {:>14}", "y", "u (lattice)", "exact");
    let mut worst: f64 = 0.0;
    for j in 0..ny {
        let y = j as f64 + 0.5;
        let u = lattice.moments(0, j).1[0];
        worst = worst.max((u - exact(y)).abs());
        if j % 4 == 0 {
            println!("{y:>6.1} {u:>14.6e} {:>14.6e}", exact(y));
        }
    }
    println!(
        "after {} steps: largest deviation {:.2e} of the centre-line speed",
        lattice.steps(),
        worst / u_max
    );
    Ok(())
}
