//! Transient flow: 1D diffusion against the Fourier-series solution (with observed orders in
//! Δt and h), and the discrete mass balance with every kind of source and boundary condition.

use porofrac_flow::{
    FlowModel, FlowProblem, Fluid, Permeability, Rock, ScalarField, SourceRate, Well, WellControl,
};
use porofrac_grid::Point;
use porofrac_grid::generate::{cartesian, simplices};

// Diffusivity c = k / (μ φ c_f) = 1e-13 / (1e-3 · 0.2 · 5e-10) = 1 m²/s on a column of length 1.
const K: f64 = 1e-13;
const MU: f64 = 1e-3;
const PHI: f64 = 0.2;
const CF: f64 = 5e-10;
const P1: f64 = 1e6;
const T_END: f64 = 0.1;

/// p(x, t) for p(x, 0) = 0, p(0, t) = P1, no flow at x = L = 1, diffusivity 1.
fn exact(x: f64, t: f64) -> f64 {
    let mut s = 0.0;
    for m in 0..200 {
        let lam = (2 * m + 1) as f64 * std::f64::consts::PI / 2.0;
        s += 2.0 / lam * (lam * x).sin() * (-lam * lam * t).exp();
    }
    P1 * (1.0 - s)
}

/// Max error at T_END relative to P1 for `n` cells and `steps` equal steps.
fn diffusion_error(n: usize, steps: usize) -> f64 {
    let grid =
        cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 0.1), [n, 1]).unwrap();
    let problem = FlowProblem::new(
        Rock::new(vec![PHI; n], Permeability::uniform(n, K).unwrap()),
        Fluid {
            viscosity: MU,
            compressibility: CF,
        },
    )
    .pressure_bc(grid.boundary("xmin").unwrap(), P1);
    let mut model = FlowModel::new(&grid, &problem).unwrap();
    let dt = T_END / steps as f64;
    let mut p = vec![0.0; n];
    for s in 0..steps {
        p = model.step(&p, dt, s as f64 * dt).unwrap().pressure;
    }
    (0..n)
        .map(|c| (p[c] - exact(grid.cell_centroid(c)[0], T_END)).abs() / P1)
        .fold(0.0, f64::max)
}

#[test]
fn diffusion_first_order_in_time() {
    // h = 1/400: the spatial error (~1e-6) is far below the time error.
    let e: Vec<f64> = [5, 10, 20]
        .iter()
        .map(|&s| diffusion_error(400, s))
        .collect();
    let orders: Vec<f64> = e.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    eprintln!(
        "Δt = 0.02, 0.01, 0.005: errors {:?}, orders {orders:.3?}",
        e.iter().map(|v| format!("{v:.3e}")).collect::<Vec<_>>()
    );
    assert!(e[2] < 1.5e-2, "error at Δt = 0.005: {:e}", e[2]);
    for o in orders {
        assert!((o - 1.0).abs() < 0.15, "observed order in Δt {o}");
    }
}

#[test]
fn diffusion_second_order_in_space() {
    // Δt = h² so that the O(Δt) error is O(h²) too.
    let e: Vec<f64> = [10, 20, 40, 80]
        .iter()
        .map(|&n| diffusion_error(n, (T_END * (n * n) as f64).round() as usize))
        .collect();
    let orders: Vec<f64> = e.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    eprintln!(
        "h = 1/10 … 1/80 (Δt = h²): errors {:?}, orders {orders:.3?}",
        e.iter().map(|v| format!("{v:.3e}")).collect::<Vec<_>>()
    );
    assert!(e[3] < 1e-3, "error at h = 1/80: {:e}", e[3]);
    for o in orders {
        assert!((o - 2.0).abs() < 0.2, "observed order in h {o}");
    }
}

/// Injected volume = storage change + net outflow through the boundary, per cell and in
/// total, over several steps of varying size, on a non-K-orthogonal simplex grid with
/// every kind of source, well and boundary condition (time- and space-dependent).
#[test]
fn mass_balance_all_terms() {
    let grid = simplices::<3>(
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(30.0, 20.0, 10.0),
        [6, 4, 3],
    )
    .unwrap();
    let n = grid.num_cells();
    let poro: Vec<f64> = (0..n)
        .map(|c| 0.1 + 0.2 * ((c * 7) % 11) as f64 / 11.0)
        .collect();
    let perm: Vec<f64> = (0..n)
        .map(|c| 1e-13 * (1.0 + ((c * 3) % 5) as f64))
        .collect();
    let rock = Rock::new(poro, Permeability::from_scalars(&perm).unwrap());
    let fluid = Fluid {
        viscosity: 1e-3,
        compressibility: 1e-9,
    };
    let problem = FlowProblem::new(rock, fluid)
        .pressure_bc(
            grid.boundary("xmax").unwrap(),
            ScalarField::from_fn(|x, t| 1e6 + 1e4 * x[1] + 1e3 * t),
        )
        .pressure_bc(grid.boundary("ymin").unwrap(), 2e6)
        .flux_bc(
            grid.boundary("xmin").unwrap(),
            ScalarField::from_fn(|x, _| -1e-7 * (1.0 + x[2])),
        )
        .flux_bc(grid.boundary("zmax").unwrap(), 3e-8)
        .source("inj", vec![0, 5, 17], SourceRate::Total(2e-3))
        .source(
            "prod",
            vec![40, 41, 42, 43],
            SourceRate::PoreVolumesPerHour(-0.05),
        )
        .well(Well::new("bhp", 100, 0.1, WellControl::Bhp(3e6)))
        .well(Well::new("rate", 60, 0.1, WellControl::Rate(-1e-3)));
    let mut model = FlowModel::new(&grid, &problem).unwrap();
    let q_src: f64 = model.source_totals().map(|(_, q)| q).sum();
    // The expected split: in proportion to the cell volumes; the producer takes 0.05 of its
    // cells' pore volume per hour.
    let vol = grid.cell_volumes();
    let mut q_source = vec![0.0; n];
    let inj = [0usize, 5, 17];
    let prod = [40usize, 41, 42, 43];
    let v_inj: f64 = inj.iter().map(|&c| vol[c]).sum();
    let v_prod: f64 = prod.iter().map(|&c| vol[c]).sum();
    let pv_prod: f64 = prod.iter().map(|&c| vol[c] * model.porosity()[c]).sum();
    let q_prod = -0.05 * pv_prod / 3600.0;
    for &c in &inj {
        q_source[c] = 2e-3 * vol[c] / v_inj;
    }
    for &c in &prod {
        q_source[c] = q_prod * vol[c] / v_prod;
    }
    assert!((q_src - (2e-3 + q_prod)).abs() < 1e-15);
    let acc = model.accumulation().to_vec();
    let mut p = vec![1.5e6; n];
    let mut t = 0.0;
    let (mut injected, mut stored, mut outflow) = (0.0, 0.0, 0.0);
    let mut worst_cell = 0.0f64;
    for dt in [10.0, 10.0, 50.0, 200.0, 1000.0, 1000.0] {
        let r = model.step(&p, dt, t).unwrap();
        // Per-cell balance: accumulation + Σ outward fluxes = sources + wells.
        let mut residual = vec![0.0; n];
        let mut cell_scale = vec![0.0f64; n];
        for c in 0..n {
            residual[c] = acc[c] * (r.pressure[c] - p[c]) / dt;
            cell_scale[c] = residual[c].abs().max(q_source[c].abs());
        }
        for f in 0..grid.num_faces() {
            let (a, b) = grid.face_cells(f);
            residual[a] += r.face_flux[f];
            cell_scale[a] = cell_scale[a].max(r.face_flux[f].abs());
            if let Some(b) = b {
                residual[b] -= r.face_flux[f];
                cell_scale[b] = cell_scale[b].max(r.face_flux[f].abs());
            }
        }
        let mut q_cells = q_source.clone();
        for (w, &c) in [100usize, 60].iter().enumerate() {
            q_cells[c] += r.well_rate[w];
        }
        let q_wells: f64 = r.well_rate.iter().sum();
        let step_in = (q_src + q_wells) * dt;
        let step_store: f64 = (0..n).map(|c| acc[c] * (r.pressure[c] - p[c])).sum();
        let step_out: f64 = grid
            .boundary_faces()
            .iter()
            .map(|&f| r.face_flux[f] * dt)
            .sum();
        injected += step_in;
        stored += step_store;
        outflow += step_out;
        let scale = step_in.abs().max(step_store.abs()).max(step_out.abs());
        let rel = (step_in - step_store - step_out).abs() / scale;
        assert!(rel < 1e-12, "step Δt = {dt}: relative imbalance {rel:e}");
        for c in 0..n {
            let e = (residual[c] - q_cells[c]).abs() / cell_scale[c].max(1e-300);
            worst_cell = worst_cell.max(e);
        }
        p = r.pressure;
        t += dt;
    }
    let rel = (injected - stored - outflow).abs() / injected.abs().max(stored.abs());
    eprintln!(
        "mass balance over 6 steps: injected {injected:.6e} m³, stored {stored:.6e}, \
         outflow {outflow:.6e}, relative imbalance {rel:.2e}, worst per-cell {worst_cell:.2e}"
    );
    assert!(rel < 1e-12);
    assert!(worst_cell < 1e-10, "per-cell imbalance {worst_cell:e}");
}
