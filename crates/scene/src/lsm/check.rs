//! Validation of a lattice solid scene: the keys of other models refused with the key
//! and the model named, every value checked (the bond law is built here, so that a bad
//! stiffness or strength names its key).

use crate::common::loaded::{LoadedScene, SceneError, k, ki};
use crate::common::sections::KeyPart;
use porofrac_lsm::{BondLaw, LsmError};

use super::file::{DampingChoice, NormalChoice};

/// Fields of a tracked cell (`torque`: the moment about the cell's centre of the forces
/// the rest of the solid exerts on the cell's disks through the bonds and contacts that
/// cross its boundary, N·m/m, [`super::reaction::exerted_on`]).
pub const CELL_FIELDS: [&str; 9] = [
    "p",
    "q",
    "anisotropy",
    "anisotropy_volume",
    "dilation_x",
    "dilation_y",
    "contacts",
    "broken_bonds",
    "torque",
];

/// The names a probe's `wall` takes in model `lsm`, with fields `fx fy torque`: the
/// platens of `[loading] platens` (`"top"`, `"bottom"`: the force each exerts on the
/// rest of the sample, N/m, and its moment about the mean centre of the platen's disks,
/// N·m/m) and the pressurised hole (`"hole"`: the force of the hole pressure on the
/// lining disks and its moment about the hole centre).
pub const WALLS: [&str; 3] = ["top", "bottom", "hole"];
/// Fields of the whole scene: wall pressure (Pa), platen load (N/m), broken bonds (all,
/// tensile, shear), extent of the crack connected to the hole wall (m from the hole
/// centre; scenes with a pressurised hole).
pub const GLOBAL_FIELDS: [&str; 6] = [
    "pressure",
    "platen_force",
    "broken",
    "broken_tensile",
    "broken_shear",
    "crack_extent",
];

/// Fields of the fluid at a point `at = [x, y]` (scenes with `[lbm]`): gauge pressure
/// (Pa) and speed (m/s), bilinear between the fluid nodes around the point.
pub const FLUID_FIELDS: [&str; 2] = ["fluid_pressure", "fluid_speed"];

/// The unit of an LSM probe or line field (particle, cell, whole-scene or fluid field).
pub fn unit(field: &str) -> &'static str {
    crate::common::particle_output::particle_unit(field).unwrap_or(match field {
        "pressure" | "fluid_pressure" => "Pa",
        "platen_force" => "N/m",
        "torque" => "N·m/m",
        "crack_extent" => "m",
        "fluid_speed" => "m/s",
        _ => "1",
    })
}

/// Check the fluid point probes; returns the scene with each of them replaced by a
/// scene-wide probe of the same name, for the checks shared with the other particle
/// model (which refuse `at`).
fn check_fluid_probes(ls: &LoadedScene) -> Result<Option<LoadedScene>, SceneError> {
    let s = &ls.scene;
    let mut out: Option<LoadedScene> = None;
    for (i, p) in s.output.probe.iter().enumerate() {
        if !FLUID_FIELDS.contains(&p.field.as_str()) {
            continue;
        }
        let key = |f: &str| ki("output.probe", i, &[f]);
        let Some(l) = &s.lbm else {
            return Err(ls.error(
                &key("field"),
                format!("= \"{}\" needs [lbm]: the fluid it probes", p.field),
            ));
        };
        if p.particle.is_some() || p.cell.is_some() {
            return Err(ls.error(
                &key(if p.particle.is_some() {
                    "particle"
                } else {
                    "cell"
                }),
                format!(
                    "is not allowed for field \"{}\" (it takes at = [x, y])",
                    p.field
                ),
            ));
        }
        let finite = p.at.len() == 2 && p.at.iter().all(|v| v.is_finite());
        if !finite {
            return Err(ls.error(&key("at"), "must be [x, y] (m)"));
        }
        let inside = (0..2).all(|a| {
            let (lo, hi) = (l.extent[0].get(a), l.extent[1].get(a));
            matches!((lo, hi), (Some(lo), Some(hi)) if p.at[a] >= *lo && p.at[a] <= *hi)
        });
        if !inside {
            return Err(ls.error(
                &key("at"),
                format!("= [{}, {}] lies outside lbm.extent", p.at[0], p.at[1]),
            ));
        }
        let o = out.get_or_insert_with(|| ls.clone());
        let q = &mut o.scene.output.probe[i];
        q.field = GLOBAL_FIELDS[0].to_string();
        q.at.clear();
    }
    Ok(out)
}

/// The `wall = NAME` probes: a name of [`WALLS`] whose platens or pressurised hole the
/// scene has (the fields are checked with the other particle model's).
fn check_wall_probes(ls: &LoadedScene) -> Result<(), SceneError> {
    let load = super::own(ls).loading.as_ref();
    let platens = load.is_some_and(|l| l.platens.is_some());
    let hole = load.is_some_and(|l| l.pressure_rate.is_some())
        && ls
            .scene
            .particles
            .as_ref()
            .is_some_and(|p| p.hole.is_some());
    for (i, p) in ls.scene.output.probe.iter().enumerate() {
        let Some(name) = &p.wall else { continue };
        let key = ki("output.probe", i, &["wall"]);
        match name.as_str() {
            "top" | "bottom" if !platens => {
                return Err(ls.error(&key, format!("= \"{name}\" needs [loading] platens")));
            }
            "hole" if !hole => {
                return Err(ls.error(
                    &key,
                    "= \"hole\" needs a pressurised hole: [particles] hole with [loading] \
                     pressure_rate",
                ));
            }
            "top" | "bottom" | "hole" => {}
            _ => {
                return Err(ls.error(
                    &key,
                    format!(
                        "= \"{name}\" is not a wall of model \"lsm\" (walls: {})",
                        WALLS.join(", ")
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The key path of a library parameter name such as `bonds.kn`.
pub fn key_of(name: &str) -> Vec<KeyPart> {
    let parts: Vec<&str> = name.split('.').collect();
    match parts.as_slice() {
        ["bonds", "tensile"] => k(&["bonds", "tensile_strength"]),
        ["contacts", "modulus"] | ["contacts", "poisson"] => k(&["contacts", "modulus"]),
        ["damping", _] => k(&["lsm", "damping_coefficient"]),
        ["E"] => k(&["bonds", "youngs_modulus"]),
        ["nu"] => k(&["bonds", "poisson_ratio"]),
        ["hole radius"] | ["hole centre x"] => k(&["particles", "hole"]),
        ["wall spacing"] | ["wall seal"] => k(&["loading", "wall"]),
        [s, f] => k(&[s, f]),
        _ => k(&["lsm"]),
    }
}

/// The error of a library error at its key.
pub fn lsm_error(ls: &LoadedScene, e: &LsmError) -> SceneError {
    let key = match e {
        LsmError::BadParameter { name, .. } => key_of(name),
        LsmError::TimeStep { .. } => k(&["lsm", "dt"]),
        LsmError::Overlap { .. } | LsmError::NotFinite { .. } => k(&["particles"]),
        LsmError::External { .. } => k(&["loading"]),
        LsmError::Calibration(_) => k(&["bonds", "calibrate"]),
        LsmError::Interrupted | LsmError::State(_) => k(&["lsm"]),
    };
    ls.error(&key, format!(": {e}"))
}

fn positive(ls: &LoadedScene, key: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ls.error(key, format!("= {v} must be a positive number")))
    }
}

/// The bond law of `[bonds]`.
pub fn bond_law(ls: &LoadedScene) -> Result<BondLaw, SceneError> {
    let Some(b) = &super::own(ls).bonds else {
        return Err(ls.error(&k(&["bonds"]), "is missing: model \"lsm\" needs [bonds]"));
    };
    let key = |f: &str| k(&["bonds", f]);
    let (kn, ks) = match (b.youngs_modulus, b.poisson_ratio, b.kn) {
        (Some(_), _, Some(_)) | (_, Some(_), Some(_)) => {
            return Err(ls.error(
                &key("kn"),
                "give youngs_modulus and poisson_ratio, or kn and ks, not both",
            ));
        }
        (Some(e), Some(nu), None) => {
            if b.ks.is_some() {
                return Err(ls.error(&key("ks"), "is set by youngs_modulus and poisson_ratio"));
            }
            crate::common::bounds::modulus(ls, &key("youngs_modulus"), e, false)?;
            porofrac_lsm::calibrate::hexagonal_springs(e, nu).map_err(|e| lsm_error(ls, &e))?
        }
        (Some(_), None, None) => {
            return Err(ls.error(&key("poisson_ratio"), "is required with youngs_modulus"));
        }
        (None, Some(_), None) => {
            return Err(ls.error(&key("youngs_modulus"), "is required with poisson_ratio"));
        }
        (None, None, Some(kn)) => {
            // A 2D bond stiffness per unit thickness has the unit of a modulus.
            crate::common::bounds::modulus(ls, &key("kn"), kn, false)?;
            (kn, b.ks.unwrap_or(0.0))
        }
        (None, None, None) => {
            return Err(ls.error(
                &key("youngs_modulus"),
                "is missing: give youngs_modulus and poisson_ratio, or kn",
            ));
        }
    };
    let phi = b.friction_angle.unwrap_or(30.0);
    if !(0.0..90.0).contains(&phi) {
        return Err(ls.error(
            &key("friction_angle"),
            format!("= {phi} must be in [0, 90) degrees"),
        ));
    }
    let tensile = b.tensile_strength.unwrap_or(f64::INFINITY);
    let law = BondLaw {
        kn,
        ks,
        kb: b.kb.unwrap_or(0.0),
        tensile,
        cohesion: b
            .cohesion
            .unwrap_or(tensile * phi.to_radians().tan().max(1e-300)),
        friction_angle: phi.to_radians(),
    };
    law.check().map_err(|e| lsm_error(ls, &e))?;
    if let Some(t) = b.tolerance
        && !(t.is_finite() && (0.0..=0.5).contains(&t))
    {
        return Err(ls.error(&key("tolerance"), format!("= {t} must be in [0, 0.5]")));
    }
    Ok(law)
}

/// Check a lattice solid scene.
pub fn check(ls: &LoadedScene) -> Result<(), SceneError> {
    let s = &ls.scene;
    if s.scene.dim != 2 {
        return Err(ls.error(
            &k(&["scene", "dim"]),
            format!("= {} must be 2: model \"lsm\" has disks", s.scene.dim),
        ));
    }
    if s.scene.plane.is_some() {
        return Err(ls.error(
            &k(&["scene", "plane"]),
            "belongs to model \"continuum\", not \"lsm\"",
        ));
    }
    for (name, set) in [
        ("mechanics", s.solver.mechanics.is_some()),
        ("linear", s.solver.linear.is_some()),
        ("tolerance", s.solver.tolerance.is_some()),
    ] {
        if set {
            return Err(ls.error(
                &k(&["solver", name]),
                "belongs to model \"continuum\", not \"lsm\"",
            ));
        }
    }
    if s.output.exact_displacement.is_some() {
        return Err(ls.error(
            &k(&["output", "exact_displacement"]),
            "belongs to model \"continuum\", not \"lsm\"",
        ));
    }
    crate::common::particles::check(ls, "lsm")?;
    bond_law(ls)?;
    if let Some(c) = &super::own(ls).contacts {
        let key = |f: &str| k(&["contacts", f]);
        for (f, v) in [("friction", c.friction), ("kn", c.kn), ("ks", c.ks)] {
            if let Some(v) = v
                && !(v.is_finite() && v >= 0.0)
            {
                return Err(ls.error(&key(f), format!("= {v} must be a number ≥ 0")));
            }
        }
        match c.normal {
            NormalChoice::Hertz => {
                positive(ls, &key("modulus"), c.modulus.unwrap_or(f64::NAN))
                    .map_err(|_| ls.error(&key("modulus"), "(a positive Young's modulus of the grains) is required with normal = \"hertz\""))?;
                let nu = c.poisson_ratio.unwrap_or(0.25);
                if !(nu > -1.0 && nu < 0.5) {
                    return Err(ls.error(
                        &key("poisson_ratio"),
                        format!("= {nu} must be in (-1, 0.5)"),
                    ));
                }
            }
            NormalChoice::Linear => {
                for (f, set) in [
                    ("modulus", c.modulus.is_some()),
                    ("poisson_ratio", c.poisson_ratio.is_some()),
                ] {
                    if set {
                        return Err(ls.error(&key(f), "applies to normal = \"hertz\""));
                    }
                }
            }
        }
    }
    if let Some(l) = &super::own(ls).lsm {
        let key = |f: &str| k(&["lsm", f]);
        if let Some(dt) = l.dt {
            positive(ls, &key("dt"), dt)?;
            if let Some(sch) = &s.schedule {
                let n = sch.end_time / dt;
                if n > crate::common::limits::MAX_STEPS as f64 {
                    return Err(ls.error(
                        &key("dt"),
                        format!(
                            "= {dt:e} s gives {n:.3e} time steps up to end_time = {} s, more \
                             than the {} a run may take (leave dt out for a fraction of the \
                             stable step)",
                            sch.end_time,
                            crate::common::limits::MAX_STEPS
                        ),
                    ));
                }
            }
        }
        if l.dt.is_some() && l.dt_fraction.is_some() {
            return Err(ls.error(
                &key("dt_fraction"),
                "has no effect when dt is given: give one of them",
            ));
        }
        if let Some(f) = l.dt_fraction
            && !(f > 0.0 && f <= 1.0)
        {
            return Err(ls.error(&key("dt_fraction"), format!("= {f} must be in (0, 1]")));
        }
        match (l.damping, l.damping_coefficient) {
            (DampingChoice::None, Some(_)) => {
                return Err(ls.error(
                    &key("damping_coefficient"),
                    "needs damping = \"local\" or \"viscous\"",
                ));
            }
            (DampingChoice::Local, Some(a)) if !(0.0..1.0).contains(&a) => {
                return Err(ls.error(
                    &key("damping_coefficient"),
                    format!("= {a} must be in [0, 1) for local damping"),
                ));
            }
            (DampingChoice::Viscous, None) => {
                return Err(ls.error(
                    &key("damping_coefficient"),
                    "(the rate, 1/s) is required with damping = \"viscous\"",
                ));
            }
            (DampingChoice::Viscous, Some(c)) if !(c.is_finite() && c >= 0.0) => {
                return Err(ls.error(&key("damping_coefficient"), format!("= {c} must be ≥ 0")));
            }
            _ => {}
        }
        if let Some(g) = l.gravity
            && !g.iter().all(|v| v.is_finite())
        {
            return Err(ls.error(&key("gravity"), "must be finite"));
        }
    }
    if let Some(l) = &super::own(ls).loading {
        let key = |f: &str| k(&["loading", f]);
        if let Some(p) = l.platens {
            positive(ls, &key("platens"), p.velocity).map_err(|_| {
                ls.error(
                    &key("platens"),
                    format!("velocity = {} must be positive", p.velocity),
                )
            })?;
            positive(ls, &key("platens"), p.thickness).map_err(|_| {
                ls.error(
                    &key("platens"),
                    format!("thickness = {} must be positive", p.thickness),
                )
            })?;
            let stop = [
                ("stop_displacement", p.stop_displacement),
                ("stop_time", p.stop_time),
            ];
            if stop.iter().all(|(_, v)| v.is_some()) {
                return Err(ls.error(
                    &key("platens"),
                    "stop_displacement and stop_time both stop the platens: give one",
                ));
            }
            if let Some(f) = p.hold_force {
                if let Some((name, _)) = stop.iter().find(|(_, v)| v.is_some()) {
                    return Err(ls.error(
                        &key("platens"),
                        format!("hold_force and {name} both end the approach: give one"),
                    ));
                }
                if !(f.is_finite() && f > 0.0) {
                    return Err(ls.error(
                        &key("platens"),
                        format!("hold_force = {f} must be a finite force > 0 (N/m, compressive)"),
                    ));
                }
                if s.lbm.is_some() {
                    return Err(ls.error(
                        &key("platens"),
                        "hold_force is not available with [lbm] (the platens of a coupled run move at velocity)",
                    ));
                }
            }
            for (f, v) in stop {
                if let Some(v) = v
                    && !(v.is_finite() && v >= 0.0)
                {
                    return Err(ls.error(
                        &key("platens"),
                        format!("{f} = {v} must be a finite number ≥ 0"),
                    ));
                }
                if v.is_some() && s.lbm.is_some() {
                    return Err(ls.error(
                        &key("platens"),
                        format!("{f} is not available with [lbm] (the platens of a coupled run move at velocity)"),
                    ));
                }
            }
        }
        if let Some(r) = l.pressure_rate {
            if !(r.is_finite() && r >= 0.0) {
                return Err(ls.error(&key("pressure_rate"), format!("= {r} must be ≥ 0")));
            }
            if s.particles.as_ref().is_none_or(|p| p.hole.is_none()) {
                return Err(ls.error(
                    &key("pressure_rate"),
                    "needs a hole: [particles] hole = { center, radius }",
                ));
            }
        }
        if let Some(m) = l.pressure_max {
            if l.pressure_rate.is_none() {
                return Err(ls.error(&key("pressure_max"), "needs pressure_rate"));
            }
            positive(ls, &key("pressure_max"), m)?;
        }
        if l.flood_cracks && l.pressure_rate.is_none() {
            return Err(ls.error(&key("flood_cracks"), "needs pressure_rate"));
        }
        if l.crack_across_pores && s.particles.as_ref().is_none_or(|p| p.hole.is_none()) {
            return Err(ls.error(
                &key("crack_across_pores"),
                "needs a hole: [particles] hole = { center, radius }",
            ));
        }
        if l.wall != super::file::WallChoice::Rays && l.pressure_rate.is_none() {
            return Err(ls.error(&key("wall"), "needs pressure_rate"));
        }
        if let Some(h) = l.wall_spacing {
            if l.wall != super::file::WallChoice::Wetted {
                return Err(ls.error(&key("wall_spacing"), "needs wall = \"wetted\""));
            }
            positive(ls, &key("wall_spacing"), h)?;
        }
    }
    let pressurised = s.particles.as_ref().is_some_and(|p| p.hole.is_some())
        && (super::own(ls)
            .loading
            .as_ref()
            .is_some_and(|l| l.pressure_rate.is_some())
            || super::own(ls).injection.is_some());
    if let Some(i) = s
        .output
        .probe
        .iter()
        .position(|p| p.field == "crack_extent")
        && !pressurised
    {
        return Err(ls.error(
            &ki("output.probe", i, &["field"]),
            "= \"crack_extent\" needs a pressurised hole: [particles] hole with \
             [loading] pressure_rate or [injection]",
        ));
    }
    check_wall_probes(ls)?;
    crate::common::particles::check_particle_schedule(ls, "lsm")?;
    super::fluid::check(ls)?;
    let shared = check_fluid_probes(ls)?;
    crate::common::particles::check_output_of(
        shared.as_ref().unwrap_or(ls),
        "lsm",
        &CELL_FIELDS,
        &GLOBAL_FIELDS,
    )
}
