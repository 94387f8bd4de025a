//! The hierarchy as `porofrac run` builds it for E2 or E3: the finest matrix in single
//! precision, `elasticity_amg_options`, CG through `Amg::solve_upper` with the
//! double-precision values to 1e-8. Times, best of `REPS` builds, the single-precision full
//! rows (`SymCsr`), the hierarchy, CG, and one V-cycle (`Amg::apply`, mean of ten).
//! First CG's product (`Amg::operator`) and the single-precision full rows' product, mean
//! of twenty each, alternated, best of `REPS`.
//!
//! `cargo run --release -p porofrac-sim --features fixtures --example amg_single -- e3 40 [REPS]
//! [products]` (`products`: the products only)

mod amg_common;

use std::time::Instant;

use porofrac_amg::{Amg, Precision, SymCsr};
use porofrac_sim::elasticity_amg_options;

fn main() {
    let argv: Vec<String> = std::env::args().collect();
    let problem = argv.get(1).map_or("e3", String::as_str);
    let n: usize = argv.get(2).map_or(40, |s| s.parse().expect("a size"));
    let reps: usize = argv.get(3).map_or(3, |s| s.parse().expect("a count"));
    match problem {
        "e3" => run(&amg_common::e3(n), reps),
        "e2" => run(&amg_common::e2(n), reps),
        other => panic!("problem {other}: want e2 or e3"),
    }
}

fn run<const D: usize>(sys: &amg_common::System<D>, reps: usize) {
    products(sys, reps);
    if std::env::args().nth(4).as_deref() == Some("products") {
        return;
    }
    let options = elasticity_amg_options(D);
    let mut best = [f64::INFINITY; 4];
    let (mut iterations, mut residual) = (0, 0.0);
    for _ in 0..reps.max(1) {
        let t = Instant::now();
        let sym = SymCsr::from_upper_csc_in(
            Precision::Single,
            sys.n(),
            sys.pattern.col_ptr(),
            sys.pattern.row_idx(),
            &sys.values,
        )
        .expect("matrix");
        let t_rows = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut amg = Amg::elasticity(sym, &sys.coords, D, &sys.eq_dofs, &options).expect("setup");
        let t_setup = t.elapsed().as_secs_f64();
        let mut x = vec![0.0; sys.n()];
        let t = Instant::now();
        let stats = amg
            .solve_upper(&sys.values, &mut x, &sys.rhs, 1e-8, 500)
            .expect("solve");
        let t_cg = t.elapsed().as_secs_f64();
        let mut z = vec![0.0; sys.n()];
        let t = Instant::now();
        for _ in 0..10 {
            amg.apply(&sys.rhs, &mut z).expect("V-cycle");
        }
        let t_cycle = t.elapsed().as_secs_f64() / 10.0;
        (iterations, residual) = (stats.iterations, stats.relative_residual);
        for (b, t) in best.iter_mut().zip([t_rows, t_setup, t_cg, t_cycle]) {
            *b = b.min(t);
        }
    }
    println!(
        "{} equations: full rows {:.4} s, hierarchy {:.4} s, CG {:.4} s ({iterations} iterations, residual {residual:e}), V-cycle {:.2} ms",
        sys.n(),
        best[0],
        best[1],
        best[2],
        1e3 * best[3]
    );
}

/// Best of `reps` means of twenty products: CG's (through [`Amg::operator`], the
/// double-precision upper triangle) and the single-precision full rows', alternated.
fn products<const D: usize>(sys: &amg_common::System<D>, reps: usize) {
    let sym = SymCsr::from_upper_csc_in(
        Precision::Single,
        sys.n(),
        sys.pattern.col_ptr(),
        sys.pattern.row_idx(),
        &sys.values,
    )
    .expect("matrix");
    let options = elasticity_amg_options(D);
    let mut amg = Amg::elasticity(sym, &sys.coords, D, &sys.eq_dofs, &options).expect("setup");
    let x: Vec<f64> = (0..sys.n()).map(|i| (0.001 * i as f64).sin()).collect();
    let mut y = vec![0.0; sys.n()];
    let mut best = [f64::INFINITY; 2];
    for _ in 0..reps.max(1) {
        let op = amg.operator(&sys.values).expect("operator");
        let t = Instant::now();
        for _ in 0..20 {
            op.apply(&x, &mut y).expect("product");
        }
        best[0] = best[0].min(t.elapsed().as_secs_f64() / 20.0);
        let t = Instant::now();
        for _ in 0..20 {
            amg.matrix().mul(&x, &mut y).expect("product");
        }
        best[1] = best[1].min(t.elapsed().as_secs_f64() / 20.0);
    }
    println!(
        "CG product (double-precision upper triangle) {:.2} ms; single-precision full rows {:.2} ms",
        1e3 * best[0],
        1e3 * best[1]
    );
}
