//! E2 of the standard problems (unit square, n × n squares split into two triangles,
//! E = 1, ν = 0.3 plane strain, manufactured solution, Dirichlet on the whole boundary)
//! solved by CG with the smoothed-aggregation preconditioner; compared with the sparse
//! Cholesky solution (AMD) up to `--cholesky-max` (default 300).
//!
//! `cargo run --release -p porofrac-sim --features fixtures --example amg_e2 -- 300 1000 [--tol 1e-8]`

mod amg_common;

fn main() {
    let args = amg_common::args(&[300, 1000], 300);
    amg_common::header();
    for &n in &args.sizes {
        let sys = amg_common::e2(n);
        amg_common::run("E2", n, &sys, &args);
    }
}
