//! DEM with normal and shear springs and micro-rotations on regular lattices
//! (Nilsen et al. (2017) §2.1, eqs. 7–14).
//!
//! # Why a lattice model and not a cell law
//!
//! A contact with a shear spring needs the particles' micro-rotations `θ` as degrees of
//! freedom: without them a rigid rotation of the assembly stretches the shear springs
//! and produces forces (the paper's remark after eq. 14, checked in the tests). The
//! [`porofrac_law::CellLaw`] trait has displacement-only degrees of freedom, so this
//! DEM variant is not a cell law. It lives here as a small lattice model used to
//! reproduce the effective-moduli relations (eqs. 12–14) that motivate MDEM.
//!
//! # Contact law (eq. 7)
//!
//! Two particles at `X¹, X²` with displacements `U¹, U²` and rotations `θ¹, θ²`:
//! `ΔX = X² − X¹`, `d = |ΔX|`, `I = ΔX/d`, `ΔU = U² − U¹`,
//!
//! ```text
//! ΔU_n = (ΔU·I) I,   ΔU_s = ΔU − ΔU_n − θ × ΔX,   θ = ½(θ¹ + θ²),
//! F = k_n ΔU_n + k_s ΔU_s.
//! ```
//!
//! A rotation is stored as the skew matrix `W` with `W x = θ × x` (in 2D,
//! `W = [[0, −θ], [θ, 0]]`), so 2D and 3D share one code path.
//!
//! # Homogeneous states and stress (eqs. 8–11)
//!
//! Every lattice here is a Bravais lattice with a centro-symmetric neighbourhood, so
//! the affine field `ΔU = ℓ ΔX` with `ℓ = e + r` and a uniform rotation `W` is an exact
//! equilibrium of the infinite lattice: the forces of the contacts `±ΔX` on a particle
//! cancel. The torque on a particle, `Σ_m ΔX^m × F^m`, is the skew part of
//! `Σ_m F^m ⊗ ΔX^m`; it is linear in `W` and [`Lattice::relaxed_rotation`] solves for
//! the `W` that makes it vanish (torque balance, eq. 6b). For the lattices here that is
//! `W = r`, the macroscopic rotation. The stress is the Love–Weber (Cauchy) sum over
//! the contacts of one particle,
//!
//! ```text
//! σ = (1/V) Σ_m d_m F^m ⊗ I^m = (1/V) Σ_m F^m ⊗ ΔX^m .
//! ```
//!
//! # Normalisation
//!
//! The paper takes `V = 1` (and `d = 1`) in this sum ("the effective volume"). Since
//! each contact is shared by two particles, the stress that is the derivative of the
//! energy per unit volume, `W = (1/V_p) Σ_m ½·½ (k_n |ΔU_n|² + k_s |ΔU_s|²)`
//! (`V_p` = volume per particle), is the sum with `V = 2 V_p`; both are available
//! ([`Normalisation`]). With the paper's `V = 1`, `d = 1`:
//!
//! * square (2D) and simple cubic (3D) lattices: `C₁₁ = 2 k_n`, `C₁₂ = 0`, shear
//!   modulus `μ = k_s`. These lattices are not isotropic; the paper's
//!   `λ = 2(k_n − k_s)` is the coefficient of `Σ_i e_ii²` in its energy expression,
//!   i.e. `C₁₁ − 2μ`, not `C₁₂` (the paper's `tr(e) I` should read `diag(e)`).
//! * FCC lattice (the vertices of the regular tetrahedral–octahedral honeycomb, the 3D
//!   "regular simplex" packing): `C₁₂ = k_n − k_s`, `C₄₄ = k_n + k_s`, which is eq. 12
//!   exactly with `λ = C₁₂`, `μ = C₄₄`; `C₁₁ = 2(k_n + k_s)`, so the lattice is
//!   cubic, isotropic only for `k_s = k_n`. Eq. 13, `ν = λ/(2(λ+μ)) = ¼(1 − k_s/k_n)`,
//!   then holds with these `λ, μ`. The isotropic (Voigt) average of the FCC stiffness
//!   has `ν = (k_n − k_s)/(4k_n + k_s)`, with the same limit `ν → 1/4` as `k_s → 0`.
//! * triangular lattice (2D regular simplices; isotropic): `λ = ¾(k_n − k_s)`,
//!   `μ = ¾(k_n + k_s)`, i.e. eq. 12 up to the factor `3d²/(4V)`. Poisson's ratio does
//!   not depend on the factor: plane strain `ν = λ/(2(λ+μ)) = ¼(1 − k_s/k_n)` (eq. 13)
//!   and plane stress `ν = λ/(λ+2μ) = (k_n − k_s)/(3k_n + k_s) ∈ (−1, 1/3)` (eq. 14).

use nalgebra::{DMatrix, DVector};
use porofrac_grid::Point;
use porofrac_law::Tensor;

use crate::MdemError;
use crate::simplex::{kelvin_pairs, kelvin_size};

/// Which volume divides the Love–Weber stress sum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Normalisation {
    /// The choice of Nilsen et al. (2017), `V = 1`.
    Seed,
    /// `V = 2 V_p`: the stress is the derivative of the energy per unit volume.
    Energy,
    /// A given volume `V`.
    Volume(f64),
}

/// A regular lattice of particles connected by normal and shear springs.
#[derive(Clone, Debug, PartialEq)]
pub struct Lattice<const D: usize> {
    neighbours: Vec<Point<D>>,
    particle_volume: f64,
    k_n: f64,
    k_s: f64,
}

fn positive(what: &'static str, value: f64) -> Result<f64, MdemError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(MdemError::LatticeParameter {
            what,
            value,
            why: "must be finite and positive",
        })
    }
}

fn non_negative(what: &'static str, value: f64) -> Result<f64, MdemError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(MdemError::LatticeParameter {
            what,
            value,
            why: "must be finite and non-negative",
        })
    }
}

impl<const D: usize> Lattice<D> {
    /// A lattice from the contact vectors `ΔX` of one particle (the set must be
    /// centro-symmetric: with every `ΔX` it contains `−ΔX`), the volume per particle,
    /// and the spring constants `k_n > 0`, `k_s ≥ 0` (force per unit displacement).
    pub fn new(
        neighbours: Vec<Point<D>>,
        particle_volume: f64,
        k_n: f64,
        k_s: f64,
    ) -> Result<Self, MdemError> {
        if D != 2 && D != 3 {
            return Err(MdemError::UnsupportedDimension(D));
        }
        positive("particle_volume", particle_volume)?;
        positive("k_n", k_n)?;
        non_negative("k_s", k_s)?;
        for (m, x) in neighbours.iter().enumerate() {
            let d = x.norm();
            positive("contact length", d)?;
            if !neighbours.iter().any(|y| (x + y).norm() <= 1e-12 * d) {
                return Err(MdemError::LatticeParameter {
                    what: "contact index",
                    value: m as f64,
                    why: "neighbourhood is not centro-symmetric",
                });
            }
        }
        if neighbours.is_empty() {
            return Err(MdemError::LatticeParameter {
                what: "number of contacts",
                value: 0.0,
                why: "must be positive",
            });
        }
        Ok(Self {
            neighbours,
            particle_volume,
            k_n,
            k_s,
        })
    }

    /// Contact vectors `ΔX` of one particle.
    pub fn neighbours(&self) -> &[Point<D>] {
        &self.neighbours
    }

    /// Volume (area in 2D) per particle.
    pub fn particle_volume(&self) -> f64 {
        self.particle_volume
    }

    /// Force of one contact (eq. 7) for relative displacement `du` and mean rotation
    /// `w` (skew matrix, `w x = θ × x`).
    pub fn contact_force(&self, dx: &Point<D>, du: &Point<D>, w: &Tensor<D>) -> Point<D> {
        let i = dx / dx.norm();
        let dun = i * du.dot(&i);
        let dus = du - dun - w * dx;
        dun * self.k_n + dus * self.k_s
    }

    /// Sum of `F^m ⊗ ΔX^m` over one particle's contacts for the homogeneous state
    /// `ΔU = ℓ ΔX` with uniform rotation `w`.
    fn moment(&self, grad: &Tensor<D>, w: &Tensor<D>) -> Tensor<D> {
        self.neighbours
            .iter()
            .fold(Tensor::<D>::zeros(), |acc, dx| {
                acc + self.contact_force(dx, &(grad * dx), w) * dx.transpose()
            })
    }

    /// Net force on a particle in the homogeneous state (zero for these lattices).
    pub fn net_force(&self, grad: &Tensor<D>, w: &Tensor<D>) -> Point<D> {
        self.neighbours.iter().fold(Point::<D>::zeros(), |acc, dx| {
            acc + self.contact_force(dx, &(grad * dx), w)
        })
    }

    /// Torque on a particle as a skew matrix: `skew(Σ_m F^m ⊗ ΔX^m)`, which is the
    /// matrix `x ↦ τ × x` of `τ = ½ Σ_m ΔX^m × F^m` (half the torque).
    pub fn torque(&self, grad: &Tensor<D>, w: &Tensor<D>) -> Tensor<D> {
        let m = self.moment(grad, w);
        (m - m.transpose()) * 0.5
    }

    /// The uniform rotation `W` (skew) that balances the torque on every particle for
    /// the displacement gradient `grad`. If `k_s = 0` the torque vanishes for every `W`
    /// and the macroscopic rotation `skew(grad)` is returned.
    pub fn relaxed_rotation(&self, grad: &Tensor<D>) -> Tensor<D> {
        let r = (grad - grad.transpose()) * 0.5;
        if self.k_s == 0.0 {
            return r;
        }
        let basis: Vec<Tensor<D>> = (0..D)
            .flat_map(|i| (i + 1..D).map(move |j| (i, j)))
            .map(|(i, j)| {
                let mut b = Tensor::<D>::zeros();
                b[(i, j)] = -1.0;
                b[(j, i)] = 1.0;
                b
            })
            .collect();
        let n = basis.len();
        let coord = |t: &Tensor<D>| -> DVector<f64> {
            DVector::from_iterator(
                n,
                (0..D)
                    .flat_map(|i| (i + 1..D).map(move |j| (i, j)))
                    .map(|(i, j)| t[(j, i)]),
            )
        };
        let t0 = self.torque(grad, &Tensor::<D>::zeros());
        let mut a = DMatrix::<f64>::zeros(n, n);
        for (c, b) in basis.iter().enumerate() {
            let col = coord(&(self.torque(grad, b) - t0));
            a.set_column(c, &col);
        }
        match a.lu().solve(&(-coord(&t0))) {
            Some(x) => basis
                .iter()
                .zip(x.iter())
                .fold(Tensor::<D>::zeros(), |acc, (b, &c)| acc + b * c),
            None => r,
        }
    }

    fn volume(&self, norm: Normalisation) -> f64 {
        match norm {
            Normalisation::Seed => 1.0,
            Normalisation::Energy => 2.0 * self.particle_volume,
            Normalisation::Volume(v) => v,
        }
    }

    /// Love–Weber stress `(1/V) Σ_m F^m ⊗ ΔX^m` for gradient `grad` and rotation `w`.
    pub fn stress(&self, grad: &Tensor<D>, w: &Tensor<D>, norm: Normalisation) -> Tensor<D> {
        self.moment(grad, w) / self.volume(norm)
    }

    /// Elastic energy per unit volume, `(1/V_p) Σ_m ¼ (k_n|ΔU_n|² + k_s|ΔU_s|²)`.
    pub fn energy_density(&self, grad: &Tensor<D>, w: &Tensor<D>) -> f64 {
        let e: f64 = self
            .neighbours
            .iter()
            .map(|dx| {
                let i = dx / dx.norm();
                let du = grad * dx;
                let dun = i * du.dot(&i);
                let dus = du - dun - w * dx;
                0.25 * (self.k_n * dun.norm_squared() + self.k_s * dus.norm_squared())
            })
            .sum();
        e / self.particle_volume
    }

    /// Effective Kelvin stiffness (`3×3` in 2D, `6×6` in 3D) with rotations relaxed:
    /// column `k` is the Kelvin stress for the unit Kelvin strain `k`.
    pub fn effective_stiffness(&self, norm: Normalisation) -> DMatrix<f64> {
        let k = kelvin_size(D);
        let pairs = kelvin_pairs(k);
        let mut c = DMatrix::zeros(k, k);
        for col in 0..k {
            let (i, j) = pairs[col];
            let mut e = Tensor::<D>::zeros();
            if i == j {
                e[(i, i)] = 1.0;
            } else {
                e[(i, j)] = std::f64::consts::FRAC_1_SQRT_2;
                e[(j, i)] = std::f64::consts::FRAC_1_SQRT_2;
            }
            let w = self.relaxed_rotation(&e);
            let s = self.stress(&e, &w, norm);
            for (row, &(a, b)) in pairs.iter().enumerate() {
                c[(row, col)] = if a == b {
                    s[(a, a)]
                } else {
                    std::f64::consts::SQRT_2 * 0.5 * (s[(a, b)] + s[(b, a)])
                };
            }
        }
        c
    }

    /// Lamé pair `(λ, μ) = (C₁₂, C_shear)` read off the effective stiffness: `λ` from
    /// the `e22 → σ11` coupling and `μ` from the last (12) shear component
    /// (`σ = 2μ ε` in Kelvin form). For the cubic lattices these are `C₁₂` and `C₄₄`.
    pub fn lame(&self, norm: Normalisation) -> (f64, f64) {
        let c = self.effective_stiffness(norm);
        let k = c.nrows();
        (c[(0, 1)], 0.5 * c[(k - 1, k - 1)])
    }
}

impl Lattice<2> {
    /// Triangular lattice (2D regular simplices), spacing `d`, 6 contacts.
    pub fn triangular(d: f64, k_n: f64, k_s: f64) -> Result<Self, MdemError> {
        positive("d", d)?;
        let n = (0..6)
            .map(|i| {
                let a = std::f64::consts::FRAC_PI_3 * i as f64;
                Point::<2>::new(d * a.cos(), d * a.sin())
            })
            .collect();
        Self::new(n, 0.5 * 3f64.sqrt() * d * d, k_n, k_s)
    }

    /// Square lattice, spacing `d`, 4 contacts.
    pub fn square(d: f64, k_n: f64, k_s: f64) -> Result<Self, MdemError> {
        positive("d", d)?;
        let n = vec![
            Point::<2>::new(d, 0.0),
            Point::<2>::new(-d, 0.0),
            Point::<2>::new(0.0, d),
            Point::<2>::new(0.0, -d),
        ];
        Self::new(n, d * d, k_n, k_s)
    }
}

impl Lattice<3> {
    /// Simple cubic lattice, spacing `d`, 6 contacts.
    pub fn simple_cubic(d: f64, k_n: f64, k_s: f64) -> Result<Self, MdemError> {
        positive("d", d)?;
        let mut n = Vec::with_capacity(6);
        for a in 0..3 {
            for s in [1.0, -1.0] {
                let mut x = Point::<3>::zeros();
                x[a] = s * d;
                n.push(x);
            }
        }
        Self::new(n, d * d * d, k_n, k_s)
    }

    /// Face-centred cubic lattice with nearest-neighbour distance `d`, 12 contacts
    /// (the vertices of the tetrahedral–octahedral honeycomb of regular simplices).
    pub fn fcc(d: f64, k_n: f64, k_s: f64) -> Result<Self, MdemError> {
        positive("d", d)?;
        let h = d * std::f64::consts::FRAC_1_SQRT_2;
        let mut n = Vec::with_capacity(12);
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            for sa in [1.0, -1.0] {
                for sb in [1.0, -1.0] {
                    let mut x = Point::<3>::zeros();
                    x[a] = sa * h;
                    x[b] = sb * h;
                    n.push(x);
                }
            }
        }
        // Cube side a = √2 d, 4 particles per cube.
        let side = 2.0 * h;
        Self::new(n, side * side * side / 4.0, k_n, k_s)
    }
}
