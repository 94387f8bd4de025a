//! Consistency of TPFA: linear pressures on K-orthogonal grids, 1D steady flow with a
//! known flux, anisotropic diagonal permeability.

use porofrac_flow::{
    FlowModel, FlowProblem, Fluid, Permeability, Rock, ScalarField, StepResult, Tensor,
    Transmissibilities,
};
use porofrac_grid::generate::{cartesian, simplices};
use porofrac_grid::{Grid, Point};

const MU: f64 = 1e-3;

fn incompressible() -> Fluid {
    Fluid {
        viscosity: MU,
        compressibility: 0.0,
    }
}

/// Solve the steady problem with `p = g·x + b` on every boundary face; return the solution
/// and the largest cell error relative to the pressure range over the grid.
fn linear_patch<const D: usize>(
    grid: &Grid<D>,
    perm: Permeability<D>,
    g: [f64; D],
    b: f64,
) -> (StepResult, f64) {
    let n = grid.num_cells();
    let exact = move |x: &[f64]| b + (0..D).map(|a| g[a] * x[a]).sum::<f64>();
    let problem = FlowProblem::new(Rock::new(vec![0.3; n], perm), incompressible()).pressure_bc(
        grid.boundary_faces(),
        ScalarField::from_fn(move |x, _| exact(x)),
    );
    let mut model = FlowModel::new(grid, &problem).unwrap();
    let r = model.solve_steady(0.0).unwrap();
    let range: f64 = (0..D)
        .map(|a| {
            let (lo, hi) = grid.bounding_box();
            g[a].abs() * (hi[a] - lo[a])
        })
        .sum();
    let err = (0..n)
        .map(|c| (r.pressure[c] - exact(grid.cell_centroid(c).as_slice())).abs())
        .fold(0.0, f64::max)
        / range;
    eprintln!("{D}D linear patch, {n} cells: max relative pressure error {err:.3e}");
    (r, err)
}

/// Largest relative error of the face fluxes against `−A_f (K ∇p)·n_f / μ`.
fn flux_error<const D: usize>(grid: &Grid<D>, k: &Tensor<D>, g: [f64; D], r: &StepResult) -> f64 {
    let grad = Point::<D>::from_fn(|a, _| g[a]);
    let u = -(k * grad) / MU;
    let scale = u.norm()
        * (0..grid.num_faces())
            .map(|f| grid.face_area(f))
            .fold(0.0, f64::max);
    let e = (0..grid.num_faces())
        .map(|f| (r.face_flux[f] - grid.face_area(f) * u.dot(grid.face_normal(f))).abs())
        .fold(0.0, f64::max)
        / scale;
    eprintln!("  max relative face flux error {e:.3e}");
    e
}

#[test]
fn linear_pressure_cartesian_2d_isotropic() {
    let grid = cartesian::<2>(
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(3.0, 2.0),
        [12, 9],
    )
    .unwrap();
    let perm = Permeability::uniform(grid.num_cells(), 2e-13).unwrap();
    let g = [1.5e5, -0.7e5];
    let (r, err) = linear_patch(&grid, perm, g, 1e6);
    assert!(err < 1e-12, "relative pressure error {err:e}");
    let ferr = flux_error(&grid, &(Tensor::<2>::identity() * 2e-13), g, &r);
    assert!(ferr < 1e-10, "relative flux error {ferr:e}");
}

#[test]
fn linear_pressure_cartesian_3d_diagonal_anisotropic() {
    let grid = cartesian::<3>(
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(2.0, 1.0, 0.5),
        [8, 5, 4],
    )
    .unwrap();
    let kd = [1e-12, 1e-13, 1e-14];
    let perm = Permeability::uniform_diagonal(grid.num_cells(), kd).unwrap();
    let g = [2e5, -3e5, 5e4];
    let (r, err) = linear_patch(&grid, perm, g, 7e6);
    assert!(err < 1e-12, "relative pressure error {err:e}");
    let k = Tensor::<3>::from_diagonal(&Point::<3>::new(kd[0], kd[1], kd[2]));
    let ferr = flux_error(&grid, &k, g, &r);
    assert!(ferr < 1e-10, "relative flux error {ferr:e}");
}

/// Equilateral triangles: the centroid is the circumcentre, so `c_f − x_K ∥ n_f` and TPFA is
/// consistent for isotropic permeability.
fn equilateral(nx: usize, ny: usize, h: f64) -> Grid<2> {
    let s = h * 3f64.sqrt() / 2.0;
    let mut nodes = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            nodes.push(Point::<2>::new(
                (i as f64 + 0.5 * (j % 2) as f64) * h,
                j as f64 * s,
            ));
        }
    }
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut pos = vec![0];
    let mut cn = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let tris = if j % 2 == 0 {
                [
                    [id(i, j), id(i + 1, j), id(i, j + 1)],
                    [id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)],
                ]
            } else {
                [
                    [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                    [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
                ]
            };
            for t in tris {
                cn.extend_from_slice(&t);
                pos.push(cn.len());
            }
        }
    }
    Grid::from_polygons(nodes, &pos, &cn).unwrap()
}

#[test]
fn linear_pressure_equilateral_triangles() {
    let grid = equilateral(10, 8, 0.5);
    let perm = Permeability::uniform(grid.num_cells(), 1e-12).unwrap();
    let tr = Transmissibilities::new(&grid, &perm).unwrap();
    assert_eq!(tr.num_negative(), 0);
    let g = [1e5, 2e5];
    let (r, err) = linear_patch(&grid, perm, g, 3e6);
    assert!(err < 1e-12, "relative pressure error {err:e}");
    let ferr = flux_error(&grid, &(Tensor::<2>::identity() * 1e-12), g, &r);
    assert!(ferr < 1e-10, "relative flux error {ferr:e}");
}

/// Right triangles (a square split by its diagonal) are *not* K-orthogonal with centroids:
/// the line between the centroids across a horizontal or vertical edge is not normal to it,
/// so TPFA does not reproduce a linear field there. This documents the limitation.
#[test]
fn right_triangles_are_not_k_orthogonal() {
    let grid =
        simplices::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 1.0), [8, 8]).unwrap();
    let perm = Permeability::uniform(grid.num_cells(), 1e-12).unwrap();
    let (_, err) = linear_patch(&grid, perm, [1e5, 0.0], 0.0);
    assert!(
        err > 1e-3,
        "expected an O(1) consistency error, got {err:e}"
    );
}

/// 1D steady flow in a column with pressures at both ends: linear pressure, flux
/// `q = k A (p_in − p_out) / (μ L)` through every cross-section.
#[test]
fn steady_1d_column_known_flux() {
    let (l, w, n) = (10.0, 0.5, 25);
    let grid = cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(l, w), [n, 1]).unwrap();
    let k = 3e-13;
    let (p_in, p_out) = (4e6, 1e6);
    let problem = FlowProblem::new(
        Rock::new(vec![0.25; n], Permeability::uniform(n, k).unwrap()),
        incompressible(),
    )
    .pressure_bc(grid.boundary("xmin").unwrap(), p_in)
    .pressure_bc(grid.boundary("xmax").unwrap(), p_out);
    let mut model = FlowModel::new(&grid, &problem).unwrap();
    let r = model.solve_steady(0.0).unwrap();
    let q = k * w * (p_in - p_out) / (MU * l);
    for f in 0..grid.num_faces() {
        let nx = grid.face_normal(f)[0];
        let expected = q * nx; // vertical faces carry q, horizontal ones 0
        assert!(
            (r.face_flux[f] - expected).abs() <= 1e-12 * q,
            "face {f}: flux {} vs {expected}",
            r.face_flux[f]
        );
    }
    for c in 0..n {
        let x = grid.cell_centroid(c)[0];
        let p = p_in + (p_out - p_in) * x / l;
        assert!((r.pressure[c] - p).abs() <= 1e-12 * p_in);
    }
}

/// The same column with an injected Darcy flux `u` (Neumann, outward −u) at the inlet and
/// pressure at the outlet: `p(x) = p_out + μ u (L − x)/k`.
#[test]
fn steady_1d_column_flux_inlet() {
    let (l, w, n) = (4.0, 1.0, 16);
    let grid = cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(l, w), [n, 1]).unwrap();
    let (k, u, p_out) = (1e-12, 2e-6, 1e5);
    let problem = FlowProblem::new(
        Rock::new(vec![0.25; n], Permeability::uniform(n, k).unwrap()),
        incompressible(),
    )
    .flux_bc(grid.boundary("xmin").unwrap(), -u)
    .pressure_bc(grid.boundary("xmax").unwrap(), p_out);
    let mut model = FlowModel::new(&grid, &problem).unwrap();
    let r = model.solve_steady(0.0).unwrap();
    for c in 0..n {
        let x = grid.cell_centroid(c)[0];
        let p = p_out + MU * u * (l - x) / k;
        assert!(
            (r.pressure[c] - p).abs() <= 1e-12 * p,
            "cell {c}: {} vs {p}",
            r.pressure[c]
        );
    }
    let out = grid.boundary("xmax").unwrap()[0];
    assert!((r.face_flux[out] - u * w).abs() <= 1e-12 * u * w);
}

/// Diagonal anisotropy on a Cartesian grid: flow along x sees k_x only, along y k_y only.
#[test]
fn anisotropic_diagonal_permeability_cartesian() {
    let grid = cartesian::<2>(
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(1.0, 1.0),
        [10, 10],
    )
    .unwrap();
    let n = grid.num_cells();
    let (kx, ky) = (5e-13, 2e-14);
    let dp = 1e5;
    for axis in 0..2 {
        let (lo, hi) = if axis == 0 {
            ("xmin", "xmax")
        } else {
            ("ymin", "ymax")
        };
        let problem = FlowProblem::new(
            Rock::new(
                vec![0.1; n],
                Permeability::uniform_diagonal(n, [kx, ky]).unwrap(),
            ),
            incompressible(),
        )
        .pressure_bc(grid.boundary(lo).unwrap(), dp)
        .pressure_bc(grid.boundary(hi).unwrap(), 0.0);
        let mut model = FlowModel::new(&grid, &problem).unwrap();
        let r = model.solve_steady(0.0).unwrap();
        let k = if axis == 0 { kx } else { ky };
        let q_exact = k * dp / MU; // total through a unit cross-section
        let q: f64 = grid
            .boundary(hi)
            .unwrap()
            .iter()
            .map(|&f| r.face_flux[f])
            .sum();
        assert!(
            (q - q_exact).abs() <= 1e-12 * q_exact,
            "axis {axis}: outflow {q:e} vs {q_exact:e}"
        );
    }
}

/// Transmissibility formula on a single rectangle pair: `t = A k / (Δx/2)`, harmonic mean.
#[test]
fn transmissibility_values_cartesian() {
    let grid =
        cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 0.5), [2, 1]).unwrap();
    let perm = Permeability::from_scalars(&[1.0, 3.0]).unwrap();
    let tr = Transmissibilities::new(&grid, &perm).unwrap();
    let interior = (0..grid.num_faces())
        .find(|&f| !grid.is_boundary_face(f))
        .unwrap();
    // t_0 = 0.5 · 1 / 0.5 = 1, t_1 = 0.5 · 3 / 0.5 = 3, T = 3/4.
    let h = tr.half(interior);
    assert!((h[0] - 1.0).abs() < 1e-14 && (h[1] - 3.0).abs() < 1e-14);
    assert!((tr.face(interior) - 0.75).abs() < 1e-14);
}
