//! Boundary conditions and loads, as plain descriptions.
//!
//! * [`Displacement`]: prescribed components `u_a = g_a(x, t)` at the nodes of a set of
//!   faces; a component given as `None` is free.
//! * [`Platen`]: a rigid loading platen. All nodes of its faces share one displacement
//!   along each loaded component, and the total force `F_a(t)` acts on that shared
//!   equation (2D: per metre of thickness). A component given as `None` is not touched
//!   by the platen.
//! * [`Traction`]: a traction vector `t(x, t)` (Pa, global components) on boundary faces.
//! * [`Loads`]: body force per unit volume `b(x, t)`, gravity `ρ_K g`, tractions.
//!
//! How they enter the discrete equations is described in [`crate::dofs`] and
//! [`crate::assembly`].

use porofrac_grid::Point;

use crate::field::{ScalarField, VectorField};

/// Prescribed displacement components on the nodes of a set of faces.
#[derive(Clone, Debug)]
pub struct Displacement<const D: usize> {
    /// A name for messages (the boundary or tag name).
    pub name: String,
    /// The faces whose nodes are constrained.
    pub faces: Vec<usize>,
    /// Per component: the prescribed value, or `None` for free.
    pub components: [Option<ScalarField>; D],
}

/// A rigid platen: the nodes of `faces` share one displacement per loaded component.
#[derive(Clone, Debug)]
pub struct Platen<const D: usize> {
    /// A name for messages (the boundary or tag name).
    pub name: String,
    /// The faces whose nodes move together.
    pub faces: Vec<usize>,
    /// Per component: the total force on the platen (evaluated at the mean position of its
    /// nodes), or `None` for a component the platen leaves free.
    pub force: [Option<ScalarField>; D],
}

/// A traction (force per unit area, global components) on boundary faces.
#[derive(Clone, Debug)]
pub struct Traction<const D: usize> {
    /// A name for messages (the boundary or tag name).
    pub name: String,
    /// Boundary faces carrying the traction.
    pub faces: Vec<usize>,
    /// Components of the traction vector.
    pub traction: [ScalarField; D],
}

/// Gravity: the body force `ρ_K g` with one density per cell.
#[derive(Clone, Debug)]
pub struct Gravity<const D: usize> {
    /// Acceleration of gravity (m/s²).
    pub g: Point<D>,
    /// Density of each cell (kg/m³).
    pub density: Vec<f64>,
}

/// The external loads of a mechanics problem.
#[derive(Clone, Debug, Default)]
pub struct Loads<const D: usize> {
    /// Body force per unit volume (N/m³).
    pub body_force: Option<VectorField<D>>,
    /// Gravity with per-cell density.
    pub gravity: Option<Gravity<D>>,
    /// Tractions on boundary faces.
    pub tractions: Vec<Traction<D>>,
}

impl<const D: usize> Loads<D> {
    /// Whether every load is a constant field ([`ScalarField::Const`] components; gravity
    /// always is): then the nodal loads do not depend on time.
    pub fn is_time_independent(&self) -> bool {
        self.body_force
            .as_ref()
            .is_none_or(|b| b.as_const().is_some())
            && self
                .tractions
                .iter()
                .all(|t| t.traction.iter().all(|c| c.as_const().is_some()))
    }
}
