//! Sneddon's pressurized crack, plane strain, static, represented as the cell method
//! represents a crack: a band of failed cells one cell thick.
//!
//! A crack of half-length `a` in an infinite plane under a uniform pressure `p` on its
//! faces opens as `w(x) = 4 p (1 − ν²)/E · √(a² − x²)` (Sneddon 1946), with the volume
//! `V = 2π p a² (1 − ν²)/E` per unit height. Here the plane is a graded grid of
//! triangles (MDEM, i.e. P1, away from the crack; uniform cells of size `h = a/n` around
//! it; 160 a across, fixed at its boundary: the volume at n = 40 changed by 0.27 % of
//! Sneddon's from 40 a to 80 a across and by 0.07 % from 80 a to 160 a); the crack is
//! the row of triangles between
//! `y = −h/2` and `y = h/2` with `|x| < a`, given the compression-only central-force law
//! of a failed cell (Nilsen et al. (2017) eqs. 32–33, open edges at 1e-6 of their
//! stiffness), and the pressure acts on the band as the pore pressure of a failed cell
//! does in the Biot coupling with α = 1: the nodal forces `p N_i` of each band cell.
//!
//! Checks, at `n` = 10, 20, 40, 80 cells per half-length (1.8 s in all):
//! - the opening measured as the jump of `u_y` across the band at its nodes, and as the
//!   smeared cell opening of `porofrac_sim::crack_flow::cell_opening` (the aperture the
//!   cubic law uses) at the band cells' centroids: relative L2 errors against Sneddon's;
//! - the crack volume (the band's volume change `Σ N_i · u_i`) against `V`;
//! - the observed orders between the resolutions.
//!
//! The tolerances are the measured errors rounded up by about 5 % (see
//! docs/hydrofrac/validation.md for the table); the orders are asserted from below.

use porofrac_grid::{Grid, Point};
use porofrac_law::{CellLaw, Stiffness};
use porofrac_mdem::{DemLaw, DemMode, MdemLaw};
use porofrac_sim::crack_flow::cell_opening;
use porofrac_sim::*;

mod common;

const A: f64 = 1.0;
const E: f64 = 1.0e10;
const NU: f64 = 0.25;
const P: f64 = 1.0e6;

/// Node coordinates on one axis: uniform spacing `h` from 0 to `inner` (a multiple of
/// `h`, or from `h/2` when `half` is set), then growing by 1.2 per cell to beyond
/// `outer`, mirrored about 0.
fn axis(h: f64, inner: f64, outer: f64, half: bool) -> Vec<f64> {
    let mut pos = Vec::new();
    let mut x = if half { 0.5 * h } else { 0.0 };
    while x < inner + 1e-9 * h {
        pos.push(x);
        x += h;
    }
    let mut step = h;
    let mut last = *pos.last().unwrap();
    while last < outer {
        step *= 1.2;
        last += step;
        pos.push(last);
    }
    let mut all: Vec<f64> = pos.iter().rev().map(|v| -v).collect();
    if !half {
        all.pop();
    }
    all.extend_from_slice(&pos);
    all
}

/// The grid of triangles on the lines `xs` × `ys`, every rectangle split along
/// alternating diagonals (mirror-symmetric about both axes through a node line).
fn triangles(xs: &[f64], ys: &[f64]) -> Grid<2> {
    let (nx, ny) = (xs.len(), ys.len());
    let nodes: Vec<Point<2>> = ys
        .iter()
        .flat_map(|&y| xs.iter().map(move |&x| Point::<2>::new(x, y)))
        .collect();
    let id = |i: usize, j: usize| j * nx + i;
    let (mut pos, mut cn) = (vec![0], Vec::new());
    let (ic, jc) = (nx / 2, ny / 2);
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            // The diagonal from the corner nearest the centre lines.
            let flip = (i < ic) != (j < jc);
            let tris = if flip {
                [[a, b, d], [b, c, d]]
            } else {
                [[a, b, c], [a, c, d]]
            };
            for t in tris {
                cn.extend_from_slice(&t);
                pos.push(cn.len());
            }
        }
    }
    Grid::from_polygons(nodes, &pos, &cn).unwrap()
}

/// Sneddon's opening at `x`.
fn sneddon(x: f64) -> f64 {
    4.0 * P * (1.0 - NU * NU) / E * (A * A - x * x).max(0.0).sqrt()
}

/// The band of `n` cells per half-length opened by `P`: the grid, the nodal
/// displacement, the band flags and the cell size.
fn opened_band(n: usize) -> (Grid<2>, Vec<f64>, Vec<bool>, f64) {
    let h = A / n as f64;
    let xs = axis(h, 1.5 * A, 80.0 * A, false);
    let ys = axis(h, 0.5 * A, 80.0 * A, true);
    let grid = triangles(&xs, &ys);
    let stiffness = Stiffness::<2>::isotropic(E, NU).unwrap();
    let mdem = MdemLaw::<2>::new(&stiffness).unwrap();
    let dem = DemLaw::<2>::new(&stiffness, DemMode::CompressionOnly)
        .unwrap()
        .with_open_stiffness(1e-6)
        .unwrap();
    let band: Vec<bool> = grid
        .cell_centroids()
        .iter()
        .map(|c| c[1].abs() < 0.5 * h && c[0].abs() < A)
        .collect();
    let law_of_cell = band.iter().map(|&b| usize::from(b)).collect();
    let laws = LawMap::new(&grid, vec![&mdem as &dyn CellLaw<2>, &dem], law_of_cell).unwrap();
    let fixed = Displacement {
        name: "boundary".into(),
        faces: grid.boundary_faces(),
        components: [Some(0.0.into()), Some(0.0.into())],
    };
    let dofs = DofMap::new(&grid, &[fixed], &[]).unwrap();
    let pattern = Pattern::new(&grid, &dofs).unwrap();
    let u = common::open_band(&grid, &laws, &dofs, &pattern, &band, P);
    (grid, u, band, h)
}

/// Relative errors (L2 of the jump, L2 of the smeared cell opening, crack volume) with
/// `n` cells per half-length.
fn errors(n: usize) -> (f64, f64, f64) {
    let (grid, u, band, h) = opened_band(n);
    let mut nn = vec![Point::<2>::zeros(); 3];

    // The jump across the band at its nodes (x = −a + i h), trapezoid weights.
    let node_at = |x: f64, y: f64| {
        (0..grid.num_nodes())
            .find(|&i| (grid.node(i) - Point::<2>::new(x, y)).norm() < 1e-9 * h)
            .unwrap()
    };
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..=2 * n {
        let x = -A + i as f64 * h;
        let jump = u[2 * node_at(x, 0.5 * h) + 1] - u[2 * node_at(x, -0.5 * h) + 1];
        let wt = if i == 0 || i == 2 * n { 0.5 * h } else { h };
        num += wt * (jump - sneddon(x)).powi(2);
        den += wt * sneddon(x).powi(2);
    }
    let l2_jump = (num / den).sqrt();

    // The smeared opening of each band cell at its centroid, weighted by its area.
    let (mut num, mut den, mut volume) = (0.0, 0.0, 0.0);
    for c in (0..grid.num_cells()).filter(|&c| band[c]) {
        grid.cell_node_normals(c, &mut nn);
        let uc: Vec<f64> = grid
            .cell_nodes(c)
            .iter()
            .flat_map(|&i| [u[2 * i], u[2 * i + 1]])
            .collect();
        let w = cell_opening(&grid, c, &nn, &uc).aperture;
        let exact = sneddon(grid.cell_centroid(c)[0]);
        let vol = grid.cell_volume(c);
        num += vol * (w - exact).powi(2);
        den += vol * exact.powi(2);
        volume += nn
            .iter()
            .zip(uc.chunks(2))
            .map(|(ni, ui)| ni[0] * ui[0] + ni[1] * ui[1])
            .sum::<f64>();
    }
    let l2_cell = (num / den).sqrt();
    let exact_volume = 2.0 * std::f64::consts::PI * P * A * A * (1.0 - NU * NU) / E;
    let vol_err = (volume - exact_volume) / exact_volume;
    (l2_jump, l2_cell, vol_err)
}

/// The errors measured (2026-11-28) rounded up by about 5 %: a change of the method that
/// costs accuracy fails here. Columns: L2 of the jump, L2 of the cell opening, crack
/// volume (the band opens less than Sneddon's crack: the volume error is negative).
const BOUNDS: [(usize, f64, f64, f64); 4] = [
    (10, 5.9e-2, 4.8e-2, 6.5e-2),
    (20, 3.2e-2, 2.65e-2, 3.65e-2),
    (40, 1.78e-2, 1.5e-2, 2.05e-2),
    (80, 1.04e-2, 9.0e-3, 1.21e-2),
];

#[test]
fn sneddon_opening_and_volume_converge_at_10_20_40_80_cells_per_half_length() {
    let e: Vec<(f64, f64, f64)> = BOUNDS.iter().map(|b| errors(b.0)).collect();
    let order = |a: f64, b: f64| (a.abs() / b.abs()).log2();
    for (b, (j, c, v)) in BOUNDS.iter().zip(&e) {
        println!(
            "n = {:>2}: L2 jump {j:.4e}, L2 cell opening {c:.4e}, volume {v:+.4e}",
            b.0
        );
        assert!(
            *j <= b.1,
            "n = {}: L2 error of the jump {j:.4e} > {:.2e}",
            b.0,
            b.1
        );
        assert!(
            *c <= b.2,
            "n = {}: L2 error of the cell opening {c:.4e} > {:.2e}",
            b.0,
            b.2
        );
        assert!(
            *v < 0.0 && -v <= b.3,
            "n = {}: volume error {v:+.4e}, bound {:.2e}",
            b.0,
            b.3
        );
    }
    for k in 1..BOUNDS.len() {
        let (j, c, v) = (
            order(e[k - 1].0, e[k].0),
            order(e[k - 1].1, e[k].1),
            order(e[k - 1].2, e[k].2),
        );
        println!(
            "orders {}→{}: jump {j:.2}, cell {c:.2}, volume {v:.2}",
            BOUNDS[k - 1].0,
            BOUNDS[k].0
        );
        // Measured: 0.88, 0.86, 0.78 (jump); 0.85, 0.83, 0.73 (cell); 0.83, 0.83, 0.77
        // (volume). The √r closure at the tips limits the order below 1.
        assert!(
            j >= 0.75 && c >= 0.7 && v >= 0.75,
            "orders {j:.2} {c:.2} {v:.2}"
        );
    }
}

/// The stress intensity of the tip cells of Sneddon's band by displacement correlation
/// (`porofrac_sim::tip_opening`) against `K_I = p √(π a)`: the smallest and the largest
/// estimate over the intact cells of the band's row next to its two tips (the two
/// triangles of the next square, at both tips), with `n` cells per half-length.
fn tip_ratios(n: usize) -> (f64, f64) {
    let (grid, u, band, h) = opened_band(n);
    let adjacency = porofrac_frac::recovery::NodeCells::new(&grid);
    let e_prime = E / (1.0 - NU * NU);
    let exact = P * (std::f64::consts::PI * A).sqrt();
    let ahead: Vec<f64> = (0..grid.num_cells())
        .filter(|&c| {
            let x = grid.cell_centroid(c);
            !band[c] && x[1].abs() < 0.5 * h && (x[0].abs() - A) < h
        })
        .map(|c| {
            porofrac_sim::tip_opening::tip_stress_intensity(
                &grid, &adjacency, &band, c, e_prime, &u,
            )
            .expect("a tip cell has an estimate")
                / exact
        })
        .collect();
    assert_eq!(ahead.len(), 4, "two cells ahead of each tip");
    let lo = ahead.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ahead.iter().copied().fold(0.0, f64::max);
    (lo, hi)
}

/// The displacement correlation on Sneddon's crack: the estimate of `K_I` at the cells
/// ahead of the tips, measured (2026-11-28) at n = 5, 10, 20, 40 cells per half-length as
/// 0.866–0.877, 0.915–0.927, 0.943–0.954, 0.959–0.970 of `p √(π a)`: below 1 (the jump
/// one cell behind the tip of a band is smaller than LEFM's `√r`) and approaching it as
/// the cells shrink. Asserted within 0.5 % of those values, and increasing with `n`.
#[test]
fn tip_stress_intensity_of_sneddons_crack() {
    let measured = [
        (5, 0.8660, 0.8770),
        (10, 0.9153, 0.9265),
        (20, 0.9431, 0.9540),
        (40, 0.9591, 0.9700),
    ];
    let mut last = 0.0;
    for (n, lo, hi) in measured {
        let (l, h) = tip_ratios(n);
        println!("n = {n}: K_est / K_I from {l:.4} to {h:.4}");
        assert!(
            (l / lo - 1.0).abs() < 5e-3 && (h / hi - 1.0).abs() < 5e-3,
            "n = {n}: {l:.4}–{h:.4}, measured {lo}–{hi}"
        );
        assert!(
            l > last,
            "n = {n}: {l:.4} not above the coarser grid's {last:.4}"
        );
        last = l;
    }
}

/// Sneddon's crack at 30° to the grid lines: the band is the zig-zag row of triangles
/// that the segment from `−a t` to `a t` (`t` = (cos 30°, sin 30°)) crosses or touches
/// (the segment passes through the node at the centre: the cells around it are all in
/// the band, else the intact cells on its two sides would pin the crack there), on the grid
/// of triangles uniform with `n` cells per half-length out to 1.5 a, opened by `P`.
/// Returns the grid, the displacement, the band and `t`.
fn opened_rotated_band(n: usize) -> (Grid<2>, Vec<f64>, Vec<bool>, Point<2>) {
    let h = A / n as f64;
    let xs = axis(h, 1.5 * A, 80.0 * A, false);
    let grid = triangles(&xs, &xs);
    let angle = 30f64.to_radians();
    let t = Point::<2>::new(angle.cos(), angle.sin());
    let n_hat = Point::<2>::new(-t[1], t[0]);
    let band: Vec<bool> = (0..grid.num_cells())
        .map(|c| {
            let (lo, hi) = grid
                .cell_nodes(c)
                .iter()
                .map(|&i| grid.node(i).dot(&n_hat))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                    (lo.min(s), hi.max(s))
                });
            lo <= 0.0 && hi >= 0.0 && grid.cell_centroid(c).dot(&t).abs() < A
        })
        .collect();
    let stiffness = Stiffness::<2>::isotropic(E, NU).unwrap();
    let mdem = MdemLaw::<2>::new(&stiffness).unwrap();
    let dem = DemLaw::<2>::new(&stiffness, DemMode::CompressionOnly)
        .unwrap()
        .with_open_stiffness(1e-6)
        .unwrap();
    let law_of_cell = band.iter().map(|&b| usize::from(b)).collect();
    let laws = LawMap::new(&grid, vec![&mdem as &dyn CellLaw<2>, &dem], law_of_cell).unwrap();
    let fixed = Displacement {
        name: "boundary".into(),
        faces: grid.boundary_faces(),
        components: [Some(0.0.into()), Some(0.0.into())],
    };
    let dofs = DofMap::new(&grid, &[fixed], &[]).unwrap();
    let pattern = Pattern::new(&grid, &dofs).unwrap();
    let u = common::open_band(&grid, &laws, &dofs, &pattern, &band, P);
    (grid, u, band, t)
}

/// The estimates `K_est / (p √(π a))` of `porofrac_sim::tip_distance` at the distance `r`
/// (a multiple of `a`) at the intact cells it finds ahead of a tip of the rotated band,
/// with `n` cells per half-length, as (smallest, largest, cells ahead at the two tips).
/// Panics when a cell it takes for ahead of a tip is not next to one.
fn rotated_tip_ratios(n: usize, r: f64) -> (f64, f64, [usize; 2]) {
    use porofrac_sim::tip_distance::{TipReading, read_tip};
    let (grid, u, band, t) = opened_rotated_band(n);
    let h = A / n as f64;
    let adjacency = porofrac_frac::recovery::NodeCells::new(&grid);
    let e_prime = E / (1.0 - NU * NU);
    let exact = P * (std::f64::consts::PI * A).sqrt();
    let (mut lo, mut hi, mut ahead) = (f64::INFINITY, 0.0f64, [0usize; 2]);
    for c in (0..grid.num_cells()).filter(|&c| !band[c]) {
        let touches = grid
            .cell_nodes(c)
            .iter()
            .any(|&i| adjacency.of(i).iter().any(|&g| band[g]));
        if !touches {
            continue;
        }
        if let TipReading::Ahead(s) = read_tip(&grid, &adjacency, &band, c, &u, r * A) {
            let along = grid.cell_centroid(c).dot(&t);
            assert!(
                along.abs() > A - h,
                "n = {n}: cell {c} at {along:.3} along the crack read as ahead of a tip"
            );
            let ratio = s.stress_intensity(e_prime) / exact;
            lo = lo.min(ratio);
            hi = hi.max(ratio);
            ahead[usize::from(along > 0.0)] += 1;
        }
    }
    (lo, hi, ahead)
}

/// The stress intensity read at a fixed distance behind the tips of Sneddon's crack at
/// 30° to the grid lines (a zig-zag band of triangles), against `K_I = p √(π a)`. LEFM's
/// `√r` law read on Sneddon's exact opening at `r` gives `√(1 − r/(2a))` of `K_I` (0.949
/// at r = 0.2 a, 0.922 at 0.3 a); the band adds the errors of a smeared tip (module docs
/// of `porofrac_sim::tip_distance`), mostly the tip's position, taken per cell ahead
/// from the nodes it shares with the band (up to a cell apart between the cells around
/// one tip). Measured 2026-11-29 over the eight cells read as ahead at each tip:
/// 0.785–1.056 at n = 10, r = 0.2 a; 0.812–0.978 at n = 20, r = 0.2 a; 0.884–0.986 at
/// n = 20, r = 0.3 a. Asserted: every estimate within 25 % of `K_I` at 10 cells per
/// half-length and within 20 % at 20, and cells read as ahead at both tips only.
#[test]
fn stress_intensity_at_a_distance_on_a_rotated_crack() {
    for (n, r, tolerance) in [(10, 0.2, 0.25), (20, 0.2, 0.2), (20, 0.3, 0.2)] {
        let (lo, hi, ahead) = rotated_tip_ratios(n, r);
        println!(
            "n = {n}, r = {r} a: K_est / K_I from {lo:.4} to {hi:.4} at {ahead:?} cells ahead"
        );
        assert!(
            ahead[0] >= 1 && ahead[1] >= 1,
            "n = {n}: cells ahead of the two tips {ahead:?}"
        );
        assert!(
            (lo - 1.0).abs() <= tolerance && (hi - 1.0).abs() <= tolerance,
            "n = {n}, r = {r} a: K_est / K_I from {lo:.4} to {hi:.4}, allowed 1 ± {tolerance}"
        );
    }
}

/// The stress intensity read behind the tips of Sneddon's crack at 30° to the grid lines
/// when the crack is shorter than the distance `r` (module docs of
/// `porofrac_sim::tip_distance`, "Short cracks"): the search finds the whole crack, of
/// length `ℓ ≈ 2a`, and reads its opening at `r′ = max(h, ℓ/4)` with Sneddon's factor
/// `1/√(1 − r′/ℓ)`, so both tips read `K_I = p √(π a)` instead of no reading (the rule
/// before, which left such a crack to the tensile strength). Measured 2026-11-29 over the
/// cells read as ahead at the two tips, `r = 2.5 a`: 0.932–1.056 at 10 cells per
/// half-length, 0.831–0.925 at 5, 0.837–1.012 at 3; 0.642–0.802 at 2 and 0.341–0.406 at 1
/// (a band of two to four cells reads low, not asserted). Asserted: within 10 % of `K_I`
/// at 10 cells per half-length and within 20 % at 5 and 3, cells read as ahead at both
/// tips only.
#[test]
fn stress_intensity_on_a_rotated_crack_shorter_than_the_distance() {
    for (n, tolerance) in [(10, 0.1), (5, 0.2), (3, 0.2)] {
        let (lo, hi, ahead) = rotated_tip_ratios(n, 2.5);
        println!(
            "n = {n}, r = 2.5 a: K_est / K_I from {lo:.4} to {hi:.4} at {ahead:?} cells ahead"
        );
        assert!(
            ahead[0] >= 1 && ahead[1] >= 1,
            "n = {n}: cells ahead of the two tips {ahead:?}"
        );
        assert!(
            (lo - 1.0).abs() <= tolerance && (hi - 1.0).abs() <= tolerance,
            "n = {n}, r = 2.5 a: K_est / K_I from {lo:.4} to {hi:.4}, allowed 1 ± {tolerance}"
        );
    }
}
