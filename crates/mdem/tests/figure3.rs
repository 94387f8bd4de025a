//! Nilsen et al. (2017) §3, first example / Figure 3: `T = C − 𝒦(diag 𝒦⁻¹(C))`, the
//! stiffness lost when a triangle keeps only the diagonal of its MDEM edge stiffness.
//! Material: E = 1, ν = 1/4, plane strain (for plane stress the equilateral triangle's 𝐊 is
//! diagonal at ν = 1/3 instead, checked below, so the paper's statement fixes plane
//! strain).

use nalgebra::DMatrix;
use porofrac_grid::Point;
use porofrac_law::Stiffness;
use porofrac_mdem::{
    cauchy_from_edge_stiffness, dem_stiffness_loss, edge_stiffness_from_cauchy, edges,
};

fn tri(x: f64, y: f64) -> [Point<2>; 3] {
    // Base along x (edge (0,1) of the edge order), apex moved.
    [
        Point::<2>::new(-0.5, 0.0),
        Point::<2>::new(0.5, 0.0),
        Point::<2>::new(x, y),
    ]
}

fn plane_strain() -> DMatrix<f64> {
    Stiffness::<2>::isotropic(1.0, 0.25).unwrap().to_dmatrix()
}

const H: f64 = 0.866_025_403_784_438_6; // √3/2

#[test]
fn equilateral_triangle_has_diagonal_k_and_zero_loss() {
    let c = plane_strain();
    let t = tri(0.0, H);
    let k = edge_stiffness_from_cauchy(&t, &c).unwrap();
    let off = (0..3)
        .flat_map(|i| (0..3).filter(move |&j| j != i).map(move |j| (i, j)))
        .fold(0.0_f64, |m, (i, j)| m.max(k[(i, j)].abs()));
    println!("equilateral 𝐊 = {k}");
    assert!(off <= 1e-12 * k.amax(), "off-diagonal {off:e}");
    let loss = dem_stiffness_loss(&t, &c).unwrap();
    assert!(loss.amax() <= 1e-12, "|T| = {:e}", loss.amax());
    // Diagonal springs all equal (by symmetry) to the closed form: with λ = μ = 0.4,
    // C = (k l²/|K|) Σ n nᵀ and Σ n nᵀ has λ-entry 3/8, so k = 0.4 |K| / (3/8 l²)
    // = 0.4 (√3/4) · 8/3.
    let k_closed = 0.4 * (3f64.sqrt() / 4.0) * 8.0 / 3.0;
    for i in 0..3 {
        assert!(
            (k[(i, i)] - k_closed).abs() <= 1e-12 * k_closed,
            "{}",
            k[(i, i)]
        );
    }
}

#[test]
fn plane_stress_quarter_is_not_diagonal_but_one_third_is() {
    let t = tri(0.0, H);
    let ps = Stiffness::<2>::isotropic_plane_stress(1.0, 0.25)
        .unwrap()
        .to_dmatrix();
    let loss = dem_stiffness_loss(&t, &ps).unwrap();
    assert!(loss.amax() > 1e-2, "{}", loss.amax());
    let ps3 = Stiffness::<2>::isotropic_plane_stress(1.0, 1.0 / 3.0)
        .unwrap()
        .to_dmatrix();
    assert!(dem_stiffness_loss(&t, &ps3).unwrap().amax() <= 1e-12);
}

#[test]
fn symmetry_line_has_zero_t13_t23() {
    let c = plane_strain();
    for i in 0..=20 {
        let y = 0.3 + 1.2 * i as f64 / 20.0;
        let t = dem_stiffness_loss(&tri(0.0, y), &c).unwrap();
        assert!(
            t[(0, 2)].abs() <= 1e-12 && t[(1, 2)].abs() <= 1e-12,
            "y = {y}: {t}"
        );
        assert!(t[(2, 0)].abs() <= 1e-12 && t[(2, 1)].abs() <= 1e-12);
        if (y - H).abs() > 0.05 {
            assert!(
                t.amax() > 1e-3,
                "y = {y}: T should not vanish off the equilateral"
            );
        }
    }
    // Off the line the 13/23 components do not vanish.
    let t = dem_stiffness_loss(&tri(0.3, 0.8), &c).unwrap();
    assert!(t[(0, 2)].abs() > 1e-3 && t[(1, 2)].abs() > 1e-3, "{t}");
}

#[test]
fn breaking_the_x_aligned_edge_changes_only_c11() {
    let c = plane_strain();
    assert_eq!(edges(2)[0], (0, 1));
    for ix in -4..=4 {
        for iy in 0..=6 {
            let t = tri(0.15 * ix as f64, 0.4 + 0.15 * iy as f64);
            let k = edge_stiffness_from_cauchy(&t, &c).unwrap();
            let kd = DMatrix::from_diagonal(&k.diagonal());
            let mut kb = kd.clone();
            kb[(0, 0)] = 0.0;
            let diff = cauchy_from_edge_stiffness(&t, &kd).unwrap()
                - cauchy_from_edge_stiffness(&t, &kb).unwrap();
            // Row 0 of M is l·[1, 0, 0] (l = 1), so the change is k₀₀ l² / |K| in C₁₁ only.
            let area = 0.5 * t[2][1];
            let expect = k[(0, 0)] / area;
            assert!((diff[(0, 0)] - expect).abs() <= 1e-12 * expect);
            for i in 0..3 {
                for j in 0..3 {
                    if (i, j) != (0, 0) {
                        assert!(
                            diff[(i, j)].abs() <= 1e-12,
                            "({i},{j}) = {:e}",
                            diff[(i, j)]
                        );
                    }
                }
            }
        }
    }
}
