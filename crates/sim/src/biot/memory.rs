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

impl SchemeMemory {
    /// The memory of a split scheme (fixed-stress, explicit pressure): the flow matrix of
    /// its factors with its `Δt`, and the mechanics stiffness.
    pub(super) fn of_split(
        flow: &super::flow_solve::FlowSolver,
        mech: &super::mech_solve::MechSolver,
    ) -> Self {
        let (factored, dt) = flow.memory();
        Self {
            factored,
            dt,
            stiffness: mech.memory(),
            ..Self::default()
        }
    }

    /// Give a split scheme's solvers this memory: their factors are computed again
    /// before the next solve.
    pub(super) fn resume_split(
        self,
        flow: &mut super::flow_solve::FlowSolver,
        mech: &mut super::mech_solve::MechSolver,
    ) {
        flow.resume(self.factored, self.dt);
        mech.resume(self.stiffness);
    }
}
