//! The patch test on corner-point grids: a faulted deck whose layers cross inside the
//! fault (nodes inside the fault surface, split sub-faces) on skewed, non-parallel pillars
//! (non-planar faces), with VEM everywhere, and with an MDEM zone of tetrahedra (cells on
//! both sides of the fault, refined 0 and 1 times) conforming with the VEM cells around
//! it (split faces, hanging nodes). `u = A x + b` prescribed on the boundary is
//! reproduced at every node and every cell stress is the exact constant stress, to 1e-9
//! relative; the zone keeps the volume of the cells it replaces.

mod common;

use common::rel;
use nalgebra::SMatrix;
use porofrac_grid::generate::tetrahedralize;
use porofrac_grid::io::grdecl::{Deck, corner_point_grid};
use porofrac_grid::{Grid, Point};
use porofrac_law::CellLaw;
use porofrac_law::stiffness::Stiffness;
use porofrac_mdem::MdemLaw;
use porofrac_sim::*;
use porofrac_vem::VemLaw;

fn faulted_deck() -> Deck {
    let (dx, dy, dz) = (10.0, 20.0, 2.0);
    let mut deck = Deck::on_vertical_pillars([3, 2, 3], [dx, dy], |[i, _], x, y, k| {
        100.0
            + k as f64 * dz
            + 0.05 * x
            + if i >= 2 {
                1.5 * dz * y / (2.0 * dy)
            } else {
                0.0
            }
    });
    // Skew the pillars, each differently: their bottom points move sideways.
    for (p, c) in deck.coord.chunks_mut(6).enumerate() {
        c[3] += 0.003 * ((p * 7) % 5) as f64;
        c[4] -= 0.002 * ((p * 3) % 4) as f64;
    }
    deck
}

/// Solve the patch test on `grid` with MDEM on the cells tagged `refined` and VEM on the
/// others; return the largest relative displacement and stress errors.
fn patch(grid: &Grid<3>) -> (f64, f64) {
    let (e, nu) = (2.0e10, 0.25);
    let stiffness = Stiffness::<3>::isotropic(e, nu).unwrap();
    let vem = VemLaw::<3>::new(stiffness.clone());
    let mdem = MdemLaw::<3>::new(&stiffness).unwrap();
    let mut law_of_cell = vec![0; grid.num_cells()];
    if let Some(zone) = grid.cell_tags().get("refined") {
        for &c in zone {
            law_of_cell[c] = 1;
        }
    }
    let laws = LawMap::new(grid, vec![&vem as &dyn CellLaw<3>, &mdem], law_of_cell).unwrap();
    let a = SMatrix::<f64, 3, 3>::from_fn(|i, j| 1e-4 * (0.4 + i as f64 - 0.9 * j as f64));
    let b = Point::<3>::new(1e-3, -2e-3, 5e-4);
    let exact = move |x: &[f64], c: usize| b[c] + (0..3).map(|j| a[(c, j)] * x[j]).sum::<f64>();
    let bc = Displacement {
        name: "boundary".into(),
        faces: grid.boundary_faces(),
        components: std::array::from_fn(|c| Some(ScalarField::from_fn(move |x, _| exact(x, c)))),
    };
    let dofs = DofMap::new(grid, &[bc], &[]).unwrap();
    assert!(dofs.num_equations() > 0, "interior nodes are free");
    let pattern = Pattern::new(grid, &dofs).unwrap();
    let mut solver = DirectSolver::new(&pattern).unwrap();
    let loads = Loads::default();
    let problem = StaticProblem {
        grid,
        laws: &laws,
        dofs: &dofs,
        pattern: &pattern,
        loads: &loads,
    };
    let u = solve_static(&problem, &mut solver, 0.0, &StaticOptions::default())
        .unwrap()
        .displacement;
    let scale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = (0..3 * grid.num_nodes())
        .map(|k| rel(u[k], exact(grid.node(k / 3).as_slice(), k % 3), scale))
        .fold(0.0, f64::max);
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let eps = (a + a.transpose()) * 0.5;
    let sig = eps * (2.0 * mu) + SMatrix::<f64, 3, 3>::identity() * (lambda * eps.trace());
    let s = cell_stresses(grid, &laws, &u).unwrap();
    let worst_s = s
        .iter()
        .map(|t| (t - sig).amax() / sig.amax())
        .fold(0.0, f64::max);
    (worst, worst_s)
}

#[test]
fn vem_patch_test_on_a_faulted_corner_point_grid() {
    let cp = corner_point_grid(&faulted_deck()).unwrap();
    let grid = &cp.grid;
    assert_eq!(grid.num_cells(), 18);
    assert!(grid.max_cell_nodes() > 8, "split faces add nodes to cells");
    let (du, ds) = patch(grid);
    eprintln!("corner-point VEM patch test: displacement {du:.2e}, stress {ds:.2e}");
    assert!(du < 1e-9, "displacement error {du:.2e}");
    assert!(ds < 1e-9, "stress error {ds:.2e}");
}

#[test]
fn mdem_zone_in_a_faulted_corner_point_grid_passes_the_patch_test() {
    let cp = corner_point_grid(&faulted_deck()).unwrap();
    // The middle layer of the two columns on either side of the fault, j = 0.
    let zone: Vec<usize> = (0..cp.grid.num_cells())
        .filter(|&c| matches!(cp.ijk[c], [1 | 2, 0, 1]))
        .collect();
    assert_eq!(zone.len(), 2);
    let before: f64 = zone.iter().map(|&c| cp.grid.cell_volume(c)).sum();
    for levels in [0, 1] {
        let t = tetrahedralize(&cp.grid, &zone, levels).unwrap();
        let g = &t.grid;
        let tets = &g.cell_tags()["refined"];
        assert!(tets.iter().all(|&c| g.cell_nodes(c).len() == 4));
        let after: f64 = tets.iter().map(|&c| g.cell_volume(c)).sum();
        assert!(
            (after - before).abs() < 1e-12 * before,
            "zone volume {after} vs {before}"
        );
        assert_eq!(g.num_cells(), 16 + tets.len());
        let (du, ds) = patch(g);
        eprintln!(
            "MDEM zone, {levels} refinements ({} tetrahedra): displacement {du:.2e}, stress {ds:.2e}",
            tets.len()
        );
        assert!(du < 1e-9, "displacement error {du:.2e}");
        assert!(ds < 1e-9, "stress error {ds:.2e}");
    }
}

/// Two blocks of a deck cut apart by inactive cells (`ACTNUM 1 0 0 1 1`) share no node:
/// with displacements fixed only on the `imin` side the east block of two cells floats,
/// and the check names it (its size, one of its cells and its six free modes) instead
/// of leaving a singular system to the solver; fixed on `imax` too, both are held.
#[test]
fn an_island_of_cells_left_free_is_named() {
    let mut deck =
        Deck::on_vertical_pillars([5, 1, 1], [10.0, 10.0], |_, _, _, k| 100.0 + 5.0 * k as f64);
    deck.actnum = Some(vec![true, false, false, true, true]);
    let cp = corner_point_grid(&deck).unwrap();
    let grid = &cp.grid;
    assert_eq!(grid.num_cells(), 3);
    let fixed = |side: &str| Displacement {
        name: side.into(),
        faces: grid.boundary(side).unwrap(),
        components: std::array::from_fn(|_| Some(ScalarField::Const(0.0))),
    };
    // `imin` holds the west cell only: the faces of the hole are imin/imax faces too, so
    // take the faces of the west cell's own side.
    let west: Vec<usize> = grid
        .boundary("imin")
        .unwrap()
        .into_iter()
        .filter(|&f| cp.ijk[grid.face_cells(f).0] == [0, 0, 0])
        .collect();
    let held_west = Displacement {
        name: "west".into(),
        faces: west,
        components: std::array::from_fn(|_| Some(ScalarField::Const(0.0))),
    };
    let dofs = DofMap::new(grid, std::slice::from_ref(&held_west), &[]).unwrap();
    match dofs.check_rigid_modes(grid) {
        Err(SimError::FloatingPart {
            cells,
            total,
            cell_index,
            modes,
            ..
        }) => {
            assert_eq!((cells, total, cp.ijk[cell_index]), (2, 3, [3, 0, 0]));
            assert_eq!(modes.len(), 6, "{modes:?}");
        }
        other => panic!("expected a floating part, got {other:?}"),
    }
    let east: Vec<usize> = grid
        .boundary("imax")
        .unwrap()
        .into_iter()
        .filter(|&f| cp.ijk[grid.face_cells(f).0] == [4, 0, 0])
        .collect();
    let held_east = Displacement {
        name: "east".into(),
        faces: east,
        ..fixed("imax")
    };
    let dofs = DofMap::new(grid, &[held_west, held_east], &[]).unwrap();
    assert!(dofs.check_rigid_modes(grid).is_ok());
}
