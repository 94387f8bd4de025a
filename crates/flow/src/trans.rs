//! Two-point flux transmissibilities.
//!
//! For a cell `K` with centroid `x_K` and a face `f` with area `A_f`, centroid `c_f` and unit
//! normal `n_{K,f}` pointing out of `K`, the *half-transmissibility* is
//!
//! ```text
//!   t_{K,f} = A_f (K n_{K,f}) · d / |d|²,      d = c_f − x_K,
//! ```
//!
//! so that the one-sided Darcy flux out of `K` through `f` is `t_{K,f} (p_K − p_f) / μ`.
//! Eliminating the face pressure `p_f` by flux continuity gives the harmonic average
//!
//! ```text
//!   T_f = 1 / (1/t_{K,f} + 1/t_{L,f}),         flux K → L = T_f (p_K − p_L) / μ,
//! ```
//!
//! and on a boundary face with prescribed pressure `p_b` the flux out is
//! `t_{K,f} (p_K − p_b) / μ`, i.e. `T_f = t_{K,f}` for boundary faces.
//!
//! The values stored here are *geometric*: viscosity is not included; the flow model divides
//! by `μ` when it assembles.
//!
//! **Consistency.** The flux is exact for linear pressure fields when `d ∥ K n_{K,f}` for every
//! cell–face pair (the grid is *K-orthogonal*): Cartesian grids with a diagonal tensor, or
//! equilateral triangles with an isotropic tensor. On other grids (right triangles, skewed
//! cells, full tensors) TPFA is not consistent; this is a property of the scheme.
//!
//! **Negative half-transmissibilities.** On strongly non-K-orthogonal cells `(K n)·d` can be
//! negative. As reservoir simulators commonly do, the absolute value is used (the count is
//! reported by [`Transmissibilities::num_negative`]), which keeps the system matrix an
//! M-matrix (monotone) at the price of the consistency error already present on such cells.
//! A zero half-transmissibility gives `T_f = 0` (a sealing face).

use porofrac_grid::{Grid, NO_CELL};
use rayon::prelude::*;

use crate::error::{FlowError, Result};
use crate::perm::Permeability;

/// Geometric transmissibilities (without viscosity) of all faces of a grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Transmissibilities {
    half: Vec<[f64; 2]>,
    face: Vec<f64>,
    face_cells: Vec<[usize; 2]>,
    num_negative: usize,
}

impl Transmissibilities {
    /// Compute half- and face transmissibilities for `grid` with the permeability `perm`.
    ///
    /// Errors if `perm` does not have one tensor per cell or a cell centroid coincides with
    /// one of its face centroids.
    pub fn new<const D: usize>(grid: &Grid<D>, perm: &Permeability<D>) -> Result<Self> {
        if perm.len() != grid.num_cells() {
            return Err(FlowError::Length {
                what: "permeability",
                got: perm.len(),
                expected: grid.num_cells(),
            });
        }
        let half_one = |c: usize, f: usize, sign: f64| -> Result<(f64, bool)> {
            let d = grid.face_centroid(f) - grid.cell_centroid(c);
            let d2 = d.norm_squared();
            if d2.is_nan() || d2 <= 0.0 {
                return Err(FlowError::Face {
                    face: f,
                    what: format!("face centroid coincides with the centroid of cell {c}"),
                });
            }
            let kn = perm.tensor(c) * grid.face_normal(f) * sign;
            let t = grid.face_area(f) * kn.dot(&d) / d2;
            Ok((t.abs(), t < 0.0))
        };
        let rows: Vec<([f64; 2], [usize; 2], usize)> = (0..grid.num_faces())
            .into_par_iter()
            .map(|f| {
                let (c0, c1) = grid.face_cells(f);
                let (t0, n0) = half_one(c0, f, 1.0)?;
                let (t1, n1, c1) = match c1 {
                    Some(c1) => {
                        let (t, n) = half_one(c1, f, -1.0)?;
                        (t, n, c1)
                    }
                    None => (0.0, false, NO_CELL),
                };
                Ok(([t0, t1], [c0, c1], n0 as usize + n1 as usize))
            })
            .collect::<Result<_>>()?;
        let mut half = Vec::with_capacity(rows.len());
        let mut face = Vec::with_capacity(rows.len());
        let mut face_cells = Vec::with_capacity(rows.len());
        let mut num_negative = 0;
        for (h, fc, neg) in rows {
            let t = if fc[1] == NO_CELL {
                h[0]
            } else {
                harmonic(h[0], h[1])
            };
            half.push(h);
            face.push(t);
            face_cells.push(fc);
            num_negative += neg;
        }
        Ok(Self {
            half,
            face,
            face_cells,
            num_negative,
        })
    }

    /// Multiply the transmissibility of each face of `faces` by `m` (a fault's
    /// transmissibility multiplier, Eclipse's `MULTFLT`).
    pub fn multiply(&mut self, faces: &[usize], m: f64) {
        for &f in faces {
            self.face[f] *= m;
        }
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face.len()
    }

    /// Face transmissibility `T_f` (m³, without viscosity): harmonic average of the two
    /// half-transmissibilities on interior faces, the cell's half-transmissibility on
    /// boundary faces.
    pub fn face(&self, f: usize) -> f64 {
        self.face[f]
    }

    /// All face transmissibilities.
    pub fn faces(&self) -> &[f64] {
        &self.face
    }

    /// Half-transmissibilities `[t_{c0,f}, t_{c1,f}]` of face `f` for its two cells in the
    /// order of [`Grid::face_cells`] (the second is 0 on a boundary face).
    pub fn half(&self, f: usize) -> [f64; 2] {
        self.half[f]
    }

    /// The cells of face `f` (`NO_CELL` as the second on the boundary).
    pub fn face_cells(&self, f: usize) -> [usize; 2] {
        self.face_cells[f]
    }

    /// All face → cells pairs.
    pub fn all_face_cells(&self) -> &[[usize; 2]] {
        &self.face_cells
    }

    /// How many half-transmissibilities were negative (non-K-orthogonal cell–face pairs) and
    /// replaced by their absolute value.
    pub fn num_negative(&self) -> usize {
        self.num_negative
    }
}

/// `1 / (1/a + 1/b)`, 0 if either is 0.
pub fn harmonic(a: f64, b: f64) -> f64 {
    if a <= 0.0 || b <= 0.0 {
        0.0
    } else {
        a * b / (a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perm::Tensor;
    use porofrac_grid::Point;

    /// A sheared cell with a strongly anisotropic tensor has `(K n)·d < 0` on its bottom
    /// face; the absolute value is used and counted.
    #[test]
    fn negative_half_transmissibility_takes_absolute_value() {
        let nodes = vec![
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 0.0),
            Point::<2>::new(3.0, 1.0),
            Point::<2>::new(2.0, 1.0),
        ];
        let grid = Grid::from_polygons(nodes, &[0, 4], &[0, 1, 2, 3]).unwrap();
        let perm =
            Permeability::from_tensors(vec![Tensor::<2>::new(1.0, -0.9, -0.9, 1.0)]).unwrap();
        let tr = Transmissibilities::new(&grid, &perm).unwrap();
        // Bottom face: n = (0, −1), K n = (0.9, −1), d = (0.5, 0) − (1.5, 0.5) = (−1, −0.5):
        // (K n)·d = −0.4, |d|² = 1.25, A = 1 → t = |−0.32|.
        let bottom = (0..grid.num_faces())
            .find(|&f| grid.face_centroid(f)[1].abs() < 1e-14)
            .unwrap();
        assert!(
            (tr.face(bottom) - 0.32).abs() < 1e-14,
            "{}",
            tr.face(bottom)
        );
        assert!(tr.num_negative() >= 1);
    }

    #[test]
    fn harmonic_average() {
        assert_eq!(harmonic(0.0, 2.0), 0.0);
        assert!((harmonic(1.0, 3.0) - 0.75).abs() < 1e-15);
    }
}
