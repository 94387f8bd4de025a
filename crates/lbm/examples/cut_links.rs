//! CPU time of a lattice step on the rock of `scenes/lsm_hydrofrac.toml`: a 900 × 900
//! lattice (walls, spacing 0.05 m, origin −22.5 m) with a file of disks `x y r` per line
//! (m, e.g. from the particles VTK of a run of that scene), enlarged by 5 % (its sealed
//! bonds), as obstacles: about 110 k cut links. The stream–collide kernel is the same
//! whatever the obstacle rules do, so the difference between two builds is theirs.
//!
//! Two cases: the disks at rest (the cut links are never rebuilt) and every disk moving
//! at 0.003 spacings per step (nodes covered and uncovered, links rebuilt, most steps).
//! Prints, per step, the CPU time summed over the process's threads (Linux
//! `/proc/self/task/*/schedstat`, insensitive to the load of other processes) and the
//! wall time: `cargo run --release -p porofrac-lbm --example cut_links -- disks.txt [steps]`.
//! `RAYON_NUM_THREADS=1` gives the work of one core. Each case runs three rounds
//! alternating the obstacle rules inside the stream–collide sweep and after it
//! (`Lattice::set_rules_in_sweep`). Also prints how many of the
//! population array's cache lines (64 bytes, natural layout) the obstacle rules load or
//! store (links spread over every pore touch lines all over the array). And the CPU time of finding the fluid nodes
//! enclosed alone by disks (`Lattice::enclosed_fluid_nodes`) against a scan node by node.

use porofrac_lbm::d2q9::{C, OPP};
use porofrac_lbm::{Lattice, LatticeConfig, Obstacle, Shape};
use std::collections::HashSet;
use std::time::Instant;

/// Cache lines (8 `f64`, natural layout, padded grid) of the populations the obstacle
/// rules read (`L(x_b, α)`, `L(x_f, α)`, `L(x_f2, ᾱ)`) or write (`L(x_f, ᾱ)`), and all
/// lines of the array.
fn lines_touched(lat: &Lattice) -> (usize, usize) {
    let (nx, ny) = lat.size();
    let (w, np) = (nx + 2, (nx + 2) * (ny + 2));
    let at = |i: isize, j: isize, q: usize| (q * np + (j + 1) as usize * w + (i + 1) as usize) / 8;
    let mut lines = HashSet::new();
    for k in 0..lat.obstacles().len() {
        for (i, j, a, _) in lat.cut_links_of(k) {
            let (i, j) = (i as isize, j as isize);
            let (cx, cy) = (C[a][0] as isize, C[a][1] as isize);
            lines.insert(at(i + cx, j + cy, a));
            lines.insert(at(i, j, a));
            lines.insert(at(i, j, OPP[a]));
            let (fi, fj) = (i - cx, j - cy);
            if fi >= 0
                && fj >= 0
                && (fi as usize) < nx
                && (fj as usize) < ny
                && !lat.is_solid(fi as usize, fj as usize)
            {
                lines.insert(at(fi, fj, OPP[a]));
            }
        }
    }
    (lines.len(), (9 * np).div_ceil(8))
}

/// CPU time of every thread of this process so far (s).
fn cpu_seconds() -> f64 {
    let mut ns = 0u64;
    if let Ok(dir) = std::fs::read_dir("/proc/self/task") {
        for t in dir.flatten() {
            if let Ok(s) = std::fs::read_to_string(t.path().join("schedstat")) {
                ns += s
                    .split_whitespace()
                    .next()
                    .and_then(|x| x.parse::<u64>().ok())
                    .unwrap_or(0);
            }
        }
    }
    ns as f64 * 1e-9
}

/// CPU time of finding the one-node pores (a coupled run does it every step), from the
/// mask (`Lattice::enclosed_fluid_nodes`) and node by node through `Lattice::is_solid`;
/// five rounds alternating.
fn one_node_pores(lat: &Lattice) {
    let (nx, ny) = lat.size();
    let by_node = || {
        let mut out = Vec::new();
        for j in 1..ny - 1 {
            for i in 1..nx - 1 {
                if !lat.is_solid(i, j)
                    && (j - 1..=j + 1)
                        .all(|b| (i - 1..=i + 1).all(|a| (a, b) == (i, j) || lat.is_solid(a, b)))
                {
                    out.push((i, j));
                }
            }
        }
        out
    };
    let reps = 50;
    for _ in 0..5 {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let c0 = cpu_seconds();
        for _ in 0..reps {
            a = std::hint::black_box(lat.enclosed_fluid_nodes());
        }
        let c1 = cpu_seconds();
        for _ in 0..reps {
            b = std::hint::black_box(by_node());
        }
        let c2 = cpu_seconds();
        assert_eq!(a, b, "the two scans disagree");
        println!(
            "one-node pores: {}, found from the mask in {:.3} ms, node by node in {:.3} ms (CPU)",
            a.len(),
            1e3 * (c1 - c0) / reps as f64,
            1e3 * (c2 - c1) / reps as f64
        );
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .expect("usage: cut_links DISKS.txt [steps] (a file of x y r per line, m)");
    let steps: usize = args
        .next()
        .map(|s| s.parse().expect("steps: a whole number"))
        .unwrap_or(20);
    let text = std::fs::read_to_string(&path).expect("a readable file of disks");
    let disks: Vec<[f64; 3]> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|x| x.parse().expect("three numbers per line"))
                .collect();
            [
                (v[0] + 22.5) / 0.05,
                (v[1] + 22.5) / 0.05,
                1.05 * v[2] / 0.05,
            ]
        })
        .collect();
    for moving in [false, true] {
        let mut cfg = LatticeConfig::periodic(900, 900, 0.6);
        cfg.periodic = [false, false];
        let mut lat = Lattice::new(cfg).expect("lattice");
        lat.init(|p| {
            let (x, y) = (p[0] / 900.0, p[1] / 900.0);
            (1.0 + 1e-3 * (7.0 * x).sin(), [1e-3 * (5.0 * y).cos(), 0.0])
        });
        for (k, d) in disks.iter().enumerate() {
            let v = if moving {
                let a = 0.7 * k as f64;
                [0.003 * a.cos(), 0.003 * a.sin()]
            } else {
                [0.0, 0.0]
            };
            lat.add_obstacle(Obstacle {
                shape: Shape::Circle {
                    center: [d[0], d[1]],
                    radius: d[2],
                },
                velocity: v,
                angular_velocity: 0.0,
            })
            .expect("a disk inside the lattice");
        }
        if !moving {
            let (touched, all) = lines_touched(&lat);
            println!(
                "the rules touch {touched} of {all} cache lines ({:.0} %)",
                100.0 * touched as f64 / all as f64
            );
            one_node_pores(&lat);
        }
        for _ in 0..3 {
            lat.step().expect("step");
        }
        // three rounds alternating the rules inside the sweep and after it
        for _ in 0..3 {
            for in_sweep in [true, false] {
                lat.set_rules_in_sweep(in_sweep);
                let (c0, t0) = (cpu_seconds(), Instant::now());
                let mut bodies = 0;
                for _ in 0..steps {
                    lat.step().expect("step");
                    bodies += lat.obstacles_in_sweep();
                }
                let (cpu, wall) = (cpu_seconds() - c0, t0.elapsed().as_secs_f64());
                println!(
                    "{}, rules {}: {} cut links, {} fluid nodes, {:.0} of {} bodies in the \
                     sweep, per step: CPU {:.2} ms, wall {:.2} ms",
                    if moving { "moving" } else { "at rest" },
                    if in_sweep { "in the sweep" } else { "after it" },
                    lat.cut_links(),
                    lat.fluid_nodes(),
                    bodies as f64 / steps as f64,
                    disks.len(),
                    1e3 * cpu / steps as f64,
                    1e3 * wall / steps as f64
                );
            }
        }
    }
}
