//! Plate with a hole (the seed's verification plan §4 E2): the stress concentration factor of the DEM against
//! the Mindlin / Kaloni–Ariman value, for several (N, r/ℓ) and mesh levels, with the wall
//! time of assembly (reconstruction included) and solve.
//!
//! `cargo run --release -p porofrac-cosserat --example plate_hole [levels]`, or
//! `… --example plate_hole mesh <level> <r> <path.vtu>` to write the O-grid mesh of a level
//! (the mesh of `scenes/cosserat_plate_hole.toml`), or
//! `… --example plate_hole run <path.vtu> <r> <r/ℓ> <N>` to solve on a mesh file and print
//! one `RESULT {json}` line (SCF, cells, dofs, nnz, assembly and solve wall time) in the
//! form of the peers `peers/cosserat/dem.py` and `peers/cosserat/fenicsx_p2p1.py`.

use std::time::Instant;

use porofrac_cosserat::reference::hole_scf;
use porofrac_cosserat::{
    BodyLoads, Condition, Cosserat, LinearOptions, LinearSolver, Material, Options, constant, mesh,
    strain_index,
};

/// SCF of the DEM: the largest cell σ22 over the applied traction T = 1.
pub fn scf(level: usize, r: f64, n: f64, length: f64) -> (f64, usize, f64, f64) {
    let grid =
        mesh::plate_with_hole(16.2, r, 16 * level, 10 * level, 0.1 * r / level as f64).unwrap();
    let (s22, cells, t_asm, t_solve, _) = scf_on(grid, n, length, LinearSolver::Lu);
    (s22, cells, t_asm, t_solve)
}

/// SCF on a given quarter-plate grid: `(SCF, cells, assembly s, solve s, nnz)`.
fn scf_on(
    grid: porofrac_grid::Grid<2>,
    n: f64,
    length: f64,
    solver: LinearSolver,
) -> (f64, usize, f64, f64, usize) {
    let (g, nu) = (1e3, 0.3);
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
    let options = LinearOptions {
        solver,
        ..Default::default()
    };
    let (w, stats, used) = model.solve_static_with(0.0, &options).unwrap();
    let t_solve = t1.elapsed().as_secs_f64();
    if solver != LinearSolver::Lu {
        eprintln!(
            "solver {} iterations {} residual {:.2e}",
            used.name(),
            stats.iterations,
            stats.max_residual
        );
    }
    let s22 = (0..cells)
        .map(|c| model.cell_stress(c, &w)[strain_index(2, 1, 1)])
        .fold(f64::MIN, f64::max);
    (s22, cells, t_asm, t_solve, model.pattern().nnz())
}

/// Peak resident memory of this process (bytes, `VmHWM` of /proc/self/status; 0 when
/// unavailable).
fn peak_memory() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
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
    if args.get(1).map(String::as_str) == Some("run") {
        let usage = "plate_hole run <path.vtu> <r> <r/l> <N> [auto|lu|gmres-amg]";
        let grid = porofrac_grid::io::read_vtu::<2>(&args[2]).expect("readable 2D .vtu mesh");
        let num = |i: usize| -> f64 { args.get(i).and_then(|s| s.parse().ok()).expect(usage) };
        let (r, rl, n) = (num(3), num(4), num(5));
        let solver = match args.get(6).map(String::as_str) {
            None | Some("auto") => LinearSolver::Auto,
            Some("lu") => LinearSolver::Lu,
            Some("gmres-amg") => LinearSolver::GmresAmg,
            Some(_) => panic!("{usage}"),
        };
        let (s22, cells, ta, ts, nnz) = scf_on(grid, n, r / rl, solver);
        println!(
            "RESULT {{\"code\": \"porofrac\", \"mesh\": \"{}\", \"cells\": {cells}, \"dofs\": {}, \
             \"nnz\": {nnz}, \"scf\": {s22:.15e}, \"scf_ref\": {:.15e}, \"t_assemble\": {ta:.6}, \
             \"t_solve\": {ts:.6}, \"solver\": \"{}\", \"peak_memory_bytes\": {}}}",
            args[2],
            3 * cells,
            hole_scf(0.3, n, r, r / rl),
            solver.resolve(3 * cells).name(),
            peak_memory()
        );
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
