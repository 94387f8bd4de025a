//! The near-null space: vectors the operator maps to (nearly) zero away from the boundary.
//!
//! Smoothed aggregation builds its coarse spaces so that they reproduce these vectors
//! exactly on every aggregate. For a scalar diffusion problem it is the constant; for
//! linear elasticity it is the rigid-body motions, `D` translations and `D(D−1)/2`
//! rotations,
//!
//! ```text
//!   t_a(x) = e_a,    r_ab(x) = e_a (x − x_c)_b − e_b (x − x_c)_a,
//! ```
//!
//! evaluated at the node and component of every equation. Prescribed (eliminated)
//! displacements simply have no equation: [`NearNullSpace::rigid_body_modes`] takes, for
//! every equation, its node and component, so any elimination pattern works. (An equation
//! shared by several nodes, like a rigid platen's, is represented by one of its nodes; the
//! near-null space need not be exact for the preconditioner to work, only good.)
//! Coordinates are shifted to their centroid `x_c` and scaled by the extent of the grid so
//! that all vectors have entries of order one.

use crate::error::{AmgError, Result, check_finite};

/// A set of `m` vectors of length `n`, stored one after the other.
#[derive(Clone, Debug, PartialEq)]
pub struct NearNullSpace {
    n: usize,
    m: usize,
    data: Vec<f64>,
}

impl NearNullSpace {
    /// From `m = data.len() / n` vectors stored one after the other (`data[k·n + i]` is
    /// entry `i` of vector `k`). Errors: no vectors, a length that is not a multiple of
    /// `n`, non-finite entries.
    pub fn from_vectors(n: usize, data: Vec<f64>) -> Result<Self> {
        if n == 0 || data.is_empty() || !data.len().is_multiple_of(n) {
            return Err(AmgError::Input(format!(
                "near-null space of {} entries for vectors of length {n}",
                data.len()
            )));
        }
        check_finite(&data, "near-null space entry")?;
        Ok(Self {
            n,
            m: data.len() / n,
            data,
        })
    }

    /// From parts known to be consistent (`data.len() = n·m`, finite).
    pub(crate) fn from_parts(n: usize, m: usize, data: Vec<f64>) -> Self {
        debug_assert_eq!(data.len(), n * m);
        Self { n, m, data }
    }

    /// The constant vector (scalar problems: diffusion, pressure).
    pub fn constant(n: usize) -> Result<Self> {
        Self::from_vectors(n, vec![1.0; n])
    }

    /// Rigid-body modes of a `dim`-dimensional displacement field (`dim` in 1..=3):
    /// `coords` holds the node coordinates (`dim` per node, node-major) and `dofs[e] =
    /// (node, component)` says what equation `e` is. Gives `dim` translations followed by
    /// `dim(dim−1)/2` rotations (about z in 2D; about x, y, z in 3D).
    ///
    /// Errors: a dimension outside 1..=3, coordinates not a multiple of `dim` or not
    /// finite, a node or component out of range, no equations.
    pub fn rigid_body_modes(coords: &[f64], dim: usize, dofs: &[(usize, usize)]) -> Result<Self> {
        if !(1..=3).contains(&dim) {
            return Err(AmgError::Input(format!(
                "rigid-body modes in dimension {dim} (want 1, 2 or 3)"
            )));
        }
        if coords.is_empty() || !coords.len().is_multiple_of(dim) {
            return Err(AmgError::Input(format!(
                "{} coordinates are not a multiple of dimension {dim}",
                coords.len()
            )));
        }
        check_finite(coords, "coordinate")?;
        let num_nodes = coords.len() / dim;
        if let Some((e, &(node, comp))) = dofs
            .iter()
            .enumerate()
            .find(|(_, (node, comp))| *node >= num_nodes || *comp >= dim)
        {
            return Err(AmgError::Input(format!(
                "equation {e} is component {comp} of node {node}; there are {num_nodes} nodes in dimension {dim}"
            )));
        }
        let n = dofs.len();
        let (centre, scale) = centre_and_scale(coords, dim);
        let rotations: &[(usize, usize)] = match dim {
            1 => &[],
            2 => &[(1, 0)],
            _ => &[(2, 1), (0, 2), (1, 0)],
        };
        let m = dim + rotations.len();
        let mut data = vec![0.0; n * m];
        for (e, &(node, comp)) in dofs.iter().enumerate() {
            data[comp * n + e] = 1.0;
            let x = |b: usize| (coords[dim * node + b] - centre[b]) * scale;
            // r_ab = e_a x_b − e_b x_a: component a gets x_b, component b gets −x_a.
            for (k, &(a, b)) in rotations.iter().enumerate() {
                let v = if comp == a {
                    x(b)
                } else if comp == b {
                    -x(a)
                } else {
                    0.0
                };
                data[(dim + k) * n + e] = v;
            }
        }
        Self::from_vectors(n, data)
    }

    /// Length of each vector (number of equations).
    pub fn len(&self) -> usize {
        self.n
    }
    /// Whether the vectors are empty (never, for a constructed space).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }
    /// Number of vectors.
    pub fn num_vectors(&self) -> usize {
        self.m
    }
    /// Vector `k`.
    pub fn vector(&self, k: usize) -> &[f64] {
        &self.data[k * self.n..(k + 1) * self.n]
    }
    /// Entry `i` of vector `k`.
    #[inline]
    pub(crate) fn get(&self, i: usize, k: usize) -> f64 {
        self.data[k * self.n + i]
    }
}

/// Centroid of the nodes and the inverse of the largest extent.
fn centre_and_scale(coords: &[f64], dim: usize) -> ([f64; 3], f64) {
    let num = coords.len() / dim;
    let mut centre = [0.0; 3];
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in coords.chunks_exact(dim) {
        for b in 0..dim {
            centre[b] += x[b];
            lo[b] = lo[b].min(x[b]);
            hi[b] = hi[b].max(x[b]);
        }
    }
    let mut extent = 0.0f64;
    for b in 0..dim {
        centre[b] /= num as f64;
        extent = extent.max(hi[b] - lo[b]);
    }
    let scale = if extent > 0.0 { 1.0 / extent } else { 1.0 };
    (centre, scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rigid_modes_in_2d_skip_eliminated_dofs() {
        // Nodes (0,0), (2,0), (0,2); node 0 fully fixed, node 2 has only its y equation.
        let coords = [0.0, 0.0, 2.0, 0.0, 0.0, 2.0];
        let dofs = [(1, 0), (1, 1), (2, 1)];
        let b = NearNullSpace::rigid_body_modes(&coords, 2, &dofs).unwrap();
        assert_eq!(b.num_vectors(), 3);
        assert_eq!(b.vector(0), &[1.0, 0.0, 0.0]);
        assert_eq!(b.vector(1), &[0.0, 1.0, 1.0]);
        // Centre (2/3, 2/3), extent 2: the rotation (−y, x) in shifted, scaled coordinates.
        let c = 2.0 / 3.0;
        let r = [-(0.0 - c) * 0.5, (2.0 - c) * 0.5, (0.0 - c) * 0.5];
        for (a, b) in b.vector(2).iter().zip(r) {
            assert!((a - b).abs() < 1e-15);
        }
    }

    #[test]
    fn rigid_modes_in_3d_are_rotations() {
        // A rotation field is orthogonal to the position: Σ_a r_a x_a = 0 per node.
        let coords: Vec<f64> = (0..8)
            .flat_map(|k| [(k & 1) as f64, ((k >> 1) & 1) as f64, (k >> 2) as f64])
            .collect();
        let dofs: Vec<(usize, usize)> = (0..8).flat_map(|n| (0..3).map(move |a| (n, a))).collect();
        let b = NearNullSpace::rigid_body_modes(&coords, 3, &dofs).unwrap();
        assert_eq!(b.num_vectors(), 6);
        for k in 3..6 {
            let v = b.vector(k);
            for node in 0..8 {
                let s: f64 = (0..3)
                    .map(|a| v[3 * node + a] * (coords[3 * node + a] - 0.5))
                    .sum();
                assert!(s.abs() < 1e-15);
            }
        }
    }

    #[test]
    fn bad_input() {
        assert!(NearNullSpace::rigid_body_modes(&[0.0; 4], 4, &[]).is_err());
        assert!(NearNullSpace::rigid_body_modes(&[0.0; 5], 2, &[(0, 0)]).is_err());
        assert!(NearNullSpace::rigid_body_modes(&[0.0; 4], 2, &[(2, 0)]).is_err());
        assert!(NearNullSpace::rigid_body_modes(&[0.0; 4], 2, &[(0, 2)]).is_err());
        assert!(NearNullSpace::rigid_body_modes(&[0.0, f64::NAN], 2, &[(0, 0)]).is_err());
        assert!(NearNullSpace::from_vectors(3, vec![1.0; 4]).is_err());
        assert!(NearNullSpace::constant(0).is_err());
    }
}
