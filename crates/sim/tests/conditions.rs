//! Boundary-condition errors and load integration.
//!
//! * Free rigid-body modes are reported by name: none → all modes; `u_y = 0` on ymin →
//!   exactly `translation x` (the line kills y translation and rotation); 3D `u_z = 0` on
//!   zmin → translations x, y and rotation about z.
//! * Conflicting conditions name the node and both conditions; equal values at corners
//!   are accepted.
//! * A disconnected, unconstrained piece fails the factorization at one of its nodes.
//! * Nodal loads: `Σ f_i = ∫ b` and `Σ f_i ⊗ x_i = ∫ b ⊗ x` for a linear body force on
//!   simplices and on Cartesian cells (1e-12), `Σ f_i = ∫ t` and the moment for a linear
//!   traction (1e-12).
//! * Nodal loads do not depend on the cell order: the same grid with its cells shuffled
//!   (cell blocks then touch nodes all over the grid) gives the same loads up to the
//!   rounding of a different summation order (1e-14 of the largest).

mod common;

use common::{P1Law, isotropic, side};
use porofrac_grid::{Grid, Point, generate};
use porofrac_sim::*;

fn setup<const D: usize>(
    grid: &Grid<D>,
    disp: &[Displacement<D>],
    platens: &[Platen<D>],
) -> Result<Vec<f64>> {
    let law = P1Law {
        d: isotropic::<D>(1.0e9, 0.25),
    };
    let dofs = DofMap::new(grid, disp, platens)?;
    let pattern = Pattern::new(grid, &dofs)?;
    let laws = LawMap::uniform(grid, &law)?;
    let mut solver = DirectSolver::new(&pattern)?;
    let loads = Loads::default();
    let problem = StaticProblem {
        grid,
        laws: &laws,
        dofs: &dofs,
        pattern: &pattern,
        loads: &loads,
    };
    Ok(solve_static(&problem, &mut solver, 0.0, &StaticOptions::default())?.displacement)
}

fn singular_modes<const D: usize>(r: Result<Vec<f64>>) -> Vec<String> {
    match r {
        Err(SimError::Singular { modes }) => modes,
        other => panic!("expected Singular, got {:?}", other.map(|_| ())),
    }
}

#[test]
fn singular_systems_name_the_free_modes() {
    let g2 =
        generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::new(2.0, 1.0), [4, 2]).unwrap();
    assert_eq!(
        singular_modes::<2>(setup(&g2, &[], &[])),
        ["translation x", "translation y", "rotation about z"]
    );
    let ymin = side(&g2, "ymin", [None, Some(0.0.into())]);
    let modes = singular_modes::<2>(setup(&g2, std::slice::from_ref(&ymin), &[]));
    assert_eq!(modes, ["translation x"]);
    let err = setup(&g2, &[ymin], &[]).unwrap_err().to_string();
    assert!(err.contains("translation x"), "{err}");

    let g3 =
        generate::simplices::<3>(Point::<3>::zeros(), Point::<3>::repeat(1.0), [2, 2, 2]).unwrap();
    let zmin = side(&g3, "zmin", [None, None, Some(0.0.into())]);
    assert_eq!(
        singular_modes::<3>(setup(&g3, &[zmin], &[])),
        ["translation x", "translation y", "rotation about z"]
    );
    assert_eq!(singular_modes::<3>(setup(&g3, &[], &[])).len(), 6);
    // Rollers on three sides remove everything.
    let rollers = vec![
        side(&g3, "xmin", [Some(0.0.into()), None, None]),
        side(&g3, "ymin", [None, Some(0.0.into()), None]),
        side(&g3, "zmin", [None, None, Some(0.0.into())]),
    ];
    setup(&g3, &rollers, &[]).unwrap();
    // A platen along y does not remove y translation by itself.
    let platen = Platen {
        name: "ymax".into(),
        faces: g2.boundary("ymax").unwrap(),
        force: [None, Some((-1.0).into())],
    };
    let xmin = side(&g2, "xmin", [Some(0.0.into()), None]);
    assert_eq!(
        singular_modes::<2>(setup(&g2, &[xmin], &[platen])),
        ["translation y"]
    );
}

#[test]
fn conflicting_conditions_name_the_node() {
    let g =
        generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::new(1.0, 1.0), [2, 2]).unwrap();
    // The corner (0, 0) is node 0: ux = 0 from xmin and ux = 1e-3 from ymin.
    let xmin = side(&g, "xmin", [Some(0.0.into()), None]);
    let ymin = side(&g, "ymin", [Some(1e-3.into()), Some(0.0.into())]);
    match setup(&g, &[xmin.clone(), ymin], &[]) {
        Err(SimError::Conflict {
            node,
            component,
            first,
            second,
            ..
        }) => {
            assert_eq!(*g.node(node), Point::<2>::new(0.0, 0.0));
            assert_eq!(component, "x");
            assert!(
                first.contains("xmin") && second.contains("ymin"),
                "{first} / {second}"
            );
        }
        other => panic!("expected Conflict, got {:?}", other.map(|_| ())),
    }
    // Equal values at the corner are fine.
    let ymin_ok = side(&g, "ymin", [Some(0.0.into()), Some(0.0.into())]);
    setup(&g, &[xmin.clone(), ymin_ok], &[]).unwrap();
    // A platen on a component that is prescribed.
    let platen = Platen {
        name: "ymax".into(),
        faces: g.boundary("ymax").unwrap(),
        force: [Some(1.0.into()), None],
    };
    let err = setup(&g, &[xmin], &[platen]).unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(err, SimError::Conflict { component: "x", .. }),
        "{msg}"
    );
    assert!(
        msg.contains("platen on `ymax`") && msg.contains("displacement on `xmin`"),
        "{msg}"
    );
    assert!(msg.contains("(0, 1)"), "corner node named: {msg}");
}

/// A fixed square of two triangles and a separate, unconstrained triangle: the global
/// rigid modes are removed, but the island is singular; the check names it (one cell of
/// three, its three free modes) before any factorisation.
#[test]
fn unconstrained_island_fails_at_its_node() {
    let nodes = vec![
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(1.0, 0.0),
        Point::<2>::new(1.0, 1.0),
        Point::<2>::new(0.0, 1.0),
        Point::<2>::new(3.0, 0.0),
        Point::<2>::new(4.0, 0.0),
        Point::<2>::new(3.0, 1.0),
    ];
    let grid = Grid::from_polygons(nodes, &[0, 3, 6, 9], &[0, 1, 2, 0, 2, 3, 4, 5, 6]).unwrap();
    let left: Vec<usize> = (0..grid.num_faces())
        .filter(|&f| {
            grid.is_boundary_face(f) && grid.face_nodes(f).iter().all(|&n| grid.node(n)[0] == 0.0)
        })
        .collect();
    let fix = Displacement {
        name: "left".into(),
        faces: left,
        components: [Some(0.0.into()), Some(0.0.into())],
    };
    match setup(&grid, &[fix], &[]) {
        Err(e @ SimError::FloatingPart { .. }) => {
            let msg = e.to_string();
            let SimError::FloatingPart {
                cells,
                total,
                cell_index,
                modes,
                ..
            } = e
            else {
                unreachable!()
            };
            assert_eq!(
                (cells, total, cell_index, modes.len()),
                (1, 3, 2, 3),
                "{msg}"
            );
            assert!(msg.contains("cell 2 at (3.333"), "{msg}");
        }
        other => panic!("expected FloatingPart, got {:?}", other.map(|_| ())),
    }
}

fn load_moments<const D: usize>(grid: &Grid<D>) {
    // b(x) = c0 + C x, linear.
    let c0 = Point::<D>::from_fn(|i, _| 1.0 + i as f64);
    let cm = nalgebra::SMatrix::<f64, D, D>::from_fn(|i, j| 0.5 + i as f64 - 0.25 * j as f64);
    let body: [ScalarField; D] = std::array::from_fn(|a| {
        ScalarField::from_fn(move |x, _| c0[a] + (0..D).map(|j| cm[(a, j)] * x[j]).sum::<f64>())
    });
    let loads = Loads {
        body_force: Some(body.into()),
        ..Loads::default()
    };
    let mut f = vec![0.0; D * grid.num_nodes()];
    nodal_loads(grid, &loads, 0.0, &mut f).unwrap();
    // On the unit box: ∫ x_j = 1/2, ∫ x_j x_k = 1/4 (j ≠ k), 1/3 (j = k).
    let int_x = |j: usize, k: usize| if j == k { 1.0 / 3.0 } else { 0.25 };
    for a in 0..D {
        let total: f64 = (0..grid.num_nodes()).map(|n| f[D * n + a]).sum();
        let exact = c0[a] + (0..D).map(|j| cm[(a, j)] * 0.5).sum::<f64>();
        assert!(
            (total - exact).abs() < 1e-12,
            "{D}D load total {a}: {total} vs {exact}"
        );
        for k in 0..D {
            let mom: f64 = (0..grid.num_nodes())
                .map(|n| f[D * n + a] * grid.node(n)[k])
                .sum();
            let exact = c0[a] * 0.5 + (0..D).map(|j| cm[(a, j)] * int_x(j, k)).sum::<f64>();
            assert!(
                (mom - exact).abs() < 1e-12,
                "{D}D load moment {a},{k}: {mom} vs {exact}"
            );
        }
    }
}

#[test]
fn body_loads_have_exact_moments() {
    let lo2 = Point::<2>::zeros();
    let hi2 = Point::<2>::repeat(1.0);
    load_moments(&generate::simplices::<2>(lo2, hi2, [3, 4]).unwrap());
    load_moments(&generate::cartesian::<2>(lo2, hi2, [3, 4]).unwrap());
    let lo3 = Point::<3>::zeros();
    let hi3 = Point::<3>::repeat(1.0);
    load_moments(&generate::simplices::<3>(lo3, hi3, [2, 3, 2]).unwrap());
    load_moments(&generate::cartesian::<3>(lo3, hi3, [2, 3, 2]).unwrap());
}

fn traction_moments<const D: usize>(grid: &Grid<D>) {
    // t(x) on ymax (y = 1): t_a = 1 + a + 2 x − 0.5 z.
    let tr: [ScalarField; D] = std::array::from_fn(|a| {
        ScalarField::from_fn(move |x, _| {
            1.0 + a as f64 + 2.0 * x[0] - if x.len() > 2 { 0.5 * x[2] } else { 0.0 }
        })
    });
    let loads = Loads {
        tractions: vec![Traction {
            name: "ymax".into(),
            faces: grid.boundary("ymax").unwrap(),
            traction: tr,
        }],
        ..Loads::default()
    };
    let mut f = vec![0.0; D * grid.num_nodes()];
    nodal_loads(grid, &loads, 0.0, &mut f).unwrap();
    let zmean = if D == 3 { -0.25 } else { 0.0 };
    for a in 0..D {
        let total: f64 = (0..grid.num_nodes()).map(|n| f[D * n + a]).sum();
        let exact = 1.0 + a as f64 + 1.0 + zmean;
        assert!(
            (total - exact).abs() < 1e-12,
            "{D}D traction total: {total} vs {exact}"
        );
        // ∫ t_a x over the face: ∫ (1 + a) x + 2 x² − 0.5 x z = (1+a)/2 + 2/3 − 0.5/4 (3D).
        let mom: f64 = (0..grid.num_nodes())
            .map(|n| f[D * n + a] * grid.node(n)[0])
            .sum();
        let exact = (1.0 + a as f64) / 2.0 + 2.0 / 3.0 - if D == 3 { 0.125 } else { 0.0 };
        // Σ_i φ_i x_i = x on every facet, so Σ_i f_i x_i = ∫ t x exactly.
        assert!(
            (mom - exact).abs() < 1e-12,
            "{D}D traction moment: {mom} vs {exact}"
        );
    }
}

#[test]
fn traction_loads_are_exact_for_linear_tractions() {
    traction_moments(
        &generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::repeat(1.0), [4, 2]).unwrap(),
    );
    traction_moments(
        &generate::cartesian::<3>(Point::<3>::zeros(), Point::<3>::repeat(1.0), [3, 2, 2]).unwrap(),
    );
}

#[test]
fn body_loads_do_not_depend_on_the_cell_order() {
    let grid =
        generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::repeat(1.0), [12, 9]).unwrap();
    let nc = grid.num_cells();
    // c ↦ 7c mod nc is a permutation (nc = 216 is coprime to 7).
    let order: Vec<usize> = (0..nc).map(|c| 7 * c % nc).collect();
    let mut pos = vec![0];
    let mut conn = Vec::new();
    for &c in &order {
        conn.extend_from_slice(grid.cell_nodes(c));
        pos.push(conn.len());
    }
    let shuffled = Grid::from_polygons(grid.nodes().to_vec(), &pos, &conn).unwrap();
    let loads = Loads {
        body_force: Some(
            [
                ScalarField::from_fn(|x, _| (3.0 * x[0]).sin() + x[1] * x[1]),
                ScalarField::from_fn(|x, _| (2.0 * x[1]).cos() * x[0]),
            ]
            .into(),
        ),
        ..Loads::default()
    };
    let (mut f, mut g) = (
        vec![0.0; 2 * grid.num_nodes()],
        vec![0.0; 2 * grid.num_nodes()],
    );
    nodal_loads(&grid, &loads, 0.0, &mut f).unwrap();
    nodal_loads(&shuffled, &loads, 0.0, &mut g).unwrap();
    let scale = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    for (i, (a, b)) in f.iter().zip(&g).enumerate() {
        assert!((a - b).abs() <= 1e-14 * scale, "dof {i}: {a} vs {b}");
    }
}

/// The loads of the nodes of one part of the grid, from the cells touching them (as a
/// process of a distributed run computes them): those nodes get `nodal_loads`'s values
/// bit for bit, and a node none of whose cells is kept gets nothing.
#[test]
fn body_loads_of_the_cells_of_some_nodes_are_those_of_the_whole_grid() {
    let grid =
        generate::simplices::<3>(Point::<3>::zeros(), Point::<3>::repeat(1.0), [5, 4, 3]).unwrap();
    let loads = Loads {
        body_force: Some(
            [
                ScalarField::from_fn(|x, _| (3.0 * x[0]).sin() + x[1] * x[2]),
                ScalarField::from_fn(|x, _| (2.0 * x[1]).cos() * x[0]),
                ScalarField::from_fn(|x, _| x[2] * x[2] - 0.5 * x[0]),
            ]
            .into(),
        ),
        ..Loads::default()
    };
    let nn = grid.num_nodes();
    let mut all = vec![0.0; 3 * nn];
    nodal_loads(&grid, &loads, 0.0, &mut all).unwrap();
    // The nodes with x < 0.45 (two of five columns of cells and their border).
    let mine: Vec<bool> = (0..nn).map(|v| grid.node(v)[0] < 0.45).collect();
    let touches = |c: usize| grid.cell_nodes(c).iter().any(|&v| mine[v]);
    let mut part = vec![0.0; 3 * nn];
    nodal_loads_of_cells(&grid, &loads, 0.0, &touches, &mut part).unwrap();
    let (mut same, mut zero) = (0, 0);
    for v in 0..nn {
        let kept = (0..grid.num_cells())
            .filter(|&c| grid.cell_nodes(c).contains(&v))
            .map(touches);
        let (any, every) = kept.fold((false, true), |(a, e), k| (a || k, e && k));
        for a in 0..3 {
            let (p, w) = (part[3 * v + a], all[3 * v + a]);
            if mine[v] {
                assert!(every);
                assert_eq!(
                    p.to_bits(),
                    w.to_bits(),
                    "node {v} component {a}: {p} vs {w}"
                );
                same += 1;
            } else if !any {
                assert_eq!(p, 0.0, "node {v} component {a}");
                zero += 1;
            }
        }
    }
    assert!(
        same > 0 && zero > 0,
        "{same} kept and {zero} untouched components"
    );
}
