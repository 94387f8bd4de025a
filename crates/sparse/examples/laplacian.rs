//! A sparse Cholesky solve with `porofrac-sparse` alone (and faer's matrix views): the
//! five-point Laplacian on `n × n` points, factorised once per grid after one symbolic
//! analysis (AMD ordering), then refactorised with new values on the kept analysis, as a
//! time-stepping code does.
//!
//! The example prints the fill of the factor (non-zeros of `L` over those of the upper
//! triangle of `A`) and the relative residual `‖A x − b‖ / ‖b‖` of each solve.
//!
//! ```sh
//! cargo run --release -p porofrac-sparse --example laplacian
//! ```

use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Par, Side};
use porofrac_sparse::{Cholesky, CholeskyError};

/// The upper triangle of `diagonal · I − (the four neighbours)` in CSC, unknowns row by row.
fn laplacian(n: usize, diagonal: f64) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    let (mut col_ptr, mut rows, mut vals) = (vec![0], Vec::new(), Vec::new());
    for j in 0..n {
        for i in 0..n {
            let c = j * n + i;
            if j > 0 {
                rows.push(c - n);
                vals.push(-1.0);
            }
            if i > 0 {
                rows.push(c - 1);
                vals.push(-1.0);
            }
            rows.push(c);
            vals.push(diagonal);
            col_ptr.push(rows.len());
        }
    }
    (col_ptr, rows, vals)
}

/// `‖A x − b‖ / ‖b‖` with `A` given by its upper triangle.
fn residual(col_ptr: &[usize], rows: &[usize], vals: &[f64], x: &[f64], b: &[f64]) -> f64 {
    let mut r: Vec<f64> = b.iter().map(|v| -v).collect();
    for c in 0..col_ptr.len() - 1 {
        for k in col_ptr[c]..col_ptr[c + 1] {
            let (i, a) = (rows[k], vals[k]);
            r[i] += a * x[c];
            if i != c {
                r[c] += a * x[i];
            }
        }
    }
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    norm(&r) / norm(b)
}

fn main() -> Result<(), CholeskyError> {
    println!(
        "{:>6} {:>10} {:>7} {:>14} {:>14}",
        "n", "unknowns", "fill", "residual", "refactorised"
    );
    for n in [50, 100, 200, 400] {
        let (col_ptr, rows, vals) = laplacian(n, 4.0);
        let pattern = SymbolicSparseColMatRef::new_checked(n * n, n * n, &col_ptr, None, &rows);
        let mut cholesky = Cholesky::analyse(pattern, Side::Upper, None)?;
        let b: Vec<f64> = (0..n * n).map(|k| (0.37 * k as f64).sin()).collect();

        cholesky.factorize(SparseColMatRef::new(pattern, &vals), Par::Seq)?;
        let mut x = b.clone();
        cholesky.solve_in_place(&mut x, Par::Seq)?;
        let first = residual(&col_ptr, &rows, &vals, &x, &b);

        // New values on the same pattern (a shifted operator, as after a time-step change):
        // only the numeric factorisation runs again.
        let shifted: Vec<f64> = laplacian(n, 4.5).2;
        cholesky.factorize(SparseColMatRef::new(pattern, &shifted), Par::Seq)?;
        let mut y = b.clone();
        cholesky.solve_in_place(&mut y, Par::Seq)?;
        let second = residual(&col_ptr, &rows, &shifted, &y, &b);

        println!(
            "{n:>6} {:>10} {:>7.2} {first:>14.2e} {second:>14.2e}",
            n * n,
            cholesky.factor_nnz() as f64 / cholesky.pattern_nnz() as f64
        );
    }
    Ok(())
}
