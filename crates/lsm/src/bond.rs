//! One bond: geometry, springs (the ESyS-Particle bond model) and the breakage test.
//!
//! With `n = (x_j − x_i)/d`, `t = ẑ × n`, `d = |x_j − x_i|`:
//!
//! * normal force `F_n = k_n (d − d₀)`, tension positive, `+F_n n` on i, `−F_n n` on j;
//! * shear displacement, accumulated from the position and rotation increments of a
//!   step, `Δδ_s = (Δx_j − Δx_i)·t − d/(R_i + R_j) (R_i Δθ_i + R_j Δθ_j)` (a rigid
//!   rotation gives no increment), `F_s = k_s δ_s`, `+F_s t` on i and `−F_s t` on j;
//! * the shear moments `F_s d R_i/(R_i+R_j)` on i and `F_s d R_j/(R_i+R_j)` on j (the
//!   work-conjugates of the rotation terms of `Δδ_s`; `F_s R_i` when the disks touch);
//! * bending `M_b = k_b (θ_j − θ_i − Δθ₀)`, `+M_b` on i and `−M_b` on j.
//!
//! Breakage: see [`crate::law`].

use crate::law::BondLaw;
use porofrac_particles::Disks;

/// How a bond broke.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BreakMode {
    /// Tension (with bending).
    Tensile,
    /// Shear (Mohr–Coulomb).
    Shear,
}

impl BreakMode {
    /// `"tensile"` or `"shear"`.
    pub fn as_str(self) -> &'static str {
        match self {
            BreakMode::Tensile => "tensile",
            BreakMode::Shear => "shear",
        }
    }
}

/// A broken bond: when, which pair, where (the contact point), how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrokenBond {
    /// Time of breakage (s).
    pub time: f64,
    /// First particle.
    pub i: usize,
    /// Second particle.
    pub j: usize,
    /// Contact point x (m): `x_i + n d R_i/(R_i + R_j)`.
    pub x: f64,
    /// Contact point y (m).
    pub y: f64,
    /// Mode.
    pub mode: BreakMode,
}

/// A bond between particles `i < j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bond {
    /// First particle.
    pub i: u32,
    /// Second particle.
    pub j: u32,
    /// Rest length (m).
    pub d0: f64,
    /// Relative rotation at bonding θ_j − θ_i (rad).
    pub dtheta0: f64,
    /// Accumulated shear displacement δ_s (m).
    pub shear: f64,
    /// Tension cut-off F_t (N/m).
    pub f_tensile: f64,
    /// Shear strength at zero normal force F_c (N/m).
    pub f_cohesion: f64,
    /// Bending strength M_max (N·m/m).
    pub m_max: f64,
    /// Not broken.
    pub intact: bool,
}

/// The forces of one bond: `[f_x, f_y]` on i (the opposite on j), moments on i and j,
/// and the normal force, shear force and bending moment for the breakage test.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BondForce {
    /// Force on i (N/m).
    pub f: [f64; 2],
    /// Moment on i (N·m/m).
    pub mi: f64,
    /// Moment on j (N·m/m).
    pub mj: f64,
    /// Normal force, tension positive (N/m).
    pub fn_: f64,
    /// Shear force (N/m).
    pub fs: f64,
    /// Bending moment (N·m/m).
    pub mb: f64,
}

impl Bond {
    /// A bond at rest in the current configuration of `disks`.
    pub fn new(disks: &Disks, i: usize, j: usize, law: &BondLaw) -> Self {
        let (ri, rj) = (disks.r[i], disks.r[j]);
        let w = 2.0 * ri.min(rj);
        Self {
            i: i as u32,
            j: j as u32,
            d0: dist(disks.x[i], disks.x[j]),
            dtheta0: disks.angle[j] - disks.angle[i],
            shear: 0.0,
            f_tensile: law.tensile * w,
            f_cohesion: law.cohesion * w,
            m_max: law.tensile * w * w / 6.0,
            intact: true,
        }
    }

    /// Advance the shear displacement by the step's increments `dx` (`[Δx, Δy, Δθ]` per
    /// particle) and return the forces.
    #[inline]
    pub fn update(&mut self, disks: &Disks, dx: &[[f64; 3]], law: &BondLaw) -> BondForce {
        let (i, j) = (self.i as usize, self.j as usize);
        let (xi, xj) = (disks.x[i], disks.x[j]);
        let e = [xj[0] - xi[0], xj[1] - xi[1]];
        let d = (e[0] * e[0] + e[1] * e[1]).sqrt();
        let n = [e[0] / d, e[1] / d];
        let t = [-n[1], n[0]];
        let (ri, rj) = (disks.r[i], disks.r[j]);
        let lever = d / (ri + rj);
        let (a, b) = (dx[i], dx[j]);
        self.shear += (b[0] - a[0]) * t[0] + (b[1] - a[1]) * t[1] - lever * (ri * a[2] + rj * b[2]);
        let fn_ = law.kn * (d - self.d0);
        let fs = law.ks * self.shear;
        let mb = law.kb * (disks.angle[j] - disks.angle[i] - self.dtheta0);
        BondForce {
            f: [fn_ * n[0] + fs * t[0], fn_ * n[1] + fs * t[1]],
            mi: fs * lever * ri + mb,
            mj: fs * lever * rj - mb,
            fn_,
            fs,
            mb,
        }
    }

    /// The breakage test of [`crate::law`]: `Some(mode)` if the bond breaks under `f`.
    #[inline]
    pub fn breaks(&self, f: &BondForce, law: &BondLaw) -> Option<BreakMode> {
        self.breaks_with(f, law.friction_angle.tan())
    }

    /// [`Self::breaks`] with `tan φ` given (computed once per step, not once per bond).
    #[inline]
    pub(crate) fn breaks_with(&self, f: &BondForce, tan_phi: f64) -> Option<BreakMode> {
        let bend = if self.m_max.is_finite() {
            f.mb.abs() / self.m_max
        } else {
            0.0
        };
        if f.fn_ / self.f_tensile + bend > 1.0 {
            return Some(BreakMode::Tensile);
        }
        if f.fs.abs() > self.f_cohesion - f.fn_ * tan_phi {
            return Some(BreakMode::Shear);
        }
        None
    }

    /// Elastic energy stored in the bond (J/m).
    pub fn energy(&self, disks: &Disks, law: &BondLaw) -> f64 {
        let (i, j) = (self.i as usize, self.j as usize);
        let s = dist(disks.x[i], disks.x[j]) - self.d0;
        let b = disks.angle[j] - disks.angle[i] - self.dtheta0;
        0.5 * (law.kn * s * s + law.ks * self.shear * self.shear + law.kb * b * b)
    }
}

pub(crate) fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}
