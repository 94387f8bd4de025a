//! E2 of the standard problems (unit square, n × n squares split into two triangles,
//! E = 1, ν = 0.3 plane strain, manufactured solution, Dirichlet on the whole boundary)
//! solved by CG with the smoothed-aggregation preconditioner; compared with the sparse
//! Cholesky solution (AMD) up to `--cholesky-max` (default 300).
//!
//! `cargo run --release -p porofrac-amg --example e2 -- 300 1000 [--tol 1e-8]`

mod common;

fn main() {
    let args = common::args(&[300, 1000], 300);
    common::header();
    for &n in &args.sizes {
        let sys = common::e2(n);
        common::run("E2", n, &sys, &args);
    }
}
