//! Recursive coordinate bisection of the nodes of a 3D box grid into P parts, as the
//! distributed solve cuts a grid over P ranks: the size of every part and the number of
//! grid edges cut (the ghost exchange's volume).
//!
//! `cargo run --release -p porofrac-dist --example partition [N] [P]` (defaults 20, 4).

use porofrac_dist::partition::recursive_bisection;

fn main() {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<usize>());
    let n = args.next().and_then(Result::ok).unwrap_or(20);
    let parts = args.next().and_then(Result::ok).unwrap_or(4).max(1);
    let index = |i: usize, j: usize, k: usize| (k * n + j) * n + i;
    let mut coords = Vec::with_capacity(3 * n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                coords.extend([i as f64, j as f64, k as f64]);
            }
        }
    }
    let part = recursive_bisection(&coords, 3, parts);
    let mut sizes = vec![0usize; parts];
    for &p in &part {
        sizes[p] += 1;
    }
    let mut cut = 0;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let here = part[index(i, j, k)];
                let right = [(i + 1, j, k), (i, j + 1, k), (i, j, k + 1)];
                cut += right
                    .iter()
                    .filter(|&&(a, b, c)| a < n && b < n && c < n)
                    .filter(|&&(a, b, c)| part[index(a, b, c)] != here)
                    .count();
            }
        }
    }
    println!("{n}³ nodes in {parts} parts: sizes {sizes:?}, {cut} grid edges cut");
}
