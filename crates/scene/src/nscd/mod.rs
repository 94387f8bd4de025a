//! The NSCD model (M. Renouf, F. Dubois, P. Alart (2006), Eur. J. Comput. Mech. 15(5);
//! `[scene] model = "nscd"`): rigid disks and walls under non-smooth contact dynamics
//! ([`porofrac_nscd`]).
//!
//! - *build*: the disks of `[particles]` (a seeded random packing, a hexagonal lattice
//!   or a list) with the initial velocities of `[[particles.velocity]]` (after the
//!   settling), the walls of `[[wall]]`, the law of `[contact]` and the solver options
//!   of `[nscd]` ([`build`]);
//! - *step*: one θ-scheme step of [`porofrac_nscd::Nscd`] per schedule step;
//! - *fields*: particle probes (`x y vx vy omega fx fy radius`, `fx fy` the sum of the
//!   contact forces on the particle), wall probes (`wall = NAME` with `fx fy torque`,
//!   [`porofrac_nscd::Nscd::body_reaction`]), tracked-cell probes (`p q anisotropy
//!   anisotropy_volume dilation_x dilation_y contacts broken_bonds`, Renouf et al. (2006)
//!   eqs. 7–11, [`porofrac_particles::tracked`]), lines (the value of the particle
//!   nearest each point), `vtk/particles_NNNN.vtp` + `vtk/contacts_NNNN.vtp` with
//!   `<name>.pvd` and `<name>_contacts.pvd`, field extrema, and `summary.json` with
//!   `particles`, `contacts` (last, mean, max), `sweeps` (mean, max), `final_residual`, `not_converged_steps`
//!   and `contact_updates_per_second` (local solves per second of NLGS wall time);
//! - *plots* ([`crate::common::particle_plots`]): probe series and the disks coloured by
//!   initial layer.

pub mod check;
pub mod fault;
pub mod file;
pub mod summary;

use crate::common::laws::LawRegistry;
use crate::common::loaded::SceneError;
use crate::common::model::ModelKind;
use crate::common::model::{OwnSections, own_sections};

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use porofrac_grid::io::PvdWriter;

use crate::common::particle_output;
use porofrac_nscd::{Axis, ContactLaw, Nscd, NscdError, Ordering, RigidBody, SolverParams};
use porofrac_particles::{ParticleError, TrackedCell};

use crate::common::checkpoint::{self, State};
use crate::common::driver::{Observer, SetupPoll};
use crate::common::loaded::{LoadedScene, k, ki, step_count};
use crate::common::model::{Built, Model, Purpose, RunError, Sizes, StepStats};
use crate::common::output::{SolverStats, WallSeconds};
use porofrac_nscd::detect::Antagonist;

use file::{OrderingChoice, WallComponent};

/// Build a checked NSCD scene's model and hand it to `purpose`.
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

/// What a probe reads.
#[derive(Clone, Copy, Debug)]
enum ProbeKind {
    Particle(usize, usize),
    Cell(usize, usize),
    /// A wall's reaction: body index, component (fx, fy, torque).
    Wall(usize, usize),
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct RunStats {
    steps: usize,
    sweeps: usize,
    max_sweeps: usize,
    final_residual: f64,
    max_residual: f64,
    not_converged: usize,
    updates: u64,
    solve_seconds: f64,
    max_contacts: usize,
    /// Σ over the steps of their contact counts.
    contact_steps: u64,
}

/// An NSCD scene being run.
pub struct NscdModel<'a> {
    ls: &'a LoadedScene,
    sys: Nscd,
    times: Vec<f64>,
    probes: Vec<ProbeKind>,
    cells: Vec<TrackedCell>,
    stats: RunStats,
    step_seconds: f64,
    contacts_pvd: RefCell<Option<PvdWriter>>,
    /// Index of the output time of the current state (the time of its VTK files).
    current: usize,
    settling: Option<(porofrac_nscd::SettleStats, f64)>,
    fault: Option<fault::FaultProbe>,
}

fn scene_error(ls: &LoadedScene, e: &NscdError) -> RunError {
    let key = match e {
        NscdError::Interrupted | NscdError::Particles(ParticleError::Interrupted) => {
            return RunError::Interrupted;
        }
        NscdError::TooManyCandidates { .. } => k(&["nscd", "alert"]),
        NscdError::BadParameter { name, .. } => match *name {
            "mu_static" | "mu_dynamic" => k(&["contact", "mu"]),
            "cohesion" => k(&["contact", "cohesion"]),
            "cohesion_distance" => k(&["contact", "d_w"]),
            "restitution" => k(&["contact", "restitution"]),
            "dt" => k(&["schedule", "dt"]),
            other => k(&["nscd", other]),
        },
        NscdError::BadBody { index, .. } => ki("wall", *index, &[]),
        NscdError::Particles(_) | NscdError::InitialOverlap { .. } => k(&["particles"]),
        NscdError::NotSettled { .. } => k(&["nscd", "settle_max_steps"]),
        NscdError::StepTooLarge { .. } => k(&[
            "schedule",
            if ls.scene.schedule.as_ref().is_some_and(|s| s.dt.is_some()) {
                "dt"
            } else {
                "steps"
            },
        ]),
    };
    RunError::Scene(ls.error(&key, format!(": {e}")))
}

fn walls(ls: &LoadedScene) -> Vec<RigidBody> {
    own(ls)
        .wall
        .iter()
        .map(|w| {
            let vertices = match (&w.from, &w.to, &w.polygon) {
                (Some(a), Some(b), _) => vec![*a, *b],
                (_, _, Some(p)) => p.clone(),
                _ => unreachable!("checked: from and to, or polygon"),
            };
            let force = w.force.unwrap_or([0.0; 2]);
            let v = w
                .velocity
                .clone()
                .unwrap_or([WallComponent::Velocity(0.0), WallComponent::Velocity(0.0)]);
            let axis = |a: usize| match &v[a] {
                WallComponent::Velocity(x) => Axis::Prescribed(*x),
                WallComponent::Word(_) => Axis::Loaded(force[a]),
            };
            let body = RigidBody::polygon(vertices)
                .with_axes([axis(0), axis(1)], w.mass.unwrap_or(f64::INFINITY));
            match w.mu {
                Some(mu) => body.with_friction(mu),
                None => body,
            }
        })
        .collect()
}

/// Build the model of a checked NSCD scene, reporting the packing and the settling to
/// `setup`.
pub fn build<'a>(
    ls: &'a LoadedScene,
    setup: &mut SetupPoll<'_>,
) -> Result<NscdModel<'a>, RunError> {
    let s = &ls.scene;
    let disks = crate::common::particles::generate(ls, setup)?;
    let c = own(ls).contact.clone().unwrap_or_default();
    let mu = c.mu.unwrap_or(0.0);
    let law = ContactLaw {
        mu_static: c.mu_static.unwrap_or(mu),
        mu_dynamic: mu,
        cohesion: c.cohesion.unwrap_or(0.0),
        cohesion_distance: c.d_w.unwrap_or(0.0),
        restitution: c.restitution.unwrap_or(0.0),
    };
    let n = own(ls).nscd.clone().unwrap_or_default();
    let defaults = SolverParams::default();
    let params = SolverParams {
        theta: n.theta.unwrap_or(defaults.theta),
        tolerance: n.tolerance.unwrap_or(defaults.tolerance),
        min_sweeps: n.min_sweeps.map_or(defaults.min_sweeps, |m| m as usize),
        max_sweeps: n.max_sweeps.map_or(defaults.max_sweeps, |m| m as usize),
        alert: n.alert,
        ordering: match n.ordering.unwrap_or_default() {
            OrderingChoice::Sorted => Ordering::Sorted,
            OrderingChoice::Coloured => Ordering::Coloured,
            OrderingChoice::Slabs => Ordering::Slabs,
            OrderingChoice::Random => Ordering::Random {
                seed: n.ordering_seed.unwrap_or(1),
            },
        },
    };
    let gravity = n.gravity.unwrap_or([0.0, -9.81]);
    setup.check()?;
    let mut sys =
        Nscd::new(disks, walls(ls), law, params, gravity).map_err(|e| scene_error(ls, &e))?;
    // Ctrl-C stops the NLGS sweeps of the settling and of every step.
    sys.set_interrupt(setup.stop_handle().flag());
    let sch = s.schedule.as_ref().expect("checked: [schedule] present");
    let steps = step_count(sch) as usize;
    let dt = sch.dt.unwrap_or(sch.end_time / steps as f64);
    let settling = match n.settle_ratio {
        Some(ratio) => {
            let t0 = Instant::now();
            setup.phase("settling");
            let st = sys
                .settle_polled(
                    porofrac_nscd::SettleParams {
                        dt: n.settle_dt.unwrap_or(dt),
                        ratio,
                        max_steps: n.settle_max_steps.map_or(20_000, |m| m as usize),
                    },
                    &mut setup.callback(),
                )
                .map_err(|e| scene_error(ls, &e))?;
            Some((st, t0.elapsed().as_secs_f64()))
        }
        None => None,
    };
    // Initial velocities and spins, after the settling (which ends at rest).
    crate::common::particles::initial_velocities(ls, &mut sys.disks)?;
    let fault = n
        .fault
        .as_ref()
        .map(|f| fault::FaultProbe::new(f, &sys, sch.end_time));
    let times: Vec<f64> = (0..=steps)
        .map(|i| {
            if i == steps {
                sch.end_time
            } else {
                (i as f64 * dt).min(sch.end_time)
            }
        })
        .collect();
    let count = sys.disks.len();
    let mut probes = Vec::new();
    let mut cells = Vec::new();
    for (i, p) in s.output.probe.iter().enumerate() {
        if let Some(name) = &p.wall {
            let walls = &own(ls).wall;
            let Some(b) = walls.iter().position(|w| w.name.as_ref() == Some(name)) else {
                let names: Vec<&str> = walls.iter().filter_map(|w| w.name.as_deref()).collect();
                return Err(ls
                    .error(
                        &ki("output.probe", i, &["wall"]),
                        format!(
                            "= \"{name}\" names no [[wall]] (named walls: {})",
                            if names.is_empty() {
                                "none".to_string()
                            } else {
                                names.join(", ")
                            }
                        ),
                    )
                    .into());
            };
            let component = crate::common::particles::WALL_FIELDS
                .iter()
                .position(|f| *f == p.field)
                .expect("checked");
            probes.push(ProbeKind::Wall(b, component));
        } else if let Some(f) = check::PARTICLE_FIELDS.iter().position(|f| *f == p.field) {
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
        } else {
            let f = check::CELL_FIELDS
                .iter()
                .position(|f| *f == p.field)
                .expect("checked");
            let c = p.cell.as_ref().expect("checked");
            let cell = TrackedCell::new(&sys.disks.x, [c.center[0], c.center[1]], c.radius);
            if cell.count == 0 {
                return Err(ls
                    .error(&ki("output.probe", i, &["cell"]), "selects no particle")
                    .into());
            }
            probes.push(ProbeKind::Cell(cells.len(), f));
            cells.push(cell);
        }
    }
    Ok(NscdModel {
        ls,
        sys,
        times,
        probes,
        cells,
        stats: RunStats::default(),
        step_seconds: 0.0,
        contacts_pvd: RefCell::new(None),
        current: 0,
        settling,
        fault,
    })
}

impl NscdModel<'_> {
    /// Sum of the contact forces on each particle (N per metre).
    fn particle_forces(&self) -> Vec<[f64; 2]> {
        let mut f = vec![[0.0; 2]; self.sys.disks.len()];
        for c in self.sys.contacts() {
            let [rn, rt] = self.sys.contact_force(c);
            let v = [rn * c.n[0] + rt * c.t[0], rn * c.n[1] + rt * c.t[1]];
            let i = c.i as usize;
            f[i][0] += v[0];
            f[i][1] += v[1];
            if let porofrac_nscd::detect::Antagonist::Disk(j) = c.other {
                f[j as usize][0] -= v[0];
                f[j as usize][1] -= v[1];
            }
        }
        f
    }

    fn particle_value(&self, i: usize, field: usize, forces: &[[f64; 2]]) -> f64 {
        particle_output::particle_value(&self.sys.disks, i, field, forces)
    }

    /// Keys added to `summary.json`.
    fn particle_statistics(&self) -> summary::NscdSummary {
        let st = &self.stats;
        let per_step = |total: f64| {
            if st.steps > 0 {
                total / st.steps as f64
            } else {
                0.0
            }
        };
        let rate = if st.solve_seconds > 0.0 {
            st.updates as f64 / st.solve_seconds
        } else {
            0.0
        };
        summary::NscdSummary {
            particles: self.sys.disks.len(),
            contacts: summary::NscdContactCounts {
                last: self.sys.contacts().len(),
                mean: per_step(st.contact_steps as f64),
                max: st.max_contacts,
            },
            sweeps: summary::NscdSweepCounts {
                mean: per_step(st.sweeps as f64),
                max: st.max_sweeps,
                total: st.sweeps,
            },
            final_residual: st.final_residual,
            not_converged_steps: st.not_converged,
            contact_updates: st.updates,
            contact_updates_per_second: rate,
            nlgs_seconds: st.solve_seconds,
            settling: self
                .settling
                .as_ref()
                .map(|(s, secs)| summary::NscdSettling {
                    steps: s.steps,
                    kinetic_energy: s.kinetic,
                    potential_energy_released: s.released,
                    sweeps: s.sweeps,
                    seconds: *secs,
                }),
            fault: self.fault.as_ref().map(|f| f.measure(&self.sys)),
        }
    }
}

impl Model for NscdModel<'_> {
    fn checkpoints(&self) -> bool {
        true
    }

    fn save_state(&self, state: &mut State) -> Result<(), RunError> {
        checkpoint::save_disks(state, "disks", &self.sys.disks);
        let b = &self.sys.bodies;
        state.put_pairs(
            "bodies/offset",
            &b.iter().map(|b| b.offset).collect::<Vec<_>>(),
        );
        state.put_pairs(
            "bodies/velocity",
            &b.iter().map(|b| b.velocity).collect::<Vec<_>>(),
        );
        state.put_pairs("force", &self.sys.force);
        state.put_f64("time", vec![self.sys.time]);
        let m = self.sys.step_memory();
        state.put_u64("steps", vec![m.steps, self.current as u64]);
        state.put_f64("h_last", vec![m.h_last]);
        let code = |a: &Antagonist| match *a {
            Antagonist::Disk(j) => u64::from(j),
            Antagonist::Body(j) => (1 << 32) | u64::from(j),
        };
        state.put_u64(
            "memory/keys",
            m.contacts
                .iter()
                .flat_map(|(k, _, _)| [u64::from(k.0), code(&k.1)])
                .collect::<Vec<_>>(),
        );
        state.put_pairs(
            "memory/impulse",
            &m.contacts.iter().map(|c| c.1).collect::<Vec<_>>(),
        );
        state.put_u8(
            "memory/stick",
            m.contacts.iter().map(|c| u8::from(c.2)).collect::<Vec<_>>(),
        );
        let r = &self.stats;
        state.put_u64(
            "stats/counts",
            vec![
                r.steps as u64,
                r.sweeps as u64,
                r.max_sweeps as u64,
                r.not_converged as u64,
                r.updates,
                r.max_contacts as u64,
                r.contact_steps,
            ],
        );
        state.put_f64(
            "stats/values",
            vec![
                r.final_residual,
                r.max_residual,
                r.solve_seconds,
                self.step_seconds,
            ],
        );
        if let Some(pvd) = self.contacts_pvd.borrow().as_ref() {
            checkpoint::save_pvd(state, "contacts_pvd", pvd);
        }
        if let Some(f) = &self.fault {
            f.save(state);
        }
        Ok(())
    }

    fn restore_state(&mut self, state: &State, out: &Path) -> Result<(), RunError> {
        checkpoint::restore_disks(state, "disks", &mut self.sys.disks)?;
        let nb = self.sys.bodies.len();
        let offset = state.pairs("bodies/offset", nb)?;
        let velocity = state.pairs("bodies/velocity", nb)?;
        for (b, (o, v)) in self
            .sys
            .bodies
            .iter_mut()
            .zip(offset.into_iter().zip(velocity))
        {
            b.offset = o;
            b.velocity = v;
        }
        self.sys.force = state.pairs("force", self.sys.disks.len())?;
        self.sys.time = state.f64("time")?;
        let steps = state.u64s_len("steps", 2)?;
        let keys = state.u64s("memory/keys")?;
        let n = keys.len() / 2;
        let impulse = state.pairs("memory/impulse", n)?;
        let stick = state.u8s("memory/stick")?;
        if stick.len() != n || keys.len() != 2 * n {
            return Err(RunError::Checkpoint(
                "the contact memory's arrays differ in length".into(),
            ));
        }
        let contacts = (0..n)
            .map(|c| {
                let (i, a) = (keys[2 * c] as u32, keys[2 * c + 1]);
                let other = if a >> 32 == 1 {
                    Antagonist::Body(a as u32)
                } else {
                    Antagonist::Disk(a as u32)
                };
                ((i, other), impulse[c], stick[c] != 0)
            })
            .collect();
        self.sys.restore_step_memory(&porofrac_nscd::StepMemory {
            steps: steps[0],
            h_last: state.f64("h_last")?,
            contacts,
        });
        self.current = steps[1] as usize;
        let c = state.u64s_len("stats/counts", 7)?;
        let v = state.f64s_len("stats/values", 4)?;
        self.stats = RunStats {
            steps: c[0] as usize,
            sweeps: c[1] as usize,
            max_sweeps: c[2] as usize,
            final_residual: v[0],
            max_residual: v[1],
            not_converged: c[3] as usize,
            updates: c[4],
            solve_seconds: v[2],
            max_contacts: c[5] as usize,
            contact_steps: c[6],
        };
        self.step_seconds = v[3];
        if let Some(pvd) = checkpoint::restore_pvd(
            state,
            "contacts_pvd",
            &particle_output::contacts_pvd_path(self.ls, out),
        )? {
            *self.contacts_pvd.borrow_mut() = Some(pvd);
        }
        if let Some(f) = &mut self.fault {
            f.restore(state)?;
        }
        Ok(())
    }

    fn summary_extras(&self) -> serde_json::Map<String, serde_json::Value> {
        self.particle_statistics().into_map()
    }

    fn times(&self) -> &[f64] {
        &self.times
    }

    fn step(&mut self, step: usize) -> Result<StepStats, RunError> {
        if step == 0 {
            return Ok(StepStats::default());
        }
        let h = self.times[step] - self.times[step - 1];
        let t0 = Instant::now();
        let st = self.sys.step(h).map_err(|e| scene_error(self.ls, &e))?;
        self.current = step;
        self.step_seconds += t0.elapsed().as_secs_f64();
        let r = &mut self.stats;
        r.steps += 1;
        r.sweeps += st.sweeps;
        r.max_sweeps = r.max_sweeps.max(st.sweeps);
        r.final_residual = st.residual;
        r.max_residual = r.max_residual.max(st.residual);
        r.not_converged += usize::from(!st.converged);
        r.updates += st.updates;
        r.solve_seconds += st.solve_seconds;
        r.max_contacts = r.max_contacts.max(st.contacts);
        r.contact_steps += st.contacts as u64;
        if let Some(f) = &mut self.fault {
            f.after_step(&self.sys);
        }
        Ok(StepStats {
            iterations: st.sweeps,
            failed: 0,
        })
    }

    fn probes(&self, values: &mut Vec<f64>) {
        let forces = self.particle_forces();
        let mut contacts = Vec::new();
        self.sys.cell_contacts(&mut contacts);
        let states: Vec<_> = self
            .cells
            .iter()
            .map(|c| c.measure(&self.sys.disks.x, &contacts))
            .collect();
        for p in &self.probes {
            values.push(match *p {
                ProbeKind::Particle(i, f) => self.particle_value(i, f, &forces),
                ProbeKind::Wall(b, c) => self.sys.body_reaction(b)[c],
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
                        // Rigid disks have no bonds.
                        _ => 0.0,
                    }
                }
            });
        }
    }

    fn line(&self, line: usize, rows: &mut Vec<Vec<f64>>) {
        let forces = self.particle_forces();
        particle_output::line_rows(self.ls, line, &self.sys.disks, &forces, rows);
    }

    fn after_step(&mut self, _out: &Path) -> Result<(), RunError> {
        Ok(())
    }

    fn write_vtk(&self, dir: &Path, index: usize) -> Result<String, RunError> {
        let mut lines = Vec::new();
        self.sys.contact_lines(&mut lines);
        particle_output::write_vtk(
            self.ls,
            dir,
            index,
            self.times[self.current],
            &self.sys.disks,
            &[],
            &lines,
            &self.contacts_pvd,
        )
    }

    fn snapshot(&self, _mesh: bool) -> Option<crate::common::snapshot::Snapshot> {
        let mut lines = Vec::new();
        self.sys.contact_lines(&mut lines);
        Some(crate::common::snapshot::Snapshot {
            particles: Some(crate::common::snapshot::Particles::of(
                &self.sys.disks,
                &[],
                &lines,
            )),
            ..Default::default()
        })
    }

    fn field_extrema(&self) -> BTreeMap<String, [f64; 2]> {
        let mut out = particle_output::disk_extrema(&self.sys.disks);
        let forces: Vec<[f64; 2]> = self
            .sys
            .contacts()
            .iter()
            .map(|c| self.sys.contact_force(c))
            .collect();
        particle_output::put_extrema(&mut out, "normal_force", forces.iter().map(|f| f[0]));
        particle_output::put_extrema(&mut out, "tangential_force", forces.iter().map(|f| f[1]));
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
            probe_unit,
        )?;
        crate::common::particle_plots::layers(
            &dir.join("layers.png"),
            &self.ls.scene.scene.name,
            written.last().copied().unwrap_or(0.0),
            &self.sys.disks,
        )?;
        Ok(())
    }

    fn work(&self) -> crate::common::limits::Work {
        crate::common::limits::Work {
            units: self.sys.disks.len() as f64 * self.times.len().saturating_sub(1) as f64,
            seconds_per_unit: crate::common::limits::NSCD_SECONDS_PER_DISK_STEP,
            unit: "disk steps",
            factor: 5.0,
        }
    }

    fn peak_bytes(&self) -> f64 {
        crate::common::limits::nscd_bytes(self.sys.disks.len() as f64)
    }

    fn sizes(&self) -> Sizes {
        Sizes {
            counts: vec![
                ("disks", self.sys.disks.len()),
                ("contacts", self.sys.contacts().len()),
            ],
            ..Sizes::default()
        }
    }

    fn unit(&self, field: &str) -> &'static str {
        probe_unit(field)
    }

    fn failed(&self) -> usize {
        0
    }

    fn solver_stats(&self) -> SolverStats {
        SolverStats {
            linear: "nlgs".into(),
            iterations: self.stats.sweeps,
            max_relative_residual: self.stats.max_residual,
            ..SolverStats::default()
        }
    }

    fn errors(&self) -> Result<BTreeMap<String, f64>, RunError> {
        Ok(BTreeMap::new())
    }

    fn wall_seconds(&self) -> WallSeconds {
        WallSeconds {
            stepping: self.step_seconds - self.stats.solve_seconds,
            solve: self.stats.solve_seconds,
            ..WallSeconds::default()
        }
    }
}

/// Unit of a probe field (a wall's `torque`: N·m per metre of thickness).
fn probe_unit(field: &str) -> &'static str {
    match field {
        "torque" => "N·m/m",
        f => particle_output::particle_unit(f).unwrap_or("1"),
    }
}

/// The model `nscd` in the registry ([`crate::MODELS`]).
pub struct NscdKind;

/// The registry's value of the model.
pub static KIND: NscdKind = NscdKind;

impl ModelKind for NscdKind {
    fn name(&self) -> &'static str {
        "nscd"
    }
    fn sections(&self) -> &'static [&'static str] {
        &["particles", "wall", "contact", "nscd"]
    }
    fn sections_of(
        &self,
        doc: toml::Spanned<toml::de::DeTable<'_>>,
    ) -> Result<std::sync::Arc<dyn OwnSections>, toml::de::Error> {
        own_sections::<file::NscdSections>(doc)
    }
    fn own_schema(&self) -> Option<schemars::Schema> {
        Some(schemars::schema_for!(file::NscdSections))
    }
    fn summary_schema(
        &self,
        generator: &mut schemars::SchemaGenerator,
    ) -> Option<schemars::Schema> {
        Some(generator.subschema_for::<summary::NscdSummary>())
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
pub(crate) fn own(ls: &LoadedScene) -> &file::NscdSections {
    ls.own::<file::NscdSections>()
}
