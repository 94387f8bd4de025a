//! Direct (sparse Cholesky) against CG-AMG on the standard problems E2 and E3
//! (docs/BENCHMARKS.md): time of assembly, solver setup and solve, CG iterations, the
//! relative residual, the L2 error against the exact solution, and the peak resident
//! memory of the process (`VmHWM`). One problem and solver per run, so that the peak
//! memory belongs to it.
//!
//! `cargo run --release -p porofrac-sim --example solvers -- e2 300 cg-amg [tolerance]`
//! (`none` instead of the solver: grid and assembly only, for the memory baseline).
//! `FAER_THREADS=n` factorizes with `Par::rayon(n)` (1: sequentially) instead of the
//! default (all threads of the pool);
//! `RAYON_NUM_THREADS` sets the pool of the parallel assembly and AMG kernels;
//! `REPEAT=3` runs the whole case (grid to error) three times in the process, one row
//! each (the peer's "best of" rule); `AMG_OPTS=theta=0.02,degree=3` overrides multigrid options (`theta`, `degree`,
//! `upper`, `ratio`, `lanczos`, `omega`, `coarse`, `aggressive`: see `porofrac_amg::AmgOptions`).
//!
//! Grids: E2 = n × n squares split in two triangles, E3 = n³ cubes split in six
//! tetrahedra (P1 = VEM on simplices), E = 1, ν = 0.3 (plane strain in 2D), Dirichlet on
//! the whole boundary, body force from the manufactured solution. Cholesky uses AMD in
//! 2D and geometric nested dissection in 3D, on all threads; setup = symbolic + numeric
//! factorization. CG-AMG: setup = the multigrid hierarchy. L2 error with a degree-5 rule
//! per simplex (Radon's 7 points, 64-point collapsed Gauss).

use std::f64::consts::PI;
use std::time::Instant;

use porofrac_grid::{Grid, Point, generate};
use porofrac_law::Stiffness;
use porofrac_sim::ordering::nested_dissection;
use porofrac_sim::{
    AmgSolver, DirectSolver, Displacement, DofMap, LawMap, LinearSolve, Loads, Pattern,
    ScalarField, assemble, elasticity_amg_options, nodal_loads,
};
use porofrac_vem::VemLaw;

type Exact<const D: usize> = fn(&[f64]) -> [f64; D];

fn e2_exact(x: &[f64]) -> [f64; 2] {
    [
        (PI * x[0]).sin() * (PI * x[1]).sin() / 100.0,
        x[0] * x[0] * x[1] / 100.0,
    ]
}

fn e3_exact(p: &[f64]) -> [f64; 3] {
    let (x, y, z) = (p[0], p[1], p[2]);
    [
        (PI * x).sin() * (PI * y).sin() * (PI * z).sin() / 100.0,
        x * x * y * z / 100.0,
        y * z * (PI * x).cos() / 100.0,
    ]
}

fn e2_force() -> [ScalarField; 2] {
    [
        ScalarField::from_fn(|x, _| {
            -x[0] / 52.0 + 9.0 * PI * PI * (PI * x[0]).sin() * (PI * x[1]).sin() / 520.0
        }),
        ScalarField::from_fn(|x, _| {
            -x[1] / 130.0 - PI * PI * (PI * x[0]).cos() * (PI * x[1]).cos() / 104.0
        }),
    ]
}

fn e3_force() -> [ScalarField; 3] {
    [
        ScalarField::from_fn(|p, _| {
            let (x, y, z) = (p[0], p[1], p[2]);
            -x * z / 52.0
                + PI * y * (PI * x).sin() / 104.0
                + 11.0 * PI * PI * (PI * x).sin() * (PI * y).sin() * (PI * z).sin() / 520.0
        }),
        ScalarField::from_fn(|p, _| {
            let (x, y, z) = (p[0], p[1], p[2]);
            -y * z / 130.0
                - PI * PI * (PI * z).sin() * (PI * x).cos() * (PI * y).cos() / 104.0
                - (PI * x).cos() / 104.0
        }),
        ScalarField::from_fn(|p, _| {
            let (x, y, z) = (p[0], p[1], p[2]);
            -x * x / 104.0 + PI * PI * y * z * (PI * x).cos() / 260.0
                - PI * PI * (PI * y).sin() * (PI * x).cos() * (PI * z).cos() / 104.0
        }),
    ]
}

/// Quadrature point: weight (summing to 1), barycentric coordinates.
type QPoint = (f64, [f64; 4]);

fn rule5<const D: usize>() -> Vec<QPoint> {
    if D == 2 {
        let s = 15f64.sqrt();
        let (a1, w1) = ((6.0 - s) / 21.0, (155.0 - s) / 1200.0);
        let (a2, w2) = ((6.0 + s) / 21.0, (155.0 + s) / 1200.0);
        let mut r = vec![(9.0 / 40.0, [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.0])];
        for (a, w) in [(a1, w1), (a2, w2)] {
            let b = 1.0 - 2.0 * a;
            r.push((w, [b, a, a, 0.0]));
            r.push((w, [a, b, a, 0.0]));
            r.push((w, [a, a, b, 0.0]));
        }
        r
    } else {
        let g = [
            (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
            (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        ];
        let g01: Vec<(f64, f64)> = g.iter().map(|&(x, w)| (0.5 * (1.0 + x), 0.5 * w)).collect();
        let mut r = Vec::with_capacity(64);
        for &(s, ws) in &g01 {
            for &(t, wt) in &g01 {
                for &(q, wq) in &g01 {
                    let (x, y, z) = (s, t * (1.0 - s), q * (1.0 - s) * (1.0 - t));
                    let w = 6.0 * ws * wt * wq * (1.0 - s) * (1.0 - s) * (1.0 - t);
                    r.push((w, [1.0 - x - y - z, x, y, z]));
                }
            }
        }
        r
    }
}

/// `‖u − u_h‖_L2` of the P1 field `u` (node-major) on a simplex grid.
fn l2_error<const D: usize>(grid: &Grid<D>, u: &[f64], exact: Exact<D>) -> f64 {
    let rule = rule5::<D>();
    let mut sum = 0.0;
    for c in 0..grid.num_cells() {
        let nodes = grid.cell_nodes(c);
        let vol = grid.cell_volume(c);
        for (w, l) in &rule {
            let mut x = [0.0; 3];
            let mut uh = [0.0; 3];
            for (k, &n) in nodes.iter().enumerate() {
                for a in 0..D {
                    x[a] += l[k] * grid.node(n)[a];
                    uh[a] += l[k] * u[D * n + a];
                }
            }
            let ue = exact(&x[..D]);
            sum += w * vol * (0..D).map(|a| (ue[a] - uh[a]).powi(2)).sum::<f64>();
        }
    }
    sum.sqrt()
}

fn peak_rss_mb() -> f64 {
    status_mb("VmHWM:")
}

/// With `MEM_TRACE` set: the resident and peak memory after a stage, on stderr.
fn trace(stage: &str) {
    if std::env::var_os("MEM_TRACE").is_some() {
        eprintln!(
            "{stage:>10}: resident {:6.0} MB, peak {:6.0} MB",
            status_mb("VmRSS:"),
            status_mb("VmHWM:")
        );
    }
}

fn status_mb(key: &str) -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with(key))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn run<const D: usize>(n: usize, solver: &str, tol: f64, exact: Exact<D>, f: [ScalarField; D]) {
    let t0 = Instant::now();
    let grid =
        generate::simplices::<D>(Point::<D>::zeros(), Point::<D>::repeat(1.0), [n; D]).unwrap();
    let t_grid = t0.elapsed().as_secs_f64();
    trace("grid");
    let t1 = Instant::now();
    let bc = Displacement {
        name: "boundary".into(),
        faces: grid.boundary_faces(),
        components: std::array::from_fn(|a| Some(ScalarField::from_fn(move |x, _| exact(x)[a]))),
    };
    let dofs = DofMap::new(&grid, &[bc], &[]).unwrap();
    trace("dofs");
    let pattern = Pattern::new(&grid, &dofs).unwrap();
    trace("pattern");
    let law = VemLaw::new(Stiffness::<D>::isotropic(1.0, 0.3).unwrap());
    let laws = LawMap::uniform(&grid, &law).unwrap();
    let mut u = vec![0.0; dofs.num_dofs()];
    dofs.set_prescribed(&grid, 0.0, &mut u);
    let mut values = vec![0.0; pattern.nnz()];
    let mut rhs = vec![0.0; dofs.num_equations()];
    assemble(&grid, &laws, &dofs, &pattern, &u, &mut values, &mut rhs).unwrap();
    let loads = Loads {
        body_force: Some(f),
        ..Loads::default()
    };
    let mut full = vec![0.0; dofs.num_dofs()];
    nodal_loads(&grid, &loads, 0.0, &mut full).unwrap();
    dofs.reduce_add(&full, &mut rhs);
    let t_asm = t1.elapsed().as_secs_f64();
    trace("assembly");
    let neq = dofs.num_equations();
    let mut x = vec![0.0; neq];
    let (t_setup, t_solve, iterations, info) = match solver {
        "cholesky" => {
            let t2 = Instant::now();
            let mut s = if D == 3 {
                DirectSolver::with_ordering(&pattern, &nested_dissection(&grid, &dofs)).unwrap()
            } else {
                DirectSolver::new(&pattern).unwrap()
            };
            if let Ok(t) = std::env::var("FAER_THREADS") {
                let t: usize = t.parse().expect("FAER_THREADS");
                s.set_parallelism(if t == 1 {
                    faer::Par::Seq
                } else {
                    faer::Par::rayon(t)
                });
            }
            s.factorize(&pattern, &values).unwrap();
            let t_setup = t2.elapsed().as_secs_f64();
            let t3 = Instant::now();
            x.copy_from_slice(&rhs);
            s.solve_in_place(&mut x).unwrap();
            let t_solve = t3.elapsed().as_secs_f64();
            (
                t_setup,
                t_solve,
                0,
                format!("factor nnz {:.3e}", s.factor_nnz() as f64),
            )
        }
        "cg-amg" => {
            let t2 = Instant::now();
            let mut s = AmgSolver::new(&grid, &dofs, &pattern, tol).unwrap();
            if let Ok(spec) = std::env::var("AMG_OPTS") {
                let mut o = elasticity_amg_options(D);
                for kv in spec.split(',') {
                    let (k, v) = kv.split_once('=').unwrap();
                    let v: f64 = v.parse().unwrap();
                    match k {
                        "theta" => o.strength_threshold = v,
                        "degree" => o.smoother_degree = v as usize,
                        "upper" => o.chebyshev_upper = v,
                        "ratio" => o.chebyshev_ratio = v,
                        "lanczos" => o.lanczos_steps = v as usize,
                        "omega" => o.prolongation_damping = v,
                        "coarse" => o.max_coarse = v as usize,
                        "aggressive" => o.aggressive_levels = v as usize,
                        _ => panic!("AMG_OPTS: unknown option {k}"),
                    }
                }
                s.set_options(o);
            }
            s.setup(&pattern, &values).unwrap();
            let t_setup = t2.elapsed().as_secs_f64();
            trace("setup");
            let t3 = Instant::now();
            let st = s.solve_system(&pattern, &values, &rhs, &mut x).unwrap();
            let t_solve = t3.elapsed().as_secs_f64();
            trace("solve");
            if std::env::var_os("MEM_TRACE").is_some() {
                eprintln!("{:?}", s.hierarchy().unwrap().memory());
            }
            let h = s.hierarchy().unwrap();
            let levels: Vec<String> = h.level_info().iter().map(|l| l.rows.to_string()).collect();
            let info = format!(
                "levels {}, op. complexity {:.2}, fine nnz {:.3e}",
                levels.join("/"),
                h.operator_complexity(),
                h.matrix().nnz() as f64
            );
            (t_setup, t_solve, st.iterations, info)
        }
        // Grid and assembly only: the memory baseline.
        "none" => (0.0, 0.0, 0, String::new()),
        other => panic!("solver {other}: cholesky, cg-amg or none"),
    };
    // Relative residual ‖A x − b‖ / ‖b‖.
    let mut ax = vec![0.0; neq];
    pattern.mul_add(&values, &x, &mut ax);
    let rn: f64 = ax
        .iter()
        .zip(&rhs)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt();
    let bn: f64 = rhs.iter().map(|b| b * b).sum::<f64>().sqrt();
    dofs.scatter_add(&x, &mut u);
    let l2 = l2_error(&grid, &u, exact);
    println!(
        "| E{D} | {n} | {} | {neq} | {solver} | {t_grid:.2} | {t_asm:.2} | {t_setup:.2} | {t_solve:.2} | {:.2} | {iterations} | {:.1e} | {l2:.4e} | {:.0} | {info} |",
        D * grid.num_nodes(),
        t_asm + t_setup + t_solve,
        rn / bn,
        peak_rss_mb(),
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        eprintln!("usage: solvers e2|e3 n cholesky|cg-amg|none [tolerance]");
        std::process::exit(2);
    }
    let n: usize = args[1].parse().expect("n");
    let tol: f64 = args.get(3).map_or(1e-8, |t| t.parse().expect("tolerance"));
    let repeat: usize = std::env::var("REPEAT").map_or(1, |r| r.parse().expect("REPEAT"));
    for _ in 0..repeat {
        match args[0].as_str() {
            "e2" => run::<2>(n, &args[2], tol, e2_exact, e2_force()),
            "e3" => run::<3>(n, &args[2], tol, e3_exact, e3_force()),
            other => panic!("problem {other}: e2 or e3"),
        }
    }
}
