//! Space- and time-dependent scalar and vector values.

use std::fmt;
use std::sync::Arc;

pub use porofrac_grid::field::{FieldFn, ScalarField};

/// A function of position `x` (a slice of length D) and time `t` giving all `D` components
/// of a vector at once.
pub type VectorFn<const D: usize> = Arc<dyn Fn(&[f64], f64) -> [f64; D] + Send + Sync>;

/// A function evaluating all `D` components at many points at once: `f(xs, t, out)` writes
/// the value at `xs[i]` into `out[i]` (an interpreter amortizes its dispatch over the points).
pub type VectorBatchFn<const D: usize> =
    Arc<dyn Fn(&[[f64; D]], f64, &mut [[f64; D]]) + Send + Sync>;

/// A vector value: its components as scalar fields (e.g. the compiled expressions of a
/// scene), or one function for all of them, which can share work between the components
/// (the sines and cosines of a manufactured load, say).
#[derive(Clone)]
pub enum VectorField<const D: usize> {
    /// One scalar field per component.
    Components([ScalarField; D]),
    /// `f(x, t)`, all components.
    Fn(VectorFn<D>),
    /// All components at many points per call.
    Batch(VectorBatchFn<D>),
}

impl<const D: usize> VectorField<D> {
    /// A field from a closure of `(x, t)` giving all components.
    pub fn from_fn(f: impl Fn(&[f64], f64) -> [f64; D] + Send + Sync + 'static) -> Self {
        Self::Fn(Arc::new(f))
    }
    /// A field from a function of many points (see [`VectorBatchFn`]).
    pub fn from_batch_fn(
        f: impl Fn(&[[f64; D]], f64, &mut [[f64; D]]) + Send + Sync + 'static,
    ) -> Self {
        Self::Batch(Arc::new(f))
    }
    /// The value at `x` and time `t`.
    #[inline]
    pub fn eval(&self, x: &[f64], t: f64) -> [f64; D] {
        match self {
            Self::Components(c) => std::array::from_fn(|a| c[a].eval(x, t)),
            Self::Fn(f) => f(x, t),
            Self::Batch(f) => {
                let p: [f64; D] = std::array::from_fn(|a| x.get(a).copied().unwrap_or(0.0));
                let mut out = [[0.0; D]];
                f(&[p], t, &mut out);
                out[0]
            }
        }
    }
    /// The values at every point of `xs` into `out` (same length), time `t`.
    pub fn eval_many(&self, xs: &[[f64; D]], t: f64, out: &mut [[f64; D]]) {
        assert_eq!(xs.len(), out.len(), "VectorField::eval_many: lengths");
        match self {
            Self::Batch(f) => f(xs, t, out),
            _ => {
                for (o, x) in out.iter_mut().zip(xs) {
                    *o = self.eval(x, t);
                }
            }
        }
    }
    /// The constant value, if every component is constant.
    pub fn as_const(&self) -> Option<[f64; D]> {
        match self {
            Self::Components(c) => {
                let mut v = [0.0; D];
                for (vi, f) in v.iter_mut().zip(c) {
                    *vi = f.as_const()?;
                }
                Some(v)
            }
            Self::Fn(_) | Self::Batch(_) => None,
        }
    }
}

impl<const D: usize> From<[ScalarField; D]> for VectorField<D> {
    fn from(c: [ScalarField; D]) -> Self {
        Self::Components(c)
    }
}

impl<const D: usize> fmt::Debug for VectorField<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Components(c) => c.fmt(f),
            Self::Fn(_) | Self::Batch(_) => write!(f, "f(x, t)"),
        }
    }
}
