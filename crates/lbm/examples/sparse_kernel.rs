//! Time of the stream–collide kernel on a 900 × 900 lattice that is mostly solid, with
//! every node visited (the mask) and with long solid stretches skipped
//! ([`porofrac_lbm::runs`]), for two geometries:
//!
//! * `hole`: fluid within 60 nodes of the centre and four straight cracks two nodes
//!   wide (the borehole of `scenes/lsm_hydrofrac.toml` before the fluid enters the rock;
//!   1.5 % of the nodes);
//! * `rock` (with a file of disks `x y r` per line, m, e.g. from the particles VTK of a
//!   run of `scenes/lsm_hydrofrac.toml`): the disks, enlarged by 5 % (its sealed bonds),
//!   on the flagship's lattice (origin −22.5 m, spacing 0.05 m).
//!
//! Prints the best of three rounds of 20 steps, per step:
//! `cargo run --release -p porofrac-lbm --example sparse_kernel [-- disks.txt]`.

use porofrac_lbm::kernel::{Grid, Layout, Physics, aa_step, aa_step_runs};
use porofrac_lbm::runs::FluidRuns;
use porofrac_lbm::{Collision, d2q9::W};
use std::time::Instant;

fn main() {
    let text = match std::env::args().nth(1) {
        Some(path) => std::fs::read_to_string(path).expect("a readable file of disks"),
        None => String::new(),
    };
    let (nx, ny) = (900usize, 900usize);
    let g = Grid { nx, ny };
    let w = nx + 2;
    let mut mask = vec![1u8; g.np()];
    for line in text.lines() {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().expect("three numbers per line"))
            .collect();
        let (cx, cy, r) = (
            (v[0] + 22.5) / 0.05,
            (v[1] + 22.5) / 0.05,
            1.05 * v[2] / 0.05,
        );
        for j in 0..ny {
            let dy = j as f64 + 0.5 - cy;
            if dy.abs() > r {
                continue;
            }
            for i in 0..nx {
                let dx = i as f64 + 0.5 - cx;
                if dx * dx + dy * dy <= r * r {
                    mask[(j + 1) * w + i + 1] = 0;
                }
            }
        }
    }
    // the borehole alone: fluid within 60 nodes of the centre, four cracks of 2 nodes
    let mut hole = vec![0u8; g.np()];
    for j in 0..ny {
        for i in 0..nx {
            let (x, y) = (i as f64 + 0.5 - 450.0, j as f64 + 0.5 - 450.0);
            let crack = (y.abs() < 1.0 || x.abs() < 1.0) && x.abs().max(y.abs()) < 200.0;
            if x * x + y * y < 3600.0 || crack {
                hole[(j + 1) * w + i + 1] = 1;
            }
        }
    }
    let mut pop = vec![0.0f64; 9 * g.np()];
    for q in 0..9 {
        pop[q * g.np()..(q + 1) * g.np()].fill(W[q]);
    }
    let phys = Physics {
        rates: Collision::Bgk.rates(0.6).unwrap(),
        accel: [0.0, 0.0],
    };
    let reps = 20;
    let geometries = if text.is_empty() {
        vec![("hole", &hole)]
    } else {
        vec![("rock", &mask), ("hole", &hole)]
    };
    for (name, mask) in geometries {
        for gap in [256usize, 100000] {
            let mut runs = FluidRuns::with_gap(nx, ny, gap);
            for j in 0..ny {
                runs.touch(j);
            }
            runs.refresh(mask);
            let mut best = (f64::MAX, f64::MAX);
            for _ in 0..3 {
                let mut lay = Layout::Natural;
                let t = Instant::now();
                for _ in 0..reps {
                    lay = aa_step(&mut pop, g, lay, Some(mask), phys);
                }
                best.0 = best.0.min(t.elapsed().as_secs_f64() / reps as f64);
                let t = Instant::now();
                for _ in 0..reps {
                    lay = aa_step_runs(&mut pop, g, lay, mask, &runs, phys);
                }
                best.1 = best.1.min(t.elapsed().as_secs_f64() / reps as f64);
                let _ = lay;
            }
            println!(
                "{name} gap {gap}: fluid {} visited {} masked {:.2} ms, segments {:.2} ms",
                runs.fluid_nodes(),
                runs.visited_nodes(),
                best.0 * 1e3,
                best.1 * 1e3
            );
        }
    }
}
