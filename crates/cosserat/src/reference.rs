//! Closed-form references for the verification problems of Marazzato (2021),
//! arXiv:2101.08712, §3.8–§4.2 (derived here).
//!
//! * [`ShearLayer`]: the 1D Cosserat shear layer (E3). With `σ12 = τ` constant and
//!   `δ² = 4 G Gc / ((G + Gc) M)` (`M` the 2D couple modulus, `m = M φ'`):
//!   `φ = K1 e^{δ(x−h)} + K2 e^{−δx} − τ/(2G)`,
//!   `u1 = τx/G − κ0 (K1 e^{δ(x−h)} − K2 e^{−δx}) + K3`, `κ0 = 2Gc/((G+Gc)δ)`, the four
//!   constants from the end data.
//! * [`hole_scf`]: the stress concentration factor of a circular hole in a plate under
//!   uniaxial tension (Mindlin; Kaloni–Ariman),
//!   `F = 8(1−ν)N² / (4 + (r/c)² + 2 (r/c) K0(r/c)/K1(r/c))`, `c = ℓ/N`,
//!   `SCF = (3 + F)/(1 + F)`, with `N² = Gc/(G+Gc)` and `ℓ` the length of `m = 4Gℓ²κ`.

use nalgebra::{Matrix4, Vector4};

/// The shear-layer closed form for one set of end data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShearLayer {
    /// Layer thickness h.
    pub h: f64,
    /// Shear modulus G.
    pub g: f64,
    /// `δ`.
    pub delta: f64,
    /// `κ0`.
    pub kappa0: f64,
    /// `K1, K2, K3`.
    pub k: [f64; 3],
    /// The constant shear stress `σ12 = τ`.
    pub tau: f64,
}

impl ShearLayer {
    /// Solve for the constants given `u1(0) = u0, φ(0) = p0, u1(h) = u1, φ(h) = p1`.
    /// `m` is the 2D couple modulus (`4Gℓ²`).
    pub fn new(h: f64, g: f64, gc: f64, m: f64, ends: [f64; 4]) -> Self {
        let delta = 2.0 * (g * gc / ((g + gc) * m)).sqrt();
        let kappa0 = 2.0 * gc / ((g + gc) * delta);
        let (e0h, e1h) = ((-delta * h).exp(), 1.0);
        // Unknowns (K1, K2, K3, τ); rows: u(0), φ(0), u(h), φ(h).
        let a = Matrix4::new(
            -kappa0 * e0h,
            kappa0,
            1.0,
            0.0,
            e0h,
            1.0,
            0.0,
            -1.0 / (2.0 * g),
            -kappa0 * e1h,
            kappa0 * e0h,
            1.0,
            h / g,
            e1h,
            e0h,
            0.0,
            -1.0 / (2.0 * g),
        );
        let [u0, p0, u1, p1] = ends;
        let x = a
            .lu()
            .solve(&Vector4::new(u0, p0, u1, p1))
            .expect("the shear-layer system is regular for δh > 0");
        Self {
            h,
            g,
            delta,
            kappa0,
            k: [x[0], x[1], x[2]],
            tau: x[3],
        }
    }

    /// Rotation φ at `x`.
    pub fn phi(&self, x: f64) -> f64 {
        let (a, b) = self.exps(x);
        self.k[0] * a + self.k[1] * b - self.tau / (2.0 * self.g)
    }

    /// Displacement u1 at `x`.
    pub fn u1(&self, x: f64) -> f64 {
        let (a, b) = self.exps(x);
        self.tau * x / self.g - self.kappa0 * (self.k[0] * a - self.k[1] * b) + self.k[2]
    }

    fn exps(&self, x: f64) -> (f64, f64) {
        ((self.delta * (x - self.h)).exp(), (-self.delta * x).exp())
    }
}

/// Modified Bessel function `I0` (Abramowitz–Stegun 9.8.1, |x| ≤ 3.75).
fn bessel_i0(x: f64) -> f64 {
    let t = (x / 3.75).powi(2);
    1.0 + t
        * (3.5156229
            + t * (3.0899424 + t * (1.2067492 + t * (0.2659732 + t * (0.0360768 + t * 0.0045813)))))
}

/// Modified Bessel function `I1` (Abramowitz–Stegun 9.8.3, |x| ≤ 3.75).
fn bessel_i1(x: f64) -> f64 {
    let t = (x / 3.75).powi(2);
    x * (0.5
        + t * (0.87890594
            + t * (0.51498869
                + t * (0.15084934 + t * (0.02658733 + t * (0.00301532 + t * 0.00032411))))))
}

/// Modified Bessel function of the second kind `K0` (Abramowitz–Stegun 9.8.5–6; relative
/// error below 1e-7).
pub fn bessel_k0(x: f64) -> f64 {
    if x <= 2.0 {
        let y = x * x / 4.0;
        -(x / 2.0).ln() * bessel_i0(x)
            + (-0.57721566
                + y * (0.42278420
                    + y * (0.23069756
                        + y * (0.03488590 + y * (0.00262698 + y * (0.00010750 + y * 0.0000074))))))
    } else {
        let y = 2.0 / x;
        (-x).exp() / x.sqrt()
            * (1.25331414
                + y * (-0.07832358
                    + y * (0.02189568
                        + y * (-0.01062446
                            + y * (0.00587872 + y * (-0.00251540 + y * 0.00053208))))))
    }
}

/// Modified Bessel function of the second kind `K1` (Abramowitz–Stegun 9.8.7–8).
pub fn bessel_k1(x: f64) -> f64 {
    if x <= 2.0 {
        let y = x * x / 4.0;
        (x / 2.0).ln() * bessel_i1(x)
            + (1.0 / x)
                * (1.0
                    + y * (0.15443144
                        + y * (-0.67278579
                            + y * (-0.18156897
                                + y * (-0.01919402 + y * (-0.00110404 + y * (-0.00004686)))))))
    } else {
        let y = 2.0 / x;
        (-x).exp() / x.sqrt()
            * (1.25331414
                + y * (0.23498619
                    + y * (-0.03655620
                        + y * (0.01504268
                            + y * (-0.00780353 + y * (0.00325614 + y * (-0.00068245)))))))
    }
}

/// Stress concentration factor of a circular hole of radius `r` (see the module docs).
/// `n` is the coupling number `N = √(Gc/(G+Gc))`; `N = 0` gives the Cauchy value 3.
pub fn hole_scf(nu: f64, n: f64, r: f64, length: f64) -> f64 {
    if n == 0.0 {
        return 3.0;
    }
    let c = length / n;
    let x = r / c;
    let f = 8.0 * (1.0 - nu) * n * n / (4.0 + x * x + 2.0 * x * bessel_k0(x) / bessel_k1(x));
    (3.0 + f) / (1.0 + f)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shear layer of Marazzato (2021) §3.9.2 with u1 = 1e-5 m on top and no end
    /// rotations: τ = 108.891 MPa and the sample points.
    #[test]
    fn shear_layer_instance_a() {
        let s = ShearLayer::new(1e-3, 1e10, 2e10, 100.0, [0.0, 0.0, 1e-5, 0.0]);
        assert!((s.delta - 16_329.9).abs() < 0.1);
        assert!((s.tau / 108.891e6 - 1.0).abs() < 1e-5);
        for (x, phi, u) in [
            (0.05e-3, -3.0382e-3, 2.9639e-7),
            (0.25e-3, -5.3527e-3, 2.2852e-6),
            (0.5e-3, -5.4414e-3, 5.0000e-6),
            (0.95e-3, -3.0382e-3, 9.7036e-6),
        ] {
            assert!((s.phi(x) / phi - 1.0).abs() < 2e-4, "φ({x})");
            assert!((s.u1(x) / u - 1.0).abs() < 2e-4, "u1({x})");
        }
        let b = ShearLayer::new(1e-3, 1e10, 2e10, 100.0, [0.0, 0.0, 1e-5, -0.1]);
        assert!((b.tau / 19.982e6 - 1.0).abs() < 1e-4);
        assert!((b.phi(0.9e-3) / -2.03383e-2 - 1.0).abs() < 2e-4);
    }

    /// The SCF of the plate with a hole of Marazzato (2021) §3.9.1, Mindlin's closed form
    /// (ν = 0.3).
    #[test]
    fn scf_table() {
        for (n, rl, want) in [
            (0.25, 1.063, 2.8493),
            (0.5, 1.063, 2.5548),
            (0.9, 1.063, 2.1579),
            (0.5, 3.0, 2.7189),
            (0.75, 3.0, 2.6050),
            (0.25, 10.63, 2.9561),
            (0.9, 10.0, 2.9149),
        ] {
            let got = hole_scf(0.3, n, rl, 1.0);
            assert!(
                (got - want).abs() < 1.5e-4,
                "N = {n}, r/ℓ = {rl}: {got} vs {want}"
            );
        }
        assert_eq!(hole_scf(0.3, 0.0, 1.0, 1.0), 3.0);
    }
}
