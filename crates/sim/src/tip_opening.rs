//! The stress intensity at a crack tip from the crack's opening (displacement
//! correlation), for a crack that is a band of failed cells.
//!
//! Near the tip of a crack in linear elasticity the opening grows as the square root of
//! the distance `r` to the tip (LEFM, mode I):
//!
//! ```text
//!   w(r) = (K′/E′) √r,      K′ = 4 √(2/π) K_I,      E′ = E/(1 − ν²),
//! ```
//!
//! so an opening measured at a distance `r` behind the tip gives
//! `K_I = E′ w(r) / (4 √(2/π) √r)`. This is how GEOS and OpenGeoSys test a tip against the
//! toughness `K_Ic` in their plane-strain hydraulic-fracture (KGD) validations; it reads
//! the displacements, which converge at the tip of a band of cells where the tip cell's
//! stress does not (it is singular, and a cell averages it over a size that depends on
//! the grid).
//!
//! # On a band of failed cells
//!
//! An intact cell `c` that shares a node with failed cells is a tip candidate. The failed
//! cells sharing a node with it, and those sharing a node with them, are the crack near
//! it: their centroids spread least across the crack, which gives its normal `n` (the
//! smeared opening of a single cell near a tip is tilted by 20–30°, too much to tell the
//! two faces of the band apart), and the crack runs along `t`, from their mean towards
//! `c`. A cell whose centroid lies outside the band (the extent of those cells' nodes
//! along `n`) is beside the crack, not ahead of a tip: `None`. The tip is the mean
//! position along `t` of the nodes `c` shares with failed cells; the sample is the line of
//! nodes of those failed cells nearest behind the tip by at least three quarters of the
//! length `L` of `c` along `t`, at the distance `r` (one cell on a band of split
//! rectangles when the tip is a line of nodes, one and a half when the tip column is
//! half failed), where the opening is the jump of `u·n` across the band (the mean over
//! the nodes on its far side minus the mean over those on its near side):
//!
//! ```text
//!   K_I ≈ E′ [u·n](r) / (4 √(2/π) √r).
//! ```
//!
//! The jump is the opening that converges on a band (Sneddon's crack,
//! docs/hydrofrac/validation.md); the estimate is checked on Sneddon's crack in
//! `crates/sim/tests/sneddon.rs` (test `tip_stress_intensity_of_sneddons_crack`). It is
//! meant for cracks along grid lines (the predefined crack path of the KGD scenes); on an
//! unstructured band the back line is a zig-zag and the estimate is rougher.
//!
//! # In 3D: a front
//!
//! The same steps read a crack front in 3D, cell by cell: `n` is the normal of the plane
//! of the failed cells near `c` (the direction of least spread of their centroids),
//! `t` the direction in that plane from them towards `c` (the normal of the front at
//! `c`), the tip the mean position along `t` of the nodes `c` shares with failed cells,
//! and the sample the nodes of the failed cells near `c` on the plane across `t` closest
//! behind the tip by at least three quarters of `c`'s length along `t` (a strip of the
//! band's two faces along the front). It needs a band whose cells span it (nodes on its
//! two faces only, as the six tetrahedra of a box split about its diagonal give) and a
//! crack of more than one box across: the centroids of the six tetrahedra of one box
//! lie in a plane through its diagonal, which would be taken for the crack's.
//! On Sneddon's penny (`crates/sim/tests/penny.rs`) the estimate at the cells just outside
//! the front is 0.45–0.78 of `K_I` (mean 0.64) at 4 cells per radius and 0.46–0.97 (mean
//! 0.74) at 8: lower and more scattered than on a straight tip, the front being a
//! staircase of boxes. `scenes/penny_toughness.toml` grows a penny with it
//! (docs/hydrofrac/validation.md, "Penny-shaped crack": the radius within 2 % of the
//! toughness vertex solution, the pressure about 40 % above it).

use porofrac_frac::recovery::NodeCells;
use porofrac_grid::{Grid, Point};
use porofrac_law::{Tensor, principal};

/// `K_I` (Pa·√m) of an LEFM crack whose opening is `w` (m) at a distance `r` (m) behind its
/// tip, in a solid of plane-strain modulus `e_prime` (Pa): `E′ w / (4 √(2/π) √r)`.
pub fn stress_intensity_from_opening(e_prime: f64, w: f64, r: f64) -> f64 {
    e_prime * w / (4.0 * (2.0 / std::f64::consts::PI).sqrt() * r.sqrt())
}

/// The stress intensity (Pa·√m) at the tip next to the intact cell `c` (see the module
/// docs), or `None` when `c` is not ahead of a crack tip. `u` is the nodal displacement
/// (`D` values per node, node order); `adjacency` the cells of every node; `e_prime` the
/// plane-strain modulus `E/(1 − ν²)` (Pa) of the solid at the tip.
pub fn tip_stress_intensity<const D: usize>(
    grid: &Grid<D>,
    adjacency: &NodeCells,
    failed: &[bool],
    c: usize,
    e_prime: f64,
    u: &[f64],
) -> Option<f64> {
    let s = tip_sample(grid, adjacency, failed, c, u)?;
    Some(stress_intensity_from_opening(
        e_prime,
        s.opening.max(0.0),
        s.distance,
    ))
}

/// The opening behind the tip next to an intact cell, as the module docs read it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TipSample<const D: usize> {
    /// The jump of `u·n` across the band on the back line (m; may be negative).
    pub opening: f64,
    /// The distance `r` from the back line to the tip along the crack (m).
    pub distance: f64,
    /// The unit direction `t` along the crack, from the crack towards the tip cell.
    pub along: Point<D>,
    /// The tip: the mean of the nodes the tip cell shares with failed cells.
    pub tip: Point<D>,
    /// The length `L` of the tip cell along `t` (m).
    pub length: f64,
}

/// The opening sample behind the tip next to the intact cell `c` (see the module docs),
/// or `None` when `c` is not ahead of a crack tip; `u` and `adjacency` as in
/// [`tip_stress_intensity`].
pub fn tip_sample<const D: usize>(
    grid: &Grid<D>,
    adjacency: &NodeCells,
    failed: &[bool],
    c: usize,
    u: &[f64],
) -> Option<TipSample<D>> {
    let failed_at = |nodes: &[usize], out: &mut Vec<usize>| {
        for &node in nodes {
            for &g in adjacency.of(node) {
                if failed[g] && !out.contains(&g) {
                    out.push(g);
                }
            }
        }
    };
    // The crack behind `c`: the failed cells sharing a node with it, and a ring farther.
    let mut behind = Vec::new();
    failed_at(grid.cell_nodes(c), &mut behind);
    if behind.is_empty() {
        return None;
    }
    let mut near = behind.clone();
    for &g in &behind {
        failed_at(grid.cell_nodes(g), &mut near);
    }
    // Its plane: the centroids' mean and the direction of their least spread.
    let mean = near
        .iter()
        .fold(Point::<D>::zeros(), |m, &g| m + grid.cell_centroid(g))
        / near.len() as f64;
    let mut spread = Tensor::<D>::zeros();
    for &g in &near {
        let d = grid.cell_centroid(g) - mean;
        spread += d * d.transpose();
    }
    let pr = principal(&spread);
    let n = Point::<D>::from_fn(|a, _| pr.directions[D - 1][a]);
    let d = grid.cell_centroid(c) - mean;
    let along = d - n * d.dot(&n);
    let rho = along.norm();
    if rho <= 0.0 || rho.is_nan() {
        return None;
    }
    let t = along / rho;
    // A cell beside the crack (its centroid outside the band of failed cells) is not
    // ahead of a tip.
    let (lo, hi) = near
        .iter()
        .flat_map(|&g| grid.cell_nodes(g).iter())
        .map(|&i| (grid.node(i) - mean).dot(&n))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    let off = d.dot(&n);
    if off <= lo || off >= hi {
        return None;
    }
    // The tip: the mean position along the crack of the nodes `c` shares with failed cells.
    let (mut sum, mut count) = (0.0, 0usize);
    let mut tip_point = Point::<D>::zeros();
    for &node in grid.cell_nodes(c) {
        if adjacency.of(node).iter().any(|&g| failed[g]) {
            sum += grid.node(node).dot(&t);
            tip_point += grid.node(node);
            count += 1;
        }
    }
    let tip = sum / count as f64;
    tip_point /= count as f64;
    // The back line: the line of nodes of the crack near `c` closest behind the tip by
    // at least three quarters of the length `L` of `c` along the crack.
    let length = {
        let (lo, hi) = grid
            .cell_nodes(c)
            .iter()
            .map(|&i| grid.node(i).dot(&t))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s), hi.max(s))
            });
        hi - lo
    };
    let mut nodes: Vec<usize> = near
        .iter()
        .flat_map(|&g| grid.cell_nodes(g).iter().copied())
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    let back = nodes
        .iter()
        .map(|&i| grid.node(i).dot(&t))
        .filter(|&s| tip - s >= 0.75 * length)
        .fold(f64::NEG_INFINITY, f64::max);
    let r = tip - back;
    if !r.is_finite() {
        return None;
    }
    let line: Vec<usize> = nodes
        .into_iter()
        .filter(|&i| (grid.node(i).dot(&t) - back).abs() <= 0.25 * length)
        .collect();
    // The jump of u·n across the band on that line: the nodes on the far side of its
    // middle against those on the near side.
    let mid = line.iter().map(|&i| grid.node(i).dot(&n)).sum::<f64>() / line.len() as f64;
    let (mut up, mut nu, mut down, mut nd) = (0.0, 0usize, 0.0, 0usize);
    for &i in &line {
        let ui = Point::<D>::from_fn(|a, _| u[D * i + a]).dot(&n);
        if grid.node(i).dot(&n) > mid {
            up += ui;
            nu += 1;
        } else {
            down += ui;
            nd += 1;
        }
    }
    if nu == 0 || nd == 0 {
        return None;
    }
    let w = up / nu as f64 - down / nd as f64;
    Some(TipSample {
        opening: w,
        distance: r,
        along: t,
        tip: tip_point,
        length,
    })
}
