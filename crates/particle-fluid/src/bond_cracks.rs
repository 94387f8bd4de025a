//! The crack network of a bonded particle model's broken bonds, carried by the cubic law
//! between the lattice nodes at its mouths, and its pressure on the particles.
//!
//! A lattice of spacing `Δx` holds no fluid in a crack narrower than about `Δx`
//! ([`crate::cracks`]); the cracks of a lattice solid open by millimetres where the fluid
//! lattice is centimetres. [`BondCracks`] builds the sub-grid network from the broken bonds
//! and couples it both ways:
//!
//! * **Channels.** Each broken bond between disks `i` and `j` is a channel of aperture
//!   `w = max(|x_j − x_i| − R_i − R_j, w_min)` (the gap of the two disks, floored at the
//!   stated minimum) and length `L = 2 min(R_i, R_j)`, the bond's contact width, along the
//!   face normal to the centre line; both are updated every fluid step from the disks'
//!   positions. It carries `Q = w³ Δp / (12 μ L)` per unit depth (the cubic law of
//!   [`crate::cracks`]) with the crack fluid's viscosity (by default the lattice's).
//! * **Pores.** The two ends of a channel lie in the pores on either side of the bond: the
//!   void of the triangle `i, j, k` with the third disk `k` bonded (initially) to both,
//!   on that side (the nearest one to the bond's midpoint if several), placed at the
//!   radical centre of the three circles; without such a disk, the face's end
//!   `c ± (L/2) t` (`c` the middle of the gap, `t` the face direction). Two broken bonds of
//!   one triangle share its pore, so the channels of a crack that cuts bonded triangles
//!   in turn form one connected network (a crack across a void of four or more disks is
//!   split there, as in [`porofrac_lsm::CrackExtent`]). A pore point within two spacings
//!   of a fluid node is a *mouth*: that node is the pore (the lattice carries it);
//!   otherwise the pore stores the fluid of half of each of its channels, volume
//!   `V = Σ w L / 2`, at density `ρ = m / V`. A pore appears full at the reference
//!   density (the rock's own pore fluid at the ambient pressure; its mass is booked as
//!   [`BondCracks::created_mass`]) and keeps its mass as its channels open or close.
//! * **Exchange.** Per fluid step the pores are advanced implicitly (backward Euler,
//!   Gauss–Seidel on `m'_p (1 + Σ K/V_p) = m_p + Σ K ρ'_other`, with the mouth nodes'
//!   densities held) — the cubic law of a low-viscosity fluid in a millimetre crack moves
//!   many times a pore's content per step, which an explicit exchange cannot — and the
//!   channels then carry `S = K (ρ_a − ρ_b)` from the final densities: each pore gains
//!   exactly what its channels bring and each mouth node gets the opposite as a lattice
//!   source ([`Lattice::set_source_rate`], acting at the end of the step), so lattice plus
//!   pores conserve mass to round-off whether or not the iteration converged. The lattice
//!   nodes stay explicit: a channel between two mouth nodes carries at most `K = ¼` per
//!   step, and a mouth node gives (or takes) at most half of its largest density gap to
//!   the network's ends per step (before or after the solve) — otherwise the fluxes of the whole connected part of
//!   the network it belongs to are scaled down by one factor `f` (counted in
//!   [`CrackSolveStats::limited`]), so that every pore of it moves to `(1 − f) m + f m'`,
//!   between its old and its implicit mass, and stays non-negative — so a network that
//!   stores more than a node cannot make the node overshoot.
//! * **Loads.** The pressure of a channel is the mean gauge pressure of its two ends,
//!   `p = c_s² (ρ̄ − 1)` in lattice units, floored at zero: a pore whose opening outruns
//!   the fluid is at the ambient pressure (the fluid lag of a hydraulic fracture), not
//!   under suction. It pushes the two disks apart along their centre line `n`: `+p L n` on
//!   `j`, `−p L n` on `i`, per metre of depth — equal and opposite forces on one line, so
//!   no net force and no net moment per channel.
//! * **Pockets.** A fluid node the disks enclose alone is a pore the lattice does not
//!   resolve; as the walls around it move apart it is kept at half the reference density
//!   or above ([`crate::pockets`]) instead of being stretched through zero density.

use std::collections::HashMap;

use porofrac_lbm::d2q9::CS2;
use porofrac_lbm::{Lattice, Units};

use crate::pockets::Pockets;
use crate::{CouplingError, ParticleSolver};

/// Options of the crack network.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BondCrackOptions {
    /// Smallest aperture of a channel (m): a broken bond whose disks still touch or
    /// overlap is a channel this wide.
    pub min_aperture: f64,
    /// Kinematic viscosity of the fluid in the cracks (m²/s); `None`: the lattice's.
    pub viscosity: Option<f64>,
}

impl Default for BondCrackOptions {
    fn default() -> Self {
        BondCrackOptions {
            min_aperture: 1.0e-5,
            viscosity: None,
        }
    }
}

/// Largest conductance (lattice mass per step and unit density difference) of a channel
/// between two lattice nodes.
const NODE_TO_NODE_MAX: f64 = 0.25;
/// Gauss–Seidel sweeps of the pore solve at most, and its tolerance (lattice density).
const MAX_SWEEPS: usize = 20_000;
const TOLERANCE: f64 = 1e-13;
/// A mouth node gives or takes at most this fraction of its largest density gap to the
/// network per step.
const MOUTH_LIMIT: f64 = 0.5;

/// Where a channel's end is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum End {
    /// A mouth: index into `nodes`.
    Node(usize),
    /// A pore: index into `pores`.
    Pore(usize),
}

/// Which pore a channel end is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Key {
    /// The void of a bonded triangle (sorted disk indices).
    Triangle([usize; 3]),
    /// The open side (`+1`: left of `i → j`) of the bond `i < j`.
    Open(usize, usize, bool),
}

#[derive(Clone, Copy, Debug)]
struct Channel {
    i: usize,
    j: usize,
    ends: [End; 2],
    /// Lattice units.
    aperture: f64,
    /// Lattice units.
    length: f64,
    /// Unit vector from disk i to disk j.
    normal: [f64; 2],
}

#[derive(Clone, Copy, Debug)]
struct Pore {
    volume: f64,
    mass: f64,
}

/// Measures of the last step of the pore solve.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CrackSolveStats {
    /// Gauss–Seidel sweeps of the last step.
    pub sweeps: usize,
    /// Largest density change of the last sweep (lattice units).
    pub residual: f64,
    /// Largest number of sweeps of any step.
    pub max_sweeps: usize,
    /// Steps whose solve stopped at the sweep limit (its mass is still conserved).
    pub unconverged_steps: u64,
    /// Channel-steps whose flux the mouth limit cut.
    pub limited: u64,
}

/// The crack network of the broken bonds of a particle model (module docs).
#[derive(Clone, Debug)]
pub struct BondCracks {
    options: BondCrackOptions,
    /// Crack fluid viscosity, lattice units.
    nu: f64,
    /// Initial bond neighbours of every disk.
    neighbours: Vec<Vec<usize>>,
    /// Broken bonds taken in.
    seen: usize,
    channels: Vec<Channel>,
    pores: Vec<Pore>,
    keys: HashMap<Key, End>,
    /// Mouth nodes and their lattice source.
    nodes: Vec<((usize, usize), usize)>,
    /// Density of every pore in the solve (scratch).
    rho: Vec<f64>,
    /// Per channel: mass carried in the last step from end 0 to end 1 (lattice units).
    carried: Vec<f64>,
    /// Per channel: gauge pressure of the last step (Pa, floored at 0).
    pressure: Vec<f64>,
    /// Loads on the disks (N/m, N).
    loads: Vec<[f64; 3]>,
    created: f64,
    exchanged: f64,
    stats: CrackSolveStats,
    /// The lattice's one-node pockets, kept from zero density.
    pockets: Pockets,
}

impl BondCracks {
    /// The network of `particles` (no channel until bonds break); `units` of the lattice
    /// the fluid runs on.
    pub fn new<P: ParticleSolver>(
        particles: &P,
        lattice: &Lattice,
        units: &Units,
        options: BondCrackOptions,
    ) -> Result<Self, CouplingError> {
        let w = options.min_aperture;
        if !(w.is_finite() && w > 0.0) {
            return Err(CouplingError::argument(
                "crack min_aperture",
                w,
                "must be a positive length (m)",
            ));
        }
        let nu_lattice = (lattice.config().tau - 0.5) / 3.0;
        let nu = match options.viscosity {
            Some(v) => {
                if !(v.is_finite() && v > 0.0) {
                    return Err(CouplingError::argument(
                        "crack viscosity",
                        v,
                        "must be a positive kinematic viscosity (m²/s)",
                    ));
                }
                v * units.dt / (units.dx * units.dx)
            }
            None => nu_lattice,
        };
        let n = particles.disks().len();
        let mut neighbours = vec![Vec::new(); n];
        for [i, j] in particles.bond_pairs() {
            if i >= n || j >= n || i == j {
                return Err(CouplingError::argument(
                    "bond pair",
                    i.max(j) as f64,
                    "is not a pair of distinct disks",
                ));
            }
            neighbours[i].push(j);
            neighbours[j].push(i);
        }
        for v in &mut neighbours {
            v.sort_unstable();
            v.dedup();
        }
        Ok(BondCracks {
            options,
            nu,
            neighbours,
            seen: 0,
            channels: Vec::new(),
            pores: Vec::new(),
            keys: HashMap::new(),
            nodes: Vec::new(),
            rho: Vec::new(),
            carried: Vec::new(),
            pressure: Vec::new(),
            loads: vec![[0.0; 3]; n],
            created: 0.0,
            exchanged: 0.0,
            stats: CrackSolveStats::default(),
            pockets: Pockets::new(),
        })
    }

    /// The options.
    pub fn options(&self) -> &BondCrackOptions {
        &self.options
    }
    /// Channels (broken bonds taken in).
    pub fn channels(&self) -> usize {
        self.channels.len()
    }
    /// Pores stored by the network (not counting mouths).
    pub fn pores(&self) -> usize {
        self.pores.len()
    }
    /// Lattice nodes at the network's mouths.
    pub fn mouths(&self) -> usize {
        self.nodes.len()
    }
    /// Disks of channel `c`.
    pub fn channel_disks(&self, c: usize) -> [usize; 2] {
        [self.channels[c].i, self.channels[c].j]
    }
    /// Aperture of channel `c` (m) in the last step.
    pub fn aperture(&self, c: usize, units: &Units) -> f64 {
        self.channels[c].aperture * units.dx
    }
    /// Gauge pressure of channel `c` in the last step (Pa, floored at 0).
    pub fn pressure(&self, c: usize) -> f64 {
        self.pressure[c]
    }
    /// Whether channel `c`'s ends are `[mouth?, mouth?]`.
    pub fn mouth_ends(&self, c: usize) -> [bool; 2] {
        self.channels[c].ends.map(|e| matches!(e, End::Node(_)))
    }
    /// The lattice nodes of channel `c`'s two ends (`None`: that end is a pore).
    pub fn mouth_nodes(&self, c: usize) -> [Option<(usize, usize)>; 2] {
        self.channels[c].ends.map(|e| match e {
            End::Node(n) => Some(self.nodes[n].0),
            End::Pore(_) => None,
        })
    }
    /// Mass carried by channel `c` in the last step from its end 0 to end 1 (lattice
    /// units).
    pub fn carried(&self, c: usize) -> f64 {
        self.carried[c]
    }
    /// Loads of the crack pressure on the disks (`[fx, fy, torque]`, N/m, N).
    pub fn loads(&self) -> &[[f64; 3]] {
        &self.loads
    }
    /// Mass in the pores (lattice units).
    pub fn pore_mass(&self) -> f64 {
        self.pores.iter().map(|p| p.mass).sum()
    }
    /// Mass the pores held when they appeared, since the start (lattice units).
    pub fn created_mass(&self) -> f64 {
        self.created
    }
    /// Net mass the network gave to the lattice since the start (lattice units; it is
    /// part of [`Lattice::injected_mass`]).
    pub fn exchanged_mass(&self) -> f64 {
        self.exchanged
    }
    /// The pore solve's measures.
    pub fn stats(&self) -> &CrackSolveStats {
        &self.stats
    }
    /// The lattice's one-node pockets kept from zero density ([`crate::pockets`]).
    pub fn pockets(&self) -> &Pockets {
        &self.pockets
    }

    /// Take in the bonds broken since the last call, refresh every channel from the disks'
    /// positions, advance the pores and set the mouth nodes' sources for the lattice's next
    /// step, and the loads of the crack pressure. Call after the particles are placed on
    /// the lattice and before [`Lattice::step`]; `origin` is the SI position of the
    /// lattice corner.
    pub fn update<P: ParticleSolver>(
        &mut self,
        particles: &P,
        lat: &mut Lattice,
        units: &Units,
        origin: [f64; 2],
    ) -> Result<(), CouplingError> {
        let d = particles.disks();
        if d.len() != self.loads.len() {
            return Err(CouplingError::argument(
                "particles (count)",
                d.len() as f64,
                "differs from the disks the crack network was built with",
            ));
        }
        let pos = |i: usize| {
            [
                (d.x[i][0] - origin[0]) / units.dx,
                (d.x[i][1] - origin[1]) / units.dx,
            ]
        };
        let rad = |i: usize| d.r[i] / units.dx;
        self.pockets.update(lat)?;
        let w_min = self.options.min_aperture / units.dx;
        // new channels
        let mut fresh = Vec::new();
        particles.broken_pairs(self.seen, &mut fresh);
        self.seen += fresh.len();
        for [a, b] in fresh {
            if a >= d.len() || b >= d.len() || a == b {
                return Err(CouplingError::argument(
                    "broken bond",
                    a.max(b) as f64,
                    "is not a pair of distinct disks",
                ));
            }
            let (i, j) = (a.min(b), a.max(b));
            let (xi, xj) = (pos(i), pos(j));
            let e = [xj[0] - xi[0], xj[1] - xi[1]];
            let dist = e[0].hypot(e[1]).max(1e-300);
            let n = [e[0] / dist, e[1] / dist];
            let mut ends = [End::Node(0); 2];
            for (k, left) in [true, false].into_iter().enumerate() {
                let third = self.third(i, j, left, &pos, &rad);
                let (key, at) = match third {
                    Some(t) => {
                        let mut tri = [i, j, t];
                        tri.sort_unstable();
                        let at = radical_centre(
                            [pos(tri[0]), pos(tri[1]), pos(tri[2])],
                            [rad(tri[0]), rad(tri[1]), rad(tri[2])],
                        );
                        (Key::Triangle(tri), at)
                    }
                    None => {
                        let gap = (dist - rad(i) - rad(j)).max(0.0);
                        let c = [
                            xi[0] + n[0] * (rad(i) + 0.5 * gap),
                            xi[1] + n[1] * (rad(i) + 0.5 * gap),
                        ];
                        let h = rad(i).min(rad(j));
                        let s = if left { 1.0 } else { -1.0 };
                        let t = [-n[1] * s, n[0] * s];
                        (Key::Open(i, j, left), [c[0] + h * t[0], c[1] + h * t[1]])
                    }
                };
                ends[k] = self.resolve(lat, key, at)?;
            }
            self.channels.push(Channel {
                i,
                j,
                ends,
                aperture: w_min,
                length: 2.0 * rad(i).min(rad(j)),
                normal: n,
            });
            self.carried.push(0.0);
            self.pressure.push(0.0);
        }
        // geometry now
        for ch in &mut self.channels {
            let (xi, xj) = (pos(ch.i), pos(ch.j));
            let e = [xj[0] - xi[0], xj[1] - xi[1]];
            let dist = e[0].hypot(e[1]);
            if dist > 0.0 {
                ch.normal = [e[0] / dist, e[1] / dist];
            }
            ch.aperture = (dist - rad(ch.i) - rad(ch.j)).max(w_min);
            ch.length = 2.0 * rad(ch.i).min(rad(ch.j));
        }
        for p in &mut self.pores {
            p.volume = 0.0;
        }
        for ch in &self.channels {
            for e in ch.ends {
                if let End::Pore(p) = e {
                    self.pores[p].volume += 0.5 * ch.aperture * ch.length;
                }
            }
        }
        // new pores start full at the reference density
        for p in &mut self.pores {
            if p.mass.is_nan() {
                p.mass = p.volume;
                self.created += p.volume;
            }
        }
        self.solve(lat)?;
        // loads
        for l in &mut self.loads {
            *l = [0.0; 3];
        }
        let node_rho: Vec<Option<f64>> = self
            .nodes
            .iter()
            .map(|&((x, y), _)| (!lat.is_solid(x, y)).then(|| lat.moments(x, y).0))
            .collect();
        for (c, ch) in self.channels.iter().enumerate() {
            let rho = |e: End| match e {
                End::Node(k) => node_rho[k],
                End::Pore(p) => Some(self.rho[p]),
            };
            let (a, b) = (rho(ch.ends[0]), rho(ch.ends[1]));
            let mean = match (a, b) {
                (Some(a), Some(b)) => 0.5 * (a + b),
                (Some(a), None) | (None, Some(a)) => a,
                (None, None) => 1.0,
            };
            let p = units.pressure_si(mean).max(0.0);
            self.pressure[c] = p;
            let f = p * ch.length * units.dx;
            let (fx, fy) = (f * ch.normal[0], f * ch.normal[1]);
            self.loads[ch.j][0] += fx;
            self.loads[ch.j][1] += fy;
            self.loads[ch.i][0] -= fx;
            self.loads[ch.i][1] -= fy;
        }
        Ok(())
    }

    /// The disk bonded at the start to both `i` and `j`, on the left (or right) of
    /// `i → j`, nearest to the bond's middle.
    fn third(
        &self,
        i: usize,
        j: usize,
        left: bool,
        pos: &impl Fn(usize) -> [f64; 2],
        rad: &impl Fn(usize) -> f64,
    ) -> Option<usize> {
        let (xi, xj) = (pos(i), pos(j));
        let m = [0.5 * (xi[0] + xj[0]), 0.5 * (xi[1] + xj[1])];
        let e = [xj[0] - xi[0], xj[1] - xi[1]];
        let (a, b) = (&self.neighbours[i], &self.neighbours[j]);
        let mut best: Option<(usize, f64)> = None;
        let (mut p, mut q) = (0, 0);
        while p < a.len() && q < b.len() {
            match a[p].cmp(&b[q]) {
                std::cmp::Ordering::Less => p += 1,
                std::cmp::Ordering::Greater => q += 1,
                std::cmp::Ordering::Equal => {
                    let k = a[p];
                    let xk = pos(k);
                    let cross = e[0] * (xk[1] - xi[1]) - e[1] * (xk[0] - xi[0]);
                    if (cross > 0.0) == left && cross != 0.0 {
                        let dist = (xk[0] - m[0]).hypot(xk[1] - m[1]) - rad(k);
                        if best.is_none_or(|(_, d)| dist < d) {
                            best = Some((k, dist));
                        }
                    }
                    p += 1;
                    q += 1;
                }
            }
        }
        best.map(|(k, _)| k)
    }

    /// The end of pore `key` at lattice point `at`: the pore or mouth it already is, a
    /// mouth at the nearest fluid node within two spacings, or a new pore.
    fn resolve(&mut self, lat: &mut Lattice, key: Key, at: [f64; 2]) -> Result<End, CouplingError> {
        if let Some(&e) = self.keys.get(&key) {
            return Ok(e);
        }
        let end = match crate::cracks::nearest_fluid(lat, at) {
            Some(n) => match self.nodes.iter().position(|(x, _)| *x == n) {
                Some(k) => End::Node(k),
                None => {
                    let s = lat.add_source(&[n])?;
                    self.nodes.push((n, s));
                    End::Node(self.nodes.len() - 1)
                }
            },
            None => {
                self.pores.push(Pore {
                    volume: 0.0,
                    mass: f64::NAN,
                });
                self.rho.push(1.0);
                End::Pore(self.pores.len() - 1)
            }
        };
        self.keys.insert(key, end);
        Ok(end)
    }

    /// `K = w³ c_s² / (12 ν L)` of channel `c` (lattice mass per step and unit density
    /// difference), limited between two mouth nodes.
    fn conductance(&self, c: usize) -> f64 {
        let ch = &self.channels[c];
        let k = ch.aperture.powi(3) * CS2 / (12.0 * self.nu * ch.length);
        match ch.ends {
            [End::Node(_), End::Node(_)] => k.min(NODE_TO_NODE_MAX),
            _ => k,
        }
    }

    /// Backward Euler on the pores, then the channels' fluxes and the mouths' sources.
    fn solve(&mut self, lat: &mut Lattice) -> Result<(), CouplingError> {
        let node_rho: Vec<Option<f64>> = self
            .nodes
            .iter()
            .map(|&((x, y), _)| (!lat.is_solid(x, y)).then(|| lat.moments(x, y).0))
            .collect();
        let k: Vec<f64> = (0..self.channels.len())
            .map(|c| self.conductance(c))
            .collect();
        let active = |ch: &Channel| {
            ch.ends[0] != ch.ends[1]
                && ch.ends.iter().all(|e| match *e {
                    End::Node(n) => node_rho[n].is_some(),
                    End::Pore(_) => true,
                })
        };
        // per pore: its channels
        let mut of_pore: Vec<Vec<usize>> = vec![Vec::new(); self.pores.len()];
        for (c, ch) in self.channels.iter().enumerate() {
            if !active(ch) {
                continue;
            }
            for e in ch.ends {
                if let End::Pore(p) = e {
                    of_pore[p].push(c);
                }
            }
        }
        for (r, p) in self.rho.iter_mut().zip(&self.pores) {
            *r = p.mass / p.volume;
        }
        let mut sweeps = 0;
        let mut residual = 0.0;
        if !self.pores.is_empty() {
            while sweeps < MAX_SWEEPS {
                residual = 0.0f64;
                for (p, list) in of_pore.iter().enumerate() {
                    let pore = self.pores[p];
                    let (mut s, mut r) = (0.0, 0.0);
                    for &c in list {
                        let ch = &self.channels[c];
                        let other = if ch.ends[0] == End::Pore(p) {
                            ch.ends[1]
                        } else {
                            ch.ends[0]
                        };
                        let rho_o = match other {
                            End::Node(n) => node_rho[n].unwrap_or(1.0),
                            End::Pore(q) => self.rho[q],
                        };
                        s += k[c];
                        r += k[c] * rho_o;
                    }
                    let new = (pore.mass + r) / (pore.volume + s);
                    residual = residual.max((new - self.rho[p]).abs());
                    self.rho[p] = new;
                }
                sweeps += 1;
                if residual <= TOLERANCE {
                    break;
                }
            }
        }
        self.stats.sweeps = sweeps;
        self.stats.residual = residual;
        self.stats.max_sweeps = self.stats.max_sweeps.max(sweeps);
        if residual > TOLERANCE {
            self.stats.unconverged_steps += 1;
        }
        // fluxes from the final densities, limited at the mouths (a node gives or takes at
        // most half its largest density gap to the network before the solve)
        let mut rate = vec![0.0; self.nodes.len()];
        let mut cap = vec![0.0f64; self.nodes.len()];
        for (c, ch) in self.channels.iter().enumerate() {
            self.carried[c] = 0.0;
            if !active(ch) {
                continue;
            }
            let rho = |e: End| match e {
                End::Node(n) => node_rho[n].unwrap_or(1.0),
                End::Pore(p) => self.rho[p],
            };
            let old = |e: End| match e {
                End::Node(n) => node_rho[n].unwrap_or(1.0),
                End::Pore(p) => self.pores[p].mass / self.pores[p].volume,
            };
            let s = k[c] * (rho(ch.ends[0]) - rho(ch.ends[1]));
            let gap = (old(ch.ends[0]) - old(ch.ends[1]))
                .abs()
                .max((rho(ch.ends[0]) - rho(ch.ends[1])).abs());
            for (e, sign) in [(ch.ends[0], -1.0), (ch.ends[1], 1.0)] {
                if let End::Node(n) = e {
                    rate[n] += sign * s;
                    cap[n] = cap[n].max(MOUTH_LIMIT * gap);
                }
            }
            self.carried[c] = s;
        }
        // one factor per connected part of the network (the smallest of its mouths'), so
        // every pore moves to `(1 − f) m + f m'`, between two non-negative masses
        let nn = self.nodes.len();
        let id = |e: End| match e {
            End::Node(n) => n,
            End::Pore(p) => nn + p,
        };
        let mut part: Vec<usize> = (0..nn + self.pores.len()).collect();
        fn root(part: &mut [usize], mut a: usize) -> usize {
            while part[a] != a {
                part[a] = part[part[a]];
                a = part[a];
            }
            a
        }
        for ch in &self.channels {
            if active(ch) {
                let (a, b) = (
                    root(&mut part, id(ch.ends[0])),
                    root(&mut part, id(ch.ends[1])),
                );
                part[a] = b;
            }
        }
        let mut factor = vec![1.0f64; part.len()];
        for (n, (r, c)) in rate.iter().zip(&cap).enumerate() {
            if r.abs() > *c {
                let k = root(&mut part, n);
                factor[k] = factor[k].min(c / r.abs());
            }
        }
        rate.fill(0.0);
        let mut gain = vec![0.0; self.pores.len()];
        for (c, ch) in self.channels.iter().enumerate() {
            let f = if active(ch) {
                factor[root(&mut part, id(ch.ends[0]))]
            } else {
                1.0
            };
            if f < 1.0 {
                self.stats.limited += 1;
            }
            let s = self.carried[c] * f;
            self.carried[c] = s;
            for (e, sign) in [(ch.ends[0], -1.0), (ch.ends[1], 1.0)] {
                match e {
                    End::Node(n) => rate[n] += sign * s,
                    End::Pore(p) => gain[p] += sign * s,
                }
            }
        }
        for ((p, g), r) in self.pores.iter_mut().zip(gain).zip(&mut self.rho) {
            p.mass += g;
            *r = p.mass / p.volume;
        }
        for (n, r) in rate.into_iter().enumerate() {
            if node_rho[n].is_some() {
                self.exchanged += r;
            }
            lat.set_source_rate(self.nodes[n].1, r)?;
        }
        Ok(())
    }
}

/// The point of equal power `|x − c|² − r²` to three circles (inside the void of three
/// touching circles); the centroid of the centres when they are collinear.
fn radical_centre(c: [[f64; 2]; 3], r: [f64; 3]) -> [f64; 2] {
    let pow = |k: usize| c[k][0] * c[k][0] + c[k][1] * c[k][1] - r[k] * r[k];
    let (a11, a12) = (2.0 * (c[1][0] - c[0][0]), 2.0 * (c[1][1] - c[0][1]));
    let (a21, a22) = (2.0 * (c[2][0] - c[0][0]), 2.0 * (c[2][1] - c[0][1]));
    let (b1, b2) = (pow(1) - pow(0), pow(2) - pow(0));
    let det = a11 * a22 - a12 * a21;
    let scale = (a11.abs() + a12.abs()) * (a21.abs() + a22.abs());
    if det.abs() <= 1e-12 * scale {
        return [
            (c[0][0] + c[1][0] + c[2][0]) / 3.0,
            (c[0][1] + c[1][1] + c[2][1]) / 3.0,
        ];
    }
    [(b1 * a22 - b2 * a12) / det, (a11 * b2 - a21 * b1) / det]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radical_centre_of_three_equal_touching_circles_is_their_centroid() {
        let h = 3f64.sqrt();
        let p = radical_centre([[0.0, 0.0], [2.0, 0.0], [1.0, h]], [1.0; 3]);
        assert!(
            (p[0] - 1.0).abs() < 1e-14 && (p[1] - h / 3.0).abs() < 1e-14,
            "{p:?}"
        );
        // equal power to all three
        let c = [[0.0, 0.0], [3.0, 0.5], [1.0, 2.5]];
        let r = [1.2, 0.7, 0.4];
        let p = radical_centre(c, r);
        let pw: Vec<f64> = (0..3)
            .map(|k| (p[0] - c[k][0]).powi(2) + (p[1] - c[k][1]).powi(2) - r[k] * r[k])
            .collect();
        assert!((pw[0] - pw[1]).abs() < 1e-12 && (pw[0] - pw[2]).abs() < 1e-12);
    }
}
