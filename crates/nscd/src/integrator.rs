//! The one-step integrator: the Moreau–Jean θ-scheme on velocities (Renouf et al. (2006) eq. 3).
//!
//! On ]t_i, t_i + h], ½ ≤ θ ≤ 1, with M the masses, F the applied forces (constant over
//! the step, so θF_{i+1} + (1 − θ)F_i = F) and H P the contact impulses:
//!
//! * predicted configuration (where contacts are detected):
//!   q_m = q_i + h(1 − θ) q̇_i, for disk centres and body offsets alike;
//! * free velocity (no contact): q̇_free = q̇_i + h M⁻¹ F; a body axis with a prescribed
//!   velocity takes it, a loaded axis is accelerated by its force;
//! * the contact problem adds M⁻¹ H P to q̇_free, giving q̇_{i+1};
//! * positions: q_{i+1} = q_i + h(θ q̇_{i+1} + (1 − θ) q̇_i).
//!
//! A disk of infinite mass (or inertia) has inverse mass (or inertia) 0: it does not
//! move (or rotate). A step that would move a disk by more than its radius is refused
//! and the velocities of the start of the step restored.

use porofrac_particles::Disks;

use crate::NscdError;
use crate::body::{Axis, RigidBody};

/// The state the θ-scheme keeps over one step: inverse masses, the velocities of the
/// start of the step, the predicted configuration and the body velocities.
#[derive(Clone, Debug, Default)]
pub struct MoreauJean {
    /// Inverse mass of every disk (0 for an infinite mass).
    pub(crate) inv_m: Vec<f64>,
    /// Inverse moment of inertia of every disk (0 for an infinite inertia).
    pub(crate) inv_i: Vec<f64>,
    v_old: Vec<[f64; 2]>,
    omega_old: Vec<f64>,
    xm: Vec<[f64; 2]>,
    offsets_m: Vec<[f64; 2]>,
    /// Velocity of every rigid body during the step (free, then with the impulses).
    pub(crate) body_v: Vec<[f64; 2]>,
    body_v_old: Vec<[f64; 2]>,
    /// Inverse mass of every rigid body per axis (0 on a prescribed axis).
    pub(crate) body_inv: Vec<[f64; 2]>,
    /// Every rigid body's own friction coefficient (`None`: the contact law's).
    pub(crate) body_mu: Vec<Option<f64>>,
}

impl MoreauJean {
    /// Start a step of length `h`: the inverse masses, the velocities of the start of
    /// the step, and the predicted configuration `q_i + h(1 − θ) q̇_i` of the disks and
    /// the bodies.
    pub fn predict(&mut self, disks: &Disks, bodies: &[RigidBody], h: f64, theta: f64) {
        // Inverse masses (0 for infinite mass or inertia).
        self.inv_m.clear();
        self.inv_m.extend(
            disks
                .mass
                .iter()
                .map(|&m| if m.is_finite() { 1.0 / m } else { 0.0 }),
        );
        self.inv_i.clear();
        self.inv_i.extend(
            disks
                .inertia
                .iter()
                .map(|&j| if j.is_finite() { 1.0 / j } else { 0.0 }),
        );
        self.v_old.clone_from(&disks.v);
        self.omega_old.clone_from(&disks.omega);
        self.xm.clear();
        let c = h * (1.0 - theta);
        self.xm.extend(
            disks
                .x
                .iter()
                .zip(&disks.v)
                .map(|(x, v)| [x[0] + c * v[0], x[1] + c * v[1]]),
        );
        self.offsets_m.clear();
        self.offsets_m.extend(bodies.iter().map(|b| {
            [
                b.offset[0] + c * b.velocity[0],
                b.offset[1] + c * b.velocity[1],
            ]
        }));
    }

    /// The predicted disk centres of the step (after [`MoreauJean::predict`]).
    pub fn predicted(&self) -> &[[f64; 2]] {
        &self.xm
    }

    /// The predicted body offsets of the step (after [`MoreauJean::predict`]).
    pub fn predicted_offsets(&self) -> &[[f64; 2]] {
        &self.offsets_m
    }

    /// Velocities of the disks and of the bodies at the start of the step (after
    /// [`MoreauJean::free_velocities`]).
    pub fn start_velocities(&self) -> (&[[f64; 2]], &[[f64; 2]]) {
        (&self.v_old, &self.body_v_old)
    }

    /// Inverse masses and inverse moments of inertia of the disks.
    pub fn inverse_masses(&self) -> (&[f64], &[f64]) {
        (&self.inv_m, &self.inv_i)
    }

    /// Velocities of the rigid bodies in the step (free after
    /// [`MoreauJean::free_velocities`], final after the contact problem).
    pub fn body_velocities(&self) -> &[[f64; 2]] {
        &self.body_v
    }

    /// Inverse masses of the rigid bodies per axis (0 on a prescribed axis).
    pub fn body_inverse_masses(&self) -> &[[f64; 2]] {
        &self.body_inv
    }

    /// Free velocities `q̇_i + h M⁻¹ F`: the disks' in place (gravity and the applied
    /// forces `force`), the bodies' into the integrator (prescribed axes take their
    /// velocity, loaded axes are accelerated by their force).
    pub fn free_velocities(
        &mut self,
        disks: &mut Disks,
        bodies: &[RigidBody],
        gravity: [f64; 2],
        force: &[[f64; 2]],
        h: f64,
    ) {
        for i in 0..disks.len() {
            if self.inv_m[i] > 0.0 {
                for a in 0..2 {
                    disks.v[i][a] += h * (gravity[a] + force[i][a] * self.inv_m[i]);
                }
            }
        }
        self.body_v_old.clear();
        self.body_v.clear();
        self.body_inv.clear();
        self.body_mu.clear();
        for b in bodies {
            self.body_v_old.push(b.velocity);
            let mut v = b.velocity;
            for a in 0..2 {
                match b.axes[a] {
                    Axis::Prescribed(p) => v[a] = p,
                    Axis::Loaded(f) => v[a] += h * f / b.mass,
                }
            }
            self.body_v.push(v);
            self.body_inv.push(b.inverse_mass());
            self.body_mu.push(b.friction);
        }
    }

    /// End the step at the velocities `q̇_{i+1}` of `disks` and of the integrator's
    /// bodies: positions `q_i + h(θ q̇_{i+1} + (1 − θ) q̇_i)` and angles likewise. A step
    /// that moves a disk by more than its radius (or gives a non-finite rotation) is
    /// refused: the velocities of the start of the step are restored and nothing moves.
    pub fn update(
        &self,
        disks: &mut Disks,
        bodies: &mut [RigidBody],
        h: f64,
        theta: f64,
        time: f64,
    ) -> Result<(), NscdError> {
        let d = disks;
        for i in 0..d.len() {
            let u = [
                h * (theta * d.v[i][0] + (1.0 - theta) * self.v_old[i][0]),
                h * (theta * d.v[i][1] + (1.0 - theta) * self.v_old[i][1]),
            ];
            let dist = (u[0] * u[0] + u[1] * u[1]).sqrt();
            if dist.is_nan() || dist > d.r[i] || !d.omega[i].is_finite() {
                // Restore the state of the start of the step.
                d.v.clone_from(&self.v_old);
                d.omega.clone_from(&self.omega_old);
                return Err(NscdError::StepTooLarge {
                    time,
                    particle: i,
                    distance: dist,
                    radius: d.r[i],
                });
            }
        }
        for i in 0..d.len() {
            for a in 0..2 {
                d.x[i][a] += h * (theta * d.v[i][a] + (1.0 - theta) * self.v_old[i][a]);
            }
            d.angle[i] += h * (theta * d.omega[i] + (1.0 - theta) * self.omega_old[i]);
        }
        for (k, b) in bodies.iter_mut().enumerate() {
            for a in 0..2 {
                b.offset[a] +=
                    h * (theta * self.body_v[k][a] + (1.0 - theta) * self.body_v_old[k][a]);
            }
            b.velocity = self.body_v[k];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A free disk under gravity: with θ = ½ the scheme integrates a constant
    /// acceleration exactly, x₁ = x₀ + h v₀ + ½ g h².
    #[test]
    fn free_fall_is_exact() {
        let mut d = Disks::new(&[[0.0, 1.0]], &[0.5], 1000.0).unwrap();
        d.v[0] = [0.25, 0.0];
        let mut ig = MoreauJean::default();
        let (h, g) = (0.01, [0.0, -9.81]);
        ig.predict(&d, &[], h, 0.5);
        assert_eq!(ig.predicted(), &[[0.25 * 0.5 * h, 1.0]]);
        ig.free_velocities(&mut d, &[], g, &[[0.0; 2]], h);
        ig.update(&mut d, &mut [], h, 0.5, 0.0).unwrap();
        assert!((d.x[0][0] - 0.25 * h).abs() < 1e-15);
        assert!((d.x[0][1] - (1.0 - 0.5 * 9.81 * h * h)).abs() < 1e-15);
        assert!((d.v[0][1] + 9.81 * h).abs() < 1e-15);
    }

    /// A step that moves a disk by more than its radius is refused and the velocities of
    /// the start of the step come back.
    #[test]
    fn too_large_a_step_is_refused() {
        let mut d = Disks::new(&[[0.0, 0.0]], &[0.1], 1000.0).unwrap();
        d.v[0] = [1.0, 0.0];
        let mut ig = MoreauJean::default();
        ig.predict(&d, &[], 1.0, 0.5);
        ig.free_velocities(&mut d, &[], [0.0, -9.81], &[[0.0; 2]], 1.0);
        let e = ig.update(&mut d, &mut [], 1.0, 0.5, 2.0).unwrap_err();
        assert!(matches!(e, NscdError::StepTooLarge { particle: 0, .. }));
        assert_eq!(d.v[0], [1.0, 0.0]);
        assert_eq!(d.x[0], [0.0, 0.0]);
    }
}
