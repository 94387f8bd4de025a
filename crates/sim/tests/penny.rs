//! Sneddon's penny-shaped crack, static, represented as the cell method represents a
//! crack: a layer of failed cells one cell thick.
//!
//! A circular crack of radius `a` in an infinite solid under a uniform pressure `p` on its
//! faces opens as `w(r) = 8 p (1 − ν²)/(π E) · √(a² − r²)` (Sneddon 1946), with the
//! volume `V = 16 p (1 − ν²) a³/(3 E)`. The solid is an eighth of a graded grid of
//! tetrahedra (each hexahedron of a tensor-product lattice split into 6 tetrahedra about
//! its diagonal; MDEM, i.e. P1, away from the crack): cells of size `h = a/n` in the box
//! `x, y < 1.25 a`, `z < a/4` around the crack, growing by a factor 1.25 per cell beyond it
//! to the far faces at `R` (fixed), rollers on the three planes of symmetry `x = 0`,
//! `y = 0`, `z = 0`. The crack is the layer of tetrahedra between `z = 0` and `z = h/2`
//! (the upper half of a band `h` thick, mirrored by the roller at `z = 0`) whose
//! centroids lie within `r < a`, given the compression-only central-force law of a failed
//! cell (Nilsen et al. (2017) eqs. 32–33, open edges at 1e-6 of their stiffness); the
//! pressure acts on it as the pore pressure of a failed cell does in the Biot coupling
//! with α = 1: the nodal forces `p N_i` of each band cell.
//!
//! Checks:
//! - the opening measured as twice `u_z` at the nodes of the plane `z = h/2` (the jump
//!   across the mirrored band), and as twice the smeared cell opening of
//!   `porofrac_sim::crack_flow::cell_opening` at the band cells' centroids: relative L2
//!   errors against Sneddon's over the crack;
//! - the crack volume (8 × the band's volume change `Σ N_i · u_i`) against `V`;
//! - between the resolutions, the observed orders.
//!
//! The test runs n = 4 and 8 cells per radius with `R = 10 a` (6 s in release; the far
//! faces change the volume at n = 8 by 0.04 % of `V` from 10 a to 20 a and by 0.006 % from
//! 20 a to 40 a). Its tolerances are the measured errors rounded up by about 5 %, the
//! orders are asserted from below. The ignored `penny_table` prints the errors at the
//! resolutions of `PENNY_N` (default 4, 8, 16) and the far faces at `PENNY_R` times `a`
//! (default 10). docs/hydrofrac/validation.md has the table.

use porofrac_grid::{CellFaceLoops, Grid, Point};
use porofrac_law::{CellLaw, Stiffness};
use porofrac_mdem::{DemLaw, DemMode, MdemLaw};
use porofrac_sim::crack_flow::cell_opening;
use porofrac_sim::*;

mod common;

const A: f64 = 1.0;
const E: f64 = 1.0e10;
const NU: f64 = 0.25;
const P: f64 = 1.0e6;

/// Node coordinates on one half-axis: uniform spacing `h` from 0 to `inner` (a multiple
/// of `h`; with `half`, 0 and then from `h/2`), then growing by 1.25 per cell to `outer`
/// or beyond.
fn axis(h: f64, inner: f64, outer: f64, half: bool) -> Vec<f64> {
    let mut pos = if half { vec![0.0] } else { Vec::new() };
    let mut x = if half { 0.5 * h } else { 0.0 };
    while x < inner + 1e-9 * h {
        pos.push(x);
        x += h;
    }
    let mut step = h;
    let mut last = *pos.last().unwrap();
    while last < outer - 1e-9 * h {
        step *= 1.25;
        last += step;
        pos.push(last);
    }
    pos
}

/// Append the tetrahedron `v` with its faces oriented outward.
fn push_tet(loops: &mut CellFaceLoops, nodes: &[Point<3>], mut v: [usize; 4]) {
    let e = |k: usize| nodes[v[k]] - nodes[v[0]];
    if e(1).cross(&e(2)).dot(&e(3)) < 0.0 {
        v.swap(1, 2);
    }
    for f in [
        [v[1], v[2], v[3]],
        [v[0], v[3], v[2]],
        [v[0], v[1], v[3]],
        [v[0], v[2], v[1]],
    ] {
        loops.push_face(&f);
    }
    loops.finish_cell();
}

/// The grid of tetrahedra on the lines `xs` × `ys` × `zs`: every hexahedron split into the
/// 6 tetrahedra about its diagonal from its lowest to its highest corner (conforming, the
/// same diagonal in every cell).
fn tetrahedra(xs: &[f64], ys: &[f64], zs: &[f64]) -> Grid<3> {
    let (nx, ny, nz) = (xs.len(), ys.len(), zs.len());
    let mut nodes = Vec::with_capacity(nx * ny * nz);
    for &z in zs {
        for &y in ys {
            for &x in xs {
                nodes.push(Point::<3>::new(x, y, z));
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
    let mut loops = CellFaceLoops::new();
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let corner = |b: usize| id(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
                for perm in [
                    [0, 1, 2],
                    [0, 2, 1],
                    [1, 0, 2],
                    [1, 2, 0],
                    [2, 0, 1],
                    [2, 1, 0],
                ] {
                    let (mut bits, mut v) = (0, [corner(0); 4]);
                    for (s, &ax) in perm.iter().enumerate() {
                        bits |= 1 << ax;
                        v[s + 1] = corner(bits);
                    }
                    push_tet(&mut loops, &nodes, v);
                }
            }
        }
    }
    Grid::from_cell_faces(nodes, &loops).unwrap()
}

/// Sneddon's opening at the distance `r` from the centre.
fn sneddon(r: f64) -> f64 {
    8.0 * P * (1.0 - NU * NU) / (std::f64::consts::PI * E) * (A * A - r * r).max(0.0).sqrt()
}

/// The measured errors of one grid.
#[derive(Clone, Copy, Debug)]
struct Errors {
    /// Relative L2 error of the jump `2 u_z` at the nodes of `z = h/2`.
    jump: f64,
    /// Relative L2 error of the smeared cell opening of the band cells.
    cell: f64,
    /// Relative error of the crack volume.
    volume: f64,
    /// The area of the band's staircase disk relative to `π a²`, less 1.
    area: f64,
}

/// The opened crack with `n` cells per radius and the far faces at `outer`: the grid, the
/// nodal displacement, the band cells and the cell size `h`.
fn opened(n: usize, outer: f64) -> (Grid<3>, Vec<f64>, Vec<bool>, f64) {
    let h = A / n as f64;
    let xs = axis(h, 1.25 * A, outer, false);
    let zs = axis(h, 0.25 * A, outer, true);
    let grid = tetrahedra(&xs, &xs, &zs);
    let stiffness = Stiffness::<3>::isotropic(E, NU).unwrap();
    let mdem = MdemLaw::<3>::new(&stiffness).unwrap();
    let dem = DemLaw::<3>::new(&stiffness, DemMode::CompressionOnly)
        .unwrap()
        .with_open_stiffness(1e-6)
        .unwrap();
    let band: Vec<bool> = grid
        .cell_centroids()
        .iter()
        .map(|c| c[2] < 0.5 * h && c[0].hypot(c[1]) < A)
        .collect();
    let law_of_cell = band.iter().map(|&b| usize::from(b)).collect();
    let laws = LawMap::new(&grid, vec![&mdem as &dyn CellLaw<3>, &dem], law_of_cell).unwrap();
    // Rollers on the planes of symmetry, the far faces fixed.
    let tiny = 1e-9 * h;
    let faces_where = |f: &dyn Fn(&Point<3>) -> bool| -> Vec<usize> {
        grid.boundary_faces()
            .into_iter()
            .filter(|&k| f(grid.face_centroid(k)))
            .collect()
    };
    let far = *xs.last().unwrap();
    let far_z = *zs.last().unwrap();
    let mut conditions = Vec::new();
    for a in 0..3 {
        let mut components = [None, None, None];
        components[a] = Some(0.0.into());
        conditions.push(Displacement {
            name: format!("symmetry {a}"),
            faces: faces_where(&|c| c[a].abs() < tiny),
            components,
        });
    }
    conditions.push(Displacement {
        name: "far".into(),
        faces: faces_where(&|c| {
            (c[0] - far).abs() < tiny || (c[1] - far).abs() < tiny || (c[2] - far_z).abs() < tiny
        }),
        components: [Some(0.0.into()), Some(0.0.into()), Some(0.0.into())],
    });
    let dofs = DofMap::new(&grid, &conditions, &[]).unwrap();
    let pattern = Pattern::new(&grid, &dofs).unwrap();
    let u = common::open_band(&grid, &laws, &dofs, &pattern, &band, P);
    (grid, u, band, h)
}

/// The errors with `n` cells per radius and the far faces at `outer`.
fn errors(n: usize, outer: f64) -> Errors {
    let (grid, u, band, h) = opened(n, outer);
    let tiny = 1e-9 * h;
    let mut nn = vec![Point::<3>::zeros(); 4];

    // The jump 2 u_z at the nodes of z = h/2 in the uniform part, weighted by the area
    // each node holds of the quarter plane (halved on the planes of symmetry).
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..grid.num_nodes() {
        let x = grid.node(i);
        if (x[2] - 0.5 * h).abs() > tiny || x[0] > 1.25 * A + tiny || x[1] > 1.25 * A + tiny {
            continue;
        }
        let mut wt = h * h;
        for a in 0..2 {
            if x[a] < tiny || x[a] > 1.25 * A - tiny {
                wt *= 0.5;
            }
        }
        let exact = sneddon(x[0].hypot(x[1]));
        num += wt * (2.0 * u[3 * i + 2] - exact).powi(2);
        den += wt * exact * exact;
    }
    let jump = (num / den).sqrt();

    // The smeared opening of each band cell at its centroid, weighted by its volume.
    let (mut num, mut den, mut volume, mut area) = (0.0, 0.0, 0.0, 0.0);
    for c in (0..grid.num_cells()).filter(|&c| band[c]) {
        area += grid.cell_volume(c) / (0.5 * h);
        grid.cell_node_normals(c, &mut nn);
        let uc: Vec<f64> = grid
            .cell_nodes(c)
            .iter()
            .flat_map(|&i| [u[3 * i], u[3 * i + 1], u[3 * i + 2]])
            .collect();
        let w = 2.0 * cell_opening(&grid, c, &nn, &uc).aperture;
        let x = grid.cell_centroid(c);
        let exact = sneddon(x[0].hypot(x[1]));
        let vol = grid.cell_volume(c);
        num += vol * (w - exact).powi(2);
        den += vol * exact.powi(2);
        volume += nn
            .iter()
            .zip(uc.chunks(3))
            .map(|(ni, ui)| ni.dot(&Point::<3>::new(ui[0], ui[1], ui[2])))
            .sum::<f64>();
    }
    let exact_volume = 16.0 * P * (1.0 - NU * NU) * A.powi(3) / (3.0 * E);
    Errors {
        jump,
        cell: (num / den).sqrt(),
        volume: (8.0 * volume - exact_volume) / exact_volume,
        area: 4.0 * area / (std::f64::consts::PI * A * A) - 1.0,
    }
}

#[test]
#[ignore = "the table of docs/hydrofrac/validation.md; minutes"]
fn penny_table() {
    let ns: Vec<usize> = std::env::var("PENNY_N")
        .map(|s| s.split(',').map(|v| v.parse().unwrap()).collect())
        .unwrap_or(vec![4, 8, 16]);
    let outer: f64 = std::env::var("PENNY_R")
        .map(|s| s.parse().unwrap())
        .unwrap_or(10.0);
    for n in ns {
        let e = errors(n, outer * A);
        println!(
            "n = {n:>2}, R = {outer}: L2 jump {:.4e}, L2 cell {:.4e}, volume {:+.4e}, \
             band area {:+.4e}",
            e.jump, e.cell, e.volume, e.area
        );
    }
}

/// The errors measured (2026-11-28, far faces at 10 a) rounded up by about 5 %: a change
/// of the method that costs accuracy fails here. Columns: L2 of the jump, L2 of the cell
/// opening, crack volume (the band opens less than Sneddon's crack: the volume error is
/// negative).
const BOUNDS: [(usize, f64, f64, f64); 2] = [(4, 0.26, 0.285, 0.235), (8, 0.128, 0.153, 0.1235)];

#[test]
fn penny_opening_and_volume_converge_at_4_and_8_cells_per_radius() {
    let e: Vec<Errors> = BOUNDS.iter().map(|b| errors(b.0, 10.0 * A)).collect();
    for (b, e) in BOUNDS.iter().zip(&e) {
        println!("n = {}: {e:?}", b.0);
        assert!(
            e.jump <= b.1,
            "n = {}: L2 error of the jump {:.4e} > {:.3e}",
            b.0,
            e.jump,
            b.1
        );
        assert!(
            e.cell <= b.2,
            "n = {}: L2 error of the cell opening {:.4e} > {:.3e}",
            b.0,
            e.cell,
            b.2
        );
        assert!(
            e.volume < 0.0 && -e.volume <= b.3,
            "n = {}: volume error {:+.4e}, bound {:.3e}",
            b.0,
            e.volume,
            b.3
        );
    }
    let order = |a: f64, b: f64| (a.abs() / b.abs()).log2();
    let (j, c, v) = (
        order(e[0].jump, e[1].jump),
        order(e[0].cell, e[1].cell),
        order(e[0].volume, e[1].volume),
    );
    println!("orders 4→8: jump {j:.2}, cell {c:.2}, volume {v:.2}");
    // Measured: 1.02 (jump), 0.89 (cell), 0.93 (volume).
    assert!(
        j >= 0.95 && c >= 0.85 && v >= 0.88,
        "orders {j:.2} {c:.2} {v:.2}"
    );
}

/// The stress intensity from the opening ([`porofrac_sim::tip_opening`]) at the cells of
/// the band's layer just outside the front (`a < r < a + h` at the centroid), relative to
/// Sneddon's `K_I = 2p√(a/π)`: the smallest, the mean and the largest. The band is the
/// upper half of the crack's (mirrored by the roller at z = 0), so the jump the rule reads
/// is half the opening and its estimate is doubled.
fn front_ratios(n: usize) -> (f64, f64, f64) {
    let (grid, u, band, h) = opened(n, 10.0 * A);
    let adjacency = porofrac_frac::recovery::NodeCells::new(&grid);
    let e_prime = E / (1.0 - NU * NU);
    let exact = 2.0 * P * (A / std::f64::consts::PI).sqrt();
    let ratios: Vec<f64> = (0..grid.num_cells())
        .filter(|&c| {
            let x = grid.cell_centroid(c);
            let r = x[0].hypot(x[1]);
            !band[c] && x[2] < 0.5 * h && r > A && r < A + h
        })
        .filter_map(|c| {
            porofrac_sim::tip_opening::tip_stress_intensity(
                &grid, &adjacency, &band, c, e_prime, &u,
            )
        })
        .map(|k| 2.0 * k / exact)
        .collect();
    assert!(
        ratios.len() > 4 * n,
        "{} cells ahead of the front",
        ratios.len()
    );
    let lo = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ratios.iter().copied().fold(0.0, f64::max);
    (lo, ratios.iter().sum::<f64>() / ratios.len() as f64, hi)
}

/// The tip rule from the opening on the front of Sneddon's penny, measured (2026-11-29) at
/// 4 and 8 cells per radius: the estimate at the cells just outside the front is
/// 0.448–0.777 (mean 0.635) and 0.457–0.967 (mean 0.738) of `K_I`: lower and more
/// scattered than on Sneddon's slit in 2D (0.87–0.93 at 5–10 cells per half-length), as
/// the front is a staircase of boxes whose cells touch the crack by a face, an edge or a
/// node. Asserted within 0.5 % of those values.
#[test]
fn tip_stress_intensity_on_the_front_of_sneddons_penny() {
    let measured = [(4, 0.4480, 0.6351, 0.7774), (8, 0.4568, 0.7383, 0.9669)];
    for (n, lo, mean, hi) in measured {
        let (l, m, h) = front_ratios(n);
        println!("n = {n}: K_est / K_I from {l:.4} to {h:.4}, mean {m:.4}");
        for (got, want) in [(l, lo), (m, mean), (h, hi)] {
            assert!(
                (got / want - 1.0).abs() < 5e-3,
                "n = {n}: {l:.4}, {m:.4}, {h:.4}; measured {lo}, {mean}, {hi}"
            );
        }
    }
}
