//! The [`CellLaw`] trait, Kelvin notation and elastic stiffness tensors.
//!
//! A *cell law* turns the nodal displacements of one cell into its elastic energy, the
//! forces it exerts on its nodes, its stress, and its local stiffness (Nilsen et al. (2017)
//! §2: VEM, MDEM and central-force DEM are all cell laws). Laws know nothing about sparse
//! matrices or grids beyond the [`CellGeometry`] view of one cell; assembly lives in
//! `porofrac-sim`.
//!
//! # Conventions
//!
//! * Displacements and forces of a cell are flat slices, node-major: dof `D·i + a` is
//!   component `a` of the cell's `i`-th node (the order of [`CellGeometry::coords`]).
//! * [`CellLaw::forces`] returns the forces the cell exerts *on* its nodes,
//!   `F = −∂E/∂u` (restoring); [`CellLaw::stiffness`] returns `K = ∂²E/∂u² = −∂F/∂u`,
//!   symmetric positive semi-definite for a stable law.
//! * Tension is positive; stress is returned as a symmetric `D × D` tensor.
//!
//! # Modules
//!
//! * [`kelvin`] — Kelvin notation for symmetric tensors (`[e11, e22, √2 e12]` in 2D,
//!   `[e11, e22, e33, √2 e23, √2 e13, √2 e12]` in 3D) and its fixed-size representation.
//! * [`stiffness`] — [`Stiffness`]: isotropic (3D, plane strain, plane stress) and
//!   general anisotropic elastic stiffness in Kelvin form, validated.
//! * [`testkit`] — the invariants every cell law must satisfy, as checks usable from any
//!   crate's tests (the `user_law` example of `porofrac-scene` defines a law outside
//!   porofrac and uses it in a scene).

pub mod error;
pub mod kelvin;
pub mod principal;
pub mod stiffness;
pub mod testkit;

pub use error::LawError;
pub use kelvin::{Kelvin, KelvinMatrix, kelvin_len};
pub use principal::{Principal, principal};
pub use stiffness::Stiffness;

use error::Result;
use nalgebra::{DMatrix, SMatrix};
use porofrac_grid::{Grid, Point};

/// Make `m` a zero `rows × cols` matrix, reusing its allocation when it is large enough.
///
/// `DMatrix::resize_mut` clones; this helper keeps the buffer, so a matrix reused across
/// cells of different sizes allocates only when it has to grow.
pub fn zero_matrix(m: &mut DMatrix<f64>, rows: usize, cols: usize) {
    if m.nrows() == rows && m.ncols() == cols {
        m.fill(0.0);
        return;
    }
    let mut v: Vec<f64> = std::mem::replace(m, DMatrix::zeros(0, 0)).data.into();
    v.clear();
    v.resize(rows * cols, 0.0);
    *m = DMatrix::from_vec(rows, cols, v);
}

/// A symmetric second-order tensor (stress or strain) in D dimensions.
pub type Tensor<const D: usize> = SMatrix<f64, D, D>;

/// The geometry of one cell as a law sees it.
///
/// `node_normals[i] = ∫_∂K φ_i n dS` (see [`Grid::cell_node_normals`]); they satisfy
/// `Σ_i node_normals[i] ⊗ coords[i] = volume · I`, and the exact volume change of the
/// cell under nodal displacements `u` is `Σ_i node_normals[i] · u_i`.
#[derive(Clone, Copy, Debug)]
pub struct CellGeometry<'a, const D: usize> {
    /// Node coordinates, in the cell's node order (counter-clockwise in 2D).
    pub coords: &'a [Point<D>],
    /// Boundary integrals of the nodal basis functions times the outward normal.
    pub node_normals: &'a [Point<D>],
    /// Cell volume (area in 2D).
    pub volume: f64,
}

impl<const D: usize> CellGeometry<'_, D> {
    /// Check that a law can evaluate the cell: as many node normals as nodes, and a
    /// positive, finite volume. Errors: [`LawError::WrongLength`] or
    /// [`LawError::DegenerateCell`] (with the largest node distance as the length scale).
    #[inline]
    pub fn check(&self) -> Result<()> {
        if self.node_normals.len() != self.coords.len() {
            return Err(LawError::WrongLength {
                what: "node normals",
                got: self.node_normals.len(),
                expected: self.coords.len(),
            });
        }
        if !(self.volume > 0.0 && self.volume.is_finite()) {
            return Err(self.degenerate());
        }
        Ok(())
    }

    /// Check that a nodal slice (`what`: displacements, forces) has `D` entries per node.
    #[inline]
    pub fn check_len(&self, what: &'static str, len: usize) -> Result<()> {
        if len == D * self.coords.len() {
            Ok(())
        } else {
            Err(LawError::WrongLength {
                what,
                got: len,
                expected: D * self.coords.len(),
            })
        }
    }

    /// [`LawError::DegenerateCell`] for this cell, with its largest node distance as the
    /// length scale.
    #[cold]
    pub fn degenerate(&self) -> LawError {
        let mut scale: f64 = 0.0;
        for (i, a) in self.coords.iter().enumerate() {
            for b in &self.coords[i + 1..] {
                scale = scale.max((a - b).norm());
            }
        }
        LawError::DegenerateCell {
            volume: self.volume,
            scale,
        }
    }
}

/// Reusable buffers that let one thread evaluate many cells without allocating.
///
/// Create one per thread (e.g. with rayon's `map_init`) and pass it to every call; a law
/// may resize and overwrite any field.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    /// Dense work matrices.
    pub mats: [DMatrix<f64>; 4],
    /// Work vectors.
    pub vecs: [Vec<f64>; 2],
}

/// Buffers for the geometry of one cell, filled from a grid.
#[derive(Clone, Debug, Default)]
pub struct GeometryBuffer<const D: usize> {
    coords: Vec<Point<D>>,
    normals: Vec<Point<D>>,
}

impl<const D: usize> GeometryBuffer<D> {
    /// Fill the buffers for cell `c` of `grid` and return the view.
    pub fn load<'a>(&'a mut self, grid: &Grid<D>, c: usize) -> CellGeometry<'a, D> {
        let nodes = grid.cell_nodes(c);
        self.coords.clear();
        self.coords.extend(nodes.iter().map(|&n| *grid.node(n)));
        self.normals.resize(nodes.len(), Point::<D>::zeros());
        grid.cell_node_normals(c, &mut self.normals);
        CellGeometry {
            coords: &self.coords,
            node_normals: &self.normals,
            volume: grid.cell_volume(c),
        }
    }
}

/// A constitutive law of one cell: energy, nodal forces, stress and stiffness.
///
/// The trait is object safe, so a scene can hold `Box<dyn CellLaw<D>>` for laws defined
/// in other crates. A law is immutable during evaluation; state that changes in time
/// (e.g. which cells are fractured) is held by the caller, which picks the law per cell.
pub trait CellLaw<const D: usize>: Send + Sync {
    /// A short name for output (`"vem"`, `"mdem"`, ...).
    fn name(&self) -> &str;

    /// Whether the stiffness is independent of the displacement. Linear laws are
    /// assembled once; nonlinear ones (e.g. compression-only DEM) are re-evaluated.
    fn is_linear(&self) -> bool {
        true
    }

    /// Whether the forces are `F(u) = −K(u) u` with `K(u)` the [`CellLaw::stiffness`] at
    /// `u`, and `K(u)` is piecewise constant (e.g. compression-only DEM: each edge spring
    /// is on or off). Such a law is solved exactly by a linear solve per *active set*:
    /// linearize at `u`, solve, repeat until the stiffness at the solution equals the one
    /// used. Linear laws are trivially piecewise linear.
    fn is_piecewise_linear(&self) -> bool {
        self.is_linear()
    }

    /// Whether the law can handle a cell with `num_nodes` nodes (MDEM: simplices only).
    fn supports(&self, num_nodes: usize) -> bool {
        let _ = num_nodes;
        true
    }

    /// Elastic energy of the cell for nodal displacements `u` (length `D·n`).
    ///
    /// Errors: a cell the law cannot evaluate ([`LawError::UnsupportedNodeCount`],
    /// [`LawError::DegenerateCell`], [`LawError::WrongLength`]); the same for every
    /// method below.
    fn energy(&self, cell: &CellGeometry<'_, D>, u: &[f64], scratch: &mut Scratch) -> Result<f64>;

    /// Forces the cell exerts on its nodes, `F = −∂E/∂u`, written to `out` (length `D·n`).
    fn forces(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<()>;

    /// Local stiffness `K = ∂²E/∂u²` at `u`, written to `out` (resized to `D·n × D·n`).
    fn stiffness(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut DMatrix<f64>,
        scratch: &mut Scratch,
    ) -> Result<()>;

    /// Cell stress for nodal displacements `u` (tension positive).
    fn stress(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        scratch: &mut Scratch,
    ) -> Result<Tensor<D>>;
}
