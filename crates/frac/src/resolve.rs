//! Resolving failures within one time step.
//!
//! Failure changes the stiffness, which changes the stress, which may fail more cells. At
//! a given time the loop is: solve with the current failure state, evaluate the criteria
//! on the cells that have not failed, fail the most critical ones, solve again, until no
//! cell fails (a consistent state: no half-updated steps). Which cells fail per round is a
//! [`FailurePolicy`]; the default fails, per round, every violating cell whose utilization
//! is within 1 % of the largest, so symmetric states fail together while a redistributed
//! stress gets the chance to relieve neighbours.
//!
//! [`FailurePolicy::MostCriticalNear`] takes the largest utilization near each cell
//! instead (within a radius of its centroid): the cells most critical in their own
//! neighbourhood fail together, one per crack tip, say, when the tips lie farther apart
//! than the radius. The global rule lets one tip grow alone whenever its utilization
//! exceeds the other's, even when both exceed 1: under one pressure the two tips of a
//! crack have the same stress intensity, and a reading that differs by a few percent
//! between them then decides which wing grows.

use porofrac_grid::Point;
use porofrac_law::Tensor;

use crate::toughness::CrackTips;
use crate::tracking::CrackTracking;
use crate::{Combined, FailureState};

/// The criteria of the cells: `criteria[k]` is the criterion of class `k`,
/// `class_of_cell[c]` the class of cell `c` (an empty [`Combined`] never fails); with
/// `tips`, the cells next to a crack check their toughness too ([`crate::toughness`]).
#[derive(Clone, Copy)]
pub struct CellCriteria<'a, const D: usize> {
    /// The criterion of every class.
    pub criteria: &'a [Combined],
    /// The class of every cell.
    pub class_of_cell: &'a [usize],
    /// Crack-tip cells and their radii, for the criteria with a toughness.
    pub tips: Option<&'a CrackTips>,
    /// The centroid of every cell, for [`FailurePolicy::MostCriticalNear`] (without them
    /// that policy is [`FailurePolicy::MostCritical`]).
    pub centroids: Option<&'a [Point<D>]>,
}

/// Which violating cells fail in one round.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FailurePolicy {
    /// Every cell that violates its criterion.
    All,
    /// Violating cells with utilization ≥ `fraction` × the largest utilization.
    MostCritical {
        /// In (0, 1].
        fraction: f64,
    },
    /// Violating cells with utilization ≥ `fraction` × the largest utilization of the
    /// violating cells within `radius` of their centroid (module docs).
    MostCriticalNear {
        /// In (0, 1].
        fraction: f64,
        /// The radius (m) of a cell's neighbourhood.
        radius: f64,
    },
}

impl Default for FailurePolicy {
    fn default() -> Self {
        FailurePolicy::MostCritical { fraction: 0.99 }
    }
}

/// An error of [`resolve`]: the solver's, or too many rounds.
#[derive(Debug, thiserror::Error)]
pub enum ResolveError<E> {
    /// The solve failed.
    #[error("{0}")]
    Solve(E),
    /// Failures kept appearing after `rounds` solves.
    #[error(
        "failures did not settle within {rounds} solves at t = {time} s ({failed} cells failed)"
    )]
    NotSettled {
        /// Solves done.
        rounds: usize,
        /// The time.
        time: f64,
        /// Cells failed so far.
        failed: usize,
    },
}

/// Solve, check, fail and re-solve at time `time` until no cell fails.
///
/// `criteria` gives every cell its criterion ([`CellCriteria`]). `solve` gets the current state and
/// returns a solution and the cell stresses (effective, tension positive) used by the
/// criteria, e.g. raw or recovered cell stresses. With `tracking`, a violating cell next
/// to failed cells fails only where [`CrackTracking::admits`] it, and every failure records
/// its crack normal ([`CrackTracking::record`]).
pub fn resolve<const D: usize, S, E>(
    state: &mut FailureState,
    time: f64,
    criteria: CellCriteria<'_, D>,
    policy: FailurePolicy,
    mut tracking: Option<&mut CrackTracking<D>>,
    max_solves: usize,
    mut solve: impl FnMut(&FailureState) -> Result<(S, Vec<Tensor<D>>), E>,
) -> Result<(S, Vec<Tensor<D>>, usize, usize), ResolveError<E>> {
    // Returns the solution, its cell stresses, the cells failed here and the solves done.
    let mut new_failures = 0;
    for round in 1..=max_solves {
        let (solution, stress) = solve(state).map_err(ResolveError::Solve)?;
        let mut violating: Vec<(usize, f64, crate::FailureMode)> = Vec::new();
        for (c, s) in stress.iter().enumerate() {
            if state.is_failed(c) {
                continue;
            }
            let crit = &criteria.criteria[criteria.class_of_cell[c]];
            if !crit.may_fail(s) {
                continue;
            }
            let tip = criteria
                .tips
                .filter(|_| crit.toughness.is_some())
                .and_then(|t| t.tip_radius(c, state.flags()));
            if let Some(mode) = crit.check_at(s, tip) {
                if let Some(t) = tracking.as_deref()
                    && !t.admits(c, s, state.flags())
                {
                    continue;
                }
                violating.push((c, crit.utilization_at(s, tip), mode));
            }
        }
        if violating.is_empty() {
            return Ok((solution, stress, new_failures, round));
        }
        let largest = violating
            .iter()
            .map(|v| v.1)
            .fold(f64::NEG_INFINITY, f64::max);
        let chosen: Vec<bool> = match (policy, criteria.centroids) {
            (FailurePolicy::All, _) => vec![true; violating.len()],
            (FailurePolicy::MostCriticalNear { fraction, radius }, Some(x)) => violating
                .iter()
                .map(|&(c, u, _)| {
                    let near = violating
                        .iter()
                        .filter(|w| (x[w.0] - x[c]).norm() <= radius)
                        .map(|w| w.1)
                        .fold(f64::NEG_INFINITY, f64::max);
                    u >= fraction * near
                })
                .collect(),
            (
                FailurePolicy::MostCritical { fraction }
                | FailurePolicy::MostCriticalNear { fraction, .. },
                _,
            ) => violating
                .iter()
                .map(|v| v.1 >= fraction * largest)
                .collect(),
        };
        let mut keep = chosen.into_iter();
        violating.retain(|_| keep.next().unwrap_or(false));
        // Every crack point is taken on the lines of the cells failed before this round.
        if let Some(t) = tracking.as_deref_mut() {
            for &(c, _, _) in &violating {
                t.record(c, &stress[c], state.flags());
            }
        }
        for &(c, _, mode) in &violating {
            if state.fail(c, time, mode) {
                new_failures += 1;
            }
        }
    }
    Err(ResolveError::NotSettled {
        rounds: max_solves,
        time,
        failed: state.count(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FailureMode, Tensile};

    /// [`resolve`] on constant uniaxial cell stresses `sigma` (σxx per cell, unchanged by
    /// failures) with one criterion class for every cell.
    fn resolve_constant(
        st: &mut FailureState,
        criterion: Combined,
        tips: Option<&CrackTips>,
        policy: FailurePolicy,
        rounds: usize,
        sigma: &[f64],
    ) -> Result<((), Vec<Tensor<2>>, usize, usize), ResolveError<()>> {
        let class = vec![0; sigma.len()];
        resolve::<2, (), ()>(
            st,
            0.0,
            CellCriteria {
                criteria: std::slice::from_ref(&criterion),
                class_of_cell: &class,
                tips,
                centroids: None,
            },
            policy,
            None,
            rounds,
            |_| {
                Ok((
                    (),
                    sigma
                        .iter()
                        .map(|&s| Tensor::<2>::new(s, 0.0, 0.0, 0.0))
                        .collect(),
                ))
            },
        )
    }

    /// A chain of springs in series under a prescribed total stretch: the stress is the
    /// same in every intact cell; a failed cell carries nothing, so after the weakest cell
    /// fails all stresses vanish and no further cell fails.
    #[test]
    fn weakest_link_fails_alone() {
        let strengths = [3.0, 2.0, 2.5, 4.0];
        let criteria: Vec<Combined> = strengths
            .iter()
            .map(|&s| Combined {
                tensile: Some(Tensile::new(s).unwrap()),
                shear: None,
                toughness: None,
            })
            .collect();
        let class: Vec<usize> = (0..4).collect();
        let mut st = FailureState::new(4);
        let load = 2.2;
        let (sol, stress, n, solves) = resolve::<2, f64, ()>(
            &mut st,
            5.0,
            CellCriteria {
                criteria: &criteria,
                class_of_cell: &class,
                tips: None,
                centroids: None,
            },
            FailurePolicy::default(),
            None,
            10,
            |st| {
                let broken = st.flags().iter().any(|&f| f);
                let s = if broken { 0.0 } else { load };
                Ok((s, vec![Tensor::<2>::new(s, 0.0, 0.0, 0.0); 4]))
            },
        )
        .unwrap();
        assert_eq!((n, solves), (1, 2));
        assert_eq!(sol, 0.0);
        assert_eq!(stress[0][(0, 0)], 0.0);
        assert_eq!(
            st.log(),
            &[crate::Failure {
                cell: 1,
                time: 5.0,
                mode: FailureMode::Tensile
            }]
        );
    }

    #[test]
    fn policy_all_fails_every_violator_and_rounds_are_bounded() {
        let criterion = Combined {
            tensile: Some(Tensile::new(1.0).unwrap()),
            shear: None,
            toughness: None,
        };
        let stresses = [1.5, 3.0, 0.5];
        let mut st = FailureState::new(3);
        let (_, _, n, _) = resolve_constant(
            &mut st,
            criterion.clone(),
            None,
            FailurePolicy::All,
            5,
            &stresses,
        )
        .unwrap();
        assert_eq!(n, 2);
        assert_eq!(st.flags(), &[true, true, false]);
        // MostCritical with fraction 0.99 fails only cell 1 per round; one round allowed.
        let mut st = FailureState::new(3);
        let err = resolve_constant(
            &mut st,
            criterion,
            None,
            FailurePolicy::default(),
            1,
            &stresses,
        )
        .unwrap_err();
        assert!(matches!(
            err,
            ResolveError::NotSettled {
                rounds: 1,
                failed: 1,
                ..
            }
        ));
    }

    /// Cells at x = 0, 0.5 and 10 with utilizations 3, 2 and 1.5 (σ_t = 1, stresses
    /// unchanged by failures), one round: the global rule fails cell 0 alone; the rule
    /// near each cell, with a radius of 1, fails cell 0 and cell 2 (the largest within 1
    /// of it is its own), not cell 1 (cell 0 lies within 1 of it); with a radius of 20 it
    /// is the global rule; without centroids too.
    #[test]
    fn the_most_critical_near_each_cell_fail_together_when_far_apart() {
        let criterion = Combined {
            tensile: Some(Tensile::new(1.0).unwrap()),
            shear: None,
            toughness: None,
        };
        let class = vec![0; 3];
        let x: Vec<Point<2>> = [0.0, 0.5, 10.0]
            .iter()
            .map(|&a| Point::<2>::new(a, 0.0))
            .collect();
        let sigma = [3.0, 2.0, 1.5];
        let one_round = |policy: FailurePolicy, centroids: Option<&[Point<2>]>| {
            let mut st = FailureState::new(3);
            let _ = resolve::<2, (), ()>(
                &mut st,
                0.0,
                CellCriteria {
                    criteria: std::slice::from_ref(&criterion),
                    class_of_cell: &class,
                    tips: None,
                    centroids,
                },
                policy,
                None,
                1,
                |_| {
                    Ok((
                        (),
                        sigma
                            .iter()
                            .map(|&s| Tensor::<2>::new(s, 0.0, 0.0, 0.0))
                            .collect(),
                    ))
                },
            );
            st.flags().to_vec()
        };
        let near = |radius| FailurePolicy::MostCriticalNear {
            fraction: 0.99,
            radius,
        };
        assert_eq!(
            one_round(FailurePolicy::default(), Some(&x)),
            [true, false, false]
        );
        assert_eq!(one_round(near(1.0), Some(&x)), [true, false, true]);
        assert_eq!(one_round(near(20.0), Some(&x)), [true, false, false]);
        assert_eq!(one_round(near(1.0), None), [true, false, false]);
    }

    /// Three unit squares in a row with constant stresses σ₁ = 3, 2, 2 and σ_t = 1. Cell 0
    /// fails first; then cell 1 shares a node with it (a tip cell, `K_c = 2 √(2π r)` with
    /// `r = 1/√π`, about 3.77) and cell 2 does not. With `K_Ic = 4` the tip cell stays
    /// intact and cell 2 fails by strength alone; with `K_Ic = 3.5` all three fail, cell 1
    /// last (its utilization `K_c/K_Ic` ≈ 1.08 is below cell 2's 2).
    #[test]
    fn toughness_holds_a_tip_cell_that_the_strength_alone_would_fail() {
        let grid = porofrac_grid::generate::cartesian([0.0, 0.0].into(), [3.0, 1.0].into(), [3, 1])
            .unwrap();
        let tips = CrackTips::new(&grid);
        let stresses = [3.0, 2.0, 2.0];
        for (k_ic, expect) in [(4.0, [true, false, true]), (3.5, [true, true, true])] {
            let criterion = Combined {
                tensile: Some(Tensile::new(1.0).unwrap()),
                shear: None,
                toughness: Some(crate::Toughness::new(k_ic).unwrap()),
            };
            let mut st = FailureState::new(3);
            resolve_constant(
                &mut st,
                criterion,
                Some(&tips),
                FailurePolicy::default(),
                10,
                &stresses,
            )
            .unwrap();
            assert_eq!(st.flags(), &expect, "K_Ic = {k_ic}");
            let order: Vec<usize> = st.log().iter().map(|f| f.cell).collect();
            let want: &[usize] = if k_ic > 3.7 { &[0, 2] } else { &[0, 2, 1] };
            assert_eq!(order, want, "K_Ic = {k_ic}");
        }
    }
}
