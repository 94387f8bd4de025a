//! Orderings that need only a sparsity pattern: the check and inverse of a caller's
//! elimination order, and a geometric nested dissection of a symmetric pattern whose
//! unknowns have positions.
//!
//! An elimination order is a permutation `perm` of `0..n`, `perm[k]` the unknown
//! eliminated `k`-th; its inverse `inv[perm[k]] = k` gives each unknown's step.
//! [`inverse_permutation`] checks and inverts it for every factorization of this crate.
//!
//! Nested dissection (George 1973) orders both halves of a split recursively and numbers
//! the separator — the unknowns of one half adjacent to the other — last, so the factor
//! fills only within the parts and the separators. [`pattern_dissection`] splits at the
//! median of the longest axis of the bounding box of the unknowns' positions: on a mesh
//! (a geometric embedding) a good, cheap dissection without a graph partitioner.

use faer::sparse::linalg::cholesky::SymmetricOrdering;

/// An elimination order that is not a permutation of the unknowns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PermutationError {
    /// The order has `len` entries for `n` unknowns.
    #[error("ordering has {len} entries for {n} unknowns")]
    Length {
        /// Entries of the order.
        len: usize,
        /// Unknowns.
        n: usize,
    },
    /// Entry `index` is out of range or repeats an earlier one.
    #[error("ordering is not a permutation (entry {index} = {value})")]
    Entry {
        /// Position in the order.
        index: usize,
        /// The unknown found there.
        value: usize,
    },
}

/// The inverse of the elimination order `perm` of `n` unknowns (`inv[perm[k]] = k`),
/// after checking that `perm` is a permutation of `0..n`: first its length, then each
/// entry in turn.
pub fn inverse_permutation(perm: &[usize], n: usize) -> Result<Vec<usize>, PermutationError> {
    if perm.len() != n {
        return Err(PermutationError::Length { len: perm.len(), n });
    }
    let mut inv = vec![usize::MAX; n];
    for (k, &e) in perm.iter().enumerate() {
        if e >= n || inv[e] != usize::MAX {
            return Err(PermutationError::Entry { index: k, value: e });
        }
        inv[e] = k;
    }
    Ok(inv)
}

/// faer's symmetric ordering for an optional elimination order: AMD for `None`, else
/// `perm` with its inverse, stored in `inverse`.
pub(crate) fn symmetric_ordering<'a>(
    perm: Option<&'a [usize]>,
    inverse: &'a mut Vec<usize>,
    n: usize,
) -> Result<SymmetricOrdering<'a, usize>, PermutationError> {
    Ok(match perm {
        None => SymmetricOrdering::Amd,
        Some(fwd) => {
            *inverse = inverse_permutation(fwd, n)?;
            SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(fwd, inverse, n))
        }
    })
}
/// Nested dissection of a symmetric sparsity pattern with a position for each unknown.
///
/// `col_ptr`, `row_idx`: the pattern's upper triangle (CSC); `pos[i]`: where unknown `i`
/// sits, `None` for unknowns coupled to many others (e.g. a platen shared by a whole
/// boundary), which are ordered last. The positioned unknowns are split at the median of
/// the longest axis of their bounding box; the separator is the unknowns of the lower
/// half adjacent (in the pattern) to the upper half; both halves are ordered
/// recursively, the separator after them (George 1973). Parts of at most `leaf`
/// unknowns keep their order. Returns `perm`, `perm[k]` the unknown eliminated `k`-th.
pub fn pattern_dissection<const D: usize>(
    pos: &[Option<[f64; D]>],
    col_ptr: &[usize],
    row_idx: &[usize],
    leaf: usize,
) -> Vec<usize> {
    let n = pos.len();
    let placed = |i: usize| i < n && pos[i].is_some();
    let mut deg = vec![0usize; n + 1];
    for j in 0..n.min(col_ptr.len().saturating_sub(1)) {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if i != j && placed(i) && placed(j) {
                deg[i + 1] += 1;
                deg[j + 1] += 1;
            }
        }
    }
    for i in 0..n {
        deg[i + 1] += deg[i];
    }
    let mut fill = deg.clone();
    let mut adj = vec![0usize; deg[n]];
    for j in 0..n.min(col_ptr.len().saturating_sub(1)) {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if i != j && placed(i) && placed(j) {
                adj[fill[i]] = j;
                fill[i] += 1;
                adj[fill[j]] = i;
                fill[j] += 1;
            }
        }
    }
    let points: Vec<[f64; D]> = pos.iter().map(|p| p.unwrap_or([0.0; D])).collect();
    let mut ctx = PatternDissection {
        points: &points,
        ptr: deg,
        adj,
        label: vec![0u32; n],
        next_label: 1,
        leaf: leaf.max(1),
        order: Vec::with_capacity(n),
    };
    let mut items: Vec<usize> = (0..n).filter(|&i| placed(i)).collect();
    ctx.dissect(&mut items);
    let mut order = ctx.order;
    order.extend((0..n).filter(|&i| !placed(i)));
    order
}

struct PatternDissection<'p, const D: usize> {
    points: &'p [[f64; D]],
    ptr: Vec<usize>,
    adj: Vec<usize>,
    label: Vec<u32>,
    next_label: u32,
    leaf: usize,
    order: Vec<usize>,
}

impl<const D: usize> PatternDissection<'_, D> {
    fn dissect(&mut self, items: &mut [usize]) {
        if items.len() <= self.leaf {
            self.order.extend_from_slice(items);
            return;
        }
        let pts = self.points;
        let mut lo = [f64::INFINITY; D];
        let mut hi = [f64::NEG_INFINITY; D];
        for &v in items.iter() {
            for a in 0..D {
                lo[a] = lo[a].min(pts[v][a]);
                hi[a] = hi[a].max(pts[v][a]);
            }
        }
        let axis = (0..D)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap_or(0);
        // Split at the median coordinate, unknowns at the same coordinate on the same side
        // (a grid line of nodes is not cut in two).
        let half = items.len() / 2;
        items.select_nth_unstable_by(half, |&p, &q| pts[p][axis].total_cmp(&pts[q][axis]));
        let pivot = pts[items[half]][axis];
        let below = |v: &usize| pts[*v][axis] < pivot;
        let mut mid = partition_in_place(items, below);
        if mid == 0 {
            mid = partition_in_place(items, |v: &usize| pts[*v][axis] <= pivot);
        }
        if mid == 0 || mid == items.len() {
            self.order.extend_from_slice(items);
            return;
        }
        let (left_label, right_label) = (self.next_label, self.next_label + 1);
        self.next_label += 2;
        for &v in &items[..mid] {
            self.label[v] = left_label;
        }
        for &v in &items[mid..] {
            self.label[v] = right_label;
        }
        // The separator: the unknowns of the lower half adjacent to the upper one.
        let (left, right) = items.split_at(mid);
        let (mut a, mut sep) = (Vec::with_capacity(left.len()), Vec::new());
        for &v in left {
            let touches = self.adj[self.ptr[v]..self.ptr[v + 1]]
                .iter()
                .any(|&q| self.label[q] == right_label);
            if touches { sep.push(v) } else { a.push(v) }
        }
        let mut b = right.to_vec();
        if a.is_empty() || b.is_empty() {
            let mut rest = if a.is_empty() { b } else { a };
            self.dissect(&mut rest);
            self.order.extend_from_slice(&sep);
            return;
        }
        self.dissect(&mut a);
        self.dissect(&mut b);
        self.order.extend_from_slice(&sep);
    }
}

/// Reorder `items` so that those satisfying `pred` come first; returns their count.
fn partition_in_place(items: &mut [usize], pred: impl Fn(&usize) -> bool) -> usize {
    let mut k = 0;
    for i in 0..items.len() {
        if pred(&items[i]) {
            items.swap(i, k);
            k += 1;
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_of_a_permutation_and_its_errors() {
        assert_eq!(inverse_permutation(&[2, 0, 1], 3), Ok(vec![1, 2, 0]));
        assert_eq!(
            inverse_permutation(&[0, 1], 3),
            Err(PermutationError::Length { len: 2, n: 3 })
        );
        assert_eq!(
            inverse_permutation(&[0, 2, 0], 3),
            Err(PermutationError::Entry { index: 2, value: 0 })
        );
        assert_eq!(
            inverse_permutation(&[0, 3, 1], 3),
            Err(PermutationError::Entry { index: 1, value: 3 })
        );
    }

    /// A path of `n` unknowns on a line: the dissection is a permutation, splits at the
    /// middle and numbers the separator last.
    #[test]
    fn dissection_of_a_path_is_a_permutation_with_the_separator_last() {
        let n = 9;
        let (mut col_ptr, mut row_idx) = (vec![0], Vec::new());
        for j in 0..n {
            if j > 0 {
                row_idx.push(j - 1);
            }
            row_idx.push(j);
            col_ptr.push(row_idx.len());
        }
        let pos: Vec<Option<[f64; 1]>> = (0..n).map(|i| Some([i as f64])).collect();
        let perm = pattern_dissection(&pos, &col_ptr, &row_idx, 2);
        assert_eq!(inverse_permutation(&perm, n).map(|_| ()), Ok(()));
        // The first split is at 4.0: unknowns 0..4 below, 4..9 above; 3 separates them.
        assert_eq!(perm[n - 1], 3);
        // An unknown without a position goes last.
        let mut pos = pos;
        pos[5] = None;
        let perm = pattern_dissection(&pos, &col_ptr, &row_idx, 2);
        assert_eq!(perm[n - 1], 5);
    }
}
