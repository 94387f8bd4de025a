//! Structured generators: counts, volumes and the discrete divergence identities.

use porofrac_grid::generate::{cartesian, simplices};
use porofrac_grid::{Grid, Point};

fn check_identities<const D: usize>(g: &Grid<D>, domain_volume: f64) {
    let total: f64 = g.cell_volumes().iter().sum();
    assert!(
        (total - domain_volume).abs() <= 1e-12 * domain_volume,
        "volume {total}"
    );
    let mut q = vec![Point::<D>::zeros(); g.max_cell_nodes()];
    for c in 0..g.num_cells() {
        // Σ_f A_f n_f = 0 and Σ_f A_f (c_f · n_f) = D |K| (planar faces).
        let mut closure = Point::<D>::zeros();
        let mut div = 0.0;
        for (&f, &out) in g.cell_faces(c).iter().zip(g.cell_face_outward(c)) {
            let s = if out { 1.0 } else { -1.0 };
            closure += g.face_normal(f) * (s * g.face_area(f));
            div += s * g.face_area(f) * g.face_centroid(f).dot(g.face_normal(f));
        }
        let h = g.cell_volume(c).powf(1.0 / D as f64);
        assert!(
            closure.norm() <= 1e-12 * h.powi(D as i32 - 1),
            "cell {c}: closure {closure}"
        );
        assert!((div - D as f64 * g.cell_volume(c)).abs() <= 1e-12 * g.cell_volume(c) * 10.0);
        // Σ_i N_i ⊗ x_i = |K| I.
        let nodes = g.cell_nodes(c);
        let q = &mut q[..nodes.len()];
        g.cell_node_normals(c, q);
        for a in 0..D {
            for b in 0..D {
                let s: f64 = nodes
                    .iter()
                    .zip(q.iter())
                    .map(|(&n, qi)| qi[a] * g.node(n)[b])
                    .sum();
                let expect = if a == b { g.cell_volume(c) } else { 0.0 };
                assert!(
                    (s - expect).abs() <= 1e-12 * g.cell_volume(c) * 10.0,
                    "cell {c} N⊗x[{a}{b}] = {s}"
                );
            }
        }
    }
    // Interior faces: two cells, normal out of the first.
    for f in 0..g.num_faces() {
        let (c0, c1) = g.face_cells(f);
        let k = g.cell_faces(c0).iter().position(|&x| x == f).unwrap();
        assert!(g.cell_face_outward(c0)[k]);
        if let Some(c1) = c1 {
            let k = g.cell_faces(c1).iter().position(|&x| x == f).unwrap();
            assert!(!g.cell_face_outward(c1)[k]);
        }
    }
}

#[test]
fn cartesian_2d() {
    let g = cartesian(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 1.0), [4, 3]).unwrap();
    assert_eq!((g.num_cells(), g.num_nodes(), g.num_faces()), (12, 20, 31));
    check_identities(&g, 2.0);
    assert_eq!(g.boundary("xmin").unwrap().len(), 3);
    assert_eq!(g.boundary("ymax").unwrap().len(), 4);
    assert!((g.cell_centroid(0) - Point::<2>::new(0.25, 1.0 / 6.0)).norm() < 1e-15);
}

#[test]
fn cartesian_3d() {
    let g = cartesian(
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(1.0, 2.0, 3.0),
        [2, 3, 4],
    )
    .unwrap();
    assert_eq!((g.num_cells(), g.num_nodes()), (24, 60));
    // faces: x-normal 3*3*4 + y-normal 2*4*4 + z-normal 2*3*5
    assert_eq!(g.num_faces(), 36 + 32 + 30);
    check_identities(&g, 6.0);
    assert_eq!(g.boundary("zmax").unwrap().len(), 6);
}

#[test]
fn triangles_and_tetrahedra() {
    let g = simplices(Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 1.0), [5, 5]).unwrap();
    assert_eq!((g.num_cells(), g.num_nodes(), g.num_faces()), (50, 36, 85));
    check_identities(&g, 1.0);
    // The diagonal (i,j)-(i+1,j+1): cell 0 and 1 share the face (0,0)-(h,h).
    let shared: Vec<_> = g
        .cell_faces(0)
        .iter()
        .filter(|f| g.cell_faces(1).contains(f))
        .collect();
    assert_eq!(shared.len(), 1);
    let fnodes = g.face_nodes(*shared[0]);
    let d = g.node(fnodes[0]) - g.node(fnodes[1]);
    assert!((d[0].abs() - 0.2).abs() < 1e-15 && (d[1].abs() - 0.2).abs() < 1e-15);

    let g = simplices(
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(1.0, 1.0, 1.0),
        [3, 3, 3],
    )
    .unwrap();
    assert_eq!((g.num_cells(), g.num_nodes()), (162, 64));
    check_identities(&g, 1.0);
    for c in 0..g.num_cells() {
        assert!((g.cell_volume(c) - 1.0 / 162.0).abs() < 1e-15);
    }
}
