//! Crack tracking: a crack grows in its own plane, perpendicular to the largest principal
//! stress at the time it opened, along a continuous line one cell wide.
//!
//! With stress constant per cell, a cell at angle θ from the tip of a mode-I crack sees the
//! largest principal stress `σ₁ ∝ cos(θ/2)(1 + sin(θ/2))`, which peaks at θ ≈ ±60°, not
//! straight ahead (θ = 0, where the hoop stress peaks). A criterion on `σ₁` alone
//! therefore lets cracks branch, widen and follow the mesh diagonals (the grid-orientation
//! effect reported by Nilsen et al. (2017) §3). Crack-tracking schemes for smeared cracks
//! (Cervera & Chiumenti 2006; Oliver's local tracking) restrict where a crack may grow to the cells
//! its path crosses; this module uses the local form:
//!
//! * when a cell fails, its *crack normal* `n_f` is recorded: the direction of its largest
//!   principal stress at that moment, and its *crack point* `p_f`: its centroid if it
//!   nucleated the crack, else the projection of its centroid on the crack line of the
//!   failed neighbour it grew from ([`CrackTracking::record`]). The crack line of `f` is
//!   the line (plane in 3D) through `p_f` normal to `n_f`;
//! * a violating cell with no failed neighbour (sharing a node) and no recorded failed
//!   cell within the *exclusion radius* `r_x` of its centroid may fail anywhere: a new
//!   crack nucleates ([`CrackTracking::with_exclusion_radius`], default 0);
//! * a violating cell within `r_x` of a failed cell but next to none stays intact: the
//!   crack's tip field does not start parallel strands beside it (Cervera & Chiumenti's
//!   exclusion radius);
//! * a violating cell `c` next to failed cells (sharing a node) may fail only if, for some
//!   failed cell `f` across one of its faces, (i) its own crack plane (normal to its
//!   `σ₁` direction `n_c`) kinks by at most `max_angle` from that of `f`,
//!   `|n_c × n_f| ≤ sin(max_angle)`, and (ii)
//!   the crack line of `f` crosses `c`: `min_v x_v·n_f ≤ p_f·n_f ≤ max_v x_v·n_f` over
//!   its nodes `x_v`. Growth goes face to face, so the fracture's flow path (two-point
//!   fluxes across faces) stays connected: a cell touching the crack at a node only would
//!   open as a pocket the fluid cannot reach.
//!
//! An angle rule on the direction between centroids (`|d̂·n_f| ≤ sin(max_angle)`, the
//! earlier form of this module), checked cell to cell, lets every step drift sideways by
//! up to `tan(max_angle)` of a cell, and on triangles the face neighbours along a crack
//! lie up to 60° off its plane: on unstructured or staircase grids the crack widened into
//! a band and parallel strands grew from the corners of a failed cluster. Rule (ii)
//! carries the crack's line from cell to cell, so the path stays continuous and one cell
//! wide; it still turns when the stress rotates (by at most `max_angle` per cell, rule
//! (i)), since each new cell records its own normal on its crack point.
//!
//! Why the exclusion radius: `σ₁` beside a crack tip peaks at θ ≈ ±60°, and the region of
//! tension there is wider than the one ring of cells that rules (i) and (ii) block. With
//! nucleation free outside that ring, cells one ring farther out fail as new cracks and
//! grow into strands parallel to the first (on the well of Nilsen et al. (2017) §3, from the
//! corners of the failed cluster). An exclusion radius of a few cells keeps the growth at the tip.
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
    /// The node coordinates of every cell (offsets in `node_pos`).
    nodes: Vec<Point<D>>,
    node_pos: Vec<usize>,
    neighbours: Vec<Vec<usize>>,
    /// The cells across the faces of every cell.
    face_neighbours: Vec<Vec<usize>>,
    normals: Vec<Option<Point<D>>>,
    points: Vec<Option<Point<D>>>,
    /// Cells with a recorded crack, in the order recorded.
    recorded: Vec<usize>,
    exclusion_radius: f64,
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
        let face_neighbours = (0..grid.num_cells())
            .map(|c| {
                grid.cell_faces(c)
                    .iter()
                    .filter_map(|&f| match grid.face_cells(f) {
                        (a, Some(b)) => Some(if a == c { b } else { a }),
                        _ => None,
                    })
                    .collect()
            })
            .collect();
        let mut node_pos = vec![0];
        let mut nodes = Vec::new();
        for c in 0..grid.num_cells() {
            nodes.extend(grid.cell_nodes(c).iter().map(|&n| *grid.node(n)));
            node_pos.push(nodes.len());
        }
        Ok(Self {
            normals: vec![None; grid.num_cells()],
            points: vec![None; grid.num_cells()],
            recorded: Vec::new(),
            exclusion_radius: 0.0,
            nodes,
            node_pos,
            centroids: grid.cell_centroids().to_vec(),
            neighbours,
            face_neighbours,
            sin_max: max_angle_deg.to_radians().sin(),
            max_angle: max_angle_deg,
        })
    }

    /// The same tracking with the exclusion radius `r` (m, ≥ 0; see the module docs).
    pub fn with_exclusion_radius(mut self, r: f64) -> Result<Self, FracError> {
        if !(r.is_finite() && r >= 0.0) {
            return Err(FracError::Parameter {
                name: "crack exclusion radius",
                value: r,
                reason: "must be finite and ≥ 0",
            });
        }
        self.exclusion_radius = r;
        Ok(self)
    }

    /// The exclusion radius (m).
    pub fn exclusion_radius(&self) -> f64 {
        self.exclusion_radius
    }

    /// The angle limit in degrees.
    pub fn max_angle(&self) -> f64 {
        self.max_angle
    }

    /// Record that cell `c` fails under the stress `s`, with the failure flags `failed` of
    /// the cells failed before it: its crack normal is the direction of the largest
    /// principal stress of `s`, its crack point the projection of its centroid on the
    /// crack line of the closest admitting failed neighbour (its own centroid when none
    /// admits it: a new crack).
    pub fn record(&mut self, c: usize, s: &Tensor<D>, failed: &[bool]) {
        let own = largest_principal_direction(s);
        let x = self.centroids[c];
        let point = self
            .parents(c, own, failed)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(x, |(f, _)| {
                let (n, p) = self.line(f, own);
                x - n * (x - p).dot(&n)
            });
        if self.normals[c].is_none() {
            self.recorded.push(c);
        }
        self.normals[c] = Some(own);
        self.points[c] = Some(point);
    }

    /// The cells with a recorded crack, in the order recorded.
    pub fn recorded(&self) -> &[usize] {
        &self.recorded
    }

    /// Put back the cracks of an earlier run: the cells of [`Self::recorded`] with their
    /// normals and points ([`Self::normal`], [`Self::point`]), replacing those recorded.
    /// Errors name a cell out of range or recorded twice, or lengths that differ.
    pub fn restore(
        &mut self,
        cells: &[usize],
        normals: &[Point<D>],
        points: &[Point<D>],
    ) -> Result<(), String> {
        let n = self.normals.len();
        if normals.len() != cells.len() || points.len() != cells.len() {
            return Err(format!(
                "{} recorded cracks with {} normals and {} points",
                cells.len(),
                normals.len(),
                points.len()
            ));
        }
        let mut normal = vec![None; n];
        let mut point = vec![None; n];
        for ((&c, nc), pc) in cells.iter().zip(normals).zip(points) {
            match normal.get_mut(c) {
                None => return Err(format!("recorded cell {c} of {n}")),
                Some(Some(_)) => return Err(format!("cell {c} recorded twice")),
                Some(x) => *x = Some(*nc),
            }
            point[c] = Some(*pc);
        }
        self.normals = normal;
        self.points = point;
        self.recorded = cells.to_vec();
        Ok(())
    }

    /// The recorded crack normal of cell `c` (`None` while intact).
    pub fn normal(&self, c: usize) -> Option<Point<D>> {
        self.normals[c]
    }

    /// The recorded crack point of cell `c` (`None` while intact).
    pub fn point(&self, c: usize) -> Option<Point<D>> {
        self.points[c]
    }

    /// Whether cell `c` with stress `s` may fail given the failure flags (see the module
    /// docs). A failed neighbour without a recorded normal (failed before tracking
    /// started) lends the candidate's own largest principal direction and its centroid as
    /// the crack point.
    pub fn admits(&self, c: usize, s: &Tensor<D>, failed: &[bool]) -> bool {
        let next_to_crack = self.neighbours[c].iter().any(|&f| failed[f]);
        if next_to_crack {
            return self
                .parents(c, largest_principal_direction(s), failed)
                .next()
                .is_some();
        }
        let (x, r2) = (self.centroids[c], self.exclusion_radius.powi(2));
        !self
            .recorded
            .iter()
            .any(|&f| failed[f] && (self.centroids[f] - x).norm_squared() < r2)
    }

    /// The crack normal and point of failed cell `f` (`own` and its centroid when not
    /// recorded).
    fn line(&self, f: usize, own: Point<D>) -> (Point<D>, Point<D>) {
        (
            self.normals[f].unwrap_or(own),
            self.points[f].unwrap_or(self.centroids[f]),
        )
    }

    /// The failed neighbours of `c` whose crack may grow into `c` (rules (i) and (ii) of
    /// the module docs), with the distance of `c`'s centroid from their crack line.
    fn parents<'s>(
        &'s self,
        c: usize,
        own: Point<D>,
        failed: &'s [bool],
    ) -> impl Iterator<Item = (usize, f64)> + 's {
        let x = self.centroids[c];
        let cell = &self.nodes[self.node_pos[c]..self.node_pos[c + 1]];
        self.face_neighbours[c]
            .iter()
            .copied()
            .filter(move |&f| f != c && failed[f])
            .filter_map(move |f| {
                let (n, p) = self.line(f, own);
                // The kink: the angle between the two crack planes.
                let in_plane = (1.0 - own.dot(&n).powi(2)).max(0.0).sqrt() <= self.sin_max + 1e-12;
                let (lo, hi) = cell
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                        let t = v.dot(&n);
                        (a.min(t), b.max(t))
                    });
                // The line's offset `p·n` lies within the cell's extent along n.
                let at = p.dot(&n);
                let tol = 1e-12 * (hi - lo);
                let crosses = lo - tol <= at && at <= hi + tol;
                (in_plane && crosses).then_some((f, (x - p).dot(&n).abs()))
            })
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
    /// along y only, so neither row neighbour (its line x = 2.5 misses them) is
    /// admissible; with σ₁ along y both are (the line y = 0.5 crosses them). Cells away
    /// from the crack always are.
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
        // Cell 2 opened under σ₁ along y; a neighbour whose σ₁ is rotated by 45° kinks by
        // 45°: not admissible at 30°, admissible at 50°.
        let mut t = CrackTracking::new(&g, 30.0).unwrap();
        let mut wide = CrackTracking::new(&g, 50.0).unwrap();
        t.record(2, &sy, &[false; 5]);
        wide.record(2, &sy, &[false; 5]);
        let s45 = Tensor::<2>::new(0.0, 1.0, 1.0, 0.0);
        assert!(!t.admits(3, &s45, &failed));
        assert!(wide.admits(3, &s45, &failed));
        for bad in [0.0, -1.0, 91.0, f64::NAN] {
            assert!(CrackTracking::<2>::new(&g, bad).is_err());
        }
    }

    /// A crack that opened under σ₁ along x grows along y: the recorded line of the failed
    /// cell decides where, so it does not widen even when a neighbour's stress has
    /// rotated within the kink limit.
    #[test]
    fn recorded_normal_keeps_the_crack_in_its_plane() {
        let g = cartesian([0.0, 0.0].into(), [3.0, 3.0].into(), [3, 3]).unwrap();
        let mut t = CrackTracking::new(&g, 20.0).unwrap();
        let mut failed = vec![false; 9];
        let sx = Tensor::<2>::new(1.0, 0.0, 0.0, -1.0);
        // σ₁ rotated by 10° from x.
        let (c, s) = (10f64.to_radians().cos(), 10f64.to_radians().sin());
        let s10 = Tensor::<2>::new(c * c - s * s, 2.0 * c * s, 2.0 * c * s, s * s - c * c);
        t.record(4, &sx, &failed);
        failed[4] = true; // the centre cell opened with its normal along x
        assert!(t.normal(4).unwrap()[0].abs() > 0.999);
        // Above (cell 7) and below (cell 1): on the crack line; beside (cells 3, 5): off
        // it, never.
        for s in [&sx, &s10] {
            assert!(t.admits(7, s, &failed) && t.admits(1, s, &failed));
            assert!(!t.admits(3, s, &failed) && !t.admits(5, s, &failed));
        }
    }

    /// Cracks put back from another tracking's record admit exactly the same cells; bad
    /// records are refused.
    #[test]
    fn restored_cracks_admit_the_same_cells() {
        let g = cartesian([0.0, 0.0].into(), [3.0, 3.0].into(), [3, 3]).unwrap();
        let mut t = CrackTracking::new(&g, 20.0).unwrap();
        let mut failed = vec![false; 9];
        let sx = Tensor::<2>::new(1.0, 0.0, 0.0, -1.0);
        let sy = Tensor::<2>::new(-1.0, 0.0, 0.0, 1.0);
        t.record(4, &sx, &failed);
        failed[4] = true;
        t.record(7, &sx, &failed);
        failed[7] = true;
        let cells = t.recorded().to_vec();
        assert_eq!(cells, [4, 7]);
        let normals: Vec<_> = cells.iter().map(|&c| t.normal(c).unwrap()).collect();
        let points: Vec<_> = cells.iter().map(|&c| t.point(c).unwrap()).collect();
        let mut u = CrackTracking::new(&g, 20.0).unwrap();
        u.restore(&cells, &normals, &points).unwrap();
        for c in 0..9 {
            assert_eq!(u.normal(c), t.normal(c));
            assert_eq!(u.point(c), t.point(c));
            for s in [&sx, &sy] {
                assert_eq!(u.admits(c, s, &failed), t.admits(c, s, &failed), "cell {c}");
            }
        }
        assert!(
            u.restore(&[4, 4], &[normals[0]; 2], &[points[0]; 2])
                .is_err()
        );
        assert!(u.restore(&[9], &normals[..1], &points[..1]).is_err());
        assert!(u.restore(&[4], &normals, &points[..1]).is_err());
    }

    /// A crack along y in a 7×7 grid of unit squares (cells of column 3, rows 2..=4,
    /// opened under σ₁ along x): its continuation above and below is admissible; a cell two
    /// columns beside it nucleates without an exclusion radius and not with one of 2.5.
    #[test]
    fn line_and_exclusion_radius_keep_one_crack() {
        let g = cartesian([0.0, 0.0].into(), [7.0, 7.0].into(), [7, 7]).unwrap();
        let sx = Tensor::<2>::new(1.0, 0.0, 0.0, -1.0);
        let cell = |i: usize, j: usize| j * 7 + i;
        for (r, beside_ok) in [(0.0, true), (2.5, false)] {
            let mut t = CrackTracking::new(&g, 15.0)
                .unwrap()
                .with_exclusion_radius(r)
                .unwrap();
            let mut failed = vec![false; 49];
            for j in 2..=4 {
                t.record(cell(3, j), &sx, &failed);
                failed[cell(3, j)] = true;
            }
            // The crack point of a continued cell lies on the first cell's line x = 3.5.
            assert!((t.point(cell(3, 4)).unwrap()[0] - 3.5).abs() < 1e-12);
            assert!(t.admits(cell(3, 5), &sx, &failed) && t.admits(cell(3, 1), &sx, &failed));
            assert!(!t.admits(cell(4, 3), &sx, &failed), "beside, touching");
            assert_eq!(t.admits(cell(5, 3), &sx, &failed), beside_ok, "r = {r}");
            assert!(t.admits(cell(6, 6), &sx, &failed) || r > 0.0);
        }
        let t = CrackTracking::new(&g, 15.0).unwrap();
        assert!(t.clone().with_exclusion_radius(-1.0).is_err());
        assert!(t.with_exclusion_radius(f64::NAN).is_err());
    }

    /// A crack opened under σ₁ along x continues straight up, not diagonally: the cell up
    /// and right touches it at a node only and lies off its line, even with a 60° kink
    /// limit.
    #[test]
    fn crack_line_refuses_sideways_drift() {
        let g = cartesian([0.0, 0.0].into(), [5.0, 5.0].into(), [5, 5]).unwrap();
        let mut t = CrackTracking::new(&g, 60.0).unwrap();
        let sx = Tensor::<2>::new(1.0, 0.0, 0.0, -1.0);
        let mut failed = vec![false; 25];
        t.record(12, &sx, &failed);
        failed[12] = true;
        // The cell up and right: within 60° of the crack plane (45°) but off its line.
        assert!(!t.admits(18, &sx, &failed));
        assert!(t.admits(17, &sx, &failed));
    }

    #[test]
    fn principal_direction_is_the_largest_eigenvector() {
        let s = Tensor::<2>::new(1.0, 2.0, 2.0, 1.0); // eigenvalues 3 (along (1,1)), −1
        let n = largest_principal_direction(&s);
        assert!((n[0].abs() - 0.5f64.sqrt()).abs() < 1e-14 && (n[0] - n[1]).abs() < 1e-14);
    }
}
