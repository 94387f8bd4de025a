//! The lattice solid model (P. Mora, Y. Wang, F. Alonso-Marroquin (2015), J. Earth Sci.
//! 26(1); `[scene] model = "lsm"`): bonded disks ([`porofrac_lsm`]).
//!
//! - *build*: the disks of `[particles]` ([`crate::common::particles`]) with their
//!   initial velocities and spins (`[[particles.velocity]]`), the bond law of
//!   `[bonds]` (E and ν through the hexagonal closed form, or k_n, k_s), `[contacts]`,
//!   `[lsm]` (time step, damping, gravity) and `[loading]` (platens that may stop or
//!   hold a force, [`servo`], a
//!   pressure ramp on
//!   the hole, on the faces seen from its centre or on the faces a fluid would wet,
//!   [`porofrac_lsm::WallFaces`]); with `[bonds] calibrate = true` a uniaxial compression
//!   and a Brazilian test of the same packing recipe first ([`porofrac_lsm::calibrate`]);
//! - *step*: [`sub_steps`] equal LSM steps between two output times (whole steps of
//!   `[lsm] dt` when the interval is a multiple of it);
//! - *fields*: particle probes (`x y vx vy omega fx fy radius`), tracked cells (`p q
//!   anisotropy anisotropy_volume dilation_x dilation_y contacts broken_bonds torque`),
//!   wall probes (`wall = "top" | "bottom" | "hole"`: `fx fy torque`, [`reaction`]), scene
//!   probes (`pressure platen_force broken broken_tensile broken_shear crack_extent`), with `[lbm]`
//!   fluid probes at a point (`fluid_pressure fluid_speed`, [`fluid::Fluid::point_values`]),
//!   lines,
//!   `vtk/particles_NNNN.vtp` (with `broken_bonds` per particle) and
//!   `vtk/contacts_NNNN.vtp` (intact bonds `bonded = 1`, touching contacts `0`; cell
//!   data `normal_force` and `tangential_force` in N/m, `bending_moment` in N·m/m: the
//!   bond's `M_b = k_b (θ_j − θ_i − Δθ₀)` on the line's first disk, 0 on a contact),
//!   `broken.csv` (`time [s],i,j,x [m],y [m],mode`), with a pressurised hole `crack.csv`
//!   ([`crack::CrackLog`]), field extrema and `summary.json` keys
//!   (`particles`, `bonds`, `broken_bonds`, `broken_tensile`, `broken_shear`,
//!   `contacts`, `lsm_steps`, `dt`, `dt_used`, `stable_dt`, `bond_updates_per_second`,
//!   `contact_updates_per_second`, `initiation_pressure`, `breakdown_pressure`,
//!   `breakdown_extent`, `crack_extent`, `calibration`);
//! - *plots*: probe series, `particles.png` (disks coloured by displacement, broken
//!   bonds drawn) and `breakage.png` (broken bonds against time, by mode).

pub mod check;
pub mod crack;
pub mod crack_flow;
pub mod file;
pub mod fluid;
pub mod reaction;
pub mod servo;

use crate::common::laws::LawRegistry;
use crate::common::loaded::SceneError;
use crate::common::model::ModelKind;
use crate::common::model::{OwnSections, own_sections};

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use porofrac_grid::io::PvdWriter;
use porofrac_lsm::calibrate::{QuasiStatic, brazilian_polled, hexagonal_moduli, uniaxial_polled};
use porofrac_lsm::{
    BreakMode, ContactLaw, Damping, LatticeSolid, LsmError, LsmSpec, Motion, NormalLaw, WallFaces,
};
use porofrac_particles::packing::Region;
use porofrac_particles::tracked::CellContact;
use porofrac_particles::vtk::ContactLine;
use porofrac_particles::{Disks, RandomPacking, TrackedCell};

use crate::common::checkpoint::{self, State};
use crate::common::driver::{Observer, SetupPoll, Stop};
use crate::common::loaded::{LoadedScene, k, ki, step_count};
use crate::common::model::{Built, Model, Purpose, RunError, Sizes, StepStats};
use crate::common::output::{SolverStats, WallSeconds};
use crate::common::particle_output::{self, PARTICLE_FIELDS};
use crate::common::plots::Column;

use file::{DampingChoice, NormalChoice, WallChoice};

/// Build a checked lattice solid scene's model and hand it to `purpose`.
pub(crate) fn build_for(
    ls: &LoadedScene,
    purpose: &Purpose<'_>,
    observer: &mut dyn Observer,
) -> Result<Built, RunError> {
    let start = Instant::now();
    let mut model = build(ls, &mut SetupPoll::new(observer))?;
    let build_seconds = start.elapsed().as_secs_f64();
    purpose.finish(ls, &mut model, observer, start, build_seconds, 2)
}

#[derive(Clone, Copy, Debug)]
enum ProbeKind {
    Particle(usize, usize),
    Cell(usize, usize),
    Global(usize),
    /// A fluid field ([`check::FLUID_FIELDS`]) at a point (m).
    Fluid([f64; 2], usize),
    /// `wall = NAME`: `fx fy torque` (component 0, 1, 2) of a platen's action on the
    /// rest of the sample about its centroid, or of the hole pressure on the lining
    /// about the hole centre ([`check::WALLS`]).
    Wall(WallProbe, usize),
}

/// What a `wall = NAME` probe measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum WallProbe {
    /// The top platen (`"top"`).
    Top,
    /// The bottom platen (`"bottom"`).
    Bottom,
    /// The hole pressure (`"hole"`).
    Hole,
}

/// Results of `[bonds] calibrate = true`.
#[derive(Clone, Copy, Debug)]
struct Calibration {
    e: f64,
    nu: f64,
    tensile: f64,
}

/// A lattice solid scene being run.
pub struct LsmModel<'a> {
    ls: &'a LoadedScene,
    solid: LatticeSolid,
    times: Vec<f64>,
    dt: f64,
    probes: Vec<ProbeKind>,
    cells: Vec<TrackedCell>,
    top: Vec<usize>,
    bottom: Vec<usize>,
    /// `[loading] platens`: speed (m/s) and how far each platen moves before it stops
    /// (m, infinite without a stop).
    platen_speed: f64,
    platen_travel: f64,
    /// `[loading] platens.hold_force`: the servo holding the platen force.
    servo: Option<servo::Servo>,
    wall: Option<usize>,
    pressure_rate: f64,
    pressure_max: f64,
    pressure: f64,
    crack: Option<crack::CrackLog>,
    /// `[loading] flood_cracks`: the crack's pressure loads, one entry per disk (empty
    /// without).
    flood: Vec<[f64; 3]>,
    calibration: Option<Calibration>,
    lsm_steps: u64,
    step_seconds: f64,
    broken_written: usize,
    history: Vec<[f64; 3]>,
    contacts_pvd: RefCell<Option<PvdWriter>>,
    /// Index of the output time of the current state (the time of its VTK files).
    current: usize,
    fluid: Option<fluid::Fluid>,
    /// Polled between the sub-steps of a step.
    stop: Stop,
}

/// How close (relative) the ratio of an output interval to `[lsm] dt` must be to an
/// integer to be taken as that integer: an interval of `10 dt` whose subtraction of two
/// output times left a round-off of a few ulps takes 10 sub-steps, not 11.
pub const WHOLE_STEPS_TOLERANCE: f64 = 1e-9;

/// The number of sub-steps of at most `dt` that cover an interval `h`: the ratio `h/dt`
/// rounded when it lies within [`WHOLE_STEPS_TOLERANCE`] of an integer (so an interval
/// that is a multiple of `dt` takes whole steps of `dt`), else rounded up; at least 1.
pub fn sub_steps(h: f64, dt: f64) -> usize {
    let ratio = h / dt;
    let nearest = ratio.round();
    let n = if (ratio - nearest).abs() <= WHOLE_STEPS_TOLERANCE * nearest.max(1.0) {
        nearest
    } else {
        ratio.ceil()
    };
    n.max(1.0) as usize
}

/// Smallest `[lsm] dt` as a fraction of the stable step: below it the run takes a
/// million times more steps than a stable one for no gain in accuracy (the explicit
/// scheme's error is already far below the bond-breakage resolution at half the stable
/// step).
const MIN_DT_FRACTION: f64 = 1e-6;

fn spec_of(ls: &LoadedScene) -> Result<LsmSpec, SceneError> {
    let law = check::bond_law(ls)?;
    let mut spec = LsmSpec::new(law);
    spec.bond_tolerance = own(ls)
        .bonds
        .as_ref()
        .and_then(|b| b.tolerance)
        .unwrap_or(0.05);
    let c = own(ls).contacts.clone().unwrap_or_default();
    spec.contacts = ContactLaw {
        normal: match c.normal {
            NormalChoice::Linear => NormalLaw::Linear,
            NormalChoice::Hertz => NormalLaw::Hertz {
                modulus: c.modulus.unwrap_or(f64::NAN),
                poisson: c.poisson_ratio.unwrap_or(0.25),
            },
        },
        kn: c.kn.unwrap_or(law.kn),
        ks: c.ks.unwrap_or(law.ks),
        friction: c.friction.unwrap_or(0.6),
    };
    let l = own(ls).lsm.clone().unwrap_or_default();
    spec.damping = match l.damping {
        DampingChoice::None => Damping::None,
        DampingChoice::Local => Damping::Local {
            alpha: l.damping_coefficient.unwrap_or(0.7),
        },
        DampingChoice::Viscous => Damping::Viscous {
            rate: l.damping_coefficient.unwrap_or(0.0),
        },
    };
    spec.gravity = l.gravity.unwrap_or([0.0; 2]);
    Ok(spec)
}

/// Calibration samples with the packing recipe of `[particles]` (random kind): a box of
/// 20 × 20 largest radii for E and ν, a disk of radius 10 largest radii for σ_t.
fn calibrate(
    ls: &LoadedScene,
    spec: &LsmSpec,
    setup: &mut SetupPoll<'_>,
) -> Result<Calibration, RunError> {
    let p = ls.scene.particles.as_ref().expect("checked");
    let key = k(&["bonds", "calibrate"]);
    let (r0, r1) = match (&p.radius_list, p.radius) {
        (Some(l), _) => (
            l.iter().copied().fold(f64::INFINITY, f64::min),
            l.iter().copied().fold(0.0, f64::max),
        ),
        (None, Some(r)) => (r.range()[0], r.range()[1]),
        _ => {
            return Err(ls
                .error(&key, "needs a random or hexagonal [particles] kind")
                .into());
        }
    };
    let error = |e: LsmError| match e {
        LsmError::Interrupted => RunError::Interrupted,
        e => check::lsm_error(ls, &e).into(),
    };
    setup.phase("calibration");
    let packing = |lo: [f64; 2],
                   hi: [f64; 2],
                   region: &Region,
                   setup: &mut SetupPoll<'_>|
     -> Result<Disks, RunError> {
        let mut rp = RandomPacking::new(
            lo,
            hi,
            r0,
            r1,
            p.packing_fraction.unwrap_or(0.8),
            p.seed.unwrap_or(1),
        );
        if let Some(l) = &p.radius_list {
            rp = rp.with_radii(l);
        }
        let pk = match rp.generate_in_polled(region, &[], &mut setup.callback()) {
            Ok(pk) => pk,
            Err(porofrac_particles::ParticleError::Interrupted) => {
                return Err(RunError::Interrupted);
            }
            Err(e) => return Err(ls.error(&key, format!(": {e}")).into()),
        };
        Ok(Disks::new(&pk.centres, &pk.radii, p.density)
            .map_err(|e| ls.error(&key, format!(": {e}")))?)
    };
    let (e_lattice, _) = hexagonal_moduli(spec.bonds.kn, spec.bonds.ks);
    let c = (e_lattice / p.density).sqrt();
    let side = 20.0 * r1;
    let boxed = packing(
        [0.0; 2],
        [side; 2],
        &Region::Box {
            lo: [0.0; 2],
            hi: [side; 2],
        },
        setup,
    )?;
    let q = QuasiStatic {
        speed: 2e-4 * c,
        ..QuasiStatic::new(1.0)
    };
    let u = uniaxial_polled(boxed, *spec, 1e-4, &q, &mut setup.callback()).map_err(error)?;
    let rad = 10.0 * r1;
    let disk = packing(
        [-rad; 2],
        [rad; 2],
        &Region::Disk {
            centre: [0.0; 2],
            radius: rad,
        },
        setup,
    )?;
    let q = QuasiStatic {
        speed: 2e-5 * c,
        ..QuasiStatic::new(1.0)
    };
    let b = brazilian_polled(disk, *spec, 2.0 * r1, &q, &mut setup.callback()).map_err(error)?;
    Ok(Calibration {
        e: u.e,
        nu: u.nu,
        tensile: b.tensile_strength,
    })
}

/// Build the model of a checked lattice solid scene, reporting the packing and the
/// calibration to `setup`.
pub fn build<'a>(ls: &'a LoadedScene, setup: &mut SetupPoll<'_>) -> Result<LsmModel<'a>, RunError> {
    let s = &ls.scene;
    let mut disks = crate::common::particles::generate(ls, setup)?;
    crate::common::particles::initial_velocities(ls, &mut disks)?;
    let spec = spec_of(ls)?;
    let calibration = if own(ls).bonds.as_ref().is_some_and(|b| b.calibrate) {
        Some(calibrate(ls, &spec, setup)?)
    } else {
        None
    };
    setup.check()?;
    let mut solid = LatticeSolid::new(disks, spec).map_err(|e| check::lsm_error(ls, &e))?;
    setup.check()?;
    let l = own(ls).lsm.clone().unwrap_or_default();
    let stable = solid.stable_dt();
    let dt = match l.dt {
        Some(dt) if dt > stable => {
            return Err(ls
                .error(
                    &k(&["lsm", "dt"]),
                    format!("= {dt:.4e} s is above the stable time step {stable:.4e} s"),
                )
                .into());
        }
        Some(dt) if dt < MIN_DT_FRACTION * stable => {
            return Err(ls
                .error(
                    &k(&["lsm", "dt"]),
                    format!(
                        "= {dt:.4e} s is below {MIN_DT_FRACTION:e} of the stable time step \
                         {stable:.4e} s: the run would take that many more steps for nothing \
                         (leave dt out for half the stable step)"
                    ),
                )
                .into());
        }
        Some(dt) => dt,
        None => l.dt_fraction.unwrap_or(0.5) * stable,
    };
    let load = own(ls).loading.clone().unwrap_or_default();
    let (mut top, mut bottom) = (Vec::new(), Vec::new());
    if let Some(pl) = load.platens {
        let d = solid.disks();
        let (lo, hi) =
            d.x.iter()
                .zip(&d.r)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (x, r)| {
                    (a.min(x[1] - r), b.max(x[1] + r))
                });
        for i in 0..d.len() {
            if d.x[i][1] + d.r[i] > hi - pl.thickness {
                top.push(i);
            } else if d.x[i][1] - d.r[i] < lo + pl.thickness {
                bottom.push(i);
            }
        }
        if top.is_empty() || bottom.is_empty() {
            return Err(ls
                .error(&k(&["loading", "platens"]), "selects no particle")
                .into());
        }
        for &i in &top {
            solid.set_motion(i, Motion::Velocity([0.0, -pl.velocity]));
        }
        for &i in &bottom {
            solid.set_motion(i, Motion::Velocity([0.0, pl.velocity]));
        }
    }
    let wall = match (
        load.pressure_rate,
        s.particles.as_ref().and_then(|p| p.hole),
    ) {
        (Some(_), Some(h)) => {
            let faces = match load.wall {
                WallChoice::Rays => WallFaces::Rays,
                WallChoice::Wetted => WallFaces::Wetted {
                    spacing: load
                        .wall_spacing
                        .unwrap_or(0.5 * solid.disks().radius_range()[0]),
                    seal: spec.bond_tolerance + 1.0,
                },
            };
            Some(
                solid
                    .add_pressure_wall_on(h.center, h.radius, faces)
                    .map_err(|e| check::lsm_error(ls, &e))?,
            )
        }
        _ => None,
    };
    let sch = s.schedule.as_ref().expect("checked: [schedule] present");
    let steps = step_count(sch) as usize;
    let h = sch.dt.unwrap_or(sch.end_time / steps as f64);
    let times: Vec<f64> = (0..=steps)
        .map(|i| {
            if i == steps {
                sch.end_time
            } else {
                (i as f64 * h).min(sch.end_time)
            }
        })
        .collect();
    let count = solid.disks().len();
    let mut probes = Vec::new();
    let mut cells = Vec::new();
    for (i, p) in s.output.probe.iter().enumerate() {
        if let Some(name) = &p.wall {
            let component = ["fx", "fy", "torque"]
                .iter()
                .position(|f| *f == p.field)
                .expect("checked");
            let which = match name.as_str() {
                "top" => WallProbe::Top,
                "bottom" => WallProbe::Bottom,
                _ => WallProbe::Hole,
            };
            probes.push(ProbeKind::Wall(which, component));
        } else if let Some(f) = check::FLUID_FIELDS.iter().position(|f| *f == p.field) {
            probes.push(ProbeKind::Fluid([p.at[0], p.at[1]], f));
        } else if let Some(f) = PARTICLE_FIELDS.iter().position(|f| *f == p.field) {
            let idx = p.particle.expect("checked") as usize;
            if idx >= count {
                return Err(ls
                    .error(
                        &ki("output.probe", i, &["particle"]),
                        format!("= {idx} but the scene has {count} particles"),
                    )
                    .into());
            }
            probes.push(ProbeKind::Particle(idx, f));
        } else if let Some(f) = check::GLOBAL_FIELDS.iter().position(|f| *f == p.field) {
            probes.push(ProbeKind::Global(f));
        } else {
            let f = check::CELL_FIELDS
                .iter()
                .position(|f| *f == p.field)
                .expect("checked");
            let c = p.cell.as_ref().expect("checked");
            let cell = TrackedCell::new(&solid.disks().x, [c.center[0], c.center[1]], c.radius);
            if cell.count == 0 {
                return Err(ls
                    .error(&ki("output.probe", i, &["cell"]), "selects no particle")
                    .into());
            }
            probes.push(ProbeKind::Cell(cells.len(), f));
            cells.push(cell);
        }
    }
    let fluid = fluid::Fluid::build(ls, &solid, dt)?;
    let crack = match s.particles.as_ref().and_then(|p| p.hole) {
        Some(h) if wall.is_some() || fluid.as_ref().is_some_and(|f| f.injects()) => Some(
            crack::CrackLog::new(&solid, h.center, h.radius, load.crack_across_pores)
                .map_err(|e| check::lsm_error(ls, &e))?,
        ),
        _ => None,
    };
    let servo = load.platens.and_then(|p| {
        p.hold_force
            .map(|f| servo::Servo::new(f, p.velocity, count, &top, &bottom))
    });
    Ok(LsmModel {
        ls,
        solid,
        times,
        dt,
        probes,
        cells,
        top,
        bottom,
        platen_speed: load.platens.map_or(0.0, |p| p.velocity),
        platen_travel: load.platens.map_or(f64::INFINITY, |p| p.travel()),
        servo,
        wall,
        pressure_rate: load.pressure_rate.unwrap_or(0.0),
        pressure_max: load.pressure_max.unwrap_or(f64::INFINITY),
        pressure: 0.0,
        crack,
        flood: if load.flood_cracks && wall.is_some() {
            vec![[0.0; 3]; count]
        } else {
            Vec::new()
        },
        calibration,
        lsm_steps: 0,
        step_seconds: 0.0,
        broken_written: 0,
        history: vec![[0.0; 3]],
        contacts_pvd: RefCell::new(None),
        current: 0,
        fluid,
        stop: setup.stop_handle(),
    })
}

impl LsmModel<'_> {
    /// Set the platens' velocity for the next sub-step of `dt` when they stop: the
    /// speed while the travel `v (t + dt)` stays within the stop, what is left of it
    /// over `dt` on the sub-step that reaches it, 0 after (held in place, no rotation).
    fn move_platens(&mut self, dt: f64) {
        let t = self.solid.time();
        let (v, travel) = (self.platen_speed, self.platen_travel);
        let speed = if v * (t + dt) <= travel {
            v
        } else if v * t < travel {
            (travel - v * t) / dt
        } else {
            0.0
        };
        self.set_platen_speed(speed);
    }

    /// Move the platens towards each other at `speed` (m/s; negative: apart).
    fn set_platen_speed(&mut self, speed: f64) {
        for &i in &self.top {
            self.solid.set_motion(i, Motion::Velocity([0.0, -speed]));
        }
        for &i in &self.bottom {
            self.solid.set_motion(i, Motion::Velocity([0.0, speed]));
        }
    }

    /// `[F_x, F_y, M]` of a `wall = NAME` probe ([`ProbeKind::Wall`]).
    fn wall_values(&self, which: WallProbe) -> [f64; 3] {
        let n = self.solid.disks().len();
        let members = |list: &[usize]| {
            let mut m = vec![false; n];
            for &i in list {
                m[i] = true;
            }
            m
        };
        match which {
            WallProbe::Top | WallProbe::Bottom => {
                let platen = members(if which == WallProbe::Top {
                    &self.top
                } else {
                    &self.bottom
                });
                let about = reaction::centroid(&self.solid, &platen);
                let rest: Vec<bool> = platen.iter().map(|m| !m).collect();
                reaction::exerted_on(&self.solid, &rest, about)
            }
            WallProbe::Hole => self
                .wall
                .map_or([f64::NAN; 3], |w| reaction::wall_load(&self.solid, w)),
        }
    }

    /// The largest sub-step taken up to the current output time (s; 0 before the
    /// first): each output interval `h` takes [`sub_steps`]`(h, dt)` equal sub-steps.
    fn dt_used(&self) -> f64 {
        self.times[..=self.current]
            .windows(2)
            .map(|w| {
                let h = w[1] - w[0];
                h / sub_steps(h, self.dt) as f64
            })
            .fold(0.0, f64::max)
    }

    fn forces2(&self) -> Vec<[f64; 2]> {
        self.solid.forces().iter().map(|f| [f[0], f[1]]).collect()
    }

    fn platen_force(&self) -> f64 {
        let f = self.solid.forces();
        0.5 * (self.top.iter().map(|&i| f[i][1]).sum::<f64>()
            - self.bottom.iter().map(|&i| f[i][1]).sum::<f64>())
    }

    fn broken_by_mode(&self) -> (usize, usize) {
        let t = self
            .solid
            .broken()
            .iter()
            .filter(|b| b.mode == BreakMode::Tensile)
            .count();
        (t, self.solid.broken().len() - t)
    }

    /// Intact bonds and touching contacts as the tracked cells and the VTK lines see
    /// them.
    /// Broken bonds per disk and the links drawn, for the VTK files and the in-memory
    /// snapshots.
    fn disk_outputs(&self) -> (Vec<f64>, Vec<ContactLine>) {
        let (per, lines, _) = self.disk_outputs_with_moments();
        (per, lines)
    }

    /// [`Self::disk_outputs`] with the bending moment of each link (N·m/m): an intact
    /// bond's `M_b = k_b (θ_j − θ_i − Δθ₀)`, the moment on its first disk (the line's
    /// first end; the opposite acts on the second), 0 for a touching contact.
    fn disk_outputs_with_moments(&self) -> (Vec<f64>, Vec<ContactLine>, Vec<f64>) {
        let d = self.solid.disks();
        let mut per = vec![0.0; d.len()];
        for b in self.solid.broken() {
            per[b.i] += 1.0;
            per[b.j] += 1.0;
        }
        let (mut cc, mut lines) = (Vec::new(), Vec::new());
        self.links(&mut cc, &mut lines);
        // `links` lists the intact bonds first, in order, then the touching contacts.
        let mut moments: Vec<f64> = self
            .solid
            .bonds()
            .iter()
            .zip(self.solid.bond_forces())
            .filter(|(b, _)| b.intact)
            .map(|(_, f)| f.mb)
            .collect();
        moments.resize(lines.len(), 0.0);
        (per, lines, moments)
    }

    fn links(&self, cell: &mut Vec<CellContact>, lines: &mut Vec<ContactLine>) {
        let d = self.solid.disks();
        for (b, f) in self.solid.bonds().iter().zip(self.solid.bond_forces()) {
            if b.intact {
                push_link(
                    d,
                    b.i as usize,
                    b.j as usize,
                    f.f,
                    -f.fn_,
                    f.fs,
                    true,
                    cell,
                    lines,
                );
            }
        }
        let (pairs, forces) = self.solid.contacts();
        for (p, f) in pairs.iter().zip(forces) {
            if f.fn_ > 0.0 {
                push_link(
                    d,
                    p.i as usize,
                    p.j as usize,
                    f.f,
                    f.fn_,
                    f.ft,
                    false,
                    cell,
                    lines,
                );
            }
        }
    }
}

fn push_link(
    d: &Disks,
    i: usize,
    j: usize,
    force_i: [f64; 2],
    normal_force: f64,
    tangential_force: f64,
    bonded: bool,
    cell: &mut Vec<CellContact>,
    lines: &mut Vec<ContactLine>,
) {
    let branch = [d.x[i][0] - d.x[j][0], d.x[i][1] - d.x[j][1]];
    let l = (branch[0] * branch[0] + branch[1] * branch[1])
        .sqrt()
        .max(1e-300);
    cell.push(CellContact {
        i,
        j: Some(j),
        normal: [branch[0] / l, branch[1] / l],
        branch,
        force: force_i,
    });
    lines.push(ContactLine {
        a: d.x[i],
        b: d.x[j],
        normal_force,
        tangential_force,
        bonded,
    });
}

impl Model for LsmModel<'_> {
    fn checkpoints(&self) -> bool {
        // With a lattice Boltzmann fluid ([lbm]) the coupled state is not saved.
        self.fluid.is_none()
    }

    fn save_state(&self, state: &mut State) -> Result<(), RunError> {
        let s = self.solid.save_state();
        for (name, v) in s.reals {
            state.put_f64(&format!("solid/{name}"), v);
        }
        for (name, v) in s.ints {
            state.put_u64(&format!("solid/{name}"), v);
        }
        state.put_f64("pressure", vec![self.pressure, self.step_seconds]);
        state.put_f64(
            "flood",
            self.flood.iter().flatten().copied().collect::<Vec<_>>(),
        );
        state.put_u64(
            "counts",
            vec![
                self.lsm_steps,
                self.current as u64,
                self.broken_written as u64,
            ],
        );
        state.put_f64(
            "history",
            self.history.iter().flatten().copied().collect::<Vec<_>>(),
        );
        if let Some(pvd) = self.contacts_pvd.borrow().as_ref() {
            checkpoint::save_pvd(state, "contacts_pvd", pvd);
        }
        if let Some(c) = &self.crack {
            c.save(state);
        }
        Ok(())
    }

    fn restore_state(&mut self, state: &State, out: &Path) -> Result<(), RunError> {
        // The solid's own arrays, by the names a freshly built solid saves.
        let template = self.solid.save_state();
        let mut s = porofrac_lsm::SolidState::default();
        for (name, _) in template.reals {
            s.reals
                .push((name, state.f64s(&format!("solid/{name}"))?.to_vec()));
        }
        for (name, _) in template.ints {
            s.ints
                .push((name, state.u64s(&format!("solid/{name}"))?.to_vec()));
        }
        self.solid
            .restore_state(&s)
            .map_err(|e| RunError::Checkpoint(e.to_string()))?;
        let p = state.f64s_len("pressure", 2)?;
        (self.pressure, self.step_seconds) = (p[0], p[1]);
        let flood = state.f64s_len("flood", 3 * self.flood.len())?;
        for (f, v) in self.flood.iter_mut().zip(flood.chunks_exact(3)) {
            *f = [v[0], v[1], v[2]];
        }
        let c = state.u64s_len("counts", 3)?;
        self.lsm_steps = c[0];
        self.current = c[1] as usize;
        // broken.csv is rewritten after the next step.
        self.broken_written = usize::MAX;
        let h = state.f64s("history")?;
        self.history = h.chunks_exact(3).map(|v| [v[0], v[1], v[2]]).collect();
        if let Some(pvd) = checkpoint::restore_pvd(
            state,
            "contacts_pvd",
            &particle_output::contacts_pvd_path(self.ls, out),
        )? {
            *self.contacts_pvd.borrow_mut() = Some(pvd);
        }
        if let Some(c) = &mut self.crack {
            c.restore(state, &self.solid)?;
        }
        Ok(())
    }

    fn summary_extras(&self) -> serde_json::Map<String, serde_json::Value> {
        let (t, sh) = self.broken_by_mode();
        let (bu, cu) = self.solid.updates();
        let rate = |n: u64| {
            if self.step_seconds > 0.0 {
                n as f64 / self.step_seconds
            } else {
                0.0
            }
        };
        let mut m = serde_json::Map::new();
        m.insert("particles".into(), self.solid.disks().len().into());
        m.insert("bonds".into(), self.solid.bonds().len().into());
        m.insert("broken_bonds".into(), self.solid.broken().len().into());
        m.insert("broken_tensile".into(), t.into());
        m.insert("broken_shear".into(), sh.into());
        m.insert("contacts".into(), self.solid.touching().into());
        m.insert("lsm_steps".into(), self.lsm_steps.into());
        m.insert("dt".into(), self.dt.into());
        if self.fluid.is_none() {
            m.insert("dt_used".into(), self.dt_used().into());
        }
        m.insert("stable_dt".into(), self.solid.stable_dt().into());
        m.insert("bond_updates".into(), bu.into());
        m.insert("bond_updates_per_second".into(), rate(bu).into());
        m.insert("contact_updates_per_second".into(), rate(cu).into());
        m.insert("step_seconds".into(), self.step_seconds.into());
        if let Some(f) = &self.fluid {
            f.summary(&mut m);
        }
        if self.wall.is_some() {
            m.insert("final_pressure".into(), self.pressure.into());
        }
        if let Some(c) = &self.crack {
            c.summary(&mut m);
        }
        if let Some(c) = self.calibration {
            let mut cal = serde_json::json!({
                "youngs_modulus": c.e,
                "poisson_ratio": c.nu,
                "tensile_strength": c.tensile,
            });
            let p = self.ls.scene.particles.as_ref().expect("checked");
            if let (Some(h), Some(dk)) = (p.hole, p.disk) {
                let (a2, b2) = (h.radius * h.radius, dk.radius * dk.radius);
                cal["breakdown_estimate"] = (c.tensile * (b2 - a2) / (b2 + a2)).into();
            }
            m.insert("calibration".into(), cal);
        }
        m
    }

    fn times(&self) -> &[f64] {
        &self.times
    }

    fn probe_may_be_undefined(&self, probe: usize) -> bool {
        // A fluid probe inside a solid disk has no fluid value.
        matches!(self.probes.get(probe), Some(ProbeKind::Fluid(..)))
    }

    fn step(&mut self, step: usize) -> Result<StepStats, RunError> {
        if step == 0 {
            return Ok(StepStats::default());
        }
        if let Some(f) = &mut self.fluid {
            let t0 = Instant::now();
            let n = f.advance(
                self.ls,
                &mut self.solid,
                self.times[step],
                self.crack.as_mut(),
                &self.stop,
            )?;
            self.step_seconds += t0.elapsed().as_secs_f64();
            self.lsm_steps += n as u64;
            self.pressure = f.pressure();
            self.current = step;
            let (t, sh) = self.broken_by_mode();
            self.history.push([self.times[step], t as f64, sh as f64]);
            return Ok(StepStats {
                iterations: n,
                failed: self.solid.broken().len(),
            });
        }
        let h = self.times[step] - self.times[step - 1];
        let n = sub_steps(h, self.dt);
        let dt = h / n as f64;
        let t0 = Instant::now();
        for _ in 0..n {
            if self.stop.requested() {
                return Err(RunError::Interrupted);
            }
            if let Some(s) = &self.servo {
                let v = s.velocity(&self.solid, self.platen_force(), dt);
                self.set_platen_speed(v);
            } else if self.platen_travel.is_finite() {
                self.move_platens(dt);
            }
            if let Some(w) = self.wall {
                self.pressure =
                    (self.pressure_rate * (self.solid.time() + dt)).min(self.pressure_max);
                self.solid
                    .set_wall_pressure(w, self.pressure)
                    .map_err(|e| check::lsm_error(self.ls, &e))?;
            }
            if !self.flood.is_empty()
                && let Some(c) = &mut self.crack
            {
                c.flood(&self.solid, self.pressure, &mut self.flood)
                    .map_err(|e| check::lsm_error(self.ls, &e))?;
            }
            let r = self
                .solid
                .step(dt, &self.flood)
                .map_err(|e| check::lsm_error(self.ls, &e))?;
            if r.broken > 0
                && let Some(c) = &mut self.crack
            {
                c.sync(&self.solid, self.pressure)
                    .map_err(|e| check::lsm_error(self.ls, &e))?;
            }
        }
        self.step_seconds += t0.elapsed().as_secs_f64();
        self.lsm_steps += n as u64;
        self.current = step;
        let (t, sh) = self.broken_by_mode();
        self.history.push([self.times[step], t as f64, sh as f64]);
        Ok(StepStats {
            iterations: n,
            failed: self.solid.broken().len(),
        })
    }

    fn probes(&self, values: &mut Vec<f64>) {
        let forces = self.forces2();
        let (mut cc, mut lines) = (Vec::new(), Vec::new());
        if !self.cells.is_empty() {
            self.links(&mut cc, &mut lines);
        }
        let x = &self.solid.disks().x;
        let states: Vec<_> = self.cells.iter().map(|c| c.measure(x, &cc)).collect();
        let (t, sh) = self.broken_by_mode();
        for p in &self.probes {
            values.push(match *p {
                ProbeKind::Particle(i, f) => {
                    particle_output::particle_value(self.solid.disks(), i, f, &forces)
                }
                ProbeKind::Global(f) => match check::GLOBAL_FIELDS[f] {
                    "pressure" => self.pressure,
                    "platen_force" => self.platen_force(),
                    "broken" => (t + sh) as f64,
                    "broken_tensile" => t as f64,
                    "crack_extent" => self.crack.as_ref().map_or(f64::NAN, |c| c.extent()),
                    _ => sh as f64,
                },
                ProbeKind::Wall(which, c) => self.wall_values(which)[c],
                ProbeKind::Fluid(x, f) => self
                    .fluid
                    .as_ref()
                    .map_or(f64::NAN, |fl| fl.point_values(x)[f]),
                ProbeKind::Cell(c, f) => {
                    let s = &states[c];
                    match check::CELL_FIELDS[f] {
                        "p" => s.p,
                        "q" => s.q,
                        "anisotropy" => s.anisotropy,
                        "anisotropy_volume" => s.anisotropy_volume,
                        "dilation_x" => s.dilation_x,
                        "dilation_y" => s.dilation_y,
                        "contacts" => s.contacts as f64,
                        "torque" => {
                            let cell = &self.cells[c];
                            reaction::exerted_on(&self.solid, &cell.member, cell.center)[2]
                        }
                        _ => {
                            let cell = &self.cells[c];
                            self.solid
                                .broken()
                                .iter()
                                .filter(|b| {
                                    (b.x - cell.center[0]).powi(2) + (b.y - cell.center[1]).powi(2)
                                        <= cell.radius * cell.radius
                                })
                                .count() as f64
                        }
                    }
                }
            });
        }
    }

    fn line(&self, line: usize, rows: &mut Vec<Vec<f64>>) {
        particle_output::line_rows(self.ls, line, self.solid.disks(), &self.forces2(), rows);
    }

    fn after_step(&mut self, out: &Path) -> Result<(), RunError> {
        if let Some(f) = &self.fluid {
            f.write_csv(out)?;
        }
        if let Some(c) = &mut self.crack {
            c.write_csv(out)?;
        }
        let broken = self.solid.broken();
        if broken.len() == self.broken_written && self.broken_written > 0 {
            return Ok(());
        }
        let mut text = String::from("time [s],i,j,x [m],y [m],mode\n");
        for b in broken {
            text.push_str(&format!(
                "{:e},{},{},{:e},{:e},{}\n",
                b.time,
                b.i,
                b.j,
                b.x,
                b.y,
                b.mode.as_str()
            ));
        }
        crate::common::output::write_atomic(&out.join("broken.csv"), text.as_bytes())?;
        self.broken_written = broken.len();
        Ok(())
    }

    fn snapshot(&self, _mesh: bool) -> Option<crate::common::snapshot::Snapshot> {
        let (per, lines) = self.disk_outputs();
        Some(crate::common::snapshot::Snapshot {
            particles: Some(crate::common::snapshot::Particles::of(
                self.solid.disks(),
                &[("broken_bonds", &per)],
                &lines,
            )),
            ..Default::default()
        })
    }

    fn write_vtk(&self, dir: &Path, index: usize) -> Result<String, RunError> {
        let d = self.solid.disks();
        let (per, lines, moments) = self.disk_outputs_with_moments();
        particle_output::write_vtk_with(
            self.ls,
            dir,
            index,
            self.times[self.current],
            d,
            &[("broken_bonds", &per)],
            &lines,
            &[("bending_moment", &moments)],
            &self.contacts_pvd,
        )
    }

    fn field_extrema(&self) -> BTreeMap<String, [f64; 2]> {
        let mut out = particle_output::disk_extrema(self.solid.disks());
        let live = self
            .solid
            .bonds()
            .iter()
            .zip(self.solid.bond_forces())
            .filter(|(b, _)| b.intact);
        particle_output::put_extrema(
            &mut out,
            "bond_normal_force",
            live.clone().map(|(_, f)| f.fn_),
        );
        particle_output::put_extrema(&mut out, "bond_shear_force", live.map(|(_, f)| f.fs));
        out
    }

    fn plots(&self, dir: &Path, written: &[f64], series: &[Vec<f64>]) -> Result<(), RunError> {
        let probes: Vec<(String, String, Vec<f64>)> = self
            .ls
            .scene
            .output
            .probe
            .iter()
            .zip(series)
            .map(|(p, v)| (p.name.clone(), p.field.clone(), v.clone()))
            .collect();
        crate::common::particle_plots::probe_plots(
            dir,
            &self.ls.scene.scene.name,
            written,
            &probes,
            check::unit,
        )?;
        if let Some(f) = &self.fluid {
            f.plots(
                dir,
                &self.solid,
                &self.ls.scene.scene.name,
                written.last().copied().unwrap_or(0.0),
            )?;
        }
        let d = self.solid.disks();
        let u: Vec<f64> = (0..d.len())
            .map(|i| {
                let u = d.displacement(i);
                (u[0] * u[0] + u[1] * u[1]).sqrt()
            })
            .collect();
        let segments: Vec<([f64; 2], [f64; 2])> = self
            .solid
            .broken()
            .iter()
            .map(|b| (d.x[b.i], d.x[b.j]))
            .collect();
        let t = written.last().copied().unwrap_or(0.0);
        let title = format!(
            "{}: displacement at t = {} s, broken bonds in black",
            self.ls.scene.scene.name,
            crate::common::plots::tick(t)
        );
        particle_output::draw_disks(
            &dir.join("particles.png"),
            d,
            &particle_output::DiskPicture {
                title: &title,
                values: &u,
                bar: "|u| [m]",
                unit: "m",
                segments: &segments,
            },
        )?;
        let times: Vec<f64> = self.history.iter().map(|h| h[0]).collect();
        let columns = vec![
            Column::new("tensile", "1", self.history.iter().map(|h| h[1]).collect()),
            Column::new("shear", "1", self.history.iter().map(|h| h[2]).collect()),
            Column::new(
                "total",
                "1",
                self.history.iter().map(|h| h[1] + h[2]).collect(),
            ),
        ];
        crate::common::plots::time_series(
            &dir.join("breakage.png"),
            &times,
            &columns,
            &format!("{}: broken bonds", self.ls.scene.scene.name),
        )?;
        Ok(())
    }

    fn work(&self) -> crate::common::limits::Work {
        use crate::common::limits::{
            LSM_FLUID_SECONDS_PER_NODE_STEP, LSM_SECONDS_PER_PARTICLE_STEP,
        };
        let end = self.times.last().copied().unwrap_or(0.0);
        let particles = self.solid.disks().len() as f64;
        let (units, seconds_per_unit, unit) = match &self.fluid {
            // The lattice dominates: the particles' sub-steps are a few per cent.
            Some(f) => (
                f.lattice_nodes() as f64 * f.lattice_steps(end),
                LSM_FLUID_SECONDS_PER_NODE_STEP,
                "node steps",
            ),
            None => (
                particles * (end / self.dt).ceil(),
                LSM_SECONDS_PER_PARTICLE_STEP,
                "particle steps",
            ),
        };
        crate::common::limits::Work {
            units,
            seconds_per_unit,
            unit,
            factor: 3.0,
        }
    }

    fn peak_bytes(&self) -> f64 {
        let nodes = self.fluid.as_ref().map_or(0, |f| f.lattice_nodes());
        crate::common::limits::lsm_bytes(
            self.solid.disks().len() as f64,
            self.solid.bonds().len() as f64,
        ) + crate::common::limits::lbm_bytes(nodes as f64, false)
    }

    fn sizes(&self) -> Sizes {
        Sizes {
            counts: {
                let mut c = vec![
                    ("particles", self.solid.disks().len()),
                    ("bonds", self.solid.bonds().len()),
                ];
                if let Some(f) = &self.fluid {
                    c.push(("lattice nodes", f.lattice_nodes()));
                }
                c
            },
            failed: Some("broken bonds"),
            ..Sizes::default()
        }
    }

    fn unit(&self, field: &str) -> &'static str {
        check::unit(field)
    }

    fn failed(&self) -> usize {
        self.solid.broken().len()
    }

    fn solver_stats(&self) -> SolverStats {
        SolverStats {
            linear: "explicit".into(),
            iterations: self.lsm_steps as usize,
            ..SolverStats::default()
        }
    }

    fn errors(&self) -> Result<BTreeMap<String, f64>, RunError> {
        Ok(BTreeMap::new())
    }

    fn wall_seconds(&self) -> WallSeconds {
        WallSeconds {
            stepping: self.step_seconds,
            ..WallSeconds::default()
        }
    }
}

/// The model `lsm` in the registry ([`crate::MODELS`]).
pub struct LsmKind;

/// The registry's value of the model.
pub static KIND: LsmKind = LsmKind;

impl ModelKind for LsmKind {
    fn name(&self) -> &'static str {
        "lsm"
    }
    fn sections(&self) -> &'static [&'static str] {
        &["bonds", "contacts", "lsm", "loading", "injection"]
    }
    fn reads(&self) -> &'static [&'static str] {
        &["particles", "lbm", "thermal"]
    }
    fn sections_of(
        &self,
        doc: toml::Spanned<toml::de::DeTable<'_>>,
    ) -> Result<std::sync::Arc<dyn OwnSections>, toml::de::Error> {
        own_sections::<file::LsmSections>(doc)
    }
    fn own_schema(&self) -> Option<schemars::Schema> {
        Some(schemars::schema_for!(file::LsmSections))
    }
    fn check(&self, ls: &LoadedScene, laws: &LawRegistry) -> Result<(), SceneError> {
        let _ = laws;
        check::check(ls)
    }
    fn build(
        &self,
        ls: &LoadedScene,
        laws: &LawRegistry,
        purpose: &Purpose<'_>,
        observer: &mut dyn Observer,
    ) -> Result<Built, RunError> {
        let _ = laws;
        build_for(ls, purpose, observer)
    }
}

/// The model's own sections of a checked scene.
pub(crate) fn own(ls: &LoadedScene) -> &file::LsmSections {
    ls.own::<file::LsmSections>()
}
