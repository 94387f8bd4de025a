//! The cut links of all obstacles in memory order: where the obstacle rules
//! ([`crate::boundary`]) load their populations and store their unknowns.
//!
//! **Why an order of its own.** A body's rule needs the sums over its own links (the mass
//! its interpolation created, `m = Σ [L(x_f, ᾱ) − L(x_b, α)]`, and its force and torque), so
//! its links are kept per body, in the order they were built. Walked that way, the loads
//! jump: a body's links span `2R` rows of each of the nine population arrays, and the
//! bodies follow each other in the order they were added, not where they lie. On a lattice
//! the stream–collide sweep has just pushed out of the cache, every load is a miss (on the
//! packed rock of `scenes/lsm_hydrofrac.toml`, 114 k links over nine arrays of 6.5 MB). So
//! the rule runs in three passes:
//!
//! 1. **gather**, in memory order (the links sorted by the row of `x_f`, a counting sort
//!    that keeps the build order within a row): every link loads the three populations
//!    its rule reads, `L(x_b, α)`, `L(x_f, α)` and `L(x_f2, ᾱ)`, into a buffer; the row
//!    order walks each array forward, so the loads stream. Chunks of the walk run in
//!    parallel, each filling its own part of the buffer.
//! 2. **rules**, per body as before (in parallel over bodies), reading the buffer instead
//!    of the arrays: the same values in the same order of summation, so every unknown,
//!    force and torque is the same to the bit.
//! 3. **scatter**, in memory order: every unknown `L(x_f, ᾱ)` is stored. No rule reads
//!    an unknown (each `(x_f, ᾱ)` belongs to one link, and the loads are of what crossed
//!    into a solid node or of populations that are no unknowns), so the order of the stores
//!    does not matter.
//!
//! The order depends only on each link's fluid node, direction and `x_f2`, which change
//! only when a body's links are rebuilt; a body whose links only had `δ` updated keeps it.

use crate::boundary::ObstacleLink;
use crate::d2q9::OPP;
use crate::kernel::{Grid, Layout};
use crate::populations::Populations;

/// Links per parallel task of the gather.
const CHUNK: usize = 4096;

/// `x_f2` of a link whose second fluid node is missing.
const NONE: u32 = u32::MAX;

/// A link as the gather and scatter see it.
#[derive(Clone, Copy, Debug)]
struct Entry {
    /// `x_f`.
    node: u32,
    /// `x_f2`, or [`NONE`].
    f2: u32,
    /// Index of the link among all bodies' links in build order.
    id: u32,
    /// Direction into the body.
    alpha: u8,
}

/// The cut links of every body in memory order, and the populations their rules read.
#[derive(Clone, Debug, Default)]
pub(crate) struct CutLinkOrder {
    /// Index of each body's first link among all links (one more entry than bodies).
    offsets: Vec<usize>,
    /// The links sorted by the row of `x_f` (build order within a row).
    entries: Vec<Entry>,
    /// Position in `entries` of every link, by build order.
    rank: Vec<u32>,
    /// In `entries` order: `L(x_b, α)`, `L(x_f, α)`, `L(x_f2, ᾱ)` (0 without `x_f2`).
    reads: Vec<[f64; 3]>,
    /// Whether links were rebuilt since the order was made.
    stale: bool,
}

impl CutLinkOrder {
    /// An order to be made at the first [`CutLinkOrder::refresh`].
    pub(crate) fn new() -> Self {
        CutLinkOrder {
            stale: true,
            ..CutLinkOrder::default()
        }
    }

    /// Some body's links were rebuilt (its nodes, directions or `x_f2` changed).
    pub(crate) fn invalidate(&mut self) {
        self.stale = true;
    }

    /// Make the order again if links were rebuilt since: a counting sort of all links by
    /// the row of their fluid node.
    pub(crate) fn refresh(&mut self, links: &[Vec<ObstacleLink>], g: Grid) {
        if !self.stale {
            return;
        }
        self.stale = false;
        self.offsets.clear();
        self.offsets.push(0);
        let mut total = 0;
        for l in links {
            total += l.len();
            self.offsets.push(total);
        }
        let stride = g.stride();
        let mut start = vec![0usize; g.ny + 3];
        for l in links.iter().flatten() {
            start[l.node as usize / stride + 1] += 1;
        }
        for r in 1..start.len() {
            start[r] += start[r - 1];
        }
        let blank = Entry {
            node: 0,
            f2: NONE,
            id: 0,
            alpha: 0,
        };
        self.entries.clear();
        self.entries.resize(total, blank);
        self.rank.clear();
        self.rank.resize(total, 0);
        for (id, l) in links.iter().flatten().enumerate() {
            let row = l.node as usize / stride;
            let at = start[row];
            start[row] += 1;
            self.entries[at] = Entry {
                node: l.node,
                f2: l.f2,
                id: id as u32,
                alpha: l.alpha,
            };
            self.rank[id] = at as u32;
        }
        self.reads.clear();
        self.reads.resize(total, [0.0; 3]);
    }

    /// Index of body `k`'s first link among all links.
    pub(crate) fn offset(&self, k: usize) -> usize {
        self.offsets[k]
    }

    /// Links of all bodies.
    pub(crate) fn len(&self) -> usize {
        self.entries.len()
    }

    /// What the rule of link `id` (build order) reads: `L(x_b, α)`, `L(x_f, α)`,
    /// `L(x_f2, ᾱ)`, as the last [`CutLinkOrder::gather`] loaded them.
    #[inline]
    pub(crate) fn read(&self, id: usize) -> [f64; 3] {
        self.reads[self.rank[id] as usize]
    }

    /// Load what every rule reads, in memory order (chunks in parallel).
    pub(crate) fn gather(&mut self, pop: &Populations, g: Grid, lay: Layout) {
        use rayon::prelude::*;
        self.entries
            .par_chunks(CHUNK)
            .zip(self.reads.par_chunks_mut(CHUNK))
            .for_each(|(entries, reads)| {
                for (e, r) in entries.iter().zip(reads.iter_mut()) {
                    let a = e.alpha as usize;
                    let xf = e.node as usize;
                    let into = pop.get(g.loc(lay, g.shift(xf, a), a));
                    *r = if e.f2 == NONE {
                        [into, 0.0, 0.0]
                    } else {
                        [
                            into,
                            pop.get(g.loc(lay, xf, a)),
                            pop.get(g.loc(lay, e.f2 as usize, OPP[a])),
                        ]
                    };
                }
            });
    }

    /// Store every unknown `L(x_f, ᾱ) = backs[id]`, in memory order.
    pub(crate) fn scatter(&self, pop: &mut Populations, g: Grid, lay: Layout, backs: &[f64]) {
        for e in &self.entries {
            let q = OPP[e.alpha as usize];
            pop.set(g.loc(lay, e.node as usize, q), backs[e.id as usize]);
        }
    }
}
