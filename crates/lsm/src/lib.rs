//! Lattice solid model (P. Mora, Y. Wang, F. Alonso-Marroquin (2015), J. Earth Sci.
//! 26(1); that paper does not give the bond model, which follows Wang (2009) and
//! ESyS-Particle): 2D disks joined by breakable bonds with normal, shear and bending
//! springs, frictional contacts between unbonded disks, explicit velocity Verlet in time.
//!
//! * [`law`]: bond law (springs, Mohr–Coulomb strength with a tension cut-off), contact
//!   law (linear or Hertz normal force, Coulomb friction), damping, prescribed motions;
//! * [`bond`]: one bond's forces and breakage test; [`contact`]: one contact's forces;
//! * [`solid`]: [`LatticeSolid`], the state and the time step;
//! * [`wall`]: the pressure of a borehole as forces on the particles lining it;
//! * [`crack`]: the crack connected to a borehole wall and its radial extent (the
//!   breakdown of a borehole as an event);
//! * [`calibrate`]: spring stiffnesses from E and ν on a hexagonal lattice (closed form
//!   below) and numerical calibration of random packings (uniaxial compression for E
//!   and ν, Brazilian test for the tensile strength);
//! * [`toughness`]: the fracture toughness of a packing from a pressurised notch, and
//!   the strength and fracture-mechanics estimates of a pressurised hole's breakdown.
//!
//! Everything is per metre of thickness: forces N/m, moments N·m/m, stiffnesses
//! `k_n`, `k_s` in N/m² (Pa), `k_b` in N·m/m per radian, masses kg/m.
//!
//! # Hexagonal lattice: E and ν from k_n and k_s (derived here)
//!
//! Equal disks of diameter d on a triangular lattice, every touching pair bonded. Under
//! a homogeneous strain ε (and a rigid rotation w) the relative displacement of a bond
//! of direction n is `d (ε + W) n`: its stretch is `d n·ε·n` and its shear
//! `δ_s = d (t·ε·n + w − θ)` with θ the particle rotation. Every particle is a centre of
//! symmetry, so all rotate alike; the energy is least for `Σ_bonds (t·ε·n + w − θ) = 0`,
//! and `Σ t_a n_b` over the six bond directions is `3(e_y e_xᵀ − e_x e_yᵀ)`, which
//! vanishes on a symmetric ε: θ = w and `δ_s = d t·ε·n`. A particle owns the area
//! `(√3/2) d²` and three bonds (α = 0°, 60°, 120°), so the energy density is
//!
//! `W = (1/√3) Σ_α [k_n (n·ε·n)² + k_s (t·ε·n)²]`.
//!
//! With `Σ cos⁴α = 9/8`, `Σ sin²α cos²α = 3/8` this gives the isotropic stiffnesses
//! `C₁₁ = (√3/4)(3k_n + k_s)` and `C₁₂ = (√3/4)(k_n − k_s)`, so that
//!
//! `E = C₁₁ − C₁₂²/C₁₁ = 2√3 k_n (k_n + k_s)/(3k_n + k_s)`,
//! `ν = C₁₂/C₁₁ = (k_n − k_s)/(3k_n + k_s)`,
//!
//! and inversely `k_n = E/(√3 (1 − ν))`, `k_s = k_n (1 − 3ν)/(1 + ν)`: a lattice of
//! non-negative springs has `ν ≤ 1/3` (2D elasticity of a sheet, E per unit thickness).
//! The bending spring does not enter (no relative rotation under a homogeneous strain).
//! The test `hexagonal_lattice_moduli` measures E and ν on a strained lattice.

#![warn(missing_docs)]

pub mod bond;
pub mod calibrate;
pub mod contact;
pub mod crack;
pub mod law;
pub mod solid;
pub mod toughness;
pub mod wall;

pub use bond::{Bond, BondForce, BreakMode, BrokenBond};
pub use crack::{CrackExtent, CrackFaces, FaceWidths};
pub use law::{BondLaw, ContactLaw, Damping, Motion, NormalLaw};
pub use solid::state::SolidState;
pub use solid::{LatticeSolid, LsmSpec, StepReport};
pub use wall::{PressureWall, WallFaces};

/// A bad parameter or a failed step. Every variant names the argument or the particle.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum LsmError {
    /// A parameter out of range.
    #[error("{name} = {value}: {message}")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What is wrong.
        message: &'static str,
    },
    /// A time step above the stable one.
    #[error("dt = {dt:.4e} s is above the stable time step {stable:.4e} s")]
    TimeStep {
        /// The step asked for.
        dt: f64,
        /// The stable step.
        stable: f64,
    },
    /// External forces for the wrong number of particles.
    #[error("external forces: {got} given for {expected} particles (or none)")]
    External {
        /// Entries given.
        got: usize,
        /// Particles.
        expected: usize,
    },
    /// A value of a particle that is not finite.
    #[error("particle {index}: {what} is not finite")]
    NotFinite {
        /// Particle.
        index: usize,
        /// Which value.
        what: &'static str,
    },
    /// Two particles overlap by more than the tolerance.
    #[error(
        "particles {i} and {j} overlap by {overlap:.3e} m, more than the {allowed:.3e} m allowed"
    )]
    Overlap {
        /// First.
        i: usize,
        /// Second.
        j: usize,
        /// Overlap (m).
        overlap: f64,
        /// Allowed (m).
        allowed: f64,
    },
    /// A calibration that could not be carried out.
    #[error("calibration: {0}")]
    Calibration(String),
    /// The progress callback asked to stop.
    #[error("interrupted")]
    Interrupted,
    /// A saved state that does not fit the solid ([`LatticeSolid::restore_state`]).
    #[error("saved state: {0}")]
    State(String),
}

impl LsmError {
    pub(crate) fn bad(name: &'static str, value: f64, message: &'static str) -> Self {
        LsmError::BadParameter {
            name,
            value,
            message,
        }
    }
}
