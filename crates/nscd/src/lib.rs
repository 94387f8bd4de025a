//! Non-smooth contact dynamics (NSCD) of rigid disks and driven rigid bodies, after
//! Renouf, Dubois & Alart (2006), the method of LMGC90 (Moreau–Jean).
//!
//! The stages of a step, each in its own module:
//!
//! * [`body`]: rigid bodies (segments and convex polygons) that translate at a
//!   prescribed velocity, or under a prescribed force along an axis left free;
//! * [`law`]: the contact law (Signorini, Coulomb with static and dynamic friction, the
//!   cohesive "non-smooth Lennard-Jones" law) and the exact solution of one local 2×2
//!   problem;
//! * [`integrator`]: the one-step integrator, the Moreau–Jean θ-scheme on velocities
//!   (eq. 3): predicted configuration, free velocities, the update of velocities and
//!   positions;
//! * [`detect`]: contact detection at the predicted configuration, broad phase (cell
//!   lists with an alert distance, body bounding boxes) then narrow phase (exact gaps,
//!   local frames);
//! * [`contacts`]: the contacts of a step, which keep their impulses for the next step's
//!   warm start;
//! * [`problem`]: the one-step contact problem: the local blocks of the Delassus
//!   operator, the law of each contact for the step, `M⁻¹ H`;
//! * [`nlgs`]: the local solver, non-linear Gauss–Seidel sweeps (eq. 5, Table 1) with
//!   body-velocity accumulation and the convergence test, and its options;
//! * [`solver`]: the system ([`Nscd`]) and its step, composed of the stages above;
//! * [`colour`]: the coloured parallel sweep (deterministic for any thread count);
//! * [`settle`]: gravity settling of a sample before its loading.
//!
//! Disks are [`porofrac_particles::Disks`]; a disk of infinite mass (or inertia) does
//! not move (or rotate).

pub mod body;
pub mod colour;
pub mod contacts;
pub mod detect;
pub mod integrator;
pub mod law;
pub mod nlgs;
pub mod problem;
pub mod settle;
pub mod slabs;
pub mod solver;

pub use body::{Axis, RigidBody};
pub use law::ContactLaw;
pub use nlgs::NlgsOptions;
pub use settle::{SettleParams, SettleStats};
pub use solver::{Nscd, Ordering, SolverParams, StepMemory, StepStats};

/// Anything that stops an NSCD computation. Each variant names the parameter,
/// particle or body at fault.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum NscdError {
    /// A parameter out of range.
    #[error("{name} = {value}: {message}")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What is allowed.
        message: &'static str,
    },
    /// A bad rigid body.
    #[error("body {index}: {message}")]
    BadBody {
        /// Body index.
        index: usize,
        /// What is wrong.
        message: &'static str,
    },
    /// A bad particle set.
    #[error(transparent)]
    Particles(#[from] porofrac_particles::ParticleError),
    /// Two bodies overlap by more than the alert distance at the start.
    #[error(
        "particle {i} overlaps {with} by {overlap:.3e} m, more than the alert distance {alert:.3e} m"
    )]
    InitialOverlap {
        /// The particle.
        i: usize,
        /// What it overlaps (`particle j` or `body b`).
        with: String,
        /// The overlap (m).
        overlap: f64,
        /// The alert distance (m).
        alert: f64,
    },
    /// A step would move a disk by more than its radius.
    #[error(
        "at t = {time} s the step would move particle {particle} by {distance:.3e} m, more than its radius {radius:.3e} m: lower the time step"
    )]
    StepTooLarge {
        /// The time at the start of the step (s).
        time: f64,
        /// The particle.
        particle: usize,
        /// How far it would move (m).
        distance: f64,
        /// Its radius (m).
        radius: f64,
    },
    /// The alert distance takes in too many disk pairs (the candidates would grow as
    /// `n²`); see [`detect::CANDIDATES_PER_DISK`].
    #[error(
        "the alert distance {alert:.3e} m gives more than {found} contact candidates for {disks} disks; lower alert (at most the largest radius)"
    )]
    TooManyCandidates {
        /// Candidates found when the search stopped.
        found: usize,
        /// Disks.
        disks: usize,
        /// The alert distance (m).
        alert: f64,
    },
    /// The progress callback asked to stop.
    #[error("interrupted")]
    Interrupted,
    /// Gravity settling did not reach its kinetic-energy criterion.
    #[error(
        "settling not finished after {steps} steps: kinetic energy {kinetic:.3e} J/m against {released:.3e} J/m of potential energy released"
    )]
    NotSettled {
        /// Steps taken.
        steps: usize,
        /// Kinetic energy at the end (J per metre).
        kinetic: f64,
        /// Potential energy released (J per metre).
        released: f64,
    },
}
