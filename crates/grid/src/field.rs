//! Space- and time-dependent scalar values: boundary values, sources, initial states
//! and loads given as numbers or as functions of position and time. One type serves the
//! flow model, the mechanics and the scene expressions.

use std::fmt;
use std::sync::Arc;

/// A function of position `x` (a slice of length D) and time `t`.
pub type FieldFn = Arc<dyn Fn(&[f64], f64) -> f64 + Send + Sync>;

/// A scalar value that is either a constant (the common case, evaluated for free) or a
/// function of position and time (e.g. a compiled scene expression).
#[derive(Clone)]
pub enum ScalarField {
    /// A constant.
    Const(f64),
    /// `f(x, t)`.
    Fn(FieldFn),
}

impl ScalarField {
    /// A field from a closure of `(x, t)`.
    pub fn from_fn(f: impl Fn(&[f64], f64) -> f64 + Send + Sync + 'static) -> Self {
        Self::Fn(Arc::new(f))
    }
    /// The value at `x` and time `t`.
    #[inline]
    pub fn eval(&self, x: &[f64], t: f64) -> f64 {
        match self {
            Self::Const(v) => *v,
            Self::Fn(f) => f(x, t),
        }
    }
    /// The constant value, if the field is constant.
    pub fn as_const(&self) -> Option<f64> {
        match self {
            Self::Const(v) => Some(*v),
            Self::Fn(_) => None,
        }
    }
}

impl From<f64> for ScalarField {
    fn from(v: f64) -> Self {
        Self::Const(v)
    }
}

impl fmt::Debug for ScalarField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Const(v) => write!(f, "{v}"),
            Self::Fn(_) => write!(f, "f(x, t)"),
        }
    }
}
