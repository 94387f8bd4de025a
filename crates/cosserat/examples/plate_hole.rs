//! Plate with a hole (the seed's verification plan §4 E2): the stress concentration factor of the DEM against
//! the Mindlin / Kaloni–Ariman value, for several (N, r/ℓ) and mesh levels, with the wall
//! time of assembly (reconstruction included) and solve.
//!
//! `cargo run --release -p porofrac-cosserat --example plate_hole [levels]`, or
//! `… --example plate_hole mesh <level> <r> <path.vtu>` to write the O-grid mesh of a level
//! (the mesh of `scenes/cosserat_plate_hole.toml`).

use std::time::Instant;

use porofrac_cosserat::reference::hole_scf;
use porofrac_cosserat::{
    BodyLoads, Condition, Cosserat, Material, Options, constant, mesh, strain_index,
};

/// SCF of the DEM: the largest cell σ22 over the applied traction T = 1.
pub fn scf(level: usize, r: f64, n: f64, length: f64) -> (f64, usize, f64, f64) {
    let (side, g, nu) = (16.2, 1e3, 0.3);
    let n_theta = 16 * level;
    let grid = mesh::plate_with_hole(side, r, n_theta, 10 * level, 0.1 * r / level as f64).unwrap();
    let a = n * n / (1.0 - n * n);
    let m = Material::with_length(g, nu, a * g, length).unwrap();
    let cells = grid.num_cells();
    let left = Condition::new(grid.boundary("xmin").unwrap())
        .fix(0, constant(0.0))
        .fix(2, constant(0.0));
    let bottom = Condition::new(grid.boundary("ymin").unwrap())
        .fix(1, constant(0.0))
        .fix(2, constant(0.0));
    let top = Condition::new(grid.boundary("ymax").unwrap()).load(1, constant(1.0));
    let t0 = Instant::now();
    let model = Cosserat::new(
        grid,
        m,
        Options::default(),
        &[left, bottom, top],
        BodyLoads::none(),
    )
    .unwrap();
    let t_asm = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let w = model.solve_static(0.0).unwrap();
    let t_solve = t1.elapsed().as_secs_f64();
    let s22 = (0..cells)
        .map(|c| model.cell_stress(c, &w)[strain_index(2, 1, 1)])
        .fold(f64::MIN, f64::max);
    (s22, cells, t_asm, t_solve)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("mesh") {
        let level: usize = args[2].parse().expect("level");
        let r: f64 = args[3].parse().expect("radius");
        let grid =
            mesh::plate_with_hole(16.2, r, 16 * level, 10 * level, 0.1 * r / level as f64).unwrap();
        porofrac_grid::io::write_vtu(&args[4], &grid, &[], &[]).unwrap();
        println!("{} triangles → {}", grid.num_cells(), args[4]);
        return;
    }
    let levels: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(2);
    println!("r_mm  r/l     N     level cells   SCF_dem  SCF_ref  err%   asm_s  solve_s");
    for (r, rl) in [(0.216, 1.063), (0.216, 10.63), (0.864, 3.0)] {
        for n in [0.0, 0.25, 0.5, 0.75, 0.9] {
            let want = hole_scf(0.3, n, r, r / rl);
            for level in 1..=levels {
                let (got, cells, ta, ts) = scf(level, r, n, r / rl);
                println!(
                    "{r:.3} {rl:6.3} {n:5.2} {level:5} {cells:6} {got:8.4} {want:8.4} {:6.2} {ta:7.3} {ts:7.3}",
                    100.0 * (got - want) / want
                );
            }
        }
    }
}
