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
//! incremental rasterisation marks them). A row cut into many short runs is stepped whole
//! with the mask instead (one mask byte per node), where that moves fewer bytes.

/// Runs of fluid nodes of every interior row, kept up to date with the mask.
#[derive(Clone, Debug)]
pub struct FluidRuns {
    nx: usize,
    /// Per interior row: half-open column ranges `[a, b)` of fluid nodes, ascending.
    runs: Vec<Vec<[u32; 2]>>,
    /// Per interior row: step it whole with the mask (many short runs).
    whole: Vec<bool>,
    /// Per interior row: fluid nodes.
    fluid: Vec<u32>,
    /// Per interior row: changed since its runs were built.
    dirty: Vec<bool>,
    /// The rows flagged in `dirty`.
    pending: Vec<u32>,
}

/// A run costs about as much as this many nodes (setting up nine row slices); a row
/// whose runs would cost more than the solid nodes they skip is stepped whole.
const RUN_COST: usize = 4;

impl FluidRuns {
    /// An `nx × ny` lattice of fluid nodes only.
    pub fn new(nx: usize, ny: usize) -> Self {
        FluidRuns {
            nx,
            runs: vec![vec![[0, nx as u32]]; ny],
            whole: vec![false; ny],
            fluid: vec![nx as u32; ny],
            dirty: vec![false; ny],
            pending: Vec::new(),
        }
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
            let runs = &mut self.runs[j];
            runs.clear();
            let mut start = None;
            let mut fluid = 0usize;
            for (i, &v) in m.iter().enumerate() {
                match (v != 0, start) {
                    (true, None) => start = Some(i),
                    (false, Some(a)) => {
                        runs.push([a as u32, i as u32]);
                        fluid += i - a;
                        start = None;
                    }
                    _ => {}
                }
            }
            if let Some(a) = start {
                runs.push([a as u32, self.nx as u32]);
                fluid += self.nx - a;
            }
            self.fluid[j] = fluid as u32;
            self.whole[j] = fluid + RUN_COST * runs.len() >= self.nx && runs.len() > 1;
            self.dirty[j] = false;
        }
        self.pending.clear();
    }

    /// The runs of interior row `j` (valid after [`FluidRuns::refresh`]).
    #[inline]
    pub fn row(&self, j: usize) -> &[[u32; 2]] {
        &self.runs[j]
    }

    /// Whether interior row `j` is stepped whole with the mask.
    #[inline]
    pub fn whole(&self, j: usize) -> bool {
        self.whole[j]
    }

    /// Fluid nodes of all rows (valid after [`FluidRuns::refresh`]).
    pub fn fluid_nodes(&self) -> usize {
        self.fluid.iter().map(|&n| n as usize).sum()
    }

    /// Nodes a step visits: the fluid nodes of rows stepped by runs and every node of
    /// rows stepped whole (valid after [`FluidRuns::refresh`]).
    pub fn visited_nodes(&self) -> usize {
        self.fluid
            .iter()
            .zip(&self.whole)
            .map(|(&n, &w)| if w { self.nx } else { n as usize })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_follow_the_mask() {
        let (nx, ny) = (40, 3);
        let w = nx + 2;
        let mut mask = vec![1u8; w * (ny + 2)];
        let mut r = FluidRuns::new(nx, ny);
        assert_eq!(r.row(1), &[[0, 40]]);
        // row 1: solid at column 0, 4..7 and 11..40
        for i in [0, 4, 5, 6].into_iter().chain(11..nx) {
            mask[2 * w + 1 + i] = 0;
        }
        r.touch(1);
        r.touch(1);
        r.refresh(&mask);
        assert_eq!(r.row(1), &[[1, 4], [7, 11]]);
        assert_eq!(r.fluid_nodes(), 40 + 7 + 40);
        assert!(!r.whole(1));
        // row 2: every other node solid, stepped whole
        for i in (0..nx).step_by(2) {
            mask[3 * w + 1 + i] = 0;
        }
        r.touch(2);
        r.refresh(&mask);
        assert_eq!(r.row(2).len(), 20);
        assert!(r.whole(2));
        assert_eq!(r.fluid_nodes(), 40 + 7 + 20);
        assert_eq!(r.visited_nodes(), 40 + 7 + 40);
        // row 0 all solid: no run, nothing visited
        for i in 0..nx {
            mask[w + 1 + i] = 0;
        }
        r.touch(0);
        r.refresh(&mask);
        assert!(r.row(0).is_empty());
        assert_eq!(r.fluid_nodes(), 7 + 20);
        assert_eq!(r.visited_nodes(), 7 + 40);
    }
}
