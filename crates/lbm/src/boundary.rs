//! Boundary conditions on the sides of the box and on obstacles, applied after every
//! stream–collide step from index lists of cut links built when the geometry changes.
//!
//! Notation: `L(x, i)` is the population `f_i` arriving at node `x` after the step (its
//! place in memory depends on the [`Layout`](crate::kernel::Layout)). A cut link is a
//! fluid node `x_f` and a direction `α` whose neighbour `x_b = x_f + c_α` is solid or
//! outside; `L(x_b, α) = f̃_α(x_f)` is what `x_f` sent across it, and the unknown is
//! `L(x_f, ᾱ)`.
//!
//! * **Periodic side**: `L(x, i)` is copied from the ghost node the other side's node sent
//!   it to.
//! * **Wall** (halfway bounce-back, Ladd): `L(x_f, ᾱ) = L(x_b, α) − 6 w_α ρ₀ c_α·u_w`, the wall
//!   half a spacing outside the last node, `ρ₀ = 1`.
//! * **Velocity inlet**: the same rule with the inlet velocity (velocity bounce-back, the
//!   `UBB` of lbmpy).
//! * **Pressure outlet**: anti-bounce-back (Ginzburg 2008; Izquierdo & Fueyo 2008),
//!   `L(x_f, ᾱ) = −L(x_b, α) + 2 w_α ρ_w [1 + 9/2 (c_α·u)² − 3/2 u²]`, `ρ_w = 1 + p/c_s²`
//!   and `u` the velocity of `x_f` at the previous time.
//! * **Obstacle**: Yu et al. (2003) interpolated bounce-back (Mora et al. (2015) eq. 7) with
//!   `δ = |x_f − x_w|/|x_f − x_b|`:
//!   `L(x_f, ᾱ) = [(1−δ) L(x_f, α) + δ L(x_b, α) + δ L(x_f2, ᾱ) − 6 w_α ρ₀ c_α·u_w]/(1+δ)`
//!   with `x_f2 = x_f − c_α`; where `x_f2` is not fluid, the plain moving bounce-back
//!   `L(x_f, ᾱ) = L(x_b, α) − 6 w_α ρ₀ c_α·u_w`.
//!   The interpolation does not conserve mass; with
//!   [`ObstacleMass::Conserved`](crate::ObstacleMass) (default) each body's imbalance
//!   `m = Σ [L(x_f, ᾱ) − L(x_b, α)]` over its cut links is removed again,
//!   `L(x_f, ᾱ) −= m w_α / Σ w_α`, before the force is summed.
//! * **Force** (Mora et al. (2015) eq. 8, momentum exchange per cut link):
//!   `ΔF = c_α [L(x_b, α) + L(x_f, ᾱ) − 2 w_α ρ₀]` (gauge: the reference density's share
//!   cancels over a body wetted all round, see [`crate::lattice`]), or with the
//!   Galilean-invariant correction of Wen et al. (2014) `ΔF = (c_α − u_w) L(x_b, α) − (c_ᾱ
//!   − u_w) L(x_f, ᾱ)`; torque `(x_w − X) × ΔF`.
//!
//! No unknown is read by another rule of the same step (a rule reads only what crossed
//! into a solid or ghost node, or populations of fluid nodes that are not unknowns), except
//! that obstacle rules may read populations a periodic copy delivered: copies go first.
//! So the order of the obstacles' rules does not matter, and those of an obstacle whose
//! cut links are two nodes or more from the box's edge (out of reach of the copies and the
//! sides' rules) may run before the sides', inside the stream–collide sweep.

/// A side of the box.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// `x = 0`.
    XMin,
    /// `x = nx`.
    XMax,
    /// `y = 0`.
    YMin,
    /// `y = ny`.
    YMax,
}

impl Side {
    /// All four sides.
    pub const ALL: [Side; 4] = [Side::XMin, Side::XMax, Side::YMin, Side::YMax];
    /// Index 0..4 in [`Side::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
    /// The axis (0 for x, 1 for y).
    pub fn axis(self) -> usize {
        match self {
            Side::XMin | Side::XMax => 0,
            _ => 1,
        }
    }
}

/// The condition on a side that is not periodic.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum SideKind {
    /// No-slip wall halfway between the last node and the ghost node; moving walls get their
    /// velocity from [`crate::Lattice::set_side_velocity`].
    #[default]
    Wall,
    /// Velocity inlet (velocity bounce-back); velocity from
    /// [`crate::Lattice::set_side_velocity`].
    Velocity,
    /// Pressure outlet (anti-bounce-back) at the given lattice density `ρ_w`.
    Pressure {
        /// Lattice density of the outlet (`1 + p / (c_s² ρ (Δx/Δt)²)`).
        density: f64,
    },
}

/// A periodic copy: `L(dst, dir) ← L(src, dir)`, `src` a ghost node.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CopyLink {
    pub dst: u32,
    pub src: u32,
    pub dir: u8,
}

/// A bounce-back link on a side (wall or inlet): the unknown `L(node, dir)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SideLink {
    pub node: u32,
    pub dir: u8,
    pub side: u8,
    /// Where the link crosses the side (lattice units).
    pub at: [f64; 2],
    /// Wall velocity there.
    pub u: [f64; 2],
}

/// An anti-bounce-back link on a pressure side.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PressureLink {
    pub node: u32,
    pub dir: u8,
    pub density: f64,
}

/// A cut link of an obstacle: fluid `node`, direction `alpha` into the solid.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ObstacleLink {
    pub node: u32,
    pub alpha: u8,
    /// `δ` of Mora et al. (2015) eq. 6.
    pub delta: f64,
    /// `x_f2`, or `u32::MAX` where it is not fluid.
    pub f2: u32,
    /// Wall point `x_w` (unwrapped lattice coordinates).
    pub xw: [f64; 2],
    /// Position of `x_f` (the image nearest the obstacle's centre when last computed).
    pub p: [f64; 2],
}

/// How the force on an obstacle is summed from its cut links (Mora et al. (2015) eq. 8).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum MomentumExchange {
    /// `ΔF = c_α [L(x_b, α) + L(x_f, ᾱ)]`.
    #[default]
    Standard,
    /// Wen et al. (2014): relative velocities `c − u_w` in both terms.
    GalileanInvariant,
}
