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
//!
//! **Storage**: every slab, and the interface, is a problem of its own for the step: its
//! contacts with the disks renumbered locally (the slab's own disks in index order, then
//! copies of the immovable disks it touches), and plain arrays of its disks'
//! velocities, inverse masses and inertias and of the bodies' velocities. A slab is
//! swept by the sequential sweep itself ([`crate::nlgs`]) on its own arrays, with the
//! same arithmetic and the same cost per update; nothing is shared between threads
//! during a sweep. After the slabs, the velocities of the disks that interface contacts
//! touch are copied from their slabs into the interface's arrays, the interface is
//! swept, and they are copied back: a few hundred numbers per sweep against the
//! thousands of contacts of a slab.

use rayon::prelude::*;

use crate::detect::{Antagonist, Contact};
use crate::nlgs::sweep;

/// No slab: the body does not move in the sweep.
const FIXED: u32 = u32::MAX;
/// The interface group (after the `P` slabs).
const INTERFACE: u32 = u32::MAX - 1;
/// No local index yet.
const NONE: u32 = u32::MAX;

/// One slab, or the interface, as a problem of its own: contacts in local numbering and
/// the arrays the sequential sweep updates.
#[derive(Clone, Debug, Default)]
struct Part {
    /// The contacts, disks numbered locally.
    contacts: Vec<Contact>,
    /// The index of every contact in the step's list.
    origin: Vec<u32>,
    /// The global index of every local disk.
    global: Vec<u32>,
    /// Velocities, angular velocities, inverse masses and inertias of the local disks.
    v: Vec<[f64; 2]>,
    omega: Vec<f64>,
    inv_m: Vec<f64>,
    inv_i: Vec<f64>,
    /// The bodies' velocities.
    body_v: Vec<[f64; 2]>,
    /// The sums (Σ ΔPᵀWΔP, Σ PᵀWP) of the last sweep.
    sums: (f64, f64),
}

impl Part {
    fn clear(&mut self) {
        self.contacts.clear();
        self.origin.clear();
        self.global.clear();
    }

    /// Local index of global disk `g`, adding it (a copy) if it is not there yet.
    fn local(&mut self, g: u32, index: &mut [u32], touched: &mut Vec<u32>) -> u32 {
        let k = &mut index[g as usize];
        if *k == NONE {
            *k = self.global.len() as u32;
            self.global.push(g);
            touched.push(g);
        }
        *k
    }
}

/// Reused buffers of the partition.
#[derive(Clone, Debug, Default)]
pub struct Slabs {
    rank: Vec<u32>,
    /// The slab of every disk ([`FIXED`] for an immovable one).
    slab: Vec<u32>,
    /// The part of every contact: its slab, or `P` for the interface.
    group: Vec<u32>,
    /// The `P` slabs, then the interface.
    parts: Vec<Part>,
    /// Local index of every global disk in its own slab.
    own: Vec<u32>,
    /// Scratch: local index of a global disk in the part being built.
    index: Vec<u32>,
    /// The moving disks of the interface: (local index in the interface, slab, local
    /// index in the slab).
    links: Vec<(u32, u32, u32)>,
}

impl Slabs {
    /// Split the disks at positions `x` into `parts` slabs and assign each of the
    /// `contacts` to its slab or to the interface.
    pub fn partition(
        &mut self,
        contacts: &[Contact],
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
        self.group
            .extend(contacts.iter().map(|c| match group_of(c) {
                INTERFACE => parts as u32,
                g => g,
            }));
        self.parts.resize_with(parts + 1, Part::default);
        self.parts.truncate(parts + 1);
    }

    /// Set up the parts of the step from `contacts` and the current velocities (after
    /// [`Slabs::partition`] of the same contacts).
    #[allow(clippy::too_many_arguments)]
    pub fn load(
        &mut self,
        contacts: &[Contact],
        v: &[[f64; 2]],
        omega: &[f64],
        body_v: &[[f64; 2]],
        inv_m: &[f64],
        inv_i: &[f64],
    ) {
        let n = v.len();
        let parts = self.parts.len() - 1;
        for part in &mut self.parts {
            part.clear();
        }
        // Every moving disk in its own slab, in index order.
        self.own.clear();
        self.own.resize(n, NONE);
        for i in 0..n {
            let s = self.slab[i];
            if s != FIXED {
                let part = &mut self.parts[s as usize];
                self.own[i] = part.global.len() as u32;
                part.global.push(i as u32);
            }
        }
        self.index.clear();
        self.index.resize(n, NONE);
        let mut touched = Vec::new();
        self.links.clear();
        for p in 0..=parts {
            let part = &mut self.parts[p];
            if p < parts {
                for &g in &part.global {
                    self.index[g as usize] = self.own[g as usize];
                }
                touched.extend_from_slice(&part.global);
            }
            for (k, c) in contacts.iter().enumerate() {
                if self.group[k] != p as u32 {
                    continue;
                }
                part.origin.push(k as u32);
                let mut local = *c;
                local.i = part.local(c.i, &mut self.index, &mut touched);
                if let Antagonist::Disk(j) = c.other {
                    local.other = Antagonist::Disk(part.local(j, &mut self.index, &mut touched));
                }
                part.contacts.push(local);
            }
            part.v.clear();
            part.omega.clear();
            part.inv_m.clear();
            part.inv_i.clear();
            for &g in &part.global {
                let g = g as usize;
                part.v.push(v[g]);
                part.omega.push(omega[g]);
                part.inv_m.push(inv_m[g]);
                part.inv_i.push(inv_i[g]);
            }
            part.body_v.clear();
            part.body_v.extend_from_slice(body_v);
            if p == parts {
                for (k, &g) in part.global.iter().enumerate() {
                    let s = self.slab[g as usize];
                    if s != FIXED {
                        self.links.push((k as u32, s, self.own[g as usize]));
                    }
                }
            }
            for g in touched.drain(..) {
                self.index[g as usize] = NONE;
            }
        }
    }

    /// One sweep: the slabs in parallel, then the interface; returns
    /// (Σ ΔPᵀWΔP, Σ PᵀWP).
    pub fn sweep(&mut self, body_inv: &[[f64; 2]]) -> (f64, f64) {
        let parts = self.parts.len() - 1;
        let (slabs, interface) = self.parts.split_at_mut(parts);
        slabs.par_iter_mut().for_each(|p| {
            p.sums = sweep(
                &mut p.contacts,
                None,
                &mut p.v,
                &mut p.omega,
                &p.inv_m,
                &p.inv_i,
                &mut p.body_v,
                body_inv,
            );
        });
        let (mut num, mut den) = (0.0, 0.0);
        for p in slabs.iter() {
            num += p.sums.0;
            den += p.sums.1;
        }
        let face = &mut interface[0];
        if face.contacts.is_empty() {
            return (num, den);
        }
        for &(k, s, l) in &self.links {
            face.v[k as usize] = slabs[s as usize].v[l as usize];
            face.omega[k as usize] = slabs[s as usize].omega[l as usize];
        }
        let (a, b) = sweep(
            &mut face.contacts,
            None,
            &mut face.v,
            &mut face.omega,
            &face.inv_m,
            &face.inv_i,
            &mut face.body_v,
            body_inv,
        );
        for &(k, s, l) in &self.links {
            slabs[s as usize].v[l as usize] = face.v[k as usize];
            slabs[s as usize].omega[l as usize] = face.omega[k as usize];
        }
        (num + a, den + b)
    }

    /// Write the impulses back into `contacts` and the velocities into
    /// `v`, `omega` and `body_v` (the moving bodies' from the interface).
    pub fn store(
        &self,
        contacts: &mut [Contact],
        v: &mut [[f64; 2]],
        omega: &mut [f64],
        body_v: &mut [[f64; 2]],
    ) {
        for part in &self.parts {
            for (&k, local) in part.origin.iter().zip(&part.contacts) {
                contacts[k as usize].p = local.p;
            }
        }
        for (i, &s) in self.slab.iter().enumerate() {
            if s != FIXED {
                let part = &self.parts[s as usize];
                let l = self.own[i] as usize;
                v[i] = part.v[l];
                omega[i] = part.omega[l];
            }
        }
        if let Some(face) = self.parts.last() {
            body_v.copy_from_slice(&face.body_v);
        }
    }
}
