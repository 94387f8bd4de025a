//! porofrac-particle-fluid: particles carried by a lattice Boltzmann fluid, with heat (seed
//! 002, §002.6).
//!
//! One coupled step advances the fluid by one lattice step `Δt` and the particles by the
//! same time in `n_sub` sub-steps of their own stable step:
//!
//! 1. **Rasterise**: every disk `i` is placed on the lattice as a moving circular
//!    obstacle, centre `(x_i − o)/Δx`, velocity `v_i Δt/Δx`, angular velocity `ω_i Δt`
//!    (`o` the lattice corner). Nodes it leaves are refilled, nodes it covers leave the
//!    fluid; the momentum they carry goes to the disk
//!    ([`porofrac_lbm::Lattice::node_exchange`]).
//! 2. **Sources**: the injection sets its mass source for the step ([`Injection`]).
//! 3. **Heat**: the temperature lattice collides and streams with the velocities of the
//!    fluid and the disks (solid nodes carry the solid diffusivity; §002.2).
//! 4. **Fluid**: collide, stream, interpolated bounce-back on the cut links (Mora et al.
//!    (2015) eq. 7). Long stretches of solid nodes (the disks' nodes) are skipped
//!    ([`porofrac_lbm::runs`]); the rasterisation of step 1 marks the rows it changed.
//! 5. **Loads**: momentum exchange on the cut links (Mora et al. (2015) eq. 8) plus the
//!    node exchange of step 1, in SI per metre of depth: `F = F* ρ Δx³/Δt²` (N/m), `T = T*
//!    ρ Δx⁴/Δt²` (N).
//! 6. **Particles**: `n_sub = ⌈Δt / Δt_p⌉` sub-steps of `Δt/n_sub`, `Δt_p` the
//!    particles' stable step ([`ParticleSolver::stable_dt`]), with the loads of step 5
//!    held constant (their time average over the lattice step is the step's momentum
//!    transfer divided by `Δt`), or with [`LoadAveraging::TwoSteps`] the mean of the
//!    loads of this step and the previous one.
//!
//! **Stability of the explicit exchange.** The loads of step 5 answer the wall velocity
//! of step 1 one lattice step late. For the small, light disks of a bonded rock
//! (radius 3 Δx, `ρ_s/ρ_f = 2.6`) this feedback has a mode that flips sign every lattice
//! step and grows by about 1.4 % per step from round-off, in fluid at rest: a rock of
//! 30 disks in still fluid reaches Mach 0.3 after about 2 700 steps, with or without
//! local damping, without any bond oscillation involved (it vanishes at 4× the solid
//! density). Taking the wall velocity as the mean of the previous sub-steps slows it
//! (growth ≈ 0.4 % per step) but does not remove it. Averaging the loads of two
//! consecutive steps ([`LoadAveraging::TwoSteps`]) cancels the flipping part of the
//! feedback exactly and keeps the slow part (a delay of half a step): the same rock stays
//! at round-off. The half of the last step's load not yet given to the particles is
//! [`ParticleFluid::pending_impulse`]; with it fluid plus particles still conserve
//! momentum to round-off.
//!
//! **Momentum.** With the standard momentum exchange the fluid loses exactly what the
//! particles gain in steps 1 and 5, so fluid plus particles conserve momentum to
//! round-off in a closed periodic box.
//!
//! **Heat** (§002.2, conjugate form): temperature lives on one D2Q5 lattice over fluid and
//! solid nodes; solid nodes relax with the solid diffusivity. The heat capacity per volume
//! `ρc_p` is the same in both, so a node holds `ρc_p Δx² T` per metre of depth and the
//! interface needs no extra rule. A disk's temperature is the mean over the nodes it
//! covers. [`HeatBudget`] keeps the books: the heat that leaves the disks' nodes per step
//! (over the lattice links to nodes they do not cover), the heat they take or leave with
//! covered and uncovered nodes, and the heat through the sides of the box.
//!
//! **Resolution.** A disk of radius below `min_radius_nodes · Δx` is refused (default 2:
//! the smallest particle of Mora et al. (2015), read as a radius, is two lattice spacings).
//! A gap between solids narrower than about `2Δx` holds no fluid node, or one without a
//! second fluid node behind it (the interpolation then falls back to plain bounce-back), so
//! fluid does not enter cracks narrower than the spacing; [`cracks`] carries the flow of
//! such cracks by the cubic law between the lattice nodes at their mouths, and
//! [`bond_cracks`] builds that network from a bonded model's broken bonds
//! ([`ParticleFluid::with_crack_flow`]): after step 2 it advances the crack fluid and sets
//! its mouth sources, and its pressure loads the disks on both sides of every broken
//! bond, added to the loads of step 5.

pub mod bond_cracks;
pub mod cracks;
mod injection;
mod lsm;
pub mod pockets;
mod solver;

pub use bond_cracks::{BondCrackOptions, BondCracks, CrackSolveStats};
pub use cracks::{CrackChannel, CrackError, CrackFlow};
pub use injection::{Injection, InjectionControl};
pub use pockets::Pockets;
pub use solver::{ParticleSolver, RigidDiskError, RigidDisks};

use std::time::Instant;

use porofrac_lbm::d2q9::CS2;
use porofrac_lbm::{
    Lattice, LbmError, MAX_MACH, Obstacle, ObstacleMotion, Shape, Thermal, ThermalSide, Units,
};

/// Errors of the coupled particle–fluid model.
#[derive(Debug, thiserror::Error)]
pub enum CouplingError {
    /// An error of the lattice Boltzmann solver.
    #[error(transparent)]
    Lbm(#[from] LbmError),
    /// A disk too small for the lattice.
    #[error(
        "particle {particle}: radius {radius:e} m is below {min_nodes} lattice spacings ({spacing:e} m each); refine the lattice or remove the particle"
    )]
    TooSmall {
        /// The particle.
        particle: usize,
        /// Its radius (m).
        radius: f64,
        /// The lattice spacing (m).
        spacing: f64,
        /// Smallest radius in spacings.
        min_nodes: f64,
    },
    /// A disk left the lattice along an axis that is not periodic.
    #[error("particle {particle} left the fluid lattice")]
    Outside {
        /// The particle.
        particle: usize,
    },
    /// A disk moving faster than the lattice can carry.
    #[error(
        "particle {particle}: surface speed at Mach {mach:.3}, above {MAX_MACH} (refine the time step: lower tau or the spacing)"
    )]
    TooFast {
        /// The particle.
        particle: usize,
        /// Mach number of its fastest surface point.
        mach: f64,
    },
    /// The particle solver failed.
    #[error("particle solver: {0}")]
    Particles(#[source] Box<dyn std::error::Error + Send + Sync>),
    /// A bad argument.
    #[error("{argument} = {value}: {message}")]
    Argument {
        /// The argument.
        argument: &'static str,
        /// Its value.
        value: f64,
        /// What is wrong.
        message: &'static str,
    },
}

impl CouplingError {
    pub(crate) fn argument(argument: &'static str, value: f64, message: &'static str) -> Self {
        CouplingError::Argument {
            argument,
            value,
            message,
        }
    }
}

/// Options of the coupling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CouplingOptions {
    /// Smallest disk radius in lattice spacings (default 2).
    pub min_radius_nodes: f64,
    /// Particle sub-steps are at most this fraction of the particles' stable step (default
    /// 1).
    pub particle_dt_fraction: f64,
    /// Heat capacity per volume `ρ c_p` of fluid and solid (J/(m³·K); default 4.18e6,
    /// water).
    pub heat_capacity: f64,
    /// Loads given to the particles (default: those of the step).
    pub loads: LoadAveraging,
    /// The fluid sees disk `i` with radius `fluid_radius_factor · R_i` (default 1; the
    /// resolution rule applies to `R_i`). Above 1 the gaps of bonded disks closer than
    /// that hold no fluid (a cemented, impermeable contact).
    pub fluid_radius_factor: f64,
}

/// The fluid loads given to the particles during a lattice step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LoadAveraging {
    /// The loads of this step.
    #[default]
    Step,
    /// The mean of the loads of this step and of the previous one (see the module docs:
    /// cancels the sign-flipping mode of the explicit exchange).
    TwoSteps,
}

impl Default for CouplingOptions {
    fn default() -> Self {
        CouplingOptions {
            min_radius_nodes: 2.0,
            particle_dt_fraction: 1.0,
            heat_capacity: 4.18e6,
            loads: LoadAveraging::Step,
            fluid_radius_factor: 1.0,
        }
    }
}

/// The temperature lattice of a coupled model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalSetup {
    /// Diffusivity of the fluid (m²/s).
    pub diffusivity: f64,
    /// Diffusivity inside the disks (m²/s).
    pub solid_diffusivity: f64,
    /// Sides `xmin, xmax, ymin, ymax` (temperatures in the units of the fields).
    pub sides: [ThermalSide; 4],
}

/// Heat books of a coupled model (J per metre of depth).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HeatBudget {
    /// Heat in the nodes the disks cover, now.
    pub particles: f64,
    /// Heat in the other nodes (fluid and fixed obstacles), now.
    pub fluid: f64,
    /// Heat of the disks at the start.
    pub particles_initial: f64,
    /// Heat of all nodes at the start.
    pub initial: f64,
    /// Heat that entered through the sides of the box since the start.
    pub sides_in: f64,
    /// Heat that left the disks' nodes through lattice links since the start (to the fluid,
    /// and to sides or fixed obstacles they touch).
    pub from_particles: f64,
    /// Heat the disks took with nodes they covered minus what they left in nodes they
    /// uncovered, since the start.
    pub carried: f64,
}

impl HeatBudget {
    /// `now − start − side inflow`: zero up to round-off.
    pub fn defect(&self) -> f64 {
        self.particles + self.fluid - self.initial - self.sides_in
    }
    /// `disks now − (disks at start − outflow + carried)`: zero up to round-off.
    pub fn particle_defect(&self) -> f64 {
        self.particles - (self.particles_initial - self.from_particles + self.carried)
    }
}

/// Where the time of the coupled steps went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CouplingStats {
    /// Lattice steps.
    pub steps: u64,
    /// Particle sub-steps.
    pub substeps: u64,
    /// Seconds in rasterisation, heat and fluid.
    pub fluid_seconds: f64,
    /// Seconds in the particle solver.
    pub particle_seconds: f64,
    /// Seconds in the crack network (part of `fluid_seconds`).
    pub crack_seconds: f64,
}

/// The fluid side of disks in a lattice Boltzmann fluid, optionally with heat (see the
/// module docs). The particle model stays with the caller and is passed to every step, so
/// a model that owns more than its disks (walls, loading, outputs) keeps them.
#[derive(Debug)]
pub struct ParticleFluid {
    count: usize,
    lattice: Lattice,
    thermal: Option<Thermal>,
    units: Units,
    origin: [f64; 2],
    first: usize,
    options: CouplingOptions,
    loads: Vec<[f64; 3]>,
    /// Loads of the previous step (two-step averaging).
    previous: Vec<[f64; 3]>,
    injection: Option<Injection>,
    cracks: Option<BondCracks>,
    heat: HeatBudget,
    stats: CouplingStats,
    time: f64,
}

impl ParticleFluid {
    /// Couple `particles` with `lattice` (lattice units from `units`; `origin` is the SI
    /// position of the lattice corner, node `(i, j)` sits at `o + (i + ½, j + ½) Δx`). The
    /// lattice may hold fixed obstacles already; one obstacle per disk is added after them.
    pub fn new<P: ParticleSolver>(
        particles: &P,
        mut lattice: Lattice,
        units: Units,
        origin: [f64; 2],
        options: CouplingOptions,
    ) -> Result<Self, CouplingError> {
        if !(options.min_radius_nodes.is_finite() && options.min_radius_nodes >= 0.0) {
            return Err(CouplingError::argument(
                "min_radius_nodes",
                options.min_radius_nodes,
                "must be finite and not negative",
            ));
        }
        if !(options.particle_dt_fraction > 0.0 && options.particle_dt_fraction <= 1.0) {
            return Err(CouplingError::argument(
                "particle_dt_fraction",
                options.particle_dt_fraction,
                "must be in (0, 1]",
            ));
        }
        if !(options.heat_capacity.is_finite() && options.heat_capacity > 0.0) {
            return Err(CouplingError::argument(
                "heat_capacity",
                options.heat_capacity,
                "must be positive",
            ));
        }
        let factor = options.fluid_radius_factor;
        if !(factor.is_finite() && (1.0..=2.0).contains(&factor)) {
            return Err(CouplingError::argument(
                "fluid_radius_factor",
                factor,
                "must be in [1, 2]",
            ));
        }
        let d = particles.disks();
        for i in 0..d.len() {
            let resolved = d.r[i] >= options.min_radius_nodes * units.dx;
            if !resolved {
                return Err(CouplingError::TooSmall {
                    particle: i,
                    radius: d.r[i],
                    spacing: units.dx,
                    min_nodes: options.min_radius_nodes,
                });
            }
        }
        let first = lattice.obstacles().len();
        for i in 0..d.len() {
            let ob = Obstacle {
                shape: Shape::Circle {
                    center: lattice_point(&units, origin, d.x[i]),
                    radius: factor * d.r[i] / units.dx,
                },
                velocity: [0.0, 0.0],
                angular_velocity: 0.0,
            };
            lattice.add_obstacle(ob).map_err(|e| match e {
                LbmError::Outside { .. } => CouplingError::Outside { particle: i },
                e => e.into(),
            })?;
        }
        lattice.set_obstacle_motion_mode(ObstacleMotion::External);
        let n = d.len();
        let mut s = ParticleFluid {
            count: n,
            lattice,
            thermal: None,
            units,
            origin,
            first,
            options,
            loads: vec![[0.0; 3]; n],
            previous: vec![[0.0; 3]; n],
            injection: None,
            cracks: None,
            heat: HeatBudget::default(),
            stats: CouplingStats::default(),
            time: 0.0,
        };
        s.place(particles)?;
        Ok(s)
    }

    /// Add the temperature lattice: fluid nodes start at `fluid(x)` (x in m), the nodes of
    /// disk `i` at `particle[i]`.
    pub fn with_thermal(
        mut self,
        setup: ThermalSetup,
        fluid: impl Fn([f64; 2]) -> f64,
        particle: &[f64],
    ) -> Result<Self, CouplingError> {
        if particle.len() != self.count {
            return Err(CouplingError::argument(
                "particle temperatures (count)",
                particle.len() as f64,
                "needs one temperature per disk",
            ));
        }
        let tau = |chi: f64, name| {
            if !(chi.is_finite() && chi > 0.0) {
                return Err(CouplingError::argument(name, chi, "must be positive"));
            }
            Ok(0.5 + chi * self.units.dt / (CS2 * self.units.dx * self.units.dx))
        };
        let (tf, ts) = (
            tau(setup.diffusivity, "diffusivity")?,
            tau(setup.solid_diffusivity, "solid_diffusivity")?,
        );
        let (u, o, first) = (self.units, self.origin, self.first);
        let lat = &self.lattice;
        let th = Thermal::new(lat, tf, ts, setup.sides, |p| {
            let (i, j) = (p[0] as usize, p[1] as usize);
            match lat.owner(i, j) {
                Some(k) if k >= first => particle[k - first],
                _ => fluid([o[0] + p[0] * u.dx, o[1] + p[1] * u.dx]),
            }
        })?;
        self.thermal = Some(th);
        let (p, f) = self.heat_content();
        self.heat = HeatBudget {
            particles: p,
            fluid: f,
            particles_initial: p,
            initial: p + f,
            ..HeatBudget::default()
        };
        Ok(self)
    }

    /// Add an injection (mass source) at a borehole of `radius` around `center` (m).
    pub fn with_injection(
        mut self,
        center: [f64; 2],
        radius: f64,
        control: InjectionControl,
    ) -> Result<Self, CouplingError> {
        let inj = Injection::new(
            &mut self.lattice,
            &self.units,
            self.origin,
            center,
            radius,
            control,
        )?;
        self.injection = Some(inj);
        Ok(self)
    }

    /// Carry the fluid in the cracks of the broken bonds of `particles` (the model given
    /// at construction) by the cubic law, its pressure loading the disks
    /// ([`bond_cracks`]).
    pub fn with_crack_flow<P: ParticleSolver>(
        mut self,
        particles: &P,
        options: BondCrackOptions,
    ) -> Result<Self, CouplingError> {
        self.cracks = Some(BondCracks::new(
            particles,
            &self.lattice,
            &self.units,
            options,
        )?);
        Ok(self)
    }

    /// The crack network of the broken bonds.
    pub fn crack_flow(&self) -> Option<&BondCracks> {
        self.cracks.as_ref()
    }

    /// The fluid lattice.
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }
    /// The fluid lattice, mutable: for side velocities and conditions between steps (the
    /// obstacles are the coupling's: placing them here is undone at the next step).
    pub fn lattice_mut(&mut self) -> &mut Lattice {
        &mut self.lattice
    }
    /// The temperature lattice.
    pub fn thermal(&self) -> Option<&Thermal> {
        self.thermal.as_ref()
    }
    /// The injection.
    pub fn injection(&self) -> Option<&Injection> {
        self.injection.as_ref()
    }
    /// Units.
    pub fn units(&self) -> &Units {
        &self.units
    }
    /// SI position of the lattice corner.
    pub fn origin(&self) -> [f64; 2] {
        self.origin
    }
    /// Options.
    pub fn options(&self) -> &CouplingOptions {
        &self.options
    }
    /// Time (s).
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Time step of the fluid (s).
    pub fn dt(&self) -> f64 {
        self.units.dt
    }
    /// Particle sub-steps per fluid step for the particles' current stable step (times
    /// `particle_dt_fraction`).
    pub fn substeps<P: ParticleSolver>(&self, particles: &P) -> usize {
        let dtp = self.options.particle_dt_fraction * particles.stable_dt();
        if dtp.is_finite() && dtp > 0.0 {
            (self.units.dt / dtp).ceil().max(1.0) as usize
        } else {
            1
        }
    }
    /// Loads of the fluid on each disk in the last step: `[fx, fy, torque]` (N/m, N).
    pub fn fluid_loads(&self) -> &[[f64; 3]] {
        &self.loads
    }
    /// Momentum the fluid has given up but the particles have not received yet
    /// (N·s/m): with [`LoadAveraging::TwoSteps`] half of the last step's load times `Δt`;
    /// zero otherwise. Fluid + particles + this is conserved.
    pub fn pending_impulse(&self) -> [f64; 2] {
        match self.options.loads {
            LoadAveraging::Step => [0.0; 2],
            LoadAveraging::TwoSteps => {
                let h = 0.5 * self.units.dt;
                self.previous
                    .iter()
                    .fold([0.0; 2], |a, f| [a[0] + h * f[0], a[1] + h * f[1]])
            }
        }
    }
    /// Heat books (zero without a temperature lattice).
    pub fn heat(&self) -> &HeatBudget {
        &self.heat
    }
    /// Where the time went.
    pub fn stats(&self) -> &CouplingStats {
        &self.stats
    }

    /// Mean temperature of the nodes disk `i` covers.
    pub fn particle_temperature(&self, i: usize) -> Option<f64> {
        self.thermal
            .as_ref()?
            .obstacle_temperature(&self.lattice, self.first + i)
    }

    /// Momentum of the fluid nodes (kg·m/s per metre of depth).
    pub fn fluid_momentum(&self) -> [f64; 2] {
        let p = self.lattice.momentum();
        let s = self.units.density * self.units.dx.powi(3) / self.units.dt;
        [p[0] * s, p[1] * s]
    }

    /// One coupled step of `particles`, the model given at construction (see the module
    /// docs).
    pub fn step<P: ParticleSolver>(&mut self, particles: &mut P) -> Result<(), CouplingError> {
        if particles.disks().len() != self.count {
            return Err(CouplingError::argument(
                "particles (count)",
                particles.disks().len() as f64,
                "differs from the disks the coupling was built with",
            ));
        }
        let t0 = Instant::now();
        let before = self.particle_heat_raw();
        self.place(particles)?;
        if self.thermal.is_some() {
            self.heat.carried += (self.particle_heat_raw() - before) * self.heat_scale();
        }
        if let Some(inj) = &self.injection {
            inj.apply(&mut self.lattice, &self.units, self.time)?;
        }
        if let Some(c) = &mut self.cracks {
            let tc = Instant::now();
            c.update(particles, &mut self.lattice, &self.units, self.origin)?;
            self.stats.crack_seconds += tc.elapsed().as_secs_f64();
        }
        if let Some(th) = &mut self.thermal {
            th.step(&self.lattice);
            let first = self.first;
            let out: f64 = (0..self.loads.len())
                .map(|i| th.obstacle_heat(first + i))
                .sum();
            self.heat.from_particles += out * self.heat_scale();
        }
        self.lattice.step()?;
        let two = self.options.loads == LoadAveraging::TwoSteps;
        for (i, (l, p)) in self.loads.iter_mut().zip(&mut self.previous).enumerate() {
            let f = self.lattice.force(self.first + i);
            let e = self.lattice.node_exchange(self.first + i);
            let now = [
                self.units.force_si(f[0] + e[0]),
                self.units.force_si(f[1] + e[1]),
                self.units.torque_si(f[2] + e[2]),
            ];
            if two {
                *l = std::array::from_fn(|a| 0.5 * (now[a] + p[a]));
                *p = now;
            } else {
                *l = now;
            }
        }
        if let Some(c) = &self.cracks {
            for (l, f) in self.loads.iter_mut().zip(c.loads()) {
                l[0] += f[0];
                l[1] += f[1];
            }
        }
        if let Some(th) = &self.thermal {
            let sides: f64 = th.side_heat().iter().sum();
            let (p, f) = self.heat_content();
            self.heat.particles = p;
            self.heat.fluid = f;
            self.heat.sides_in = sides * self.heat_scale();
        }
        let t1 = Instant::now();
        let n = self.substeps(particles);
        let h = self.units.dt / n as f64;
        for _ in 0..n {
            particles
                .advance(h, &self.loads)
                .map_err(|e| CouplingError::Particles(Box::new(e)))?;
        }
        let t2 = Instant::now();
        self.time += self.units.dt;
        self.stats.steps += 1;
        self.stats.substeps += n as u64;
        self.stats.fluid_seconds += (t1 - t0).as_secs_f64();
        self.stats.particle_seconds += (t2 - t1).as_secs_f64();
        Ok(())
    }

    /// J/m per lattice unit of `Σ T`.
    fn heat_scale(&self) -> f64 {
        self.options.heat_capacity * self.units.dx * self.units.dx
    }

    fn particle_heat_raw(&self) -> f64 {
        match &self.thermal {
            Some(th) => (0..self.loads.len())
                .map(|i| th.obstacle_total(&self.lattice, self.first + i))
                .sum(),
            None => 0.0,
        }
    }

    /// (disks, rest) heat content (J/m).
    fn heat_content(&self) -> (f64, f64) {
        match &self.thermal {
            Some(th) => {
                let p = self.particle_heat_raw();
                let s = self.heat_scale();
                (p * s, (th.total() - p) * s)
            }
            None => (0.0, 0.0),
        }
    }

    /// Step 1: place every disk on the lattice and rasterise.
    fn place<P: ParticleSolver>(&mut self, particles: &P) -> Result<(), CouplingError> {
        let d = particles.disks();
        let cs = CS2.sqrt();
        for i in 0..d.len() {
            let c = lattice_point(&self.units, self.origin, d.x[i]);
            let v = [
                self.units.velocity(d.v[i][0]),
                self.units.velocity(d.v[i][1]),
            ];
            let w = d.omega[i] * self.units.dt;
            let r = self.options.fluid_radius_factor * d.r[i] / self.units.dx;
            let mach = ((v[0] * v[0] + v[1] * v[1]).sqrt() + w.abs() * r) / cs;
            let slow = mach <= MAX_MACH;
            if !slow {
                return Err(CouplingError::TooFast { particle: i, mach });
            }
            self.lattice
                .place_obstacle(self.first + i, c, d.angle[i], v, w);
        }
        let first = self.first;
        self.lattice.update_obstacles().map_err(|e| match e {
            LbmError::Outside { obstacle } if obstacle >= first => CouplingError::Outside {
                particle: obstacle - first,
            },
            e => e.into(),
        })
    }
}

/// Lattice coordinates of SI point `x`.
fn lattice_point(u: &Units, origin: [f64; 2], x: [f64; 2]) -> [f64; 2] {
    [(x[0] - origin[0]) / u.dx, (x[1] - origin[1]) / u.dx]
}
