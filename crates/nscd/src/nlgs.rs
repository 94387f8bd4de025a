//! The local solver: non-linear Gauss–Seidel (NLGS) sweeps over the contacts (seed
//! eq. 5, Table 1), with options of its own.
//!
//! **Body-velocity accumulation**: W is never formed. The solver keeps the body
//! velocities q̇ = q̇_free + M⁻¹ H P up to date; a contact reads its relative velocity
//! U = Hᵀ q̇, removes its own contribution (b = U − W_αα P_α), solves its local problem
//! exactly ([`crate::law::solve_local`]) and adds M⁻¹ H ΔP back to its two bodies
//! ([`crate::problem`]).
//!
//! **Convergence test** after each sweep k: with ΔP_α the change of P_α during the
//! sweep, e_k = √(Σ ΔP_αᵀ W_αα ΔP_α / Σ P_αᵀ W_αα P_α). `min_sweeps` is a floor: the
//! sweeps stop once k ≥ `min_sweeps` and either e_k ≤ `tolerance` or the sweep changed
//! nothing at all (an exact fixed point, also when Σ PᵀWP = 0), or at `max_sweeps`
//! (counted as not converged). A step without contacts does no sweep.
//!
//! **Ordering** ([`Ordering`]): by default the contacts are swept in their sorted order
//! (candidate, then antagonist), the same every sweep; [`Ordering::Random`] draws a new
//! permutation for every sweep from a seed and the step number, reproducible too;
//! [`Ordering::Coloured`] sweeps colour groups of independent contacts in parallel
//! ([`crate::colour`]), with a result that does not depend on the thread count;
//! [`Ordering::Slabs`] sweeps one slab of disks per thread in parallel, each in sorted
//! order, then the contacts between slabs ([`crate::slabs`]), with a result that depends
//! on the thread count only.

use porofrac_particles::rng::SplitMix64;

use crate::NscdError;
use crate::detect::{Antagonist, Contact};
use crate::law::solve_local;
use crate::problem::apply;

/// Order of the contacts within a sweep.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ordering {
    /// Sorted by candidate, then antagonist (disks before bodies), every sweep.
    #[default]
    Sorted,
    /// A new random permutation every sweep, drawn from this seed and the step number.
    Random {
        /// Seed of the permutations.
        seed: u64,
    },
    /// Colour groups swept in parallel ([`crate::colour`]): the same result for any
    /// number of threads.
    Coloured,
    /// One slab of disks per thread swept in parallel, each in sorted order, then the
    /// contacts between slabs ([`crate::slabs`]): the same result for a given number of
    /// threads.
    Slabs,
}

/// Options of the NLGS solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NlgsOptions {
    /// Tolerance of the W-weighted relative impulse change (default 1.666e-4,
    /// LMGC90's).
    pub tolerance: f64,
    /// Fewest sweeps of a step with contacts, always done (default 100, the paper's
    /// "minimal number of iterations").
    pub min_sweeps: usize,
    /// Most sweeps (default 10 000).
    pub max_sweeps: usize,
    /// Order of the contacts within a sweep.
    pub ordering: Ordering,
}

impl Default for NlgsOptions {
    fn default() -> Self {
        Self {
            tolerance: 1.666e-4,
            min_sweeps: 100,
            max_sweeps: 10_000,
            ordering: Ordering::Sorted,
        }
    }
}

impl NlgsOptions {
    /// Check the options: a positive tolerance, at least one sweep, and
    /// `min_sweeps ≤ max_sweeps`.
    pub fn check(&self) -> Result<(), NscdError> {
        let bad = |name, value, message| {
            Err(NscdError::BadParameter {
                name,
                value,
                message,
            })
        };
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return bad("tolerance", self.tolerance, "must be a positive number");
        }
        if self.max_sweeps == 0 {
            return bad("max_sweeps", 0.0, "must be at least 1");
        }
        if self.min_sweeps > self.max_sweeps {
            return bad(
                "min_sweeps",
                self.min_sweeps as f64,
                "must not exceed max_sweeps",
            );
        }
        Ok(())
    }
}

/// What one NLGS solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NlgsStats {
    /// Sweeps done.
    pub sweeps: usize,
    /// Convergence measure e_k of the last sweep.
    pub residual: f64,
    /// The sweeps stopped on the tolerance or a fixed point (not on `max_sweeps`).
    pub converged: bool,
    /// The sweeps stopped because the interrupt flag was set ([`Nlgs::interrupt`]).
    pub interrupted: bool,
}

/// The velocities the sweeps update: the disks' `v` and `ω`, the bodies' `v`.
#[derive(Debug)]
pub struct Velocities<'a> {
    /// Disk velocities.
    pub v: &'a mut [[f64; 2]],
    /// Disk angular velocities.
    pub omega: &'a mut [f64],
    /// Body velocities.
    pub body_v: &'a mut [[f64; 2]],
}

/// The inverse masses the sweeps apply impulses with.
#[derive(Clone, Copy, Debug)]
pub struct InverseMasses<'a> {
    /// Disk inverse masses (0: infinite).
    pub m: &'a [f64],
    /// Disk inverse moments of inertia (0: infinite).
    pub i: &'a [f64],
    /// Body inverse masses per axis (0: prescribed).
    pub body: &'a [[f64; 2]],
}

/// The reused buffers of the solver: the random permutation, the colouring, the slabs
/// and the velocities shared by the parallel sweeps.
#[derive(Clone, Debug, Default)]
pub struct Nlgs {
    order: Vec<u32>,
    shared: crate::colour::SharedVelocities,
    masks: Vec<u64>,
    starts: Vec<usize>,
    slabs: crate::slabs::Slabs,
    /// Checked before every sweep: once set, the sweeps stop (a caller's Ctrl-C).
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

impl Nlgs {
    /// Sweep `contacts` (local problems set up, impulses warm-started and applied to
    /// `vel`) until the options' stopping test holds; `x` are the disk centres (the
    /// slab partition), `step` the step number (the random permutations). On return
    /// the contacts hold their impulses and `vel` the velocities `q̇_free + M⁻¹ H P`.
    pub fn solve(
        &mut self,
        options: &NlgsOptions,
        step: u64,
        contacts: &mut Vec<Contact>,
        x: &[[f64; 2]],
        vel: Velocities<'_>,
        inv: InverseMasses<'_>,
    ) -> NlgsStats {
        let Velocities { v, omega, body_v } = vel;
        let mut stats = NlgsStats::default();
        let mut rng = match options.ordering {
            Ordering::Random { seed } => Some(SplitMix64::new(
                seed ^ step.wrapping_mul(0x9E37_79B9_7F4A_7C15),
            )),
            _ => None,
        };
        let n = v.len();
        let coloured = options.ordering == Ordering::Coloured && !contacts.is_empty();
        let slabs = options.ordering == Ordering::Slabs && !contacts.is_empty();
        let mut serial_last = false;
        if coloured || slabs {
            let moving: Vec<bool> = (0..n).map(|i| inv.m[i] > 0.0 || inv.i[i] > 0.0).collect();
            let body_moving: Vec<bool> = inv.body.iter().map(|b| *b != [0.0, 0.0]).collect();
            if coloured {
                serial_last = crate::colour::colour(
                    contacts,
                    &moving,
                    &body_moving,
                    &mut self.masks,
                    &mut self.starts,
                );
                self.shared.load(v, omega, body_v);
            } else {
                self.slabs.partition(
                    contacts,
                    x,
                    &moving,
                    &body_moving,
                    rayon::current_num_threads(),
                );
                self.slabs.load(contacts, v, omega, body_v, inv.m, inv.i);
            }
        }
        if !contacts.is_empty() {
            // The sweeps of the step, with the stopping test.
            let mut run = || {
                for k in 1..=options.max_sweeps {
                    if self
                        .interrupt
                        .as_ref()
                        .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
                    {
                        stats.interrupted = true;
                        break;
                    }
                    let (num, den) = if coloured {
                        crate::colour::sweep(
                            contacts,
                            &self.starts,
                            serial_last,
                            &self.shared,
                            inv.m,
                            inv.i,
                            inv.body,
                        )
                    } else if slabs {
                        self.slabs.sweep(inv.body)
                    } else {
                        match rng.as_mut() {
                            None => sweep(contacts, None, v, omega, inv.m, inv.i, body_v, inv.body),
                            Some(rng) => {
                                self.order.clear();
                                self.order.extend(0..contacts.len() as u32);
                                for a in (1..self.order.len()).rev() {
                                    self.order.swap(a, rng.below(a + 1));
                                }
                                sweep(
                                    contacts,
                                    Some(&self.order),
                                    v,
                                    omega,
                                    inv.m,
                                    inv.i,
                                    body_v,
                                    inv.body,
                                )
                            }
                        }
                    };
                    stats.sweeps = k;
                    stats.residual = if den > 0.0 {
                        (num / den).sqrt()
                    } else if num > 0.0 {
                        f64::INFINITY
                    } else {
                        0.0
                    };
                    if k >= options.min_sweeps
                        && (num == 0.0 || stats.residual <= options.tolerance)
                    {
                        stats.converged = true;
                        break;
                    }
                }
            };
            if slabs {
                // On a worker of the pool for the whole step: each sweep then hands one
                // slab to the other workers, and the calling thread waits once per step
                // rather than once per sweep.
                rayon::scope(|_| run());
            } else {
                run();
            }
        } else {
            stats.converged = true;
        }
        if coloured {
            self.shared.store(v, omega, body_v);
        } else if slabs {
            self.slabs.store(contacts, v, omega, body_v);
        }
        stats
    }
}

/// One Gauss–Seidel sweep; returns (Σ ΔPᵀWΔP, Σ PᵀWP). Also the sweep of every slab
/// of [`crate::slabs`], on the slab's own arrays.
#[allow(clippy::too_many_arguments)]
pub(crate) fn sweep(
    contacts: &mut [Contact],
    order: Option<&[u32]>,
    v: &mut [[f64; 2]],
    omega: &mut [f64],
    inv_m: &[f64],
    inv_i: &[f64],
    body_v: &mut [[f64; 2]],
    body_inv: &[[f64; 2]],
) -> (f64, f64) {
    let mut num = 0.0;
    let mut den = 0.0;
    let count = contacts.len();
    for k in 0..count {
        let a = match order {
            Some(o) => o[k] as usize,
            None => k,
        };
        let c = &contacts[a];
        let i = c.i as usize;
        let (vj, wj) = match c.other {
            Antagonist::Disk(j) => (v[j as usize], omega[j as usize]),
            Antagonist::Body(b) => (body_v[b as usize], 0.0),
        };
        let dv = [v[i][0] - vj[0], v[i][1] - vj[1]];
        let un = dv[0] * c.n[0] + dv[1] * c.n[1];
        let ut = dv[0] * c.t[0] + dv[1] * c.t[1] - c.ri * omega[i] - c.rj * wj;
        let w = c.w;
        let b = [
            un - (w.nn * c.p[0] + w.nt * c.p[1]) + c.bias[0],
            ut - (w.nt * c.p[0] + w.tt * c.p[1]) + c.bias[1],
        ];
        let pbar = solve_local(&w, b, c.mu);
        let p = [pbar[0] - c.shift, pbar[1]];
        let dp = [p[0] - c.p[0], p[1] - c.p[1]];
        num += w.energy(dp);
        den += w.energy(p);
        if dp != [0.0, 0.0] {
            apply(c, dp, v, omega, inv_m, inv_i, body_v, body_inv);
            contacts[a].p = p;
        }
    }
    (num, den)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::RigidBody;
    use crate::contacts::ContactSet;
    use crate::detect::Detector;
    use crate::law::ContactLaw;
    use porofrac_particles::Disks;

    /// A disk touching a fixed floor and moving into it at 2 m/s: the solver finds the
    /// normal impulse m·v that stops it (inelastic shock), without friction since there
    /// is no tangential velocity, in one sweep plus the one that confirms the fixed point.
    #[test]
    fn inelastic_shock_on_a_floor() {
        let mut d = Disks::new(&[[0.0, 0.5]], &[0.5], 1000.0).unwrap();
        d.v[0] = [0.0, -2.0];
        let floor = [RigidBody::segment([-2.0, 0.0], [2.0, 0.0])];
        let mut set = ContactSet::default();
        set.detect(&mut Detector::default(), &d.x, &d, &floor, &[[0.0; 2]], 0.1)
            .unwrap();
        assert_eq!(set.as_slice().len(), 1);
        let (inv_m, inv_i) = ([1.0 / d.mass[0]], [1.0 / d.inertia[0]]);
        let body_inv = [[0.0; 2]];
        crate::problem::build(
            &mut set,
            &ContactLaw::frictional(0.3),
            &inv_m,
            &inv_i,
            &body_inv,
            &[None],
            1e-3,
            0.5,
        );
        let mut body_v = [[0.0; 2]];
        let stats = Nlgs::default().solve(
            &NlgsOptions {
                min_sweeps: 1,
                ..NlgsOptions::default()
            },
            0,
            &mut set.list,
            &d.x,
            Velocities {
                v: &mut d.v,
                omega: &mut d.omega,
                body_v: &mut body_v,
            },
            InverseMasses {
                m: &inv_m,
                i: &inv_i,
                body: &body_inv,
            },
        );
        assert!(stats.converged && stats.sweeps == 2, "{stats:?}");
        let p = set.as_slice()[0].p;
        assert!((p[0] - 2.0 * d.mass[0]).abs() < 1e-9 * d.mass[0], "{p:?}");
        assert_eq!(p[1], 0.0);
        assert!(d.v[0][1].abs() < 1e-12);
    }

    /// `min_sweeps` is a floor: the same shock reaches its exact fixed point after two
    /// sweeps, and with `min_sweeps = 7` seven sweeps are done, the impulse unchanged.
    #[test]
    fn min_sweeps_is_a_floor() {
        let solve = |min_sweeps: usize| {
            let mut d = Disks::new(&[[0.0, 0.5]], &[0.5], 1000.0).unwrap();
            d.v[0] = [0.0, -2.0];
            let floor = [RigidBody::segment([-2.0, 0.0], [2.0, 0.0])];
            let mut set = ContactSet::default();
            set.detect(&mut Detector::default(), &d.x, &d, &floor, &[[0.0; 2]], 0.1)
                .unwrap();
            let (inv_m, inv_i, body_inv) = ([1.0 / d.mass[0]], [1.0 / d.inertia[0]], [[0.0; 2]]);
            let law = ContactLaw::frictional(0.3);
            crate::problem::build(
                &mut set,
                &law,
                &inv_m,
                &inv_i,
                &body_inv,
                &[None],
                1e-3,
                0.5,
            );
            let options = NlgsOptions {
                min_sweeps,
                ..NlgsOptions::default()
            };
            let stats = Nlgs::default().solve(
                &options,
                0,
                &mut set.list,
                &d.x,
                Velocities {
                    v: &mut d.v,
                    omega: &mut d.omega,
                    body_v: &mut [[0.0; 2]],
                },
                InverseMasses {
                    m: &inv_m,
                    i: &inv_i,
                    body: &body_inv,
                },
            );
            (stats, set.as_slice()[0].p)
        };
        let (few, p_few) = solve(1);
        let (floor, p_floor) = solve(7);
        assert_eq!((few.sweeps, floor.sweeps), (2, 7));
        assert!(floor.converged);
        assert_eq!(p_few, p_floor);
    }
}
