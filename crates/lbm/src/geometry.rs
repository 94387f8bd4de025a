//! Obstacle shapes in lattice units (node `(i, j)` sits at `(i + ½, j + ½)`): inside test
//! and where a lattice link enters the shape (Mora et al. (2015) eq. 6).

/// A rigid shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A disk.
    Circle {
        /// Centre.
        center: [f64; 2],
        /// Radius.
        radius: f64,
    },
    /// The outside of a circle: the wall of an enclosing cylinder, solid everywhere in
    /// the lattice beyond `radius` from `center` (circular Couette flow, a rotating drum).
    Hollow {
        /// Centre.
        center: [f64; 2],
        /// Radius of the fluid region.
        radius: f64,
    },
    /// A rectangle, possibly rotated.
    Box {
        /// Centre.
        center: [f64; 2],
        /// Half side lengths along its own axes.
        half: [f64; 2],
        /// Rotation of its axes (rad, counter-clockwise).
        angle: f64,
    },
}

impl Shape {
    /// An axis-aligned box from two corners.
    pub fn aligned_box(lo: [f64; 2], hi: [f64; 2]) -> Self {
        Shape::Box {
            center: [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])],
            half: [0.5 * (hi[0] - lo[0]).abs(), 0.5 * (hi[1] - lo[1]).abs()],
            angle: 0.0,
        }
    }

    /// The reference point (centre) about which the shape rotates.
    pub fn center(&self) -> [f64; 2] {
        match *self {
            Shape::Circle { center, .. }
            | Shape::Hollow { center, .. }
            | Shape::Box { center, .. } => center,
        }
    }

    /// Translate by `d` and rotate by `dangle` about the centre.
    pub fn advance(&mut self, d: [f64; 2], dangle: f64) {
        match self {
            Shape::Circle { center, .. } | Shape::Hollow { center, .. } => {
                center[0] += d[0];
                center[1] += d[1];
            }
            Shape::Box { center, angle, .. } => {
                center[0] += d[0];
                center[1] += d[1];
                *angle += dangle;
            }
        }
    }

    /// Axis-aligned bounding box `[lo, hi]` (of the circle for [`Shape::Hollow`]).
    pub fn bounds(&self) -> [[f64; 2]; 2] {
        match *self {
            Shape::Circle { center, radius } | Shape::Hollow { center, radius } => [
                [center[0] - radius, center[1] - radius],
                [center[0] + radius, center[1] + radius],
            ],
            Shape::Box {
                center,
                half,
                angle,
            } => {
                let (s, c) = angle.sin_cos();
                let ex = (c * half[0]).abs() + (s * half[1]).abs();
                let ey = (s * half[0]).abs() + (c * half[1]).abs();
                [
                    [center[0] - ex, center[1] - ey],
                    [center[0] + ex, center[1] + ey],
                ]
            }
        }
    }

    fn to_local(center: [f64; 2], angle: f64, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = angle.sin_cos();
        let d = [p[0] - center[0], p[1] - center[1]];
        [c * d[0] + s * d[1], -s * d[0] + c * d[1]]
    }

    /// Whether `p` is inside (boundary included).
    #[inline]
    pub fn contains(&self, p: [f64; 2]) -> bool {
        match *self {
            Shape::Circle { center, radius } => {
                let d = [p[0] - center[0], p[1] - center[1]];
                d[0] * d[0] + d[1] * d[1] <= radius * radius
            }
            Shape::Hollow { center, radius } => {
                let d = [p[0] - center[0], p[1] - center[1]];
                d[0] * d[0] + d[1] * d[1] >= radius * radius
            }
            Shape::Box {
                center,
                half,
                angle,
            } => {
                let l = Self::to_local(center, angle, p);
                l[0].abs() <= half[0] && l[1].abs() <= half[1]
            }
        }
    }

    /// The fraction `δ ∈ [0, 1]` of the segment `p → p + d` (from a point outside to one
    /// inside) at which it enters the shape.
    #[inline]
    pub fn entry(&self, p: [f64; 2], d: [f64; 2]) -> f64 {
        let t = match *self {
            Shape::Circle { center, radius } => {
                let o = [p[0] - center[0], p[1] - center[1]];
                let a = d[0] * d[0] + d[1] * d[1];
                let b = o[0] * d[0] + o[1] * d[1];
                let c = o[0] * o[0] + o[1] * o[1] - radius * radius;
                let disc = (b * b - a * c).max(0.0);
                (-b - disc.sqrt()) / a
            }
            Shape::Hollow { center, radius } => {
                // from inside the circle outwards: the larger root
                let o = [p[0] - center[0], p[1] - center[1]];
                let a = d[0] * d[0] + d[1] * d[1];
                let b = o[0] * d[0] + o[1] * d[1];
                let c = o[0] * o[0] + o[1] * o[1] - radius * radius;
                let disc = (b * b - a * c).max(0.0);
                (-b + disc.sqrt()) / a
            }
            Shape::Box {
                center,
                half,
                angle,
            } => {
                let o = Self::to_local(center, angle, p);
                let (s, c) = angle.sin_cos();
                let dl = [c * d[0] + s * d[1], -s * d[0] + c * d[1]];
                let mut t0 = f64::NEG_INFINITY;
                for a in 0..2 {
                    if dl[a] != 0.0 {
                        let t1 = (-half[a] - o[a]) / dl[a];
                        let t2 = (half[a] - o[a]) / dl[a];
                        t0 = t0.max(t1.min(t2));
                    }
                }
                t0
            }
        };
        t.clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_points_lie_on_the_surface() {
        let c = Shape::Circle {
            center: [5.3, 4.1],
            radius: 2.2,
        };
        let p = [2.5, 4.5];
        assert!(!c.contains(p) && c.contains([3.5, 4.5]));
        let t = c.entry(p, [1.0, 0.0]);
        let x = p[0] + t - 5.3;
        assert!((x * x + 0.4f64.powi(2) - 2.2f64.powi(2)).abs() < 1e-12);
        let b = Shape::Box {
            center: [5.0, 5.0],
            half: [2.0, 1.0],
            angle: std::f64::consts::FRAC_PI_2,
        };
        // rotated by 90°: extends ±1 in x and ±2 in y
        assert!(b.contains([5.9, 6.9]) && !b.contains([6.1, 5.0]));
        let t = b.entry([6.5, 5.5], [-1.0, 0.0]);
        assert!((t - 0.5).abs() < 1e-12);
        // the outside of a circle: a link from the fluid inside leaves at the surface
        let h = Shape::Hollow {
            center: [5.3, 4.1],
            radius: 2.2,
        };
        assert!(!h.contains([5.3, 4.1]) && h.contains([8.0, 4.1]));
        let p = [7.0, 4.5];
        let t = h.entry(p, [1.0, 0.0]);
        let x = p[0] + t - 5.3;
        assert!(t > 0.0 && t < 1.0);
        assert!((x * x + 0.4f64.powi(2) - 2.2f64.powi(2)).abs() < 1e-12);
    }
}
