//! Space- and time-dependent scalar and vector values.

use std::fmt;
use std::sync::Arc;

pub use porofrac_grid::field::{FieldFn, ScalarField};

/// A function of position `x` (a slice of length D) and time `t` giving all `D` components
/// of a vector at once.
pub type VectorFn<const D: usize> = Arc<dyn Fn(&[f64], f64) -> [f64; D] + Send + Sync>;

/// A vector value: its components as scalar fields (e.g. the compiled expressions of a
/// scene), or one function for all of them, which can share work between the components
/// (the sines and cosines of a manufactured load, say).
#[derive(Clone)]
pub enum VectorField<const D: usize> {
    /// One scalar field per component.
    Components([ScalarField; D]),
    /// `f(x, t)`, all components.
    Fn(VectorFn<D>),
}

impl<const D: usize> VectorField<D> {
    /// A field from a closure of `(x, t)` giving all components.
    pub fn from_fn(f: impl Fn(&[f64], f64) -> [f64; D] + Send + Sync + 'static) -> Self {
        Self::Fn(Arc::new(f))
    }
    /// The value at `x` and time `t`.
    #[inline]
    pub fn eval(&self, x: &[f64], t: f64) -> [f64; D] {
        match self {
            Self::Components(c) => std::array::from_fn(|a| c[a].eval(x, t)),
            Self::Fn(f) => f(x, t),
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
            Self::Fn(_) => None,
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
            Self::Fn(_) => write!(f, "f(x, t)"),
        }
    }
}
