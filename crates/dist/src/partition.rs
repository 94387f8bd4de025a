//! Recursive coordinate bisection (RCB) of points into `P` parts.
//!
//! A set of points to be split into `P` parts is cut by a plane normal to the axis of its
//! bounding box's longest side, at the point count `⌊n P_lo / P⌋` with `P_lo = ⌊P/2⌋`;
//! the two halves are split recursively into `P_lo` and `P − P_lo` parts. Points are
//! ordered along the axis by coordinate and, for equal coordinates, by index, so the
//! result is deterministic (the same on every process that computes it).
//!
//! Balance: a set of `n` points split into `p` parts gives parts of `⌊n/p⌋` or `⌈n/p⌉`
//! points. By induction: the left set has `m = ⌊n p_l/p⌋` points and `p_l` parts, and
//! `⌊n/p⌋ p_l ≤ m ≤ ⌈n/p⌉ p_l`, so its parts lie within `⌊n/p⌋..⌈n/p⌉` again (likewise the
//! right); every part therefore differs from every other by at most one point.
//!
//! Cost: `O(n log P)` (selection, not sorting, at every cut).

use std::cmp::Ordering;

/// The part (`0..parts`) of every point: `coords` holds `dim` coordinates per point,
/// point-major. Parts are numbered left to right in the bisection tree, so part `k`'s
/// neighbours in space tend to have nearby numbers.
///
/// # Panics
/// Never for valid input; `dim == 0`, `parts == 0` or `coords.len()` not a multiple of
/// `dim` give every point part 0.
pub fn recursive_bisection(coords: &[f64], dim: usize, parts: usize) -> Vec<usize> {
    if dim == 0 || parts == 0 || !coords.len().is_multiple_of(dim) {
        return vec![0; coords.len().checked_div(dim).unwrap_or(0)];
    }
    let n = coords.len() / dim;
    let mut part = vec![0usize; n];
    let mut ids: Vec<usize> = (0..n).collect();
    split(coords, dim, &mut ids, 0, parts, &mut part);
    part
}

/// Split the points `ids` into the parts `first..first + parts`.
fn split(
    coords: &[f64],
    dim: usize,
    ids: &mut [usize],
    first: usize,
    parts: usize,
    out: &mut [usize],
) {
    if parts <= 1 || ids.len() <= 1 {
        for &i in ids.iter() {
            out[i] = first;
        }
        return;
    }
    // Longest side of the bounding box.
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &i in ids.iter() {
        for d in 0..dim.min(3) {
            let x = coords[i * dim + d];
            lo[d] = lo[d].min(x);
            hi[d] = hi[d].max(x);
        }
    }
    let axis = (0..dim.min(3))
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])).then(b.cmp(&a)))
        .unwrap_or(0);
    let left_parts = parts / 2;
    let m = ids.len() * left_parts / parts;
    let key = |i: &usize, j: &usize| -> Ordering {
        coords[i * dim + axis]
            .total_cmp(&coords[j * dim + axis])
            .then(i.cmp(j))
    };
    if m > 0 && m < ids.len() {
        ids.select_nth_unstable_by(m, key);
    }
    let (l, r) = ids.split_at_mut(m);
    split(coords, dim, l, first, left_parts, out);
    split(coords, dim, r, first + left_parts, parts - left_parts, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(nx: usize, ny: usize, nz: usize) -> Vec<f64> {
        let mut c = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    c.extend([i as f64, j as f64 * 0.7, k as f64 * 1.3]);
                }
            }
        }
        c
    }

    #[test]
    fn parts_are_balanced_to_one_point() {
        let c = grid(13, 7, 5);
        let n = c.len() / 3;
        for p in 1..=11 {
            let part = recursive_bisection(&c, 3, p);
            let mut count = vec![0usize; p];
            for &q in &part {
                count[q] += 1;
            }
            let (mn, mx) = (*count.iter().min().unwrap(), *count.iter().max().unwrap());
            assert!(mx - mn <= 1, "P = {p}: sizes {count:?}");
            assert_eq!(count.iter().sum::<usize>(), n);
            assert_eq!(mn, n / p);
        }
    }

    #[test]
    fn two_parts_cut_the_longest_axis() {
        // 10 × 2 points: the cut is normal to x, at x between 4 and 5.
        let mut c = Vec::new();
        for j in 0..2 {
            for i in 0..10 {
                c.extend([i as f64, j as f64]);
            }
        }
        let part = recursive_bisection(&c, 2, 2);
        for (p, xy) in part.iter().zip(c.chunks(2)) {
            assert_eq!(*p, usize::from(xy[0] >= 5.0));
        }
        // Deterministic: the same answer again.
        assert_eq!(part, recursive_bisection(&c, 2, 2));
    }
}
