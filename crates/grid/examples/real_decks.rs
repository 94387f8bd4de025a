//! Read and process corner-point decks given on the command line, check every cell
//! against its triangulated faces, and time reading and processing (median of 5 runs).
//!
//! ```sh
//! cargo run --release -p porofrac-grid --example real_decks -- drogon.grdecl reek.grdecl
//! ```
//!
//! For each deck it prints the size, the active, pinched and inactive cells, the median
//! times of `read_deck` and `corner_point_grid`, and the largest relative difference
//! between a cell's volume and the volume enclosed by its triangulated faces (divergence
//! theorem, each face split into triangles about its vertex average).

use std::time::Instant;

use porofrac_grid::io::grdecl::{corner_point_grid, read_deck};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    for path in std::env::args().skip(1) {
        let (mut t_read, mut t_proc) = (Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..5 {
            let t = Instant::now();
            let deck = match read_deck(&path) {
                Ok(d) => d,
                Err(e) => {
                    println!("{path}: {e}");
                    break;
                }
            };
            t_read.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            match corner_point_grid(&deck) {
                Ok(cp) => {
                    t_proc.push(t.elapsed().as_secs_f64());
                    last = Some((deck, cp));
                }
                Err(e) => {
                    println!("{path}: {e}");
                    break;
                }
            }
        }
        let Some((deck, cp)) = last else { continue };
        let g = &cp.grid;
        let (mut worst, mut total) = (0.0f64, 0.0);
        for c in 0..g.num_cells() {
            let v = g.enclosed_volume(c);
            total += v;
            worst = worst.max((v - g.cell_volume(c)).abs() / g.cell_volume(c).abs().max(1e-300));
        }
        // Connected components of cells through shared faces.
        let mut comp = vec![usize::MAX; g.num_cells()];
        let mut sizes = Vec::new();
        let mut cell_faces: Vec<Vec<usize>> = vec![Vec::new(); g.num_cells()];
        for f in 0..g.num_faces() {
            if let (a, Some(b)) = g.face_cells(f) {
                cell_faces[a].push(b);
                cell_faces[b].push(a);
            }
        }
        for start in 0..g.num_cells() {
            if comp[start] != usize::MAX {
                continue;
            }
            let id = sizes.len();
            let mut stack = vec![start];
            comp[start] = id;
            let mut n = 0;
            while let Some(c) = stack.pop() {
                n += 1;
                for &d in &cell_faces[c] {
                    if comp[d] == usize::MAX {
                        comp[d] = id;
                        stack.push(d);
                    }
                }
            }
            sizes.push(n);
        }
        sizes.sort_unstable_by(|a, b| b.cmp(a));
        // Parts sharing a node with another part.
        let mut node_part = vec![usize::MAX; g.num_nodes()];
        let mut touching = 0;
        for c in 0..g.num_cells() {
            for &n in g.cell_nodes(c) {
                if node_part[n] == usize::MAX {
                    node_part[n] = comp[c];
                } else if node_part[n] != comp[c] {
                    touching += 1;
                }
            }
        }
        println!("{path}: {touching} node contacts between parts joined by no face");
        for (name, faces) in g.face_tags() {
            let mut per_part = std::collections::BTreeMap::new();
            for &f in faces {
                *per_part.entry(comp[g.face_cells(f).0]).or_insert(0usize) += 1;
            }
            println!("{path}: tag {name}: faces per part {per_part:?}");
        }
        println!(
            "{path}: {} connected parts of cells, sizes {:?}",
            sizes.len(),
            &sizes[..sizes.len().min(8)]
        );
        let [nx, ny, nz] = deck.dims;
        println!(
            "{path}: {nx} × {ny} × {nz}, {} cells ({} pinched, {} inactive), {} faces, {} nodes; \
             read {:.3} s, process {:.3} s (median of {}); volume {total:.6e} m³, largest \
             relative volume difference {worst:.2e}",
            g.num_cells(),
            cp.pinched,
            cp.inactive,
            g.num_faces(),
            g.num_nodes(),
            median(t_read),
            median(t_proc.clone()),
            t_proc.len()
        );
    }
}
