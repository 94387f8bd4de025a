//! Permeability: a symmetric positive definite tensor `K` per cell (m²).
//!
//! A cell's permeability may be given as a scalar `k` (`K = k I`), as the diagonal
//! `[kx, ky(, kz)]` of an axis-aligned anisotropic tensor, or as a full symmetric tensor.
//! Every tensor is checked on construction: finite entries, symmetric to a relative
//! `1e-12`, positive definite (a Cholesky factorization exists). A bad tensor is an error
//! naming the cell.

use nalgebra::SMatrix;

use crate::error::{Result, cell_err};

/// A D×D permeability tensor.
pub type Tensor<const D: usize> = SMatrix<f64, D, D>;

/// One permeability tensor per cell, validated to be symmetric positive definite.
#[derive(Clone, Debug, PartialEq)]
pub struct Permeability<const D: usize> {
    tensors: Vec<Tensor<D>>,
}

impl<const D: usize> Permeability<D> {
    /// The same scalar (isotropic) permeability `k` in all `num_cells` cells.
    pub fn uniform(num_cells: usize, k: f64) -> Result<Self> {
        Self::from_scalars(&vec![k; num_cells])
    }

    /// Isotropic permeability `K = k_c I` per cell.
    pub fn from_scalars(k: &[f64]) -> Result<Self> {
        Self::from_tensors(k.iter().map(|&k| Tensor::<D>::identity() * k).collect())
    }

    /// The same diagonal (axis-aligned anisotropic) permeability `[kx, ky(, kz)]` in all cells.
    pub fn uniform_diagonal(num_cells: usize, k: [f64; D]) -> Result<Self> {
        Self::from_diagonals(&vec![k; num_cells])
    }

    /// Axis-aligned anisotropic permeability `diag(kx, ky(, kz))` per cell.
    pub fn from_diagonals(k: &[[f64; D]]) -> Result<Self> {
        Self::from_tensors(
            k.iter()
                .map(|d| Tensor::<D>::from_fn(|i, j| if i == j { d[i] } else { 0.0 }))
                .collect(),
        )
    }

    /// Full symmetric positive definite tensors, one per cell.
    pub fn from_tensors(tensors: Vec<Tensor<D>>) -> Result<Self> {
        for (c, k) in tensors.iter().enumerate() {
            check_spd(c, k)?;
        }
        Ok(Self { tensors })
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.tensors.len()
    }

    /// Whether there are no cells.
    pub fn is_empty(&self) -> bool {
        self.tensors.is_empty()
    }

    /// The tensor of cell `c`.
    pub fn tensor(&self, c: usize) -> &Tensor<D> {
        &self.tensors[c]
    }

    /// All tensors.
    pub fn tensors(&self) -> &[Tensor<D>] {
        &self.tensors
    }

    /// Replace the tensor of cell `c` (e.g. a fractured cell's raised permeability); the new
    /// tensor is validated.
    pub fn set(&mut self, c: usize, k: Tensor<D>) -> Result<()> {
        if c >= self.tensors.len() {
            return Err(cell_err(
                c,
                format!("no such cell (permeability has {})", self.tensors.len()),
            ));
        }
        check_spd(c, &k)?;
        self.tensors[c] = k;
        Ok(())
    }
}

fn check_spd<const D: usize>(c: usize, k: &Tensor<D>) -> Result<()> {
    if k.iter().any(|v| !v.is_finite()) {
        return Err(cell_err(
            c,
            format!("permeability has a non-finite entry: {:?}", k.as_slice()),
        ));
    }
    let scale = k.amax();
    if (k - k.transpose()).amax() > 1e-12 * scale {
        return Err(cell_err(
            c,
            format!("permeability tensor is not symmetric: {:?}", k.as_slice()),
        ));
    }
    if scale <= 0.0 || k.cholesky().is_none() {
        return Err(cell_err(
            c,
            format!(
                "permeability must be positive definite (k > 0), got {:?}",
                k.as_slice()
            ),
        ));
    }
    Ok(())
}
