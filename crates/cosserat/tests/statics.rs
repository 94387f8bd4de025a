//! Static verification against closed forms (the patch tests, shear layer and plate with a
//! hole of Marazzato (2021) §3.8–§3.9):
//!
//! * patch tests 1 and 2 (E1): affine `u`, constant `φ`, Dirichlet (Nitsche) on the whole
//!   boundary; every cell stress equals the exact constant stress to 1e-9 relative, on the
//!   crossed E1 mesh and on a perturbed mesh, for both strain variants (test 2 with the
//!   consistent load pairing); the 3D analogue on perturbed tetrahedra
//!   (with the body couple `c_k = ε_kij σ_ij` that balances the skew stress);
//! * patch test 3 (affine stress, body force and affine body couple): cell stresses within
//!   2 % on the E1 mesh, the error falling at least at first order from 12 × 6 to 25 × 12
//!   squares (this test is not exact for the method, like CR P1 elements);
//! * rigid modes are in the kernel of the matrix without Dirichlet conditions (2D, 3D);
//! * the shear boundary layer (E3) against its closed form: 2 % pointwise for φ and u1,
//!   τ within 1 %.

mod common;

use std::sync::Arc;

use common::{clamp_all, sample};
use porofrac_cosserat::reference::ShearLayer;
use porofrac_cosserat::{
    BodyLoads, Condition, Cosserat, Material, Options, StrainVariant, constant, mesh, strain_index,
};
use porofrac_grid::generate::{perturb, simplices};
use porofrac_grid::{Grid, Point};

fn e1_material() -> Material {
    Material::with_length(1000.0, 0.25, 500.0, 0.1).unwrap()
}

/// Patch test in 2D: exact fields with `φ = phi`, exact stresses, body couple `c`.
fn patch_2d(grid: Grid<2>, variant: StrainVariant, phi: f64, couple: f64, want: [f64; 4]) -> f64 {
    let exact = move |x: &Point<2>| vec![1e-3 * (x[0] + x[1] / 2.0), 1e-3 * (x[0] + x[1]), phi];
    let cond = clamp_all(&grid, exact);
    let body = if couple != 0.0 {
        BodyLoads::none().with(2, constant(couple))
    } else {
        BodyLoads::none()
    };
    let opts = Options {
        strain: variant,
        ..Options::default()
    };
    let model = Cosserat::new(grid, e1_material(), opts, &[cond], body).unwrap();
    let w = common::solve_checked(&model);
    let mut worst: f64 = 0.0;
    for c in 0..model.grid().num_cells() {
        let s = model.cell_stress(c, &w);
        let got = [
            s[strain_index(2, 0, 0)],
            s[strain_index(2, 1, 1)],
            s[strain_index(2, 0, 1)],
            s[strain_index(2, 1, 0)],
        ];
        for k in 0..4 {
            worst = worst.max((got[k] - want[k]).abs() / 4.0);
        }
        // Couple stress vanishes.
        worst = worst.max(
            s[strain_index(2, 2, 0)]
                .abs()
                .max(s[strain_index(2, 2, 1)].abs())
                / 4.0,
        );
    }
    // The solution is the exact field sampled at the barycentres.
    let exact_w = sample(model.grid(), exact);
    let err = w
        .iter()
        .zip(&exact_w)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let size = exact_w.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    worst.max(err / size)
}

fn e1_meshes() -> Vec<Grid<2>> {
    let lo = Point::<2>::new(-0.12, -0.06);
    let hi = Point::<2>::new(0.12, 0.06);
    vec![
        mesh::crossed(lo, hi, [25, 25]).unwrap(),
        perturb(&simplices(lo, hi, [16, 10]).unwrap(), 0.25, 7).unwrap(),
    ]
}

#[test]
fn patch_test_1_exact() {
    for g in e1_meshes() {
        for v in [StrainVariant::Facet, StrainVariant::Cell] {
            let e = patch_2d(g.clone(), v, 0.25e-3, 0.0, [4.0, 4.0, 1.5, 1.5]);
            assert!(e < 1e-9, "{v:?}: relative error {e:e}");
        }
    }
}

#[test]
fn patch_test_2_exact_with_consistent_loads() {
    for g in e1_meshes() {
        for v in [StrainVariant::Facet, StrainVariant::Cell] {
            let e = patch_2d(g.clone(), v, -0.25e-3, -1.0, [4.0, 4.0, 1.0, 2.0]);
            assert!(e < 1e-9, "{v:?}: relative error {e:e}");
        }
    }
}

/// 3D patch test: an affine displacement with a constant rotation; the cell stress is the
/// law applied to the exact strain `e = ∇u + ε·φ`.
#[test]
fn patch_test_3d_exact() {
    let g = perturb(
        &simplices(
            Point::<3>::zeros(),
            Point::<3>::new(1.0, 0.8, 0.6),
            [3, 3, 2],
        )
        .unwrap(),
        0.2,
        5,
    )
    .unwrap();
    let grad = [[1.0, 0.5, -0.3], [0.2, 1.0, 0.4], [-0.1, 0.6, 0.8]];
    let phi = [0.1, -0.2, 0.3];
    let exact = move |x: &Point<3>| {
        let mut v: Vec<f64> = (0..3)
            .map(|i| 1e-3 * (0.1 + (0..3).map(|j| grad[i][j] * x[j]).sum::<f64>()))
            .collect();
        v.extend(phi.iter().map(|p| 1e-3 * p));
        v
    };
    let m = Material::with_couple_moduli(1000.0, 0.25, 300.0, [1.0, 2.0, 0.5]).unwrap();
    let law = m.law_matrix(3);
    let mut strain = [0.0; 18];
    for i in 0..3 {
        for j in 0..3 {
            strain[strain_index(3, i, j)] = 1e-3 * grad[i][j];
            for k in 0..3 {
                strain[strain_index(3, i, j)] +=
                    porofrac_cosserat::material::levi_civita(3, i, j, k) * 1e-3 * phi[k];
            }
        }
    }
    let want: Vec<f64> = (0..18)
        .map(|r| (0..18).map(|q| law[(r, q)] * strain[q]).sum())
        .collect();
    let scale = want.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    // Body couple balancing the skew stress: c_k = ε_kij σ_ij.
    let mut body = BodyLoads::none();
    for k in 0..3 {
        let mut ck = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                ck += porofrac_cosserat::material::levi_civita(3, i, j, k)
                    * want[strain_index(3, i, j)];
            }
        }
        body = body.with(3 + k, constant(ck));
    }
    for v in [StrainVariant::Facet, StrainVariant::Cell] {
        let opts = Options {
            strain: v,
            ..Options::default()
        };
        let cond = clamp_all(&g, exact);
        let model = Cosserat::new(g.clone(), m.clone(), opts, &[cond], body.clone()).unwrap();
        let w = common::solve_checked(&model);
        for c in 0..g.num_cells() {
            let s = model.cell_stress(c, &w);
            for r in 0..18 {
                assert!(
                    (s[r] - want[r]).abs() < 1e-9 * scale,
                    "{v:?} cell {c} entry {r}: {} vs {}",
                    s[r],
                    want[r]
                );
            }
        }
    }
}

/// `|K r| ≤ 1e-12 Σ|K||r|` rowwise for every rigid mode `r`.
fn kernel_defect<const D: usize>(model: &Cosserat<D>, modes: &[Vec<f64>]) -> f64 {
    let p = model.pattern();
    let vals = model.system_values();
    let abs: Vec<f64> = vals.iter().map(|v| v.abs()).collect();
    let mut worst: f64 = 0.0;
    for r in modes {
        let mut y = vec![0.0; r.len()];
        let mut ya = vec![0.0; r.len()];
        let ra: Vec<f64> = r.iter().map(|v| v.abs()).collect();
        p.mul(&vals, r, &mut y);
        p.mul(&abs, &ra, &mut ya);
        for i in 0..y.len() {
            if ya[i] > 0.0 {
                worst = worst.max(y[i].abs() / ya[i]);
            }
        }
    }
    worst
}

#[test]
fn rigid_modes_in_the_kernel() {
    let g2 = perturb(
        &simplices(Point::<2>::zeros(), Point::<2>::new(1.0, 0.6), [8, 5]).unwrap(),
        0.2,
        1,
    )
    .unwrap();
    let m = e1_material();
    for v in [StrainVariant::Facet, StrainVariant::Cell] {
        let opts = Options {
            strain: v,
            ..Options::default()
        };
        let model = Cosserat::new(g2.clone(), m.clone(), opts, &[], BodyLoads::none()).unwrap();
        let modes = vec![
            sample(&g2, |_| vec![1.0, 0.0, 0.0]),
            sample(&g2, |_| vec![0.0, 1.0, 0.0]),
            sample(&g2, |x| vec![-x[1], x[0], 1.0]),
        ];
        let d = kernel_defect(&model, &modes);
        assert!(d < 1e-12, "2D {v:?}: {d:e}");
    }
    let g3 = perturb(
        &simplices(
            Point::<3>::zeros(),
            Point::<3>::new(1.0, 0.6, 0.5),
            [3, 2, 2],
        )
        .unwrap(),
        0.2,
        2,
    )
    .unwrap();
    let m3 = Material::with_couple_moduli(1000.0, 0.25, 300.0, [1.0, 2.0, 0.5]).unwrap();
    let model = Cosserat::new(g3.clone(), m3, Options::default(), &[], BodyLoads::none()).unwrap();
    let mut modes = Vec::new();
    for a in 0..3 {
        let mut e = Point::<3>::zeros();
        e[a] = 1.0;
        modes.push(sample(&g3, move |_| {
            let mut v = vec![0.0; 6];
            v[a] = 1.0;
            v
        }));
        modes.push(sample(&g3, move |x| {
            let u = e.cross(x);
            vec![u[0], u[1], u[2], e[0], e[1], e[2]]
        }));
    }
    let d = kernel_defect(&model, &modes);
    assert!(d < 1e-12, "3D: {d:e}");
    // And the matrix is not zero on a non-rigid field.
    let stretch = sample(&g3, |x| vec![x[0], 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert!(kernel_defect(&model, &[stretch]) > 1e-3);
}

/// The shear layer of Marazzato (2021) §3.9.2, u1 = 1e-5 m on top, no end rotations: strip
/// of width h = 1 mm, 10 × 50 crossed squares, ν = 0, G = 10 GPa, Gc = 20 GPa, couple modulus
/// 4Gℓ² = 100 N.
pub fn shear_layer(variant: StrainVariant, ends: [f64; 4]) -> (f64, f64, f64) {
    let h = 1e-3;
    let grid = mesh::crossed(
        Point::<2>::new(-h / 2.0, 0.0),
        Point::<2>::new(h / 2.0, h),
        [10, 50],
    )
    .unwrap();
    let m = Material::with_length(1e10, 0.0, 2e10, 0.05e-3).unwrap();
    let [u0, p0, u1, p1] = ends;
    let bottom = Condition::new(grid.boundary("ymin").unwrap())
        .fix(0, constant(u0))
        .fix(1, constant(0.0))
        .fix(2, constant(p0));
    let top = Condition::new(grid.boundary("ymax").unwrap())
        .fix(0, constant(u1))
        .fix(1, constant(0.0))
        .fix(2, constant(p1));
    let mut sides = grid.boundary("xmin").unwrap();
    sides.extend(grid.boundary("xmax").unwrap());
    let mirror = Condition::new(sides).fix(1, Arc::new(|_: &Point<2>, _: f64| 0.0));
    let opts = Options {
        strain: variant,
        ..Options::default()
    };
    let model = Cosserat::new(grid, m, opts, &[bottom, top, mirror], BodyLoads::none()).unwrap();
    let w = common::solve_checked(&model);
    let exact = ShearLayer::new(h, 1e10, 2e10, 100.0, ends);
    let (mut ephi, mut eu): (f64, f64) = (0.0, 0.0);
    for k in 1..20 {
        let x = Point::<2>::new(1e-9, k as f64 * h / 20.0);
        let c = mesh::locate(model.grid(), &x).unwrap();
        let r = model.reconstruction();
        let phi = r.p1_value(model.grid(), c, &x, &w, 3, 2);
        let u = r.p1_value(model.grid(), c, &x, &w, 3, 0);
        let (pe, ue) = (exact.phi(x[1]), exact.u1(x[1]));
        if pe.abs() > 1e-6 * exact.phi(h / 2.0).abs().max(p1.abs()) {
            ephi = ephi.max((phi - pe).abs() / pe.abs());
        }
        if ue.abs() > 1e-6 * u1.abs() {
            eu = eu.max((u - ue).abs() / ue.abs());
        }
    }
    // τ: mean σ12 over the cells (constant in the exact solution).
    let n = model.grid().num_cells();
    let tau: f64 = (0..n)
        .map(|c| model.cell_stress(c, &w)[strain_index(2, 0, 1)] * model.grid().cell_volume(c))
        .sum::<f64>()
        / 1e-6;
    (ephi, eu, (tau - exact.tau).abs() / exact.tau.abs())
}

#[test]
fn shear_layer_against_closed_form() {
    for v in [StrainVariant::Facet, StrainVariant::Cell] {
        let (ephi, eu, etau) = shear_layer(v, [0.0, 0.0, 1e-5, 0.0]);
        eprintln!("shear layer A, {v:?}: φ {ephi:.4e}, u1 {eu:.4e}, τ {etau:.4e}");
        assert!(
            ephi < 0.02 && eu < 0.02 && etau < 0.01,
            "{v:?}: {ephi} {eu} {etau}"
        );
    }
}

/// Patch test 3: largest cell-stress error relative to max |σ| = 4 on an `n × n/2` crossed
/// mesh of the E1 domain.
fn patch_3(n: usize, variant: StrainVariant) -> f64 {
    let lo = Point::<2>::new(-0.12, -0.06);
    let hi = Point::<2>::new(0.12, 0.06);
    let grid = mesh::crossed(lo, hi, [n, n.div_ceil(2)]).unwrap();
    let exact = |x: &Point<2>| {
        vec![
            1e-3 * (x[0] + x[1] / 2.0),
            1e-3 * (x[0] + x[1]),
            1e-3 * (0.25 - (x[0] - x[1])),
        ]
    };
    let cond = clamp_all(&grid, exact);
    let body = BodyLoads::none()
        .with(0, constant(-1.0))
        .with(1, constant(-1.0))
        .with(2, Arc::new(|x: &Point<2>, _: f64| -2.0 * (x[0] - x[1])));
    let opts = Options {
        strain: variant,
        ..Options::default()
    };
    let model = Cosserat::new(grid, e1_material(), opts, &[cond], body).unwrap();
    let w = common::solve_checked(&model);
    let mut worst: f64 = 0.0;
    for c in 0..model.grid().num_cells() {
        let x = model.grid().cell_centroid(c);
        let d = x[0] - x[1];
        let s = model.cell_stress(c, &w);
        let want = [4.0, 4.0, 1.5 - d, 1.5 + d, -0.04, 0.04];
        let got = [
            s[strain_index(2, 0, 0)],
            s[strain_index(2, 1, 1)],
            s[strain_index(2, 0, 1)],
            s[strain_index(2, 1, 0)],
            s[strain_index(2, 2, 0)],
            s[strain_index(2, 2, 1)],
        ];
        for k in 0..6 {
            worst = worst.max((got[k] - want[k]).abs() / 4.0);
        }
    }
    worst
}

#[test]
fn patch_test_3_converges() {
    for v in [StrainVariant::Facet, StrainVariant::Cell] {
        let coarse = patch_3(12, v);
        let fine = patch_3(25, v);
        eprintln!("patch test 3, {v:?}: 12 squares {coarse:.3e}, 25 squares {fine:.3e}");
        assert!(fine < 0.02, "{v:?}: {fine}");
        // At least first order: the spacing falls by 25/12.
        assert!(
            fine < coarse * 12.0 / 25.0 * 1.1,
            "{v:?}: {coarse} → {fine}"
        );
    }
}
