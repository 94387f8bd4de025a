//! Central-force DEM law (Nilsen et al. (2017) eqs. 32–33): springs = diag of the MDEM edge
//! stiffness, effective stiffness `Mᵀ𝐊_d M/|K|`, and the compression-only post-failure law.

mod common;

use common::{Simplex, anisotropic, rel_diff, tetrahedron, triangle};
use nalgebra::DMatrix;
use porofrac_grid::Point;
use porofrac_law::testkit::{
    KitOptions, check_all, check_forces_gradient, check_linear_field, check_stiffness_jacobian,
    check_stiffness_symmetric, linear_field,
};
use porofrac_law::{CellLaw, Scratch, Stiffness, Tensor};
use porofrac_mdem::{
    DemLaw, DemMode, EdgeState, MdemLaw, cauchy_from_edge_stiffness, edge_matrix, edges,
};

fn materials<const D: usize>() -> Vec<Stiffness<D>> {
    let k = D * (D + 1) / 2;
    vec![
        Stiffness::<D>::isotropic(2.5, 0.3).unwrap(),
        Stiffness::<D>::from_kelvin(anisotropic(k).as_view()).unwrap(),
    ]
}

fn elastic<const D: usize>(s: &Simplex<D>) {
    for mat in materials::<D>() {
        let law = DemLaw::<D>::new(&mat, DemMode::Elastic).unwrap();
        assert!(law.is_linear());
        assert_eq!(law.name(), "dem");
        let kk = MdemLaw::<D>::new(&mat)
            .unwrap()
            .edge_stiffness(&s.coords)
            .unwrap();
        let k = kk.nrows();
        let mut springs = vec![0.0; k];
        law.spring_stiffness(&s.coords, &mut springs).unwrap();
        for i in 0..k {
            assert_eq!(springs[i], kk[(i, i)]);
        }
        // The kit without material (the DEM stiffness is not D) ...
        let opts = KitOptions::default();
        let r = check_all(&law, &s.cell(), None, &opts).unwrap_or_else(|e| panic!("{e}"));
        assert!(r.symmetry <= 1e-14 && r.rigid_body <= 1e-12, "{r:?}");
        // ... and the linear-field check against the effective stiffness Mᵀ𝐊_d M/|K|.
        let kd = DMatrix::from_diagonal(&kk.diagonal());
        let c_eff = cauchy_from_edge_stiffness(&s.coords, &kd).unwrap();
        let eff = Stiffness::<D>::from_kelvin(c_eff.as_view()).unwrap();
        let grad = Tensor::<D>::from_fn(|i, j| 1e-3 * (1.0 + i as f64 - 0.7 * j as f64));
        let (ee, es) = check_linear_field(
            &law,
            &s.cell(),
            &eff,
            &grad,
            &Point::<D>::zeros(),
            &opts,
            &mut Scratch::default(),
        )
        .unwrap();
        assert!(ee <= 1e-12 && es <= 1e-12, "{ee:e} {es:e}");
        // The effective stiffness differs from D for these (generic) cells.
        assert!(rel_diff(&c_eff, &mat.to_dmatrix()) > 1e-3);
    }
}

#[test]
fn elastic_dem_2d() {
    elastic(&triangle());
}

#[test]
fn elastic_dem_3d() {
    elastic(&tetrahedron());
}

fn compression_only<const D: usize>(s: &Simplex<D>) {
    let mat = Stiffness::<D>::isotropic(2.5, 0.3).unwrap();
    let law = DemLaw::<D>::new(&mat, DemMode::CompressionOnly).unwrap();
    let full = DemLaw::<D>::new(&mat, DemMode::Elastic).unwrap();
    assert!(!law.is_linear());
    assert_eq!(law.name(), "dem-compression");
    let cell = s.cell();
    let n = D * (D + 1);
    let k = D * (D + 1) / 2;
    let mut sc = Scratch::default();
    let mut u = vec![0.0; n];
    let mut f = vec![0.0; n];
    let mut f_full = vec![0.0; n];
    let mut states = vec![EdgeState::Closed; k];

    // Uniform expansion: every edge lengthens, all open, no force, energy or stress.
    linear_field(
        &cell,
        &(Tensor::<D>::identity() * 1e-2),
        &Point::<D>::zeros(),
        &mut u,
    );
    law.edge_states(&s.coords, &u, &mut states).unwrap();
    assert!(states.iter().all(|&x| x == EdgeState::Open));
    law.forces(&cell, &u, &mut f, &mut sc).unwrap();
    assert!(f.iter().all(|&v| v == 0.0));
    assert_eq!(law.energy(&cell, &u, &mut sc).unwrap(), 0.0);
    assert_eq!(
        law.stress(&cell, &u, &mut sc).unwrap(),
        Tensor::<D>::zeros()
    );

    // With a residual open stiffness ratio r, the open springs carry r times the elastic
    // force; invalid ratios are errors.
    let r = 1e-6;
    let soft = law.clone().with_open_stiffness(r).unwrap();
    assert_eq!(soft.open_stiffness(), r);
    soft.forces(&cell, &u, &mut f, &mut sc).unwrap();
    full.forces(&cell, &u, &mut f_full, &mut sc).unwrap();
    for i in 0..n {
        assert!((f[i] - r * f_full[i]).abs() <= 1e-15 * f_full[i].abs().max(1e-300));
    }
    for bad in [-0.1, 1.0, f64::NAN] {
        assert!(law.clone().with_open_stiffness(bad).is_err());
    }

    // Uniform compression: all closed, identical to the elastic DEM law.
    linear_field(
        &cell,
        &(Tensor::<D>::identity() * -1e-2),
        &Point::<D>::zeros(),
        &mut u,
    );
    law.edge_states(&s.coords, &u, &mut states).unwrap();
    assert!(states.iter().all(|&x| x == EdgeState::Closed));
    law.forces(&cell, &u, &mut f, &mut sc).unwrap();
    full.forces(&cell, &u, &mut f_full, &mut sc).unwrap();
    assert_eq!(f, f_full);
    assert_eq!(
        law.energy(&cell, &u, &mut sc).unwrap(),
        full.energy(&cell, &u, &mut sc).unwrap()
    );

    // Mixed state: stretch along x, compress along y.
    let mut g = Tensor::<D>::identity() * -1e-2;
    g[(0, 0)] = 2e-2;
    linear_field(&cell, &g, &Point::<D>::zeros(), &mut u);
    let mut du = vec![0.0; k];
    MdemLaw::<D>::new(&mat)
        .unwrap()
        .edge_elongations(&s.coords, &u, &mut du)
        .unwrap();
    law.edge_states(&s.coords, &u, &mut states).unwrap();
    let open = states.iter().filter(|&&x| x == EdgeState::Open).count();
    assert!(open > 0 && open < k, "want a mixed state: {states:?}");
    for i in 0..k {
        assert_eq!(states[i] == EdgeState::Open, du[i] >= 0.0);
        assert!(
            du[i].abs() > 1e-4,
            "edge {i} too close to the switch for FD"
        );
    }
    // Edge forces: K_ii U_i on shortening edges, 0 on lengthening ones (eq. 33).
    let mut springs = vec![0.0; k];
    law.spring_stiffness(&s.coords, &mut springs).unwrap();
    let mut fe = vec![0.0; k];
    law.edge_forces(&s.coords, &u, &mut fe).unwrap();
    for i in 0..k {
        let expect = if du[i] < 0.0 { springs[i] * du[i] } else { 0.0 };
        assert_eq!(fe[i], expect);
    }
    // Forces are −∇E and the stiffness is the Jacobian, in the mixed state (the FD step
    // 1e-6·diam does not cross U_i = 0).
    let opts = KitOptions::default();
    let eg = check_forces_gradient(&law, &cell, &u, &opts, &mut sc).unwrap();
    let ej = check_stiffness_jacobian(&law, &cell, &u, &opts, &mut sc).unwrap();
    let es = check_stiffness_symmetric(&law, &cell, &u, &opts, &mut sc).unwrap();
    println!("{D}D compression-only: grad {eg:e}, jacobian {ej:e}, symmetry {es:e}");
    // Piecewise linear through the origin: F(u) = −K(u) u exactly (active-set solves).
    assert!(law.is_piecewise_linear());
    let mut kmat = nalgebra::DMatrix::<f64>::zeros(0, 0);
    law.stiffness(&cell, &u, &mut kmat, &mut sc).unwrap();
    law.forces(&cell, &u, &mut f, &mut sc).unwrap();
    let ku = &kmat * nalgebra::DVector::from_column_slice(&u);
    let fscale = f.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for i in 0..n {
        assert!(
            (f[i] + ku[i]).abs() <= 1e-13 * fscale,
            "F ≠ −K(u) u at {i}: {} vs {}",
            f[i],
            -ku[i]
        );
    }
    // Stress eq. 18: (1/|K|) Σ F_i l_i t_i ⊗ t_i.
    let mut sig = Tensor::<D>::zeros();
    for (i, &(a, b)) in edges(D).iter().enumerate() {
        let dx = s.coords[b] - s.coords[a];
        sig += dx * dx.transpose() * (fe[i] / dx.norm() / s.volume);
    }
    let got = law.stress(&cell, &u, &mut sc).unwrap();
    assert!((got - sig).amax() <= 1e-13 * sig.amax(), "{got} vs {sig}");

    // A rigid rotation does not lengthen any edge (linearised): no force.
    let w = Tensor::<D>::from_fn(|i, j| {
        if i < j {
            1e-2
        } else if i > j {
            -1e-2
        } else {
            0.0
        }
    });
    linear_field(&cell, &w, &Point::<D>::from_element(0.3), &mut u);
    law.forces(&cell, &u, &mut f, &mut sc).unwrap();
    full.forces(&cell, &u, &mut f_full, &mut sc).unwrap();
    let fmax = f.iter().chain(&f_full).fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(fmax <= 1e-16 * 2.5, "rigid rotation force {fmax:e}");
}

#[test]
fn compression_only_dem_2d() {
    compression_only(&triangle());
}

#[test]
fn compression_only_dem_3d() {
    compression_only(&tetrahedron());
}

#[test]
fn edge_map_has_unit_rows_for_axis_edges() {
    // Right triangle with legs 2 and 3 along the axes: row (0,1) = 2·[1,0,0],
    // row (0,2) = 3·[0,1,0].
    let c = [
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(2.0, 0.0),
        Point::<2>::new(0.0, 3.0),
    ];
    let m = edge_matrix(&c).unwrap();
    assert_eq!(
        m.row(0).iter().copied().collect::<Vec<_>>(),
        vec![2.0, 0.0, 0.0]
    );
    assert_eq!(
        m.row(1).iter().copied().collect::<Vec<_>>(),
        vec![0.0, 3.0, 0.0]
    );
}
