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
//! each, then the peer's "best of" figure (each timed key, assembly and setup + solve, the
//! minimum over the runs); `AMG_OPTS=theta=0.02,degree=3` overrides multigrid options (`theta`, `degree`,
//! `upper`, `ratio`, `lanczos`, `omega`, `coarse`, `aggressive`: see `porofrac_amg::AmgOptions`);
//! `AMG_PRECISION=double` stores the hierarchy's finest matrix in double instead of single
//! precision (`AmgSolver::set_precision`);
//! `SYSTEM_HEAP=1` leaves glibc's heap policy as it is instead of keeping freed memory
//! (`retain_freed_memory` below, the policy of the `porofrac` binary: the figures in
//! docs/BENCHMARKS.md were measured with it).
//!
//! Grids: E2 = n × n squares split in two triangles, E3 = n³ cubes split in six
//! tetrahedra (P1 = VEM on simplices), E = 1, ν = 0.3 (plane strain in 2D), Dirichlet on
//! the whole boundary, body force from the manufactured solution
//! ([`porofrac_sim::standard`]). Cholesky uses AMD in
//! 2D and geometric nested dissection in 3D, on all threads; setup = symbolic + numeric
//! factorization. CG-AMG: setup = the multigrid hierarchy. L2 error with a degree-5 rule
//! per simplex (Radon's 7 points, 64-point collapsed Gauss).

use std::time::Instant;

use porofrac_grid::{Point, generate};
use porofrac_law::Stiffness;
use porofrac_sim::ordering::nested_dissection;
use porofrac_sim::standard::{self, Manufactured};
use porofrac_sim::{
    AmgSolver, DirectSolver, DofMap, LawMap, LinearSolve, Loads, Pattern, assemble,
    elasticity_amg_options, nodal_loads,
};
use porofrac_vem::VemLaw;

fn peak_rss_mb() -> f64 {
    status_mb("VmHWM:")
}

/// With `MEM_TRACE` set: the time since the process started, the resident and peak
/// memory after a stage, on stderr.
fn trace(stage: &str) {
    static START: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    let t = START.get_or_init(Instant::now).elapsed().as_secs_f64();
    if std::env::var_os("MEM_TRACE").is_some() {
        eprintln!(
            "{stage:>10}: {t:7.3} s, resident {:6.0} MB, peak {:6.0} MB",
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

/// Times of one run: assembly, and solver setup + solve (the two keys the peer times).
type Times = (f64, f64);

fn run<const D: usize>(n: usize, solver: &str, tol: f64, problem: &Manufactured<D>) -> Times {
    trace("start");
    let t0 = Instant::now();
    let grid =
        generate::simplices::<D>(Point::<D>::zeros(), Point::<D>::repeat(1.0), [n; D]).unwrap();
    let t_grid = t0.elapsed().as_secs_f64();
    trace("grid");
    let t1 = Instant::now();
    let bc = problem.boundary("boundary", grid.boundary_faces());
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
    trace("stiffness");
    let loads = Loads {
        body_force: Some(problem.body_force()),
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
            if std::env::var("AMG_PRECISION").as_deref() == Ok("double") {
                s.set_precision(porofrac_amg::Precision::Double);
            }
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
    let l2 = problem
        .l2_error_simplices(&grid, &u)
        .expect("a grid of simplices");
    println!(
        "| E{D} | {n} | {} | {neq} | {solver} | {t_grid:.2} | {t_asm:.2} | {t_setup:.2} | {t_solve:.2} | {:.2} | {iterations} | {:.1e} | {l2:.4e} | {:.0} | {info} |",
        D * grid.num_nodes(),
        t_asm + t_setup + t_solve,
        rn / bn,
        peak_rss_mb(),
    );
    (t_asm, t_setup + t_solve)
}

/// glibc's heap keeps freed memory for reuse: no `mmap` for large blocks, no trimming
/// (the policy of the `porofrac` binary, `crates/cli/src/heap.rs`, which explains it).
/// Elsewhere than Linux with glibc it does nothing.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
fn retain_freed_memory() {
    // SAFETY: `mallopt` only sets allocator parameters; it is called with constants glibc
    // documents, before any other thread starts.
    unsafe {
        libc::mallopt(libc::M_MMAP_MAX, 0);
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn retain_freed_memory() {}

fn main() {
    if std::env::var_os("SYSTEM_HEAP").is_none() {
        retain_freed_memory();
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        eprintln!("usage: solvers e2|e3 n cholesky|cg-amg|none [tolerance]");
        std::process::exit(2);
    }
    let n: usize = args[1].parse().expect("n");
    let tol: f64 = args.get(3).map_or(1e-8, |t| t.parse().expect("tolerance"));
    let repeat: usize = std::env::var("REPEAT").map_or(1, |r| r.parse().expect("REPEAT"));
    let mut best = (f64::INFINITY, f64::INFINITY);
    for _ in 0..repeat {
        let (asm, solve) = match args[0].as_str() {
            "e2" => run::<2>(n, &args[2], tol, &standard::e2()),
            "e3" => run::<3>(n, &args[2], tol, &standard::e3()),
            other => panic!("problem {other}: e2 or e3"),
        };
        best = (best.0.min(asm), best.1.min(solve));
    }
    if repeat > 1 {
        // The FEniCSx driver's rule (`best_of` in the FEniCSx driver's common.py, kept
        // outside this repository): every timed key is the minimum over the repetitions.
        println!(
            "best of {repeat}, per-key minima: assembly {:.2} s, setup + solve {:.2} s, total {:.2} s",
            best.0,
            best.1,
            best.0 + best.1
        );
    }
}
