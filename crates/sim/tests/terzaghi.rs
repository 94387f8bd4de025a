//! Terzaghi's consolidation of a column (2D plane strain and 3D), VEM mechanics on
//! Cartesian cells + TPFA flow, monolithic and fixed-stress couplings.
//!
//! Setup: a column of height `H` (vertical axis `D − 1`), rollers on the sides and the
//! bottom, a compressive load `σ₀` on the top from `t = 0⁺`, the top drained
//! (`p = p₀`, the initial pressure), the bottom and sides impermeable. With the
//! oedometric modulus `M_v = λ + 2μ`, storage `S = φ c_f` and Biot coefficient α:
//!
//! ```text
//!   p(0⁺) − p₀ = p_i = α σ₀ / (α² + S M_v),        c_v = (k/μ_f) / (S + α²/M_v),
//!   p − p₀ = p_i Σ_m 4/((2m+1)π) sin((2m+1)π ζ/2) exp(−(2m+1)² π² T/4),
//!   u_top = −σ₀ H / M_v + (α/M_v) ∫₀^H (p − p₀) dy,
//! ```
//!
//! with `ζ = (H − y)/H` the depth from the drained top and `T = c_v t / H²`.
//!
//! On these columns every cell deforms linearly (u varies along the vertical only), so
//! the VEM stiffness is the exact linear (1D P1) one and `div_d` is exact; the pressure is
//! cell-wise constant (TPFA). The undrained response is an explicit `Δt = 0` step; the
//! consolidation is then integrated with implicit Euler on geometrically growing steps.

use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock};
use porofrac_grid::{Grid, Point, generate};
use porofrac_law::stiffness::Stiffness;
use porofrac_sim::*;
use porofrac_vem::VemLaw;

const E: f64 = 1e9;
const NU: f64 = 0.25;
const H: f64 = 10.0;
const SIGMA0: f64 = 1e6;
const P0: f64 = 1e7;
const PERM: f64 = 1e-15;
const VISC: f64 = 1e-3;
const PHI: f64 = 0.2;
const CF: f64 = 4.4e-10;
const SIDES: [&str; 6] = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"];

fn lame() -> (f64, f64) {
    (
        E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU)),
        E / (2.0 * (1.0 + NU)),
    )
}

struct Analytic {
    p_i: f64,
    c_v: f64,
    m_v: f64,
}

impl Analytic {
    fn new() -> Self {
        let (l, m) = lame();
        let m_v = l + 2.0 * m;
        let s = PHI * CF;
        Self {
            p_i: SIGMA0 / (1.0 + s * m_v),
            c_v: PERM / VISC / (s + 1.0 / m_v),
            m_v,
        }
    }
    fn tv(&self, t: f64) -> f64 {
        self.c_v * t / (H * H)
    }
    /// `p − p₀` at height `y`.
    fn pressure(&self, y: f64, t: f64) -> f64 {
        let (zeta, tv) = ((H - y) / H, self.tv(t));
        let mut s = 0.0;
        for m in 0..2000 {
            let k = (2 * m + 1) as f64 * std::f64::consts::PI;
            s += 4.0 / k * (k * zeta / 2.0).sin() * (-k * k * tv / 4.0).exp();
        }
        self.p_i * s
    }
    /// Degree of consolidation `U(T)`.
    fn degree(tv: f64) -> f64 {
        let mut s = 0.0;
        for m in 0..2000 {
            let k = (2 * m + 1) as f64 * std::f64::consts::PI;
            s += 8.0 / (k * k) * (-k * k * tv / 4.0).exp();
        }
        1.0 - s
    }
    fn settlement(&self, t: f64) -> f64 {
        let integral = self.p_i * H * (1.0 - Self::degree(self.tv(t)));
        -SIGMA0 * H / self.m_v + integral / self.m_v
    }
    /// The time at which the degree of consolidation is `u` (bisection on `T`).
    fn time_of_degree(&self, u: f64) -> f64 {
        let (mut lo, mut hi) = (1e-8f64, 10.0f64);
        for _ in 0..200 {
            let mid = (lo * hi).sqrt();
            if Self::degree(mid) < u {
                lo = mid
            } else {
                hi = mid
            }
        }
        lo * H * H / self.c_v
    }
}

struct Column<const D: usize> {
    grid: Grid<D>,
    law: VemLaw<D>,
    dofs: DofMap<D>,
    pattern: Pattern,
    loads: Loads<D>,
    flow: FlowModel<D>,
    top: Vec<usize>,
}

fn column<const D: usize>(n: usize) -> Column<D> {
    let v = D - 1;
    let mut hi = Point::<D>::repeat(1.0);
    hi[v] = H;
    let mut cells = [1usize; D];
    cells[v] = n;
    let grid = generate::cartesian::<D>(Point::<D>::zeros(), hi, cells).unwrap();
    let mut bcs = Vec::new();
    for a in 0..D {
        let faces: Vec<usize> = if a < v {
            [SIDES[2 * a], SIDES[2 * a + 1]]
                .iter()
                .flat_map(|s| grid.boundary(s).unwrap())
                .collect()
        } else {
            grid.boundary(SIDES[2 * v]).unwrap()
        };
        let mut components: [Option<ScalarField>; D] = std::array::from_fn(|_| None);
        components[a] = Some(0.0.into());
        bcs.push(Displacement {
            name: format!("roller {a}"),
            faces,
            components,
        });
    }
    let dofs = DofMap::new(&grid, &bcs, &[]).unwrap();
    let pattern = Pattern::new(&grid, &dofs).unwrap();
    let top_faces = grid.boundary(SIDES[2 * v + 1]).unwrap();
    let loads = Loads {
        tractions: vec![Traction {
            name: "top".into(),
            faces: top_faces.clone(),
            traction: std::array::from_fn(|a| if a == v { (-SIGMA0).into() } else { 0.0.into() }),
        }],
        ..Loads::default()
    };
    let nc = grid.num_cells();
    let rock = Rock::new(vec![PHI; nc], Permeability::uniform(nc, PERM).unwrap());
    let fluid = Fluid {
        viscosity: VISC,
        compressibility: CF,
    };
    let problem = FlowProblem::new(rock, fluid).pressure_bc(top_faces, P0);
    let flow = FlowModel::new(&grid, &problem).unwrap();
    let (l, m) = lame();
    let law = VemLaw::<D>::new(Stiffness::<D>::from_lame(l, m).unwrap());
    let top = grid.nodes_of_faces(&grid.boundary(SIDES[2 * v + 1]).unwrap());
    Column {
        grid,
        law,
        dofs,
        pattern,
        loads,
        flow,
        top,
    }
}

/// Errors at the consolidation degrees 0.1, 0.5, 0.9: max over cells of
/// `|p − p_exact| / p_i` and the relative settlement error; plus the undrained error,
/// the number of steps and the fixed-stress iterations.
struct Run {
    undrained: f64,
    p_err: [f64; 3],
    w_err: [f64; 3],
    steps: usize,
    iterations: usize,
}

/// `dt0`: the first consolidation step as a fraction of `H²/c_v`; `ratio`: growth factor.
fn run<const D: usize>(n: usize, dt0: f64, ratio: f64, fixed_stress: bool) -> Run {
    let col = column::<D>(n);
    let laws = LawMap::uniform(&col.grid, &col.law).unwrap();
    let mech = StaticProblem {
        grid: &col.grid,
        laws: &laws,
        dofs: &col.dofs,
        pattern: &col.pattern,
        loads: &col.loads,
    };
    let nc = col.grid.num_cells();
    let (l, m) = lame();
    let sys = BiotSystem::new(mech, &col.flow, vec![1.0; nc], vec![P0; nc])
        .unwrap()
        .with_drained_bulk_modulus(vec![l + 2.0 * m / D as f64; nc])
        .unwrap();
    let mut scheme: Box<dyn BiotCoupling<D>> = if fixed_stress {
        Box::new(FixedStress::new(1e-11, 500))
    } else {
        Box::new(Monolithic::new(&sys, None).unwrap())
    };
    let an = Analytic::new();
    let v = D - 1;
    let mut state = sys.rest_state();
    // Undrained response: an explicit Δt = 0 step with the load applied.
    let first = scheme.step(&sys, &state, 0.0, 0.0).unwrap();
    state = first.state;
    let mut iterations = first.iterations;
    let undrained = state
        .pressure
        .iter()
        .map(|p| ((p - P0) - an.p_i).abs() / an.p_i)
        .fold(0.0, f64::max);
    let targets = [0.1, 0.5, 0.9].map(|u| an.time_of_degree(u));
    let tscale = H * H / an.c_v;
    let (mut t, mut dt) = (0.0, dt0 * tscale);
    let mut steps = 0;
    let mut p_err = [0.0; 3];
    let mut w_err = [0.0; 3];
    for (k, &target) in targets.iter().enumerate() {
        while t < target * (1.0 - 1e-12) {
            let h = dt.min(target - t);
            let s = scheme.step(&sys, &state, t, h).unwrap();
            iterations += s.iterations;
            state = s.state;
            t += h;
            if h == dt {
                dt *= ratio;
            }
            steps += 1;
        }
        p_err[k] = (0..nc)
            .map(|c| {
                let y = col.grid.cell_centroid(c)[v];
                ((state.pressure[c] - P0) - an.pressure(y, t)).abs() / an.p_i
            })
            .fold(0.0, f64::max);
        let w = col
            .top
            .iter()
            .map(|&nd| state.displacement[D * nd + v])
            .sum::<f64>()
            / col.top.len() as f64;
        let we = an.settlement(t);
        w_err[k] = ((w - we) / we).abs();
    }
    Run {
        undrained,
        p_err,
        w_err,
        steps,
        iterations,
    }
}

fn print_row(label: &str, r: &Run) {
    println!(
        "{label:<34} steps {:>4}  undrained {:.1e}  p err U=.1/.5/.9: {:.2e} {:.2e} {:.2e}  w err: {:.2e} {:.2e} {:.2e}",
        r.steps,
        r.undrained,
        r.p_err[0],
        r.p_err[1],
        r.p_err[2],
        r.w_err[0],
        r.w_err[1],
        r.w_err[2]
    );
}

fn check(label: &str, r: &Run) {
    print_row(label, r);
    assert!(
        r.undrained < 1e-10,
        "{label}: undrained {:.2e}",
        r.undrained
    );
    for k in 0..3 {
        assert!(
            r.p_err[k] < 0.01,
            "{label}: pressure error {:.3e} at degree {k}",
            r.p_err[k]
        );
        assert!(
            r.w_err[k] < 0.01,
            "{label}: settlement error {:.3e} at degree {k}",
            r.w_err[k]
        );
    }
}

/// Monolithic, 2D: pressure within 1% of `p_i` and settlement within 1% at U = 0.1, 0.5,
/// 0.9; the undrained step is exact to 1e-10; convergence tables in h and Δt are printed
/// and the errors must decrease under refinement.
#[test]
fn terzaghi_2d_monolithic() {
    println!("Terzaghi 2D, monolithic: convergence in h (dt0 = 1e-5 H²/c_v, ratio 1.05)");
    for n in [25, 50, 100, 200] {
        print_row(&format!("  cells {n}"), &run::<2>(n, 1e-5, 1.05, false));
    }
    println!("Terzaghi 2D, monolithic: convergence in h with small steps (ratio 1.01)");
    let mut last = f64::INFINITY;
    for n in [25, 50, 100, 200] {
        let r = run::<2>(n, 1e-6, 1.01, false);
        print_row(&format!("  cells {n}"), &r);
        // The early-time (U = 0.1) pressure error is dominated by h here: it must drop.
        assert!(r.p_err[0] < last, "no convergence in h at {n} cells");
        last = r.p_err[0];
    }
    println!("Terzaghi 2D, monolithic: convergence in Δt (100 cells)");
    let mut last = f64::INFINITY;
    for ratio in [1.4, 1.2, 1.1, 1.05, 1.025] {
        let r = run::<2>(100, 1e-5, ratio, false);
        print_row(&format!("  ratio {ratio}"), &r);
        let worst = r.p_err.iter().fold(0.0f64, |m, &e| m.max(e));
        assert!(worst < last, "no convergence in Δt at ratio {ratio}");
        last = worst;
    }
    check(
        "2D monolithic, 100 cells, ratio 1.05",
        &run::<2>(100, 1e-5, 1.05, false),
    );
}

/// Fixed-stress, 2D: the same accuracy as the monolithic scheme.
#[test]
fn terzaghi_2d_fixed_stress() {
    let r = run::<2>(100, 1e-5, 1.05, true);
    println!("fixed-stress iterations in total: {}", r.iterations);
    check("2D fixed-stress, 100 cells, ratio 1.05", &r);
}

/// Monolithic and fixed-stress, 3D column of hexahedra.
#[test]
fn terzaghi_3d() {
    check(
        "3D monolithic, 100 cells, ratio 1.05",
        &run::<3>(100, 1e-5, 1.05, false),
    );
    let r = run::<3>(100, 1e-5, 1.05, true);
    println!("fixed-stress iterations in total: {}", r.iterations);
    check("3D fixed-stress, 100 cells, ratio 1.05", &r);
}
