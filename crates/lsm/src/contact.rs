//! Frictional contacts between unbonded (or broken-bond) disks.
//!
//! A Verlet list holds the pairs whose gap is below a skin (built from a
//! [`porofrac_particles::CellList`], rebuilt once a disk has moved by half the skin), each
//! with the index of its bond if it has one and its tangential spring. A pair with an
//! intact bond carries no contact force. Otherwise, with the overlap
//! `δ = R_i + R_j − d > 0`:
//!
//! * normal force `F_n(δ)` (compression positive, [`crate::law::NormalLaw`]), `−F_n n` on i;
//! * tangential spring `u_t` advanced by the increment of [`crate::bond`], `F_t = k_s u_t`
//!   capped by Coulomb `|F_t| ≤ μ F_n` (the spring is reset to the cap on sliding),
//!   `+F_t t` on i, moments as for a bond.
//!
//! Pairs that separate reset their spring. When the list is rebuilt the springs of the
//! pairs present before are carried over (a merge of the two sorted lists).

use crate::law::ContactLaw;
use porofrac_particles::Disks;

/// A candidate contact pair `i < j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pair {
    /// First particle.
    pub i: u32,
    /// Second particle.
    pub j: u32,
    /// Bond index, or `u32::MAX` without a bond.
    pub bond: u32,
    /// Tangential spring (m).
    pub ut: f64,
}

/// Forces of a contact: on i (opposite on j), moments on i and j, normal force.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactForce {
    /// Force on i (N/m).
    pub f: [f64; 2],
    /// Moment on i.
    pub mi: f64,
    /// Moment on j.
    pub mj: f64,
    /// Normal force, compression positive (N/m); 0 if the disks do not touch.
    pub fn_: f64,
    /// Tangential force.
    pub ft: f64,
}

impl Pair {
    /// Advance the tangential spring by the increments `dx` and return the forces (zero
    /// if the disks do not touch).
    #[inline]
    pub fn update(&mut self, disks: &Disks, dx: &[[f64; 3]], law: &ContactLaw) -> ContactForce {
        let (i, j) = (self.i as usize, self.j as usize);
        let (xi, xj) = (disks.x[i], disks.x[j]);
        let e = [xj[0] - xi[0], xj[1] - xi[1]];
        let d = (e[0] * e[0] + e[1] * e[1]).sqrt();
        let (ri, rj) = (disks.r[i], disks.r[j]);
        let overlap = ri + rj - d;
        if overlap <= 0.0 || d == 0.0 {
            self.ut = 0.0;
            return ContactForce::default();
        }
        let n = [e[0] / d, e[1] / d];
        let t = [-n[1], n[0]];
        let lever = d / (ri + rj);
        let (a, b) = (dx[i], dx[j]);
        self.ut += (b[0] - a[0]) * t[0] + (b[1] - a[1]) * t[1] - lever * (ri * a[2] + rj * b[2]);
        let fn_ = law.normal_force(overlap, ri * rj / (ri + rj));
        let mut ft = law.ks * self.ut;
        let cap = law.friction * fn_;
        if ft.abs() > cap {
            ft = cap * ft.signum();
            self.ut = if law.ks > 0.0 { ft / law.ks } else { 0.0 };
        }
        ContactForce {
            f: [-fn_ * n[0] + ft * t[0], -fn_ * n[1] + ft * t[1]],
            mi: ft * lever * ri,
            mj: ft * lever * rj,
            fn_,
            ft,
        }
    }
}
