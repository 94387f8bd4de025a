//! Reconstruction exactness (this project's check of Marazzato (2021) §3.1): for affine
//! fields the facet values (9), the Stokes gradients (11) and the P1 reconstruction (14) are
//! exact to 1e-12 relative,
//! on structured, perturbed and crossed triangles and on (perturbed) tetrahedra, including
//! boundary facets. Also: a grid with a non-simplex cell is an error naming the cell.

use porofrac_cosserat::{CosseratError, Reconstruction, mesh};
use porofrac_grid::generate::{cartesian, perturb, simplices};
use porofrac_grid::{Grid, Point};
use proptest::prelude::*;

/// Check all three operators on the affine field `w(x) = c + G x` (one component).
fn check_affine<const D: usize>(grid: &Grid<D>, c: f64, g: Point<D>) -> f64 {
    let r = Reconstruction::new(grid).unwrap();
    let w: Vec<f64> = grid.cell_centroids().iter().map(|x| c + g.dot(x)).collect();
    let scale = c.abs() + g.norm() * 1.0;
    let mut worst: f64 = 0.0;
    for f in 0..grid.num_faces() {
        let want = c + g.dot(grid.face_centroid(f));
        worst = worst.max((r.facet_value(f, &w, 1, 0) - want).abs() / scale);
    }
    for k in 0..grid.num_cells() {
        worst = worst.max((r.cell_gradient(k, &w, 1, 0) - g).norm() / g.norm().max(1e-300));
        // P1 reconstruction at a vertex of the cell.
        let x = grid.node(grid.cell_nodes(k)[0]);
        worst = worst.max((r.p1_value(grid, k, x, &w, 1, 0) - (c + g.dot(x))).abs() / scale);
    }
    worst
}

#[test]
fn affine_exact_on_structured_and_crossed_triangles() {
    let lo = Point::<2>::new(-0.12, -0.06);
    let hi = Point::<2>::new(0.12, 0.06);
    let g = Point::<2>::new(0.7, -1.3);
    assert!(check_affine(&simplices(lo, hi, [12, 6]).unwrap(), 0.4, g) < 1e-12);
    assert!(check_affine(&mesh::crossed(lo, hi, [12, 6]).unwrap(), 0.4, g) < 1e-12);
}

#[test]
fn affine_exact_on_tetrahedra() {
    let g3 = simplices(
        Point::<3>::zeros(),
        Point::<3>::new(1.0, 0.5, 0.5),
        [4, 3, 3],
    )
    .unwrap();
    let p3 = perturb(&g3, 0.2, 3).unwrap();
    let g = Point::<3>::new(0.3, -0.8, 1.1);
    assert!(check_affine(&g3, -0.2, g) < 1e-12);
    assert!(check_affine(&p3, -0.2, g) < 1e-12);
}

#[test]
fn non_simplex_cell_is_an_error_naming_it() {
    let g = cartesian(Point::<2>::zeros(), Point::<2>::new(1.0, 1.0), [2, 2]).unwrap();
    match Reconstruction::new(&g) {
        Err(CosseratError::NotSimplex { cell: 0, .. }) => {}
        other => panic!("want NotSimplex for cell 0, got {other:?}"),
    }
}

#[test]
fn weights_stay_admissible() {
    let g = perturb(
        &simplices(Point::<2>::zeros(), Point::<2>::new(1.0, 1.0), [10, 10]).unwrap(),
        0.25,
        9,
    )
    .unwrap();
    let r = Reconstruction::new(&g).unwrap();
    assert!(r.max_weight() < porofrac_cosserat::recon::MAX_WEIGHT);
    for (f, s) in r.facets.iter().enumerate() {
        assert_eq!(s.cells.len(), 3, "facet {f}");
        assert!((s.weights.iter().sum::<f64>() - 1.0).abs() < 1e-13);
        if !g.is_boundary_face(f) {
            // Interior facets interpolate when the pool allows it.
            assert!(s.weights.iter().all(|w| w.abs() < 10.0));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    /// Random perturbations of triangles and random affine fields.
    #[test]
    fn affine_exact_on_random_perturbed_triangles(
        seed in 0u64..1000, amp in 0.0f64..0.3, c in -2.0f64..2.0,
        gx in -3.0f64..3.0, gy in -3.0f64..3.0,
    ) {
        let g = perturb(&simplices(Point::<2>::zeros(), Point::<2>::new(1.0, 0.7), [7, 5]).unwrap(), amp, seed).unwrap();
        let grad = Point::<2>::new(gx, gy);
        prop_assume!(grad.norm() > 1e-3);
        prop_assert!(check_affine(&g, c, grad) < 1e-12);
    }

    /// Random perturbations of tetrahedra.
    #[test]
    fn affine_exact_on_random_perturbed_tetrahedra(
        seed in 0u64..1000, amp in 0.0f64..0.25,
        gx in -3.0f64..3.0, gy in -3.0f64..3.0, gz in -3.0f64..3.0,
    ) {
        let g = perturb(&simplices(Point::<3>::zeros(), Point::<3>::new(1.0, 1.0, 0.6), [3, 3, 2]).unwrap(), amp, seed).unwrap();
        let grad = Point::<3>::new(gx, gy, gz);
        prop_assume!(grad.norm() > 1e-3);
        prop_assert!(check_affine(&g, 0.5, grad) < 1e-12);
    }
}
