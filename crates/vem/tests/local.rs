//! Deterministic tests of the VEM law on fixed cells: stabilization constants, spectra,
//! patch tests, P1 equivalence on simplices, the projection, Biot's volumetric strain,
//! and the law test kit.

mod common;

use common::*;
use nalgebra::{DMatrix, DVector, Matrix2, Matrix3};
use porofrac_grid::{Grid, Point};
use porofrac_law::testkit::{KitOptions, check_all};
use porofrac_law::{CellLaw, GeometryBuffer, Scratch, Stiffness};
use porofrac_vem::*;

const STABS: [Stabilization; 3] = [
    Stabilization::Mrst,
    Stabilization::Trace,
    Stabilization::DRecipe,
];

fn law2(s: Stabilization) -> VemLaw<2> {
    VemLaw::new(Stiffness::<2>::isotropic(1.0, 0.3).unwrap())
        .with_stabilization(s, 1.0)
        .unwrap()
}

fn law3(s: Stabilization) -> VemLaw<3> {
    VemLaw::new(Stiffness::<3>::isotropic(1.0, 0.3).unwrap())
        .with_stabilization(s, 1.0)
        .unwrap()
}

fn cells2() -> Vec<(&'static str, Grid<2>)> {
    vec![
        ("unit square", polygon(unit_square())),
        (
            "triangle",
            polygon(vec![
                Point::<2>::new(0.0, 0.0),
                Point::<2>::new(2.0, 0.5),
                Point::<2>::new(0.3, 1.2),
            ]),
        ),
        (
            "regular hexagon",
            polygon(regular(6, 1.0, Point::<2>::new(3.0, -2.0))),
        ),
        ("star (non-convex)", polygon(star(5, 1.0, 0.4))),
        (
            "L-shape (non-convex)",
            polygon(vec![
                Point::<2>::new(0.0, 0.0),
                Point::<2>::new(2.0, 0.0),
                Point::<2>::new(2.0, 1.0),
                Point::<2>::new(1.0, 1.0),
                Point::<2>::new(1.0, 2.0),
                Point::<2>::new(0.0, 2.0),
            ]),
        ),
        (
            "square with hanging nodes",
            polygon(with_hanging(&unit_square(), &[1, 0, 2, 0])),
        ),
        (
            "triangle with a hanging node",
            polygon(with_hanging(&regular(3, 1.0, Point::<2>::zeros()), &[1])),
        ),
    ]
}

fn cells3() -> Vec<(&'static str, Grid<3>)> {
    let jittered: Vec<Point<3>> = cube_corners()
        .into_iter()
        .enumerate()
        .map(|(k, x)| x + jitter(k, 0.2))
        .collect();
    vec![
        (
            "tetrahedron",
            tetrahedron([
                Point::<3>::new(0.0, 0.0, 0.0),
                Point::<3>::new(1.0, 0.2, 0.1),
                Point::<3>::new(0.1, 1.3, -0.2),
                Point::<3>::new(0.3, 0.2, 0.9),
            ])
            .unwrap(),
        ),
        ("unit cube", hexahedron(cube_corners())),
        (
            "perturbed hexahedron (non-planar faces)",
            hexahedron(jittered),
        ),
        (
            "prism",
            prism(vec![
                Point::<3>::new(0.0, 0.0, 0.0),
                Point::<3>::new(1.0, 0.0, 0.1),
                Point::<3>::new(0.2, 0.9, 0.0),
                Point::<3>::new(0.1, 0.0, 1.0),
                Point::<3>::new(1.1, 0.1, 1.2),
                Point::<3>::new(0.3, 1.0, 0.9),
            ]),
        ),
        ("cube with split top face (hanging nodes)", cube_split_top()),
        (
            "12-face polyhedron, perturbed",
            twelve_faces(|k| jitter(k, 0.05)),
        ),
    ]
}

/// MRST α for the unit square, E = 1, ν = 0.3, plane strain:
/// |K| (D11 + D22 + 2 D33) / (2 Σ|x_i − x̄|²) = (2·1.346154 + 2·0.769231)/(2·2) = 55/52.
#[test]
fn alpha_unit_square() {
    let g = polygon(unit_square());
    let mut b = GeometryBuffer::default();
    let cell = b.load(&g, 0);
    let a = law2(Stabilization::Mrst).alpha(&cell).unwrap();
    assert!((a - 55.0 / 52.0).abs() < 1e-14, "{a}");
    assert!((a - 1.0577).abs() < 5e-5, "{a}");
    // Trace recipe: |K| tr(D) / (1.5 Σ|d|²) = (2·35/26 + 10/13)/(1.5·2) = 45/78... computed:
    // tr D = 1.346154·2 + 0.769231 = 3.461538 = 45/13; / 3 = 15/13.
    let t = law2(Stabilization::Trace).alpha(&cell).unwrap();
    assert!((t - 15.0 / 13.0).abs() < 1e-14, "{t}");
    let scaled = law2(Stabilization::Mrst)
        .with_stabilization(Stabilization::Mrst, 2.5)
        .unwrap();
    assert!((scaled.alpha(&cell).unwrap() - 2.5 * 55.0 / 52.0).abs() < 1e-14);
    assert_eq!(law2(Stabilization::DRecipe).alpha(&cell), None);
}

/// MRST α for the unit cube, E = 1, ν = 0.3: λ = 15/26, μ = 5/13,
/// |K| (3(λ+2μ) + 2·3·2μ) / (3 Σ|x_i − x̄|²) = (3·35/26 + 60/13) / (3·8·¾) = (225/26)/18
/// = 25/52 ≈ 0.480769.
#[test]
fn alpha_unit_cube() {
    let g = hexahedron(cube_corners());
    let mut b = GeometryBuffer::default();
    let a = law3(Stabilization::Mrst).alpha(&b.load(&g, 0)).unwrap();
    assert!((a - 25.0 / 52.0).abs() < 1e-14, "{a}");
}

/// Hourglass mode of the unit square, u_x = (1, −1, 1, −1), u_y = 0: its projection is
/// zero (G = Σ γ_j N_j = 0, ū = 0), so the energy is pure stabilization, ½ α |u|² = 2α.
#[test]
fn hourglass_energy_unit_square() {
    let g = polygon(unit_square());
    let mut b = GeometryBuffer::default();
    let cell = b.load(&g, 0);
    let u = [1.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0, 0.0];
    let law = law2(Stabilization::Mrst);
    let mut s = Scratch::default();
    let e = law.energy(&cell, &u, &mut s).unwrap();
    assert!((e - 2.0 * 55.0 / 52.0).abs() < 1e-14, "{e}");
    assert!(law.stress(&cell, &u, &mut s).unwrap().amax() < 1e-15);
    assert!(volumetric_strain(&cell, &u).abs() < 1e-15);
}

/// Symmetric PSD with exactly 3 (2D) / 6 (3D) null modes, for every cell and every
/// stabilization. Prints the spectra.
#[test]
fn spectra_of_fixed_cells() {
    let mut b2 = GeometryBuffer::default();
    let mut b3 = GeometryBuffer::default();
    let mut a = DMatrix::zeros(0, 0);
    let mut s = Scratch::default();
    for st in STABS {
        for (name, g) in cells2() {
            law2(st).local_stiffness(&b2.load(&g, 0), &mut a, &mut s);
            let sp = assert_spectrum::<2>(&a, &format!("{name} {st:?}"));
            println!(
                "{st:?} {name}: null ≤ {:.1e}, smallest other {:.2e}",
                sp.worst_zero, sp.smallest_nonzero
            );
        }
        for (name, g) in cells3() {
            law3(st).local_stiffness(&b3.load(&g, 0), &mut a, &mut s);
            let sp = assert_spectrum::<3>(&a, &format!("{name} {st:?}"));
            println!(
                "{st:?} {name}: null ≤ {:.1e}, smallest other {:.2e}",
                sp.worst_zero, sp.smallest_nonzero
            );
        }
    }
}

/// Local patch test: A_K (A x + b) = σ N_i at every node to 1e-10, σ_h = C : sym(A) to
/// 1e-12, for every cell, every stabilization, isotropic and anisotropic materials.
#[test]
fn patch_test_fixed_cells() {
    let grad2 = Matrix2::new(1e-3, -4e-4, 7e-4, 2e-4);
    let grad3 = Matrix3::new(1e-3, -4e-4, 2e-4, 7e-4, 2e-4, -3e-4, 5e-4, 1e-4, -6e-4);
    let aniso2 =
        Stiffness::<2>::from_kelvin_rows(&[5.0, 1.0, 0.4, 1.0, 3.0, -0.3, 0.4, -0.3, 2.0]).unwrap();
    let mut worst: f64 = 0.0;
    for st in STABS {
        for m in [Stiffness::<2>::isotropic(1.0, 0.3).unwrap(), aniso2.clone()] {
            let law = VemLaw::new(m).with_stabilization(st, 1.0).unwrap();
            for (name, g) in cells2() {
                let mut b = GeometryBuffer::default();
                let (ef, es) =
                    patch_errors(&law, &b.load(&g, 0), &grad2, &Point::<2>::new(0.3, -0.1));
                assert!(
                    ef < 1e-10 && es < 1e-12,
                    "{name} {st:?}: force {ef:e} stress {es:e}"
                );
                worst = worst.max(ef);
            }
        }
        for (name, g) in cells3() {
            let mut b = GeometryBuffer::default();
            let (ef, es) = patch_errors(
                &law3(st),
                &b.load(&g, 0),
                &grad3,
                &Point::<3>::new(0.3, -0.1, 0.2),
            );
            assert!(
                ef < 1e-10 && es < 1e-12,
                "{name} {st:?}: force {ef:e} stress {es:e}"
            );
            worst = worst.max(ef);
        }
    }
    println!("worst patch-test force error {worst:e}");
}

/// On simplices P = I, the stabilization vanishes, and VEM = P1 FEM to 1e-12.
#[test]
fn simplices_equal_p1() {
    let mut a = DMatrix::zeros(0, 0);
    let mut p = DMatrix::zeros(0, 0);
    let mut s = Scratch::default();
    let tri = vec![
        Point::<2>::new(0.1, 0.0),
        Point::<2>::new(2.0, 0.5),
        Point::<2>::new(0.3, 1.2),
    ];
    let g = polygon(tri.clone());
    let mut b = GeometryBuffer::default();
    let cell = b.load(&g, 0);
    projection_matrix(&cell, &mut p);
    assert!((&p - DMatrix::<f64>::identity(6, 6)).amax() < 1e-14);
    let m = Stiffness::<2>::isotropic(1.0, 0.3).unwrap();
    let reference = p1_stiffness::<2>(cell.coords, &m);
    for st in STABS {
        law2(st).local_stiffness(&cell, &mut a, &mut s);
        let err = (&a - &reference).amax() / reference.amax();
        assert!(err < 1e-12, "{st:?}: {err:e}");
    }
    let gt = &cells3()[0].1;
    let mut b3 = GeometryBuffer::default();
    let cell = b3.load(gt, 0);
    projection_matrix(&cell, &mut p);
    assert!((&p - DMatrix::<f64>::identity(12, 12)).amax() < 1e-14);
    let m3 = Stiffness::<3>::isotropic(1.0, 0.3).unwrap();
    let reference = p1_stiffness::<3>(cell.coords, &m3);
    for st in STABS {
        law3(st).local_stiffness(&cell, &mut a, &mut s);
        let err = (&a - &reference).amax() / reference.amax();
        assert!(err < 1e-12, "{st:?}: {err:e}");
    }
}

/// P² = P and P reproduces linear fields, on every non-simplex cell.
#[test]
fn projection_is_a_projection_onto_linears() {
    let mut p = DMatrix::zeros(0, 0);
    for (name, g) in cells2() {
        let mut b = GeometryBuffer::default();
        let cell = b.load(&g, 0);
        projection_matrix(&cell, &mut p);
        assert!((&p * &p - &p).amax() < 1e-13, "{name}");
        let mut u = vec![0.0; 2 * cell.coords.len()];
        porofrac_law::testkit::linear_field(
            &cell,
            &Matrix2::new(0.3, -1.0, 2.0, 0.5),
            &Point::<2>::new(1.0, 2.0),
            &mut u,
        );
        let u = DVector::from_vec(u);
        assert!((&p * &u - &u).amax() < 1e-13, "{name}");
    }
    for (name, g) in cells3() {
        let mut b = GeometryBuffer::default();
        let cell = b.load(&g, 0);
        projection_matrix(&cell, &mut p);
        assert!((&p * &p - &p).amax() < 1e-13, "{name}");
        let mut u = vec![0.0; 3 * cell.coords.len()];
        let a = Matrix3::new(0.3, -1.0, 2.0, 0.5, 0.1, -0.7, 0.2, 0.4, 1.1);
        porofrac_law::testkit::linear_field(&cell, &a, &Point::<3>::new(1.0, 2.0, -1.0), &mut u);
        let u = DVector::from_vec(u);
        assert!((&p * &u - &u).amax() < 1e-13, "{name}");
    }
}

/// An anisotropic 3D material: isotropic plus a rank-one Kelvin term (SPD).
fn aniso3() -> Stiffness<3> {
    let v = DVector::from_vec(vec![1.0, -0.5, 0.2, 0.3, 0.1, -0.4]);
    let m = Stiffness::<3>::isotropic(2.0, 0.3).unwrap().to_dmatrix() + &v * v.transpose();
    Stiffness::<3>::from_kelvin(m.as_view()).unwrap()
}

/// The consistency part equals |K| W_c D W_cᵀ formed with dense products (checks the
/// direct formulas: the isotropic fast path and the general tensor path), with the stabilization removed by the hourglass-free check
/// A_K − |K| W_c D W_cᵀ = α (I − P)ᵀ (I − P) for the uniform stabilizations.
#[test]
fn direct_formula_matches_dense_products() {
    let mut a = DMatrix::zeros(0, 0);
    let mut w = DMatrix::zeros(0, 0);
    let mut p = DMatrix::zeros(0, 0);
    let mut s = Scratch::default();
    for (name, g) in cells3() {
        let mut b = GeometryBuffer::default();
        let cell = b.load(&g, 0);
        for (st, law) in [Stabilization::Mrst, Stabilization::Trace]
            .into_iter()
            .flat_map(|st| {
                [
                    (st, law3(st)),
                    (
                        st,
                        VemLaw::new(aniso3()).with_stabilization(st, 1.0).unwrap(),
                    ),
                ]
            })
        {
            law.local_stiffness(&cell, &mut a, &mut s);
            strain_matrix(&cell, &mut w);
            projection_matrix(&cell, &mut p);
            let nd = p.nrows();
            let q = DMatrix::<f64>::identity(nd, nd) - &p;
            let dense = &w * law.material().to_dmatrix() * w.transpose() * cell.volume
                + q.transpose() * &q * law.alpha(&cell).unwrap();
            let err = (&a - &dense).amax() / a.amax();
            assert!(err < 1e-13, "{name} {st:?}: {err:e}");
        }
    }
}

/// Scaling the stabilization: A(s) = A_c + s·A_stab, so A(3) − A(1) = 2 (A(2) − A(1)),
/// and A(2) ≠ A(1) on a non-simplex. Invalid scales are errors.
#[test]
fn stabilization_scale_is_linear() {
    let g = polygon(star(4, 1.0, 0.5));
    let mut b = GeometryBuffer::default();
    let cell = b.load(&g, 0);
    let mut s = Scratch::default();
    for st in STABS {
        let mats: Vec<DMatrix<f64>> = [1.0, 2.0, 3.0]
            .iter()
            .map(|&k| {
                let mut a = DMatrix::zeros(0, 0);
                law2(st)
                    .with_stabilization(st, k)
                    .unwrap()
                    .local_stiffness(&cell, &mut a, &mut s);
                a
            })
            .collect();
        let d1 = &mats[1] - &mats[0];
        let d2 = &mats[2] - &mats[0];
        assert!(d1.amax() > 1e-3 * mats[0].amax(), "{st:?}");
        assert!((d2 - d1 * 2.0).amax() < 1e-13 * mats[0].amax(), "{st:?}");
    }
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            law2(Stabilization::Mrst).with_stabilization(Stabilization::Mrst, bad),
            Err(VemError::InvalidScale { .. })
        ));
    }
}

/// Biot: the volumetric strain is tr(A) for u = A x + b, and |K| times it is the exact
/// derivative of the cell volume along u. The grid's volume of the moved cell (nodes
/// x + h u, same face triangulation) is a cubic polynomial in h, so the central difference
/// is V'(0) + h² V'''(0)/6 and the Richardson combination (4 D(h/2) − D(h))/3 is exact up
/// to round-off; with h = 1e-2 the tolerance is 1e-11 relative to Σ_i |N_i| |u_i|.
#[test]
fn volumetric_strain_is_exact_volume_change() {
    for (name, g) in cells3() {
        let mut b = GeometryBuffer::default();
        let cell = b.load(&g, 0);
        let n = cell.coords.len();
        let mut u = vec![0.0; 3 * n];
        let a = Matrix3::new(0.3, -1.0, 2.0, 0.5, 0.1, -0.7, 0.2, 0.4, 1.1);
        porofrac_law::testkit::linear_field(&cell, &a, &Point::<3>::new(1.0, 2.0, -1.0), &mut u);
        assert!(
            (volumetric_strain(&cell, &u) - a.trace()).abs() < 1e-13,
            "{name}"
        );
        porofrac_law::testkit::sample_displacement(&cell, 1.0, 3, &mut u);
        let mut wts = vec![0.0; 3 * n];
        volumetric_strain_weights(&cell, &mut wts);
        let dot: f64 = wts.iter().zip(&u).map(|(w, v)| w * v).sum();
        let ev = volumetric_strain(&cell, &u);
        assert!((dot - ev).abs() < 1e-14 * ev.abs().max(1.0), "{name}");
        // Move the nodes of the grid by ±h u and difference the volumes.
        let moved = |h: f64| {
            let mut nodes = g.nodes().to_vec();
            for (i, &gn) in g.cell_nodes(0).iter().enumerate() {
                for c in 0..3 {
                    nodes[gn][c] += h * u[3 * i + c];
                }
            }
            let mut loops = porofrac_grid::CellFaceLoops::new();
            for (&f, &o) in g.cell_faces(0).iter().zip(g.cell_face_outward(0)) {
                let l: Vec<usize> = g.oriented_face_nodes(f, o).collect();
                loops.push_face(&l);
            }
            loops.finish_cell();
            Grid::<3>::from_cell_faces(nodes, &loops)
                .unwrap()
                .cell_volume(0)
        };
        let central = |h: f64| (moved(h) - moved(-h)) / (2.0 * h);
        let h = 1e-2;
        let fd = (4.0 * central(h / 2.0) - central(h)) / 3.0;
        let exact = ev * cell.volume;
        let scale: f64 = (0..n)
            .map(|i| {
                cell.node_normals[i].norm()
                    * Point::<3>::from_column_slice(&u[3 * i..3 * i + 3]).norm()
            })
            .sum();
        assert!(
            (fd - exact).abs() < 1e-11 * scale,
            "{name}: fd {fd} vs {exact}"
        );
    }
}

/// The law test kit passes on every cell and stabilization.
#[test]
fn law_test_kit_on_vem() {
    let opts = KitOptions::default();
    let mut worst = [0.0_f64; 4];
    for st in STABS {
        for (name, g) in cells2() {
            let mut b = GeometryBuffer::default();
            let law = law2(st);
            let r = check_all(&law, &b.load(&g, 0), Some(law.material()), &opts)
                .unwrap_or_else(|e| panic!("{name} {st:?}: {e}"));
            worst[0] = worst[0].max(r.forces_gradient);
            worst[1] = worst[1].max(r.stiffness_jacobian);
            worst[2] = worst[2].max(r.rigid_body);
            worst[3] = worst[3].max(r.linear_energy.unwrap());
        }
        for (name, g) in cells3() {
            let mut b = GeometryBuffer::default();
            let law = law3(st);
            let r = check_all(&law, &b.load(&g, 0), Some(law.material()), &opts)
                .unwrap_or_else(|e| panic!("{name} {st:?}: {e}"));
            worst[0] = worst[0].max(r.forces_gradient);
            worst[1] = worst[1].max(r.stiffness_jacobian);
            worst[2] = worst[2].max(r.rigid_body);
            worst[3] = worst[3].max(r.linear_energy.unwrap());
        }
    }
    println!(
        "kit worst: forces {:.1e} stiffness {:.1e} rigid {:.1e} linear energy {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
}

/// Forces and energy agree with the assembled matrix: F = −A u, E = ½ uᵀ A u (1e-13).
#[test]
fn matrix_free_matches_matrix() {
    let mut a = DMatrix::zeros(0, 0);
    let mut s = Scratch::default();
    for st in STABS {
        for (name, g) in cells3() {
            let mut b = GeometryBuffer::default();
            let cell = b.load(&g, 0);
            let law = law3(st);
            law.local_stiffness(&cell, &mut a, &mut s);
            let mut u = vec![0.0; a.nrows()];
            porofrac_law::testkit::sample_displacement(&cell, 1.0, 11, &mut u);
            let uv = DVector::from_column_slice(&u);
            let au = &a * &uv;
            let mut f = vec![0.0; u.len()];
            law.forces(&cell, &u, &mut f, &mut s).unwrap();
            let ef = (DVector::from_vec(f) + &au).amax() / au.amax();
            let e = law.energy(&cell, &u, &mut s).unwrap();
            let ee = (e - 0.5 * uv.dot(&au)).abs() / e;
            assert!(ef < 1e-13 && ee < 1e-13, "{name} {st:?}: {ef:e} {ee:e}");
        }
    }
}

/// One scratch and one output matrix reused across cells of different sizes give the
/// same matrices as fresh buffers (no stale data).
#[test]
fn scratch_reuse_across_sizes() {
    let cells = cells3();
    let mut s = Scratch::default();
    let mut a = DMatrix::zeros(0, 0);
    for st in STABS {
        let law = law3(st);
        for (name, g) in cells.iter().chain(cells.iter().rev()) {
            let mut b = GeometryBuffer::default();
            let cell = b.load(g, 0);
            law.local_stiffness(&cell, &mut a, &mut s);
            let mut fresh = DMatrix::zeros(0, 0);
            law.local_stiffness(&cell, &mut fresh, &mut Scratch::default());
            assert_eq!(a, fresh, "{name}");
        }
    }
}

/// The law is usable as a trait object.
#[test]
fn vem_as_trait_object() {
    let laws: Vec<Box<dyn CellLaw<2>>> = vec![
        Box::new(law2(Stabilization::Mrst)),
        Box::new(law2(Stabilization::Trace)),
    ];
    let g = polygon(unit_square());
    let mut b = GeometryBuffer::default();
    let cell = b.load(&g, 0);
    let mut s = Scratch::default();
    let u = [0.0, 0.0, 1e-3, 0.0, 1e-3, 0.0, 0.0, 0.0]; // u_x = 1e-3 x
    for l in &laws {
        assert_eq!(l.name(), "vem");
        let sig = l.stress(&cell, &u, &mut s).unwrap();
        // σ_xx = (λ + 2μ) 1e-3 = 35/26 · 1e-3, σ_yy = λ 1e-3 = 15/26 · 1e-3.
        assert!((sig[(0, 0)] - 35.0 / 26.0 * 1e-3).abs() < 1e-17);
        assert!((sig[(1, 1)] - 15.0 / 26.0 * 1e-3).abs() < 1e-17);
    }
}
