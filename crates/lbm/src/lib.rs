//! A lattice Boltzmann fluid: D2Q9 with BGK or TRT collision and Guo forcing, fused
//! stream–collide with in-place AA streaming, periodic sides, halfway bounce-back walls
//! (moving walls included), velocity inlets and pressure outlets, and rigid obstacles whose
//! surfaces fall between nodes (Yu et al. interpolated bounce-back, eq. 7 of the paper
//! below) with force and torque by momentum exchange (its eq. 8).
//!
//! Mora, Wang & Alonso-Marroquin (2015), eqs. 1–3 and 6–8. Everything here is in lattice
//! units (`Δx = Δt = 1`, reference density 1); [`Units`] converts from SI. The crate knows
//! no particles: an obstacle is a [`Shape`] with a velocity and an angular velocity, which a
//! caller may change before every step ([`Lattice::set_obstacle_motion`]), or place itself
//! ([`ObstacleMotion::External`], [`Lattice::place_obstacle`],
//! [`Lattice::update_obstacles`]: how coupled particles are carried; only what moved is
//! re-rasterised, and the momentum of covered and uncovered nodes is reported). Mass
//! sources ([`Lattice::add_source`]) inject fluid (as in that paper's Fig. 9); the
//! temperature lattice ([`Thermal`]) keeps the books of the heat through the sides and out
//! of each obstacle. [`slab`] cuts a lattice into slabs of columns for a run on several
//! MPI ranks (the `mpi` feature) whose numbers are those of the serial run, bit for bit.
//! Populations are stored in `f64` or, with [`Lattice::set_precision`], in `f32`
//! ([`Precision`]; the arithmetic stays `f64`). Obstacles may lie across periodic sides,
//! and with [`ObstacleOverhang::Clipped`] overhang the other sides (clipped to the box);
//! [`Lattice::contact`] reports an obstacle that overlaps another. With obstacles, a step
//! skips the long stretches of solid nodes along each row ([`runs`],
//! [`Lattice::set_skip_solid`]): the fluid is the same to the bit, only faster where the
//! lattice is mostly solid.
//!
//! ```
//! use porofrac_lbm::{Lattice, LatticeConfig, Obstacle, Shape};
//! let mut lat = Lattice::new(LatticeConfig::periodic(32, 32, 0.8))?;
//! let disk = lat.add_obstacle(Obstacle {
//!     shape: Shape::Circle { center: [16.2, 15.7], radius: 5.3 },
//!     velocity: [0.0, 0.0],
//!     angular_velocity: 0.0,
//! })?;
//! lat.step()?;
//! assert!(lat.force(disk)[0].abs() < 1e-12);
//! # Ok::<(), porofrac_lbm::LbmError>(())
//! ```

pub mod boundary;
pub mod collision;
pub mod d2q9;
pub mod geometry;
pub mod image;
pub mod kernel;
pub mod lattice;
pub mod populations;
pub mod runs;
pub mod slab;
pub mod thermal;
pub mod units;

pub use boundary::{MomentumExchange, Side, SideKind};
pub use collision::{Collision, Rates};
pub use geometry::Shape;
pub use lattice::{
    Lattice, LatticeConfig, LatticeState, MAX_MACH, Obstacle, ObstacleMass, ObstacleMotion,
    ObstacleOverhang,
};
pub use populations::Precision;
pub use thermal::{HeatBooks, Thermal, ThermalSide, ThermalState};
pub use units::Units;

/// Smallest relaxation time accepted: `τ` must exceed `½ + 0.005` (at `τ → ½` the viscosity
/// vanishes and the scheme is unstable).
pub const TAU_MIN: f64 = 0.505;

/// Errors of the lattice Boltzmann solver.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LbmError {
    /// Relaxation time out of the stable range.
    #[error("tau = {0} must be a number above {TAU_MIN} (tau = 1/2 is zero viscosity)")]
    Tau(f64),
    /// TRT magic parameter not positive.
    #[error("magic = {0} must be positive")]
    Magic(f64),
    /// A lattice too small or too large.
    #[error("lattice of {0} × {1} nodes: each side needs 2 to 32768 nodes")]
    Size(usize, usize),
    /// A value that must be positive and finite.
    #[error("{0} = {1} must be positive and finite")]
    Value(&'static str, f64),
    /// A velocity above the Mach limit.
    #[error(
        "{what}: Mach number {mach:.3} above {MAX_MACH} (lower the velocity, refine the spacing or lower tau)"
    )]
    Mach {
        /// What moves.
        what: &'static str,
        /// Its Mach number.
        mach: f64,
    },
    /// An obstacle outside the box (partly, or with [`ObstacleOverhang::Clipped`]
    /// entirely) along an axis that is not periodic.
    #[error("obstacle {obstacle} is not inside the box")]
    Outside {
        /// Its index.
        obstacle: usize,
    },
    /// An obstacle moving a node or more per step.
    #[error("obstacle {obstacle} moves {speed:.3} nodes per step (must be below 1)")]
    TooFast {
        /// Its index.
        obstacle: usize,
        /// Largest surface speed (lattice units).
        speed: f64,
    },
    /// A density not positive or not finite.
    #[error("the flow diverged at step {step}, node ({i}, {j})")]
    Diverged {
        /// Step.
        step: u64,
        /// Node column.
        i: usize,
        /// Node row.
        j: usize,
    },
}
