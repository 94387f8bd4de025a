//! Disk particles in 2D, shared by the particle models of porofrac (non-smooth contact
//! dynamics, bonded-particle lattice solids). Nothing here knows a contact law or an
//! integrator:
//!
//! * [`Disks`]: the state as structure-of-arrays (centres, radii, velocities, angular
//!   velocities, rotations, masses, moments of inertia, reference centres);
//! * [`packing`]: a hexagonal lattice and a seeded dense random polydisperse packing in a
//!   box, with the checks of a packing (overlap, packing fraction, coordination number);
//! * [`cells`]: neighbour search by cell lists with an alert distance;
//! * [`tracked`]: tracked cells and their stress, fabric and dilatations (Renouf et al.
//!   2006, eqs. 7–11);
//! * [`trishear`]: the analytic trishear velocity field and its mismatch with particle
//!   velocities;
//! * [`vtk`]: particle and contact VTK PolyData files (`.vtp`).
//!
//! Per unit thickness (1 m): a disk of radius r and density ρ has m = ρπr² and
//! I = m r²/2.

pub mod cells;
pub mod disks;
pub mod fault;
pub mod packing;
pub mod rng;
pub mod tracked;
pub mod trishear;
pub mod vtk;

pub use cells::CellList;
pub use disks::Disks;
pub use packing::{Hole, Packing, RadiusDistribution, RandomPacking, Region};
pub use tracked::{CellContact, CellState, TrackedCell};

/// Where a long computation is, for a progress callback: `done` of `total` units of the
/// phase `what` (disks placed, sweeps done, steps taken...).
///
/// The long computations of the particle crates (packing, settling, calibration) take a
/// callback `&mut dyn FnMut(Progress) -> bool`, call it every few thousand units of work,
/// and stop with an `Interrupted` error when it returns `true`: this is how a caller
/// shows progress and honours Ctrl-C without these crates knowing either.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// What is being done ("placing disks", "settling, step"...).
    pub what: &'static str,
    /// Units done.
    pub done: usize,
    /// Units in all (an estimate where the end is not known in advance).
    pub total: usize,
}

impl Progress {
    /// `done` of `total` units of `what`.
    pub fn new(what: &'static str, done: usize, total: usize) -> Self {
        Self { what, done, total }
    }
}

/// A bad particle set or packing request. Every variant names the offending index or
/// argument.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum ParticleError {
    /// A radius that is zero, negative or not finite.
    #[error("particle {index}: radius {radius} must be a positive finite number")]
    BadRadius {
        /// Particle index.
        index: usize,
        /// The radius given.
        radius: f64,
    },
    /// A centre or velocity that is not finite.
    #[error("particle {index}: {what} is not finite")]
    NotFinite {
        /// Particle index.
        index: usize,
        /// Which quantity.
        what: &'static str,
    },
    /// Density not positive.
    #[error("density {0} must be a positive finite number")]
    BadDensity(f64),
    /// Two disks overlap by more than allowed.
    #[error(
        "particles {i} and {j} overlap by {overlap:.3e} m, more than the {allowed:.3e} m allowed"
    )]
    Overlap {
        /// First particle.
        i: usize,
        /// Second particle.
        j: usize,
        /// Overlap (m).
        overlap: f64,
        /// Allowed overlap (m).
        allowed: f64,
    },
    /// An argument of a generator is out of range.
    #[error("{argument} = {value}: {message}")]
    BadArgument {
        /// The argument.
        argument: &'static str,
        /// Its value.
        value: f64,
        /// What is wrong.
        message: &'static str,
    },
    /// The random packing did not relax to the overlap tolerance.
    #[error(
        "the random packing did not relax: overlap {overlap:.3e} m after {sweeps} sweeps; lower packing_fraction"
    )]
    NotRelaxed {
        /// Largest overlap left (m).
        overlap: f64,
        /// Sweeps done.
        sweeps: usize,
    },
    /// The progress callback asked to stop.
    #[error("interrupted")]
    Interrupted,
    /// Writing a file failed.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The error.
        message: String,
    },
}
