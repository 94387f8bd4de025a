//! One aggregation step as a stand-alone public function, for hierarchies built outside
//! this crate (a distributed hierarchy aggregates the rows each process owns with it).
//!
//! [`aggregate_tentative`] runs exactly the serial setup's first two steps on a given
//! matrix — block strength of connection, greedy aggregation ([`crate::aggregate`]) and
//! the tentative prolongator by local QR of the near-null space — and returns the result
//! as plain arrays: the aggregate of every equation, the coarse equations of every
//! aggregate, the prolongator's values row by row and the coarse near-null space.

use crate::aggregate::{Blocks, Tentative, aggregate, strength, tentative};
use crate::csr::CsrMatrix;
use crate::error::{AmgError, Result};
use crate::nullspace::NearNullSpace;

/// An aggregation of the equations of a matrix and its tentative prolongator `P_tent`.
///
/// Row `e` of `P_tent` has the entries `values[row_ptr[e]..row_ptr[e+1]]` in the columns
/// `coarse_ptr[a]..coarse_ptr[a+1]` with `a = aggregate[e]` (an equation whose aggregate
/// has no coarse equation has an empty row).
#[derive(Clone, Debug)]
pub struct LocalAggregation {
    /// Aggregate of every equation.
    pub aggregate: Vec<u32>,
    /// Coarse equations of aggregate `a`: `coarse_ptr[a]..coarse_ptr[a+1]`.
    pub coarse_ptr: Vec<usize>,
    /// Start of every row's values in [`Self::values`].
    pub row_ptr: Vec<usize>,
    /// The values of `P_tent`, row by row (rounded to single precision, as the serial
    /// hierarchy stores them).
    pub values: Vec<f64>,
    /// The near-null space on the coarse equations (`P_tent B_coarse = B`).
    pub coarse_null: NearNullSpace,
}

/// Aggregate the equations of `a` (full symmetric matrix) grouped into nodes by
/// `node_of_equation` with the strength threshold `theta` (on the distance-two graph when
/// `aggressive`), and build the tentative prolongator from the near-null space `near_null`.
///
/// Errors: lengths that disagree, more equations than 32-bit indices hold.
pub fn aggregate_tentative(
    a: &CsrMatrix,
    node_of_equation: &[usize],
    near_null: &NearNullSpace,
    theta: f64,
    aggressive: bool,
) -> Result<LocalAggregation> {
    let n = a.nrows();
    if node_of_equation.len() != n || near_null.len() != n || a.ncols() != n {
        return Err(AmgError::Input(format!(
            "aggregation of a {n} × {} matrix with {} node ids and near-null vectors of length {}",
            a.ncols(),
            node_of_equation.len(),
            near_null.len()
        )));
    }
    let blocks = Blocks::from_ids(node_of_equation)?;
    let s = strength(a, &blocks, theta);
    let (agg, num_agg) = aggregate(&s, aggressive);
    drop(s);
    let Tentative {
        p,
        eq_agg,
        coarse_null,
        coarse_blocks,
    } = tentative(&blocks, &agg, num_agg, near_null)?;
    let mut row_ptr = Vec::with_capacity(n + 1);
    for e in 0..n {
        row_ptr.push(p.row_start(e));
    }
    row_ptr.push(p.values().len());
    let values = p.values().iter().map(|&v| f64::from(v)).collect();
    Ok(LocalAggregation {
        aggregate: eq_agg,
        coarse_ptr: coarse_blocks.ptr,
        row_ptr,
        values,
        coarse_null,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csr::SymCsr;

    #[test]
    fn tentative_reproduces_the_constant_on_a_chain() {
        let n = 10;
        let (mut cp, mut ri, mut v) = (vec![0], vec![], vec![]);
        for c in 0..n {
            if c > 0 {
                ri.push(c - 1);
                v.push(-1.0);
            }
            ri.push(c);
            v.push(2.0);
            cp.push(ri.len());
        }
        let a = SymCsr::from_upper_csc(n, &cp, &ri, &v).unwrap();
        let ids: Vec<usize> = (0..n).collect();
        let b = NearNullSpace::constant(n).unwrap();
        let g = aggregate_tentative(a.matrix(), &ids, &b, 0.0, false).unwrap();
        // P_tent B_coarse = B = 1 on every row.
        for e in 0..n {
            let ag = g.aggregate[e] as usize;
            let c0 = g.coarse_ptr[ag];
            let row = &g.values[g.row_ptr[e]..g.row_ptr[e + 1]];
            assert_eq!(row.len(), g.coarse_ptr[ag + 1] - c0);
            let s: f64 = row
                .iter()
                .enumerate()
                .map(|(j, p)| p * g.coarse_null.vector(0)[c0 + j])
                .sum();
            assert!((s - 1.0).abs() < 1e-6, "row {e}: {s}");
        }
        assert!(g.coarse_ptr.len() - 1 < n / 2);
    }
}
