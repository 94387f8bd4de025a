//! Assembly of the reduced stiffness, the internal forces and the external loads.
//!
//! # Weak form
//!
//! Find `u` with `u = g` on the Dirichlet boundary such that for all admissible `v`
//!
//! ```text
//!   Σ_K a_K(u, v) = ∫_Ω (b + ρ g) · v dx + ∫_Γt t · v ds  (+ platen forces)
//! ```
//!
//! where `a_K` is the bilinear form of the cell law of cell `K` (Nilsen et al. (2017) §2.2–2.3:
//! VEM, MDEM or P1), represented by its local stiffness `K_K` and its nodal forces
//! `F_K(u) = −∂E_K/∂u`. [`assemble`] evaluates, at a given nodal displacement `u`
//! (prescribed values filled in), the reduced tangent `Tᵀ K_ff T` (see [`crate::dofs`])
//! into the values of a [`Pattern`] and the reduced internal forces `Tᵀ F(u)`. For a
//! linear law `F(u) = −K u`, so at `u = (0, u_p)` the internal forces are exactly the
//! elimination term `−K_fp u_p`; for nonlinear laws [`porofrac_law::CellLaw::forces`] is called and the
//! same vector is the Newton residual.
//!
//! # Load integration
//!
//! The virtual-element basis function `φ_i` is not known inside a cell, so loads are
//! integrated with a piecewise-linear surrogate that is exact on simplices: each cell is
//! split into the simplices formed by the facets of its faces (the grid's face-point
//! triangulation, [`porofrac_grid::point::for_each_facet`]) and the cell's vertex average
//! `x_K`. On each sub-simplex φ_i is linear, with value `δ_ij` at face vertices `j`,
//! `1/m` at the face point of an `m`-gon face (3D), and `1/n` at `x_K` (`n` nodes). Then
//! `Σ_i φ_i = 1`, `Σ_i φ_i x_i = x` (so constant and linear loads have exact moments), and
//! on a triangle or tetrahedron φ_i is the P1 hat function. The nodal load is
//!
//! ```text
//!   f_i = Σ_{sub-simplices S} |S| Σ_q w_q φ_i(x_q) (b(x_q, t) + ρ_K g)
//! ```
//!
//! with a rule exact for degree 4 on triangles (6 points) and degree 2 on tetrahedra (4
//! points), so loads linear in x are integrated exactly. A cell that is itself a simplex
//! (`D + 1` nodes) is not split: φ_i are its barycentric coordinates and the rule acts on
//! the whole cell with a degree-4 rule (6 points on triangles, Keast's 11 on tetrahedra),
//! like the standard P1 reference and with fewer load evaluations (6 instead of 18, 11
//! instead of 16). Tractions use φ restricted to
//! the face: on a 2D edge `∫_e t φ_i ds` by 2-point Gauss (exact to degree 3), on a 3D face
//! the same facets with the edge-midpoint rule (degree 2); nodal loads are exact for
//! linear tractions.

use nalgebra::DMatrix;
use porofrac_grid::point::for_each_facet;
use porofrac_grid::{Grid, Point};
use porofrac_law::{GeometryBuffer, LawError, Scratch};
use rayon::prelude::*;
use std::sync::{Arc, Mutex};

use crate::bc::Loads;
use crate::dofs::DofMap;
use crate::error::{AXES, Result, SimError, fmt_point};
use crate::laws::LawMap;
use crate::pattern::{Pattern, ScatterBuffer};
use crate::quadrature::{cell_rule, facet_rule, simplex_rule};

/// Per-thread buffers for evaluating cells.
#[derive(Default)]
pub(crate) struct Work<const D: usize> {
    pub(crate) scratch: Scratch,
    pub(crate) geo: GeometryBuffer<D>,
    pub(crate) k: DMatrix<f64>,
    pub(crate) u: Vec<f64>,
    pub(crate) f: Vec<f64>,
    pub(crate) map: ScatterBuffer,
}

impl<const D: usize> Work<D> {
    /// Gather the displacements of cell `c` from the nodal vector `u`.
    pub(crate) fn gather(&mut self, grid: &Grid<D>, c: usize, u: &[f64]) {
        self.u.clear();
        for &n in grid.cell_nodes(c) {
            self.u.extend_from_slice(&u[D * n..D * n + D]);
        }
    }
    /// Nodal forces of cell `c` at the gathered displacement, into `self.f`.
    pub(crate) fn forces(&mut self, grid: &Grid<D>, laws: &LawMap<'_, D>, c: usize) -> Result<()> {
        let law = laws.law(c);
        let geo = self.geo.load(grid, c);
        self.f.clear();
        self.f.resize(self.u.len(), 0.0);
        law.forces(&geo, &self.u, &mut self.f, &mut self.scratch)
            .map_err(law_error(laws, c))
    }
}

/// The error of cell `c`'s law, with the cell and the law's name.
///
/// The closure allocates (the name) only when it is called, on the error path.
pub(crate) fn law_error<'m, const D: usize>(
    laws: &'m LawMap<'_, D>,
    c: usize,
) -> impl FnOnce(LawError) -> SimError + 'm {
    move |source| SimError::Law {
        cell: c,
        law: laws.law(c).name().to_string(),
        source,
    }
}

pub(crate) fn cell_error<const D: usize>(laws: &LawMap<'_, D>, c: usize, what: String) -> SimError {
    SimError::Cell {
        cell: c,
        law: laws.law(c).name().to_string(),
        what,
    }
}

/// Assemble the reduced tangent stiffness and internal forces at the nodal displacement
/// `u` (length `D · nodes`, prescribed values filled in).
///
/// `values` (length [`Pattern::nnz`]) receives `Tᵀ K_ff(u) T` in the pattern's upper
/// triangle; `forces` (length = equations) receives `Tᵀ F(u)`, the restoring forces of the
/// cells summed into the equations. Both are overwritten. Cells are evaluated in parallel
/// (see [`crate::pattern`] for the race-free partition). Errors name the cell whose law
/// failed on it or returned a wrong-sized stiffness.
pub fn assemble<const D: usize>(
    grid: &Grid<D>,
    laws: &LawMap<'_, D>,
    dofs: &DofMap<D>,
    pattern: &Pattern,
    u: &[f64],
    values: &mut [f64],
    forces: &mut [f64],
) -> Result<()> {
    assemble_with(
        grid,
        laws,
        dofs,
        pattern,
        u,
        Some(values),
        Some(forces),
        None,
    )
}

/// The element stiffness `K_K` of every cell whose law is linear, kept between assemblies.
///
/// A linear law's stiffness depends on the cell's geometry only, so a fracturing run that
/// re-linearizes at every active-set iteration needs it once per cell: only the cells
/// whose law is nonlinear (the failed, compression-only cells) are evaluated again.
/// A matrix is kept with the index of the law it was computed with in the [`LawMap`], and
/// used only while the cell has that law, so a cell that switches law is evaluated by its
/// new law. The cache serves every map over the same list of laws as the one it was
/// built from (the maps of a run differ only in the law of each cell).
/// The assembled sum of the kept matrices of the cells that use them is kept too (for
/// the last set of such cells, which changes only when a cell switches law): an assembly
/// starts from it and scatters only the other cells. It equals the assembly without the
/// cache up to the order of the sums (rounding). A set that differs from the last one in
/// a few cells (a failure round) is summed again only in the entries those cells
/// scatter into, to the same bits as a full sum (`ElementCache::resum`): on the 3D
/// hydraulic-fracture scene with `refine = 6` 1.1 s of sums become 0.13 s.
pub(crate) struct ElementCache {
    /// Per cell: the index in the law map of the law its matrix was computed with
    /// ([`NOT_KEPT`]: none).
    law: Vec<usize>,
    /// Per cell: its matrix in `values[start[c]..start[c + 1]]` (column-major `m × m`).
    start: Vec<usize>,
    values: Vec<f64>,
    /// The assembled sum of the kept matrices over the cells flagged (see [`KeptSum`]).
    sum: Mutex<Option<KeptSum>>,
}

/// A new sum of the kept matrices is formed from the last one ([`ElementCache::resum`])
/// when at most one cell in this many changed, else summed afresh.
const INCREMENTAL_SUM_FRACTION: usize = 8;

/// The assembled (pattern values) sum of the kept element matrices of the cells `used`.
struct KeptSum {
    used: Vec<bool>,
    values: Arc<[f64]>,
}

/// The law key of a cell of [`ElementCache`] without a kept matrix.
const NOT_KEPT: usize = usize::MAX;

impl ElementCache {
    /// Evaluate and keep the stiffness of every cell of `grid` whose law in `laws` is
    /// linear. Errors: a law failing on a cell or a wrong-sized stiffness, naming the cell.
    pub(crate) fn new<const D: usize>(grid: &Grid<D>, laws: &LawMap<'_, D>) -> Result<Self> {
        let nc = grid.num_cells();
        let mut start = Vec::with_capacity(nc + 1);
        start.push(0);
        let mut law = vec![NOT_KEPT; nc];
        for c in 0..nc {
            let l = laws.law(c);
            let m = D * grid.cell_nodes(c).len();
            let len = if l.is_linear() { m * m } else { 0 };
            if len > 0 {
                law[c] = laws.law_index(c);
            }
            start.push(start[c] + len);
        }
        let mut values = vec![0.0; start[nc]];
        let mut w = Work::<D>::default();
        let zero = vec![0.0; D * grid.num_nodes()];
        for c in (0..nc).filter(|&c| law[c] != NOT_KEPT) {
            w.gather(grid, c, &zero);
            stiffness(grid, laws, c, &mut w)?;
            values[start[c]..start[c + 1]].copy_from_slice(w.k.as_slice());
        }
        Ok(Self {
            law,
            start,
            values,
            sum: Mutex::new(None),
        })
    }

    /// The assembled sum of the kept matrices of the cells whose law in `laws` is the
    /// kept one, computed when that set of cells changed since the last call.
    fn kept_sum<const D: usize>(
        &self,
        grid: &Grid<D>,
        laws: &LawMap<'_, D>,
        dofs: &DofMap<D>,
        pattern: &Pattern,
    ) -> Arc<[f64]> {
        let used: Vec<bool> = (0..grid.num_cells())
            .map(|c| self.matrix(c, laws.law_index(c)).is_some())
            .collect();
        // A poisoned lock only means another thread panicked while computing: recompute.
        let mut guard = self.sum.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(k) = guard.as_ref()
            && k.used == used
            && k.values.len() == pattern.nnz()
        {
            return k.values.clone();
        }
        if let Some(k) = guard.as_ref()
            && k.used.len() == used.len()
            && k.values.len() == pattern.nnz()
        {
            let changed: Vec<usize> = (0..used.len()).filter(|&c| used[c] != k.used[c]).collect();
            if changed.len() <= used.len() / INCREMENTAL_SUM_FRACTION {
                let values = self.resum(grid, dofs, pattern, &used, &changed, &k.values);
                *guard = Some(KeptSum {
                    used,
                    values: values.clone(),
                });
                return values;
            }
        }
        let mut values = vec![0.0; pattern.nnz()];
        let mut parts = Vec::with_capacity(pattern.chunks.len());
        let mut rest = &mut values[..];
        for ch in &pattern.chunks {
            let (v, r) = rest.split_at_mut(ch.vals.len());
            parts.push((ch, v));
            rest = r;
        }
        parts
            .into_par_iter()
            .for_each_init(ScatterBuffer::default, |map, (ch, vals)| {
                for &c in &pattern.chunk_cells[ch.cells.clone()] {
                    if used[c] {
                        let k = &self.values[self.start[c]..self.start[c + 1]];
                        pattern.add_cell(grid, dofs, c, k, map, ch.vals.start, vals);
                    }
                }
            });
        let values: Arc<[f64]> = Arc::from(values);
        *guard = Some(KeptSum {
            used,
            values: values.clone(),
        });
        values
    }

    /// The sum over the cells `used` from the sum `old` over a set that differs from it
    /// in the cells `changed`: only the entries a changed cell scatters into are summed
    /// again, over the used cells that share an equation with a changed cell (every cell
    /// with a matrix entry there does) in the order of the full sum — per chunk, its
    /// cells in turn — so the result is the full sum to the last bit, at the cost of the
    /// changed cells' neighbourhood.
    fn resum<const D: usize>(
        &self,
        grid: &Grid<D>,
        dofs: &DofMap<D>,
        pattern: &Pattern,
        used: &[bool],
        changed: &[usize],
        old: &[f64],
    ) -> Arc<[f64]> {
        let equations = |c: usize| {
            grid.cell_nodes(c)
                .iter()
                .flat_map(move |&n| (0..D).filter_map(move |a| dofs.equation(n, a)))
        };
        let mut near = vec![false; dofs.num_equations()];
        // Entries a changed cell scatters into: nonzero in `mark` after adding ones.
        let mut mark = vec![0.0; pattern.nnz()];
        let mut buf = ScatterBuffer::default();
        let mut ones = Vec::new();
        for &c in changed {
            for e in equations(c) {
                near[e] = true;
            }
            let m = D * grid.cell_nodes(c).len();
            ones.clear();
            ones.resize(m * m, 1.0);
            pattern.add_cell(grid, dofs, c, &ones, &mut buf, 0, &mut mark);
        }
        let mut sum = vec![0.0; pattern.nnz()];
        for ch in &pattern.chunks {
            let vals = &mut sum[ch.vals.clone()];
            for &c in &pattern.chunk_cells[ch.cells.clone()] {
                if used[c] && equations(c).any(|e| near[e]) {
                    let k = &self.values[self.start[c]..self.start[c + 1]];
                    pattern.add_cell(grid, dofs, c, k, &mut buf, ch.vals.start, vals);
                }
            }
        }
        old.iter()
            .zip(&mark)
            .zip(&sum)
            .map(|((&o, &m), &s)| if m != 0.0 { s } else { o })
            .collect()
    }

    /// Whether the stiffness of cell `c` under the law of index `law` is kept.
    pub(crate) fn keeps(&self, c: usize, law: usize) -> bool {
        self.matrix(c, law).is_some()
    }

    /// The kept stiffness of cell `c` if its law is the law of index `law`.
    #[inline]
    fn matrix(&self, c: usize, law: usize) -> Option<&[f64]> {
        let a = *self.law.get(c)?;
        (a != NOT_KEPT && a == law).then(|| &self.values[self.start[c]..self.start[c + 1]])
    }
}

/// The stiffness of cell `c` at the gathered displacement `w.u` into `w.k`, checked for
/// its size.
fn stiffness<const D: usize>(
    grid: &Grid<D>,
    laws: &LawMap<'_, D>,
    c: usize,
    w: &mut Work<D>,
) -> Result<()> {
    let law = laws.law(c);
    let m = w.u.len();
    {
        let geo = w.geo.load(grid, c);
        law.stiffness(&geo, &w.u, &mut w.k, &mut w.scratch)
            .map_err(law_error(laws, c))?;
    }
    if w.k.nrows() != m || w.k.ncols() != m {
        return Err(cell_error(
            laws,
            c,
            format!(
                "stiffness is {}×{}, expected {m}×{m}",
                w.k.nrows(),
                w.k.ncols()
            ),
        ));
    }
    Ok(())
}

/// The stiffness matrices of `cells` at the nodal displacement `u`, appended to `out`
/// in turn (column-major, as [`CellLaw::stiffness`](porofrac_law::CellLaw::stiffness) gives them). Errors as the assembly.
pub(crate) fn cell_tangents<const D: usize>(
    grid: &Grid<D>,
    laws: &LawMap<'_, D>,
    cells: &[usize],
    u: &[f64],
    out: &mut Vec<f64>,
) -> Result<()> {
    let mut w = Work::<D>::default();
    for &c in cells {
        w.gather(grid, c, u);
        stiffness(grid, laws, c, &mut w)?;
        out.extend_from_slice(w.k.as_slice());
    }
    Ok(())
}

/// [`assemble`], taking the stiffness of the linear cells from `cache` when given; the
/// stiffness `values` and the internal `forces` each only when asked for (the same sums
/// either way: every chunk adds its cells in turn).
#[allow(clippy::too_many_arguments)]
pub(crate) fn assemble_with<const D: usize>(
    grid: &Grid<D>,
    laws: &LawMap<'_, D>,
    dofs: &DofMap<D>,
    pattern: &Pattern,
    u: &[f64],
    values: Option<&mut [f64]>,
    forces: Option<&mut [f64]>,
    cache: Option<&ElementCache>,
) -> Result<()> {
    if dofs.num_equations() != pattern.num_equations() || grid.num_cells() != pattern.num_cells() {
        return Err(SimError::Input(format!(
            "assemble: a pattern of {} equations and {} cells for {} equations and {} cells",
            pattern.num_equations(),
            pattern.num_cells(),
            dofs.num_equations(),
            grid.num_cells()
        )));
    }
    let values_len = values.as_ref().map_or(pattern.nnz(), |v| v.len());
    let forces_len = forces.as_ref().map_or(pattern.num_equations(), |f| f.len());
    if u.len() != dofs.num_dofs()
        || values_len != pattern.nnz()
        || forces_len != pattern.num_equations()
    {
        return Err(SimError::Input(format!(
            "assemble: lengths u {} (want {}), values {} (want {}), forces {} (want {})",
            u.len(),
            dofs.num_dofs(),
            values_len,
            pattern.nnz(),
            forces_len,
            pattern.num_equations()
        )));
    }
    let raw = dofs.raw();
    let kept_sum = match (&values, cache) {
        (Some(_), Some(e)) => Some(e.kept_sum(grid, laws, dofs, pattern)),
        _ => None,
    };
    /// The part of `rest` of length `len` (none when nothing is asked for).
    fn take<'s>(rest: &mut Option<&'s mut [f64]>, len: usize) -> Option<&'s mut [f64]> {
        let (part, r) = rest.take()?.split_at_mut(len);
        *rest = Some(r);
        Some(part)
    }
    let mut parts = Vec::with_capacity(pattern.chunks.len());
    let (mut vrest, mut frest) = (values, forces);
    for ch in &pattern.chunks {
        let v = take(&mut vrest, ch.vals.len());
        let f = take(&mut frest, ch.cols.len());
        parts.push((ch, v, f));
    }
    parts
        .into_par_iter()
        .try_for_each_init(Work::<D>::default, |w, (ch, mut vals, mut frc)| {
            if let Some(vals) = vals.as_deref_mut() {
                match &kept_sum {
                    Some(sum) => vals.copy_from_slice(&sum[ch.vals.clone()]),
                    None => vals.fill(0.0),
                }
            }
            if let Some(frc) = frc.as_deref_mut() {
                frc.fill(0.0);
            }
            for &c in &pattern.chunk_cells[ch.cells.clone()] {
                let law = laws.law(c);
                // A kept matrix is in `kept_sum` already.
                let kept = cache.and_then(|e| e.matrix(c, laws.law_index(c)));
                if kept.is_some() && frc.is_none() {
                    continue;
                }
                w.gather(grid, c, u);
                let m = w.u.len();
                if kept.is_none() && (vals.is_some() || law.is_linear()) {
                    stiffness(grid, laws, c, w)?;
                    if let Some(vals) = vals.as_deref_mut() {
                        pattern.add_cell(
                            grid,
                            dofs,
                            c,
                            w.k.as_slice(),
                            &mut w.map,
                            ch.vals.start,
                            vals,
                        );
                    }
                }
                let Some(frc) = frc.as_deref_mut() else {
                    continue;
                };
                let k = kept.unwrap_or(w.k.as_slice());
                // Internal forces: −K u for linear laws (nothing to do at u = 0), else the law's.
                if law.is_linear() {
                    if w.u.iter().all(|&x| x == 0.0) {
                        continue;
                    }
                    w.f.clear();
                    w.f.resize(m, 0.0);
                    for j in 0..m {
                        let uj = w.u[j];
                        if uj != 0.0 {
                            for (fi, kij) in w.f.iter_mut().zip(&k[j * m..(j + 1) * m]) {
                                *fi -= kij * uj;
                            }
                        }
                    }
                } else {
                    w.forces(grid, laws, c)?;
                }
                let (c0, clen) = (ch.cols.start, frc.len());
                let nodes = grid.cell_nodes(c);
                for (i, fi) in w.f.iter().enumerate() {
                    let e = raw[D * nodes[i / D] + i % D];
                    let k = e.wrapping_sub(c0);
                    if k < clen {
                        frc[k] += fi;
                    }
                }
            }
            Ok(())
        })
}

/// Nodal external loads at time `t` (body force, gravity and tractions; platen forces are
/// added to the reduced system by [`DofMap::add_platen_forces`]), written to `out`
/// (length `D · nodes`, node-major). See the module docs for the integration rules.
///
/// Errors: a density array of the wrong length, a traction on an interior or out-of-range
/// face, or a non-finite load (naming the node).
pub fn nodal_loads<const D: usize>(
    grid: &Grid<D>,
    loads: &Loads<D>,
    t: f64,
    out: &mut [f64],
) -> Result<()> {
    nodal_loads_of_cells(grid, loads, t, &|_| true, out)
}

/// [`nodal_loads`] with the body force and gravity of the cells `c` with `keep(c)` only
/// (tractions on every face). A node all of whose cells are kept gets the value
/// [`nodal_loads`] gives it, bit for bit (the same blocks of cells, summed in the same
/// order): a process of a distributed run computes the loads of its own nodes from the
/// cells that touch them.
///
/// Errors: as [`nodal_loads`].
pub fn nodal_loads_of_cells<const D: usize>(
    grid: &Grid<D>,
    loads: &Loads<D>,
    t: f64,
    keep: &(dyn Fn(usize) -> bool + Sync),
    out: &mut [f64],
) -> Result<()> {
    let ndof = D * grid.num_nodes();
    if out.len() != ndof {
        return Err(SimError::Input(format!(
            "nodal_loads: output length {}, want {ndof}",
            out.len()
        )));
    }
    out.fill(0.0);
    if let Some(gr) = &loads.gravity
        && gr.density.len() != grid.num_cells()
    {
        return Err(SimError::Input(format!(
            "gravity: {} densities for {} cells",
            gr.density.len(),
            grid.num_cells()
        )));
    }
    if loads.body_force.is_some() || loads.gravity.is_some() {
        // Blocks of consecutive cells, a fixed number of them (so the sums do not depend
        // on the thread count): each block sums into the span of nodes its cells touch —
        // a thin band of the nodal vector when the grid is numbered in space — and the
        // spans are added into `out` in block order.
        const BLOCKS: usize = 16;
        let nc = grid.num_cells();
        let spans: Vec<(usize, Vec<f64>)> = (0..BLOCKS.min(nc))
            .into_par_iter()
            .map(|b| {
                let cells = nc * b / BLOCKS.min(nc)..nc * (b + 1) / BLOCKS.min(nc);
                let nodes = || {
                    cells
                        .clone()
                        .flat_map(|c| grid.cell_nodes(c).iter().copied())
                };
                let first = nodes().min().unwrap_or(0);
                let last = nodes().max().unwrap_or(0);
                let mut acc = vec![0.0; D * (last + 1 - first)];
                let (mut pts, mut ids) = (Vec::new(), Vec::new());
                let mut simplices = SimplexBatch::<D>::default();
                for c in cells.clone() {
                    if !keep(c) {
                        continue;
                    }
                    if grid.cell_nodes(c).len() == D + 1 {
                        simplices.cells.push(c);
                        if simplices.cells.len() == SimplexBatch::<D>::CELLS {
                            simplices.load(grid, loads, t, first, &mut acc);
                        }
                    } else {
                        body_load_cell(grid, loads, t, c, first, &mut acc, &mut pts, &mut ids);
                    }
                }
                simplices.load(grid, loads, t, first, &mut acc);
                (D * first, acc)
            })
            .collect();
        for (start, acc) in spans {
            out[start..start + acc.len()]
                .iter_mut()
                .zip(&acc)
                .for_each(|(o, a)| *o += a);
        }
    }
    let mut pts: Vec<Point<D>> = Vec::new();
    let rule = facet_rule::<D>();
    for tr in &loads.tractions {
        for &f in &tr.faces {
            if f >= grid.num_faces() || !grid.is_boundary_face(f) {
                return Err(SimError::Face {
                    condition: format!("traction on `{}`", tr.name),
                    face: f,
                    what: if f >= grid.num_faces() {
                        "is out of range".into()
                    } else {
                        "is not a boundary face".into()
                    },
                });
            }
            let ids = grid.face_nodes(f);
            pts.clear();
            pts.extend(ids.iter().map(|&n| *grid.node(n)));
            let m = ids.len();
            let xf = pts.iter().sum::<Point<D>>() / m as f64;
            for_each_facet::<D>(&pts, |area, _centroid, corners| {
                let a = area.norm();
                let vert = |k: usize| {
                    if corners[k] == usize::MAX {
                        xf
                    } else {
                        pts[corners[k]]
                    }
                };
                for (w, l) in rule {
                    let x: Point<D> = (0..D).map(|k| vert(k) * l[k]).sum();
                    for comp in 0..D {
                        let tv = tr.traction[comp].eval(x.as_slice(), t) * w * a;
                        for k in 0..D {
                            let share = l[k] * tv;
                            if corners[k] == usize::MAX {
                                for &n in ids {
                                    out[D * n + comp] += share / m as f64;
                                }
                            } else {
                                out[D * ids[corners[k]] + comp] += share;
                            }
                        }
                    }
                }
            });
        }
    }
    if let Some(i) = out.iter().position(|v| !v.is_finite()) {
        return Err(SimError::NotFinite {
            location: format!(
                "the external load at node {} at {}, component {}",
                i / D,
                fmt_point(grid.node(i / D).as_slice()),
                AXES[i % D]
            ),
        });
    }
    Ok(())
}

/// Simplices whose body force and gravity are added together: their quadrature points
/// go to the body force in one call ([`crate::VectorField::eval_many`]), so an interpreted
/// expression pays its dispatch once per batch rather than once per point.
#[derive(Default)]
struct SimplexBatch<const D: usize> {
    cells: Vec<usize>,
    points: Vec<[f64; D]>,
    values: Vec<[f64; D]>,
}

impl<const D: usize> SimplexBatch<D> {
    /// Cells per batch.
    const CELLS: usize = 64;

    /// Add the loads of the pending cells to `acc` (the nodal vector from node `first`
    /// on) and empty the batch. On a simplex `φ_i = λ_i` on the whole cell.
    fn load(&mut self, grid: &Grid<D>, loads: &Loads<D>, t: f64, first: usize, acc: &mut [f64]) {
        let rule = simplex_rule::<D>();
        self.points.clear();
        self.values.clear();
        if let Some(b) = &loads.body_force {
            for &c in &self.cells {
                let cn = grid.cell_nodes(c);
                for (_, l) in rule {
                    let x: Point<D> = cn.iter().zip(l).map(|(&i, &li)| grid.node(i) * li).sum();
                    self.points.push(x.into());
                }
            }
            self.values.resize(self.points.len(), [0.0; D]);
            b.eval_many(&self.points, t, &mut self.values);
        }
        for (j, &c) in self.cells.iter().enumerate() {
            let cn = grid.cell_nodes(c);
            let vol = grid.cell_volume(c);
            let rho_g = loads
                .gravity
                .as_ref()
                .map_or(Point::<D>::zeros(), |g| g.g * g.density[c]);
            for (q, (w, l)) in rule.iter().enumerate() {
                let mut fv = rho_g;
                if let Some(v) = self.values.get(j * rule.len() + q) {
                    fv += Point::<D>::from(*v);
                }
                fv *= w * vol;
                for (&i, &li) in cn.iter().zip(l) {
                    for a in 0..D {
                        acc[D * (i - first) + a] += li * fv[a];
                    }
                }
            }
        }
        self.cells.clear();
    }
}

/// Body force and gravity of cell `c` (not a simplex: see [`SimplexBatch`]), added to `acc`, the nodal vector from node `first`
/// on (see the module docs).
fn body_load_cell<const D: usize>(
    grid: &Grid<D>,
    loads: &Loads<D>,
    t: f64,
    c: usize,
    first: usize,
    acc: &mut [f64],
    pts: &mut Vec<Point<D>>,
    ids: &mut Vec<usize>,
) {
    let cn = grid.cell_nodes(c);
    let n = cn.len();
    let rho_g = loads
        .gravity
        .as_ref()
        .map_or(Point::<D>::zeros(), |g| g.g * g.density[c]);
    let xc = cn.iter().map(|&i| grid.node(i)).sum::<Point<D>>() / n as f64;
    let rule = cell_rule::<D>();
    let mut centre = Point::<D>::zeros();
    for (&face, &outward) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
        ids.clear();
        ids.extend(grid.oriented_face_nodes(face, outward));
        pts.clear();
        pts.extend(ids.iter().map(|&i| *grid.node(i)));
        let (pts, ids): (&[Point<D>], &[usize]) = (pts, ids);
        let m = ids.len();
        let xf = pts.iter().sum::<Point<D>>() / m as f64;
        for_each_facet::<D>(pts, |area, centroid, corners| {
            let vol = area.dot(&(centroid - xc)) / D as f64;
            let vert = |k: usize| {
                if corners[k] == usize::MAX {
                    xf
                } else {
                    pts[corners[k]]
                }
            };
            for (w, l) in rule {
                let x: Point<D> = (0..D).map(|k| vert(k) * l[k]).sum::<Point<D>>() + xc * l[D];
                let mut fv = rho_g;
                if let Some(b) = &loads.body_force {
                    fv += Point::<D>::from(b.eval(x.as_slice(), t));
                }
                fv *= w * vol;
                centre += fv * l[D];
                for k in 0..D {
                    if corners[k] == usize::MAX {
                        let share = fv * (l[k] / m as f64);
                        for &i in ids.iter() {
                            for a in 0..D {
                                acc[D * (i - first) + a] += share[a];
                            }
                        }
                    } else {
                        let i = ids[corners[k]];
                        for a in 0..D {
                            acc[D * (i - first) + a] += l[k] * fv[a];
                        }
                    }
                }
            }
        });
    }
    centre /= n as f64;
    for &i in cn {
        for a in 0..D {
            acc[D * (i - first) + a] += centre[a];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::Displacement;
    use porofrac_grid::generate::simplices;
    use porofrac_law::{CellLaw, Stiffness};
    use porofrac_mdem::{DemLaw, DemMode, MdemLaw};
    use porofrac_vem::VemLaw;

    /// With the kept element matrices an assembly equals the one without to rounding (the
    /// forces bitwise), at a displacement that opens some compression-only springs; a cell
    /// that switches law (MDEM → DEM) after the cache was built is evaluated by its new
    /// law, and switching back reuses the first sum.
    #[test]
    fn element_cache_gives_the_same_assembly() {
        let grid = simplices::<2>(Point::<2>::zeros(), Point::<2>::new(2.0, 1.0), [8, 4]).unwrap();
        let st = Stiffness::<2>::isotropic(1.0e9, 0.3).unwrap();
        let vem = VemLaw::new(st.clone());
        let mdem = MdemLaw::new(&st).unwrap();
        let dem = DemLaw::new(&st, DemMode::CompressionOnly).unwrap();
        let nc = grid.num_cells();
        let laws: Vec<&dyn CellLaw<2>> = vec![&vem, &mdem, &dem];
        // VEM, MDEM and a few failed (DEM) cells.
        let of = |c: usize| match c % 7 {
            0 => 2,
            1 | 2 => 0,
            _ => 1,
        };
        let mut map = LawMap::new(&grid, laws, (0..nc).map(of).collect()).unwrap();
        let fix = Displacement {
            name: "ymin".into(),
            faces: grid.boundary("ymin").unwrap(),
            components: [Some(0.0.into()), Some(0.0.into())],
        };
        let dofs = DofMap::new(&grid, std::slice::from_ref(&fix), &[]).unwrap();
        let pattern = Pattern::new(&grid, &dofs).unwrap();
        let cache = ElementCache::new(&grid, &map).unwrap();
        // A displacement with stretched and compressed springs.
        let u: Vec<f64> = (0..dofs.num_dofs())
            .map(|i| 1e-4 * (((i * 37 + 11) % 23) as f64 - 11.0))
            .collect();
        let run = |map: &LawMap<'_, 2>, cache: Option<&ElementCache>| {
            let mut v = vec![0.0; pattern.nnz()];
            let mut f = vec![0.0; dofs.num_equations()];
            assemble_with(
                &grid,
                map,
                &dofs,
                &pattern,
                &u,
                Some(&mut v),
                Some(&mut f),
                cache,
            )
            .unwrap();
            (v, f)
        };
        // Stiffness entries equal up to the order of the sums: 1e-15 of the largest.
        let same = |a: &(Vec<f64>, Vec<f64>), b: &(Vec<f64>, Vec<f64>)| {
            let big = a.0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let dv =
                a.0.iter()
                    .zip(&b.0)
                    .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            dv <= 1e-15 * big && a.1 == b.1
        };
        let before = run(&map, None);
        assert!(same(&before, &run(&map, Some(&cache))));
        // Cells 3 and 4 (MDEM when cached) fail: the cache must not serve them.
        map.set_law(&grid, 3, 2).unwrap();
        map.set_law(&grid, 4, 2).unwrap();
        let after = run(&map, Some(&cache));
        assert!(same(&after, &run(&map, None)));
        // The sum over the new set was formed from the last one where cells 3 and 4
        // scatter: the bits of a full sum (that of a cache built for the new laws).
        let full = |map: &LawMap<'_, 2>| {
            ElementCache::new(&grid, map)
                .unwrap()
                .kept_sum(&grid, map, &dofs, &pattern)
        };
        assert_eq!(*cache.kept_sum(&grid, &map, &dofs, &pattern), *full(&map));
        let big = before.0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let dv = after
            .0
            .iter()
            .zip(&before.0)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(dv > 1e-6 * big, "the failed cells changed the stiffness");
        map.set_law(&grid, 3, 1).unwrap();
        map.set_law(&grid, 4, 1).unwrap();
        assert!(same(&before, &run(&map, Some(&cache))));
        assert_eq!(*cache.kept_sum(&grid, &map, &dofs, &pattern), *full(&map));
        assert!(after.0.iter().chain(&after.1).all(|x| x.is_finite()));
    }

    /// A law that fails on a cell: the assembly, the element cache and the stresses
    /// return its error with the cell and the law's name.
    #[test]
    fn law_errors_name_the_cell() {
        /// VEM, except that its `bad`-th stiffness or stress evaluation (from 0) fails.
        struct Failing {
            inner: VemLaw<2>,
            bad: usize,
            calls: std::sync::atomic::AtomicUsize,
        }
        impl Failing {
            fn fail(&self) -> std::result::Result<(), LawError> {
                let k = self
                    .calls
                    .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                if k == self.bad {
                    return Err(LawError::Evaluation("refused".into()));
                }
                Ok(())
            }
        }
        impl CellLaw<2> for Failing {
            fn name(&self) -> &str {
                "failing"
            }
            fn energy(
                &self,
                cell: &porofrac_law::CellGeometry<'_, 2>,
                u: &[f64],
                s: &mut Scratch,
            ) -> std::result::Result<f64, LawError> {
                self.inner.energy(cell, u, s)
            }
            fn forces(
                &self,
                cell: &porofrac_law::CellGeometry<'_, 2>,
                u: &[f64],
                out: &mut [f64],
                s: &mut Scratch,
            ) -> std::result::Result<(), LawError> {
                self.inner.forces(cell, u, out, s)
            }
            fn stiffness(
                &self,
                cell: &porofrac_law::CellGeometry<'_, 2>,
                u: &[f64],
                out: &mut DMatrix<f64>,
                s: &mut Scratch,
            ) -> std::result::Result<(), LawError> {
                self.fail()?;
                self.inner.stiffness(cell, u, out, s)
            }
            fn stress(
                &self,
                cell: &porofrac_law::CellGeometry<'_, 2>,
                u: &[f64],
                s: &mut Scratch,
            ) -> std::result::Result<porofrac_law::Tensor<2>, LawError> {
                self.fail()?;
                self.inner.stress(cell, u, s)
            }
        }
        let grid = simplices::<2>(Point::<2>::zeros(), Point::<2>::new(2.0, 1.0), [2, 1]).unwrap();
        let st = Stiffness::<2>::isotropic(1.0e9, 0.3).unwrap();
        let vem = VemLaw::new(st);
        // Only cell 3 uses the failing law, so its first call fails.
        let failing = Failing {
            inner: vem.clone(),
            bad: 0,
            calls: Default::default(),
        };
        let laws: Vec<&dyn CellLaw<2>> = vec![&vem, &failing];
        let of = (0..grid.num_cells()).map(|c| usize::from(c == 3)).collect();
        let map = LawMap::new(&grid, laws, of).unwrap();
        let expect = |e: SimError| match e {
            SimError::Law { cell, law, source } => {
                assert_eq!((cell, law.as_str()), (3, "failing"));
                assert_eq!(source, LawError::Evaluation("refused".into()));
            }
            other => panic!("expected a law error, got {other:?}"),
        };
        let Err(e) = ElementCache::new(&grid, &map) else {
            panic!("the failing cell was accepted");
        };
        expect(e);
        failing.calls.store(0, std::sync::atomic::Ordering::Relaxed);
        let u = vec![0.0; 2 * grid.num_nodes()];
        expect(crate::solve::cell_stresses(&grid, &map, &u).unwrap_err());
    }
}
