//! Explicit damped dynamics (dynamic relaxation) against the direct solver and closed forms.
//!
//! * (a) mixed VEM / MDEM / DEM (elastic) triangle grid with rollers and a traction: the
//!   damped explicit solution equals the direct static solution to 1e-6 (max nodal
//!   difference / max displacement); also the nonlinear compression-only DEM under
//!   compression against Newton's method.
//! * (b) undamped bar (fixed at x = 0, rollers u_y = 0 on every node, released from a
//!   uniform strain): the first longitudinal period is `T = 4L/c`, `c = √(M/ρ)`,
//!   `M = λ + 2μ` (plane strain with u_y = 0: uniaxial strain), within 1 %; total energy
//!   (kinetic + strain) is conserved within the stated bound.
//! * (c) the computed step on a uniform mesh: below the CFL estimate `h/c_p`, below the
//!   exact critical step `2/ω_max` (dense eigenvalues of `M⁻¹A`) and within a factor 2 of it;
//!   1.05 × the exact critical step diverges, 0.95 × stays bounded.
//! * (d) a too-large time step gives an error naming a cell, not NaN.
//! * (e) the 1e5 well/rock stiffness contrast of Nilsen et al. (2017) §3 on the composite well
//!   grid, with and without density scaling.

mod common;

use std::time::Instant;

use common::{hash01, side};
use porofrac_grid::generate::{CompositeSpec, composite};
use porofrac_grid::{Grid, Point, generate};
use porofrac_law::{CellLaw, Stiffness};
use porofrac_mdem::{DemLaw, DemMode, MdemLaw};
use porofrac_sim::*;
use porofrac_vem::VemLaw;

const E: f64 = 1.0e9;
const NU: f64 = 0.25;
const RHO: f64 = 2500.0;

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    d / max_abs(b)
}

struct Setup<'a> {
    dofs: DofMap<2>,
    pattern: Pattern,
    laws: LawMap<'a, 2>,
    loads: Loads<2>,
}

impl<'a> Setup<'a> {
    fn new(grid: &Grid<2>, laws: LawMap<'a, 2>, disp: &[Displacement<2>], loads: Loads<2>) -> Self {
        let dofs = DofMap::new(grid, disp, &[]).unwrap();
        let pattern = Pattern::new(grid, &dofs).unwrap();
        Self {
            dofs,
            pattern,
            laws,
            loads,
        }
    }
    fn problem<'b>(&'b self, grid: &'b Grid<2>) -> StaticProblem<'b, 2> {
        StaticProblem {
            grid,
            laws: &self.laws,
            dofs: &self.dofs,
            pattern: &self.pattern,
            loads: &self.loads,
        }
    }
    fn direct(&self, grid: &Grid<2>) -> Vec<f64> {
        let mut solver = DirectSolver::new(&self.pattern).unwrap();
        solve_static(
            &self.problem(grid),
            &mut solver,
            0.0,
            &StaticOptions::default(),
        )
        .unwrap()
        .displacement
    }
}

fn rollers_and_top_traction(grid: &Grid<2>, t: [f64; 2]) -> (Vec<Displacement<2>>, Loads<2>) {
    let disp = vec![
        side(grid, "xmin", [Some(0.0.into()), None]),
        side(grid, "ymin", [None, Some(0.0.into())]),
    ];
    let loads = Loads {
        tractions: vec![Traction {
            name: "ymax".into(),
            faces: grid.boundary("ymax").unwrap(),
            traction: [t[0].into(), t[1].into()],
        }],
        ..Loads::default()
    };
    (disp, loads)
}

fn mixed_grid() -> Grid<2> {
    generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::new(2.0, 1.0), [12, 6]).unwrap()
}

#[test]
fn mixed_vem_mdem_dem_grid_reaches_the_direct_solution() {
    let grid = mixed_grid();
    let st = Stiffness::<2>::isotropic(E, NU).unwrap();
    let vem = VemLaw::new(st.clone());
    let mdem = MdemLaw::new(&st).unwrap();
    let dem = DemLaw::new(&st, DemMode::Elastic).unwrap();
    let laws = LawMap::new(
        &grid,
        vec![&vem as &dyn CellLaw<2>, &mdem, &dem],
        (0..grid.num_cells()).map(|c| (c / 2 + c) % 3).collect(),
    )
    .unwrap();
    let (disp, loads) = rollers_and_top_traction(&grid, [2.0e5, -1.0e6]);
    let s = Setup::new(&grid, laws, &disp, loads);
    let direct = s.direct(&grid);
    let density = vec![RHO; grid.num_cells()];
    let opts = ExplicitOptions {
        tolerance: 1e-9,
        max_steps: 200_000,
        ..ExplicitOptions::default()
    };
    let t0 = Instant::now();
    let sol = solve_explicit(&s.problem(&grid), &density, 0.0, &opts, None).unwrap();
    let err = rel_diff(&sol.displacement, &direct);
    eprintln!(
        "mixed grid ({} cells): {} steps, dt = {:.3e} s, ratio {:.2e}, rel. error {err:.2e}, {:.2} s",
        grid.num_cells(),
        sol.steps,
        sol.dt,
        sol.unbalanced_ratio,
        t0.elapsed().as_secs_f64()
    );
    assert!(sol.unbalanced_ratio <= 1e-9);
    assert!(err < 1e-6, "relative difference {err:.3e}");
    // Same with density scaling: the same static solution.
    let scaled = ExplicitOptions {
        density_scaling: Some(1.0),
        ..opts
    };
    let sol2 = solve_explicit(&s.problem(&grid), &density, 0.0, &scaled, None).unwrap();
    let err2 = rel_diff(&sol2.displacement, &direct);
    eprintln!(
        "mixed grid, density scaled: {} steps, dt = {}, rel. error {err2:.2e}",
        sol2.steps, sol2.dt
    );
    assert!((sol2.dt - 1.0).abs() < 1e-12);
    assert!(err2 < 1e-6, "relative difference {err2:.3e}");
}

#[test]
fn compression_only_dem_reaches_equilibrium() {
    // DEM in compression-only mode (Nilsen et al. (2017) eq. 33) in the right half, MDEM in the
    // left, a top and a lateral pressure: all springs start open at u = 0 (a Newton solve from
    // u = 0 meets a singular tangent), so only the explicit solver applies. Check: the
    // equilibrium residual recomputed independently with `assemble` and `nodal_loads` is
    // below 1e-8 of the load, and the solution differs from the all-closed (elastic DEM)
    // one, i.e. some springs stayed open.
    let grid = mixed_grid();
    let st = Stiffness::<2>::isotropic(E, NU).unwrap();
    let dem_c = DemLaw::new(&st, DemMode::CompressionOnly).unwrap();
    let dem_e = DemLaw::new(&st, DemMode::Elastic).unwrap();
    let mdem = MdemLaw::new(&st).unwrap();
    let law_of: Vec<usize> = (0..grid.num_cells())
        .map(|c| usize::from(grid.cell_centroid(c)[0] > 1.0))
        .collect();
    let (disp, mut loads) = rollers_and_top_traction(&grid, [0.0, -1.0e6]);
    loads.tractions.push(Traction {
        name: "xmax".into(),
        faces: grid.boundary("xmax").unwrap(),
        traction: [(-1.0e6).into(), 0.0.into()],
    });
    let elastic = LawMap::new(
        &grid,
        vec![&mdem as &dyn CellLaw<2>, &dem_e],
        law_of.clone(),
    )
    .unwrap();
    let closed = Setup::new(&grid, elastic, &disp, loads.clone()).direct(&grid);
    let nonlinear = LawMap::new(&grid, vec![&mdem as &dyn CellLaw<2>, &dem_c], law_of).unwrap();
    let s = Setup::new(&grid, nonlinear, &disp, loads);
    let density = vec![RHO; grid.num_cells()];
    let opts = ExplicitOptions {
        tolerance: 1e-9,
        max_steps: 200_000,
        density_scaling: Some(1.0),
        ..ExplicitOptions::default()
    };
    let sol = solve_explicit(&s.problem(&grid), &density, 0.0, &opts, None).unwrap();
    let neq = s.dofs.num_equations();
    let mut values = vec![0.0; s.pattern.nnz()];
    let mut fint = vec![0.0; neq];
    assemble(
        &grid,
        &s.laws,
        &s.dofs,
        &s.pattern,
        &sol.displacement,
        &mut values,
        &mut fint,
    )
    .unwrap();
    let mut full = vec![0.0; s.dofs.num_dofs()];
    nodal_loads(&grid, &s.loads, 0.0, &mut full).unwrap();
    let mut fext = vec![0.0; neq];
    s.dofs.reduce_add(&full, &mut fext);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let r: Vec<f64> = fext.iter().zip(&fint).map(|(a, b)| a + b).collect();
    let ratio = norm(&r) / norm(&fext);
    let diff = rel_diff(&sol.displacement, &closed);
    eprintln!(
        "compression-only DEM: {} steps, independent residual ratio {ratio:.2e}, \
         difference to the all-closed solution {diff:.2e}",
        sol.steps
    );
    assert!(ratio < 1e-8, "residual ratio {ratio:.3e}");
    assert!(diff > 1e-4, "no spring opened ({diff:.3e})");
}

/// Bar `[0, L] × [0, H]`, `n × 1` squares of two triangles, MDEM, `u_x = 0` at x = 0 and
/// `u_y = 0` on every node.
fn bar(n: usize, l: f64, h: f64) -> Grid<2> {
    generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::new(l, h), [n, 1]).unwrap()
}

#[test]
fn undamped_bar_period_and_energy() {
    let (l, h, n) = (10.0, 0.25, 40);
    let grid = bar(n, l, h);
    let st = Stiffness::<2>::isotropic(E, NU).unwrap();
    let law = MdemLaw::new(&st).unwrap();
    let disp = vec![
        side(&grid, "xmin", [Some(0.0.into()), None]),
        side(&grid, "ymin", [None, Some(0.0.into())]),
        side(&grid, "ymax", [None, Some(0.0.into())]),
    ];
    let s = Setup::new(
        &grid,
        LawMap::uniform(&grid, &law).unwrap(),
        &disp,
        Loads::default(),
    );
    // Constrained (uniaxial-strain) modulus.
    let m_mod = E * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU));
    let c = (m_mod / RHO).sqrt();
    let period = 4.0 * l / c;
    let eps0 = 1e-4;
    let u0: Vec<f64> = (0..2 * grid.num_nodes())
        .map(|d| {
            if d % 2 == 0 {
                eps0 * grid.node(d / 2)[0]
            } else {
                0.0
            }
        })
        .collect();
    let density = vec![RHO; grid.num_cells()];
    let opts = ExplicitOptions {
        damping: 0.0,
        ..ExplicitOptions::default()
    };
    let problem = s.problem(&grid);
    let mut st8 = ExplicitState::new(&problem, &density, 0.0, &opts, Some(&u0), None).unwrap();
    let tip = (0..grid.num_nodes())
        .find(|&k| (grid.node(k)[0] - l).abs() < 1e-12 && grid.node(k)[1].abs() < 1e-12)
        .unwrap();
    let e0 = st8.kinetic_energy() + st8.strain_energy().unwrap();
    // Exact: E0 = ½ M ε0² L H.
    let e_exact = 0.5 * m_mod * eps0 * eps0 * l * h;
    assert!((e0 - e_exact).abs() < 1e-10 * e_exact, "{e0} vs {e_exact}");
    let mut crossings = Vec::new();
    let mut prev = (st8.time(), st8.displacement()[2 * tip]);
    let mut worst = 0.0f64;
    while st8.time() < 5.2 * period {
        st8.step().unwrap();
        let cur = (st8.time(), st8.displacement()[2 * tip]);
        if prev.1 > 0.0 && cur.1 <= 0.0 {
            crossings.push(prev.0 + (cur.0 - prev.0) * prev.1 / (prev.1 - cur.1));
        }
        prev = cur;
        let e = st8.kinetic_energy() + st8.strain_energy().unwrap();
        worst = worst.max((e - e0).abs() / e0);
    }
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let rel = (measured - period).abs() / period;
    eprintln!(
        "bar: dt = {:.3e} s ({} steps/period), T = {period:.6e} s, measured {measured:.6e} s \
         ({} crossings, rel. error {rel:.2e}); energy drift max {worst:.2e}",
        st8.time_step(),
        (period / st8.time_step()) as usize,
        crossings.len()
    );
    assert!(crossings.len() >= 5);
    assert!(rel < 0.01, "period off by {rel:.3e}");
    assert!(worst < 1e-2, "energy oscillation {worst:.3e}");
}

#[test]
fn undamped_smooth_mode_conserves_energy() {
    // Released in the first mode shape u = ε0 (2L/π) sin(πx/2L): leapfrog keeps the
    // total energy within 1e-3 (bounded O((ωΔt)²) oscillation) over 5 periods.
    let (l, h, n) = (10.0, 0.25, 40);
    let grid = bar(n, l, h);
    let st = Stiffness::<2>::isotropic(E, NU).unwrap();
    let law = MdemLaw::new(&st).unwrap();
    let disp = vec![
        side(&grid, "xmin", [Some(0.0.into()), None]),
        side(&grid, "ymin", [None, Some(0.0.into())]),
        side(&grid, "ymax", [None, Some(0.0.into())]),
    ];
    let s = Setup::new(
        &grid,
        LawMap::uniform(&grid, &law).unwrap(),
        &disp,
        Loads::default(),
    );
    let m_mod = E * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU));
    let period = 4.0 * l / (m_mod / RHO).sqrt();
    let u0: Vec<f64> = (0..2 * grid.num_nodes())
        .map(|d| {
            let x = grid.node(d / 2)[0];
            if d % 2 == 0 {
                1e-4 * (std::f64::consts::FRAC_PI_2 * x / l).sin()
            } else {
                0.0
            }
        })
        .collect();
    let density = vec![RHO; grid.num_cells()];
    let opts = ExplicitOptions {
        damping: 0.0,
        ..ExplicitOptions::default()
    };
    let problem = s.problem(&grid);
    let mut st8 = ExplicitState::new(&problem, &density, 0.0, &opts, Some(&u0), None).unwrap();
    let e0 = st8.kinetic_energy() + st8.strain_energy().unwrap();
    let mut worst = 0.0f64;
    while st8.time() < 5.0 * period {
        st8.step().unwrap();
        let e = st8.kinetic_energy() + st8.strain_energy().unwrap() + st8.load_potential();
        worst = worst.max((e - e0).abs() / e0);
    }
    eprintln!("smooth mode: energy oscillation max {worst:.2e}");
    assert!(worst < 1e-3, "energy oscillation {worst:.3e}");
}

/// Dense `M^{-1/2} A M^{-1/2}` from the assembled reduced stiffness; its largest eigenvalue.
fn lambda_max(grid: &Grid<2>, s: &Setup<'_>, masses: &[f64]) -> f64 {
    let n = s.pattern.num_equations();
    let u = vec![0.0; s.dofs.num_dofs()];
    let mut values = vec![0.0; s.pattern.nnz()];
    let mut forces = vec![0.0; n];
    assemble(
        grid,
        &s.laws,
        &s.dofs,
        &s.pattern,
        &u,
        &mut values,
        &mut forces,
    )
    .unwrap();
    let mut a = nalgebra::DMatrix::<f64>::zeros(n, n);
    let (cp, ri) = (s.pattern.col_ptr(), s.pattern.row_idx());
    for c in 0..n {
        for p in cp[c]..cp[c + 1] {
            let r = ri[p];
            let v = values[p] / (masses[r] * masses[c]).sqrt();
            a[(r, c)] = v;
            a[(c, r)] = v;
        }
    }
    a.symmetric_eigen().eigenvalues.max()
}

#[test]
fn time_step_bound_against_cfl_and_exact_limit() {
    let nx = 10;
    let grid =
        generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::repeat(1.0), [nx, nx]).unwrap();
    let st = Stiffness::<2>::isotropic(E, NU).unwrap();
    let law = MdemLaw::new(&st).unwrap();
    let disp = vec![side(&grid, "xmin", [Some(0.0.into()), Some(0.0.into())])];
    let s = Setup::new(
        &grid,
        LawMap::uniform(&grid, &law).unwrap(),
        &disp,
        Loads::default(),
    );
    let density = vec![RHO; grid.num_cells()];
    let undamped = ExplicitOptions {
        damping: 0.0,
        ..ExplicitOptions::default()
    };
    let problem = s.problem(&grid);
    let state = ExplicitState::new(&problem, &density, 0.0, &undamped, None, None).unwrap();
    let lam = lambda_max(&grid, &s, state.masses());
    let dt_exact = 2.0 / lam.sqrt();
    let h = 1.0 / nx as f64;
    let cp = ((E * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU))) / RHO).sqrt();
    let cfl = h / cp;
    let dt_bound = state.critical_time_step();
    eprintln!(
        "uniform mesh h = {h}: Gershgorin critical {dt_bound:.4e} s, exact 2/ω_max {dt_exact:.4e} s \
         (ratio {:.3}), stable (safety 0.9) {:.4e} s, CFL h/c_p {cfl:.4e} s (exact/CFL {:.3})",
        dt_bound / dt_exact,
        state.stable_time_step(),
        dt_exact / cfl
    );
    // Gershgorin is an upper bound on λ_max: the computed critical step is never too large.
    assert!(dt_bound <= dt_exact * (1.0 + 1e-12));
    // ... and conservative by less than a factor 2.
    assert!(dt_bound >= 0.5 * dt_exact);
    // The computed stable step is below the CFL estimate h / c_p.
    assert!(state.stable_time_step() <= cfl);
    // 1.05 × the exact limit diverges (caught as an error), 0.95 × stays bounded.
    let u0: Vec<f64> = (0..s.dofs.num_dofs())
        .map(|d| 1e-6 * hash01(d as u64))
        .collect();
    let run = |factor: f64| {
        let opts = ExplicitOptions {
            time_step: Some(factor * dt_exact),
            ..undamped
        };
        let mut st8 = ExplicitState::new(&problem, &density, 0.0, &opts, Some(&u0), None)?;
        let e0 = st8.kinetic_energy() + st8.strain_energy()?;
        let mut worst = 0.0f64;
        for _ in 0..3000 {
            st8.step()?;
            worst = worst.max(st8.strain_energy()? / e0);
        }
        Ok::<_, SimError>(worst)
    };
    let stable = run(0.95).unwrap();
    eprintln!("0.95 × exact limit: max strain energy / E0 = {stable:.3}");
    // Leapfrog's shadow energy near the limit: the strain energy stays O(1) · E0.
    assert!(stable < 20.0);
    match run(1.05) {
        Err(SimError::Cell { cell, what, .. }) => {
            eprintln!("1.05 × exact limit: cell {cell}: {what}");
            assert!(cell < grid.num_cells());
            assert!(what.contains("diverged"));
        }
        other => panic!("expected divergence naming a cell, got {other:?}"),
    }
}

#[test]
fn too_large_time_step_is_reported_with_its_cell() {
    let grid = mixed_grid();
    let st = Stiffness::<2>::isotropic(E, NU).unwrap();
    let vem = VemLaw::new(st.clone());
    let (disp, loads) = rollers_and_top_traction(&grid, [0.0, -1.0e6]);
    let s = Setup::new(&grid, LawMap::uniform(&grid, &vem).unwrap(), &disp, loads);
    let density = vec![RHO; grid.num_cells()];
    let problem = s.problem(&grid);
    let probe = ExplicitState::new(
        &problem,
        &density,
        0.0,
        &ExplicitOptions::default(),
        None,
        None,
    )
    .unwrap();
    let opts = ExplicitOptions {
        time_step: Some(3.0 * probe.critical_time_step()),
        max_steps: 100_000,
        ..ExplicitOptions::default()
    };
    let err = solve_explicit(&problem, &density, 0.0, &opts, None).unwrap_err();
    eprintln!("{err}");
    match err {
        SimError::Cell { cell, law, what } => {
            assert!(cell < grid.num_cells());
            assert_eq!(law, "vem");
            assert!(what.contains("diverged") && what.contains("node"));
        }
        other => panic!("expected a cell error, got {other:?}"),
    }
    // Bad density names the cell.
    let mut bad = density.clone();
    bad[7] = -1.0;
    match ExplicitState::new(&problem, &bad, 0.0, &ExplicitOptions::default(), None, None) {
        Err(SimError::Cell { cell: 7, .. }) => {}
        Err(e) => panic!("wrong error {e}"),
        Ok(_) => panic!("negative density accepted"),
    }
}

#[test]
fn stiffness_contrast_well_with_and_without_density_scaling() {
    let spec = CompositeSpec::new(
        Point::<2>::zeros(),
        Point::<2>::new(30.0, 30.0),
        [30, 30],
        Point::<2>::new(15.0, 15.0),
        3.0,
        6,
        0.25,
    );
    let grid = composite(&spec).unwrap();
    let hard = VemLaw::new(Stiffness::<2>::isotropic(1e9, NU).unwrap());
    let soft = VemLaw::new(Stiffness::<2>::isotropic(1e4, NU).unwrap());
    let mut law_of = vec![0usize; grid.num_cells()];
    for &c in &grid.cell_tags()["well"] {
        law_of[c] = 1;
    }
    let n_well = grid.cell_tags()["well"].len();
    let laws = LawMap::new(&grid, vec![&hard as &dyn CellLaw<2>, &soft], law_of).unwrap();
    let disp = vec![
        side(&grid, "xmin", [Some(0.0.into()), None]),
        side(&grid, "xmax", [Some(0.0.into()), None]),
        side(&grid, "ymin", [None, Some(0.0.into())]),
    ];
    let loads = Loads {
        tractions: vec![Traction {
            name: "ymax".into(),
            faces: grid.boundary("ymax").unwrap(),
            traction: [0.0.into(), (-1.0e7).into()],
        }],
        ..Loads::default()
    };
    let s = Setup::new(&grid, laws, &disp, loads);
    let direct = s.direct(&grid);
    let density = vec![RHO; grid.num_cells()];
    let problem = s.problem(&grid);
    // Where the physical-mass step comes from.
    let probe = ExplicitState::new(
        &problem,
        &density,
        0.0,
        &ExplicitOptions::default(),
        None,
        None,
    )
    .unwrap();
    let (g, m) = (probe.stiffness_bounds(), probe.masses());
    let e_crit = (0..g.len())
        .max_by(|&a, &b| (g[a] / m[a]).total_cmp(&(g[b] / m[b])))
        .unwrap();
    let where_ = s.dofs.describe_equation(&grid, e_crit);
    eprintln!(
        "contrast grid: {} cells ({n_well} soft), {} equations; physical-mass stable step \
         {:.3e} s, set by {where_}",
        grid.num_cells(),
        s.dofs.num_equations(),
        probe.stable_time_step()
    );
    let budget = 60_000;
    let tol = 1e-9;
    let scaled = ExplicitOptions {
        tolerance: tol,
        max_steps: budget,
        density_scaling: Some(1.0),
        ..ExplicitOptions::default()
    };
    let t0 = Instant::now();
    let sol = solve_explicit(&problem, &density, 0.0, &scaled, None).unwrap();
    let err = rel_diff(&sol.displacement, &direct);
    eprintln!(
        "density scaled: {} steps, ratio {:.2e}, rel. error {err:.2e}, {:.1} s",
        sol.steps,
        sol.unbalanced_ratio,
        t0.elapsed().as_secs_f64()
    );
    assert!(err < 1e-6, "relative difference {err:.3e}");
    // The physical-mass step is set by a small stiff node of the refined zone, not by
    // the soft well cells.
    let crit_node = (0..grid.num_nodes())
        .find(|&k| s.dofs.equation(k, 0) == Some(e_crit) || s.dofs.equation(k, 1) == Some(e_crit))
        .unwrap();
    let x = grid.node(crit_node);
    assert!((x[0] - 15.0).abs() <= 3.0 + 1e-9 && (x[1] - 15.0).abs() <= 3.0 + 1e-9);
    assert!(
        !grid.cell_tags()["well"]
            .iter()
            .any(|&c| grid.cell_nodes(c).contains(&crit_node))
    );
    // With physical masses the soft cells relax on a time scale √(1e5) ≈ 316 times longer
    // than stiff cells of their size: within twice the steps the scaled run needed, the
    // physical-mass run has not converged.
    let plain = ExplicitOptions {
        density_scaling: None,
        max_steps: 2 * sol.steps,
        ..scaled
    };
    let t0 = Instant::now();
    match solve_explicit(&problem, &density, 0.0, &plain, None) {
        Err(SimError::NoConvergence {
            iterations,
            residual,
        }) => {
            eprintln!(
                "physical mass: not converged after {iterations} steps, ratio {residual:.2e} ({:.1} s)",
                t0.elapsed().as_secs_f64()
            );
            assert!(residual > 1e3 * tol);
        }
        other => panic!(
            "physical mass: expected no convergence, got {:?}",
            other.map(|s| s.steps)
        ),
    }
}
