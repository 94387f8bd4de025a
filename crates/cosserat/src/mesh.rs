//! Simplex meshes the Cosserat experiments use that the grid crate does not generate.
//!
//! * [`crossed`]: each square of an `nx × ny` lattice cut into 4 triangles by its centre
//!   (the "crossed" meshes of the patch tests and the shear layer of Marazzato (2021),
//!   arXiv:2101.08712, §3.8 and §3.9.2).
//! * [`crossed_perturbed`]: the same mesh with its interior nodes jittered by a bounded,
//!   seeded amount that keeps every triangle valid (the bound is derived there).
//! * [`plate_with_hole`]: the quarter plate `[0, L]²` minus the disc of radius `r` at the
//!   origin (E2), an O-grid graded towards the hole, each quad cut by its shorter diagonal.
//! * [`locate`]: the simplex containing a point.

use porofrac_grid::{CellFaceLoops, Grid, GridError, Point};

use crate::error::Result;

/// A crossed triangle mesh of `[lo, hi]` with `n[0] × n[1]` squares, 4 triangles each.
///
/// Errors: a zero count or an empty box (from the grid builder, or named here).
pub fn crossed(lo: Point<2>, hi: Point<2>, n: [usize; 2]) -> Result<Grid<2>> {
    crossed_with(lo, hi, n, |_, _| {})
}

/// Largest jitter amplitude of [`crossed_perturbed`] (the documented maximum of the
/// scene key `perturb`, the same as the grid crate's).
pub const MAX_PERTURB: f64 = porofrac_grid::generate::MAX_PERTURB;

/// A crossed mesh ([`crossed`]) whose interior nodes (corners not on the box boundary,
/// and every square centre) move by `amplitude · m · ξ`, with `ξ` uniform in the unit disc
/// (a SplitMix64 stream seeded with `seed`, node by node in node order) and
/// `m = min(dx/2, dy/2, dx·dy/√(dx²+dy²))` the smallest altitude of the mesh's triangles.
///
/// Why every triangle stays valid for `amplitude < 1/2`: a triangle degenerates only when
/// a vertex reaches the line of the opposite side. Each point of that side is a convex
/// combination of its two ends, so it moves by at most `amplitude · m`, and the vertex by
/// at most `amplitude · m` too: the distance, initially the altitude `h ≥ m`, stays at
/// least `h − 2 · amplitude · m ≥ (1 − 2 · amplitude) h > 0` along the whole straight
/// motion, so the orientation never flips. At the maximum 0.3 every altitude keeps at
/// least 40 % of its length, whatever the aspect ratio of the squares (the grid crate's
/// bound, a fraction of the shortest incident edge, is not enough for crossed triangles
/// of elongated squares, whose apex lies only `dy/2` from the base).
///
/// Errors: those of [`crossed`], and `amplitude` outside `[0, MAX_PERTURB]`.
pub fn crossed_perturbed(
    lo: Point<2>,
    hi: Point<2>,
    n: [usize; 2],
    amplitude: f64,
    seed: u64,
) -> Result<Grid<2>> {
    if !(0.0..=MAX_PERTURB).contains(&amplitude) {
        return Err(GridError::Input(format!(
            "perturbation amplitude must be in [0, {MAX_PERTURB}] (fraction of the smallest \
             altitude of the triangles), got {amplitude}"
        ))
        .into());
    }
    if n[0] == 0 || n[1] == 0 {
        return crossed(lo, hi, n);
    }
    let dx = (hi[0] - lo[0]) / n[0] as f64;
    let dy = (hi[1] - lo[1]) / n[1] as f64;
    let m = (0.5 * dx).min(0.5 * dy).min(dx * dy / dx.hypot(dy));
    let mut rng = SplitMix64(seed);
    crossed_with(lo, hi, n, |p, interior| {
        if interior {
            let xi = rng.unit_disc();
            *p += xi * (amplitude * m);
        }
    })
}

/// The SplitMix64 generator (Steele, Lea, Flood 2014): a 64-bit state stepped by a
/// constant and mixed; enough for a reproducible jitter.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)` (53 bits).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in the unit disc, by rejection.
    fn unit_disc(&mut self) -> Point<2> {
        loop {
            let p = Point::<2>::new(2.0 * self.unit() - 1.0, 2.0 * self.unit() - 1.0);
            if p.norm_squared() <= 1.0 {
                return p;
            }
        }
    }
}

/// [`crossed`] with `place(node, interior)` called on every node in node order before the
/// cells are built (`interior`: not on the box boundary).
fn crossed_with(
    lo: Point<2>,
    hi: Point<2>,
    n: [usize; 2],
    mut place: impl FnMut(&mut Point<2>, bool),
) -> Result<Grid<2>> {
    if n[0] == 0 || n[1] == 0 || !(hi[0] > lo[0] && hi[1] > lo[1]) {
        return Err(GridError::Input(format!(
            "crossed mesh: need n > 0 and hi > lo, got n = {n:?}, lo = {lo:?}, hi = {hi:?}"
        ))
        .into());
    }
    let (nx, ny) = (n[0], n[1]);
    let dx = (hi[0] - lo[0]) / nx as f64;
    let dy = (hi[1] - lo[1]) / ny as f64;
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1) + nx * ny);
    for j in 0..=ny {
        for i in 0..=nx {
            let mut p = Point::<2>::new(lo[0] + i as f64 * dx, lo[1] + j as f64 * dy);
            place(&mut p, i > 0 && i < nx && j > 0 && j < ny);
            nodes.push(p);
        }
    }
    let corner = |i: usize, j: usize| j * (nx + 1) + i;
    let centre0 = nodes.len();
    for j in 0..ny {
        for i in 0..nx {
            let mut p =
                Point::<2>::new(lo[0] + (i as f64 + 0.5) * dx, lo[1] + (j as f64 + 0.5) * dy);
            place(&mut p, true);
            nodes.push(p);
        }
    }
    let mut loops = CellFaceLoops::new();
    for j in 0..ny {
        for i in 0..nx {
            let c = centre0 + j * nx + i;
            let q = [
                corner(i, j),
                corner(i + 1, j),
                corner(i + 1, j + 1),
                corner(i, j + 1),
            ];
            for k in 0..4 {
                loops.push_polygon(&[q[k], q[(k + 1) % 4], c]);
            }
        }
    }
    Ok(Grid::from_cell_faces(nodes, &loops)?)
}

/// The quarter plate with a hole (see the module docs): `n_theta` (even) divisions along the
/// hole and along the outer edges, `n_radial` layers whose thickness grows geometrically
/// from `first_layer` (m) at the hole. The hole faces carry the face tag `hole`.
///
/// Errors: `r ≥ side`, an odd or zero `n_theta`, `n_radial = 0`, a non-positive first
/// layer or one too thick for the plate.
pub fn plate_with_hole(
    side: f64,
    radius: f64,
    n_theta: usize,
    n_radial: usize,
    first_layer: f64,
) -> Result<Grid<2>> {
    if !(radius > 0.0 && radius < side)
        || n_theta < 2
        || n_theta % 2 == 1
        || n_radial == 0
        || !(first_layer > 0.0 && first_layer < side - radius)
    {
        return Err(GridError::Input(format!(
            "plate with a hole: need 0 < r < L, even n_theta ≥ 2, n_radial ≥ 1, 0 < first layer \
             < L − r; got L = {side}, r = {radius}, n_theta = {n_theta}, n_radial = {n_radial}, \
             first layer = {first_layer}"
        ))
        .into());
    }
    // Growth ratio q with first_layer · (q^n − 1)/(q − 1) = mean radial distance (bisection).
    let span = side - radius;
    let total = |q: f64| {
        if (q - 1.0).abs() < 1e-12 {
            first_layer * n_radial as f64
        } else {
            first_layer * (q.powi(n_radial as i32) - 1.0) / (q - 1.0)
        }
    };
    let (mut a, mut b) = (1.0f64, 2.0f64);
    while total(b) < span {
        b *= 2.0;
    }
    if total(a) > span {
        a = 1e-3;
    }
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if total(m) < span { a = m } else { b = m }
    }
    let q = 0.5 * (a + b);
    let mut rho = vec![0.0];
    for i in 0..n_radial {
        rho.push(rho[i] + first_layer * q.powi(i as i32));
    }
    let last = rho[n_radial];
    rho.iter_mut().for_each(|v| *v /= last);
    let half = n_theta / 2;
    let mut nodes = Vec::with_capacity((n_theta + 1) * (n_radial + 1));
    for (i, &s) in rho.iter().enumerate() {
        for k in 0..=n_theta {
            let t = k as f64 / n_theta as f64;
            let th = t * std::f64::consts::FRAC_PI_2;
            let inner = Point::<2>::new(radius * th.cos(), radius * th.sin());
            // Outer point: uniform along x = L (k ≤ half), then along y = L.
            let outer = if k <= half {
                Point::<2>::new(side, side * k as f64 / half as f64)
            } else {
                Point::<2>::new(side * (n_theta - k) as f64 / half as f64, side)
            };
            let mut p = inner * (1.0 - s) + outer * s;
            if k == 0 {
                p[1] = 0.0;
            }
            if k == n_theta {
                p[0] = 0.0;
            }
            if i == n_radial {
                p = outer;
            }
            nodes.push(p);
        }
    }
    let id = |i: usize, k: usize| i * (n_theta + 1) + k;
    let mut loops = CellFaceLoops::new();
    for i in 0..n_radial {
        for k in 0..n_theta {
            // Counter-clockwise quad: (i,k) → (i+1,k) → (i+1,k+1) → (i,k+1).
            let q = [id(i, k), id(i + 1, k), id(i + 1, k + 1), id(i, k + 1)];
            let d02 = (nodes[q[0]] - nodes[q[2]]).norm();
            let d13 = (nodes[q[1]] - nodes[q[3]]).norm();
            if d02 <= d13 {
                loops.push_polygon(&[q[0], q[1], q[2]]);
                loops.push_polygon(&[q[0], q[2], q[3]]);
            } else {
                loops.push_polygon(&[q[0], q[1], q[3]]);
                loops.push_polygon(&[q[1], q[2], q[3]]);
            }
        }
    }
    let mut grid = Grid::from_cell_faces(nodes, &loops)?;
    let hole: Vec<usize> = (0..grid.num_faces())
        .filter(|&f| {
            grid.is_boundary_face(f)
                && grid
                    .face_nodes(f)
                    .iter()
                    .all(|&n| (grid.node(n).norm() - radius).abs() < 1e-9 * side)
        })
        .collect();
    grid.set_face_tag("hole", hole)?;
    Ok(grid)
}

/// The first simplex (lowest id) whose closure contains `x` (tolerance `1e-10` in the
/// barycentric coordinates), or `None`. A linear scan: meant for probes, not hot loops.
pub fn locate<const D: usize>(grid: &Grid<D>, x: &Point<D>) -> Option<usize> {
    (0..grid.num_cells()).find(|&c| {
        let nodes = grid.cell_nodes(c);
        if nodes.len() != D + 1 {
            return false;
        }
        let x0 = grid.node(nodes[0]);
        let mut e = nalgebra::DMatrix::<f64>::zeros(D, D);
        for k in 0..D {
            let col = grid.node(nodes[k + 1]) - x0;
            for i in 0..D {
                e[(i, k)] = col[i];
            }
        }
        let r = nalgebra::DVector::from_iterator(D, (x - x0).iter().copied());
        match e.lu().solve(&r) {
            Some(l) => {
                let s: f64 = l.iter().sum();
                l.iter().all(|&v| v >= -1e-10) && s <= 1.0 + 1e-10
            }
            None => false,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At the maximum amplitude, for squares of aspect ratio 1:8 to 8:1 and 300 seeds,
    /// every triangle keeps an area of at least 0.4² of its own (a side `b ≥ m` and its
    /// altitude `h ≥ m` each shrink by at most 2·a·m, so keep 40 %), no node moves more than
    /// a·m, boundary nodes stay, and the total area is the box's.
    #[test]
    fn perturbed_crossed_meshes_stay_valid_at_the_maximum() {
        let a = MAX_PERTURB;
        for (w, h, n) in [
            (1.0, 1.0, [4, 4]),
            (8.0, 1.0, [4, 4]),
            (1.0, 8.0, [4, 4]),
            (2000.0, 1000.0, [10, 50]),
            (1e-3, 1e-3, [10, 50]),
        ] {
            let (lo, hi) = (Point::<2>::new(-0.5 * w, 0.0), Point::<2>::new(0.5 * w, h));
            let base = crossed(lo, hi, n).unwrap();
            let (dx, dy) = (w / n[0] as f64, h / n[1] as f64);
            let m = (0.5 * dx).min(0.5 * dy).min(dx * dy / dx.hypot(dy));
            for seed in 0..300 {
                let g = crossed_perturbed(lo, hi, n, a, seed).unwrap();
                let mut total = 0.0;
                for c in 0..g.num_cells() {
                    let (v0, v) = (base.cell_volume(c), g.cell_volume(c));
                    assert!(v >= 0.4 * 0.4 * v0, "seed {seed} cell {c}: {v} vs {v0}");
                    total += v;
                }
                assert!(
                    (total - w * h).abs() <= 1e-12 * w * h,
                    "{total} vs {}",
                    w * h
                );
                for (p, q) in base.nodes().iter().zip(g.nodes()) {
                    let on_side = [0, 1].iter().any(|&k| p[k] == lo[k] || p[k] == hi[k]);
                    let moved = (q - p).norm();
                    assert!(moved <= a * m * (1.0 + 1e-12), "{moved} > {}", a * m);
                    assert!(!on_side || moved == 0.0);
                }
            }
        }
        // Reproducible, and refused above the maximum.
        let (lo, hi) = (Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 1.0));
        let g1 = crossed_perturbed(lo, hi, [3, 3], 0.2, 7).unwrap();
        let g2 = crossed_perturbed(lo, hi, [3, 3], 0.2, 7).unwrap();
        assert_eq!(g1.nodes(), g2.nodes());
        assert!(crossed_perturbed(lo, hi, [3, 3], 0.31, 7).is_err());
        assert!(crossed_perturbed(lo, hi, [3, 3], f64::NAN, 7).is_err());
    }

    #[test]
    fn crossed_mesh_counts_and_area() {
        let g = crossed(
            Point::<2>::new(-0.12, -0.06),
            Point::<2>::new(0.12, 0.06),
            [5, 3],
        )
        .unwrap();
        assert_eq!(g.num_cells(), 60);
        let area: f64 = g.cell_volumes().iter().sum();
        assert!((area - 0.24 * 0.12).abs() < 1e-15);
        assert_eq!(g.boundary("ymin").unwrap().len(), 5);
        assert!(crossed(Point::<2>::zeros(), Point::<2>::new(1.0, 1.0), [0, 2]).is_err());
    }

    #[test]
    fn plate_with_hole_area_and_sides() {
        let (l, r) = (16.2, 0.216);
        let g = plate_with_hole(l, r, 16, 12, 0.02).unwrap();
        assert_eq!(g.num_cells(), 2 * 16 * 12);
        let area: f64 = g.cell_volumes().iter().sum();
        // The hole is polygonal: the area lies between the disc and the inscribed polygon.
        let disc = l * l - std::f64::consts::PI * r * r / 4.0;
        assert!(
            area > disc && area < disc + r * r * 0.01,
            "{area} vs {disc}"
        );
        for side in ["xmin", "ymin", "xmax", "ymax"] {
            assert!(!g.boundary(side).unwrap().is_empty(), "{side}");
        }
        assert_eq!(g.boundary("hole").unwrap().len(), 16);
        assert!(plate_with_hole(1.0, 2.0, 4, 4, 0.1).is_err());
        assert!(plate_with_hole(1.0, 0.1, 3, 4, 0.1).is_err());
    }
}
