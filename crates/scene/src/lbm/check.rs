//! Checking a lattice Boltzmann scene: keys of other models are refused by name, every
//! value is checked, and the lattice it asks for is bounded, before anything is allocated.

use porofrac_lbm::Units;

use crate::common::lattice::check::{
    check_section, check_thermal, expr, mach_of, positive, vector,
};
use crate::common::lattice::sections::ShapeChoice;
use crate::common::loaded::{LoadedScene, SceneError, k, ki};
use crate::common::sections::KeyPart;

/// Probe and line fields of the model.
pub const FIELDS: [&str; 5] = ["vx", "vy", "pressure", "density", "temperature"];
/// Obstacle probe fields.
pub const OBSTACLE_FIELDS: [&str; 3] = ["fx", "fy", "torque"];

/// The unit of a field of [`FIELDS`] or [`OBSTACLE_FIELDS`] (forces and torques per
/// metre of depth: N/m, N).
pub fn unit(field: &str) -> &'static str {
    match field {
        "vx" | "vy" => "m/s",
        "pressure" => "Pa",
        "density" => "kg/m³",
        "temperature" => "°C",
        "fx" | "fy" => "N/m",
        "torque" => "N",
        _ => "1",
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
    if let Some(t) = &s.thermal {
        for (name, set) in [("particle_temperature", t.particle_temperature.is_some())] {
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
    let extent = [
        [l.extent[0][0], l.extent[0][1]],
        [l.extent[1][0], l.extent[1][1]],
    ];
    let periodic = super::periodic_axes(l);
    let mut placed: Vec<Placed> = Vec::new();
    for (i, o) in super::own(ls).obstacle.iter().enumerate() {
        let ok = |f: &str| ki("obstacle", i, &[f]);
        if o.name.is_empty() || !names.insert(o.name.clone()) {
            return Err(ls.error(
                &ok("name"),
                format!("= \"{}\" is empty or repeated", o.name),
            ));
        }
        let (lo, hi, disk) = match &o.shape {
            ShapeChoice::Circle(c) => {
                if c.center.len() != 2 || !c.center.iter().all(|v| v.is_finite()) {
                    return Err(ls.error(&ok("shape"), "circle center must be two finite numbers"));
                }
                positive(ls, &ok("shape"), c.radius)?;
                (
                    [c.center[0] - c.radius, c.center[1] - c.radius],
                    [c.center[0] + c.radius, c.center[1] + c.radius],
                    Some(([c.center[0], c.center[1]], c.radius)),
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
                ([b[0][0], b[0][1]], [b[1][0], b[1][1]], None)
            }
        };
        // clipped to the lattice along a side that is not periodic, wrapped along one that is
        for a in 0..2 {
            let reaches = lo[a] < extent[1][a] && hi[a] > extent[0][a];
            if !(periodic[a] || reaches) {
                return Err(ls.error(
                    &ok("shape"),
                    format!(
                        "lies entirely outside lbm.extent along {} (an obstacle may overhang                          a side, and is clipped to the lattice, but must reach into it)",
                        ["x", "y"][a]
                    ),
                ));
            }
        }
        let this = Placed { lo, hi, disk };
        for (j, other) in placed.iter().enumerate() {
            if overlap(&this, other, &extent, periodic) {
                let first = ki("obstacle", j, &["shape"]);
                return Err(ls.error(
                    &ok("shape"),
                    format!(
                        "overlaps obstacle[{j}].shape (\"{}\", line {}): obstacles may not \
                         overlap (a node both cover would give its links, and the force, to \
                         one of them only); move or shrink one",
                        super::own(ls).obstacle[j].name,
                        ls.line_of(&first)
                    ),
                ));
            }
        }
        placed.push(this);
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
    super::grains::check_keys(ls, &units)?;
    check_output(ls, &names)
}

/// An obstacle's shape in scene units: its bounding box, and the disk it is, if one.
struct Placed {
    lo: [f64; 2],
    hi: [f64; 2],
    disk: Option<([f64; 2], f64)>,
}

/// Whether two obstacles overlap by an area inside the lattice, with the images of `b`
/// across the periodic sides. Two disks overlap when their centres are closer than the sum
/// of the radii, a disk and a box when the box's nearest point to the centre is closer than
/// the radius, two boxes when their intervals overlap along both axes; touching is not
/// overlapping. The overlap must lie inside `extent` (the bounding boxes' common part
/// reaches into it), since what overhangs a side is clipped away.
fn overlap(a: &Placed, b: &Placed, extent: &[[f64; 2]; 2], periodic: [bool; 2]) -> bool {
    let span = [extent[1][0] - extent[0][0], extent[1][1] - extent[0][1]];
    let shifts = |p: bool| if p { vec![-1.0, 0.0, 1.0] } else { vec![0.0] };
    for sx in shifts(periodic[0]) {
        for sy in shifts(periodic[1]) {
            let d = [sx * span[0], sy * span[1]];
            let b = Placed {
                lo: [b.lo[0] + d[0], b.lo[1] + d[1]],
                hi: [b.hi[0] + d[0], b.hi[1] + d[1]],
                disk: b.disk.map(|(c, r)| ([c[0] + d[0], c[1] + d[1]], r)),
            };
            let common_lo = [a.lo[0].max(b.lo[0]), a.lo[1].max(b.lo[1])];
            let common_hi = [a.hi[0].min(b.hi[0]), a.hi[1].min(b.hi[1])];
            let in_lattice = (0..2).all(|k| {
                common_lo[k] < common_hi[k]
                    && (periodic[k] || (common_lo[k] < extent[1][k] && common_hi[k] > extent[0][k]))
            });
            if !in_lattice {
                continue;
            }
            let hit = match (a.disk, b.disk) {
                (Some((c, r)), Some((e, q))) => {
                    (c[0] - e[0]).powi(2) + (c[1] - e[1]).powi(2) < (r + q).powi(2)
                }
                (Some((c, r)), None) => box_disk(&b, c, r),
                (None, Some((c, r))) => box_disk(a, c, r),
                (None, None) => true,
            };
            if hit {
                return true;
            }
        }
    }
    false
}

/// Whether the box of `b` and the disk `(c, r)` overlap by an area.
fn box_disk(b: &Placed, c: [f64; 2], r: f64) -> bool {
    let dx = c[0] - c[0].clamp(b.lo[0], b.hi[0]);
    let dy = c[1] - c[1].clamp(b.lo[1], b.hi[1]);
    dx * dx + dy * dy < r * r
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
    if lattice_steps > crate::common::limits::MAX_STEPS as f64 * 100.0 {
        return Err(ls.error(
            &k(&["schedule", "end_time"]),
            format!(
                "= {} s is {lattice_steps:.3e} lattice steps of {:.3e} s: too many",
                sch.end_time, units.dt
            ),
        ));
    }
    if crate::common::loaded::step_count_f64(sch) > crate::common::limits::MAX_STEPS as f64 {
        return Err(ls.error(
            &k(&["schedule"]),
            format!(
                "asks for more than {} output steps",
                crate::common::limits::MAX_STEPS
            ),
        ));
    }
    // Output times are whole numbers of lattice steps (as lbmpy and Palabos write every
    // N iterations): an interval or end time between two lattice steps is refused with
    // the nearest valid values, rather than rounded silently.
    let n = crate::common::loaded::step_count_f64(sch);
    let (what, interval) = match sch.dt {
        Some(dt) => ("dt", dt),
        None => ("steps", sch.end_time / n),
    };
    for (key, v) in [("end_time", sch.end_time), (what, interval)] {
        let m = v / units.dt;
        if (m - m.round()).abs() > 1e-9 * m.max(1.0) || m.round() < 1.0 {
            let below = short(m.floor().max(1.0) * units.dt);
            let above = short(m.ceil().max(1.0) * units.dt);
            let (interval, lattice_dt) = (short(interval), short(units.dt));
            let hint = if key == "steps" {
                format!(
                    "gives output every {interval} s, not a whole number of lattice steps \
                     of {lattice_dt} s ({m:.4} steps): choose end_time and steps so that \
                     end_time / steps is {below} s or {above} s"
                )
            } else {
                format!(
                    "= {} s is not a whole number of lattice steps of {lattice_dt} s ({m:.4} \
                     steps): use {below} s or {above} s",
                    short(v)
                )
            };
            return Err(ls.error(&k(&["schedule", key]), hint));
        }
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
                if !inside_lattice(ls, &p.at) {
                    return Err(ls.error(
                        &pk("at"),
                        format!("= {:?} is outside the lattice (lbm.extent)", p.at),
                    ));
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
            if !inside_lattice(ls, v) {
                return Err(ls.error(
                    &lk(f),
                    format!("= {v:?}: the line leaves the lattice (lbm.extent)"),
                ));
            }
        }
        crate::common::loaded::line_points_and_name(ls, i, l)?;
    }
    Ok(())
}

/// `v` to 12 significant digits, printed as short as that allows (`0.065`, not
/// `6.500000000000001e-2`): precise enough for the 1e-9 check it is a hint for.
fn short(v: f64) -> String {
    format!("{v:.11e}")
        .parse::<f64>()
        .map_or_else(|_| v.to_string(), |x| x.to_string())
}

/// Whether the point `x` lies in `lbm.extent` (boundary included).
fn inside_lattice(ls: &LoadedScene, x: &[f64]) -> bool {
    let l = ls.scene.lbm.as_ref().expect("checked by check_section");
    (0..2).all(|a| x[a] >= l.extent[0][a] && x[a] <= l.extent[1][a])
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

/// The keys of the continuum model in a lattice Boltzmann scene, refused by name (an
/// array of tables by its first element, a material by its name).
pub(crate) fn refuse_continuum(ls: &LoadedScene) -> Result<(), SceneError> {
    let s = &ls.scene;
    // Keys of the continuum model.
    let foreign: Option<Vec<KeyPart>> = if ls.has_section("grid") {
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
    Ok(())
}
