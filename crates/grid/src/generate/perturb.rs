//! Random jitter of the interior nodes of a grid.
//!
//! Every interior node `x_n` moves to `x_n + a h_n ξ_n`, where `h_n` is the length of the
//! shortest edge incident to the node (an edge is a pair of consecutive nodes of a face
//! loop), `a` is the amplitude (a fraction, `0 ≤ a ≤` [`MAX_PERTURB`]) and `ξ_n` is drawn
//! uniformly from the unit disc (2D) or ball (3D) by a `ChaCha8Rng` seeded with
//! `seed`, node by node in node order, so the result depends only on the grid and the seed.
//! Nodes of boundary faces stay fixed, so the domain and its named sides do not change.
//!
//! Why `a ≤ 0.3` keeps the grids of the structured generators valid: a node of a cell
//! leaves the half-space of the cell's opposite facet (the cell inverts or a quadrilateral
//! becomes non-convex) only if the node and that facet approach each other by the node's
//! distance to it. For squares, cubes and the Kuhn triangles and tetrahedra that distance
//! is at least `h/√2 ≈ 0.707 h` with `h` the shortest incident edge, and the two can
//! approach by at most `2 a h = 0.6 h`. For other grids a cell may still invert; this is
//! reported as an error naming the cell (the grid is validated again), never a panic.
//! Hexahedra get non-planar faces, which the grid handles through its face triangulation.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::point::Point;

/// Largest accepted jitter amplitude, as a fraction of the shortest incident edge.
pub const MAX_PERTURB: f64 = 0.3;

/// Length of the shortest edge at every node (`∞` for a node on no edge).
pub(crate) fn shortest_incident_edge<const D: usize>(grid: &Grid<D>) -> Vec<f64> {
    let mut h = vec![f64::INFINITY; grid.num_nodes()];
    for f in 0..grid.num_faces() {
        let l = grid.face_nodes(f);
        let m = l.len();
        let edges = if D == 2 { 1 } else { m };
        for k in 0..edges {
            let (a, b) = (l[k], l[(k + 1) % m]);
            let len = (grid.node(a) - grid.node(b)).norm();
            h[a] = h[a].min(len);
            h[b] = h[b].min(len);
        }
    }
    h
}

/// A point uniformly distributed in the unit disc (2D) or ball (3D), by rejection.
pub(crate) fn unit_ball<const D: usize>(rng: &mut ChaCha8Rng) -> Point<D> {
    loop {
        let p = Point::<D>::from_fn(|_, _| 2.0 * rng.random::<f64>() - 1.0);
        if p.norm_squared() <= 1.0 {
            return p;
        }
    }
}

/// Check a jitter amplitude against `[0, MAX_PERTURB]`.
pub(crate) fn check_amplitude(amplitude: f64) -> Result<()> {
    if !(0.0..=MAX_PERTURB).contains(&amplitude) {
        return Err(GridError::Input(format!(
            "perturbation amplitude must be in [0, {MAX_PERTURB}] (fraction of the local \
             cell size), got {amplitude}"
        )));
    }
    Ok(())
}

/// A copy of `grid` with every interior node moved by at most `amplitude × h_n` (see the
/// module docs). Topology and tags are kept; the geometry is recomputed and validated.
///
/// Errors: `amplitude` outside `[0, MAX_PERTURB]`, or a cell that the jitter made
/// degenerate or inverted (the error names the cell).
pub fn perturb<const D: usize>(grid: &Grid<D>, amplitude: f64, seed: u64) -> Result<Grid<D>> {
    check_amplitude(amplitude)?;
    let h = shortest_incident_edge(grid);
    let mut fixed = vec![false; grid.num_nodes()];
    for f in 0..grid.num_faces() {
        if grid.is_boundary_face(f) {
            for &n in grid.face_nodes(f) {
                fixed[n] = true;
            }
        }
    }
    let mut out = grid.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for (n, x) in out.nodes.iter_mut().enumerate() {
        if !fixed[n] && h[n].is_finite() {
            *x += unit_ball::<D>(&mut rng) * (amplitude * h[n]);
        }
    }
    out.compute_geometry()?;
    Ok(out)
}
