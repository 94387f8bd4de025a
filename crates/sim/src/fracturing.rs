//! Fracturing of a poroelastic body: failure criteria, law switching, fracture
//! permeability and the coupled step (Nilsen et al. (2017) §2.5–2.7).
//!
//! # The model
//!
//! Every cell has an intact law (VEM, MDEM, ...) and a failure criterion on its
//! effective (skeleton) stress, tension positive ([`porofrac_frac::Combined`]: tensile,
//! Nilsen et al. (2017) eq. 31, Mohr–Coulomb, and at crack tips the toughness of
//! [`porofrac_frac::toughness`]). A cell that fails stays failed: its law switches to the
//! post-failure law of its instance (a failed MDEM cell becomes the compression-only
//! central-force DEM of eqs. 32–33 of Nilsen et al. (2017); a law without a post-failure law
//! keeps its own)
//! and, when a fracture permeability is set ([`FracturePermeability`]: one value, or a
//! crack transmissivity shared over the cell's width), its permeability becomes that
//! value so the fluid enters the fracture.
//!
//! **Fluid lag.** An intact cell keeps the rock's permeability, so the cell ahead of a
//! crack tip opens undrained: in a tight rock its pressure falls far below the crack's
//! (the suction `Δp ≈ −M α ε_v`, `M` the Biot modulus) and holds the tip shut in
//! effective stress, by an amount that grows as the cells shrink. With
//! [`FractureFlow::zero_lag`] the intact cells across a face from a failed cell take the
//! fracture permeability as well: the fluid front sits at the crack tip, the assumption of
//! the classical plane-strain and toughness-dominated hydraulic-fracture solutions
//! (Detournay 2004), and the tip fails once the crack's pressure and the tip's stress
//! intensity ([`porofrac_frac::toughness`]) are enough.
//!
//! # One time step
//!
//! From the state `(uⁿ, pⁿ)` at `t` to `t + Δt`, with the failure state `F`:
//!
//! 1. **Coupled solve** for the current `F`: the laws of `F`, the permeability of `F`,
//!    then an *active-set* iteration: linearize at `uⁿ` (in a later failure round of the
//!    step, at the solution of the previous round: its active set differs only near the
//!    cells just failed), take the coupled step
//!    (monolithic, fixed-stress or explicit-pressure, [`crate::biot`]), re-linearize at
//!    the new displacement ([`BiotSystem::linearize`]) and repeat until the stiffness at
//!    the solution is the one used (the compression-only law is piecewise linear, so that
//!    solution is exact) or the nonlinear equilibrium residual is below
//!    [`FractureSettings::active_set_tolerance`] (an edge that chatters across `U = 0`
//!    carries almost no force). When a full step does not reduce the residual (edges
//!    flipping open and closed, "chatter"), the step is backtracked (halved, down to 1/64)
//!    between the best iterate and the new one: both satisfy the linear flow equations,
//!    so every point between them does, and the next linearization is taken there. More than [`FractureSettings::max_active_set`] iterations
//!    is an error ([`FractureError::ActiveSet`]) naming the time and the residual.
//! 2. **Failure check** on the cells that have not failed, on the cell stress or the
//!    recovered (Zienkiewicz–Zhu) stress ([`StressMeasure`]); the violating cells chosen
//!    by the [`FailurePolicy`] fail at `t + Δt`, and the step is solved again from
//!    `(uⁿ, pⁿ)` ([`porofrac_frac::resolve()`]) until no cell fails: a step never ends half
//!    updated. More than [`FractureSettings::max_rounds`] rounds is an error.
//!
//! The initial state ([`Fracturing::initial_state`]) is the mechanical equilibrium with
//! the loads at `t₀` and `p = p₀` (the coupling acts on `p − p₀`), with the same failure
//! resolution.

use porofrac_flow::{FlowError, FlowModel, Permeability};
use porofrac_frac::recovery::{NodeCells, StressRecovery, cell_average};
use porofrac_frac::{
    CellCriteria, Combined, CrackTips, CrackTracking, FailurePolicy, FailureState, ResolveError,
    resolve,
};
use porofrac_grid::{Grid, Point};
use porofrac_law::{CellGeometry, CellLaw, Scratch, Tensor};
use rayon::prelude::*;

use crate::bc::Loads;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::assembly::{ElementCache, law_error};
use crate::biot::{
    BiotCoupling, BiotError, BiotState, BiotSystem, CouplingStats, ExplicitPressure, FixedStress,
    Monolithic, Operators, SchemeMemory,
};
use crate::dofs::DofMap;
use crate::error::SimError;
use crate::laws::LawMap;
use crate::pattern::Pattern;
use crate::solve::StaticProblem;
use crate::stress_cache::StressCache;

/// Errors of the fracturing driver.
#[derive(Debug, thiserror::Error)]
pub enum FractureError {
    /// The coupled solve failed.
    #[error("{0}")]
    Biot(#[from] BiotError),
    /// The mechanics (laws, assembly, stresses) failed.
    #[error("mechanics: {0}")]
    Mechanics(#[from] SimError),
    /// The flow model rejected the fracture permeability.
    #[error("flow: {0}")]
    Flow(#[from] FlowError),
    /// Invalid input (naming what).
    #[error("invalid input: {0}")]
    Input(String),
    /// The active set of the piecewise-linear laws did not settle.
    #[error(
        "the open/closed state of fractured cells did not settle at t = {time} s after \
         {iterations} solves (relative equilibrium residual {residual:.3e} > {tolerance:.1e})"
    )]
    ActiveSet {
        /// Time at the end of the step.
        time: f64,
        /// Solves done.
        iterations: usize,
        /// The last relative residual.
        residual: f64,
        /// The tolerance.
        tolerance: f64,
    },
    /// Failures kept appearing.
    #[error(
        "failures did not settle within {rounds} solves at t = {time} s ({failed} cells failed)"
    )]
    NotSettled {
        /// Rounds done.
        rounds: usize,
        /// Time.
        time: f64,
        /// Cells failed so far.
        failed: usize,
    },
    /// A stop was requested (the flag of [`Fracturing::set_interrupt`]) between two
    /// solves of a step.
    #[error("interrupted")]
    Interrupted,
}

/// Result alias of this module.
pub type FractureResult<T> = std::result::Result<T, FractureError>;

/// The stress the failure criteria see.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StressMeasure {
    /// The cell stress of the law (constant per cell).
    #[default]
    Cell,
    /// The cell average of the Zienkiewicz–Zhu recovered nodal stress (Nilsen et al.
    /// (2017) Fig. 5).
    Recovered,
}

/// The laws of a fracturing body: instances, the intact instance of every cell and the
/// post-failure instance of every instance.
pub struct FractureLaws<'a, const D: usize> {
    /// Law instances.
    pub laws: Vec<&'a dyn CellLaw<D>>,
    /// The intact law instance of every cell.
    pub law_of_cell: Vec<usize>,
    /// For every instance, the instance a failed cell switches to (itself: no switch).
    pub post_failure: Vec<usize>,
}

impl<'a, const D: usize> FractureLaws<'a, D> {
    /// The law map for the failure flags `failed` (one per cell).
    pub fn law_map(&self, grid: &Grid<D>, failed: &[bool]) -> FractureResult<LawMap<'a, D>> {
        let of: Vec<usize> = self
            .law_of_cell
            .iter()
            .zip(failed)
            .map(|(&l, &f)| if f { self.post_failure[l] } else { l })
            .collect();
        Ok(LawMap::new(grid, self.laws.clone(), of)?)
    }
}

/// Failure criteria and iteration limits.
#[derive(Clone, Debug)]
pub struct FractureSettings {
    /// Criterion of every class (an empty [`Combined`] never fails).
    pub criteria: Vec<Combined>,
    /// The class of every cell.
    pub class_of_cell: Vec<usize>,
    /// Which violating cells fail per round.
    pub policy: FailurePolicy,
    /// The stress the criteria see.
    pub stress: StressMeasure,
    /// Crack tracking: the largest angle (degrees) between a crack's growth and the plane
    /// normal to `σ₁` ([`porofrac_frac::tracking`]); `None`: no tracking.
    pub tracking_angle: Option<f64>,
    /// Crack tracking: no new crack nucleates within this distance (m) of a failed cell
    /// ([`CrackTracking::with_exclusion_radius`]); 0: only the cells next to a crack are
    /// excluded.
    pub exclusion_radius: f64,
    /// Failure rounds (coupled solves with a new failure state) allowed per step.
    pub max_rounds: usize,
    /// Active-set iterations allowed per coupled solve.
    pub max_active_set: usize,
    /// Relative equilibrium residual accepted when the active set has not settled.
    pub active_set_tolerance: f64,
    /// How a crack-tip cell's stress intensity is measured for the toughness.
    pub tip: TipRule,
}

/// How the stress intensity of a crack-tip cell (an intact cell sharing a node with a
/// failed cell, of a class with a toughness) is measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum TipRule {
    /// From the tip cell's own stress: `K_c = σ₁ √(2π r_c)` ([`porofrac_frac::toughness`]).
    #[default]
    Stress,
    /// From the opening of the failed cell next to it (displacement correlation,
    /// [`crate::tip_opening`]), with the plane-strain modulus `E/(1 − ν²)` (Pa) of every
    /// cell: the tip cell fails exactly when that `K_I` exceeds `K_Ic`, whatever its own
    /// stress and tensile strength (the strength still governs the cells away from tips).
    Opening(Vec<f64>),
    /// From the opening at a fixed distance behind the tip, for a crack through
    /// unstructured cells ([`crate::tip_distance`]): an intact cell ahead of a tip fails
    /// when that `K_I` exceeds `K_Ic`; one beside a crack is held; one next to a crack
    /// that does not reach the distance behind it (a crack of a few cells at a wall) fails
    /// by its tensile strength, as away from cracks. The measure keeps the principal
    /// directions of the cell's own stress, which crack tracking reads. Under the
    /// policy [`FailurePolicy::MostCritical`] the cells fail per round by the largest
    /// utilization within the distance of them ([`FailurePolicy::MostCriticalNear`]):
    /// the most critical cell of every tip, so the tips of a crack under one pressure
    /// grow together when each reads more than `K_Ic` ([`crate::tip_distance`], "Which
    /// tips grow").
    OpeningAt {
        /// `E′ = E/(1 − ν²)` (Pa) of every cell.
        e_prime: Vec<f64>,
        /// The distance `r` (m) behind the tip where the opening is read.
        distance: f64,
    },
    /// From the opening behind the tip read with the regime's tip asymptote
    /// ([`crate::tip_asymptote`]): the front's position and speed follow from the opening
    /// on the back line ([`crate::tip_opening`]), and the tip cell fails when the front
    /// lies beyond the tip. The plane-strain modulus `E/(1 − ν²)` (Pa) of every cell and the
    /// fluid's `μ′ = 12 μ` (Pa·s).
    Asymptote {
        /// `E′` (Pa) of every cell.
        e_prime: Vec<f64>,
        /// `μ′ = 12 μ` (Pa·s).
        mu_prime: f64,
    },
}

impl FractureSettings {
    /// The policy the resolution applies: [`Self::policy`], except that
    /// [`TipRule::OpeningAt`] takes [`FailurePolicy::MostCritical`] near each cell, within
    /// its sample distance.
    pub fn policy_of_rule(&self) -> FailurePolicy {
        match (&self.tip, self.policy) {
            (TipRule::OpeningAt { distance, .. }, FailurePolicy::MostCritical { fraction }) => {
                FailurePolicy::MostCriticalNear {
                    fraction,
                    radius: *distance,
                }
            }
            (_, policy) => policy,
        }
    }

    /// Settings with the given criteria, default policy, cell stress, 500 rounds, 30
    /// active-set iterations and tolerance 1e-6.
    pub fn new(criteria: Vec<Combined>, class_of_cell: Vec<usize>) -> Self {
        Self {
            criteria,
            class_of_cell,
            policy: FailurePolicy::default(),
            stress: StressMeasure::Cell,
            tracking_angle: None,
            exclusion_radius: 0.0,
            max_rounds: 500,
            max_active_set: 30,
            active_set_tolerance: 1e-6,
            tip: TipRule::Stress,
        }
    }
}

/// Failure resolution within a step, shared by every driver that fractures (the coupled
/// [`Fracturing`] and the static mechanics of the scenes): the settings, the stress
/// measure (cell or recovered), crack tracking and the round limit live here once.
pub struct FailureResolution<const D: usize> {
    settings: FractureSettings,
    /// The recovery operator, when the criteria read the recovered stress.
    recovery: Option<StressRecovery>,
    tracking: Option<CrackTracking<D>>,
    /// Crack-tip cells, when a criterion has a toughness.
    tips: Option<CrackTips>,
}

/// A step with its failures resolved: the solution and its cell stresses, the cells
/// failed in the step and the solves done.
pub struct Resolved<S, const D: usize> {
    /// The solution of the last solve and its cell stresses (effective, tension positive).
    pub solution: (S, Vec<Tensor<D>>),
    /// Cells failed in this step.
    pub new_failures: usize,
    /// Solves done (1: nothing failed).
    pub rounds: usize,
}

/// The error of [`FailureResolution::resolve`]: the solver's, or failures that did not
/// settle within [`FractureSettings::max_rounds`].
pub type ResolutionError<E> = ResolveError<E>;

impl<const D: usize> FailureResolution<D> {
    /// Resolution with `settings` on `grid`; an error describes an invalid tracking angle.
    pub fn new(grid: &Grid<D>, settings: FractureSettings) -> Result<Self, String> {
        let can_fail = settings.criteria.iter().any(|c| !c.is_empty());
        let recovery = (can_fail && settings.stress == StressMeasure::Recovered)
            .then(|| StressRecovery::new(grid, &NodeCells::new(grid)));
        let tracking = match (can_fail, settings.tracking_angle) {
            (true, Some(a)) => Some(
                CrackTracking::new(grid, a)
                    .and_then(|t| t.with_exclusion_radius(settings.exclusion_radius))
                    .map_err(|e| e.to_string())?,
            ),
            _ => None,
        };
        let tips = (can_fail && settings.criteria.iter().any(|c| c.toughness.is_some()))
            .then(|| CrackTips::new(grid));
        Ok(Self {
            settings,
            recovery,
            tracking,
            tips,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &FractureSettings {
        &self.settings
    }

    /// The crack tracking, when the settings track cracks (its recorded cracks are the
    /// state it carries between steps).
    pub fn tracking(&self) -> Option<&CrackTracking<D>> {
        self.tracking.as_ref()
    }

    /// The crack tracking, to put back the cracks of an earlier run
    /// ([`CrackTracking::restore`]).
    pub fn tracking_mut(&mut self) -> Option<&mut CrackTracking<D>> {
        self.tracking.as_mut()
    }

    /// Whether any cell has a failure criterion (else [`Self::resolve`] solves once and
    /// needs no stresses).
    pub fn can_fail(&self) -> bool {
        self.settings.criteria.iter().any(|c| !c.is_empty())
    }

    /// Solve, check the criteria on the chosen stress measure, fail and re-solve at time
    /// `t` until no cell fails ([`porofrac_frac::resolve()`]). `solve` gets the failure
    /// state and returns a solution and its cell stresses (which may be empty when
    /// [`Self::can_fail`] is false).
    pub fn resolve<S, E>(
        &mut self,
        grid: &Grid<D>,
        failures: &mut FailureState,
        t: f64,
        mut solve: impl FnMut(&FailureState) -> Result<(S, Vec<Tensor<D>>), E>,
    ) -> Result<Resolved<S, D>, ResolutionError<E>> {
        let can_fail = self.can_fail();
        if !can_fail {
            // Nothing can fail: one solve, its stresses (if any) passed on as they are.
            let solution = solve(failures).map_err(ResolutionError::Solve)?;
            return Ok(Resolved {
                solution,
                new_failures: 0,
                rounds: 1,
            });
        }
        let recovery = &self.recovery;
        let ((solution, stress), _, new_failures, rounds) = resolve(
            failures,
            t,
            CellCriteria {
                criteria: &self.settings.criteria,
                class_of_cell: &self.settings.class_of_cell,
                tips: self.tips.as_ref(),
                centroids: Some(grid.cell_centroids()),
            },
            self.settings.policy_of_rule(),
            self.tracking.as_mut(),
            if can_fail {
                self.settings.max_rounds
            } else {
                1
            },
            |fs| {
                let (sol, stress) = solve(fs)?;
                let measure = match recovery {
                    Some(r) => cell_average(grid, &r.nodal(&stress)),
                    None => stress.clone(),
                };
                Ok(((sol, stress), measure))
            },
        )?;
        Ok(Resolved {
            solution: (solution, stress),
            new_failures,
            rounds,
        })
    }
}

/// The coupling scheme of a [`Fracturing`] run.
pub enum Scheme {
    /// Fully implicit monolithic (Nilsen et al. (2017) eq. 30).
    Monolithic(Monolithic),
    /// Fixed-stress split; needs the drained bulk modulus of every cell.
    FixedStress(FixedStress, Vec<f64>),
    /// The explicit-pressure update of Nilsen et al. (2017) §2.5: the volumetric term in the
    /// failed cells and in the cells flagged here (e.g. the injection cells).
    ExplicitPressure(ExplicitPressure, Vec<bool>),
}

impl Scheme {
    fn name(&self) -> &'static str {
        match self {
            Scheme::Monolithic(_) => "monolithic",
            Scheme::FixedStress(..) => "fixed-stress",
            Scheme::ExplicitPressure(..) => "explicit-pressure",
        }
    }

    /// What the linear algebra of the scheme did (see [`CouplingStats`]).
    pub fn stats(&self) -> CouplingStats {
        match self {
            Scheme::Monolithic(m) => m.stats(),
            Scheme::FixedStress(f, _) => f.stats(),
            Scheme::ExplicitPressure(e, _) => e.stats(),
        }
    }

    /// What the scheme carries from one step to the next (see [`SchemeMemory`]).
    pub fn memory(&self) -> SchemeMemory {
        match self {
            Scheme::Monolithic(m) => m.memory(),
            Scheme::FixedStress(f, _) => f.memory(),
            Scheme::ExplicitPressure(e, _) => e.memory(),
        }
    }

    /// Go on from `memory` (of a scheme of the same kind on the same system).
    pub fn resume(&mut self, memory: SchemeMemory) {
        match self {
            Scheme::Monolithic(m) => m.resume(memory),
            Scheme::FixedStress(f, _) => f.resume(memory),
            Scheme::ExplicitPressure(e, _) => e.resume(memory),
        }
    }
}

/// The mechanics of the body: grid, dof map, pattern and loads.
#[derive(Clone, Copy)]
pub struct Body<'a, const D: usize> {
    /// The grid.
    pub grid: &'a Grid<D>,
    /// Dof map (conditions).
    pub dofs: &'a DofMap<D>,
    /// Stiffness pattern.
    pub pattern: &'a Pattern,
    /// Loads.
    pub loads: &'a Loads<D>,
}

/// The flow of the body with its permeability before and after failure.
pub struct FractureFlow<const D: usize> {
    /// The flow model (its permeability is updated as cells fail).
    pub model: FlowModel<D>,
    /// The intact permeability of every cell.
    pub permeability: Permeability<D>,
    /// The isotropic permeability of failed cells; `None` keeps the intact value.
    pub fracture_permeability: Option<FracturePermeability>,
    /// No fluid lag: the intact cells across a face from a failed cell take the fracture
    /// permeability too, so the fluid front reaches the crack's tip (see the module docs).
    pub zero_lag: bool,
    /// Biot coefficient per cell.
    pub alpha: Vec<f64>,
    /// Initial pressure per cell.
    pub p0: Vec<f64>,
}

impl<const D: usize> FractureFlow<D> {
    /// The cells the crack's fluid fills: the failed cells and, without fluid lag
    /// ([`Self::zero_lag`]), the intact cells across a face from a failed cell. They take
    /// the fracture permeability, and the explicit-pressure coupling
    /// ([`ExplicitPressure::fractured`]) keeps their volumetric term.
    pub fn wet_cells(&self, grid: &Grid<D>, failed: &[bool]) -> Vec<bool> {
        wet_cells(grid, failed, self.zero_lag)
    }
}

/// The failed cells and, when `zero_lag`, their intact face neighbours
/// ([`FractureFlow::wet_cells`]).
fn wet_cells<const D: usize>(grid: &Grid<D>, failed: &[bool], zero_lag: bool) -> Vec<bool> {
    let mut wet = failed.to_vec();
    if zero_lag {
        for c in (0..failed.len()).filter(|&c| failed[c]) {
            for &face in grid.cell_faces(c) {
                if let (a, Some(b)) = grid.face_cells(face) {
                    wet[if a == c { b } else { a }] = true;
                }
            }
        }
    }
    wet
}

/// The permeability a cell takes when it fails.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FracturePermeability {
    /// The same permeability `k` (m²) in every failed cell: the crack's transmissivity
    /// `k·w` then scales with the width `w` of the band of failed cells, i.e. with the
    /// cell size.
    Fixed(f64),
    /// A crack transmissivity `T` (m³, `k·w` of the crack per unit length, `w³/12` for a
    /// parallel-plate aperture `w`): a failed cell of equivalent radius `r_c` (the disk or
    /// ball of its area or volume) takes `k = T / (2 r_c)`, so the band of failed cells,
    /// about `2 r_c` wide, conducts `T` on every grid.
    Transmissivity(f64),
    /// The cubic law from the crack's own opening ([`crate::crack_flow`]): a wet cell of
    /// aperture `w` and thickness `h_n` across the opening takes
    /// `k = max(w³/12, T_min) / h_n`, with `T_min` (m³) the value given, the
    /// transmissivity of a closed or just-failed crack. The aperture is measured at the
    /// displacement of the start of each step (the initial equilibrium: none), so the
    /// permeability lags the opening by one step. A failed cell's Biot coefficient
    /// becomes 1: the crack stores the volume it opens (the coupling data are rebuilt
    /// when cells fail).
    CubicLaw(f64),
}

impl FracturePermeability {
    /// The permeability (m²) of a failed cell of area or volume `v`.
    /// For [`Self::CubicLaw`] this is the floor `T_min / (2 r_c)` of a crack that has not
    /// opened ([`crate::crack_flow::cubic_law_permeability`] gives the value of an opening).
    pub fn of_cell<const D: usize>(self, v: f64) -> f64 {
        match self {
            Self::Fixed(k) => k,
            Self::Transmissivity(t) | Self::CubicLaw(t) => {
                t / (2.0 * porofrac_frac::toughness::equivalent_radius::<D>(v))
            }
        }
    }

    fn value(self) -> f64 {
        match self {
            Self::Fixed(v) | Self::Transmissivity(v) | Self::CubicLaw(v) => v,
        }
    }
}

/// The result of one step.
#[derive(Clone, Debug)]
pub struct FractureStep<const D: usize> {
    /// The state at the end of the step.
    pub state: BiotState,
    /// Cell stresses of the laws at that state (effective, tension positive).
    pub stress: Vec<Tensor<D>>,
    /// Cells failed in this step.
    pub new_failures: usize,
    /// Coupled solves with a new failure state (1: nothing failed).
    pub rounds: usize,
    /// Linear coupled solves (all rounds and active-set iterations).
    pub solves: usize,
    /// Largest relative equilibrium residual accepted. When every law is linear there is
    /// no active set to settle (the stiffness does not depend on the displacement), and
    /// this is the residual of the coupled step ([`crate::BiotStep::residual`]).
    pub residual: f64,
    /// The change of the void of every cell over the step (m³; m² in 2D) under a
    /// cavitation bound ([`Fracturing::set_cavitation_pressure`]); empty without one.
    pub void_change: Vec<f64>,
}

/// A fracturing poroelastic body advanced step by step (see the module docs).
pub struct Fracturing<'a, const D: usize> {
    body: Body<'a, D>,
    laws: FractureLaws<'a, D>,
    flow: FractureFlow<D>,
    scheme: Scheme,
    failures: FailureState,
    resolution: FailureResolution<D>,
    perm_of_failed: Vec<bool>,
    /// The coupling data (α, `p₀`, node normals), built once.
    operators: Arc<Operators<D>>,
    /// The node coordinates of every cell, aligned with the node normals of `operators`.
    coords: Vec<Point<D>>,
    /// The law map and the assembled stiffness of the last failure state solved.
    cached: Option<Cached<'a, D>>,
    /// The stiffness of the cells with a linear intact law (assembled once).
    elements: Arc<ElementCache>,
    /// The stress operators of the cells with a linear law (built at the first solve).
    stress_cache: Option<StressCache>,
    /// Polled before every solve of a step (failure rounds, active-set iterations).
    interrupt: Option<Arc<AtomicBool>>,
    /// The tip rule [`TipRule::Opening`], when chosen.
    opening_tips: Option<OpeningTips>,
    /// The cavitation pressure bounding the pore pressure below (Pa), when set.
    cavitation: Option<f64>,
    /// The void of every cell (m³; m² in 2D) at the end of the last step.
    void: Vec<f64>,
    /// The responses of cavitating cells kept between steps.
    responses: crate::cavitation::ResponseCache,
}

/// What [`TipRule::Opening`] needs at every failure check: the plane-strain modulus, the
/// toughness and tensile strength of every cell's class, the tip cells and the cells of
/// every node.
struct OpeningTips {
    e_prime: Vec<f64>,
    /// `(K_Ic, σ_t)` of every criterion class (`None`: no toughness or no strength).
    class: Vec<Option<(f64, f64)>>,
    class_of_cell: Vec<usize>,
    tips: CrackTips,
    adjacency: NodeCells,
    /// `μ′` of [`TipRule::Asymptote`] (`None`: [`TipRule::Opening`]).
    mu_prime: Option<f64>,
    /// The fronts at the end of the last step ([`TipRule::Asymptote`]).
    fronts: crate::tip_asymptote::FrontMemory,
    /// The distance of [`TipRule::OpeningAt`] (m).
    distance: Option<f64>,
}

impl OpeningTips {
    fn new<const D: usize>(
        grid: &Grid<D>,
        settings: &FractureSettings,
    ) -> FractureResult<Option<Self>> {
        let mut distance = None;
        let (e_prime, mu_prime) = match &settings.tip {
            TipRule::Stress => return Ok(None),
            TipRule::Opening(e_prime) => (e_prime, None),
            TipRule::OpeningAt {
                e_prime,
                distance: r,
            } => {
                if !(r.is_finite() && *r > 0.0) {
                    return Err(FractureError::Input(format!(
                        "sample distance of the tip rule must be finite and > 0, got {r}"
                    )));
                }
                distance = Some(*r);
                (e_prime, None)
            }
            TipRule::Asymptote { e_prime, mu_prime } => {
                if !(mu_prime.is_finite() && *mu_prime >= 0.0) {
                    return Err(FractureError::Input(format!(
                        "fluid viscosity of the tip rule must be finite and >= 0, got {mu_prime}"
                    )));
                }
                (e_prime, Some(*mu_prime))
            }
        };
        if e_prime.len() != grid.num_cells() {
            return Err(FractureError::Input(format!(
                "plane-strain modulus of the tip rule: length {}, want {}",
                e_prime.len(),
                grid.num_cells()
            )));
        }
        if let Some(c) = e_prime.iter().position(|e| !(e.is_finite() && *e > 0.0)) {
            return Err(FractureError::Input(format!(
                "cell {c}: plane-strain modulus of the tip rule must be finite and > 0"
            )));
        }
        if settings.stress == StressMeasure::Recovered {
            return Err(FractureError::Input(
                "the tip rule from the opening reads the cell stress away from tips; \
                 it cannot be combined with the recovered stress"
                    .into(),
            ));
        }
        Ok(Some(Self {
            e_prime: e_prime.clone(),
            class: settings
                .criteria
                .iter()
                .map(|c| match (&c.toughness, &c.tensile) {
                    (Some(k), Some(t)) => Some((k.value(), t.strength())),
                    _ => None,
                })
                .collect(),
            class_of_cell: settings.class_of_cell.clone(),
            tips: CrackTips::new(grid),
            adjacency: NodeCells::new(grid),
            mu_prime,
            fronts: Default::default(),
            distance,
        }))
    }

    /// The stress the criteria see: `stress`, except at the intact tip cells of a class
    /// with a toughness, which get the isotropic stress `(K_I/K_Ic) · S · I` with
    /// `S = max(σ_t, K_Ic/√(2π r_c))`: its tensile utilization (the smaller of `σ₁/σ_t`
    /// and `σ₁ √(2π r_c)/K_Ic`) is `K_I/K_Ic`, with `K_I` from the opening
    /// ([`crate::tip_opening`]) at the nodal displacement `u`.
    ///
    /// With [`TipRule::Asymptote`] the utilization is instead `d/r`: the distance `d` from
    /// the back line to the front over the step `dt` against the distance `r` to the tip
    /// ([`crate::tip_asymptote`]).
    ///
    /// With [`TipRule::OpeningAt`] the tip cell's own stress is shifted by a multiple of
    /// `I` (its principal directions kept, for crack tracking) so that its `σ₁` is `u S`,
    /// the utilization `u` being `K_I/K_Ic` ahead of a tip ([`crate::tip_distance`]),
    /// `σ₁/σ_t` of the unshifted stress next to a crack too short to sample, and 0 beside
    /// a crack.
    fn measure<const D: usize>(
        &self,
        grid: &Grid<D>,
        failed: &[bool],
        stress: &[Tensor<D>],
        u: &[f64],
        dt: f64,
    ) -> Vec<Tensor<D>> {
        let mut out = stress.to_vec();
        for (c, s) in out.iter_mut().enumerate() {
            if failed[c] {
                continue;
            }
            let Some((k_ic, sigma_t)) = self.class[self.class_of_cell[c]] else {
                continue;
            };
            let Some(r) = self.tips.tip_radius(c, failed) else {
                continue;
            };
            let reference = sigma_t.max(k_ic / (2.0 * std::f64::consts::PI * r).sqrt());
            if let Some(distance) = self.distance {
                let sigma_1 = porofrac_law::principal(s).values[0];
                let utilization = match crate::tip_distance::read_tip(
                    grid,
                    &self.adjacency,
                    failed,
                    c,
                    u,
                    distance,
                ) {
                    crate::tip_distance::TipReading::Ahead(sample) => {
                        sample.stress_intensity(self.e_prime[c]) / k_ic
                    }
                    crate::tip_distance::TipReading::Short => sigma_1 / sigma_t,
                    crate::tip_distance::TipReading::Beside => 0.0,
                };
                *s += Tensor::<D>::identity() * (utilization * reference - sigma_1);
                continue;
            }
            let k = match self.mu_prime {
                None => crate::tip_opening::tip_stress_intensity(
                    grid,
                    &self.adjacency,
                    failed,
                    c,
                    self.e_prime[c],
                    u,
                )
                .unwrap_or(0.0),
                Some(mu_prime) => self
                    .front(grid, failed, c, u, dt, k_ic, mu_prime)
                    .map_or(0.0, |(f, s)| {
                        k_ic * (f.position - (s.tip.dot(&s.along) - s.distance)) / s.distance
                    }),
            };
            *s = Tensor::<D>::identity() * (k.max(0.0) / k_ic * reference);
        }
        out
    }
}

impl OpeningTips {
    /// The front ahead of the intact cell `c` over a step of `dt` and its opening sample
    /// ([`crate::tip_asymptote`]), or `None` when `c` is not ahead of a tip.
    #[allow(clippy::too_many_arguments)]
    fn front<const D: usize>(
        &self,
        grid: &Grid<D>,
        failed: &[bool],
        c: usize,
        u: &[f64],
        dt: f64,
        k_ic: f64,
        mu_prime: f64,
    ) -> Option<(
        crate::tip_asymptote::Front,
        crate::tip_opening::TipSample<D>,
    )> {
        let s = crate::tip_opening::tip_sample(grid, &self.adjacency, failed, c, u)?;
        let asymptote = crate::tip_asymptote::TipAsymptote {
            k_prime: crate::tip_asymptote::k_prime(k_ic),
            e_prime: self.e_prime[c],
            mu_prime,
        };
        let tip = s.tip.dot(&s.along);
        let previous = self
            .fronts
            .previous(&s.tip, &s.along, 2.0 * s.length)
            .unwrap_or(tip);
        let front = asymptote.front(s.opening.max(0.0), tip - s.distance, previous, dt);
        Some((front, s))
    }

    /// Remember the fronts ahead of every intact tip cell at the end of a step of `dt`
    /// (nothing without [`TipRule::Asymptote`] or for `dt ≤ 0`).
    fn remember_fronts<const D: usize>(
        &mut self,
        grid: &Grid<D>,
        failed: &[bool],
        u: &[f64],
        dt: f64,
    ) {
        let Some(mu_prime) = self.mu_prime else {
            return;
        };
        if dt <= 0.0 {
            return;
        }
        let mut points = Vec::new();
        for c in 0..grid.num_cells() {
            if failed[c] {
                continue;
            }
            let Some((k_ic, _)) = self.class[self.class_of_cell[c]] else {
                continue;
            };
            if self.tips.tip_radius(c, failed).is_none() {
                continue;
            }
            if let Some((f, s)) = self.front(grid, failed, c, u, dt, k_ic, mu_prime)
                && f.position.is_finite()
            {
                points.push(s.tip + s.along * (f.position - s.tip.dot(&s.along)));
            }
        }
        self.fronts = crate::tip_asymptote::FrontMemory::new(&points);
    }
}

/// A solve checked for failures: the state and its cell stresses, and the stress the
/// criteria see (the same, or with the tip cells of [`TipRule::Opening`]).
/// The solution carries the void change of its step (empty without a cavitation bound).
type Checked<const D: usize> = ((BiotState, Vec<Tensor<D>>, Vec<f64>), Vec<Tensor<D>>);

/// A failure state's law map and stiffness (at zero displacement).
struct Cached<'a, const D: usize> {
    flags: Vec<bool>,
    map: LawMap<'a, D>,
    stiffness: Option<Arc<[f64]>>,
}

impl<'a, const D: usize> Fracturing<'a, D> {
    /// Set up the run. `scheme` builds the coupling for the intact system (e.g.
    /// `|sys| Ok(Scheme::Monolithic(Monolithic::new(sys, None)?))`).
    ///
    /// Errors: lengths of the per-cell arrays, a class or post-failure index out of range,
    /// a failed law that does not support its cell, or an error of the scheme.
    pub fn new(
        body: Body<'a, D>,
        laws: FractureLaws<'a, D>,
        settings: FractureSettings,
        flow: FractureFlow<D>,
        scheme: impl FnOnce(&BiotSystem<'_, D>) -> FractureResult<Scheme>,
    ) -> FractureResult<Self> {
        let nc = body.grid.num_cells();
        let len = |what: &str, got: usize| {
            if got == nc {
                Ok(())
            } else {
                Err(FractureError::Input(format!(
                    "{what}: length {got}, want {nc}"
                )))
            }
        };
        len("law of cell", laws.law_of_cell.len())?;
        len("class of cell", settings.class_of_cell.len())?;
        if laws.post_failure.len() != laws.laws.len()
            || laws.post_failure.iter().any(|&l| l >= laws.laws.len())
        {
            return Err(FractureError::Input(
                "post-failure laws: one valid instance per law".into(),
            ));
        }
        if let Some(c) = settings
            .class_of_cell
            .iter()
            .position(|&k| k >= settings.criteria.len())
        {
            return Err(FractureError::Input(format!(
                "cell {c}: criterion class out of range"
            )));
        }
        if let Some(k) = flow.fracture_permeability
            && !(k.value().is_finite() && k.value() > 0.0)
        {
            return Err(FractureError::Input(format!(
                "fracture permeability must be finite and > 0, got {k:?}"
            )));
        }
        // Every cell must accept its failed law too.
        laws.law_map(body.grid, &vec![true; nc])?;
        let intact = laws.law_map(body.grid, &vec![false; nc])?;
        let system = BiotSystem::new(
            problem(&body, &intact),
            &flow.model,
            flow.alpha.clone(),
            flow.p0.clone(),
        )?;
        let scheme = scheme(&system)?;
        let elements = Arc::new(ElementCache::new(body.grid, &intact)?);
        let (operators, stiffness) = system.parts();
        drop(system);
        let cached = Some(Cached {
            flags: vec![false; nc],
            map: intact,
            stiffness: Some(stiffness),
        });
        let opening_tips = OpeningTips::new(body.grid, &settings)?;
        let resolution =
            FailureResolution::new(body.grid, settings).map_err(FractureError::Input)?;
        Ok(Self {
            body,
            laws,
            flow,
            scheme,
            failures: FailureState::new(nc),
            resolution,
            perm_of_failed: vec![false; nc],
            coords: (0..nc)
                .flat_map(|c| body.grid.cell_nodes(c).iter().map(|&n| *body.grid.node(n)))
                .collect(),
            operators,
            cached,
            elements,
            stress_cache: None,
            interrupt: None,
            opening_tips,
            cavitation: None,
            void: vec![0.0; nc],
            responses: crate::cavitation::ResponseCache::new(),
        })
    }

    /// Poll `flag` before every solve of a step — failure rounds, active-set iterations
    /// and the iterations of a fixed-stress scheme: when it is set, the step ends with
    /// [`FractureError::Interrupted`] and the state stays at the start of the step.
    pub fn set_interrupt(&mut self, flag: Option<Arc<AtomicBool>>) {
        if let Scheme::FixedStress(f, _) = &mut self.scheme {
            f.set_interrupt(flag.clone());
        }
        self.interrupt = flag;
    }

    /// Bound the pore pressure of every cell below by `p_cav` (Pa, absolute) from the next
    /// step on ([`crate::cavitation`]): a cell that would fall below it stays at it and
    /// the volume it opens without fluid is a void, booked per cell ([`Self::void`]).
    /// `None` (the default): no bound, the steps as without it, bit for bit.
    ///
    /// Errors: a non-finite pressure.
    pub fn set_cavitation_pressure(&mut self, p_cav: Option<f64>) -> FractureResult<()> {
        if let Some(p) = p_cav
            && !p.is_finite()
        {
            return Err(FractureError::Input(format!(
                "cavitation pressure must be finite, got {p}"
            )));
        }
        self.cavitation = p_cav;
        Ok(())
    }

    /// The cavitation pressure bounding the pore pressure, when set.
    pub fn cavitation_pressure(&self) -> Option<f64> {
        self.cavitation
    }

    /// The fronts of the tip rule [`TipRule::Asymptote`] at the end of the last step, as
    /// `D` coordinates per front (`None` with another rule).
    pub fn tip_fronts(&self) -> Option<&[f64]> {
        self.opening_tips
            .as_ref()
            .filter(|t| t.mu_prime.is_some())
            .map(|t| t.fronts.coordinates())
    }

    /// Resume the fronts of [`TipRule::Asymptote`] saved by [`Fracturing::tip_fronts`].
    ///
    /// Errors: another rule, or not `D` finite coordinates per front.
    pub fn resume_tip_fronts(&mut self, points: &[f64]) -> FractureResult<()> {
        let tips = self
            .opening_tips
            .as_mut()
            .filter(|t| t.mu_prime.is_some())
            .ok_or_else(|| {
                FractureError::Input(
                    "tip fronts saved, but the tip rule is not the asymptote".into(),
                )
            })?;
        tips.fronts =
            crate::tip_asymptote::FrontMemory::from_coordinates(D, points).ok_or_else(|| {
                FractureError::Input(format!(
                    "tip fronts: {} values, not {D} finite per front",
                    points.len()
                ))
            })?;
        Ok(())
    }

    /// The void of every cell (m³; m² per unit height in 2D) at the end of the last step:
    /// the volume opened at the cavitation pressure that fluid has not filled (all zero
    /// without a bound).
    pub fn void(&self) -> &[f64] {
        &self.void
    }

    /// Go on with the void `void` of every cell (m³; m² in 2D) of an earlier run of the
    /// same scene ([`Self::void`]).
    ///
    /// Errors: a length other than the number of cells, a negative or non-finite void.
    pub fn resume_void(&mut self, void: &[f64]) -> FractureResult<()> {
        if void.len() != self.void.len() {
            return Err(FractureError::Input(format!(
                "void of {} cells, the grid has {}",
                void.len(),
                self.void.len()
            )));
        }
        if let Some(c) = void.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(FractureError::Input(format!(
                "cell {c}: void must be finite and >= 0, got {}",
                void[c]
            )));
        }
        self.void.copy_from_slice(void);
        Ok(())
    }

    /// The failure state (flags and the log of failures).
    pub fn failures(&self) -> &FailureState {
        &self.failures
    }
    /// The failure resolution (its crack tracking carries state between steps).
    pub fn resolution(&self) -> &FailureResolution<D> {
        &self.resolution
    }
    /// The failure resolution, to put back its crack tracking ([`Self::resume`]).
    pub fn resolution_mut(&mut self) -> &mut FailureResolution<D> {
        &mut self.resolution
    }
    /// What the coupling scheme carries from one step to the next.
    pub fn scheme_memory(&self) -> SchemeMemory {
        self.scheme.memory()
    }

    /// Go on after a step of an earlier run of the same scene: its failure state and its
    /// scheme's memory ([`Self::scheme_memory`]); the crack tracking is put back through
    /// [`Self::resolution_mut`]. The permeability of the failed cells and the law map
    /// follow from the failure state at the next solve, the stress operators are those of
    /// the intact laws as at the first solve of a run: the next steps are those of the run
    /// never stopped, bit for bit. Errors: a failure state of another grid.
    pub fn resume(&mut self, failures: FailureState, scheme: SchemeMemory) -> FractureResult<()> {
        let grid = self.body.grid;
        let nc = grid.num_cells();
        if failures.flags().len() != nc {
            return Err(FractureError::Input(format!(
                "failure state of {} cells, the grid has {nc}",
                failures.flags().len()
            )));
        }
        if self.stress_cache.is_none() {
            let intact = self.laws.law_map(grid, &vec![false; nc])?;
            self.stress_cache = Some(StressCache::new(
                &intact,
                &self.operators,
                &self.coords,
                grid.cell_volumes(),
            ));
        }
        self.failures = failures;
        self.scheme.resume(scheme);
        Ok(())
    }
    /// The flow model with the current permeability.
    pub fn flow(&self) -> &FlowModel<D> {
        &self.flow.model
    }
    /// The initial pressure `p₀` of every cell.
    pub fn initial_pressure(&self) -> &[f64] {
        &self.flow.p0
    }
    /// The name of the coupling scheme.
    pub fn scheme_name(&self) -> &'static str {
        self.scheme.name()
    }
    /// What the linear algebra of the coupling did so far: solver, numeric and symbolic
    /// factorizations, factor entries and solves (see [`CouplingStats`]).
    pub fn stats(&self) -> CouplingStats {
        self.scheme.stats()
    }
    /// The law map of the current failure state.
    pub fn law_map(&self) -> FractureResult<LawMap<'a, D>> {
        self.laws.law_map(self.body.grid, self.failures.flags())
    }

    /// The initial state at `t`: mechanical equilibrium with the loads and `p = p₀`,
    /// failures resolved.
    pub fn initial_state(&mut self, t: f64) -> FractureResult<FractureStep<D>> {
        self.advance(None, t, 0.0)
    }

    /// Advance `state` at `t` to `t + dt` (see the module docs).
    pub fn step(&mut self, state: &BiotState, t: f64, dt: f64) -> FractureResult<FractureStep<D>> {
        self.advance(Some(state), t, dt)
    }

    fn advance(
        &mut self,
        state: Option<&BiotState>,
        t: f64,
        dt: f64,
    ) -> FractureResult<FractureStep<D>> {
        let Self {
            body,
            laws,
            flow,
            scheme,
            failures,
            resolution,
            perm_of_failed,
            operators,
            coords,
            cached,
            elements,
            stress_cache,
            interrupt,
            opening_tips,
            cavitation,
            void,
            responses,
        } = self;
        let void_start = void.clone();
        let stop = || {
            interrupt
                .as_ref()
                .is_some_and(|f| f.load(Ordering::Relaxed))
        };
        let grid = body.grid;
        let t1 = t + dt;
        let limits = ActiveSetLimits {
            iterations: resolution.settings().max_active_set,
            tolerance: resolution.settings().active_set_tolerance,
        };
        let mut solves = 0;
        let mut worst = 0.0f64;
        // The state of the previous round of this step: the next round's active set
        // starts from its stiffness (see `active_set_solve`).
        let mut warm: Option<BiotState> = None;
        let solve = |fs: &FailureState| -> FractureResult<Checked<D>> {
            if stop() {
                return Err(FractureError::Interrupted);
            }
            if cached.as_ref().is_none_or(|c| c.flags != fs.flags()) {
                *cached = Some(Cached {
                    flags: fs.flags().to_vec(),
                    map: laws.law_map(grid, fs.flags())?,
                    stiffness: None,
                });
            }
            let Some(Cached { map, stiffness, .. }) = cached.as_mut() else {
                return Err(FractureError::Input("law map missing".into()));
            };
            if matches!(
                flow.fracture_permeability,
                Some(FracturePermeability::CubicLaw(_))
            ) {
                // A failed cell is the crack's fluid: it stores the volume it opens.
                let alpha: Vec<f64> = fs
                    .flags()
                    .iter()
                    .zip(&flow.alpha)
                    .map(|(&f, &a)| if f { 1.0 } else { a })
                    .collect();
                if alpha != operators.alpha {
                    *operators = Arc::new(operators.with_alpha(grid, body.dofs, alpha));
                }
            }
            update_permeability(
                grid,
                flow,
                fs.flags(),
                perm_of_failed,
                operators,
                state.map(|s| s.displacement.as_slice()),
            )?;
            let mut system = BiotSystem::from_parts(
                problem(body, map),
                &flow.model,
                operators.clone(),
                stiffness.clone(),
                Some(elements.clone()),
            )?;
            if stiffness.is_none() {
                *stiffness = Some(system.parts().1);
            }
            if let Scheme::FixedStress(_, k_dr) = scheme {
                system = system.with_drained_bulk_modulus(k_dr.clone())?;
            }
            if let Scheme::ExplicitPressure(ep, extra) = scheme {
                ep.fractured = flow
                    .wet_cells(grid, fs.flags())
                    .iter()
                    .zip(extra.iter())
                    .map(|(a, b)| *a || *b)
                    .collect();
            }
            let cav = cavitation.map(|p| Cavity {
                pressure: p,
                void: &void_start,
                cache: &mut *responses,
            });
            let (new, residual, n, void_change) = active_set_solve(
                &mut system,
                scheme,
                state,
                warm.as_ref(),
                t,
                dt,
                limits,
                &stop,
                cav,
            )?;
            solves += n;
            warm = Some(new.clone());
            worst = worst.max(residual);
            let cache = stress_cache.get_or_insert_with(|| {
                StressCache::new(map, operators, coords, grid.cell_volumes())
            });
            let stress = stresses(grid, map, operators, coords, cache, &new.displacement)?;
            if let Some(tips) = opening_tips.as_ref() {
                let measure = tips.measure(grid, fs.flags(), &stress, &new.displacement, dt);
                return Ok(((new, stress, void_change), measure));
            }
            Ok(((new, stress.clone(), void_change), stress))
        };
        let done = resolution
            .resolve(grid, failures, t1, solve)
            .map_err(|e| match e {
                ResolveError::Solve(e) => e,
                ResolveError::NotSettled {
                    rounds,
                    time,
                    failed,
                } => FractureError::NotSettled {
                    rounds,
                    time,
                    failed,
                },
            })?;
        let ((state, stress, void_change), _) = done.solution;
        if let Some(tips) = opening_tips.as_mut() {
            tips.remember_fronts(grid, failures.flags(), &state.displacement, dt);
        }
        if !void_change.is_empty() {
            for (v, dv) in void.iter_mut().zip(&void_change) {
                *v = (*v + dv).max(0.0);
            }
        }
        Ok(FractureStep {
            state,
            stress,
            new_failures: done.new_failures,
            rounds: done.rounds,
            solves,
            residual: worst,
            void_change,
        })
    }
}

fn problem<'b, const D: usize>(
    body: &Body<'b, D>,
    laws: &'b LawMap<'b, D>,
) -> StaticProblem<'b, D> {
    StaticProblem {
        grid: body.grid,
        laws,
        dofs: body.dofs,
        pattern: body.pattern,
        loads: body.loads,
    }
}

/// Grids with fewer cells evaluate the cell stresses on the calling thread: a few
/// microseconds of work per thousand cells gain nothing from a fork–join.
const PARALLEL_STRESS_CELLS: usize = 16_384;

/// The stress of every cell ([`CellLaw::stress`]) at the nodal displacement `u`, the
/// same values as [`crate::cell_stresses`] with the node normals of `ops` and the node
/// coordinates `coords` (aligned with them) instead of gathering and recomputing them
/// per cell; cells in parallel blocks.
fn stresses<const D: usize>(
    grid: &Grid<D>,
    map: &LawMap<'_, D>,
    ops: &Operators<D>,
    coords: &[Point<D>],
    cache: &StressCache,
    u: &[f64],
) -> FractureResult<Vec<Tensor<D>>> {
    /// Cells per block, each block evaluated by one thread; all on the calling thread
    /// below [`PARALLEL_STRESS_CELLS`] cells.
    const BLOCK: usize = 1024;
    if u.len() != D * grid.num_nodes() {
        return Err(FractureError::Input(format!(
            "displacement of length {}, want {}",
            u.len(),
            D * grid.num_nodes()
        )));
    }
    let mut out = vec![Tensor::<D>::zeros(); grid.num_cells()];
    let volumes = grid.cell_volumes();
    let block = |(b, chunk): (usize, &mut [Tensor<D>])| {
        let mut scratch = Scratch::default();
        let mut uc = Vec::new();
        for (i, s) in chunk.iter_mut().enumerate() {
            let c = b * BLOCK + i;
            let k = ops.node_ptr[c]..ops.node_ptr[c + 1];
            uc.clear();
            uc.extend(ops.dofs[D * k.start..D * k.end].iter().map(|&d| u[d]));
            let geo = CellGeometry {
                coords: &coords[k.clone()],
                node_normals: &ops.normals[k],
                volume: volumes[c],
            };
            *s = match cache.stress(c, map.law_index(c), &uc) {
                Some(s) => s,
                None => map
                    .law(c)
                    .stress(&geo, &uc, &mut scratch)
                    .map_err(law_error(map, c))?,
            };
        }
        Ok::<_, SimError>(())
    };
    if out.len() < PARALLEL_STRESS_CELLS {
        out.chunks_mut(BLOCK).enumerate().try_for_each(block)?;
    } else {
        out.par_chunks_mut(BLOCK).enumerate().try_for_each(block)?;
    }
    Ok(out)
}

/// Raise the permeability of newly failed cells (only when the flags changed); with the
/// cubic law ([`FracturePermeability::CubicLaw`]) the permeability of every wet cell from
/// its opening at the displacement `u` (the start of the step; `None`: not opened), at
/// every call (the flow model's matrix changes only where the values do).
fn update_permeability<const D: usize>(
    grid: &Grid<D>,
    flow: &mut FractureFlow<D>,
    failed: &[bool],
    applied: &mut [bool],
    ops: &Operators<D>,
    u: Option<&[f64]>,
) -> FractureResult<()> {
    let Some(k) = flow.fracture_permeability else {
        return Ok(());
    };
    let cubic = matches!(k, FracturePermeability::CubicLaw(_));
    if applied == failed && !cubic {
        return Ok(());
    }
    let mut perm = flow.permeability.clone();
    let volumes = grid.cell_volumes();
    let mut uc = Vec::new();
    for (c, wet) in flow.wet_cells(grid, failed).into_iter().enumerate() {
        if !wet {
            continue;
        }
        let kc = match (k, u) {
            (FracturePermeability::CubicLaw(t_min), Some(u)) => {
                let nodes = ops.node_ptr[c]..ops.node_ptr[c + 1];
                uc.clear();
                uc.extend(
                    ops.dofs[D * nodes.start..D * nodes.end]
                        .iter()
                        .map(|&d| u[d]),
                );
                let opening = crate::crack_flow::cell_opening(grid, c, &ops.normals[nodes], &uc);
                crate::crack_flow::cubic_law_permeability(&opening, t_min)
            }
            _ => k.of_cell::<D>(volumes[c]),
        };
        perm.set(c, Tensor::<D>::identity() * kc)?;
    }
    flow.model.set_permeability(grid, &perm)?;
    applied.copy_from_slice(failed);
    Ok(())
}

/// Limits of the active-set iteration ([`FractureSettings::max_active_set`],
/// [`FractureSettings::active_set_tolerance`]).
#[derive(Clone, Copy)]
struct ActiveSetLimits {
    iterations: usize,
    tolerance: f64,
}

/// One coupled step (or the initial equilibrium when `state` is `None`) iterated over the
/// active set of the piecewise-linear laws. Returns the state, the accepted residual and
/// the number of linear solves.
///
/// The first stiffness is the tangent at `warm` (the state of the previous failure round
/// of the same step, at `t + Δt`) when given, else at `state` (the start of the step).
/// An iteration that ends with the stiffness of its solution ends at the same solution
/// from either start (up to rounding); one accepted by the residual tolerance (chatter)
/// ends at a point that depends on the start, within that tolerance. A round that fails
/// a few cells changes the previous round's active set only near them: on the 3D
/// hydraulic-fracture scene the warm start takes 1.8 solves per round against 2.5.
fn active_set_solve<const D: usize>(
    system: &mut BiotSystem<'_, D>,
    scheme: &mut Scheme,
    state: Option<&BiotState>,
    warm: Option<&BiotState>,
    t: f64,
    dt: f64,
    limits: ActiveSetLimits,
    stop: &dyn Fn() -> bool,
    mut cav: Option<Cavity<'_>>,
) -> FractureResult<(BiotState, f64, usize, Vec<f64>)> {
    let t1 = t + dt;
    if system.mechanics().laws.all_linear() {
        // The stiffness does not depend on the displacement: one solve is exact.
        return Ok(match state {
            None => (system.initial_state(t)?, 0.0, 1, Vec::new()),
            Some(s) => {
                let (res, void_change, n) = scheme_step(system, scheme, s, t, dt, cav.as_mut())?;
                (res.state, res.residual, n, void_change)
            }
        });
    }
    let mut extra = 0;
    let mut void_change = Vec::new();
    let p0 = system.initial_pressure().to_vec();
    // The first stiffness only (its residual is not used).
    match (warm, state) {
        (Some(w), _) => system.tangent_at(&w.displacement)?,
        (None, Some(s)) => system.tangent_at(&s.displacement)?,
        (None, None) => system.tangent_at(&vec![0.0; system.mechanics().dofs.num_dofs()])?,
    };
    // The best iterate so far: state, the pressure its mechanics balances, residual.
    let mut best: Option<(BiotState, Vec<f64>, f64)> = None;
    let mut residual = f64::INFINITY;
    for it in 1..=limits.iterations.max(1) {
        if it > 1 && stop() {
            return Err(FractureError::Interrupted);
        }
        let (new, p_used, solve_residual) = match state {
            None => {
                let st = system.initial_state(t)?;
                (st, p0.clone(), None)
            }
            Some(s) => {
                let (res, dv, n) = scheme_step(system, scheme, s, t, dt, cav.as_mut())?;
                extra += n - 1;
                void_change = dv;
                // The explicit-pressure mechanics is in equilibrium with the old pressure.
                let p_used = match scheme {
                    Scheme::ExplicitPressure(..) => s.pressure.clone(),
                    _ => res.state.pressure.clone(),
                };
                (res.state, p_used, Some(res.residual))
            }
        };
        // The solution of a linear step with the tangent at itself is exact: accepted
        // with the step's own residual, as a step of linear laws is (the equilibrium
        // residual is measured only when the tangent changed).
        let changed = system.tangent_at(&new.displacement)?;
        if !changed && let Some(r) = solve_residual {
            return Ok((new, r, it + extra, void_change));
        }
        residual = system.equilibrium_residual(&new.displacement, &p_used, t1)?;
        if !changed || residual <= limits.tolerance {
            return Ok((new, residual, it + extra, void_change));
        }
        let Some((b_state, b_p, b_res)) = best.take() else {
            best = Some((new, p_used, residual));
            continue;
        };
        if residual < b_res {
            best = Some((new, p_used, residual));
            continue;
        }
        // Chatter: the full step did not reduce the residual. Backtrack along the segment
        // from the best iterate to the new one; both satisfy the (linear) flow equations,
        // so every point between them does too, and only the equilibrium residual of the
        // piecewise-linear laws decides. The point found (or the shortest step tried) is
        // the next linearization point.
        let mut omega = 0.5;
        let mut next = None;
        while omega >= 1.0 / 64.0 {
            let mix = |a: &[f64], b: &[f64]| -> Vec<f64> {
                a.iter().zip(b).map(|(x, y)| x + omega * (y - x)).collect()
            };
            let cand = BiotState {
                displacement: mix(&b_state.displacement, &new.displacement),
                pressure: mix(&b_state.pressure, &new.pressure),
            };
            let cand_p = mix(&b_p, &p_used);
            let l = system.linearize(&cand.displacement, &cand_p, t1)?;
            residual = l.residual;
            if residual <= limits.tolerance {
                return Ok((cand, residual, it + extra, void_change));
            }
            let descent = residual < b_res;
            next = Some((cand, cand_p, residual));
            if descent {
                break;
            }
            omega *= 0.5;
        }
        best = next;
    }
    Err(FractureError::ActiveSet {
        time: t1,
        iterations: limits.iterations,
        residual,
        tolerance: limits.tolerance,
    })
}

/// The cavitation bound of a step: the pressure, the void at the start of the step and the
/// kept responses ([`crate::cavitation::bounded_step`]).
struct Cavity<'c> {
    pressure: f64,
    void: &'c [f64],
    cache: &'c mut crate::cavitation::ResponseCache,
}

/// One step of `scheme`, bounded below by the cavitation pressure of `cav` with the void
/// of every cell at the start of the step ([`crate::cavitation::bounded_step`]) when given
/// and `dt > 0`. Returns the step, the void change (empty without a bound) and the
/// coupled solves done.
fn scheme_step<const D: usize>(
    system: &mut BiotSystem<'_, D>,
    scheme: &mut Scheme,
    s: &BiotState,
    t: f64,
    dt: f64,
    cav: Option<&mut Cavity<'_>>,
) -> FractureResult<(crate::BiotStep, Vec<f64>, usize)> {
    use crate::cavitation::CavitationSolver;
    let mut solver = SchemeSolver {
        scheme,
        state: s,
        t,
        dt,
    };
    match cav {
        Some(c) if dt > 0.0 => {
            let b =
                crate::cavitation::bounded_step(system, c.pressure, c.void, dt, c.cache, solver)?;
            Ok((b.step, b.void_change, b.solves))
        }
        _ => Ok((
            CavitationSolver::<D>::solve(&mut solver, system)?,
            Vec::new(),
            1,
        )),
    }
}

/// A step of `scheme` from `state` as the cavitation bound solves it: the monolithic
/// scheme gives the responses to void sources from its factors
/// ([`crate::Monolithic::pressure_responses`]), the split ones by solves.
struct SchemeSolver<'a> {
    scheme: &'a mut Scheme,
    state: &'a BiotState,
    t: f64,
    dt: f64,
}

impl<const D: usize> crate::cavitation::CavitationSolver<D> for SchemeSolver<'_> {
    fn solve(&mut self, sys: &BiotSystem<'_, D>) -> crate::biot::BiotResult<crate::BiotStep> {
        let (s, t, dt) = (self.state, self.t, self.dt);
        match self.scheme {
            Scheme::Monolithic(m) => m.step(sys, s, t, dt),
            Scheme::FixedStress(f, _) => f.step(sys, s, t, dt),
            Scheme::ExplicitPressure(e, _) => e.step(sys, s, t, dt),
        }
    }
    fn responses(
        &mut self,
        sys: &BiotSystem<'_, D>,
        cells: &[usize],
        volumes: &[f64],
    ) -> crate::biot::BiotResult<Option<Vec<f64>>> {
        match self.scheme {
            Scheme::Monolithic(m) => m.pressure_responses(sys, cells, volumes),
            _ => Ok(None),
        }
    }
    fn pressure_accuracy(
        &mut self,
        sys: &BiotSystem<'_, D>,
        cells: &[usize],
    ) -> crate::biot::BiotResult<Option<Vec<f64>>> {
        match self.scheme {
            Scheme::Monolithic(m) => m.pressure_accuracy(sys, cells),
            _ => Ok(None),
        }
    }
    fn refine(
        &mut self,
        sys: &BiotSystem<'_, D>,
    ) -> crate::biot::BiotResult<Option<crate::BiotStep>> {
        match self.scheme {
            Scheme::Monolithic(m) => m.refine_last(sys, self.state),
            _ => Ok(None),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use porofrac_grid::generate::cartesian;

    #[test]
    fn wet_cells_are_the_failed_cells_and_without_lag_their_face_neighbours() {
        // 3 × 3 squares: the centre cell shares a face with four cells and only a
        // corner with the other four.
        let grid = cartesian(Point::<2>::new(0.0, 0.0), Point::<2>::new(3.0, 3.0), [3, 3]).unwrap();
        let centre = (0..9)
            .find(|&c| {
                let faces = grid.cell_faces(c);
                faces.iter().all(|&f| grid.face_cells(f).1.is_some())
            })
            .unwrap();
        let mut failed = vec![false; 9];
        failed[centre] = true;
        assert_eq!(wet_cells(&grid, &failed, false), failed);
        let wet = wet_cells(&grid, &failed, true);
        assert_eq!(wet.iter().filter(|&&w| w).count(), 5);
        for &face in grid.cell_faces(centre) {
            let (a, b) = grid.face_cells(face);
            assert!(wet[a] && wet[b.unwrap()]);
        }
    }
}
