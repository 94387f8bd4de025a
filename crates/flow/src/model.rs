//! The assembled TPFA flow model and its time stepping.
//!
//! With cell pressures `p`, implicit Euler from `t^n` to `t^{n+1} = t^n + Δt` solves, for
//! every cell `K` (Nilsen et al. (2017) eq. 29 with `S_c = S_K`),
//!
//! ```text
//!   |K| S_K (p_K − p_K^n)/Δt + Σ_{f interior} T_f/μ (p_K − p_L) + Σ_{f Dirichlet} T_f/μ (p_K − p_b)
//!     + Σ_{f Neumann} u_f A_f + Σ_{wells, BHP} WI/μ (p_K − p_bh) = Q_K + Σ_{wells, rate} q_w ,
//! ```
//!
//! i.e. `(M/Δt + A) p^{n+1} = M/Δt p^n + b(t^{n+1})` with
//!
//! * `M = diag(|K| S_K)` — [`FlowModel::accumulation`];
//! * `A` — [`FlowModel::flux_matrix`]: the symmetric TPFA matrix `T/μ` plus the Dirichlet
//!   and bottom-hole-pressure well terms on its diagonal; `A` is symmetric positive
//!   semi-definite and `M/Δt + A` is positive definite when every connected region has
//!   storage or a pressure anchor, so a sparse Cholesky factorization is used;
//! * `b(t)` — [`FlowModel::forcing`]: sources, Dirichlet and well pressures, Neumann fluxes.
//!
//! A Biot coupling (Nilsen et al. (2017) eq. 30) adds `α div_d (u^{n+1} − u^n)` to the left-hand
//! side of each cell equation (times `1/Δt` in this scaling) and the block `−α div_dᵀ` to the
//! mechanics; it can be assembled from these public pieces without touching this crate.
//!
//! The matrix pattern (cells and their face neighbours) is built once; the symbolic
//! Cholesky factorization is computed on the first solve and reused for every later step;
//! the numeric factorization is reused as long as `Δt` and the transmissibilities do not
//! change. The steady (incompressible) problem `A p = b` is [`FlowModel::solve_steady`].
//!
//! Gravity is not included.

use faer::Side;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use porofrac_grid::{Grid, NO_CELL, Point};
use porofrac_sparse::{Cholesky, CholeskyError};
use rayon::prelude::*;

use crate::error::{FlowError, Result, cell_err};
use crate::perm::Permeability;
use crate::problem::{BoundaryKind, FlowProblem, ScalarField, SourceRate, WellControl};
use crate::trans::Transmissibilities;
use crate::well::peaceman_well_index;

/// A boundary face with a condition.
#[derive(Clone, Debug)]
struct BcFace<const D: usize> {
    face: usize,
    cell: usize,
    bc: usize,
    x: Point<D>,
    /// `T_f/μ` for a pressure condition, `A_f` for a flux condition.
    coeff: f64,
}

/// A well after validation.
#[derive(Clone, Debug)]
struct WellData {
    name: String,
    cell: usize,
    radius: f64,
    skin: f64,
    override_wi: Option<f64>,
    control: WellControl,
    /// Geometric well index (m³), without viscosity.
    wi: f64,
}

/// The result of a time step or a steady solve.
#[derive(Clone, Debug, PartialEq)]
pub struct StepResult {
    /// Cell pressures at the new time (Pa).
    pub pressure: Vec<f64>,
    /// Volumetric flux through each face (m³/s; m²/s in 2D) along the face normal, i.e.
    /// from [`Grid::face_cells`]`.0` to `.1`; on boundary faces this is the outflow.
    pub face_flux: Vec<f64>,
    /// Rate of each well (m³/s), positive for injection, in the order of the problem's wells.
    pub well_rate: Vec<f64>,
    /// Bottom-hole pressure of each well (Pa).
    pub well_bhp: Vec<f64>,
}

/// A TPFA single-phase flow model on a fixed grid.
pub struct FlowModel<const D: usize> {
    volumes: Vec<f64>,
    porosity: Vec<f64>,
    storage: Vec<f64>,
    accumulation: Vec<f64>,
    viscosity: f64,
    trans: Transmissibilities,
    /// Transmissibility multipliers, applied whenever the transmissibilities are computed.
    multipliers: Vec<(Vec<usize>, f64)>,
    pattern: SymbolicSparseColMat<usize>,
    diag_pos: Vec<usize>,
    face_pos: Vec<[usize; 2]>,
    flux_vals: Vec<f64>,
    dirichlet: Vec<BcFace<D>>,
    neumann: Vec<BcFace<D>>,
    bc_values: Vec<ScalarField>,
    source_cell_rate: Vec<f64>,
    source_names: Vec<String>,
    source_totals: Vec<f64>,
    wells: Vec<WellData>,
    /// Connected regions without a pressure anchor: (a cell of the region, whether the
    /// region has storage).
    floating: Vec<(usize, bool)>,
    /// The Cholesky factorization of `M/Δt + A` (analysed on the first solve) and the
    /// `1/Δt` of its numeric factors (`None`: not factorized).
    cholesky: Option<Cholesky>,
    factored_inv_dt: Option<f64>,
    sys_vals: Vec<f64>,
    linear: FlowLinearSolver,
    /// CG-AMG: the hierarchy and the `1/Δt` it was built for.
    amg: Option<(f64, porofrac_amg::Amg)>,
    cg_iterations: usize,
}

/// How the pressure systems `M/Δt + A` (symmetric positive definite) are solved.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum FlowLinearSolver {
    /// Sparse Cholesky, the symbolic factorization kept, the numeric one per `Δt`.
    #[default]
    Cholesky,
    /// Conjugate gradients preconditioned by smoothed-aggregation AMG (constant near-null
    /// space, `porofrac-amg`) to the relative residual `tolerance`, from the old pressure;
    /// the hierarchy is rebuilt numerically when `Δt` or the permeability changes.
    CgAmg {
        /// Relative residual.
        tolerance: f64,
    },
}

impl<const D: usize> FlowModel<D> {
    /// Validate `problem` against `grid` and assemble the time-independent parts.
    pub fn new(grid: &Grid<D>, problem: &FlowProblem<D>) -> Result<Self> {
        let n = grid.num_cells();
        let rock = &problem.rock;
        let fluid = &problem.fluid;
        check_len("porosity", rock.porosity.len(), n)?;
        check_len("biot_alpha", rock.biot_alpha.len(), n)?;
        if !(fluid.viscosity.is_finite() && fluid.viscosity > 0.0) {
            return Err(FlowError::Fluid {
                property: "viscosity",
                what: format!("must be finite and > 0, got {}", fluid.viscosity),
            });
        }
        if !(fluid.compressibility.is_finite() && fluid.compressibility >= 0.0) {
            return Err(FlowError::Fluid {
                property: "compressibility",
                what: format!("must be finite and ≥ 0, got {}", fluid.compressibility),
            });
        }
        let ks = rock.solid_bulk_modulus;
        if ks.is_nan() || ks <= 0.0 {
            return Err(FlowError::Rock {
                property: "solid_bulk_modulus",
                what: format!("K_s must be > 0 (or ∞), got {ks}"),
            });
        }
        let mut storage = Vec::with_capacity(n);
        for c in 0..n {
            let phi = rock.porosity[c];
            if !(phi > 0.0 && phi <= 1.0) {
                return Err(cell_err(
                    c,
                    format!("porosity must be in (0, 1], got {phi}"),
                ));
            }
            let alpha = rock.biot_alpha[c];
            if !(alpha.is_finite() && (0.0..=1.0).contains(&alpha)) {
                return Err(cell_err(
                    c,
                    format!("Biot coefficient must be in [0, 1], got {alpha}"),
                ));
            }
            if ks.is_finite() && alpha < phi {
                return Err(cell_err(
                    c,
                    format!(
                        "Biot coefficient α = {alpha} < porosity φ = {phi} gives negative storage"
                    ),
                ));
            }
            let grain = if ks.is_finite() {
                (alpha - phi) / ks
            } else {
                0.0
            };
            storage.push(phi * fluid.compressibility + grain);
        }
        let volumes = grid.cell_volumes().to_vec();
        let accumulation = volumes.iter().zip(&storage).map(|(v, s)| v * s).collect();
        for (faces, m) in &problem.transmissibility_multipliers {
            if !(m.is_finite() && *m >= 0.0) {
                return Err(FlowError::Face {
                    face: faces.first().copied().unwrap_or(0),
                    what: format!("transmissibility multiplier {m} is not a finite number ≥ 0"),
                });
            }
            if let Some(&f) = faces
                .iter()
                .find(|&&f| f >= grid.num_faces() || grid.is_boundary_face(f))
            {
                return Err(FlowError::Face {
                    face: f,
                    what: "a transmissibility multiplier needs an interior face".into(),
                });
            }
        }
        let mut trans = Transmissibilities::new(grid, &rock.permeability)?;
        for (faces, m) in &problem.transmissibility_multipliers {
            trans.multiply(faces, *m);
        }
        let (pattern, diag_pos, face_pos) = build_pattern(n, trans.all_face_cells());

        // Boundary conditions.
        let mut face_bc = vec![usize::MAX; grid.num_faces()];
        let mut dirichlet = Vec::new();
        let mut neumann = Vec::new();
        let mut bc_values = Vec::with_capacity(problem.boundary_conditions.len());
        for (i, bc) in problem.boundary_conditions.iter().enumerate() {
            let kind = bc.kind.name();
            let err = |what: String| FlowError::Boundary {
                index: i,
                kind,
                what,
            };
            if bc.faces.is_empty() {
                return Err(err("empty face set".into()));
            }
            if let ScalarField::Const(v) = bc.value
                && !v.is_finite()
            {
                return Err(err(format!("value must be finite, got {v}")));
            }
            for &f in &bc.faces {
                if f >= grid.num_faces() {
                    return Err(err(format!(
                        "face {f} out of range (grid has {})",
                        grid.num_faces()
                    )));
                }
                if !grid.is_boundary_face(f) {
                    return Err(FlowError::Face {
                        face: f,
                        what: format!("boundary condition #{i} ({kind}) on an interior face"),
                    });
                }
                if face_bc[f] != usize::MAX {
                    return Err(FlowError::Face {
                        face: f,
                        what: format!(
                            "in boundary conditions #{} and #{i}; a face takes one condition",
                            face_bc[f]
                        ),
                    });
                }
                face_bc[f] = i;
                let (cell, _) = grid.face_cells(f);
                let entry = BcFace {
                    face: f,
                    cell,
                    bc: i,
                    x: *grid.face_centroid(f),
                    coeff: 0.0,
                };
                match bc.kind {
                    BoundaryKind::Pressure => dirichlet.push(entry),
                    BoundaryKind::Flux => neumann.push(BcFace {
                        coeff: grid.face_area(f),
                        ..entry
                    }),
                }
            }
            bc_values.push(bc.value.clone());
        }

        // Sources.
        let mut source_cell_rate = vec![0.0; n];
        let mut source_names = Vec::new();
        let mut source_totals = Vec::new();
        let mut seen = vec![false; n];
        for s in &problem.sources {
            let err = |what: String| FlowError::Source {
                name: s.name.clone(),
                what,
            };
            if s.cells.is_empty() {
                return Err(err("empty cell set".into()));
            }
            let mut vol = 0.0;
            let mut pore = 0.0;
            for &c in &s.cells {
                if c >= n {
                    return Err(err(format!("cell {c} out of range (grid has {n})")));
                }
                if seen[c] {
                    return Err(err(format!("cell {c} listed twice")));
                }
                seen[c] = true;
                vol += volumes[c];
                pore += volumes[c] * rock.porosity[c];
            }
            let total = match s.rate {
                SourceRate::Total(q) => q,
                SourceRate::PoreVolumesPerHour(r) => r * pore / 3600.0,
            };
            if !total.is_finite() {
                return Err(err(format!("rate must be finite, got {:?}", s.rate)));
            }
            for &c in &s.cells {
                seen[c] = false;
                source_cell_rate[c] += total * volumes[c] / vol;
            }
            source_names.push(s.name.clone());
            source_totals.push(total);
        }

        // Wells.
        let mut wells = Vec::with_capacity(problem.wells.len());
        for w in &problem.wells {
            let err = |what: String| FlowError::Well {
                name: w.name.clone(),
                what,
            };
            if w.cell >= n {
                return Err(err(format!("cell {} out of range (grid has {n})", w.cell)));
            }
            match w.control {
                WellControl::Bhp(v) | WellControl::Rate(v) if !v.is_finite() => {
                    return Err(err(format!("control must be finite, got {:?}", w.control)));
                }
                _ => {}
            }
            if let Some(wi) = w.well_index
                && !(wi.is_finite() && wi > 0.0)
            {
                return Err(err(format!("well index must be > 0, got {wi}")));
            }
            let mut data = WellData {
                name: w.name.clone(),
                cell: w.cell,
                radius: w.radius,
                skin: w.skin,
                override_wi: w.well_index,
                control: w.control,
                wi: 0.0,
            };
            data.wi = well_index(grid, &rock.permeability, &data)?;
            wells.push(data);
        }

        let mut model = Self {
            volumes,
            porosity: rock.porosity.clone(),
            storage,
            accumulation,
            viscosity: fluid.viscosity,
            trans,
            multipliers: problem.transmissibility_multipliers.clone(),
            flux_vals: vec![0.0; pattern.row_idx().len()],
            sys_vals: vec![0.0; pattern.row_idx().len()],
            pattern,
            diag_pos,
            face_pos,
            dirichlet,
            neumann,
            bc_values,
            source_cell_rate,
            source_names,
            source_totals,
            wells,
            floating: Vec::new(),
            cholesky: None,
            factored_inv_dt: None,
            linear: FlowLinearSolver::Cholesky,
            amg: None,
            cg_iterations: 0,
        };
        model.fill_flux_matrix();
        Ok(model)
    }

    /// Number of cells (unknowns).
    pub fn num_cells(&self) -> usize {
        self.volumes.len()
    }

    /// The transmissibilities in use.
    pub fn transmissibilities(&self) -> &Transmissibilities {
        &self.trans
    }

    /// Storage coefficient `S_K = φ c_f + (α − φ)/K_s` per cell (1/Pa).
    pub fn storage(&self) -> &[f64] {
        &self.storage
    }

    /// The accumulation diagonal `M_KK = |K| S_K` (m³/Pa).
    pub fn accumulation(&self) -> &[f64] {
        &self.accumulation
    }

    /// Porosity per cell.
    pub fn porosity(&self) -> &[f64] {
        &self.porosity
    }

    /// Fluid viscosity μ.
    pub fn viscosity(&self) -> f64 {
        self.viscosity
    }

    /// The geometric well index `WI` (m³, without μ) of each well.
    pub fn well_indices(&self) -> Vec<f64> {
        self.wells.iter().map(|w| w.wi).collect()
    }

    /// Total rate (m³/s) of each source, in the problem's order, with its name.
    pub fn source_totals(&self) -> impl Iterator<Item = (&str, f64)> {
        self.source_names
            .iter()
            .map(String::as_str)
            .zip(self.source_totals.iter().copied())
    }

    /// The flux matrix `A` (Pa⁻¹ m³/s): `T/μ` between face neighbours plus the Dirichlet
    /// (`T_f/μ`) and bottom-hole-pressure well (`WI/μ`) terms on the diagonal. Symmetric,
    /// both triangles stored, sorted row indices, with the pattern of
    /// [`Self::pattern`] (every cell column holds its diagonal).
    pub fn flux_matrix(&self) -> SparseColMatRef<'_, usize, f64> {
        SparseColMatRef::new(self.pattern.as_ref(), &self.flux_vals)
    }

    /// The symbolic pattern of the flux matrix and of the system matrix `M/Δt + A`.
    pub fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }

    /// Position of the diagonal entry of each column in the values of [`Self::pattern`].
    pub fn diagonal_positions(&self) -> &[usize] {
        &self.diag_pos
    }

    /// The right-hand side `b(t)` of `(M/Δt + A) p = M/Δt p^n + b`: sources, rate wells,
    /// `T_f/μ p_b` on Dirichlet faces, `WI/μ p_bh` for pressure wells, `−u_f A_f` on flux
    /// faces, all evaluated at time `t`. `out` has one entry per cell and is overwritten.
    pub fn forcing(&self, t: f64, out: &mut [f64]) -> Result<()> {
        check_len("forcing output", out.len(), self.num_cells())?;
        out.copy_from_slice(&self.source_cell_rate);
        for b in &self.dirichlet {
            let v = self.bc_value(b, t)?;
            out[b.cell] += b.coeff * v;
        }
        for b in &self.neumann {
            let v = self.bc_value(b, t)?;
            out[b.cell] -= b.coeff * v;
        }
        for w in &self.wells {
            match w.control {
                WellControl::Bhp(p) => out[w.cell] += w.wi / self.viscosity * p,
                WellControl::Rate(q) => out[w.cell] += q,
            }
        }
        Ok(())
    }

    /// Replace the permeability (e.g. raised in fractured cells): recomputes the
    /// transmissibilities, Dirichlet coefficients and Peaceman well indices; the matrix
    /// pattern and the symbolic factorization are kept.
    pub fn set_permeability(&mut self, grid: &Grid<D>, perm: &Permeability<D>) -> Result<()> {
        check_len("grid cells", grid.num_cells(), self.num_cells())?;
        let mut trans = Transmissibilities::new(grid, perm)?;
        for (faces, m) in &self.multipliers {
            trans.multiply(faces, *m);
        }
        for w in &mut self.wells {
            w.wi = well_index(grid, perm, w)?;
        }
        self.trans = trans;
        self.fill_flux_matrix();
        if let Some(amg) = &mut self.amg {
            amg.0 = f64::NAN; // values changed: rebuild before the next solve
        }
        Ok(())
    }

    /// Choose how the pressure systems are solved (default [`FlowLinearSolver::Cholesky`]).
    /// Errors: a CG tolerance that is not a finite number in (0, 1).
    pub fn set_linear_solver(&mut self, solver: FlowLinearSolver) -> Result<()> {
        if let FlowLinearSolver::CgAmg { tolerance } = solver
            && !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0)
        {
            return Err(FlowError::Solver(format!(
                "CG tolerance must be in (0, 1), got {tolerance}"
            )));
        }
        self.linear = solver;
        self.amg = None;
        Ok(())
    }

    /// CG iterations of the last CG-AMG solve (0 with Cholesky).
    pub fn last_cg_iterations(&self) -> usize {
        self.cg_iterations
    }

    /// One implicit Euler step from time `t` (pressure `p_old`) to `t + dt`; boundary values
    /// are evaluated at `t + dt`.
    pub fn step(&mut self, p_old: &[f64], dt: f64, t: f64) -> Result<StepResult> {
        check_len("p_old", p_old.len(), self.num_cells())?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(FlowError::Time(format!(
                "Δt must be finite and > 0, got {dt}"
            )));
        }
        if !t.is_finite() {
            return Err(FlowError::Time(format!("t must be finite, got {t}")));
        }
        if let Some(c) = p_old.iter().position(|p| !p.is_finite()) {
            return Err(cell_err(c, format!("old pressure is {}", p_old[c])));
        }
        self.solve(Some(p_old), 1.0 / dt, t + dt)
    }

    /// Solve the steady problem `A p = b(t)` (no accumulation). Needs a pressure anchor
    /// (a Dirichlet face or a pressure-controlled well) in every connected region.
    pub fn solve_steady(&mut self, t: f64) -> Result<StepResult> {
        if !t.is_finite() {
            return Err(FlowError::Time(format!("t must be finite, got {t}")));
        }
        self.solve(None, 0.0, t)
    }

    fn solve(&mut self, p_old: Option<&[f64]>, inv_dt: f64, t: f64) -> Result<StepResult> {
        let n = self.num_cells();
        if let Some(&(cell, has_storage)) = self
            .floating
            .iter()
            .find(|(_, storage)| inv_dt == 0.0 || !storage)
        {
            return Err(FlowError::Singular(format!(
                "the region of connected cells containing cell {cell} has {} and no pressure \
                 boundary condition or pressure-controlled well",
                if has_storage && inv_dt == 0.0 {
                    "storage (but the steady problem ignores it)"
                } else {
                    "zero storage"
                }
            )));
        }
        let mut p = vec![0.0; n];
        self.forcing(t, &mut p)?;
        if let Some(p_old) = p_old {
            for c in 0..n {
                p[c] += self.accumulation[c] * inv_dt * p_old[c];
            }
        }
        match self.linear {
            FlowLinearSolver::Cholesky => {
                self.factorize(inv_dt)?;
                let cholesky = self.cholesky.as_ref().expect("factorized above");
                cholesky
                    .solve_in_place(&mut p, faer::get_global_parallelism())
                    .map_err(|e| FlowError::Solver(format!("Cholesky solve: {e}")))?;
            }
            FlowLinearSolver::CgAmg { tolerance } => {
                self.amg_setup(inv_dt)?;
                let (_, amg) = self.amg.as_mut().expect("set up above");
                let mut x = p_old.map_or_else(|| vec![0.0; n], <[f64]>::to_vec);
                let stats = amg
                    .solve(&mut x, &p, tolerance, 1000)
                    .map_err(|e| FlowError::Solver(format!("CG-AMG: {e}")))?;
                self.cg_iterations = stats.iterations;
                p = x;
            }
        }
        if let Some(c) = p.iter().position(|v| !v.is_finite()) {
            return Err(FlowError::Solver(format!(
                "non-finite pressure {} in cell {c}",
                p[c]
            )));
        }
        self.result(p, t)
    }

    /// `M·inv_dt + A` into `sys_vals`.
    fn fill_system(&mut self, inv_dt: f64) {
        self.sys_vals.copy_from_slice(&self.flux_vals);
        for c in 0..self.num_cells() {
            self.sys_vals[self.diag_pos[c]] += self.accumulation[c] * inv_dt;
        }
    }

    /// Build (or rebuild numerically) the AMG hierarchy of `M·inv_dt + A`.
    fn amg_setup(&mut self, inv_dt: f64) -> Result<()> {
        if let Some((cached, _)) = &self.amg
            && cached.to_bits() == inv_dt.to_bits()
        {
            return Ok(());
        }
        self.fill_system(inv_dt);
        // The upper triangle, column by column (the pattern stores both).
        let (cp, ri) = (self.pattern.col_ptr(), self.pattern.row_idx());
        let n = self.num_cells();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let (mut rows, mut vals) = (Vec::new(), Vec::new());
        col_ptr.push(0);
        for c in 0..n {
            for k in cp[c]..cp[c + 1] {
                if ri[k] <= c {
                    rows.push(ri[k]);
                    vals.push(self.sys_vals[k]);
                }
            }
            col_ptr.push(rows.len());
        }
        let err = |e: porofrac_amg::AmgError| FlowError::Solver(format!("AMG setup: {e}"));
        match self.amg.take() {
            Some((_, mut amg)) => {
                amg.update_values(&vals).map_err(err)?;
                self.amg = Some((inv_dt, amg));
            }
            None => {
                let a =
                    porofrac_amg::SymCsr::from_upper_csc(n, &col_ptr, &rows, &vals).map_err(err)?;
                let amg = porofrac_amg::Amg::scalar(a, &porofrac_amg::AmgOptions::default())
                    .map_err(err)?;
                self.amg = Some((inv_dt, amg));
            }
        }
        Ok(())
    }

    /// Assemble `M·inv_dt + A` and factorize it (symbolic once, numeric when needed).
    fn factorize(&mut self, inv_dt: f64) -> Result<()> {
        if let Some(cached) = self.factored_inv_dt
            && cached.to_bits() == inv_dt.to_bits()
        {
            return Ok(());
        }
        self.factored_inv_dt = None;
        self.fill_system(inv_dt);
        if self.cholesky.is_none() {
            let c = Cholesky::analyse(self.pattern.as_ref(), Side::Lower, None).map_err(|e| {
                let e = match e {
                    CholeskyError::Symbolic(e) => format!("{e:?}"),
                    e => e.to_string(),
                };
                FlowError::Solver(format!("symbolic Cholesky: {e}"))
            })?;
            self.cholesky = Some(c);
        }
        let cholesky = self.cholesky.as_mut().expect("set above");
        let mat = SparseColMatRef::new(self.pattern.as_ref(), &self.sys_vals);
        cholesky
            .factorize(mat, faer::get_global_parallelism())
            .map_err(|e| {
                // faer's error, as faer prints it.
                let e = match e {
                    CholeskyError::NonPositivePivot { source, .. } => source,
                    _ => faer::sparse::linalg::LltError::Generic(
                        faer::sparse::FaerError::OutOfMemory,
                    ),
                };
                FlowError::Singular(format!(
                    "Cholesky factorization failed ({e}); the system is not positive definite"
                ))
            })?;
        self.factored_inv_dt = Some(inv_dt);
        Ok(())
    }

    fn result(&self, pressure: Vec<f64>, t: f64) -> Result<StepResult> {
        let mu = self.viscosity;
        let fc = self.trans.all_face_cells();
        let tf = self.trans.faces();
        let mut face_flux: Vec<f64> = (0..fc.len())
            .into_par_iter()
            .map(|f| {
                let [a, b] = fc[f];
                if b == NO_CELL {
                    0.0
                } else {
                    tf[f] / mu * (pressure[a] - pressure[b])
                }
            })
            .collect();
        for b in &self.dirichlet {
            face_flux[b.face] = b.coeff * (pressure[b.cell] - self.bc_value(b, t)?);
        }
        for b in &self.neumann {
            face_flux[b.face] = b.coeff * self.bc_value(b, t)?;
        }
        let mut well_rate = Vec::with_capacity(self.wells.len());
        let mut well_bhp = Vec::with_capacity(self.wells.len());
        for w in &self.wells {
            let pk = pressure[w.cell];
            let (q, bhp) = match w.control {
                WellControl::Bhp(pb) => (w.wi / mu * (pb - pk), pb),
                WellControl::Rate(q) => (q, pk + q * mu / w.wi),
            };
            well_rate.push(q);
            well_bhp.push(bhp);
        }
        Ok(StepResult {
            pressure,
            face_flux,
            well_rate,
            well_bhp,
        })
    }

    fn bc_value(&self, b: &BcFace<D>, t: f64) -> Result<f64> {
        let v = self.bc_values[b.bc].eval(b.x.as_slice(), t);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(FlowError::Face {
                face: b.face,
                what: format!("boundary condition #{} evaluates to {v} at t = {t}", b.bc),
            })
        }
    }

    /// Fill `flux_vals` from the transmissibilities, Dirichlet faces and BHP wells; find the
    /// connected regions without a pressure anchor; drop the numeric factorization.
    fn fill_flux_matrix(&mut self) {
        let mu = self.viscosity;
        self.flux_vals.iter_mut().for_each(|v| *v = 0.0);
        let fc = self.trans.all_face_cells();
        let n = self.volumes.len();
        let mut uf = UnionFind::new(n);
        for (f, &[a, b]) in fc.iter().enumerate() {
            if b == NO_CELL {
                continue;
            }
            let t = self.trans.face(f) / mu;
            let [pa, pb] = self.face_pos[f];
            self.flux_vals[self.diag_pos[a]] += t;
            self.flux_vals[self.diag_pos[b]] += t;
            self.flux_vals[pa] -= t;
            self.flux_vals[pb] -= t;
            if t > 0.0 {
                uf.union(a, b);
            }
        }
        let mut anchored = vec![false; n];
        let mut stored = vec![false; n];
        for d in &mut self.dirichlet {
            d.coeff = self.trans.face(d.face) / mu;
            self.flux_vals[self.diag_pos[d.cell]] += d.coeff;
            if d.coeff > 0.0 {
                anchored[uf.find(d.cell)] = true;
            }
        }
        for w in &self.wells {
            if let WellControl::Bhp(_) = w.control {
                self.flux_vals[self.diag_pos[w.cell]] += w.wi / mu;
                anchored[uf.find(w.cell)] = true;
            }
        }
        for c in 0..n {
            if self.accumulation[c] > 0.0 {
                stored[uf.find(c)] = true;
            }
        }
        self.floating.clear();
        for c in 0..n {
            let r = uf.find(c);
            if r == c && !anchored[r] {
                self.floating.push((c, stored[r]));
            }
        }
        self.factored_inv_dt = None;
    }
}

fn check_len(what: &'static str, got: usize, expected: usize) -> Result<()> {
    if got == expected {
        Ok(())
    } else {
        Err(FlowError::Length {
            what,
            got,
            expected,
        })
    }
}

fn well_index<const D: usize>(grid: &Grid<D>, perm: &Permeability<D>, w: &WellData) -> Result<f64> {
    if let Some(wi) = w.override_wi {
        return Ok(wi);
    }
    peaceman_well_index(grid, w.cell, perm.tensor(w.cell), w.radius, w.skin)
        .map(|(_, wi)| wi)
        .map_err(|what| FlowError::Well {
            name: w.name.clone(),
            what,
        })
}

/// The CSC pattern of cells and their face neighbours (both triangles, sorted rows), the
/// diagonal positions, and per interior face the positions of `(row c1, col c0)` and
/// `(row c0, col c1)`.
fn build_pattern(
    n: usize,
    face_cells: &[[usize; 2]],
) -> (SymbolicSparseColMat<usize>, Vec<usize>, Vec<[usize; 2]>) {
    let mut count = vec![1usize; n];
    for &[a, b] in face_cells {
        if b != NO_CELL {
            count[a] += 1;
            count[b] += 1;
        }
    }
    let mut start = vec![0usize; n + 1];
    for c in 0..n {
        start[c + 1] = start[c] + count[c];
    }
    let mut rows = vec![0usize; start[n]];
    let mut fill = start[..n].to_vec();
    for c in 0..n {
        rows[fill[c]] = c;
        fill[c] += 1;
    }
    for &[a, b] in face_cells {
        if b != NO_CELL {
            rows[fill[a]] = b;
            fill[a] += 1;
            rows[fill[b]] = a;
            fill[b] += 1;
        }
    }
    // Sort and deduplicate each column (two cells may share several faces).
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::with_capacity(rows.len());
    for c in 0..n {
        let col = &mut rows[start[c]..start[c + 1]];
        col.sort_unstable();
        let mut last = usize::MAX;
        for &r in col.iter() {
            if r != last {
                row_idx.push(r);
                last = r;
            }
        }
        col_ptr.push(row_idx.len());
    }
    let pos = |row: usize, col: usize| -> usize {
        let s = col_ptr[col];
        // Invariant: the pattern holds (row, col) for every face neighbour and the diagonal.
        s + row_idx[s..col_ptr[col + 1]]
            .binary_search(&row)
            .expect("entry in pattern")
    };
    let diag_pos = (0..n).map(|c| pos(c, c)).collect();
    let face_pos = face_cells
        .iter()
        .map(|&[a, b]| {
            if b == NO_CELL {
                [usize::MAX; 2]
            } else {
                [pos(b, a), pos(a, b)]
            }
        })
        .collect();
    let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    (pattern, diag_pos, face_pos)
}

/// Union–find with path halving, for the connected regions of the face graph.
struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        Self {
            parent: (0..n).collect(),
        }
    }
    fn find(&mut self, mut a: usize) -> usize {
        while self.parent[a] != a {
            self.parent[a] = self.parent[self.parent[a]];
            a = self.parent[a];
        }
        a
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb)] = ra.min(rb);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::{Fluid, Rock};
    use porofrac_grid::generate::cartesian;

    /// Two cells sharing two faces (a hanging node on both sides of their common edge): the
    /// pattern holds one entry per pair, both faces add up, and the flux is conserved.
    #[test]
    fn cells_sharing_two_faces() {
        let nodes = vec![
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 0.0),
            Point::<2>::new(1.0, 0.5),
            Point::<2>::new(1.0, 1.0),
            Point::<2>::new(0.0, 1.0),
            Point::<2>::new(2.0, 0.0),
            Point::<2>::new(2.0, 1.0),
        ];
        let grid = Grid::from_polygons(nodes, &[0, 5, 10], &[0, 1, 2, 3, 4, 1, 5, 6, 3, 2])
            .expect("valid grid");
        let rock = Rock::new(vec![0.2; 2], Permeability::uniform(2, 1.0).unwrap());
        let fluid = Fluid {
            viscosity: 1.0,
            compressibility: 0.0,
        };
        let problem = FlowProblem::new(rock, fluid)
            .pressure_bc(grid.boundary("xmin").unwrap(), 1.0)
            .pressure_bc(grid.boundary("xmax").unwrap(), 0.0);
        let mut m = FlowModel::new(&grid, &problem).unwrap();
        assert_eq!(m.pattern().row_idx(), &[0, 1, 0, 1]);
        // Each half face: t = 0.5 · (0.5)/(0.5² + 0.25²) = 0.8 from both sides, T = 0.4 each.
        let a = m.flux_matrix();
        assert!((a.val()[1] + 0.8).abs() < 1e-14, "{:?}", a.val());
        let r = m.solve_steady(0.0).unwrap();
        let q_in = r.face_flux[grid.boundary("xmin").unwrap()[0]];
        let q_out = r.face_flux[grid.boundary("xmax").unwrap()[0]];
        assert!((q_in + q_out).abs() < 1e-14 * q_out.abs());
    }

    /// Reusing the factorization (same Δt), refactorizing (new Δt) and changing the
    /// permeability give the same numbers as a freshly built model.
    #[test]
    fn factorization_reuse_matches_fresh_model() {
        let grid =
            cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 1.0), [7, 5]).unwrap();
        let n = grid.num_cells();
        let problem = |k: f64| {
            FlowProblem::new(
                Rock::new(vec![0.2; n], Permeability::uniform(n, k).unwrap()),
                Fluid {
                    viscosity: 1e-3,
                    compressibility: 1e-9,
                },
            )
            .pressure_bc(grid.boundary("xmin").unwrap(), 1e6)
        };
        let mut m = FlowModel::new(&grid, &problem(1e-13)).unwrap();
        let p0 = vec![0.0; n];
        let a = m.step(&p0, 10.0, 0.0).unwrap().pressure;
        let b = m.step(&a, 10.0, 10.0).unwrap().pressure;
        let c = m.step(&b, 5.0, 20.0).unwrap().pressure;
        let mut fresh = FlowModel::new(&grid, &problem(1e-13)).unwrap();
        let b2 = fresh.step(&a, 10.0, 10.0).unwrap().pressure;
        let mut fresh = FlowModel::new(&grid, &problem(1e-13)).unwrap();
        let c2 = fresh.step(&b, 5.0, 20.0).unwrap().pressure;
        let close = |x: &[f64], y: &[f64]| x.iter().zip(y).all(|(u, v)| (u - v).abs() <= 1e-9);
        assert!(close(&b, &b2) && close(&c, &c2));
        let perm = Permeability::uniform(n, 3e-13).unwrap();
        m.set_permeability(&grid, &perm).unwrap();
        let d = m.step(&c, 5.0, 25.0).unwrap().pressure;
        let mut fresh = FlowModel::new(&grid, &problem(3e-13)).unwrap();
        let d2 = fresh.step(&c, 5.0, 25.0).unwrap().pressure;
        assert!(close(&d, &d2));
        // …and the permeability change matters.
        let mut old = FlowModel::new(&grid, &problem(1e-13)).unwrap();
        let d_old = old.step(&c, 5.0, 25.0).unwrap().pressure;
        assert!(d.iter().zip(&d_old).any(|(u, v)| (u - v).abs() > 1.0));
    }

    /// Storage with compressible grains, and boundary values taken at the end of the step.
    #[test]
    fn storage_formula_and_boundary_time() {
        let grid =
            cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 1.0), [2, 1]).unwrap();
        let mut rock = Rock::new(vec![0.2, 0.3], Permeability::uniform(2, 1e-13).unwrap());
        rock.biot_alpha = vec![0.8, 0.9];
        rock.solid_bulk_modulus = 4e10;
        let fluid = Fluid {
            viscosity: 1e-3,
            compressibility: 5e-10,
        };
        let problem = FlowProblem::new(rock, fluid);
        let m = FlowModel::new(&grid, &problem).unwrap();
        let s0 = 0.2 * 5e-10 + (0.8 - 0.2) / 4e10;
        let s1 = 0.3 * 5e-10 + (0.9 - 0.3) / 4e10;
        assert!((m.storage()[0] - s0).abs() < 1e-25 && (m.storage()[1] - s1).abs() < 1e-25);
        assert!((m.accumulation()[1] - s1 * 1.0).abs() < 1e-25);

        // Zero storage: the step's pressure is the boundary value at t + Δt.
        let mut rock = Rock::new(vec![0.2, 0.2], Permeability::uniform(2, 1e-13).unwrap());
        rock.biot_alpha = vec![1.0; 2];
        let problem = FlowProblem::new(
            rock,
            Fluid {
                viscosity: 1e-3,
                compressibility: 0.0,
            },
        )
        .pressure_bc(
            grid.boundary("xmin").unwrap(),
            ScalarField::from_fn(|_, t| 1e5 * t),
        );
        let mut m = FlowModel::new(&grid, &problem).unwrap();
        let r = m.step(&[0.0, 0.0], 2.0, 3.0).unwrap();
        assert!(
            r.pressure.iter().all(|&p| (p - 5e5).abs() < 1e-8),
            "{:?}",
            r.pressure
        );
    }
}
