//! Bounds on the numbers of a material, a fluid and an output point, checked when a
//! scene is checked so that a run never starts from a number that makes its systems
//! overflow (or a probe that samples nowhere).
//!
//! - **Moduli** (Young's, shear, bulk, Cosserat shear and couple moduli; Pa or the
//!   scene's unit of stress) lie in [`MIN_MODULUS`] … [`MAX_MODULUS`]: soft gels are
//!   about 1e2 Pa and diamond 1.2e12 Pa, so the range holds every rock and every
//!   nondimensional scene (E = 1) with three orders of magnitude to spare either way,
//!   while a modulus of 1e300 (whose stiffness matrix overflows when assembled) is
//!   refused with its key and line.
//! - **Fluid**: the viscosity lies in [`MIN_VISCOSITY`] … [`MAX_VISCOSITY`] (gases are
//!   about 1e-5 Pa s, bitumen 1e5 Pa s) and the compressibility is finite and ≥ 0.
//! - **Output points** (`[[output.probe]] at`, `[[output.line]] from`/`to`) are finite
//!   and, where the grid's box is known from its keys, inside that box.
//! - **States**: a run whose stresses pass [`MAX_STRESS`] has overflowed; the models end
//!   it with an error naming the loads and moduli of the scene.

use crate::common::loaded::{LoadedScene, SceneError};
use crate::common::sections::KeyPart;

/// Largest stress component a state may hold (Pa): the invariants of the output fields
/// (von Mises, principal stresses) square the components, which overflows beyond about
/// 1e154; no rock holds a stress within a hundred orders of magnitude of this, so a larger
/// one is an overflowed load.
pub const MAX_STRESS: f64 = 1e150;

/// Smallest modulus a scene may give (Pa).
pub const MIN_MODULUS: f64 = 1e-3;
/// Largest modulus a scene may give (Pa).
pub const MAX_MODULUS: f64 = 1e15;
/// Smallest fluid viscosity (Pa s).
pub const MIN_VISCOSITY: f64 = 1e-9;
/// Largest fluid viscosity (Pa s).
pub const MAX_VISCOSITY: f64 = 1e12;

/// `v` is a modulus in [`MIN_MODULUS`] … [`MAX_MODULUS`]; `zero_ok` also lets `0` through
/// (a Cosserat shear modulus of zero is the classical medium).
pub fn modulus(
    ls: &LoadedScene,
    path: &[KeyPart],
    v: f64,
    zero_ok: bool,
) -> Result<(), SceneError> {
    if (zero_ok && v == 0.0) || (MIN_MODULUS..=MAX_MODULUS).contains(&v) {
        return Ok(());
    }
    let zero = if zero_ok { "0 or " } else { "" };
    Err(ls.error(
        path,
        format!(
            "= {} must be {zero}in {MIN_MODULUS:e} … {MAX_MODULUS:e} Pa (a modulus outside \
             this range makes the stiffness of the scene overflow or vanish)",
            number(v)
        ),
    ))
}

/// The `[fluid]` numbers: viscosity in [`MIN_VISCOSITY`] … [`MAX_VISCOSITY`] and a
/// finite compressibility ≥ 0.
pub fn fluid(ls: &LoadedScene, fluid: &crate::common::sections::Fluid) -> Result<(), SceneError> {
    let key = |f: &str| crate::common::loaded::k(&["fluid", f]);
    let mu = fluid.viscosity;
    if !(MIN_VISCOSITY..=MAX_VISCOSITY).contains(&mu) {
        return Err(ls.error(
            &key("viscosity"),
            format!(
                "= {} must be in {MIN_VISCOSITY:e} … {MAX_VISCOSITY:e} Pa s",
                number(mu)
            ),
        ));
    }
    let c = fluid.compressibility;
    if !(c.is_finite() && c >= 0.0) {
        return Err(ls.error(
            &key("compressibility"),
            format!("= {c} must be a finite number ≥ 0 (1/Pa)"),
        ));
    }
    Ok(())
}

/// A point of the outputs is finite and, when `extent` (the grid's box from its keys) is
/// known, inside it (up to a relative 1e-9 of the box for points on its sides).
pub fn point_inside(
    ls: &LoadedScene,
    path: &[KeyPart],
    x: &[f64],
    extent: Option<&[Vec<f64>; 2]>,
) -> Result<(), SceneError> {
    if let Some(v) = x.iter().find(|v| !v.is_finite()) {
        return Err(ls.error(
            path,
            format!("has the component {v}: a point must have finite coordinates"),
        ));
    }
    let Some([lo, hi]) = extent else {
        return Ok(());
    };
    let axes = ["x", "y", "z"];
    for (a, &v) in x.iter().enumerate() {
        let (Some(&l), Some(&h)) = (lo.get(a), hi.get(a)) else {
            continue;
        };
        let slack = 1e-9 * (h - l).abs();
        if v < l - slack || v > h + slack {
            return Err(ls.error(
                path,
                format!(
                    "has {} = {v}, outside the grid (grid.extent: {l} … {h})",
                    axes.get(a).copied().unwrap_or("?")
                ),
            ));
        }
    }
    Ok(())
}

/// A number as a user wrote it: plain between 10⁻³ and 10⁶ (`-1`, `0.5`), else in
/// exponent form (`1e300`), so a message never spells out hundreds of digits.
fn number(v: f64) -> String {
    if v == 0.0 || (1e-3..1e6).contains(&v.abs()) || !v.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}
