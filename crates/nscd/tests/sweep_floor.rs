//! `min_sweeps` is a floor for every ordering of the sweeps (sorted, random, coloured,
//! slabs): a step with contacts does at least `min_sweeps` sweeps even when its impulses
//! reach an exact fixed point earlier, and a step without contacts does none. The
//! sweeps are counted step by step ([`porofrac_nscd::StepStats::sweeps`]).

use porofrac_nscd::{ContactLaw, Nscd, Ordering, RigidBody, SolverParams};
use porofrac_particles::Disks;

const G: f64 = 9.81;

fn orderings() -> [Ordering; 4] {
    [
        Ordering::Sorted,
        Ordering::Random { seed: 7 },
        Ordering::Coloured,
        Ordering::Slabs,
    ]
}

/// Two columns of ten disks at rest on a floor, `min_sweeps` = 37, tolerance 1e-13: the
/// first steps need more sweeps (about 1 000 from zero impulses, then 104, 62, 44 in
/// sorted order); once the warm start is within the tolerance after a few sweeps, every
/// step does exactly 37, never fewer, and the floor carries the weight (to 1e-9)
/// whatever the ordering.
#[test]
fn a_resting_column_does_min_sweeps_in_every_ordering() {
    let (n, r) = (10, 0.05);
    let mut centres = Vec::new();
    for x in [0.0, 0.5] {
        centres.extend((0..n).map(|k| [x, r + 2.0 * r * k as f64]));
    }
    for ordering in orderings() {
        let d = Disks::new(&centres, &vec![r; 2 * n], 2000.0).unwrap();
        let weight = d.mass.iter().sum::<f64>() * G;
        let floor = RigidBody::segment([-1.0, 0.0], [1.0, 0.0]);
        let p = SolverParams {
            tolerance: 1e-13,
            min_sweeps: 37,
            max_sweeps: 100_000,
            ordering,
            ..SolverParams::default()
        };
        let mut s = Nscd::new(d, vec![floor], ContactLaw::frictional(0.3), p, [0.0, -G]).unwrap();
        for step in 0..20 {
            let st = s.step(1e-3).unwrap();
            assert_eq!(st.contacts, 2 * n, "{ordering:?}");
            assert!(st.converged, "{ordering:?} step {step}: {st:?}");
            assert!(st.sweeps >= 37, "{ordering:?} step {step}: {st:?}");
            if step >= 10 {
                assert_eq!(st.sweeps, 37, "{ordering:?} step {step}: {st:?}");
            }
            assert_eq!(st.updates, st.sweeps as u64 * st.contacts as u64);
        }
        let fy = s.body_reaction(0)[1];
        assert!(
            (fy - weight).abs() < 1e-9 * weight,
            "{ordering:?}: floor {fy}, weight {weight}"
        );
    }
}

/// A disk falling towards a floor inside the alert distance: its contact is open (no
/// impulse; the first sweep changes nothing), still `min_sweeps` = 12 sweeps are done;
/// once out of the alert distance there is no contact and no sweep.
#[test]
fn an_open_contact_still_gets_min_sweeps() {
    for ordering in orderings() {
        let mut d = Disks::new(&[[0.0, 0.1 + 0.02]], &[0.1], 2000.0).unwrap();
        d.v[0] = [0.0, 1.0];
        let floor = RigidBody::segment([-1.0, 0.0], [1.0, 0.0]);
        let p = SolverParams {
            min_sweeps: 12,
            alert: Some(0.05),
            ordering,
            ..SolverParams::default()
        };
        let mut s = Nscd::new(d, vec![floor], ContactLaw::default(), p, [0.0; 2]).unwrap();
        let st = s.step(1e-3).unwrap();
        assert_eq!((st.contacts, st.sweeps), (1, 12), "{ordering:?}: {st:?}");
        assert!(st.converged && st.residual == 0.0, "{ordering:?}: {st:?}");
        assert_eq!(s.contacts()[0].p, [0.0; 2]);
        for _ in 0..40 {
            s.step(1e-3).unwrap();
        }
        let st = s.step(1e-3).unwrap();
        assert_eq!((st.contacts, st.sweeps), (0, 0), "{ordering:?}: {st:?}");
        assert!(st.converged);
    }
}
