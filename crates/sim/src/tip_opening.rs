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
//! An intact cell `c` that shares a node with failed cells is a tip candidate. Among the
//! failed cells sharing a node with it, the one that has opened most, `f`, samples the
//! opening ([`crate::crack_flow::cell_opening`]: the smeared aperture `w_f`, the normal
//! `n` of the opening). The crack runs across `n`; the distance `ρ` from the centroid of
//! `f` to that of `c` along the crack (the component of `x_c − x_f` normal to `n`) sets
//! the distance of the sample to the tip, which lies between the two cells (a cell whose
//! centroid lies outside the band of `f`, farther than half its thickness `h_n` across
//! the crack, is beside the crack, not ahead of a tip: `None`):
//!
//! ```text
//!   K_I ≈ E′ w_f / (4 √(2/π) √(λ ρ)),      λ = TIP_FRACTION,
//! ```
//!
//! with `λ` calibrated on Sneddon's pressurized crack (a band of split rectangles, the
//! tip on a line of nodes, `crates/sim/tests/sneddon.rs`, test `tip_stress_intensity`):
//! the smeared aperture of the last failed cell averages `√r` over its width, and its
//! centroid and the candidate's are a fixed fraction of a cell from the tip on a
//! structured band. The estimate is for cracks along grid lines of split rectangles
//! (the predefined crack path of the KGD scenes); on an unstructured band the fraction
//! differs by the shape of the cells.

use porofrac_frac::recovery::NodeCells;
use porofrac_grid::{Grid, Point};

use crate::crack_flow::{Opening, cell_opening};

/// `λ`: the distance of the opening sample from the tip, as a fraction of the distance
/// `ρ` between the sampled failed cell and the tip candidate along the crack (see the
/// module docs; calibrated on Sneddon's crack).
pub const TIP_FRACTION: f64 = 1.0;

/// `K_I` (Pa·√m) of an LEFM crack whose opening is `w` (m) at a distance `r` (m) behind its
/// tip, in a solid of plane-strain modulus `e_prime` (Pa): `E′ w / (4 √(2/π) √r)`.
pub fn stress_intensity_from_opening(e_prime: f64, w: f64, r: f64) -> f64 {
    e_prime * w / (4.0 * (2.0 / std::f64::consts::PI).sqrt() * r.sqrt())
}

/// The stress intensity (Pa·√m) at the tip next to the intact cell `c` (see the module
/// docs), or `None` when `c` shares no node with a failed cell. `opening(f)` is the
/// opening of the failed cell `f`; `adjacency` the cells of every node; `e_prime` the
/// plane-strain modulus `E/(1 − ν²)` (Pa) of the solid at the tip.
pub fn tip_stress_intensity<const D: usize>(
    grid: &Grid<D>,
    adjacency: &NodeCells,
    failed: &[bool],
    c: usize,
    e_prime: f64,
    mut opening: impl FnMut(usize) -> Opening<D>,
) -> Option<f64> {
    let mut best: Option<(usize, Opening<D>)> = None;
    for &node in grid.cell_nodes(c) {
        for &f in adjacency.of(node) {
            if !failed[f] || best.as_ref().is_some_and(|(g, _)| *g == f) {
                continue;
            }
            let o = opening(f);
            if best.as_ref().is_none_or(|(_, b)| o.aperture > b.aperture) {
                best = Some((f, o));
            }
        }
    }
    let (f, o) = best?;
    let d: Point<D> = grid.cell_centroid(c) - grid.cell_centroid(f);
    let across = d.dot(&o.normal);
    let rho = (d - o.normal * across).norm();
    // A cell beside the crack (its centroid outside the band of `f`) is not ahead of a tip.
    if !(rho > 0.0) || across.abs() >= 0.5 * o.thickness {
        return None;
    }
    Some(stress_intensity_from_opening(
        e_prime,
        o.aperture,
        TIP_FRACTION * rho,
    ))
}

/// The opening of cell `c` at the nodal displacement `u` (all dofs of the grid, `D` per
/// node in node order) with the node normals of the grid.
pub fn opening_at<const D: usize>(grid: &Grid<D>, c: usize, u: &[f64]) -> Opening<D> {
    let nodes = grid.cell_nodes(c);
    let mut normals = vec![Point::<D>::zeros(); nodes.len()];
    grid.cell_node_normals(c, &mut normals);
    let uc: Vec<f64> = nodes
        .iter()
        .flat_map(|&i| (0..D).map(move |a| u[D * i + a]))
        .collect();
    cell_opening(grid, c, &normals, &uc)
}
