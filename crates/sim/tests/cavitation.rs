//! The pore pressure bounded below by a cavitation pressure
//! ([`Fracturing::set_cavitation_pressure`], `porofrac_sim::cavitation`).
//!
//! A tight poroelastic square, fixed on its boundary and closed to flow, from which a
//! source withdraws fluid in the cells about its centre faster than the rock can supply
//! it: without a bound their pressure falls far below zero. With the bound `p_c`:
//!
//! 1. no cell is below `p_c`, and the cells that reach it hold it exactly;
//! 2. the fluid volume balances to rounding at every step: the injected volume
//!    (negative: withdrawn) equals the stored one `Σ M Δp + α ΔV` less the void change
//!    `Σ ΔV_v` (the domain is closed, the fluxes cancel);
//! 3. a void forms only where the pressure is at the bound;
//! 4. when the source turns to injection the void closes first (the fluid fills it at
//!    `p_c`), then the pressure rises: at the end no void is left and every cell is above
//!    the bound;
//! 5. a bound the pressure never reaches changes nothing, bit for bit.

use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock, SourceRate};
use porofrac_frac::Combined;
use porofrac_grid::generate::simplices;
use porofrac_grid::{Grid, Point};
use porofrac_law::{CellLaw, Stiffness};
use porofrac_mdem::MdemLaw;
use porofrac_sim::*;

struct Setup {
    grid: Grid<2>,
    centre: Vec<usize>,
}

fn setup() -> Setup {
    let grid = simplices(Point::<2>::new(0.0, 0.0), Point::<2>::new(4.0, 4.0), [8, 8]).unwrap();
    let centre = (0..grid.num_cells())
        .filter(|&c| (grid.cell_centroid(c) - Point::<2>::new(2.0, 2.0)).norm() < 0.5)
        .collect::<Vec<_>>();
    Setup { grid, centre }
}

/// The flow model with a source of `rate` (m²/s) in the centre cells.
fn flow_model(s: &Setup, rate: f64) -> (FlowModel<2>, Permeability<2>) {
    let nc = s.grid.num_cells();
    let permeability = Permeability::uniform(nc, 1e-19).unwrap();
    let mut rock = Rock::new(vec![0.1; nc], permeability.clone());
    rock.biot_alpha = vec![0.8; nc];
    let fluid = Fluid {
        viscosity: 1e-3,
        compressibility: 1e-9,
    };
    let problem =
        FlowProblem::new(rock, fluid).source("pump", s.centre.clone(), SourceRate::Total(rate));
    (FlowModel::new(&s.grid, &problem).unwrap(), permeability)
}

/// A step's state, its void change and the void after it.
type Stepped = (BiotState, Vec<f64>, Vec<f64>);

/// Steps of `dt` with the source rates `rates` (one per step), bounded by `p_cav` when
/// given; per step the state, the void change and the void after it.
fn run(s: &Setup, rates: &[f64], dt: f64, p_cav: Option<f64>) -> (BiotState, Vec<Stepped>) {
    let grid = &s.grid;
    let nc = grid.num_cells();
    let stiffness = Stiffness::<2>::isotropic(1e9, 0.25).unwrap();
    let mdem = MdemLaw::<2>::new(&stiffness).unwrap();
    let fixed = Displacement {
        name: "boundary".into(),
        faces: grid.boundary_faces(),
        components: [Some(0.0.into()), Some(0.0.into())],
    };
    let dofs = DofMap::new(grid, &[fixed], &[]).unwrap();
    let pattern = Pattern::new(grid, &dofs).unwrap();
    let loads = Loads::default();
    let body = Body {
        grid,
        dofs: &dofs,
        pattern: &pattern,
        loads: &loads,
    };
    let mut states = Vec::new();
    let mut state: Option<BiotState> = None;
    let mut first = None;
    for (n, &rate) in rates.iter().enumerate() {
        // The source changes from step to step: a run per rate, resumed from the state
        // and the void of the last (a fresh `Fracturing` per rate keeps the test simple).
        let (model, permeability) = flow_model(s, rate);
        let flow = FractureFlow {
            model,
            permeability,
            fracture_permeability: None,
            zero_lag: false,
            alpha: vec![0.8; nc],
            p0: vec![1e6; nc],
        };
        let laws = FractureLaws {
            laws: vec![&mdem as &dyn CellLaw<2>],
            law_of_cell: vec![0; nc],
            post_failure: vec![0],
        };
        let settings = FractureSettings::new(vec![Combined::default()], vec![0; nc]);
        let mut frac = Fracturing::new(body, laws, settings, flow, |sys| {
            Ok(Scheme::Monolithic(Monolithic::new(sys, None)?))
        })
        .unwrap();
        frac.set_cavitation_pressure(p_cav).unwrap();
        let start = match &state {
            Some(st) => st.clone(),
            None => {
                let st = frac.initial_state(0.0).unwrap().state;
                first = Some(st.clone());
                st
            }
        };
        let void_old: Vec<f64> = states
            .last()
            .map(|(_, _, v): &Stepped| v.clone())
            .unwrap_or_else(|| vec![0.0; nc]);
        frac.resume_void(&void_old).unwrap();
        let step = frac.step(&start, n as f64 * dt, dt).unwrap();
        let dv = if step.void_change.is_empty() {
            vec![0.0; nc]
        } else {
            step.void_change.clone()
        };
        state = Some(step.state.clone());
        states.push((step.state, dv, frac.void().to_vec()));
    }
    (first.unwrap(), states)
}

#[test]
fn the_pressure_stays_at_the_bound_and_the_void_balances_the_fluid_volume() {
    let s = setup();
    let nc = s.grid.num_cells();
    let (dt, p_cav) = (10.0, 2.0e3);
    // Withdraw for 6 steps, then inject for 14.
    let mut rates = vec![-2e-5; 6];
    rates.extend(vec![2e-5; 14]);

    // Without the bound the centre falls far below zero.
    let (_, free) = run(&s, &rates[..6], dt, None);
    let lowest = free
        .last()
        .unwrap()
        .0
        .pressure
        .iter()
        .cloned()
        .fold(f64::MAX, f64::min);
    assert!(
        lowest < -1e6,
        "unbounded suction expected, lowest {lowest:.3e}"
    );

    let (initial, steps) = run(&s, &rates, dt, Some(p_cav));
    // The measures of the balance: accumulation, α and the volume change.
    let (model, _) = flow_model(&s, 0.0);
    let m = model.accumulation().to_vec();
    let stiffness = Stiffness::<2>::isotropic(1e9, 0.25).unwrap();
    let mdem = MdemLaw::<2>::new(&stiffness).unwrap();
    let fixed = Displacement {
        name: "boundary".into(),
        faces: s.grid.boundary_faces(),
        components: [Some(0.0.into()), Some(0.0.into())],
    };
    let dofs = DofMap::new(&s.grid, &[fixed], &[]).unwrap();
    let pattern = Pattern::new(&s.grid, &dofs).unwrap();
    let loads = Loads::default();
    let laws = LawMap::uniform(&s.grid, &mdem as &dyn CellLaw<2>).unwrap();
    let problem = StaticProblem {
        grid: &s.grid,
        laws: &laws,
        dofs: &dofs,
        pattern: &pattern,
        loads: &loads,
    };
    let system = BiotSystem::new(problem, &model, vec![0.8; nc], vec![1e6; nc]).unwrap();
    let volume = |u: &[f64]| {
        let mut v = vec![0.0; nc];
        system.volume_change(u, &mut v).unwrap();
        v
    };

    let mut prev = initial;
    let mut most_void = 0.0f64;
    let mut cavitated_steps = 0;
    for (n, (st, dv, void)) in steps.iter().enumerate() {
        // 1. The bound.
        for c in 0..nc {
            assert!(
                st.pressure[c] >= p_cav,
                "step {n}, cell {c}: {}",
                st.pressure[c]
            );
        }
        // 3. A void only at the bound.
        for c in 0..nc {
            if void[c] > 0.0 {
                assert_eq!(st.pressure[c], p_cav, "step {n}, cell {c}");
            }
        }
        // 2. The balance.
        let (v0, v1) = (volume(&prev.displacement), volume(&st.displacement));
        let stored: f64 = (0..nc)
            .map(|c| m[c] * (st.pressure[c] - prev.pressure[c]) + 0.8 * (v1[c] - v0[c]))
            .sum();
        let injected = rates[n] * dt;
        let void_change: f64 = dv.iter().sum();
        let err = (injected - (stored - void_change)).abs();
        assert!(
            err < 1e-12 * rates[n].abs() * dt,
            "step {n}: injected {injected:.6e}, stored {stored:.6e}, void {void_change:.6e}, \
             error {err:.3e}"
        );
        let total: f64 = void.iter().sum();
        if total > 0.0 {
            cavitated_steps += 1;
        }
        most_void = most_void.max(total);
        prev = st.clone();
    }
    // The withdrawal opened a void of a good part of what it withdrew.
    assert!(cavitated_steps >= 3, "{cavitated_steps}");
    println!(
        "largest void {most_void:.4e} m² of {:.4e} withdrawn",
        2e-5 * 6.0 * dt
    );
    assert!(most_void > 0.5 * 2e-5 * 6.0 * dt, "{most_void:.3e}");
    // 4. Injection closed it, then raised the pressure.
    let (last, _, void) = steps.last().unwrap();
    assert!(void.iter().all(|&v| v == 0.0), "{void:?}");
    assert!(last.pressure.iter().all(|&p| p > p_cav));
}

#[test]
fn a_bound_never_reached_changes_nothing() {
    let s = setup();
    let rates = vec![2e-5; 4];
    let (_, free) = run(&s, &rates, 10.0, None);
    let (_, bounded) = run(&s, &rates, 10.0, Some(-1e9));
    for ((a, _, _), (b, dv, v)) in free.iter().zip(&bounded) {
        assert_eq!(a.pressure, b.pressure);
        assert_eq!(a.displacement, b.displacement);
        assert!(dv.iter().all(|&x| x == 0.0));
        assert!(v.iter().all(|&x| x == 0.0));
    }
}
