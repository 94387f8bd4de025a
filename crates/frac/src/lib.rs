//! Failure criteria, the irreversible failure state of cells, and stress recovery.
//!
//! * [`FailureCriterion`]: a stress-based criterion on the effective (skeleton) stress
//!   that the cell laws compute, tension positive. Built in: [`Tensile`] (Nilsen et al.
//!   (2017) eq. 31, `max σ > σ_tens`) and [`MohrCoulomb`]; [`Combined`] checks several and reports
//!   the first mode that fails.
//! * [`FailureState`]: which cells have failed, when and how. Failure is irreversible.
//! * [`mod@resolve`]: the loop that solves, checks, fails and re-solves within a time step
//!   until the state is consistent.
//! * [`recovery`]: superconvergent patch recovery (Zienkiewicz–Zhu) of nodal stresses
//!   from cell stresses on any grid (Nilsen et al. (2017) Fig. 5), and cell values from the
//!   recovered nodal field, so a criterion can be evaluated on a smoother stress near a tip.
//! * [`tracking`]: crack tracking, so a crack grows perpendicular to the largest principal
//!   stress rather than along mesh diagonals.
//! * [`toughness`]: fracture toughness at crack tips ([`Toughness`], [`CrackTips`]), so a
//!   crack grows at the same stress intensity on every grid.
//!
//! What a failed cell becomes is the caller's choice: in porofrac's scenes a failed MDEM
//! cell switches to the compression-only central-force law (Nilsen et al. (2017) eqs. 32–33).

pub mod recovery;
pub mod resolve;
pub mod toughness;
pub mod tracking;

pub use resolve::{CellCriteria, FailurePolicy, ResolveError, resolve};
pub use toughness::{CrackTips, Toughness};
pub use tracking::CrackTracking;

use porofrac_law::Tensor;

/// How a cell failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FailureMode {
    /// The largest principal stress exceeded the tensile strength.
    Tensile,
    /// The Mohr–Coulomb shear criterion was met.
    Shear,
}

impl FailureMode {
    /// `"tensile"` or `"shear"` (as written in `fracture.csv`).
    pub fn as_str(self) -> &'static str {
        match self {
            FailureMode::Tensile => "tensile",
            FailureMode::Shear => "shear",
        }
    }
}

/// Errors of this crate: invalid strength parameters.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FracError {
    /// A parameter is out of range.
    #[error("{name} = {value} {reason}")]
    Parameter {
        /// Parameter name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Why it is invalid.
        reason: &'static str,
    },
}

/// Principal stresses in decreasing order (tension positive), `D` of them followed by
/// zeros ([`porofrac_law::principal()`]).
pub fn principal_stresses<const D: usize>(s: &Tensor<D>) -> [f64; 3] {
    let mut e = [0.0; 3];
    e[..D].copy_from_slice(&porofrac_law::principal(s).values);
    e
}

/// A stress-based failure criterion.
pub trait FailureCriterion<const D: usize>: Send + Sync {
    /// The failure mode if the effective stress `s` (tension positive) fails the
    /// criterion, else `None`.
    fn check(&self, s: &Tensor<D>) -> Option<FailureMode>;

    /// How close the stress is to failure: ≥ 1 means failed (used to pick the most
    /// critical cell when failures are resolved one at a time).
    fn utilization(&self, s: &Tensor<D>) -> f64;
}

/// Tensile failure (Nilsen et al. (2017) eq. 31): `max σ > σ_tens`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tensile {
    strength: f64,
}

impl Tensile {
    /// A tensile criterion; the strength must be positive and finite.
    pub fn new(strength: f64) -> Result<Self, FracError> {
        if !(strength.is_finite() && strength > 0.0) {
            return Err(FracError::Parameter {
                name: "tensile_strength",
                value: strength,
                reason: "must be > 0",
            });
        }
        Ok(Self { strength })
    }
    /// The tensile strength (Pa).
    pub fn strength(&self) -> f64 {
        self.strength
    }
}

impl Tensile {
    /// Whether the effective stress `s` can fail this criterion. `false` when Gershgorin's
    /// bound on the largest principal stress, `max_i (s_ii + Σ_{j≠i} |s_ij|)`, stays below
    /// the strength by more than the rounding of an eigen-solver (1e-10 of the largest
    /// entry): a screen of a few additions that never changes a decision of
    /// [`FailureCriterion::check`] (a non-finite stress is never screened out).
    pub fn may_fail<const D: usize>(&self, s: &Tensor<D>) -> bool {
        let bound = (0..D)
            .map(|i| {
                s[(i, i)]
                    + (0..D)
                        .filter(|&j| j != i)
                        .map(|j| s[(i, j)].abs())
                        .sum::<f64>()
            })
            .fold(f64::NEG_INFINITY, f64::max);
        let margin = bound + 1e-10 * s.amax();
        // NaN compares false: a non-finite stress is never screened out.
        margin >= self.strength || margin.is_nan()
    }
}

impl<const D: usize> FailureCriterion<D> for Tensile {
    fn check(&self, s: &Tensor<D>) -> Option<FailureMode> {
        (principal_stresses(s)[0] > self.strength).then_some(FailureMode::Tensile)
    }
    fn utilization(&self, s: &Tensor<D>) -> f64 {
        principal_stresses(s)[0] / self.strength
    }
}

/// Mohr–Coulomb shear failure with cohesion `c` and friction angle `φ`.
///
/// With principal stresses σ₁ ≥ σ₃ (tension positive; in 2D the in-plane ones), the
/// Mohr circle touches the envelope `|τ| = c − σₙ tan φ` when
/// `(σ₁ − σ₃)/2 ≥ c cos φ − (σ₁ + σ₃)/2 · sin φ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MohrCoulomb {
    cohesion: f64,
    sin_phi: f64,
    cos_phi: f64,
}

impl MohrCoulomb {
    /// A Mohr–Coulomb criterion; `cohesion ≥ 0`, `0 ≤ friction_angle_deg < 90`.
    pub fn new(cohesion: f64, friction_angle_deg: f64) -> Result<Self, FracError> {
        if !(cohesion.is_finite() && cohesion >= 0.0) {
            return Err(FracError::Parameter {
                name: "cohesion",
                value: cohesion,
                reason: "must be ≥ 0",
            });
        }
        if !(0.0..90.0).contains(&friction_angle_deg) {
            return Err(FracError::Parameter {
                name: "friction_angle",
                value: friction_angle_deg,
                reason: "must be in [0, 90) degrees",
            });
        }
        let phi = friction_angle_deg.to_radians();
        Ok(Self {
            cohesion,
            sin_phi: phi.sin(),
            cos_phi: phi.cos(),
        })
    }

    fn radius_and_limit<const D: usize>(&self, s: &Tensor<D>) -> (f64, f64) {
        let p = principal_stresses(s);
        let (s1, s3) = (p[0], p[D - 1]);
        let radius = 0.5 * (s1 - s3);
        let limit = self.cohesion * self.cos_phi - 0.5 * (s1 + s3) * self.sin_phi;
        (radius, limit)
    }
}

impl<const D: usize> FailureCriterion<D> for MohrCoulomb {
    fn check(&self, s: &Tensor<D>) -> Option<FailureMode> {
        let (radius, limit) = self.radius_and_limit(s);
        (radius >= limit && radius > 0.0).then_some(FailureMode::Shear)
    }
    fn utilization(&self, s: &Tensor<D>) -> f64 {
        let (radius, limit) = self.radius_and_limit(s);
        if limit <= 0.0 {
            if radius > 0.0 { f64::INFINITY } else { 0.0 }
        } else {
            radius / limit
        }
    }
}

/// Several criteria: the first that fails gives the mode.
#[derive(Clone, Debug, Default)]
pub struct Combined {
    /// Tensile criterion, if the material has a tensile strength.
    pub tensile: Option<Tensile>,
    /// Shear criterion, if the material has a cohesion and friction angle.
    pub shear: Option<MohrCoulomb>,
    /// Fracture toughness: a crack-tip cell also needs `K_c > K_Ic` to fail in tension
    /// ([`toughness`]).
    pub toughness: Option<Toughness>,
}

impl Combined {
    /// Whether no criterion is set (the material never fails).
    pub fn is_empty(&self) -> bool {
        self.tensile.is_none() && self.shear.is_none()
    }

    /// Whether the stress `s` can fail any criterion here, at a crack tip or not: a cheap
    /// screen ([`Tensile::may_fail`]) that is `true` whenever [`Self::check_at`] could
    /// return a mode.
    pub fn may_fail<const D: usize>(&self, s: &Tensor<D>) -> bool {
        self.shear.is_some() || self.tensile.as_ref().is_some_and(|t| t.may_fail(s))
    }

    /// Tensile utilization; at a crack tip (`tip_radius`: the cell's equivalent radius,
    /// see [`CrackTips::tip_radius`]) with a toughness, the smaller of `σ₁/σ_t` and
    /// `K_c/K_Ic`: both must exceed 1.
    fn tensile_utilization<const D: usize>(&self, s: &Tensor<D>, tip_radius: Option<f64>) -> f64 {
        let Some(t) = &self.tensile else {
            return 0.0;
        };
        let strength = FailureCriterion::<D>::utilization(t, s);
        match (tip_radius, &self.toughness) {
            (Some(r), Some(k)) => strength.min(k.utilization(toughness::sigma_1(s), r)),
            _ => strength,
        }
    }

    /// The failure mode of stress `s` in a cell that is at a crack tip with equivalent
    /// radius `r` (`tip_radius = Some(r)`) or not (`None`): tension first, then shear.
    pub fn check_at<const D: usize>(
        &self,
        s: &Tensor<D>,
        tip_radius: Option<f64>,
    ) -> Option<FailureMode> {
        if self.tensile_utilization(s, tip_radius) > 1.0 {
            return Some(FailureMode::Tensile);
        }
        self.shear
            .as_ref()
            .and_then(|c| FailureCriterion::<D>::check(c, s))
    }

    /// The utilization of [`Self::check_at`]: the largest over the criteria.
    pub fn utilization_at<const D: usize>(&self, s: &Tensor<D>, tip_radius: Option<f64>) -> f64 {
        let m = self
            .shear
            .as_ref()
            .map_or(0.0, |c| FailureCriterion::<D>::utilization(c, s));
        self.tensile_utilization(s, tip_radius).max(m)
    }
}

impl<const D: usize> FailureCriterion<D> for Combined {
    fn check(&self, s: &Tensor<D>) -> Option<FailureMode> {
        self.check_at(s, None)
    }
    fn utilization(&self, s: &Tensor<D>) -> f64 {
        self.utilization_at(s, None)
    }
}

/// One recorded failure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Failure {
    /// The cell.
    pub cell: usize,
    /// When it failed (s).
    pub time: f64,
    /// How.
    pub mode: FailureMode,
}

/// Irreversible failure state of the cells of a grid.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FailureState {
    failed: Vec<bool>,
    log: Vec<Failure>,
}

impl FailureState {
    /// No cell failed yet.
    pub fn new(num_cells: usize) -> Self {
        Self {
            failed: vec![false; num_cells],
            log: Vec::new(),
        }
    }
    /// The state of `num_cells` cells after the failures of `log` (in the order they
    /// happened, as [`Self::log`] gives them: a saved state put back). Errors name a cell
    /// out of range or recorded twice.
    pub fn from_log(num_cells: usize, log: Vec<Failure>) -> Result<Self, String> {
        let mut failed = vec![false; num_cells];
        for f in &log {
            match failed.get_mut(f.cell) {
                None => return Err(format!("failed cell {} of {num_cells}", f.cell)),
                Some(true) => return Err(format!("cell {} failed twice", f.cell)),
                Some(x) => *x = true,
            }
        }
        Ok(Self { failed, log })
    }
    /// Whether cell `c` has failed.
    pub fn is_failed(&self, c: usize) -> bool {
        self.failed[c]
    }
    /// Per-cell flags.
    pub fn flags(&self) -> &[bool] {
        &self.failed
    }
    /// All failures in the order they happened.
    pub fn log(&self) -> &[Failure] {
        &self.log
    }
    /// Number of failed cells.
    pub fn count(&self) -> usize {
        self.log.len()
    }
    /// Record a failure; returns `false` (and changes nothing) if the cell had already
    /// failed: failure is irreversible and recorded once.
    pub fn fail(&mut self, cell: usize, time: f64, mode: FailureMode) -> bool {
        if self.failed[cell] {
            return false;
        }
        self.failed[cell] = true;
        self.log.push(Failure { cell, time, mode });
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t2(a: f64, b: f64, c: f64) -> Tensor<2> {
        Tensor::<2>::new(a, c, c, b)
    }

    proptest::proptest! {
        /// The screen never hides a failure: whenever `may_fail` is false, the criterion
        /// does not fail (random symmetric stresses around the strength, 2D and 3D).
        #[test]
        fn tensile_screen_never_hides_a_failure(
            e in proptest::collection::vec(-3.0f64..1.5, 6),
        ) {
            let t = Tensile::new(1.0).unwrap();
            let s3 = Tensor::<3>::new(e[0], e[3], e[4], e[3], e[1], e[5], e[4], e[5], e[2]);
            if !t.may_fail(&s3) {
                proptest::prop_assert!(FailureCriterion::<3>::check(&t, &s3).is_none());
            }
            let s2 = t2(e[0], e[1], e[3]);
            if !t.may_fail(&s2) {
                proptest::prop_assert!(FailureCriterion::<2>::check(&t, &s2).is_none());
            }
        }
    }

    /// A log put back gives the same state; a cell out of range or failed twice is
    /// refused.
    #[test]
    fn failure_state_from_its_log() {
        let mut f = FailureState::new(5);
        f.fail(3, 1.0, FailureMode::Tensile);
        f.fail(0, 2.5, FailureMode::Shear);
        assert_eq!(FailureState::from_log(5, f.log().to_vec()).unwrap(), f);
        let twice = vec![f.log()[0]; 2];
        assert!(
            FailureState::from_log(5, twice)
                .unwrap_err()
                .contains("twice")
        );
        assert!(FailureState::from_log(3, f.log().to_vec()).is_err());
    }

    #[test]
    fn tensile_screen_passes_over_compression_and_keeps_tension() {
        let t = Tensile::new(2.0e5).unwrap();
        let compressive = Tensor::<3>::new(-4e6, 1e5, 0.0, 1e5, -1.5e7, 2e4, 0.0, 2e4, -5.7e6);
        assert!(!t.may_fail(&compressive));
        // Diagonal below the strength, but a shear that lifts σ₁ above it.
        let sheared = t2(1.0e5, 1.0e5, 1.5e5);
        assert!(t.may_fail(&sheared));
        assert_eq!(
            FailureCriterion::<2>::check(&t, &sheared),
            Some(FailureMode::Tensile)
        );
    }

    #[test]
    fn principal_stresses_of_a_rotated_state() {
        // σ = R diag(3, -1) Rᵀ with a 30° rotation.
        let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
        let r = nalgebra::Matrix2::new(c, -s, s, c);
        let m = r * nalgebra::Matrix2::new(3.0, 0.0, 0.0, -1.0) * r.transpose();
        let p = principal_stresses::<2>(&m);
        assert!((p[0] - 3.0).abs() < 1e-14 && (p[1] + 1.0).abs() < 1e-14);
        let m3 = nalgebra::Matrix3::new(2.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, -5.0);
        let p = principal_stresses::<3>(&m3);
        assert!(
            (p[0] - 3.0).abs() < 1e-13 && (p[1] - 1.0).abs() < 1e-13 && (p[2] + 5.0).abs() < 1e-13
        );
    }

    #[test]
    fn tensile_criterion_is_eq_31() {
        let c = Tensile::new(2e5).unwrap();
        assert_eq!(
            FailureCriterion::<2>::check(&c, &t2(1.9e5, -1e7, 0.0)),
            None
        );
        assert_eq!(
            FailureCriterion::<2>::check(&c, &t2(2.1e5, -1e7, 0.0)),
            Some(FailureMode::Tensile)
        );
        // Pure shear τ has principal stresses ±τ.
        assert_eq!(
            FailureCriterion::<2>::check(&c, &t2(0.0, 0.0, 2.5e5)),
            Some(FailureMode::Tensile)
        );
        assert!((FailureCriterion::<2>::utilization(&c, &t2(1e5, 0.0, 0.0)) - 0.5).abs() < 1e-15);
        assert!(Tensile::new(0.0).is_err() && Tensile::new(f64::NAN).is_err());
    }

    #[test]
    fn mohr_coulomb_matches_the_envelope() {
        // φ = 30°: failure when σ1 − σ3 ≥ c·√3 − (σ1 + σ3)/2 (sin 30° = 1/2, times 2).
        let c = MohrCoulomb::new(1e6, 30.0).unwrap();
        // Uniaxial compression σ3 = −q: fails at q = 2c cos φ / (1 − sin φ) = 2√3·1e6.
        let q = 2.0 * 1e6 * 30f64.to_radians().cos() / (1.0 - 0.5);
        assert_eq!(
            FailureCriterion::<2>::check(&c, &t2(0.0, -0.999 * q, 0.0)),
            None
        );
        assert_eq!(
            FailureCriterion::<2>::check(&c, &t2(0.0, -1.001 * q, 0.0)),
            Some(FailureMode::Shear)
        );
        assert!((FailureCriterion::<2>::utilization(&c, &t2(0.0, -q, 0.0)) - 1.0).abs() < 1e-12);
        // Confinement strengthens: the same deviator with −5 MPa all round does not fail.
        assert_eq!(
            FailureCriterion::<2>::check(&c, &t2(-5e6, -5e6 - 1.001 * q, 0.0)),
            None
        );
        // Hydrostatic compression never fails.
        assert_eq!(
            FailureCriterion::<3>::check(&c, &Tensor::<3>::identity().scale(-1e9)),
            None
        );
        assert!(MohrCoulomb::new(-1.0, 30.0).is_err() && MohrCoulomb::new(1.0, 90.0).is_err());
    }

    #[test]
    fn combined_reports_tension_first_and_state_is_irreversible() {
        let c = Combined {
            tensile: Some(Tensile::new(1e5).unwrap()),
            shear: Some(MohrCoulomb::new(1e5, 30.0).unwrap()),
            toughness: None,
        };
        assert_eq!(
            FailureCriterion::<2>::check(&c, &t2(2e5, -1e7, 0.0)),
            Some(FailureMode::Tensile)
        );
        assert_eq!(
            FailureCriterion::<2>::check(&c, &t2(-1e5, -1e7, 0.0)),
            Some(FailureMode::Shear)
        );
        assert!(Combined::default().is_empty());
        assert_eq!(
            FailureCriterion::<2>::check(&Combined::default(), &t2(1e12, 0.0, 0.0)),
            None
        );
        let mut st = FailureState::new(4);
        assert!(st.fail(2, 1.0, FailureMode::Tensile));
        assert!(!st.fail(2, 2.0, FailureMode::Shear));
        assert_eq!(st.count(), 1);
        assert_eq!(
            st.log()[0],
            Failure {
                cell: 2,
                time: 1.0,
                mode: FailureMode::Tensile
            }
        );
        assert_eq!(st.flags(), &[false, false, true, false]);
    }
}
