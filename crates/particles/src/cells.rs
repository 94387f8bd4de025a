//! Neighbour search by cell lists.
//!
//! The bounding box of the centres is cut into square cells of side
//! `s ≥ 2 r_max + alert`, so two disks whose gap `|x_i − x_j| − r_i − r_j` is below the
//! alert distance sit in the same or in adjacent cells. The cells are flat arrays built
//! by a counting sort (`start[c]..start[c + 1]` indexes `items`), so a rebuild allocates
//! nothing once the arrays have grown. Each cell is compared with itself and with four
//! of its eight neighbours (east, north-west, north, north-east), which visits every
//! adjacent pair once. The pairs are returned sorted by `(i, j)` with `i < j`, so the
//! result does not depend on the cell layout.
//!
//! If the disks are spread far apart (a disk thrown away), the cell side grows so that
//! there are at most `4 n + 16` cells: the search stays linear in memory. The cell
//! counts are computed in floating point before anything is allocated, so centres as
//! far apart as `±f64::MAX` still give a bounded grid; a centre that is not finite is
//! put in the first cell and pairs with nothing. [`CellList::pairs_at_most`] stops once
//! a given number of pairs is found, for callers that must bound their memory (a huge
//! alert distance makes the pairs grow as `n²`).

/// A cell list over disk centres.
#[derive(Clone, Debug, Default)]
pub struct CellList {
    lo: [f64; 2],
    side: f64,
    nx: usize,
    ny: usize,
    start: Vec<usize>,
    items: Vec<u32>,
    cell_of: Vec<u32>,
}

impl CellList {
    /// An empty cell list.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sort the centres `x` into cells of side at least `min_side` (use
    /// `2 r_max + alert`).
    pub fn build(&mut self, x: &[[f64; 2]], min_side: f64) {
        let n = x.len();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in x {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        if n == 0 || !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
            // No disk, or no finite centre.
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        // Extents that overflow (centres near ±f64::MAX) count as the largest float.
        let extent = [0, 1].map(|a| {
            let e = hi[a] - lo[a];
            if e.is_finite() { e } else { f64::MAX }
        });
        let mut side = if min_side > 0.0 && min_side.is_finite() {
            min_side
        } else {
            1.0
        };
        // Cells per axis as floats: `as usize` would saturate and wrap for far centres.
        let cells = |side: f64| {
            let nx = (extent[0] / side).floor() + 1.0;
            let ny = (extent[1] / side).floor() + 1.0;
            (nx, ny)
        };
        let max_cells = (4 * n + 16) as f64;
        let (mut fx, mut fy) = cells(side);
        while fx * fy > max_cells {
            side *= 2.0;
            (fx, fy) = cells(side);
        }
        let (nx, ny) = (fx as usize, fy as usize);
        self.lo = lo;
        self.side = side;
        self.nx = nx;
        self.ny = ny;
        self.start.clear();
        self.start.resize(nx * ny + 1, 0);
        self.cell_of.clear();
        for p in x {
            let c = self.cell_index(p);
            self.cell_of.push(c as u32);
            self.start[c + 1] += 1;
        }
        for c in 0..nx * ny {
            self.start[c + 1] += self.start[c];
        }
        self.items.clear();
        self.items.resize(n, 0);
        // Fill in increasing index order: `fill` counts the entries placed per cell.
        let mut fill = std::mem::take(&mut self.cell_of);
        let mut next: Vec<usize> = self.start[..nx * ny].to_vec();
        for (i, c) in fill.iter().enumerate() {
            let c = *c as usize;
            self.items[next[c]] = i as u32;
            next[c] += 1;
        }
        fill.clear();
        self.cell_of = fill;
    }

    /// The cell of a centre; centres outside the box (or not finite) are clamped into
    /// it (`as usize` maps NaN and negative values to 0 and saturates large ones).
    fn cell_index(&self, p: &[f64; 2]) -> usize {
        let cx = (((p[0] - self.lo[0]) / self.side) as usize).min(self.nx - 1);
        let cy = (((p[1] - self.lo[1]) / self.side) as usize).min(self.ny - 1);
        cy * self.nx + cx
    }

    /// Side of the cells (m).
    pub fn side(&self) -> f64 {
        self.side
    }

    /// Every pair `(i, j)`, `i < j`, whose gap `|x_i − x_j| − r_i − r_j` is below `alert`,
    /// sorted, into `out` (cleared first). The list must have been built from the same
    /// `x` with a side of at least `2 r_max + alert`.
    pub fn pairs(&self, x: &[[f64; 2]], r: &[f64], alert: f64, out: &mut Vec<(u32, u32)>) {
        // Without a bound the search always completes.
        let _ = self.pairs_at_most(x, r, alert, usize::MAX, out);
    }

    /// [`CellList::pairs`], stopping as soon as more than `max` pairs are found:
    /// `Err(found)` then (with `found > max`, `out` holding the pairs found so far),
    /// so the memory of the search stays below `max + 1` pairs.
    pub fn pairs_at_most(
        &self,
        x: &[[f64; 2]],
        r: &[f64],
        alert: f64,
        max: usize,
        out: &mut Vec<(u32, u32)>,
    ) -> Result<(), usize> {
        out.clear();
        let (nx, ny) = (self.nx, self.ny);
        let mut push = |i: u32, j: u32| {
            let (a, b) = (i as usize, j as usize);
            let d = ((x[a][0] - x[b][0]).powi(2) + (x[a][1] - x[b][1]).powi(2)).sqrt();
            if d - r[a] - r[b] < alert {
                out.push(if i < j { (i, j) } else { (j, i) });
            }
            out.len() > max
        };
        for cy in 0..ny {
            for cx in 0..nx {
                let c = cy * nx + cx;
                let own = &self.items[self.start[c]..self.start[c + 1]];
                for (k, &i) in own.iter().enumerate() {
                    for &j in &own[k + 1..] {
                        if push(i, j) {
                            return Err(out.len());
                        }
                    }
                }
                let neighbours = [(1i64, 0i64), (-1, 1), (0, 1), (1, 1)];
                for (dx, dy) in neighbours {
                    let (ox, oy) = (cx as i64 + dx, cy as i64 + dy);
                    if ox < 0 || oy < 0 || ox >= nx as i64 || oy >= ny as i64 {
                        continue;
                    }
                    let o = oy as usize * nx + ox as usize;
                    let other = &self.items[self.start[o]..self.start[o + 1]];
                    for &i in own {
                        for &j in other {
                            if push(i, j) {
                                return Err(out.len());
                            }
                        }
                    }
                }
            }
        }
        out.sort_unstable();
        Ok(())
    }
}

/// The pairs of [`CellList::pairs`] by comparing every pair (O(n²)), for tests.
pub fn brute_force_pairs(x: &[[f64; 2]], r: &[f64], alert: f64) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            let d = ((x[i][0] - x[j][0]).powi(2) + (x[i][1] - x[j][1]).powi(2)).sqrt();
            if d - r[i] - r[j] < alert {
                out.push((i as u32, j as u32));
            }
        }
    }
    out
}

/// Largest radius of a set (0 if empty).
pub fn max_radius(r: &[f64]) -> f64 {
    r.iter().fold(0.0, |a, &b| a.max(b))
}
