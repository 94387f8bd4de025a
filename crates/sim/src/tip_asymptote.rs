//! The position of a hydraulic fracture's front from the opening behind it and the tip
//! asymptote of its propagation regime (the tip rule `TipRule::Asymptote` of
//! [`crate::fracturing`]).
//!
//! A fluid-driven crack in an impermeable rock, its front moving at the speed `V`, opens
//! near the front as the universal tip asymptote of Garagash & Detournay (2000), between
//! two limits at a distance `r` from the front:
//!
//! ```text
//!   toughness:  w_k(r) = (K′/E′) r^{1/2},               K′ = 4 √(2/π) K_Ic,
//!   viscosity:  w_m(r) = β_m (μ′V/E′)^{1/3} r^{2/3},     β_m = 2^{1/3} 3^{5/6},  μ′ = 12 μ.
//! ```
//!
//! Between them this module takes `w³ = w_k³ + w_m³` (the zeroth-order approximation of the
//! toughness–viscosity edge, exact in both limits; the crossover lies at
//! `r ≈ (K′³/(μ′V E′²))²`, a fraction of a millimetre on `scenes/kgd_viscosity.toml`, so
//! at the scale of a cell either limit holds and the approximation in between does not
//! matter there).
//!
//! The tip rule from the opening ([`crate::tip_opening`]) reads an opening `w` at the
//! distance `r` behind a tip as if the profile were `√r`. On a viscous `r^{2/3}` profile
//! that estimate of `K_I` grows as `r^{1/6}`, so it depends on the cell size (12 % per
//! halving), and the crack stops converging. Here, as the implicit level-set algorithm
//! of Peirce & Detournay (2008) does, the opening `w` on the back line, at the position
//! `b` along the crack, is inverted for the distance `d(w, V)` to the front that this
//! asymptote gives, with the speed `V` the front's own over the step (backward Euler):
//!
//! ```text
//!   x_f = b + d(w, V),      V = (x_f − x_f⁰)/Δt ≥ 0,
//! ```
//!
//! `x_f⁰` the front at the start of the step (or the tip when there was none). The
//! distance `d` falls as `V` grows, so the equation has one root, found by bisection; when
//! the front at rest (`V = 0`, the toughness asymptote) lies behind `x_f⁰`, the front does
//! not move. The tip cell fails when the front lies beyond the tip, `x_f > tip`: the band
//! of failed cells is the crack the rock sees, so a front beyond its tip means an opening
//! behind it larger than a crack ending at the tip can have at that speed (for a crack at
//! rest, `K_I > K_Ic`: the rule of [`crate::tip_opening`], unchanged). Asking the front to
//! cross a fraction `θ` of the tip cell instead raises the toughness the band must reach
//! by `√(1 + θL/r)`, whatever the cell size (with `θ = 1/2`, +30 % on the inlet pressure of
//! `scenes/kgd_toughness.toml`).
//!
//! The speed is the front's over a step, and a cell that fails during a step is dry until
//! the fluid reaches it: the front advances about one cell per step at most, so the step
//! must shrink with the cells (`V Δt ≲ h`; docs/hydrofrac/validation.md, "KGD,
//! viscosity-dominated").

use porofrac_grid::Point;

/// `β_m = 2^{1/3} 3^{5/6}`, the constant of the viscosity tip asymptote.
pub fn beta_m() -> f64 {
    2f64.powf(1.0 / 3.0) * 3f64.powf(5.0 / 6.0)
}

/// `K′ = 4 √(2/π) K_Ic` (Pa·√m) of a toughness `K_Ic` (Pa·√m).
pub fn k_prime(k_ic: f64) -> f64 {
    4.0 * (2.0 / std::f64::consts::PI).sqrt() * k_ic
}

/// The tip asymptote of a fluid-driven crack (module docs): the toughness `K′` (Pa·√m),
/// the plane-strain modulus `E′` (Pa) and the fluid's `μ′ = 12 μ` (Pa·s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TipAsymptote {
    /// `K′ = 4 √(2/π) K_Ic` (Pa·√m).
    pub k_prime: f64,
    /// `E′ = E/(1 − ν²)` (Pa).
    pub e_prime: f64,
    /// `μ′ = 12 μ` (Pa·s).
    pub mu_prime: f64,
}

/// The front found by [`TipAsymptote::front`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Front {
    /// The front's position along the crack (m, the coordinate of the back line's).
    pub position: f64,
    /// Its speed over the step (m/s, ≥ 0).
    pub speed: f64,
}

impl TipAsymptote {
    /// The opening (m) at the distance `r` (m) behind a front moving at `v` (m/s):
    /// `(w_k³ + w_m³)^{1/3}`.
    pub fn opening(&self, r: f64, v: f64) -> f64 {
        let (a, b) = self.coefficients(v);
        let s = r.max(0.0).sqrt();
        (a * s * s * s + b * s * s * s * s).cbrt()
    }

    /// `(K′/E′)³` and `β_m³ μ′ v/E′`: the opening cubed is `a r^{3/2} + b r²`.
    fn coefficients(&self, v: f64) -> (f64, f64) {
        let a = (self.k_prime / self.e_prime).powi(3);
        let b = beta_m().powi(3) * self.mu_prime * v.max(0.0) / self.e_prime;
        (a, b)
    }

    /// The distance (m) behind a front moving at `v` (m/s) where the asymptote opens by
    /// `w` (m): the inverse of [`TipAsymptote::opening`] in `r`; 0 for `w ≤ 0`, infinite
    /// when neither toughness nor speed holds the crack (`K′ = 0` and `v = 0`).
    pub fn distance(&self, w: f64, v: f64) -> f64 {
        if w <= 0.0 {
            return 0.0;
        }
        let (a, b) = self.coefficients(v);
        let w3 = w * w * w;
        // In s = √r: f(s) = a s³ + b s⁴ − w³, increasing and convex for s > 0; Newton
        // from the smaller of the two one-term roots (above the root) falls monotonically.
        let mut s = f64::INFINITY;
        if a > 0.0 {
            s = s.min((w3 / a).cbrt());
        }
        if b > 0.0 {
            s = s.min((w3 / b).powf(0.25));
        }
        if !s.is_finite() {
            return f64::INFINITY;
        }
        for _ in 0..100 {
            let f = a * s * s * s + b * s * s * s * s - w3;
            let df = 3.0 * a * s * s + 4.0 * b * s * s * s;
            if f <= 0.0 || df <= 0.0 {
                break;
            }
            let next = s - f / df;
            if next >= s || next <= 0.0 {
                break;
            }
            s = next;
        }
        s * s
    }

    /// The front at the end of a step of `dt` (s) from an opening `w` (m) on the back
    /// line at the position `back` (m along the crack), the front having been at
    /// `previous` at the start of the step (module docs). With `dt ≤ 0` the front is the
    /// one at rest.
    pub fn front(&self, w: f64, back: f64, previous: f64, dt: f64) -> Front {
        let at_rest = back + self.distance(w, 0.0);
        if dt <= 0.0 || at_rest <= previous {
            return Front {
                position: at_rest,
                speed: 0.0,
            };
        }
        // g(v) = back + d(w, v) − previous − v dt falls with v; g(0) > 0.
        let g = |v: f64| back + self.distance(w, v) - previous - v * dt;
        let mut hi = if at_rest.is_finite() {
            (at_rest - previous) / dt
        } else {
            let mut v = w.max(f64::MIN_POSITIVE) / dt;
            while g(v) > 0.0 && v < f64::MAX / 4.0 {
                v *= 2.0;
            }
            v
        };
        let mut lo = 0.0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if g(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let speed = 0.5 * (lo + hi);
        Front {
            position: back + self.distance(w, speed),
            speed,
        }
    }
}

/// The fronts found at the end of the last step: points in space, each where the front
/// crossed the line along the crack through a tip.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrontMemory {
    /// The points, `dim` coordinates each.
    points: Vec<f64>,
    dim: usize,
}

impl FrontMemory {
    /// Fronts at these points.
    pub fn new<const D: usize>(points: &[Point<D>]) -> Self {
        Self {
            points: points.iter().flat_map(|p| p.iter().copied()).collect(),
            dim: D,
        }
    }

    /// Fronts at the points given as `dim` coordinates each (a checkpoint's), or `None`
    /// when the length is not a multiple of `dim` or a coordinate is not finite.
    pub fn from_coordinates(dim: usize, points: &[f64]) -> Option<Self> {
        if dim == 0 || !points.len().is_multiple_of(dim) || points.iter().any(|x| !x.is_finite()) {
            return None;
        }
        Some(Self {
            points: points.to_vec(),
            dim,
        })
    }

    /// The points' coordinates, `dim` each.
    pub fn coordinates(&self) -> &[f64] {
        &self.points
    }

    /// The number of fronts remembered.
    pub fn len(&self) -> usize {
        self.points.len().checked_div(self.dim).unwrap_or(0)
    }

    /// Whether no front is remembered.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The position along `along` of the remembered front nearest to `tip`, when one lies
    /// within `reach` (m) of it.
    pub fn previous<const D: usize>(
        &self,
        tip: &Point<D>,
        along: &Point<D>,
        reach: f64,
    ) -> Option<f64> {
        if self.dim != D {
            return None;
        }
        let mut best: Option<(f64, f64)> = None;
        for chunk in self.points.chunks_exact(D) {
            let p = Point::<D>::from_fn(|a, _| chunk[a]);
            let d = (p - tip).norm();
            if d <= reach && best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, p.dot(along)));
            }
        }
        best.map(|(_, x)| x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kgd(k_ic: f64, mu: f64) -> TipAsymptote {
        TipAsymptote {
            k_prime: k_prime(k_ic),
            e_prime: 1.0e10 / (1.0 - 0.0625),
            mu_prime: 12.0 * mu,
        }
    }

    #[test]
    fn beta_m_cubed_is_18_root_3() {
        assert!((beta_m().powi(3) - 18.0 * 3f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn the_limits_are_the_toughness_and_the_viscosity_asymptotes() {
        let at_rest = kgd(1.0e6, 1.0e-3);
        for r in [1e-3f64, 0.1, 2.0] {
            let wk = at_rest.k_prime / at_rest.e_prime * r.sqrt();
            assert!((at_rest.opening(r, 0.0) / wk - 1.0).abs() < 1e-14);
        }
        let viscous = kgd(0.0, 1.0e-3);
        for (r, v) in [(1e-3f64, 0.1), (0.1, 0.05), (2.0, 1e-3)] {
            let wm = beta_m() * (viscous.mu_prime * v / viscous.e_prime).cbrt() * r.powf(2.0 / 3.0);
            assert!((viscous.opening(r, v) / wm - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn the_distance_inverts_the_opening() {
        let a = kgd(3.0e4, 1.0e-3);
        for r in [1e-6, 1e-4, 0.0625, 0.3, 5.0] {
            for v in [0.0, 1e-3, 0.05, 3.0] {
                let w = a.opening(r, v);
                assert!(
                    (a.distance(w, v) / r - 1.0).abs() < 1e-10,
                    "r {r}, v {v}: {}",
                    a.distance(w, v)
                );
            }
        }
        assert_eq!(a.distance(0.0, 1.0), 0.0);
        assert_eq!(kgd(0.0, 1.0e-3).distance(1e-4, 0.0), f64::INFINITY);
    }

    #[test]
    fn the_front_moves_at_the_speed_its_asymptote_needs() {
        // A front that was at 1.0 m and is now at 1.05 m after 0.8 s (V = 0.0625 m/s)
        // opens the back line 0.0625 m behind it by w(0.0625, V): the inversion finds it.
        let a = kgd(3.0e4, 1.0e-3);
        let (previous, dt, v) = (1.0, 0.8, 0.0625);
        let position = previous + v * dt;
        let back = position - 0.0625;
        let w = a.opening(0.0625, v);
        let f = a.front(w, back, previous, dt);
        assert!((f.speed / v - 1.0).abs() < 1e-9, "{f:?}");
        assert!((f.position - position).abs() < 1e-10, "{f:?}");
        // The same opening with the front already beyond: at rest, where toughness puts it.
        let f = a.front(a.opening(0.01, 0.0), back, back + 0.5, dt);
        assert_eq!(f.speed, 0.0);
        assert!((f.position - back - 0.01).abs() < 1e-12);
        // Without toughness and time, nothing holds the front.
        assert_eq!(
            kgd(0.0, 1e-3).front(1e-4, 0.0, 0.0, 0.0).position,
            f64::INFINITY
        );
        let f = kgd(0.0, 1e-3).front(1e-4, 0.0, 0.0, 0.5);
        assert!(f.position.is_finite() && (f.position - 0.5 * f.speed).abs() < 1e-9);
    }

    #[test]
    fn the_memory_answers_with_the_nearest_front_in_reach() {
        let m = FrontMemory::new(&[Point::<2>::new(1.0, 0.0), Point::<2>::new(-1.0, 0.0)]);
        assert_eq!(m.len(), 2);
        let t = Point::<2>::new(1.0, 0.0);
        assert_eq!(m.previous(&Point::<2>::new(0.9, 0.0), &t, 0.2), Some(1.0));
        assert_eq!(m.previous(&Point::<2>::new(-0.9, 0.0), &t, 0.2), Some(-1.0));
        assert_eq!(m.previous(&Point::<2>::new(0.0, 0.0), &t, 0.2), None);
        assert!(FrontMemory::default().is_empty());
        let back = FrontMemory::from_coordinates(2, m.coordinates()).unwrap();
        assert_eq!(back, m);
        assert!(FrontMemory::from_coordinates(2, &[1.0, 2.0, 3.0]).is_none());
        assert!(FrontMemory::from_coordinates(2, &[1.0, f64::NAN]).is_none());
    }
}
