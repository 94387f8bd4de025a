//! Biot coupling: operators (adjointness, exact volume change), scaling invariance of the
//! monolithic solve, fixed-stress against monolithic, the explicit pressure update against
//! a hand computation, a uniform initial pressure that must not move anything, and the
//! low-permeability (10 nD) instantaneous-load case (no pressure oscillations).

mod common;

use common::perturb;
use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock, ScalarField};
use porofrac_grid::{Grid, Point, generate};
use porofrac_law::stiffness::Stiffness;
use porofrac_sim::*;
use porofrac_vem::VemLaw;

const SIDES: [&str; 6] = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"];

/// Owned pieces of a coupled problem (the borrowing structs are built per test).
struct Setup<const D: usize> {
    grid: Grid<D>,
    law: VemLaw<D>,
    k_dr: f64,
    dofs: DofMap<D>,
    pattern: Pattern,
    loads: Loads<D>,
    flow: FlowModel<D>,
}

/// Rollers on the `min` sides; `load` on the top (a traction on the vertical component,
/// may depend on position); `flow` the flow problem builder from the grid.
fn setup<const D: usize>(
    grid: Grid<D>,
    e: f64,
    nu: f64,
    load: Option<ScalarField>,
    flow: impl Fn(&Grid<D>) -> FlowProblem<D>,
) -> Setup<D> {
    let v = D - 1;
    let bcs: Vec<Displacement<D>> = (0..D)
        .map(|a| {
            let mut components: [Option<ScalarField>; D] = std::array::from_fn(|_| None);
            components[a] = Some(0.0.into());
            Displacement {
                name: SIDES[2 * a].into(),
                faces: grid.boundary(SIDES[2 * a]).unwrap(),
                components,
            }
        })
        .collect();
    let dofs = DofMap::new(&grid, &bcs, &[]).unwrap();
    let pattern = Pattern::new(&grid, &dofs).unwrap();
    let mut loads = Loads::default();
    if let Some(f) = load {
        loads.tractions.push(Traction {
            name: "top".into(),
            faces: grid.boundary(SIDES[2 * v + 1]).unwrap(),
            traction: std::array::from_fn(|a| if a == v { f.clone() } else { 0.0.into() }),
        });
    }
    let stiffness = Stiffness::<D>::isotropic(e, nu).unwrap();
    let k_dr = drained_bulk_modulus(&stiffness);
    let flow = FlowModel::new(&grid, &flow(&grid)).unwrap();
    Setup {
        law: VemLaw::<D>::new(stiffness),
        k_dr,
        dofs,
        pattern,
        loads,
        flow,
        grid,
    }
}

/// Run `f` with the coupled system of `s` (α per cell, p₀ per cell).
fn with_system<const D: usize, R>(
    s: &Setup<D>,
    alpha: Vec<f64>,
    p0: Vec<f64>,
    f: impl FnOnce(&BiotSystem<'_, D>) -> R,
) -> R {
    let laws = LawMap::uniform(&s.grid, &s.law).unwrap();
    let mech = StaticProblem {
        grid: &s.grid,
        laws: &laws,
        dofs: &s.dofs,
        pattern: &s.pattern,
        loads: &s.loads,
    };
    let nc = s.grid.num_cells();
    let sys = BiotSystem::new(mech, &s.flow, alpha, p0)
        .unwrap()
        .with_drained_bulk_modulus(vec![s.k_dr; nc])
        .unwrap();
    f(&sys)
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}
fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// The largest change of the displacement between two states, relative to the largest
/// displacement of `a`, and of the pressure, relative to the largest pressure change of
/// `a` from `initial`.
fn relative_changes(a: &BiotState, b: &BiotState, initial: &[f64]) -> (f64, f64) {
    let du = max_diff(&a.displacement, &b.displacement) / max_abs(&a.displacement);
    let dp0: Vec<f64> = a.pressure.iter().zip(initial).map(|(p, q)| p - q).collect();
    let dp = max_diff(&a.pressure, &b.pressure) / max_abs(&dp0);
    (du, dp)
}

/// A small non-trivial problem: perturbed cells, a load on half the top, a drained
/// `xmax` side with a varying pressure, a non-uniform `p₀` and α.
fn small<const D: usize>(n: usize) -> Setup<D> {
    small_with(n, 1e9)
}

/// [`small`] with Young's modulus `e`.
fn small_with<const D: usize>(n: usize, e: f64) -> Setup<D> {
    let grid = perturb(
        &generate::cartesian::<D>(Point::<D>::zeros(), Point::<D>::repeat(1.0), [n; D]).unwrap(),
        1.0 / n as f64,
        0.2,
    );
    let load = ScalarField::from_fn(|x, _| if x[0] < 0.5 { -1e6 } else { 0.0 });
    setup(grid, e, 0.25, Some(load), |g| {
        let nc = g.num_cells();
        let mut rock = Rock::new(vec![0.2; nc], Permeability::uniform(nc, 1e-14).unwrap());
        rock.biot_alpha = alpha_of(nc);
        FlowProblem::new(
            rock,
            Fluid {
                viscosity: 1e-3,
                compressibility: 4.4e-10,
            },
        )
        .pressure_bc(
            g.boundary("xmax").unwrap(),
            ScalarField::from_fn(|x, _| 1e7 + 1e5 * x[1]),
        )
    })
}

fn alpha_of(nc: usize) -> Vec<f64> {
    (0..nc).map(|c| 0.7 + 0.3 * (c % 3) as f64 / 2.0).collect()
}
fn p0_of<const D: usize>(g: &Grid<D>) -> Vec<f64> {
    g.cell_centroids()
        .iter()
        .map(|x| 1e7 + 1e5 * x[1])
        .collect()
}

/// The steps used by the scheme comparisons: undrained (Δt = 0) then three steps.
const STEPS: [f64; 4] = [0.0, 5.0, 5.0, 20.0];

fn march<const D: usize>(
    sys: &BiotSystem<'_, D>,
    scheme: &mut dyn BiotCoupling<D>,
) -> Vec<BiotState> {
    let mut state = sys.rest_state();
    let mut t = 0.0;
    let mut out = Vec::new();
    for dt in STEPS {
        state = scheme.step(sys, &state, t, dt).unwrap().state;
        t += dt;
        out.push(state.clone());
    }
    out
}

/// `⟨Cᵀ(p − p₀), u⟩ = Σ_K α_K (p_K − p₀_K) ΔV_K(u)` to 1e-13 relative for random fields
/// (the pore-pressure force is the exact transpose of the volume change), and
/// `ΔV_K = |K| tr(A)` for `u = A x + b` on perturbed cells to 1e-13 relative.
fn operators<const D: usize>() {
    let s = small::<D>(3);
    let nc = s.grid.num_cells();
    let p0 = p0_of(&s.grid);
    with_system(&s, alpha_of(nc), p0.clone(), |sys| {
        let nd = D * s.grid.num_nodes();
        let u: Vec<f64> = (0..nd).map(|k| common::hash01(k as u64) * 1e-3).collect();
        let p: Vec<f64> = (0..nc)
            .map(|c| p0[c] + 1e6 * common::hash01(1000 + c as u64))
            .collect();
        let mut f = vec![0.0; nd];
        sys.pore_pressure_forces(&p, &mut f).unwrap();
        let mut dv = vec![0.0; nc];
        sys.volume_change(&u, &mut dv).unwrap();
        let lhs: f64 = f.iter().zip(&u).map(|(a, b)| a * b).sum();
        let rhs: f64 = (0..nc)
            .map(|c| sys.alpha()[c] * (p[c] - p0[c]) * dv[c])
            .sum();
        let scale: f64 = (0..nc)
            .map(|c| (sys.alpha()[c] * (p[c] - p0[c]) * dv[c]).abs())
            .sum();
        assert!(
            (lhs - rhs).abs() <= 1e-13 * scale,
            "{D}D adjoint: {lhs} vs {rhs}"
        );
        // Linear field.
        let a = nalgebra::SMatrix::<f64, D, D>::from_fn(|i, j| {
            1e-3 * (0.3 + i as f64 - 0.7 * j as f64)
        });
        let mut u = vec![0.0; nd];
        for nde in 0..s.grid.num_nodes() {
            let x = s.grid.node(nde);
            let ux = a * x;
            for k in 0..D {
                u[D * nde + k] = ux[k] + 1e-4;
            }
        }
        sys.volume_change(&u, &mut dv).unwrap();
        let worst = (0..nc)
            .map(|c| {
                (dv[c] - s.grid.cell_volume(c) * a.trace()).abs()
                    / (s.grid.cell_volume(c) * a.trace().abs())
            })
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-13,
            "{D}D volume change of a linear field: {worst:.2e}"
        );
        println!(
            "{D}D operators: adjoint gap {:.2e}, linear-field error {worst:.2e}",
            (lhs - rhs).abs() / scale
        );
    });
}

#[test]
fn coupling_operators() {
    operators::<2>();
    operators::<3>();
}

/// The monolithic solution does not depend on the pressure scale `s`: `s` × 1e-3 and
/// × 1e3 agree with the default to 1e-10 (relative to max |u| and max |p − p₀|).
fn scaling<const D: usize>(n: usize) {
    let s = small::<D>(n);
    let nc = s.grid.num_cells();
    with_system(&s, alpha_of(nc), p0_of(&s.grid), |sys| {
        let s0 = sys.default_pressure_scale();
        let reference = march(sys, &mut Monolithic::new(sys, None).unwrap());
        for f in [1e-3, 1e3] {
            let other = march(sys, &mut Monolithic::new(sys, Some(s0 * f)).unwrap());
            for (a, b) in reference.iter().zip(&other) {
                let (du, dp) = relative_changes(a, b, sys.initial_pressure());
                println!("{D}D scale s0 = {s0:.3e} × {f:e}: du {du:.1e}, dp {dp:.1e}");
                assert!(
                    du < 1e-10 && dp < 1e-10,
                    "{D}D scaling ×{f}: du {du:.2e} dp {dp:.2e}"
                );
            }
        }
    });
}

#[test]
fn monolithic_scaling_invariance() {
    scaling::<2>(6);
    scaling::<3>(3);
}

/// A band of cells across the block that conducts like an open crack: permeability
/// 1e-2 m² (the cubic law's `w³/12 h` of an aperture of a quarter of the band's width)
/// against the rock's 1e-14, so the diagonal of the band's pressure rows is about 1e13
/// times the rock's, the spread of the crack cell at a well's wall
/// (docs/hydrofrac/validation.md). Every step is accepted with a Jacobi-scaled relative
/// residual ≤ 1e-8, the solution is the same for the pressure scale × 1e-3 and × 1e3 to
/// 1e-8 (relative to max |u| and max |p − p₀|), and the band's pressure is uniform to
/// 1e-6 of the largest pressure change.
fn crack_band<const D: usize>(n: usize) {
    let grid = perturb(
        &generate::cartesian::<D>(Point::<D>::zeros(), Point::<D>::repeat(1.0), [n; D]).unwrap(),
        1.0 / n as f64,
        0.2,
    );
    // The layer of cells between y = 0.5 and 0.5 + 1/n (centroids perturbed by < 0.2 h).
    let band = |x: &Point<D>| (x[1] - 0.5 - 0.5 / n as f64).abs() < 0.25 / n as f64;
    let load = ScalarField::from_fn(|x, _| if x[0] < 0.5 { -1e6 } else { 0.0 });
    let s = setup(grid, 1e9, 0.25, Some(load), |g| {
        let k: Vec<f64> = g
            .cell_centroids()
            .iter()
            .map(|x| if band(x) { 1e-2 } else { 1e-14 })
            .collect();
        let nc = g.num_cells();
        let mut rock = Rock::new(vec![0.2; nc], Permeability::from_scalars(&k).unwrap());
        rock.biot_alpha = alpha_of(nc);
        FlowProblem::new(
            rock,
            Fluid {
                viscosity: 1e-3,
                compressibility: 4.4e-10,
            },
        )
        .pressure_bc(g.boundary("xmin").unwrap(), 1.2e7)
    });
    let nc = s.grid.num_cells();
    let cells: Vec<usize> = (0..nc)
        .filter(|&c| band(&s.grid.cell_centroids()[c]))
        .collect();
    assert!(cells.len() >= n, "{} band cells", cells.len());
    with_system(&s, alpha_of(nc), p0_of(&s.grid), |sys| {
        let s0 = sys.default_pressure_scale();
        let run = |scale: f64| {
            let mut mono = Monolithic::new(sys, Some(scale)).unwrap();
            let mut state = sys.rest_state();
            let mut t = 0.0;
            let mut out = Vec::new();
            for dt in [5.0, 60.0, 60.0] {
                let r = mono.step(sys, &state, t, dt).unwrap();
                assert!(r.residual <= 1e-8, "{D}D residual {:.2e}", r.residual);
                state = r.state;
                t += dt;
                out.push(state.clone());
            }
            out
        };
        let reference = run(s0);
        for a in &reference {
            let dp0: Vec<f64> = a
                .pressure
                .iter()
                .zip(sys.initial_pressure())
                .map(|(p, q)| p - q)
                .collect();
            let pb: Vec<f64> = cells.iter().map(|&c| a.pressure[c]).collect();
            let spread = pb.iter().fold(f64::NEG_INFINITY, |m, &p| m.max(p))
                - pb.iter().fold(f64::INFINITY, |m, &p| m.min(p));
            println!("{D}D band pressure spread {:.1e}", spread / max_abs(&dp0));
            assert!(
                spread <= 1e-6 * max_abs(&dp0),
                "{D}D band spread {spread:.2e}"
            );
        }
        for f in [1e-3, 1e3] {
            for (a, b) in reference.iter().zip(&run(s0 * f)) {
                let (du, dp) = relative_changes(a, b, sys.initial_pressure());
                println!("{D}D crack band, scale × {f:e}: du {du:.1e}, dp {dp:.1e}");
                assert!(du < 1e-8 && dp < 1e-8, "{D}D ×{f}: du {du:.2e} dp {dp:.2e}");
            }
        }
    });
}

#[test]
fn a_band_that_conducts_like_an_open_crack_is_solved_and_accepted() {
    crack_band::<2>(8);
    crack_band::<3>(4);
}

/// Fixed-stress (tolerance 1e-12) reproduces the monolithic states to 1e-8 relative,
/// including the undrained (Δt = 0) step.
fn fixed_vs_monolithic<const D: usize>(n: usize) {
    let s = small::<D>(n);
    let nc = s.grid.num_cells();
    with_system(&s, alpha_of(nc), p0_of(&s.grid), |sys| {
        let mono = march(sys, &mut Monolithic::new(sys, None).unwrap());
        let mut fs = FixedStress::new(1e-12, 1000);
        let mut state = sys.rest_state();
        let mut t = 0.0;
        for (k, dt) in STEPS.into_iter().enumerate() {
            let r = fs.step(sys, &state, t, dt).unwrap();
            state = r.state;
            t += dt;
            let a = &mono[k];
            let du = max_diff(&a.displacement, &state.displacement) / max_abs(&a.displacement);
            let dp0: Vec<f64> = a
                .pressure
                .iter()
                .zip(sys.initial_pressure())
                .map(|(p, q)| p - q)
                .collect();
            let dp = max_diff(&a.pressure, &state.pressure) / max_abs(&dp0);
            println!(
                "{D}D fixed-stress step {k} (Δt {dt}): {} iterations, du {du:.1e}, dp {dp:.1e}",
                r.iterations
            );
            assert!(
                du < 1e-8 && dp < 1e-8,
                "{D}D step {k}: du {du:.2e} dp {dp:.2e}"
            );
        }
    });
}

#[test]
fn fixed_stress_matches_monolithic() {
    fixed_vs_monolithic::<2>(6);
    fixed_vs_monolithic::<3>(3);
}

/// Two unit cells side by side, `S|K| = 0.5`, `T/μ = 1`, Δt = 1, α = 1, `pⁿ = (1, 0)`;
/// cell 0 expands by 0.1 and cell 1 by 0.05. By hand,
/// `(M + ΔtA) δ = −ΔtA pⁿ − ΔV_F` with `M + A = [[1.5, −1], [−1, 1.5]]`:
/// only cell 0 fractured: `δ = (−0.52, 0.32)`, `p = (0.48, 0.32)`;
/// both fractured: `δ = (−0.56, 0.26)`, `p = (0.44, 0.26)`.
#[test]
fn explicit_pressure_update_by_hand() {
    let grid =
        generate::cartesian::<2>(Point::<2>::zeros(), Point::<2>::new(2.0, 1.0), [2, 1]).unwrap();
    let s = setup(grid, 1e9, 0.25, None, |_| {
        FlowProblem::new(
            Rock::new(vec![0.5; 2], Permeability::uniform(2, 1.0).unwrap()),
            Fluid {
                viscosity: 1.0,
                compressibility: 1.0,
            },
        )
    });
    with_system(&s, vec![1.0; 2], vec![0.0; 2], |sys| {
        let nd = 2 * s.grid.num_nodes();
        let u_old = vec![0.0; nd];
        let mut u_new = vec![0.0; nd];
        for n in 0..s.grid.num_nodes() {
            let x = s.grid.node(n)[0];
            if x == 0.0 {
                u_new[2 * n] = -0.1;
            } else if x == 2.0 {
                u_new[2 * n] = 0.05;
            }
        }
        let mut dv = vec![0.0; 2];
        sys.volume_change(&u_new, &mut dv).unwrap();
        assert!(
            (dv[0] - 0.1).abs() < 1e-15 && (dv[1] - 0.05).abs() < 1e-15,
            "{dv:?}"
        );
        for (fractured, want) in [
            (vec![true, false], [0.48, 0.32]),
            (vec![true, true], [0.44, 0.26]),
            (vec![false, false], [1.0 - 0.4, 0.4]),
        ] {
            let mut ex = ExplicitPressure::new(fractured.clone());
            let p = ex
                .update_pressure(sys, &u_new, &u_old, &[1.0, 0.0], 0.0, 1.0)
                .unwrap();
            println!("explicit update, fractured {fractured:?}: p = {p:?}, want {want:?}");
            assert!(
                (p[0] - want[0]).abs() < 1e-14 && (p[1] - want[1]).abs() < 1e-14,
                "fractured {fractured:?}: {p:?} vs {want:?}"
            );
        }
    });
}

/// A 2D or 3D column (vertical axis D − 1, height `h`, `n` cells high, `w` wide), rollers
/// on the min sides and the lateral max sides, top drained at `p₀`.
fn column<const D: usize>(
    n: usize,
    w: usize,
    h: f64,
    e: f64,
    perm: f64,
    p0: f64,
    load: Option<f64>,
) -> Setup<D> {
    let v = D - 1;
    let mut hi = Point::<D>::repeat(h / n as f64 * w as f64);
    hi[v] = h;
    let mut cells = [w; D];
    cells[v] = n;
    let grid = generate::cartesian::<D>(Point::<D>::zeros(), hi, cells).unwrap();
    let mut s = setup(grid, e, 0.25, load.map(|l| (-l).into()), |g| {
        let nc = g.num_cells();
        FlowProblem::new(
            Rock::new(vec![0.1; nc], Permeability::uniform(nc, perm).unwrap()),
            Fluid::water(),
        )
        .pressure_bc(g.boundary(SIDES[2 * v + 1]).unwrap(), p0)
    });
    // Lateral rollers on the max sides too.
    let mut bcs: Vec<Displacement<D>> = Vec::new();
    for a in 0..D {
        let mut faces = s.grid.boundary(SIDES[2 * a]).unwrap();
        if a < v {
            faces.extend(s.grid.boundary(SIDES[2 * a + 1]).unwrap());
        }
        let mut components: [Option<ScalarField>; D] = std::array::from_fn(|_| None);
        components[a] = Some(0.0.into());
        bcs.push(Displacement {
            name: format!("roller {a}"),
            faces,
            components,
        });
    }
    s.dofs = DofMap::new(&s.grid, &bcs, &[]).unwrap();
    s.pattern = Pattern::new(&s.grid, &s.dofs).unwrap();
    s
}

/// A uniform initial pressure `p₀ = 1e7` with no load moves nothing: after an undrained
/// step and three steps, every scheme gives `|u| ≤ 1e-15 p₀ H / E` (machine precision of
/// the displacement scale) and `|p − p₀| ≤ 1e-15 p₀`.
fn uniform_p0<const D: usize>() {
    let (h, e, p0) = (10.0, 1e9, 1e7);
    let s = column::<D>(8, 2, h, e, 1e-15, p0, None);
    let nc = s.grid.num_cells();
    with_system(&s, vec![1.0; nc], vec![p0; nc], |sys| {
        let schemes: Vec<Box<dyn BiotCoupling<D>>> = vec![
            Box::new(Monolithic::new(sys, None).unwrap()),
            Box::new(FixedStress::new(1e-10, 100)),
            Box::new(ExplicitPressure::new(vec![true; nc])),
        ];
        for mut scheme in schemes {
            let states = march(sys, scheme.as_mut());
            let last = states.last().unwrap();
            let du = max_abs(&last.displacement);
            let dp = last
                .pressure
                .iter()
                .fold(0.0f64, |m, p| m.max((p - p0).abs()));
            println!(
                "{D}D uniform p0, {}: max |u| = {du:.2e} m, max |p − p0| = {dp:.2e} Pa",
                scheme.name()
            );
            assert!(
                du <= 1e-15 * p0 * h / e,
                "{D}D {}: |u| = {du:.3e}",
                scheme.name()
            );
            assert!(
                dp <= 1e-15 * p0,
                "{D}D {}: |p − p0| = {dp:.3e}",
                scheme.name()
            );
        }
    });
}

#[test]
fn uniform_initial_pressure_moves_nothing() {
    uniform_p0::<2>();
    uniform_p0::<3>();
}

/// 10 nD (1e-20 m²) under an instantaneous load σ₀ = 1e7 Pa (E = 1e10 Pa) on a 2D column
/// (40 × 3 cells) and a 3D column (20 × 2 × 2): the first implicit step from rest (no separate undrained solve) for Δt from 1 s to 1e6 s.
/// The pressure change must be monotone in depth (non-increasing towards the drained
/// top) in every vertical line of cells and bounded by the undrained value
/// `p_i = α σ₀ / (α² + S M_v)` (no overshoot, Haga, Osnes & Langtangen 2012).
fn low_permeability<const D: usize>(n: usize, w: usize) {
    let (h, e, p0, sigma0) = (10.0, 1e10, 1e7, 1e7);
    let s = column::<D>(n, w, h, e, 1e-20, p0, Some(sigma0));
    let nc = s.grid.num_cells();
    let lateral = nc / n;
    let nu = 0.25;
    let m_v = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let storage = 0.1 * Fluid::water().compressibility;
    let p_i = sigma0 / (1.0 + storage * m_v);
    with_system(&s, vec![1.0; nc], vec![p0; nc], |sys| {
        for dt in [1.0, 1e2, 1e4, 1e6] {
            let mut mono = Monolithic::new(sys, None).unwrap();
            let mut fs = FixedStress::new(1e-12, 2000);
            let rest = sys.rest_state();
            for (name, st) in [
                ("monolithic", mono.step(sys, &rest, 0.0, dt).unwrap().state),
                ("fixed-stress", fs.step(sys, &rest, 0.0, dt).unwrap().state),
            ] {
                // Cells are numbered x fastest, the vertical last: cell (l, j) = j L + l
                // with L the cells of a layer, j counted from the bottom.
                let mut worst_rise = 0.0f64;
                let mut max_p = 0.0f64;
                for l in 0..lateral {
                    for j in 0..n - 1 {
                        let below = st.pressure[j * lateral + l] - p0;
                        let above = st.pressure[(j + 1) * lateral + l] - p0;
                        worst_rise = worst_rise.max((above - below) / p_i);
                    }
                }
                for p in &st.pressure {
                    max_p = max_p.max((p - p0) / p_i);
                }
                let top = st.pressure[(n - 1) * lateral] - p0;
                println!(
                    "{D}D 10 nD, Δt = {dt:e} s, {name}: top cell p/p_i = {:.4}, max p/p_i = {max_p:.6}, worst upward rise {worst_rise:.2e}",
                    top / p_i
                );
                assert!(
                    worst_rise <= 1e-12,
                    "{D}D {name} Δt {dt}: pressure rises upward by {worst_rise:.3e} p_i"
                );
                assert!(
                    max_p <= 1.0 + 1e-12,
                    "{D}D {name} Δt {dt}: overshoot {max_p}"
                );
            }
        }
    });
}

#[test]
fn low_permeability_first_step_is_monotone() {
    low_permeability::<2>(40, 3);
    low_permeability::<3>(20, 2);
}

/// A prescribed top displacement `−δ` (instead of a load) on the drained column, first step
/// `Δt = 0` (undrained): uniform strain `−δ/H` and, from `α ΔV + S |K| δp = 0`,
/// `p − p₀ = α δ / (H S)` in every cell, to 1e-10 relative, for the monolithic and the
/// fixed-stress schemes (this exercises the prescribed-displacement terms `C u_p`).
fn prescribed_top<const D: usize>() {
    let (h, e, p0, delta) = (10.0, 1e9, 1e7, 1e-3);
    let mut s = column::<D>(10, 2, h, e, 1e-15, p0, None);
    let v = D - 1;
    let mut bcs: Vec<Displacement<D>> = Vec::new();
    for a in 0..D {
        let mut faces = s.grid.boundary(SIDES[2 * a]).unwrap();
        if a < v {
            faces.extend(s.grid.boundary(SIDES[2 * a + 1]).unwrap());
        }
        let mut components: [Option<ScalarField>; D] = std::array::from_fn(|_| None);
        components[a] = Some(0.0.into());
        bcs.push(Displacement {
            name: format!("roller {a}"),
            faces,
            components,
        });
    }
    let mut components: [Option<ScalarField>; D] = std::array::from_fn(|_| None);
    components[v] = Some((-delta).into());
    bcs.push(Displacement {
        name: "top".into(),
        faces: s.grid.boundary(SIDES[2 * v + 1]).unwrap(),
        components,
    });
    s.dofs = DofMap::new(&s.grid, &bcs, &[]).unwrap();
    s.pattern = Pattern::new(&s.grid, &s.dofs).unwrap();
    let nc = s.grid.num_cells();
    let storage = 0.1 * Fluid::water().compressibility;
    let want = delta / (h * storage);
    with_system(&s, vec![1.0; nc], vec![p0; nc], |sys| {
        let schemes: Vec<Box<dyn BiotCoupling<D>>> = vec![
            Box::new(Monolithic::new(sys, None).unwrap()),
            Box::new(FixedStress::new(1e-12, 1000)),
        ];
        for mut scheme in schemes {
            let st = scheme.step(sys, &sys.rest_state(), 0.0, 0.0).unwrap().state;
            let worst = st
                .pressure
                .iter()
                .map(|p| ((p - p0) - want).abs() / want)
                .fold(0.0, f64::max);
            let strain = (0..s.grid.num_nodes())
                .map(|n| {
                    let y = s.grid.node(n)[v];
                    let exact = -delta * y / h;
                    (st.displacement[D * n + v] - exact).abs() / delta
                })
                .fold(0.0, f64::max);
            println!(
                "{D}D prescribed top, {}: p error {worst:.2e}, u error {strain:.2e}",
                scheme.name()
            );
            assert!(worst < 1e-10 && strain < 1e-10, "{D}D {}", scheme.name());
        }
    });
}

#[test]
fn prescribed_displacement_undrained() {
    prescribed_top::<2>();
    prescribed_top::<3>();
}

/// An undrained (`Δt = 0`) monolithic step without storage (`c_f = 0`, `K_s = ∞`) is a
/// saddle point: rejected with an error naming the cell, not a panic or a wrong answer.
#[test]
fn undrained_step_without_storage_is_an_error() {
    let s = setup(
        generate::cartesian::<2>(Point::<2>::zeros(), Point::<2>::new(3.0, 3.0), [3, 3]).unwrap(),
        1e9,
        0.25,
        Some((-1e6).into()),
        |g| {
            let nc = g.num_cells();
            FlowProblem::new(
                Rock::new(vec![0.1; nc], Permeability::uniform(nc, 1e-15).unwrap()),
                Fluid {
                    viscosity: 1e-3,
                    compressibility: 0.0,
                },
            )
            .pressure_bc(g.boundary("ymax").unwrap(), 1e7)
        },
    );
    with_system(&s, vec![1.0; 9], vec![1e7; 9], |sys| {
        let mut mono = Monolithic::new(sys, None).unwrap();
        let err = mono.step(sys, &sys.rest_state(), 0.0, 0.0).unwrap_err();
        assert!(err.to_string().contains("cell 0"), "{err}");
        // A small Δt > 0 is fine.
        let ok = mono.step(sys, &sys.rest_state(), 0.0, 1e-3).unwrap();
        assert!(ok.residual < 1e-8);
    });
}

/// Bad input returns errors naming what is wrong.
#[test]
fn bad_input_is_an_error() {
    let s = small::<2>(3);
    let laws = LawMap::uniform(&s.grid, &s.law).unwrap();
    let mech = StaticProblem {
        grid: &s.grid,
        laws: &laws,
        dofs: &s.dofs,
        pattern: &s.pattern,
        loads: &s.loads,
    };
    let nc = s.grid.num_cells();
    let msg = |r: Result<BiotSystem<'_, 2>, BiotError>| r.err().map(|e| e.to_string()).unwrap();
    assert!(
        msg(BiotSystem::new(
            mech,
            &s.flow,
            vec![1.0; nc - 1],
            vec![0.0; nc]
        ))
        .contains("alpha")
    );
    let mut a = vec![1.0; nc];
    a[4] = 1.5;
    assert!(msg(BiotSystem::new(mech, &s.flow, a, vec![0.0; nc])).contains("cell 4"));
    let mut p0 = vec![0.0; nc];
    p0[2] = f64::NAN;
    assert!(msg(BiotSystem::new(mech, &s.flow, vec![1.0; nc], p0)).contains("cell 2"));
    let sys = BiotSystem::new(mech, &s.flow, vec![1.0; nc], vec![0.0; nc]).unwrap();
    let rest = sys.rest_state();
    let mut fs = FixedStress::new(1e-10, 10);
    let e = fs.step(&sys, &rest, 0.0, 1.0).unwrap_err().to_string();
    assert!(e.contains("drained bulk modulus"), "{e}");
    let mut mono = Monolithic::new(&sys, None).unwrap();
    let e = mono.step(&sys, &rest, 0.0, -1.0).unwrap_err().to_string();
    assert!(e.contains("time step"), "{e}");
    let short = BiotState {
        displacement: vec![0.0; 3],
        pressure: rest.pressure.clone(),
    };
    let e = mono.step(&sys, &short, 0.0, 1.0).unwrap_err().to_string();
    assert!(e.contains("state displacement"), "{e}");
    let mut ex = ExplicitPressure::new(vec![false; nc + 1]);
    let e = ex
        .update_pressure(
            &sys,
            &rest.displacement,
            &rest.displacement,
            &rest.pressure,
            0.0,
            1.0,
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("fractured"), "{e}");
    assert!(Monolithic::new(&sys, Some(-1.0)).is_err());
    assert!(
        BiotSystem::new(mech, &s.flow, vec![1.0; nc], vec![0.0; nc])
            .unwrap()
            .with_drained_bulk_modulus(vec![0.0; nc])
            .is_err()
    );
}

/// The initial state is the drained equilibrium with the loads at `t` and `p = p₀`: its
/// displacement equals [`solve_static`]'s to 1e-12 relative (a non-uniform `p₀` exerts no
/// force), and a monolithic step of the unchanged loads from it with `Δt = 0` changes
/// nothing (to 1e-12 relative).
#[test]
fn initial_state_is_static_equilibrium() {
    let s = small::<2>(5);
    let nc = s.grid.num_cells();
    let laws = LawMap::uniform(&s.grid, &s.law).unwrap();
    let mech = StaticProblem {
        grid: &s.grid,
        laws: &laws,
        dofs: &s.dofs,
        pattern: &s.pattern,
        loads: &s.loads,
    };
    let mut solver = DirectSolver::new(&s.pattern).unwrap();
    let reference = solve_static(&mech, &mut solver, 0.0, &StaticOptions::default())
        .unwrap()
        .displacement;
    let sys = BiotSystem::new(mech, &s.flow, alpha_of(nc), p0_of(&s.grid)).unwrap();
    let init = sys.initial_state(0.0).unwrap();
    let du = max_diff(&init.displacement, &reference) / max_abs(&reference);
    assert!(du < 1e-12, "initial state vs static: {du:.2e}");
    let next = Monolithic::new(&sys, None)
        .unwrap()
        .step(&sys, &init, 0.0, 0.0)
        .unwrap()
        .state;
    let du = max_diff(&next.displacement, &init.displacement) / max_abs(&reference);
    let dp = max_diff(&next.pressure, &init.pressure);
    println!("initial state: undrained step from it moves {du:.2e} (relative), p by {dp:.2e} Pa");
    assert!(du < 1e-12 && dp < 1e-12 * 1e7, "du {du:.2e}, dp {dp:.2e}");
}

/// A monolithic solver that factorizes a new matrix of another pressure scale (here the
/// stiffness is three times larger; `set_max_rank(0)`: no low-rank update) solves it as
/// a fresh solver does, to 1e-10 relative: the pressure rows of the right-hand side and
/// the pressure of the solution take the scale of the new factors, not the old one.
#[test]
fn refactorized_solver_matches_a_fresh_one() {
    let (a, b) = (small_with::<2>(5, 1e9), small_with::<2>(5, 3e9));
    let nc = a.grid.num_cells();
    with_system(&a, alpha_of(nc), p0_of(&a.grid), |sa| {
        with_system(&b, alpha_of(nc), p0_of(&b.grid), |sb| {
            assert!(sa.default_pressure_scale() != sb.default_pressure_scale());
            let mut reused = Monolithic::new(sa, None).unwrap();
            reused.set_max_rank(0);
            reused.step(sa, &sa.rest_state(), 0.0, 10.0).unwrap();
            let got = reused.step(sb, &sb.rest_state(), 0.0, 10.0).unwrap().state;
            let want = Monolithic::new(sb, None)
                .unwrap()
                .step(sb, &sb.rest_state(), 0.0, 10.0)
                .unwrap()
                .state;
            let du = max_diff(&got.displacement, &want.displacement) / max_abs(&want.displacement);
            let p0 = p0_of(&b.grid);
            let dp_want: Vec<f64> = want.pressure.iter().zip(&p0).map(|(p, q)| p - q).collect();
            let dp = max_diff(&got.pressure, &want.pressure) / max_abs(&dp_want);
            println!("refactorized vs fresh: u {du:.2e}, p {dp:.2e} (relative)");
            assert!(du < 1e-10 && dp < 1e-10, "u {du:.2e}, p {dp:.2e}");
        })
    });
}
