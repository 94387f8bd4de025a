//! Fluid in cracks narrower than the lattice: a sub-grid flow along crack channels (the
//! openings of broken bonds between particles) that exchanges mass with the lattice nodes
//! at their two mouths.
//!
//! A lattice with spacing `Δx` holds no fluid node in a gap narrower than about `2Δx`
//! (module docs of the crate), so a crack a millimetre wide in a rock resolved at 5 cm
//! stays dry. A [`CrackChannel`] carries that flow with the cubic law of a slot of
//! aperture `w` and length `L` (per unit depth, laminar, parallel walls):
//!
//! `Q = w³ Δp / (12 μ L)`
//!
//! between the lattice fluid nodes at its two mouths, `Δp = c_s² (ρ_a − ρ_b)` the
//! lattice pressure difference of those nodes and `μ = ρ₀ ν`. In lattice units (`Δx = Δt =
//! ρ₀ = 1`) the mass carried per step is `S = K (ρ_a − ρ_b)`, `K = w³ c_s² / (12 ν L)`; it
//! is taken from mouth `a` and given to mouth `b` as mass sources at rest (`f_α += w_α S`,
//! [`Lattice::set_source_rate`]) after the lattice step, so what one node loses the other
//! gains: the fluid's mass is conserved to round-off. The exchange is explicit; a mouth
//! node whose channels' `Σ K` exceeds ½ would overshoot (the density difference would
//! change sign within a step), which is refused ([`CrackError::TooWide`]): such a crack is
//! wide enough for the lattice to carry it.
//!
//! **Mouths and pores.** Each end of a channel is attached to the fluid node nearest to it
//! within two spacings (a mouth). An end with no fluid node that near is a *pore* of the
//! crack network inside the rock: ends within 1e-6 spacings of each other are the same
//! pore, which joins its channels. A pore stores the fluid of half of each of its channels,
//! volume `V = Σ w L / 2` (per unit depth), at density `ρ = m / V` (the lattice's equation
//! of state, `p = c_s² ρ`), starting at the reference density; it is advanced with the
//! same explicit fluxes, so the mass of lattice plus pores is conserved to round-off. A
//! mouth that an obstacle covers later carries nothing in that step. The explicit
//! exchange needs `Σ K` of a mouth node below ½ and `Σ K / V` of a pore below ½
//! ([`CrackError::TooWide`]; for a pore `K/V ∝ w²/L²`, so only a crack wide and short
//! against the spacing is refused).
//!
//! The network of a lattice solid's broken bonds, with its pressure on the particles and
//! its coupling to [`crate::ParticleFluid`], is [`crate::bond_cracks`].

use porofrac_lbm::d2q9::CS2;
use porofrac_lbm::{Lattice, LbmError};

/// One crack channel between two points of the lattice (lattice units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrackChannel {
    /// Its two ends (lattice coordinates: node `(i, j)` at `(i + ½, j + ½)`).
    pub ends: [[f64; 2]; 2],
    /// Aperture (spacings), below the spacing for a sub-grid crack.
    pub aperture: f64,
    /// Length along the flow (spacings).
    pub length: f64,
}

/// Errors of the crack flow.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CrackError {
    /// An aperture or length that is not positive and finite, or an end that is not
    /// finite.
    #[error(
        "crack channel {channel}: {what} = {value} must be finite (and positive for an aperture or length)"
    )]
    Value {
        /// The channel.
        channel: usize,
        /// Which value.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A mouth node or pore whose channels conduct too much for the explicit exchange.
    #[error(
        "{what} at ({x:.3}, {y:.3}): its crack channels conduct {k:.3} of its content per \
         step (limit 0.5); a crack that wide is carried by the lattice itself"
    )]
    TooWide {
        /// "lattice node" or "crack pore".
        what: &'static str,
        /// Its position (lattice units).
        x: f64,
        /// Its position (lattice units).
        y: f64,
        /// `Σ K` (node) or `Σ K / V` (pore).
        k: f64,
    },
    /// An error of the lattice.
    #[error(transparent)]
    Lbm(#[from] LbmError),
}

/// Where a channel's end is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum End {
    /// A mouth: index into `nodes`.
    Node(usize),
    /// A pore of the network: index into `pores`.
    Pore(usize),
}

/// A pore of the crack network.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Pore {
    at: [f64; 2],
    volume: f64,
    mass: f64,
}

/// The crack channels of a lattice and their mass exchange.
#[derive(Clone, Debug)]
pub struct CrackFlow {
    channels: Vec<CrackChannel>,
    /// Per channel: where its ends are.
    ends: Vec<[End; 2]>,
    /// Mouth nodes and their lattice source.
    nodes: Vec<((usize, usize), usize)>,
    pores: Vec<Pore>,
    /// Lattice kinematic viscosity.
    nu: f64,
    /// Mass carried by each channel in the last step, from end 0 to end 1.
    carried: Vec<f64>,
    /// Mass carried by each channel since the start, from end 0 to end 1.
    cumulative: Vec<f64>,
}

impl CrackFlow {
    /// Attach `channels` to `lat` (its relaxation time gives the viscosity). Mouths are
    /// found now, from the nodes that are fluid now; the pores start at the reference
    /// density 1.
    pub fn new(lat: &mut Lattice, channels: Vec<CrackChannel>) -> Result<Self, CrackError> {
        let nu = (lat.config().tau - 0.5) / 3.0;
        let mut nodes: Vec<((usize, usize), usize)> = Vec::new();
        let mut pores: Vec<Pore> = Vec::new();
        let mut ends = Vec::with_capacity(channels.len());
        for (c, ch) in channels.iter().enumerate() {
            if let Some(&v) = ch.ends.iter().flatten().find(|v| !v.is_finite()) {
                return Err(CrackError::Value {
                    channel: c,
                    what: "end coordinate",
                    value: v,
                });
            }
            for (what, value) in [("aperture", ch.aperture), ("length", ch.length)] {
                if !(value.is_finite() && value > 0.0) {
                    return Err(CrackError::Value {
                        channel: c,
                        what,
                        value,
                    });
                }
            }
            let mut e = [End::Pore(0); 2];
            for k in 0..2 {
                let p = ch.ends[k];
                e[k] = match nearest_fluid(lat, p) {
                    Some(n) => match nodes.iter().position(|(x, _)| *x == n) {
                        Some(i) => End::Node(i),
                        None => {
                            let s = lat.add_source(&[n])?;
                            nodes.push((n, s));
                            End::Node(nodes.len() - 1)
                        }
                    },
                    None => {
                        let near = pores
                            .iter()
                            .position(|q| (q.at[0] - p[0]).hypot(q.at[1] - p[1]) < 1e-6);
                        let i = near.unwrap_or_else(|| {
                            pores.push(Pore {
                                at: p,
                                volume: 0.0,
                                mass: 0.0,
                            });
                            pores.len() - 1
                        });
                        End::Pore(i)
                    }
                };
            }
            ends.push(e);
        }
        let mut flow = CrackFlow {
            carried: vec![0.0; channels.len()],
            cumulative: vec![0.0; channels.len()],
            channels,
            ends,
            nodes,
            pores,
            nu,
        };
        flow.set_volumes();
        for p in &mut flow.pores {
            p.mass = p.volume;
        }
        flow.check_conductance()?;
        Ok(flow)
    }

    /// Pore volumes from the channels' apertures (the mass stays).
    fn set_volumes(&mut self) {
        for p in &mut self.pores {
            p.volume = 0.0;
        }
        for (c, e) in self.ends.iter().enumerate() {
            let ch = &self.channels[c];
            for end in e {
                if let End::Pore(i) = *end {
                    self.pores[i].volume += 0.5 * ch.aperture * ch.length;
                }
            }
        }
    }

    /// `K = w³ c_s² / (12 ν L)` of channel `c` (mass per step and unit density difference).
    pub fn conductance(&self, c: usize) -> f64 {
        let ch = &self.channels[c];
        ch.aperture.powi(3) * CS2 / (12.0 * self.nu * ch.length)
    }

    fn check_conductance(&self) -> Result<(), CrackError> {
        let mut kn = vec![0.0; self.nodes.len()];
        let mut kp = vec![0.0; self.pores.len()];
        for (c, e) in self.ends.iter().enumerate() {
            if e[0] == e[1] {
                continue;
            }
            let k = self.conductance(c);
            for end in e {
                match *end {
                    End::Node(i) => kn[i] += k,
                    End::Pore(i) => kp[i] += k,
                }
            }
        }
        for (i, &k) in kn.iter().enumerate() {
            if k > 0.5 {
                let (x, y) = self.nodes[i].0;
                return Err(CrackError::TooWide {
                    what: "lattice node",
                    x: x as f64 + 0.5,
                    y: y as f64 + 0.5,
                    k,
                });
            }
        }
        for (i, &k) in kp.iter().enumerate() {
            let p = &self.pores[i];
            if p.volume > 0.0 && k / p.volume > 0.5 {
                return Err(CrackError::TooWide {
                    what: "crack pore",
                    x: p.at[0],
                    y: p.at[1],
                    k: k / p.volume,
                });
            }
        }
        Ok(())
    }

    /// Change the aperture of channel `c` (an opening or closing crack; 0 closes it). The
    /// pores keep their mass: their volume and so their density change.
    pub fn set_aperture(&mut self, c: usize, aperture: f64) -> Result<(), CrackError> {
        if !(aperture.is_finite() && aperture >= 0.0) {
            return Err(CrackError::Value {
                channel: c,
                what: "aperture",
                value: aperture,
            });
        }
        let old = self.channels[c].aperture;
        self.channels[c].aperture = aperture;
        self.set_volumes();
        if let Err(e) = self.check_conductance() {
            self.channels[c].aperture = old;
            self.set_volumes();
            return Err(e);
        }
        Ok(())
    }

    /// The channels.
    pub fn channels(&self) -> &[CrackChannel] {
        &self.channels
    }

    /// The mouth nodes of channel `c`'s two ends (`None`: that end is a pore).
    pub fn mouths(&self, c: usize) -> [Option<(usize, usize)>; 2] {
        self.ends[c].map(|e| match e {
            End::Node(i) => Some(self.nodes[i].0),
            End::Pore(_) => None,
        })
    }

    /// Density of the pore at channel `c`'s end `k` (`None`: a mouth).
    pub fn pore_density(&self, c: usize, k: usize) -> Option<f64> {
        match self.ends[c][k] {
            End::Pore(i) => {
                let p = &self.pores[i];
                Some(if p.volume > 0.0 {
                    p.mass / p.volume
                } else {
                    1.0
                })
            }
            End::Node(_) => None,
        }
    }

    /// Mass held in the pores of the network (lattice units).
    pub fn pore_mass(&self) -> f64 {
        self.pores.iter().map(|p| p.mass).sum()
    }

    /// Mass channel `c` carried in the last step from end 0 to end 1 (lattice units).
    pub fn carried(&self, c: usize) -> f64 {
        self.carried[c]
    }

    /// Mass channel `c` carried since the start from end 0 to end 1 (lattice units).
    pub fn cumulative(&self, c: usize) -> f64 {
        self.cumulative[c]
    }

    /// Set the lattice's mouth sources for its next step from the densities now, and
    /// advance the pores by the same fluxes (call before [`Lattice::step`]; the sources
    /// act at the end of that step).
    pub fn update(&mut self, lat: &mut Lattice) -> Result<(), CrackError> {
        let mut rate = vec![0.0; self.nodes.len()];
        let mut gain = vec![0.0; self.pores.len()];
        let density = |e: End, lat: &Lattice| -> Option<f64> {
            match e {
                End::Node(i) => {
                    let (x, y) = self.nodes[i].0;
                    (!lat.is_solid(x, y)).then(|| lat.moments(x, y).0)
                }
                End::Pore(i) => {
                    let p = &self.pores[i];
                    (p.volume > 0.0).then(|| p.mass / p.volume)
                }
            }
        };
        for (c, e) in self.ends.iter().enumerate() {
            self.carried[c] = 0.0;
            if e[0] == e[1] {
                continue;
            }
            let (Some(a), Some(b)) = (density(e[0], lat), density(e[1], lat)) else {
                continue;
            };
            let s = self.conductance(c) * (a - b);
            for (end, sign) in [(e[0], -1.0), (e[1], 1.0)] {
                match end {
                    End::Node(i) => rate[i] += sign * s,
                    End::Pore(i) => gain[i] += sign * s,
                }
            }
            self.carried[c] = s;
            self.cumulative[c] += s;
        }
        for (p, g) in self.pores.iter_mut().zip(gain) {
            p.mass += g;
        }
        for (n, r) in rate.into_iter().enumerate() {
            lat.set_source_rate(self.nodes[n].1, r)?;
        }
        Ok(())
    }
}

/// The fluid node nearest to `p` within two spacings.
pub(crate) fn nearest_fluid(lat: &Lattice, p: [f64; 2]) -> Option<(usize, usize)> {
    let (nx, ny) = lat.size();
    let mut best: Option<((usize, usize), f64)> = None;
    let (ci, cj) = ((p[0] - 0.5).round() as isize, (p[1] - 0.5).round() as isize);
    for dj in -2..=2 {
        for di in -2..=2 {
            let (i, j) = (ci + di, cj + dj);
            if i < 0 || j < 0 || i >= nx as isize || j >= ny as isize {
                continue;
            }
            let (i, j) = (i as usize, j as usize);
            if lat.is_solid(i, j) {
                continue;
            }
            let d = (i as f64 + 0.5 - p[0]).powi(2) + (j as f64 + 0.5 - p[1]).powi(2);
            if d <= 4.0 && best.is_none_or(|(_, b)| d < b) {
                best = Some(((i, j), d));
            }
        }
    }
    best.map(|(n, _)| n)
}
