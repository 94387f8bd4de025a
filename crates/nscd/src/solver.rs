//! The NSCD system and its time step, composed of the stages of the other modules.
//!
//! **Time step** (Renouf et al. (2006) eq. 3, Moreau–Jean) on ]t_i, t_i + h], ½ ≤ θ ≤ 1:
//!
//! 1. predicted configuration q_m = q_i + h(1 − θ) q̇_i (bodies: their offset likewise),
//!    [`crate::integrator::MoreauJean::predict`];
//! 2. detection at q_m, broad then narrow phase ([`crate::detect`]), into the step's
//!    [`crate::contacts::ContactSet`];
//! 3. free velocity q̇_free = q̇_i + h M⁻¹ F (gravity, applied forces; constant over the
//!    step, so θF_{i+1} + (1 − θ)F_i = F),
//!    [`crate::integrator::MoreauJean::free_velocities`];
//! 4. the contact problem: W blocks, law and warm start of each contact
//!    ([`crate::problem`]; with restitution, Newton's impact law,
//!    [`crate::problem::newton`]);
//! 5. NLGS (eq. 5, Table 1) on the impulses P_α = h r_α ([`crate::nlgs`]);
//! 6. q̇_{i+1} = q̇_free + M⁻¹ H P and q_{i+1} = q_i + h(θ q̇_{i+1} + (1 − θ) q̇_i)
//!    ([`crate::integrator::MoreauJean::update`]), and the impulses kept for the next
//!    step's warm start ([`crate::contacts::ContactSet::remember`]).
//!
//! **Warm start**: a contact found again (same candidate and antagonist) starts from
//! the impulse it ended the previous step with; a new one from zero.
//!
//! Defaults: the paper's minimum of 100 sweeps, tolerance 1.666e-4 (LMGC90's), at most
//! 10 000 sweeps, θ = ½.

use porofrac_particles::Disks;
use porofrac_particles::tracked::CellContact;
use porofrac_particles::vtk::ContactLine;

use crate::NscdError;
use crate::body::RigidBody;
use crate::contacts::ContactSet;
use crate::detect::{Antagonist, Contact, Detector};
use crate::integrator::MoreauJean;
use crate::law::ContactLaw;
pub use crate::nlgs::Ordering;
use crate::nlgs::{InverseMasses, Nlgs, NlgsOptions, Velocities};

/// Options of the time stepping and of NLGS.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverParams {
    /// θ of the θ-scheme, in [½, 1] (default ½). With θ < 1 a contact that closes at
    /// speed v_n keeps an overlap of at most h(1 − θ)v_n (h the step; h v_n/2 at θ = ½,
    /// none at θ = 1): it is detected at q + h(1 − θ)q̇ and the step moves by
    /// h(θ q̇⁺ + (1 − θ) q̇⁻). The law pushes nothing apart, so the overlap stays.
    pub theta: f64,
    /// Tolerance of the W-weighted relative impulse change (default 1.666e-4).
    pub tolerance: f64,
    /// Fewest sweeps of a step with contacts, always done (default 100, the paper's): a
    /// floor for every [`Ordering`]; a step without contacts does none.
    pub min_sweeps: usize,
    /// Most sweeps per step (default 10 000).
    pub max_sweeps: usize,
    /// Alert distance (m); `None`: half the smallest radius.
    pub alert: Option<f64>,
    /// Order of the contacts within a sweep.
    pub ordering: Ordering,
}

impl Default for SolverParams {
    fn default() -> Self {
        Self {
            theta: 0.5,
            tolerance: 1.666e-4,
            min_sweeps: 100,
            max_sweeps: 10_000,
            alert: None,
            ordering: Ordering::Sorted,
        }
    }
}

impl SolverParams {
    /// The options of the local solver.
    pub fn nlgs(&self) -> NlgsOptions {
        NlgsOptions {
            tolerance: self.tolerance,
            min_sweeps: self.min_sweeps,
            max_sweeps: self.max_sweeps,
            ordering: self.ordering,
        }
    }

    /// Check the options.
    pub fn check(&self) -> Result<(), NscdError> {
        let bad = |name, value, message| {
            Err(NscdError::BadParameter {
                name,
                value,
                message,
            })
        };
        if !(0.5..=1.0).contains(&self.theta) {
            return bad("theta", self.theta, "must be in [0.5, 1]");
        }
        self.nlgs().check()?;
        if let Some(a) = self.alert
            && !(a.is_finite() && a >= 0.0)
        {
            return bad("alert", a, "must be a finite number ≥ 0");
        }
        Ok(())
    }
}

/// What one step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    /// Contacts (pairs within the alert distance).
    pub contacts: usize,
    /// NLGS sweeps done.
    pub sweeps: usize,
    /// Convergence measure e_k of the last sweep.
    pub residual: f64,
    /// The sweeps stopped on the tolerance or a fixed point (not on `max_sweeps`).
    pub converged: bool,
    /// Local solves done (sweeps × contacts).
    pub updates: u64,
    /// Wall time of the sweeps (s).
    pub solve_seconds: f64,
}

/// An NSCD system: disks, rigid bodies, the law and the solver state.
#[derive(Clone, Debug)]
pub struct Nscd {
    /// The disks (positions, velocities, masses...).
    pub disks: Disks,
    /// The rigid bodies.
    pub bodies: Vec<RigidBody>,
    /// The contact law (disk–disk and disk–body).
    pub law: ContactLaw,
    /// Solver options.
    pub params: SolverParams,
    /// Gravity (m/s²).
    pub gravity: [f64; 2],
    /// Applied force on each disk (N per metre), constant over a step.
    pub force: Vec<[f64; 2]>,
    /// Current time (s).
    pub time: f64,
    alert: f64,
    steps: u64,
    h_last: f64,
    /// The θ-scheme's state over a step.
    integrator: MoreauJean,
    /// Broad and narrow phase buffers.
    detector: Detector,
    /// The contacts of the last step and their impulses.
    contacts: ContactSet,
    /// The local solver's buffers.
    nlgs: Nlgs,
}

/// What a system carries from one step to the next besides its public fields (disks,
/// bodies, time): the step count (which seeds the random NLGS ordering), the last step
/// length (contact forces are impulses over it) and the contact memory of the warm start.
/// Saved and put back by a checkpoint, with [`Nscd::step_memory`] and
/// [`Nscd::restore_step_memory`]; the other buffers are rebuilt by every step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepMemory {
    /// Steps taken.
    pub steps: u64,
    /// Length of the last step (s).
    pub h_last: f64,
    /// Per contact of the last step, sorted by key: key, impulse `[P_n, P_t]`, sticking.
    pub contacts: Vec<(crate::contacts::ContactKey, [f64; 2], bool)>,
}

impl Nscd {
    /// A system; checks the law, the options, the bodies, and that no two bodies overlap
    /// by more than the alert distance.
    pub fn new(
        disks: Disks,
        bodies: Vec<RigidBody>,
        law: ContactLaw,
        params: SolverParams,
        gravity: [f64; 2],
    ) -> Result<Self, NscdError> {
        law.check()?;
        params.check()?;
        for (k, b) in bodies.iter().enumerate() {
            b.check(k)?;
        }
        if !gravity.iter().all(|g| g.is_finite()) {
            return Err(NscdError::BadParameter {
                name: "gravity",
                value: gravity[0] + gravity[1],
                message: "must be finite",
            });
        }
        let [r_min, _] = disks.radius_range();
        let alert = params.alert.unwrap_or(0.5 * r_min);
        let n = disks.len();
        let mut s = Self {
            force: vec![[0.0; 2]; n],
            disks,
            bodies,
            law,
            params,
            gravity,
            time: 0.0,
            alert,
            steps: 0,
            h_last: 0.0,
            integrator: MoreauJean::default(),
            detector: Detector::default(),
            contacts: ContactSet::default(),
            nlgs: Nlgs::default(),
        };
        let offsets: Vec<[f64; 2]> = s.bodies.iter().map(|b| b.offset).collect();
        let mut found = Vec::new();
        s.detector.detect(
            &s.disks.x, &s.disks.r, &s.bodies, &offsets, s.alert, &mut found,
        )?;
        if let Some(c) = found.iter().find(|c| c.gap < -s.alert) {
            return Err(NscdError::InitialOverlap {
                i: c.i as usize,
                with: match c.other {
                    Antagonist::Disk(j) => format!("particle {j}"),
                    Antagonist::Body(b) => format!("body {b}"),
                },
                overlap: -c.gap,
                alert: s.alert,
            });
        }
        Ok(s)
    }

    /// A flag checked before every NLGS sweep (of steps and of the settling): once set,
    /// the step ends with [`NscdError::Interrupted`] and the state is partial.
    pub fn set_interrupt(&mut self, flag: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>) {
        self.nlgs.interrupt = flag;
    }

    /// The alert distance in use (m).
    pub fn alert(&self) -> f64 {
        self.alert
    }

    /// The contacts of the last step, with their impulses.
    pub fn contacts(&self) -> &[Contact] {
        self.contacts.as_slice()
    }

    /// The time step of the last step (s; 0 before the first).
    pub fn last_step(&self) -> f64 {
        self.h_last
    }

    /// Force of a contact of the last step on its candidate (N per metre), `P/h` in
    /// the frame, as (r_n, r_t).
    pub fn contact_force(&self, c: &Contact) -> [f64; 2] {
        if self.h_last > 0.0 {
            [c.p[0] / self.h_last, c.p[1] / self.h_last]
        } else {
            [0.0; 2]
        }
    }

    /// The reaction of body `b` over the last step: `[f_x, f_y, τ]`, the sum of the
    /// contact forces the body exerts on the disks (N per metre of thickness) and their
    /// moment about the body's centroid (N·m per metre; counter-clockwise positive), both
    /// at the step's predicted configuration. For a prescribed axis this is the force
    /// the body's drive applies to hold its motion against the disks (a floor under a
    /// column at rest: f_y = the column's weight). `[0, 0, 0]` before the first step or
    /// for a body index out of range.
    pub fn body_reaction(&self, b: usize) -> [f64; 3] {
        let mut out = [0.0; 3];
        let (Some(body), Some(offset)) = (
            self.bodies.get(b),
            self.integrator.predicted_offsets().get(b),
        ) else {
            return out;
        };
        let c0 = body.centroid();
        let centre = [c0[0] + offset[0], c0[1] + offset[1]];
        for c in self.contacts.as_slice() {
            if c.other != Antagonist::Body(b as u32) {
                continue;
            }
            let [rn, rt] = self.contact_force(c);
            let f = [rn * c.n[0] + rt * c.t[0], rn * c.n[1] + rt * c.t[1]];
            let arm = [c.point[0] - centre[0], c.point[1] - centre[1]];
            out[0] += f[0];
            out[1] += f[1];
            out[2] += arm[0] * f[1] - arm[1] * f[0];
        }
        out
    }

    /// The contacts of the last step that carry a force, as tracked cells see them
    /// (branch vector (r_i + r_j) n, Renouf et al. (2006) eq. 7).
    pub fn cell_contacts(&self, out: &mut Vec<CellContact>) {
        out.clear();
        for c in self.contacts.as_slice() {
            if c.p == [0.0, 0.0] {
                continue;
            }
            let [fn_, ft] = self.contact_force(c);
            let l = c.ri + c.rj;
            out.push(CellContact {
                i: c.i as usize,
                j: match c.other {
                    Antagonist::Disk(j) => Some(j as usize),
                    Antagonist::Body(_) => None,
                },
                normal: c.n,
                branch: [l * c.n[0], l * c.n[1]],
                force: [fn_ * c.n[0] + ft * c.t[0], fn_ * c.n[1] + ft * c.t[1]],
            });
        }
    }

    /// The contacts of the last step as lines from the antagonist (centre or contact
    /// point) to the candidate's centre, for VTK.
    pub fn contact_lines(&self, out: &mut Vec<ContactLine>) {
        out.clear();
        for c in self.contacts.as_slice() {
            let [fn_, ft] = self.contact_force(c);
            let a = match c.other {
                Antagonist::Disk(j) => self.disks.x[j as usize],
                Antagonist::Body(_) => c.point,
            };
            out.push(ContactLine {
                a,
                b: self.disks.x[c.i as usize],
                normal_force: fn_,
                tangential_force: ft,
                bonded: false,
            });
        }
    }

    /// The memory a next step needs besides the public fields ([`StepMemory`]).
    pub fn step_memory(&self) -> StepMemory {
        StepMemory {
            steps: self.steps,
            h_last: self.h_last,
            contacts: self.contacts.memory(),
        }
    }

    /// Put back a [`StepMemory`] (into a system built the same way, whose public fields
    /// are restored too).
    pub fn restore_step_memory(&mut self, m: &StepMemory) {
        self.steps = m.steps;
        self.h_last = m.h_last;
        self.contacts.set_memory(&m.contacts);
    }

    /// Advance by one step of length `h`: the stages of the module docs in order.
    pub fn step(&mut self, h: f64) -> Result<StepStats, NscdError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(NscdError::BadParameter {
                name: "dt",
                value: h,
                message: "must be a positive number",
            });
        }
        let theta = self.params.theta;
        let ig = &mut self.integrator;
        ig.predict(&self.disks, &self.bodies, h, theta);
        self.contacts.detect(
            &mut self.detector,
            ig.predicted(),
            &self.disks,
            &self.bodies,
            ig.predicted_offsets(),
            self.alert,
        )?;
        ig.free_velocities(&mut self.disks, &self.bodies, self.gravity, &self.force, h);
        crate::problem::build(
            &mut self.contacts,
            &self.law,
            &ig.inv_m,
            &ig.inv_i,
            &ig.body_inv,
            &ig.body_mu,
            h,
            theta,
        );
        if self.law.restitution > 0.0 {
            let (v0, bv0) = ig.start_velocities();
            crate::problem::newton(&mut self.contacts, self.law.restitution, v0, bv0);
        }
        let d = &mut self.disks;
        crate::problem::apply_impulses(
            &self.contacts.list,
            &mut d.v,
            &mut d.omega,
            &ig.inv_m,
            &ig.inv_i,
            &mut ig.body_v,
            &ig.body_inv,
        );
        let t0 = std::time::Instant::now();
        let solved = self.nlgs.solve(
            &self.params.nlgs(),
            self.steps,
            &mut self.contacts.list,
            &d.x,
            Velocities {
                v: &mut d.v,
                omega: &mut d.omega,
                body_v: &mut ig.body_v,
            },
            InverseMasses {
                m: &ig.inv_m,
                i: &ig.inv_i,
                body: &ig.body_inv,
            },
        );
        if solved.interrupted {
            return Err(NscdError::Interrupted);
        }
        let num_contacts = self.contacts.list.len();
        let stats = StepStats {
            contacts: num_contacts,
            sweeps: solved.sweeps,
            residual: solved.residual,
            converged: solved.converged,
            updates: solved.sweeps as u64 * num_contacts as u64,
            solve_seconds: t0.elapsed().as_secs_f64(),
        };
        ig.update(d, &mut self.bodies, h, theta, self.time)?;
        self.contacts.remember();
        self.time += h;
        self.steps += 1;
        self.h_last = h;
        Ok(stats)
    }
}
