//! The coloured parallel sweep.
//!
//! The contacts are grouped by a greedy colouring in their sorted order: a contact takes
//! the smallest colour that no other contact of either of its bodies has taken, where
//! only bodies whose velocity the sweep changes count (disks of finite mass or inertia,
//! rigid bodies with a free axis); at most 64 colours, and a contact that finds none
//! free (a loaded wall touching many disks) goes to a last group swept in order. Within
//! a colour no two contacts share a moving body, so their local problems are independent:
//! they are solved in parallel and the result does not depend on the number of threads
//! or on the order within the colour. The colours are swept one after the other (a
//! Gauss–Seidel sweep over the colours, Jacobi-free within one). Sums for the convergence
//! test are taken per chunk of 512 contacts and added in chunk order, so they are the
//! same for any thread count too.
//!
//! Velocities live in relaxed atomics during the sweeps (plain loads and stores on
//! x86-64): the colouring, not a lock, keeps the writes apart.

use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

use rayon::prelude::*;

use crate::detect::{Antagonist, Contact};
use crate::law::solve_local;

/// Contacts per parallel chunk.
const CHUNK: usize = 512;

/// Velocities shared by the parallel sweep: `[vx, vy, ω]` per disk, `[vx, vy]` per body.
#[derive(Debug, Default)]
pub struct SharedVelocities {
    disks: Vec<AtomicU64>,
    bodies: Vec<AtomicU64>,
}

impl Clone for SharedVelocities {
    fn clone(&self) -> Self {
        let copy = |a: &[AtomicU64]| a.iter().map(|x| AtomicU64::new(x.load(Relaxed))).collect();
        Self {
            disks: copy(&self.disks),
            bodies: copy(&self.bodies),
        }
    }
}

impl SharedVelocities {
    /// Load the velocities.
    pub fn load(&mut self, v: &[[f64; 2]], omega: &[f64], body_v: &[[f64; 2]]) {
        self.disks.clear();
        for (v, w) in v.iter().zip(omega) {
            self.disks.push(AtomicU64::new(v[0].to_bits()));
            self.disks.push(AtomicU64::new(v[1].to_bits()));
            self.disks.push(AtomicU64::new(w.to_bits()));
        }
        self.bodies.clear();
        for v in body_v {
            self.bodies.push(AtomicU64::new(v[0].to_bits()));
            self.bodies.push(AtomicU64::new(v[1].to_bits()));
        }
    }

    /// Store the velocities back.
    pub fn store(&self, v: &mut [[f64; 2]], omega: &mut [f64], body_v: &mut [[f64; 2]]) {
        for i in 0..v.len() {
            v[i] = [
                self.get(&self.disks, 3 * i),
                self.get(&self.disks, 3 * i + 1),
            ];
            omega[i] = self.get(&self.disks, 3 * i + 2);
        }
        for b in 0..body_v.len() {
            body_v[b] = [
                self.get(&self.bodies, 2 * b),
                self.get(&self.bodies, 2 * b + 1),
            ];
        }
    }

    #[inline(always)]
    fn get(&self, a: &[AtomicU64], k: usize) -> f64 {
        f64::from_bits(a[k].load(Relaxed))
    }

    #[inline(always)]
    fn add(&self, a: &[AtomicU64], k: usize, dv: f64) {
        a[k].store((f64::from_bits(a[k].load(Relaxed)) + dv).to_bits(), Relaxed);
    }
}

/// Colour the contacts (see the module docs) and permute them into colour groups, with
/// the start of every group in `starts` and the end last; returns whether the last group
/// is the one swept in order (contacts that found no free colour).
pub fn colour(
    contacts: &mut Vec<Contact>,
    moving: &[bool],
    body_moving: &[bool],
    masks: &mut Vec<u64>,
    starts: &mut Vec<usize>,
) -> bool {
    let n = moving.len();
    masks.clear();
    masks.resize(n + body_moving.len(), 0);
    let node = |o: Antagonist| match o {
        Antagonist::Disk(j) => moving[j as usize].then_some(j as usize),
        Antagonist::Body(b) => body_moving[b as usize].then_some(n + b as usize),
    };
    let mut colours: Vec<u8> = Vec::with_capacity(contacts.len());
    let mut counts = [0usize; 65];
    for c in contacts.iter() {
        let a = moving[c.i as usize].then_some(c.i as usize);
        let b = node(c.other);
        let used = a.map_or(0, |a| masks[a]) | b.map_or(0, |b| masks[b]);
        let k = (!used).trailing_zeros() as usize;
        if k < 64 {
            for x in [a, b].into_iter().flatten() {
                masks[x] |= 1 << k;
            }
        }
        colours.push(k as u8);
        counts[k] += 1;
    }
    starts.clear();
    let mut offset = 0;
    let mut next = [0usize; 65];
    for k in 0..65 {
        if counts[k] > 0 {
            starts.push(offset);
        }
        next[k] = offset;
        offset += counts[k];
    }
    starts.push(offset);
    let Some(&first) = contacts.first() else {
        return false;
    };
    let mut out = vec![first; contacts.len()];
    for (c, &k) in contacts.iter().zip(&colours) {
        out[next[k as usize]] = *c;
        next[k as usize] += 1;
    }
    *contacts = out;
    counts[64] > 0
}

/// One sweep over the colour groups; returns (Σ ΔPᵀWΔP, Σ PᵀWP).
pub fn sweep(
    contacts: &mut [Contact],
    starts: &[usize],
    serial_last: bool,
    vel: &SharedVelocities,
    inv_m: &[f64],
    inv_i: &[f64],
    body_inv: &[[f64; 2]],
) -> (f64, f64) {
    let (mut num, mut den) = (0.0, 0.0);
    let groups = starts.len() - 1;
    for g in 0..groups {
        let group = &mut contacts[starts[g]..starts[g + 1]];
        if serial_last && g + 1 == groups {
            let (a, b) = solve_chunk(group, vel, inv_m, inv_i, body_inv);
            num += a;
            den += b;
        } else {
            let sums: Vec<(f64, f64)> = group
                .par_chunks_mut(CHUNK)
                .map(|chunk| solve_chunk(chunk, vel, inv_m, inv_i, body_inv))
                .collect();
            for (a, b) in sums {
                num += a;
                den += b;
            }
        }
    }
    (num, den)
}

pub(crate) fn solve_chunk(
    chunk: &mut [Contact],
    vel: &SharedVelocities,
    inv_m: &[f64],
    inv_i: &[f64],
    body_inv: &[[f64; 2]],
) -> (f64, f64) {
    let (mut num, mut den) = (0.0, 0.0);
    let d = &vel.disks;
    for c in chunk {
        let i = c.i as usize;
        let (vj, wj) = match c.other {
            Antagonist::Disk(j) => {
                let j = j as usize;
                (
                    [vel.get(d, 3 * j), vel.get(d, 3 * j + 1)],
                    vel.get(d, 3 * j + 2),
                )
            }
            Antagonist::Body(b) => {
                let b = b as usize;
                (
                    [vel.get(&vel.bodies, 2 * b), vel.get(&vel.bodies, 2 * b + 1)],
                    0.0,
                )
            }
        };
        let dv = [vel.get(d, 3 * i) - vj[0], vel.get(d, 3 * i + 1) - vj[1]];
        let un = dv[0] * c.n[0] + dv[1] * c.n[1];
        let ut = dv[0] * c.t[0] + dv[1] * c.t[1] - c.ri * vel.get(d, 3 * i + 2) - c.rj * wj;
        let w = c.w;
        let b = [
            un - (w.nn * c.p[0] + w.nt * c.p[1]) + c.bias[0],
            ut - (w.nt * c.p[0] + w.tt * c.p[1]) + c.bias[1],
        ];
        let pbar = solve_local(&w, b, c.mu);
        let p = [pbar[0] - c.shift, pbar[1]];
        let dp = [p[0] - c.p[0], p[1] - c.p[1]];
        num += w.energy(dp);
        den += w.energy(p);
        if dp != [0.0, 0.0] {
            let f = [
                dp[0] * c.n[0] + dp[1] * c.t[0],
                dp[0] * c.n[1] + dp[1] * c.t[1],
            ];
            if inv_m[i] > 0.0 || inv_i[i] > 0.0 {
                vel.add(d, 3 * i, inv_m[i] * f[0]);
                vel.add(d, 3 * i + 1, inv_m[i] * f[1]);
                vel.add(d, 3 * i + 2, -c.ri * dp[1] * inv_i[i]);
            }
            match c.other {
                Antagonist::Disk(j) => {
                    let j = j as usize;
                    if inv_m[j] > 0.0 || inv_i[j] > 0.0 {
                        vel.add(d, 3 * j, -inv_m[j] * f[0]);
                        vel.add(d, 3 * j + 1, -inv_m[j] * f[1]);
                        vel.add(d, 3 * j + 2, -c.rj * dp[1] * inv_i[j]);
                    }
                }
                Antagonist::Body(b) => {
                    let b = b as usize;
                    if body_inv[b] != [0.0, 0.0] {
                        vel.add(&vel.bodies, 2 * b, -body_inv[b][0] * f[0]);
                        vel.add(&vel.bodies, 2 * b + 1, -body_inv[b][1] * f[1]);
                    }
                }
            }
            c.p = p;
        }
    }
    (num, den)
}
