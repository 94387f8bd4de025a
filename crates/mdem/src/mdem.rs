//! The MDEM cell law (Nilsen et al. (2017) §2.2, eqs. 15–21).

use nalgebra::{DMatrix, SMatrix, SVector};
use porofrac_grid::Point;
use porofrac_law::{CellGeometry, CellLaw, LawError, Scratch, Stiffness, Tensor};

use crate::MdemError;
use crate::simplex::{Frame, kelvin_size, tensor_from_kelvin, with_k};

/// A validated Kelvin material stiffness, padded to 6×6 so one type serves 2D and 3D.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Material {
    pub d: SMatrix<f64, 6, 6>,
}

impl Material {
    pub fn new(dim: usize, d: &DMatrix<f64>) -> Result<Self, MdemError> {
        if dim != 2 && dim != 3 {
            return Err(MdemError::UnsupportedDimension(dim));
        }
        let k = kelvin_size(dim);
        if d.nrows() != k || d.ncols() != k {
            return Err(MdemError::MaterialShape {
                rows: d.nrows(),
                cols: d.ncols(),
                expected: k,
            });
        }
        let scale = d.amax();
        for i in 0..k {
            for j in 0..k {
                if !d[(i, j)].is_finite() {
                    return Err(MdemError::MaterialNotFinite { i, j });
                }
                if (d[(i, j)] - d[(j, i)]).abs() > 1e-12 * scale {
                    return Err(MdemError::MaterialNotSymmetric {
                        i,
                        j,
                        a: d[(i, j)],
                        b: d[(j, i)],
                    });
                }
            }
        }
        if d.clone().cholesky().is_none() {
            return Err(MdemError::MaterialNotPositiveDefinite);
        }
        let mut p = SMatrix::<f64, 6, 6>::zeros();
        for i in 0..k {
            for j in 0..k {
                p[(i, j)] = 0.5 * (d[(i, j)] + d[(j, i)]);
            }
        }
        Ok(Self { d: p })
    }

    #[inline]
    pub fn fixed<const K: usize>(&self) -> SMatrix<f64, K, K> {
        SMatrix::<f64, K, K>::from_fn(|i, j| self.d[(i, j)])
    }

    pub fn dynamic(&self, dim: usize) -> DMatrix<f64> {
        let k = kelvin_size(dim);
        DMatrix::from_fn(k, k, |i, j| self.d[(i, j)])
    }
}

pub(crate) fn check_len(what: &'static str, got: usize, expected: usize) -> Result<(), MdemError> {
    if got != expected {
        return Err(MdemError::Length {
            what,
            got,
            expected,
        });
    }
    Ok(())
}

/// The MDEM law: linear elasticity on a simplex expressed through edge elongations.
///
/// Energy `E = ½ Uᵀ 𝐊 U` with `𝐊 = |K| M⁻ᵀ D M⁻¹` (see the crate docs), which equals
/// `|K| · ½ ε·Dε` for the cell's (constant) strain; the local stiffness is the P1 FEM
/// stiffness of the simplex.
///
/// The law stores the material `D`; everything geometric is computed per cell on the
/// stack (fixed-size 3×3 / 6×6 matrices), so evaluation never allocates (the
/// [`Scratch`] is not needed; [`CellLaw::stiffness`] only resizes `out` when its shape
/// is wrong).
///
/// # Cells that are not simplices
///
/// [`CellLaw::supports`] is true only for `D + 1` nodes. Evaluating the law through the
/// [`CellLaw`] trait on any other cell, on a degenerate simplex, or with slices of the
/// wrong length does not panic: it returns the [`porofrac_law::LawError`] (a wrong
/// node count, a degenerate cell, a wrong length) and leaves the outputs untouched. The
/// methods [`MdemLaw::try_energy`], [`MdemLaw::try_forces`], ... return the
/// [`MdemError`] itself. A scene rejects such a composition before evaluating.
#[derive(Clone, Debug, PartialEq)]
pub struct MdemLaw<const D: usize> {
    mat: Material,
}

impl<const D: usize> MdemLaw<D> {
    /// A law for the material `stiffness` (any anisotropy). Errors only if `D` is not
    /// 2 or 3.
    pub fn new(stiffness: &Stiffness<D>) -> Result<Self, MdemError> {
        Self::from_kelvin(&stiffness.to_dmatrix())
    }

    /// A law for the Kelvin stiffness matrix `d` (`3×3` in 2D, `6×6` in 3D; symmetric
    /// positive definite; any anisotropy).
    pub fn from_kelvin(d: &DMatrix<f64>) -> Result<Self, MdemError> {
        Ok(Self {
            mat: Material::new(D, d)?,
        })
    }

    /// The material stiffness `D` (Kelvin form).
    pub fn material(&self) -> DMatrix<f64> {
        self.mat.dynamic(D)
    }

    /// The MDEM edge stiffness `𝐊 = |K| M⁻ᵀ D M⁻¹` of the simplex `coords` (`K × K`,
    /// edges in [`crate::edges`] order).
    pub fn edge_stiffness(&self, coords: &[Point<D>]) -> Result<DMatrix<f64>, MdemError> {
        with_k!(D, |K| {
            let f = Frame::<D, K>::new(coords)?;
            let k = f.edge_stiffness(&self.mat.fixed::<K>());
            Ok(DMatrix::from_fn(K, K, |i, j| k[(i, j)]))
        })
    }

    /// Edge elongations `U` (length `K`) for nodal displacements `u` (length `D(D+1)`).
    pub fn edge_elongations(
        &self,
        coords: &[Point<D>],
        u: &[f64],
        out: &mut [f64],
    ) -> Result<(), MdemError> {
        with_k!(D, |K| {
            let f = Frame::<D, K>::new(coords)?;
            check_len("u", u.len(), D * (D + 1))?;
            check_len("out", out.len(), K)?;
            out.copy_from_slice(f.elongations(u).as_slice());
            Ok(())
        })
    }

    /// Edge forces `F = 𝐊 U` (Nilsen et al. (2017) eq. 17; tension positive), length `K`.
    pub fn edge_forces(
        &self,
        coords: &[Point<D>],
        u: &[f64],
        out: &mut [f64],
    ) -> Result<(), MdemError> {
        with_k!(D, |K| {
            let f = Frame::<D, K>::new(coords)?;
            check_len("u", u.len(), D * (D + 1))?;
            check_len("out", out.len(), K)?;
            let fe = f.edge_stiffness(&self.mat.fixed::<K>()) * f.elongations(u);
            out.copy_from_slice(fe.as_slice());
            Ok(())
        })
    }

    fn frame_for<const K: usize>(
        cell: &CellGeometry<'_, D>,
        u: &[f64],
    ) -> Result<Frame<D, K>, MdemError> {
        let f = Frame::<D, K>::new(cell.coords)?;
        check_len("u", u.len(), D * (D + 1))?;
        Ok(f)
    }

    /// Strain (Kelvin) `ε = M⁻¹ U` of the cell.
    fn strain<const K: usize>(f: &Frame<D, K>, u: &[f64]) -> SVector<f64, K> {
        f.minv * f.elongations(u)
    }

    /// Energy `½ Uᵀ𝐊U = |K| · ½ ε·Dε`, or an error for a bad cell.
    pub fn try_energy(&self, cell: &CellGeometry<'_, D>, u: &[f64]) -> Result<f64, MdemError> {
        with_k!(D, |K| {
            let f = Self::frame_for::<K>(cell, u)?;
            let eps = Self::strain(&f, u);
            Ok(0.5 * f.volume * eps.dot(&(self.mat.fixed::<K>() * eps)))
        })
    }

    /// Nodal forces `−∂E/∂u` (the edge forces along the edges), or an error.
    pub fn try_forces(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut [f64],
    ) -> Result<(), MdemError> {
        with_k!(D, |K| {
            let f = Self::frame_for::<K>(cell, u)?;
            check_len("out", out.len(), D * (D + 1))?;
            // F = 𝐊 U = |K| M⁻ᵀ D ε.
            let fe = f.minv.transpose() * (self.mat.fixed::<K>() * Self::strain(&f, u)) * f.volume;
            f.nodal_forces(&fe, out);
            Ok(())
        })
    }

    /// Local stiffness `Rᵀ 𝐊 R` into `out` (resized to `D(D+1)` square), or an error.
    pub fn try_stiffness(
        &self,
        cell: &CellGeometry<'_, D>,
        out: &mut DMatrix<f64>,
    ) -> Result<(), MdemError> {
        with_k!(D, |K| {
            let f = Frame::<D, K>::new(cell.coords)?;
            let n = D * (D + 1);
            if out.shape() != (n, n) {
                *out = DMatrix::zeros(n, n);
            }
            f.nodal_stiffness(&f.edge_stiffness(&self.mat.fixed::<K>()), out);
            Ok(())
        })
    }

    /// Stress `σ = (1/|K|) Mᵀ F = D ε` (Nilsen et al. (2017) eq. 18), or an error.
    pub fn try_stress(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
    ) -> Result<Tensor<D>, MdemError> {
        with_k!(D, |K| {
            let f = Self::frame_for::<K>(cell, u)?;
            let s = self.mat.fixed::<K>() * Self::strain(&f, u);
            Ok(tensor_from_kelvin::<D, K>(&s))
        })
    }
}

impl<const D: usize> CellLaw<D> for MdemLaw<D> {
    fn name(&self) -> &str {
        "mdem"
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
        _u: &[f64],
        out: &mut DMatrix<f64>,
        _scratch: &mut Scratch,
    ) -> Result<(), LawError> {
        Ok(self.try_stiffness(cell, out)?)
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
