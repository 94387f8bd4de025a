//! The state of a [`LatticeSolid`] that changes during a run, as named arrays, so that a
//! run can be saved and continued with the same results ([`LatticeSolid::save_state`],
//! [`LatticeSolid::restore_state`]): disk positions, velocities and rotations, the
//! motion of each disk, the bonds' shear springs and intact flags, the Verlet list of
//! candidate contacts with their tangential springs and the positions it was built at,
//! the forces of the current configuration (the first half-kick of the next step uses
//! them), applied loads, wall pressures, the broken bonds, the time and the counters.
//! What the scene fixes (radii, masses, bond stiffnesses and strengths) is not saved:
//! the solid is rebuilt from the scene first.

use super::LatticeSolid;
use crate::LsmError;
use crate::bond::{BreakMode, BrokenBond};
use crate::contact::Pair;
use crate::law::Motion;

/// Named arrays of a solid's state (see the module docs).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolidState {
    /// Named `f64` arrays.
    pub reals: Vec<(&'static str, Vec<f64>)>,
    /// Named integer arrays.
    pub ints: Vec<(&'static str, Vec<u64>)>,
}

impl SolidState {
    fn real(&self, name: &str) -> Result<&[f64], LsmError> {
        self.reals
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| v.as_slice())
            .ok_or_else(|| LsmError::State(format!("no array `{name}`")))
    }
    fn int(&self, name: &str) -> Result<&[u64], LsmError> {
        self.ints
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| v.as_slice())
            .ok_or_else(|| LsmError::State(format!("no array `{name}`")))
    }
}

fn flat<const N: usize>(v: &[[f64; N]]) -> Vec<f64> {
    v.iter().flatten().copied().collect()
}

fn unflat<const N: usize>(name: &str, v: &[f64], len: usize) -> Result<Vec<[f64; N]>, LsmError> {
    if v.len() != N * len {
        return Err(LsmError::State(format!(
            "array `{name}` has {} values, {} expected",
            v.len(),
            N * len
        )));
    }
    Ok(v.chunks_exact(N)
        .map(|c| std::array::from_fn(|k| c[k]))
        .collect())
}

fn sized<'a, T>(name: &str, v: &'a [T], len: usize) -> Result<&'a [T], LsmError> {
    if v.len() == len {
        Ok(v)
    } else {
        Err(LsmError::State(format!(
            "array `{name}` has {} values, {len} expected",
            v.len()
        )))
    }
}

impl LatticeSolid {
    /// The state that changes during a run (see the module docs).
    pub fn save_state(&self) -> SolidState {
        let d = &self.disks;
        // Motion: kind (0 free, 1 fixed, 2 velocity, 3 axis) and axis; values vx vy.
        let mut motion_kind = Vec::with_capacity(d.len());
        let mut motion_value = Vec::with_capacity(2 * d.len());
        for m in &self.motion {
            let (k, v) = match *m {
                Motion::Free => (0, [0.0; 2]),
                Motion::Fixed => (1, [0.0; 2]),
                Motion::Velocity(u) => (2, u),
                Motion::Axis { axis, velocity } => (3 + axis as u64, [velocity, 0.0]),
            };
            motion_kind.push(k);
            motion_value.extend(v);
        }
        let broken_modes = self
            .broken
            .iter()
            .flat_map(|b| {
                [
                    b.i as u64,
                    b.j as u64,
                    u64::from(b.mode == BreakMode::Shear),
                ]
            })
            .collect();
        SolidState {
            reals: vec![
                ("x", flat(&d.x)),
                ("x0", flat(&d.x0)),
                ("v", flat(&d.v)),
                ("angle", d.angle.clone()),
                ("omega", d.omega.clone()),
                ("motion_value", motion_value),
                ("bond_shear", self.bonds.iter().map(|b| b.shear).collect()),
                (
                    "bond_force",
                    self.bond_force
                        .iter()
                        .flat_map(|f| [f.f[0], f.f[1], f.mi, f.mj, f.fn_, f.fs, f.mb])
                        .collect(),
                ),
                ("pair_ut", self.pairs.iter().map(|p| p.ut).collect()),
                (
                    "pair_force",
                    self.pair_force
                        .iter()
                        .flat_map(|f| [f.f[0], f.f[1], f.mi, f.mj, f.fn_, f.ft])
                        .collect(),
                ),
                ("x_build", flat(&self.x_build)),
                ("force", flat(&self.force)),
                ("applied", flat(&self.applied)),
                ("loads", flat(&self.loads)),
                (
                    "wall_pressure",
                    self.walls.iter().map(|w| w.pressure).collect(),
                ),
                ("dx", flat(&self.dx)),
                ("time", vec![self.time]),
                (
                    "broken_at",
                    self.broken
                        .iter()
                        .flat_map(|b| [b.time, b.x, b.y])
                        .collect(),
                ),
            ],
            ints: vec![
                ("motion_kind", motion_kind),
                (
                    "bond_intact",
                    self.bonds.iter().map(|b| u64::from(b.intact)).collect(),
                ),
                (
                    "pairs",
                    self.pairs
                        .iter()
                        .flat_map(|p| [u64::from(p.i), u64::from(p.j), u64::from(p.bond)])
                        .collect(),
                ),
                ("broken", broken_modes),
                ("updates", vec![self.bond_updates, self.contact_updates]),
            ],
        }
    }

    /// Put back a state [`LatticeSolid::save_state`] gave, into a solid built from the
    /// same scene. Arrays whose sizes do not fit the solid are refused, naming the array.
    pub fn restore_state(&mut self, s: &SolidState) -> Result<(), LsmError> {
        let n = self.disks.len();
        let nb = self.bonds.len();
        let d = &mut self.disks;
        d.x = unflat("x", s.real("x")?, n)?;
        d.x0 = unflat("x0", s.real("x0")?, n)?;
        d.v = unflat("v", s.real("v")?, n)?;
        d.angle = sized("angle", s.real("angle")?, n)?.to_vec();
        d.omega = sized("omega", s.real("omega")?, n)?.to_vec();
        let kinds = sized("motion_kind", s.int("motion_kind")?, n)?;
        let values: Vec<[f64; 2]> = unflat("motion_value", s.real("motion_value")?, n)?;
        for ((m, &k), v) in self.motion.iter_mut().zip(kinds).zip(values) {
            *m = match k {
                0 => Motion::Free,
                1 => Motion::Fixed,
                2 => Motion::Velocity(v),
                3 | 4 => Motion::Axis {
                    axis: (k - 3) as usize,
                    velocity: v[0],
                },
                k => return Err(LsmError::State(format!("motion kind {k}"))),
            };
        }
        let shear = sized("bond_shear", s.real("bond_shear")?, nb)?;
        let intact = sized("bond_intact", s.int("bond_intact")?, nb)?;
        for ((b, &sh), &ok) in self.bonds.iter_mut().zip(shear).zip(intact) {
            b.shear = sh;
            b.intact = ok != 0;
        }
        let bf: Vec<[f64; 7]> = unflat("bond_force", s.real("bond_force")?, nb)?;
        for (f, v) in self.bond_force.iter_mut().zip(bf) {
            (f.f, f.mi, f.mj, f.fn_, f.fs, f.mb) = ([v[0], v[1]], v[2], v[3], v[4], v[5], v[6]);
        }
        let ut = s.real("pair_ut")?;
        let np = ut.len();
        let ids = sized("pairs", s.int("pairs")?, 3 * np)?;
        let mut pairs = Vec::with_capacity(np);
        for (k, &u) in ut.iter().enumerate() {
            let (i, j, b) = (ids[3 * k], ids[3 * k + 1], ids[3 * k + 2]);
            if i >= n as u64 || j >= n as u64 || (b >= nb as u64 && b != u64::from(u32::MAX)) {
                return Err(LsmError::State(format!(
                    "pair {k} names a missing disk or bond"
                )));
            }
            pairs.push(Pair {
                i: i as u32,
                j: j as u32,
                bond: b as u32,
                ut: u,
            });
        }
        self.pairs = pairs;
        let pf: Vec<[f64; 6]> = unflat("pair_force", s.real("pair_force")?, np)?;
        self.pair_force = pf
            .into_iter()
            .map(|v| crate::contact::ContactForce {
                f: [v[0], v[1]],
                mi: v[2],
                mj: v[3],
                fn_: v[4],
                ft: v[5],
            })
            .collect();
        self.rebuild_pair_adjacency();
        self.x_build = unflat("x_build", s.real("x_build")?, n)?;
        self.force = unflat("force", s.real("force")?, n)?;
        self.applied = unflat("applied", s.real("applied")?, n)?;
        self.loads = unflat("loads", s.real("loads")?, n)?;
        let p = sized("wall_pressure", s.real("wall_pressure")?, self.walls.len())?;
        for (w, &p) in self.walls.iter_mut().zip(p) {
            w.pressure = p;
        }
        self.dx = unflat("dx", s.real("dx")?, n)?;
        self.time = sized("time", s.real("time")?, 1)?[0];
        let at = s.real("broken_at")?;
        let nbk = at.len() / 3;
        let ids = sized("broken", s.int("broken")?, 3 * nbk)?;
        let at: Vec<[f64; 3]> = unflat("broken_at", at, nbk)?;
        self.broken = (0..nbk)
            .map(|k| BrokenBond {
                time: at[k][0],
                i: ids[3 * k] as usize,
                j: ids[3 * k + 1] as usize,
                x: at[k][1],
                y: at[k][2],
                mode: if ids[3 * k + 2] == 1 {
                    BreakMode::Shear
                } else {
                    BreakMode::Tensile
                },
            })
            .collect();
        if self.broken.iter().any(|b| b.i >= n || b.j >= n) {
            return Err(LsmError::State("a broken bond names a missing disk".into()));
        }
        let u = sized("updates", s.int("updates")?, 2)?;
        (self.bond_updates, self.contact_updates) = (u[0], u[1]);
        Ok(())
    }
}
