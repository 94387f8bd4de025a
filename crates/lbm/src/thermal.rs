//! Temperature as a passive scalar on a D2Q5 lattice, advected by the fluid of a
//! [`Lattice`], with its own diffusivity inside obstacles (conjugate heat transfer).
//!
//! `g_i^eq = w_i T (1 + 3 c_i·u)` with `w = 1/3` (rest) and `1/6` (axes), `T = Σ g_i`,
//! BGK relaxation with `τ_g` per node: `χ = c_s² (τ_g − ½)` in the fluid and `χ_s` in solid
//! nodes (a passive-scalar form in place of the internal-energy equilibrium of Mora et al. (2015)
//! eqs. 4–5, which as printed carries no temperature; their solid distribution `h` is the
//! same lattice with the solid relaxation time, so heat crosses the interface without an
//! extra rule: with equal `ρ c_p` on both sides the flux is continuous to first order).
//! Solid nodes are advected with the body's velocity.
//!
//! Sides, on the halfway link between the last node `x_f` and the ghost node:
//! * periodic;
//! * fixed temperature `T_w`: anti-bounce-back `g_ī(x_f) = −g*_i(x_f) + 2 w_i T_w`;
//! * fixed flux `q` (into the box, lattice units `q Δt/Δx`, temperature times velocity):
//!   `g_ī(x_f) = g*_i(x_f) + q`, so exactly `q` per link and step enters (0: adiabatic).
//!
//! * outflow: zero gradient, `g_ī(x_f) = g*_ī(x_f)` (what the last node sends inwards is
//!   what comes in: advected heat leaves, nothing is reflected).
//!
//! Collision conserves `T` at every node and streaming moves it, so with periodic and
//! adiabatic sides `Σ T` is constant to round-off, and a flux side adds exactly `q` per link
//! and step.
//!
//! **Bookkeeping.** With `ρ c_p` the same in solid and fluid, the heat of a node is
//! `ρ c_p Δx² T` per unit depth, and the step balance is exact:
//! `Σ T(t+1) − Σ T(t) = Σ_sides` [`Thermal::side_heat`] increments. Per obstacle,
//! [`Thermal::obstacle_heat`] is what left its nodes in the last step towards any node it
//! does not cover (fluid, another obstacle or a side): for an obstacle that does not move,
//! `Σ_{its nodes} T` drops by exactly that. A moving obstacle also takes or leaves the
//! heat of the nodes it covers or uncovers (the heat stays on the lattice).
//!
//! **Held nodes** ([`Thermal::hold`]): solid grains kept at a temperature by a reservoir
//! (a Dirichlet condition on the solid); after the collision their populations are the
//! equilibrium at rest at that temperature, and [`Thermal::held_heat`] is what this took
//! from the reservoir in the step.
//!
//! **Heat books** ([`Thermal::keep_books`], [`HeatBooks`]): per step, over the fluid nodes
//! of the step, the change of the stored heat against conduction and advection through the
//! sides and the heat the solid nodes gave, exact to round-off.

use rayon::prelude::*;

use crate::LbmError;
use crate::boundary::Side;
use crate::lattice::Lattice;

const C5: [[isize; 2]; 5] = [[0, 0], [1, 0], [0, 1], [-1, 0], [0, -1]];
const W5: [f64; 5] = [1.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0];
const OPP5: [usize; 5] = [0, 3, 4, 1, 2];

/// The condition on a side for the temperature (ignored on periodic axes).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum ThermalSide {
    /// No flux.
    #[default]
    Adiabatic,
    /// Fixed temperature.
    Temperature(f64),
    /// Fixed flux into the box (lattice units).
    Flux(f64),
    /// Zero-gradient outflow.
    Outflow,
}

/// The temperature lattice.
#[derive(Clone, Debug)]
pub struct Thermal {
    nx: usize,
    ny: usize,
    periodic: [bool; 2],
    sides: [ThermalSide; 4],
    omega_fluid: f64,
    omega_solid: f64,
    /// Populations (padded, node-major).
    g: Vec<[f64; 5]>,
    post: Vec<[f64; 5]>,
    /// Heat that entered through each side since the start (Σ T units).
    side_heat: [f64; 4],
    /// Heat that left each obstacle's nodes in the last step.
    obstacle_heat: Vec<f64>,
    /// Nodes held at a temperature (padded index, temperature).
    held: Vec<(usize, f64)>,
    /// Heat the held nodes took from their reservoir in the last step.
    held_heat: f64,
    /// The books of the last step, when kept ([`Thermal::keep_books`]).
    books: Option<HeatBooks>,
}

/// The heat books of one step over the fluid nodes of that step (lattice units:
/// temperature × nodes; `ρ c_p Δx²` per unit depth turns them into J/m).
///
/// `stored_after − stored_before = conduction_in + advection_in − advection_out + solids`
/// to round-off, where:
/// * `solids` is the net heat the solid nodes (grains, obstacles) gave the fluid nodes
///   across their links (what hot grains give);
/// * through the sides that are not periodic, the net of each link (what enters minus
///   what leaves) is split into an advective part `u_n T` and the remainder,
///   `conduction_in` (the diffusive flux, `−χ ∂T/∂n` to first order): on a side of fixed
///   temperature (an inlet) `T` is that temperature, on an outflow side the node's; `u_n`
///   is the velocity of the node into the box; the part is `advection_in` or
///   `advection_out` by its sign. Adiabatic and flux sides carry no advection (a wall lets
///   no fluid through).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HeatBooks {
    /// `Σ T` over the step's fluid nodes before the step.
    pub stored_before: f64,
    /// `Σ T` over the same nodes after the step.
    pub stored_after: f64,
    /// Diffusive heat in through the sides.
    pub conduction_in: f64,
    /// Advected heat in through the sides.
    pub advection_in: f64,
    /// Advected heat out through the sides.
    pub advection_out: f64,
    /// Heat the solid nodes gave the fluid nodes.
    pub solids: f64,
}

impl HeatBooks {
    /// `stored_after − stored_before − (conduction_in + advection_in − advection_out +
    /// solids)`: zero to round-off.
    pub fn defect(&self) -> f64 {
        (self.stored_after - self.stored_before)
            - (self.conduction_in + self.advection_in - self.advection_out + self.solids)
    }
}

/// What a temperature field carries from one step to the next ([`Thermal::raw_state`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ThermalState {
    /// The distributions.
    pub g: Vec<[f64; 5]>,
    /// The post-collision distributions of the last step.
    pub post: Vec<[f64; 5]>,
    /// Heat through each side since the start.
    pub side_heat: [f64; 4],
    /// The last step's heat out of each obstacle.
    pub obstacle_heat: Vec<f64>,
}

impl Thermal {
    /// A temperature lattice matching `lat`, with relaxation times `tau` (fluid) and
    /// `tau_solid` (obstacles), at temperature `t0(position)` (lattice coordinates).
    pub fn new(
        lat: &Lattice,
        tau: f64,
        tau_solid: f64,
        sides: [ThermalSide; 4],
        t0: impl Fn([f64; 2]) -> f64,
    ) -> Result<Self, LbmError> {
        for t in [tau, tau_solid] {
            if !(t > crate::TAU_MIN && t.is_finite()) {
                return Err(LbmError::Tau(t));
            }
        }
        let (nx, ny) = lat.size();
        let np = (nx + 2) * (ny + 2);
        let mut th = Thermal {
            nx,
            ny,
            periodic: lat.config().periodic,
            sides,
            omega_fluid: 1.0 / tau,
            omega_solid: 1.0 / tau_solid,
            g: vec![[0.0; 5]; np],
            post: vec![[0.0; 5]; np],
            side_heat: [0.0; 4],
            obstacle_heat: vec![0.0; lat.obstacles().len()],
            held: Vec::new(),
            held_heat: 0.0,
            books: None,
        };
        // a window of a bigger lattice ([`Lattice::window`]) starts at column `x0` of the box
        let x0 = lat.origin();
        for j in 0..ny {
            for i in 0..nx {
                let t = t0([(i + x0) as f64 + 0.5, j as f64 + 0.5]);
                let u = lat.moments(i, j).1;
                th.g[(j + 1) * (nx + 2) + i + 1] = equilibrium(t, u);
            }
        }
        Ok(th)
    }

    /// The distributions as stored (padded, node-major) and the padded row length (the
    /// slab exchange).
    #[cfg(feature = "mpi")]
    pub(crate) fn stored_mut(&mut self) -> (&mut [[f64; 5]], usize) {
        (&mut self.g, self.nx + 2)
    }

    /// Temperature of interior node `(i, j)`.
    pub fn temperature(&self, i: usize, j: usize) -> f64 {
        self.g[(j + 1) * (self.nx + 2) + i + 1].iter().sum()
    }

    /// `Σ T` over all interior nodes.
    pub fn total(&self) -> f64 {
        (0..self.ny)
            .map(|j| (0..self.nx).map(|i| self.temperature(i, j)).sum::<f64>())
            .sum()
    }

    /// Heat that entered through each side `xmin, xmax, ymin, ymax` since the start
    /// (lattice units: temperature × nodes).
    pub fn side_heat(&self) -> [f64; 4] {
        self.side_heat
    }

    /// The state carried from one step to the next ([`ThermalState`]), for a checkpoint.
    pub fn raw_state(&self) -> ThermalState {
        ThermalState {
            g: self.g.clone(),
            post: self.post.clone(),
            side_heat: self.side_heat,
            obstacle_heat: self.obstacle_heat.clone(),
        }
    }

    /// Put back what [`Thermal::raw_state`] gave, into a field built the same way; `Err`
    /// says which array does not fit.
    pub fn restore_raw_state(&mut self, s: ThermalState) -> Result<(), String> {
        if s.g.len() != self.g.len() || s.post.len() != self.post.len() {
            return Err(format!(
                "{} temperature nodes, the lattice has {}",
                s.g.len(),
                self.g.len()
            ));
        }
        if s.obstacle_heat.len() != self.obstacle_heat.len() {
            return Err(format!(
                "{} obstacle heats, the lattice has {} obstacles",
                s.obstacle_heat.len(),
                self.obstacle_heat.len()
            ));
        }
        self.g = s.g;
        self.post = s.post;
        self.side_heat = s.side_heat;
        self.obstacle_heat = s.obstacle_heat;
        Ok(())
    }

    /// Heat that left obstacle `k`'s nodes in the last step (lattice units).
    pub fn obstacle_heat(&self, k: usize) -> f64 {
        self.obstacle_heat.get(k).copied().unwrap_or(0.0)
    }

    /// `Σ T` over the nodes obstacle `k` of `lat` covers.
    pub fn obstacle_total(&self, lat: &Lattice, k: usize) -> f64 {
        lat.obstacle_nodes(k)
            .map(|(i, j)| self.temperature(i, j))
            .sum()
    }

    /// Mean temperature of the nodes obstacle `k` of `lat` covers (`None` if it covers none).
    pub fn obstacle_temperature(&self, lat: &Lattice, k: usize) -> Option<f64> {
        let n = lat.obstacle_nodes(k).count();
        (n > 0).then(|| self.obstacle_total(lat, k) / n as f64)
    }

    /// Mean temperature of every interior node whose centre lies within `radius` of `center`
    /// (lattice units), or `None` if there is none.
    pub fn mean_in_disk(&self, center: [f64; 2], radius: f64) -> Option<f64> {
        let (mut s, mut n) = (0.0, 0usize);
        let j0 = (center[1] - radius - 0.5).floor().max(0.0) as usize;
        let j1 = ((center[1] + radius - 0.5).ceil().max(0.0) as usize).min(self.ny - 1);
        let i0 = (center[0] - radius - 0.5).floor().max(0.0) as usize;
        let i1 = ((center[0] + radius - 0.5).ceil().max(0.0) as usize).min(self.nx - 1);
        for j in j0..=j1 {
            for i in i0..=i1 {
                let d = [i as f64 + 0.5 - center[0], j as f64 + 0.5 - center[1]];
                if d[0] * d[0] + d[1] * d[1] <= radius * radius {
                    s += self.temperature(i, j);
                    n += 1;
                }
            }
        }
        (n > 0).then(|| s / n as f64)
    }

    /// Set interior node `(i, j)` to temperature `t` (equilibrium at rest).
    pub fn set_temperature(&mut self, i: usize, j: usize, t: f64) {
        self.g[(j + 1) * (self.nx + 2) + i + 1] = equilibrium(t, [0.0, 0.0]);
    }

    /// Hold interior nodes `nodes` at temperature `t` (a Dirichlet condition on solid
    /// grains kept hot by a reservoir): from now on their post-collision populations are
    /// the equilibrium at rest at `t`, and the heat this takes from the reservoir is
    /// [`Thermal::held_heat`].
    pub fn hold(&mut self, nodes: impl IntoIterator<Item = (usize, usize)>, t: f64) {
        let w = self.nx + 2;
        for (i, j) in nodes {
            self.set_temperature(i, j, t);
            self.held.push(((j + 1) * w + i + 1, t));
        }
    }

    /// Heat the held nodes ([`Thermal::hold`]) took from their reservoir in the last step
    /// (`Σ (t − T)` over them, `T` their temperature before the step).
    pub fn held_heat(&self) -> f64 {
        self.held_heat
    }

    /// Keep the books of every step from now on ([`HeatBooks`], [`Thermal::books`]).
    pub fn keep_books(&mut self) {
        self.books = Some(HeatBooks::default());
    }

    /// The books of the last step (`None` unless [`Thermal::keep_books`] was called).
    pub fn books(&self) -> Option<HeatBooks> {
        self.books
    }

    /// One step with the velocities of `lat` (call before `lat.step()`, so both use the
    /// same time level).
    pub fn step(&mut self, lat: &Lattice) {
        let (nx, ny) = (self.nx, self.ny);
        let w = nx + 2;
        let (of, os) = (self.omega_fluid, self.omega_solid);
        let g = &self.g;
        self.post
            .par_chunks_mut(w)
            .enumerate()
            .for_each(|(jp, row)| {
                if jp == 0 || jp > ny {
                    return;
                }
                let j = jp - 1;
                for i in 0..nx {
                    let n = jp * w + i + 1;
                    let t: f64 = g[n].iter().sum();
                    let (_, u) = lat.moments(i, j);
                    let om = if lat.is_solid(i, j) { os } else { of };
                    let eq = equilibrium(t, u);
                    for q in 0..5 {
                        row[i + 1][q] = g[n][q] - om * (g[n][q] - eq[q]);
                    }
                }
            });
        if !self.held.is_empty() {
            let mut taken = 0.0;
            for &(n, t) in &self.held {
                taken += t - self.g[n].iter().sum::<f64>();
                self.post[n] = equilibrium(t, [0.0, 0.0]);
            }
            self.held_heat = taken;
        }
        self.fill_ghosts();
        self.sum_obstacle_heat(lat);
        let mut books = self.books.map(|_| self.books_before(lat));
        let post = &self.post;
        self.g.par_chunks_mut(w).enumerate().for_each(|(jp, row)| {
            if jp == 0 || jp > ny {
                return;
            }
            for ip in 1..=nx {
                for q in 0..5 {
                    let src =
                        ((jp as isize - C5[q][1]) as usize) * w + (ip as isize - C5[q][0]) as usize;
                    row[ip][q] = post[src][q];
                }
            }
        });
        if let Some(b) = &mut books {
            b.stored_after = self.fluid_total(lat);
            self.books = Some(*b);
        }
    }

    /// `Σ T` over the fluid nodes of `lat`.
    fn fluid_total(&self, lat: &Lattice) -> f64 {
        let mut s = 0.0;
        for j in 0..self.ny {
            for i in 0..self.nx {
                if !lat.is_solid(i, j) {
                    s += self.temperature(i, j);
                }
            }
        }
        s
    }

    /// The books of this step but `stored_after`, from the post-collision populations and
    /// the filled ghosts: every link between a fluid node and a solid node or a side.
    fn books_before(&self, lat: &Lattice) -> HeatBooks {
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        let w = self.nx + 2;
        let idx = |i: isize, j: isize| ((j + 1) as usize) * w + (i + 1) as usize;
        let mut b = HeatBooks {
            stored_before: self.fluid_total(lat),
            ..HeatBooks::default()
        };
        for j in 0..ny {
            for i in 0..nx {
                if lat.is_solid(i as usize, j as usize) {
                    continue;
                }
                let n = idx(i, j);
                for q in 1..5 {
                    // the neighbour whose population q arrives here
                    let (mi, mj) = (i - C5[q][0], j - C5[q][1]);
                    let inside = (0..nx).contains(&mi) && (0..ny).contains(&mj);
                    let (wi, wj) = (
                        if self.periodic[0] {
                            mi.rem_euclid(nx)
                        } else {
                            mi
                        },
                        if self.periodic[1] {
                            mj.rem_euclid(ny)
                        } else {
                            mj
                        },
                    );
                    let wrapped = (0..nx).contains(&wi) && (0..ny).contains(&wj);
                    let net = self.post[idx(mi, mj)][q] - self.post[n][OPP5[q]];
                    if wrapped {
                        if lat.is_solid(wi as usize, wj as usize) {
                            b.solids += net;
                        }
                        continue;
                    }
                    debug_assert!(!inside);
                    let side = match (mi < 0, mi >= nx, mj < 0) {
                        (true, _, _) => Side::XMin,
                        (_, true, _) => Side::XMax,
                        (_, _, true) => Side::YMin,
                        _ => Side::YMax,
                    };
                    // heat is advected through a side of fixed temperature (an inlet) or
                    // an outflow; adiabatic and flux sides only conduct
                    let t = match self.sides[side.index()] {
                        ThermalSide::Temperature(t) => Some(t),
                        ThermalSide::Outflow => Some(self.temperature(i as usize, j as usize)),
                        ThermalSide::Adiabatic | ThermalSide::Flux(_) => None,
                    };
                    let adv = t.map_or(0.0, |t| {
                        let u = lat.moments(i as usize, j as usize).1;
                        ((C5[q][0] as f64) * u[0] + (C5[q][1] as f64) * u[1]) * t
                    });
                    if adv >= 0.0 {
                        b.advection_in += adv;
                    } else {
                        b.advection_out -= adv;
                    }
                    b.conduction_in += net - adv;
                }
            }
        }
        b
    }

    /// What leaves each obstacle's nodes in this step towards nodes it does not cover
    /// (after the ghosts are filled, so a side's incoming population is known).
    fn sum_obstacle_heat(&mut self, lat: &Lattice) {
        let n_ob = lat.obstacles().len();
        self.obstacle_heat.resize(n_ob, 0.0);
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        let w = self.nx + 2;
        for k in 0..n_ob {
            let mut out = 0.0;
            for (i, j) in lat.obstacle_nodes(k) {
                let (i, j) = (i as isize, j as isize);
                let n = ((j + 1) as usize) * w + (i + 1) as usize;
                for q in 1..5 {
                    let (mi, mj) = (i + C5[q][0], j + C5[q][1]);
                    let wi = if self.periodic[0] {
                        mi.rem_euclid(nx)
                    } else {
                        mi
                    };
                    let wj = if self.periodic[1] {
                        mj.rem_euclid(ny)
                    } else {
                        mj
                    };
                    if (0..nx).contains(&wi)
                        && (0..ny).contains(&wj)
                        && lat.owner(wi as usize, wj as usize) == Some(k)
                    {
                        continue;
                    }
                    // the neighbour's population towards this node (a ghost on a side holds
                    // what enters there, periodic or not)
                    let m = ((mj + 1) as usize) * w + (mi + 1) as usize;
                    out += self.post[n][q] - self.post[m][OPP5[q]];
                }
            }
            self.obstacle_heat[k] = out;
        }
    }

    /// Ghost populations that stream into the box: periodic copies or the side rules.
    fn fill_ghosts(&mut self) {
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        let w = self.nx + 2;
        let idx = |i: isize, j: isize| ((j + 1) as usize) * w + (i + 1) as usize;
        for side in Side::ALL {
            let (q_in, len) = match side {
                Side::XMin => (1, ny),
                Side::XMax => (3, ny),
                Side::YMin => (2, nx),
                Side::YMax => (4, nx),
            };
            let periodic = self.periodic[side.axis()];
            for s in 0..len {
                // ghost node, the interior node it feeds, the node across the box
                let (ghost, node, across) = match side {
                    Side::XMin => ((-1, s), (0, s), (nx - 1, s)),
                    Side::XMax => ((nx, s), (nx - 1, s), (0, s)),
                    Side::YMin => ((s, -1), (s, 0), (s, ny - 1)),
                    Side::YMax => ((s, ny), (s, ny - 1), (s, 0)),
                };
                let g = idx(ghost.0, ghost.1);
                let value = if periodic {
                    self.post[idx(across.0, across.1)][q_in]
                } else {
                    let out = self.post[idx(node.0, node.1)][OPP5[q_in]];
                    let v = match self.sides[side.index()] {
                        ThermalSide::Adiabatic => out,
                        ThermalSide::Flux(q) => out + q,
                        ThermalSide::Temperature(t) => -out + 2.0 * W5[q_in] * t,
                        ThermalSide::Outflow => self.post[idx(node.0, node.1)][q_in],
                    };
                    self.side_heat[side.index()] += v - out;
                    v
                };
                self.post[g][q_in] = value;
            }
        }
    }
}

fn equilibrium(t: f64, u: [f64; 2]) -> [f64; 5] {
    std::array::from_fn(|q| {
        W5[q] * t * (1.0 + 3.0 * (C5[q][0] as f64 * u[0] + C5[q][1] as f64 * u[1]))
    })
}
