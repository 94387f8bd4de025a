//! The discrete problem (21)–(22): elastic form (13), interior penalty (17), Nitsche terms
//! (18)–(20) and loads, assembled once into a [`BlockPattern`].
//!
//! **Elastic form.** At each quadrature point `q` of cell `K` the generalised strain is
//! `s_q = B_q W` with the gradient part `∂_j w_a = Σ_c g_{K,c,j} w_{c,a}` (eq. 11) and the
//! rotation coupling `e_ij += ε_ijk φ_{q,k}` (eq. 12). Two variants of `φ_q`
//! ([`StrainVariant`]): the cell value `φ_K` at one point of weight `|K|` (the DEM reading
//! of eq. 24), or the Crouzeix–Raviart value `φ_F` at each facet centroid with weight
//! `|K|/(D+1)` (the author's code). The cell matrix is `Σ_q w_q B_qᵀ A B_q` (`Rᵀ A R`).
//!
//! **Interior penalty (17).** On an interior facet `F = K⁻ ∩ K⁺` (normal from `K⁻` to `K⁺`)
//! `(η/h_F) ∫_F [w]ᵀ Q(n) [v]` with the jump of the P1 reconstructions (14),
//! `h_F` the mean diameter of the two cells, and a facet rule exact for quadratics
//! (2-point Gauss on segments, edge midpoints on triangles).
//!
//! **Nitsche (18)–(20)**, penalty-free and non-symmetric, on each fixed component `k` of a
//! boundary facet `F ⊂ ∂K`: `−|F| (Σ̄_K(W) n)_k v_{F,k} + |F| (Σ̄_K(V) n)_k w_{F,k}` and the
//! right-hand side `+|F| (Σ̄_K(V) n)_k ū_{D,k}` (`Σ̄_K` the cell's mean generalised stress,
//! `ū_D` the facet mean of the data).
//!
//! **Loads.** Volume loads are tested with the rotation/displacement of the same
//! quadrature as the strain (the consistent pairing, derived here so that the body-couple
//! patch test is exact: `Σ_q w_q f(x_q)·v_q`);
//! tractions with the facet values, `Σ_F |F| t̄·v_F`.
//!
//! The stiffness is kept in two value arrays on one pattern: the symmetric part (elastic +
//! penalty) whose quadratic form is the stored energy, and the Nitsche part.
//!
//! **Parallel assembly.** The cell and facet matrices are added by threads that own
//! disjoint ranges of column cells (contiguous in the value arrays): each walks all the
//! cells or facets in order and adds the columns it owns, so every entry receives its
//! contributions in the sequential order and the values are bitwise the same for any
//! number of threads. The penalty matrix of a facet is `M ⊗ Q(n)` (`M` over the cells,
//! `Q` over the components), added block by block.

use nalgebra::DMatrix;
use porofrac_grid::{Grid, Point};
use rayon::prelude::*;
use std::sync::Mutex;

use crate::conditions::{BodyLoads, Condition, Field, Slot};
use crate::error::{CosseratError, Result};
use crate::linear::{
    AUTO_GMRES_EQUATIONS, AUTO_SCHUR_UNKNOWNS, Linear, LinearOptions, LinearSolver, LinearStats,
    LowRankDifference, SchurAnalysis,
};
use crate::material::{Material, components, levi_civita, rotations, strain_index, strain_len};
use crate::pattern::{BlockPattern, SparseLu};
use crate::recon::{Reconstruction, StencilRule};

/// `γ` of the boundary penalty in [`Cosserat::preconditioner_values`]: of 1, 10, 30, 100
/// and 1000, 30 gave the fewest GMRES iterations on the plate with a hole (8,000 and 20,480
/// triangles, docs/BENCHMARKS.md).
pub const PRECONDITIONER_PENALTY: f64 = 30.0;

/// Where the rotation in the strain (12) is taken.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StrainVariant {
    /// Crouzeix–Raviart facet values at the facet centroids (the author's code, the
    /// reference variant).
    #[default]
    Facet,
    /// The cell value (the DEM reading of eq. 24).
    Cell,
}

/// Discretisation options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// η of the interior penalty (17); 1 in every case of the paper.
    pub penalty: f64,
    /// Strain variant of eq. (12).
    pub strain: StrainVariant,
    /// How the cells of each facet value are chosen (eqs. 8–10).
    pub stencil: StencilRule,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            penalty: 1.0,
            strain: StrainVariant::default(),
            stencil: StencilRule::default(),
        }
    }
}

/// A fixed component of a boundary facet: its Nitsche right-hand-side row.
#[derive(Clone, Debug)]
struct FixedTerm {
    face: usize,
    field: usize,
    /// `(equation, |F| (Σ̄(e_eq) n)_k)`.
    coef: Vec<(usize, f64)>,
    /// The facet value of the component, `(equation, stencil weight)`.
    trace: Vec<(usize, f64)>,
    /// The preconditioner's penalty coefficient `(|F|/h_K) Q_kk(n)` (times `γ` there).
    penalty: f64,
}

/// A loaded component of a boundary facet.
#[derive(Clone, Debug)]
struct LoadTerm {
    face: usize,
    field: usize,
    k: usize,
}

/// Quadrature on a facet: up to 3 points, weights summing to 1.
pub fn facet_rule<const D: usize>(grid: &Grid<D>, f: usize) -> ([Point<D>; 3], [f64; 3], usize) {
    let nodes = grid.face_nodes(f);
    let mut p = [Point::<D>::zeros(); 3];
    if D == 2 {
        let (a, b) = (grid.node(nodes[0]), grid.node(nodes[1]));
        let mid = (a + b) * 0.5;
        let half = (b - a) * (0.5 / 3f64.sqrt());
        p[0] = mid - half;
        p[1] = mid + half;
        (p, [0.5, 0.5, 0.0], 2)
    } else {
        let v = [
            grid.node(nodes[0]),
            grid.node(nodes[1]),
            grid.node(nodes[2]),
        ];
        for k in 0..3 {
            p[k] = (v[k] + v[(k + 1) % 3]) * 0.5;
        }
        (p, [1.0 / 3.0; 3], 3)
    }
}

/// The assembled Cosserat DEM problem on a simplex grid.
pub struct Cosserat<const D: usize> {
    grid: Grid<D>,
    material: Material,
    options: Options,
    recon: Reconstruction<D>,
    law: DMatrix<f64>,
    pattern: BlockPattern,
    /// Elastic + penalty values (symmetric).
    symmetric: Vec<f64>,
    /// Nitsche values (zero outside the columns of `nitsche_cells`).
    nitsche: Vec<f64>,
    /// The cells whose columns hold Nitsche values (sorted).
    nitsche_cells: Vec<usize>,
    /// Boundary penalty of the preconditioner: `(value position, value)`.
    boundary: Vec<(usize, f64)>,
    fields: Vec<Field<D>>,
    fixed: Vec<FixedTerm>,
    loads: Vec<LoadTerm>,
    body: BodyLoads<D>,
    /// The symbolic analysis of the Schur complement solve, prepared during the assembly
    /// and taken by the first [`Self::linear`].
    prepared: Mutex<Option<SchurAnalysis>>,
    /// The system and preconditioning values, computed beside that analysis (while it
    /// allocates the factors) and taken by the first [`Self::system_values`] and
    /// [`Self::preconditioner_values`].
    prepared_values: Mutex<PreparedValues>,
}

/// The values of a static solve computed during [`Cosserat::new`], each taken once.
#[derive(Default)]
struct PreparedValues {
    system: Option<Vec<f64>>,
    preconditioner: Option<Vec<f64>>,
}

impl<const D: usize> std::fmt::Debug for Cosserat<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cosserat")
            .field("cells", &self.grid.num_cells())
            .field("equations", &self.pattern.equations())
            .field("nnz", &self.pattern.nnz())
            .finish()
    }
}

/// One local matrix over the sorted `cells`: the dense column-major matrix `k` over their
/// components, or, when `q` is not empty, `k ⊗ q` with `k` over the cells and `q` over
/// the components ([`BlockPattern::add_local_columns`]).
#[derive(Default)]
struct Local {
    cells: Vec<usize>,
    k: Vec<f64>,
    q: Vec<f64>,
}

/// [`Material::acoustic`] into `q` (column-major, `n × n`), without allocating.
fn acoustic_into(law: &DMatrix<f64>, d: usize, normal: &[f64], q: &mut [f64]) {
    let c = components(d);
    for b in 0..c {
        for a in 0..c {
            let mut v = 0.0;
            for j in 0..d {
                for l in 0..d {
                    v +=
                        normal[j] * law[(strain_index(d, a, j), strain_index(d, b, l))] * normal[l];
                }
            }
            q[b * c + a] = v;
        }
    }
}

/// Scratch buffers of the local assembly (reused across cells and facets).
#[derive(Default)]
struct Scratch {
    cells: Vec<usize>,
    b: Vec<f64>,
    ab: Vec<f64>,
    k: Vec<f64>,
    bbar: Vec<f64>,
    beta: Vec<f64>,
}

/// The system values: the symmetric part plus the Nitsche part, which is zero outside
/// the columns of the cells `nitsche_cells`.
fn system_values(
    pattern: &BlockPattern,
    symmetric: &[f64],
    nitsche: &[f64],
    nitsche_cells: &[usize],
) -> Vec<f64> {
    let mut v = symmetric.to_vec();
    for q in nitsche_cells
        .iter()
        .flat_map(|&c| pattern.col_ptr[c * pattern.block]..pattern.col_ptr[(c + 1) * pattern.block])
    {
        v[q] += nitsche[q];
    }
    v
}

/// The preconditioning values: the symmetric part plus the boundary penalty.
fn preconditioner_values(symmetric: &[f64], boundary: &[(usize, f64)]) -> Vec<f64> {
    let mut p = symmetric.to_vec();
    for &(pos, v) in boundary {
        p[pos] += PRECONDITIONER_PENALTY * v;
    }
    p
}

impl<const D: usize> Cosserat<D> {
    /// Build the reconstruction, the pattern and the matrices.
    ///
    /// Errors: non-simplex cells, facets without stencil, `penalty ≤ 0` or non-finite,
    /// conditions on interior faces, a component fixed and loaded on one face, or fixed or
    /// loaded twice.
    pub fn new(
        grid: Grid<D>,
        material: Material,
        options: Options,
        conditions: &[Condition<D>],
        body: BodyLoads<D>,
    ) -> Result<Self> {
        if !(options.penalty.is_finite() && options.penalty > 0.0) {
            return Err(CosseratError::Input {
                what: format!("penalty η = {} must be positive", options.penalty),
            });
        }
        let n = components(D);
        if body.fields.len() != n {
            return Err(CosseratError::Input {
                what: format!("body loads: {} components, want {n}", body.fields.len()),
            });
        }
        let recon = Reconstruction::with_rule(&grid, options.stencil)?;
        let law = material.law_matrix(D);
        let nbr = neighbours(&grid, &recon);
        let pattern = BlockPattern::new(&nbr, n);
        let mut me = Self {
            symmetric: vec![0.0; pattern.nnz()],
            nitsche: vec![0.0; pattern.nnz()],
            nitsche_cells: Vec::new(),
            boundary: Vec::new(),
            grid,
            material,
            options,
            recon,
            law,
            pattern,
            fields: Vec::new(),
            fixed: Vec::new(),
            loads: Vec::new(),
            body,
            prepared: Mutex::new(None),
            prepared_values: Mutex::new(PreparedValues::default()),
        };
        me.assemble_conditions(conditions)?;
        // The symbolic analysis of the solve the automatic choice takes needs only the
        // pattern and the boundary difference (from the Nitsche terms above): it runs
        // beside the assembly.
        // The values of the static solve are computed on the assembling thread after the
        // assembly, while the other one still allocates the factors.
        let border = me.schur_border(LinearSolver::Auto);
        let static_candidate = border.is_some();
        let mut values = std::mem::take(&mut me.symmetric);
        let (prepared, static_values) = rayon::join(
            || border.and_then(|e| SchurAnalysis::bordered(&me.pattern, &e, true).ok()),
            || {
                // Touch the fresh pages once, on one thread: page faults taken by two
                // threads at once doubled the time of the cell assembly (measured).
                values.fill(0.0);
                me.assemble_cells(&mut values);
                me.assemble_penalty(&mut values);
                static_candidate.then(|| {
                    (
                        system_values(&me.pattern, &values, &me.nitsche, &me.nitsche_cells),
                        preconditioner_values(&values, &me.boundary),
                    )
                })
            },
        );
        me.symmetric = values;
        me.prepared = Mutex::new(prepared);
        if let Some((system, preconditioner)) = static_values {
            me.prepared_values = Mutex::new(PreparedValues {
                system: Some(system),
                preconditioner: Some(preconditioner),
            });
        }
        Ok(me)
    }

    /// The grid.
    pub fn grid(&self) -> &Grid<D> {
        &self.grid
    }
    /// The material.
    pub fn material(&self) -> &Material {
        &self.material
    }
    /// The options.
    pub fn options(&self) -> Options {
        self.options
    }
    /// The reconstruction.
    pub fn reconstruction(&self) -> &Reconstruction<D> {
        &self.recon
    }
    /// The pattern.
    pub fn pattern(&self) -> &BlockPattern {
        &self.pattern
    }
    /// Values of the symmetric part (elastic + penalty).
    pub fn symmetric_values(&self) -> &[f64] {
        &self.symmetric
    }
    /// Values of the Nitsche part.
    pub fn nitsche_values(&self) -> &[f64] {
        &self.nitsche
    }
    /// Values of the symmetric positive definite matrix that preconditions the system:
    /// the symmetric part plus a boundary penalty `γ (|F|/h_K) Q_kk(n) w_{F,k} v_{F,k}`
    /// (`γ` = [`PRECONDITIONER_PENALTY`]) on
    /// every fixed component (it removes the rigid motions from the kernel of the
    /// symmetric part; the system itself has no penalty).
    pub fn preconditioner_values(&self) -> Vec<f64> {
        let prepared = self
            .prepared_values
            .lock()
            .ok()
            .and_then(|mut v| v.preconditioner.take());
        prepared.unwrap_or_else(|| preconditioner_values(&self.symmetric, &self.boundary))
    }
    /// Drop what [`Self::new`] prepared for a first static solve (the analysis and the
    /// value arrays) when it will not be used (dynamics).
    pub(crate) fn release_prepared(&self) {
        if let Ok(mut p) = self.prepared.lock() {
            p.take();
        }
        if let Ok(mut v) = self.prepared_values.lock() {
            *v = PreparedValues::default();
        }
    }
    /// Values of the full system matrix (symmetric + Nitsche).
    pub fn system_values(&self) -> Vec<f64> {
        let prepared = self
            .prepared_values
            .lock()
            .ok()
            .and_then(|mut v| v.system.take());
        prepared.unwrap_or_else(|| {
            system_values(
                &self.pattern,
                &self.symmetric,
                &self.nitsche,
                &self.nitsche_cells,
            )
        })
    }
    /// The difference between the system and the preconditioning matrix,
    /// [`Self::system_values`] − [`Self::preconditioner_values`] (also between the Newmark
    /// matrices, which add the same mass to both), as a sum of rank-two terms, one per
    /// fixed component `k` of a boundary facet `F`:
    ///
    /// ```text
    ///   K − P = Σ_(F,k)  c wᵀ − w cᵀ − γ p w wᵀ  =  Σ_(F,k) [w c] [[−γ p, −1], [1, 0]] [w c]ᵀ
    /// ```
    ///
    /// with `w` the facet value of component `k` (the stencil weights), `c = |F| T_k` the
    /// Nitsche traction row of the facet's cell and `p = (|F|/h_K) Q_kk(n)`, `γ` =
    /// [`PRECONDITIONER_PENALTY`].
    pub fn boundary_difference(&self) -> LowRankDifference {
        let mut columns = Vec::with_capacity(2 * self.fixed.len());
        let mut blocks = Vec::with_capacity(self.fixed.len());
        for ft in &self.fixed {
            columns.push(ft.trace.clone());
            columns.push(ft.coef.clone());
            blocks.push([-PRECONDITIONER_PENALTY * ft.penalty, 1.0, -1.0, 0.0]);
        }
        LowRankDifference { columns, blocks }
    }
    /// Number of unknowns.
    pub fn equations(&self) -> usize {
        self.pattern.equations()
    }
    /// The law matrix `A`.
    pub fn law(&self) -> &DMatrix<f64> {
        &self.law
    }

    /// Quadrature of cell `c`: `(weight, point, rotation source)`, the source a facet or
    /// the cell itself (`None`).
    fn quadrature(&self, c: usize, mut visit: impl FnMut(f64, &Point<D>, Option<usize>)) {
        let vol = self.grid.cell_volume(c);
        match self.options.strain {
            StrainVariant::Cell => visit(vol, self.grid.cell_centroid(c), None),
            StrainVariant::Facet => {
                let w = vol / (D + 1) as f64;
                for &f in self.grid.cell_faces(c) {
                    visit(w, self.grid.face_centroid(f), Some(f));
                }
            }
        }
    }

    /// Fill `b` (row-major `S × m`, `m = cells.len()·n`) with `B_q` of cell `c` for the
    /// rotation source `src` (accumulated with factor `scale`).
    fn add_strain_operator(
        &self,
        c: usize,
        cells: &[usize],
        src: Option<usize>,
        scale: f64,
        b: &mut [f64],
    ) {
        let n = components(D);
        let m = cells.len() * n;
        let (gc, gg) = self.recon.gradient(c);
        for (&cc, g) in gc.iter().zip(gg) {
            let l = cells
                .binary_search(&cc)
                .expect("stencil cell in local list");
            for a in 0..n {
                for j in 0..D {
                    b[strain_index(D, a, j) * m + l * n + a] += scale * g[j];
                }
            }
        }
        let mut rot = |cc: usize, r: f64| {
            let l = cells
                .binary_search(&cc)
                .expect("stencil cell in local list");
            for i in 0..D {
                for j in 0..D {
                    for k in 0..rotations(D) {
                        let e = levi_civita(D, i, j, k);
                        if e != 0.0 {
                            b[strain_index(D, i, j) * m + l * n + D + k] += scale * e * r;
                        }
                    }
                }
            }
        };
        match src {
            None => rot(c, 1.0),
            Some(f) => {
                let st = &self.recon.facets[f];
                for (&cc, &l) in st.cells.iter().zip(&st.weights) {
                    rot(cc, l);
                }
            }
        }
    }

    /// Mean strain operator `B̄_K = (1/|K|) Σ_q w_q B_q` over `recon.gradient(c)` cells.
    fn mean_operator(&self, c: usize, s: &mut Scratch) {
        let n = components(D);
        s.cells.clear();
        s.cells.extend_from_slice(self.recon.gradient(c).0);
        let m = s.cells.len() * n;
        s.bbar.clear();
        s.bbar.resize(strain_len(D) * m, 0.0);
        let vol = self.grid.cell_volume(c);
        let cells = std::mem::take(&mut s.cells);
        let mut bbar = std::mem::take(&mut s.bbar);
        self.quadrature(c, |w, _, src| {
            self.add_strain_operator(c, &cells, src, w / vol, &mut bbar)
        });
        s.cells = cells;
        s.bbar = bbar;
    }

    fn assemble_cells(&self, values: &mut [f64]) {
        self.assemble_parallel(
            values,
            self.grid.num_cells(),
            |c, cols| self.recon.gradient(c).0.iter().any(|x| cols.contains(x)),
            |c, s, local| self.cell_local(c, s, local),
        );
    }

    fn assemble_penalty(&self, values: &mut [f64]) {
        self.assemble_parallel(
            values,
            self.grid.num_faces(),
            |f, cols| match self.grid.face_cells(f) {
                (km, Some(kp)) => [km, kp]
                    .iter()
                    .any(|&k| self.recon.gradient(k).0.iter().any(|x| cols.contains(x))),
                _ => false,
            },
            |f, s, local| self.penalty_local(f, s, local),
        );
    }

    /// The difference between the system and the preconditioning matrix
    /// ([`Self::boundary_difference`]) when `solver` takes the Schur complement solve:
    /// [`LinearSolver::LdltSchur`], or [`LinearSolver::Auto`] in 2D below
    /// [`AUTO_GMRES_EQUATIONS`] equations with at most [`AUTO_SCHUR_UNKNOWNS`] columns.
    fn schur_border(&self, solver: LinearSolver) -> Option<LowRankDifference> {
        let n = self.pattern.equations();
        let columns = 2 * self.fixed.len();
        let auto = D == 2 && n < AUTO_GMRES_EQUATIONS && columns <= AUTO_SCHUR_UNKNOWNS;
        let taken = match solver {
            LinearSolver::LdltSchur => true,
            LinearSolver::Auto => auto,
            _ => false,
        };
        (taken && columns > 0).then(|| self.boundary_difference())
    }

    /// Add the local matrices of items `0..count` (cells or facets; `local` fills one)
    /// into `values`, in parallel: each thread owns a range of column cells (contiguous in
    /// `values`, about equal in size) and walks every item in order, computing the local
    /// matrix of those that `touches` its columns and adding their part in its columns.
    /// Every entry receives its contributions in item order, so the sums are bitwise those
    /// of a sequential assembly for any thread count; an item that straddles two ranges
    /// is computed twice (few: the cells of a stencil are neighbours).
    fn assemble_parallel<T, F>(&self, values: &mut [f64], count: usize, touches: T, local: F)
    where
        T: Fn(usize, &std::ops::Range<usize>) -> bool + Sync,
        F: Fn(usize, &mut Scratch, &mut Local) + Sync,
    {
        let p = &self.pattern;
        let nb = p.block * p.block;
        let nc = p.nbr_pos.len() - 1;
        let parts = rayon::current_num_threads().clamp(1, nc.max(1));
        let mut chunks = Vec::with_capacity(parts);
        let mut rest = values;
        let mut lo = 0;
        for k in 1..=parts {
            let target = p.nbr_pos[nc] * k / parts;
            let hi = p.nbr_pos.partition_point(|&q| q < target).clamp(lo, nc);
            let (head, tail) = rest.split_at_mut((p.nbr_pos[hi] - p.nbr_pos[lo]) * nb);
            chunks.push((lo..hi, head));
            rest = tail;
            lo = hi;
        }
        chunks.into_par_iter().for_each(|(cols, chunk)| {
            let offset = p.nbr_pos[cols.start] * nb;
            let mut s = Scratch::default();
            let mut loc = Local::default();
            for item in (0..count).filter(|&i| touches(i, &cols)) {
                local(item, &mut s, &mut loc);
                p.add_local_columns(chunk, offset, cols.clone(), &loc.cells, &loc.k, &loc.q);
            }
        });
    }

    /// The local matrix of cell `c`: `Σ_q w_q B_qᵀ A B_q` over its gradient stencil.
    fn cell_local(&self, c: usize, s: &mut Scratch, local: &mut Local) {
        let n = components(D);
        let sl = strain_len(D);
        local.cells.clear();
        local.cells.extend_from_slice(self.recon.gradient(c).0);
        local.q.clear();
        let m = local.cells.len() * n;
        local.k.clear();
        local.k.resize(m * m, 0.0);
        self.quadrature(c, |w, _, src| {
            s.b.clear();
            s.b.resize(sl * m, 0.0);
            self.add_strain_operator(c, &local.cells, src, 1.0, &mut s.b);
            add_btab(&self.law, &s.b, w, m, &mut s.ab, &mut local.k);
        });
    }

    /// The local interior-penalty matrix of the interior facet `f`.
    fn penalty_local(&self, f: usize, s: &mut Scratch, local: &mut Local) {
        let n = components(D);
        let eta = self.options.penalty;
        let (km, Some(kp)) = self.grid.face_cells(f) else {
            unreachable!("interior facet");
        };
        let cells = &mut local.cells;
        cells.clear();
        cells.extend_from_slice(self.recon.gradient(km).0);
        cells.extend_from_slice(self.recon.gradient(kp).0);
        cells.sort_unstable();
        cells.dedup();
        let nl = cells.len();
        let normal = self.grid.face_normal(f);
        // The local matrix is M ⊗ Q: M = Σ_q (η/h) w_q |F| β_q β_qᵀ over the cells, Q(n)
        // over the components.
        let k = &mut local.k;
        k.clear();
        k.resize(nl * nl, 0.0);
        local.q.clear();
        local.q.resize(n * n, 0.0);
        acoustic_into(&self.law, D, normal.as_slice(), &mut local.q);
        let h = 0.5 * (self.recon.diameter[km] + self.recon.diameter[kp]);
        let area = self.grid.face_area(f);
        let (pts, wts, np) = facet_rule(&self.grid, f);
        for (x, &w) in pts.iter().zip(&wts).take(np) {
            s.beta.clear();
            s.beta.resize(nl, 0.0);
            for (sign, kk) in [(1.0, km), (-1.0, kp)] {
                let xk = self.grid.cell_centroid(kk);
                let (gc, gg) = self.recon.gradient(kk);
                for (&cc, g) in gc.iter().zip(gg) {
                    let l = cells.binary_search(&cc).unwrap();
                    s.beta[l] += sign * g.dot(&(x - xk));
                }
                let l = cells.binary_search(&kk).unwrap();
                s.beta[l] += sign;
            }
            let scale = eta / h * w * area;
            for (lj, &bj) in s.beta.iter().enumerate() {
                let f = scale * bj;
                for (kij, &bi) in k[lj * nl..(lj + 1) * nl].iter_mut().zip(&s.beta) {
                    *kij += f * bi;
                }
            }
        }
    }

    fn assemble_conditions(&mut self, conditions: &[Condition<D>]) -> Result<()> {
        let n = components(D);
        // Per face: the slot of each component and the condition that set it.
        let mut per_face: std::collections::BTreeMap<usize, Vec<(usize, usize, bool)>> =
            Default::default();
        for (ci, cond) in conditions.iter().enumerate() {
            if cond.slots.len() != n {
                return Err(CosseratError::Condition {
                    index: ci,
                    what: format!("{} components, want {n}", cond.slots.len()),
                });
            }
            let mut ids = vec![usize::MAX; n];
            for (k, slot) in cond.slots.iter().enumerate() {
                match slot {
                    Slot::Free => {}
                    Slot::Fixed(fld) | Slot::Load(fld) => {
                        ids[k] = self.fields.len();
                        self.fields.push(fld.clone());
                    }
                }
            }
            for &f in &cond.faces {
                if f >= self.grid.num_faces() || !self.grid.is_boundary_face(f) {
                    return Err(CosseratError::Condition {
                        index: ci,
                        what: format!("face {f} is not a boundary face"),
                    });
                }
                let entry = per_face.entry(f).or_default();
                for (k, slot) in cond.slots.iter().enumerate() {
                    let fixed = match slot {
                        Slot::Free => continue,
                        Slot::Fixed(_) => true,
                        Slot::Load(_) => false,
                    };
                    if let Some(prev) = entry.iter().find(|e| e.0 == k) {
                        let what = if prev.2 == fixed {
                            "set twice"
                        } else {
                            "both fixed and loaded"
                        };
                        return Err(CosseratError::Condition {
                            index: ci,
                            what: format!("component {k} of face {f} is {what}"),
                        });
                    }
                    entry.push((k, ids[k], fixed));
                }
            }
        }
        let mut s = Scratch::default();
        let mut values = std::mem::take(&mut self.nitsche);
        for (&f, slots) in &per_face {
            let c = self.grid.face_cells(f).0;
            let area = self.grid.face_area(f);
            let normal = *self.grid.face_normal(f); // outward on the boundary
            self.mean_operator(c, &mut s);
            let m = s.cells.len() * n;
            let st = self.recon.facets[f].clone();
            let mut any_fixed = false;
            s.k.clear();
            s.k.resize(m * m, 0.0);
            for &(k, field, fixed) in slots {
                if !fixed {
                    self.loads.push(LoadTerm { face: f, field, k });
                    continue;
                }
                any_fixed = true;
                // T_k[ρ] = Σ_j n_j (A B̄)[idx(k, j), ρ].
                let mut t = vec![0.0; m];
                for j in 0..D {
                    let row = strain_index(D, k, j);
                    for sidx in 0..strain_len(D) {
                        let a = self.law[(row, sidx)] * normal[j];
                        if a == 0.0 {
                            continue;
                        }
                        for (tr, bv) in t.iter_mut().zip(&s.bbar[sidx * m..(sidx + 1) * m]) {
                            *tr += a * bv;
                        }
                    }
                }
                for (&cc, &l) in st.cells.iter().zip(&st.weights) {
                    let lc = s.cells.binary_search(&cc).unwrap() * n + k;
                    for rho in 0..m {
                        // −|F| λ_c T_k[ρ] at (row (cc,k), col ρ); +|F| T_k[ρ] λ_c at (ρ, (cc,k)).
                        s.k[rho * m + lc] -= area * l * t[rho];
                        s.k[lc * m + rho] += area * l * t[rho];
                    }
                }
                // Preconditioner only: (|F|/h) Q_kk(n) w_{F,k} v_{F,k}, symmetric positive.
                let q = Material::acoustic(&self.law, D, normal.as_slice())[(k, k)];
                let pen = area / self.recon.diameter[c] * q;
                for (&cj, &lj) in st.cells.iter().zip(&st.weights) {
                    let col = self.pattern.column_len(cj);
                    for (&ci, &li) in st.cells.iter().zip(&st.weights) {
                        let pos = self.pattern.position(ci, cj).expect("stencil cells couple");
                        self.boundary.push((pos + k * col + k, pen * li * lj));
                    }
                }
                let coef = s
                    .cells
                    .iter()
                    .enumerate()
                    .flat_map(|(li, &cc)| (0..n).map(move |a| (li, cc, a)))
                    .filter_map(|(li, cc, a)| {
                        let v = area * t[li * n + a];
                        (v != 0.0).then_some((cc * n + a, v))
                    })
                    .collect();
                let trace = st
                    .cells
                    .iter()
                    .zip(&st.weights)
                    .map(|(&cc, &l)| (cc * n + k, l))
                    .collect();
                self.fixed.push(FixedTerm {
                    face: f,
                    field,
                    coef,
                    trace,
                    penalty: pen,
                });
            }
            if any_fixed {
                self.pattern.add_local(&mut values, &s.cells, &s.k);
                self.nitsche_cells.extend_from_slice(&s.cells);
            }
        }
        self.nitsche = values;
        self.nitsche_cells.sort_unstable();
        self.nitsche_cells.dedup();
        Ok(())
    }

    /// Mean over facet `f` of field `i` at time `t`.
    fn facet_mean(&self, f: usize, i: usize, t: f64) -> f64 {
        let (p, w, np) = facet_rule(&self.grid, f);
        (0..np).map(|q| w[q] * (self.fields[i])(&p[q], t)).sum()
    }

    /// The right-hand side at time `t`: volume loads, tractions and the Nitsche data.
    pub fn rhs(&self, t: f64, out: &mut [f64]) {
        let n = components(D);
        out.fill(0.0);
        if !self.body.is_empty() {
            for c in 0..self.grid.num_cells() {
                self.quadrature(c, |w, x, src| {
                    for (k, fld) in self.body.fields.iter().enumerate() {
                        let Some(fld) = fld else { continue };
                        let v = w * fld(x, t);
                        // Displacements are always tested with the same source as the
                        // rotation (consistent pairing of the variant).
                        match src {
                            None => out[c * n + k] += v,
                            Some(f) => {
                                let st = &self.recon.facets[f];
                                for (&cc, &l) in st.cells.iter().zip(&st.weights) {
                                    out[cc * n + k] += v * l;
                                }
                            }
                        }
                    }
                });
            }
        }
        for lt in &self.loads {
            let v = self.grid.face_area(lt.face) * self.facet_mean(lt.face, lt.field, t);
            let st = &self.recon.facets[lt.face];
            for (&cc, &l) in st.cells.iter().zip(&st.weights) {
                out[cc * n + lt.k] += v * l;
            }
        }
        for ft in &self.fixed {
            let v = self.facet_mean(ft.face, ft.field, t);
            for &(e, a) in &ft.coef {
                out[e] += a * v;
            }
        }
    }

    /// Solve the static problem at time `t` with a fresh LU.
    pub fn solve_static(&self, t: f64) -> Result<Vec<f64>> {
        let mut lu = SparseLu::new(&self.pattern)?;
        lu.factorize(&self.pattern, &self.system_values())?;
        let mut x = vec![0.0; self.equations()];
        self.rhs(t, &mut x);
        lu.solve_in_place(&mut x)?;
        Ok(x)
    }

    /// Cell barycentres, `D` per cell (the multigrid's rigid motions).
    pub fn centres(&self) -> Vec<f64> {
        (0..self.grid.num_cells())
            .flat_map(|c| {
                self.grid
                    .cell_centroid(c)
                    .iter()
                    .copied()
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    /// Set up the solver `options` for the system matrix with `values` (the system or
    /// the Newmark matrix) and the preconditioning matrix with `preconditioner`. The
    /// Schur complement solve takes their difference to be
    /// [`Self::boundary_difference`] (as for the system and the Newmark matrix, which adds
    /// the same mass to both); for other values it is an inexact preconditioner, and
    /// GMRES, which checks the true residual, needs more iterations.
    pub fn linear(
        &self,
        values: Vec<f64>,
        preconditioner: Vec<f64>,
        options: &LinearOptions,
    ) -> Result<Linear> {
        let centres = self.centres();
        let prepared = self.prepared.lock().ok().and_then(|mut p| p.take());
        // After the first solve (or for the Newmark matrix): a new analysis of the
        // bordered matrix when the solver takes it.
        let prepared = prepared.or_else(|| {
            self.schur_border(options.solver)
                .and_then(|e| SchurAnalysis::bordered(&self.pattern, &e, false).ok())
        });
        Linear::with_values(
            &self.pattern,
            values,
            preconditioner,
            &centres,
            D,
            options,
            prepared,
        )
    }

    /// Solve the static problem at time `t` with the solver `options`; also returns the
    /// solver's statistics.
    pub fn solve_static_with(
        &self,
        t: f64,
        options: &LinearOptions,
    ) -> Result<(Vec<f64>, LinearStats, LinearSolver)> {
        let mut solver =
            self.linear(self.system_values(), self.preconditioner_values(), options)?;
        let mut x = vec![0.0; self.equations()];
        self.rhs(t, &mut x);
        solver.solve(&mut x, None)?;
        Ok((x, solver.stats(), solver.solver()))
    }

    /// Mean generalised strain of cell `c` for the field `w` (length `strain_len(D)`).
    pub fn cell_strain(&self, c: usize, w: &[f64]) -> [f64; 18] {
        let n = components(D);
        let mut s = [0.0; 18];
        for a in 0..n {
            let g = self.recon.cell_gradient(c, w, n, a);
            for j in 0..D {
                s[strain_index(D, a, j)] = g[j];
            }
        }
        let vol = self.grid.cell_volume(c);
        let mut phi = [0.0; 3];
        self.quadrature(c, |wq, _, src| {
            for k in 0..rotations(D) {
                let v = match src {
                    None => w[c * n + D + k],
                    Some(f) => self.recon.facet_value(f, w, n, D + k),
                };
                phi[k] += wq / vol * v;
            }
        });
        for i in 0..D {
            for j in 0..D {
                for k in 0..rotations(D) {
                    s[strain_index(D, i, j)] += levi_civita(D, i, j, k) * phi[k];
                }
            }
        }
        s
    }

    /// Mean generalised stress `Σ̄ = A s̄` of cell `c`: `σ_ij` at `strain_index(i, j)`,
    /// `m_kj` at `strain_index(D + k, j)`.
    pub fn cell_stress(&self, c: usize, w: &[f64]) -> [f64; 18] {
        let s = self.cell_strain(c, w);
        let sl = strain_len(D);
        let mut out = [0.0; 18];
        for r in 0..sl {
            out[r] = (0..sl).map(|q| self.law[(r, q)] * s[q]).sum();
        }
        out
    }

    /// Stored energy `½ Wᵀ K_sym W` (elastic + penalty).
    pub fn energy(&self, w: &[f64]) -> f64 {
        0.5 * self.pattern.form(&self.symmetric, w, w)
    }
}

/// `K += w Bᵀ A B` with `B` row-major `S × m`, `K` column-major `m × m`.
fn add_btab(a: &DMatrix<f64>, b: &[f64], w: f64, m: usize, ab: &mut Vec<f64>, k: &mut [f64]) {
    let sl = a.nrows();
    ab.clear();
    ab.resize(sl * m, 0.0);
    for r in 0..sl {
        for q in 0..sl {
            let arq = a[(r, q)];
            if arq == 0.0 {
                continue;
            }
            let src = &b[q * m..(q + 1) * m];
            let dst = &mut ab[r * m..(r + 1) * m];
            for (d, s) in dst.iter_mut().zip(src) {
                *d += arq * s;
            }
        }
    }
    for r in 0..sl {
        let brow = &b[r * m..(r + 1) * m];
        let abrow = &ab[r * m..(r + 1) * m];
        for (i, &bi) in brow.iter().enumerate() {
            if bi == 0.0 {
                continue;
            }
            let f = w * bi;
            for (j, &abj) in abrow.iter().enumerate() {
                k[j * m + i] += f * abj;
            }
        }
    }
}

/// Cells coupled to each cell: the union of `grad(K')` over the elements containing it.
fn neighbours<const D: usize>(grid: &Grid<D>, recon: &Reconstruction<D>) -> Vec<Vec<usize>> {
    let nc = grid.num_cells();
    // Element groups per cell K: grad(K) and grad(K) ∪ grad(K') for every face neighbour.
    // c ∈ element(K) ⇒ nbr[c] ⊇ cells of element(K).
    let mut in_grad: Vec<Vec<usize>> = vec![Vec::new(); nc];
    for k in 0..nc {
        for &c in recon.gradient(k).0 {
            in_grad[c].push(k);
        }
    }
    let face_nb = |k: usize| {
        grid.cell_faces(k).iter().filter_map(move |&f| {
            let (a, b) = grid.face_cells(f);
            b.map(|b| if a == k { b } else { a })
        })
    };
    (0..nc)
        .into_par_iter()
        .map_init(Vec::new, |buf, c| {
            buf.clear();
            buf.push(c);
            for &k in &in_grad[c] {
                buf.extend_from_slice(recon.gradient(k).0);
                for k2 in face_nb(k) {
                    buf.extend_from_slice(recon.gradient(k2).0);
                }
            }
            buf.sort_unstable();
            buf.dedup();
            buf.clone()
        })
        .collect()
}
