//! Bond and contact laws, damping and prescribed motions: plain parameter types.
//!
//! Units are per metre of thickness (2D): forces in N/m, moments in N·m/m, normal and
//! shear bond stiffnesses `k_n`, `k_s` in N/m² (force per metre per metre of stretch),
//! bending stiffness `k_b` in N·m/m per radian.
//!
//! # Bond strength (ESyS-Particle "direct Mohr–Coulomb" with a tension cut-off)
//!
//! A bond between disks of radii `R_i`, `R_j` has the width `w = 2 min(R_i, R_j)` and
//! the strengths `F_t = σ_t w` (tension cut-off), `F_c = c w` (shear strength at zero
//! normal force) and `M_max = σ_t w²/6` (bending, the elastic section modulus of a beam
//! of width `w`). With `F_n` tension positive, it breaks
//!
//! * in **tension** if `F_n/F_t + |M_b|/M_max > 1` (β₁ = 1);
//! * in **shear** if `|F_s| > F_c − F_n tan φ` (Mohr–Coulomb: compression raises the
//!   shear strength, tension lowers it).
//!
//! With `σ_t = c / tan φ` this is the ESyS `σ̂ > 1 or τ̂ > 1 − σ̂`; a cut-off above
//! that apex of the Mohr–Coulomb line is refused (the shear test would fire first in
//! pure tension).

use crate::LsmError;

/// The springs and strengths of the bonds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BondLaw {
    /// Normal stiffness `k_n` (N/m²).
    pub kn: f64,
    /// Shear stiffness `k_s` (N/m²).
    pub ks: f64,
    /// Bending stiffness `k_b` (N·m/m per rad).
    pub kb: f64,
    /// Tensile strength σ_t (Pa): the tension cut-off `F_t = σ_t w`.
    pub tensile: f64,
    /// Cohesion c (Pa): the shear strength `F_c = c w` at zero normal force.
    pub cohesion: f64,
    /// Internal friction angle φ of the bond's shear strength (rad).
    pub friction_angle: f64,
}

impl BondLaw {
    /// Unbreakable springs (infinite strengths).
    pub fn elastic(kn: f64, ks: f64, kb: f64) -> Self {
        Self {
            kn,
            ks,
            kb,
            tensile: f64::INFINITY,
            cohesion: f64::INFINITY,
            friction_angle: 0.0,
        }
    }

    /// An error naming the first bad parameter.
    pub fn check(&self) -> Result<(), LsmError> {
        nonneg("bonds.kn", self.kn)?;
        if self.kn == 0.0 {
            return Err(LsmError::bad("bonds.kn", self.kn, "must be positive"));
        }
        nonneg("bonds.ks", self.ks)?;
        nonneg("bonds.kb", self.kb)?;
        for (name, v) in [
            ("bonds.tensile", self.tensile),
            ("bonds.cohesion", self.cohesion),
        ] {
            if v.is_nan() || v <= 0.0 {
                return Err(LsmError::bad(
                    name,
                    v,
                    "must be positive (infinite: unbreakable)",
                ));
            }
        }
        if !(0.0..std::f64::consts::FRAC_PI_2).contains(&self.friction_angle) {
            return Err(LsmError::bad(
                "bonds.friction_angle",
                self.friction_angle,
                "must be in [0, 90°)",
            ));
        }
        if self.tensile > self.cohesion / self.friction_angle.tan() {
            return Err(LsmError::bad(
                "bonds.tensile",
                self.tensile,
                "the tension cut-off must not exceed the apex c/tan φ of the Mohr–Coulomb line",
            ));
        }
        Ok(())
    }
}

/// The normal force law of a contact between unbonded disks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum NormalLaw {
    /// `F_n = k_n δ` with δ the overlap.
    #[default]
    Linear,
    /// `F_n = (4/3) E* √R* δ^{3/2}` with `1/R* = 1/R_i + 1/R_j` and
    /// `E* = E / (2 (1 − ν²))` (Hertz law of two equal elastic materials, applied per
    /// metre of thickness as the classic 2D DEM simplification).
    Hertz {
        /// Young's modulus of the grains (Pa).
        modulus: f64,
        /// Poisson's ratio of the grains.
        poisson: f64,
    },
}

/// Frictional contacts between unbonded disks (also the broken bonds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    /// Normal law.
    pub normal: NormalLaw,
    /// Normal stiffness of the linear law (N/m²).
    pub kn: f64,
    /// Tangential spring stiffness (N/m²), capped by Coulomb friction.
    pub ks: f64,
    /// Coulomb friction coefficient μ (0.6 by default, a common choice).
    pub friction: f64,
}

impl ContactLaw {
    /// Linear contacts with the stiffnesses of the bonds and μ = 0.6.
    pub fn like_bonds(b: &BondLaw) -> Self {
        Self {
            normal: NormalLaw::Linear,
            kn: b.kn,
            ks: b.ks,
            friction: 0.6,
        }
    }

    /// An error naming the first bad parameter.
    pub fn check(&self) -> Result<(), LsmError> {
        nonneg("contacts.kn", self.kn)?;
        nonneg("contacts.ks", self.ks)?;
        nonneg("contacts.friction", self.friction)?;
        if let NormalLaw::Hertz { modulus, poisson } = self.normal {
            if !(modulus.is_finite() && modulus > 0.0) {
                return Err(LsmError::bad(
                    "contacts.modulus",
                    modulus,
                    "must be positive",
                ));
            }
            if !(poisson > -1.0 && poisson < 0.5) {
                return Err(LsmError::bad(
                    "contacts.poisson",
                    poisson,
                    "must be in (-1, 0.5)",
                ));
            }
        }
        Ok(())
    }

    /// Normal force (compression positive) and tangent stiffness at overlap δ ≥ 0 for
    /// the effective radius `r_eff`.
    #[inline]
    pub(crate) fn normal_force(&self, overlap: f64, r_eff: f64) -> f64 {
        match self.normal {
            NormalLaw::Linear => self.kn * overlap,
            NormalLaw::Hertz { modulus, poisson } => {
                let e = modulus / (2.0 * (1.0 - poisson * poisson));
                4.0 / 3.0 * e * r_eff.sqrt() * overlap * overlap.sqrt()
            }
        }
    }

    /// Normal tangent stiffness used in the stable time step: the linear `k_n`, or the
    /// Hertz tangent at an overlap of 5 % of the effective radius.
    pub(crate) fn normal_stiffness(&self, r_eff: f64) -> f64 {
        match self.normal {
            NormalLaw::Linear => self.kn,
            NormalLaw::Hertz { modulus, poisson } => {
                let e = modulus / (2.0 * (1.0 - poisson * poisson));
                2.0 * e * r_eff.sqrt() * (0.05 * r_eff).sqrt()
            }
        }
    }
}

/// Damping of the motion, for quasi-static loading.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Damping {
    /// None: the velocity Verlet scheme conserves energy.
    #[default]
    None,
    /// Local (Cundall) damping: each force component `f` becomes
    /// `f − α |f| sign(v)`, α in [0, 1).
    Local {
        /// α.
        alpha: f64,
    },
    /// Mass-proportional viscous damping: force `−c m v`, torque `−c I ω` (c in 1/s).
    Viscous {
        /// c (1/s).
        rate: f64,
    },
}

impl Damping {
    /// An error naming the bad parameter.
    pub fn check(&self) -> Result<(), LsmError> {
        match *self {
            Damping::None => Ok(()),
            Damping::Local { alpha } if !(0.0..1.0).contains(&alpha) => {
                Err(LsmError::bad("damping.alpha", alpha, "must be in [0, 1)"))
            }
            Damping::Viscous { rate } if !(rate.is_finite() && rate >= 0.0) => {
                Err(LsmError::bad("damping.rate", rate, "must be non-negative"))
            }
            _ => Ok(()),
        }
    }

    /// The damped force component for the velocity component `v` and mass `m`.
    #[inline]
    pub(crate) fn apply(&self, f: f64, v: f64, m: f64) -> f64 {
        match *self {
            Damping::None => f,
            Damping::Local { alpha } => f - alpha * f.abs() * v.signum() * (v != 0.0) as u8 as f64,
            Damping::Viscous { rate } => f - rate * m * v,
        }
    }
}

/// How a disk moves.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Motion {
    /// Newton's law under its forces.
    #[default]
    Free,
    /// Held in place, no rotation.
    Fixed,
    /// Moves with a prescribed velocity (m/s), no rotation (a platen or wall particle).
    Velocity([f64; 2]),
    /// The velocity along one axis (0 = x, 1 = y) is prescribed; the other axis and the
    /// rotation are free (a frictionless platen).
    Axis {
        /// 0 or 1.
        axis: usize,
        /// Prescribed velocity along it (m/s).
        velocity: f64,
    },
}

fn nonneg(name: &'static str, v: f64) -> Result<(), LsmError> {
    if !(v.is_finite() && v >= 0.0) {
        return Err(LsmError::bad(
            name,
            v,
            "must be a non-negative finite number",
        ));
    }
    Ok(())
}
