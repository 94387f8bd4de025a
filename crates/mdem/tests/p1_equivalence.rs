//! Property test (Nilsen et al. (2017) §2.4): on every non-degenerate simplex the MDEM
//! local stiffness equals the P1 FEM stiffness `|K| Bᵀ D B` and the VEM stiffness
//! (`porofrac-vem`, whose stabilisation vanishes on simplices), for isotropic and random
//! anisotropic `D`. Tolerance: 1e-12 relative to `max |K_FEM|`.

mod common;

use common::{Simplex, rel_diff};
use nalgebra::DMatrix;
use porofrac_grid::Point;
use porofrac_law::{CellLaw, Scratch, Stiffness};
use porofrac_mdem::MdemLaw;
use porofrac_vem::VemLaw;
use proptest::prelude::*;

/// Shape-regularity filter: `|K| / l_max^D` above a threshold (the regular triangle has
/// 0.43, the regular tetrahedron 0.118).
fn regular_enough<const D: usize>(c: &[Point<D>], min: f64) -> bool {
    let s = Simplex::new(c.to_vec());
    let lmax = (0..c.len())
        .flat_map(|i| (0..i).map(move |j| (i, j)))
        .map(|(i, j)| (c[i] - c[j]).norm())
        .fold(0.0_f64, f64::max);
    s.volume / lmax.powi(D as i32) > min
}

fn simplex<const D: usize>(min_quality: f64) -> impl Strategy<Value = Vec<Point<D>>> {
    proptest::collection::vec(proptest::collection::vec(-1.0f64..1.0, D), D + 1)
        .prop_map(|v| {
            v.into_iter()
                .map(Point::<D>::from_iterator)
                .collect::<Vec<_>>()
        })
        .prop_filter("degenerate simplex", move |c| {
            let j = DMatrix::from_fn(D, D, |r, k| c[k + 1][r] - c[0][r]);
            j.determinant().abs() > 1e-3 && regular_enough(c, min_quality)
        })
}

/// Isotropic (E, ν) or anisotropic AᵀA + δI with random A.
fn material<const D: usize>() -> impl Strategy<Value = Stiffness<D>> {
    let k = D * (D + 1) / 2;
    prop_oneof![
        (0.1f64..100.0, -0.9f64..0.49)
            .prop_map(|(e, nu)| Stiffness::<D>::isotropic(e, nu).unwrap()),
        (
            proptest::collection::vec(-1.0f64..1.0, k * k),
            0.01f64..1.0,
            0.1f64..10.0
        )
            .prop_map(move |(a, delta, scale)| {
                let a = DMatrix::from_vec(k, k, a);
                let d = (a.transpose() * &a + DMatrix::identity(k, k) * delta) * scale;
                Stiffness::<D>::from_kelvin(d.as_view()).unwrap()
            }),
    ]
}

fn compare<const D: usize>(c: Vec<Point<D>>, mat: Stiffness<D>) -> Result<(), TestCaseError> {
    let s = Simplex::new(c);
    let law = MdemLaw::<D>::new(&mat).unwrap();
    let mut k = DMatrix::zeros(0, 0);
    law.stiffness(
        &s.cell(),
        &vec![0.0; D * (D + 1)],
        &mut k,
        &mut Scratch::default(),
    )
    .unwrap();
    let p1 = s.p1_stiffness(&mat.to_dmatrix());
    let err = rel_diff(&k, &p1);
    prop_assert!(
        err <= 1e-12,
        "{}D MDEM vs P1: relative difference {:e}",
        D,
        err
    );
    let vem = VemLaw::<D>::new(mat);
    let mut kv = DMatrix::zeros(0, 0);
    vem.stiffness(
        &s.cell(),
        &vec![0.0; D * (D + 1)],
        &mut kv,
        &mut Scratch::default(),
    )
    .unwrap();
    let err_v = rel_diff(&k, &kv);
    prop_assert!(
        err_v <= 1e-12,
        "{}D MDEM vs VEM: relative difference {:e}",
        D,
        err_v
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn mdem_equals_p1_on_triangles(c in simplex::<2>(0.02), mat in material::<2>()) {
        compare(c, mat)?;
    }

    #[test]
    fn mdem_equals_p1_on_tetrahedra(c in simplex::<3>(0.01), mat in material::<3>()) {
        compare(c, mat)?;
    }
}
