//! Mandel's problem through the command: `porofrac run scenes/mandel.toml` against the
//! closed-form solution.
//!
//! # The problem
//!
//! A specimen `2a × 2b` (plane strain) between two rigid, frictionless, impermeable
//! platens is squeezed by the total force `2F` per metre, switched on at `t = 0⁺`; its
//! sides `x = ±a` are free and drained. The scene models the quarter `[0, a] × [0, b]`
//! (a = b = 1 m, F = 1e6 N/m): rollers on `x = 0` and `y = 0`, the platen on `y = b`
//! (one vertical displacement shared by its nodes, the force `−F`, horizontal sliding
//! free), `p = 0` on `x = a`, no flow elsewhere; 40 × 40 VEM squares, TPFA, monolithic
//! implicit Euler with Δt = 0.01 s to 2 s.
//!
//! # The closed form (Mandel 1953; Cheng & Detournay 1988; Abousleiman et al. 1996)
//!
//! With the drained constants `G`, `ν`, the drained bulk modulus `K = λ + 2G/3` (plane
//! strain uses the three-dimensional constants, `ε_zz = 0`), the Biot modulus `M`
//! (`1/M = φ c_f` for α = 1 and incompressible grains), `K_u = K + α² M`, Skempton's
//! `B = α M / K_u`, the undrained Poisson ratio `ν_u = (3K_u − 2G)/(2(3K_u + G))`, the
//! mobility `κ = k/μ` and the consolidation coefficient
//!
//! ```text
//!   c = 2κ B² G (1 − ν)(1 + ν_u)² / (9 (1 − ν_u)(ν_u − ν))  (= κ M (K + 4G/3)/(K_u + 4G/3)),
//! ```
//!
//! the pore pressure and the platen settlement are
//!
//! ```text
//!   p(x, t) = 2 p₀ Σ_{n≥1} sin β_n / (β_n − sin β_n cos β_n) · (cos(β_n x/a) − cos β_n) · e^{−β_n² c t/a²},
//!   p₀ = F B (1 + ν_u) / (3a)                     (the undrained pressure at t = 0⁺),
//!   u_y(b, t) = b [ −F (1 − ν)/(2Ga) + F (1 − ν_u)/(G a) Σ_{n≥1} sin β_n cos β_n / (β_n − sin β_n cos β_n) · e^{−β_n² c t/a²} ],
//! ```
//!
//! with `β_n` the positive roots of `tan β = (1 − ν)/(ν_u − ν) · β`, one in each interval
//! `((n − 1)π, (n − ½)π)` (the coefficient exceeds 1, so the first lies in `(0, π/2)`),
//! found by bisection of `sin β − C β cos β`. At `t = 0` the pressure series sums to `p₀`
//! inside the specimen and the settlement to the undrained `−F (1 − ν_u) b/(2Ga)`;
//! both identities are checked below. The scene's values give `G = 4e8 Pa`,
//! `K = 6.667e8 Pa`, `M = 3.333e9 Pa`, `B = 5/6`, `ν_u = 0.45161`, `c = 0.88235 m²/s`,
//! `p₀ = 403 226 Pa`; the time factor `c t/a²` is 0.088 at the first written step
//! (t = 0.1 s) and 1.76 at the end.
//!
//! # What is checked, with which tolerance
//!
//! The probes sit at the centres of the cells above `y = b/2` (`x = 0.0125, 0.1375, …,
//! 0.8875, 0.9875`) and hold the cell pressure, which is compared with `p` at the cell
//! centre:
//!
//! * `max |p − p_exact| / p₀ ≤ 1.5 %` at t = 0.1 s (the first written step; the drained
//!   edge is then a boundary layer about four cells thick, resolved in time by ten
//!   implicit Euler steps: measured 1.27 %) and `≤ 0.6 %` at every written time from
//!   t = 0.2 s on (measured at most 0.50 %, at t = 0.2 s);
//! * the Mandel–Cryer effect: the centre pressure at t = 0.1 s exceeds `p₀` by more than
//!   4 % (closed form 6.1 %, computed 5.2 %), and falls below `p₀` by t = 0.2 s;
//! * the platen settlement within 0.2 % of the closed form at every written time from
//!   t = 0.1 s on (measured at most 0.11 %).

mod common;

use common::{read_csv, root, run_ok, tmp_dir};
use std::f64::consts::PI;

/// The material and loading of `scenes/mandel.toml`.
struct Mandel {
    g: f64,
    nu: f64,
    nu_u: f64,
    c: f64,
    p0: f64,
    force: f64,
    a: f64,
    b: f64,
    roots: Vec<f64>,
}

impl Mandel {
    fn new(n_roots: usize) -> Self {
        let (e, nu): (f64, f64) = (1e9, 0.25);
        let (phi, cf, perm, visc): (f64, f64, f64, f64) = (0.3, 1e-9, 1e-12, 1e-3);
        let (force, a, b) = (1e6, 1.0, 1.0);
        let g = e / (2.0 * (1.0 + nu));
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let k = lambda + 2.0 * g / 3.0;
        let m = 1.0 / (phi * cf);
        let k_u = k + m;
        let skempton = m / k_u;
        let nu_u = (3.0 * k_u - 2.0 * g) / (2.0 * (3.0 * k_u + g));
        let kappa = perm / visc;
        let c = 2.0 * kappa * skempton * skempton * g * (1.0 - nu) * (1.0 + nu_u).powi(2)
            / (9.0 * (1.0 - nu_u) * (nu_u - nu));
        let c_alt = kappa * m * (k + 4.0 * g / 3.0) / (k_u + 4.0 * g / 3.0);
        assert!((c - c_alt).abs() <= 1e-12 * c, "{c} vs {c_alt}");
        let p0 = force * skempton * (1.0 + nu_u) / (3.0 * a);
        let coef = (1.0 - nu) / (nu_u - nu);
        assert!(coef > 1.0);
        let f = |x: f64| x.sin() - coef * x * x.cos();
        let roots = (1..=n_roots)
            .map(|n| {
                let (mut lo, mut hi) = ((n - 1) as f64 * PI, (n as f64 - 0.5) * PI);
                if n == 1 {
                    lo = 1e-9;
                }
                let flo = f(lo).signum();
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if f(mid).signum() == flo {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                0.5 * (lo + hi)
            })
            .collect();
        Self {
            g,
            nu,
            nu_u,
            c,
            p0,
            force,
            a,
            b,
            roots,
        }
    }

    /// Pore pressure at `x` and `t`.
    fn pressure(&self, x: f64, t: f64) -> f64 {
        let s: f64 = self
            .roots
            .iter()
            .map(|&bn| {
                let (sn, cn) = bn.sin_cos();
                sn / (bn - sn * cn)
                    * ((bn * x / self.a).cos() - cn)
                    * (-bn * bn * self.c * t / (self.a * self.a)).exp()
            })
            .sum();
        2.0 * self.p0 * s
    }

    /// Vertical displacement of the platen (y = b) at `t`.
    fn settlement(&self, t: f64) -> f64 {
        let s: f64 = self
            .roots
            .iter()
            .map(|&bn| {
                let (sn, cn) = bn.sin_cos();
                sn * cn / (bn - sn * cn) * (-bn * bn * self.c * t / (self.a * self.a)).exp()
            })
            .sum();
        let (f, g, a) = (self.force, self.g, self.a);
        self.b * (-f * (1.0 - self.nu) / (2.0 * g * a) + f * (1.0 - self.nu_u) / (g * a) * s)
    }
}

/// The series themselves: the roots solve `tan β = C β`, the scene's constants come out
/// as stated, and at `t = 0` the pressure is `p₀` inside the specimen and the settlement
/// the undrained one.
#[test]
fn closed_form_series_is_consistent() {
    let m = Mandel::new(4000);
    let coef = (1.0 - m.nu) / (m.nu_u - m.nu);
    for &bn in &m.roots[..50] {
        assert!((bn.tan() - coef * bn).abs() <= 1e-9 * coef * bn, "{bn}");
    }
    assert!((m.c - 0.882_352_941).abs() < 1e-8, "c = {}", m.c);
    assert!((m.p0 - 403_225.806).abs() < 1e-2, "p0 = {}", m.p0);
    assert!((m.nu_u - 0.451_612_903).abs() < 1e-8, "nu_u = {}", m.nu_u);
    for x in [0.2, 0.5, 0.8] {
        let p = m.pressure(x, 0.0);
        assert!((p / m.p0 - 1.0).abs() < 1e-3, "p({x}, 0) = {p}");
    }
    let undrained = -m.force * (1.0 - m.nu_u) * m.b / (2.0 * m.g * m.a);
    let u = m.settlement(0.0);
    assert!((u / undrained - 1.0).abs() < 1e-4, "{u} vs {undrained}");
}

/// The scene's probes against the closed form (tolerances in the module docs).
#[test]
fn mandel_scene_matches_the_closed_form() {
    let out = tmp_dir("mandel");
    run_ok(&root().join("scenes/mandel.toml"), &out);
    let (header, rows) = read_csv(&out.join("probes.csv"));
    let xs = [
        0.0125, 0.1375, 0.2625, 0.3875, 0.5125, 0.6375, 0.7625, 0.8875, 0.9875,
    ];
    let names: Vec<String> = xs
        .iter()
        .map(|x| format!("p_{:04}", (x * 1e4_f64).round() as i64))
        .map(|n| format!("{n} [Pa]"))
        .chain(["platen_uy [m]".to_string()])
        .collect();
    assert_eq!(header[0], "time [s]");
    assert_eq!(&header[1..], names.as_slice());
    // Probes at every step of 0.01 s up to 2 s; the checks below are at the written
    // times, t = 0 and every tenth step.
    assert_eq!(rows.len(), 201);
    let rows: Vec<Vec<f64>> = rows.into_iter().step_by(10).collect();
    assert_eq!(rows.len(), 21);
    assert!((rows[20][0] - 2.0).abs() < 1e-12);
    let m = Mandel::new(400);
    let mut worst_early: f64 = 0.0;
    let mut worst_late: f64 = 0.0;
    let mut worst_settlement: f64 = 0.0;
    for r in &rows[1..] {
        let t = r[0];
        let err = xs
            .iter()
            .zip(&r[1..10])
            .map(|(&x, &p)| (p - m.pressure(x, t)).abs() / m.p0)
            .fold(0.0f64, f64::max);
        if t < 0.15 {
            worst_early = worst_early.max(err);
        } else {
            worst_late = worst_late.max(err);
        }
        let u = m.settlement(t);
        worst_settlement = worst_settlement.max((r[10] - u).abs() / u.abs());
    }
    assert!(
        worst_early <= 0.015,
        "t = 0.1 s: max error / p0 = {worst_early:.4}"
    );
    assert!(
        worst_late <= 0.006,
        "t ≥ 0.2 s: max error / p0 = {worst_late:.4}"
    );
    assert!(
        worst_settlement <= 0.002,
        "settlement: max relative error {worst_settlement:.4}"
    );
    // Mandel–Cryer: the centre pressure rises above the undrained value, then falls.
    let (r1, r2) = (&rows[1], &rows[2]);
    assert!((r1[0] - 0.1).abs() < 1e-12 && (r2[0] - 0.2).abs() < 1e-12);
    let exact = m.pressure(xs[0], 0.1) / m.p0;
    assert!(
        exact > 1.05,
        "closed form at the centre, t = 0.1 s: {exact}"
    );
    assert!(r1[1] / m.p0 > 1.04, "centre at t = 0.1 s: {}", r1[1] / m.p0);
    assert!((r1[1] / m.p0 - exact).abs() < 0.01);
    assert!(r2[1] < m.p0, "centre at t = 0.2 s: {}", r2[1] / m.p0);
    // Rest at t = 0 (the load acts from t = 0⁺).
    assert!(rows[0][1..].iter().all(|&v| v == 0.0));
}
