//! The lattice: populations, geometry and boundary lists, and the step that ties them.

use crate::LbmError;
use crate::boundary::{
    CopyLink, MomentumExchange, ObstacleLink, PressureLink, Side, SideKind, SideLink,
};
use crate::collision::{Collision, Rates};
use crate::d2q9::{C, OPP, Q, W, cf, feq};
use crate::geometry::Shape;
use crate::kernel::{Grid, Layout, Physics, aa_step};

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

/// A D2Q9 lattice with its boundaries and obstacles.
#[derive(Clone, Debug)]
pub struct Lattice {
    cfg: LatticeConfig,
    grid: Grid,
    rates: Rates,
    pop: Vec<f64>,
    layout: Layout,
    /// 1 fluid, 0 solid (padded).
    mask: Vec<u8>,
    /// Obstacle owning a solid node, or NONE.
    owner: Vec<u32>,
    obstacles: Vec<Obstacle>,
    solid_nodes: Vec<Vec<u32>>,
    forces: Vec<[f64; 3]>,
    copies: Vec<CopyLink>,
    side_links: Vec<SideLink>,
    pressure_links: Vec<PressureLink>,
    obstacle_links: Vec<ObstacleLink>,
    steps: u64,
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
            pop: vec![0.0; Q * np],
            layout: Layout::Natural,
            mask: vec![1; np],
            owner: vec![NONE; np],
            obstacles: Vec::new(),
            solid_nodes: Vec::new(),
            forces: Vec::new(),
            copies: Vec::new(),
            side_links: Vec::new(),
            pressure_links: Vec::new(),
            obstacle_links: Vec::new(),
            steps: 0,
            cfg,
        };
        l.build_side_links();
        l.init(|_| (1.0, [0.0, 0.0]));
        Ok(l)
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
    /// Bytes of population storage.
    pub fn population_bytes(&self) -> usize {
        self.pop.len() * std::mem::size_of::<f64>()
    }

    /// Set every interior fluid node to the equilibrium of `(ρ, u) = f(node position)`.
    /// Velocities are corrected by half the body force (Guo), so that the velocity read back
    /// is the one given.
    pub fn init(&mut self, f: impl Fn([f64; 2]) -> (f64, [f64; 2])) {
        let g = self.grid;
        for j in 0..g.ny as isize {
            for i in 0..g.nx as isize {
                let node = g.node(i, j);
                let p = [i as f64 + 0.5, j as f64 + 0.5];
                let (rho, u) = if self.owner[node] == NONE {
                    f(p)
                } else {
                    (
                        1.0,
                        self.obstacles[self.owner[node] as usize].velocity_at(p),
                    )
                };
                let u = [
                    u[0] - 0.5 * self.cfg.accel[0],
                    u[1] - 0.5 * self.cfg.accel[1],
                ];
                for q in 0..Q {
                    self.pop[g.loc(self.layout, node, q)] = feq(q, rho, u);
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

    /// Add an obstacle; it must lie inside the box. Returns its index.
    pub fn add_obstacle(&mut self, ob: Obstacle) -> Result<usize, LbmError> {
        let k = self.obstacles.len();
        self.check_inside(k, &ob.shape)?;
        self.obstacles.push(ob);
        self.solid_nodes.push(Vec::new());
        self.forces.push([0.0; 3]);
        self.rasterize(k, false);
        self.build_obstacle_links();
        Ok(k)
    }

    /// The obstacles.
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// Prescribe the motion of obstacle `k` for the next steps (the hook for coupled
    /// bodies: set the velocities before every [`Lattice::step`]).
    pub fn set_obstacle_motion(&mut self, k: usize, velocity: [f64; 2], angular_velocity: f64) {
        self.obstacles[k].velocity = velocity;
        self.obstacles[k].angular_velocity = angular_velocity;
    }

    /// Force `(fx, fy)` and torque on obstacle `k` from the last step (lattice units,
    /// momentum exchange over the cut links).
    pub fn force(&self, k: usize) -> [f64; 3] {
        self.forces[k]
    }

    /// Whether an interior node is solid.
    pub fn is_solid(&self, i: usize, j: usize) -> bool {
        self.owner[self.grid.node(i as isize, j as isize)] != NONE
    }

    /// Interior fluid nodes.
    pub fn fluid_nodes(&self) -> usize {
        self.grid.nx * self.grid.ny - self.solid_nodes.iter().map(Vec::len).sum::<usize>()
    }

    /// Density and velocity of interior node `(i, j)` (solid nodes: 1 and the body's
    /// velocity).
    pub fn moments(&self, i: usize, j: usize) -> (f64, [f64; 2]) {
        let g = self.grid;
        let node = g.node(i as isize, j as isize);
        if self.owner[node] != NONE {
            let p = [i as f64 + 0.5, j as f64 + 0.5];
            return (
                1.0,
                self.obstacles[self.owner[node] as usize].velocity_at(p),
            );
        }
        let (mut rho, mut jx, mut jy) = (0.0, 0.0, 0.0);
        for q in 0..Q {
            let f = self.pop[g.loc(self.layout, node, q)];
            rho += f;
            jx += C[q][0] as f64 * f;
            jy += C[q][1] as f64 * f;
        }
        let a = self.cfg.accel;
        (rho, [jx / rho + 0.5 * a[0], jy / rho + 0.5 * a[1]])
    }

    /// Population `f_q` arriving at interior node `(i, j)`.
    pub fn population(&self, i: usize, j: usize, q: usize) -> f64 {
        self.pop[self
            .grid
            .loc(self.layout, self.grid.node(i as isize, j as isize), q)]
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

    /// One time step: collide and stream every node, apply the boundary lists, sum the
    /// obstacle forces, then move the obstacles (refilling uncovered nodes).
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
        let mask = if self.obstacles.is_empty() {
            None
        } else {
            Some(&self.mask[..])
        };
        self.layout = aa_step(&mut self.pop, self.grid, self.layout, mask, phys);
        self.apply_copies();
        self.apply_sides();
        self.apply_obstacles();
        self.steps += 1;
        if self
            .obstacles
            .iter()
            .any(|o| o.velocity != [0.0, 0.0] || o.angular_velocity != 0.0)
        {
            self.move_obstacles()?;
        }
        Ok(())
    }

    fn check_inside(&self, k: usize, s: &Shape) -> Result<(), LbmError> {
        let [lo, hi] = s.bounds();
        let n = [self.grid.nx as f64, self.grid.ny as f64];
        for a in 0..2 {
            let inside = lo[a] >= 0.0 && hi[a] <= n[a];
            // Along a periodic axis a body may also span the whole period (a wall).
            let spans = self.cfg.periodic[a] && lo[a] <= 0.0 && hi[a] >= n[a];
            if !(inside || spans) {
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
                            let p = [i as f64 + 0.5, j as f64 + 0.5];
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
            self.pop[g.loc(lay, c.dst as usize, q)] = self.pop[g.loc(lay, c.src as usize, q)];
        }
    }

    fn apply_sides(&mut self) {
        let (g, lay) = (self.grid, self.layout);
        for l in &self.side_links {
            let i = l.dir as usize;
            let a = OPP[i];
            let xb = g.shift(l.node as usize, a);
            let cu = C[i][0] as f64 * l.u[0] + C[i][1] as f64 * l.u[1];
            self.pop[g.loc(lay, l.node as usize, i)] =
                self.pop[g.loc(lay, xb, a)] + 6.0 * W[i] * cu;
        }
        let acc = self.cfg.accel;
        for l in &self.pressure_links {
            let x = l.node as usize;
            let (mut rho, mut jx, mut jy) = (0.0, 0.0, 0.0);
            for q in 0..Q {
                let f = self.pop[g.loc(lay, g.shift(x, q), q)];
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
            self.pop[g.loc(lay, x, i)] = -self.pop[g.loc(lay, xb, a)]
                + 2.0 * W[i] * l.density * (1.0 + 4.5 * cu * cu - 1.5 * usq);
        }
    }

    fn apply_obstacles(&mut self) {
        let (g, lay) = (self.grid, self.layout);
        for f in &mut self.forces {
            *f = [0.0; 3];
        }
        let gi = self.cfg.momentum_exchange == MomentumExchange::GalileanInvariant;
        for l in &self.obstacle_links {
            let a = l.alpha as usize;
            let i = OPP[a];
            let xf = l.node as usize;
            let ob = &self.obstacles[l.obstacle as usize];
            let uw = ob.velocity_at(l.xw);
            let ca = cf(a);
            let wall = 6.0 * W[a] * (ca[0] * uw[0] + ca[1] * uw[1]);
            let into = self.pop[g.loc(lay, g.shift(xf, a), a)];
            let back = if l.f2 == NONE {
                into - wall
            } else {
                let d = l.delta;
                ((1.0 - d) * self.pop[g.loc(lay, xf, a)]
                    + d * into
                    + d * self.pop[g.loc(lay, l.f2 as usize, i)]
                    - wall)
                    / (1.0 + d)
            };
            self.pop[g.loc(lay, xf, i)] = back;
            let df = if gi {
                [
                    (ca[0] - uw[0]) * into - (-ca[0] - uw[0]) * back,
                    (ca[1] - uw[1]) * into - (-ca[1] - uw[1]) * back,
                ]
            } else {
                [ca[0] * (into + back), ca[1] * (into + back)]
            };
            let c = ob.shape.center();
            let r = [l.xw[0] - c[0], l.xw[1] - c[1]];
            let f = &mut self.forces[l.obstacle as usize];
            f[0] += df[0];
            f[1] += df[1];
            f[2] += r[0] * df[1] - r[1] * df[0];
        }
    }

    /// Mark the nodes inside obstacle `k`; with `refill`, give the nodes it uncovered the
    /// equilibrium at the mean density of their fluid neighbours and the body's velocity.
    fn rasterize(&mut self, k: usize, refill: bool) {
        let g = self.grid;
        let old = std::mem::take(&mut self.solid_nodes[k]);
        for &n in &old {
            self.owner[n as usize] = NONE;
            self.mask[n as usize] = 1;
        }
        let shape = self.obstacles[k].shape;
        let [lo, hi] = shape.bounds();
        let i0 = (lo[0] - 0.5).floor().max(0.0) as isize;
        let j0 = (lo[1] - 0.5).floor().max(0.0) as isize;
        let i1 = ((hi[0] - 0.5).ceil() as isize).min(g.nx as isize - 1);
        let j1 = ((hi[1] - 0.5).ceil() as isize).min(g.ny as isize - 1);
        let mut now = Vec::new();
        for j in j0..=j1 {
            for i in i0..=i1 {
                let n = g.node(i, j);
                if self.owner[n] == NONE && shape.contains([i as f64 + 0.5, j as f64 + 0.5]) {
                    self.owner[n] = k as u32;
                    self.mask[n] = 0;
                    now.push(n as u32);
                }
            }
        }
        self.solid_nodes[k] = now;
        if refill {
            for &n in &old {
                let n = n as usize;
                if self.owner[n] != NONE {
                    continue;
                }
                let (mut sum, mut cnt) = (0.0, 0usize);
                for q in 1..Q {
                    let m = g.shift(n, q);
                    let (mi, mj) = (m % g.stride(), m / g.stride());
                    if mi >= 1
                        && mi <= g.nx
                        && mj >= 1
                        && mj <= g.ny
                        && self.owner[m] == NONE
                        && !old.contains(&(m as u32))
                    {
                        let rho: f64 = (0..Q).map(|p| self.pop[g.loc(self.layout, m, p)]).sum();
                        sum += rho;
                        cnt += 1;
                    }
                }
                let rho = if cnt > 0 { sum / cnt as f64 } else { 1.0 };
                let p = [(n % g.stride()) as f64 - 0.5, (n / g.stride()) as f64 - 0.5];
                let u = self.obstacles[k].velocity_at(p);
                for q in 0..Q {
                    self.pop[g.loc(self.layout, n, q)] = feq(q, rho, u);
                }
            }
        }
    }

    fn move_obstacles(&mut self) -> Result<(), LbmError> {
        for k in 0..self.obstacles.len() {
            let ob = &self.obstacles[k];
            if ob.velocity == [0.0, 0.0] && ob.angular_velocity == 0.0 {
                continue;
            }
            let mut s = ob.shape;
            s.advance(ob.velocity, ob.angular_velocity);
            // A body spanning a periodic axis keeps its centre in the first period.
            let [lo, hi] = s.bounds();
            let n = [self.grid.nx as f64, self.grid.ny as f64];
            let c = s.center();
            for a in 0..2 {
                if self.cfg.periodic[a]
                    && lo[a] <= 0.0
                    && hi[a] >= n[a]
                    && hi[a] - lo[a] >= 2.0 * n[a]
                {
                    let mut d = [0.0, 0.0];
                    d[a] = c[a].rem_euclid(n[a]) - c[a];
                    s.advance(d, 0.0);
                }
            }
            self.check_inside(k, &s)?;
            self.obstacles[k].shape = s;
            self.rasterize(k, true);
        }
        self.build_obstacle_links();
        Ok(())
    }

    fn build_obstacle_links(&mut self) {
        let g = self.grid;
        let (nx, ny) = (g.nx as isize, g.ny as isize);
        let per = self.cfg.periodic;
        self.obstacle_links.clear();
        let wrap = |i: isize, n: isize, p: bool| -> Option<isize> {
            if (0..n).contains(&i) {
                Some(i)
            } else if p {
                Some(i.rem_euclid(n))
            } else {
                None
            }
        };
        for (k, nodes) in self.solid_nodes.iter().enumerate() {
            let shape = self.obstacles[k].shape;
            for &b in nodes {
                let b = b as usize;
                let (bi, bj) = ((b % g.stride()) as isize - 1, (b / g.stride()) as isize - 1);
                for a in 1..Q {
                    let (fi, fj) = (bi - C[a][0] as isize, bj - C[a][1] as isize);
                    let (Some(wi), Some(wj)) = (wrap(fi, nx, per[0]), wrap(fj, ny, per[1])) else {
                        continue;
                    };
                    let xf = g.node(wi, wj);
                    if self.owner[xf] != NONE {
                        continue;
                    }
                    let p = [fi as f64 + 0.5, fj as f64 + 0.5];
                    let c = cf(a);
                    let delta = shape.entry(p, c);
                    let f2 = match (
                        wrap(fi - C[a][0] as isize, nx, per[0]),
                        wrap(fj - C[a][1] as isize, ny, per[1]),
                    ) {
                        (Some(i2), Some(j2)) if self.owner[g.node(i2, j2)] == NONE => {
                            g.node(i2, j2) as u32
                        }
                        _ => NONE,
                    };
                    self.obstacle_links.push(ObstacleLink {
                        node: xf as u32,
                        alpha: a as u8,
                        delta,
                        f2,
                        obstacle: k as u32,
                        xw: [p[0] + delta * c[0], p[1] + delta * c[1]],
                    });
                }
            }
        }
    }

    /// Cut links of all obstacles.
    pub fn cut_links(&self) -> usize {
        self.obstacle_links.len()
    }
}
