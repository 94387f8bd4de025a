//! The stress intensity at the tip of a crack that is a band of failed cells through
//! unstructured cells, read from the crack's opening at a fixed *physical* distance `r`
//! behind the tip (displacement correlation).
//!
//! Near the tip of a crack in linear elasticity the opening grows as `√r` (LEFM, mode I):
//!
//! ```text
//!   w(r) = (K′/E′) √r,      K′ = 4 √(2/π) K_I,      E′ = E/(1 − ν²),
//!   K_I  = E′ w(r) / (4 √(2/π) √r).
//! ```
//!
//! [`crate::tip_opening`] reads `w` one cell behind the tip, on a line of nodes across a
//! band of cells along grid lines: on a zig-zag band of triangles it often finds no such
//! line, and its `r` shrinks with the cells. Here `r` is a length of the scene (a few cells
//! on every grid, but the same in metres), and the opening is fitted from the nodes of the
//! band's two faces, wherever they lie:
//!
//! 1. **The crack near the tip.** An intact cell `c` sharing a node with failed cells is
//!    a tip candidate. The failed cells connected to those through shared nodes, with
//!    centroids within `r + 3h` of `c`'s centroid (`h` the cells' size,
//!    `(D! |cell|)^{1/D}`, the leg of a right triangle or tetrahedron), are the crack near
//!    `c`. Its normal `n` is the direction of least spread of their centroids (the line
//!    through them in 2D, the plane in 3D), and the crack runs along `t`, from their mean
//!    towards `c`'s centroid, in the plane across `n`.
//! 2. **Ahead, beside, or too short.** With positions `s = x·t` along the crack and the
//!    tip `s_tip` the mean position of the nodes `c` shares with failed cells, the sample
//!    lies at `s* = s_tip − r′` (the distance `r′` of the section "Short cracks": `r`
//!    behind the tip of a long crack, less behind a short one). When the crack is shorter
//!    than two cells there is no sample: [`TipReading::Short`]. Otherwise `c` is ahead of
//!    the tip when its centroid lies no more than half a cell behind the farthest failed
//!    centroid of the crack near it along `t`; else it lies beside the crack ([`TipReading::Beside`]). This admits
//!    every cell around the tip, those beside the last failed cells too: on a zig-zag
//!    band of triangles the cell that continues the crack face to face may lie beside
//!    the last failed triangle (when that triangle ends on a vertex, the cells beyond it
//!    touch it at a node only). Which of them the crack enters is left to crack tracking
//!    ([`porofrac_frac::tracking`]: face to face, into a cell the crack's line crosses),
//!    which the rule therefore needs to keep the band one cell wide.
//! 3. **The opening at `s*`.** The failed cells with centroids within `h` of `s*` along
//!    the crack are the band there; its mid-line is the mean of their centroids along `n`,
//!    `η*`. Their nodes within `1.5 h` of `s*` that also belong to an intact cell are the
//!    band's faces (nodes inside a band two cells thick are left out), on the far side
//!    (`x·n > η*`) or the near side. On each face `u·n` is fitted by a line in `s` (least
//!    squares; the mean when the nodes do not spread along the crack) and evaluated at
//!    `s*`; the opening is the difference, `w = [u·n]₊(s*) − [u·n]₋(s*)`, and
//!    `K_I = E′ w / (4 √(2/π) √r′)` with `r′ = s_tip − s*`, divided by `√(1 − r′/ℓ)` on a
//!    short crack (next section).
//!
//! # Short cracks
//!
//! A crack shorter than `r` (a wing of a few cells at a well, a crack younger than `r`)
//! has no opening `r` behind its tip, and the `√r` law read far behind the tip of a
//! short crack reads low: on Sneddon's crack of length `2a` under a pressure `p`,
//! `w(r) = (4p/E′) √(r (2a − r))` at a distance `r` behind a tip, so the law above gives
//! `K_I √(1 − r/(2a))`. The crack near `c` is therefore also measured: when the search of
//! step 1 met no failed cell beyond its reach `r + 3h`, it holds the whole crack, of length
//! `ℓ = s_tip − s_back + h/2` behind the tip (`s_back` the farthest failed centroid, about
//! half a cell inside the crack's back end), and the opening is read at
//!
//! ```text
//!   r′ = min(r, max(h, ℓ/4)),        K_I = E′ w(r′) / (4 √(2/π) √r′) / √(1 − r′/ℓ),
//! ```
//!
//! which is exact on Sneddon's profile with `ℓ = 2a`. A crack shorter than two cells
//! (`r′ > ℓ/2`) is [`TipReading::Short`]: the criteria take it by strength, so a wing
//! grows by strength by at most a cell or two before its opening is read. A crack the
//! search cut at its reach is at least `r + 3h` long and is read at `r` without the factor
//! (as before: the factor is unknown, and at least `√(1 − r/(r + 3h))`).
//!
//! A wing from a well is not a crack with two free tips: its back end is the well's wall,
//! where it stays open, and the crack it belongs to runs across the well into the other
//! wing, longer than `ℓ`. There the factor overstates `K_I`, by at most `1/√(1 − r′/ℓ)`
//! (1.15 at `r′ = ℓ/4`, `√2` for a wing of two cells, read at `r′ = h = ℓ/2`).
//!
//! # Which tips grow
//!
//! The failure resolution fails, per round, the cells whose utilization is within 1 % of
//! the largest ([`porofrac_frac::FailurePolicy::MostCritical`]). Under one pressure the two
//! tips of a toughness-dominated crack have the same `K_I`, and their readings differ by
//! the scatter of the reading (the tip's position, below: ±10–20 % on Sneddon's crack at
//! 10 cells per half-length): with the largest utilization of the whole body, the tip
//! that reads higher grows alone, round after round, even while the other reads more than
//! `K_Ic` too, and the other waits until the first reaches a cell that reads low. With
//! this rule the largest utilization is therefore taken near each cell, within `r` of its
//! centroid ([`porofrac_frac::FailurePolicy::MostCriticalNear`],
//! [`crate::FractureSettings::policy_of_rule`]): the most critical cell of every tip
//! fails in the same round, and a tip waits only while its own reading is below `K_Ic`.
//!
//! The band's faces lie about half a cell off the crack's line, so `w` also holds the
//! elastic strain of the rock across half a cell on each side: an error of the order of
//! `ε h / w`, which vanishes with the cells. The tip position is that of the band's
//! last nodes, uncertain by a fraction of a cell: an error of about `δ/(2r)` in `K_I` for
//! a tip misplaced by `δ`, also vanishing with the cells at a fixed `r`. Checked in
//! `crates/sim/tests/sneddon.rs` (`stress_intensity_at_a_distance_on_a_rotated_crack`):
//! Sneddon's crack at 30° to the grid lines of a triangle grid, with `K_I` from the
//! opening the same `r` gives on Sneddon's profile.

use porofrac_frac::recovery::NodeCells;
use porofrac_grid::{Grid, Point};
use porofrac_law::{Tensor, principal};

use crate::tip_opening::stress_intensity_from_opening;

/// The opening read at the distance `r` behind a crack tip (module docs, step 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistanceSample<const D: usize> {
    /// The opening `w` (m) at `s*` (may be negative: a closed crack).
    pub opening: f64,
    /// The distance `r′ = s_tip − s*` (m).
    pub distance: f64,
    /// The length `ℓ` (m) of the crack behind the tip when the search found all of it
    /// (module docs, "Short cracks"); `None` for a crack longer than its reach.
    pub crack_length: Option<f64>,
    /// The unit direction `t` along the crack, towards the tip.
    pub along: Point<D>,
    /// The unit normal `n` of the crack.
    pub normal: Point<D>,
    /// The tip: the mean of the nodes the tip cell shares with failed cells.
    pub tip: Point<D>,
}

impl<const D: usize> DistanceSample<D> {
    /// `K_I` (Pa·√m) of this sample in a solid of plane-strain modulus `e_prime` (Pa),
    /// with Sneddon's factor `1/√(1 − r′/ℓ)` on a crack of known length `ℓ`; a closed crack
    /// (`w ≤ 0`) gives 0.
    pub fn stress_intensity(&self, e_prime: f64) -> f64 {
        let k = stress_intensity_from_opening(e_prime, self.opening.max(0.0), self.distance);
        match self.crack_length {
            Some(length) => k / (1.0 - self.distance / length).sqrt(),
            None => k,
        }
    }
}

/// What the sample at a fixed distance finds at an intact cell next to failed cells
/// (module docs, step 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TipReading<const D: usize> {
    /// The cell lies ahead of a crack tip: the opening behind it.
    Ahead(DistanceSample<D>),
    /// The crack near the cell is shorter than two cells: no sample (module docs, "Short
    /// cracks").
    Short,
    /// The cell lies beside a crack (or touches no failed cell).
    Beside,
}

/// The size `h = (D! |cell|)^{1/D}` of cell `c` (the leg of a right triangle or
/// tetrahedron of that measure).
fn cell_size<const D: usize>(grid: &Grid<D>, c: usize) -> f64 {
    let factorial: f64 = (1..=D).map(|k| k as f64).product();
    (factorial * grid.cell_volume(c)).powf(1.0 / D as f64)
}

/// The value at `at` of the least-squares line through the points `(s, v)`; their mean
/// when the `s` do not spread by more than `tiny`; `None` without points.
fn line_value(points: &[(f64, f64)], at: f64, tiny: f64) -> Option<f64> {
    if points.is_empty() {
        return None;
    }
    let n = points.len() as f64;
    let sm = points.iter().map(|p| p.0).sum::<f64>() / n;
    let vm = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - sm).powi(2)).sum();
    if sxx <= tiny * tiny * n {
        return Some(vm);
    }
    let sxv: f64 = points.iter().map(|p| (p.0 - sm) * (p.1 - vm)).sum();
    Some(vm + sxv / sxx * (at - sm))
}

/// The reading at the intact cell `c` of the opening at the distance `r` (m) behind the
/// crack tip next to it (module docs). `adjacency` holds the cells of every node,
/// `failed` one flag per cell, `u` the nodal displacement (`D` values per node).
pub fn read_tip<const D: usize>(
    grid: &Grid<D>,
    adjacency: &NodeCells,
    failed: &[bool],
    c: usize,
    u: &[f64],
    r: f64,
) -> TipReading<D> {
    let xc = *grid.cell_centroid(c);
    // The failed cells sharing a node with `c`.
    let mut crack: Vec<usize> = Vec::new();
    for &node in grid.cell_nodes(c) {
        for &g in adjacency.of(node) {
            if failed[g] && !crack.contains(&g) {
                crack.push(g);
            }
        }
    }
    if crack.is_empty() {
        return TipReading::Beside;
    }
    let h = crack.iter().map(|&g| cell_size(grid, g)).sum::<f64>() / crack.len() as f64;
    // The crack near `c`: connected through shared nodes, within `r + 3h`.
    let reach = r + 3.0 * h;
    let mut cut = false;
    let mut next = 0;
    while next < crack.len() {
        let g = crack[next];
        next += 1;
        for &node in grid.cell_nodes(g) {
            for &f in adjacency.of(node) {
                if !failed[f] || crack.contains(&f) {
                    continue;
                }
                if (grid.cell_centroid(f) - xc).norm() <= reach {
                    crack.push(f);
                } else {
                    cut = true;
                }
            }
        }
    }
    // Its normal: the direction of least spread of the centroids.
    let centroids: Vec<Point<D>> = crack.iter().map(|&g| *grid.cell_centroid(g)).collect();
    let mean = centroids.iter().fold(Point::<D>::zeros(), |m, x| m + x) / crack.len() as f64;
    let mut spread = Tensor::<D>::zeros();
    for x in &centroids {
        let d = x - mean;
        spread += d * d.transpose();
    }
    let pr = principal(&spread);
    let n = Point::<D>::from_fn(|a, _| pr.directions[D - 1][a]);
    let d = xc - mean;
    let along = d - n * d.dot(&n);
    let rho = along.norm();
    if rho <= 1e-9 * h || rho.is_nan() {
        return TipReading::Beside;
    }
    let t = along / rho;
    // The tip: the mean of the nodes `c` shares with failed cells.
    let (mut tip, mut count) = (Point::<D>::zeros(), 0usize);
    for &node in grid.cell_nodes(c) {
        if adjacency.of(node).iter().any(|&g| failed[g]) {
            tip += grid.node(node);
            count += 1;
        }
    }
    tip /= count as f64;
    let s_tip = tip.dot(&t);
    let (s_back, s_front) = centroids
        .iter()
        .map(|x| x.dot(&t))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    // The distance read: `r`, or less behind a short crack (module docs, "Short cracks").
    let crack_length = (!cut).then_some(s_tip - s_back + 0.5 * h);
    let distance = match crack_length {
        Some(length) => {
            let shortened = r.min(h.max(0.25 * length));
            if shortened > 0.5 * length {
                return TipReading::Short;
            }
            shortened
        }
        None => r,
    };
    let s_star = s_tip - distance;
    if s_back > s_star - 0.5 * h {
        return TipReading::Short;
    }
    // Ahead: not behind the last failed centroid by more than half a cell.
    if xc.dot(&t) <= s_front - 0.5 * h {
        return TipReading::Beside;
    }
    // The band at s*: its mid-line and the nodes of its two faces.
    let window: Vec<usize> = crack
        .iter()
        .zip(&centroids)
        .filter(|(_, x)| (x.dot(&t) - s_star).abs() <= h)
        .map(|(&g, _)| g)
        .collect();
    if window.is_empty() {
        return TipReading::Short;
    }
    let eta = window
        .iter()
        .map(|&g| grid.cell_centroid(g).dot(&n))
        .sum::<f64>()
        / window.len() as f64;
    let mut faces: Vec<usize> = window
        .iter()
        .flat_map(|&g| grid.cell_nodes(g).iter().copied())
        .filter(|&i| {
            (grid.node(i).dot(&t) - s_star).abs() <= 1.5 * h
                && adjacency.of(i).iter().any(|&g| !failed[g])
        })
        .collect();
    faces.sort_unstable();
    faces.dedup();
    let (mut far, mut near) = (Vec::new(), Vec::new());
    for &i in &faces {
        let x = grid.node(i);
        let un = Point::<D>::from_fn(|a, _| u[D * i + a]).dot(&n);
        if x.dot(&n) > eta {
            far.push((x.dot(&t), un));
        } else {
            near.push((x.dot(&t), un));
        }
    }
    let tiny = 1e-6 * h;
    let (Some(plus), Some(minus)) = (
        line_value(&far, s_star, tiny),
        line_value(&near, s_star, tiny),
    ) else {
        return TipReading::Short;
    };
    TipReading::Ahead(DistanceSample {
        opening: plus - minus,
        distance,
        crack_length,
        along: t,
        normal: n,
        tip,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fitted_line_is_exact_on_a_line_and_the_mean_without_spread() {
        let pts = [(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)];
        assert!((line_value(&pts, 0.5, 1e-9).unwrap() - 2.0).abs() < 1e-14);
        let flat = [(1.0, 1.0), (1.0, 3.0)];
        assert_eq!(line_value(&flat, 7.0, 1e-9), Some(2.0));
        assert_eq!(line_value(&[], 0.0, 1e-9), None);
    }
}
