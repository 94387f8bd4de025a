//! A composite 2D grid: a Cartesian far field with a refined triangle zone around a point,
//! joined by hanging nodes.
//!
//! ```text
//!   +-----+-----+-----+-----+      coarse cells of the far field: squares
//!   |     |     |     |     |
//!   +-----+--*--+--*--+-----+      * hanging nodes: the fine interface nodes are
//!   |     |/ | /|/ | /|     |        extra (collinear) vertices of the coarse polygons
//!   |     *--+--*--+--*     |
//!   |     |/ | /|/ | /|     |      the zone: whole coarse cells whose centroid lies in
//!   +-----+--*--+--*--+-----+      the square |x − c|∞ ≤ zone_half_width, each split
//!   |     |     |     |     |      into refine × refine squares of 2 triangles
//!   +-----+-----+-----+-----+
//! ```
//!
//! Cells are numbered coarse first (x fastest, zone cells skipped), then the fine
//! triangles (fine square by fine square, x fastest). A coarse cell sharing `s` edges
//! with the zone has `4 + s (refine − 1)` nodes. Tags: the fine cells get `refined`; the
//! cells whose centroid lies within `well_radius` of `center` get `well_tag`.
//!
//! Optionally the fine nodes strictly inside the zone are jittered by up to
//! `perturb × min(fine spacing)` (`perturb ≤` [`MAX_PERTURB`](crate::generate::MAX_PERTURB), seeded `ChaCha8Rng`); the
//! zone boundary and the far field stay exact.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::error::{GridError, Result};
use crate::generate::perturb::{check_amplitude, unit_ball};
use crate::grid::Grid;
use crate::point::Point;

/// Name of the cell tag of the refined zone.
pub const REFINED_TAG: &str = "refined";

/// How each fine square of the zone is split into two triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Diagonals {
    /// Every square split by its diagonal from the lower-left to the upper-right corner.
    Structured,
    /// Alternating (checkerboard): the other diagonal where `I + J` is odd.
    Alternating,
}

/// Parameters of [`composite`] (scene-file keys in brackets).
#[derive(Clone, Debug, PartialEq)]
pub struct CompositeSpec {
    /// Lower-left corner of the box (`extent[0]`), m.
    pub lo: Point<2>,
    /// Upper-right corner of the box (`extent[1]`), m.
    pub hi: Point<2>,
    /// Far-field cells per axis (`cells`).
    pub cells: [usize; 2],
    /// Centre of the refined zone and of the well (`center`), m.
    pub center: Point<2>,
    /// Half-width of the square zone, snapped to whole coarse cells (`zone_half_width`), m.
    pub zone_half_width: f64,
    /// Fine squares per coarse cell edge (`refine`, ≥ 1).
    pub refine: usize,
    /// Radius of the well tag around `center` (`well_radius`), m; `0 <` r and the disc
    /// must lie inside the snapped zone.
    pub well_radius: f64,
    /// Name of the well cell tag (default `well`).
    pub well_tag: String,
    /// Triangle split of the fine squares (default [`Diagonals::Structured`]).
    pub diagonals: Diagonals,
    /// Jitter of the fine interior nodes as a fraction of the fine spacing (`perturb`,
    /// default 0, at most [`MAX_PERTURB`](crate::generate::MAX_PERTURB)).
    pub perturb: f64,
    /// Seed of the jitter (`seed`, default 0).
    pub seed: u64,
}

impl CompositeSpec {
    /// A spec with the required parameters; `well_tag = "well"`, structured diagonals,
    /// no jitter, seed 0.
    pub fn new(
        lo: Point<2>,
        hi: Point<2>,
        cells: [usize; 2],
        center: Point<2>,
        zone_half_width: f64,
        refine: usize,
        well_radius: f64,
    ) -> Self {
        Self {
            lo,
            hi,
            cells,
            center,
            zone_half_width,
            refine,
            well_radius,
            well_tag: "well".into(),
            diagonals: Diagonals::Structured,
            perturb: 0.0,
            seed: 0,
        }
    }

    /// The zone as inclusive coarse cell ranges `[i0, i1] × [j0, j1]`, after checking the
    /// spec.
    pub fn zone_cells(&self) -> Result<([usize; 2], [usize; 2])> {
        let bad = |what: String| Err(GridError::Input(format!("composite grid: {what}")));
        for a in 0..2 {
            if self.cells[a] == 0 {
                return bad(format!("cells must be ≥ 1 per axis, got {:?}", self.cells));
            }
            if !(self.lo[a].is_finite() && self.hi[a].is_finite() && self.hi[a] > self.lo[a]) {
                return bad(format!(
                    "extent must have min < max on every axis, got axis {a}: [{}, {}]",
                    self.lo[a], self.hi[a]
                ));
            }
        }
        if self.refine == 0 {
            return bad("refine must be ≥ 1".into());
        }
        let w = self.zone_half_width;
        if !(w.is_finite() && w > 0.0) {
            return bad(format!("zone_half_width must be > 0, got {w}"));
        }
        if !(self.center.iter().all(|x| x.is_finite())) {
            return bad(format!("center {:?} is not finite", self.center.as_slice()));
        }
        for a in 0..2 {
            if self.center[a] - w < self.lo[a] || self.center[a] + w > self.hi[a] {
                return bad(format!(
                    "the zone [{}, {}] on axis {a} is not inside the extent [{}, {}]",
                    self.center[a] - w,
                    self.center[a] + w,
                    self.lo[a],
                    self.hi[a]
                ));
            }
        }
        let mut range = [[0usize; 2]; 2];
        for a in 0..2 {
            let h = (self.hi[a] - self.lo[a]) / self.cells[a] as f64;
            // Cells whose centroid x_i = lo + (i + ½) h lies in [c − w, c + w].
            let first = ((self.center[a] - w - self.lo[a]) / h - 0.5)
                .ceil()
                .max(0.0) as usize;
            let last = ((self.center[a] + w - self.lo[a]) / h - 0.5).floor();
            if last < first as f64 {
                return bad(format!(
                    "the zone (half-width {w}) contains no coarse cell centroid on axis {a} \
                     (coarse spacing {h})"
                ));
            }
            range[a] = [first, (last as usize).min(self.cells[a] - 1)];
        }
        let r = self.well_radius;
        if !(r.is_finite() && r > 0.0) {
            return bad(format!("well_radius must be > 0, got {r}"));
        }
        for a in 0..2 {
            let h = (self.hi[a] - self.lo[a]) / self.cells[a] as f64;
            let z0 = self.lo[a] + h * range[a][0] as f64;
            let z1 = self.lo[a] + h * (range[a][1] + 1) as f64;
            if self.center[a] - r < z0 || self.center[a] + r > z1 {
                return bad(format!(
                    "the well (radius {r}) is bigger than the refined zone [{z0}, {z1}] on \
                     axis {a}"
                ));
            }
        }
        check_amplitude(self.perturb)?;
        Ok((range[0], range[1]))
    }
}

/// Build the composite grid of `spec` (see the module docs).
///
/// Errors: a bad spec (non-positive sizes, zone not inside the box or holding no coarse
/// cell, `refine = 0`, `well_radius ≤ 0` or reaching outside the zone, jitter out of
/// range) or a well radius that selects no cell.
pub fn composite(spec: &CompositeSpec) -> Result<Grid<2>> {
    let ([i0, i1], [j0, j1]) = spec.zone_cells()?;
    let [nx, ny] = spec.cells;
    let r = spec.refine;
    let (lo, hi) = (spec.lo, spec.hi);
    let h = [(hi[0] - lo[0]) / nx as f64, (hi[1] - lo[1]) / ny as f64];
    let coarse_x = |i: usize, a: usize, n: usize| {
        if i == n {
            hi[a]
        } else {
            lo[a] + h[a] * i as f64
        }
    };
    let in_zone = |i: usize, j: usize| (i0..=i1).contains(&i) && (j0..=j1).contains(&j);
    // Coarse lattice nodes strictly inside the zone are dropped.
    let strictly_inside = |i: usize, j: usize| i > i0 && i <= i1 && j > j0 && j <= j1;

    let mut nodes: Vec<Point<2>> = Vec::new();
    let mut coarse_id = vec![usize::MAX; (nx + 1) * (ny + 1)];
    for j in 0..=ny {
        for i in 0..=nx {
            if !strictly_inside(i, j) {
                coarse_id[j * (nx + 1) + i] = nodes.len();
                nodes.push(Point::<2>::new(coarse_x(i, 0, nx), coarse_x(j, 1, ny)));
            }
        }
    }
    // Fine lattice of the zone.
    let (fx, fy) = ((i1 - i0 + 1) * r, (j1 - j0 + 1) * r);
    let z0 = Point::<2>::new(coarse_x(i0, 0, nx), coarse_x(j0, 1, ny));
    let z1 = Point::<2>::new(coarse_x(i1 + 1, 0, nx), coarse_x(j1 + 1, 1, ny));
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let hf = ((z1[0] - z0[0]) / fx as f64).min((z1[1] - z0[1]) / fy as f64);
    let mut fine_id = vec![usize::MAX; (fx + 1) * (fy + 1)];
    for jj in 0..=fy {
        for ii in 0..=fx {
            let on_boundary = ii == 0 || jj == 0 || ii == fx || jj == fy;
            if on_boundary && ii % r == 0 && jj % r == 0 {
                fine_id[jj * (fx + 1) + ii] = coarse_id[(j0 + jj / r) * (nx + 1) + i0 + ii / r];
                continue;
            }
            let mut p = Point::<2>::new(
                z0[0] + (z1[0] - z0[0]) * ii as f64 / fx as f64,
                z0[1] + (z1[1] - z0[1]) * jj as f64 / fy as f64,
            );
            if on_boundary {
                // Exact zone boundary coordinate.
                if ii == 0 || ii == fx {
                    p[0] = if ii == 0 { z0[0] } else { z1[0] };
                }
                if jj == 0 || jj == fy {
                    p[1] = if jj == 0 { z0[1] } else { z1[1] };
                }
            } else if spec.perturb > 0.0 {
                p += unit_ball::<2>(&mut rng) * (spec.perturb * hf);
            }
            fine_id[jj * (fx + 1) + ii] = nodes.len();
            nodes.push(p);
        }
    }
    let fine = |ii: usize, jj: usize| fine_id[jj * (fx + 1) + ii];
    let (mut pos, mut cell_nodes) = far_field_cells(
        [nx, ny],
        [i0, j0],
        r,
        in_zone,
        |i, j| coarse_id[j * (nx + 1) + i],
        fine,
    );
    let num_coarse = pos.len() - 1;
    for jj in 0..fy {
        for ii in 0..fx {
            let (v00, v10, v11, v01) = (
                fine(ii, jj),
                fine(ii + 1, jj),
                fine(ii + 1, jj + 1),
                fine(ii, jj + 1),
            );
            let flip = spec.diagonals == Diagonals::Alternating && (ii + jj) % 2 == 1;
            let tris = if flip {
                [[v00, v10, v01], [v10, v11, v01]]
            } else {
                [[v00, v10, v11], [v00, v11, v01]]
            };
            for t in tris {
                cell_nodes.extend_from_slice(&t);
                pos.push(cell_nodes.len());
            }
        }
    }
    let mut grid = Grid::from_polygons(nodes, &pos, &cell_nodes)?;
    let num_cells = grid.num_cells();
    grid.set_cell_tag(REFINED_TAG, (num_coarse..num_cells).collect())?;
    let well: Vec<usize> = (0..num_cells)
        .filter(|&c| (grid.cell_centroid(c) - spec.center).norm() <= spec.well_radius)
        .collect();
    if well.is_empty() {
        return Err(GridError::Input(format!(
            "composite grid: no cell centroid within well_radius {} of the center {:?} \
             (fine spacing {hf})",
            spec.well_radius,
            spec.center.as_slice()
        )));
    }
    grid.set_cell_tag(spec.well_tag.clone(), well)?;
    Ok(grid)
}

/// The coarse far-field quadrilaterals of a composite-style grid: every cell of the
/// `nx × ny` lattice outside the zone (`in_zone`), counter-clockwise from its lower-left
/// corner, with the `r − 1` hanging nodes of each edge shared with the zone inserted.
/// `coarse(i, j)` is the node of coarse lattice point `(i, j)`, `fine(ii, jj)` the node of
/// zone lattice point `(ii, jj)` counted from the zone corner `(i0, j0)`. Returns the
/// offsets and the node list of the cells.
pub(crate) fn far_field_cells(
    [nx, ny]: [usize; 2],
    [i0, j0]: [usize; 2],
    r: usize,
    in_zone: impl Fn(usize, usize) -> bool,
    coarse: impl Fn(usize, usize) -> usize,
    fine: impl Fn(usize, usize) -> usize,
) -> (Vec<usize>, Vec<usize>) {
    // Zone lattice index of a coarse lattice point on the zone boundary.
    let to_fine = |i: usize, j: usize| ((i - i0) * r, (j - j0) * r);
    let mut pos = vec![0usize];
    let mut cell_nodes: Vec<usize> = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            if in_zone(i, j) {
                continue;
            }
            let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            // Cell across each edge (bottom, right, top, left).
            let across = [
                (j > 0).then(|| (i, j - 1)),
                Some((i + 1, j)),
                Some((i, j + 1)),
                (i > 0).then(|| (i - 1, j)),
            ];
            for e in 0..4 {
                let (a, b) = (corners[e], corners[(e + 1) % 4]);
                cell_nodes.push(coarse(a.0, a.1));
                if across[e].is_some_and(|(x, y)| x < nx && y < ny && in_zone(x, y)) {
                    let (fa, fb) = (to_fine(a.0, a.1), to_fine(b.0, b.1));
                    for k in 1..r {
                        let ii = (fa.0 * (r - k) + fb.0 * k) / r;
                        let jj = (fa.1 * (r - k) + fb.1 * k) / r;
                        cell_nodes.push(fine(ii, jj));
                    }
                }
            }
            pos.push(cell_nodes.len());
        }
    }
    (pos, cell_nodes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zone_snaps_to_whole_cells() {
        // 10 × 10 unit cells, zone half-width 1.2 around (5, 5): centroids 4.5 and 5.5 are
        // within [3.8, 6.2] → cells 4..=5 on each axis.
        let s = CompositeSpec::new(
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(10.0, 10.0),
            [10, 10],
            Point::<2>::new(5.0, 5.0),
            1.2,
            3,
            0.5,
        );
        assert_eq!(s.zone_cells().unwrap(), ([4, 5], [4, 5]));
    }
}
