//! Smoothed-aggregation AMG as the preconditioner of CG with `porofrac-amg` alone: the
//! Poisson problem `−Δu = f` on the unit square, `u = 0` on the boundary, by the five-point
//! finite-difference Laplacian on `n × n` interior points.
//!
//! With the manufactured solution `u = sin(πx) sin(πy)` (`f = 2π² u`), the discrete
//! solution differs from `u` by `O(h²)`; the example prints, per grid, the CG iterations
//! to a relative residual of 1e-10 (a multigrid preconditioner keeps them nearly
//! constant as the grid is refined), the hierarchy's levels, and the largest error
//! against `u` with its observed order.
//!
//! ```sh
//! cargo run --release -p porofrac-amg --example poisson
//! ```

use std::error::Error;
use std::f64::consts::PI;

use porofrac_amg::{Amg, AmgOptions, SymCsr};

/// The upper triangle of the five-point Laplacian (times `h²`) in CSC, unknowns row by row.
fn laplacian(n: usize) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    let (mut col_ptr, mut rows, mut vals) = (vec![0], Vec::new(), Vec::new());
    for j in 0..n {
        for i in 0..n {
            let c = j * n + i;
            // Rows above the diagonal of column c, in increasing order.
            if j > 0 {
                rows.push(c - n);
                vals.push(-1.0);
            }
            if i > 0 {
                rows.push(c - 1);
                vals.push(-1.0);
            }
            rows.push(c);
            vals.push(4.0);
            col_ptr.push(rows.len());
        }
    }
    (col_ptr, rows, vals)
}

fn main() -> Result<(), Box<dyn Error>> {
    println!(
        "{:>6} {:>10} {:>7} {:>11} {:>12} {:>6}",
        "n", "unknowns", "levels", "iterations", "max error", "order"
    );
    let mut previous: Option<(f64, f64)> = None;
    for n in [63, 127, 255, 511] {
        let h = 1.0 / (n + 1) as f64;
        let (col_ptr, rows, vals) = laplacian(n);
        let a = SymCsr::from_upper_csc(n * n, &col_ptr, &rows, &vals)?;
        let mut amg = Amg::scalar(a, &AmgOptions::default())?;
        let exact =
            |i: usize, j: usize| ((i + 1) as f64 * h * PI).sin() * ((j + 1) as f64 * h * PI).sin();
        let b: Vec<f64> = (0..n * n)
            .map(|c| h * h * 2.0 * PI * PI * exact(c % n, c / n))
            .collect();
        let mut x = vec![0.0; n * n];
        let stats = amg.solve(&mut x, &b, 1e-10, 200)?;
        let error = (0..n * n)
            .map(|c| (x[c] - exact(c % n, c / n)).abs())
            .fold(0.0_f64, f64::max);
        let order = previous.map_or(String::from("-"), |(e0, h0)| {
            format!("{:.2}", (e0 / error).ln() / (h0 / h).ln())
        });
        println!(
            "{n:>6} {:>10} {:>7} {:>11} {error:>12.3e} {order:>6}",
            n * n,
            amg.level_info().len(),
            stats.iterations
        );
        previous = Some((error, h));
    }
    Ok(())
}
