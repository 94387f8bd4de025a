//! Contact detection and local frames.
//!
//! Pairs of disks come from a cell list ([`porofrac_particles::CellList`]) of side
//! `2 r_max + alert`; disk–body pairs from the body's bounding box grown by
//! `r_max + alert`, then the exact closest point. A pair is a contact candidate when its
//! gap is below the alert distance. The candidate of a disk pair is the lower index i,
//! the antagonist j; n points from j to i, t = ẑ × n, g = |x_i − x_j| − r_i − r_j. For a
//! body, n points from its closest point to the disk centre. Contacts come out sorted
//! by (candidate, antagonist), disks before bodies, so the order does not depend on the
//! cell layout.

use porofrac_particles::CellList;

use crate::NscdError;

/// Most disk–disk candidates per disk the broad phase keeps (plus [`EXTRA_CANDIDATES`]):
/// with the alert distance at most the largest radius, a disk has its touching
/// neighbours and part of the next ring within reach, a few dozen at most even for
/// wide radius ranges. More means the alert distance takes in far disks and the
/// candidates grow as `n²`: the detection stops with
/// [`NscdError::TooManyCandidates`] before allocating them.
pub const CANDIDATES_PER_DISK: usize = 64;

/// Candidates allowed on top of [`CANDIDATES_PER_DISK`] per disk, for small systems.
pub const EXTRA_CANDIDATES: usize = 1024;

use crate::body::RigidBody;
use crate::law::Block;

/// The antagonist of a contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Antagonist {
    /// Another disk.
    Disk(u32),
    /// A rigid body.
    Body(u32),
}

/// One contact: geometry at the predicted configuration, its 2×2 block of W and its
/// impulse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Candidate disk.
    pub i: u32,
    /// Antagonist.
    pub other: Antagonist,
    /// Unit normal, from the antagonist to the candidate.
    pub n: [f64; 2],
    /// Unit tangent ẑ × n.
    pub t: [f64; 2],
    /// Gap at the predicted configuration (m).
    pub gap: f64,
    /// Radius of the candidate (its lever arm).
    pub ri: f64,
    /// Radius of the antagonist disk (0 for a body).
    pub rj: f64,
    /// Contact point at the predicted configuration (m).
    pub point: [f64; 2],
    /// Diagonal block of the Delassus operator.
    pub w: Block,
    /// Impulse (P_n, P_t) = h (r_n, r_t) of the step.
    pub p: [f64; 2],
    /// Cohesive shift hγ of the normal impulse (0 when not cohesive).
    pub shift: f64,
    /// Friction coefficient of the step.
    pub mu: f64,
    /// Bias added to b: `[max(0, g)/(θh) − W_nn·shift, −W_nt·shift]`.
    pub bias: [f64; 2],
}

impl Contact {
    fn new(
        i: u32,
        other: Antagonist,
        n: [f64; 2],
        gap: f64,
        ri: f64,
        rj: f64,
        point: [f64; 2],
    ) -> Self {
        Self {
            i,
            other,
            n,
            t: [-n[1], n[0]],
            gap,
            ri,
            rj,
            point,
            w: Block::default(),
            p: [0.0; 2],
            shift: 0.0,
            mu: 0.0,
            bias: [0.0; 2],
        }
    }
}

/// Reused buffers of the detection: the broad phase's candidate pairs, the narrow
/// phase's exact gaps.
#[derive(Clone, Debug, Default)]
pub struct Detector {
    cells: CellList,
    pairs: Vec<(u32, u32)>,
    /// Disk–body candidates `(body, disk)` in body-major order.
    body_pairs: Vec<(u32, u32)>,
}

impl Detector {
    /// Every disk–disk and disk–body pair with a gap below `alert`, at centres `x` and
    /// body offsets `offsets`, into `out` (cleared first), sorted: the broad phase
    /// ([`Detector::broad_phase`]) then the narrow phase ([`Detector::narrow_phase`]).
    pub fn detect(
        &mut self,
        x: &[[f64; 2]],
        r: &[f64],
        bodies: &[RigidBody],
        offsets: &[[f64; 2]],
        alert: f64,
        out: &mut Vec<Contact>,
    ) -> Result<(), NscdError> {
        self.broad_phase(x, r, bodies, offsets, alert)?;
        self.narrow_phase(x, r, bodies, offsets, alert, out);
        Ok(())
    }

    /// The candidate pairs: disk pairs from a cell list of side `2 r_max + alert` whose
    /// gap is below `alert`, sorted by `(i, j)`, and the disks within `r_max + alert`
    /// of each body's bounding box. More than [`CANDIDATES_PER_DISK`] disk pairs per
    /// disk (plus [`EXTRA_CANDIDATES`]) is [`NscdError::TooManyCandidates`].
    pub fn broad_phase(
        &mut self,
        x: &[[f64; 2]],
        r: &[f64],
        bodies: &[RigidBody],
        offsets: &[[f64; 2]],
        alert: f64,
    ) -> Result<(), NscdError> {
        let r_max = porofrac_particles::cells::max_radius(r);
        self.cells.build(x, 2.0 * r_max + alert);
        let max = CANDIDATES_PER_DISK
            .saturating_mul(x.len())
            .saturating_add(EXTRA_CANDIDATES);
        if let Err(found) = self.cells.pairs_at_most(x, r, alert, max, &mut self.pairs) {
            self.pairs = Vec::new();
            return Err(NscdError::TooManyCandidates {
                found,
                disks: x.len(),
                alert,
            });
        }
        self.body_pairs.clear();
        for (k, body) in bodies.iter().enumerate() {
            let (lo, hi) = body.bounds(offsets[k]);
            let grow = r_max + alert;
            for (i, c) in x.iter().enumerate() {
                if c[0] < lo[0] - grow
                    || c[0] > hi[0] + grow
                    || c[1] < lo[1] - grow
                    || c[1] > hi[1] + grow
                {
                    continue;
                }
                self.body_pairs.push((k as u32, i as u32));
            }
        }
        Ok(())
    }

    /// The contacts of the broad phase's candidates: normal, gap and contact point of
    /// every disk pair, and of every disk–body candidate whose exact gap (to the body's
    /// closest point) is below `alert`; into `out` (cleared first), sorted by
    /// (candidate, antagonist), disks before bodies.
    pub fn narrow_phase(
        &self,
        x: &[[f64; 2]],
        r: &[f64],
        bodies: &[RigidBody],
        offsets: &[[f64; 2]],
        alert: f64,
        out: &mut Vec<Contact>,
    ) {
        out.clear();
        for &(i, j) in &self.pairs {
            let (a, b) = (i as usize, j as usize);
            let d = [x[a][0] - x[b][0], x[a][1] - x[b][1]];
            let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
            let n = if len > 0.0 {
                [d[0] / len, d[1] / len]
            } else {
                [1.0, 0.0]
            };
            let point = [x[b][0] + r[b] * n[0], x[b][1] + r[b] * n[1]];
            out.push(Contact::new(
                i,
                Antagonist::Disk(j),
                n,
                len - r[a] - r[b],
                r[a],
                r[b],
                point,
            ));
        }
        let start = out.len();
        for &(k, i) in &self.body_pairs {
            let (k, i) = (k as usize, i as usize);
            let (dist, n, point) = bodies[k].closest(offsets[k], x[i]);
            let gap = dist - r[i];
            if gap < alert {
                out.push(Contact::new(
                    i as u32,
                    Antagonist::Body(k as u32),
                    n,
                    gap,
                    r[i],
                    0.0,
                    point,
                ));
            }
        }
        // Disk pairs are sorted by (i, j); merge in the body contacts by candidate.
        if out.len() > start {
            out.sort_by_key(|c| (c.i, c.other));
        }
    }
}
