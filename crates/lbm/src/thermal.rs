//! Temperature as a passive scalar on a D2Q5 lattice, advected by the fluid of a
//! [`Lattice`], with its own diffusivity inside obstacles (conjugate heat transfer).
//!
//! `g_i^eq = w_i T (1 + 3 c_i·u)` with `w = 1/3` (rest) and `1/6` (axes), `T = Σ g_i`,
//! BGK relaxation with `τ_g` per node: `χ = c_s² (τ_g − ½)` in the fluid and `χ_s` in solid
//! nodes (seed §002.2, the recommended passive-scalar form; the solid distribution `h` of
//! the seed is the same lattice with the solid relaxation time, so heat crosses the
//! interface without an extra rule: with equal `ρ c_p` on both sides the flux is continuous
//! to first order). Solid nodes are advected with the body's velocity.
//!
//! Sides, on the halfway link between the last node `x_f` and the ghost node:
//! * periodic;
//! * fixed temperature `T_w`: anti-bounce-back `g_ī(x_f) = −g*_i(x_f) + 2 w_i T_w`;
//! * fixed flux `q` (into the box, lattice units `q Δt/Δx`, temperature times velocity):
//!   `g_ī(x_f) = g*_i(x_f) + q`, so exactly `q` per link and step enters (0: adiabatic).
//!
//! Collision conserves `T` at every node and streaming moves it, so with periodic and
//! adiabatic sides `Σ T` is constant to round-off, and a flux side adds exactly `q` per link
//! and step.

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
        };
        for j in 0..ny {
            for i in 0..nx {
                let t = t0([i as f64 + 0.5, j as f64 + 0.5]);
                let u = lat.moments(i, j).1;
                th.g[(j + 1) * (nx + 2) + i + 1] = equilibrium(t, u);
            }
        }
        Ok(th)
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
        self.fill_ghosts();
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
                    match self.sides[side.index()] {
                        ThermalSide::Adiabatic => out,
                        ThermalSide::Flux(q) => out + q,
                        ThermalSide::Temperature(t) => -out + 2.0 * W5[q_in] * t,
                    }
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
