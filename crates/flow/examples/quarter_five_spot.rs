//! Five-spot pattern: the injection rate of a regular five-spot against Muskat's formula.
//!
//! In a regular five-spot (injectors and producers on a checkerboard, unlike wells a
//! distance `d` apart along the axes) the lines halfway between an injector and its four
//! producers are, by antisymmetry, at the mean pressure `(p_inj + p_prod)/2`. So one injector
//! at the centre of a `d × d` square with that pressure on the boundary carries the full
//! well rate of the pattern (four quarter five-spots), which Muskat gives as
//! `q = π k h (p_inj − p_prod) / (μ (ln(d/r_w) − 0.619))`.
//!
//! The example solves the steady problem with a bottom-hole-pressure controlled Peaceman well
//! for a few grid sizes, and then a compressible transient from rest.
//!
//! Run with `cargo run -p porofrac-flow --example quarter_five_spot`.

use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock, Well, WellControl};
use porofrac_grid::Point;
use porofrac_grid::generate::cartesian;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let d: f64 = 200.0; // injector–producer distance (m)
    let k = 1e-13; // ≈ 100 mD
    let (p_inj, p_prod, rw) = (2.0e7, 1.0e7, 0.1);
    let p_mid = 0.5 * (p_inj + p_prod);
    let fluid = Fluid::water();
    let muskat =
        std::f64::consts::PI * k * (p_inj - p_prod) / (fluid.viscosity * ((d / rw).ln() - 0.619));
    println!(
        "five-spot, d = {d} m, k = 1e-13 m², Δp = 10 MPa, r_w = {rw} m (per metre of thickness)"
    );
    println!("Muskat injection rate: {muskat:.5e} m²/s");

    let mut last = None;
    for n in [21usize, 61, 101] {
        let grid = cartesian::<2>(
            Point::<2>::new(-d / 2.0, -d / 2.0),
            Point::<2>::new(d / 2.0, d / 2.0),
            [n, n],
        )?;
        let nc = grid.num_cells();
        let rock = Rock::<2>::new(vec![0.2; nc], Permeability::uniform(nc, k)?);
        let centre = (n / 2) * n + n / 2;
        let problem = FlowProblem::new(rock, fluid)
            .pressure_bc(grid.boundary_faces(), p_mid)
            .well(Well::new("injector", centre, rw, WellControl::Bhp(p_inj)));
        let mut model = FlowModel::new(&grid, &problem)?;
        let steady = model.solve_steady(0.0)?;
        let q = steady.well_rate[0];
        println!(
            "{n:4}×{n:<4} cells: steady rate {q:.5e} m²/s ({:+.3}% vs Muskat)",
            100.0 * (q - muskat) / muskat
        );
        last = Some((grid, model, q));
    }

    // Transient from rest at the mean pressure: the rate decays towards the steady one.
    let (grid, mut model, q_steady) = last.expect("the loop ran");
    let mut p = vec![p_mid; grid.num_cells()];
    let (mut t, mut dt) = (0.0, 1.0);
    for i in 0..18 {
        let r = model.step(&p, dt, t)?;
        t += dt;
        p = r.pressure;
        if i % 3 == 2 {
            println!(
                "t = {t:9.0} s: injection {:.4e} m²/s ({:.3} × steady)",
                r.well_rate[0],
                r.well_rate[0] / q_steady
            );
        }
        dt *= 2.0;
    }
    Ok(())
}
