//! MDEM law: the law test kit, the defining identities of Nilsen et al. (2017) eqs. 15–21, P1
//! equivalence on fixed cells, and error handling.

mod common;

use common::{Simplex, anisotropic, rel_diff, tetrahedron, triangle};
use nalgebra::{DMatrix, DVector};
use porofrac_grid::Point;
use porofrac_law::testkit::{KitOptions, check_all, linear_field};
use porofrac_law::{CellLaw, LawError, Scratch, Stiffness, Tensor};
use porofrac_mdem::{MdemError, MdemLaw, edge_matrix, edges};

fn kelvin<const D: usize>(t: &Tensor<D>) -> DVector<f64> {
    let pairs: &[(usize, usize)] = if D == 2 {
        &[(0, 0), (1, 1), (0, 1)]
    } else {
        &[(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
    };
    DVector::from_iterator(
        pairs.len(),
        pairs.iter().map(|&(a, b)| {
            if a == b {
                t[(a, a)]
            } else {
                std::f64::consts::SQRT_2 * t[(a, b)]
            }
        }),
    )
}

fn materials<const D: usize>() -> Vec<Stiffness<D>> {
    let k = D * (D + 1) / 2;
    vec![
        Stiffness::<D>::isotropic(2.5, 0.3).unwrap(),
        Stiffness::<D>::from_kelvin(anisotropic(k).as_view()).unwrap(),
    ]
}

fn run_kit<const D: usize>(s: &Simplex<D>) {
    for mat in materials::<D>() {
        let law = MdemLaw::<D>::new(&mat).unwrap();
        let report = check_all(&law, &s.cell(), Some(&mat), &KitOptions::default())
            .unwrap_or_else(|e| panic!("{D}D: {e}"));
        println!("{D}D kit report: {report:?}");
        // Linear law: the kit's exact checks hold to round-off.
        assert!(report.symmetry <= 1e-14, "{report:?}");
        assert!(report.rigid_body <= 1e-12, "{report:?}");
        assert!(report.linear_energy.unwrap() <= 1e-12, "{report:?}");
        assert!(report.linear_stress.unwrap() <= 1e-12, "{report:?}");
    }
}

#[test]
fn law_test_kit_2d() {
    run_kit(&triangle());
}

#[test]
fn law_test_kit_3d() {
    run_kit(&tetrahedron());
}

/// U = M ε for u = A x + b (any skew part of A and shift b are invisible), and
/// Mᵀ 𝐊 M = |K| D (eq. 20 with the volume factor).
fn identities<const D: usize>(s: &Simplex<D>) {
    let cell = s.cell();
    let m = edge_matrix(&s.coords).unwrap();
    let a = Tensor::<D>::from_fn(|i, j| 1e-3 * ((3 * i + 2 * j) as f64 - 2.5));
    let b = Point::<D>::from_fn(|i, _| 0.01 * (i as f64 + 1.0));
    let mut u = vec![0.0; D * (D + 1)];
    linear_field(&cell, &a, &b, &mut u);
    let eps = kelvin::<D>(&((a + a.transpose()) * 0.5));
    for mat in materials::<D>() {
        let d = mat.to_dmatrix();
        let law = MdemLaw::<D>::new(&mat).unwrap();
        let k = d.nrows();
        let mut du = vec![0.0; k];
        law.edge_elongations(&s.coords, &u, &mut du).unwrap();
        let me = &m * &eps;
        let err_u = (DVector::from_column_slice(&du) - &me).amax() / me.amax();
        assert!(err_u < 1e-13, "U = M ε: {err_u:e}");

        let kk = law.edge_stiffness(&s.coords).unwrap();
        let err_k = rel_diff(&(m.transpose() * &kk * &m), &(&d * s.volume));
        assert!(err_k < 1e-13, "Mᵀ𝐊M = |K|D: {err_k:e}");

        // Edge forces F = 𝐊U, stress (eq. 18) σ = (1/|K|) Mᵀ F = D ε.
        let mut f = vec![0.0; k];
        law.edge_forces(&s.coords, &u, &mut f).unwrap();
        let fv = DVector::from_column_slice(&f);
        let err_f = (&fv - &kk * DVector::from_column_slice(&du)).amax() / fv.amax();
        assert!(err_f < 1e-14, "F = 𝐊U: {err_f:e}");
        let sig18 = m.transpose() * &fv / s.volume;
        let de = &d * &eps;
        assert!((&sig18 - &de).amax() / de.amax() < 1e-12);
        let sig = law.stress(&cell, &u, &mut Scratch::default()).unwrap();
        let err_s = (kelvin::<D>(&sig) - &de).amax() / de.amax();
        assert!(err_s < 1e-12, "stress: {err_s:e}");

        // Nodal forces are the edge forces along the edges, restoring: node a gets
        // +F t, node b gets −F t.
        let mut fn_ = vec![0.0; D * (D + 1)];
        law.forces(&cell, &u, &mut fn_, &mut Scratch::default())
            .unwrap();
        let mut expect = vec![0.0; D * (D + 1)];
        for (e, &(p, q)) in edges(D).iter().enumerate() {
            let t = (s.coords[q] - s.coords[p]).normalize();
            for c in 0..D {
                expect[D * p + c] += f[e] * t[c];
                expect[D * q + c] -= f[e] * t[c];
            }
        }
        let scale = expect.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (x, y) in fn_.iter().zip(&expect) {
            assert!((x - y).abs() <= 1e-14 * scale, "{x} vs {y}");
        }

        // Energy ½ UᵀKU = |K| ½ ε·Dε.
        let e = law.energy(&cell, &u, &mut Scratch::default()).unwrap();
        let e_ref = 0.5 * s.volume * eps.dot(&(&d * &eps));
        assert!((e - e_ref).abs() <= 1e-13 * e_ref, "{e} vs {e_ref}");
        let e_edges = 0.5 * DVector::from_column_slice(&du).dot(&fv);
        assert!((e_edges - e_ref).abs() <= 1e-12 * e_ref);
    }
}

#[test]
fn defining_identities_2d() {
    identities(&triangle());
}

#[test]
fn defining_identities_3d() {
    identities(&tetrahedron());
}

fn p1<const D: usize>(s: &Simplex<D>) {
    for mat in materials::<D>() {
        let law = MdemLaw::<D>::new(&mat).unwrap();
        let mut k = DMatrix::zeros(0, 0);
        let u = vec![0.0; D * (D + 1)];
        law.stiffness(&s.cell(), &u, &mut k, &mut Scratch::default())
            .unwrap();
        let err = rel_diff(&k, &s.p1_stiffness(&mat.to_dmatrix()));
        println!("{D}D MDEM vs P1: relative difference {err:e}");
        assert!(err < 1e-12, "{D}D MDEM vs P1: {err:e}");
    }
}

#[test]
fn stiffness_equals_p1_on_fixed_cells() {
    p1(&triangle());
    p1(&tetrahedron());
}

#[test]
fn non_simplex_cells_give_errors() {
    let law = MdemLaw::<2>::new(&Stiffness::<2>::isotropic(1.0, 0.25).unwrap()).unwrap();
    assert!(law.supports(3));
    assert!(!law.supports(4));
    let law3 = MdemLaw::<3>::new(&Stiffness::<3>::isotropic(1.0, 0.25).unwrap()).unwrap();
    assert!(law3.supports(4) && !law3.supports(8));

    let quad = [
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(1.0, 0.0),
        Point::<2>::new(1.0, 1.0),
        Point::<2>::new(0.0, 1.0),
    ];
    let normals = [Point::<2>::zeros(); 4];
    let cell = porofrac_law::CellGeometry {
        coords: &quad,
        node_normals: &normals,
        volume: 1.0,
    };
    let u = [0.0; 8];
    let mut s = Scratch::default();
    let unsupported = LawError::UnsupportedNodeCount {
        nodes: 4,
        expected: 3,
    };
    assert_eq!(law.energy(&cell, &u, &mut s), Err(unsupported.clone()));
    let mut f = [0.0; 8];
    assert_eq!(
        law.forces(&cell, &u, &mut f, &mut s),
        Err(unsupported.clone())
    );
    assert!(f.iter().all(|&v| v == 0.0));
    let mut k = DMatrix::zeros(1, 1);
    assert_eq!(
        law.stiffness(&cell, &u, &mut k, &mut s),
        Err(unsupported.clone())
    );
    assert_eq!(law.stress(&cell, &u, &mut s), Err(unsupported));
    assert_eq!(
        law.try_energy(&cell, &u),
        Err(MdemError::NotASimplex {
            got: 4,
            expected: 3
        })
    );

    // Wrong displacement length on a good simplex.
    let t = triangle();
    assert_eq!(
        law.try_energy(&t.cell(), &[0.0; 5]),
        Err(MdemError::Length {
            what: "u",
            got: 5,
            expected: 6
        })
    );
    // Degenerate triangle.
    let flat = [
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(1.0, 0.0),
        Point::<2>::new(3.0, 1e-14),
    ];
    assert!(matches!(
        law.edge_stiffness(&flat),
        Err(MdemError::Degenerate { .. })
    ));
}

#[test]
fn bad_materials_are_errors() {
    assert!(matches!(
        MdemLaw::<2>::from_kelvin(&DMatrix::identity(6, 6)),
        Err(MdemError::MaterialShape {
            rows: 6,
            cols: 6,
            expected: 3
        })
    ));
    let mut d = DMatrix::<f64>::identity(3, 3);
    d[(0, 1)] = 0.5;
    assert!(matches!(
        MdemLaw::<2>::from_kelvin(&d),
        Err(MdemError::MaterialNotSymmetric { i: 0, j: 1, .. })
    ));
    d[(1, 0)] = 2.0;
    d[(0, 1)] = 2.0;
    assert_eq!(
        MdemLaw::<2>::from_kelvin(&d),
        Err(MdemError::MaterialNotPositiveDefinite)
    );
    d[(0, 1)] = f64::NAN;
    assert!(matches!(
        MdemLaw::<2>::from_kelvin(&d),
        Err(MdemError::MaterialNotFinite { .. })
    ));
    assert_eq!(
        MdemLaw::<4>::from_kelvin(&DMatrix::identity(10, 10)),
        Err(MdemError::UnsupportedDimension(4))
    );
}
