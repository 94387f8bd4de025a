//! DEM lattices with normal/shear springs and micro-rotations (Nilsen et al. (2017) §2.1,
//! eqs. 7–14): effective moduli against closed forms, Poisson-ratio limits, torque balance,
//! energy consistency of the stress.

use nalgebra::DMatrix;
use porofrac_law::Tensor;
use porofrac_mdem::lattice::{Lattice, Normalisation};

const TOL: f64 = 1e-10;

fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= TOL * b.abs().max(1.0),
        "{what}: {a} vs {b}"
    );
}

const SPRINGS: [(f64, f64); 4] = [(1.0, 0.0), (1.0, 0.3), (2.0, 1.0), (0.5, 2.0)];

#[test]
fn triangular_lattice_matches_eq12_up_to_normalisation() {
    for (kn, ks) in SPRINGS {
        let l = Lattice::<2>::triangular(1.0, kn, ks).unwrap();
        let c = l.effective_stiffness(Normalisation::Seed);
        let (lam, mu) = l.lame(Normalisation::Seed);
        // Seed normalisation V = 1, d = 1: λ = ¾(k_n − k_s), μ = ¾(k_n + k_s).
        close(lam, 0.75 * (kn - ks), "λ");
        close(mu, 0.75 * (kn + ks), "μ");
        // Isotropic: C₁₁ = C₂₂ = λ + 2μ, no normal–shear coupling.
        close(c[(0, 0)], lam + 2.0 * mu, "C11");
        close(c[(1, 1)], lam + 2.0 * mu, "C22");
        close(c[(0, 2)], 0.0, "C13");
        close(c[(1, 2)], 0.0, "C23");
        // With V = 3/4 eq. 12 holds exactly.
        let (l34, m34) = l.lame(Normalisation::Volume(0.75));
        close(l34, kn - ks, "λ (V=3/4)");
        close(m34, kn + ks, "μ (V=3/4)");
        // Eq. 13 (plane strain), eq. 14 (plane stress).
        close(
            lam / (2.0 * (lam + mu)),
            0.25 * (1.0 - ks / kn),
            "ν plane strain",
        );
        close(
            lam / (lam + 2.0 * mu),
            (kn - ks) / (3.0 * kn + ks),
            "ν plane stress",
        );
    }
}

#[test]
fn square_and_cubic_lattices_match_the_seed_relations() {
    for (kn, ks) in SPRINGS {
        let sq = Lattice::<2>::square(1.0, kn, ks).unwrap();
        let cu = Lattice::<3>::simple_cubic(1.0, kn, ks).unwrap();
        for c in [
            sq.effective_stiffness(Normalisation::Seed),
            cu.effective_stiffness(Normalisation::Seed),
        ] {
            let k = c.nrows();
            let dim = if k == 3 { 2 } else { 3 };
            // C_ii = 2k_n, C_ij = 0 (i ≠ j normal), shear Kelvin entries 2μ = 2k_s.
            let mut expect = DMatrix::zeros(k, k);
            for i in 0..k {
                expect[(i, i)] = if i < dim { 2.0 * kn } else { 2.0 * ks };
            }
            assert!((&c - &expect).amax() <= TOL, "{c} vs {expect}");
            // The λ = 2(k_n − k_s) of Nilsen et al. (2017) is C₁₁ − 2μ (coefficient of Σ
            // e_ii²), μ = k_s.
            let mu = 0.5 * c[(k - 1, k - 1)];
            close(mu, ks, "μ");
            close(c[(0, 0)] - 2.0 * mu, 2.0 * (kn - ks), "seed λ");
        }
    }
}

#[test]
fn fcc_lattice_reproduces_eq12_and_eq13() {
    for (kn, ks) in SPRINGS {
        let l = Lattice::<3>::fcc(1.0, kn, ks).unwrap();
        let c = l.effective_stiffness(Normalisation::Seed);
        let (lam, mu) = l.lame(Normalisation::Seed);
        close(lam, kn - ks, "λ = C12 (eq. 12)");
        close(mu, kn + ks, "μ = C44 (eq. 12)");
        close(c[(0, 0)], 2.0 * (kn + ks), "C11");
        for (i, j) in [(0, 2), (1, 2), (3, 3), (4, 4)] {
            let expect = if i == j { 2.0 * (kn + ks) } else { kn - ks };
            close(c[(i, j)], expect, "cubic symmetry");
        }
        close(lam / (2.0 * (lam + mu)), 0.25 * (1.0 - ks / kn), "ν eq. 13");
        // Voigt isotropic average: ν = (k_n − k_s)/(4k_n + k_s).
        let (c11, c12, c44) = (c[(0, 0)], c[(0, 1)], 0.5 * c[(3, 3)]);
        let mu_v = (c11 - c12 + 3.0 * c44) / 5.0;
        let lam_v = (c11 + 4.0 * c12 - 2.0 * c44) / 5.0;
        close(
            lam_v / (2.0 * (lam_v + mu_v)),
            (kn - ks) / (4.0 * kn + ks),
            "ν Voigt",
        );
    }
}

#[test]
fn poisson_ratio_limits() {
    let ratios: Vec<f64> = (-8..=8).map(|e| 10f64.powf(e as f64 * 0.75)).collect();
    let mut last_ps = f64::INFINITY;
    for &r in &ratios {
        let tri = Lattice::<2>::triangular(1.0, 1.0, r).unwrap();
        let (lam, mu) = tri.lame(Normalisation::Seed);
        let ps = lam / (lam + 2.0 * mu);
        assert!(
            -1.0 < ps && ps < 1.0 / 3.0,
            "plane stress ν = {ps} at k_s/k_n = {r}"
        );
        assert!(ps < last_ps, "plane-stress ν decreases with k_s/k_n");
        last_ps = ps;
        let pe = lam / (2.0 * (lam + mu));
        assert!(pe < 0.25);
        let fcc = Lattice::<3>::fcc(1.0, 1.0, r).unwrap();
        let (l3, m3) = fcc.lame(Normalisation::Seed);
        assert!(l3 / (2.0 * (l3 + m3)) < 0.25);
    }
    // Limits k_s → 0: plane strain and 3D → 1/4, plane stress → 1/3; k_s → ∞: −1.
    let eps = 1e-12;
    let (lam, mu) = Lattice::<2>::triangular(1.0, 1.0, eps)
        .unwrap()
        .lame(Normalisation::Seed);
    close(lam / (2.0 * (lam + mu)), 0.25, "plane strain, k_s → 0");
    close(lam / (lam + 2.0 * mu), 1.0 / 3.0, "plane stress, k_s → 0");
    let (l3, m3) = Lattice::<3>::fcc(1.0, 1.0, eps)
        .unwrap()
        .lame(Normalisation::Seed);
    close(l3 / (2.0 * (l3 + m3)), 0.25, "3D, k_s → 0");
    let (lam, mu) = Lattice::<2>::triangular(1.0, eps, 1.0)
        .unwrap()
        .lame(Normalisation::Seed);
    close(lam / (lam + 2.0 * mu), -1.0, "plane stress, k_s → ∞");
    // k_s = 0 exactly (central forces): Cauchy relation λ = μ.
    let (lam, mu) = Lattice::<2>::triangular(1.0, 1.0, 0.0)
        .unwrap()
        .lame(Normalisation::Seed);
    close(lam, mu, "Cauchy relation");
}

fn skew<const D: usize>(a: f64) -> Tensor<D> {
    Tensor::<D>::from_fn(|i, j| {
        if i < j {
            a * (1.0 + i as f64 + j as f64)
        } else if i > j {
            -a * (1.0 + i as f64 + j as f64)
        } else {
            0.0
        }
    })
}

fn rotation_checks<const D: usize>(l: &Lattice<D>) {
    // Rigid rotation ℓ = r: relaxed θ = r, zero stress and energy. Without the rotation
    // dof (θ = 0) the shear springs react: that is why DEM with shear needs θ.
    let r = skew::<D>(1e-3);
    let w = l.relaxed_rotation(&r);
    assert!((w - r).amax() <= 1e-15, "θ = r");
    assert!(l.stress(&r, &w, Normalisation::Energy).amax() <= 1e-16);
    // Round-off relative to the energy scale k·|r|² ≈ 1e-6.
    assert!(l.energy_density(&r, &w).abs() <= 1e-22);
    assert!(
        l.stress(&r, &Tensor::<D>::zeros(), Normalisation::Energy)
            .amax()
            > 1e-5
    );
    assert!(l.torque(&r, &Tensor::<D>::zeros()).amax() > 1e-5);

    // General gradient: torque balanced after relaxation, net force zero, stress
    // symmetric and equal to ∂W/∂e (central differences, V = 2 V_p).
    let g = Tensor::<D>::from_fn(|i, j| 1e-3 * (1.0 + 2.0 * i as f64 - 1.3 * j as f64));
    let w = l.relaxed_rotation(&g);
    assert!(l.torque(&g, &w).amax() <= 1e-16);
    assert!(l.net_force(&g, &w).amax() <= 1e-16);
    let s = l.stress(&g, &w, Normalisation::Energy);
    assert!((s - s.transpose()).amax() <= 1e-16);
    let h = 1e-6;
    for i in 0..D {
        for j in 0..D {
            let mut gp = g;
            let mut gm = g;
            gp[(i, j)] += h;
            gm[(i, j)] -= h;
            let dw = (l.energy_density(&gp, &l.relaxed_rotation(&gp))
                - l.energy_density(&gm, &l.relaxed_rotation(&gm)))
                / (2.0 * h);
            assert!(
                (dw - s[(i, j)]).abs() <= 1e-8 * s.amax(),
                "∂W/∂ℓ{i}{j} = {dw} vs σ = {}",
                s[(i, j)]
            );
        }
    }
}

#[test]
fn torque_balance_and_energy_consistency() {
    rotation_checks(&Lattice::<2>::triangular(0.7, 1.0, 0.4).unwrap());
    rotation_checks(&Lattice::<2>::square(1.3, 1.0, 0.4).unwrap());
    rotation_checks(&Lattice::<3>::simple_cubic(0.9, 2.0, 0.5).unwrap());
    rotation_checks(&Lattice::<3>::fcc(1.1, 1.0, 0.8).unwrap());
}

#[test]
fn bad_parameters_are_errors() {
    assert!(Lattice::<2>::triangular(1.0, 0.0, 1.0).is_err());
    assert!(Lattice::<2>::triangular(1.0, 1.0, -1.0).is_err());
    assert!(Lattice::<3>::fcc(f64::NAN, 1.0, 1.0).is_err());
    let one_sided = vec![nalgebra::Vector2::new(1.0, 0.0)];
    assert!(Lattice::<2>::new(one_sided, 1.0, 1.0, 1.0).is_err());
}
