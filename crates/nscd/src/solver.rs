//! The θ-scheme on velocities and the non-linear Gauss–Seidel (NLGS) solver.
//!
//! **Time step** (seed eq. 3, Moreau–Jean) on ]t_i, t_i + h], ½ ≤ θ ≤ 1:
//!
//! 1. predicted configuration q_m = q_i + h(1 − θ) q̇_i (bodies: their offset likewise);
//! 2. detection at q_m ([`crate::detect`]), local frames, W blocks;
//! 3. free velocity q̇_free = q̇_i + h M⁻¹ F (gravity, applied forces; constant over the
//!    step, so θF_{i+1} + (1 − θ)F_i = F);
//! 4. NLGS (eq. 5, Table 1) on the impulses P_α = h r_α;
//! 5. q̇_{i+1} = q̇_free + M⁻¹ H P and q_{i+1} = q_i + h(θ q̇_{i+1} + (1 − θ) q̇_i).
//!
//! **Body-velocity accumulation**: W is never formed. The solver keeps the body
//! velocities q̇ = q̇_free + M⁻¹ H P up to date; a contact reads its relative velocity
//! U = Hᵀ q̇, removes its own contribution (b = U − W_αα P_α), solves its local problem
//! exactly ([`crate::law::solve_local`]) and adds M⁻¹ H ΔP back to its two bodies. For
//! disks i (candidate) and j: U_n = (v_i − v_j)·n, U_t = (v_i − v_j)·t − r_i ω_i − r_j ω_j;
//! the impulse P_n n + P_t t acts on i at −r_i n and its opposite on j at r_j n, so
//! Δω_i = −r_i P_t/I_i and Δω_j = −r_j P_t/I_j.
//!
//! **Warm start**: a contact found again (same candidate and antagonist) starts from
//! the impulse it ended the previous step with; a new one from zero.
//!
//! **Convergence test** after each sweep k: with ΔP_α the change of P_α during the
//! sweep, e_k = √(Σ ΔP_αᵀ W_αα ΔP_α / Σ P_αᵀ W_αα P_α). The sweeps stop when
//! k ≥ `min_sweeps` and e_k ≤ `tolerance`, when a sweep changed nothing at all (an exact
//! fixed point: further sweeps would repeat it), or at `max_sweeps` (counted as not
//! converged in [`StepStats`]). Defaults: the paper's minimum of 100 sweeps,
//! tolerance 1.666e-4 (LMGC90's), at most 10 000 sweeps, θ = ½.
//!
//! **Ordering** ([`Ordering`]): by default the contacts are swept in their sorted order
//! (candidate, then antagonist), the same every sweep; [`Ordering::Random`] draws a new
//! permutation for every sweep from a seed and the step number, reproducible too;
//! [`Ordering::Coloured`] sweeps colour groups of independent contacts in parallel
//! ([`crate::colour`]), with a result that does not depend on the thread count;
//! [`Ordering::Slabs`] sweeps one slab of disks per thread in parallel, each in sorted
//! order, then the contacts between slabs ([`crate::slabs`]), with a result that depends
//! on the thread count only.

use porofrac_particles::Disks;
use porofrac_particles::rng::SplitMix64;
use porofrac_particles::tracked::CellContact;
use porofrac_particles::vtk::ContactLine;

use crate::NscdError;
use crate::body::{Axis, RigidBody};
use crate::detect::{Antagonist, Contact, Detector};
use crate::law::{Block, ContactLaw, solve_local};

/// Order of the contacts within a sweep.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ordering {
    /// Sorted by candidate, then antagonist (disks before bodies), every sweep.
    #[default]
    Sorted,
    /// A new random permutation every sweep, drawn from this seed and the step number.
    Random {
        /// Seed of the permutations.
        seed: u64,
    },
    /// Colour groups swept in parallel ([`crate::colour`]): the same result for any
    /// number of threads.
    Coloured,
    /// One slab of disks per thread swept in parallel, each in sorted order, then the
    /// contacts between slabs ([`crate::slabs`]): the same result for a given number of
    /// threads.
    Slabs,
}

/// Options of the time stepping and of NLGS.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverParams {
    /// θ of the θ-scheme, in [½, 1] (default ½).
    pub theta: f64,
    /// Tolerance of the W-weighted relative impulse change (default 1.666e-4).
    pub tolerance: f64,
    /// Fewest sweeps per step (default 100, the paper's).
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
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return bad("tolerance", self.tolerance, "must be a positive number");
        }
        if self.max_sweeps == 0 {
            return bad("max_sweeps", 0.0, "must be at least 1");
        }
        if self.min_sweeps > self.max_sweeps {
            return bad(
                "min_sweeps",
                self.min_sweeps as f64,
                "must not exceed max_sweeps",
            );
        }
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

#[derive(Clone, Copy, Debug)]
struct Previous {
    key: (u32, Antagonist),
    p: [f64; 2],
    stick: bool,
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
    inv_m: Vec<f64>,
    inv_i: Vec<f64>,
    v_old: Vec<[f64; 2]>,
    omega_old: Vec<f64>,
    xm: Vec<[f64; 2]>,
    body_v: Vec<[f64; 2]>,
    body_v_old: Vec<[f64; 2]>,
    body_inv: Vec<[f64; 2]>,
    offsets_m: Vec<[f64; 2]>,
    contacts: Vec<Contact>,
    previous: Vec<Previous>,
    detector: Detector,
    order: Vec<u32>,
    h_last: f64,
    shared: crate::colour::SharedVelocities,
    masks: Vec<u64>,
    starts: Vec<usize>,
    slabs: crate::slabs::Slabs,
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
            inv_m: Vec::new(),
            inv_i: Vec::new(),
            v_old: Vec::new(),
            omega_old: Vec::new(),
            xm: Vec::new(),
            body_v: Vec::new(),
            body_v_old: Vec::new(),
            body_inv: Vec::new(),
            offsets_m: Vec::new(),
            contacts: Vec::new(),
            previous: Vec::new(),
            detector: Detector::default(),
            order: Vec::new(),
            h_last: 0.0,
            shared: Default::default(),
            masks: Vec::new(),
            starts: Vec::new(),
            slabs: crate::slabs::Slabs::default(),
        };
        let offsets: Vec<[f64; 2]> = s.bodies.iter().map(|b| b.offset).collect();
        let mut found = Vec::new();
        s.detector.detect(
            &s.disks.x, &s.disks.r, &s.bodies, &offsets, s.alert, &mut found,
        );
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

    /// The alert distance in use (m).
    pub fn alert(&self) -> f64 {
        self.alert
    }

    /// The contacts of the last step, with their impulses.
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
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

    /// The contacts of the last step that carry a force, as tracked cells see them
    /// (branch vector (r_i + r_j) n, seed eq. 7).
    pub fn cell_contacts(&self, out: &mut Vec<CellContact>) {
        out.clear();
        for c in &self.contacts {
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
        for c in &self.contacts {
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

    /// Advance by one step of length `h`.
    pub fn step(&mut self, h: f64) -> Result<StepStats, NscdError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(NscdError::BadParameter {
                name: "dt",
                value: h,
                message: "must be a positive number",
            });
        }
        let theta = self.params.theta;
        let n = self.disks.len();
        let d = &mut self.disks;
        // Inverse masses (0 for infinite mass or inertia).
        self.inv_m.clear();
        self.inv_m.extend(
            d.mass
                .iter()
                .map(|&m| if m.is_finite() { 1.0 / m } else { 0.0 }),
        );
        self.inv_i.clear();
        self.inv_i.extend(
            d.inertia
                .iter()
                .map(|&j| if j.is_finite() { 1.0 / j } else { 0.0 }),
        );
        // 1. Predicted configuration.
        self.v_old.clone_from(&d.v);
        self.omega_old.clone_from(&d.omega);
        self.xm.clear();
        let c = h * (1.0 - theta);
        self.xm.extend(
            d.x.iter()
                .zip(&d.v)
                .map(|(x, v)| [x[0] + c * v[0], x[1] + c * v[1]]),
        );
        self.offsets_m.clear();
        self.offsets_m.extend(self.bodies.iter().map(|b| {
            [
                b.offset[0] + c * b.velocity[0],
                b.offset[1] + c * b.velocity[1],
            ]
        }));
        // 2. Detection.
        self.detector.detect(
            &self.xm,
            &d.r,
            &self.bodies,
            &self.offsets_m,
            self.alert,
            &mut self.contacts,
        );
        // 3. Free velocities.
        for i in 0..n {
            if self.inv_m[i] > 0.0 {
                for a in 0..2 {
                    d.v[i][a] += h * (self.gravity[a] + self.force[i][a] * self.inv_m[i]);
                }
            }
        }
        self.body_v_old.clear();
        self.body_v.clear();
        self.body_inv.clear();
        for b in &self.bodies {
            self.body_v_old.push(b.velocity);
            let mut v = b.velocity;
            for a in 0..2 {
                match b.axes[a] {
                    Axis::Prescribed(p) => v[a] = p,
                    Axis::Loaded(f) => v[a] += h * f / b.mass,
                }
            }
            self.body_v.push(v);
            self.body_inv.push(b.inverse_mass());
        }
        // Blocks of W, law of each contact, warm start.
        let law = self.law;
        let mut prev = 0usize;
        for ct in self.contacts.iter_mut() {
            let i = ct.i as usize;
            let (mut nn, mut nt, mut tt) = (
                self.inv_m[i],
                0.0,
                self.inv_m[i] + ct.ri * ct.ri * self.inv_i[i],
            );
            match ct.other {
                Antagonist::Disk(j) => {
                    let j = j as usize;
                    nn += self.inv_m[j];
                    tt += self.inv_m[j] + ct.rj * ct.rj * self.inv_i[j];
                }
                Antagonist::Body(b) => {
                    let ib = self.body_inv[b as usize];
                    nn += ib[0] * ct.n[0] * ct.n[0] + ib[1] * ct.n[1] * ct.n[1];
                    nt += ib[0] * ct.n[0] * ct.t[0] + ib[1] * ct.n[1] * ct.t[1];
                    tt += ib[0] * ct.t[0] * ct.t[0] + ib[1] * ct.t[1] * ct.t[1];
                }
            }
            ct.w = Block { nn, nt, tt };
            let key = (ct.i, ct.other);
            while prev < self.previous.len() && self.previous[prev].key < key {
                prev += 1;
            }
            let (p0, stick) = match self.previous.get(prev) {
                Some(q) if q.key == key => (q.p, q.stick),
                _ => ([0.0; 2], false),
            };
            ct.mu = if stick { law.mu_static } else { law.mu_dynamic };
            let cohesive = law.cohesion > 0.0 && ct.gap <= law.cohesion_distance;
            ct.shift = if cohesive { h * law.cohesion } else { 0.0 };
            ct.bias = [
                ct.gap.max(0.0) / (theta * h) - nn * ct.shift,
                -nt * ct.shift,
            ];
            // Two immovable bodies: nothing to solve.
            ct.p = if nn > 0.0 { p0 } else { [0.0; 2] };
        }
        self.contacts.retain(|c| c.w.nn > 0.0);
        for ct in &self.contacts {
            apply(
                ct,
                ct.p,
                &mut d.v,
                &mut d.omega,
                &self.inv_m,
                &self.inv_i,
                &mut self.body_v,
                &self.body_inv,
            );
        }
        // 4. NLGS.
        let t0 = std::time::Instant::now();
        let mut stats = StepStats {
            contacts: self.contacts.len(),
            ..StepStats::default()
        };
        let mut rng = match self.params.ordering {
            Ordering::Random { seed } => Some(SplitMix64::new(
                seed ^ self.steps.wrapping_mul(0x9E37_79B9_7F4A_7C15),
            )),
            _ => None,
        };
        let coloured = self.params.ordering == Ordering::Coloured && !self.contacts.is_empty();
        let slabs = self.params.ordering == Ordering::Slabs && !self.contacts.is_empty();
        let mut serial_last = false;
        if coloured || slabs {
            let moving: Vec<bool> = (0..n)
                .map(|i| self.inv_m[i] > 0.0 || self.inv_i[i] > 0.0)
                .collect();
            let body_moving: Vec<bool> = self.body_inv.iter().map(|b| *b != [0.0, 0.0]).collect();
            if coloured {
                serial_last = crate::colour::colour(
                    &mut self.contacts,
                    &moving,
                    &body_moving,
                    &mut self.masks,
                    &mut self.starts,
                );
            } else {
                self.slabs.partition(
                    &mut self.contacts,
                    &d.x,
                    &moving,
                    &body_moving,
                    rayon::current_num_threads(),
                );
            }
            self.shared.load(&d.v, &d.omega, &self.body_v);
        }
        if !self.contacts.is_empty() {
            for k in 1..=self.params.max_sweeps {
                let (num, den) = if coloured {
                    crate::colour::sweep(
                        &mut self.contacts,
                        &self.starts,
                        serial_last,
                        &self.shared,
                        &self.inv_m,
                        &self.inv_i,
                        &self.body_inv,
                    )
                } else if slabs {
                    self.slabs.sweep(
                        &mut self.contacts,
                        &self.shared,
                        &self.inv_m,
                        &self.inv_i,
                        &self.body_inv,
                    )
                } else {
                    match rng.as_mut() {
                        None => sweep(
                            &mut self.contacts,
                            None,
                            &mut d.v,
                            &mut d.omega,
                            &self.inv_m,
                            &self.inv_i,
                            &mut self.body_v,
                            &self.body_inv,
                        ),
                        Some(rng) => {
                            self.order.clear();
                            self.order.extend(0..self.contacts.len() as u32);
                            for a in (1..self.order.len()).rev() {
                                self.order.swap(a, rng.below(a + 1));
                            }
                            sweep(
                                &mut self.contacts,
                                Some(&self.order),
                                &mut d.v,
                                &mut d.omega,
                                &self.inv_m,
                                &self.inv_i,
                                &mut self.body_v,
                                &self.body_inv,
                            )
                        }
                    }
                };
                stats.sweeps = k;
                stats.residual = if den > 0.0 {
                    (num / den).sqrt()
                } else if num > 0.0 {
                    f64::INFINITY
                } else {
                    0.0
                };
                if num == 0.0
                    || (k >= self.params.min_sweeps && stats.residual <= self.params.tolerance)
                {
                    stats.converged = true;
                    break;
                }
            }
        } else {
            stats.converged = true;
        }
        if coloured || slabs {
            self.shared.store(&mut d.v, &mut d.omega, &mut self.body_v);
        }
        stats.updates = stats.sweeps as u64 * self.contacts.len() as u64;
        stats.solve_seconds = t0.elapsed().as_secs_f64();
        // 5. Positions; refuse a step that moves a disk by more than its radius.
        for i in 0..n {
            let u = [
                h * (theta * d.v[i][0] + (1.0 - theta) * self.v_old[i][0]),
                h * (theta * d.v[i][1] + (1.0 - theta) * self.v_old[i][1]),
            ];
            let dist = (u[0] * u[0] + u[1] * u[1]).sqrt();
            if dist.is_nan() || dist > d.r[i] || !d.omega[i].is_finite() {
                // Restore the state of the start of the step.
                d.v.clone_from(&self.v_old);
                d.omega.clone_from(&self.omega_old);
                return Err(NscdError::StepTooLarge {
                    time: self.time,
                    particle: i,
                    distance: dist,
                    radius: d.r[i],
                });
            }
        }
        for i in 0..n {
            for a in 0..2 {
                d.x[i][a] += h * (theta * d.v[i][a] + (1.0 - theta) * self.v_old[i][a]);
            }
            d.angle[i] += h * (theta * d.omega[i] + (1.0 - theta) * self.omega_old[i]);
        }
        for (k, b) in self.bodies.iter_mut().enumerate() {
            for a in 0..2 {
                b.offset[a] +=
                    h * (theta * self.body_v[k][a] + (1.0 - theta) * self.body_v_old[k][a]);
            }
            b.velocity = self.body_v[k];
        }
        // Keep the impulses and the stick status for the next step's warm start.
        self.previous.clear();
        self.previous.extend(self.contacts.iter().map(|c| {
            let pn = c.p[0] + c.shift;
            Previous {
                key: (c.i, c.other),
                p: c.p,
                stick: pn > 0.0 && c.p[1].abs() < c.mu * pn * (1.0 - 1e-9),
            }
        }));
        // Sorted by key for the merge of the next warm start (colouring permutes).
        self.previous.sort_unstable_by_key(|q| q.key);
        self.time += h;
        self.steps += 1;
        self.h_last = h;
        Ok(stats)
    }
}

/// Add M⁻¹ H dp of one contact to the velocities of its two bodies.
#[inline(always)]
fn apply(
    c: &Contact,
    dp: [f64; 2],
    v: &mut [[f64; 2]],
    omega: &mut [f64],
    inv_m: &[f64],
    inv_i: &[f64],
    body_v: &mut [[f64; 2]],
    body_inv: &[[f64; 2]],
) {
    let f = [
        dp[0] * c.n[0] + dp[1] * c.t[0],
        dp[0] * c.n[1] + dp[1] * c.t[1],
    ];
    let i = c.i as usize;
    v[i][0] += inv_m[i] * f[0];
    v[i][1] += inv_m[i] * f[1];
    omega[i] -= c.ri * dp[1] * inv_i[i];
    match c.other {
        Antagonist::Disk(j) => {
            let j = j as usize;
            v[j][0] -= inv_m[j] * f[0];
            v[j][1] -= inv_m[j] * f[1];
            omega[j] -= c.rj * dp[1] * inv_i[j];
        }
        Antagonist::Body(b) => {
            let b = b as usize;
            body_v[b][0] -= body_inv[b][0] * f[0];
            body_v[b][1] -= body_inv[b][1] * f[1];
        }
    }
}

/// One Gauss–Seidel sweep; returns (Σ ΔPᵀWΔP, Σ PᵀWP).
#[allow(clippy::too_many_arguments)]
fn sweep(
    contacts: &mut [Contact],
    order: Option<&[u32]>,
    v: &mut [[f64; 2]],
    omega: &mut [f64],
    inv_m: &[f64],
    inv_i: &[f64],
    body_v: &mut [[f64; 2]],
    body_inv: &[[f64; 2]],
) -> (f64, f64) {
    let mut num = 0.0;
    let mut den = 0.0;
    let count = contacts.len();
    for k in 0..count {
        let a = match order {
            Some(o) => o[k] as usize,
            None => k,
        };
        let c = &contacts[a];
        let i = c.i as usize;
        let (vj, wj) = match c.other {
            Antagonist::Disk(j) => (v[j as usize], omega[j as usize]),
            Antagonist::Body(b) => (body_v[b as usize], 0.0),
        };
        let dv = [v[i][0] - vj[0], v[i][1] - vj[1]];
        let un = dv[0] * c.n[0] + dv[1] * c.n[1];
        let ut = dv[0] * c.t[0] + dv[1] * c.t[1] - c.ri * omega[i] - c.rj * wj;
        let w = c.w;
        let b = [
            un - (w.nn * c.p[0] + w.nt * c.p[1]) + c.bias[0],
            ut - (w.nt * c.p[0] + w.tt * c.p[1]) + c.bias[1],
        ];
        let pbar = solve_local(&w, b, c.mu);
        let p = [pbar[0] - c.shift, pbar[1]];
        let dp = [p[0] - c.p[0], p[1] - c.p[1]];
        num += w.energy(dp);
        den += w.energy(p);
        if dp != [0.0, 0.0] {
            apply(c, dp, v, omega, inv_m, inv_i, body_v, body_inv);
            contacts[a].p = p;
        }
    }
    (num, den)
}
