//! Error norms of discrete fields against exact ones.
//!
//! The L2 error of a nodal field `u_h` taken as its P1 interpolant on a grid of simplices,
//! against an exact field `u`:
//!
//! ```text
//!   ‖u − u_h‖²_L2 = Σ_K |K| Σ_q w_q |u(x_q) − u_h(x_q)|² ,
//!   x_q = Σ_k λ_qk x_k ,   u_h(x_q) = Σ_k λ_qk u_k ,
//! ```
//!
//! with the degree-5 rules of [`simplex_rule5`] (weights `w_q` summing to 1, barycentric
//! points `λ_q`): exact for the error of a quadratic field and accurate to high order
//! for smooth ones. The cells are summed in fixed chunks in order, so the value does not
//! depend on the number of threads.

use porofrac_grid::{Grid, Point};

use crate::field::VectorField;

/// `‖u − u_h‖_L2` of the nodal field `u` (`D` per node, node-major) as the P1
/// interpolant on a grid of simplices against `exact`, with the degree-5 rules of
/// [`simplex_rule5`]. `None` if a cell is not a simplex.
pub fn l2_error_p1<const D: usize>(
    grid: &Grid<D>,
    u: &[f64],
    exact: impl Fn(&Point<D>) -> Point<D> + Sync,
) -> Option<f64> {
    l2_error_p1_many(grid, u, |xs, out| {
        for (o, x) in out.iter_mut().zip(xs) {
            *o = exact(&Point::<D>::from(*x)).into();
        }
    })
}

/// [`l2_error_p1`] against a field at time `t`, evaluated at all quadrature points of a
/// cell in one call ([`VectorField::eval_many`]).
pub fn l2_error_p1_field<const D: usize>(
    grid: &Grid<D>,
    u: &[f64],
    exact: &VectorField<D>,
    t: f64,
) -> Option<f64> {
    l2_error_p1_many(grid, u, |xs, out| exact.eval_many(xs, t, out))
}

/// [`l2_error_p1`] with `exact(xs, out)` giving the exact values at many points.
fn l2_error_p1_many<const D: usize>(
    grid: &Grid<D>,
    u: &[f64],
    exact: impl Fn(&[[f64; D]], &mut [[f64; D]]) + Sync,
) -> Option<f64> {
    use rayon::prelude::*;
    let rule = simplex_rule5::<D>();
    // Fixed chunks summed in order: the same value on any number of threads.
    const CHUNK: usize = 4096;
    let n = grid.num_cells();
    let partial: Option<Vec<f64>> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|k| {
            let mut sum = 0.0;
            let mut xs = vec![[0.0; D]; rule.len()];
            let mut uh = vec![Point::<D>::zeros(); rule.len()];
            let mut values = vec![[0.0; D]; rule.len()];
            for c in k * CHUNK..((k + 1) * CHUNK).min(n) {
                let nodes = grid.cell_nodes(c);
                if nodes.len() != D + 1 {
                    return None;
                }
                let vol = grid.cell_volume(c);
                for (q, (_, l)) in rule.iter().enumerate() {
                    let mut x = Point::<D>::zeros();
                    uh[q] = Point::<D>::zeros();
                    for (k, &n) in nodes.iter().enumerate() {
                        x += grid.node(n) * l[k];
                        uh[q] += Point::<D>::from_column_slice(&u[D * n..D * n + D]) * l[k];
                    }
                    xs[q] = x.into();
                }
                exact(&xs, &mut values);
                for (q, (w, _)) in rule.iter().enumerate() {
                    sum += w * vol * (Point::<D>::from(values[q]) - uh[q]).norm_squared();
                }
            }
            Some(sum)
        })
        .collect();
    Some(partial?.iter().sum::<f64>().sqrt())
}

/// A quadrature point on a simplex: weight (summing to 1) and barycentric coordinates.
pub type QPoint = (f64, [f64; 4]);

/// Triangle rule of degree 5 (Radon's 7 points).
pub fn triangle_rule5() -> Vec<QPoint> {
    let s = 15f64.sqrt();
    let (a1, w1) = ((6.0 - s) / 21.0, (155.0 - s) / 1200.0);
    let (a2, w2) = ((6.0 + s) / 21.0, (155.0 + s) / 1200.0);
    let mut r = vec![(9.0 / 40.0, [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.0])];
    for (a, w) in [(a1, w1), (a2, w2)] {
        let b = 1.0 - 2.0 * a;
        r.push((w, [b, a, a, 0.0]));
        r.push((w, [a, b, a, 0.0]));
        r.push((w, [a, a, b, 0.0]));
    }
    r
}

/// Tetrahedron rule of degree 5 with 14 points and positive weights (Walkington,
/// *Quadrature on simplices of arbitrary dimension*, 2000; also in Keast 1986): two orbits
/// of 4 points `(a, a, a, 1 − 3a)` and one of 6 points `(b, b, ½ − b, ½ − b)`. Exact for
/// every polynomial of degree 5 (checked by the tests against `∫ λ₁^i λ₂^j λ₃^k`).
pub fn tetrahedron_rule5() -> Vec<QPoint> {
    let mut r = Vec::with_capacity(14);
    for (a, w) in [
        (0.310_885_919_263_300_6, 0.112_687_925_718_015_85),
        (0.092_735_250_310_891_23, 0.073_493_043_116_361_95),
    ] {
        let b = 1.0 - 3.0 * a;
        for k in 0..4 {
            let mut l = [a; 4];
            l[k] = b;
            r.push((w, l));
        }
    }
    let (b, w) = (0.045_503_704_125_649_65, 0.042_546_020_777_081_466);
    let c = 0.5 - b;
    for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
        let mut l = [c; 4];
        l[i] = b;
        l[j] = b;
        r.push((w, l));
    }
    r
}

/// The degree-5 rule for a `D`-simplex.
pub fn simplex_rule5<const D: usize>() -> Vec<QPoint> {
    if D == 2 {
        triangle_rule5()
    } else {
        tetrahedron_rule5()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degree_five_rules_integrate_degree_five_exactly() {
        // ∫ over the unit simplex of λ₁^i λ₂^j (λ₃^k) = i! j! k! D! / (i + j + k + D)!, as
        // a fraction of the volume.
        let fact = |n: usize| (1..=n).map(|v| v as f64).product::<f64>();
        for (d, rule) in [(2usize, triangle_rule5()), (3, tetrahedron_rule5())] {
            let w: f64 = rule.iter().map(|(w, _)| w).sum();
            assert!((w - 1.0).abs() < 1e-15, "weights sum to {w}");
            for i in 0..=5 {
                for j in 0..=5 - i {
                    for k in 0..=(5 - i - j) * (d - 2) {
                        let q: f64 = rule
                            .iter()
                            .map(|(w, l)| {
                                w * l[1].powi(i as i32)
                                    * l[2].powi(j as i32)
                                    * if d == 3 { l[3].powi(k as i32) } else { 1.0 }
                            })
                            .sum();
                        let exact = fact(i) * fact(j) * fact(k) * fact(d) / fact(i + j + k + d);
                        assert!(
                            (q - exact).abs() < 1e-15,
                            "D = {d}, λ^({i},{j},{k}): {q} against {exact}"
                        );
                    }
                }
            }
        }
    }
}
