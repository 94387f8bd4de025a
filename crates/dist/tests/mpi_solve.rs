//! The distributed AMG-preconditioned CG against the serial `porofrac-amg` solve, on 1,
//! 2 and 4 MPI processes (oversubscribed), for P1 linear elasticity on a 2D triangle
//! mesh and a 3D tetrahedral mesh of the unit square/cube, clamped on the boundary.
//!
//! Each case runs this test binary under `mpirun -n P --oversubscribe` with the ignored
//! rank body selected by `--exact`. The rank body checks on rank 0 that the distributed
//! solution equals the serial one to `1e-6` relative (both solved to a relative residual
//! of `1e-10`; the difference is bounded by the condition number times the tolerances)
//! and prints its iteration count; the driver asserts that the iterations on four
//! processes are at most 1.2 times those on one.
#![cfg(feature = "mpi")]

use std::process::Command;

use nalgebra::DMatrix;
use porofrac_amg::{Amg, AmgOptions, NearNullSpace, SymCsr};
use porofrac_dist::matrix::{all_gather_vec, sum};
use porofrac_dist::{DistAmg, DistCsr, Layout, recursive_bisection};

/// A structured simplex mesh of the unit box: `(coords, simplices)`, `n` cells a side
/// (squares split in two triangles, cubes in six Kuhn tetrahedra).
fn mesh(dim: usize, n: usize) -> (Vec<f64>, Vec<Vec<usize>>) {
    let h = 1.0 / n as f64;
    let np = n + 1;
    let mut coords = Vec::new();
    let mut cells = Vec::new();
    if dim == 2 {
        for j in 0..np {
            for i in 0..np {
                coords.extend([i as f64 * h, j as f64 * h]);
            }
        }
        let id = |i: usize, j: usize| j * np + i;
        for j in 0..n {
            for i in 0..n {
                cells.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                cells.push(vec![id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    } else {
        for k in 0..np {
            for j in 0..np {
                for i in 0..np {
                    coords.extend([i as f64 * h, j as f64 * h, k as f64 * h]);
                }
            }
        }
        let id = |i: usize, j: usize, k: usize| (k * np + j) * np + i;
        let perms = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    for p in perms {
                        let mut c = [i, j, k];
                        let mut t = vec![id(c[0], c[1], c[2])];
                        for a in p {
                            c[a] += 1;
                            t.push(id(c[0], c[1], c[2]));
                        }
                        cells.push(t);
                    }
                }
            }
        }
    }
    (coords, cells)
}

/// P1 element stiffness, E = 1, ν = 0.3 (plane strain in 2D).
fn element(dim: usize, x: &[[f64; 3]]) -> DMatrix<f64> {
    let (e, nu) = (1.0, 0.3);
    let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let nn = dim + 1;
    let jac = DMatrix::from_fn(dim, dim, |r, c| x[c + 1][r] - x[0][r]);
    let det = jac.determinant();
    let inv = jac.try_inverse().expect("non-degenerate simplex");
    let vol = det.abs() / if dim == 2 { 2.0 } else { 6.0 };
    // Gradients of the barycentric functions.
    let mut g = vec![vec![0.0; dim]; nn];
    for a in 1..nn {
        for d in 0..dim {
            g[a][d] = inv[(a - 1, d)];
        }
    }
    for d in 0..dim {
        g[0][d] = -(1..nn).map(|a| g[a][d]).sum::<f64>();
    }
    // K_(a i)(b j) = vol (λ g_a,i g_b,j + μ g_a,j g_b,i + μ δ_ij g_a·g_b).
    DMatrix::from_fn(nn * dim, nn * dim, |r, c| {
        let (a, i, b, j) = (r / dim, r % dim, c / dim, c % dim);
        let ab: f64 = (0..dim).map(|d| g[a][d] * g[b][d]).sum();
        vol * (lam * g[a][i] * g[b][j]
            + mu * g[a][j] * g[b][i]
            + if i == j { mu * ab } else { 0.0 })
    })
}

/// The problem with its equations numbered part by part: per equation its (node,
/// component), the full matrix by rows in that numbering, the right-hand side, and the
/// part ranges.
struct Problem {
    dim: usize,
    coords: Vec<f64>,
    dofs: Vec<(usize, usize)>,
    rows: Vec<Vec<(usize, f64)>>,
    b: Vec<f64>,
    starts: Vec<usize>,
}

fn problem(dim: usize, n: usize, parts: usize) -> Problem {
    let (coords, cells) = mesh(dim, n);
    let nn = coords.len() / dim;
    let boundary = |v: usize| {
        (0..dim).any(|d| {
            let x = coords[v * dim + d];
            !(1e-12..=1.0 - 1e-12).contains(&x)
        })
    };
    let part = recursive_bisection(&coords, dim, parts);
    let mut eq = vec![usize::MAX; nn * dim];
    let mut dofs = Vec::new();
    let mut starts = vec![0];
    for p in 0..parts {
        for v in 0..nn {
            if part[v] == p && !boundary(v) {
                for c in 0..dim {
                    eq[v * dim + c] = dofs.len();
                    dofs.push((v, c));
                }
            }
        }
        starts.push(dofs.len());
    }
    let neq = dofs.len();
    let mut rows: Vec<std::collections::BTreeMap<usize, f64>> = vec![Default::default(); neq];
    let mut b = vec![0.0; neq];
    for cell in &cells {
        let x: Vec<[f64; 3]> = cell
            .iter()
            .map(|&v| {
                let mut p = [0.0; 3];
                p[..dim].copy_from_slice(&coords[v * dim..(v + 1) * dim]);
                p
            })
            .collect();
        let k = element(dim, &x);
        let m = cell.len() * dim;
        for r in 0..m {
            let er = eq[cell[r / dim] * dim + r % dim];
            if er == usize::MAX {
                continue;
            }
            // A smooth load: f = (1, 0.5, 0.25) weighted by the position.
            b[er] += (1.0 + x[r / dim][0]) / (m as f64) * [1.0, 0.5, 0.25][r % dim];
            for c in 0..m {
                let ec = eq[cell[c / dim] * dim + c % dim];
                if ec != usize::MAX {
                    *rows[er].entry(ec).or_insert(0.0) += k[(r, c)];
                }
            }
        }
    }
    Problem {
        dim,
        coords,
        dofs,
        rows: rows.into_iter().map(|r| r.into_iter().collect()).collect(),
        b,
        starts,
    }
}

/// Options of both solves: a small coarsest level, so the hierarchy has three levels and
/// two Galerkin products across processes.
fn options() -> AmgOptions {
    AmgOptions {
        max_coarse: 150,
        ..AmgOptions::default()
    }
}

/// The serial solve of `porofrac-amg` (the reference).
fn serial(p: &Problem, tol: f64) -> (Vec<f64>, usize) {
    let n = p.rows.len();
    let (mut cp, mut ri, mut v) = (vec![0], vec![], vec![]);
    for (j, row) in p.rows.iter().enumerate() {
        for &(i, a) in row {
            if i <= j {
                ri.push(i);
                v.push(a);
            }
        }
        cp.push(ri.len());
    }
    let sym = SymCsr::from_upper_csc(n, &cp, &ri, &v).unwrap();
    let mut amg = Amg::elasticity(sym, &p.coords, p.dim, &p.dofs, &options()).unwrap();
    let mut x = vec![0.0; n];
    let stats = amg.solve(&mut x, &p.b, tol, 500).unwrap();
    (x, stats.iterations)
}

/// The rank body: distributed solve, compared with the serial one on rank 0; levels of
/// at most `gather_below` equations are gathered ([`DistAmg::with_gathering`]).
fn rank_body(dim: usize, n: usize, gather_below: usize) {
    let universe = mpi::initialize().expect("MPI initializes once");
    let world = universe.world();
    use mpi::traits::Communicator;
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let p = problem(dim, n, size);
    let tol = 1e-10;
    let own = p.starts[rank]..p.starts[rank + 1];
    let layout = Layout::from_local(&world, own.len());
    assert_eq!(layout.start(), own.start);
    let (mut ptr, mut col, mut val) = (vec![0], vec![], vec![]);
    for i in own.clone() {
        for &(j, a) in &p.rows[i] {
            col.push(j);
            val.push(a);
        }
        ptr.push(col.len());
    }
    let a = DistCsr::from_rows(&world, layout.clone(), layout, &ptr, &col, &val).unwrap();
    let dofs: Vec<(usize, usize)> = p.dofs[own.clone()].to_vec();
    let null = NearNullSpace::rigid_body_modes(&p.coords, dim, &dofs).unwrap();
    let nodes: Vec<usize> = dofs.iter().map(|d| d.0).collect();
    let amg = DistAmg::with_gathering(&world, a, &nodes, &null, &options(), gather_below).unwrap();
    let mut x = vec![0.0; own.len()];
    let stats = amg
        .solve(&world, &mut x, &p.b[own.clone()], tol, 500)
        .unwrap();
    assert!(stats.relative_residual <= tol);
    // The true residual of the distributed solution.
    let mut ax = vec![0.0; own.len()];
    amg.matrix().mul(&world, &x, &mut ax);
    let r2 = sum(
        &world,
        ax.iter()
            .zip(&p.b[own.clone()])
            .map(|(a, b)| (a - b).powi(2))
            .sum(),
    );
    let b2 = sum(&world, p.b[own].iter().map(|b| b * b).sum());
    assert!(
        (r2 / b2).sqrt() <= 1.01 * tol,
        "true residual {}",
        (r2 / b2).sqrt()
    );
    let all = all_gather_vec(&world, &x);
    if rank == 0 {
        let (xs, its) = serial(&p, tol);
        let diff = all
            .iter()
            .zip(&xs)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        let norm = xs.iter().map(|a| a * a).sum::<f64>().sqrt();
        assert!(
            diff <= 1e-6 * norm,
            "distributed and serial differ by {:e}",
            diff / norm
        );
        let levels = amg.level_info(&world);
        let gathered = amg.gathered_levels();
        if gather_below > options().max_coarse {
            // The gathered level is above the direct-solve size: a serial multilevel
            // hierarchy handles it.
            assert!(
                gathered.len() >= 2 && gathered[0].rows > options().max_coarse,
                "gathered levels {gathered:?}"
            );
        }
        println!(
            "DIST dim={dim} n={n} ranks={size} iterations={} serial_iterations={its} rel_diff={:.3e} levels={:?} gathered={:?}",
            stats.iterations,
            diff / norm,
            levels.iter().map(|l| l.rows).collect::<Vec<_>>(),
            gathered.iter().map(|l| l.rows).collect::<Vec<_>>()
        );
    } else {
        let _ = amg.level_info(&world);
    }
}

#[test]
#[ignore = "rank body: runs under mpirun from the driver tests"]
fn rank_elasticity_2d() {
    rank_body(2, 48, 0);
}

#[test]
#[ignore = "rank body: runs under mpirun from the driver tests"]
fn rank_elasticity_3d() {
    rank_body(3, 14, 0);
}

#[test]
#[ignore = "rank body: runs under mpirun from the driver tests"]
fn rank_elasticity_3d_gathered() {
    rank_body(3, 14, 1500);
}

/// Run `name` on `ranks` processes; returns its iteration count.
fn run(name: &str, ranks: usize) -> usize {
    let exe = std::env::current_exe().unwrap();
    let out = Command::new("mpirun")
        .args([
            "--oversubscribe",
            "--allow-run-as-root",
            "-n",
            &ranks.to_string(),
        ])
        .arg(&exe)
        .args([
            "--exact",
            name,
            "--include-ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .expect("mpirun (OpenMPI or MPICH) on the PATH: scripts/install-mpi");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{name} on {ranks} ranks failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = stdout
        .lines()
        .find_map(|l| l.find("DIST ").map(|k| &l[k..]))
        .unwrap_or_else(|| panic!("no result line from {name}:\n{stdout}"));
    eprintln!("{line}");
    line.split_whitespace()
        .find_map(|w| w.strip_prefix("iterations="))
        .and_then(|v| v.parse().ok())
        .expect("iterations in the result line")
}

fn check_iterations(name: &str) {
    let it: Vec<usize> = [1, 2, 4].iter().map(|&p| run(name, p)).collect();
    assert!(
        it[2] as f64 <= 1.2 * it[0] as f64,
        "{name}: iterations on 1, 2, 4 ranks {it:?} grow by more than 20 %"
    );
}

#[test]
fn elasticity_2d_on_1_2_4_ranks_matches_serial() {
    check_iterations("rank_elasticity_2d");
}

#[test]
fn elasticity_3d_on_1_2_4_ranks_matches_serial() {
    check_iterations("rank_elasticity_3d");
}

#[test]
fn elasticity_3d_gathered_coarse_levels_on_1_2_4_ranks_matches_serial() {
    check_iterations("rank_elasticity_3d_gathered");
}
