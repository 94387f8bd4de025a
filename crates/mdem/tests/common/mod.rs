//! Helpers shared by the integration tests: simplex geometry and the P1 FEM reference.
#![allow(dead_code)]

use nalgebra::DMatrix;
use porofrac_grid::Point;
use porofrac_law::CellGeometry;

/// Coordinates, node normals and volume of a simplex, owned.
pub struct Simplex<const D: usize> {
    pub coords: Vec<Point<D>>,
    pub normals: Vec<Point<D>>,
    pub volume: f64,
    /// Gradients of the barycentric (P1) shape functions.
    pub grads: Vec<Point<D>>,
}

impl<const D: usize> Simplex<D> {
    pub fn new(coords: Vec<Point<D>>) -> Self {
        assert_eq!(coords.len(), D + 1);
        let j = DMatrix::from_fn(D, D, |r, c| coords[c + 1][r] - coords[0][r]);
        let det = j.determinant();
        let fact: f64 = (1..=D).map(|i| i as f64).product();
        let volume = det.abs() / fact;
        let jinv = j.try_inverse().expect("non-degenerate test simplex");
        let mut grads = vec![Point::<D>::zeros(); D + 1];
        for i in 1..=D {
            grads[i] = Point::<D>::from_fn(|a, _| jinv[(i - 1, a)]);
        }
        grads[0] = -grads[1..].iter().fold(Point::<D>::zeros(), |s, g| s + g);
        // ∫_∂K φ_i n dS = ∫_K ∇φ_i dV = |K| ∇φ_i.
        let normals = grads.iter().map(|g| g * volume).collect();
        Self {
            coords,
            normals,
            volume,
            grads,
        }
    }

    pub fn cell(&self) -> CellGeometry<'_, D> {
        CellGeometry {
            coords: &self.coords,
            node_normals: &self.normals,
            volume: self.volume,
        }
    }

    /// Kelvin strain operator B (K × D(D+1)) of P1 FEM.
    pub fn b_matrix(&self) -> DMatrix<f64> {
        let pairs: &[(usize, usize)] = if D == 2 {
            &[(0, 0), (1, 1), (0, 1)]
        } else {
            &[(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
        };
        let mut b = DMatrix::zeros(pairs.len(), D * (D + 1));
        for (k, &(p, q)) in pairs.iter().enumerate() {
            for (i, g) in self.grads.iter().enumerate() {
                if p == q {
                    b[(k, D * i + p)] += g[p];
                } else {
                    let w = std::f64::consts::FRAC_1_SQRT_2;
                    b[(k, D * i + p)] += w * g[q];
                    b[(k, D * i + q)] += w * g[p];
                }
            }
        }
        b
    }

    /// P1 FEM stiffness `|K| Bᵀ D B`.
    pub fn p1_stiffness(&self, d: &DMatrix<f64>) -> DMatrix<f64> {
        let b = self.b_matrix();
        b.transpose() * d * &b * self.volume
    }
}

/// Relative difference `max|a − b| / max|b|`; infinite if the shapes differ or an entry
/// is not finite (so a NaN-filled matrix never passes).
pub fn rel_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    if a.shape() != b.shape() || a.iter().chain(b.iter()).any(|v| !v.is_finite()) {
        return f64::INFINITY;
    }
    (a - b).amax() / b.amax()
}

/// The reference right triangle / tetrahedron, slightly perturbed.
pub fn triangle() -> Simplex<2> {
    Simplex::new(vec![
        Point::<2>::new(0.1, -0.2),
        Point::<2>::new(1.3, 0.1),
        Point::<2>::new(0.4, 0.9),
    ])
}

pub fn tetrahedron() -> Simplex<3> {
    Simplex::new(vec![
        Point::<3>::new(0.0, 0.1, -0.1),
        Point::<3>::new(1.2, 0.0, 0.2),
        Point::<3>::new(0.3, 0.9, 0.0),
        Point::<3>::new(0.2, 0.3, 1.1),
    ])
}

/// A fixed anisotropic SPD Kelvin matrix of size k: AᵀA + k·I with a deterministic A.
pub fn anisotropic(k: usize) -> DMatrix<f64> {
    let a = DMatrix::from_fn(k, k, |i, j| (((i * 5 + j * 3 + 1) % 7) as f64 - 3.0) / 3.0);
    a.transpose() * &a + DMatrix::identity(k, k) * (k as f64)
}
