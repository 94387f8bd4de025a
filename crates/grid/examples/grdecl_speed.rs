//! Read and process a synthetic faulted corner-point deck of `n × n × n` cells: the
//! figures of docs/BENCHMARKS.md "Corner-point decks".
//!
//! ```sh
//! cargo run --release -p porofrac-grid --example grdecl_speed -- 100 /tmp/deck.grdecl
//! ```
//!
//! Writes the deck (layers dipping 2 % in x, a fault across x = L/2 with a throw of half a
//! layer, every tenth layer pinched out), then times `read_deck` and
//! `corner_point_grid`, and prints the peak resident memory.

use std::time::Instant;

use porofrac_grid::io::grdecl::{Deck, corner_point_grid, read_deck};

fn peak_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(100);
    let path = args
        .get(2)
        .cloned()
        .unwrap_or_else(|| format!("/tmp/porofrac-deck-{n}.grdecl"));
    let (dx, dz) = (10.0, 2.0);
    // Boundary k at depth (k − ⌊k/10⌋) dz: layers 9, 19, … have zero thickness.
    let deck = Deck::on_vertical_pillars([n, n, n], [dx, dx], |[i, _], x, _, k| {
        let throw = if i >= n / 2 { dz / 2.0 } else { 0.0 };
        1000.0 + (k - k / 10) as f64 * dz + 0.02 * x + throw
    });
    let t = Instant::now();
    let mut out = std::io::BufWriter::new(std::fs::File::create(&path).expect("create the deck"));
    deck.write_text(&mut out).expect("write the deck");
    drop(out);
    drop(deck);
    let size = std::fs::metadata(&path).map_or(0, |m| m.len());
    eprintln!(
        "wrote {path} ({:.1} MB) in {:.2} s",
        size as f64 / 1e6,
        t.elapsed().as_secs_f64()
    );
    let base = peak_mib();
    let t = Instant::now();
    let deck = read_deck(&path).expect("read the deck");
    let t_read = t.elapsed().as_secs_f64();
    let after_read = peak_mib();
    let t = Instant::now();
    let cp = corner_point_grid(&deck).expect("process the deck");
    let t_process = t.elapsed().as_secs_f64();
    println!(
        "| {n}³ = {} | {} | {} | {} | {} | {:.2} | {:.2} | {:.0} | {:.0} |",
        n * n * n,
        cp.grid.num_cells(),
        cp.pinched,
        cp.grid.num_faces(),
        cp.grid.num_nodes(),
        t_read,
        t_process,
        after_read - base,
        peak_mib()
    );
}
