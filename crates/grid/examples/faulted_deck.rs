//! Write the small synthetic faulted deck bundled with the scenes,
//! `scenes/corner_point/faulted.grdecl`:
//!
//! ```sh
//! cargo run --release -p porofrac-grid --example faulted_deck -- scenes/corner_point/faulted.grdecl
//! ```
//!
//! 10 × 8 × 6 cells of 20 m × 20 m × 5 m on vertical pillars, the layers dipping 3 % in
//! x from 1000 m depth; a fault between columns i = 5 and 6 (1-based) throws the columns
//! east of it down by half a layer; layer 4 pinches out west of the fault (zero
//! thickness); the two cells of column (1, 1) in the deepest layers are inactive. PORO
//! 0.2 (0.1 in layer 3), PERMX = PERMY = 100 mD, PERMZ = 10 mD, NTG 0.9.

use porofrac_grid::io::grdecl::{Deck, MILLIDARCY};

fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "scenes/corner_point/faulted.grdecl".into());
    let (nx, ny, nz) = (10, 8, 6);
    let dz = 5.0;
    let mut deck = Deck::on_vertical_pillars([nx, ny, nz], [20.0, 20.0], |[i, _], x, _, k| {
        let west = i < 5;
        // Boundaries 0..=6; in the west boundary 4 coincides with boundary 3.
        let layers = if west && k >= 4 { k - 1 } else { k } as f64;
        let throw = if west { 0.0 } else { dz / 2.0 };
        1000.0 + 0.03 * x + layers * dz + throw
    });
    let n = nx * ny * nz;
    let cell = |i: usize, j: usize, k: usize| i + nx * (j + ny * k);
    let mut actnum = vec![true; n];
    for k in 4..6 {
        actnum[cell(0, 0, k)] = false;
    }
    deck.actnum = Some(actnum);
    deck.properties.poro = Some(
        (0..n)
            .map(|d| if d / (nx * ny) == 2 { 0.1 } else { 0.2 })
            .collect(),
    );
    deck.properties.perm = [
        Some(vec![100.0 * MILLIDARCY; n]),
        Some(vec![100.0 * MILLIDARCY; n]),
        Some(vec![10.0 * MILLIDARCY; n]),
    ];
    deck.properties.ntg = Some(vec![0.9; n]);
    let mut out = Vec::new();
    out.extend_from_slice(
        b"-- A synthetic faulted block (crates/grid/examples/faulted_deck.rs): 10 x 8 x 6\n\
          -- cells, layers dipping 3 % in x, a fault between i = 5 and 6 with a throw of half\n\
          -- a layer, layer 4 pinched out west of the fault, two inactive cells.\nMETRIC\n",
    );
    deck.write_text(&mut out).expect("write to memory");
    std::fs::write(&path, out).expect("write the deck");
    eprintln!("wrote {path}");
}
