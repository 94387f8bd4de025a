//! E3 of the standard problems (unit cube, n³ cubes split into six tetrahedra, E = 1,
//! ν = 0.3, manufactured solution, Dirichlet on the whole boundary) solved by CG with the
//! smoothed-aggregation preconditioner; compared with the sparse Cholesky solution
//! (nested dissection) up to `--cholesky-max` (default 30).
//!
//! `cargo run --release -p porofrac-sim --features fixtures --example amg_e3 -- 10 20 30 40 [--tol 1e-8]`

mod amg_common;

fn main() {
    let args = amg_common::args(&[10, 20, 30, 40], 30);
    amg_common::header();
    for &n in &args.sizes {
        let sys = amg_common::e3(n);
        amg_common::run("E3", n, &sys, &args);
    }
}
