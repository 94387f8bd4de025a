//! Fluid nodes the moving disks enclose alone: a pore the lattice does not resolve, kept
//! from being stretched through zero density.
//!
//! A fluid node whose eight neighbours are all solid is a pocket of one node. When the
//! disks around it move apart (a rock that dilates as it cracks), the moving-wall
//! bounce-back takes `6 w_α ρ₀ c_α·u_w` from it on every link each step — mass in
//! proportion to the walls' speed, not to what the node holds — and nothing flows in: its
//! density falls linearly through zero and the lattice stops with "the flow diverged". A
//! liquid cannot be stretched without limit (it cavitates), and a lattice node of zero
//! density has no state at all. [`Pockets::update`] therefore tops every one-node pocket
//! whose density has fallen below [`FLOOR`] (half the reference density: a gauge pressure
//! of `−c_s² ρ₀ / 2`, far below any pressure a run carries) back up to it through a
//! lattice source (acting at the end of the next [`Lattice::step`]) and books the mass it
//! adds ([`Pockets::added_mass`]). The floor lies far from the ambient density on purpose:
//! topping up at the ambient density would pump mass into a node whose walls vibrate
//! (every dip refilled, every rise kept) until its pressure throws the disks apart. Nodes
//! with a fluid neighbour are left to the lattice.

use std::collections::HashMap;

use porofrac_lbm::Lattice;

use crate::CouplingError;

/// The lowest density of a one-node pocket (lattice units; the reference density is 1).
pub const FLOOR: f64 = 0.5;

/// The one-node pockets of a lattice and the sources that keep them at [`FLOOR`] or above
/// (module docs).
#[derive(Clone, Debug, Default)]
pub struct Pockets {
    /// Lattice source of every node topped up so far.
    sources: HashMap<(usize, usize), usize>,
    /// Sources given a rate for the coming step.
    active: Vec<usize>,
    added: f64,
    topped: u64,
}

impl Pockets {
    /// No pocket yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Mass added to one-node pockets since the start (lattice units; part of
    /// [`Lattice::injected_mass`]).
    pub fn added_mass(&self) -> f64 {
        self.added
    }

    /// Node-steps topped up since the start.
    pub fn topped(&self) -> u64 {
        self.topped
    }

    /// Set the sources of the coming [`Lattice::step`]: every fluid node of the interior
    /// whose eight neighbours are solid and whose density is below [`FLOOR`] receives
    /// `FLOOR − ρ`. Call after the obstacles are placed, before the step.
    pub fn update(&mut self, lat: &mut Lattice) -> Result<(), CouplingError> {
        for s in self.active.drain(..) {
            lat.set_source_rate(s, 0.0)?;
        }
        for (i, j) in lat.enclosed_fluid_nodes() {
            let gap = FLOOR - lat.moments(i, j).0;
            if gap.is_nan() || gap <= 0.0 {
                continue;
            }
            let s = match self.sources.get(&(i, j)) {
                Some(&s) => s,
                None => {
                    let s = lat.add_source(&[(i, j)])?;
                    self.sources.insert((i, j), s);
                    s
                }
            };
            lat.set_source_rate(s, gap)?;
            self.active.push(s);
            self.added += gap;
            self.topped += 1;
        }
        Ok(())
    }
}
