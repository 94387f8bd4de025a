//! What a coupling scheme carries from one step to the next: the matrices of its factors,
//! the step they were built for and the change of a low-rank update. A run that saves it
//! after a step and gives it to a scheme built anew ([`crate::Scheme::resume`]) goes on
//! with the same factors, hence the same iterates bit for bit, as the run never stopped.
//! The factors themselves are not saved: they are computed again from the saved matrices
//! (a numeric factorization of the same values gives the same factors), and that
//! factorization is not counted in [`super::CouplingStats`].

/// The state of a coupling scheme between steps (see the module docs). Empty vectors
/// mean "none yet".
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SchemeMemory {
    /// The matrix of the current factors: the coupled matrix (monolithic, upper
    /// triangle) or the flow matrix `diag(d) + Δt A` (split schemes).
    pub factored: Vec<f64>,
    /// The monolithic scheme's current matrix, which differs from `factored` by the
    /// low-rank change (empty for the split schemes).
    pub current: Vec<f64>,
    /// The stiffness of the split schemes' mechanics factorization.
    pub stiffness: Vec<f64>,
    /// `Δt` of the current matrix (a later step within rounding of it takes it exactly).
    pub dt: Option<f64>,
    /// The monolithic pressure scale of the factors.
    pub scale: f64,
    /// The unknowns whose columns of the inverse the low-rank update holds, in the order
    /// computed.
    pub columns: Vec<usize>,
    /// The right-hand side and forward sweep of the last low-rank solve with the current
    /// factors.
    pub forward: Option<(Vec<f64>, Vec<f64>)>,
    /// Relative residual of the first solve with the current factors.
    pub residual: f64,
    /// Matrices solved by a low-rank update so far.
    pub updates: usize,
}
