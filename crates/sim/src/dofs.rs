//! The map from nodal degrees of freedom to equations, and the rigid-body-mode check.
//!
//! # Elimination of prescribed displacements
//!
//! Let `u ∈ R^{D·N}` be the nodal displacements (node-major: dof `D·n + a` is component
//! `a` of node `n`). The dofs split into *prescribed* ones `p` (displacement conditions)
//! and *free* ones. Free dofs map to equations through a matrix `T` with one `1` per row:
//! `u_free = T x`. Normally each free dof has its own equation; the nodes of a platen
//! share one equation per loaded component, so there `T` maps many dofs to one equation.
//! With `K` the global stiffness and `f` the nodal loads, the reduced system is
//!
//! ```text
//!   (Tᵀ K_ff T) x = Tᵀ (f_f − K_fp u_p) + F_platen
//! ```
//!
//! `Tᵀ K_ff T` stays symmetric positive definite when the conditions remove every
//! rigid-body mode; `F_platen` is the total platen force on its equation.
//!
//! # Rigid-body modes
//!
//! The rigid modes are the D translations and the `D(D−1)/2` rotations
//! `r(x) = e_i (x − x_c)_j − e_j (x − x_c)_i` about the grid centre `x_c`, scaled by the
//! grid size. A mode survives the conditions when it vanishes at every prescribed dof and
//! is constant over the nodes of every platen component. With `c_k` the value of mode `k`
//! in one constraint, the surviving modes span the null space of `G = Σ c cᵀ` (a 3×3 or
//! 6×6 matrix): eigenvalues below `1e-10 · max(λ_max, 1)` count as zero.

use nalgebra::DMatrix;
use porofrac_grid::{Grid, Point};

use crate::bc::{Displacement, Platen};
use crate::error::{AXES, Result, SimError, fmt_point};
use crate::field::ScalarField;

/// Marker of a prescribed dof in the dof → equation map.
const FIXED: usize = usize::MAX;

/// One equation shared by the nodes of a platen along one component.
#[derive(Clone, Debug)]
struct PlatenEq {
    name: String,
    component: usize,
    equation: usize,
    force: ScalarField,
    nodes: Vec<usize>,
}

#[derive(Clone, Copy)]
enum Owner {
    None,
    Fixed(usize),
    Platen(usize),
}

/// Maps each nodal dof `(node, component)` to an equation of the reduced system, or marks
/// it prescribed. Built once per grid and set of conditions.
#[derive(Clone, Debug)]
pub struct DofMap<const D: usize> {
    map: Vec<usize>,
    num_eq: usize,
    fixed_dofs: Vec<usize>,
    fixed_values: Vec<ScalarField>,
    platens: Vec<PlatenEq>,
    /// For each equation: the first dof mapped to it (for messages).
    eq_dof: Vec<usize>,
}

impl<const D: usize> DofMap<D> {
    /// Build the map from displacement and platen conditions.
    ///
    /// Errors: a face index out of range; two displacement conditions that prescribe
    /// different values for the same node and component (values are compared at the node
    /// at `t = 0`; equal values from overlapping sides, like rollers meeting at a corner,
    /// are fine); a platen component on a node that also has a prescribed value or
    /// belongs to another platen on that component.
    pub fn new(
        grid: &Grid<D>,
        displacements: &[Displacement<D>],
        platens: &[Platen<D>],
    ) -> Result<Self> {
        let n_dof = D * grid.num_nodes();
        let mut owner = vec![Owner::None; n_dof];
        let mut value_of: Vec<Option<(usize, f64)>> = vec![None; n_dof];
        let describe_fixed =
            |bc: usize, v: f64| format!("displacement on `{}` = {v}", displacements[bc].name);
        for (b, bc) in displacements.iter().enumerate() {
            check_faces(grid, &bc.faces, &format!("displacement on `{}`", bc.name))?;
            for n in grid.nodes_of_faces(&bc.faces) {
                let x = grid.node(n);
                for (a, comp) in bc.components.iter().enumerate() {
                    let Some(field) = comp else { continue };
                    let v = field.eval(x.as_slice(), 0.0);
                    let dof = D * n + a;
                    match owner[dof] {
                        Owner::None => {
                            owner[dof] = Owner::Fixed(b);
                            value_of[dof] = Some((b, v));
                        }
                        Owner::Fixed(b0) => {
                            let (_, v0) = value_of[dof].unwrap_or((b0, v));
                            if (v - v0).abs() > 1e-12 * v.abs().max(v0.abs()) {
                                return Err(conflict(
                                    grid,
                                    n,
                                    a,
                                    describe_fixed(b0, v0),
                                    describe_fixed(b, v),
                                ));
                            }
                        }
                        Owner::Platen(_) => unreachable!("platens are processed later"),
                    }
                }
            }
        }
        let mut platen_eqs: Vec<PlatenEq> = Vec::new();
        for pl in platens {
            check_faces(grid, &pl.faces, &format!("platen on `{}`", pl.name))?;
            let nodes = grid.nodes_of_faces(&pl.faces);
            for (a, force) in pl.force.iter().enumerate() {
                let Some(force) = force else { continue };
                let k = platen_eqs.len();
                for &n in &nodes {
                    let dof = D * n + a;
                    match owner[dof] {
                        Owner::None => owner[dof] = Owner::Platen(k),
                        Owner::Fixed(b) => {
                            let v = value_of[dof].map_or(0.0, |(_, v)| v);
                            return Err(conflict(
                                grid,
                                n,
                                a,
                                describe_fixed(b, v),
                                format!("platen on `{}`", pl.name),
                            ));
                        }
                        Owner::Platen(k0) => {
                            return Err(conflict(
                                grid,
                                n,
                                a,
                                format!("platen on `{}`", platen_eqs[k0].name),
                                format!("platen on `{}`", pl.name),
                            ));
                        }
                    }
                }
                platen_eqs.push(PlatenEq {
                    name: pl.name.clone(),
                    component: a,
                    equation: FIXED,
                    force: force.clone(),
                    nodes: nodes.clone(),
                });
            }
        }
        // Number equations in dof order; a platen's equation gets the number of its first dof.
        let mut map = vec![FIXED; n_dof];
        let mut fixed_dofs = Vec::new();
        let mut fixed_values = Vec::new();
        let mut eq_dof = Vec::new();
        for dof in 0..n_dof {
            match owner[dof] {
                Owner::None => {
                    map[dof] = eq_dof.len();
                    eq_dof.push(dof);
                }
                Owner::Fixed(b) => {
                    fixed_dofs.push(dof);
                    let field = displacements[b].components[dof % D]
                        .clone()
                        .unwrap_or(ScalarField::Const(0.0));
                    fixed_values.push(field);
                }
                Owner::Platen(k) => {
                    if platen_eqs[k].equation == FIXED {
                        platen_eqs[k].equation = eq_dof.len();
                        eq_dof.push(dof);
                    }
                    map[dof] = platen_eqs[k].equation;
                }
            }
        }
        Ok(Self {
            map,
            num_eq: eq_dof.len(),
            fixed_dofs,
            fixed_values,
            platens: platen_eqs,
            eq_dof,
        })
    }

    /// Number of equations of the reduced system.
    pub fn num_equations(&self) -> usize {
        self.num_eq
    }
    /// Number of nodal dofs, `D · nodes`.
    pub fn num_dofs(&self) -> usize {
        self.map.len()
    }
    /// The equation of component `a` of node `n`, or `None` if it is prescribed.
    #[inline]
    pub fn equation(&self, node: usize, a: usize) -> Option<usize> {
        let e = self.map[D * node + a];
        (e != FIXED).then_some(e)
    }
    /// The equation of every dof (node-major), `usize::MAX` for prescribed ones.
    pub(crate) fn raw(&self) -> &[usize] {
        &self.map
    }
    /// The prescribed dofs, in increasing order.
    pub fn prescribed_dofs(&self) -> &[usize] {
        &self.fixed_dofs
    }

    /// A description of equation `e` for messages: `node 12 (x, y) component y`, or the
    /// platen it belongs to.
    pub fn describe_equation(&self, grid: &Grid<D>, e: usize) -> String {
        if let Some(p) = self.platens.iter().find(|p| p.equation == e) {
            return format!("platen on `{}`, component {}", p.name, AXES[p.component]);
        }
        match self.eq_dof.get(e) {
            Some(&dof) => {
                let n = dof / D;
                format!(
                    "node {n} at {}, component {}",
                    fmt_point(grid.node(n).as_slice()),
                    AXES[dof % D]
                )
            }
            None => format!("equation {e} out of range"),
        }
    }

    /// Whether every prescribed value and platen force is a constant
    /// ([`ScalarField::Const`]): then they do not depend on time.
    pub fn is_time_independent(&self) -> bool {
        self.fixed_values.iter().all(|f| f.as_const().is_some())
            && self.platens.iter().all(|p| p.force.as_const().is_some())
    }

    /// Write the prescribed values at time `t` into the nodal vector `u` (length
    /// [`Self::num_dofs`]); other entries are left as they are.
    pub fn set_prescribed(&self, grid: &Grid<D>, t: f64, u: &mut [f64]) {
        for (&dof, field) in self.fixed_dofs.iter().zip(&self.fixed_values) {
            u[dof] = field.eval(grid.node(dof / D).as_slice(), t);
        }
    }

    /// Set the free entries of the nodal vector `u` from the equation values `x`
    /// (`u_f = T x`); prescribed entries are left as they are.
    pub fn scatter(&self, x: &[f64], u: &mut [f64]) {
        for (ui, &e) in u.iter_mut().zip(&self.map) {
            if e != FIXED {
                *ui = x[e];
            }
        }
    }

    /// Add the equation increments `dx` to the free entries of the nodal vector `u`
    /// (`u_f += T dx`).
    pub fn scatter_add(&self, dx: &[f64], u: &mut [f64]) {
        for (ui, &e) in u.iter_mut().zip(&self.map) {
            if e != FIXED {
                *ui += dx[e];
            }
        }
    }

    /// Add `Tᵀ f` to `out`: the nodal vector `f` summed into the equations.
    pub fn reduce_add(&self, f: &[f64], out: &mut [f64]) {
        for (fi, &e) in f.iter().zip(&self.map) {
            if e != FIXED {
                out[e] += fi;
            }
        }
    }

    /// Add the total platen forces at time `t` to their equations in `out`.
    pub fn add_platen_forces(&self, grid: &Grid<D>, t: f64, out: &mut [f64]) {
        for p in &self.platens {
            let mean = p.nodes.iter().map(|&n| grid.node(n)).sum::<Point<D>>()
                / p.nodes.len().max(1) as f64;
            out[p.equation] += p.force.eval(mean.as_slice(), t);
        }
    }

    /// The rigid-body modes that the conditions leave free (empty when the stiffness of a
    /// connected grid is positive definite). See the module docs for the test.
    pub fn free_rigid_modes(&self, grid: &Grid<D>) -> Vec<String> {
        self.free_modes_where(grid, |_| true)
    }

    /// The parts of the grid joined through shared nodes: the part of every node (the
    /// nodes of a platen count as joined, as they share an equation; `usize::MAX` for a
    /// node of no cell), and the number of parts.
    fn node_parts(&self, grid: &Grid<D>) -> (Vec<usize>, usize) {
        let n = grid.num_nodes();
        let mut parent: Vec<usize> = (0..n).collect();
        fn root(parent: &mut [usize], mut a: usize) -> usize {
            while parent[a] != a {
                parent[a] = parent[parent[a]];
                a = parent[a];
            }
            a
        }
        let mut join = |nodes: &[usize]| {
            if let Some(&first) = nodes.first() {
                let r = root(&mut parent, first);
                for &m in &nodes[1..] {
                    let q = root(&mut parent, m);
                    parent[q] = r;
                }
            }
        };
        for c in 0..grid.num_cells() {
            join(grid.cell_nodes(c));
        }
        for p in &self.platens {
            join(&p.nodes);
        }
        let mut used = vec![false; n];
        for c in 0..grid.num_cells() {
            for &m in grid.cell_nodes(c) {
                used[m] = true;
            }
        }
        let mut id = vec![usize::MAX; n];
        let mut part = vec![usize::MAX; n];
        let mut count = 0;
        for m in 0..n {
            if used[m] {
                let r = root(&mut parent, m);
                if id[r] == usize::MAX {
                    id[r] = count;
                    count += 1;
                }
                part[m] = id[r];
            }
        }
        (part, count)
    }

    /// [`Self::free_rigid_modes`] counting only the conditions on nodes `keep` accepts.
    fn free_modes_where(&self, grid: &Grid<D>, keep: impl Fn(usize) -> bool) -> Vec<String> {
        let names = rigid_mode_names::<D>();
        let m = names.len();
        let (lo, hi) = grid.bounding_box();
        let centre = (lo + hi) * 0.5;
        let scale = (hi - lo).amax().max(f64::MIN_POSITIVE);
        let mode = |k: usize, x: &Point<D>, a: usize| rigid_mode::<D>(k, x, &centre, scale, a);
        let mut g = DMatrix::<f64>::zeros(m, m);
        let mut c = vec![0.0; m];
        let mut add = |c: &[f64]| {
            for i in 0..m {
                for j in 0..m {
                    g[(i, j)] += c[i] * c[j];
                }
            }
        };
        for &dof in self.fixed_dofs.iter().filter(|&&dof| keep(dof / D)) {
            let x = grid.node(dof / D);
            for (k, ck) in c.iter_mut().enumerate() {
                *ck = mode(k, x, dof % D);
            }
            add(&c);
        }
        for p in &self.platens {
            let Some(&first) = p.nodes.first().filter(|&&n| keep(n)) else {
                continue;
            };
            let x0 = grid.node(first);
            for &n in &p.nodes[1..] {
                let x = grid.node(n);
                for (k, ck) in c.iter_mut().enumerate() {
                    *ck = mode(k, x, p.component) - mode(k, x0, p.component);
                }
                add(&c);
            }
        }
        let eig = g.clone().symmetric_eigen();
        let lmax = eig.eigenvalues.amax();
        let tol = 1e-10 * lmax.max(1.0);
        let null: Vec<usize> = (0..m).filter(|&i| eig.eigenvalues[i] <= tol).collect();
        // Basic modes in the null space (G e_k = 0 ⇔ G_kk = 0 for G ⪰ 0).
        let basic: Vec<usize> = (0..m).filter(|&k| g[(k, k)] <= tol).collect();
        let mut out: Vec<String> = basic.iter().map(|&k| names[k].clone()).collect();
        if basic.len() < null.len() {
            // Combinations: null vectors with the basic components removed, orthonormalised.
            let mut kept: Vec<Vec<f64>> = Vec::new();
            for &i in &null {
                let mut v: Vec<f64> = eig.eigenvectors.column(i).iter().copied().collect();
                for &k in &basic {
                    v[k] = 0.0;
                }
                for w in &kept {
                    let d: f64 = v.iter().zip(w).map(|(a, b)| a * b).sum();
                    v.iter_mut().zip(w).for_each(|(a, b)| *a -= d * b);
                }
                let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
                if norm > 1e-6 {
                    v.iter_mut().for_each(|a| *a /= norm);
                    kept.push(v);
                }
                if basic.len() + kept.len() == null.len() {
                    break;
                }
            }
            for v in kept {
                let big = v.iter().fold(0.0f64, |acc, a| acc.max(a.abs()));
                let terms: Vec<String> = v
                    .iter()
                    .enumerate()
                    .filter(|(_, a)| a.abs() > 1e-8 * big)
                    .map(|(k, a)| format!("{:.3} {}", a / big, names[k]))
                    .collect();
                out.push(terms.join(" + "));
            }
        }
        out
    }

    /// Error [`SimError::Singular`] naming the free rigid-body modes, if there are any;
    /// for a grid in parts joined by no node (an island of cells), each part must have
    /// none, else [`SimError::FloatingPart`] names the part's size and one of its cells.
    pub fn check_rigid_modes(&self, grid: &Grid<D>) -> Result<()> {
        let (part, parts) = self.node_parts(grid);
        if parts > 1 {
            let mut cells = vec![0usize; parts];
            let mut first = vec![usize::MAX; parts];
            for c in 0..grid.num_cells() {
                let p = part[grid.cell_nodes(c)[0]];
                cells[p] += 1;
                first[p] = first[p].min(c);
            }
            // Smallest parts first, so that an error names an island rather than the
            // main part when both are free.
            let mut order: Vec<usize> = (0..parts).collect();
            order.sort_by_key(|&p| (std::cmp::Reverse(cells[p]), first[p]));
            for &p in order.iter().rev() {
                let modes = self.free_modes_where(grid, |n| part[n] == p);
                if !modes.is_empty() {
                    let c = first[p];
                    return Err(SimError::FloatingPart {
                        cells: cells[p],
                        total: grid.num_cells(),
                        cell: format!(
                            "cell {c} at {}",
                            fmt_point(grid.cell_centroid(c).as_slice())
                        ),
                        cell_index: c,
                        modes,
                    });
                }
            }
            return Ok(());
        }
        let modes = self.free_rigid_modes(grid);
        if modes.is_empty() {
            Ok(())
        } else {
            Err(SimError::Singular { modes })
        }
    }
}

/// Names of the rigid modes: translations, then rotations.
fn rigid_mode_names<const D: usize>() -> Vec<String> {
    let mut v: Vec<String> = (0..D).map(|a| format!("translation {}", AXES[a])).collect();
    for &(_, _, axis) in rotation_pairs::<D>() {
        v.push(format!("rotation about {axis}"));
    }
    v
}

fn rotation_pairs<const D: usize>() -> &'static [(usize, usize, &'static str)] {
    if D == 2 {
        &[(0, 1, "z")]
    } else {
        &[(1, 2, "x"), (2, 0, "y"), (0, 1, "z")]
    }
}

/// Component `a` of rigid mode `k` at `x`.
fn rigid_mode<const D: usize>(
    k: usize,
    x: &Point<D>,
    centre: &Point<D>,
    scale: f64,
    a: usize,
) -> f64 {
    if k < D {
        return if a == k { 1.0 } else { 0.0 };
    }
    let (i, j, _) = rotation_pairs::<D>()[k - D];
    if a == i {
        -(x[j] - centre[j]) / scale
    } else if a == j {
        (x[i] - centre[i]) / scale
    } else {
        0.0
    }
}

fn check_faces<const D: usize>(grid: &Grid<D>, faces: &[usize], what: &str) -> Result<()> {
    match faces.iter().find(|&&f| f >= grid.num_faces()) {
        Some(&f) => Err(SimError::Face {
            condition: what.to_string(),
            face: f,
            what: format!("is out of range (grid has {} faces)", grid.num_faces()),
        }),
        None => Ok(()),
    }
}

fn conflict<const D: usize>(
    grid: &Grid<D>,
    node: usize,
    a: usize,
    first: String,
    second: String,
) -> SimError {
    SimError::Conflict {
        node,
        position: fmt_point(grid.node(node).as_slice()),
        component: AXES[a],
        first,
        second,
    }
}
