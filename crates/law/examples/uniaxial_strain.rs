//! Stiffness tensors in Kelvin notation with `porofrac-law` alone: the oedometer
//! (uniaxial-strain) modulus, plane stress against plane strain, and principal stresses.
//!
//! In Kelvin notation a symmetric tensor is the vector `[e11, e22, √2 e12]` (3D:
//! `[e11, e22, e33, √2 e23, √2 e13, √2 e12]`), so an isotropic stiffness is a symmetric
//! 3×3 (6×6) matrix and `σ = 2μ ε + λ tr(ε) I` is a matrix–vector product. The example
//! checks three closed forms:
//!
//! * uniaxial strain `ε = ε₀ e₁⊗e₁`: `σ₁₁ = (λ + 2μ) ε₀`, `σ₂₂ = σ₃₃ = λ ε₀`;
//! * plane stress: a uniaxial stress `σ₁₁` needs `ε₁₁ = σ₁₁ / E` (and `ε₂₂ = −ν ε₁₁`);
//! * a pure shear strain `γ` has principal stresses `±μγ` at 45°.
//!
//! ```sh
//! cargo run --release -p porofrac-law --example uniaxial_strain
//! ```

use porofrac_law::{LawError, Stiffness, Tensor, principal};

fn main() -> Result<(), LawError> {
    let (e, nu) = (20.0e9, 0.25);
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));

    // Uniaxial strain in 3D.
    let d3 = Stiffness::<3>::isotropic(e, nu)?;
    let eps0 = 1.0e-4;
    let mut strain = Tensor::<3>::zeros();
    strain[(0, 0)] = eps0;
    let s = d3.stress(&strain);
    println!("uniaxial strain ε₀ = {eps0:e}");
    println!(
        "  σ11 = {:.6e} Pa   (λ + 2μ) ε₀ = {:.6e}",
        s[(0, 0)],
        (lambda + 2.0 * mu) * eps0
    );
    println!(
        "  σ22 = {:.6e} Pa   λ ε₀        = {:.6e}",
        s[(1, 1)],
        lambda * eps0
    );
    println!(
        "  energy density {:.6e} J/m³ = ½ σ11 ε₀ = {:.6e}",
        d3.energy_density(&strain),
        0.5 * s[(0, 0)] * eps0
    );

    // Plane stress: the strain of a uniaxial stress σ11 = E ε (ε22 = −ν ε).
    let d2 = Stiffness::<2>::isotropic_plane_stress(e, nu)?;
    let mut strain2 = Tensor::<2>::zeros();
    strain2[(0, 0)] = eps0;
    strain2[(1, 1)] = -nu * eps0;
    let s2 = d2.stress(&strain2);
    println!("plane stress, ε = (ε₀, −ν ε₀)");
    println!(
        "  σ11 = {:.6e} Pa   E ε₀ = {:.6e}; σ22 = {:.1e} Pa",
        s2[(0, 0)],
        e * eps0,
        s2[(1, 1)]
    );

    // Pure shear: principal stresses ±μγ along the diagonals.
    let gamma = 2.0e-4;
    let mut shear = Tensor::<2>::zeros();
    shear[(0, 1)] = 0.5 * gamma;
    shear[(1, 0)] = 0.5 * gamma;
    let p = principal(&Stiffness::<2>::isotropic(e, nu)?.stress(&shear));
    let dir = p.directions[0];
    println!("pure shear γ = {gamma:e}");
    println!(
        "  σ_max = {:.6e}, σ_min = {:.6e} Pa (±μγ = {:.6e}); direction of σ_max at {:.1}°",
        p.values[0],
        p.values[1],
        mu * gamma,
        dir[1].atan2(dir[0]).to_degrees()
    );
    Ok(())
}
