//! Property tests of the VEM law on random cells: symmetric PSD local matrices with
//! exactly D(D+1)/2 null modes (null < 1e-10 λ_max, others > 1e-8 λ_max), the local patch
//! test (forces 1e-10, stress 1e-12), and VEM = P1 on simplices (1e-12).
//!
//! Patch-test fields are `u = 1e-3 (G0 + R) (x − x̄) + 1e-3 b` with `G0 = 1.5 I`, `R`
//! random in `[−1, 1]` and `x̄` the vertex average: the strain is bounded away from zero
//! and the translation is of the same size as the strain times the cell size, so the
//! relative errors are well defined (a translation many orders larger than the strain
//! leaks the rounding of the node coordinates into the forces; `far_from_the_origin`
//! checks that leak against its bound).

mod common;

use common::*;
use nalgebra::{DMatrix, Matrix2, Matrix3};
use porofrac_grid::Point;
use porofrac_law::{GeometryBuffer, Scratch, Stiffness};
use porofrac_vem::{Stabilization, VemLaw};
use proptest::prelude::*;

fn stab(k: u8) -> Stabilization {
    [
        Stabilization::Mrst,
        Stabilization::Trace,
        Stabilization::DRecipe,
    ][k as usize % 3]
}

fn material2(nu: f64) -> Stiffness<2> {
    Stiffness::<2>::isotropic(1.0 + 10.0 * nu.abs(), nu).unwrap()
}

/// Increasing angles in [0, 2π) with gaps of at least 0.15 rad (well-shaped polygons).
fn angles(n: usize) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.15f64..1.0, n).prop_map(|gaps| {
        let total: f64 = gaps.iter().sum();
        let mut t = 0.0;
        gaps.iter()
            .map(|g| {
                let a = t;
                t += g / total * std::f64::consts::TAU;
                a
            })
            .collect()
    })
}

fn check2(
    pts: Vec<Point<2>>,
    nu: f64,
    st: Stabilization,
    grad: [f64; 4],
) -> Result<(), TestCaseError> {
    let g = polygon(pts);
    let mut b = GeometryBuffer::default();
    let cell = b.load(&g, 0);
    let law = VemLaw::new(material2(nu))
        .with_stabilization(st, 1.0)
        .unwrap();
    let mut a = DMatrix::zeros(0, 0);
    law.local_stiffness(&cell, &mut a, &mut Scratch::default());
    let s = spectrum(&a);
    prop_assert!(s.asymmetry < 1e-13, "{s:?}");
    prop_assert_eq!(s.zeros, 3, "{:?}", s);
    prop_assert!(s.smallest_nonzero > 1e-8, "{s:?}");
    let grad =
        (Matrix2::new(grad[0], grad[1], grad[2], grad[3]) + Matrix2::identity() * 1.5) * 1e-3;
    let xbar = cell.coords.iter().sum::<Point<2>>() / cell.coords.len() as f64;
    let (ef, es) = patch_errors(
        &law,
        &cell,
        &grad,
        &(Point::<2>::new(1e-3, -2e-3) - grad * xbar),
    );
    prop_assert!(
        ef < 1e-10 && es < 1e-12,
        "patch: force {ef:e} stress {es:e}"
    );
    Ok(())
}

fn check3(
    grid: porofrac_grid::Grid<3>,
    st: Stabilization,
    grad: [f64; 9],
) -> Result<(), TestCaseError> {
    let mut b = GeometryBuffer::default();
    let cell = b.load(&grid, 0);
    let law = VemLaw::new(Stiffness::<3>::isotropic(2.0, 0.27).unwrap())
        .with_stabilization(st, 1.0)
        .unwrap();
    let mut a = DMatrix::zeros(0, 0);
    law.local_stiffness(&cell, &mut a, &mut Scratch::default());
    let s = spectrum(&a);
    prop_assert!(s.asymmetry < 1e-13, "{s:?}");
    prop_assert_eq!(s.zeros, 6, "{:?}", s);
    prop_assert!(s.smallest_nonzero > 1e-8, "{s:?}");
    let grad = (Matrix3::from_row_slice(&grad) + Matrix3::identity() * 1.5) * 1e-3;
    let (ef, es) = patch_errors(&law, &cell, &grad, &Point::<3>::new(1e-3, -2e-3, 3e-3));
    prop_assert!(
        ef < 1e-10 && es < 1e-12,
        "patch: force {ef:e} stress {es:e}"
    );
    Ok(())
}

/// `u = A x + b` with the translation of a cell up to 10⁵ sizes from the origin: the
/// forces are exact to the rounding of the node coordinates, `ε |x̄| / diam` relative (up
/// to a factor 50), for every stabilization. (Before the differences `x_i − x̄` were
/// re-centred in the law, the closed-form stabilization leaked `ε |x̄|`-sized remainders
/// of the translation: 2.9e-10 at 600 sizes, 4.9e-5 at 6·10⁵.)
#[test]
fn far_from_the_origin() {
    for k in 0..3 {
        for (t, offset) in [
            (vec![0.0, 2.1, 4.2], 98.0),
            (vec![0.0, 2.1, 4.2], 1e5),
            (vec![0.0, 1.0, 2.0, 3.1, 4.2, 5.3], 1e3),
            (vec![0.0, 1.0, 2.0, 3.1, 4.2, 5.3], 1e5),
        ] {
            let pts = convex(&t, 0.2, 0.2, 0.0, Point::<2>::new(offset, 2.0 * offset));
            let g = polygon(pts);
            let mut b = GeometryBuffer::default();
            let cell = b.load(&g, 0);
            let law = VemLaw::new(material2(0.0))
                .with_stabilization(stab(k), 1.0)
                .unwrap();
            let grad = Matrix2::identity() * 1.5e-3;
            let (ef, _) = patch_errors(&law, &cell, &grad, &Point::<2>::new(1e-3, -2e-3));
            let xbar = cell.coords.iter().sum::<Point<2>>() / cell.coords.len() as f64;
            let diam = cell
                .coords
                .iter()
                .flat_map(|p| cell.coords.iter().map(move |q| (p - q).norm()))
                .fold(0.0, f64::max);
            let bound = 50.0 * f64::EPSILON * xbar.norm() / diam;
            assert!(
                ef < bound,
                "{:?} at {offset}: force {ef:e} > {bound:e}",
                stab(k)
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random convex polygons (3–12 vertices on a sheared ellipse, far from the origin).
    #[test]
    fn convex_polygons(
        t in (3usize..=12).prop_flat_map(angles),
        a in 0.2f64..3.0, b in 0.2f64..3.0, shear in -1.0f64..1.0,
        cx in -100.0f64..100.0, nu in -0.5f64..0.45, k in 0u8..3,
        grad in prop::array::uniform4(-1.0f64..1.0),
    ) {
        check2(convex(&t, a, b, shear, Point::<2>::new(cx, 2.0 * cx)), nu, stab(k), grad)?;
    }

    /// Star-shaped non-convex polygons.
    #[test]
    fn star_polygons(
        tips in 3usize..=8, r_in in 0.25f64..0.9, nu in 0.0f64..0.45, k in 0u8..3,
        grad in prop::array::uniform4(-1.0f64..1.0),
    ) {
        check2(star(tips, 1.0, r_in), nu, stab(k), grad)?;
    }

    /// Convex polygons with 0–3 hanging nodes on each edge.
    #[test]
    fn polygons_with_hanging_nodes(
        t in (3usize..=6).prop_flat_map(angles),
        extra in prop::collection::vec(0usize..=3, 6),
        a in 0.5f64..2.0, nu in 0.0f64..0.45, k in 0u8..3,
        grad in prop::array::uniform4(-1.0f64..1.0),
    ) {
        check2(with_hanging(&convex(&t, a, 1.0, 0.3, Point::<2>::zeros()), &extra), nu, stab(k), grad)?;
    }

    /// Triangles: VEM = P1 FEM (1e-12 relative), for every stabilization.
    #[test]
    fn triangles_equal_p1(
        p in prop::array::uniform6(-1.0f64..1.0), nu in -0.5f64..0.45, k in 0u8..3,
    ) {
        let mut pts = vec![Point::<2>::new(p[0], p[1]), Point::<2>::new(p[2], p[3]), Point::<2>::new(p[4], p[5])];
        let area = 0.5 * ((pts[1] - pts[0]).perp(&(pts[2] - pts[0])));
        prop_assume!(area.abs() > 0.05);
        if area < 0.0 { pts.swap(1, 2); }
        let g = polygon(pts);
        let mut b = GeometryBuffer::default();
        let cell = b.load(&g, 0);
        let m = material2(nu);
        let law = VemLaw::new(m.clone()).with_stabilization(stab(k), 1.0).unwrap();
        let mut a = DMatrix::zeros(0, 0);
        law.local_stiffness(&cell, &mut a, &mut Scratch::default());
        let r = p1_stiffness::<2>(cell.coords, &m);
        let err = (&a - &r).amax() / r.amax();
        prop_assert!(err < 1e-12, "{err:e}");
        let s = spectrum(&a);
        prop_assert_eq!(s.zeros, 3, "{:?}", s);
        prop_assert!(s.smallest_nonzero > 1e-8, "{s:?}");
    }

    /// Tetrahedra: VEM = P1 FEM (1e-12 relative), 6 null modes.
    #[test]
    fn tetrahedra_equal_p1(p in prop::array::uniform12(-1.0f64..1.0), k in 0u8..3) {
        let pts = [
            Point::<3>::new(p[0], p[1], p[2]),
            Point::<3>::new(p[3], p[4], p[5]),
            Point::<3>::new(p[6], p[7], p[8]),
            Point::<3>::new(p[9], p[10], p[11]),
        ];
        let vol = (pts[1] - pts[0]).cross(&(pts[2] - pts[0])).dot(&(pts[3] - pts[0])) / 6.0;
        prop_assume!(vol.abs() > 0.02);
        let g = tetrahedron(pts).unwrap();
        let mut b = GeometryBuffer::default();
        let cell = b.load(&g, 0);
        let m = Stiffness::<3>::isotropic(1.0, 0.3).unwrap();
        let law = VemLaw::new(m.clone()).with_stabilization(stab(k), 1.0).unwrap();
        let mut a = DMatrix::zeros(0, 0);
        law.local_stiffness(&cell, &mut a, &mut Scratch::default());
        let r = p1_stiffness::<3>(cell.coords, &m);
        let err = (&a - &r).amax() / r.amax();
        prop_assert!(err < 1e-12, "{err:e}");
        let s = spectrum(&a);
        prop_assert_eq!(s.zeros, 6, "{:?}", s);
        prop_assert!(s.smallest_nonzero > 1e-8, "{s:?}");
    }

    /// Randomly perturbed hexahedra (non-planar faces).
    #[test]
    fn perturbed_hexahedra(
        d in prop::collection::vec(-0.2f64..0.2, 24), k in 0u8..3,
        grad in prop::array::uniform9(-1.0f64..1.0),
    ) {
        let corners: Vec<Point<3>> = cube_corners()
            .into_iter()
            .enumerate()
            .map(|(i, x)| x + Point::<3>::new(d[3 * i], d[3 * i + 1], d[3 * i + 2]))
            .collect();
        check3(hexahedron(corners), stab(k), grad)?;
    }

    /// Randomly perturbed triangular prisms (non-planar quadrilateral faces).
    #[test]
    fn perturbed_prisms(
        d in prop::collection::vec(-0.15f64..0.15, 18), k in 0u8..3,
        grad in prop::array::uniform9(-1.0f64..1.0),
    ) {
        let base = [(0.0, 0.0), (1.0, 0.0), (0.3, 0.9)];
        let mut p = Vec::new();
        for z in [0.0, 1.0] {
            for (x, y) in base {
                p.push(Point::<3>::new(x, y, z));
            }
        }
        for (i, x) in p.iter_mut().enumerate() {
            *x += Point::<3>::new(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
        }
        check3(prism(p), stab(k), grad)?;
    }

    /// The 12-face, 18-node polyhedron (hanging nodes on split faces), perturbed.
    #[test]
    fn perturbed_twelve_face_polyhedra(
        d in prop::collection::vec(-0.08f64..0.08, 54), k in 0u8..3,
        grad in prop::array::uniform9(-1.0f64..1.0),
    ) {
        check3(twelve_faces(|i| Point::<3>::new(d[3 * i], d[3 * i + 1], d[3 * i + 2])), stab(k), grad)?;
    }
}
