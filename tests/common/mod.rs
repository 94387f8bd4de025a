//! Shared helpers of the workspace validation tests: a one-call static solve, affine
//! fields, the per-cell L2 and energy errors, the patch-test check, and rate fitting. The
//! manufactured solutions E2/E3 and the degree-5 simplex rules are
//! `porofrac::sim::standard`'s, re-exported here.
//!
//! # Error norms
//!
//! The discrete displacement is reconstructed on each cell as the piecewise-linear field
//! on the sub-simplices formed by the facets of the cell's faces (the grid's face
//! triangulation, [`for_each_facet`]) and the cell's vertex average `x̄`: its value at a
//! vertex is the nodal value, at a face point the average of the face's nodal values, at
//! `x̄` the average of the cell's nodal values. On a simplex this is the P1 field itself.
//! `‖u − u_h‖_L2` is integrated on each sub-simplex with a degree-5 rule. The energy error
//! uses the cell's projected (constant) strain `ε_h = sym G(u_h)` of the VEM:
//! `‖u − u_h‖_E² = Σ_K ∫_K (ε − ε_h) : C : (ε − ε_h)`, with the same quadrature.
#![allow(dead_code)]

use std::sync::Arc;

use porofrac::grid::point::for_each_facet;
use porofrac::grid::{Grid, Point};
use porofrac::law::{GeometryBuffer, Stiffness, Tensor};
use porofrac::sim::{
    DirectSolver, Displacement, DofMap, LawMap, Loads, Pattern, ScalarField, SimError,
    StaticOptions, StaticProblem, StaticSolution, solve_static,
};
use porofrac::vem::projected_gradient;

// Each test binary uses a part of these.
#[allow(unused_imports)]
pub use porofrac::sim::standard::{
    Manufactured, QPoint, TenFn, VecFn, components, dirichlet, e2, e3, simplex_rule5,
    tetrahedron_rule5, triangle_rule5,
};

/// Component `a` fixed to zero on `faces` (a roller).
pub fn roller<const D: usize>(name: &str, faces: Vec<usize>, a: usize) -> Displacement<D> {
    Displacement {
        name: name.into(),
        faces,
        components: std::array::from_fn(|k| (k == a).then_some(ScalarField::Const(0.0))),
    }
}

/// Solve the static problem (one linear solve for linear laws).
pub fn solve<const D: usize>(
    grid: &Grid<D>,
    laws: &LawMap<'_, D>,
    disp: &[Displacement<D>],
    loads: &Loads<D>,
) -> Result<StaticSolution<D>, SimError> {
    let dofs = DofMap::new(grid, disp, &[])?;
    let pattern = Pattern::new(grid, &dofs)?;
    let mut solver = DirectSolver::new(&pattern)?;
    let problem = StaticProblem {
        grid,
        laws,
        dofs: &dofs,
        pattern: &pattern,
        loads,
    };
    solve_static(&problem, &mut solver, 0.0, &StaticOptions::default())
}

/// The affine field `u = A x + b`.
pub fn affine<const D: usize>(a: Tensor<D>, b: Point<D>) -> VecFn<D> {
    Arc::new(move |x| a * x + b)
}

/// Nodes that lie on no boundary face.
pub fn interior_nodes<const D: usize>(grid: &Grid<D>) -> Vec<usize> {
    let mut on = vec![false; grid.num_nodes()];
    for n in grid.nodes_of_faces(&grid.boundary_faces()) {
        on[n] = true;
    }
    (0..grid.num_nodes()).filter(|&n| !on[n]).collect()
}

/// Largest nodal error `max_n |u_h(x_n) − u(x_n)|` over `nodes`, divided by `scale`.
pub fn max_node_error<const D: usize>(
    grid: &Grid<D>,
    u: &[f64],
    exact: &VecFn<D>,
    nodes: &[usize],
    scale: f64,
) -> f64 {
    nodes
        .iter()
        .map(|&n| {
            let uh = Point::<D>::from_column_slice(&u[D * n..D * n + D]);
            (uh - exact(grid.node(n))).norm()
        })
        .fold(0.0, f64::max)
        / scale
}

/// Largest `|u(x_n)|` over all nodes (the scale of relative nodal errors).
pub fn max_node_value<const D: usize>(grid: &Grid<D>, exact: &VecFn<D>) -> f64 {
    grid.nodes()
        .iter()
        .map(|x| exact(x).norm())
        .fold(0.0, f64::max)
}

/// Largest relative stress error `max_K ‖σ_K − σ_exact(K)‖_F / max_K ‖σ_exact(K)‖_F`.
pub fn max_stress_error<const D: usize>(
    stress: &[Tensor<D>],
    exact: impl Fn(usize) -> Tensor<D>,
) -> f64 {
    let scale = (0..stress.len())
        .map(|c| exact(c).norm())
        .fold(0.0, f64::max);
    stress
        .iter()
        .enumerate()
        .map(|(c, s)| (s - exact(c)).norm())
        .fold(0.0, f64::max)
        / scale
}

/// Largest error of `rule` (k barycentric coordinates) on the monomials `λ^α`, `|α| ≤
/// degree`, against `α! d! / (|α| + d)!`.
pub fn rule_error(rule: &[QPoint], k: usize, degree: u32) -> f64 {
    let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
    let mut worst = 0.0f64;
    let mut alpha = vec![0u32; k];
    loop {
        let total: u32 = alpha.iter().sum();
        if total <= degree {
            let q: f64 = rule
                .iter()
                .map(|(w, l)| {
                    w * alpha
                        .iter()
                        .zip(l)
                        .map(|(&a, x)| x.powi(a as i32))
                        .product::<f64>()
                })
                .sum();
            let e = alpha.iter().map(|&a| fact(a)).product::<f64>() * fact(k as u32 - 1)
                / fact(total + k as u32 - 1);
            worst = worst.max((q - e).abs() / e);
        }
        let mut i = 0;
        loop {
            if i == k {
                return worst;
            }
            alpha[i] += 1;
            if alpha[i] <= degree {
                break;
            }
            alpha[i] = 0;
            i += 1;
        }
    }
}

/// Errors and exact norms of a discrete displacement (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct Errors {
    /// `‖u − u_h‖_L2`.
    pub l2: f64,
    /// `‖u − u_h‖_E` with the projected strain.
    pub energy: f64,
    /// `‖u‖_L2` by the same quadrature.
    pub norm_l2: f64,
    /// `‖u‖_E` by the same quadrature.
    pub norm_energy: f64,
}

/// L2 and energy errors of the nodal displacement `u` against `exact` (gradient
/// `grad`), material `mat` (see the module docs).
pub fn errors<const D: usize>(
    grid: &Grid<D>,
    u: &[f64],
    exact: &VecFn<D>,
    grad: &TenFn<D>,
    mat: &Stiffness<D>,
) -> Errors {
    let rule = simplex_rule5::<D>();
    let mut geo = GeometryBuffer::<D>::default();
    let mut cu: Vec<f64> = Vec::new();
    let mut pts: Vec<Point<D>> = Vec::new();
    let mut vals: Vec<Point<D>> = Vec::new();
    let (mut l2, mut en, mut nl2, mut nen) = (0.0, 0.0, 0.0, 0.0);
    let uat = |n: usize| Point::<D>::from_column_slice(&u[D * n..D * n + D]);
    for c in 0..grid.num_cells() {
        let cn = grid.cell_nodes(c);
        cu.clear();
        for &n in cn {
            cu.extend_from_slice(&u[D * n..D * n + D]);
        }
        let cell = geo.load(grid, c);
        let g = projected_gradient(&cell, &cu);
        let eps_h = (g + g.transpose()) * 0.5;
        let nn = cn.len() as f64;
        let xc = cn.iter().map(|&n| grid.node(n)).sum::<Point<D>>() / nn;
        let uc = cn.iter().map(|&n| uat(n)).sum::<Point<D>>() / nn;
        for (&face, &out) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
            pts.clear();
            vals.clear();
            for n in grid.oriented_face_nodes(face, out) {
                pts.push(*grid.node(n));
                vals.push(uat(n));
            }
            let m = pts.len() as f64;
            let xf = pts.iter().sum::<Point<D>>() / m;
            let uf = vals.iter().sum::<Point<D>>() / m;
            for_each_facet::<D>(&pts, |area, centroid, corners| {
                let vol = area.dot(&(centroid - xc)) / D as f64;
                let vx = |k: usize| {
                    if corners[k] == usize::MAX {
                        xf
                    } else {
                        pts[corners[k]]
                    }
                };
                let vu = |k: usize| {
                    if corners[k] == usize::MAX {
                        uf
                    } else {
                        vals[corners[k]]
                    }
                };
                for (w, l) in &rule {
                    let x = (0..D).map(|k| vx(k) * l[k]).sum::<Point<D>>() + xc * l[D];
                    let uh = (0..D).map(|k| vu(k) * l[k]).sum::<Point<D>>() + uc * l[D];
                    let ue = exact(&x);
                    let ge = grad(&x);
                    let eps = (ge + ge.transpose()) * 0.5;
                    let wv = w * vol;
                    l2 += wv * (ue - uh).norm_squared();
                    nl2 += wv * ue.norm_squared();
                    en += wv * 2.0 * mat.energy_density(&(eps - eps_h));
                    nen += wv * 2.0 * mat.energy_density(&eps);
                }
            });
        }
    }
    Errors {
        l2: l2.sqrt(),
        energy: en.sqrt(),
        norm_l2: nl2.sqrt(),
        norm_energy: nen.sqrt(),
    }
}

/// Least-squares slope of `log e` against `log h`.
pub fn fitted_rate(h: &[f64], e: &[f64]) -> f64 {
    let x: Vec<f64> = h.iter().map(|v| v.ln()).collect();
    let y: Vec<f64> = e.iter().map(|v| v.ln()).collect();
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// Mean cell size `(|Ω| / cells)^(1/D)`.
pub fn mean_cell_size<const D: usize>(grid: &Grid<D>) -> f64 {
    let vol: f64 = grid.cell_volumes().iter().sum();
    (vol / grid.num_cells() as f64).powf(1.0 / D as f64)
}

/// The Timoshenko–Goodier cantilever (Timoshenko & Goodier, *Theory of Elasticity*, §21):
/// `x ∈ [0, L]`, `y ∈ [−D/2, D/2]`, unit thickness, `I = D³/12`, clamped at `x = 0`
/// (the exact displacement prescribed there), loaded at `x = L` by the parabolic shear
/// traction `t_y = P/(2I) (D²/4 − y²)` (total `P`). With plane-stress constants `E`, `ν`
/// (plane strain: `E/(1 − ν²)` and `ν/(1 − ν)`):
///
/// ```text
///   u_x = −P y/(6EI) [(6L − 3x) x + (2 + ν)(y² − D²/4)]
///   u_y =  P/(6EI) [3ν y² (L − x) + (4 + 5ν) D² x/4 + (3L − x) x²]
///   σ_xx = −P (L − x) y/I,  σ_yy = 0,  σ_xy = P/(2I) (D²/4 − y²)
/// ```
///
/// so the tip deflection is `u_y(L, 0) = P L³/(3EI) + (4 + 5ν) P D² L/(24 E I)`.
#[derive(Clone, Copy, Debug)]
pub struct Beam {
    /// Length `L`.
    pub l: f64,
    /// Height `D`.
    pub d: f64,
    /// End load `P`.
    pub p: f64,
    /// Plane-stress Young's modulus (or `E/(1 − ν²)` for plane strain).
    pub e: f64,
    /// Plane-stress Poisson ratio (or `ν/(1 − ν)` for plane strain).
    pub nu: f64,
}

impl Beam {
    /// Second moment of area.
    pub fn inertia(&self) -> f64 {
        self.d.powi(3) / 12.0
    }
    /// The exact displacement.
    pub fn displacement(&self) -> VecFn<2> {
        let b = *self;
        let k = b.p / (6.0 * b.e * b.inertia());
        Arc::new(move |x: &Point<2>| {
            let (x, y) = (x[0], x[1]);
            let d2 = b.d * b.d;
            Point::<2>::new(
                -k * y * ((6.0 * b.l - 3.0 * x) * x + (2.0 + b.nu) * (y * y - d2 / 4.0)),
                k * (3.0 * b.nu * y * y * (b.l - x)
                    + (4.0 + 5.0 * b.nu) * d2 * x / 4.0
                    + (3.0 * b.l - x) * x * x),
            )
        })
    }
    /// The exact tip deflection `u_y(L, 0)`.
    pub fn tip(&self) -> f64 {
        self.displacement()(&Point::<2>::new(self.l, 0.0))[1]
    }
    /// The end traction on `x = L`.
    pub fn end_traction(&self) -> [ScalarField; 2] {
        let (p, i, d) = (self.p, self.inertia(), self.d);
        [
            ScalarField::Const(0.0),
            ScalarField::from_fn(move |x, _| p / (2.0 * i) * (d * d / 4.0 - x[1] * x[1])),
        ]
    }
    /// The grid box `[0, L] × [−D/2, D/2]`.
    pub fn box_corners(&self) -> (Point<2>, Point<2>) {
        (
            Point::<2>::new(0.0, -self.d / 2.0),
            Point::<2>::new(self.l, self.d / 2.0),
        )
    }
    /// Solve on `grid` (a grid of the box) with `laws`; returns the computed tip
    /// deflection (at the node at `(L, 0)`, which must exist) and the displacement.
    pub fn solve(&self, grid: &Grid<2>, laws: &LawMap<'_, 2>) -> (f64, Vec<f64>) {
        let exact = self.displacement();
        let bc = dirichlet("xmin", grid.boundary("xmin").unwrap(), &exact);
        let loads = Loads {
            tractions: vec![porofrac::sim::Traction {
                name: "xmax".into(),
                faces: grid.boundary("xmax").unwrap(),
                traction: self.end_traction(),
            }],
            ..Default::default()
        };
        let sol = solve(grid, laws, &[bc], &loads).unwrap();
        let tip = (0..grid.num_nodes())
            .find(|&n| (grid.node(n) - Point::<2>::new(self.l, 0.0)).norm() < 1e-9 * self.l)
            .expect("a node at (L, 0)");
        (sol.displacement[2 * tip + 1], sol.displacement)
    }
}
