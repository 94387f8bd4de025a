//! Crack tracking: a crack grows in its own plane, perpendicular to the largest principal
//! stress at the time it opened.
//!
//! With stress constant per cell, a cell at angle θ from the tip of a mode-I crack sees the
//! largest principal stress `σ₁ ∝ cos(θ/2)(1 + sin(θ/2))`, which peaks at θ ≈ ±60°, not
//! straight ahead (θ = 0, where the hoop stress peaks). A criterion on `σ₁` alone
//! therefore lets cracks branch, widen and follow the mesh diagonals (the grid-orientation
//! effect of the seed, §3). Crack-tracking schemes for smeared cracks (Cervera &
//! Chiumenti 2006) restrict where a crack may grow; this module uses the local form:
//!
//! * when a cell fails, its *crack normal* `n_f` is recorded: the direction of its largest
//!   principal stress at that moment ([`CrackTracking::record`]);
//! * a violating cell with no failed neighbour (sharing a node) may fail anywhere: a new
//!   crack nucleates;
//! * a violating cell `c` next to failed cells may fail only if, for some failed neighbour
//!   `f`, the direction `d̂ = (x_c − x_f)/|x_c − x_f|` between their centroids lies within
//!   `max_angle` of the crack plane of `f`, i.e. `|d̂ · n_f| ≤ sin(max_angle)`: the crack
//!   continues in its plane instead of widening. A crack still turns when the stress
//!   rotates, since each new cell records its own normal.
//!
//! Violating cells that are not admissible stay intact in this round (the criterion is
//! checked again after every re-solve).

use porofrac_grid::{Grid, Point};
use porofrac_law::Tensor;

use crate::FracError;
use crate::recovery::NodeCells;

/// The crack-tracking rule of this module, built once per grid.
#[derive(Clone, Debug)]
pub struct CrackTracking<const D: usize> {
    centroids: Vec<Point<D>>,
    neighbours: Vec<Vec<usize>>,
    normals: Vec<Option<Point<D>>>,
    sin_max: f64,
    max_angle: f64,
}

impl<const D: usize> CrackTracking<D> {
    /// Tracking on `grid` with the largest deviation `max_angle_deg` (degrees, in (0, 90])
    /// between a new crack segment and the plane normal to `σ₁`.
    pub fn new(grid: &Grid<D>, max_angle_deg: f64) -> Result<Self, FracError> {
        if !(max_angle_deg.is_finite() && max_angle_deg > 0.0 && max_angle_deg <= 90.0) {
            return Err(FracError::Parameter {
                name: "crack tracking angle",
                value: max_angle_deg,
                reason: "must be in (0, 90] degrees",
            });
        }
        let adj = NodeCells::new(grid);
        let neighbours = (0..grid.num_cells())
            .map(|c| {
                let mut v: Vec<usize> = grid
                    .cell_nodes(c)
                    .iter()
                    .flat_map(|&n| adj.of(n).iter().copied())
                    .filter(|&o| o != c)
                    .collect();
                v.sort_unstable();
                v.dedup();
                v
            })
            .collect();
        Ok(Self {
            normals: vec![None; grid.num_cells()],
            centroids: grid.cell_centroids().to_vec(),
            neighbours,
            sin_max: max_angle_deg.to_radians().sin(),
            max_angle: max_angle_deg,
        })
    }

    /// The angle limit in degrees.
    pub fn max_angle(&self) -> f64 {
        self.max_angle
    }

    /// Record that cell `c` failed under the stress `s`: its crack normal is the direction
    /// of the largest principal stress of `s`.
    pub fn record(&mut self, c: usize, s: &Tensor<D>) {
        self.normals[c] = Some(largest_principal_direction(s));
    }

    /// The recorded crack normal of cell `c` (`None` while intact).
    pub fn normal(&self, c: usize) -> Option<Point<D>> {
        self.normals[c]
    }

    /// Whether cell `c` with stress `s` may fail given the failure flags (see the module
    /// docs). A failed neighbour without a recorded normal (failed before tracking
    /// started) lends the candidate's own largest principal direction.
    pub fn admits(&self, c: usize, s: &Tensor<D>, failed: &[bool]) -> bool {
        let mut near_crack = false;
        let own = largest_principal_direction(s);
        for &f in &self.neighbours[c] {
            if !failed[f] {
                continue;
            }
            near_crack = true;
            let n = self.normals[f].unwrap_or(own);
            let d = self.centroids[c] - self.centroids[f];
            let len = d.norm();
            if len > 0.0 && (d.dot(&n) / len).abs() <= self.sin_max + 1e-12 {
                return true;
            }
        }
        !near_crack
    }
}

/// Unit eigenvector of the largest eigenvalue of a symmetric tensor
/// ([`porofrac_law::principal()`]).
pub fn largest_principal_direction<const D: usize>(s: &Tensor<D>) -> Point<D> {
    porofrac_law::principal(s).directions[0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use porofrac_grid::generate::cartesian;

    /// A 5×1 row of unit squares, the middle one failed: with σ₁ along x the crack may grow
    /// along y only, so neither row neighbour (d̂ = ±x) is admissible; with σ₁ along y both
    /// are (d̂ ⊥ n₁). Cells away from the crack always are.
    #[test]
    fn growth_follows_the_plane_normal_to_the_largest_principal_stress() {
        let g = cartesian([0.0, 0.0].into(), [5.0, 1.0].into(), [5, 1]).unwrap();
        let t = CrackTracking::new(&g, 30.0).unwrap();
        let mut failed = vec![false; 5];
        failed[2] = true;
        let sx = Tensor::<2>::new(1.0, 0.0, 0.0, -1.0);
        let sy = Tensor::<2>::new(-1.0, 0.0, 0.0, 1.0);
        assert!(!t.admits(1, &sx, &failed) && !t.admits(3, &sx, &failed));
        assert!(t.admits(1, &sy, &failed) && t.admits(3, &sy, &failed));
        assert!(t.admits(0, &sx, &failed) && t.admits(4, &sx, &failed));
        // A stress rotated by 45°: |d̂·n₁| = sin 45° > sin 30° → not admissible at 30°,
        // admissible at 50°.
        let s45 = Tensor::<2>::new(0.0, 1.0, 1.0, 0.0);
        assert!(!t.admits(3, &s45, &failed));
        let wide = CrackTracking::new(&g, 50.0).unwrap();
        assert!(wide.admits(3, &s45, &failed));
        for bad in [0.0, -1.0, 91.0, f64::NAN] {
            assert!(CrackTracking::<2>::new(&g, bad).is_err());
        }
    }

    /// A crack that opened under σ₁ along x grows along y even when its neighbours' stress
    /// has rotated: the recorded normal of the failed cell decides, so it does not widen.
    #[test]
    fn recorded_normal_keeps_the_crack_in_its_plane() {
        let g = cartesian([0.0, 0.0].into(), [3.0, 3.0].into(), [3, 3]).unwrap();
        let mut t = CrackTracking::new(&g, 20.0).unwrap();
        let mut failed = vec![false; 9];
        let sx = Tensor::<2>::new(1.0, 0.0, 0.0, -1.0);
        let sy = Tensor::<2>::new(-1.0, 0.0, 0.0, 1.0);
        failed[4] = true; // the centre cell opened with its normal along x
        t.record(4, &sx);
        assert!(t.normal(4).unwrap()[0].abs() > 0.999);
        // Above (cell 7) and below (cell 1): in the crack plane, admissible whatever
        // their own stress; beside (cells 3, 5): across the plane, never.
        for s in [&sx, &sy] {
            assert!(t.admits(7, s, &failed) && t.admits(1, s, &failed));
            assert!(!t.admits(3, s, &failed) && !t.admits(5, s, &failed));
        }
    }

    #[test]
    fn principal_direction_is_the_largest_eigenvector() {
        let s = Tensor::<2>::new(1.0, 2.0, 2.0, 1.0); // eigenvalues 3 (along (1,1)), −1
        let n = largest_principal_direction(&s);
        assert!((n[0].abs() - 0.5f64.sqrt()).abs() < 1e-14 && (n[0] - n[1]).abs() < 1e-14);
    }
}
