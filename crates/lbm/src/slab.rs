//! The lattice cut into slabs of columns for a run on several processes (MPI ranks, the
//! `mpi` feature): which columns each rank owns and which it computes, and (with the
//! feature) the exchange that keeps them equal to the whole lattice's.
//!
//! **Slabs along x.** Rank `r` of `P` owns columns `⌊r·nx/P⌋ .. ⌊(r+1)·nx/P⌋` of the box
//! and every row. It steps a [`Lattice::window`] (and a [`Thermal`] on it) of the columns
//! it owns plus [`HALO`] columns on each side. A window computes, node for node, the
//! arithmetic of the whole lattice (positions, obstacles, sides and interpolation are
//! those of the box) wherever its inputs are the whole lattice's; where it ends inside the
//! box it has a wall, whose error travels a column or two per step. So after every step
//! each rank overwrites the columns of its window that others own with their values
//! (`Exchange::lattice`, `Exchange::thermal`, with the feature): all nine stored
//! populations of the AA pattern's layout of the step (the even step's swapped layout keeps a node's
//! outgoing populations in its neighbours' slots, the odd step's natural layout its
//! incoming ones, so whole columns of the storage carry exactly what the next step of
//! either parity reads), and the five temperature distributions. The columns a rank owns
//! are then computed from exactly the numbers of the whole lattice, and are bit for bit
//! those of a serial run.
//!
//! **Obstacles across a border.** The obstacle rules read the populations two nodes away
//! and, with [`crate::ObstacleMass::Conserved`], every cut link of the obstacle at once;
//! the force on an obstacle is the sum over its cut links in their order. So a window
//! that reaches an obstacle's columns (widened by two nodes and the halo) is widened to
//! hold the whole of them ([`Plan::new`]): every rank that touches the obstacle computes
//! all its cut links, in the order of the whole lattice, and the force and torque of
//! obstacle `k` are those of the first rank holding it whole ([`Plan::holders`]), the
//! serial numbers to the bit. An obstacle as wide as the box makes every window the box
//! (correct, not faster).
//!
//! Not distributed: obstacles that move (their columns change), mass sources, periodic
//! x (slabs along a periodic axis), the sums over a whole window ([`Lattice::mass`],
//! [`Thermal::side_heat`]): a caller refuses those or sums over owned columns.
//!
//! [`Thermal`]: crate::Thermal
//! [`Thermal::side_heat`]: crate::Thermal::side_heat

use crate::LbmError;
use crate::geometry::Shape;
#[cfg(doc)]
use crate::lattice::Lattice;

/// Columns of overlap on each side of the owned ones: what a window's own wall spoils in
/// one step stays inside them.
pub const HALO: usize = 4;

/// The columns of one rank (half-open ranges of columns of the box).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Slab {
    /// Columns the rank owns (its values are the run's).
    pub owned: [usize; 2],
    /// Columns the rank computes: the owned ones, the halo, and every obstacle the halo
    /// reaches, whole.
    pub window: [usize; 2],
}

/// Slabs of every rank of a lattice of `nx` columns.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Columns of the box.
    pub nx: usize,
    /// One slab per rank, in rank order (owned ranges ascending and tiling the box).
    pub slabs: Vec<Slab>,
    /// For each obstacle, the first rank whose window holds it whole: its force is that
    /// rank's.
    pub holders: Vec<usize>,
}

/// Columns `[a, b)` an obstacle's rules read: its nodes, two more (the interpolation's
/// second fluid node), and the halo; clamped to the box.
fn reach(shape: &Shape, nx: usize) -> [usize; 2] {
    if let Shape::Hollow { .. } = shape {
        return [0, nx];
    }
    let [lo, hi] = shape.bounds();
    let pad = (2 + HALO) as f64;
    let a = ((lo[0] - 0.5).floor() - pad).max(0.0);
    let b = ((hi[0] - 0.5).ceil() + pad + 1.0).max(0.0);
    [(a as usize).min(nx), (b as usize).min(nx)]
}

impl Plan {
    /// Cut `nx` columns into `ranks` slabs, windows widened for `obstacles` (in box
    /// coordinates, lattice units). Every rank needs at least two columns of its own.
    pub fn new(nx: usize, ranks: usize, obstacles: &[Shape]) -> Result<Self, LbmError> {
        if ranks == 0 || nx < 2 * ranks {
            return Err(LbmError::Size(nx, ranks));
        }
        let reaches: Vec<[usize; 2]> = obstacles.iter().map(|s| reach(s, nx)).collect();
        let slabs = (0..ranks)
            .map(|r| {
                let owned = [r * nx / ranks, (r + 1) * nx / ranks];
                let mut window = [owned[0].saturating_sub(HALO), (owned[1] + HALO).min(nx)];
                // widen until every obstacle it reaches is whole in it
                loop {
                    let mut changed = false;
                    for &[a, b] in &reaches {
                        let meets = a < window[1] && window[0] < b;
                        if meets && (a < window[0] || b > window[1]) {
                            window = [window[0].min(a), window[1].max(b)];
                            changed = true;
                        }
                    }
                    if !changed {
                        break;
                    }
                }
                Slab { owned, window }
            })
            .collect::<Vec<_>>();
        let holders = reaches
            .iter()
            .map(|&[a, b]| {
                slabs
                    .iter()
                    .position(|s| s.window[0] <= a && b <= s.window[1])
                    .unwrap_or(0)
            })
            .collect();
        Ok(Plan { nx, slabs, holders })
    }

    /// The columns rank `to` receives from rank `from` after every step: those of `to`'s
    /// window that `from` owns (empty when `to == from`).
    pub fn shared(&self, from: usize, to: usize) -> [usize; 2] {
        if from == to {
            return [0, 0];
        }
        let (o, w) = (self.slabs[from].owned, self.slabs[to].window);
        let (a, b) = (o[0].max(w[0]), o[1].min(w[1]));
        if a < b { [a, b] } else { [0, 0] }
    }
}

#[cfg(feature = "mpi")]
pub use exchange::Exchange;

#[cfg(feature = "mpi")]
mod exchange {
    use mpi::topology::SimpleCommunicator;
    use mpi::traits::*;

    use super::Plan;
    use crate::d2q9::Q;
    use crate::lattice::Lattice;
    use crate::thermal::Thermal;

    /// The exchange of one rank's columns with the others after every step (see the
    /// module docs). Collective: every rank calls the same methods in the same order.
    pub struct Exchange<'c> {
        comm: &'c SimpleCommunicator,
        plan: Plan,
        rank: usize,
        /// Columns sent to each other rank, and received from each.
        sends: Vec<(usize, [usize; 2])>,
        recvs: Vec<(usize, [usize; 2])>,
    }

    impl<'c> Exchange<'c> {
        /// The exchange of this rank of `comm` under `plan` (one slab per rank of `comm`).
        pub fn new(comm: &'c SimpleCommunicator, plan: Plan) -> Self {
            let rank = comm.rank() as usize;
            let ranks = plan.slabs.len();
            let sends = (0..ranks)
                .map(|to| (to, plan.shared(rank, to)))
                .filter(|(_, c)| c[0] < c[1])
                .collect();
            let recvs = (0..ranks)
                .map(|from| (from, plan.shared(from, rank)))
                .filter(|(_, c)| c[0] < c[1])
                .collect();
            Exchange {
                comm,
                plan,
                rank,
                sends,
                recvs,
            }
        }

        /// The plan.
        pub fn plan(&self) -> &Plan {
            &self.plan
        }

        /// This rank's slab.
        pub fn slab(&self) -> super::Slab {
            self.plan.slabs[self.rank]
        }

        /// Bytes this rank sends per step for the fluid (and, with `thermal`, the
        /// temperature) with `ny` rows.
        pub fn bytes_per_step(&self, ny: usize, thermal: bool) -> usize {
            let cols: usize = self.sends.iter().map(|(_, c)| c[1] - c[0]).sum();
            let per_col = (ny + 2) * (Q + if thermal { 5 } else { 0 });
            cols * per_col * std::mem::size_of::<f64>()
        }

        /// Overwrite the columns of `lat` (this rank's window) that other ranks own with
        /// theirs, and send them the ones they need of this rank's.
        pub fn lattice(&self, lat: &mut Lattice) {
            let w0 = self.slab().window[0];
            let (nx, ny) = lat.size();
            let (pop, np) = lat.stored_mut();
            let rows = ny + 2;
            let stride = nx + 2;
            let pack = |c: [usize; 2], pop: &crate::populations::Populations| {
                let mut buf = Vec::with_capacity((c[1] - c[0]) * Q * rows);
                for col in c[0]..c[1] {
                    let ip = col - w0 + 1;
                    for q in 0..Q {
                        buf.extend((0..rows).map(|jp| pop.get(q * np + jp * stride + ip)));
                    }
                }
                buf
            };
            let sent: Vec<Vec<f64>> = self.sends.iter().map(|&(_, c)| pack(c, pop)).collect();
            let mut got: Vec<Vec<f64>> = self
                .recvs
                .iter()
                .map(|&(_, c)| vec![0.0; (c[1] - c[0]) * Q * rows])
                .collect();
            self.swap(&sent, &mut got);
            for (&(_, c), buf) in self.recvs.iter().zip(&got) {
                let mut v = buf.iter();
                for col in c[0]..c[1] {
                    let ip = col - w0 + 1;
                    for q in 0..Q {
                        for jp in 0..rows {
                            pop.set(q * np + jp * stride + ip, *v.next().expect("sized above"));
                        }
                    }
                }
            }
        }

        /// [`Exchange::lattice`] for the temperature distributions of `th`.
        pub fn thermal(&self, th: &mut Thermal) {
            let w0 = self.slab().window[0];
            let (g, stride) = th.stored_mut();
            let rows = g.len() / stride;
            let pack = |c: [usize; 2], g: &[[f64; 5]]| {
                let mut buf = Vec::with_capacity((c[1] - c[0]) * 5 * rows);
                for col in c[0]..c[1] {
                    let ip = col - w0 + 1;
                    for jp in 0..rows {
                        buf.extend_from_slice(&g[jp * stride + ip]);
                    }
                }
                buf
            };
            let sent: Vec<Vec<f64>> = self.sends.iter().map(|&(_, c)| pack(c, g)).collect();
            let mut got: Vec<Vec<f64>> = self
                .recvs
                .iter()
                .map(|&(_, c)| vec![0.0; (c[1] - c[0]) * 5 * rows])
                .collect();
            self.swap(&sent, &mut got);
            for (&(_, c), buf) in self.recvs.iter().zip(&got) {
                let mut v = buf.chunks_exact(5);
                for col in c[0]..c[1] {
                    let ip = col - w0 + 1;
                    for jp in 0..rows {
                        let d = v.next().expect("sized above");
                        g[jp * stride + ip].copy_from_slice(d);
                    }
                }
            }
        }

        /// Send `sent[i]` to the `i`-th rank of `sends` and receive `got[i]` from the
        /// `i`-th of `recvs`, all at once.
        fn swap(&self, sent: &[Vec<f64>], got: &mut [Vec<f64>]) {
            mpi::request::scope(|scope| {
                let mut requests = Vec::with_capacity(sent.len() + got.len());
                for (&(from, _), buf) in self.recvs.iter().zip(got.iter_mut()) {
                    requests.push(
                        self.comm
                            .process_at_rank(from as i32)
                            .immediate_receive_into(scope, &mut buf[..]),
                    );
                }
                for (&(to, _), buf) in self.sends.iter().zip(sent) {
                    requests.push(
                        self.comm
                            .process_at_rank(to as i32)
                            .immediate_send(scope, &buf[..]),
                    );
                }
                for r in requests {
                    r.wait();
                }
            });
        }

        /// The force and torque on every obstacle, each from the rank holding it whole
        /// ([`Plan::holders`]): the numbers of the whole lattice. Collective; the same on
        /// every rank.
        pub fn forces(&self, lat: &Lattice) -> Vec<[f64; 3]> {
            let n = lat.obstacles().len();
            let mine: Vec<f64> = (0..n).flat_map(|k| lat.force(k)).collect();
            let mut all = vec![0.0; mine.len() * self.plan.slabs.len()];
            self.comm.all_gather_into(&mine[..], &mut all[..]);
            (0..n)
                .map(|k| {
                    let at = (self.plan.holders[k] * n + k) * 3;
                    [all[at], all[at + 1], all[at + 2]]
                })
                .collect()
        }

        /// `per_node(i, j, values)` for every node this rank owns (`i` a column of its
        /// window, `j` a row), gathered on rank 0 in the order of the box: columns
        /// ascending, rows ascending within a column. `None` on the other ranks.
        /// Collective.
        pub fn gather_owned(
            &self,
            ny: usize,
            per_node: impl Fn(usize, usize, &mut Vec<f64>),
        ) -> Option<Vec<f64>> {
            let s = self.slab();
            let mut mine = Vec::new();
            for col in s.owned[0]..s.owned[1] {
                for j in 0..ny {
                    per_node(col - s.window[0], j, &mut mine);
                }
            }
            if self.rank != 0 {
                self.comm.process_at_rank(0).send(&mine[..]);
                return None;
            }
            for from in 1..self.plan.slabs.len() {
                let (theirs, _) = self.comm.process_at_rank(from as i32).receive_vec::<f64>();
                mine.extend(theirs);
            }
            Some(mine)
        }
    }
}
