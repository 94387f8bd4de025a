//! Quadrature rules on simplices in barycentric coordinates.

/// Weight (summing to 1) and barycentric coordinates (the first `k` used) of a point.
pub(crate) type QPoint = (f64, [f64; 4]);

const B1: f64 = 0.445_948_490_915_964_9;
const B2: f64 = 0.091_576_213_509_770_74;
const W1: f64 = 0.223_381_589_678_011_47;
const W2: f64 = 1.0 / 3.0 - W1;
const A1: f64 = 1.0 - 2.0 * B1;
const A2: f64 = 1.0 - 2.0 * B2;
/// Triangle, degree 4 (Dunavant, 6 points).
const TRI4: [QPoint; 6] = [
    (W1, [A1, B1, B1, 0.0]),
    (W1, [B1, A1, B1, 0.0]),
    (W1, [B1, B1, A1, 0.0]),
    (W2, [A2, B2, B2, 0.0]),
    (W2, [B2, A2, B2, 0.0]),
    (W2, [B2, B2, A2, 0.0]),
];
const TA: f64 = 0.585_410_196_624_968_5;
const TB: f64 = (1.0 - TA) / 3.0;
/// Tetrahedron, degree 2 (4 points).
const TET2: [QPoint; 4] = [
    (0.25, [TA, TB, TB, TB]),
    (0.25, [TB, TA, TB, TB]),
    (0.25, [TB, TB, TA, TB]),
    (0.25, [TB, TB, TB, TA]),
];
/// Keast's tetrahedron rule of degree 4 (11 points, the centroid weight negative):
/// `1/14, 11/14` and `(1 ± √(5/14))/4`.
const K1: f64 = 1.0 / 14.0;
const K2: f64 = 11.0 / 14.0;
const K3: f64 = 0.399_403_576_166_799_2;
const K4: f64 = 0.100_596_423_833_200_8;
const KW0: f64 = -74.0 * 6.0 / 5625.0;
const KW1: f64 = 343.0 * 6.0 / 45000.0;
const KW2: f64 = 56.0 * 6.0 / 2250.0;
/// Tetrahedron, degree 4 (Keast, 11 points).
const TET4: [QPoint; 11] = [
    (KW0, [0.25, 0.25, 0.25, 0.25]),
    (KW1, [K2, K1, K1, K1]),
    (KW1, [K1, K2, K1, K1]),
    (KW1, [K1, K1, K2, K1]),
    (KW1, [K1, K1, K1, K2]),
    (KW2, [K3, K3, K4, K4]),
    (KW2, [K3, K4, K3, K4]),
    (KW2, [K3, K4, K4, K3]),
    (KW2, [K4, K3, K3, K4]),
    (KW2, [K4, K3, K4, K3]),
    (KW2, [K4, K4, K3, K3]),
];
const G: f64 = 0.288_675_134_594_812_9; // 1 / (2√3)
/// Segment, degree 3 (2-point Gauss).
const SEG3: [QPoint; 2] = [
    (0.5, [0.5 + G, 0.5 - G, 0.0, 0.0]),
    (0.5, [0.5 - G, 0.5 + G, 0.0, 0.0]),
];
/// Triangle, degree 2 (edge midpoints).
const TRI2: [QPoint; 3] = [
    (1.0 / 3.0, [0.5, 0.5, 0.0, 0.0]),
    (1.0 / 3.0, [0.0, 0.5, 0.5, 0.0]),
    (1.0 / 3.0, [0.5, 0.0, 0.5, 0.0]),
];

/// The rule for a D-simplex (D + 1 barycentric coordinates): degree 4 in 2D, 2 in 3D.
pub(crate) fn cell_rule<const D: usize>() -> &'static [QPoint] {
    if D == 2 { &TRI4 } else { &TET2 }
}

/// The rule for a whole simplex cell: degree 4 (6 points in 2D, 11 in 3D).
pub(crate) fn simplex_rule<const D: usize>() -> &'static [QPoint] {
    if D == 2 { &TRI4 } else { &TET4 }
}

/// The rule for a (D−1)-simplex facet (D barycentric coordinates): degree 3 in 2D, 2 in 3D.
pub(crate) fn facet_rule<const D: usize>() -> &'static [QPoint] {
    if D == 2 { &SEG3 } else { &TRI2 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ λ^α over the reference simplex: α! d! / (|α| + d)! (times |T|).
    fn exact(alpha: &[u32], d: u32) -> f64 {
        let f = |k: u32| (1..=k).map(f64::from).product::<f64>();
        alpha.iter().map(|&a| f(a)).product::<f64>() * f(d) / f(alpha.iter().sum::<u32>() + d)
    }

    fn check(rule: &[QPoint], k: usize, degree: u32) {
        // All monomials λ^α with |α| ≤ degree in k barycentric coordinates.
        let mut alpha = vec![0u32; k];
        loop {
            if alpha.iter().sum::<u32>() <= degree {
                let q: f64 = rule
                    .iter()
                    .map(|(w, l)| {
                        w * alpha
                            .iter()
                            .zip(l)
                            .map(|(&a, x)| x.powi(a as i32))
                            .product::<f64>()
                    })
                    .sum();
                let e = exact(&alpha, k as u32 - 1);
                assert!((q - e).abs() < 1e-14, "alpha {alpha:?}: {q} vs {e}");
            }
            let mut i = 0;
            loop {
                if i == k {
                    return;
                }
                alpha[i] += 1;
                if alpha[i] <= degree {
                    break;
                }
                alpha[i] = 0;
                i += 1;
            }
        }
    }

    #[test]
    fn rules_are_exact_to_their_degree() {
        check(&TRI4, 3, 4);
        check(&TET2, 4, 2);
        check(&TET4, 4, 4);
        check(&SEG3, 2, 3);
        check(&TRI2, 3, 2);
    }
}
