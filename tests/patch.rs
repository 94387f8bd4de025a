//! Global patch tests of the VEM on general grids.
//!
//! Checks (random data drawn by proptest, 8 cases per test; `A` with entries in
//! [−1, 1], `b` in [−1, 1]^D, E = 1, ν drawn in [0.1, 0.45]):
//!
//! * `affine_*`: `u = A x + b` prescribed at the nodes of every boundary face is
//!   reproduced at every interior node to 1e-10 relative to `max |u|`, and every cell's
//!   stress equals the exact constant stress `C : sym A` to 1e-10 relative. Grids:
//!   perturbed Cartesian (amplitude 0.3), Voronoi without Lloyd iterations (rough cells,
//!   short edges), composite with hanging nodes and a jittered refined zone (2D, plane
//!   strain); perturbed Kuhn tetrahedra, perturbed hexahedra (non-planar faces), and a
//!   mixed grid of hexahedra and tetrahedra whose hexahedra next to a split cube carry the
//!   shared square as two triangles (polyhedra with 7 to 9 faces), perturbed (3D).
//!   Reference: the VEM consistency (Nilsen et al. (2017) eq. 26) makes linear fields exact.
//! * `uniaxial_traction_*`: rollers on `xmin` (u_x = 0) and `ymin` (u_y = 0), traction
//!   `(s, 0)` on `xmax`, the rest free. Exact: `σ = s e_x ⊗ e_x`,
//!   plane strain `u = (s (1 − ν²)/E x, −s ν (1 + ν)/E y)`, plane stress
//!   `u = (s/E x, −s ν/E y)`. Reproduced at every node and in every cell's stress to 1e-10
//!   relative on a Voronoi grid and a composite grid.

mod common;

use common::*;
use porofrac::grid::generate::{CompositeSpec, cartesian, composite, perturb, simplices, voronoi};
use porofrac::grid::{CellFaceLoops, Grid, Point};
use porofrac::law::{Stiffness, Tensor};
use porofrac::sim::{LawMap, Loads, ScalarField, Traction, cell_stresses};
use porofrac::vem::VemLaw;
use proptest::prelude::*;

const TOL: f64 = 1e-10;

/// Solve the affine patch test and return (nodal error, stress error), both relative.
fn affine_patch<const D: usize>(grid: &Grid<D>, nu: f64, a: Tensor<D>, b: Point<D>) -> (f64, f64) {
    let mat = Stiffness::<D>::isotropic(1.0, nu).unwrap();
    let law = VemLaw::new(mat.clone());
    let laws = LawMap::uniform(grid, &law).unwrap();
    let exact = affine(a, b);
    let bc = dirichlet("boundary", grid.boundary_faces(), &exact);
    let sol = solve(grid, &laws, &[bc], &Loads::default()).unwrap();
    let inner = interior_nodes(grid);
    assert!(!inner.is_empty(), "the grid has no interior node");
    let eu = max_node_error(
        grid,
        &sol.displacement,
        &exact,
        &inner,
        max_node_value(grid, &exact),
    );
    let sigma = mat.stress(&((a + a.transpose()) * 0.5));
    let stress = cell_stresses(grid, &laws, &sol.displacement).unwrap();
    let es = max_stress_error(&stress, |_| sigma);
    println!(
        "affine patch, {} cells: nodes {eu:.1e}, stress {es:.1e}",
        grid.num_cells()
    );
    (eu, es)
}

fn tensor<const D: usize>(v: &[f64]) -> Tensor<D> {
    Tensor::<D>::from_row_slice(&v[..D * D])
}

fn composite_grid(seed: u64) -> Grid<2> {
    let mut spec = CompositeSpec::new(
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(6.0, 6.0),
        [6, 6],
        Point::<2>::new(3.0, 3.0),
        1.0,
        3,
        0.5,
    );
    spec.perturb = 0.2;
    spec.seed = seed;
    composite(&spec).unwrap()
}

/// A box of `n³` unit cubes; cubes with `i + j + k ≡ 0 (mod 4)` are split into the 6 Kuhn
/// tetrahedra around their (0,0,0)–(1,1,1) diagonal, the others stay hexahedra, and a
/// hexahedron's face shared with a split cube is given as the same two triangles (split by
/// the diagonal from the face's lowest to its highest corner), so the hexahedra next to
/// split cubes are polyhedra with 7 to 9 faces. Loops are oriented outward by checking
/// the sign of the area vector against the cell centre (all cells are convex).
fn mixed_grid(n: usize) -> Grid<3> {
    let id = |i: usize, j: usize, k: usize| i + (n + 1) * (j + (n + 1) * k);
    let mut nodes = Vec::new();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                nodes.push(Point::<3>::new(i as f64, j as f64, k as f64));
            }
        }
    }
    let split = |c: [usize; 3]| (c[0] + c[1] + c[2]).is_multiple_of(4);
    let corner = |c: [usize; 3], bits: usize| {
        id(
            c[0] + (bits & 1),
            c[1] + ((bits >> 1) & 1),
            c[2] + ((bits >> 2) & 1),
        )
    };
    let mut loops = CellFaceLoops::new();
    let push = |loops: &mut CellFaceLoops, f: &[usize], centre: Point<3>| {
        let p: Vec<Point<3>> = f.iter().map(|&v| nodes[v]).collect();
        let area = (p[1] - p[0]).cross(&(p[2] - p[0]));
        let mid = p.iter().sum::<Point<3>>() / p.len() as f64;
        if area.dot(&(mid - centre)) > 0.0 {
            loops.push_face(f);
        } else {
            let r: Vec<usize> = f.iter().rev().copied().collect();
            loops.push_face(&r);
        }
    };
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = [i, j, k];
                if split(c) {
                    for perm in [
                        [0, 1, 2],
                        [0, 2, 1],
                        [1, 0, 2],
                        [1, 2, 0],
                        [2, 0, 1],
                        [2, 1, 0],
                    ] {
                        let mut v = [corner(c, 0); 4];
                        let mut bits = 0;
                        for (s, &ax) in perm.iter().enumerate() {
                            bits |= 1 << ax;
                            v[s + 1] = corner(c, bits);
                        }
                        let centre = v.iter().map(|&x| nodes[x]).sum::<Point<3>>() / 4.0;
                        for skip in 0..4 {
                            let f: Vec<usize> =
                                (0..4).filter(|&q| q != skip).map(|q| v[q]).collect();
                            push(&mut loops, &f, centre);
                        }
                        loops.finish_cell();
                    }
                } else {
                    let centre = Point::<3>::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5);
                    for ax in 0..3 {
                        let (b, c2) = ((ax + 1) % 3, (ax + 2) % 3);
                        for side in 0..2 {
                            // Face corners: lowest, +b, highest, +c (a loop).
                            let base = side << ax;
                            let q = [
                                base,
                                base | (1 << b),
                                base | (1 << b) | (1 << c2),
                                base | (1 << c2),
                            ];
                            let f: Vec<usize> = q.iter().map(|&bits| corner(c, bits)).collect();
                            let mut nb = c.map(|x| x as isize);
                            nb[ax] += if side == 1 { 1 } else { -1 };
                            let inside = nb.iter().all(|&x| x >= 0 && x < n as isize);
                            if inside && split(nb.map(|x| x as usize)) {
                                push(&mut loops, &[f[0], f[1], f[2]], centre);
                                push(&mut loops, &[f[0], f[2], f[3]], centre);
                            } else {
                                push(&mut loops, &f, centre);
                            }
                        }
                    }
                    loops.finish_cell();
                }
            }
        }
    }
    Grid::from_cell_faces(nodes, &loops).unwrap()
}

fn uniaxial(grid: &Grid<2>, mat: Stiffness<2>, exx: f64, eyy: f64, s: f64) -> (f64, f64) {
    let law = VemLaw::new(mat);
    let laws = LawMap::uniform(grid, &law).unwrap();
    let bcs = [
        roller::<2>("xmin", grid.boundary("xmin").unwrap(), 0),
        roller::<2>("ymin", grid.boundary("ymin").unwrap(), 1),
    ];
    let loads = Loads {
        tractions: vec![Traction {
            name: "xmax".into(),
            faces: grid.boundary("xmax").unwrap(),
            traction: [ScalarField::Const(s), ScalarField::Const(0.0)],
        }],
        ..Default::default()
    };
    let sol = solve(grid, &laws, &bcs, &loads).unwrap();
    let a = Tensor::<2>::new(exx, 0.0, 0.0, eyy);
    let exact = affine(a, Point::<2>::zeros());
    let all: Vec<usize> = (0..grid.num_nodes()).collect();
    let eu = max_node_error(
        grid,
        &sol.displacement,
        &exact,
        &all,
        max_node_value(grid, &exact),
    );
    let stress = cell_stresses(grid, &laws, &sol.displacement).unwrap();
    let es = max_stress_error(&stress, |_| Tensor::<2>::new(s, 0.0, 0.0, 0.0));
    println!(
        "uniaxial, {} cells: nodes {eu:.1e}, stress {es:.1e}",
        grid.num_cells()
    );
    (eu, es)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn affine_perturbed_quads(a in prop::array::uniform4(-1.0f64..1.0), b in prop::array::uniform2(-1.0f64..1.0),
                              nu in 0.1f64..0.45, seed in 0u64..1_000_000, n in 3usize..9) {
        let g = cartesian(Point::<2>::zeros(), Point::<2>::new(2.0, 1.0), [2 * n, n]).unwrap();
        let g = perturb(&g, 0.3, seed).unwrap();
        let (eu, es) = affine_patch(&g, nu, tensor(&a), Point::<2>::from(b));
        prop_assert!(eu < TOL && es < TOL, "nodes {eu:e}, stress {es:e}");
    }

    #[test]
    fn affine_voronoi(a in prop::array::uniform4(-1.0f64..1.0), b in prop::array::uniform2(-1.0f64..1.0),
                      nu in 0.1f64..0.45, seed in 0u64..1_000_000, n in 20usize..120) {
        let g = voronoi(Point::<2>::zeros(), Point::<2>::new(1.0, 1.0), n, seed, 0).unwrap();
        let (eu, es) = affine_patch(&g, nu, tensor(&a), Point::<2>::from(b));
        prop_assert!(eu < TOL && es < TOL, "nodes {eu:e}, stress {es:e}");
    }

    #[test]
    fn affine_composite(a in prop::array::uniform4(-1.0f64..1.0), b in prop::array::uniform2(-1.0f64..1.0),
                        nu in 0.1f64..0.45, seed in 0u64..1_000_000) {
        let g = composite_grid(seed);
        let (eu, es) = affine_patch(&g, nu, tensor(&a), Point::<2>::from(b));
        prop_assert!(eu < TOL && es < TOL, "nodes {eu:e}, stress {es:e}");
    }

    #[test]
    fn affine_perturbed_tetrahedra(a in prop::array::uniform9(-1.0f64..1.0), b in prop::array::uniform3(-1.0f64..1.0),
                                   nu in 0.1f64..0.45, seed in 0u64..1_000_000, n in 2usize..5) {
        let g = simplices(Point::<3>::zeros(), Point::<3>::new(1.0, 2.0, 1.0), [n, 2 * n, n]).unwrap();
        let g = perturb(&g, 0.3, seed).unwrap();
        let (eu, es) = affine_patch(&g, nu, tensor(&a), Point::<3>::from(b));
        prop_assert!(eu < TOL && es < TOL, "nodes {eu:e}, stress {es:e}");
    }

    #[test]
    fn affine_perturbed_hexahedra(a in prop::array::uniform9(-1.0f64..1.0), b in prop::array::uniform3(-1.0f64..1.0),
                                  nu in 0.1f64..0.45, seed in 0u64..1_000_000, n in 2usize..6) {
        let g = cartesian(Point::<3>::zeros(), Point::<3>::new(1.0, 1.0, 2.0), [n, n, 2 * n]).unwrap();
        let g = perturb(&g, 0.3, seed).unwrap();
        let (eu, es) = affine_patch(&g, nu, tensor(&a), Point::<3>::from(b));
        prop_assert!(eu < TOL && es < TOL, "nodes {eu:e}, stress {es:e}");
    }

    #[test]
    fn affine_mixed_hex_tet(a in prop::array::uniform9(-1.0f64..1.0), b in prop::array::uniform3(-1.0f64..1.0),
                            nu in 0.1f64..0.45, seed in 0u64..1_000_000) {
        let g = perturb(&mixed_grid(4), 0.2, seed).unwrap();
        let (eu, es) = affine_patch(&g, nu, tensor(&a), Point::<3>::from(b));
        prop_assert!(eu < TOL && es < TOL, "nodes {eu:e}, stress {es:e}");
    }

    #[test]
    fn uniaxial_traction_voronoi(s in -2.0f64..2.0, nu in 0.1f64..0.45, seed in 0u64..1_000_000) {
        let g = voronoi(Point::<2>::zeros(), Point::<2>::new(2.0, 1.0), 80, seed, 1).unwrap();
        let e = 3.0;
        let (eu, es) = uniaxial(&g, Stiffness::<2>::isotropic(e, nu).unwrap(),
                                s * (1.0 - nu * nu) / e, -s * nu * (1.0 + nu) / e, s);
        prop_assert!(eu < TOL && es < TOL, "plane strain: nodes {eu:e}, stress {es:e}");
        let (eu, es) = uniaxial(&g, Stiffness::<2>::isotropic_plane_stress(e, nu).unwrap(),
                                s / e, -s * nu / e, s);
        prop_assert!(eu < TOL && es < TOL, "plane stress: nodes {eu:e}, stress {es:e}");
    }

    #[test]
    fn uniaxial_traction_composite(s in -2.0f64..2.0, nu in 0.1f64..0.45, seed in 0u64..1_000_000) {
        let g = composite_grid(seed);
        let e = 3.0;
        let (eu, es) = uniaxial(&g, Stiffness::<2>::isotropic(e, nu).unwrap(),
                                s * (1.0 - nu * nu) / e, -s * nu * (1.0 + nu) / e, s);
        prop_assert!(eu < TOL && es < TOL, "plane strain: nodes {eu:e}, stress {es:e}");
        let (eu, es) = uniaxial(&g, Stiffness::<2>::isotropic_plane_stress(e, nu).unwrap(),
                                s / e, -s * nu / e, s);
        prop_assert!(eu < TOL && es < TOL, "plane stress: nodes {eu:e}, stress {es:e}");
    }
}

/// The mixed grid really mixes: tetrahedra, plain hexahedra and hexahedra with split faces.
#[test]
fn mixed_grid_has_all_cell_kinds() {
    let g = mixed_grid(4);
    let faces: Vec<usize> = (0..g.num_cells()).map(|c| g.cell_faces(c).len()).collect();
    let tets = faces.iter().filter(|&&f| f == 4).count();
    let hexes = faces.iter().filter(|&&f| f == 6).count();
    let split_hexes = faces.iter().filter(|&&f| f > 6).count();
    println!("mixed grid: {tets} tetrahedra, {hexes} hexahedra, {split_hexes} polyhedra");
    // 64 cubes, 16 with i + j + k ≡ 0 (mod 4) split into 6 tetrahedra each.
    assert_eq!(tets, 6 * 16);
    assert_eq!(hexes + split_hexes, 64 - 16);
    assert!(hexes > 0 && split_hexes > 0);
    assert_eq!(faces.iter().max(), Some(&9));
    let vol: f64 = g.cell_volumes().iter().sum();
    assert!((vol - 64.0).abs() < 1e-12);
}
