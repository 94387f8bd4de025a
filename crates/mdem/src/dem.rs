//! The central-force DEM law (Nilsen et al. (2017) §2.6, eqs. 32–33).
//!
//! Each edge of the simplex is an independent spring with stiffness
//! `k_i = 𝐊_ii`, the diagonal of the MDEM edge stiffness `𝐊 = |K| M⁻ᵀ D M⁻¹` of the
//! cell's geometry and material. Edge forces are `F = 𝐊_d(U) U`:
//!
//! * [`DemMode::Elastic`] — `𝐊_d = diag(𝐊)` in tension and compression (a linear law;
//!   `law = "dem"` in a scene). Its effective Cauchy stiffness `Mᵀ 𝐊_d M / |K|`
//!   differs from `D` unless `𝐊` is diagonal (see [`crate::dem_stiffness_loss`]).
//! * [`DemMode::CompressionOnly`] — the post-failure law of eq. 33:
//!   `𝐊_d(U)_ii = 𝐊_ii` if `U_i < 0` (the edge shortens), else 0. The energy is
//!   `E = ½ Σ_i 𝐊_ii min(U_i, 0)²` (continuously differentiable), the forces are its
//!   exact negative gradient and the stiffness its Hessian away from `U_i = 0` (an edge
//!   with `U_i = 0` counts as open). Not linear: [`CellLaw::is_linear`] is false, but
//!   piecewise linear ([`CellLaw::is_piecewise_linear`]: `F = −K(u) u`). Optionally open
//!   edges keep a residual fraction of their stiffness ([`DemLaw::with_open_stiffness`]).
//!
//! Stress follows eq. 18: `σ = (1/|K|) Mᵀ F`, i.e. `σ = (1/|K|) Σ_i F_i l_i t_i ⊗ t_i`.

use nalgebra::{DMatrix, SMatrix, SVector};
use porofrac_grid::Point;
use porofrac_law::{CellGeometry, CellLaw, LawError, Scratch, Stiffness, Tensor};

use crate::MdemError;
use crate::mdem::{Material, check_len};
use crate::simplex::{Frame, tensor_from_kelvin, with_k};

/// Which edges carry load.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DemMode {
    /// All edges act, in tension and compression.
    Elastic,
    /// Only shortening edges act (post-failure, Nilsen et al. (2017) eq. 33).
    CompressionOnly,
}

/// State of one edge spring.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeState {
    /// The spring carries load.
    Closed,
    /// The spring is open (a lengthened edge of a fractured cell): no force.
    Open,
}

/// The central-force DEM law on simplices; see the module docs.
///
/// Misuse through the [`CellLaw`] trait (a cell that is not a simplex, a degenerate
/// simplex, slices of the wrong length) returns a [`porofrac_law::LawError`], as for
/// [`crate::MdemLaw`]; the `try_*` methods return the [`MdemError`].
#[derive(Clone, Debug, PartialEq)]
pub struct DemLaw<const D: usize> {
    mat: Material,
    mode: DemMode,
    open_ratio: f64,
}

impl<const D: usize> DemLaw<D> {
    /// A DEM law whose springs are the diagonal of the MDEM edge stiffness of the
    /// material `stiffness` on each cell. Errors only if `D` is not 2 or 3.
    pub fn new(stiffness: &Stiffness<D>, mode: DemMode) -> Result<Self, MdemError> {
        Self::from_kelvin(&stiffness.to_dmatrix(), mode)
    }

    /// As [`DemLaw::new`], from a Kelvin stiffness matrix (`3×3` in 2D, `6×6` in 3D;
    /// symmetric positive definite).
    pub fn from_kelvin(d: &DMatrix<f64>, mode: DemMode) -> Result<Self, MdemError> {
        Ok(Self {
            mat: Material::new(D, d)?,
            mode,
            open_ratio: 0.0,
        })
    }

    /// Keep a residual fraction `ratio` (in [0, 1)) of the spring stiffness on open edges
    /// of the compression-only law: `𝐊_d(U)_ii = ratio · 𝐊_ii` for `U_i ≥ 0`. The default
    /// 0 is eq. 33 exactly; a small ratio (e.g. 1e-6) keeps a node whose every edge is
    /// open determined in an implicit solve (the law stays piecewise linear). Errors if
    /// `ratio` is not in [0, 1).
    pub fn with_open_stiffness(mut self, ratio: f64) -> Result<Self, MdemError> {
        if !(ratio.is_finite() && (0.0..1.0).contains(&ratio)) {
            return Err(MdemError::OpenStiffness(ratio));
        }
        self.open_ratio = ratio;
        Ok(self)
    }

    /// The residual stiffness ratio of open edges (see [`DemLaw::with_open_stiffness`]).
    pub fn open_stiffness(&self) -> f64 {
        self.open_ratio
    }

    /// The mode.
    pub fn mode(&self) -> DemMode {
        self.mode
    }

    /// The material stiffness `D` (Kelvin form) the springs derive from.
    pub fn material(&self) -> DMatrix<f64> {
        self.mat.dynamic(D)
    }

    /// Per edge: the acting spring stiffness `𝐊_d(U)_ii`, and the elongation.
    fn springs<const K: usize>(
        &self,
        f: &Frame<D, K>,
        u: &[f64],
    ) -> (SVector<f64, K>, SVector<f64, K>) {
        let kmat: SMatrix<f64, K, K> = f.edge_stiffness(&self.mat.fixed::<K>());
        let du = f.elongations(u);
        let kd = SVector::<f64, K>::from_fn(|i, _| match self.mode {
            DemMode::Elastic => kmat[(i, i)],
            DemMode::CompressionOnly if du[i] < 0.0 => kmat[(i, i)],
            DemMode::CompressionOnly => self.open_ratio * kmat[(i, i)],
        });
        (kd, du)
    }

    fn frame_for<const K: usize>(coords: &[Point<D>], u: &[f64]) -> Result<Frame<D, K>, MdemError> {
        let f = Frame::<D, K>::new(coords)?;
        check_len("u", u.len(), D * (D + 1))?;
        Ok(f)
    }

    /// The full (unswitched) spring stiffnesses `diag 𝐊` of a simplex, length `K`.
    pub fn spring_stiffness(&self, coords: &[Point<D>], out: &mut [f64]) -> Result<(), MdemError> {
        with_k!(D, |K| {
            let f = Frame::<D, K>::new(coords)?;
            check_len("out", out.len(), K)?;
            let kmat = f.edge_stiffness(&self.mat.fixed::<K>());
            for i in 0..K {
                out[i] = kmat[(i, i)];
            }
            Ok(())
        })
    }

    /// Which edges are open for displacements `u` (edge order of [`crate::edges`]):
    /// in compression-only mode an edge with `U_i ≥ 0` is open; in elastic mode all are
    /// closed.
    pub fn edge_states(
        &self,
        coords: &[Point<D>],
        u: &[f64],
        out: &mut [EdgeState],
    ) -> Result<(), MdemError> {
        with_k!(D, |K| {
            let f = Self::frame_for::<K>(coords, u)?;
            check_len("out", out.len(), K)?;
            let du = f.elongations(u);
            for i in 0..K {
                out[i] = match self.mode {
                    DemMode::CompressionOnly if du[i] >= 0.0 => EdgeState::Open,
                    _ => EdgeState::Closed,
                };
            }
            Ok(())
        })
    }

    /// Edge forces `F = 𝐊_d(U) U` (eq. 32; tension positive), length `K`.
    pub fn edge_forces(
        &self,
        coords: &[Point<D>],
        u: &[f64],
        out: &mut [f64],
    ) -> Result<(), MdemError> {
        with_k!(D, |K| {
            let f = Self::frame_for::<K>(coords, u)?;
            check_len("out", out.len(), K)?;
            let (kd, du) = self.springs(&f, u);
            out.copy_from_slice(kd.component_mul(&du).as_slice());
            Ok(())
        })
    }

    /// Energy `½ Σ 𝐊_d(U)_ii U_i²`, or an error.
    pub fn try_energy(&self, cell: &CellGeometry<'_, D>, u: &[f64]) -> Result<f64, MdemError> {
        with_k!(D, |K| {
            let f = Self::frame_for::<K>(cell.coords, u)?;
            let (kd, du) = self.springs(&f, u);
            Ok(0.5 * (0..K).map(|i| kd[i] * du[i] * du[i]).sum::<f64>())
        })
    }

    /// Nodal forces `−∂E/∂u`, or an error.
    pub fn try_forces(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut [f64],
    ) -> Result<(), MdemError> {
        with_k!(D, |K| {
            let f = Self::frame_for::<K>(cell.coords, u)?;
            check_len("out", out.len(), D * (D + 1))?;
            let (kd, du) = self.springs(&f, u);
            f.nodal_forces(&kd.component_mul(&du), out);
            Ok(())
        })
    }

    /// Local stiffness `Rᵀ 𝐊_d(U) R` at `u`, or an error.
    pub fn try_stiffness(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), MdemError> {
        with_k!(D, |K| {
            let f = Self::frame_for::<K>(cell.coords, u)?;
            let n = D * (D + 1);
            if out.shape() != (n, n) {
                *out = DMatrix::zeros(n, n);
            }
            let (kd, _) = self.springs(&f, u);
            f.nodal_stiffness(&SMatrix::<f64, K, K>::from_diagonal(&kd), out);
            Ok(())
        })
    }

    /// Stress `σ = (1/|K|) Mᵀ F` (Nilsen et al. (2017) eq. 18), or an error.
    pub fn try_stress(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
    ) -> Result<Tensor<D>, MdemError> {
        with_k!(D, |K| {
            let f = Self::frame_for::<K>(cell.coords, u)?;
            let (kd, du) = self.springs(&f, u);
            let s = f.m.transpose() * kd.component_mul(&du) / f.volume;
            Ok(tensor_from_kelvin::<D, K>(&s))
        })
    }
}

impl<const D: usize> CellLaw<D> for DemLaw<D> {
    fn name(&self) -> &str {
        match self.mode {
            DemMode::Elastic => "dem",
            DemMode::CompressionOnly => "dem-compression",
        }
    }

    fn is_linear(&self) -> bool {
        self.mode == DemMode::Elastic
    }

    /// Both modes: an edge force is `𝐊_ii U_i` or 0, so `F = −K(u) u` exactly.
    fn is_piecewise_linear(&self) -> bool {
        true
    }

    fn supports(&self, num_nodes: usize) -> bool {
        (D == 2 || D == 3) && num_nodes == D + 1
    }

    fn energy(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        _scratch: &mut Scratch,
    ) -> Result<f64, LawError> {
        Ok(self.try_energy(cell, u)?)
    }

    fn forces(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut [f64],
        _scratch: &mut Scratch,
    ) -> Result<(), LawError> {
        Ok(self.try_forces(cell, u, out)?)
    }

    fn stiffness(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut DMatrix<f64>,
        _scratch: &mut Scratch,
    ) -> Result<(), LawError> {
        Ok(self.try_stiffness(cell, u, out)?)
    }

    fn stress(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        _scratch: &mut Scratch,
    ) -> Result<Tensor<D>, LawError> {
        Ok(self.try_stress(cell, u)?)
    }
}
