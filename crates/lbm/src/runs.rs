//! The fluid nodes of a lattice row by row, as runs of consecutive columns: what the
//! stream–collide step visits when the lattice holds obstacles ([`crate::kernel::aa_step_runs`]).
//!
//! **Why solid nodes can be left alone.** The kernel collides a solid node with rate 0
//! (`f* = f`) and streams it like any other, so solid nodes pass meaningless populations
//! around; nothing of the fluid depends on them. Every population a solid node sends into a
//! fluid node is the unknown of a cut link (a fluid node next to a solid one has a cut
//! link towards it) and is overwritten by the obstacle rule before it is collided;
//! the rules read only what fluid nodes sent into solid nodes (written by the fluid node
//! into slots the solid node does not write in either step of the AA pattern), and
//! populations of fluid nodes; a node an obstacle uncovers is refilled in all nine
//! populations; moments, mass and momentum are read on fluid nodes only. So a step that
//! skips the solid nodes computes every fluid node bit for bit as one that visits them
//! (only the solid nodes' own storage differs, and it is never read): the work of a step
//! is that of its fluid nodes. This is the sparse-list answer of lattice Boltzmann codes
//! to lattices that are mostly solid (porous media, packed particles), at the granularity
//! of runs, so the kernel stays vectorised along a row.
//!
//! Rows are rebuilt only when a node of theirs changed between fluid and solid (the
//! incremental rasterisation marks them). Skipping is worth it only over long stretches of
//! solid nodes: the kernel streams nine arrays, and every jump restarts nine hardware
//! prefetch streams, which costs more than the bytes of a short solid stretch (on the
//! packed rock of `scenes/lsm_hydrofrac.toml`, runs of 25 fluid nodes on average, stepping
//! each run alone was 1.5 times slower than stepping every node). So runs closer than
//! [`FluidRuns::gap`] solid nodes are merged into one *segment*, stepped with the mask
//! (solid nodes inside it collided with rate 0, as before), and only longer solid
//! stretches are skipped.

/// One stretch of a row the kernel steps: columns `[a, b)`, and whether it holds solid
/// nodes (then it is stepped with the mask).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    /// First column.
    pub a: u32,
    /// One past the last column.
    pub b: u32,
    /// Whether it holds solid nodes.
    pub masked: bool,
}

/// The segments of every interior row, kept up to date with the mask.
#[derive(Clone, Debug)]
pub struct FluidRuns {
    nx: usize,
    gap: usize,
    /// Per interior row: its segments, ascending.
    segments: Vec<Vec<Segment>>,
    /// Per interior row: fluid nodes.
    fluid: Vec<u32>,
    /// Per interior row: changed since its segments were built.
    dirty: Vec<bool>,
    /// The rows flagged in `dirty`.
    pending: Vec<u32>,
}

/// Solid stretches shorter than this (in nodes) are stepped, not skipped (see the module
/// docs; measured on the rock of `scenes/lsm_hydrofrac.toml`, docs/BENCHMARKS.md).
pub const DEFAULT_GAP: usize = 256;

impl FluidRuns {
    /// An `nx × ny` lattice of fluid nodes only, skipping solid stretches of at least
    /// [`DEFAULT_GAP`] nodes.
    pub fn new(nx: usize, ny: usize) -> Self {
        Self::with_gap(nx, ny, DEFAULT_GAP)
    }

    /// [`FluidRuns::new`] skipping solid stretches of at least `gap` nodes (at least 1).
    pub fn with_gap(nx: usize, ny: usize, gap: usize) -> Self {
        let whole = Segment {
            a: 0,
            b: nx as u32,
            masked: false,
        };
        FluidRuns {
            nx,
            gap: gap.max(1),
            segments: vec![vec![whole]; ny],
            fluid: vec![nx as u32; ny],
            dirty: vec![false; ny],
            pending: Vec::new(),
        }
    }

    /// The shortest solid stretch that is skipped.
    pub fn gap(&self) -> usize {
        self.gap
    }

    /// Interior row `j` holds a node that changed between fluid and solid.
    #[inline]
    pub fn touch(&mut self, j: usize) {
        if !self.dirty[j] {
            self.dirty[j] = true;
            self.pending.push(j as u32);
        }
    }

    /// Rebuild the rows touched since the last call from `mask` (padded, 1 fluid, 0
    /// solid; rows of `nx + 2` bytes).
    pub fn refresh(&mut self, mask: &[u8]) {
        let w = self.nx + 2;
        for &j in &self.pending {
            let j = j as usize;
            let m = &mask[(j + 1) * w + 1..][..self.nx];
            let segs = &mut self.segments[j];
            segs.clear();
            let mut i = 0;
            while i < self.nx {
                if m[i] == 0 {
                    i += 1;
                    continue;
                }
                // a run of fluid nodes at i; extend it over solid stretches shorter than
                // the gap that are followed by more fluid
                let a = i;
                let mut masked = false;
                let b = loop {
                    while i < self.nx && m[i] != 0 {
                        i += 1;
                    }
                    let end = i;
                    while i < self.nx && m[i] == 0 {
                        i += 1;
                    }
                    // i: past the solid stretch [end, i); a short one inside the row is
                    // stepped with the mask
                    if i < self.nx && i - end < self.gap {
                        masked = true;
                    } else {
                        break end;
                    }
                };
                segs.push(Segment {
                    a: a as u32,
                    b: b as u32,
                    masked,
                });
            }
            self.fluid[j] = m.iter().filter(|&&v| v != 0).count() as u32;
            self.dirty[j] = false;
        }
        self.pending.clear();
    }

    /// The segments of interior row `j` (valid after [`FluidRuns::refresh`]).
    #[inline]
    pub fn row(&self, j: usize) -> &[Segment] {
        &self.segments[j]
    }

    /// Fluid nodes of all rows (valid after [`FluidRuns::refresh`]).
    pub fn fluid_nodes(&self) -> usize {
        self.fluid.iter().map(|&n| n as usize).sum()
    }

    /// Nodes a step visits: those of every segment (valid after [`FluidRuns::refresh`]).
    pub fn visited_nodes(&self) -> usize {
        self.segments
            .iter()
            .flatten()
            .map(|s| (s.b - s.a) as usize)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_follow_the_mask() {
        let (nx, ny) = (40, 3);
        let w = nx + 2;
        let mut mask = vec![1u8; w * (ny + 2)];
        let mut r = FluidRuns::with_gap(nx, ny, 5);
        let seg = |a, b, masked| Segment { a, b, masked };
        assert_eq!(r.row(1), &[seg(0, 40, false)]);
        // row 1: solid at column 0, 4..7 (shorter than the gap: merged), 11..20 (skipped),
        // 22..40 (to the end)
        for i in [0, 4, 5, 6].into_iter().chain(11..20).chain(22..nx) {
            mask[2 * w + 1 + i] = 0;
        }
        r.touch(1);
        r.touch(1);
        r.refresh(&mask);
        assert_eq!(r.row(1), &[seg(1, 11, true), seg(20, 22, false)]);
        assert_eq!(r.fluid_nodes(), 40 + 9 + 40);
        assert_eq!(r.visited_nodes(), 40 + 12 + 40);
        // row 0 all solid: no segment, nothing visited
        for i in 0..nx {
            mask[w + 1 + i] = 0;
        }
        r.touch(0);
        r.refresh(&mask);
        assert!(r.row(0).is_empty());
        assert_eq!(r.fluid_nodes(), 9 + 40);
        assert_eq!(r.visited_nodes(), 12 + 40);
        // a gap of exactly `gap` nodes is skipped, one less is merged
        for i in (5..10).chain(15..19) {
            mask[3 * w + 1 + i] = 0;
        }
        r.touch(2);
        r.refresh(&mask);
        assert_eq!(r.row(2), &[seg(0, 5, false), seg(10, 40, true)]);
    }
}
