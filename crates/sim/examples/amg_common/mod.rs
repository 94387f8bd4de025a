//! The standard problems for the examples: assemble, solve with CG-AMG, compare with
//! Cholesky, print a table row.
#![allow(dead_code)]

#[path = "../../tests/elasticity_systems/mod.rs"]
mod systems;

use std::time::Instant;

use porofrac_amg::{Amg, AmgOptions};
#[allow(unused_imports)]
pub use systems::{System, e2, e3, rel_diff};

/// Command-line settings shared by the examples.
pub struct Args {
    pub sizes: Vec<usize>,
    pub tol: f64,
    /// Largest size compared with Cholesky.
    pub cholesky_max: usize,
    pub options: AmgOptions,
}

/// Parse `[sizes…] [--tol T] [--cholesky-max N] [--degree K] [--ratio R] [--coarse N]
/// [--theta T] [--damping W] [--aggressive L] [--upper U]`.
pub fn args(default_sizes: &[usize], cholesky_max: usize) -> Args {
    let mut out = Args {
        sizes: Vec::new(),
        tol: 1e-8,
        cholesky_max,
        options: AmgOptions::default(),
    };
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let mut k = 0;
    while k < argv.len() {
        let a = &argv[k];
        let val = || argv.get(k + 1).cloned().unwrap_or_default();
        match a.as_str() {
            "--tol" => out.tol = val().parse().expect("--tol T"),
            "--cholesky-max" => out.cholesky_max = val().parse().expect("--cholesky-max N"),
            "--degree" => out.options.smoother_degree = val().parse().expect("--degree K"),
            "--ratio" => out.options.chebyshev_ratio = val().parse().expect("--ratio R"),
            "--coarse" => out.options.max_coarse = val().parse().expect("--coarse N"),
            "--theta" => out.options.strength_threshold = val().parse().expect("--theta T"),
            "--damping" => out.options.prolongation_damping = val().parse().expect("--damping W"),
            "--aggressive" => {
                out.options.aggressive_levels = val().parse().expect("--aggressive L")
            }
            "--upper" => out.options.chebyshev_upper = val().parse().expect("--upper U"),
            s => {
                out.sizes.push(s.parse().expect("a size"));
                k += 1;
                continue;
            }
        }
        k += 2;
    }
    if out.sizes.is_empty() {
        out.sizes = default_sizes.to_vec();
    }
    out
}

/// Print the table header.
pub fn header() {
    println!(
        "| problem | n | equations | levels | op. complexity | setup | iterations | solve | setup + solve | rel. residual | vs Cholesky | Cholesky |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
}

/// Solve `sys` and print one row.
pub fn run<const D: usize>(name: &str, n: usize, sys: &System<D>, args: &Args) {
    let t0 = Instant::now();
    let mut amg =
        Amg::elasticity(sys.sym(), &sys.coords, D, &sys.eq_dofs, &args.options).expect("setup");
    let t_setup = t0.elapsed().as_secs_f64();
    let mut x = vec![0.0; sys.n()];
    let t1 = Instant::now();
    let stats = amg.solve(&mut x, &sys.rhs, args.tol, 500).expect("solve");
    let t_solve = t1.elapsed().as_secs_f64();
    let levels: Vec<String> = amg
        .level_info()
        .iter()
        .map(|l| l.rows.to_string())
        .collect();
    let (diff, t_chol) = if n <= args.cholesky_max {
        let t2 = Instant::now();
        let chol = sys.cholesky();
        let t = t2.elapsed().as_secs_f64();
        (format!("{:.2e}", rel_diff(&x, &chol)), format!("{t:.2} s"))
    } else {
        ("–".into(), "–".into())
    };
    println!(
        "| {name} | {n} | {} | {} | {:.2} | {t_setup:.3} s | {} | {t_solve:.3} s | {:.3} s | {:.1e} | {diff} | {t_chol} |",
        sys.n(),
        levels.join("/"),
        amg.operator_complexity(),
        stats.iterations,
        t_setup + t_solve,
        stats.relative_residual,
    );
}
