//! Speed against error on the standard problems E2 (2D plane strain) and E3 (3D) of
//! `BENCHMARKS.md`: for each method and a ladder of grid sizes, the wall time of assembly
//! and solve and the L2 error against the exact solution; written to a CSV and drawn as
//! log–log plots (x = time, y = L2 error), with the FEniCSx peer points beside them.
//!
//! ```text
//! cargo run --release --example speed_error -- [--quick] [--problem e2|e3|all]
//!     [--peers docs/data/fenicsx_e2e3.csv] [--csv docs/data/speed_error.csv]
//!     [--out-dir docs] [--explicit-tol 1e-8] [--plot-only]
//! ```
//!
//! # What is measured
//!
//! * Grid construction is excluded (like FEniCSx's `t_mesh`).
//! * **Assembly** = dof map + sparsity pattern + law map + stiffness + load vector (for
//!   the explicit solver: dof map + pattern + law map, it assembles no matrix).
//! * **Solve** = solver construction, setup (symbolic + numeric factorization, or the
//!   multigrid hierarchy) and the solve itself, through [`porofrac::sim::StaticSolver`]:
//!   sparse Cholesky (AMD in 2D, geometric nested dissection in 3D; the default direct
//!   solver) or CG preconditioned by smoothed-aggregation AMG to the relative residual
//!   1e-8 ([`porofrac::sim::AmgSolver`]). For the explicit solver: damped dynamics with
//!   density scaling ([`porofrac::sim::solve_explicit`]) until the unbalanced-force
//!   ratio is below `--explicit-tol` (default 1e-8, the same number as CG's relative
//!   residual, though not the same quantity).
//! * The time plotted is assembly + solve. Like the peer script (`common.best_of`), a
//!   point is repeated (up to 3 passes) while one pass is cheap (below 20 s, and all
//!   passes below 60 s), and each of the two times is the minimum over the passes. The
//!   process keeps freed memory, as the `porofrac` command does (`retain_freed_memory`
//!   below, the policy of `crates/cli/src/heap.rs`).
//! * **L2 error** `‖u − u_h‖_L2`: the piecewise-linear reconstruction of the nodal field on
//!   the face-facet / vertex-average sub-simplices of each cell (on simplices the P1 field
//!   itself), degree-5 quadrature (`tests/common`, shared with `tests/convergence.rs`).
//!   It is not timed.
//!
//! # Methods
//!
//! E2: VEM on triangles (= P1) with Cholesky and with CG-AMG; MDEM on triangles (on
//! simplices exactly linear elasticity, so its error equals P1's) with Cholesky; VEM on
//! squares and on Voronoi cells (3 Lloyd iterations, seed 7) with Cholesky; the explicit
//! solver (VEM law) on triangles. E3: the same on tetrahedra and cubes (no Voronoi), plus
//! CG-AMG on cubes. Material E = 1, ν = 0.3 (plane strain in 2D), `u = u_exact` on the
//! whole boundary, body force from the manufactured solution.
//!
//! # Peers
//!
//! FEniCSx points are read from `--peers` (`dim,n,solver,t_assemble,t_solve,l2_err,ndofs`;
//! lines starting with `#` are comments), written by `docs/data/fenicsx_e2e3.sh`, which
//! runs the FEniCSx driver `run_dolfinx.py` (kept outside this repository). They are
//! copied into the output CSV and plotted with time = `t_assemble + t_solve`.
//!
//! # Output
//!
//! `--csv` (all points, one line each) and `<out-dir>/speed_error_e2.png`,
//! `<out-dir>/speed_error_e3.png`. `--plot-only` redraws the plots from an existing CSV
//! without measuring. `--quick` runs a tiny ladder (a smoke test, seconds) and by
//! default writes to `target/speed_error_quick/` instead of `docs/`.

#[path = "../tests/common/mod.rs"]
mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use common::{Manufactured, dirichlet, e2, e3, errors};
use plotters::prelude::*;
use porofrac::grid::generate::{DEFAULT_LLOYD, cartesian, simplices, voronoi};
use porofrac::grid::{Grid, Point};
use porofrac::law::{CellLaw, Stiffness};
use porofrac::mdem::MdemLaw;
use porofrac::sim::{
    DofMap, ExplicitOptions, LawMap, LinearSolve, LinearSolver, Loads, Pattern, StaticProblem,
    StaticSolver, assemble, nodal_loads, solve_explicit,
};
use porofrac::vem::VemLaw;

type BoxError = Box<dyn std::error::Error>;

/// The grid family of a ladder.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mesh {
    /// n^D boxes split in simplices (the standard grids).
    Simplices,
    /// n^D squares / cubes.
    Boxes,
    /// n Voronoi cells (2D).
    Voronoi,
}

/// The cell law.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Law {
    Vem,
    Mdem,
}

/// How the static problem is solved.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Solve {
    Cholesky,
    CgAmg,
    Explicit,
}

/// One ladder: a method and its sizes.
struct Ladder {
    mesh: Mesh,
    law: Law,
    solve: Solve,
    sizes: &'static [usize],
}

impl Ladder {
    fn label(&self, dim: usize) -> String {
        let law = match self.law {
            Law::Vem => "VEM",
            Law::Mdem => "MDEM",
        };
        let mesh = match (self.mesh, dim) {
            (Mesh::Simplices, 2) => "triangles",
            (Mesh::Simplices, _) => "tetrahedra",
            (Mesh::Boxes, 2) => "squares",
            (Mesh::Boxes, _) => "cubes",
            (Mesh::Voronoi, _) => "Voronoi",
        };
        match self.solve {
            Solve::Cholesky => format!("{law} {mesh}, Cholesky"),
            Solve::CgAmg => format!("{law} {mesh}, CG-AMG"),
            Solve::Explicit => format!("{law} {mesh}, explicit"),
        }
    }
}

/// One measured (or peer) point.
#[derive(Clone, Debug)]
struct Row {
    problem: String,
    method: String,
    n: usize,
    cells: usize,
    ndofs: usize,
    equations: usize,
    t_assemble: f64,
    t_solve: f64,
    iterations: usize,
    l2: f64,
    reps: usize,
}

const CSV_HEADER: &str =
    "problem,method,n,cells,ndofs,equations,t_assemble,t_solve,t_total,iterations,l2_err,reps";

impl Row {
    fn total(&self) -> f64 {
        self.t_assemble + self.t_solve
    }
    fn csv(&self) -> String {
        format!(
            "{},\"{}\",{},{},{},{},{:.6},{:.6},{:.6},{},{:.6e},{}",
            self.problem,
            self.method,
            self.n,
            self.cells,
            self.ndofs,
            self.equations,
            self.t_assemble,
            self.t_solve,
            self.total(),
            self.iterations,
            self.l2,
            self.reps
        )
    }
    fn parse(line: &str) -> Result<Self, BoxError> {
        // The method (second field) is quoted: it contains commas.
        let (head, rest) = line
            .split_once(",\"")
            .ok_or_else(|| format!("CSV line without a quoted method: {line}"))?;
        let (method, tail) = rest
            .split_once("\",")
            .ok_or_else(|| format!("CSV line with an unterminated method: {line}"))?;
        let mut f: Vec<&str> = vec![head.trim(), method];
        f.extend(tail.split(',').map(str::trim));
        if f.len() != 12 {
            return Err(format!("CSV line with {} fields, want 12: {line}", f.len()).into());
        }
        Ok(Self {
            problem: f[0].into(),
            method: f[1].into(),
            n: f[2].parse()?,
            cells: f[3].parse()?,
            ndofs: f[4].parse()?,
            equations: f[5].parse()?,
            t_assemble: f[6].parse()?,
            t_solve: f[7].parse()?,
            iterations: f[9].parse()?,
            l2: f[10].parse()?,
            reps: f[11].parse()?,
        })
    }
}

/// Assembly and solve times, iterations (CG or explicit steps) and the nodal field of
/// one pass.
struct Pass {
    t_assemble: f64,
    t_solve: f64,
    iterations: usize,
    u: Vec<f64>,
    equations: usize,
}

fn one_pass<const D: usize>(
    grid: &Grid<D>,
    law: &dyn CellLaw<D>,
    solve: Solve,
    m: &Manufactured<D>,
    explicit_tol: f64,
) -> Result<Pass, BoxError> {
    let bc = dirichlet("boundary", grid.boundary_faces(), &m.u);
    let loads = Loads {
        body_force: Some(m.body_force()),
        ..Loads::default()
    };
    let t0 = Instant::now();
    let dofs = DofMap::new(grid, &[bc], &[])?;
    let pattern = Pattern::new(grid, &dofs)?;
    let laws = LawMap::uniform(grid, law)?;
    if solve == Solve::Explicit {
        let t_assemble = t0.elapsed().as_secs_f64();
        let problem = StaticProblem {
            grid,
            laws: &laws,
            dofs: &dofs,
            pattern: &pattern,
            loads: &loads,
        };
        let options = ExplicitOptions {
            tolerance: explicit_tol,
            max_steps: 5_000_000,
            density_scaling: Some(1.0),
            ..ExplicitOptions::default()
        };
        let density = vec![1.0; grid.num_cells()];
        let t1 = Instant::now();
        let sol = solve_explicit(&problem, &density, 0.0, &options, None)?;
        return Ok(Pass {
            t_assemble,
            t_solve: t1.elapsed().as_secs_f64(),
            iterations: sol.steps,
            u: sol.displacement,
            equations: dofs.num_equations(),
        });
    }
    let mut u = vec![0.0; dofs.num_dofs()];
    dofs.set_prescribed(grid, 0.0, &mut u);
    let mut values = vec![0.0; pattern.nnz()];
    let mut rhs = vec![0.0; dofs.num_equations()];
    assemble(grid, &laws, &dofs, &pattern, &u, &mut values, &mut rhs)?;
    let mut full = vec![0.0; dofs.num_dofs()];
    nodal_loads(grid, &loads, 0.0, &mut full)?;
    dofs.reduce_add(&full, &mut rhs);
    let t_assemble = t0.elapsed().as_secs_f64();

    let t1 = Instant::now();
    let choice = match solve {
        Solve::Cholesky => LinearSolver::Cholesky,
        _ => LinearSolver::CgAmg { tolerance: 1e-8 },
    };
    let mut solver = StaticSolver::new(grid, &dofs, &pattern, choice)?;
    let mut x = vec![0.0; dofs.num_equations()];
    let stats = solver.solve_system(&pattern, &values, &rhs, &mut x)?;
    let t_solve = t1.elapsed().as_secs_f64();
    dofs.scatter_add(&x, &mut u);
    Ok(Pass {
        t_assemble,
        t_solve,
        iterations: stats.iterations,
        u,
        equations: dofs.num_equations(),
    })
}

/// Measure one point: repeat while cheap (as `common.best_of` of the peer scripts), keep
/// the minimum of each time, compute the L2 error of the last pass.
fn measure<const D: usize>(
    grid: &Grid<D>,
    law: &dyn CellLaw<D>,
    solve: Solve,
    m: &Manufactured<D>,
    explicit_tol: f64,
) -> Result<(Pass, usize, f64), BoxError> {
    const MAX_REPS: usize = 3;
    const CHEAP_S: f64 = 20.0;
    let mut best = one_pass(grid, law, solve, m, explicit_tol)?;
    let tot = best.t_assemble + best.t_solve;
    let mut reps = 1;
    while reps < MAX_REPS && tot * ((MAX_REPS - reps) as f64) < CHEAP_S * 3.0 && tot < CHEAP_S {
        let p = one_pass(grid, law, solve, m, explicit_tol)?;
        reps += 1;
        best.t_assemble = best.t_assemble.min(p.t_assemble);
        best.t_solve = best.t_solve.min(p.t_solve);
        best.u = p.u;
    }
    let mat = Stiffness::<D>::isotropic(1.0, 0.3)?;
    let l2 = errors(grid, &best.u, &m.u, &m.grad, &mat).l2;
    Ok((best, reps, l2))
}

fn grid2(mesh: Mesh, n: usize) -> Result<Grid<2>, BoxError> {
    let (lo, hi) = (Point::<2>::zeros(), Point::<2>::repeat(1.0));
    Ok(match mesh {
        Mesh::Simplices => simplices(lo, hi, [n; 2])?,
        Mesh::Boxes => cartesian(lo, hi, [n; 2])?,
        Mesh::Voronoi => voronoi(lo, hi, n, 7, DEFAULT_LLOYD)?,
    })
}

fn grid3(mesh: Mesh, n: usize) -> Result<Grid<3>, BoxError> {
    let (lo, hi) = (Point::<3>::zeros(), Point::<3>::repeat(1.0));
    Ok(match mesh {
        Mesh::Simplices => simplices(lo, hi, [n; 3])?,
        Mesh::Boxes => cartesian(lo, hi, [n; 3])?,
        Mesh::Voronoi => return Err("Voronoi grids are 2D only".into()),
    })
}

fn run_ladders<const D: usize>(
    problem: &str,
    ladders: &[Ladder],
    m: &Manufactured<D>,
    make_grid: fn(Mesh, usize) -> Result<Grid<D>, BoxError>,
    explicit_tol: f64,
    rows: &mut Vec<Row>,
) -> Result<(), BoxError> {
    let st = Stiffness::<D>::isotropic(1.0, 0.3)?;
    let vem = VemLaw::new(st.clone());
    let mdem = MdemLaw::new(&st)?;
    for ladder in ladders {
        let method = ladder.label(D);
        for &n in ladder.sizes {
            let grid = make_grid(ladder.mesh, n)?;
            let law: &dyn CellLaw<D> = match ladder.law {
                Law::Vem => &vem,
                Law::Mdem => &mdem,
            };
            let (pass, reps, l2) = measure(&grid, law, ladder.solve, m, explicit_tol)?;
            let row = Row {
                problem: problem.into(),
                method: method.clone(),
                n,
                cells: grid.num_cells(),
                ndofs: D * grid.num_nodes(),
                equations: pass.equations,
                t_assemble: pass.t_assemble,
                t_solve: pass.t_solve,
                iterations: pass.iterations,
                l2,
                reps,
            };
            eprintln!(
                "{problem} {method:<28} n {n:>7} cells {:>8} eqs {:>8}: assembly {:>8.4} s, \
                 solve {:>8.4} s ({} its), L2 {:.4e} [{reps} pass(es)]",
                row.cells, row.equations, row.t_assemble, row.t_solve, row.iterations, row.l2
            );
            rows.push(row);
        }
    }
    Ok(())
}

/// Read the FEniCSx peer CSV (`dim,n,solver,t_assemble,t_solve,l2_err,ndofs`).
fn read_peers(path: &Path) -> Result<Vec<Row>, BoxError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        format!(
            "peer CSV {}: {e} (run docs/data/fenicsx_e2e3.sh)",
            path.display()
        )
    })?;
    let mut rows = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with("dim,") {
            continue;
        }
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() < 7 {
            return Err(format!("{}: short line {line}", path.display()).into());
        }
        let dim: usize = f[0].parse()?;
        let n: usize = f[1].parse()?;
        let solver = match f[2] {
            "gamg" => "CG+GAMG",
            "mumps" => "MUMPS",
            other => other,
        };
        let ndofs: usize = f[6].parse()?;
        rows.push(Row {
            problem: format!("E{dim}"),
            method: format!("FEniCSx P1, {solver}"),
            n,
            cells: if dim == 2 { 2 * n * n } else { 6 * n * n * n },
            ndofs,
            equations: 0,
            t_assemble: f[3].parse()?,
            t_solve: f[4].parse()?,
            iterations: 0,
            l2: f[5].parse()?,
            reps: 0,
        });
    }
    Ok(rows)
}

fn register_font() {
    // The bundled DejaVu Sans of the command-line crate: no system font library needed.
    let _ = plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        include_bytes!("../crates/scene/assets/DejaVuSans.ttf"),
    );
}

/// Colour and marker of a method (stable across plots).
fn style_of(method: &str) -> (RGBColor, usize) {
    const TABLE: &[(&str, RGBColor, usize)] = &[
        ("MDEM", RGBColor(44, 160, 44), 2),
        ("explicit", RGBColor(188, 189, 34), 3),
        ("triangles, Cholesky", RGBColor(31, 119, 180), 0),
        ("tetrahedra, Cholesky", RGBColor(31, 119, 180), 0),
        ("triangles, CG-AMG", RGBColor(255, 127, 14), 1),
        ("tetrahedra, CG-AMG", RGBColor(255, 127, 14), 1),
        ("squares", RGBColor(148, 103, 189), 3),
        ("cubes, Cholesky", RGBColor(148, 103, 189), 3),
        ("cubes, CG-AMG", RGBColor(140, 86, 75), 2),
        ("Voronoi", RGBColor(227, 119, 194), 1),
        ("GAMG", RGBColor(0, 0, 0), 0),
        ("MUMPS", RGBColor(127, 127, 127), 3),
    ];
    TABLE
        .iter()
        .find(|(key, ..)| method.contains(key))
        .map_or((RGBColor(23, 190, 207), 0), |&(_, c, k)| (c, k))
}

fn plot(path: &Path, title: &str, rows: &[&Row]) -> Result<(), BoxError> {
    register_font();
    // Series in order of first appearance (the ladders, then the peers).
    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for r in rows {
        if r.total() > 0.0 && r.l2 > 0.0 {
            let p = (r.total(), r.l2);
            match series.iter_mut().find(|s| s.0 == r.method) {
                Some(s) => s.1.push(p),
                None => series.push((r.method.clone(), vec![p])),
            }
        }
    }
    if series.is_empty() {
        return Err(format!("{}: no points to plot", path.display()).into());
    }
    let xs = series.iter().flat_map(|s| &s.1).map(|p| p.0);
    let ys = series.iter().flat_map(|s| &s.1).map(|p| p.1);
    let (x0, x1) = (
        xs.clone().fold(f64::INFINITY, f64::min),
        xs.fold(0.0, f64::max),
    );
    let (y0, y1) = (
        ys.clone().fold(f64::INFINITY, f64::min),
        ys.fold(0.0, f64::max),
    );
    // Whole decades around the data.
    let dec_lo = |v: f64| 10f64.powf(v.log10().floor());
    let dec_hi = |v: f64| 10f64.powf(v.log10().ceil());
    let (x0, x1, y0, y1) = (dec_lo(x0), dec_hi(x1 * 1.05), dec_lo(y0), dec_hi(y1));
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let root = BitMapBackend::new(path, (1000, 700)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("wall time, assembly + solve [s]")
        .y_desc("L2 error ‖u − u_h‖")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .draw()?;
    for (method, pts) in &series {
        let mut pts = pts.clone();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (color, kind) = style_of(method);
        let peer = method.starts_with("FEniCSx");
        let line = if peer {
            color.stroke_width(1)
        } else {
            color.stroke_width(2)
        };
        let dot = if peer {
            color.stroke_width(2)
        } else {
            color.filled()
        };
        chart.draw_series(LineSeries::new(pts.clone(), line))?;
        // One marker shape per kind: circle, triangle, cross, square (peers hollow).
        macro_rules! markers {
            ($shape:expr) => {{
                let shape = $shape;
                chart
                    .draw_series(pts.iter().map(|&p| EmptyElement::at(p) + shape(dot)))?
                    .label(method.clone())
                    .legend(move |(x, y)| {
                        EmptyElement::at((x, y))
                            + PathElement::new(vec![(-12, 0), (12, 0)], line)
                            + shape(dot)
                    });
            }};
        }
        match kind {
            0 => markers!(|st: ShapeStyle| Circle::new((0, 0), 5, st)),
            1 => markers!(|st: ShapeStyle| TriangleMarker::new((0, 0), 7, st)),
            2 => markers!(|st: ShapeStyle| Cross::new((0, 0), 5, st.stroke_width(2))),
            _ => markers!(|st: ShapeStyle| Rectangle::new([(-4, -4), (4, 4)], st)),
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

struct Args {
    quick: bool,
    problems: Vec<String>,
    peers: PathBuf,
    csv: PathBuf,
    out_dir: PathBuf,
    explicit_tol: f64,
    plot_only: bool,
}

fn parse_args() -> Result<Args, BoxError> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut it = std::env::args().skip(1);
    let mut quick = false;
    let mut problem = "all".to_string();
    let (mut peers, mut csv, mut out_dir) = (None, None, None);
    let mut explicit_tol = 1e-8;
    let mut plot_only = false;
    while let Some(a) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{a} needs a value"));
        match a.as_str() {
            "--quick" => quick = true,
            "--plot-only" => plot_only = true,
            "--problem" => problem = value()?,
            "--peers" => peers = Some(PathBuf::from(value()?)),
            "--csv" => csv = Some(PathBuf::from(value()?)),
            "--out-dir" => out_dir = Some(PathBuf::from(value()?)),
            "--explicit-tol" => explicit_tol = value()?.parse()?,
            "-h" | "--help" => {
                println!(
                    "speed_error [--quick] [--problem e2|e3|all] [--peers CSV] [--csv CSV] \
                     [--out-dir DIR] [--explicit-tol T] [--plot-only]"
                );
                std::process::exit(0);
            }
            other => return Err(format!("unknown argument {other} (try --help)").into()),
        }
    }
    let problems = match problem.as_str() {
        "all" => vec!["E2".to_string(), "E3".to_string()],
        "e2" | "E2" => vec!["E2".to_string()],
        "e3" | "E3" => vec!["E3".to_string()],
        other => return Err(format!("--problem {other}: e2, e3 or all").into()),
    };
    let default_out = if quick {
        root.join("target/speed_error_quick")
    } else {
        root.join("docs")
    };
    let out_dir = out_dir.unwrap_or(default_out);
    Ok(Args {
        quick,
        problems,
        peers: peers.unwrap_or_else(|| root.join("docs/data/fenicsx_e2e3.csv")),
        csv: csv.unwrap_or_else(|| {
            if quick {
                out_dir.join("speed_error.csv")
            } else {
                root.join("docs/data/speed_error.csv")
            }
        }),
        out_dir,
        explicit_tol,
        plot_only,
    })
}

/// The methods and sizes of each problem (`quick`: a tiny ladder for a smoke test).
fn ladders(dim: usize, quick: bool) -> Vec<Ladder> {
    use {Law::*, Mesh::*, Solve::*};
    type Sizes = &'static [usize];
    // (mesh, law, solve, E2 sizes, E3 sizes, E2 quick, E3 quick); empty = not run.
    let table: [(Mesh, Law, Solve, Sizes, Sizes, Sizes, Sizes); 7] = [
        (
            Simplices,
            Vem,
            Cholesky,
            &[50, 100, 200, 300, 500, 700, 1000],
            &[5, 10, 15, 20, 30],
            &[20, 40],
            &[4, 8],
        ),
        (
            Simplices,
            Vem,
            CgAmg,
            &[50, 100, 200, 300, 500, 700, 1000],
            &[5, 10, 15, 20, 30, 40],
            &[20, 40],
            &[4, 8],
        ),
        (
            Simplices,
            Mdem,
            Cholesky,
            &[50, 100, 200, 300, 500],
            &[5, 10, 15, 20],
            &[20, 40],
            &[4, 8],
        ),
        (
            Boxes,
            Vem,
            Cholesky,
            &[50, 100, 200, 316, 500],
            &[5, 10, 15, 20, 30],
            &[20, 40],
            &[4, 8],
        ),
        (Boxes, Vem, CgAmg, &[], &[10, 20, 30, 40], &[], &[4, 8]),
        (
            Voronoi,
            Vem,
            Cholesky,
            &[2_500, 10_000, 40_000, 100_000],
            &[],
            &[400, 1600],
            &[],
        ),
        (
            Simplices,
            Vem,
            Explicit,
            &[10, 20, 40, 80],
            &[4, 6, 8, 10],
            &[8, 16],
            &[4],
        ),
    ];
    table
        .into_iter()
        .filter_map(|(mesh, law, solve, e2, e3, e2q, e3q)| {
            let sizes = match (dim, quick) {
                (2, false) => e2,
                (2, true) => e2q,
                (_, false) => e3,
                (_, true) => e3q,
            };
            (!sizes.is_empty()).then_some(Ladder {
                mesh,
                law,
                solve,
                sizes,
            })
        })
        .collect()
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

/// glibc's heap keeps freed memory for reuse: no `mmap` for large blocks, no trimming
/// (the policy of the `porofrac` binary, `crates/cli/src/heap.rs`, which explains it).
/// Elsewhere than Linux with glibc it does nothing.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
fn retain_freed_memory() {
    // SAFETY: `mallopt` only sets allocator parameters; it is called with constants glibc
    // documents, before any other thread starts.
    unsafe {
        libc::mallopt(libc::M_MMAP_MAX, 0);
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn retain_freed_memory() {}

fn main() -> Result<(), BoxError> {
    retain_freed_memory();
    let args = parse_args()?;
    let mut rows: Vec<Row> = Vec::new();
    if args.plot_only {
        let text = std::fs::read_to_string(&args.csv)
            .map_err(|e| format!("{}: {e}", args.csv.display()))?;
        for line in text.lines() {
            if line.starts_with('#') || line.starts_with("problem,") || line.trim().is_empty() {
                continue;
            }
            rows.push(Row::parse(line)?);
        }
    } else {
        let load_before = load_average();
        let started = Instant::now();
        for p in &args.problems {
            if p == "E2" {
                run_ladders::<2>(
                    "E2",
                    &ladders(2, args.quick),
                    &e2(),
                    grid2,
                    args.explicit_tol,
                    &mut rows,
                )?;
            } else {
                run_ladders::<3>(
                    "E3",
                    &ladders(3, args.quick),
                    &e3(),
                    grid3,
                    args.explicit_tol,
                    &mut rows,
                )?;
            }
        }
        let load_after = load_average();
        let peers = read_peers(&args.peers);
        match peers {
            Ok(p) => rows.extend(p.into_iter().filter(|r| args.problems.contains(&r.problem))),
            Err(e) => eprintln!("no peer points: {e}"),
        }
        let mut out = String::new();
        writeln!(
            out,
            "# speed_error: {} s of measurements; load average (1/5/15 min) {load_before} \
             before, {load_after} after; {} threads; explicit tolerance {:e}",
            started.elapsed().as_secs(),
            std::thread::available_parallelism().map_or(0, |n| n.get()),
            args.explicit_tol
        )?;
        writeln!(out, "{CSV_HEADER}")?;
        for r in &rows {
            writeln!(out, "{}", r.csv())?;
        }
        if let Some(dir) = args.csv.parent() {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(&args.csv, out)?;
        eprintln!("wrote {}", args.csv.display());
    }
    for p in &args.problems {
        let pts: Vec<&Row> = rows.iter().filter(|r| &r.problem == p).collect();
        if pts.is_empty() {
            continue;
        }
        let title = match p.as_str() {
            "E2" => {
                "E2: 2D plane strain, manufactured solution, unit square — L2 error against time"
            }
            _ => "E3: 3D elasticity, manufactured solution, unit cube — L2 error against time",
        };
        let png = args
            .out_dir
            .join(format!("speed_error_{}.png", p.to_lowercase()));
        plot(&png, title, &pts)?;
        eprintln!("wrote {}", png.display());
        // The table of the points (markdown), for the docs.
        println!(
            "\n| {p} method | n | cells | dofs | assembly [s] | solve [s] | total [s] | its | L2 error |"
        );
        println!("|---|---|---|---|---|---|---|---|---|");
        for r in &pts {
            println!(
                "| {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {} | {:.3e} |",
                r.method,
                r.n,
                r.cells,
                r.ndofs,
                r.t_assemble,
                r.t_solve,
                r.total(),
                if r.iterations > 0 {
                    r.iterations.to_string()
                } else {
                    "–".into()
                },
                r.l2
            );
        }
    }
    Ok(())
}
