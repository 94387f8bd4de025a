//! Peaceman wells against the radial (logarithmic) analytic solution.
//!
//! A well at the centre of a square domain of uniform square cells injects `q` (per unit
//! thickness in 2D). The exact pressure of a line source in an infinite medium is
//! `p(x) = p_ref − q μ / (2π k̄) ln(ρ/R)` with, for diagonal anisotropy, `k̄ = √(k_x k_y)` and
//! `ρ² = x² √(k_y/k_x) + y² √(k_x/k_y)`; it is imposed on the outer boundary. A circular
//! wellbore of radius `r_w` maps to an ellipse of equivalent radius
//! `r_w' = r_w ((k_y/k_x)^¼ + (k_x/k_y)^¼)/2`, so the exact bottom-hole pressure is
//! `p(ρ = r_w')`. The TPFA + Peaceman bottom-hole pressure is compared with it, relative to
//! the pressure drop `p_w − p_ref`.

use porofrac_flow::{
    FlowModel, FlowProblem, Fluid, Permeability, Rock, ScalarField, Well, WellControl,
    peaceman_well_index,
};
use porofrac_grid::Point;
use porofrac_grid::generate::cartesian;

const MU: f64 = 1e-3;
const P_REF: f64 = 1e7;
const R: f64 = 50.0;
const RW: f64 = 0.1;

struct Outcome {
    bhp_err: f64,
    rate_err: f64,
    far_err: f64,
}

fn run(kx: f64, ky: f64, n: usize, q: f64) -> Outcome {
    let half = 50.0;
    let grid = cartesian::<2>(
        Point::<2>::new(-half, -half),
        Point::<2>::new(half, half),
        [n, n],
    )
    .unwrap();
    let nc = grid.num_cells();
    let centre = (n / 2) * n + n / 2;
    let kbar = (kx * ky).sqrt();
    let (sx, sy) = ((ky / kx).sqrt(), (kx / ky).sqrt());
    let exact = move |x: f64, y: f64| {
        P_REF
            - q * MU / (2.0 * std::f64::consts::PI * kbar)
                * ((x * x * sx + y * y * sy).sqrt() / R).ln()
    };
    let rw_eq = RW * ((ky / kx).powf(0.25) + (kx / ky).powf(0.25)) / 2.0;
    let p_w = P_REF - q * MU / (2.0 * std::f64::consts::PI * kbar) * (rw_eq / R).ln();
    let rock = Rock::new(
        vec![0.2; nc],
        Permeability::uniform_diagonal(nc, [kx, ky]).unwrap(),
    );
    let fluid = Fluid {
        viscosity: MU,
        compressibility: 0.0,
    };
    let bc = ScalarField::from_fn(move |x, _| exact(x[0], x[1]));
    // Rate control: compare the bottom-hole pressure.
    let problem = FlowProblem::new(rock.clone(), fluid)
        .pressure_bc(grid.boundary_faces(), bc.clone())
        .well(Well::new("w", centre, RW, WellControl::Rate(q)));
    let mut model = FlowModel::new(&grid, &problem).unwrap();
    let r = model.solve_steady(0.0).unwrap();
    let bhp_err = (r.well_bhp[0] - p_w).abs() / (p_w - P_REF).abs();
    // Cells at ρ ≥ 5 Δx from the well: the log solution itself.
    let dx = 2.0 * half / n as f64;
    let mut far_err = 0.0f64;
    for c in 0..nc {
        let x = grid.cell_centroid(c);
        if (x[0] * x[0] * sx + x[1] * x[1] * sy).sqrt() >= 5.0 * dx {
            let e = (r.pressure[c] - exact(x[0], x[1])).abs() / (p_w - P_REF).abs();
            far_err = far_err.max(e);
        }
    }
    // Pressure control at the exact p_w: compare the rate.
    let problem = FlowProblem::new(rock, fluid)
        .pressure_bc(grid.boundary_faces(), bc)
        .well(Well::new("w", centre, RW, WellControl::Bhp(p_w)));
    let mut model = FlowModel::new(&grid, &problem).unwrap();
    let r2 = model.solve_steady(0.0).unwrap();
    let rate_err = (r2.well_rate[0] - q).abs() / q;
    eprintln!(
        "kx/ky = {}, {n}×{n}: BHP error {bhp_err:.3e} of the drawdown, rate error {rate_err:.3e}, \
         far-field error {far_err:.3e}",
        kx / ky
    );
    Outcome {
        bhp_err,
        rate_err,
        far_err,
    }
}

#[test]
fn peaceman_isotropic_matches_radial_solution() {
    let o = run(1e-13, 1e-13, 41, 1e-5);
    assert!(o.bhp_err < 5e-3, "BHP error {:e}", o.bhp_err);
    assert!(o.rate_err < 5e-3, "rate error {:e}", o.rate_err);
    assert!(o.far_err < 5e-3, "far-field error {:e}", o.far_err);
}

#[test]
fn peaceman_anisotropic_matches_radial_solution() {
    let o = run(4e-13, 1e-13, 41, 1e-5);
    assert!(o.bhp_err < 1e-2, "BHP error {:e}", o.bhp_err);
    assert!(o.rate_err < 1e-2, "rate error {:e}", o.rate_err);
    assert!(o.far_err < 1e-2, "far-field error {:e}", o.far_err);
}

#[test]
fn peaceman_formula_values() {
    // Isotropic square cell Δx = Δy = 2: r_e = 0.14 √8, WI = 2π k / ln(r_e/r_w).
    let grid =
        cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 2.0), [1, 1]).unwrap();
    let k = porofrac_flow::Tensor::<2>::identity() * 3e-13;
    let (re, wi) = peaceman_well_index(&grid, 0, &k, 0.1, 0.5).unwrap();
    let re_exact = 0.14 * 8f64.sqrt();
    assert!((re - re_exact).abs() < 1e-15);
    let wi_exact = 2.0 * std::f64::consts::PI * 3e-13 / ((re_exact / 0.1).ln() + 0.5);
    assert!((wi - wi_exact).abs() < 1e-12 * wi_exact);
    // 3D: h = Δz.
    let grid3 = cartesian::<3>(
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(2.0, 2.0, 5.0),
        [1, 1, 1],
    )
    .unwrap();
    let k3 = porofrac_flow::Tensor::<3>::identity() * 3e-13;
    let (_, wi3) = peaceman_well_index(&grid3, 0, &k3, 0.1, 0.5).unwrap();
    assert!((wi3 - 5.0 * wi_exact).abs() < 1e-12 * wi3);
}

/// A vertical well through a 3D layered box with no-flow top and bottom gives the 2D
/// solution times the thickness.
#[test]
fn peaceman_3d_vertical_well() {
    let (n, nz, h, k, q2) = (21, 2, 4.0, 1e-13, 1e-5);
    let grid = cartesian::<3>(
        Point::<3>::new(-50.0, -50.0, 0.0),
        Point::<3>::new(50.0, 50.0, h),
        [n, n, nz],
    )
    .unwrap();
    let nc = grid.num_cells();
    let exact = move |x: &[f64]| {
        P_REF
            - q2 * MU / (2.0 * std::f64::consts::PI * k)
                * ((x[0] * x[0] + x[1] * x[1]).sqrt() / R).ln()
    };
    let mut sides = Vec::new();
    for s in ["xmin", "xmax", "ymin", "ymax"] {
        sides.extend(grid.boundary(s).unwrap());
    }
    let p_w = exact(&[RW, 0.0, 0.0]);
    // One well per layer, each with its share of the total rate q2·h.
    let mut problem = FlowProblem::new(
        Rock::new(vec![0.2; nc], Permeability::uniform(nc, k).unwrap()),
        Fluid {
            viscosity: MU,
            compressibility: 0.0,
        },
    )
    .pressure_bc(sides, ScalarField::from_fn(move |x, _| exact(x)));
    for l in 0..nz {
        let c = l * n * n + (n / 2) * n + n / 2;
        problem = problem.well(Well::new(
            format!("w{l}"),
            c,
            RW,
            WellControl::Rate(q2 * h / nz as f64),
        ));
    }
    let mut model = FlowModel::new(&grid, &problem).unwrap();
    let bhp = model.solve_steady(0.0).unwrap().well_bhp;
    let err = (bhp[0] - p_w).abs() / (p_w - P_REF);
    eprintln!("3D vertical well, {n}×{n}×{nz}: BHP error {err:.3e} of the drawdown");
    assert!((bhp[0] - bhp[1]).abs() < 1e-9 * P_REF);
    assert!(err < 1e-2, "BHP error {err:e}");
}

/// Regular five-spot: an injector at the centre of a d × d square with the mean pressure on
/// the boundary carries the pattern's well rate, Muskat's
/// `q = π k (p_inj − p_prod) / (μ (ln(d/r_w) − 0.619))`.
#[test]
fn five_spot_rate_matches_muskat() {
    let (d, k, p_inj, p_prod, n) = (200.0f64, 1e-13, 2e7, 1e7, 61);
    let grid = cartesian::<2>(
        Point::<2>::new(-d / 2.0, -d / 2.0),
        Point::<2>::new(d / 2.0, d / 2.0),
        [n, n],
    )
    .unwrap();
    let nc = grid.num_cells();
    let problem = FlowProblem::new(
        Rock::new(vec![0.2; nc], Permeability::uniform(nc, k).unwrap()),
        Fluid {
            viscosity: MU,
            compressibility: 0.0,
        },
    )
    .pressure_bc(grid.boundary_faces(), 0.5 * (p_inj + p_prod))
    .well(Well::new(
        "inj",
        (n / 2) * n + n / 2,
        RW,
        WellControl::Bhp(p_inj),
    ));
    let q = FlowModel::new(&grid, &problem)
        .unwrap()
        .solve_steady(0.0)
        .unwrap()
        .well_rate[0];
    let muskat = std::f64::consts::PI * k * (p_inj - p_prod) / (MU * ((d / RW).ln() - 0.619));
    let err = (q - muskat).abs() / muskat;
    eprintln!("five-spot {n}×{n}: rate {q:.5e} vs Muskat {muskat:.5e}, relative {err:.2e}");
    assert!(err < 1e-3, "relative rate error {err:e}");
}
