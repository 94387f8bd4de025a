//! The one-step contact problem: the local blocks of the Delassus operator, the law of
//! every contact for the step, the warm start, and the map `M⁻¹ H` from contact
//! impulses to body velocities.
//!
//! For a contact α between disk i (candidate) and disk j or a body, with normal n and
//! tangent t, the impulse P_n n + P_t t acts on i at −r_i n and its opposite on j at
//! r_j n. The relative velocity `U = Hᵀ q̇` is U_n = (v_i − v_j)·n,
//! U_t = (v_i − v_j)·t − r_i ω_i − r_j ω_j, and the diagonal block
//! `W_αα = Hᵀ M⁻¹ H` restricted to α is
//!
//! ```text
//!   W_nn = m_i⁻¹ + m_j⁻¹,   W_nt = 0,   W_tt = m_i⁻¹ + r_i² I_i⁻¹ + m_j⁻¹ + r_j² I_j⁻¹
//! ```
//!
//! for two disks; a body with per-axis inverse mass `b` adds `nᵀ diag(b) n`,
//! `nᵀ diag(b) t` and `tᵀ diag(b) t` instead of the disk j terms. W itself is never
//! formed: the local solver keeps the velocities `q̇ = q̇_free + M⁻¹ H P` up to date.
//!
//! Per contact and step: the friction coefficient is the body's own for a contact with a
//! body that has one ([`crate::RigidBody::friction`]), else the static one if the contact
//! was sticking at the end of the previous step and the dynamic one otherwise; a cohesive contact
//! (gap ≤ `cohesion_distance`) shifts its normal impulse by hγ; the bias of the local
//! problem is `[max(0, g)/(θh) − W_nn·shift, −W_nt·shift]`. Contacts between two
//! immovable bodies (`W_nn = 0`) are dropped.
//!
//! With restitution e > 0 ([`newton`]), Newton's impact law replaces the gap-aware
//! bias: the contacts whose predicted gap is > 0 are dropped for the step (no impulse),
//! the others get the bias `e min(0, U_n⁻)`, U_n⁻ = (v_i − v_j)·n at the start of the step.

use crate::contacts::ContactSet;
use crate::detect::{Antagonist, Contact};
use crate::law::{Block, ContactLaw};

/// Set up the local problems of the step's contacts (blocks of W, friction, cohesive
/// shift, bias and warm-start impulse) for a step of length `h` with θ `theta`, and drop
/// the contacts between immovable bodies. `inv_m`, `inv_i`: the disks' inverse masses
/// and inertias; `body_inv`: the bodies' inverse masses per axis; `body_mu`: the bodies'
/// own friction coefficients (`None`: the law's).
#[allow(clippy::too_many_arguments)]
pub fn build(
    contacts: &mut ContactSet,
    law: &ContactLaw,
    inv_m: &[f64],
    inv_i: &[f64],
    body_inv: &[[f64; 2]],
    body_mu: &[Option<f64>],
    h: f64,
    theta: f64,
) {
    let law = *law;
    let mut prev = 0usize;
    let mut list = std::mem::take(&mut contacts.list);
    for ct in list.iter_mut() {
        let i = ct.i as usize;
        let (mut nn, mut nt, mut tt) = (inv_m[i], 0.0, inv_m[i] + ct.ri * ct.ri * inv_i[i]);
        match ct.other {
            Antagonist::Disk(j) => {
                let j = j as usize;
                nn += inv_m[j];
                tt += inv_m[j] + ct.rj * ct.rj * inv_i[j];
            }
            Antagonist::Body(b) => {
                let ib = body_inv[b as usize];
                nn += ib[0] * ct.n[0] * ct.n[0] + ib[1] * ct.n[1] * ct.n[1];
                nt += ib[0] * ct.n[0] * ct.t[0] + ib[1] * ct.n[1] * ct.t[1];
                tt += ib[0] * ct.t[0] * ct.t[0] + ib[1] * ct.t[1] * ct.t[1];
            }
        }
        ct.w = Block { nn, nt, tt };
        let (p0, stick) = contacts.warm_start(&mut prev, (ct.i, ct.other));
        let own = match ct.other {
            Antagonist::Body(b) => body_mu[b as usize],
            Antagonist::Disk(_) => None,
        };
        ct.mu = own.unwrap_or(if stick { law.mu_static } else { law.mu_dynamic });
        let cohesive = law.cohesion > 0.0 && ct.gap <= law.cohesion_distance;
        ct.shift = if cohesive { h * law.cohesion } else { 0.0 };
        ct.bias = [
            ct.gap.max(0.0) / (theta * h) - nn * ct.shift,
            -nt * ct.shift,
        ];
        // Two immovable bodies: nothing to solve.
        ct.p = if nn > 0.0 { p0 } else { [0.0; 2] };
    }
    list.retain(|c| c.w.nn > 0.0);
    contacts.list = list;
}

/// Newton's impact law of restitution `e` > 0 on the contacts set up by [`build`]: keep
/// the active ones (gap at the predicted configuration ≤ 0) with the bias
/// `[e min(0, U_n⁻), 0]`, U_n⁻ the relative normal velocity at the start of the step
/// from the disks' velocities `v_start` and the bodies' `body_v_start`; drop the others.
pub fn newton(contacts: &mut ContactSet, e: f64, v_start: &[[f64; 2]], body_v_start: &[[f64; 2]]) {
    contacts.list.retain(|c| c.gap <= 0.0);
    for ct in contacts.list.iter_mut() {
        let vi = v_start[ct.i as usize];
        let vj = match ct.other {
            Antagonist::Disk(j) => v_start[j as usize],
            Antagonist::Body(b) => body_v_start[b as usize],
        };
        let un = (vi[0] - vj[0]) * ct.n[0] + (vi[1] - vj[1]) * ct.n[1];
        ct.bias = [e * un.min(0.0), 0.0];
    }
}

/// Add the contacts' current impulses to the body velocities, `q̇ += M⁻¹ H P`: the warm
/// start of the local solver, from the free velocities.
#[allow(clippy::too_many_arguments)]
pub fn apply_impulses(
    contacts: &[Contact],
    v: &mut [[f64; 2]],
    omega: &mut [f64],
    inv_m: &[f64],
    inv_i: &[f64],
    body_v: &mut [[f64; 2]],
    body_inv: &[[f64; 2]],
) {
    for ct in contacts {
        apply(ct, ct.p, v, omega, inv_m, inv_i, body_v, body_inv);
    }
}

/// Add M⁻¹ H dp of one contact to the velocities of its two bodies.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn apply(
    c: &Contact,
    dp: [f64; 2],
    v: &mut [[f64; 2]],
    omega: &mut [f64],
    inv_m: &[f64],
    inv_i: &[f64],
    body_v: &mut [[f64; 2]],
    body_inv: &[[f64; 2]],
) {
    let f = [
        dp[0] * c.n[0] + dp[1] * c.t[0],
        dp[0] * c.n[1] + dp[1] * c.t[1],
    ];
    let i = c.i as usize;
    v[i][0] += inv_m[i] * f[0];
    v[i][1] += inv_m[i] * f[1];
    omega[i] -= c.ri * dp[1] * inv_i[i];
    match c.other {
        Antagonist::Disk(j) => {
            let j = j as usize;
            v[j][0] -= inv_m[j] * f[0];
            v[j][1] -= inv_m[j] * f[1];
            omega[j] -= c.rj * dp[1] * inv_i[j];
        }
        Antagonist::Body(b) => {
            let b = b as usize;
            body_v[b][0] -= body_inv[b][0] * f[0];
            body_v[b][1] -= body_inv[b][1] * f[1];
        }
    }
}
