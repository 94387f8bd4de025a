//! The patch test of the virtual element law with `porofrac-vem` alone, cell by cell on a
//! Voronoi grid (polygons of 3 to 10+ sides).
//!
//! A first-order VEM is exact for linear displacement fields `u(x) = A x + b`: on every
//! cell its stress is `σ = C : sym(A)` and its energy `|K| · ½ sym(A) : C : sym(A)`, the
//! stabilization never acts (the field is in the projection's range), and a rigid motion
//! (`A` skew) gives no force at all. The example evaluates the law on every cell for one
//! general linear field and one rigid rotation and prints the largest relative
//! deviations (round-off, ~1e-15).
//!
//! ```sh
//! cargo run --release -p porofrac-vem --example patch_test
//! ```

use std::error::Error;

use porofrac_grid::{Point, generate};
use porofrac_law::{CellLaw, GeometryBuffer, Scratch, Stiffness, Tensor};
use porofrac_vem::VemLaw;

fn main() -> Result<(), Box<dyn Error>> {
    let grid = generate::voronoi(
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(1.0, 1.0),
        400,
        3,
        2,
    )?;
    let material = Stiffness::<2>::isotropic(1.0e10, 0.3)?;
    let law = VemLaw::new(material.clone());

    // A general linear field (stretch, shear and rotation) and a rigid rotation.
    let a = Tensor::<2>::new(2.0e-4, -1.0e-4, 3.0e-4, -0.5e-4);
    let rotation = Tensor::<2>::new(0.0, -1.0e-3, 1.0e-3, 0.0);
    let strain = 0.5 * (a + a.transpose());
    let stress = material.stress(&strain);
    let energy_density = material.energy_density(&strain);

    let mut geometry = GeometryBuffer::default();
    let mut scratch = Scratch::default();
    let (mut u, mut f) = (Vec::new(), Vec::new());
    let (mut stress_error, mut energy_error, mut rigid_force): (f64, f64, f64) = (0.0, 0.0, 0.0);
    let mut sides = [usize::MAX, 0];
    for c in 0..grid.num_cells() {
        let cell = geometry.load(&grid, c);
        let n = cell.coords.len();
        sides = [sides[0].min(n), sides[1].max(n)];
        let field = |m: &Tensor<2>, u: &mut Vec<f64>| {
            u.clear();
            for x in cell.coords {
                u.extend((m * x).iter());
            }
        };
        field(&a, &mut u);
        let s = law.stress(&cell, &u, &mut scratch)?;
        stress_error = stress_error.max((s - stress).amax() / stress.amax());
        let e = law.energy(&cell, &u, &mut scratch)?;
        let exact = cell.volume * energy_density;
        energy_error = energy_error.max((e - exact).abs() / exact);
        field(&rotation, &mut u);
        f.resize(u.len(), 0.0);
        law.forces(&cell, &u, &mut f, &mut scratch)?;
        let scale = material.max_eigenvalue() * 1.0e-3 * cell.volume.sqrt();
        rigid_force = rigid_force.max(f.iter().fold(0.0_f64, |m, v| m.max(v.abs())) / scale);
    }
    println!(
        "{} cells with {} to {} nodes",
        grid.num_cells(),
        sides[0],
        sides[1]
    );
    println!(
        "linear field: largest stress error {stress_error:.1e}, energy error {energy_error:.1e} (relative)"
    );
    println!("rigid rotation: largest nodal force {rigid_force:.1e} (relative to E·θ·h)");
    Ok(())
}
