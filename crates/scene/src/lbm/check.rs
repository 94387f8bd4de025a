//! Checking a lattice Boltzmann scene: keys of other models are refused by name, every
//! value is checked, and the lattice it asks for is bounded, before anything is allocated.

use porofrac_lbm::{MAX_MACH, TAU_MIN, Units};

use super::file::{BoundaryKindChoice, PrecisionChoice, ShapeChoice};
use crate::check::{LoadedScene, SceneError, k, ki};
use crate::expr::Expr;
use crate::file::{KeyPart, NumOrExpr};

/// Probe and line fields of the model.
pub const FIELDS: [&str; 5] = ["vx", "vy", "pressure", "density", "temperature"];
/// Obstacle probe fields.
pub const OBSTACLE_FIELDS: [&str; 3] = ["fx", "fy", "torque"];
/// Most lattice nodes a scene may ask for.
pub const MAX_NODES: f64 = 1.0e9;

fn positive(ls: &LoadedScene, key: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if !(v.is_finite() && v > 0.0) {
        return Err(ls.error(key, format!("= {v} must be > 0")));
    }
    Ok(())
}

fn expr(ls: &LoadedScene, key: &[KeyPart], v: &NumOrExpr) -> Result<(), SceneError> {
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

fn vector(ls: &LoadedScene, key: &[KeyPart], v: &[NumOrExpr]) -> Result<(), SceneError> {
    if v.len() != 2 {
        return Err(ls.error(key, format!("has {} components, the scene is 2D", v.len())));
    }
    v.iter().try_for_each(|c| expr(ls, key, c))
}

/// Refuse the keys of the lattice Boltzmann model in a scene of another `model`.
pub fn refuse_sections(ls: &LoadedScene, model: &str) -> Result<(), SceneError> {
    let s = &ls.scene;
    let key = if s.lbm.is_some() {
        Some(k(&["lbm"]))
    } else if !s.obstacle.is_empty() {
        Some(ki("obstacle", 0, &[]))
    } else if s.thermal.is_some() {
        Some(k(&["thermal"]))
    } else {
        s.output
            .probe
            .iter()
            .position(|p| p.obstacle.is_some())
            .map(|i| ki("output.probe", i, &["obstacle"]))
    };
    match key {
        Some(key) => Err(ls.error(&key, format!("belongs to model \"lbm\", not \"{model}\""))),
        None => Ok(()),
    }
}

/// Check a scene with `[scene] model = "lbm"`.
pub fn check(ls: &LoadedScene) -> Result<(), SceneError> {
    let s = &ls.scene;
    if s.scene.dim != 2 {
        return Err(ls.error(
            &k(&["scene", "dim"]),
            format!("= {} must be 2 (D2Q9)", s.scene.dim),
        ));
    }
    if s.scene.name.is_empty() || s.scene.name.contains(['/', '\\']) {
        return Err(ls.error(
            &k(&["scene", "name"]),
            "must be a non-empty name without slashes",
        ));
    }
    // Keys of the continuum model.
    let foreign: Option<Vec<KeyPart>> = if crate::nscd::check::has_section(ls, "grid") {
        Some(k(&["grid"]))
    } else if s.scene.plane.is_some() {
        Some(k(&["scene", "plane"]))
    } else if !s.region.is_empty() {
        Some(ki("region", 0, &[]))
    } else if let Some(m) = s.material.keys().next() {
        Some(k(&["material", m]))
    } else if s.fluid.is_some() {
        Some(k(&["fluid"]))
    } else if !s.bc.is_empty() {
        Some(ki("bc", 0, &[]))
    } else if s.loads.is_some() {
        Some(k(&["loads"]))
    } else if !s.source.is_empty() {
        Some(ki("source", 0, &[]))
    } else if !s.well.is_empty() {
        Some(ki("well", 0, &[]))
    } else if s.initial.is_some() {
        Some(k(&["initial"]))
    } else if s.physics.flow.is_some()
        || s.physics.coupling.is_some()
        || s.physics.fracture.is_some()
        || s.physics.failure_stress.is_some()
    {
        Some(k(&["physics"]))
    } else if s.solver.mechanics.is_some()
        || s.solver.linear.is_some()
        || s.solver.tolerance.is_some()
    {
        Some(k(&["solver"]))
    } else if s.output.exact_displacement.is_some() {
        Some(k(&["output", "exact_displacement"]))
    } else {
        None
    };
    if let Some(key) = foreign {
        return Err(ls.error(&key, "belongs to model \"continuum\", not \"lbm\""));
    }
    if let Some(t) = &s.thermal {
        for (name, set) in [
            ("particle_temperature", t.particle_temperature.is_some()),
            ("heat_capacity", t.heat_capacity.is_some()),
        ] {
            if set {
                return Err(ls.error(
                    &k(&["thermal", name]),
                    "belongs to model \"lsm\", not \"lbm\"",
                ));
            }
        }
    }
    let (units, seen) = check_section(ls)?;
    let l = s.lbm.as_ref().expect("checked by check_section");
    let mut names = std::collections::BTreeSet::new();
    let (x0, y0) = (l.extent[0][0], l.extent[0][1]);
    let (x1, y1) = (l.extent[1][0], l.extent[1][1]);
    for (i, o) in s.obstacle.iter().enumerate() {
        let ok = |f: &str| ki("obstacle", i, &[f]);
        if o.name.is_empty() || !names.insert(o.name.clone()) {
            return Err(ls.error(
                &ok("name"),
                format!("= \"{}\" is empty or repeated", o.name),
            ));
        }
        let (lo, hi) = match &o.shape {
            ShapeChoice::Circle(c) => {
                if c.center.len() != 2 || !c.center.iter().all(|v| v.is_finite()) {
                    return Err(ls.error(&ok("shape"), "circle center must be two finite numbers"));
                }
                positive(ls, &ok("shape"), c.radius)?;
                (
                    [c.center[0] - c.radius, c.center[1] - c.radius],
                    [c.center[0] + c.radius, c.center[1] + c.radius],
                )
            }
            ShapeChoice::Box(b) => {
                if b[0].len() != 2 || b[1].len() != 2 || !b.iter().flatten().all(|v| v.is_finite())
                {
                    return Err(ls.error(&ok("shape"), "box must be [[x0, y0], [x1, y1]]"));
                }
                if !(b[1][0] > b[0][0] && b[1][1] > b[0][1]) {
                    return Err(ls.error(&ok("shape"), "box needs x0 < x1 and y0 < y1"));
                }
                ([b[0][0], b[0][1]], [b[1][0], b[1][1]])
            }
        };
        let inside_x = lo[0] >= x0 && hi[0] <= x1;
        let inside_y = lo[1] >= y0 && hi[1] <= y1;
        if !(inside_x && inside_y) {
            return Err(ls.error(&ok("shape"), "is not inside lbm.extent"));
        }
        if let Some(v) = &o.velocity {
            vector(ls, &ok("velocity"), v)?;
            mach_of(ls, &ok("velocity"), v, &units)?;
        }
        if let Some(w) = &o.angular_velocity {
            expr(ls, &ok("angular_velocity"), w)?;
        }
    }
    check_thermal(ls, &units, seen)?;
    check_schedule(ls, &units)?;
    check_output(ls, &names)
}

/// Constant velocities above the Mach limit are refused here; expressions are checked at
/// every step of the run.
fn mach_of(
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

fn check_schedule(ls: &LoadedScene, units: &Units) -> Result<(), SceneError> {
    let Some(sch) = &ls.scene.schedule else {
        return Err(ls.error(&k(&["schedule"]), "is required by model \"lbm\" (end_time)"));
    };
    positive(ls, &k(&["schedule", "end_time"]), sch.end_time)?;
    match (sch.dt, sch.steps) {
        (Some(dt), None) => positive(ls, &k(&["schedule", "dt"]), dt)?,
        (None, Some(n)) if n < 1 => {
            return Err(ls.error(&k(&["schedule", "steps"]), format!("= {n} must be ≥ 1")));
        }
        (Some(_), Some(_)) => {
            return Err(ls.error(&k(&["schedule"]), "takes at most one of dt and steps"));
        }
        _ => {}
    }
    let lattice_steps = sch.end_time / units.dt;
    if lattice_steps > crate::limits::MAX_STEPS as f64 * 100.0 {
        return Err(ls.error(
            &k(&["schedule", "end_time"]),
            format!(
                "= {} s is {lattice_steps:.3e} lattice steps of {:.3e} s: too many",
                sch.end_time, units.dt
            ),
        ));
    }
    if crate::check::step_count_f64(sch) > crate::limits::MAX_STEPS as f64 {
        return Err(ls.error(
            &k(&["schedule"]),
            format!(
                "asks for more than {} output steps",
                crate::limits::MAX_STEPS
            ),
        ));
    }
    Ok(())
}

fn check_output(
    ls: &LoadedScene,
    obstacles: &std::collections::BTreeSet<String>,
) -> Result<(), SceneError> {
    let s = &ls.scene;
    if s.output.every < 1 {
        return Err(ls.error(
            &k(&["output", "every"]),
            format!("= {} must be ≥ 1", s.output.every),
        ));
    }
    if let Some(t) = s.solver.threads
        && !(0..=1024).contains(&t)
    {
        return Err(ls.error(
            &k(&["solver", "threads"]),
            format!("= {t} must be in 0..=1024 (0: one thread per core)"),
        ));
    }
    let mut names = std::collections::BTreeSet::new();
    for (i, p) in s.output.probe.iter().enumerate() {
        let pk = |f: &str| ki("output.probe", i, &[f]);
        if !names.insert(p.name.clone())
            || p.name == "time"
            || p.name.contains(',')
            || p.name.is_empty()
        {
            return Err(ls.error(
                &pk("name"),
                format!(
                    "= \"{}\" is empty, repeated, reserved or contains a comma",
                    p.name
                ),
            ));
        }
        match &p.obstacle {
            Some(o) => {
                if !obstacles.contains(o) {
                    return Err(
                        ls.error(&pk("obstacle"), format!("= \"{o}\" names no [[obstacle]]"))
                    );
                }
                if !OBSTACLE_FIELDS.contains(&p.field.as_str()) {
                    return Err(ls.error(
                        &pk("field"),
                        format!(
                            "= \"{}\": obstacle probes give {}",
                            p.field,
                            OBSTACLE_FIELDS.join(" ")
                        ),
                    ));
                }
                if !p.at.is_empty() {
                    return Err(ls.error(&pk("at"), "does not apply to an obstacle probe"));
                }
            }
            None => {
                field(ls, &pk("field"), &p.field)?;
                if p.at.len() != 2 || !p.at.iter().all(|v| v.is_finite()) {
                    return Err(ls.error(&pk("at"), "must be two finite numbers (m)"));
                }
            }
        }
    }
    for (i, l) in s.output.line.iter().enumerate() {
        let lk = |f: &str| ki("output.line", i, &[f]);
        field(ls, &lk("field"), &l.field)?;
        for (f, v) in [("from", &l.from), ("to", &l.to)] {
            if v.len() != 2 || !v.iter().all(|x| x.is_finite()) {
                return Err(ls.error(&lk(f), "must be two finite numbers (m)"));
            }
        }
        crate::check::line_points_and_name(ls, i, l)?;
    }
    Ok(())
}

fn field(ls: &LoadedScene, key: &[KeyPart], f: &str) -> Result<(), SceneError> {
    if f == "temperature" && ls.scene.thermal.is_none() {
        return Err(ls.error(key, "= \"temperature\" needs [thermal]"));
    }
    if !FIELDS.contains(&f) {
        return Err(ls.error(
            key,
            format!(
                "= \"{f}\" is not a field of model \"lbm\" ({})",
                FIELDS.join(" ")
            ),
        ));
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
        if l.collision != super::file::CollisionChoice::Trt {
            return Err(ls.error(&key("magic"), "applies to collision = \"trt\" only"));
        }
        positive(ls, &key("magic"), m)?;
    }
    if l.precision == PrecisionChoice::Single {
        return Err(ls.error(
            &key("precision"),
            "= \"single\" is not available in this version of porofrac (double only)",
        ));
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
    crate::limits::fits_in_memory(nx * ny * 100.0, &format!("a lattice of {nx} × {ny} nodes"))
        .map_err(|e| ls.error(&key("spacing"), e))?;
    let units = Units::from_viscosity(l.spacing, l.viscosity, l.density, l.tau)
        .map_err(|e| ls.error(&key("tau"), e))?;
    if let Some(b) = &l.body_force
        && (b.len() != 2 || !b.iter().all(|v| v.is_finite()))
    {
        return Err(ls.error(&key("body_force"), "must be two finite numbers (m/s²)"));
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
            super::file::SideChoice::Xmin | super::file::SideChoice::Xmax => 0,
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
                super::file::SideChoice::Xmin | super::file::SideChoice::Xmax => 0,
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
