//! Rigid bodies that bound the disks: segments (two vertices) and convex polygons
//! (three or more, counter-clockwise). A body translates without rotating. Along each
//! axis its velocity is either prescribed ([`Axis::Prescribed`], infinite mass) or free
//! under a prescribed force ([`Axis::Loaded`], with the body's mass): a wall pushed by a
//! known load.
//!
//! Friction: a body may carry its own Coulomb coefficient μ_b ([`RigidBody::with_friction`]),
//! used by every contact of a disk with it, whether it stuck at the previous step or not
//! (a single coefficient, static and dynamic); without one the contact law's coefficients
//! apply. A disk on such a body slides when its tangential force would exceed μ_b times
//! its normal force: a block of weight m g pushed along a flat base at constant speed
//! needs μ_b m g.
//!
//! Closest point: a disk of centre c faces the closest point of the body's boundary;
//! the normal points from that point to c and the gap is the distance minus the radius.
//! A centre inside a polygon gives a negative gap, the outward normal of the nearest
//! edge.

use crate::NscdError;

/// Motion along one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Axis {
    /// Velocity prescribed (m/s), whatever the contacts do.
    Prescribed(f64),
    /// Free, under a constant applied force (N per metre of thickness).
    Loaded(f64),
}

impl Default for Axis {
    fn default() -> Self {
        Self::Prescribed(0.0)
    }
}

/// A segment or convex polygon translating as a rigid body.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidBody {
    /// Vertices at t = 0 (m); two for a segment, else counter-clockwise.
    pub vertices: Vec<[f64; 2]>,
    /// Displacement since t = 0 (m).
    pub offset: [f64; 2],
    /// Current velocity (m/s).
    pub velocity: [f64; 2],
    /// Motion along x and y.
    pub axes: [Axis; 2],
    /// Mass (kg per metre), used along loaded axes.
    pub mass: f64,
    /// Coulomb coefficient of the contacts of disks with this body; `None`: the contact
    /// law's.
    pub friction: Option<f64>,
}

impl RigidBody {
    /// A fixed segment from `a` to `b`.
    pub fn segment(a: [f64; 2], b: [f64; 2]) -> Self {
        Self::polygon(vec![a, b])
    }

    /// A fixed polygon (or segment).
    pub fn polygon(vertices: Vec<[f64; 2]>) -> Self {
        Self {
            vertices,
            offset: [0.0; 2],
            velocity: [0.0; 2],
            axes: [Axis::Prescribed(0.0); 2],
            mass: f64::INFINITY,
            friction: None,
        }
    }

    /// The same body moving at a prescribed velocity.
    pub fn moving(mut self, v: [f64; 2]) -> Self {
        self.axes = [Axis::Prescribed(v[0]), Axis::Prescribed(v[1])];
        self.velocity = v;
        self
    }

    /// The same body with the given axes and mass.
    pub fn with_axes(mut self, axes: [Axis; 2], mass: f64) -> Self {
        self.axes = axes;
        self.mass = mass;
        for a in 0..2 {
            if let Axis::Prescribed(v) = axes[a] {
                self.velocity[a] = v;
            }
        }
        self
    }

    /// The same body with its own friction coefficient μ_b for the contacts of disks with
    /// it (instead of the contact law's).
    pub fn with_friction(mut self, mu: f64) -> Self {
        self.friction = Some(mu);
        self
    }

    /// Check the body; `index` names it in errors.
    pub fn check(&self, index: usize) -> Result<(), NscdError> {
        let bad = |message| Err(NscdError::BadBody { index, message });
        if self.vertices.len() < 2 {
            return bad("needs at least two vertices");
        }
        if self.vertices.iter().flatten().any(|v| !v.is_finite()) {
            return bad("has a vertex that is not finite");
        }
        let n = self.vertices.len();
        for k in 0..n {
            let (a, b) = (self.vertices[k], self.vertices[(k + 1) % n]);
            if a == b {
                return bad("has two equal consecutive vertices");
            }
        }
        if n >= 3 {
            for k in 0..n {
                let (a, b, c) = (
                    self.vertices[k],
                    self.vertices[(k + 1) % n],
                    self.vertices[(k + 2) % n],
                );
                if cross(sub(b, a), sub(c, b)) <= 0.0 {
                    return bad("is not convex and counter-clockwise");
                }
            }
        }
        if let Some(mu) = self.friction
            && !(mu.is_finite() && mu >= 0.0)
        {
            return bad("has a friction coefficient that is not a non-negative number");
        }
        let loaded = self.axes.iter().any(|a| matches!(a, Axis::Loaded(_)));
        if loaded && !(self.mass.is_finite() && self.mass > 0.0) {
            return bad("has a loaded axis and needs a positive finite mass");
        }
        for a in &self.axes {
            let (Axis::Prescribed(v) | Axis::Loaded(v)) = a;
            if !v.is_finite() {
                return bad("has a velocity or force that is not finite");
            }
        }
        Ok(())
    }

    /// Inverse mass along x and y (0 along prescribed axes).
    pub fn inverse_mass(&self) -> [f64; 2] {
        let f = |a: Axis| match a {
            Axis::Prescribed(_) => 0.0,
            Axis::Loaded(_) => 1.0 / self.mass,
        };
        [f(self.axes[0]), f(self.axes[1])]
    }

    /// Centroid of the body at zero offset: the midpoint of a segment, the area centroid
    /// of a polygon (the vertex mean if its area is zero).
    pub fn centroid(&self) -> [f64; 2] {
        let n = self.vertices.len();
        let mean = {
            let s = self
                .vertices
                .iter()
                .fold([0.0; 2], |a, v| [a[0] + v[0], a[1] + v[1]]);
            [s[0] / n as f64, s[1] / n as f64]
        };
        if n < 3 {
            return mean;
        }
        let (mut a2, mut cx, mut cy) = (0.0, 0.0, 0.0);
        for k in 0..n {
            let p = sub(self.vertices[k], mean);
            let q = sub(self.vertices[(k + 1) % n], mean);
            let w = cross(p, q);
            a2 += w;
            cx += (p[0] + q[0]) * w;
            cy += (p[1] + q[1]) * w;
        }
        if a2 == 0.0 {
            return mean;
        }
        [mean[0] + cx / (3.0 * a2), mean[1] + cy / (3.0 * a2)]
    }

    /// Axis-aligned bounding box of the body displaced by `offset`.
    pub fn bounds(&self, offset: [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for v in &self.vertices {
            for a in 0..2 {
                lo[a] = lo[a].min(v[a] + offset[a]);
                hi[a] = hi[a].max(v[a] + offset[a]);
            }
        }
        (lo, hi)
    }

    /// Distance from `c` to the boundary of the body displaced by `offset` (negative
    /// inside a polygon), the unit normal from the body to `c`, and the closest point.
    pub fn closest(&self, offset: [f64; 2], c: [f64; 2]) -> (f64, [f64; 2], [f64; 2]) {
        let n = self.vertices.len();
        let edges = if n == 2 { 1 } else { n };
        let vert = |k: usize| {
            let v = self.vertices[k % n];
            [v[0] + offset[0], v[1] + offset[1]]
        };
        let mut best = (f64::INFINITY, [0.0; 2], [0.0; 2]);
        let mut inside = n >= 3;
        let mut nearest_edge = (f64::NEG_INFINITY, [0.0; 2], [0.0; 2]);
        for k in 0..edges {
            let (a, b) = (vert(k), vert(k + 1));
            let e = sub(b, a);
            let len2 = dot(e, e);
            let s = (dot(sub(c, a), e) / len2).clamp(0.0, 1.0);
            let p = [a[0] + s * e[0], a[1] + s * e[1]];
            let d = sub(c, p);
            let dist = dot(d, d).sqrt();
            // Outward normal of a counter-clockwise edge: (e_y, −e_x)/|e|.
            let len = len2.sqrt();
            let out = [e[1] / len, -e[0] / len];
            let signed = dot(sub(c, a), out);
            if signed > 0.0 {
                inside = false;
            }
            if signed > nearest_edge.0 {
                nearest_edge = (
                    signed,
                    out,
                    [c[0] - signed * out[0], c[1] - signed * out[1]],
                );
            }
            if dist < best.0 {
                let normal = if dist > 0.0 {
                    [d[0] / dist, d[1] / dist]
                } else if n == 2 {
                    [-out[0], -out[1]]
                } else {
                    out
                };
                best = (dist, normal, p);
            }
        }
        if inside {
            let (signed, out, p) = nearest_edge;
            return (signed, out, p);
        }
        best
    }
}

pub(crate) fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
pub(crate) fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
