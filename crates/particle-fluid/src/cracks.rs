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
//! **Mouths.** Each end of a channel is attached to the fluid node nearest to it within
//! two spacings (none: the channel is dry and carries nothing). A mouth that an obstacle
//! covers later carries nothing in that step (both ends must be fluid), so no mass is
//! created or lost.
//!
//! What is not done here: the crack network of a broken rock (channels along the broken
//! bonds' faces joined at the pores between three particles) and its coupling to
//! [`crate::ParticleFluid`]; this module is the channel, its exchange and its test.

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
    /// An aperture or length that is not positive and finite.
    #[error("crack channel {channel}: {what} = {value} must be positive and finite")]
    Value {
        /// The channel.
        channel: usize,
        /// Which value.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A mouth whose channels conduct too much for the explicit exchange.
    #[error(
        "lattice node ({i}, {j}): its crack channels conduct K = {k:.3} per step (limit 0.5); \
         a crack that wide is carried by the lattice itself"
    )]
    TooWide {
        /// Node column.
        i: usize,
        /// Node row.
        j: usize,
        /// Its `Σ K`.
        k: f64,
    },
    /// An error of the lattice.
    #[error(transparent)]
    Lbm(#[from] LbmError),
}

/// The crack channels of a lattice and their mass exchange.
#[derive(Clone, Debug)]
pub struct CrackFlow {
    channels: Vec<CrackChannel>,
    /// Per channel: its mouths' indices into `nodes`, or `None` (dry).
    mouths: Vec<Option<[usize; 2]>>,
    /// Mouth nodes and their lattice source.
    nodes: Vec<((usize, usize), usize)>,
    /// Lattice kinematic viscosity.
    nu: f64,
    /// Mass carried by each channel in the last step, from end 0 to end 1.
    carried: Vec<f64>,
    /// Mass carried through all channels since the start, from end 0 to end 1.
    total: f64,
}

impl CrackFlow {
    /// Attach `channels` to `lat` (its relaxation time gives the viscosity). Mouths are
    /// found now, from the nodes that are fluid now.
    pub fn new(lat: &mut Lattice, channels: Vec<CrackChannel>) -> Result<Self, CrackError> {
        let nu = (lat.config().tau - 0.5) / 3.0;
        let mut nodes: Vec<((usize, usize), usize)> = Vec::new();
        let mut mouths = Vec::with_capacity(channels.len());
        for (c, ch) in channels.iter().enumerate() {
            for (what, value) in [("aperture", ch.aperture), ("length", ch.length)] {
                if !(value.is_finite() && value > 0.0) {
                    return Err(CrackError::Value {
                        channel: c,
                        what,
                        value,
                    });
                }
            }
            let ends = [
                nearest_fluid(lat, ch.ends[0]),
                nearest_fluid(lat, ch.ends[1]),
            ];
            let m = match ends {
                [Some(a), Some(b)] if a != b => {
                    let mut idx = [0; 2];
                    for (k, n) in [a, b].into_iter().enumerate() {
                        idx[k] = match nodes.iter().position(|(x, _)| *x == n) {
                            Some(p) => p,
                            None => {
                                let s = lat.add_source(&[n])?;
                                nodes.push((n, s));
                                nodes.len() - 1
                            }
                        };
                    }
                    Some(idx)
                }
                _ => None,
            };
            mouths.push(m);
        }
        let flow = CrackFlow {
            carried: vec![0.0; channels.len()],
            channels,
            mouths,
            nodes,
            nu,
            total: 0.0,
        };
        flow.check_conductance()?;
        Ok(flow)
    }

    /// `K = w³ c_s² / (12 ν L)` of channel `c` (mass per step and unit density difference).
    pub fn conductance(&self, c: usize) -> f64 {
        let ch = &self.channels[c];
        ch.aperture.powi(3) * CS2 / (12.0 * self.nu * ch.length)
    }

    fn check_conductance(&self) -> Result<(), CrackError> {
        let mut k = vec![0.0; self.nodes.len()];
        for (c, m) in self.mouths.iter().enumerate() {
            if let Some([a, b]) = *m {
                let kc = self.conductance(c);
                k[a] += kc;
                k[b] += kc;
            }
        }
        for (n, &kn) in k.iter().enumerate() {
            if kn > 0.5 {
                let (i, j) = self.nodes[n].0;
                return Err(CrackError::TooWide { i, j, k: kn });
            }
        }
        Ok(())
    }

    /// Change the aperture of channel `c` (an opening or closing crack).
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
        if let Err(e) = self.check_conductance() {
            self.channels[c].aperture = old;
            return Err(e);
        }
        Ok(())
    }

    /// The channels.
    pub fn channels(&self) -> &[CrackChannel] {
        &self.channels
    }

    /// The mouth nodes of channel `c` (`None`: dry, no fluid node near an end).
    pub fn mouths(&self, c: usize) -> Option<[(usize, usize); 2]> {
        self.mouths[c].map(|[a, b]| [self.nodes[a].0, self.nodes[b].0])
    }

    /// Mass channel `c` carried in the last step from end 0 to end 1 (lattice units).
    pub fn carried(&self, c: usize) -> f64 {
        self.carried[c]
    }

    /// Mass carried through all channels since the start, end 0 to end 1.
    pub fn total_carried(&self) -> f64 {
        self.total
    }

    /// Set the lattice's mouth sources for its next step from the mouths' densities now
    /// (call before [`Lattice::step`]; the sources act at the end of that step).
    pub fn update(&mut self, lat: &mut Lattice) -> Result<(), CrackError> {
        let mut rate = vec![0.0; self.nodes.len()];
        for (c, m) in self.mouths.iter().enumerate() {
            self.carried[c] = 0.0;
            let Some([a, b]) = *m else { continue };
            let ((ia, ja), (ib, jb)) = (self.nodes[a].0, self.nodes[b].0);
            if lat.is_solid(ia, ja) || lat.is_solid(ib, jb) {
                continue;
            }
            let ch = &self.channels[c];
            let k = ch.aperture.powi(3) * CS2 / (12.0 * self.nu * ch.length);
            let s = k * (lat.moments(ia, ja).0 - lat.moments(ib, jb).0);
            rate[a] -= s;
            rate[b] += s;
            self.carried[c] = s;
            self.total += s;
        }
        for (n, r) in rate.into_iter().enumerate() {
            lat.set_source_rate(self.nodes[n].1, r)?;
        }
        Ok(())
    }
}

/// The fluid node nearest to `p` within two spacings.
fn nearest_fluid(lat: &Lattice, p: [f64; 2]) -> Option<(usize, usize)> {
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
