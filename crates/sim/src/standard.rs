//! The standard problems E2 and E3 of `docs/BENCHMARKS.md`: manufactured displacements on
//! the unit square and cube for `E = 1`, `ν = 0.3` (plane strain in 2D), their gradients,
//! the body forces `f = −div σ(u)`; the L2 error of a nodal (P1) field on a simplex grid
//! and its quadrature rules are re-exported from [`crate::norms`]. One definition for the
//! validation tests, the solver benchmarks and the speed-against-error study: test
//! fixtures, compiled with the cargo feature `fixtures` only.
//!
//! ```text
//!   E2: u = (sin πx sin πy, x² y) / 100,
//!   E3: u = (sin πx sin πy sin πz, x² y z, y z cos πx) / 100,
//! ```
//!
//! with `λ = 15/26`, `μ = 5/13`: `f = −(λ + μ) ∇(div u) − μ Δu`.

use std::f64::consts::PI;
use std::sync::Arc;

use porofrac_grid::{Grid, Point};
use porofrac_law::Tensor;

use crate::bc::Displacement;
use crate::field::{ScalarField, VectorField};
pub use crate::norms::{
    QPoint, l2_error_p1, l2_error_p1_field, simplex_rule5, tetrahedron_rule5, triangle_rule5,
};

/// A vector field of position.
pub type VecFn<const D: usize> = Arc<dyn Fn(&Point<D>) -> Point<D> + Send + Sync>;
/// A tensor field of position (the displacement gradient `∂u_a/∂x_b` at `(a, b)`).
pub type TenFn<const D: usize> = Arc<dyn Fn(&Point<D>) -> Tensor<D> + Send + Sync>;

/// A manufactured solution: displacement, its gradient and the body force.
#[derive(Clone)]
pub struct Manufactured<const D: usize> {
    /// The displacement.
    pub u: VecFn<D>,
    /// Its gradient.
    pub grad: TenFn<D>,
    /// The body force.
    pub f: VecFn<D>,
    /// The body force as one function of all components (the sines and cosines shared
    /// between them), evaluated once per point by the load integration.
    f_all: fn(&[f64]) -> [f64; D],
}

/// `(sin πs, cos πs)`.
fn sin_cos_pi(s: f64) -> (f64, f64) {
    (PI * s).sin_cos()
}

/// The E2 body force.
fn e2_f(p: &[f64]) -> [f64; 2] {
    let (x, y) = (p[0], p[1]);
    let ((sx, cx), (sy, cy)) = (sin_cos_pi(x), sin_cos_pi(y));
    [
        -x / 52.0 + 9.0 * PI * PI * sx * sy / 520.0,
        -y / 130.0 - PI * PI * cx * cy / 104.0,
    ]
}

/// The E3 body force.
fn e3_f(p: &[f64]) -> [f64; 3] {
    let (x, y, z) = (p[0], p[1], p[2]);
    let ((sx, cx), (sy, cy), (sz, cz)) = (sin_cos_pi(x), sin_cos_pi(y), sin_cos_pi(z));
    [
        -x * z / 52.0 + PI * y * sx / 104.0 + 11.0 * PI * PI * sx * sy * sz / 520.0,
        -y * z / 130.0 - PI * PI * sz * cx * cy / 104.0 - cx / 104.0,
        -x * x / 104.0 + PI * PI * y * z * cx / 260.0 - PI * PI * sy * cx * cz / 104.0,
    ]
}

/// E2: `u = (sin πx sin πy, x² y) / 100`.
pub fn e2() -> Manufactured<2> {
    Manufactured {
        u: Arc::new(|p: &Point<2>| {
            let (x, y) = (p[0], p[1]);
            Point::<2>::new((PI * x).sin() * (PI * y).sin(), x * x * y) / 100.0
        }),
        grad: Arc::new(|p: &Point<2>| {
            let (x, y) = (p[0], p[1]);
            Tensor::<2>::new(
                PI * (PI * x).cos() * (PI * y).sin(),
                PI * (PI * x).sin() * (PI * y).cos(),
                2.0 * x * y,
                x * x,
            ) / 100.0
        }),
        f: Arc::new(|p: &Point<2>| Point::<2>::from(e2_f(p.as_slice()))),
        f_all: e2_f,
    }
}

/// E3: `u = (sin πx sin πy sin πz, x² y z, y z cos πx) / 100`.
pub fn e3() -> Manufactured<3> {
    Manufactured {
        u: Arc::new(|p: &Point<3>| {
            let (x, y, z) = (p[0], p[1], p[2]);
            Point::<3>::new(
                (PI * x).sin() * (PI * y).sin() * (PI * z).sin(),
                x * x * y * z,
                y * z * (PI * x).cos(),
            ) / 100.0
        }),
        grad: Arc::new(|p: &Point<3>| {
            let (x, y, z) = (p[0], p[1], p[2]);
            let (sx, sy, sz) = ((PI * x).sin(), (PI * y).sin(), (PI * z).sin());
            let (cx, cy, cz) = ((PI * x).cos(), (PI * y).cos(), (PI * z).cos());
            Tensor::<3>::new(
                PI * cx * sy * sz,
                PI * sx * cy * sz,
                PI * sx * sy * cz,
                2.0 * x * y * z,
                x * x * z,
                x * x * y,
                -PI * y * z * sx,
                z * cx,
                y * cx,
            ) / 100.0
        }),
        f: Arc::new(|p: &Point<3>| Point::<3>::from(e3_f(p.as_slice()))),
        f_all: e3_f,
    }
}

/// The components of a vector field as scalar fields (for conditions and loads).
pub fn components<const D: usize>(f: &VecFn<D>) -> [ScalarField; D] {
    std::array::from_fn(|a| {
        let f = f.clone();
        ScalarField::from_fn(move |x, _| f(&Point::<D>::from_column_slice(x))[a])
    })
}

/// `u = f` prescribed (all components) on the nodes of `faces`.
pub fn dirichlet<const D: usize>(name: &str, faces: Vec<usize>, f: &VecFn<D>) -> Displacement<D> {
    Displacement {
        name: name.into(),
        faces,
        components: components(f).map(Some),
    }
}

impl<const D: usize> Manufactured<D> {
    /// The body force ([`crate::Loads::body_force`]).
    pub fn body_force(&self) -> VectorField<D> {
        let f = self.f_all;
        VectorField::from_fn(move |x, _| f(x))
    }

    /// The exact displacement prescribed on the nodes of `faces`.
    pub fn boundary(&self, name: &str, faces: Vec<usize>) -> Displacement<D> {
        dirichlet(name, faces, &self.u)
    }

    /// `‖u − u_h‖_L2` of the nodal field `u` (`D` per node, node-major) as the P1
    /// interpolant on a grid of simplices, with the degree-5 rules of
    /// [`simplex_rule5`]. `None` if a cell is not a simplex.
    pub fn l2_error_simplices(&self, grid: &Grid<D>, u: &[f64]) -> Option<f64> {
        l2_error_p1(grid, u, |x| (self.u)(x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `u`, `grad` and `f` agree: the gradient with central differences of `u`, the body
    /// force with `−div σ` from central differences of the gradient (λ = 15/26, μ = 5/13),
    /// and the component fields with `f`.
    fn consistent<const D: usize>(m: &Manufactured<D>) {
        let (lambda, mu) = (15.0 / 26.0, 5.0 / 13.0);
        let stress = |x: &Point<D>| {
            let g = (m.grad)(x);
            let eps = (g + g.transpose()) * 0.5;
            Tensor::<D>::identity() * (lambda * eps.trace()) + eps * (2.0 * mu)
        };
        let body = m.body_force();
        for k in 0..5 {
            let x = Point::<D>::from_fn(|a, _| 0.13 + 0.17 * k as f64 + 0.11 * a as f64);
            let h = 1e-5;
            let mut div = Point::<D>::zeros();
            for b in 0..D {
                let mut e = Point::<D>::zeros();
                e[b] = h;
                let du = ((m.u)(&(x + e)) - (m.u)(&(x - e))) / (2.0 * h);
                let g = (m.grad)(&x);
                for a in 0..D {
                    assert!((du[a] - g[(a, b)]).abs() < 1e-9, "∂u{a}/∂x{b} at {x:?}");
                }
                let ds = (stress(&(x + e)) - stress(&(x - e))) / (2.0 * h);
                for a in 0..D {
                    div[a] += ds[(a, b)];
                }
            }
            let f = (m.f)(&x);
            for a in 0..D {
                assert!(
                    (f[a] + div[a]).abs() < 1e-7,
                    "f{a} at {x:?}: {} vs {}",
                    f[a],
                    -div[a]
                );
                assert_eq!(body.eval(x.as_slice(), 0.0)[a], f[a]);
            }
        }
    }

    #[test]
    fn manufactured_fields_are_consistent() {
        consistent(&e2());
        consistent(&e3());
    }
}
