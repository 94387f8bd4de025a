//! Gravity settling (Renouf et al. (2006) §5.1.1; the criterion is this project's): the
//! criterion K < ratio × ΔE_p, the energy released by a dropped disk, held bodies, and the
//! state handed to the loading.

use porofrac_nscd::{ContactLaw, Nscd, NscdError, RigidBody, SettleParams, SolverParams};
use porofrac_particles::{Disks, RandomPacking};

const G: f64 = 9.81;

/// A disk dropped from 5 cm above the floor (θ = 1, no rebound) settles on it: the
/// energy released is m g · 0.05 to 1e-12 relative and it ends at rest on the floor
/// (gap below 1e-15), with `x0` reset and the clock at 0.
#[test]
fn dropped_disk_releases_m_g_h() {
    let floor = RigidBody::segment([-10.0, 0.0], [10.0, 0.0]);
    let d = Disks::new(&[[0.0, 0.55]], &[0.5], 1000.0).unwrap();
    let m = d.mass[0];
    let p = SolverParams {
        theta: 1.0,
        tolerance: 1e-12,
        ..SolverParams::default()
    };
    let mut s = Nscd::new(d, vec![floor], ContactLaw::frictional(0.3), p, [0.0, -G]).unwrap();
    let st = s
        .settle(SettleParams {
            dt: 1e-3,
            ratio: 1e-6,
            max_steps: 1000,
        })
        .unwrap();
    let expected = m * G * 0.05;
    assert!(
        (st.released - expected).abs() < 1e-12 * expected,
        "{} vs {expected}",
        st.released
    );
    assert!(st.kinetic < 1e-6 * st.released);
    assert!((s.disks.x[0][1] - 0.5).abs() < 1e-15);
    assert_eq!(s.disks.x0, s.disks.x);
    assert_eq!(s.time, 0.0);
    assert_eq!(s.disks.v[0], [0.0; 2]);
}

/// A random pile in a box with a moving right wall: the settling holds the wall (its
/// offset stays 0), meets K < 1e-6 ΔE_p, and gives the wall its velocity back.
#[test]
fn pile_settles_with_walls_held() {
    let p = RandomPacking::new([0.0, 0.0], [6.0, 3.0], 0.13, 0.26, 0.75, 3)
        .generate()
        .unwrap();
    let d = Disks::new(&p.centres, &p.radii, 2800.0).unwrap();
    let walls = vec![
        RigidBody::segment([-1.0, 0.0], [7.0, 0.0]),
        RigidBody::segment([0.0, 6.0], [0.0, 0.0]),
        RigidBody::segment([6.0, 0.0], [6.0, 6.0]).moving([-0.3, 0.0]),
    ];
    let mut s = Nscd::new(
        d,
        walls,
        ContactLaw::frictional(0.4),
        SolverParams::default(),
        [0.0, -G],
    )
    .unwrap();
    let st = s
        .settle(SettleParams {
            dt: 0.01,
            ratio: 1e-6,
            max_steps: 5000,
        })
        .unwrap();
    assert!(
        st.released > 0.0 && st.kinetic < 1e-6 * st.released,
        "{st:?}"
    );
    assert_eq!(s.bodies[2].offset, [0.0; 2]);
    assert_eq!(s.bodies[2].velocity, [-0.3, 0.0]);
    s.step(0.01).unwrap();
    assert!((s.bodies[2].offset[0] + 0.003).abs() < 1e-15);
}

/// Too few steps is an error naming the energies; bad options are refused by name.
#[test]
fn settling_errors() {
    let d = Disks::new(&[[0.0, 1.0]], &[0.5], 1000.0).unwrap();
    let floor = RigidBody::segment([-10.0, 0.0], [10.0, 0.0]);
    let mut s = Nscd::new(
        d,
        vec![floor],
        ContactLaw::frictional(0.3),
        SolverParams::default(),
        [0.0, -G],
    )
    .unwrap();
    let opts = SettleParams {
        dt: 1e-3,
        ratio: 1e-6,
        max_steps: 3,
    };
    assert!(matches!(
        s.settle(opts),
        Err(NscdError::NotSettled { steps: 3, .. })
    ));
    for (o, name) in [
        (SettleParams { dt: 0.0, ..opts }, "settle_dt"),
        (
            SettleParams {
                ratio: -1.0,
                ..opts
            },
            "settle_ratio",
        ),
        (
            SettleParams {
                max_steps: 0,
                ..opts
            },
            "settle_max_steps",
        ),
    ] {
        match s.settle(o) {
            Err(NscdError::BadParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{other:?}"),
        }
    }
}

/// An alert distance that takes in every pair of a large packing stops the detection
/// with `TooManyCandidates` (before the `n²` candidates are allocated); the settling
/// stops at the first poll that asks to.
#[test]
fn huge_alert_distances_are_refused_and_settling_can_be_interrupted() {
    use porofrac_nscd::{ContactLaw, Nscd, NscdError, SettleParams, SolverParams};
    use porofrac_particles::{Disks, packing::hexagonal};
    let p = hexagonal([0.0; 2], [20.0; 2], 0.25).unwrap();
    let n = p.len();
    let disks = Disks::new(&p.centres, &p.radii, 1000.0).unwrap();
    let params = SolverParams {
        alert: Some(30.0),
        ..SolverParams::default()
    };
    let law = ContactLaw::default();
    match Nscd::new(disks.clone(), vec![], law, params, [0.0, -9.81]) {
        Err(NscdError::TooManyCandidates { found, disks, .. }) => {
            assert_eq!(disks, n);
            assert!(found > porofrac_nscd::detect::CANDIDATES_PER_DISK * n);
        }
        other => panic!("{other:?}"),
    }
    let mut sys = Nscd::new(disks, vec![], law, SolverParams::default(), [0.0, -9.81]).unwrap();
    let mut polls = 0;
    let r = sys.settle_polled(
        SettleParams {
            dt: 1e-3,
            ratio: 1e-6,
            max_steps: 1000,
        },
        &mut |p| {
            polls += 1;
            p.done == 3
        },
    );
    assert_eq!(r, Err(NscdError::Interrupted));
    assert_eq!(polls, 4);
}
