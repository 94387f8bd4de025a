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

use porofrac_grid::Grid;
use porofrac_grid::io::grdecl::{corner_point_grid, read_deck};

/// Volume enclosed by the faces of cell `c`, each face split into triangles about its
/// vertex average: `V = Σ ((a − o) × (b − o)) · (m − o) / 6` over the outward triangles
/// `(m, a, b)`, about a node `o` of the cell (map coordinates are large: about the origin
/// the sum would cancel).
fn enclosed_volume(grid: &Grid<3>, c: usize) -> f64 {
    let o = *grid.node(grid.cell_nodes(c)[0]);
    let mut v = 0.0;
    for (&f, &out) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
        let nodes = grid.face_nodes(f);
        let m = nodes.iter().map(|&n| grid.node(n) - o).sum::<porofrac_grid::Point<3>>()
            / nodes.len() as f64;
        let mut s = 0.0;
        for k in 0..nodes.len() {
            let a = grid.node(nodes[k]) - o;
            let b = grid.node(nodes[(k + 1) % nodes.len()]) - o;
            s += a.cross(&b).dot(&m);
        }
        v += if out { s } else { -s } / 6.0;
    }
    v
}

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
            let v = enclosed_volume(g, c);
            total += v;
            worst = worst.max((v - g.cell_volume(c)).abs() / g.cell_volume(c).abs().max(1e-300));
        }
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
