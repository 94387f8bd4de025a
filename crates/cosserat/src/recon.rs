//! Facet reconstruction (eqs. 8–10), discrete Stokes gradients (11) and the cellwise P1
//! reconstruction (14).
//!
//! **Facet values.** For each facet `F` with centroid `x_F` we pick `D + 1` cells `S_F`
//! whose barycentres span a non-degenerate simplex and solve
//! `Σ λ_K = 1, Σ λ_K x_K = x_F` (10); then `w_F = Σ_{K∈S_F} λ_K w_K` (9) for every
//! component. The cells are chosen from a *pool* (Marazzato (2021) §3.1, eqs. 8–10):
//!
//! * interior facet: its two cells and their face neighbours (2D), every cell within graph
//!   distance 2 of either (3D, where smaller pools can be all-degenerate, Remark 4);
//! * boundary facet: the cells within graph distance `D` of its cell.
//!
//! The pool is sorted by distance of the barycentre to `x_F` (ties by cell id), so the
//! choice is deterministic, and capped at [`MAX_POOL`] cells. The `(D+1)`-subsets are
//! visited in lexicographic order; singular ones are skipped (`|det| < 1e-10 Π|edges|`).
//! On an interior facet the first subset with `max|λ| < 1` is accepted (the nearest cells
//! that interpolate `x_F`); otherwise the subset minimising `max|λ|` among those with
//! `max|λ| <` [`MAX_WEIGHT`]. A boundary facet extrapolates (`x_F` lies outside the hull
//! of the barycentres): by default ([`StencilRule::SmallestBoundaryWeight`]) it takes, in
//! 2D, the subset with the smallest `max|λ|` of all, which bounds how much the
//! extrapolation amplifies the cell values (in 3D the first with `max|λ| < 1`). If there
//! is no admissible subset, the pool is widened by one graph level (twice at most) and
//! then the facet is an error naming it (the first such facet by id).
//!
//! Two other rules are kept ([`StencilRule`]): the seed's reading (the first subset with
//! `max|λ| < 1` on boundary facets too) and the paper's wider pool with the smallest
//! `max|λ|` everywhere. All are exact for affine fields; what each costs in accuracy is
//! measured in docs/models/cosserat.md ("Which stencil").
//!
//! **Gradients.** `G_K(w) = (1/|K|) Σ_{F⊂∂K} |F| w_F ⊗ n_{K,F}` (11), exact for affine `w`
//! because `Σ_F |F| x_F ⊗ n_{K,F} = |K| I`. Substituting (9) gives the *gradient stencil*
//! `G_K(w) = Σ_c w_c ⊗ g_{K,c}` with `g_{K,c} = Σ_F (|F|/|K|) λ_{F,c} n_{K,F}`.
//!
//! **P1 reconstruction (14).** `w_K(x) = w_K + G_K(w)(x − x_K)`: the coefficient of cell `c`
//! is `δ_{cK} + g_{K,c}·(x − x_K)`, the same for every component.

use porofrac_grid::{Grid, Point};
use rayon::prelude::*;

use crate::error::{CosseratError, Result};

/// Largest admissible barycentric weight of a fallback stencil (Marazzato (2021) §3.1; the
/// best subset with max|λ| < 10).
pub const MAX_WEIGHT: f64 = 10.0;
/// Pool cap per dimension index (`[2D, 3D]`): the nearest cells are kept.
pub const MAX_POOL: [usize; 2] = [12, 16];

/// How the `D + 1` cells of a facet value are chosen from the pool.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StencilRule {
    /// Interior facets: the first subset, nearest cells first, with `max|λ| < 1`;
    /// boundary facets in 2D: the subset with the smallest `max|λ|` (the default: a
    /// smaller stress concentration error than the seed's rule on every plate mesh
    /// measured, and its shear-layer errors). In 3D the same as
    /// [`Self::FirstInterpolating`]: on the clamped beam of the dynamics tests the smallest
    /// boundary weight made the beam stiffer than the Cosserat bound of its period.
    #[default]
    SmallestBoundaryWeight,
    /// The seed's reading: the first subset with `max|λ| < 1` on every facet (else the
    /// smallest `max|λ|`).
    FirstInterpolating,
    /// The paper's pool for interior facets in 2D as well (graph distance 2 of the facet's
    /// cells: "repeat the last operation once") and the subset with the smallest `max|λ|`
    /// on every facet: wider stencils (about twice the matrix entries), a smaller
    /// stress concentration error on coarse plates but larger L2 errors on the shear layer.
    SmallestWeight,
}

/// One facet's reconstruction: `D + 1` cells and their barycentric weights.
#[derive(Clone, Debug, PartialEq)]
pub struct FacetStencil {
    /// The cells (sorted by id).
    pub cells: Vec<usize>,
    /// Their weights, `Σ = 1`, `Σ λ_c x_c = x_F`.
    pub weights: Vec<f64>,
}

/// Facet stencils of every face and gradient stencils of every cell.
#[derive(Clone, Debug)]
pub struct Reconstruction<const D: usize> {
    /// Stencil of each face (index = face id).
    pub facets: Vec<FacetStencil>,
    /// Offsets into `grad_cells` / `grad_coef`, one per cell plus one.
    pub grad_pos: Vec<usize>,
    /// Cells of the gradient stencil of each cell, sorted, including the cell itself.
    pub grad_cells: Vec<usize>,
    /// `g_{K,c}` aligned with `grad_cells`.
    pub grad_coef: Vec<Point<D>>,
    /// Diameter of each cell (largest vertex–vertex distance).
    pub diameter: Vec<f64>,
}

impl<const D: usize> Reconstruction<D> {
    /// Build the stencils of every facet and cell of a simplex grid with the default
    /// [`StencilRule`].
    ///
    /// Errors: a non-simplex cell ([`CosseratError::NotSimplex`]) or a facet without an
    /// admissible stencil ([`CosseratError::NoStencil`], naming the facet).
    pub fn new(grid: &Grid<D>) -> Result<Self> {
        Self::with_rule(grid, StencilRule::default())
    }

    /// Build the stencils of every facet and cell with the stencil rule `rule` (errors as
    /// [`Self::new`]).
    pub fn with_rule(grid: &Grid<D>, rule: StencilRule) -> Result<Self> {
        for c in 0..grid.num_cells() {
            let (nf, nn) = (grid.cell_faces(c).len(), grid.cell_nodes(c).len());
            if nf != D + 1 || nn != D + 1 {
                return Err(CosseratError::NotSimplex {
                    cell: c,
                    faces: nf,
                    nodes: nn,
                });
            }
        }
        let neighbours = neighbours(grid);
        // Facets are independent: in parallel, each thread with its own search scratch;
        // the error of the first failing facet by id, whatever the thread count.
        let facets = (0..grid.num_faces())
            .into_par_iter()
            .with_min_len(1024)
            .map_init(
                || Bfs::new(grid.num_cells()),
                |bfs, f| facet_stencil(grid, &neighbours, bfs, f, rule),
            )
            .collect::<Vec<_>>()
            .into_iter()
            .collect::<Result<Vec<_>>>()?;
        let mut grad_pos = vec![0];
        let mut grad_cells = Vec::new();
        let mut grad_coef = Vec::new();
        let mut local: Vec<(usize, Point<D>)> = Vec::new();
        for c in 0..grid.num_cells() {
            local.clear();
            local.push((c, Point::<D>::zeros()));
            let vol = grid.cell_volume(c);
            for (&f, &out) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
                let n = if out {
                    *grid.face_normal(f)
                } else {
                    -grid.face_normal(f)
                };
                let s = grid.face_area(f) / vol;
                let st = &facets[f];
                for (&cc, &l) in st.cells.iter().zip(&st.weights) {
                    local.push((cc, n * (s * l)));
                }
            }
            local.sort_by_key(|p| p.0);
            let start = grad_cells.len();
            for &(cc, g) in &local {
                if grad_cells.len() > start && *grad_cells.last().unwrap() == cc {
                    *grad_coef.last_mut().unwrap() += g;
                } else {
                    grad_cells.push(cc);
                    grad_coef.push(g);
                }
            }
            grad_pos.push(grad_cells.len());
        }
        let diameter = (0..grid.num_cells())
            .map(|c| {
                let nodes = grid.cell_nodes(c);
                let mut h: f64 = 0.0;
                for (i, &a) in nodes.iter().enumerate() {
                    for &b in &nodes[i + 1..] {
                        h = h.max((grid.node(a) - grid.node(b)).norm());
                    }
                }
                h
            })
            .collect();
        Ok(Self {
            facets,
            grad_pos,
            grad_cells,
            grad_coef,
            diameter,
        })
    }

    /// Gradient stencil of cell `c`: cells and `g_{K,c}`.
    pub fn gradient(&self, c: usize) -> (&[usize], &[Point<D>]) {
        let r = self.grad_pos[c]..self.grad_pos[c + 1];
        (&self.grad_cells[r.clone()], &self.grad_coef[r])
    }

    /// Reconstructed value of component `a` of a cell field `w` (stride `stride`) at facet `f`.
    pub fn facet_value(&self, f: usize, w: &[f64], stride: usize, a: usize) -> f64 {
        let s = &self.facets[f];
        s.cells
            .iter()
            .zip(&s.weights)
            .map(|(&c, &l)| l * w[c * stride + a])
            .sum()
    }

    /// Cell gradient `∂_j w_a` of component `a` of a cell field `w` (stride `stride`).
    pub fn cell_gradient(&self, c: usize, w: &[f64], stride: usize, a: usize) -> Point<D> {
        let (cells, g) = self.gradient(c);
        let mut out = Point::<D>::zeros();
        for (&cc, gc) in cells.iter().zip(g) {
            out += gc * w[cc * stride + a];
        }
        out
    }

    /// The P1 reconstruction (14) of component `a` in cell `c` at `x`.
    pub fn p1_value(
        &self,
        grid: &Grid<D>,
        c: usize,
        x: &Point<D>,
        w: &[f64],
        stride: usize,
        a: usize,
    ) -> f64 {
        w[c * stride + a]
            + self
                .cell_gradient(c, w, stride, a)
                .dot(&(x - grid.cell_centroid(c)))
    }

    /// Largest `|λ|` over all facet stencils (a conditioning indicator, Remark 5).
    pub fn max_weight(&self) -> f64 {
        self.facets
            .iter()
            .flat_map(|s| s.weights.iter())
            .fold(0.0f64, |m, w| m.max(w.abs()))
    }
}

/// Face neighbours of each cell.
fn neighbours<const D: usize>(grid: &Grid<D>) -> Vec<Vec<usize>> {
    let mut nb = vec![Vec::with_capacity(D + 1); grid.num_cells()];
    for f in 0..grid.num_faces() {
        if let (a, Some(b)) = grid.face_cells(f) {
            nb[a].push(b);
            nb[b].push(a);
        }
    }
    nb
}

/// Breadth-first search scratch (reused for every facet).
struct Bfs {
    mark: Vec<u32>,
    stamp: u32,
    out: Vec<usize>,
}

impl Bfs {
    fn new(n: usize) -> Self {
        Self {
            mark: vec![0; n],
            stamp: 0,
            out: Vec::new(),
        }
    }

    /// Cells within graph distance `depth` of `seeds`, into `self.out`.
    fn run(&mut self, nb: &[Vec<usize>], seeds: &[usize], depth: usize) {
        self.stamp += 1;
        self.out.clear();
        for &s in seeds {
            if self.mark[s] != self.stamp {
                self.mark[s] = self.stamp;
                self.out.push(s);
            }
        }
        let mut level = 0..self.out.len();
        for _ in 0..depth {
            let end = self.out.len();
            for i in level.clone() {
                let c = self.out[i];
                for &n in &nb[c] {
                    if self.mark[n] != self.stamp {
                        self.mark[n] = self.stamp;
                        self.out.push(n);
                    }
                }
            }
            level = end..self.out.len();
        }
    }
}

fn facet_stencil<const D: usize>(
    grid: &Grid<D>,
    nb: &[Vec<usize>],
    bfs: &mut Bfs,
    f: usize,
    rule: StencilRule,
) -> Result<FacetStencil> {
    let xf = *grid.face_centroid(f);
    let (a, b) = grid.face_cells(f);
    let interior = match rule {
        StencilRule::SmallestWeight => 2,
        _ if D == 2 => 1,
        _ => 2,
    };
    let first = match rule {
        StencilRule::SmallestWeight => false,
        StencilRule::FirstInterpolating => true,
        // 3D: the seed's rule (measured on the beam of tests/dynamics.rs, the smallest
        // weight on its boundary facets made it stiffer, below the Cosserat bound).
        StencilRule::SmallestBoundaryWeight => b.is_some() || D == 3,
    };
    let (seeds, depth): (Vec<usize>, usize) = match b {
        Some(b) => (vec![a, b], interior),
        None => (vec![a], D),
    };
    let cap = MAX_POOL[D - 2];
    let mut pool: Vec<usize> = Vec::with_capacity(4 * cap);
    for extra in 0..3 {
        bfs.run(nb, &seeds, depth + extra);
        pool.clear();
        pool.extend_from_slice(&bfs.out);
        pool.sort_by(|&p, &q| {
            let dp = (grid.cell_centroid(p) - xf).norm_squared();
            let dq = (grid.cell_centroid(q) - xf).norm_squared();
            dp.total_cmp(&dq).then(p.cmp(&q))
        });
        pool.truncate(cap);
        if let Some(s) = best_subset(grid, &pool, &xf, first) {
            return Ok(s);
        }
        if bfs.out.len() <= cap && extra > 0 && bfs.out.len() == pool.len() {
            // The whole connected component is already in the pool.
            break;
        }
    }
    Err(CosseratError::NoStencil {
        face: f,
        centroid: format!("{:?}", xf.as_slice()),
        need: D + 1,
        limit: MAX_WEIGHT,
        pool: pool.len(),
    })
}

/// Barycentric weights of `x` in the simplex of barycentres `cells`, or `None` if it is
/// degenerate.
pub fn barycentric<const D: usize>(
    grid: &Grid<D>,
    cells: &[usize],
    x: &Point<D>,
) -> Option<[f64; 4]> {
    let x0 = grid.cell_centroid(cells[0]);
    // Edge matrix E (columns x_c − x_0) in a row-major array, solved by Gaussian
    // elimination with partial pivoting; det E = ± Π pivots.
    let mut e = [[0.0f64; 4]; 3];
    let mut scale = 1.0;
    for k in 0..D {
        let col = grid.cell_centroid(cells[k + 1]) - x0;
        scale *= col.norm();
        for i in 0..D {
            e[i][k] = col[i];
        }
    }
    let r = x - x0;
    for i in 0..D {
        e[i][D] = r[i];
    }
    let mut det = 1.0;
    for p in 0..D {
        let piv = (p..D).max_by(|&a, &b| e[a][p].abs().total_cmp(&e[b][p].abs()))?;
        e.swap(p, piv);
        det *= e[p][p];
        if e[p][p] == 0.0 {
            return None;
        }
        for i in p + 1..D {
            let f = e[i][p] / e[p][p];
            for j in p..=D {
                e[i][j] -= f * e[p][j];
            }
        }
    }
    if det.is_nan() || det.abs() <= 1e-10 * scale {
        return None;
    }
    let mut l = [0.0f64; 3];
    for p in (0..D).rev() {
        let mut v = e[p][D];
        for j in p + 1..D {
            v -= e[p][j] * l[j];
        }
        l[p] = v / e[p][p];
    }
    let mut w = [0.0; 4];
    let mut s = 0.0;
    for k in 0..D {
        w[k + 1] = l[k];
        s += l[k];
    }
    w[0] = 1.0 - s;
    Some(w)
}

fn best_subset<const D: usize>(
    grid: &Grid<D>,
    pool: &[usize],
    xf: &Point<D>,
    first: bool,
) -> Option<FacetStencil> {
    let k = D + 1;
    let p = pool.len();
    if p < k {
        return None;
    }
    let mut idx: Vec<usize> = (0..k).collect();
    let mut cells = [0usize; 4];
    let mut best: Option<(f64, [usize; 4], [f64; 4])> = None;
    loop {
        for (s, &i) in idx.iter().enumerate() {
            cells[s] = pool[i];
        }
        if let Some(w) = barycentric(grid, &cells[..k], xf) {
            let m = w[..k].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if first && m < 1.0 {
                best = Some((m, cells, w));
                break;
            }
            if m < MAX_WEIGHT && best.as_ref().is_none_or(|b| m < b.0) {
                best = Some((m, cells, w));
            }
        }
        // Next combination in lexicographic order.
        let mut i = k;
        loop {
            if i == 0 {
                return best.map(|(_, c, w)| stencil(&c[..k], &w[..k]));
            }
            i -= 1;
            if idx[i] < p - k + i {
                break;
            }
        }
        idx[i] += 1;
        for j in i + 1..k {
            idx[j] = idx[j - 1] + 1;
        }
    }
    best.map(|(_, c, w)| stencil(&c[..k], &w[..k]))
}

fn stencil(cells: &[usize], w: &[f64]) -> FacetStencil {
    let mut pairs: Vec<(usize, f64)> = cells.iter().copied().zip(w.iter().copied()).collect();
    pairs.sort_by_key(|p| p.0);
    FacetStencil {
        cells: pairs.iter().map(|p| p.0).collect(),
        weights: pairs.iter().map(|p| p.1).collect(),
    }
}
