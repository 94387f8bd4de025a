//! The contact law and the exact solution of one local problem (Renouf et al. (2006) eq.
//! 6 and the cohesive law of Fig. 3).
//!
//! Unknowns of a contact in its frame (n from the antagonist to the candidate,
//! t = ẑ × n): the impulse P = (P_n, P_t) = h r over the step and the relative velocity
//! at the end of the step, v = b + W P, where W is the 2×2 diagonal block of the
//! Delassus operator and b the velocity without this contact's own impulse.
//!
//! * **Signorini, gap-aware (IQS, zero restitution)**: the complementarity acts on
//!   v̄_n = v_n + max(0, g)/(θh): P_n ≥ 0, v̄_n ≥ 0, P_n v̄_n = 0, so an open gap g is
//!   closed exactly in the step and the contact never rebounds.
//! * **Newton's impact law** (restitution e > 0, Moreau–Jean as in Siconos'
//!   `NewtonImpactFrictionNSL` and LMGC90's `RST_CLB`): a contact whose gap at the
//!   predicted configuration is ≤ 0 is active and the complementarity acts on
//!   v̄_n = v_n + e min(0, v_n⁻), v_n⁻ the relative normal velocity at the start of the
//!   step: an impact at v_n⁻ < 0 leaves at v_n = −e v_n⁻ unless friction or other
//!   contacts hold it; a contact whose predicted gap is > 0 carries no impulse in that
//!   step. With e = 0 the gap-aware law above is used unchanged.
//! * **Cohesion** γ within d_w (status from the gap at the predicted configuration,
//!   g ≤ d_w with γ > 0): the same law on P̄_n = P_n + hγ, so −hγ ≤ P_n; Coulomb acts on
//!   P̄_n (|P_t| ≤ μ P̄_n, as LMGC90's IQS_WET_DS_CLB).
//! * **Coulomb**: |P_t| ≤ μ P̄_n; stick v_t = 0 inside, slide P_t = −μ P̄_n sign(v_t) on
//!   the boundary. μ is μ_s for a contact that stuck at the end of the previous step,
//!   μ_d otherwise.
//!
//! For disks W is diagonal (the lever arm is along n and r²/I = 2/m) and the solution is
//! P̄_n = max(0, −b̄_n/W_nn), P_t = clamp(−b_t/W_tt, ±μ P̄_n). A body free along one
//! axis couples n and t; then the four cases (open, stick, slide+, slide−) are tried in
//! turn and the admissible one is returned.

/// Parameters of the contact law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    /// Static friction coefficient μ_s.
    pub mu_static: f64,
    /// Dynamic friction coefficient μ_d.
    pub mu_dynamic: f64,
    /// Cohesion γ (N per metre of thickness), ≥ 0.
    pub cohesion: f64,
    /// Attraction distance d_w (m), ≥ 0.
    pub cohesion_distance: f64,
    /// Normal restitution coefficient e of Newton's impact law, in [0, 1] (0: the
    /// gap-aware inelastic law). Not with cohesion.
    pub restitution: f64,
}

impl Default for ContactLaw {
    fn default() -> Self {
        Self::frictional(0.0)
    }
}

impl ContactLaw {
    /// Coulomb friction μ (static = dynamic), no cohesion.
    pub fn frictional(mu: f64) -> Self {
        Self {
            mu_static: mu,
            mu_dynamic: mu,
            cohesion: 0.0,
            cohesion_distance: 0.0,
            restitution: 0.0,
        }
    }

    /// The same law with Newton's impact law of restitution `e`.
    pub fn with_restitution(mut self, e: f64) -> Self {
        self.restitution = e;
        self
    }

    /// The same law with cohesion γ within d_w.
    pub fn with_cohesion(mut self, gamma: f64, d_w: f64) -> Self {
        self.cohesion = gamma;
        self.cohesion_distance = d_w;
        self
    }

    /// Check the parameters.
    pub fn check(&self) -> Result<(), crate::NscdError> {
        let non_negative = |name, value: f64| {
            if value.is_finite() && value >= 0.0 {
                Ok(())
            } else {
                Err(crate::NscdError::BadParameter {
                    name,
                    value,
                    message: "must be a finite number ≥ 0",
                })
            }
        };
        non_negative("mu_static", self.mu_static)?;
        non_negative("mu_dynamic", self.mu_dynamic)?;
        non_negative("cohesion", self.cohesion)?;
        non_negative("cohesion_distance", self.cohesion_distance)?;
        if !(0.0..=1.0).contains(&self.restitution) {
            return Err(crate::NscdError::BadParameter {
                name: "restitution",
                value: self.restitution,
                message: "must be in [0, 1]",
            });
        }
        if self.restitution > 0.0 && self.cohesion > 0.0 {
            return Err(crate::NscdError::BadParameter {
                name: "restitution",
                value: self.restitution,
                message: "must be 0 with cohesion (a cohesive contact does not rebound)",
            });
        }
        Ok(())
    }
}

/// The symmetric 2×2 block `[[nn, nt], [nt, tt]]` of W for one contact.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Block {
    /// W_nn.
    pub nn: f64,
    /// W_nt.
    pub nt: f64,
    /// W_tt.
    pub tt: f64,
}

impl Block {
    /// `Pᵀ W P`.
    #[inline]
    pub fn energy(&self, p: [f64; 2]) -> f64 {
        self.nn * p[0] * p[0] + 2.0 * self.nt * p[0] * p[1] + self.tt * p[1] * p[1]
    }
}

/// Solve `v = b + W P` with P_n ≥ 0, v_n ≥ 0, P_n v_n = 0 and Coulomb with μ, exactly.
/// `b` already holds the gap and cohesion shifts; returns (P_n, P_t) (P_n shifted).
#[inline]
pub fn solve_local(w: &Block, b: [f64; 2], mu: f64) -> [f64; 2] {
    if b[0] >= 0.0 {
        return [0.0, 0.0];
    }
    if w.nt == 0.0 {
        let pn = -b[0] / w.nn;
        let pt = if w.tt > 0.0 {
            (-b[1] / w.tt).clamp(-mu * pn, mu * pn)
        } else {
            // No tangential mobility (a fixed disk against a body prescribed along
            // the tangent): the impulse cannot change v_t = b_t; slide against it.
            if b[1] > 0.0 {
                -mu * pn
            } else if b[1] < 0.0 {
                mu * pn
            } else {
                0.0
            }
        };
        return [pn, pt];
    }
    // Stick: W P = −b.
    let det = w.nn * w.tt - w.nt * w.nt;
    if det > 0.0 {
        let pn = (-b[0] * w.tt + b[1] * w.nt) / det;
        let pt = (b[0] * w.nt - b[1] * w.nn) / det;
        if pn >= 0.0 && pt.abs() <= mu * pn {
            return [pn, pt];
        }
    }
    // Slide with v_t of sign s: P_t = −s μ P_n, v_n = 0.
    for s in [1.0, -1.0] {
        let denom = w.nn - s * mu * w.nt;
        if denom <= 0.0 {
            continue;
        }
        let pn = -b[0] / denom;
        let vt = b[1] + w.nt * pn - s * mu * w.tt * pn;
        if pn >= 0.0 && s * vt >= 0.0 {
            return [pn, -s * mu * pn];
        }
    }
    // Not reached for a positive definite W; the projection keeps P admissible (a W
    // of rank one, a fixed disk against a body mobile along one axis, ends here when
    // it neither slides nor opens: its tangential impulse is then left at 0).
    let pn = -b[0] / w.nn;
    let pt = if w.tt > 0.0 { -b[1] / w.tt } else { 0.0 };
    [pn, pt.clamp(-mu * pn, mu * pn)]
}
