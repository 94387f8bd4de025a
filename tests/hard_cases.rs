//! Hard cases for the VEM mechanics: near-incompressibility, extreme aspect ratios,
//! stiffness contrast and nearly coincident nodes. Each test states its outcome.
//!
//! * `near_incompressible_locking`: the plane-strain Timoshenko cantilever (`common::Beam`
//!   with `E' = E/(1 − ν²)`, `ν' = ν/(1 − ν)`), 64 × 8 cells, `ν = 0.3` and `ν = 0.4999`.
//!   Outcome: the solve succeeds and is finite; the ratio computed/exact tip deflection
//!   on triangles (P1) drops from 0.946 (ν = 0.3) to 0.047 at ν = 0.4999 (volumetric
//!   locking; asserted in [0.02, 0.1]); the VEM on squares locks as well, from 0.972 to
//!   0.140 (asserted in [0.08, 0.25]): its consistency part is the one-point
//!   (constant-strain) one, but the MRST stabilization `α ∝ λ + 2μ` penalises the
//!   bending (hourglass) modes of the squares with the bulk modulus. It locks 3× less than
//!   triangles, still badly.
//! * `aspect_ratio_1000`: cells of 1e-3 × 1 (a 0.02 × 3 strip, 20 × 3 squares; the same
//!   split into triangles; and the squares perturbed by 0.3 of the short edge): the affine
//!   patch test holds to 1e-9 relative at the interior nodes and in the stresses
//!   (measured 5e-15 and 7e-12), and the solve does not fail.
//! * `layered_contrast_1e5`: horizontal layers with E alternating 1e9 / 1e4 (contrast
//!   1e5), ν = 0.25, plane strain, uniaxial strain: rollers `u_x = 0` on `xmin` and `xmax`,
//!   `u_y = 0` on `ymin`, traction `(0, −p)` on `ymax`. Exact: `u_x = 0`,
//!   `u_y(y) = −p ∫₀^y ds / M(s)` with `M = λ + 2μ` per layer (piecewise linear), uniform
//!   stress `σ_yy = −p`, `σ_xx = −p ν/(1 − ν)`. Reproduced to 1e-8 relative (nodes and
//!   stresses; measured 9e-12 / 2.5e-10 on squares, 1.6e-10 / 2.2e-9 on the composite
//!   grid) on 8 × 8 squares and on the composite grid without jitter (hanging nodes
//!   on the layer interfaces; jitter would move interface nodes off the interfaces).
//! * `soft_well_inclusion`: the composite grid with E = 1e4 in the well cells and 1e9
//!   elsewhere, compressed by `(0, −p)` on `ymax` over rollers: the factorization and solve
//!   succeed, the solution is finite, and the reaction on `ymin` balances the applied load
//!   to 1e-8 relative.
//! * `short_edges_1e8`: a 5 × 5 grid of unit squares with every interior node split into
//!   two nodes 1e-8 apart joined by a short edge (quadrilaterals to hexagons with edges of
//!   1e-8; split along x, then along y): the affine patch test holds to 1e-9 relative
//!   (measured 1e-15 nodes, 6e-15 stress) and no degenerate-matrix error occurs.

mod common;

use common::*;
use porofrac::grid::generate::{CompositeSpec, cartesian, composite, perturb, simplices};
use porofrac::grid::{Grid, Point};
use porofrac::law::{Stiffness, Tensor};
use porofrac::sim::{LawMap, Loads, ScalarField, Traction, cell_stresses, reaction};
use porofrac::vem::VemLaw;

fn plane_strain_beam(nu: f64) -> Beam {
    let e = 1000.0;
    Beam {
        l: 8.0,
        d: 1.0,
        p: 1.0,
        e: e / (1.0 - nu * nu),
        nu: nu / (1.0 - nu),
    }
}

fn tip_ratio(grid: &Grid<2>, nu: f64) -> f64 {
    let beam = plane_strain_beam(nu);
    let law = VemLaw::new(Stiffness::<2>::isotropic(1000.0, nu).unwrap());
    let laws = LawMap::uniform(grid, &law).unwrap();
    let (tip, u) = beam.solve(grid, &laws);
    assert!(u.iter().all(|v| v.is_finite()));
    tip / beam.tip()
}

#[test]
fn near_incompressible_locking() {
    let beam = plane_strain_beam(0.3);
    let (lo, hi) = beam.box_corners();
    let tri = simplices(lo, hi, [64, 8]).unwrap();
    let quad = cartesian(lo, hi, [64, 8]).unwrap();
    let t = [tip_ratio(&tri, 0.3), tip_ratio(&tri, 0.4999)];
    let q = [tip_ratio(&quad, 0.3), tip_ratio(&quad, 0.4999)];
    println!("computed / exact tip deflection, plane strain, 64x8:");
    println!("  triangles: nu = 0.3 {:.4}, nu = 0.4999 {:.4}", t[0], t[1]);
    println!("  squares:   nu = 0.3 {:.4}, nu = 0.4999 {:.4}", q[0], q[1]);
    assert!(t[0] > 0.9 && t[0] < 1.0 && q[0] > 0.9 && q[0] < 1.0);
    assert!((0.02..0.1).contains(&t[1]), "triangles at 0.4999: {}", t[1]);
    assert!((0.08..0.25).contains(&q[1]), "squares at 0.4999: {}", q[1]);
    assert!(q[1] > t[1]);
}

/// Affine patch test: (nodal error, stress error), relative.
fn patch(grid: &Grid<2>, mats: &[Stiffness<2>], law_of_cell: Vec<usize>) -> (f64, f64) {
    let a = Tensor::<2>::new(0.3, -0.7, 0.2, -0.4);
    let b = Point::<2>::new(0.1, -0.2);
    let vems: Vec<VemLaw<2>> = mats.iter().map(|m| VemLaw::new(m.clone())).collect();
    let laws = LawMap::new(
        grid,
        vems.iter()
            .map(|l| l as &dyn porofrac::law::CellLaw<2>)
            .collect(),
        law_of_cell,
    )
    .unwrap();
    let exact = affine(a, b);
    let bc = dirichlet("boundary", grid.boundary_faces(), &exact);
    let sol = solve(grid, &laws, &[bc], &Loads::default()).expect("solve");
    let inner = interior_nodes(grid);
    assert!(!inner.is_empty());
    let eu = max_node_error(
        grid,
        &sol.displacement,
        &exact,
        &inner,
        max_node_value(grid, &exact),
    );
    let eps = (a + a.transpose()) * 0.5;
    let stress = cell_stresses(grid, &laws, &sol.displacement).unwrap();
    let es = max_stress_error(&stress, |c| mats[laws.law_of_cell()[c]].stress(&eps));
    (eu, es)
}

#[test]
fn aspect_ratio_1000() {
    let (lo, hi) = (Point::<2>::zeros(), Point::<2>::new(0.02, 3.0));
    let mat = [Stiffness::<2>::isotropic(1.0, 0.3).unwrap()];
    let quads = cartesian(lo, hi, [20, 3]).unwrap();
    let grids = [
        ("squares", quads.clone()),
        ("triangles", simplices(lo, hi, [20, 3]).unwrap()),
        ("perturbed", perturb(&quads, 0.3, 5).unwrap()),
    ];
    for (name, g) in &grids {
        let (eu, es) = patch(g, &mat, vec![0; g.num_cells()]);
        println!("aspect 1000, {name}: nodes {eu:.2e}, stress {es:.2e}");
        assert!(eu < 1e-9 && es < 1e-9, "{name}: {eu:e} {es:e}");
    }
}

/// The uniaxial-strain layered problem; `layer(c)` = 0 for stiff, 1 for soft cells.
fn layered(grid: &Grid<2>, layer_of_cell: Vec<usize>, interfaces: &[(f64, usize)]) -> (f64, f64) {
    let nu = 0.25;
    let es = [1e9, 1e4];
    let mats: Vec<Stiffness<2>> = es
        .iter()
        .map(|&e| Stiffness::<2>::isotropic(e, nu).unwrap())
        .collect();
    let vems: Vec<VemLaw<2>> = mats.iter().map(|m| VemLaw::new(m.clone())).collect();
    let laws = LawMap::new(
        grid,
        vems.iter()
            .map(|l| l as &dyn porofrac::law::CellLaw<2>)
            .collect(),
        layer_of_cell,
    )
    .unwrap();
    let p = 1e3;
    let bcs = [
        roller::<2>("xmin", grid.boundary("xmin").unwrap(), 0),
        roller::<2>("xmax", grid.boundary("xmax").unwrap(), 0),
        roller::<2>("ymin", grid.boundary("ymin").unwrap(), 1),
    ];
    let loads = Loads {
        tractions: vec![Traction {
            name: "ymax".into(),
            faces: grid.boundary("ymax").unwrap(),
            traction: [ScalarField::Const(0.0), ScalarField::Const(-p)],
        }],
        ..Default::default()
    };
    let sol = solve(grid, &laws, &bcs, &loads).expect("solve");
    // Constrained modulus M = E (1 − ν) / ((1 + ν)(1 − 2ν)).
    let m: Vec<f64> = es
        .iter()
        .map(|e| e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu)))
        .collect();
    // interfaces: (upper end y of the layer, its material), increasing.
    let iv = interfaces.to_vec();
    let exact: VecFn<2> = std::sync::Arc::new(move |x: &Point<2>| {
        let (mut y0, mut uy) = (0.0, 0.0);
        for &(y1, k) in &iv {
            let top = x[1].min(y1);
            if top > y0 {
                uy -= p * (top - y0) / m[k];
            }
            y0 = y1;
        }
        Point::<2>::new(0.0, uy)
    });
    let all: Vec<usize> = (0..grid.num_nodes()).collect();
    let eu = max_node_error(
        grid,
        &sol.displacement,
        &exact,
        &all,
        max_node_value(grid, &exact),
    );
    let sigma = Tensor::<2>::new(-p * nu / (1.0 - nu), 0.0, 0.0, -p);
    let stress = cell_stresses(grid, &laws, &sol.displacement).unwrap();
    let es = max_stress_error(&stress, |_| sigma);
    (eu, es)
}

fn well_composite(jitter: f64) -> Grid<2> {
    let mut spec = CompositeSpec::new(
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(6.0, 6.0),
        [6, 6],
        Point::<2>::new(3.0, 3.0),
        1.0,
        4,
        0.6,
    );
    spec.perturb = jitter;
    spec.seed = 3;
    composite(&spec).unwrap()
}

#[test]
fn layered_contrast_1e5() {
    // 8 × 8 unit squares, rows alternate stiff / soft.
    let g = cartesian(Point::<2>::zeros(), Point::<2>::new(8.0, 8.0), [8, 8]).unwrap();
    let layer = |y: f64| (y.floor() as usize) % 2;
    let of_cell: Vec<usize> = (0..g.num_cells())
        .map(|c| layer(g.cell_centroid(c)[1]))
        .collect();
    let iface: Vec<(f64, usize)> = (0..8).map(|j| ((j + 1) as f64, j % 2)).collect();
    let (eu, es) = layered(&g, of_cell, &iface);
    println!("layered 1e5, squares: nodes {eu:.2e}, stress {es:.2e}");
    assert!(eu < 1e-8 && es < 1e-8, "{eu:e} {es:e}");

    // No jitter: the layer interfaces y = 1, 2, … must stay grid lines.
    let g = well_composite(0.0);
    let of_cell: Vec<usize> = (0..g.num_cells())
        .map(|c| layer(g.cell_centroid(c)[1]))
        .collect();
    let iface: Vec<(f64, usize)> = (0..6).map(|j| ((j + 1) as f64, j % 2)).collect();
    let (eu, es) = layered(&g, of_cell, &iface);
    println!(
        "layered 1e5, composite ({} cells): nodes {eu:.2e}, stress {es:.2e}",
        g.num_cells()
    );
    assert!(eu < 1e-8 && es < 1e-8, "{eu:e} {es:e}");
}

#[test]
fn soft_well_inclusion() {
    let g = well_composite(0.2);
    let well = g.cell_tags()["well"].clone();
    assert!(!well.is_empty());
    let mut of_cell = vec![0; g.num_cells()];
    for &c in &well {
        of_cell[c] = 1;
    }
    let mats = [
        VemLaw::new(Stiffness::<2>::isotropic(1e9, 0.25).unwrap()),
        VemLaw::new(Stiffness::<2>::isotropic(1e4, 0.25).unwrap()),
    ];
    let laws = LawMap::new(&g, vec![&mats[0], &mats[1]], of_cell).unwrap();
    let p = 1e6;
    let bottom = g.boundary("ymin").unwrap();
    let bcs = [
        roller::<2>("xmin", g.boundary("xmin").unwrap(), 0),
        roller::<2>("ymin", bottom.clone(), 1),
    ];
    let loads = Loads {
        tractions: vec![Traction {
            name: "ymax".into(),
            faces: g.boundary("ymax").unwrap(),
            traction: [ScalarField::Const(0.0), ScalarField::Const(-p)],
        }],
        ..Default::default()
    };
    let sol = solve(&g, &laws, &bcs, &loads).expect("factorization and solve");
    assert!(sol.displacement.iter().all(|v| v.is_finite()));
    let r = reaction(&g, &laws, &sol.displacement, &bottom).unwrap();
    let applied = p * 6.0;
    let err = (r[1] - applied).abs() / applied;
    let umax = sol.displacement.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    println!(
        "soft well ({} well cells of {}): residual {:.1e}, reaction {:.6e} vs {applied:.6e} (rel. {err:.1e}), max |u| {umax:.3e}",
        well.len(),
        g.num_cells(),
        sol.residual,
        r[1]
    );
    assert!(err < 1e-8, "reaction {r:?}");
}

/// A `n × n` grid of unit squares with every interior node `X` split into `X ∓ δ/2 e`
/// (e = e_x or e_y) joined by an edge of length δ (see the test docs).
fn split_grid(n: usize, delta: f64, horizontal: bool) -> Grid<2> {
    let id = |i: usize, j: usize| i + (n + 1) * j;
    let interior = |i: usize, j: usize| i > 0 && j > 0 && i < n && j < n;
    let mut nodes: Vec<Point<2>> = Vec::new();
    let mut first = vec![0usize; (n + 1) * (n + 1)];
    let e = if horizontal {
        Point::<2>::new(delta / 2.0, 0.0)
    } else {
        Point::<2>::new(0.0, delta / 2.0)
    };
    for j in 0..=n {
        for i in 0..=n {
            let x = Point::<2>::new(i as f64, j as f64);
            first[id(i, j)] = nodes.len();
            if interior(i, j) {
                nodes.push(x - e); // "L"
                nodes.push(x + e); // "R"
            } else {
                nodes.push(x);
            }
        }
    }
    let mut pos = vec![0];
    let mut cn = Vec::new();
    for j in 0..n {
        for i in 0..n {
            // Corners counter-clockwise: (i,j), (i+1,j), (i+1,j+1), (i,j+1).
            let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            for (k, &(ci, cj)) in corners.iter().enumerate() {
                let f = first[id(ci, cj)];
                if !interior(ci, cj) {
                    cn.push(f);
                    continue;
                }
                let (l, r) = (f, f + 1);
                if horizontal {
                    // Lower-left corner → R; lower-right → L, R; upper-right → L; upper-left → R, L.
                    match k {
                        0 => cn.push(r),
                        1 => cn.extend([l, r]),
                        2 => cn.push(l),
                        _ => cn.extend([r, l]),
                    }
                } else {
                    // Split along y ("L" below, "R" above): lower-left → R, L; lower-right → R;
                    // upper-right → L, R; upper-left → L.
                    match k {
                        0 => cn.extend([r, l]),
                        1 => cn.push(r),
                        2 => cn.extend([l, r]),
                        _ => cn.push(l),
                    }
                }
            }
            pos.push(cn.len());
        }
    }
    Grid::from_polygons(nodes, &pos, &cn).unwrap()
}

#[test]
fn short_edges_1e8() {
    let mat = [Stiffness::<2>::isotropic(1.0, 0.3).unwrap()];
    for horizontal in [true, false] {
        let g = split_grid(5, 1e-8, horizontal);
        let shortest = (0..g.num_faces())
            .map(|f| g.face_area(f))
            .fold(f64::INFINITY, f64::min);
        assert!(
            (shortest - 1e-8).abs() < 1e-12,
            "shortest edge {shortest:e}"
        );
        // Connected as intended: only the 4 · 5 outer edges are boundary faces.
        assert_eq!(g.boundary_faces().len(), 20);
        let (eu, es) = patch(&g, &mat, vec![0; g.num_cells()]);
        println!(
            "short edges 1e-8 (split along {}): {} cells, nodes {eu:.2e}, stress {es:.2e}",
            if horizontal { "x" } else { "y" },
            g.num_cells()
        );
        assert!(eu < 1e-9 && es < 1e-9, "{eu:e} {es:e}");
    }
}
