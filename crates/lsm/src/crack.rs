//! The crack that grows from a borehole: which broken bonds are connected to the hole
//! wall, and how far from the hole centre the farthest of them lies.
//!
//! **Breakdown as an event.** In laboratory and field hydraulic fracturing the breakdown
//! pressure is the pressure at which a fracture runs away from the borehole; the first
//! microcracks start well below it. Counting broken bonds (the first, the tenth) is
//! therefore not a measure of breakdown. What is measurable in a lattice solid is the
//! *radial extent of the crack connected to the hole*:
//!
//! * the graph whose vertices are the disks plus one vertex for the hole, and whose edges
//!   are the broken bonds, plus an edge from the hole to every disk lining it (the disks
//!   seen from the hole centre, [`crate::WallFaces::Rays`]);
//! * the crack connected to the hole is the connected component of the hole vertex; its
//!   extent is `r_c = max |x_k − c|` over the broken bonds `k` of that component (`x_k`
//!   the contact point where the bond broke, `c` the hole centre), and `0` while the
//!   component holds no broken bond.
//!
//! A tensile crack in a bonded packing separates disks along a path in the dual of the
//! bond network: two consecutive bonds it cuts belong to one bonded triangle and share a
//! disk, so the bonds broken along one crack form a connected set of edges. A crack that
//! crosses a pore bounded by four or more disks can be split in two by this rule (it
//! has no edge across the pore); the extent then stops at the pore, which errs towards a
//! later, higher breakdown. [`CrackExtent::across_pores`] closes that gap: a broken bond
//! then also joins the disks of the pores on its two sides (the faces of the bond
//! network), so a crack is one crack across any pore it opens. It matters: a pressurised
//! notch of half-length 3 m in the packing of the borehole scenes (radii 0.1–1 m) runs at
//! 4.14 MPa when joined across pores and at 8.97 MPa when not, after 268 broken bonds of
//! diffuse damage around a crack that its own pressure never reaches
//! (`crates/lsm/tests/notch_toughness.rs`). Broken bonds in the rock that are not connected to the hole
//! (isolated microcracks, or cracks in fluid-filled pockets behind the lining that have
//! not yet joined the wall) do not count.
//!
//! The extent never decreases (bonds do not heal), and is computed incrementally with a
//! disjoint-set forest (union by size, path halving): `O(α(n))` per broken bond.
//!
//! **A flooded crack** ([`CrackExtent::flood_loads`]). A fluid that follows the crack
//! (the zero-lag limit of hydraulic fracturing) puts the hole pressure `p` on its faces.
//! A broken bond `k` between disks `i` and `j` of the hole's component is one segment of
//! the crack; the bond carried the normal stress `F_n/w` over its width
//! `w = 2 min(R_i, R_j)` ([`crate::law`]), so the pressure in the opened gap pushes the
//! two disks apart with `p w` along the current centre line `n = (x_j − x_i)/|x_j − x_i|`:
//! `+p w n` on j and `−p w n` on i (no moment: the gap faces are normal to `n`). A crack
//! under its own pressure loads its tip with a stress intensity that grows with its
//! length (roughly `K_I ∝ p √(π(a + L))` for a crack of length L from a hole of radius
//! a, linear elastic fracture mechanics), so it keeps growing at a rising pressure; a
//! dry crack (pressure on the hole wall only) is loaded by the hoop stress
//! `σ_θθ ∝ p a²/r²` alone, which falls away from the wall, and it stalls.
//!
//! **Which width.** The bond width `w = 2 min(R_i, R_j)` is the bond's section, not the
//! length of crack face it stands for: in a hexagonal lattice the flooded bonds of a
//! straight crack push its faces apart with √3 times `p` times its length; along straight
//! notches through random packings of radii 0.1–1 m with `Σ w_k |n_k · m|` = 0.86–1.29
//! of it (m the notch normal, six notches; [`crate::toughness::NotchTest::face_load`]),
//! right on average but not bond by bond.
//! [`FaceWidths::radical`] gives every bond the length of its *face*: the edge shared by
//! the two disks' cells of the power (radical Voronoi) diagram, between the radical
//! centres of the bonded triangles on either side. The cells tile the plane, so the faces
//! crossed by a straight crack add up, projected, to its length, and the flooded loads of
//! [`CrackExtent::flood_loads_on_faces`] are a pressure `p` on the crack: in a hexagonal
//! lattice exactly (`flooded_faces_of_a_hexagonal_lattice_carry_the_pressure`). A side
//! with no bonded triangle (a pore of four or more disks, a free surface) ends the face
//! at `min(R_i, R_j)` from the centre line, as the bond width does.

use crate::LsmError;
use crate::bond::{Bond, BrokenBond};
use porofrac_particles::Disks;

/// The most disks of a pore that [`CrackExtent::across_pores`] joins.
pub const MAX_PORE: usize = 8;

/// Which length of crack face a flooded broken bond stands for (module docs, "Which
/// width").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CrackFaces {
    /// The bond width `w = 2 min(R_i, R_j)` ([`CrackExtent::flood_loads`]).
    #[default]
    BondWidth,
    /// The power-diagram face ([`FaceWidths::radical`],
    /// [`CrackExtent::flood_loads_on_faces`]).
    Radical,
}

/// The crack-face length of every bond of a packing (module docs, "Which width").
#[derive(Clone, Debug, PartialEq)]
pub struct FaceWidths {
    /// `(i, j)` of every bond, `i < j`, sorted.
    pairs: Vec<(u32, u32)>,
    /// Face length (m) of each.
    width: Vec<f64>,
}

impl FaceWidths {
    /// The power-diagram face of each of `bonds` (intact or broken) between the disks
    /// of `disks` in their current configuration: the segment of the radical line of
    /// `i` and `j` between the radical centres of the triangles `(i, j, k)` closest to
    /// the bond on either side, `k` bonded to both; a side without one ends at
    /// `min(R_i, R_j)`; each end at most `max(R_i, R_j)` from the centre line.
    pub fn radical(disks: &Disks, bonds: &[Bond]) -> Self {
        let n = disks.len();
        let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
        for b in bonds {
            adj[b.i as usize].push(b.j);
            adj[b.j as usize].push(b.i);
        }
        adj.iter_mut().for_each(|a| a.sort_unstable());
        let mut order: Vec<usize> = (0..bonds.len()).collect();
        order.sort_unstable_by_key(|&k| (bonds[k].i.min(bonds[k].j), bonds[k].i.max(bonds[k].j)));
        let mut pairs = Vec::with_capacity(bonds.len());
        let mut width = Vec::with_capacity(bonds.len());
        for k in order {
            let (i, j) = (bonds[k].i.min(bonds[k].j), bonds[k].i.max(bonds[k].j));
            pairs.push((i, j));
            width.push(radical_face(disks, i as usize, j as usize, &adj));
        }
        Self { pairs, width }
    }

    /// The face length (m) of the bond between `i` and `j`, if there is one.
    pub fn get(&self, i: usize, j: usize) -> Option<f64> {
        let key = (i.min(j) as u32, i.max(j) as u32);
        self.pairs.binary_search(&key).ok().map(|k| self.width[k])
    }
}

/// The power-diagram face of the bond `i`–`j` ([`FaceWidths::radical`]).
fn radical_face(disks: &Disks, i: usize, j: usize, adj: &[Vec<u32>]) -> f64 {
    let (xi, xj) = (disks.x[i], disks.x[j]);
    let (ri, rj) = (disks.r[i], disks.r[j]);
    let e = [xj[0] - xi[0], xj[1] - xi[1]];
    let d = e[0].hypot(e[1]);
    let t = [-e[1] / d, e[0] / d];
    let (rmin, rmax) = (ri.min(rj), ri.max(rj));
    let power = |x: [f64; 2], r: f64| x[0] * x[0] + x[1] * x[1] - r * r;
    let (mut left, mut right) = (f64::INFINITY, f64::NEG_INFINITY);
    let (ai, aj) = (&adj[i], &adj[j]);
    let (mut p, mut q) = (0, 0);
    while p < ai.len() && q < aj.len() {
        if ai[p] < aj[q] {
            p += 1;
            continue;
        }
        if aj[q] < ai[p] {
            q += 1;
            continue;
        }
        let k = ai[p] as usize;
        p += 1;
        q += 1;
        let xk = disks.x[k];
        let f = [xk[0] - xi[0], xk[1] - xi[1]];
        // the radical centre c: 2 e·c = P_j − P_i, 2 f·c = P_k − P_i (P = |x|² − R²)
        let det = 2.0 * (e[0] * f[1] - e[1] * f[0]);
        if det == 0.0 {
            continue;
        }
        let g = power(xj, rj) - power(xi, ri);
        let h = power(xk, disks.r[k]) - power(xi, ri);
        let c = [(g * f[1] - h * e[1]) / det, (e[0] * h - f[0] * g) / det];
        let s = ((c[0] - xi[0]) * t[0] + (c[1] - xi[1]) * t[1]).clamp(-rmax, rmax);
        if f[0] * t[0] + f[1] * t[1] > 0.0 {
            left = left.min(s);
        } else {
            right = right.max(s);
        }
    }
    if left == f64::INFINITY {
        left = rmin;
    }
    if right == f64::NEG_INFINITY {
        right = -rmin;
    }
    (left - right).max(0.0)
}

/// The crack connected to a hole wall, grown one broken bond at a time (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct CrackExtent {
    centre: [f64; 2],
    /// With [`Self::across_pores`]: the bonded neighbours of every disk in
    /// counter-clockwise order (offsets, items).
    pores: Option<(Vec<u32>, Vec<u32>)>,
    /// Parent of every disk; index `n` is the hole.
    parent: Vec<u32>,
    /// Size of the tree of every root.
    size: Vec<u32>,
    /// Largest distance from the centre of a broken bond in the tree of every root.
    reach: Vec<f64>,
}

impl CrackExtent {
    /// A hole of centre `centre` in a packing of `disks` disks, lined by the disks
    /// `lining` (indices below `disks`, e.g. the members of a
    /// [`crate::PressureWall`] built with [`crate::WallFaces::Rays`]).
    pub fn new(disks: usize, lining: &[usize], centre: [f64; 2]) -> Result<Self, LsmError> {
        if disks >= u32::MAX as usize {
            return Err(LsmError::bad("disks", disks as f64, "too many particles"));
        }
        if !(centre[0].is_finite() && centre[1].is_finite()) {
            return Err(LsmError::bad("centre", f64::NAN, "must be finite"));
        }
        if lining.is_empty() {
            return Err(LsmError::bad("lining", 0.0, "no disk lines the hole"));
        }
        let mut s = Self {
            centre,
            pores: None,
            parent: (0..=disks as u32).collect(),
            size: vec![1; disks + 1],
            reach: vec![0.0; disks + 1],
        };
        for &i in lining {
            if i >= disks {
                return Err(LsmError::bad(
                    "lining",
                    i as f64,
                    "is not the index of a disk",
                ));
            }
            s.union(i, disks);
        }
        Ok(s)
    }

    /// Join cracks across pores: a broken bond also joins every disk of the pores on its
    /// two sides (the faces of the bond network `bonds` of `disks`, traced in the current
    /// configuration; faces of more than [`MAX_PORE`] disks, such as the hole or the
    /// outer surface, are left alone), so that a crack that crosses a pore of four or more
    /// disks stays one crack (module docs). Errors when `disks` is not the packing of
    /// [`Self::new`].
    pub fn across_pores(mut self, disks: &Disks, bonds: &[Bond]) -> Result<Self, LsmError> {
        let n = self.parent.len() - 1;
        if disks.len() != n {
            return Err(LsmError::bad(
                "disks",
                disks.len() as f64,
                "is not the hole's packing",
            ));
        }
        let mut start = vec![0u32; n + 1];
        for b in bonds {
            if b.i as usize >= n || b.j as usize >= n {
                return Err(LsmError::bad(
                    "bonds",
                    b.i.max(b.j) as f64,
                    "is not the index of a disk",
                ));
            }
            start[b.i as usize + 1] += 1;
            start[b.j as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut items = vec![0u32; start[n] as usize];
        let mut next: Vec<u32> = start[..n].to_vec();
        for b in bonds {
            for (u, v) in [(b.i, b.j), (b.j, b.i)] {
                items[next[u as usize] as usize] = v;
                next[u as usize] += 1;
            }
        }
        for u in 0..n {
            let x = disks.x[u];
            let angle = |v: &u32| {
                let y = disks.x[*v as usize];
                (y[1] - x[1]).atan2(y[0] - x[0])
            };
            items[start[u] as usize..start[u + 1] as usize]
                .sort_by(|a, b| angle(a).total_cmp(&angle(b)));
        }
        self.pores = Some((start, items));
        Ok(self)
    }

    /// The disks of the face left of the directed bond `u → v` (at most [`MAX_PORE`];
    /// `None` for a larger face or a bond not in the network).
    fn pore(&self, u: usize, v: usize) -> Option<Vec<u32>> {
        let (start, items) = self.pores.as_ref()?;
        let around = |k: usize| &items[start[k] as usize..start[k + 1] as usize];
        let mut face = vec![u as u32];
        let (mut a, mut b) = (u, v);
        for _ in 0..MAX_PORE {
            if b == u {
                return Some(face);
            }
            face.push(b as u32);
            // the neighbour of b just clockwise of a: the face stays on the left
            let nb = around(b);
            let k = nb.iter().position(|&w| w as usize == a)?;
            let w = nb[(k + nb.len() - 1) % nb.len()] as usize;
            (a, b) = (b, w);
        }
        None
    }

    /// Record the broken bond between disks `i` and `j` that broke at `at` (m); returns
    /// the extent of the crack connected to the hole afterwards.
    pub fn add(&mut self, i: usize, j: usize, at: [f64; 2]) -> Result<f64, LsmError> {
        let n = self.parent.len() - 1;
        for (name, k) in [("i", i), ("j", j)] {
            if k >= n {
                return Err(LsmError::bad(name, k as f64, "is not the index of a disk"));
            }
        }
        if !(at[0].is_finite() && at[1].is_finite()) {
            return Err(LsmError::bad("at", f64::NAN, "must be finite"));
        }
        let d = (at[0] - self.centre[0]).hypot(at[1] - self.centre[1]);
        for (u, v) in [(i, j), (j, i)] {
            if let Some(face) = self.pore(u, v) {
                for k in face {
                    self.union(i, k as usize);
                }
            }
        }
        let r = self.union(i, j);
        self.reach[r] = self.reach[r].max(d);
        Ok(self.extent())
    }

    /// The extent `r_c` of the crack connected to the hole (m from the centre), `0` while
    /// no broken bond is connected to it.
    pub fn extent(&self) -> f64 {
        let mut k = self.parent.len() - 1;
        while self.parent[k] as usize != k {
            k = self.parent[k] as usize;
        }
        self.reach[k]
    }

    /// Whether disk `i` (an index below the number of disks) is connected to the hole
    /// through broken bonds or the lining.
    pub fn connected(&mut self, i: usize) -> bool {
        let n = self.parent.len() - 1;
        i < n && self.find(i) == self.find(n)
    }

    /// Add to `loads` (`[f_x, f_y, torque]` per disk, N/m) the forces of the pressure `p`
    /// (Pa) in the broken bonds `broken` that belong to the crack connected to the hole
    /// (module docs: `±p w n`), in the configuration of `disks`; returns how many bonds
    /// are flooded. Bonds not yet [`Self::add`]ed are not connected.
    pub fn flood_loads(
        &mut self,
        disks: &Disks,
        broken: &[BrokenBond],
        p: f64,
        loads: &mut [[f64; 3]],
    ) -> Result<usize, LsmError> {
        self.flood_with(disks, broken, p, loads, |b| {
            Ok(2.0 * disks.r[b.i].min(disks.r[b.j]))
        })
    }

    /// [`Self::flood_loads`] with the face length of each broken bond from `faces`
    /// (module docs, "Which width"): `±p ℓ_k n` instead of `±p w n`. A broken bond that
    /// `faces` does not know is an error.
    pub fn flood_loads_on_faces(
        &mut self,
        disks: &Disks,
        broken: &[BrokenBond],
        p: f64,
        faces: &FaceWidths,
        loads: &mut [[f64; 3]],
    ) -> Result<usize, LsmError> {
        self.flood_with(disks, broken, p, loads, |b| {
            faces.get(b.i, b.j).ok_or(LsmError::bad(
                "faces",
                b.i as f64,
                "has no face for a broken bond of this disk",
            ))
        })
    }

    fn flood_with(
        &mut self,
        disks: &Disks,
        broken: &[BrokenBond],
        p: f64,
        loads: &mut [[f64; 3]],
        width: impl Fn(&BrokenBond) -> Result<f64, LsmError>,
    ) -> Result<usize, LsmError> {
        let n = self.parent.len() - 1;
        if disks.len() != n || loads.len() != n {
            return Err(LsmError::bad(
                "loads",
                loads.len() as f64,
                "must have one entry per disk of the hole's packing",
            ));
        }
        if !p.is_finite() {
            return Err(LsmError::bad("p", p, "must be finite"));
        }
        let hole = self.find(n);
        let mut flooded = 0;
        for b in broken {
            if b.i >= n || b.j >= n {
                return Err(LsmError::bad(
                    "broken",
                    b.i.max(b.j) as f64,
                    "is not the index of a disk",
                ));
            }
            if self.find(b.i) != hole || self.find(b.j) != hole {
                continue;
            }
            let (xi, xj) = (disks.x[b.i], disks.x[b.j]);
            let e = [xj[0] - xi[0], xj[1] - xi[1]];
            let d = e[0].hypot(e[1]);
            if d == 0.0 {
                continue;
            }
            let f = p * width(b)? / d;
            loads[b.j][0] += f * e[0];
            loads[b.j][1] += f * e[1];
            loads[b.i][0] -= f * e[0];
            loads[b.i][1] -= f * e[1];
            flooded += 1;
        }
        Ok(flooded)
    }

    fn find(&mut self, mut k: usize) -> usize {
        while self.parent[k] as usize != k {
            let g = self.parent[self.parent[k] as usize];
            self.parent[k] = g;
            k = g as usize;
        }
        k
    }

    /// Join the trees of `a` and `b`; returns the root.
    fn union(&mut self, a: usize, b: usize) -> usize {
        let (mut ra, mut rb) = (self.find(a), self.find(b));
        if ra == rb {
            return ra;
        }
        if self.size[ra] < self.size[rb] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.parent[rb] = ra as u32;
        self.size[ra] += self.size[rb];
        self.reach[ra] = self.reach[ra].max(self.reach[rb]);
        ra
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-made bond set around a hole of centre (1, 2): lining disks 0, 1, 2; a
    /// chain 1–3–4–5 running out; an isolated pair 6–7 farther out; a link 5–6 that
    /// joins them last.
    #[test]
    fn extent_follows_the_crack_connected_to_the_hole() {
        let c = [1.0, 2.0];
        let at = |r: f64| [c[0] + 0.6 * r, c[1] - 0.8 * r];
        let mut x = CrackExtent::new(8, &[0, 1, 2], c).unwrap();
        assert_eq!(x.extent(), 0.0);
        // an isolated microcrack far out does not count
        assert_eq!(x.add(6, 7, at(9.0)).unwrap(), 0.0);
        // a bond between two lining disks: the crack mouth
        let e = x.add(0, 1, at(3.5)).unwrap();
        assert!((e - 3.5).abs() < 1e-12, "{e}");
        // the chain grows from lining disk 1
        assert!((x.add(1, 3, at(4.5)).unwrap() - 4.5).abs() < 1e-12);
        assert!((x.add(4, 5, at(6.5)).unwrap() - 4.5).abs() < 1e-12);
        assert!(!x.connected(4));
        // the link 3–4 joins the chain 4–5 to the crack
        assert!((x.add(3, 4, at(5.5)).unwrap() - 6.5).abs() < 1e-12);
        assert!(x.connected(5) && !x.connected(6));
        // a nearer break does not lower the extent
        assert!((x.add(0, 2, at(3.2)).unwrap() - 6.5).abs() < 1e-12);
        // joining the isolated pair brings its reach in
        assert!((x.add(5, 6, at(7.0)).unwrap() - 9.0).abs() < 1e-12);
        assert!(x.connected(7));
    }

    /// A bond of one lining disk counts (the lining is joined to the hole); a crack
    /// that never touches the lining does not, however long.
    #[test]
    fn cracks_away_from_the_lining_do_not_count() {
        let mut x = CrackExtent::new(20, &[0], [0.0, 0.0]).unwrap();
        for k in 1..19 {
            assert_eq!(x.add(k, k + 1, [k as f64, 0.0]).unwrap(), 0.0);
        }
        assert!((x.add(0, 10, [2.0, 0.0]).unwrap() - 18.0).abs() < 1e-12);
    }

    /// The flooded bonds of the hole's crack push their disks apart with `p · 2 min(R)`
    /// along the centre line; a crack not connected to the hole gets nothing.
    #[test]
    fn flooded_crack_pushes_its_faces_apart() {
        use crate::bond::BreakMode;
        let centres = [[3.0, 0.0], [4.0, 1.0], [8.0, 0.0], [9.0, 0.0]];
        let radii = [0.5, 0.8, 0.4, 0.6];
        let disks = Disks::new(&centres, &radii, 2600.0).unwrap();
        let bond = |i, j| BrokenBond {
            time: 0.0,
            i,
            j,
            x: 0.5 * (centres[i][0] + centres[j][0]),
            y: 0.5 * (centres[i][1] + centres[j][1]),
            mode: BreakMode::Tensile,
        };
        let broken = [bond(0, 1), bond(2, 3)];
        let mut x = CrackExtent::new(4, &[0], [0.0, 0.0]).unwrap();
        for b in &broken {
            x.add(b.i, b.j, [b.x, b.y]).unwrap();
        }
        let mut loads = vec![[0.0; 3]; 4];
        let p = 2.0e6;
        assert_eq!(x.flood_loads(&disks, &broken, p, &mut loads).unwrap(), 1);
        // bond 0-1: w = 1.0, n = (1, 1)/√2
        let f = p * 1.0 / 2f64.sqrt();
        for (k, sign) in [(0, -1.0), (1, 1.0)] {
            for c in 0..2 {
                assert!((loads[k][c] - sign * f).abs() < 1e-9 * f, "{k} {loads:?}");
            }
            assert_eq!(loads[k][2], 0.0);
        }
        assert_eq!(loads[2], [0.0; 3]);
        assert_eq!(loads[3], [0.0; 3]);
        // joining 1-2 floods the far pair too: w = 0.8 along x for 2-3
        x.add(1, 2, [6.0, 0.5]).unwrap();
        let mut loads = vec![[0.0; 3]; 4];
        assert_eq!(x.flood_loads(&disks, &broken, p, &mut loads).unwrap(), 2);
        assert!((loads[3][0] - p * 0.8).abs() < 1e-9 * p && loads[3][1].abs() < 1e-9 * p);
        let e = x
            .flood_loads(&disks, &broken, p, &mut loads[..3])
            .unwrap_err();
        assert!(e.to_string().starts_with("loads"), "{e}");
        let e = x
            .flood_loads(&disks, &broken, f64::NAN, &mut loads)
            .unwrap_err();
        assert!(e.to_string().starts_with("p = NaN"), "{e}");
    }

    /// A square pore of four disks 0-1-2-3 (bonded around, no diagonal) between the
    /// hole's lining disk 0 and the far disks: the crack through bond 0–1 and the crack
    /// through the opposite bond 2–3 share no disk; across pores they are one crack.
    #[test]
    fn a_crack_through_a_four_disk_pore_is_one_crack_across_pores() {
        use crate::law::BondLaw;
        let centres = [
            [2.0, 0.0],
            [2.0, 1.0],
            [3.0, 1.0],
            [3.0, 0.0],
            [4.0, 0.0],
            [4.0, 1.0],
        ];
        let disks = Disks::new(&centres, &[0.5; 6], 2600.0).unwrap();
        let law = BondLaw::elastic(1e9, 1e9, 0.0);
        let bonds: Vec<Bond> = [(0, 1), (1, 2), (2, 3), (0, 3), (3, 4), (2, 5), (4, 5)]
            .iter()
            .map(|&(i, j)| Bond::new(&disks, i, j, &law))
            .collect();
        for pores in [false, true] {
            let mut x = CrackExtent::new(6, &[0], [0.0, 0.5]).unwrap();
            if pores {
                x = x.across_pores(&disks, &bonds).unwrap();
            }
            x.add(0, 3, [2.5, 0.0]).unwrap();
            // the bond 2–3 on the far side of the pore
            let e = x.add(1, 2, [2.5, 1.0]).unwrap();
            assert!((e - 2.5f64.hypot(0.5)).abs() < 1e-12, "{e}");
            let e = x.add(4, 5, [4.0, 0.5]).unwrap();
            if pores {
                // the pore 2-3-4-5 joins 4-5 to the crack
                assert!((e - 4.0).abs() < 1e-12, "{e}");
                assert!(x.connected(5));
            } else {
                assert!((e - 2.5f64.hypot(0.5)).abs() < 1e-12, "{e}");
                assert!(!x.connected(5) && !x.connected(4));
            }
        }
        let e = CrackExtent::new(5, &[0], [0.0; 2])
            .unwrap()
            .across_pores(&disks, &bonds)
            .unwrap_err();
        assert!(e.to_string().starts_with("disks = 6"), "{e}");
    }

    /// Faces of a hexagonal lattice of diameter d: every bond's power-diagram face is
    /// d/√3 long, so the flooded bonds of a straight crack along a row direction load
    /// its faces with p per unit length (the bond width d loads them with √3 p).
    #[test]
    fn flooded_faces_of_a_hexagonal_lattice_carry_the_pressure() {
        use crate::law::BondLaw;
        let d = 0.6;
        let (nx, ny) = (12, 10);
        let mut centres = Vec::new();
        for row in 0..ny {
            for col in 0..nx {
                let x = col as f64 * d + if row % 2 == 1 { 0.5 * d } else { 0.0 };
                centres.push([x, row as f64 * d * 3f64.sqrt() / 2.0]);
            }
        }
        let n = centres.len();
        let disks = Disks::new(&centres, &vec![0.5 * d; n], 2600.0).unwrap();
        let law = BondLaw::elastic(1e9, 1e9, 0.0);
        let mut bonds = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let e = [centres[j][0] - centres[i][0], centres[j][1] - centres[i][1]];
                if e[0].hypot(e[1]) < 1.01 * d {
                    bonds.push(Bond::new(&disks, i, j, &law));
                }
            }
        }
        let faces = FaceWidths::radical(&disks, &bonds);
        // interior bonds: d/√3
        let interior = |k: usize| {
            let (r, c) = (k / nx, k % nx);
            (2..ny - 2).contains(&r) && (2..nx - 2).contains(&c)
        };
        let mut checked = 0;
        for b in &bonds {
            let (i, j) = (b.i as usize, b.j as usize);
            if interior(i) && interior(j) {
                let w = faces.get(i, j).unwrap();
                assert!((w - d / 3f64.sqrt()).abs() < 1e-12, "{i}-{j}: {w}");
                checked += 1;
            }
        }
        assert!(checked > 100);
        assert_eq!(faces.get(0, n - 1), None);
        // a crack between rows 4 and 5, columns 3..9: the bonds crossing y = y_4 + h/2
        let h = d * 3f64.sqrt() / 2.0;
        let y = 4.5 * h;
        let (x0, x1) = (3.0 * d, 9.0 * d);
        let broken: Vec<BrokenBond> = bonds
            .iter()
            .filter(|b| {
                let (ci, cj) = (centres[b.i as usize], centres[b.j as usize]);
                let xm = 0.5 * (ci[0] + cj[0]);
                (ci[1] - y) * (cj[1] - y) < 0.0 && xm > x0 && xm < x1
            })
            .map(|b| BrokenBond {
                time: 0.0,
                i: b.i as usize,
                j: b.j as usize,
                x: 0.5 * (centres[b.i as usize][0] + centres[b.j as usize][0]),
                y,
                mode: crate::bond::BreakMode::Tensile,
            })
            .collect();
        assert_eq!(broken.len(), 12);
        let lining = [broken[0].i];
        let mut x = CrackExtent::new(n, &lining, [0.0, y]).unwrap();
        for b in &broken {
            x.add(b.i, b.j, [b.x, b.y]).unwrap();
        }
        let p = 1.0e6;
        let upper = |loads: &[[f64; 3]]| -> f64 {
            (0..n)
                .filter(|&k| centres[k][1] > y)
                .map(|k| loads[k][1])
                .sum()
        };
        let mut loads = vec![[0.0; 3]; n];
        x.flood_loads_on_faces(&disks, &broken, p, &faces, &mut loads)
            .unwrap();
        // 12 bonds, two per lattice spacing: a crack 6 d long
        let f = upper(&loads);
        assert!((f / (p * 6.0 * d) - 1.0).abs() < 1e-12, "{f}");
        let mut loads = vec![[0.0; 3]; n];
        x.flood_loads(&disks, &broken, p, &mut loads).unwrap();
        let f = upper(&loads);
        assert!((f / (p * 6.0 * d) - 3f64.sqrt()).abs() < 1e-12, "{f}");
    }

    #[test]
    fn bad_arguments_are_named() {
        let e = CrackExtent::new(3, &[3], [0.0, 0.0]).unwrap_err();
        assert!(e.to_string().starts_with("lining = 3"), "{e}");
        let e = CrackExtent::new(3, &[], [0.0, 0.0]).unwrap_err();
        assert!(e.to_string().starts_with("lining"), "{e}");
        let e = CrackExtent::new(3, &[0], [f64::NAN, 0.0]).unwrap_err();
        assert!(e.to_string().starts_with("centre"), "{e}");
        let mut x = CrackExtent::new(3, &[0], [0.0, 0.0]).unwrap();
        let e = x.add(0, 5, [1.0, 0.0]).unwrap_err();
        assert!(e.to_string().starts_with("j = 5"), "{e}");
        let e = x.add(0, 1, [f64::INFINITY, 0.0]).unwrap_err();
        assert!(e.to_string().starts_with("at"), "{e}");
        assert_eq!(x.extent(), 0.0);
    }
}
