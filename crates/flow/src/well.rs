//! Peaceman well index.
//!
//! A well in cell `K` exchanges `q = WI (p_bh − p_K) / μ` with the cell (positive:
//! injection), where `p_bh` is the bottom-hole pressure and, after Peaceman (1978, 1983),
//!
//! ```text
//!   WI  = 2π k̄ h / (ln(r_e / r_w) + s),       k̄ = √(k_x k_y),
//!   r_e = 0.28 √( √(k_y/k_x) Δx² + √(k_x/k_y) Δy² ) / ( (k_y/k_x)^¼ + (k_x/k_y)^¼ ),
//! ```
//!
//! which for isotropic `k` is `r_e = 0.14 √(Δx² + Δy²)`. `Δx, Δy` (and `h = Δz` in 3D) are
//! the extents of the cell's bounding box, `k_x = K₁₁`, `k_y = K₂₂` (off-diagonal terms
//! are ignored); the well is vertical (along z) in 3D, and `h = 1` in 2D (a 2D model is
//! per unit thickness). `r_e` is the radius at which the radial (log) solution equals the
//! cell pressure of the five-point scheme on a uniform grid; on other cells it is the usual
//! approximation.

use porofrac_grid::Grid;

use crate::perm::Tensor;

/// Peaceman's equivalent radius and well index of a well of radius `radius` and skin `skin`
/// in cell `cell`: returns `(r_e, WI)`; `Err` describes why no positive index exists.
pub fn peaceman_well_index<const D: usize>(
    grid: &Grid<D>,
    cell: usize,
    k: &Tensor<D>,
    radius: f64,
    skin: f64,
) -> Result<(f64, f64), String> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(format!("radius must be > 0, got {radius}"));
    }
    if !skin.is_finite() {
        return Err(format!("skin must be finite, got {skin}"));
    }
    let mut lo = [f64::INFINITY; D];
    let mut hi = [f64::NEG_INFINITY; D];
    for &n in grid.cell_nodes(cell) {
        let x = grid.node(n);
        for a in 0..D {
            lo[a] = lo[a].min(x[a]);
            hi[a] = hi[a].max(x[a]);
        }
    }
    let (dx, dy) = (hi[0] - lo[0], hi[1] - lo[1]);
    let h = if D == 3 { hi[2] - lo[2] } else { 1.0 };
    let (kx, ky) = (k[(0, 0)], k[(1, 1)]);
    let (rx, ry) = ((ky / kx).sqrt(), (kx / ky).sqrt());
    let re = 0.28 * (rx * dx * dx + ry * dy * dy).sqrt() / (rx.sqrt() + ry.sqrt());
    let denom = (re / radius).ln() + skin;
    if denom.is_nan() || denom <= 0.0 {
        return Err(format!(
            "ln(r_e/r_w) + s = {denom} ≤ 0 (r_e = {re}, r_w = {radius}, s = {skin}): \
             the well is too large for its cell"
        ));
    }
    Ok((
        re,
        2.0 * std::f64::consts::PI * (kx * ky).sqrt() * h / denom,
    ))
}
