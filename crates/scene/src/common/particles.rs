//! `[particles]`, shared by the particle models (`nscd`, `lsm`): the section, its
//! checks and the generation of the disks (a seeded random packing, a hexagonal lattice
//! or a list; in a box, a disk or a polygon, with an optional hole;
//! [`porofrac_particles::packing`]).

use serde::Deserialize;

use porofrac_particles::packing::{Hole, RadiusDistribution, Region, hexagonal_in};
use porofrac_particles::{Disks, ParticleError, RandomPacking};

use crate::common::driver::SetupPoll;
use crate::common::model::RunError;

use crate::common::loaded::{LoadedScene, SceneError, k, ki, step_count_f64};
use crate::common::particle_output::PARTICLE_FIELDS;

/// `[particles] kind`: how the disks are generated.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum ParticleKind {
    /// A dense random polydisperse packing in `region` (random placement with overlap
    /// relaxation, [`porofrac_particles::RandomPacking`]).
    #[default]
    Random,
    /// Equal disks on a triangular lattice filling `region`.
    Hexagonal,
    /// The disks listed in `centres` and `radii`.
    List,
}

/// A radius, or a `[min, max]` range drawn uniformly.
#[derive(Clone, Copy, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(untagged)]
#[schemars(extend("expected" = "a radius or a range [min, max], e.g. 0.5e-3 or [0.4e-3, 0.6e-3]"))]
pub enum RadiusSpec {
    /// One radius (m).
    One(f64),
    /// `[min, max]` (m).
    Range([f64; 2]),
}

impl RadiusSpec {
    /// `[min, max]`.
    pub fn range(&self) -> [f64; 2] {
        match *self {
            Self::One(r) => [r, r],
            Self::Range(r) => r,
        }
    }
}

/// `[particles]`.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ParticlesSection {
    /// Generator (default `"random"`).
    #[serde(default)]
    pub kind: ParticleKind,
    /// The box filled: `[[x0, y0], [x1, y1]]` (m); or `disk`, or `polygon`.
    #[schemars(extend("unit" = "m"))]
    pub region: Option<[[f64; 2]; 2]>,
    /// Radius (hexagonal) or `[min, max]` (random), m.
    #[schemars(extend("unit" = "m"))]
    pub radius: Option<RadiusSpec>,
    /// Random: disk area over box area (default 0.8).
    pub packing_fraction: Option<f64>,
    /// Random: seed (default 1).
    pub seed: Option<u64>,
    /// List: centres (m).
    #[schemars(extend("unit" = "m"))]
    pub centres: Option<Vec<[f64; 2]>>,
    /// List: radii (m).
    #[schemars(extend("unit" = "m"))]
    pub radii: Option<Vec<f64>>,
    /// Density (kg/m³; masses per metre of thickness).
    #[schemars(extend("unit" = "kg/m³"))]
    pub density: f64,
    /// Instead of `region`: a disk region `{ center = [x, y], radius = R }`.
    #[schemars(extend("unit" = "m"))]
    pub disk: Option<CircleSpec>,
    /// Instead of `region`: a polygon region, vertices in order (m).
    #[schemars(extend("unit" = "m"))]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// A circular hole left empty (a borehole): `{ center = [x, y], radius = a }`; the
    /// disks overlapping it are left out (kind `list` too: the indices of the disks
    /// then count the kept ones, in the listed order).
    #[schemars(extend("unit" = "m"))]
    pub hole: Option<CircleSpec>,
    /// Random: how radii are drawn (default uniform in `radius`).
    #[serde(default)]
    pub distribution: Distribution,
    /// Random with `distribution = "list"`: the radii drawn from, with equal
    /// probability (m).
    #[schemars(extend("unit" = "m"))]
    pub radius_list: Option<Vec<f64>>,
    /// Initial velocities and spins of selected disks, one table per selection, applied
    /// in the file's order (model nscd: after the settling when there is one; model
    /// lsm: before the bonds form, which a velocity does not change; platen disks take
    /// the platens' velocity).
    #[serde(default)]
    pub velocity: Vec<crate::common::particle_velocity::ParticleVelocity>,
}

/// A circle `{ center = [x, y], radius = r }`.
#[derive(Clone, Copy, Debug, Deserialize, schemars::JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CircleSpec {
    /// Centre (m).
    #[schemars(extend("unit" = "m"))]
    pub center: [f64; 2],
    /// Radius (m).
    #[schemars(extend("unit" = "m"))]
    pub radius: f64,
}

/// `[particles] distribution`.
#[derive(Clone, Copy, Debug, Default, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Distribution {
    /// Uniform in `radius = [min, max]`.
    #[default]
    Uniform,
    /// One of `radius_list`, with equal probability.
    List,
}

/// Most disks a scene may generate.
pub const MAX_PARTICLES: f64 = 2.0e7;

/// Farthest a listed centre may lie from the median centre, in largest diameters. The
/// neighbour search cuts the bounding box of the centres into at most `4 n + 16` cells:
/// one disk far away makes the cells huge and the search quadratic, and nothing a
/// particle model simulates spans a million grain diameters (a 2e7-disk packing is
/// about 5000 diameters across).
pub const MAX_SPREAD: f64 = 1e6;

/// The listed centre farthest from the component-wise median centre, with its distance
/// and the allowed one, when it lies beyond [`MAX_SPREAD`] largest diameters.
fn farthest_beyond(c: &[[f64; 2]], r: &[f64]) -> Option<(usize, f64, f64)> {
    let median = |a: usize| {
        let mut v: Vec<f64> = c.iter().map(|p| p[a]).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    if c.is_empty() {
        return None;
    }
    let m = [median(0), median(1)];
    let reach = MAX_SPREAD * 2.0 * r.iter().copied().fold(0.0, f64::max);
    let (i, d) = c
        .iter()
        .map(|p| (p[0] - m[0]).hypot(p[1] - m[1]))
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    (d > reach).then_some((i, d, reach))
}

/// Smallest and largest radius a checked `[particles]` section gives (m).
pub fn radius_range(p: &ParticlesSection) -> [f64; 2] {
    let fold = |v: &[f64]| {
        [
            v.iter().copied().fold(f64::INFINITY, f64::min),
            v.iter().copied().fold(0.0, f64::max),
        ]
    };
    match (p.kind, &p.radius_list, p.radius, &p.radii) {
        (ParticleKind::List, _, _, Some(radii)) => fold(radii),
        (_, Some(list), _, _) => fold(list),
        (_, None, Some(r), _) => r.range(),
        _ => [0.0, 0.0],
    }
}

fn positive(ls: &LoadedScene, f: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ls.error(
            &k(&["particles", f]),
            format!("= {v} must be a positive number"),
        ))
    }
}

/// The region of a checked `[particles]` section.
pub fn region(p: &ParticlesSection) -> Option<Region> {
    if let Some(b) = p.region {
        return Some(Region::Box { lo: b[0], hi: b[1] });
    }
    if let Some(c) = p.disk {
        return Some(Region::Disk {
            centre: c.center,
            radius: c.radius,
        });
    }
    p.polygon.clone().map(Region::Polygon)
}

/// The hole of a checked `[particles]` section.
pub fn hole(p: &ParticlesSection) -> Vec<Hole> {
    p.hole
        .map(|h| Hole {
            centre: h.center,
            radius: h.radius,
        })
        .into_iter()
        .collect()
}

/// `hole`, when given: a positive radius and a finite centre.
fn check_hole(ls: &LoadedScene, p: &ParticlesSection) -> Result<(), SceneError> {
    if let Some(h) = p.hole {
        positive(ls, "hole", h.radius)?;
        if !(h.center[0].is_finite() && h.center[1].is_finite()) {
            return Err(ls.error(&k(&["particles", "hole"]), "center is not finite"));
        }
    }
    Ok(())
}

/// The listed disks outside the hole of `[particles]` (all of them without one), in
/// their listed order: a disk is cut when it overlaps the hole, as the generated
/// packings are carved ([`porofrac_particles::packing::carve`]).
fn list_outside_hole(p: &ParticlesSection) -> (Vec<[f64; 2]>, Vec<f64>) {
    let centres = p.centres.clone().unwrap_or_default();
    let radii = p.radii.clone().unwrap_or_default();
    if p.hole.is_none() || centres.is_empty() {
        return (centres, radii);
    }
    // A box holding every listed disk with a margin, so that only the hole cuts.
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (c, &r) in centres.iter().zip(&radii) {
        for a in 0..2 {
            lo[a] = lo[a].min(c[a] - 2.0 * r);
            hi[a] = hi[a].max(c[a] + 2.0 * r);
        }
    }
    let packing = porofrac_particles::packing::Packing { centres, radii };
    let kept = porofrac_particles::packing::carve(&packing, &Region::Box { lo, hi }, &hole(p));
    (kept.centres, kept.radii)
}

/// Check `[particles]` of a scene of `model`.
pub fn check(ls: &LoadedScene, model: &str) -> Result<(), SceneError> {
    let Some(p) = &ls.scene.particles else {
        return Err(ls.error(
            &k(&["particles"]),
            format!("is missing: model \"{model}\" needs [particles]"),
        ));
    };
    let key = |f: &str| k(&["particles", f]);
    positive(ls, "density", p.density)?;
    crate::common::particle_velocity::check(ls, model, &p.velocity)?;
    let kind_name = match p.kind {
        ParticleKind::Random => "random",
        ParticleKind::Hexagonal => "hexagonal",
        ParticleKind::List => "list",
    };
    for (f, set, applies) in [
        (
            "packing_fraction",
            p.packing_fraction.is_some(),
            p.kind == ParticleKind::Random,
        ),
        ("seed", p.seed.is_some(), p.kind == ParticleKind::Random),
        (
            "distribution",
            p.distribution != Distribution::Uniform,
            p.kind == ParticleKind::Random,
        ),
        ("radius", p.radius.is_some(), p.kind != ParticleKind::List),
        ("region", p.region.is_some(), p.kind != ParticleKind::List),
        ("centres", p.centres.is_some(), p.kind == ParticleKind::List),
        ("radii", p.radii.is_some(), p.kind == ParticleKind::List),
    ] {
        if set && !applies {
            return Err(ls.error(
                &key(f),
                format!("has no effect with kind = \"{kind_name}\""),
            ));
        }
    }
    match p.kind {
        ParticleKind::Random | ParticleKind::Hexagonal => {
            let given = [p.region.is_some(), p.disk.is_some(), p.polygon.is_some()];
            if given.iter().filter(|g| **g).count() != 1 {
                return Err(ls.error(
                    &key("region"),
                    "(or disk, or polygon): exactly one region is required for this kind",
                ));
            }
            if let Some(region) = p.region {
                for a in 0..2 {
                    if !(region[0][a].is_finite()
                        && region[1][a].is_finite()
                        && region[1][a] > region[0][a])
                    {
                        return Err(ls.error(
                            &key("region"),
                            "must be [[x0, y0], [x1, y1]] with x1 > x0, y1 > y0",
                        ));
                    }
                }
            }
            if let Some(c) = p.disk {
                positive(ls, "disk", c.radius)?;
                if !(c.center[0].is_finite() && c.center[1].is_finite()) {
                    return Err(ls.error(&key("disk"), "center is not finite"));
                }
            }
            if let Some(poly) = &p.polygon {
                let r = Region::Polygon(poly.clone());
                if poly.iter().any(|v| !(v[0].is_finite() && v[1].is_finite()))
                    || r.check().is_err()
                {
                    return Err(ls.error(
                        &key("polygon"),
                        "must list at least 3 finite vertices enclosing an area",
                    ));
                }
            }
            check_hole(ls, p)?;
            let radius = match (p.distribution, p.radius, &p.radius_list) {
                (Distribution::List, _, Some(list)) => {
                    if p.kind == ParticleKind::Hexagonal {
                        return Err(ls.error(
                            &key("distribution"),
                            "= \"list\" applies to kind = \"random\"",
                        ));
                    }
                    if list.is_empty() || list.iter().any(|r| !(r.is_finite() && *r > 0.0)) {
                        return Err(
                            ls.error(&key("radius_list"), "must list positive finite radii")
                        );
                    }
                    let lo = list.iter().copied().fold(f64::INFINITY, f64::min);
                    let hi = list.iter().copied().fold(0.0, f64::max);
                    RadiusSpec::Range([lo, hi])
                }
                (Distribution::List, _, None) => {
                    return Err(ls.error(
                        &key("radius_list"),
                        "is required with distribution = \"list\"",
                    ));
                }
                (Distribution::Uniform, _, Some(_)) => {
                    return Err(ls.error(&key("radius_list"), "needs distribution = \"list\""));
                }
                (Distribution::Uniform, Some(r), None) => r,
                (Distribution::Uniform, None, None) => {
                    return Err(ls.error(&key("radius"), "is required for this kind"));
                }
            };
            let [r0, r1] = radius.range();
            positive(ls, "radius", r0)?;
            if !(r1.is_finite() && r1 >= r0) {
                return Err(ls.error(&key("radius"), "must be [min, max] with max ≥ min"));
            }
            if p.kind == ParticleKind::Hexagonal
                && matches!(radius, RadiusSpec::Range(_))
                && r1 != r0
            {
                return Err(ls.error(
                    &key("radius"),
                    "must be one number for kind = \"hexagonal\"",
                ));
            }
            let (lo, hi) = region(p).expect("one region").bounds();
            for a in 0..2 {
                if hi[a] - lo[a] < 2.0 * r1 {
                    return Err(ls.error(&key("region"), "is narrower than one largest diameter"));
                }
            }
            let phi = p.packing_fraction.unwrap_or(0.8);
            if p.kind == ParticleKind::Random && !(phi > 0.0 && phi < 0.84) {
                return Err(ls.error(
                    &key("packing_fraction"),
                    format!("= {phi} must be in (0, 0.84)"),
                ));
            }
            let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
            let count = area / (std::f64::consts::PI * r0 * r0);
            if count > MAX_PARTICLES {
                return Err(ls.error(
                    &key("radius"),
                    format!("gives up to {count:.3e} disks in the region, more than the {MAX_PARTICLES:.0e} a scene may have"),
                ));
            }
        }
        ParticleKind::List => {
            for (f, set) in [
                ("disk", p.disk.is_some()),
                ("polygon", p.polygon.is_some()),
                ("radius_list", p.radius_list.is_some()),
            ] {
                if set {
                    return Err(ls.error(&key(f), "does not apply to kind = \"list\""));
                }
            }
            check_hole(ls, p)?;
            let (Some(c), Some(r)) = (&p.centres, &p.radii) else {
                return Err(ls.error(
                    &key("centres"),
                    "and radii are required for kind = \"list\"",
                ));
            };
            if c.len() != r.len() {
                return Err(ls.error(
                    &key("radii"),
                    format!("has {} values for {} centres", r.len(), c.len()),
                ));
            }
            for (i, &ri) in r.iter().enumerate() {
                if !(ri.is_finite() && ri > 0.0) {
                    return Err(ls.error(
                        &key("radii"),
                        format!("[{i}] = {ri} must be a positive radius"),
                    ));
                }
            }
            for (i, ci) in c.iter().enumerate() {
                if !(ci[0].is_finite() && ci[1].is_finite()) {
                    return Err(ls.error(&key("centres"), format!("[{i}] is not finite")));
                }
            }
            if let Some((i, d, reach)) = farthest_beyond(c, r) {
                return Err(ls.error(
                    &key("centres"),
                    format!(
                        "[{i}] = [{}, {}] lies {d:.3e} m from the median centre of the \
                         particles, more than {MAX_SPREAD:.0e} largest diameters \
                         ({reach:.3e} m): a particle so far away is a typing error",
                        c[i][0], c[i][1]
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The disks of a checked `[particles]` section, reporting the packing's progress to
/// `setup` (phase `"packing"`); a stop request ends it with [`RunError::Interrupted`].
pub fn generate(ls: &LoadedScene, setup: &mut SetupPoll<'_>) -> Result<Disks, RunError> {
    let p = ls
        .scene
        .particles
        .as_ref()
        .expect("checked: [particles] present");
    let key = |f: &str| k(&["particles", f]);
    let (centres, radii) = match p.kind {
        ParticleKind::List => list_outside_hole(p),
        ParticleKind::Hexagonal | ParticleKind::Random => {
            let region = region(p).expect("checked");
            let holes = hole(p);
            let packing = if p.kind == ParticleKind::Hexagonal {
                let [r0, _] = p.radius.expect("checked").range();
                hexagonal_in(&region, &holes, r0)
                    .map_err(|e| ls.error(&key("radius"), format!(": {e}")))?
            } else {
                let (lo, hi) = region.bounds();
                let mut spec = match (&p.radius_list, p.radius) {
                    (Some(list), _) => {
                        RandomPacking::new(lo, hi, 0.0, 0.0, 0.8, 1).with_radii(list)
                    }
                    (None, r) => {
                        let [r0, r1] = r.expect("checked").range();
                        RandomPacking::new(lo, hi, r0, r1, 0.8, 1)
                    }
                };
                spec.packing_fraction = p.packing_fraction.unwrap_or(0.8);
                spec.seed = p.seed.unwrap_or(1);
                if !matches!(spec.distribution, RadiusDistribution::List(_)) {
                    spec.distribution = RadiusDistribution::Uniform;
                }
                setup.phase("packing");
                match spec.generate_in_polled(&region, &holes, &mut setup.callback()) {
                    Ok(p) => p,
                    Err(ParticleError::Interrupted) => return Err(RunError::Interrupted),
                    Err(e) => {
                        return Err(ls.error(&key("packing_fraction"), format!(": {e}")).into());
                    }
                }
            };
            (packing.centres, packing.radii)
        }
    };
    if centres.is_empty() {
        return Err(ls.error(&key("kind"), "generates no particle").into());
    }
    setup.check()?;
    Ok(Disks::new(&centres, &radii, p.density)
        .map_err(|e| ls.error(&k(&["particles"]), format!(": {e}")))?)
}

/// Set the initial velocities and spins of `disks` from `[[particles.velocity]]`
/// ([`crate::common::particle_velocity`]).
pub fn initial_velocities(ls: &LoadedScene, disks: &mut Disks) -> Result<(), RunError> {
    match &ls.scene.particles {
        Some(p) => crate::common::particle_velocity::apply(ls, &p.velocity, disks),
        None => Ok(()),
    }
}

/// Shortest schedule step of a particle model (s): forces are impulses divided by the
/// step, velocities displacements divided by it; below this the quotients overflow for
/// ordinary masses and speeds (1e-300 s gives `inf`).
pub const MIN_STEP: f64 = 1e-200;

/// The `[schedule]` of a particle model: present, `end_time > 0`, exactly one of
/// `dt > 0` (with `end_time ≥ dt`) and `steps ≥ 1`, a step of at least [`MIN_STEP`], and
/// no more output steps than a run may take.
pub fn check_particle_schedule(ls: &LoadedScene, model: &str) -> Result<(), SceneError> {
    let Some(sch) = &ls.scene.schedule else {
        return Err(ls.error(
            &k(&["schedule"]),
            format!("is missing: model \"{model}\" needs end_time and dt or steps"),
        ));
    };
    positive_at(ls, &k(&["schedule", "end_time"]), sch.end_time)?;
    match (sch.dt, sch.steps) {
        (Some(dt), None) => {
            positive_at(ls, &k(&["schedule", "dt"]), dt)?;
            if sch.end_time < dt * (1.0 - 1e-9) {
                return Err(ls.error(
                    &k(&["schedule", "end_time"]),
                    format!(
                        "= {:e} s is shorter than one step dt = {dt:e} s",
                        sch.end_time
                    ),
                ));
            }
        }
        (None, Some(n)) if n >= 1 => {}
        (None, Some(n)) => {
            return Err(ls.error(&k(&["schedule", "steps"]), format!("= {n} must be ≥ 1")));
        }
        (Some(_), Some(_)) => {
            return Err(ls.error(&k(&["schedule"]), "needs exactly one of dt and steps"));
        }
        (None, None) => {
            return Err(ls.error(&k(&["schedule", "dt"]), "is missing: give dt or steps"));
        }
    }
    // The step each output time is reached with, and what the models divide by it
    // (velocities, forces = impulse / h): both must be normal numbers.
    let n = step_count_f64(sch);
    let h = sch.dt.unwrap_or(sch.end_time / n);
    if !(h.is_normal() && (1.0 / h).is_finite() && h >= MIN_STEP) {
        return Err(ls.error(
            &k(&["schedule", if sch.dt.is_some() { "dt" } else { "end_time" }]),
            format!(
                "gives a step of {h:e} s, below the {MIN_STEP:e} s a particle model can \
                 divide by (end_time = {:e} s)",
                sch.end_time
            ),
        ));
    }
    if n > crate::common::limits::MAX_STEPS as f64 {
        return Err(ls.error(
            &k(&["schedule", if sch.dt.is_some() { "dt" } else { "steps" }]),
            format!(
                "gives {n:.3e} steps, more than the {} a run may take",
                crate::common::limits::MAX_STEPS
            ),
        ));
    }
    Ok(())
}

/// Fields of a wall probe (`wall = NAME`, models `nscd` and `lsm`), in the order of
/// their index: the force on the disks (N/m) and its moment (N·m/m).
pub const WALL_FIELDS: [&str; 3] = ["fx", "fy", "torque"];

/// Check the probes and lines of a particle scene of `model`: particle fields with
/// `particle = N`, `cell_fields` with `cell = { center, radius }`, `global_fields` with
/// neither.
pub fn check_output_of(
    ls: &LoadedScene,
    model: &str,
    cell_fields: &[&str],
    global_fields: &[&str],
) -> Result<(), SceneError> {
    let s = &ls.scene;
    if s.output.every < 1 {
        return Err(ls.error(
            &k(&["output", "every"]),
            format!("= {} must be ≥ 1", s.output.every),
        ));
    }
    let mut names = std::collections::BTreeSet::new();
    for (i, p) in s.output.probe.iter().enumerate() {
        let key = |f: &str| ki("output.probe", i, &[f]);
        if !names.insert(p.name.clone()) || p.name == "time" || p.name.contains(',') {
            return Err(ls.error(
                &key("name"),
                format!("= \"{}\" is repeated, reserved or contains a comma", p.name),
            ));
        }
        if !p.at.is_empty() {
            return Err(ls.error(
                &key("at"),
                format!("is for grid models; model \"{model}\" probes a particle or a cell"),
            ));
        }
        let f = p.field.as_str();
        if p.wall.is_some() {
            // The reaction of a wall (its name is checked by the model).
            if !WALL_FIELDS.contains(&f) || p.particle.is_some() || p.cell.is_some() {
                return Err(ls.error(
                    &key("wall"),
                    format!(
                        "probes a wall's reaction: field must be fx, fy or torque (not \"{f}\"), \
                         without particle or cell"
                    ),
                ));
            }
        } else if PARTICLE_FIELDS.contains(&f) {
            match (p.particle, &p.cell) {
                (Some(n), None) if n >= 0 => {}
                (Some(n), None) => {
                    return Err(ls.error(&key("particle"), format!("= {n} must be ≥ 0")));
                }
                _ => {
                    return Err(ls.error(
                        &key("particle"),
                        format!("is required (and cell is not allowed) for field \"{f}\""),
                    ));
                }
            }
        } else if global_fields.contains(&f) {
            if p.particle.is_some() || p.cell.is_some() {
                return Err(ls.error(
                    &key(if p.particle.is_some() {
                        "particle"
                    } else {
                        "cell"
                    }),
                    format!("is not allowed for field \"{f}\" (a value of the whole scene)"),
                ));
            }
        } else if cell_fields.contains(&f) {
            match (p.particle, &p.cell) {
                (None, Some(c)) => {
                    if c.center.len() != 2 || !c.center.iter().all(|v| v.is_finite()) {
                        return Err(ls.error(&key("cell"), "center must be [x, y]"));
                    }
                    positive_at(ls, &key("cell"), c.radius)?;
                }
                _ => {
                    return Err(ls.error(
                        &key("cell"),
                        format!("is required (and particle is not allowed) for field \"{f}\""),
                    ));
                }
            }
        } else {
            return Err(ls.error(
                &key("field"),
                format!(
                    "= \"{f}\" is not a field of model \"{model}\" (particle: {}; cell: {}; scene: {})",
                    PARTICLE_FIELDS.join(" "),
                    cell_fields.join(" "),
                    global_fields.join(" ")
                ),
            ));
        }
    }
    for (i, l) in s.output.line.iter().enumerate() {
        let key = |f: &str| ki("output.line", i, &[f]);
        if !PARTICLE_FIELDS.contains(&l.field.as_str()) {
            return Err(ls.error(
                &key("field"),
                format!(
                    "= \"{}\" must be a particle field: {}",
                    l.field,
                    PARTICLE_FIELDS.join(" ")
                ),
            ));
        }
        if l.from.len() != 2 || l.to.len() != 2 {
            return Err(ls.error(&key("from"), "and to must be [x, y]"));
        }
        crate::common::loaded::line_points_and_name(ls, i, l)?;
    }
    Ok(())
}

/// `v` is a finite number > 0.
fn positive_at(
    ls: &crate::common::loaded::LoadedScene,
    key: &[crate::common::sections::KeyPart],
    v: f64,
) -> Result<(), crate::common::loaded::SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ls.error(key, format!("= {v} must be a positive number")))
    }
}
