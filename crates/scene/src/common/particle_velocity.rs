//! `[[particles.velocity]]`: initial velocities and spins of the disks of a particle
//! scene, for a selection of them (the disks whose centre lies in a box, a disk or a
//! polygon, written as the region keys of `[particles]`, or listed by index; all of them
//! when nothing selects), as numbers or expressions of the centre.
//!
//! The tables apply in the file's order, a later one overriding an earlier one on the
//! disks both select; a table sets only the components it gives.

use serde::Deserialize;

use porofrac_particles::Disks;
use porofrac_particles::packing::Region;

use crate::common::expr::Expr;
use crate::common::loaded::{LoadedScene, SceneError, expr_ok, ki};
use crate::common::model::RunError;
use crate::common::particles::CircleSpec;
use crate::common::sections::NumOrExpr;

/// One `[[particles.velocity]]` table.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ParticleVelocity {
    /// Select the disks whose centre lies in the box `[[x0, y0], [x1, y1]]` (m).
    #[schemars(extend("unit" = "m"))]
    pub region: Option<[[f64; 2]; 2]>,
    /// Or in the disk `{ center = [x, y], radius = R }` (m).
    #[schemars(extend("unit" = "m"))]
    pub disk: Option<CircleSpec>,
    /// Or in the polygon, vertices in order (m).
    #[schemars(extend("unit" = "m"))]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// Or the disks of these indices (from 0, in the order of the particles).
    pub particles: Option<Vec<i64>>,
    /// Velocity `[vx, vy]` (m/s): numbers or expressions in x, y (the disk's centre).
    #[schemars(extend("unit" = "m/s"))]
    pub v: Option<[NumOrExpr; 2]>,
    /// Angular velocity (rad/s, counter-clockwise): a number or an expression in x, y.
    #[schemars(extend("unit" = "rad/s"))]
    pub omega: Option<NumOrExpr>,
}

impl ParticleVelocity {
    fn region(&self) -> Option<Region> {
        if let Some(b) = self.region {
            return Some(Region::Box { lo: b[0], hi: b[1] });
        }
        if let Some(c) = self.disk {
            return Some(Region::Disk {
                centre: c.center,
                radius: c.radius,
            });
        }
        self.polygon.clone().map(Region::Polygon)
    }
}

/// Check the `[[particles.velocity]]` tables of a scene of `model` (models `nscd` and
/// `lsm` read them): at most one selection, a non-degenerate region, indices ≥ 0, and `v` or
/// `omega` given as finite numbers or expressions that parse.
pub fn check(ls: &LoadedScene, model: &str, tables: &[ParticleVelocity]) -> Result<(), SceneError> {
    if !tables.is_empty() && !["nscd", "lsm"].contains(&model) {
        return Err(ls.error(
            &ki("particles.velocity", 0, &[]),
            format!("belongs to models \"nscd\" and \"lsm\", not \"{model}\""),
        ));
    }
    for (i, t) in tables.iter().enumerate() {
        let key = |f: &str| ki("particles.velocity", i, &[f]);
        let chosen: Vec<&str> = [
            ("region", t.region.is_some()),
            ("disk", t.disk.is_some()),
            ("polygon", t.polygon.is_some()),
            ("particles", t.particles.is_some()),
        ]
        .iter()
        .filter(|(_, set)| *set)
        .map(|(f, _)| *f)
        .collect();
        if chosen.len() > 1 {
            return Err(ls.error(
                &key(chosen[1]),
                format!(
                    "and {} both select: give one of region, disk, polygon, particles \
                     (none: every disk)",
                    chosen[0]
                ),
            ));
        }
        if let Some(r) = t.region()
            && (r.check().is_err()
                || !r
                    .bounds()
                    .0
                    .iter()
                    .chain(&r.bounds().1)
                    .all(|v| v.is_finite()))
        {
            return Err(ls.error(
                &key(chosen[0]),
                "must be a finite box [[x0, y0], [x1, y1]] with x1 > x0 and y1 > y0, \
                 a disk of positive radius, or a polygon enclosing an area",
            ));
        }
        if let Some(list) = &t.particles
            && let Some(n) = list.iter().find(|n| **n < 0)
        {
            return Err(ls.error(&key("particles"), format!("lists {n}: indices are ≥ 0")));
        }
        if t.v.is_none() && t.omega.is_none() {
            return Err(ls.error(
                &ki("particles.velocity", i, &[]),
                "sets nothing: give v = [vx, vy] (m/s), omega (rad/s), or both",
            ));
        }
        if let Some(v) = &t.v {
            for c in v {
                expr_ok(ls, &key("v"), c, false)?;
            }
        }
        if let Some(w) = &t.omega {
            expr_ok(ls, &key("omega"), w, false)?;
        }
    }
    Ok(())
}

/// Set the velocities and spins of `disks` from the checked tables (in order). An index
/// beyond the particles, or a value that is not finite at a selected centre, is an
/// error naming the key.
pub fn apply(
    ls: &LoadedScene,
    tables: &[ParticleVelocity],
    disks: &mut Disks,
) -> Result<(), RunError> {
    let n = disks.len();
    let compile = |v: &NumOrExpr| match v {
        NumOrExpr::Num(x) => Expr::constant(*x),
        NumOrExpr::Expr(s) => Expr::parse(s).unwrap_or_else(|_| Expr::constant(f64::NAN)),
    };
    for (i, t) in tables.iter().enumerate() {
        let key = |f: &str| ki("particles.velocity", i, &[f]);
        let selected: Vec<usize> = match (&t.particles, t.region()) {
            (Some(list), _) => {
                let mut out = Vec::with_capacity(list.len());
                for &k in list {
                    if k as u64 >= n as u64 {
                        return Err(ls
                            .error(
                                &key("particles"),
                                format!("lists {k} but the scene has {n} particles"),
                            )
                            .into());
                    }
                    out.push(k as usize);
                }
                out
            }
            (None, Some(r)) => (0..n)
                .filter(|&k| r.contains_disk(disks.x[k], 0.0))
                .collect(),
            (None, None) => (0..n).collect(),
        };
        let v = t.v.as_ref().map(|v| [compile(&v[0]), compile(&v[1])]);
        let w = t.omega.as_ref().map(compile);
        for k in selected {
            let x = disks.x[k];
            if let Some(v) = &v {
                let value = [v[0].eval(&x, 0.0), v[1].eval(&x, 0.0)];
                if !value.iter().all(|c| c.is_finite()) {
                    return Err(ls
                        .error(
                            &key("v"),
                            format!(
                                "is {value:?} at particle {k} (centre [{}, {}]): not finite",
                                x[0], x[1]
                            ),
                        )
                        .into());
                }
                disks.v[k] = value;
            }
            if let Some(w) = &w {
                let value = w.eval(&x, 0.0);
                if !value.is_finite() {
                    return Err(ls
                        .error(
                            &key("omega"),
                            format!(
                                "is {value} at particle {k} (centre [{}, {}]): not finite",
                                x[0], x[1]
                            ),
                        )
                        .into());
                }
                disks.omega[k] = value;
            }
        }
    }
    Ok(())
}
