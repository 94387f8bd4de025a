//! A fluid node enclosed alone by disks moving apart: the moving-wall bounce-back drains it
//! by `6 w_α ρ₀ c_α·u_w` per link and step whatever it holds, so its density falls through
//! zero and the lattice reports "the flow diverged" (the 8 m borehole rock with the crack
//! flow stopped so at t = 0.36 s, on a node at r = 7.25 m with eight solid neighbours);
//! [`Pockets`] keeps such a node at half the reference density or above and books the
//! mass it adds.

use porofrac_lbm::{Lattice, LatticeConfig, LbmError, Obstacle, ObstacleMotion, Shape, SideKind};
use porofrac_particle_fluid::Pockets;
use porofrac_particle_fluid::pockets::FLOOR;

const N: usize = 24;
/// The enclosed node and its lattice position (node `(i, j)` sits at `(i + ½, j + ½)`).
const NODE: (usize, usize) = (12, 12);
const SPEED: f64 = 0.01;

/// Four disks of radius 2 east, north, west and south of `NODE`, 2.5 from it, covering its
/// eight neighbours and not it, each moving away from it at `SPEED` (their nodes stay put:
/// the walls' velocity is what drains the node). Walls all round.
fn lattice() -> Lattice {
    let cfg = LatticeConfig {
        periodic: [false, false],
        sides: [SideKind::Wall; 4],
        ..LatticeConfig::periodic(N, N, 0.6)
    };
    let mut lat = Lattice::new(cfg).unwrap();
    // the walls' velocity enters the wall rule only: the disks stay where they are
    lat.set_obstacle_motion_mode(ObstacleMotion::External);
    let c = [NODE.0 as f64 + 0.5, NODE.1 as f64 + 0.5];
    for d in [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]] {
        lat.add_obstacle(Obstacle {
            shape: Shape::Circle {
                center: [c[0] + 2.5 * d[0], c[1] + 2.5 * d[1]],
                radius: 2.0,
            },
            velocity: [SPEED * d[0], SPEED * d[1]],
            angular_velocity: 0.0,
        })
        .unwrap();
    }
    assert!(!lat.is_solid(NODE.0, NODE.1));
    for (a, b) in [
        (-1i64, -1i64),
        (0, -1),
        (1, -1),
        (-1, 0),
        (1, 0),
        (-1, 1),
        (0, 1),
        (1, 1),
    ] {
        let (i, j) = ((NODE.0 as i64 + a) as usize, (NODE.1 as i64 + b) as usize);
        assert!(lat.is_solid(i, j), "neighbour ({i}, {j}) is fluid");
    }
    lat
}

#[test]
fn an_enclosed_node_between_receding_disks_diverges_without_the_floor() {
    let mut lat = lattice();
    let mut steps = 0;
    let err = loop {
        lat.step().unwrap();
        steps += 1;
        if let Err(e) = lat.max_speed() {
            break e;
        }
        assert!(steps < 100, "density {}", lat.moments(NODE.0, NODE.1).0);
    };
    // drained linearly, 6 Σ_α w_α c_α·u_w over the eight links (3.3 u, about 4.2 u with
    // the interpolation and the bodies' mass balance): zero is crossed in about 25 steps
    eprintln!("diverged after {steps} steps: {err}");
    assert!(matches!(err, LbmError::Diverged { i, j, .. } if (i, j) == NODE));
}

#[test]
fn pockets_keep_an_enclosed_node_above_the_floor_and_book_the_mass() {
    let mut lat = lattice();
    let mut pockets = Pockets::new();
    let mut lowest = f64::INFINITY;
    let mut drain = 0.0f64;
    for _ in 0..1000 {
        pockets.update(&mut lat).unwrap();
        let before = lat.moments(NODE.0, NODE.1).0;
        lat.step().unwrap();
        let after = lat.moments(NODE.0, NODE.1).0;
        lowest = lowest.min(after);
        drain = drain.max(before + (FLOOR - before).max(0.0) - after);
        if let Err(e) = lat.max_speed() {
            panic!("{e}: density {after}, drain {drain}");
        }
    }
    eprintln!(
        "lowest density {lowest}, drain per step {drain}, added {} over {} node-steps",
        pockets.added_mass(),
        pockets.topped()
    );
    // once down to the floor, each step starts there and loses one step's drain
    assert!(
        drain > 0.0 && lowest >= FLOOR - 1.0001 * drain,
        "{lowest} {drain}"
    );
    assert!(lowest > 0.4);
    // it reaches the floor after (1 − FLOOR) / drain steps and stays there
    let late = (1.0 - FLOOR) / drain;
    assert!(
        pockets.topped() as f64 >= 1000.0 - late - 2.0,
        "{} node-steps",
        pockets.topped()
    );
    // the only source of the lattice
    let added = pockets.added_mass();
    assert!(
        (added - lat.injected_mass()).abs() <= 1e-12 * added,
        "{added} vs {}",
        lat.injected_mass()
    );
}
