//! Shared test helpers: a P1 simplex law, isotropic stiffness, grid perturbation, a
//! pressurized band of failed cells.
#![allow(dead_code)]

use nalgebra::{DMatrix, SMatrix};
use porofrac_grid::{CellFaceLoops, Grid, Point};
use porofrac_law::{CellGeometry, CellLaw, LawError, Scratch, Tensor};
use porofrac_sim::{Displacement, ScalarField};

/// Index pairs of the Kelvin components: 2D [11, 22, 12], 3D [11, 22, 33, 23, 13, 12].
pub fn kelvin_pairs<const D: usize>() -> &'static [(usize, usize)] {
    if D == 2 {
        &[(0, 0), (1, 1), (0, 1)]
    } else {
        &[(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
    }
}

/// Isotropic Kelvin stiffness `σ = 2μ ε + λ tr(ε) I` (plane strain in 2D).
pub fn isotropic<const D: usize>(e: f64, nu: f64) -> DMatrix<f64> {
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let p = kelvin_pairs::<D>();
    let mut d = DMatrix::zeros(p.len(), p.len());
    for i in 0..D {
        for j in 0..D {
            d[(i, j)] = lambda + if i == j { 2.0 * mu } else { 0.0 };
        }
    }
    for k in D..p.len() {
        d[(k, k)] = 2.0 * mu;
    }
    d
}

/// The P1 law on simplices: `∇φ_i = N_i / |K|`, `K = |K| Bᵀ D B`, linear.
pub struct P1Law {
    pub d: DMatrix<f64>,
}

impl P1Law {
    fn b_matrix<const D: usize>(&self, cell: &CellGeometry<'_, D>, b: &mut DMatrix<f64>) {
        let n = cell.coords.len();
        let p = kelvin_pairs::<D>();
        *b = DMatrix::zeros(p.len(), D * n);
        let s = std::f64::consts::FRAC_1_SQRT_2;
        for i in 0..n {
            let g = cell.node_normals[i] / cell.volume;
            for (r, &(a, c)) in p.iter().enumerate() {
                if a == c {
                    b[(r, D * i + a)] = g[a];
                } else {
                    b[(r, D * i + a)] = s * g[c];
                    b[(r, D * i + c)] = s * g[a];
                }
            }
        }
    }
}

impl<const D: usize> CellLaw<D> for P1Law {
    fn name(&self) -> &str {
        "p1"
    }
    fn supports(&self, num_nodes: usize) -> bool {
        num_nodes == D + 1
    }
    fn energy(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        scratch: &mut Scratch,
    ) -> Result<f64, LawError> {
        let mut k = DMatrix::zeros(0, 0);
        self.stiffness(cell, u, &mut k, scratch)?;
        let uv = nalgebra::DVector::from_column_slice(u);
        Ok(0.5 * uv.dot(&(&k * &uv)))
    }
    fn forces(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<(), LawError> {
        let mut k = std::mem::take(&mut scratch.mats[1]);
        self.stiffness(cell, u, &mut k, scratch)?;
        for (i, o) in out.iter_mut().enumerate() {
            *o = -(0..u.len()).map(|j| k[(i, j)] * u[j]).sum::<f64>();
        }
        scratch.mats[1] = k;
        Ok(())
    }
    fn stiffness(
        &self,
        cell: &CellGeometry<'_, D>,
        _u: &[f64],
        out: &mut DMatrix<f64>,
        scratch: &mut Scratch,
    ) -> Result<(), LawError> {
        let mut b = std::mem::take(&mut scratch.mats[0]);
        self.b_matrix(cell, &mut b);
        *out = b.transpose() * &self.d * &b * cell.volume;
        scratch.mats[0] = b;
        Ok(())
    }
    fn stress(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        scratch: &mut Scratch,
    ) -> Result<Tensor<D>, LawError> {
        let mut b = std::mem::take(&mut scratch.mats[0]);
        self.b_matrix(cell, &mut b);
        let eps = &b * nalgebra::DVector::from_column_slice(u);
        let sig = &self.d * eps;
        scratch.mats[0] = b;
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let mut t = SMatrix::<f64, D, D>::zeros();
        for (r, &(a, c)) in kelvin_pairs::<D>().iter().enumerate() {
            if a == c {
                t[(a, a)] = sig[r];
            } else {
                t[(a, c)] = s * sig[r];
                t[(c, a)] = s * sig[r];
            }
        }
        Ok(t)
    }
}

/// A deterministic pseudo-random number in [−1, 1) from an integer.
pub fn hash01(mut k: u64) -> f64 {
    k = k
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(0x632B_E59B_D9B4_E019);
    k ^= k >> 31;
    k = k.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    k ^= k >> 29;
    (k >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// Move the interior nodes of `grid` by up to `frac · h` per axis and rebuild it.
pub fn perturb<const D: usize>(grid: &Grid<D>, h: f64, frac: f64) -> Grid<D> {
    let mut boundary = vec![false; grid.num_nodes()];
    for n in grid.nodes_of_faces(&grid.boundary_faces()) {
        boundary[n] = true;
    }
    let nodes: Vec<Point<D>> = (0..grid.num_nodes())
        .map(|n| {
            let mut p = *grid.node(n);
            if !boundary[n] {
                for a in 0..D {
                    p[a] += frac * h * hash01((D * n + a) as u64);
                }
            }
            p
        })
        .collect();
    let mut loops = CellFaceLoops::new();
    for c in 0..grid.num_cells() {
        for (&f, &o) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
            let v: Vec<usize> = grid.oriented_face_nodes(f, o).collect();
            loops.push_face(&v);
        }
        loops.finish_cell();
    }
    Grid::from_cell_faces(nodes, &loops).expect("perturbed grid is valid")
}

/// Displacement condition on a named side.
pub fn side<const D: usize>(
    grid: &Grid<D>,
    name: &str,
    comps: [Option<ScalarField>; D],
) -> Displacement<D> {
    Displacement {
        name: name.into(),
        faces: grid.boundary(name).expect("side exists"),
        components: comps,
    }
}

/// Relative difference `|a − b| / scale`.
pub fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / scale
}

/// The displacements of a body whose band of cells (`band[c]`, given a compression-only
/// law that opens freely) is loaded by a uniform pressure `p` as the pore pressure of a
/// failed cell: nodal forces `p N_i` (the cell's outward node normals), then Newton on the
/// piecewise-linear laws until the stiffness of the solution is the one solved with (the
/// residual at 1e-9 of the load). The sneddon and penny tests open their cracks with it.
pub fn open_band<const D: usize>(
    grid: &Grid<D>,
    laws: &porofrac_sim::LawMap<'_, D>,
    dofs: &porofrac_sim::DofMap<D>,
    pattern: &porofrac_sim::Pattern,
    band: &[bool],
    p: f64,
) -> Vec<f64> {
    let mut full = vec![0.0; dofs.num_dofs()];
    let mut nn = Vec::new();
    for c in (0..grid.num_cells()).filter(|&c| band[c]) {
        nn.resize(grid.cell_nodes(c).len(), Point::<D>::zeros());
        grid.cell_node_normals(c, &mut nn);
        for (&i, ni) in grid.cell_nodes(c).iter().zip(&nn) {
            for a in 0..D {
                full[D * i + a] += p * ni[a];
            }
        }
    }
    let neq = dofs.num_equations();
    let mut fext = vec![0.0; neq];
    dofs.reduce_add(&full, &mut fext);
    let fnorm = fext.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut u = vec![0.0; dofs.num_dofs()];
    let mut values = vec![0.0; pattern.nnz()];
    let mut forces = vec![0.0; neq];
    let mut solver = porofrac_sim::DirectSolver::new(pattern).unwrap();
    for _ in 0..40 {
        porofrac_sim::assemble(grid, laws, dofs, pattern, &u, &mut values, &mut forces).unwrap();
        let mut r: Vec<f64> = fext.iter().zip(&forces).map(|(a, b)| a + b).collect();
        if r.iter().map(|v| v * v).sum::<f64>().sqrt() <= 1e-9 * fnorm {
            return u;
        }
        solver.factorize(pattern, &values).unwrap();
        solver.solve_in_place(&mut r).unwrap();
        dofs.scatter_add(&r, &mut u);
    }
    panic!("the open/closed edges of the band did not settle in 40 Newton steps");
}
