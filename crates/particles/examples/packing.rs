//! A dense random packing of polydisperse disks with `porofrac-particles` alone, and its
//! neighbour pairs found by cell lists.
//!
//! The packing (seeded, so reproducible) fills a 20 m × 10 m box to a disk-area fraction
//! of 0.8 with radii between 0.13 and 0.26 m; the example prints the fraction reached, the
//! largest overlap, the mean coordination number, and checks that the cell-list search
//! finds exactly the pairs a brute-force search over all `n(n−1)/2` pairs finds.
//!
//! ```sh
//! cargo run --release -p porofrac-particles --example packing
//! ```

use porofrac_particles::cells::{CellList, brute_force_pairs, max_radius};
use porofrac_particles::{ParticleError, RandomPacking};

fn main() -> Result<(), ParticleError> {
    let (lo, hi) = ([0.0, 0.0], [20.0, 10.0]);
    let spec = RandomPacking::new(lo, hi, 0.13, 0.26, 0.8, 7);
    let packing = spec.generate()?;
    let (overlap, pair) = packing.max_overlap();
    println!("{} disks", packing.len());
    println!("packing fraction  {:.4}", packing.packing_fraction(lo, hi));
    println!("largest overlap   {overlap:.3e} m (pair {pair:?})");
    println!(
        "coordination      {:.2} (gaps below 1 % of r_min)",
        packing.coordination(0.01 * spec.r_min)
    );

    // Pairs closer than an alert distance, by cell lists and by brute force.
    let alert = 0.05;
    let mut cells = CellList::new();
    cells.build(&packing.centres, 2.0 * max_radius(&packing.radii) + alert);
    let mut pairs = Vec::new();
    cells.pairs(&packing.centres, &packing.radii, alert, &mut pairs);
    let brute = brute_force_pairs(&packing.centres, &packing.radii, alert);
    println!(
        "pairs within {alert} m: {} by cell lists, {} by brute force ({})",
        pairs.len(),
        brute.len(),
        if pairs == brute {
            "the same"
        } else {
            "DIFFERENT"
        }
    );
    Ok(())
}
