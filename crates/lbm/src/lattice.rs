//! The lattice: populations, geometry and boundary lists, and the step that ties them.
//!
//! Obstacles move in one of two ways ([`ObstacleMotion`]): the lattice advances them by
//! their own velocity after every step, or a caller places them
//! ([`Lattice::place_obstacle`]) and re-rasterises them ([`Lattice::update_obstacles`]),
//! which is how coupled particles are carried. Either way only what changed is rebuilt:
//!
//! * an obstacle that did not move keeps its solid nodes and cut links;
//! * an obstacle that moved is rasterised again (its bounding box); if it covers the same
//!   nodes, only `δ` and the wall point of its cut links are recomputed (the usual case for
//!   slowly moving particles);
//! * if nodes changed owner, the cut links of every obstacle with a solid node within two
//!   nodes of a changed node are rebuilt (a link reads its fluid node `x_f` and `x_f2`).
//!
//! **Covered and uncovered nodes** (Mora et al. (2015) eqs. 6–7 with moving particles). A
//! fluid node that an obstacle covers leaves the fluid with its momentum `ρu`; the body
//! gains it. A node it uncovers is refilled with `f^eq(ρ̄, u_w)`, `ρ̄` the mean density of
//! its fluid neighbours and `u_w` the body's velocity there; the body loses `ρ̄ u_w`. These
//! transfers are reported by [`Lattice::node_exchange`] apart from the momentum exchange on
//! cut links ([`Lattice::force`]); the sum of both is the momentum the fluid gave the body,
//! so the momentum of fluid plus bodies is conserved to round-off with the standard
//! momentum exchange (the Galilean-invariant variant is not conservative).
//!
//! **Gauge forces.** The momentum exchange of each cut link is taken relative to the fluid
//! at rest at the reference density, `ΔF = c_α [L(x_b, α) + L(x_f, ᾱ) − 2 w_α ρ₀]`: the
//! reference terms of the entry and exit links of every lattice line through a body cancel,
//! so a body wetted all round feels exactly the same force and torque; a body partly
//! covered by others (touching particles of a rock) is not pushed by the ambient pressure
//! `c_s² ρ₀` on its wetted part only, which the solid contacts would carry.
//!
//! **Mass sources** (the injection of Mora et al. (2015), Fig. 9): `f_α += w_α S` on the
//! fluid nodes of a source after every step, `S` the mass per node and step
//! ([`Lattice::set_source_rate`]); it adds mass and no momentum. [`Lattice::injected_mass`]
//! counts what went in.
//!
//! **Periodic sides**: an obstacle may cross a periodic side; its nodes are taken modulo the
//! period and its geometry is computed with the image nearest its centre, which is kept in
//! the first period.
//!
//! **Sides that are not periodic**: with [`ObstacleOverhang::Clipped`] (set by
//! [`Lattice::set_obstacle_overhang`]) an obstacle may overhang them. It is clipped to the
//! box: the nodes inside that it covers are solid, its cut links are those of the fluid
//! nodes inside, and its force and torque are what the fluid exerts on the part inside
//! (a link that leaves the box belongs to the side's rule, not to the obstacle).
//!
//! **Overlapping obstacles**: a node two obstacles cover belongs to the one that took it
//! first (in a coupled rock, touching particles), and every cut link into it to that one.
//! [`Lattice::contact`] says which obstacle each one found in its way at its last
//! rasterisation, so that a caller whose bodies must not overlap can refuse it.

use crate::LbmError;
use crate::boundary::{
    CopyLink, MomentumExchange, ObstacleLink, PressureLink, Side, SideKind, SideLink,
};
use crate::collision::{Collision, Rates};
use crate::d2q9::{C, OPP, Q, W, cf, feq};
use crate::geometry::Shape;
use crate::kernel::{BandHook, BandView, Grid, Layout, Physics, Storage};
use crate::populations::{Populations, Precision};
use crate::runs::{DEFAULT_GAP, FluidRuns};

/// Largest Mach number `|u|/c_s` accepted for prescribed velocities and reached in a run.
pub const MAX_MACH: f64 = 0.3;

const NONE: u32 = u32::MAX;

/// What a lattice is made of (all lattice units).
#[derive(Clone, Debug)]
pub struct LatticeConfig {
    /// Interior nodes along x.
    pub nx: usize,
    /// Interior nodes along y.
    pub ny: usize,
    /// Relaxation time `τ` (`ν = (τ − ½)/3`).
    pub tau: f64,
    /// Collision operator.
    pub collision: Collision,
    /// Axes that wrap around.
    pub periodic: [bool; 2],
    /// Conditions of the sides `xmin, xmax, ymin, ymax` (ignored on periodic axes).
    pub sides: [SideKind; 4],
    /// Body acceleration.
    pub accel: [f64; 2],
    /// Force summation on obstacles.
    pub momentum_exchange: MomentumExchange,
    /// Whether the obstacle rules are corrected to create no mass.
    pub obstacle_mass: ObstacleMass,
}

/// The mass balance of the obstacle rules.
///
/// The interpolated bounce-back (Mora et al. (2015) eq. 7) does not conserve mass: what it returns
/// along the cut links of a body differs from what arrived, by an amount that depends on
/// the flow next to the wall. Against a body at rest in a symmetric flow it cancels; at a
/// turning wall it does not (a disk of radius 6 turning at 0.02 spacings per step in a
/// closed 28² box gains 0.3 % of the fluid's mass in 5 000 steps), so the pressure drifts
/// and the flow never settles. A rigid surface lets no net mass through, so with
/// [`ObstacleMass::Conserved`] each body's imbalance of the step, `Σ_links (back − into)`,
/// is taken back from its returned populations in proportion to the link weights `w_α`
/// (the correction of the mass-conserving curved-boundary schemes, e.g. Bao, Yuan & Schaefer
/// 2008). Covering and refilling nodes as a body moves are booked separately.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ObstacleMass {
    /// Each body's cut links create no mass (default).
    #[default]
    Conserved,
    /// The rules as they are.
    Uncorrected,
}

impl LatticeConfig {
    /// A fully periodic `nx × ny` BGK lattice.
    pub fn periodic(nx: usize, ny: usize, tau: f64) -> Self {
        LatticeConfig {
            nx,
            ny,
            tau,
            collision: Collision::Bgk,
            periodic: [true, true],
            sides: [SideKind::Wall; 4],
            accel: [0.0, 0.0],
            momentum_exchange: MomentumExchange::Standard,
            obstacle_mass: ObstacleMass::Conserved,
        }
    }
}

/// A rigid obstacle (lattice units per step).
#[derive(Clone, Debug)]
pub struct Obstacle {
    /// Shape and current position.
    pub shape: Shape,
    /// Velocity of its centre.
    pub velocity: [f64; 2],
    /// Angular velocity about its centre.
    pub angular_velocity: f64,
}

impl Obstacle {
    /// The rigid-body velocity at point `p`.
    pub fn velocity_at(&self, p: [f64; 2]) -> [f64; 2] {
        let c = self.shape.center();
        [
            self.velocity[0] - self.angular_velocity * (p[1] - c[1]),
            self.velocity[1] + self.angular_velocity * (p[0] - c[0]),
        ]
    }
}

/// Whether an obstacle may reach beyond a side that is not periodic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ObstacleOverhang {
    /// It must lie inside the box: one that does not is an error, [`LbmError::Outside`]
    /// (default; a coupled particle that leaves the lattice is a failed run).
    #[default]
    Refused,
    /// It is clipped to the box (a wall block that overhangs a side); only one that lies
    /// entirely outside is an error.
    Clipped,
}

/// Who moves the obstacles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ObstacleMotion {
    /// After every step the lattice advances each obstacle by its velocity and angular
    /// velocity (one step's worth) and re-rasterises it.
    #[default]
    Integrated,
    /// The caller places the obstacles ([`Lattice::place_obstacle`]) and calls
    /// [`Lattice::update_obstacles`] before a step; the velocities only enter the wall
    /// rule and the refill.
    External,
}

/// Scratch state of the incremental obstacle update (kept to avoid allocating per step).
#[derive(Clone, Debug, Default)]
struct Scratch {
    /// Nodes a raster finds.
    nodes: Vec<u32>,
    /// Nodes that changed owner in this update.
    changed: Vec<u32>,
    /// Nodes released in this update and the obstacle that released them.
    released: Vec<(u32, u32)>,
    /// Per node: released in this update and not yet covered again.
    fresh: Vec<bool>,
    /// Per obstacle: placed or advanced since the last update.
    moved: Vec<bool>,
    /// Per obstacle: cut links to rebuild.
    dirty: Vec<bool>,
    /// Per obstacle: centre at its last rasterisation.
    raster_at: Vec<[f64; 2]>,
    /// Per obstacle: how far it may move from `raster_at` without a node centre crossing
    /// its surface (circles; 0 for boxes).
    margin: Vec<f64>,
    /// Per obstacle: shape when `δ` of its links was last computed.
    linked_at: Vec<Shape>,
}

/// What an obstacle update does to one obstacle's cut links.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LinkWork {
    Keep,
    Deltas,
    Rebuild,
}

/// A set of nodes that receive mass.
#[derive(Clone, Debug)]
struct Source {
    nodes: Vec<u32>,
    rate: f64,
}

/// A D2Q9 lattice with its boundaries and obstacles.
#[derive(Clone, Debug)]
pub struct Lattice {
    cfg: LatticeConfig,
    grid: Grid,
    rates: Rates,
    pop: Populations,
    layout: Layout,
    /// 1 fluid, 0 solid (padded).
    mask: Vec<u8>,
    /// The segments of each row a step visits ([`crate::runs`]).
    runs: FluidRuns,
    /// Whether a step skips long stretches of solid nodes ([`Lattice::set_skip_solid`]).
    skip_solid: bool,
    /// Nodes the last step visited.
    visited: usize,
    /// Obstacle owning a solid node, or NONE.
    owner: Vec<u32>,
    obstacles: Vec<Obstacle>,
    /// Solid nodes of each obstacle (sorted).
    solid_nodes: Vec<Vec<u32>>,
    /// Cut links of each obstacle.
    links: Vec<Vec<ObstacleLink>>,
    /// Unknowns of each obstacle's cut links in the current step (scratch).
    backs: Vec<Vec<f64>>,
    /// Per obstacle: the first and last interior row of its cut links' fluid nodes, or
    /// `None` if it has none or one lies within two nodes of the box's edge.
    link_rows: Vec<Option<(u32, u32)>>,
    /// Whether obstacles' rules run inside the stream–collide sweep where they can
    /// ([`Lattice::set_rules_in_sweep`]).
    rules_in_sweep: bool,
    /// Scratch of the rules run inside the sweep.
    in_sweep: InSweep,
    forces: Vec<[f64; 3]>,
    exchange: Vec<[f64; 3]>,
    motion: ObstacleMotion,
    overhang: ObstacleOverhang,
    /// Per obstacle: another obstacle that held a node of its raster at its last
    /// rasterisation.
    contact: Vec<Option<usize>>,
    scratch: Scratch,
    sources: Vec<Source>,
    injected: f64,
    geometry_tolerance: f64,
    copies: Vec<CopyLink>,
    side_links: Vec<SideLink>,
    pressure_links: Vec<PressureLink>,
    steps: u64,
    /// Column of the whole box that local column 0 is (0 unless a window of a bigger box,
    /// [`Lattice::window`]): positions are those of the whole box, so a window computes
    /// the same numbers as the whole lattice.
    x0: isize,
    /// Columns of the whole box.
    box_nx: usize,
}

/// What a lattice with fixed obstacles carries from one step to the next
/// ([`Lattice::raw_state`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LatticeState {
    /// The populations as stored.
    pub populations: Vec<f64>,
    /// Whether they are in the swapped layout of the AA pattern (after an even step).
    pub swapped: bool,
    /// Steps done.
    pub steps: u64,
    /// Mass injected by the sources so far.
    pub injected: f64,
    /// The last step's force and torque on each obstacle.
    pub forces: Vec<[f64; 3]>,
    /// The last step's momentum exchange of each obstacle.
    pub exchange: Vec<[f64; 3]>,
}

impl Lattice {
    /// A lattice at rest with density 1.
    pub fn new(cfg: LatticeConfig) -> Result<Self, LbmError> {
        if cfg.nx < 2 || cfg.ny < 2 || cfg.nx > 1 << 15 || cfg.ny > 1 << 15 {
            return Err(LbmError::Size(cfg.nx, cfg.ny));
        }
        let rates = cfg.collision.rates(cfg.tau)?;
        let a = cfg.accel;
        if !(a[0].is_finite() && a[1].is_finite()) {
            return Err(LbmError::Value("body acceleration", f64::NAN));
        }
        for (s, kind) in cfg.sides.iter().enumerate() {
            if let SideKind::Pressure { density } = kind
                && !(*density > 0.0 && density.is_finite())
            {
                return Err(LbmError::Value(
                    ["xmin", "xmax", "ymin", "ymax"][s],
                    *density,
                ));
            }
        }
        let grid = Grid {
            nx: cfg.nx,
            ny: cfg.ny,
        };
        let np = grid.np();
        let mut l = Lattice {
            grid,
            rates,
            pop: Populations::new(Precision::Double, np),
            layout: Layout::Natural,
            mask: vec![1; np],
            runs: FluidRuns::new(cfg.nx, cfg.ny),
            skip_solid: true,
            visited: 0,
            owner: vec![NONE; np],
            obstacles: Vec::new(),
            solid_nodes: Vec::new(),
            links: Vec::new(),
            backs: Vec::new(),
            link_rows: Vec::new(),
            rules_in_sweep: true,
            in_sweep: InSweep::default(),
            forces: Vec::new(),
            exchange: Vec::new(),
            motion: ObstacleMotion::Integrated,
            overhang: ObstacleOverhang::Refused,
            contact: Vec::new(),
            scratch: Scratch {
                fresh: vec![false; np],
                ..Scratch::default()
            },
            sources: Vec::new(),
            injected: 0.0,
            geometry_tolerance: 0.0,
            copies: Vec::new(),
            side_links: Vec::new(),
            pressure_links: Vec::new(),
            steps: 0,
            x0: 0,
            box_nx: cfg.nx,
            cfg,
        };
        l.build_side_links();
        l.init(|_| (1.0, [0.0, 0.0]));
        Ok(l)
    }

    /// The columns `x0 .. x0 + width` of the lattice `cfg` describes, with every row: a
    /// window that computes, node for node, the numbers of the whole lattice wherever its
    /// inputs are those of the whole lattice (positions, obstacles, sides and the
    /// interpolation are those of the whole box). Where the window ends inside the box
    /// it has a wall; what comes in there is wrong, so a distributed run
    /// ([`crate::slab`]) overwrites the columns next to it with their owners' before
    /// every step. The x axis may not be periodic. Obstacles are added in the box's
    /// coordinates and may lie partly outside the window.
    pub fn window(cfg: LatticeConfig, x0: usize, width: usize) -> Result<Self, LbmError> {
        if cfg.periodic[0] || width < 2 || x0 + width > cfg.nx {
            return Err(LbmError::Size(width, cfg.ny));
        }
        let box_nx = cfg.nx;
        let mut local = cfg;
        local.nx = width;
        if x0 > 0 {
            local.sides[Side::XMin.index()] = SideKind::Wall;
        }
        if x0 + width < box_nx {
            local.sides[Side::XMax.index()] = SideKind::Wall;
        }
        let mut l = Lattice::new(local)?;
        l.x0 = x0 as isize;
        l.box_nx = box_nx;
        l.build_side_links();
        l.init(|_| (1.0, [0.0, 0.0]));
        Ok(l)
    }

    /// Nodes of the whole box along x and y (those of [`Lattice::size`] but for a
    /// [`Lattice::window`]).
    pub fn box_size(&self) -> (usize, usize) {
        (self.box_nx, self.grid.ny)
    }

    /// Column of the whole box that local column 0 is (0 but for a [`Lattice::window`]).
    pub fn origin(&self) -> usize {
        self.x0 as usize
    }

    /// Position of local column `i` (node centre, lattice units of the whole box).
    #[inline]
    fn gx(&self, i: isize) -> f64 {
        (i + self.x0) as f64 + 0.5
    }

    /// The populations as stored, and the padded nodes per direction (the slab exchange).
    #[cfg(feature = "mpi")]
    pub(crate) fn stored_mut(&mut self) -> (&mut Populations, usize) {
        let np = self.grid.np();
        (&mut self.pop, np)
    }

    /// The configuration.
    pub fn config(&self) -> &LatticeConfig {
        &self.cfg
    }
    /// Interior nodes `(nx, ny)`.
    pub fn size(&self) -> (usize, usize) {
        (self.grid.nx, self.grid.ny)
    }
    /// Steps done.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// Relaxation rates in use.
    pub fn rates(&self) -> Rates {
        self.rates
    }
    /// The state a lattice with fixed obstacles carries from one step to the next
    /// ([`LatticeState`]), for a checkpoint.
    pub fn raw_state(&self) -> LatticeState {
        LatticeState {
            populations: self.pop.to_f64(),
            swapped: self.layout == Layout::Swapped,
            steps: self.steps,
            injected: self.injected,
            forces: self.forces.clone(),
            exchange: self.exchange.clone(),
        }
    }

    /// Put back what [`Lattice::raw_state`] gave, into a lattice built the same way (same
    /// size, sides and obstacles, which must not have moved); `Err` says which array does
    /// not fit.
    pub fn restore_raw_state(&mut self, s: LatticeState) -> Result<(), String> {
        if s.populations.len() != self.pop.len() {
            return Err(format!(
                "{} populations, the lattice has {}",
                s.populations.len(),
                self.pop.len()
            ));
        }
        if s.forces.len() != self.forces.len() || s.exchange.len() != self.exchange.len() {
            return Err(format!(
                "{} obstacle forces, the lattice has {} obstacles",
                s.forces.len(),
                self.forces.len()
            ));
        }
        for (i, f) in s.populations.into_iter().enumerate() {
            self.pop.set(i, f);
        }
        self.layout = if s.swapped {
            Layout::Swapped
        } else {
            Layout::Natural
        };
        self.steps = s.steps;
        self.injected = s.injected;
        self.forces = s.forces;
        self.exchange = s.exchange;
        Ok(())
    }

    /// Store the populations as `precision` from now on (default [`Precision::Double`]);
    /// the values held are kept (rounded to `f32` for [`Precision::Single`]).
    pub fn set_precision(&mut self, precision: Precision) {
        self.pop = self.pop.converted(precision, self.grid.np());
    }

    /// Which solid nodes a step leaves alone: `Some(gap)` skips every stretch of at least
    /// `gap` solid nodes along a row (default [`DEFAULT_GAP`]; 1 skips every solid node),
    /// `None` visits every node (solid ones collided with rate 0 and streamed, as before).
    /// The fluid is the same bit for bit either way, and so is everything read from the
    /// lattice: solid nodes' populations are never read ([`crate::runs`]); only the time of
    /// a step differs, and the solid nodes' storage ([`Lattice::raw_state`]).
    pub fn set_skip_solid(&mut self, gap: Option<usize>) {
        self.skip_solid = gap.is_some();
        let gap = gap.unwrap_or(DEFAULT_GAP).max(1);
        if gap != self.runs.gap() {
            self.runs = FluidRuns::with_gap(self.grid.nx, self.grid.ny, gap);
            for j in 0..self.grid.ny {
                self.runs.touch(j);
            }
        }
    }

    /// Nodes the last step collided and streamed: those of the segments of
    /// [`crate::runs`] (the fluid nodes and the solid stretches shorter than the gap of
    /// [`Lattice::set_skip_solid`]), or every node without obstacles or with
    /// [`Lattice::set_skip_solid`]`(None)`; 0 before the first step.
    pub fn visited_nodes(&self) -> usize {
        self.visited
    }

    /// The floating-point type of the populations.
    pub fn precision(&self) -> Precision {
        self.pop.precision()
    }

    /// Bytes of population storage.
    pub fn population_bytes(&self) -> usize {
        self.pop.bytes()
    }

    /// Set every interior fluid node to the equilibrium of `(ρ, u) = f(node position)`.
    /// Velocities are corrected by half the body force (Guo), so that the velocity read back
    /// is the one given.
    pub fn init(&mut self, f: impl Fn([f64; 2]) -> (f64, [f64; 2])) {
        let g = self.grid;
        for j in 0..g.ny as isize {
            for i in 0..g.nx as isize {
                let node = g.node(i, j);
                let p = [self.gx(i), j as f64 + 0.5];
                let (rho, u) = if self.owner[node] == NONE {
                    f(p)
                } else {
                    (1.0, self.body_velocity(self.owner[node] as usize, node))
                };
                let u = [
                    u[0] - 0.5 * self.cfg.accel[0],
                    u[1] - 0.5 * self.cfg.accel[1],
                ];
                for q in 0..Q {
                    self.pop.set(g.loc(self.layout, node, q), feq(q, rho, u));
                }
            }
        }
    }

    /// Set the velocity of the walls or inlet of `side` from `u(point)`, the point where each
    /// link crosses the side (lattice units).
    pub fn set_side_velocity(&mut self, side: Side, u: impl Fn([f64; 2]) -> [f64; 2]) {
        for l in &mut self.side_links {
            if l.side as usize == side.index() {
                l.u = u(l.at);
            }
        }
    }

    /// Add an obstacle; along an axis that is not periodic it must lie inside the box, or
    /// with [`ObstacleOverhang::Clipped`] reach into it, what lies beyond a side being
    /// clipped away (the nodes inside are solid, and its force is what the fluid exerts on
    /// that part). Returns its index.
    pub fn add_obstacle(&mut self, ob: Obstacle) -> Result<usize, LbmError> {
        let k = self.obstacles.len();
        let mut ob = ob;
        self.check_inside(k, &mut ob.shape)?;
        self.obstacles.push(ob);
        self.solid_nodes.push(Vec::new());
        self.contact.push(None);
        self.links.push(Vec::new());
        self.link_rows.push(None);
        self.forces.push([0.0; 3]);
        self.exchange.push([0.0; 3]);
        self.scratch.moved.push(true);
        self.scratch.dirty.push(true);
        self.scratch.raster_at.push([f64::NAN; 2]);
        self.scratch.margin.push(0.0);
        self.scratch.linked_at.push(self.obstacles[k].shape);
        // A new body takes its nodes without refill or momentum bookkeeping.
        self.rasterize(k, false);
        self.exchange[k] = [0.0; 3];
        self.finish_update();
        Ok(k)
    }

    /// The obstacles.
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// Keep `δ` and the wall points of an obstacle's cut links until it has moved by more
    /// than `tolerance` spacings since they were computed (default 0: recompute whenever it
    /// moves). The solid nodes and the wall velocities are always current; only the wall
    /// position seen by the interpolation lags, by less than `tolerance`.
    pub fn set_geometry_tolerance(&mut self, tolerance: f64) -> Result<(), LbmError> {
        if !(tolerance.is_finite() && (0.0..0.5).contains(&tolerance)) {
            return Err(LbmError::Value("geometry tolerance (below 0.5)", tolerance));
        }
        self.geometry_tolerance = tolerance;
        Ok(())
    }

    /// Whether obstacles may overhang the sides that are not periodic (default
    /// [`ObstacleOverhang::Refused`]); set it before adding them.
    pub fn set_obstacle_overhang(&mut self, overhang: ObstacleOverhang) {
        self.overhang = overhang;
    }

    /// Who moves the obstacles (default [`ObstacleMotion::Integrated`]).
    pub fn set_obstacle_motion_mode(&mut self, motion: ObstacleMotion) {
        self.motion = motion;
    }

    /// Prescribe the motion of obstacle `k` for the next steps (the hook for coupled
    /// bodies: set the velocities before every [`Lattice::step`]).
    pub fn set_obstacle_motion(&mut self, k: usize, velocity: [f64; 2], angular_velocity: f64) {
        self.obstacles[k].velocity = velocity;
        self.obstacles[k].angular_velocity = angular_velocity;
    }

    /// Place obstacle `k`: its centre, its rotation angle (boxes; ignored for circles), its
    /// velocity and angular velocity. Takes effect at [`Lattice::update_obstacles`].
    pub fn place_obstacle(
        &mut self,
        k: usize,
        center: [f64; 2],
        angle: f64,
        velocity: [f64; 2],
        angular_velocity: f64,
    ) {
        let ob = &mut self.obstacles[k];
        let old = ob.shape;
        match &mut ob.shape {
            Shape::Circle { center: c, .. } | Shape::Hollow { center: c, .. } => *c = center,
            Shape::Box {
                center: c,
                angle: a,
                ..
            } => {
                *c = center;
                *a = angle;
            }
        }
        ob.velocity = velocity;
        ob.angular_velocity = angular_velocity;
        if ob.shape != old {
            self.scratch.moved[k] = true;
        }
    }

    /// Re-rasterise the obstacles placed since the last update: cover and uncover nodes
    /// (refill, momentum bookkeeping in [`Lattice::node_exchange`]) and rebuild what
    /// changed. Errors if an obstacle left the box (entirely, with
    /// [`ObstacleOverhang::Clipped`]) along an axis that is not periodic.
    pub fn update_obstacles(&mut self) -> Result<(), LbmError> {
        for e in &mut self.exchange {
            *e = [0.0; 3];
        }
        for k in 0..self.obstacles.len() {
            if !self.scratch.moved[k] {
                continue;
            }
            let mut s = self.obstacles[k].shape;
            self.check_inside(k, &mut s)?;
            self.obstacles[k].shape = s;
            // A circle that moved less than the distance from its surface to the nearest
            // node centre covers the same nodes.
            let (c, at) = (s.center(), self.scratch.raster_at[k]);
            let d = ((c[0] - at[0]).powi(2) + (c[1] - at[1]).powi(2)).sqrt();
            let same_nodes = d < self.scratch.margin[k];
            if !same_nodes {
                self.rasterize(k, true);
            }
        }
        self.refill();
        self.finish_update();
        Ok(())
    }

    /// Force `(fx, fy)` and torque on obstacle `k` from the last step (lattice units,
    /// momentum exchange over the cut links).
    pub fn force(&self, k: usize) -> [f64; 3] {
        self.forces[k]
    }

    /// Momentum `(px, py)` and angular momentum the body `k` took from the fluid by covering
    /// and uncovering nodes at its last update (lattice units; zero if it did not move).
    pub fn node_exchange(&self, k: usize) -> [f64; 3] {
        self.exchange[k]
    }

    /// An obstacle that already covered a node of obstacle `k`'s shape when `k` was last
    /// rasterised (the node stayed with it), or `None` if `k` overlaps no other obstacle
    /// by a node. An obstacle added on top of an earlier one reports it at once; one that
    /// moves into another, at the update that makes them share a node.
    pub fn contact(&self, k: usize) -> Option<usize> {
        self.contact[k]
    }

    /// Whether an interior node is solid.
    pub fn is_solid(&self, i: usize, j: usize) -> bool {
        self.owner[self.grid.node(i as isize, j as isize)] != NONE
    }

    /// The fluid nodes `(i, j)` off the box's edge rows and columns whose eight
    /// neighbours are all solid (pores of one node, which the lattice cannot resolve),
    /// row by row and along each row.
    ///
    /// Reads the mask (one byte per node, 1 fluid and 0 solid) eight nodes at a time: a
    /// candidate is a fluid node between two solid ones along its row, `m & !m_left &
    /// !m_right` of the words of eight bytes at its column, one to its left and one to its
    /// right; only those are checked against the rows above and below.
    pub fn enclosed_fluid_nodes(&self) -> Vec<(usize, usize)> {
        let (nx, ny, w) = (self.grid.nx, self.grid.ny, self.grid.stride());
        let mut out = Vec::new();
        if nx < 3 || ny < 3 {
            return out;
        }
        let word = |row: &[u8], c: usize| {
            let mut b = [0u8; 8];
            b.copy_from_slice(&row[c..c + 8]);
            u64::from_le_bytes(b)
        };
        // padded rows j, j + 1, j + 2 are interior rows j − 1, j, j + 1
        for j in 1..ny - 1 {
            let below = &self.mask[j * w..(j + 1) * w];
            let row = &self.mask[(j + 1) * w..(j + 2) * w];
            let above = &self.mask[(j + 2) * w..(j + 3) * w];
            let enclosed = |c: usize| {
                row[c] == 1
                    && row[c - 1] == 0
                    && row[c + 1] == 0
                    && below[c - 1..=c + 1] == [0, 0, 0]
                    && above[c - 1..=c + 1] == [0, 0, 0]
            };
            // padded column c is interior column c − 1; candidates c in 2 .. nx
            let mut c = 2;
            while c + 8 <= nx {
                let lone = word(row, c) & !word(row, c - 1) & !word(row, c + 1);
                if lone != 0 {
                    for k in 0..8 {
                        if (lone >> (8 * k)) & 1 == 1 && enclosed(c + k) {
                            out.push((c + k - 1, j));
                        }
                    }
                }
                c += 8;
            }
            for c in c..nx {
                if enclosed(c) {
                    out.push((c - 1, j));
                }
            }
        }
        out
    }

    /// The obstacle covering interior node `(i, j)`, if any.
    pub fn owner(&self, i: usize, j: usize) -> Option<usize> {
        let o = self.owner[self.grid.node(i as isize, j as isize)];
        (o != NONE).then_some(o as usize)
    }

    /// Interior nodes `(i, j)` covered by obstacle `k`.
    pub fn obstacle_nodes(&self, k: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        let w = self.grid.stride();
        self.solid_nodes[k]
            .iter()
            .map(move |&n| (n as usize % w - 1, n as usize / w - 1))
    }

    /// Interior fluid nodes.
    pub fn fluid_nodes(&self) -> usize {
        self.grid.nx * self.grid.ny - self.solid_nodes.iter().map(Vec::len).sum::<usize>()
    }

    /// Density and velocity of interior node `(i, j)` (solid nodes: 1 and the body's
    /// velocity).
    pub fn moments(&self, i: usize, j: usize) -> (f64, [f64; 2]) {
        let node = self.grid.node(i as isize, j as isize);
        if self.owner[node] != NONE {
            return (1.0, self.body_velocity(self.owner[node] as usize, node));
        }
        self.fluid_moments(node)
    }

    fn fluid_moments(&self, node: usize) -> (f64, [f64; 2]) {
        let g = self.grid;
        let (mut rho, mut jx, mut jy) = (0.0, 0.0, 0.0);
        for q in 0..Q {
            let f = self.pop.get(g.loc(self.layout, node, q));
            rho += f;
            jx += C[q][0] as f64 * f;
            jy += C[q][1] as f64 * f;
        }
        let a = self.cfg.accel;
        (rho, [jx / rho + 0.5 * a[0], jy / rho + 0.5 * a[1]])
    }

    /// Total momentum `Σ ρu` of the fluid nodes (lattice units).
    pub fn momentum(&self) -> [f64; 2] {
        let mut p = [0.0; 2];
        for j in 0..self.grid.ny {
            for i in 0..self.grid.nx {
                let node = self.grid.node(i as isize, j as isize);
                if self.owner[node] == NONE {
                    let (rho, u) = self.fluid_moments(node);
                    p[0] += rho * u[0];
                    p[1] += rho * u[1];
                }
            }
        }
        p
    }

    /// Population `f_q` arriving at interior node `(i, j)`.
    pub fn population(&self, i: usize, j: usize, q: usize) -> f64 {
        self.pop.get(
            self.grid
                .loc(self.layout, self.grid.node(i as isize, j as isize), q),
        )
    }

    /// Largest speed over fluid nodes, or an error if a density is not positive and finite.
    pub fn max_speed(&self) -> Result<f64, LbmError> {
        let mut m: f64 = 0.0;
        for j in 0..self.grid.ny {
            for i in 0..self.grid.nx {
                let (rho, u) = self.moments(i, j);
                if !(rho > 0.0 && rho.is_finite()) {
                    return Err(LbmError::Diverged {
                        step: self.steps,
                        i,
                        j,
                    });
                }
                m = m.max((u[0] * u[0] + u[1] * u[1]).sqrt());
            }
        }
        Ok(m)
    }

    /// Total mass of the fluid nodes.
    pub fn mass(&self) -> f64 {
        let mut s = 0.0;
        for j in 0..self.grid.ny {
            for i in 0..self.grid.nx {
                if !self.is_solid(i, j) {
                    s += self.moments(i, j).0;
                }
            }
        }
        s
    }

    /// Add a mass source on interior nodes `(i, j)` (rate 0 until
    /// [`Lattice::set_source_rate`]). Returns its index.
    pub fn add_source(&mut self, nodes: &[(usize, usize)]) -> Result<usize, LbmError> {
        if nodes.is_empty() {
            return Err(LbmError::Value("source nodes (count)", 0.0));
        }
        let mut v = Vec::with_capacity(nodes.len());
        for &(i, j) in nodes {
            if i >= self.grid.nx || j >= self.grid.ny {
                return Err(LbmError::Value("source node index", i.max(j) as f64));
            }
            v.push(self.grid.node(i as isize, j as isize) as u32);
        }
        v.sort_unstable();
        v.dedup();
        self.sources.push(Source {
            nodes: v,
            rate: 0.0,
        });
        Ok(self.sources.len() - 1)
    }

    /// Mass added to every fluid node of source `s` per step (lattice units; negative is a
    /// sink).
    pub fn set_source_rate(&mut self, s: usize, rate: f64) -> Result<(), LbmError> {
        if !rate.is_finite() {
            return Err(LbmError::Value("source rate", rate));
        }
        self.sources[s].rate = rate;
        Ok(())
    }

    /// Mean density of the fluid nodes of source `s` (1 if all are solid).
    pub fn source_density(&self, s: usize) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for &node in &self.sources[s].nodes {
            if self.owner[node as usize] == NONE {
                sum += self.fluid_moments(node as usize).0;
                n += 1;
            }
        }
        if n == 0 { 1.0 } else { sum / n as f64 }
    }

    /// Mass the sources added since the start (lattice units).
    pub fn injected_mass(&self) -> f64 {
        self.injected
    }

    /// One time step: collide and stream every node, apply the boundary lists, sum the
    /// obstacle forces, add the sources, then (with [`ObstacleMotion::Integrated`]) move
    /// the obstacles. Most obstacles' rules run inside the stream–collide sweep, as soon
    /// as the rows they read are final ([`Lattice::set_rules_in_sweep`]); the results are
    /// those of applying them after it.
    pub fn step(&mut self) -> Result<(), LbmError> {
        for (k, ob) in self.obstacles.iter().enumerate() {
            let [lo, hi] = ob.shape.bounds();
            let c = ob.shape.center();
            let r = (lo[0] - c[0])
                .abs()
                .max((hi[0] - c[0]).abs())
                .max((lo[1] - c[1]).abs())
                .max((hi[1] - c[1]).abs());
            let s = (ob.velocity[0].powi(2) + ob.velocity[1].powi(2)).sqrt()
                + ob.angular_velocity.abs() * r * std::f64::consts::SQRT_2;
            if s.is_nan() || s >= 1.0 {
                return Err(LbmError::TooFast {
                    obstacle: k,
                    speed: s,
                });
            }
        }
        let phys = Physics {
            rates: self.rates,
            accel: self.cfg.accel,
        };
        self.visited = self.grid.nx * self.grid.ny;
        self.layout = if self.obstacles.is_empty() {
            self.pop.aa_step(self.grid, self.layout, None, phys)
        } else {
            if self.skip_solid {
                self.runs.refresh(&self.mask);
                self.visited = self.runs.visited_nodes();
            }
            self.step_with_rules(phys)
        };
        self.apply_copies();
        self.apply_sides();
        self.apply_obstacles();
        self.apply_sources();
        self.steps += 1;
        if self.motion == ObstacleMotion::Integrated {
            let mut any = false;
            for k in 0..self.obstacles.len() {
                let ob = &mut self.obstacles[k];
                if ob.velocity != [0.0, 0.0] || ob.angular_velocity != 0.0 {
                    let (v, w) = (ob.velocity, ob.angular_velocity);
                    ob.shape.advance(v, w);
                    self.scratch.moved[k] = true;
                    any = true;
                }
            }
            if any {
                self.update_obstacles()?;
            }
        }
        Ok(())
    }

    /// Along a non-periodic axis the shape must lie inside the box, or with
    /// [`ObstacleOverhang::Clipped`] reach into it (the part beyond a side is clipped
    /// away); along a periodic one its centre is brought into the first period.
    fn check_inside(&self, k: usize, s: &mut Shape) -> Result<(), LbmError> {
        let n = [self.box_nx as f64, self.grid.ny as f64];
        let c = s.center();
        let mut d = [0.0; 2];
        for a in 0..2 {
            if self.cfg.periodic[a] {
                if !c[a].is_finite() {
                    return Err(LbmError::Outside { obstacle: k });
                }
                d[a] = c[a].rem_euclid(n[a]) - c[a];
            }
        }
        if d != [0.0, 0.0] {
            s.advance(d, 0.0);
        }
        let [lo, hi] = s.bounds();
        for a in 0..2 {
            let ok = match self.overhang {
                ObstacleOverhang::Refused => lo[a] >= 0.0 && hi[a] <= n[a],
                ObstacleOverhang::Clipped => {
                    lo[a] < n[a] && hi[a] > 0.0 && lo[a].is_finite() && hi[a].is_finite()
                }
            };
            if !self.cfg.periodic[a] && !ok {
                return Err(LbmError::Outside { obstacle: k });
            }
        }
        Ok(())
    }

    fn build_side_links(&mut self) {
        let g = self.grid;
        let (nx, ny) = (g.nx as isize, g.ny as isize);
        self.copies.clear();
        self.side_links.clear();
        self.pressure_links.clear();
        let per = self.cfg.periodic;
        for j in 0..ny {
            for i in 0..nx {
                if i != 0 && i != nx - 1 && j != 0 && j != ny - 1 {
                    continue;
                }
                let node = g.node(i, j) as u32;
                for q in 1..Q {
                    let (si, sj) = (i - C[q][0] as isize, j - C[q][1] as isize);
                    let out_x = if si < 0 {
                        Some(Side::XMin)
                    } else if si >= nx {
                        Some(Side::XMax)
                    } else {
                        None
                    };
                    let out_y = if sj < 0 {
                        Some(Side::YMin)
                    } else if sj >= ny {
                        Some(Side::YMax)
                    } else {
                        None
                    };
                    if out_x.is_none() && out_y.is_none() {
                        continue;
                    }
                    // A non-periodic side decides; walls before inlets and outlets.
                    let mut hit: Option<Side> = None;
                    for s in [out_y, out_x].into_iter().flatten() {
                        if per[s.axis()] {
                            continue;
                        }
                        let better = match hit {
                            None => true,
                            Some(h) => {
                                self.cfg.sides[h.index()] != SideKind::Wall
                                    && self.cfg.sides[s.index()] == SideKind::Wall
                            }
                        };
                        if better {
                            hit = Some(s);
                        }
                    }
                    match hit {
                        None => {
                            let wi = si.rem_euclid(nx) + C[q][0] as isize;
                            let wj = sj.rem_euclid(ny) + C[q][1] as isize;
                            self.copies.push(CopyLink {
                                dst: node,
                                src: g.node(wi, wj) as u32,
                                dir: q as u8,
                            });
                        }
                        Some(s) => {
                            let p = [self.gx(i), j as f64 + 0.5];
                            let at = [p[0] - 0.5 * C[q][0] as f64, p[1] - 0.5 * C[q][1] as f64];
                            match self.cfg.sides[s.index()] {
                                SideKind::Wall | SideKind::Velocity => {
                                    self.side_links.push(SideLink {
                                        node,
                                        dir: q as u8,
                                        side: s.index() as u8,
                                        at,
                                        u: [0.0, 0.0],
                                    })
                                }
                                SideKind::Pressure { density } => {
                                    self.pressure_links.push(PressureLink {
                                        node,
                                        dir: q as u8,
                                        density,
                                    })
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    fn apply_copies(&mut self) {
        let (g, lay) = (self.grid, self.layout);
        for c in &self.copies {
            let q = c.dir as usize;
            let f = self.pop.get(g.loc(lay, c.src as usize, q));
            self.pop.set(g.loc(lay, c.dst as usize, q), f);
        }
    }

    fn apply_sides(&mut self) {
        let (g, lay) = (self.grid, self.layout);
        for l in &self.side_links {
            let i = l.dir as usize;
            let a = OPP[i];
            let xb = g.shift(l.node as usize, a);
            let cu = C[i][0] as f64 * l.u[0] + C[i][1] as f64 * l.u[1];
            let f = self.pop.get(g.loc(lay, xb, a)) + 6.0 * W[i] * cu;
            self.pop.set(g.loc(lay, l.node as usize, i), f);
        }
        let acc = self.cfg.accel;
        for l in &self.pressure_links {
            let x = l.node as usize;
            let (mut rho, mut jx, mut jy) = (0.0, 0.0, 0.0);
            for q in 0..Q {
                let f = self.pop.get(g.loc(lay, g.shift(x, q), q));
                rho += f;
                jx += C[q][0] as f64 * f;
                jy += C[q][1] as f64 * f;
            }
            let u = [jx / rho - 0.5 * acc[0], jy / rho - 0.5 * acc[1]];
            let i = l.dir as usize;
            let a = OPP[i];
            let c = cf(i);
            let cu = c[0] * u[0] + c[1] * u[1];
            let usq = u[0] * u[0] + u[1] * u[1];
            let xb = g.shift(x, a);
            let f = -self.pop.get(g.loc(lay, xb, a))
                + 2.0 * W[i] * l.density * (1.0 + 4.5 * cu * cu - 1.5 * usq);
            self.pop.set(g.loc(lay, x, i), f);
        }
    }

    /// The stream–collide step of a lattice with obstacles (over the segments of
    /// [`crate::runs`] with `skip_solid`). Each band of the parallel sweep
    /// ([`crate::kernel::band_ranges`]) applies the rules of the obstacles whose cut links
    /// lie in it, a row from either end, as soon as what they read is final: the
    /// populations are still in cache. The rule of a link reads and writes four
    /// locations, those the sweep gives the nodes `x_f`, `x_f2` and `x_b` (see
    /// [`crate::kernel::BandHook`]), so it may run once the row after the link's is
    /// stepped. What a rule reads and writes, and the
    /// order of its sums, are those of [`Lattice::apply_obstacles`], which does the other
    /// obstacles after the sweep; no rule reads another's unknown, and a body two nodes
    /// from the box's edge reads nothing the sides' rules write, so the bits are those of
    /// applying every rule after the sweep. Returns the layout after the step.
    fn step_with_rules(&mut self, phys: Physics) -> Layout {
        let (g, lay) = (self.grid, self.layout);
        let runs = self.skip_solid.then_some(&self.runs);
        let ranges = self.sweep_bands();
        let rule = self.rule_kind();
        let plan = &mut self.in_sweep;
        plan.fused.clear();
        plan.fused.resize(self.obstacles.len(), false);
        plan.bodies.resize_with(ranges.len(), Vec::new);
        plan.forces.resize_with(ranges.len(), Vec::new);
        plan.backs.resize_with(ranges.len(), Vec::new);
        for b in plan.bodies.iter_mut() {
            b.clear();
        }
        if self.rules_in_sweep {
            for (k, r) in self.link_rows.iter().enumerate() {
                let Some((lo, hi)) = *r else { continue };
                let (lo, hi) = (lo as usize, hi as usize);
                let b = ranges.partition_point(|&(row0, _)| row0 <= lo) - 1;
                let (row0, n) = ranges[b];
                // a rule of a link at row j touches what the nodes x_f, x_f2 and x_b of
                // rows j − 1 ..= j + 1 touch in the sweep: final once row hi + 1 is stepped
                if lo > row0 && hi + 1 < row0 + n {
                    plan.bodies[b].push(((hi + 1) as u32, k as u32));
                    plan.fused[k] = true;
                }
            }
        }
        let new_layout = match lay {
            Layout::Natural => Layout::Swapped,
            Layout::Swapped => Layout::Natural,
        };
        let hooks: Vec<RulesInBand<'_>> = plan
            .bodies
            .iter_mut()
            .zip(plan.forces.iter_mut())
            .zip(plan.backs.iter_mut())
            .map(|((bodies, forces), back)| {
                bodies.sort_unstable();
                forces.clear();
                RulesInBand {
                    bodies,
                    next: 0,
                    obstacles: &self.obstacles,
                    links: &self.links,
                    g,
                    lay: new_layout,
                    rule,
                    back,
                    forces,
                }
            })
            .collect();
        let out = self
            .pop
            .aa_step_hooked(g, lay, &self.mask, runs, phys, &ranges, hooks);
        for band in &self.in_sweep.forces {
            for &(k, f) in band {
                self.forces[k as usize] = f;
            }
        }
        out
    }

    /// The row bands of the sweep, `(first row, rows)`: two per thread (the rules of an
    /// obstacle that straddles two bands wait for the end of the sweep, so fewer bands
    /// leave fewer for then), each split moved by up to a quarter of a band to the row
    /// that the fewest obstacles straddle.
    fn sweep_bands(&self) -> Vec<(usize, usize)> {
        let ny = self.grid.ny;
        let bands = (2 * rayon::current_num_threads().max(1)).min(ny);
        let rows = ny.div_ceil(bands);
        // straddle[s]: obstacles whose rules read rows s − 1 and s (rows lo − 1 ..= hi + 1)
        let mut straddle = vec![0i32; ny + 2];
        if self.rules_in_sweep {
            for &(lo, hi) in self.link_rows.iter().flatten() {
                straddle[lo as usize] += 1;
                straddle[(hi as usize + 2).min(ny + 1)] -= 1;
            }
            for s in 1..straddle.len() {
                straddle[s] += straddle[s - 1];
            }
        }
        let mut out = Vec::with_capacity(bands);
        let mut row0 = 0;
        for b in 1..bands {
            let nominal = b * rows;
            let (a, z) = (
                (nominal - rows / 4).max(row0 + 1),
                (nominal + rows / 4).min(ny - 1),
            );
            if a > z {
                break;
            }
            let split = (a..=z).min_by_key(|&s| straddle[s]).unwrap_or(nominal);
            out.push((row0, split - row0));
            row0 = split;
        }
        out.push((row0, ny - row0));
        out
    }

    /// Whether the obstacles' rules run inside the stream–collide sweep wherever they can
    /// (default `true`) or all after it. The results are the same to the bit either way
    /// (see [`Lattice::step`]); only the time differs.
    pub fn set_rules_in_sweep(&mut self, on: bool) {
        self.rules_in_sweep = on;
    }

    /// How many obstacles' rules the last step ran inside the sweep (the others ran
    /// after it).
    pub fn obstacles_in_sweep(&self) -> usize {
        self.in_sweep.fused.iter().filter(|&&f| f).count()
    }

    fn rule_kind(&self) -> RuleKind {
        RuleKind {
            galilean: self.cfg.momentum_exchange == MomentumExchange::GalileanInvariant,
            conserve: self.cfg.obstacle_mass == ObstacleMass::Conserved,
        }
    }

    /// The rules of the obstacles not done inside the sweep, in two passes: every
    /// obstacle's unknowns and force in parallel (a rule reads no unknown of another
    /// rule, see [`crate::boundary`]), then the unknowns written back.
    fn apply_obstacles(&mut self) {
        use rayon::prelude::*;
        let (g, lay) = (self.grid, self.layout);
        let np = g.np();
        let rule = self.rule_kind();
        let mut backs = std::mem::take(&mut self.backs);
        backs.resize_with(self.links.len(), Vec::new);
        let pop = &self.pop;
        let obstacles = &self.obstacles;
        let fused = &self.in_sweep.fused;
        let done = |k: usize| fused.get(k).copied().unwrap_or(false);
        self.forces
            .par_iter_mut()
            .zip(backs.par_iter_mut())
            .zip(self.links.par_iter())
            .enumerate()
            .for_each(|(k, ((force, back_k), links))| {
                if done(k) {
                    back_k.clear();
                    return;
                }
                *force = obstacle_rules(g, lay, &obstacles[k], links, rule, back_k, |(q, n)| {
                    pop.get_slot(np, q, n)
                });
            });
        for (links, back_k) in self.links.iter().zip(&backs) {
            for (l, &b) in links.iter().zip(back_k) {
                let (q, n) = g.slot(lay, l.node as usize, OPP[l.alpha as usize]);
                self.pop.set_slot(np, q, n, b);
            }
        }
        self.backs = backs;
    }

    fn apply_sources(&mut self) {
        let (g, lay) = (self.grid, self.layout);
        for s in &self.sources {
            if s.rate == 0.0 {
                continue;
            }
            for &n in &s.nodes {
                let n = n as usize;
                if self.owner[n] != NONE {
                    continue;
                }
                for q in 0..Q {
                    let i = g.loc(lay, n, q);
                    self.pop.set(i, self.pop.get(i) + W[q] * s.rate);
                }
                self.injected += s.rate;
            }
        }
    }

    /// Interior coordinates of padded node `n`.
    fn ij(&self, n: usize) -> (isize, isize) {
        let w = self.grid.stride();
        ((n % w) as isize - 1, (n / w) as isize - 1)
    }

    /// The image of coordinate `x` along axis `a` nearest to `c` (periodic axes).
    fn near(&self, a: usize, x: f64, c: f64) -> f64 {
        if self.cfg.periodic[a] {
            // both in the first period (or close to it): one image shift at most
            let n = if a == 0 { self.grid.nx } else { self.grid.ny } as f64;
            let d = x - c;
            if d > 0.5 * n {
                x - n
            } else if d < -0.5 * n {
                x + n
            } else {
                x
            }
        } else {
            x
        }
    }

    /// Position of padded node `n`, as the image nearest to obstacle `k`'s centre.
    fn position_near(&self, k: usize, n: usize) -> [f64; 2] {
        let (i, j) = self.ij(n);
        let c = self.obstacles[k].shape.center();
        [
            self.near(0, self.gx(i), c[0]),
            self.near(1, j as f64 + 0.5, c[1]),
        ]
    }

    /// Rigid-body velocity of obstacle `k` at padded node `n`.
    fn body_velocity(&self, k: usize, n: usize) -> [f64; 2] {
        self.obstacles[k].velocity_at(self.position_near(k, n))
    }

    /// Padded node of interior coordinates `(i, j)` wrapped along periodic axes, or `None`
    /// outside the box.
    fn wrap(&self, i: isize, j: isize) -> Option<usize> {
        let (nx, ny) = (self.grid.nx as isize, self.grid.ny as isize);
        let per = self.cfg.periodic;
        let w = |x: isize, n: isize, p: bool| {
            if (0..n).contains(&x) {
                Some(x)
            } else if p {
                Some(x.rem_euclid(n))
            } else {
                None
            }
        };
        Some(self.grid.node(w(i, nx, per[0])?, w(j, ny, per[1])?))
    }

    /// Nodes whose centre lies in obstacle `k` (wrapped, sorted, deduplicated) into
    /// `scratch.nodes`.
    fn raster(&mut self, k: usize) {
        let shape = self.obstacles[k].shape;
        let [lo, hi] = shape.bounds();
        let (i0, j0, i1, j1) = if let Shape::Hollow { .. } = shape {
            // solid beyond its circle: the whole lattice
            (
                self.x0,
                0,
                self.x0 + self.grid.nx as isize - 1,
                self.grid.ny as isize - 1,
            )
        } else {
            (
                (lo[0] - 0.5).floor() as isize,
                (lo[1] - 0.5).floor() as isize,
                (hi[0] - 0.5).ceil() as isize,
                (hi[1] - 0.5).ceil() as isize,
            )
        };
        let mut out = std::mem::take(&mut self.scratch.nodes);
        out.clear();
        let mut margin = 0.0;
        if let Shape::Circle { center, radius } = shape {
            // nodes beyond one spacing outside the scanned box are at least that far from
            // the surface
            margin = 1.0f64;
            for j in j0 - 1..=j1 + 1 {
                let dy = j as f64 + 0.5 - center[1];
                for i in i0 - 1..=i1 + 1 {
                    let dx = i as f64 + 0.5 - center[0];
                    let r = (dx * dx + dy * dy).sqrt();
                    margin = margin.min((r - radius).abs());
                    if r <= radius
                        && let Some(n) = self.wrap(i - self.x0, j)
                    {
                        out.push(n as u32);
                    }
                }
            }
        } else {
            for j in j0..=j1 {
                for i in i0..=i1 {
                    if shape.contains([i as f64 + 0.5, j as f64 + 0.5])
                        && let Some(n) = self.wrap(i - self.x0, j)
                    {
                        out.push(n as u32);
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        self.scratch.nodes = out;
        self.scratch.raster_at[k] = shape.center();
        self.scratch.margin[k] = margin;
    }

    /// Rasterise obstacle `k` again. Nodes it leaves become fluid (fresh, refilled later by
    /// [`Lattice::refill`]); fluid nodes it takes give it their momentum (with
    /// `bookkeeping`). A node another obstacle owns is left to it.
    fn rasterize(&mut self, k: usize, bookkeeping: bool) {
        self.raster(k);
        let kk = k as u32;
        let mut new = std::mem::take(&mut self.scratch.nodes);
        let mut met = None;
        new.retain(|&n| {
            let o = self.owner[n as usize];
            if o != NONE && o != kk && met.is_none() {
                met = Some(o as usize);
            }
            o == NONE || o == kk
        });
        self.contact[k] = met;
        let old = std::mem::take(&mut self.solid_nodes[k]);
        if new != old {
            let (mut a, mut b) = (0, 0);
            while a < old.len() || b < new.len() {
                let (o, n) = (old.get(a).copied(), new.get(b).copied());
                match (o, n) {
                    (Some(x), Some(y)) if x == y => {
                        a += 1;
                        b += 1;
                    }
                    (Some(x), y) if y.is_none_or(|y| x < y) => {
                        // released
                        let x = x as usize;
                        self.owner[x] = NONE;
                        self.mask[x] = 1;
                        self.runs.touch(x / self.grid.stride() - 1);
                        self.scratch.fresh[x] = true;
                        self.scratch.released.push((x as u32, kk));
                        self.scratch.changed.push(x as u32);
                        a += 1;
                    }
                    (_, Some(y)) => {
                        // covered
                        let y = y as usize;
                        if self.scratch.fresh[y] {
                            self.scratch.fresh[y] = false;
                        } else if bookkeeping {
                            let (rho, u) = self.fluid_moments(y);
                            let p = self.position_near(k, y);
                            let c = self.obstacles[k].shape.center();
                            let m = [rho * u[0], rho * u[1]];
                            let e = &mut self.exchange[k];
                            e[0] += m[0];
                            e[1] += m[1];
                            e[2] += (p[0] - c[0]) * m[1] - (p[1] - c[1]) * m[0];
                        }
                        self.owner[y] = kk;
                        self.mask[y] = 0;
                        self.runs.touch(y / self.grid.stride() - 1);
                        self.scratch.changed.push(y as u32);
                        b += 1;
                    }
                    _ => unreachable!("merge of two sorted lists"),
                }
            }
            self.scratch.dirty[k] = true;
        }
        self.scratch.nodes = old;
        self.solid_nodes[k] = new;
    }

    /// Refill the nodes released in this update and still fluid: `f^eq(ρ̄, u_w)`, `ρ̄` the
    /// mean density of the neighbours that were fluid before; the body that released a node
    /// loses the momentum it now carries.
    fn refill(&mut self) {
        let g = self.grid;
        let released = std::mem::take(&mut self.scratch.released);
        for &(n, k) in &released {
            let (n, k) = (n as usize, k as usize);
            if self.owner[n] != NONE {
                continue;
            }
            let (i, j) = self.ij(n);
            let (mut sum, mut cnt) = (0.0, 0usize);
            for q in 1..Q {
                if let Some(m) = self.wrap(i + C[q][0] as isize, j + C[q][1] as isize)
                    && self.owner[m] == NONE
                    && !self.scratch.fresh[m]
                {
                    sum += self.fluid_moments(m).0;
                    cnt += 1;
                }
            }
            let rho = if cnt > 0 { sum / cnt as f64 } else { 1.0 };
            let p = self.position_near(k, n);
            let u = self.obstacles[k].velocity_at(p);
            let a = self.cfg.accel;
            let ue = [u[0] - 0.5 * a[0], u[1] - 0.5 * a[1]];
            for q in 0..Q {
                self.pop.set(g.loc(self.layout, n, q), feq(q, rho, ue));
            }
            let c = self.obstacles[k].shape.center();
            let m = [rho * u[0], rho * u[1]];
            let e = &mut self.exchange[k];
            e[0] -= m[0];
            e[1] -= m[1];
            e[2] -= (p[0] - c[0]) * m[1] - (p[1] - c[1]) * m[0];
        }
        for &(n, _) in &released {
            self.scratch.fresh[n as usize] = false;
        }
        let mut released = released;
        released.clear();
        self.scratch.released = released;
    }

    /// Padded node `(i + di, j + dj)` of padded node `n` at `(i, j)`, wrapped along
    /// periodic axes, or `None` outside the box.
    #[inline]
    fn offset(&self, n: usize, (i, j): (isize, isize), di: isize, dj: isize) -> Option<usize> {
        let (nx, ny) = (self.grid.nx as isize, self.grid.ny as isize);
        if i >= 2 && j >= 2 && i < nx - 2 && j < ny - 2 {
            Some((n as isize + dj * self.grid.stride() as isize + di) as usize)
        } else {
            self.wrap(i + di, j + dj)
        }
    }

    /// Mark the obstacles whose cut links see a changed node, rebuild their links, update
    /// `δ` of the other moved obstacles (in parallel over obstacles), clear the flags.
    fn finish_update(&mut self) {
        let changed = std::mem::take(&mut self.scratch.changed);
        for &n in &changed {
            let n = n as usize;
            let ij = self.ij(n);
            for dj in -2..=2 {
                for di in -2..=2 {
                    if let Some(m) = self.offset(n, ij, di, dj) {
                        let o = self.owner[m];
                        if o != NONE {
                            self.scratch.dirty[o as usize] = true;
                        }
                    }
                }
            }
        }
        let mut changed = changed;
        changed.clear();
        self.scratch.changed = changed;
        let tol = self.geometry_tolerance;
        let work: Vec<LinkWork> = (0..self.obstacles.len())
            .map(|k| {
                if self.scratch.dirty[k] {
                    LinkWork::Rebuild
                } else if self.scratch.moved[k]
                    && moved_by(&self.scratch.linked_at[k], &self.obstacles[k].shape) > tol
                {
                    LinkWork::Deltas
                } else {
                    LinkWork::Keep
                }
            })
            .collect();
        let mut links = std::mem::take(&mut self.links);
        {
            use rayon::prelude::*;
            let this = &*self;
            links
                .par_iter_mut()
                .zip(work.par_iter())
                .enumerate()
                .for_each(|(k, (l, w))| match w {
                    LinkWork::Rebuild => this.build_links(k, l),
                    LinkWork::Deltas => this.update_deltas(k, l),
                    LinkWork::Keep => {}
                });
        }
        self.links = links;
        for (k, w) in work.iter().enumerate() {
            if *w == LinkWork::Rebuild {
                self.link_rows[k] = self.rows_of_links(k);
            }
            if *w != LinkWork::Keep {
                self.scratch.linked_at[k] = self.obstacles[k].shape;
            }
            self.scratch.dirty[k] = false;
            self.scratch.moved[k] = false;
        }
    }

    /// `δ` and the wall point of a link from fluid node at `p` along `a` into obstacle
    /// `k`.
    #[inline]
    fn link_geometry(&self, k: usize, p: [f64; 2], a: usize) -> (f64, [f64; 2]) {
        let c = cf(a);
        let delta = self.obstacles[k].shape.entry(p, c);
        (delta, [p[0] + delta * c[0], p[1] + delta * c[1]])
    }

    fn update_deltas(&self, k: usize, links: &mut [ObstacleLink]) {
        let c = self.obstacles[k].shape.center();
        for l in links {
            // the centre may have been brought back into the first period
            l.p = [self.near(0, l.p[0], c[0]), self.near(1, l.p[1], c[1])];
            (l.delta, l.xw) = self.link_geometry(k, l.p, l.alpha as usize);
        }
    }

    fn build_links(&self, k: usize, links: &mut Vec<ObstacleLink>) {
        links.clear();
        for &b in &self.solid_nodes[k] {
            let b = b as usize;
            let ij = self.ij(b);
            for a in 1..Q {
                let (cx, cy) = (C[a][0] as isize, C[a][1] as isize);
                let Some(xf) = self.offset(b, ij, -cx, -cy) else {
                    continue;
                };
                if self.owner[xf] != NONE {
                    continue;
                }
                let f2 = match self.offset(b, ij, -2 * cx, -2 * cy) {
                    Some(m) if self.owner[m] == NONE => m as u32,
                    _ => NONE,
                };
                let p = self.position_near(k, xf);
                let (delta, xw) = self.link_geometry(k, p, a);
                links.push(ObstacleLink {
                    node: xf as u32,
                    alpha: a as u8,
                    delta,
                    f2,
                    xw,
                    p,
                });
            }
        }
    }

    /// The first and last interior row of obstacle `k`'s cut links' fluid nodes; `None`
    /// if it has no link or one lies within two nodes of the box's edge (where the
    /// sides' rules and the periodic copies act).
    fn rows_of_links(&self, k: usize) -> Option<(u32, u32)> {
        let (nx, ny) = (self.grid.nx as isize, self.grid.ny as isize);
        let mut rows: Option<(u32, u32)> = None;
        for l in &self.links[k] {
            let (i, j) = self.ij(l.node as usize);
            if i < 2 || j < 2 || i > nx - 3 || j > ny - 3 {
                return None;
            }
            let j = j as u32;
            rows = Some(rows.map_or((j, j), |(lo, hi)| (lo.min(j), hi.max(j))));
        }
        rows
    }

    /// The cut links of obstacle `k`: fluid node `(i, j)`, direction `α` into the body and
    /// `δ` (Mora et al. (2015) eq. 6).
    pub fn cut_links_of(&self, k: usize) -> impl Iterator<Item = (usize, usize, usize, f64)> + '_ {
        self.links[k].iter().map(|l| {
            let (i, j) = self.ij(l.node as usize);
            (i as usize, j as usize, l.alpha as usize, l.delta)
        })
    }

    /// Cut links of all obstacles.
    pub fn cut_links(&self) -> usize {
        self.links.iter().map(Vec::len).sum()
    }
}

/// Largest displacement of a point of shape `b` from where it was in shape `a` (lattice
/// units; a rotation counts at the corners of a box).
fn moved_by(a: &Shape, b: &Shape) -> f64 {
    let (ca, cb) = (a.center(), b.center());
    let d = ((ca[0] - cb[0]).powi(2) + (ca[1] - cb[1]).powi(2)).sqrt();
    match (a, b) {
        (Shape::Box { angle: x, half, .. }, Shape::Box { angle: y, .. }) => {
            d + (x - y).abs() * (half[0] * half[0] + half[1] * half[1]).sqrt()
        }
        _ => d,
    }
}

/// The variant of the obstacle rules in use.
#[derive(Clone, Copy, Debug)]
struct RuleKind {
    /// Galilean-invariant momentum exchange.
    galilean: bool,
    /// Each body's cut links create no mass ([`ObstacleMass::Conserved`]).
    conserve: bool,
}

/// The rules of one obstacle's cut links ([`crate::boundary`]): their unknowns into
/// `back`, in the order of `links`, and the force and torque the fluid exerts on the
/// body. `get((slot, node))` reads the populations after the stream–collide step, in
/// layout `lay`.
#[inline(always)]
fn obstacle_rules(
    g: Grid,
    lay: Layout,
    ob: &Obstacle,
    links: &[ObstacleLink],
    rule: RuleKind,
    back: &mut Vec<f64>,
    get: impl Fn((usize, usize)) -> f64,
) -> [f64; 3] {
    let c = ob.shape.center();
    let mut f = [0.0; 3];
    back.clear();
    // what the rules return, and the mass they create: Σ (back − into)
    let (mut gained, mut weights) = (0.0, 0.0);
    for l in links {
        let a = l.alpha as usize;
        let i = OPP[a];
        let xf = l.node as usize;
        let uw = ob.velocity_at(l.xw);
        let ca = cf(a);
        let wall = 6.0 * W[a] * (ca[0] * uw[0] + ca[1] * uw[1]);
        let into = get(g.slot(lay, g.shift(xf, a), a));
        let b = if l.f2 == NONE {
            into - wall
        } else {
            let d = l.delta;
            ((1.0 - d) * get(g.slot(lay, xf, a))
                + d * into
                + d * get(g.slot(lay, l.f2 as usize, i))
                - wall)
                / (1.0 + d)
        };
        gained += b - into;
        weights += W[a];
        back.push(b);
    }
    if rule.conserve && weights > 0.0 {
        // no net flux through a rigid surface: the mass the rules created goes back,
        // shared by the links in proportion to their weights
        let per_weight = gained / weights;
        for (l, b) in links.iter().zip(back.iter_mut()) {
            *b -= per_weight * W[l.alpha as usize];
        }
    }
    for (l, &b) in links.iter().zip(back.iter()) {
        let a = l.alpha as usize;
        let xf = l.node as usize;
        let uw = ob.velocity_at(l.xw);
        let ca = cf(a);
        let into = get(g.slot(lay, g.shift(xf, a), a));
        // the reference density's share, 2 w_α ρ₀ c_α: only gauge pressure loads the body
        // (zero for a body wetted all round)
        let amb = 2.0 * W[a];
        let df = if rule.galilean {
            [
                (ca[0] - uw[0]) * into - (-ca[0] - uw[0]) * b - amb * ca[0],
                (ca[1] - uw[1]) * into - (-ca[1] - uw[1]) * b - amb * ca[1],
            ]
        } else {
            [ca[0] * (into + b - amb), ca[1] * (into + b - amb)]
        };
        let r = [l.xw[0] - c[0], l.xw[1] - c[1]];
        f[0] += df[0];
        f[1] += df[1];
        f[2] += r[0] * df[1] - r[1] * df[0];
    }
    f
}

/// Scratch of the obstacle rules run inside the sweep, per band of the sweep.
#[derive(Clone, Debug, Default)]
struct InSweep {
    /// Per obstacle: its rules ran inside the sweep of the current step.
    fused: Vec<bool>,
    /// Per band: `(row, obstacle)`, the obstacles whose rules the band applies once it
    /// has stepped `row`.
    bodies: Vec<Vec<(u32, u32)>>,
    /// Per band: the force and torque of each obstacle it applied.
    forces: Vec<Vec<(u32, [f64; 3])>>,
    /// Per band: the unknowns of the obstacle at hand.
    backs: Vec<Vec<f64>>,
}

/// The hook of one band: the rules of its obstacles, each applied and written back as
/// soon as the rows it reads are final ([`BandHook`]).
struct RulesInBand<'a> {
    bodies: &'a [(u32, u32)],
    next: usize,
    obstacles: &'a [Obstacle],
    links: &'a [Vec<ObstacleLink>],
    g: Grid,
    /// The layout after the step.
    lay: Layout,
    rule: RuleKind,
    back: &'a mut Vec<f64>,
    forces: &'a mut Vec<(u32, [f64; 3])>,
}

impl<T: Storage> BandHook<T> for RulesInBand<'_> {
    #[inline(always)]
    fn rows_done(&mut self, last: usize, view: &mut BandView<'_, '_, T>) {
        while let Some(&(row, k)) = self.bodies.get(self.next) {
            if row as usize > last {
                return;
            }
            self.next += 1;
            let (g, lay) = (self.g, self.lay);
            let links = &self.links[k as usize];
            let f = obstacle_rules(
                g,
                lay,
                &self.obstacles[k as usize],
                links,
                self.rule,
                self.back,
                |(q, n)| view.get(q, n),
            );
            for (l, &b) in links.iter().zip(self.back.iter()) {
                let (q, n) = g.slot(lay, l.node as usize, OPP[l.alpha as usize]);
                view.set(q, n, b);
            }
            self.forces.push((k, f));
        }
    }
}
