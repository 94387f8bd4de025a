//! Checks of `[lbm]` and `[thermal]` (every model that has a fluid): the lattice a scene
//! asks for is bounded, velocities stay below the Mach limit, relaxation times above
//! `TAU_MIN`, before anything is allocated.

use porofrac_lbm::{MAX_MACH, TAU_MIN, Units};

use super::sections::BoundaryKindChoice;
use crate::common::expr::Expr;
use crate::common::loaded::{LoadedScene, SceneError, k, ki};
use crate::common::sections::{KeyPart, NumOrExpr};

/// Most lattice nodes a scene may ask for.
pub const MAX_NODES: f64 = 1.0e9;

/// `v` is a finite number > 0.
pub(crate) fn positive(ls: &LoadedScene, key: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if !(v.is_finite() && v > 0.0) {
        return Err(ls.error(key, format!("= {v} must be > 0")));
    }
    Ok(())
}

/// A finite number or an expression that parses.
pub(crate) fn expr(ls: &LoadedScene, key: &[KeyPart], v: &NumOrExpr) -> Result<(), SceneError> {
    match v {
        NumOrExpr::Num(x) if !x.is_finite() => {
            Err(ls.error(key, format!("= {x} is not a finite number")))
        }
        NumOrExpr::Num(_) => Ok(()),
        NumOrExpr::Expr(s) => Expr::parse(s)
            .map(|_| ())
            .map_err(|e| ls.error(key, format!("= \"{s}\": bad expression at {e}"))),
    }
}

/// Two components, each a finite number or an expression that parses.
pub(crate) fn vector(ls: &LoadedScene, key: &[KeyPart], v: &[NumOrExpr]) -> Result<(), SceneError> {
    if v.len() != 2 {
        return Err(ls.error(key, format!("has {} components, the scene is 2D", v.len())));
    }
    v.iter().try_for_each(|c| expr(ls, key, c))
}

/// Constant velocities above the Mach limit are refused here; expressions are checked at
/// every step of the run.
pub(crate) fn mach_of(
    ls: &LoadedScene,
    key: &[KeyPart],
    v: &[NumOrExpr],
    units: &Units,
) -> Result<(), SceneError> {
    if let (NumOrExpr::Num(a), NumOrExpr::Num(b)) = (&v[0], &v[1]) {
        let speed = (a * a + b * b).sqrt();
        let ma = units.mach(speed);
        if ma > MAX_MACH {
            return Err(ls.error(
                key,
                format!(
                    "= {speed} m/s is Mach {ma:.3} on this lattice (limit {MAX_MACH}): refine the spacing, lower tau or the velocity"
                ),
            ));
        }
        if units.velocity(speed) >= 1.0 {
            return Err(ls.error(key, "moves a node or more per step"));
        }
    }
    Ok(())
}

/// Check `[lbm]` and its `[[lbm.boundary]]`s (every model that has a fluid). Returns the
/// units and the periodic axes.
pub(crate) fn check_section(ls: &LoadedScene) -> Result<(Units, [bool; 2]), SceneError> {
    let s = &ls.scene;
    let Some(l) = &s.lbm else {
        return Err(ls.error(
            &k(&["lbm"]),
            format!("is required by model \"{}\"", ls.model()),
        ));
    };
    let key = |f: &str| k(&["lbm", f]);
    for a in 0..2 {
        if l.extent[a].len() != 2 {
            return Err(ls.error(&key("extent"), "must be [[x0, y0], [x1, y1]]"));
        }
    }
    for a in 0..2 {
        let (lo, hi) = (l.extent[0][a], l.extent[1][a]);
        if !(lo.is_finite() && hi.is_finite() && hi > lo) {
            return Err(ls.error(&key("extent"), format!("needs min < max on axis {a}")));
        }
    }
    positive(ls, &key("spacing"), l.spacing)?;
    positive(ls, &key("density"), l.density)?;
    positive(ls, &key("viscosity"), l.viscosity)?;
    if !(l.tau > TAU_MIN && l.tau.is_finite()) {
        return Err(ls.error(
            &key("tau"),
            format!(
                "= {} must be above {TAU_MIN} (tau = 1/2 is zero viscosity)",
                l.tau
            ),
        ));
    }
    if let Some(m) = l.magic {
        if l.collision != super::sections::CollisionChoice::Trt {
            return Err(ls.error(&key("magic"), "applies to collision = \"trt\" only"));
        }
        positive(ls, &key("magic"), m)?;
    }
    let (nx, ny) = super::nodes(l);
    if !((2.0..=32768.0).contains(&nx) && (2.0..=32768.0).contains(&ny)) || nx * ny > MAX_NODES {
        return Err(ls.error(
            &key("spacing"),
            format!(
                "= {} gives {nx} × {ny} nodes: each side needs 2 to 32768 nodes",
                l.spacing
            ),
        ));
    }
    crate::common::limits::fits_in_memory(
        nx * ny * 100.0,
        &format!("a lattice of {nx} × {ny} nodes"),
    )
    .map_err(|e| ls.error(&key("spacing"), e))?;
    let units = Units::from_viscosity(l.spacing, l.viscosity, l.density, l.tau)
        .map_err(|e| ls.error(&key("tau"), e))?;
    if let Some(b) = &l.body_force
        && (b.len() != 2 || !b.iter().all(|v| v.is_finite()))
    {
        return Err(ls.error(&key("body_force"), "must be two finite numbers (m/s²)"));
    }
    if let Some(b) = &l.body_force {
        // One lattice step of the body force alone must not carry the fluid past the
        // Mach limit: the lattice acceleration is a velocity gained per step.
        let g = b[0].hypot(b[1]);
        let per_step = units.acceleration(g);
        let limit = MAX_MACH * (1.0f64 / 3.0).sqrt();
        if !per_step.is_finite() || per_step >= limit {
            return Err(ls.error(
                &key("body_force"),
                format!(
                    "= {g:e} m/s² adds {per_step:.3e} lattice velocity units per step, more \
                     than the Mach limit {MAX_MACH} allows in one step ({limit:.3e}): lower \
                     the body force, or refine the spacing or lower tau"
                ),
            ));
        }
    }
    if let Some(v) = &l.initial_velocity {
        vector(ls, &key("initial_velocity"), v)?;
    }
    let mut seen = [false; 2];
    for &a in &l.periodic {
        let i = a as usize;
        if seen[i] {
            return Err(ls.error(&key("periodic"), "names an axis twice"));
        }
        seen[i] = true;
    }
    let mut sides = std::collections::BTreeSet::new();
    for (i, b) in l.boundary.iter().enumerate() {
        let bk = |f: &str| ki("lbm.boundary", i, &[f]);
        let axis = match b.side {
            super::sections::SideChoice::Xmin | super::sections::SideChoice::Xmax => 0,
            _ => 1,
        };
        if seen[axis] {
            return Err(ls.error(
                &bk("side"),
                format!("= \"{}\" is on a periodic axis", b.side.as_str()),
            ));
        }
        if !sides.insert(b.side.as_str()) {
            return Err(ls.error(
                &bk("side"),
                format!("= \"{}\" is given twice", b.side.as_str()),
            ));
        }
        match b.kind {
            BoundaryKindChoice::Pressure => {
                if b.velocity.is_some() {
                    return Err(ls.error(&bk("velocity"), "does not apply to kind = \"pressure\""));
                }
                let Some(p) = b.pressure else {
                    return Err(ls.error(&bk("pressure"), "is required for kind = \"pressure\""));
                };
                if !p.is_finite() {
                    return Err(ls.error(&bk("pressure"), format!("= {p} is not a finite number")));
                }
                let rho = units.pressure_density(p);
                if !(rho > 0.5 && rho < 1.5) {
                    return Err(ls.error(
                        &bk("pressure"),
                        format!(
                            "= {p} Pa is a lattice density of {rho:.3}: keep it within 1 ± 0.5"
                        ),
                    ));
                }
            }
            BoundaryKindChoice::Wall | BoundaryKindChoice::Velocity => {
                if b.pressure.is_some() {
                    return Err(ls.error(&bk("pressure"), "applies to kind = \"pressure\" only"));
                }
                if let Some(v) = &b.velocity {
                    vector(ls, &bk("velocity"), v)?;
                    mach_of(ls, &bk("velocity"), v, &units)?;
                } else if b.kind == BoundaryKindChoice::Velocity {
                    return Err(ls.error(&bk("velocity"), "is required for kind = \"velocity\""));
                }
            }
        }
    }
    Ok((units, seen))
}

/// Check `[thermal]` against the lattice of `units` with periodic axes `seen`.
pub(crate) fn check_thermal(
    ls: &LoadedScene,
    units: &Units,
    seen: [bool; 2],
) -> Result<(), SceneError> {
    let s = &ls.scene;
    if let Some(t) = &s.thermal {
        let tk = |f: &str| k(&["thermal", f]);
        for (f, chi) in [
            ("diffusivity", Some(t.diffusivity)),
            ("solid_diffusivity", t.solid_diffusivity),
        ] {
            let Some(chi) = chi else { continue };
            positive(ls, &tk(f), chi)?;
            let tau = super::thermal_tau(chi, units);
            if !(tau > TAU_MIN && tau.is_finite()) {
                return Err(ls.error(
                    &tk(f),
                    format!(
                        "= {chi} m²/s gives a thermal relaxation time of {tau:.4} on this lattice (must exceed {TAU_MIN}): raise lbm.tau or refine lbm.spacing"
                    ),
                ));
            }
        }
        if let Some(v) = &t.initial {
            expr(ls, &tk("initial"), v)?;
        }
        let mut tsides = std::collections::BTreeSet::new();
        for (i, b) in t.boundary.iter().enumerate() {
            let bk = |f: &str| ki("thermal.boundary", i, &[f]);
            let axis = match b.side {
                super::sections::SideChoice::Xmin | super::sections::SideChoice::Xmax => 0,
                _ => 1,
            };
            if seen[axis] {
                return Err(ls.error(
                    &bk("side"),
                    format!("= \"{}\" is on a periodic axis", b.side.as_str()),
                ));
            }
            if !tsides.insert(b.side.as_str()) {
                return Err(ls.error(
                    &bk("side"),
                    format!("= \"{}\" is given twice", b.side.as_str()),
                ));
            }
            let given = b.temperature.is_some() as u8 + b.flux.is_some() as u8 + b.outflow as u8;
            if given != 1 {
                return Err(ls.error(
                    &bk("side"),
                    "needs exactly one of temperature, flux and outflow = true",
                ));
            }
            if let Some(v) = b.temperature
                && !v.is_finite()
            {
                return Err(ls.error(&bk("temperature"), format!("= {v} is not a finite number")));
            }
            if let Some(v) = b.flux
                && !v.is_finite()
            {
                return Err(ls.error(&bk("flux"), format!("= {v} is not a finite number")));
            }
        }
    }
    Ok(())
}

/// In a scene of `model` without a lattice: probes of an obstacle are refused.
pub fn refuse_obstacle_probes(ls: &LoadedScene, model: &str) -> Result<(), SceneError> {
    match ls
        .scene
        .output
        .probe
        .iter()
        .position(|p| p.obstacle.is_some())
    {
        Some(i) => Err(ls.error(
            &ki("output.probe", i, &["obstacle"]),
            format!("belongs to model \"lbm\", not \"{model}\""),
        )),
        None => Ok(()),
    }
}
