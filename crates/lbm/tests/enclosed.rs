//! `Lattice::enclosed_fluid_nodes` (the one-node pores a coupled run tops up) is the set of
//! fluid nodes off the box's edges whose eight neighbours are solid, in row order: checked
//! against the definition node by node on a ring of boxes around one node and on random
//! packings of disks, before and after the bodies move.

use porofrac_lbm::{Lattice, LatticeConfig, Obstacle, Shape};

/// The definition, from `is_solid`, row by row.
fn by_definition(l: &Lattice) -> Vec<(usize, usize)> {
    let (nx, ny) = l.size();
    let mut out = Vec::new();
    for j in 1..ny - 1 {
        for i in 1..nx - 1 {
            if !l.is_solid(i, j)
                && (j - 1..=j + 1)
                    .all(|b| (i - 1..=i + 1).all(|a| (a, b) == (i, j) || l.is_solid(a, b)))
            {
                out.push((i, j));
            }
        }
    }
    out
}

fn body(shape: Shape, velocity: [f64; 2]) -> Obstacle {
    Obstacle {
        shape,
        velocity,
        angular_velocity: 0.0,
    }
}

#[test]
fn a_ring_of_boxes_encloses_one_node() {
    let mut l = Lattice::new(LatticeConfig::periodic(24, 20, 0.8)).unwrap();
    for (lo, hi) in [
        ([8.0, 8.0], [10.0, 13.0]),
        ([11.0, 8.0], [13.0, 13.0]),
        ([10.0, 8.0], [11.0, 10.0]),
        ([10.0, 11.0], [11.0, 13.0]),
    ] {
        l.add_obstacle(body(Shape::aligned_box(lo, hi), [0.0, 0.0]))
            .unwrap();
    }
    assert_eq!(l.enclosed_fluid_nodes(), vec![(10, 10)]);
    assert_eq!(by_definition(&l), vec![(10, 10)]);
}

#[test]
fn random_packings_match_the_definition() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut pockets = 0;
    for _ in 0..6 {
        let mut l = Lattice::new(LatticeConfig::periodic(48, 40, 0.8)).unwrap();
        // dense, overlapping small disks: many one-node pores, some on the periodic seams
        for _ in 0..260 {
            let c = [48.0 * rnd(), 40.0 * rnd()];
            let r = 0.9 + 1.1 * rnd();
            let v = [0.2 * (rnd() - 0.5), 0.2 * (rnd() - 0.5)];
            l.add_obstacle(body(
                Shape::Circle {
                    center: c,
                    radius: r,
                },
                v,
            ))
            .unwrap();
        }
        for _ in 0..4 {
            let found = l.enclosed_fluid_nodes();
            assert_eq!(found, by_definition(&l));
            pockets += found.len();
            l.step().unwrap();
        }
    }
    assert!(
        pockets > 20,
        "only {pockets} one-node pores: not a test of them"
    );
}
