//! Plate with a hole (Marazzato (2021), arXiv:2101.08712, §3.9.1): the stress concentration
//! factor of the DEM against the Mindlin / Kaloni–Ariman value, for several (N, r/ℓ) and mesh
//! levels, with the wall time of assembly (reconstruction included) and solve.
//!
//! `cargo run --release -p porofrac-cosserat --example plate_hole [levels]`, or
//! `… --example plate_hole mesh <level> <r> <path.vtu>` to write the O-grid mesh of a level
//! (the mesh of `scenes/cosserat_plate_hole.toml`), or
//! `… --example plate_hole run <path.vtu> <r> <r/ℓ> <N> [auto|lu|gmres-amg|gmres-ldlt|ldlt-schur]
//! [single|double] [smallest-weight|first-interpolating]`
//! to solve on a mesh file and print one `RESULT {json}` line (SCF, cells, dofs, nnz,
//! assembly and solve wall time, and the split: reconstruction alone, solver setup,
//! solve, iterations, entries of the factors) in the form of the peers
//! `peers/cosserat/dem.py` and `peers/cosserat/fenicsx_p2p1.py`.

use std::time::Instant;

use porofrac_cosserat::reference::hole_scf;
use porofrac_cosserat::{
    BodyLoads, Condition, Cosserat, FactorPrecision, GmresOptions, LinearOptions, LinearSolver,
    LinearStats, Material, Options, Reconstruction, StencilRule, constant, mesh, strain_index,
};

/// SCF of the DEM: the largest cell σ22 over the applied traction T = 1.
pub fn scf(level: usize, r: f64, n: f64, length: f64) -> (f64, usize, f64, f64) {
    let grid =
        mesh::plate_with_hole(16.2, r, 16 * level, 10 * level, 0.1 * r / level as f64).unwrap();
    let m = scf_on(
        grid,
        n,
        length,
        LinearSolver::Lu,
        FactorPrecision::default(),
        StencilRule::default(),
    );
    (m.scf, m.cells, m.t_asm, m.t_setup + m.t_iter)
}

/// What one solve on a plate grid measured.
struct Measured {
    scf: f64,
    cells: usize,
    nnz: usize,
    /// Reconstruction alone (s), timed on its own before the assembly.
    t_recon: f64,
    /// Assembly including the reconstruction (s).
    t_asm: f64,
    /// Solver setup: factorisation or multigrid hierarchy (s).
    t_setup: f64,
    /// Solve (triangular solves or GMRES iterations) (s).
    t_iter: f64,
    stats: LinearStats,
    used: LinearSolver,
}

/// SCF on a given quarter-plate grid.
fn scf_on(
    grid: porofrac_grid::Grid<2>,
    n: f64,
    length: f64,
    solver: LinearSolver,
    precision: FactorPrecision,
    stencil: StencilRule,
) -> Measured {
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
    let tr = Instant::now();
    drop(Reconstruction::with_rule(&grid, stencil).unwrap());
    let t_recon = tr.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let model = Cosserat::new(
        grid,
        m,
        Options {
            stencil,
            ..Options::default()
        },
        &[left, bottom, top],
        BodyLoads::none(),
    )
    .unwrap();
    let t_asm = t0.elapsed().as_secs_f64();
    let options = LinearOptions {
        solver,
        gmres: GmresOptions {
            factor_precision: precision,
            ..Default::default()
        },
    };
    let t1 = Instant::now();
    let mut lin = model
        .linear(
            model.system_values(),
            model.preconditioner_values(),
            &options,
        )
        .unwrap();
    let t_setup = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let mut w = vec![0.0; model.equations()];
    model.rhs(0.0, &mut w);
    lin.solve(&mut w, None).unwrap();
    let t_iter = t2.elapsed().as_secs_f64();
    let s22 = (0..cells)
        .map(|c| model.cell_stress(c, &w)[strain_index(2, 1, 1)])
        .fold(f64::MIN, f64::max);
    Measured {
        scf: s22,
        cells,
        nnz: model.pattern().nnz(),
        t_recon,
        t_asm,
        t_setup,
        t_iter,
        stats: lin.stats(),
        used: lin.solver(),
    }
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
        let usage = "plate_hole run <path.vtu> <r> <r/l> <N> \
                     [auto|lu|gmres-amg|gmres-ldlt|ldlt-schur] [single|double] \
                     [smallest-weight|first-interpolating]";
        let grid = porofrac_grid::io::read_vtu::<2>(&args[2]).expect("readable 2D .vtu mesh");
        let num = |i: usize| -> f64 { args.get(i).and_then(|s| s.parse().ok()).expect(usage) };
        let (r, rl, n) = (num(3), num(4), num(5));
        let solver = match args.get(6).map(String::as_str) {
            None | Some("auto") => LinearSolver::Auto,
            Some("lu") => LinearSolver::Lu,
            Some("gmres-amg") => LinearSolver::GmresAmg,
            Some("gmres-ldlt") => LinearSolver::GmresLdlt,
            Some("ldlt-schur") => LinearSolver::LdltSchur,
            Some(_) => panic!("{usage}"),
        };
        let precision = match args.get(7).map(String::as_str) {
            None | Some("single") => FactorPrecision::Single,
            Some("double") => FactorPrecision::Double,
            Some(_) => panic!("{usage}"),
        };
        let stencil = match args.get(8).map(String::as_str) {
            None | Some("smallest-boundary-weight") => StencilRule::SmallestBoundaryWeight,
            Some("first-interpolating") => StencilRule::FirstInterpolating,
            Some("smallest-weight") => StencilRule::SmallestWeight,
            Some(_) => panic!("{usage}"),
        };
        let m = scf_on(grid, n, r / rl, solver, precision, stencil);
        println!(
            "RESULT {{\"code\": \"porofrac\", \"mesh\": \"{}\", \"cells\": {}, \"dofs\": {}, \
             \"nnz\": {}, \"scf\": {:.15e}, \"scf_ref\": {:.15e}, \"t_assemble\": {:.6}, \
             \"t_solve\": {:.6}, \"t_reconstruction\": {:.6}, \"t_setup\": {:.6}, \
             \"t_iterations\": {:.6}, \"iterations\": {}, \"residual\": {:.3e}, \
             \"factor_nnz\": {}, \"factor_precision\": \"{}\", \"solver\": \"{}\", \
             \"peak_memory_bytes\": {}}}",
            args[2],
            m.cells,
            3 * m.cells,
            m.nnz,
            m.scf,
            hole_scf(0.3, n, r, r / rl),
            m.t_asm,
            m.t_setup + m.t_iter,
            m.t_recon,
            m.t_setup,
            m.t_iter,
            m.stats.iterations,
            m.stats.max_residual,
            m.stats.factor_entries,
            match m.stats.factor_precision {
                None => "",
                Some(FactorPrecision::Single) => "single",
                Some(FactorPrecision::Double) => "double",
            },
            m.used.name(),
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
