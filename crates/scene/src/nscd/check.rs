//! Validation of an NSCD scene: every value checked, every key of another model refused
//! with the key and the model named.

use crate::common::loaded::{LoadedScene, SceneError, k, ki};
use crate::common::particles::{check_output_of, check_particle_schedule};
use crate::common::sections::KeyPart;

use super::file::WallComponent;

pub use crate::common::particle_output::PARTICLE_FIELDS;
/// Fields of a tracked cell (`cell = { center, radius }` probes).
pub const CELL_FIELDS: [&str; 8] = [
    "p",
    "q",
    "anisotropy",
    "anisotropy_volume",
    "dilation_x",
    "dilation_y",
    "contacts",
    "broken_bonds",
];

fn finite(ls: &LoadedScene, key: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ls.error(key, format!("= {v} is not a finite number")))
    }
}

fn positive(ls: &LoadedScene, key: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ls.error(key, format!("= {v} must be a positive number")))
    }
}

fn non_negative(ls: &LoadedScene, key: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(ls.error(key, format!("= {v} must be a number ≥ 0")))
    }
}

pub use crate::common::particles::MAX_PARTICLES;

/// Check an NSCD scene.
pub fn check(ls: &LoadedScene) -> Result<(), SceneError> {
    let s = &ls.scene;
    crate::common::lattice::check::refuse_obstacle_probes(ls, "nscd")?;
    if s.scene.dim != 2 {
        return Err(ls.error(
            &k(&["scene", "dim"]),
            format!("= {} must be 2: model \"nscd\" has disks", s.scene.dim),
        ));
    }
    if s.scene.name.is_empty() || s.scene.name.contains(['/', '\\']) {
        return Err(ls.error(
            &k(&["scene", "name"]),
            "must be a non-empty name without slashes",
        ));
    }
    if s.scene.plane.is_some() {
        return Err(ls.error(
            &k(&["scene", "plane"]),
            "belongs to model \"continuum\", not \"nscd\"",
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
                "belongs to model \"continuum\", not \"nscd\" (the NLGS keys are in [nscd])",
            ));
        }
    }
    if let Some(t) = s.solver.threads
        && !(0..=1024).contains(&t)
    {
        return Err(ls.error(
            &k(&["solver", "threads"]),
            format!("= {t} must be in 0..=1024"),
        ));
    }
    if s.output.exact_displacement.is_some() {
        return Err(ls.error(
            &k(&["output", "exact_displacement"]),
            "belongs to model \"continuum\", not \"nscd\"",
        ));
    }
    crate::common::particles::check(ls, "nscd")?;
    check_walls(ls)?;
    if let Some(c) = &super::own(ls).contact {
        let key = |f: &str| k(&["contact", f]);
        for (f, v) in [
            ("mu", c.mu),
            ("mu_static", c.mu_static),
            ("cohesion", c.cohesion),
            ("d_w", c.d_w),
        ] {
            if let Some(v) = v {
                non_negative(ls, &key(f), v)?;
            }
        }
        if let Some(e) = c.restitution {
            if !(0.0..=1.0).contains(&e) {
                return Err(ls.error(&key("restitution"), format!("= {e} must be in [0, 1]")));
            }
            if e > 0.0 && c.cohesion.is_some_and(|g| g > 0.0) {
                return Err(ls.error(
                    &key("restitution"),
                    format!(
                        "= {e} with cohesion > 0: a cohesive contact does not rebound \
                         (restitution applies to non-cohesive contacts)"
                    ),
                ));
            }
        }
    }
    if let Some(n) = &super::own(ls).nscd {
        let key = |f: &str| k(&["nscd", f]);
        if let Some(t) = n.theta
            && !(0.5..=1.0).contains(&t)
        {
            return Err(ls.error(&key("theta"), format!("= {t} must be in [0.5, 1]")));
        }
        if let Some(t) = n.tolerance {
            positive(ls, &key("tolerance"), t)?;
        }
        if let Some(m) = n.min_sweeps
            && m < 0
        {
            return Err(ls.error(&key("min_sweeps"), format!("= {m} must be ≥ 0")));
        }
        if let Some(m) = n.max_sweeps
            && !(1..=100_000_000).contains(&m)
        {
            return Err(ls.error(&key("max_sweeps"), format!("= {m} must be in 1..=1e8")));
        }
        let (lo, hi) = (n.min_sweeps.unwrap_or(100), n.max_sweeps.unwrap_or(10_000));
        if lo > hi {
            return Err(ls.error(
                &key(if n.min_sweeps.is_some() {
                    "min_sweeps"
                } else {
                    "max_sweeps"
                }),
                format!("min_sweeps = {lo} must not exceed max_sweeps = {hi}"),
            ));
        }
        if let Some(a) = n.alert {
            non_negative(ls, &key("alert"), a)?;
            // At most the largest radius: a step moves a disk by much less than its
            // radius (a larger move is refused), so contacts that can close within a
            // step are all within that gap; a larger alert only adds candidates, as
            // (alert / r)² per disk, up to all n² pairs.
            if let Some(p) = &s.particles {
                let [_, r_max] = crate::common::particles::radius_range(p);
                if r_max > 0.0 && a > r_max {
                    return Err(ls.error(
                        &key("alert"),
                        format!(
                            "= {a} m is above the largest particle radius {r_max} m: contacts \
                             that can close in a step lie within one radius, and a larger \
                             alert distance makes the contact candidates grow as the square \
                             of the particle count"
                        ),
                    ));
                }
            }
        }
        for (f, set) in [
            ("settle_dt", n.settle_dt.is_some()),
            ("settle_max_steps", n.settle_max_steps.is_some()),
        ] {
            if set && n.settle_ratio.is_none() {
                return Err(ls.error(
                    &key(f),
                    "has no effect without settle_ratio (which turns the settling on)",
                ));
            }
        }
        if n.ordering_seed.is_some()
            && !matches!(n.ordering, Some(super::file::OrderingChoice::Random))
        {
            return Err(ls.error(
                &key("ordering_seed"),
                "has no effect without ordering = \"random\"",
            ));
        }
        if let Some(g) = n.gravity {
            for v in g {
                finite(ls, &key("gravity"), v)?;
            }
        }
        if let Some(r) = n.settle_ratio {
            positive(ls, &key("settle_ratio"), r)?;
        }
        if let Some(d) = n.settle_dt {
            positive(ls, &key("settle_dt"), d)?;
        }
        if let Some(m) = n.settle_max_steps
            && !(1..=100_000_000).contains(&m)
        {
            return Err(ls.error(
                &key("settle_max_steps"),
                format!("= {m} must be in 1..=1e8"),
            ));
        }
        if let Some(f) = &n.fault {
            let key = |f: &str| k(&["nscd", "fault", f]);
            for v in f.tip {
                finite(ls, &key("tip"), v)?;
            }
            if !(f64::MIN_POSITIVE..90.0).contains(&f.dip) {
                return Err(ls.error(
                    &key("dip"),
                    format!("= {} must be in (0, 90) degrees", f.dip),
                ));
            }
            positive(ls, &key("slip_rate"), f.slip_rate)?;
            let [a, b] = f.window;
            if !(a.iter().chain(&b).all(|v| v.is_finite()) && b[0] > a[0] && b[1] > a[1]) {
                return Err(ls.error(
                    &key("window"),
                    "must be [[x0, y0], [x1, y1]] with x1 > x0 and y1 > y0",
                ));
            }
            if let Some(w) = f.velocity_window {
                positive(ls, &key("velocity_window"), w)?;
            }
            if let Some(h) = f.half_apex
                && !(f64::MIN_POSITIVE..90.0).contains(&h)
            {
                return Err(ls.error(
                    &key("half_apex"),
                    format!("= {h} must be in (0, 90) degrees"),
                ));
            }
            if let Some(b) = f.band {
                positive(ls, &key("band"), b)?;
            }
            if let Some(l) = f.limit_fraction
                && !(l > 0.0 && l < 0.5)
            {
                return Err(ls.error(&key("limit_fraction"), format!("= {l} must be in (0, 0.5)")));
            }
        }
    }
    check_particle_schedule(ls, "nscd")?;
    check_output_of(ls, "nscd", &CELL_FIELDS, &[])
}

fn check_walls(ls: &LoadedScene) -> Result<(), SceneError> {
    let walls = &super::own(ls).wall;
    for (i, w) in walls.iter().enumerate() {
        let key = |f: &str| ki("wall", i, &[f]);
        if let Some(name) = &w.name
            && let Some(j) = walls[..i]
                .iter()
                .position(|o| o.name.as_ref() == Some(name))
        {
            return Err(ls.error(
                &key("name"),
                format!(
                    "= \"{name}\" is the name of wall[{j}] too: a name picks one wall \
                     (`wall = NAME` probes)"
                ),
            ));
        }
        match (&w.from, &w.to, &w.polygon) {
            (Some(a), Some(b), None) => {
                if a == b || !a.iter().chain(b).all(|v| v.is_finite()) {
                    return Err(ls.error(&key("to"), "must be a finite point other than from"));
                }
            }
            (None, None, Some(p)) => {
                let body = porofrac_nscd::RigidBody::polygon(p.clone());
                if p.len() < 3 {
                    return Err(ls.error(
                        &key("polygon"),
                        "needs at least three vertices (a segment: from, to)",
                    ));
                }
                body.check(i).map_err(|_| {
                    ls.error(
                        &key("polygon"),
                        "must be convex, counter-clockwise, with finite distinct vertices",
                    )
                })?;
            }
            _ => {
                return Err(ls.error(
                    &ki("wall", i, &[]),
                    "needs either from and to (a segment) or polygon",
                ));
            }
        }
        let mut free = false;
        if let Some(v) = &w.velocity {
            for c in v {
                match c {
                    WallComponent::Velocity(x) => finite(ls, &key("velocity"), *x)?,
                    WallComponent::Word(s) if s == "free" => free = true,
                    WallComponent::Word(s) => {
                        return Err(ls.error(
                            &key("velocity"),
                            format!("= \"{s}\": a component is a number (m/s) or \"free\""),
                        ));
                    }
                }
            }
        }
        if free {
            positive(ls, &key("mass"), w.mass.unwrap_or(f64::NAN)).map_err(|_| {
                ls.error(
                    &key("mass"),
                    "must be a positive number when a velocity component is \"free\"",
                )
            })?;
        } else if w.mass.is_some() || w.force.is_some() {
            return Err(ls.error(
                &key(if w.mass.is_some() { "mass" } else { "force" }),
                "applies only to a wall with a \"free\" velocity component",
            ));
        }
        if let Some(f) = w.force {
            for v in f {
                finite(ls, &key("force"), v)?;
            }
        }
        if let Some(mu) = w.mu {
            non_negative(ls, &key("mu"), mu)?;
        }
    }
    Ok(())
}
