//! Principal values and directions of a symmetric tensor: the one routine every part of
//! porofrac uses for principal stresses (failure criteria, crack tracking, probes,
//! plots).
//!
//! In 2D the closed form: with `m = (s₁₁ + s₂₂)/2` and `r = √(((s₁₁ − s₂₂)/2)² + s₁₂²)`,
//! the values are `m ± r` and the first direction is at `θ = ½ atan2(2 s₁₂, s₁₁ − s₂₂)`.
//! In 3D the symmetric eigen-decomposition of nalgebra.

use nalgebra::{Matrix3, SVector};

use crate::Tensor;

/// Principal values in decreasing order and their unit directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principal<const D: usize> {
    /// `values[0] ≥ values[1] (≥ values[2])`; tension positive for stresses.
    pub values: [f64; D],
    /// `directions[i]` is the unit eigenvector of `values[i]`.
    pub directions: [SVector<f64, D>; D],
}

/// The principal values and directions of the symmetric tensor `s`.
pub fn principal<const D: usize>(s: &Tensor<D>) -> Principal<D> {
    let mut values = [0.0; D];
    let mut directions = [SVector::<f64, D>::zeros(); D];
    if D == 2 {
        let (a, b, c) = (s[(0, 0)], s[(1, 1)], s[(0, 1)]);
        let m = 0.5 * (a + b);
        let r = (0.25 * (a - b) * (a - b) + c * c).sqrt();
        let theta = 0.5 * (2.0 * c).atan2(a - b);
        let (cos, sin) = (theta.cos(), theta.sin());
        values[0] = m + r;
        values[1] = m - r;
        directions[0][0] = cos;
        directions[0][1] = sin;
        directions[1][0] = -sin;
        directions[1][1] = cos;
    } else {
        // D is 1 or 3 here: embed in 3×3 (zeros outside D×D); the eigenvectors of the
        // embedded block have zero components outside it.
        let m = Matrix3::from_fn(|i, j| if i < D && j < D { s[(i, j)] } else { 0.0 });
        let e = m.symmetric_eigen();
        let mut order = [0usize, 1, 2];
        order.sort_by(|&i, &j| e.eigenvalues[j].total_cmp(&e.eigenvalues[i]));
        let in_block: Vec<usize> = order
            .into_iter()
            .filter(|&i| (D..3).all(|j| e.eigenvectors[(j, i)].abs() < 0.5))
            .take(D)
            .collect();
        for (k, &i) in in_block.iter().enumerate() {
            values[k] = e.eigenvalues[i];
            directions[k] = SVector::<f64, D>::from_fn(|a, _| e.eigenvectors[(a, i)]);
        }
    }
    Principal { values, directions }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rotated<const D: usize>(values: [f64; D], angle: f64) -> (Tensor<D>, Tensor<D>) {
        // A rotation about z (in 2D: the plane rotation).
        let r = Tensor::<D>::from_fn(|i, j| match (i, j) {
            (0, 0) | (1, 1) => angle.cos(),
            (0, 1) => -angle.sin(),
            (1, 0) => angle.sin(),
            (i, j) if i == j => 1.0,
            _ => 0.0,
        });
        let d = Tensor::<D>::from_fn(|i, j| if i == j { values[i] } else { 0.0 });
        (r * d * r.transpose(), r)
    }

    #[test]
    fn values_and_directions_of_rotated_states() {
        for angle in [0.0, 0.3, 1.2, -2.0] {
            let (s, r) = rotated([3.0, -1.0], angle);
            let p = principal(&s);
            assert!((p.values[0] - 3.0).abs() < 1e-13 && (p.values[1] + 1.0).abs() < 1e-13);
            for k in 0..2 {
                let along = r.column(k).dot(&p.directions[k]).abs();
                assert!((along - 1.0).abs() < 1e-13, "{angle}: {along}");
            }
            let (s, r) = rotated([-1.0, 5.0, 2.0], angle);
            let p = principal(&s);
            assert!((p.values[0] - 5.0).abs() < 1e-12);
            assert!((p.values[1] - 2.0).abs() < 1e-12);
            assert!((p.values[2] + 1.0).abs() < 1e-12);
            for (k, col) in [1, 2, 0].into_iter().enumerate() {
                let along = r.column(col).dot(&p.directions[k]).abs();
                assert!((along - 1.0).abs() < 1e-12, "{angle}: {along}");
            }
        }
    }
}
