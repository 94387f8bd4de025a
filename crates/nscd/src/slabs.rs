//! The slab-partitioned parallel sweep.
//!
//! The disks are split into `P` slabs of equal count along the longer side of their
//! bounding box (`P` = the threads of rayon's pool), ranked by that coordinate with the
//! disk index breaking ties. A contact belongs to a slab when every body whose velocity
//! the sweep changes (a disk of finite mass or inertia, a rigid body with a free axis)
//! lies in it; the others — contacts across a slab boundary and contacts with a moving
//! rigid body — form the interface. One sweep solves the `P` slabs in parallel, each in
//! the sorted order of the contacts (candidate, then antagonist), then the interface in
//! sorted order. No two slabs share a moving body, so each slab is an ordinary
//! Gauss–Seidel sweep over its own contacts with the locality of the sequential sweep;
//! the order within a sweep is fixed by `P` and the positions at the start of the step,
//! so the result is the same in every run with the same thread count (and, with one
//! thread, the same as [`crate::Ordering::Sorted`] up to the interface being last). The
//! sums of the convergence test are added in slab order. The slabs are recomputed at
//! every step from the positions, an `O(n log n)` sort against the 100 or more sweeps
//! of the step.

use rayon::prelude::*;

use crate::colour::{SharedVelocities, solve_chunk};
use crate::detect::{Antagonist, Contact};

/// No slab: the body does not move in the sweep.
const FIXED: u32 = u32::MAX;
/// The interface group (after the `P` slabs).
const INTERFACE: u32 = u32::MAX - 1;

/// Reused buffers of the partition.
#[derive(Clone, Debug, Default)]
pub struct Slabs {
    rank: Vec<u32>,
    slab: Vec<u32>,
    group: Vec<u32>,
    /// Start of every slab's contacts, then of the interface, then the end.
    pub starts: Vec<usize>,
}

impl Slabs {
    /// Split the disks at positions `x` into `parts` slabs and permute `contacts` (in
    /// sorted order) into the slabs' groups and the interface, each keeping its order.
    pub fn partition(
        &mut self,
        contacts: &mut Vec<Contact>,
        x: &[[f64; 2]],
        moving: &[bool],
        body_moving: &[bool],
        parts: usize,
    ) {
        let n = x.len();
        let parts = parts.clamp(1, n.max(1));
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in x {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let axis = usize::from(hi[1] - lo[1] > hi[0] - lo[0]);
        self.rank.clear();
        self.rank.extend(0..n as u32);
        self.rank.sort_unstable_by(|&a, &b| {
            x[a as usize][axis]
                .total_cmp(&x[b as usize][axis])
                .then(a.cmp(&b))
        });
        self.slab.clear();
        self.slab.resize(n, FIXED);
        for (r, &i) in self.rank.iter().enumerate() {
            if moving[i as usize] {
                self.slab[i as usize] = (r * parts / n.max(1)) as u32;
            }
        }
        let slab = &self.slab;
        let group_of = |c: &Contact| {
            let a = slab[c.i as usize];
            let b = match c.other {
                Antagonist::Disk(j) => slab[j as usize],
                Antagonist::Body(k) if body_moving[k as usize] => INTERFACE,
                Antagonist::Body(_) => FIXED,
            };
            match (a, b) {
                (FIXED, FIXED) => INTERFACE,
                (s, FIXED) | (FIXED, s) => s,
                (s, t) if s == t => s,
                _ => INTERFACE,
            }
        };
        self.group.clear();
        self.group.extend(contacts.iter().map(group_of));
        let slot = |g: u32| if g == INTERFACE { parts } else { g as usize };
        let mut counts = vec![0usize; parts + 1];
        for &g in &self.group {
            counts[slot(g)] += 1;
        }
        self.starts.clear();
        let mut next = Vec::with_capacity(parts + 1);
        let mut offset = 0;
        for c in &counts {
            self.starts.push(offset);
            next.push(offset);
            offset += c;
        }
        self.starts.push(offset);
        let Some(&first) = contacts.first() else {
            return;
        };
        let mut out = vec![first; contacts.len()];
        for (c, &g) in contacts.iter().zip(&self.group) {
            let s = slot(g);
            out[next[s]] = *c;
            next[s] += 1;
        }
        *contacts = out;
    }

    /// One sweep: the slabs in parallel, then the interface; returns
    /// (Σ ΔPᵀWΔP, Σ PᵀWP).
    pub fn sweep(
        &self,
        contacts: &mut [Contact],
        vel: &SharedVelocities,
        inv_m: &[f64],
        inv_i: &[f64],
        body_inv: &[[f64; 2]],
    ) -> (f64, f64) {
        let parts = self.starts.len() - 2;
        let (inner, interface) = contacts.split_at_mut(self.starts[parts]);
        let mut groups: Vec<&mut [Contact]> = Vec::with_capacity(parts);
        let mut rest = inner;
        for p in 0..parts {
            let (g, r) = rest.split_at_mut(self.starts[p + 1] - self.starts[p]);
            groups.push(g);
            rest = r;
        }
        let sums: Vec<(f64, f64)> = groups
            .into_par_iter()
            .map(|g| solve_chunk(g, vel, inv_m, inv_i, body_inv))
            .collect();
        let (mut num, mut den) = (0.0, 0.0);
        for (a, b) in sums {
            num += a;
            den += b;
        }
        let (a, b) = solve_chunk(interface, vel, inv_m, inv_i, body_inv);
        (num + a, den + b)
    }
}
