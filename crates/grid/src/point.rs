//! Points and the few dimension-dependent geometric primitives.
//!
//! The dimension is the const parameter `D` (2 or 3). Everything dimension-dependent in the
//! crate funnels through [`facet_area_vector`]: the area-weighted normal of a *facet*, the
//! (D−1)-simplex a face is split into (a segment in 2D, a triangle in 3D).

use nalgebra::SVector;

/// A point or vector in D dimensions.
pub type Point<const D: usize> = SVector<f64, D>;

/// Compile-time guard: the grid types exist for D = 2 and D = 3 only.
pub(crate) const fn assert_dim<const D: usize>() {
    assert!(D == 2 || D == 3, "porofrac grids are 2D or 3D");
}

/// Area-weighted normal of a facet given by its `D` corner points.
///
/// * 2D, segment `a → b`: `(b − a)` rotated clockwise by 90°, `[b_y − a_y, −(b_x − a_x)]`,
///   whose length is the segment length. For a counter-clockwise polygon it points outward.
/// * 3D, triangle `a, b, c`: `½ (b − a) × (c − a)` (right-hand rule).
#[inline]
pub fn facet_area_vector<const D: usize>(p: &[Point<D>]) -> Point<D> {
    const { assert_dim::<D>() };
    let mut n = Point::<D>::zeros();
    if D == 2 {
        let e = p[1] - p[0];
        n[0] = e[1];
        n[1] = -e[0];
    } else {
        let u = p[1] - p[0];
        let v = p[2] - p[0];
        n[0] = 0.5 * (u[1] * v[2] - u[2] * v[1]);
        n[1] = 0.5 * (u[2] * v[0] - u[0] * v[2]);
        n[2] = 0.5 * (u[0] * v[1] - u[1] * v[0]);
    }
    n
}

/// Visit the facets of a face given as an oriented node loop.
///
/// In 2D a face is a segment and is its own facet. In 3D a triangle is its own facet and a
/// face with `m > 3` nodes is split into the `m` triangles `(x_k, x_{k+1}, x̄)` about its
/// vertex average `x̄` (the triangulation of DESIGN.md that volumes, normals and the VEM
/// face integrals all share).
///
/// The callback receives the facet's area vector, its centroid, and the facet's corners as
/// loop positions (`usize::MAX` stands for the face point `x̄`).
#[inline]
pub fn for_each_facet<const D: usize>(
    loop_points: &[Point<D>],
    mut f: impl FnMut(Point<D>, Point<D>, [usize; 3]),
) {
    let m = loop_points.len();
    if D == 2 || m == 3 {
        let c = loop_points.iter().sum::<Point<D>>() / m as f64;
        let corners = if D == 2 {
            [0, 1, usize::MAX]
        } else {
            [0, 1, 2]
        };
        f(facet_area_vector::<D>(loop_points), c, corners);
        return;
    }
    let xf = loop_points.iter().sum::<Point<D>>() / m as f64;
    for k in 0..m {
        let a = loop_points[k];
        let b = loop_points[(k + 1) % m];
        let tri = [a, b, xf];
        f(
            facet_area_vector::<D>(&tri),
            (a + b + xf) / 3.0,
            [k, (k + 1) % m, usize::MAX],
        );
    }
}
