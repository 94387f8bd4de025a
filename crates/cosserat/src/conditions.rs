//! Boundary conditions (5)–(6) and volume loads, as functions of position and time.
//!
//! A [`Condition`] applies to a list of boundary faces. Per generalised component (`u`
//! then `φ`, see [`crate::material`]) it is *free* (nothing, i.e. zero traction),
//! *fixed* (`u_k` or `φ_k` prescribed, imposed weakly by the non-symmetric Nitsche terms
//! (18)–(20)) or *loaded* (traction `t_k` or couple traction `μ_k` prescribed). A
//! component may not be both fixed and loaded on one face.

use std::sync::Arc;

use porofrac_grid::Point;

/// A scalar function of position and time.
pub type Field<const D: usize> = Arc<dyn Fn(&Point<D>, f64) -> f64 + Send + Sync>;

/// A constant [`Field`].
pub fn constant<const D: usize>(v: f64) -> Field<D> {
    Arc::new(move |_, _| v)
}

/// What a condition prescribes for one component.
#[derive(Clone, Default)]
pub enum Slot<const D: usize> {
    /// Nothing (natural condition: zero traction).
    #[default]
    Free,
    /// Prescribed value (Dirichlet, weakly).
    Fixed(Field<D>),
    /// Prescribed traction or couple traction (Neumann).
    Load(Field<D>),
}

impl<const D: usize> std::fmt::Debug for Slot<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Slot::Free => write!(f, "Free"),
            Slot::Fixed(_) => write!(f, "Fixed(..)"),
            Slot::Load(_) => write!(f, "Load(..)"),
        }
    }
}

/// A boundary condition on a set of faces.
#[derive(Clone, Debug)]
pub struct Condition<const D: usize> {
    /// Boundary faces (grid face ids).
    pub faces: Vec<usize>,
    /// One slot per generalised component (`D + R`).
    pub slots: Vec<Slot<D>>,
}

impl<const D: usize> Condition<D> {
    /// A condition on `faces` with every component free.
    pub fn new(faces: Vec<usize>) -> Self {
        Self {
            faces,
            slots: vec![Slot::Free; crate::material::components(D)],
        }
    }

    /// Prescribe component `k` (`u_k` for `k < D`, `φ_{k−D}` otherwise).
    pub fn fix(mut self, k: usize, value: Field<D>) -> Self {
        self.slots[k] = Slot::Fixed(value);
        self
    }

    /// Prescribe the traction (`k < D`) or couple traction (`k ≥ D`) component `k`.
    pub fn load(mut self, k: usize, value: Field<D>) -> Self {
        self.slots[k] = Slot::Load(value);
        self
    }

    /// Fix every displacement and rotation component to the given fields.
    pub fn clamp(mut self, values: Vec<Field<D>>) -> Self {
        for (k, v) in values.into_iter().enumerate() {
            self.slots[k] = Slot::Fixed(v);
        }
        self
    }
}

/// Body force `f` (first `D` entries) and body couple `c` (last `R`); `None` is zero.
#[derive(Clone, Default)]
pub struct BodyLoads<const D: usize> {
    /// One optional field per generalised component.
    pub fields: Vec<Option<Field<D>>>,
}

impl<const D: usize> BodyLoads<D> {
    /// No body loads.
    pub fn none() -> Self {
        Self {
            fields: vec![None; crate::material::components(D)],
        }
    }

    /// Set component `k` (force for `k < D`, couple for `k ≥ D`).
    pub fn with(mut self, k: usize, value: Field<D>) -> Self {
        self.fields[k] = Some(value);
        self
    }

    /// Whether every component is absent.
    pub fn is_empty(&self) -> bool {
        self.fields.iter().all(Option::is_none)
    }
}

impl<const D: usize> std::fmt::Debug for BodyLoads<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let set: Vec<bool> = self.fields.iter().map(Option::is_some).collect();
        f.debug_struct("BodyLoads").field("set", &set).finish()
    }
}
