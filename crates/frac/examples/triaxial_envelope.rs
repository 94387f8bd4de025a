//! The strength of a rock sample in a triaxial test, from `porofrac-frac`'s criteria alone.
//!
//! A cylinder under a confining pressure `p` is loaded axially until it fails. With
//! tension positive, its principal stresses are `σ₁ = −p` (radial) and `σ₃ = −q` (axial);
//! the Mohr–Coulomb criterion of cohesion `c` and friction angle `φ` is met when
//! `(σ₁ − σ₃)/2 = c cos φ − (σ₁ + σ₃)/2 · sin φ`, i.e. at the axial stress
//!
//! `q_f = p (1 + sin φ)/(1 − sin φ) + 2 c cos φ/(1 − sin φ)`.
//!
//! The example finds `q_f` by bisection on the criterion's own decision
//! ([`FailureCriterion::check`]) for a few confining pressures and prints it beside the
//! closed form; it also checks the tensile cut-off on a sample pulled along its axis.
//!
//! ```sh
//! cargo run --release -p porofrac-frac --example triaxial_envelope
//! ```

use porofrac_frac::{FailureCriterion, FailureMode, FracError, MohrCoulomb, Tensile};
use porofrac_law::Tensor;

/// The stress of the sample: radial `-p` on x and y, axial `-q` on z (Pa, tension positive).
fn triaxial(p: f64, q: f64) -> Tensor<3> {
    Tensor::<3>::from_diagonal(&nalgebra::Vector3::new(-p, -p, -q))
}

fn main() -> Result<(), FracError> {
    let (cohesion, phi_deg) = (5.0e6, 30.0);
    let shear = MohrCoulomb::new(cohesion, phi_deg)?;
    let s = phi_deg.to_radians().sin();
    let c = phi_deg.to_radians().cos();
    println!("Mohr–Coulomb, c = {cohesion:.1e} Pa, φ = {phi_deg}°");
    println!(
        "{:>12} {:>16} {:>16} {:>10}",
        "p (Pa)", "q_f bisection", "q_f closed form", "rel. diff"
    );
    for p in [0.0, 5.0e6, 10.0e6, 20.0e6, 40.0e6] {
        // Bracket: intact at q = p (hydrostatic), failed at a very large axial load.
        let (mut lo, mut hi) = (p, p + 1.0e10);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            match shear.check(&triaxial(p, mid)) {
                Some(FailureMode::Shear) => hi = mid,
                _ => lo = mid,
            }
        }
        let exact = p * (1.0 + s) / (1.0 - s) + 2.0 * cohesion * c / (1.0 - s);
        let found = 0.5 * (lo + hi);
        println!(
            "{p:>12.3e} {found:>16.6e} {exact:>16.6e} {:>10.1e}",
            (found - exact).abs() / exact
        );
    }

    // Tensile cut-off: pulled along z with no confinement, the sample fails when the axial
    // tension exceeds the strength.
    let tensile = Tensile::new(2.0e6)?;
    for pull in [1.9e6, 2.1e6] {
        let stress = triaxial(0.0, -pull);
        println!(
            "pulled at {pull:.2e} Pa: {:?} (utilization {:.3})",
            tensile.check(&stress),
            tensile.utilization(&stress)
        );
    }
    Ok(())
}
