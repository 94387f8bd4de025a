//! The state of a set of rigid disks as structure-of-arrays.
//!
//! Per unit thickness: m = ρπr², I = m r²/2. A mass or inertia of `f64::INFINITY` makes a
//! disk immovable in translation or in rotation (its inverse is 0).

use crate::ParticleError;

/// Rigid disks: one entry per disk in every array.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Disks {
    /// Centres (m).
    pub x: Vec<[f64; 2]>,
    /// Centres at creation, for displacements (m).
    pub x0: Vec<[f64; 2]>,
    /// Radii (m).
    pub r: Vec<f64>,
    /// Velocities (m/s).
    pub v: Vec<[f64; 2]>,
    /// Rotation angles (rad, counter-clockwise).
    pub angle: Vec<f64>,
    /// Angular velocities (rad/s, counter-clockwise).
    pub omega: Vec<f64>,
    /// Masses (kg per metre of thickness).
    pub mass: Vec<f64>,
    /// Moments of inertia about the centre (kg m²/m).
    pub inertia: Vec<f64>,
}

impl Disks {
    /// Disks at rest with the given centres and radii and a uniform density (kg/m³).
    pub fn new(centres: &[[f64; 2]], radii: &[f64], density: f64) -> Result<Self, ParticleError> {
        if !(density.is_finite() && density > 0.0) {
            return Err(ParticleError::BadDensity(density));
        }
        if centres.len() != radii.len() {
            return Err(ParticleError::BadArgument {
                argument: "radii",
                value: radii.len() as f64,
                message: "needs one radius per centre",
            });
        }
        for (i, (&c, &r)) in centres.iter().zip(radii).enumerate() {
            if !(r.is_finite() && r > 0.0) {
                return Err(ParticleError::BadRadius {
                    index: i,
                    radius: r,
                });
            }
            if !(c[0].is_finite() && c[1].is_finite()) {
                return Err(ParticleError::NotFinite {
                    index: i,
                    what: "centre",
                });
            }
        }
        let n = centres.len();
        let mass: Vec<f64> = radii
            .iter()
            .map(|r| density * std::f64::consts::PI * r * r)
            .collect();
        let inertia = mass
            .iter()
            .zip(radii)
            .map(|(m, r)| 0.5 * m * r * r)
            .collect();
        Ok(Self {
            x: centres.to_vec(),
            x0: centres.to_vec(),
            r: radii.to_vec(),
            v: vec![[0.0; 2]; n],
            angle: vec![0.0; n],
            omega: vec![0.0; n],
            mass,
            inertia,
        })
    }

    /// Number of disks.
    pub fn len(&self) -> usize {
        self.r.len()
    }

    /// No disks.
    pub fn is_empty(&self) -> bool {
        self.r.is_empty()
    }

    /// Displacement of disk `i` from its centre at creation (m).
    pub fn displacement(&self, i: usize) -> [f64; 2] {
        [self.x[i][0] - self.x0[i][0], self.x[i][1] - self.x0[i][1]]
    }

    /// Area of disk `i` (m² per metre of thickness).
    pub fn area(&self, i: usize) -> f64 {
        std::f64::consts::PI * self.r[i] * self.r[i]
    }

    /// Smallest and largest radius (`[0, 0]` without disks).
    pub fn radius_range(&self) -> [f64; 2] {
        if self.r.is_empty() {
            return [0.0; 2];
        }
        self.r
            .iter()
            .fold([f64::INFINITY, 0.0], |[a, b], &r| [a.min(r), b.max(r)])
    }

    /// Total kinetic energy (J per metre).
    pub fn kinetic_energy(&self) -> f64 {
        (0..self.len())
            .map(|i| {
                let m = if self.mass[i].is_finite() {
                    self.mass[i]
                } else {
                    0.0
                };
                let j = if self.inertia[i].is_finite() {
                    self.inertia[i]
                } else {
                    0.0
                };
                0.5 * m * (self.v[i][0].powi(2) + self.v[i][1].powi(2))
                    + 0.5 * j * self.omega[i].powi(2)
            })
            .sum()
    }
}
