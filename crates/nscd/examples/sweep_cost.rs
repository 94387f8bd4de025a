//! CPU cost per contact update of the NLGS orderings on a sample of the full-size
//! fault experiment's packing (150 m × 15 m, radii 0.13–0.26 m, about 14 500 disks on
//! a floor between two walls, settled for a few steps under gravity).
//!
//! ```text
//! cargo run --release -p porofrac-nscd --example sweep_cost -- [ROUNDS] [STEPS] [ORDERING...]
//! ```
//!
//! Every round runs `STEPS` steps of 0.01 s with exactly 100 sweeps each (min = max =
//! 100) from the same settled state for each ordering in turn (`sorted`, `slabs`,
//! `coloured`; default `sorted slabs`), and prints the process's CPU time (user + system,
//! all threads, from `/proc/self/stat`) and wall time per million contact updates.

use std::time::Instant;

use porofrac_nscd::{ContactLaw, Nscd, Ordering, RigidBody, SolverParams};
use porofrac_particles::{Disks, RandomPacking};

/// CPU seconds of the process (user + system, all threads), from `/proc/self/stat`.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    // Fields 14 and 15 of the file (utime, stime), in clock ticks of 1/100 s.
    let ticks = |k: usize| f.get(k).and_then(|s| s.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let rounds: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(5);
    let steps: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(20);
    let mut orderings: Vec<(String, Ordering)> = args
        .iter()
        .skip(2)
        .map(|s| {
            let o = match s.as_str() {
                "sorted" => Ordering::Sorted,
                "slabs" => Ordering::Slabs,
                "coloured" => Ordering::Coloured,
                other => panic!("unknown ordering {other}"),
            };
            (s.clone(), o)
        })
        .collect();
    if orderings.is_empty() {
        orderings = vec![
            ("sorted".into(), Ordering::Sorted),
            ("slabs".into(), Ordering::Slabs),
        ];
    }
    let (w, h) = (150.0, 15.0);
    let p = RandomPacking::new([0.0, 0.0], [w, h], 0.13, 0.26, 0.8, 1)
        .generate()
        .expect("packing");
    let d = Disks::new(&p.centres, &p.radii, 2800.0).expect("disks");
    let walls = vec![
        RigidBody::segment([-1.0, 0.0], [w + 1.0, 0.0]),
        RigidBody::segment([0.0, 2.0 * h], [0.0, 0.0]),
        RigidBody::segment([w, 0.0], [w, 2.0 * h]),
    ];
    let law = ContactLaw::frictional(0.4);
    let mut settled =
        Nscd::new(d, walls, law, SolverParams::default(), [0.0, -9.81]).expect("system");
    for _ in 0..30 {
        settled.step(0.01).expect("settling step");
    }
    println!(
        "{} disks, {} contacts, {} threads",
        settled.disks.len(),
        settled.contacts().len(),
        rayon::current_num_threads()
    );
    for round in 1..=rounds {
        for (name, ordering) in &orderings {
            let mut s = settled.clone();
            s.params = SolverParams {
                min_sweeps: 100,
                max_sweeps: 100,
                ordering: *ordering,
                ..SolverParams::default()
            };
            let (c0, t0) = (cpu_seconds(), Instant::now());
            let mut updates = 0u64;
            for _ in 0..steps {
                updates += s.step(0.01).expect("step").updates;
            }
            let (cpu, wall) = (cpu_seconds() - c0, t0.elapsed().as_secs_f64());
            let m = updates as f64 / 1e6;
            // A hash of the final state's bits: the same in every run of an ordering.
            let mut hash = 0xcbf2_9ce4_8422_2325u64;
            let bits = s
                .disks
                .x
                .iter()
                .chain(&s.disks.v)
                .flatten()
                .chain(&s.disks.omega);
            for b in bits {
                hash = (hash ^ b.to_bits()).wrapping_mul(0x100_0000_01b3);
            }
            println!(
                "round {round} {name:>8}: {m:.1} M updates, CPU {:.4} s/M, wall {:.4} s/M, state {hash:016x}",
                cpu / m,
                wall / m
            );
        }
    }
}
