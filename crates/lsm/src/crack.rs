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
//! later, higher breakdown. Sharing a disk also joins too much: microcracks that touch
//! the lining disks, or touch each other at a disk without opening a common gap, count
//! as the wall's crack. [`CrackExtent::across_pores`] traces the crack the way a fluid
//! would follow it instead (next section).
//!
//! **Across pores: the faces of the bond network.** With the disk centres as vertices
//! and the bonds as straight edges, the bond network of a packing is a plane graph (no
//! two bonds cross: `tests/bond_faces.rs` checks the borehole scenes' packings, seeds
//! 1–5); its faces are the pores — bonded triangles, pores of four or more disks, the
//! hole, the outside. They are traced from the rotation system: the bonded neighbours of
//! every disk sorted by angle, the face left of the half-edge `u → v` continued at `v`
//! by the neighbour just clockwise of `u`. Every bond separates two faces (one face on
//! both sides for a bond that hangs free). A broken bond *opens* its two faces into one
//! gap: the crack is the connected component of faces joined by broken bonds, i.e. two
//! broken bonds are one crack when a chain of broken bonds joins them in which each
//! consecutive pair bounds a common face. The crack connected to the hole is the
//! component of the face that holds the hole centre (the bounded face of smallest area
//! whose boundary winds around it; the lining disks of [`CrackExtent::new`] no longer
//! enter), its extent as above over its broken bonds. A pressure in the hole can cross
//! an opened pore from one broken bond to another; it cannot cross from one broken bond
//! to another that only touches the same disk, so those stay two cracks. The faces are
//! traced once, in the reference configuration (bonds do not form during a run).
//! It matters: a pressurised
//! notch of half-length 3 m in the packing of the borehole scenes (radii 0.1–1 m) runs at
//! 6.62 MPa traced through faces (103 broken bonds) and at 8.97 MPa joined through shared
//! disks, after 268 broken bonds of diffuse damage around a crack that its own pressure
//! does not reach across the pores (`crates/lsm/tests/notch_toughness.rs`). Broken bonds in
//! the rock that are not connected to the hole (isolated microcracks, or cracks in
//! fluid-filled pockets behind the lining that have not yet joined the wall) do not
//! count.
//!
//! The extent never decreases (bonds do not heal), and is computed incrementally with a
//! disjoint-set forest over the disks (or the faces) (union by size, path halving):
//! `O(α(n))` per broken bond, plus a binary search for the bond's faces.
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

/// The faces of the planar bond network (module docs, "Across pores"): every bond's two
/// sides, and the face that holds the hole.
#[derive(Clone, Debug, PartialEq)]
struct BondFaces {
    /// `(i, j)` of every bond, `i < j`, sorted, without repeats.
    pairs: Vec<(u32, u32)>,
    /// The face left of `i → j` and the face left of `j → i`, per pair.
    sides: Vec<[u32; 2]>,
    /// Number of faces.
    count: usize,
}

impl BondFaces {
    /// Trace the faces of the bonds `pairs` between the disks of `disks` (module docs);
    /// returns them and the bounded face that holds `centre` (the smallest when pores
    /// nest), `None` when no bounded face does.
    fn trace(disks: &Disks, pairs: &[(u32, u32)], centre: [f64; 2]) -> (Self, Option<usize>) {
        let n = disks.len();
        let mut start = vec![0usize; n + 1];
        for &(i, j) in pairs {
            start[i as usize + 1] += 1;
            start[j as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut around = vec![0u32; start[n]];
        let mut next: Vec<usize> = start[..n].to_vec();
        for &(i, j) in pairs {
            for (u, v) in [(i, j), (j, i)] {
                around[next[u as usize]] = v;
                next[u as usize] += 1;
            }
        }
        for u in 0..n {
            let x = disks.x[u];
            let angle = |v: &u32| {
                let y = disks.x[*v as usize];
                (y[1] - x[1]).atan2(y[0] - x[0])
            };
            around[start[u]..start[u + 1]].sort_by(|a, b| angle(a).total_cmp(&angle(b)));
        }
        // half-edge u → around[s] is slot s; the slot of v → u among v's neighbours
        let slot = |v: usize, u: u32| {
            start[v]
                + around[start[v]..start[v + 1]]
                    .iter()
                    .position(|&w| w == u)
                    .expect("every bond is listed at both ends")
        };
        let mut owner = vec![u32::MAX; around.len()];
        let mut count = 0usize;
        let mut hole: Option<(usize, f64)> = None;
        for first in 0..n {
            for s0 in start[first]..start[first + 1] {
                if owner[s0] != u32::MAX {
                    continue;
                }
                // walk the face left of the half-edge s0: at v, arriving from u, leave by
                // the neighbour of v just clockwise of u
                let (mut u, mut s) = (first, s0);
                let (mut area, mut winding) = (0.0, 0i32);
                loop {
                    owner[s] = count as u32;
                    let v = around[s] as usize;
                    let (a, b) = (disks.x[u], disks.x[v]);
                    area += 0.5 * (a[0] * b[1] - b[0] * a[1]);
                    winding += crossing(a, b, centre);
                    let k = slot(v, u as u32);
                    let s_next = if k == start[v] {
                        start[v + 1] - 1
                    } else {
                        k - 1
                    };
                    (u, s) = (v, s_next);
                    if s == s0 {
                        break;
                    }
                }
                if area > 0.0 && winding != 0 && hole.is_none_or(|(_, a)| area < a) {
                    hole = Some((count, area));
                }
                count += 1;
            }
        }
        let sides = pairs
            .iter()
            .map(|&(i, j)| [owner[slot(i as usize, j)], owner[slot(j as usize, i)]])
            .collect();
        let faces = Self {
            pairs: pairs.to_vec(),
            sides,
            count,
        };
        (faces, hole.map(|h| h.0))
    }

    /// The two faces of the bond `i`–`j`, if it is one.
    fn of(&self, i: usize, j: usize) -> Option<[u32; 2]> {
        let key = (i.min(j) as u32, i.max(j) as u32);
        self.pairs.binary_search(&key).ok().map(|k| self.sides[k])
    }
}

/// The signed crossing of the segment `a → b` with the ray from `c` towards +x: `+1`
/// upwards, `−1` downwards, `0` if it misses (the winding number is their sum).
fn crossing(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i32 {
    let side = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if a[1] <= c[1] && b[1] > c[1] && side > 0.0 {
        1
    } else if a[1] > c[1] && b[1] <= c[1] && side < 0.0 {
        -1
    } else {
        0
    }
}

/// The crack connected to a hole wall, grown one broken bond at a time (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct CrackExtent {
    centre: [f64; 2],
    /// Number of disks.
    disks: usize,
    /// With [`Self::across_pores`]: the faces of the bond network; the nodes of the
    /// forest are then the faces, else the disks and the hole.
    faces: Option<BondFaces>,
    /// The node of the hole: index `disks`, or the face that holds the hole.
    hole: usize,
    /// Parent of every node.
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
            disks,
            faces: None,
            hole: disks,
            parent: Vec::new(),
            size: Vec::new(),
            reach: Vec::new(),
        };
        s.reset(disks + 1);
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

    /// A forest of `nodes` single-node trees.
    fn reset(&mut self, nodes: usize) {
        self.parent = (0..nodes as u32).collect();
        self.size = vec![1; nodes];
        self.reach = vec![0.0; nodes];
    }

    /// Join cracks through the faces of the bond network (module docs, "Across pores"):
    /// the faces of `bonds` (intact or broken, every bond the packing had) between the
    /// disks of `disks`, traced in their configuration; the hole is the bounded face that
    /// holds the centre; a broken bond joins the two faces it separates, and the crack
    /// connected to the hole is the set of broken bonds whose faces are joined to the
    /// hole's. Replaces the lining of [`Self::new`]. Call before [`Self::add`]. Errors
    /// when `disks` is not the packing of [`Self::new`], a bond names a disk it does not
    /// have or joins a disk to itself, or no pore of the network holds the centre.
    pub fn across_pores(mut self, disks: &Disks, bonds: &[Bond]) -> Result<Self, LsmError> {
        let n = self.disks;
        if disks.len() != n {
            return Err(LsmError::bad(
                "disks",
                disks.len() as f64,
                "is not the hole's packing",
            ));
        }
        let mut pairs = Vec::with_capacity(bonds.len());
        for b in bonds {
            if b.i as usize >= n || b.j as usize >= n {
                return Err(LsmError::bad(
                    "bonds",
                    b.i.max(b.j) as f64,
                    "is not the index of a disk",
                ));
            }
            if b.i == b.j {
                return Err(LsmError::bad("bonds", b.i as f64, "joins a disk to itself"));
            }
            pairs.push((b.i.min(b.j), b.i.max(b.j)));
        }
        pairs.sort_unstable();
        pairs.dedup();
        let (faces, hole) = BondFaces::trace(disks, &pairs, self.centre);
        let hole = hole.ok_or(LsmError::bad(
            "centre",
            self.centre[0],
            "lies in no pore of the bond network",
        ))?;
        self.reset(faces.count);
        self.hole = hole;
        self.faces = Some(faces);
        Ok(self)
    }

    /// The two nodes the broken bond `i`–`j` joins.
    fn ends(&self, i: usize, j: usize) -> Result<(usize, usize), LsmError> {
        match &self.faces {
            None => Ok((i, j)),
            Some(f) => f
                .of(i, j)
                .map(|s| (s[0] as usize, s[1] as usize))
                .ok_or(LsmError::bad(
                    "j",
                    j as f64,
                    "is not bonded to i in the bond network",
                )),
        }
    }

    /// Record the broken bond between disks `i` and `j` that broke at `at` (m); returns
    /// the extent of the crack connected to the hole afterwards.
    pub fn add(&mut self, i: usize, j: usize, at: [f64; 2]) -> Result<f64, LsmError> {
        for (name, k) in [("i", i), ("j", j)] {
            if k >= self.disks {
                return Err(LsmError::bad(name, k as f64, "is not the index of a disk"));
            }
        }
        if !(at[0].is_finite() && at[1].is_finite()) {
            return Err(LsmError::bad("at", f64::NAN, "must be finite"));
        }
        let d = (at[0] - self.centre[0]).hypot(at[1] - self.centre[1]);
        let (u, v) = self.ends(i, j)?;
        let r = self.union(u, v);
        self.reach[r] = self.reach[r].max(d);
        Ok(self.extent())
    }

    /// The extent `r_c` of the crack connected to the hole (m from the centre), `0` while
    /// no broken bond is connected to it.
    pub fn extent(&self) -> f64 {
        let mut k = self.hole;
        while self.parent[k] as usize != k {
            k = self.parent[k] as usize;
        }
        self.reach[k]
    }

    /// The bonds `(i, j)`, `i < j`, that bound the pore holding the hole (with
    /// [`Self::across_pores`]; empty otherwise).
    pub fn hole_pore(&self) -> Vec<(usize, usize)> {
        let Some(f) = &self.faces else {
            return Vec::new();
        };
        f.pairs
            .iter()
            .zip(&f.sides)
            .filter(|(_, s)| s.iter().any(|&k| k as usize == self.hole))
            .map(|(&(i, j), _)| (i as usize, j as usize))
            .collect()
    }

    /// Whether the broken bond between disks `i` and `j` belongs to the crack connected
    /// to the hole (false for a pair that is not a bond of [`Self::across_pores`]).
    pub fn on_crack(&mut self, i: usize, j: usize) -> bool {
        if i >= self.disks || j >= self.disks {
            return false;
        }
        let Ok((u, v)) = self.ends(i, j) else {
            return false;
        };
        let hole = self.find(self.hole);
        self.find(u) == hole && self.find(v) == hole
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
        let n = self.disks;
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
        let mut flooded = 0;
        for b in broken {
            if b.i >= n || b.j >= n {
                return Err(LsmError::bad(
                    "broken",
                    b.i.max(b.j) as f64,
                    "is not the index of a disk",
                ));
            }
            if !self.on_crack(b.i, b.j) {
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
        assert!(!x.on_crack(4, 5));
        // the link 3–4 joins the chain 4–5 to the crack
        assert!((x.add(3, 4, at(5.5)).unwrap() - 6.5).abs() < 1e-12);
        assert!(x.on_crack(4, 5) && !x.on_crack(6, 7));
        // a nearer break does not lower the extent
        assert!((x.add(0, 2, at(3.2)).unwrap() - 6.5).abs() < 1e-12);
        // joining the isolated pair brings its reach in
        assert!((x.add(5, 6, at(7.0)).unwrap() - 9.0).abs() < 1e-12);
        assert!(x.on_crack(6, 7));
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

    /// A hexagonal lattice of spacing 1 around a hole of radius 1.5 at the origin (the
    /// centre and its six neighbours removed; the hole is lined by a ring of twelve
    /// disks), bonded between touching disks except the pairs `unbonded`; returns the
    /// disks, bonds, the index of the disk at a point, and the lining.
    fn holed_lattice(unbonded: &[([f64; 2], [f64; 2])]) -> (Disks, Vec<Bond>, Vec<usize>) {
        use crate::law::BondLaw;
        let h = 3f64.sqrt() / 2.0;
        let mut centres = Vec::new();
        for row in -8i32..=8 {
            for col in -9i32..=9 {
                let x = [
                    col as f64 + 0.5 * (row.rem_euclid(2)) as f64,
                    row as f64 * h,
                ];
                if x[0].hypot(x[1]) > 1.5 {
                    centres.push(x);
                }
            }
        }
        let n = centres.len();
        let disks = Disks::new(&centres, &vec![0.5; n], 2600.0).unwrap();
        let law = BondLaw::elastic(1e9, 1e9, 0.0);
        let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < 1e-9;
        let mut bonds = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (centres[i], centres[j]);
                let skip = unbonded
                    .iter()
                    .any(|&(p, q)| (near(a, p) && near(b, q)) || (near(a, q) && near(b, p)));
                if (a[0] - b[0]).hypot(a[1] - b[1]) < 1.01 && !skip {
                    bonds.push(Bond::new(&disks, i, j, &law));
                }
            }
        }
        let lining = (0..n)
            .filter(|&k| centres[k][0].hypot(centres[k][1]) < 2.01)
            .collect();
        (disks, bonds, lining)
    }

    /// The disk of `disks` at `x`.
    fn at(disks: &Disks, x: [f64; 2]) -> usize {
        (0..disks.len())
            .find(|&k| (disks.x[k][0] - x[0]).hypot(disks.x[k][1] - x[1]) < 1e-9)
            .unwrap()
    }

    /// Break the bond between the disks at `p` and `q` (at its midpoint); the extent.
    fn split(x: &mut CrackExtent, disks: &Disks, p: [f64; 2], q: [f64; 2]) -> f64 {
        let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
        x.add(at(disks, p), at(disks, q), mid).unwrap()
    }

    const H: f64 = 0.866_025_403_784_438_6;

    /// Euler's formula for the traced faces of the planar bond network of the holed
    /// lattice: V − E + F = 2 (one component), the hole is one face of twelve sides.
    #[test]
    fn the_faces_of_a_holed_lattice_satisfy_euler() {
        let (disks, bonds, lining) = holed_lattice(&[]);
        assert_eq!(lining.len(), 12);
        let x = CrackExtent::new(disks.len(), &lining, [0.0; 2])
            .unwrap()
            .across_pores(&disks, &bonds)
            .unwrap();
        let f = x.faces.as_ref().unwrap();
        let (v, e) = (disks.len() as i64, bonds.len() as i64);
        assert_eq!(v - e + f.count as i64, 2, "V {v}, E {e}, F {}", f.count);
        let hole_sides = f
            .sides
            .iter()
            .flatten()
            .filter(|&&s| s as usize == x.hole)
            .count();
        assert_eq!(hole_sides, 12);
    }

    /// A crack from the wall crosses a pore of four disks (the hole's lining disk L0 at
    /// (2, 0) not bonded to P at (2.5, h)): the wall bond L0–L1 and the bond P–R on the
    /// far side of the pore share no disk but open the same face, so they are one crack;
    /// a broken bond that touches the pore's disk R without bounding the pore is not
    /// joined. Through shared disks alone the far bond is cut off.
    #[test]
    fn a_crack_across_a_four_disk_pore_is_one_crack() {
        let (l0, l1, p, r, r2) = ([2.0, 0.0], [1.5, H], [2.5, H], [3.0, 0.0], [4.0, 0.0]);
        let (disks, bonds, lining) = holed_lattice(&[(l0, p)]);
        let wall = 1.75f64.hypot(0.5 * H);
        let far = 2.75f64.hypot(0.5 * H);
        for faces in [true, false] {
            let mut x = CrackExtent::new(disks.len(), &lining, [0.0; 2]).unwrap();
            if faces {
                x = x.across_pores(&disks, &bonds).unwrap();
            }
            // a microcrack touching R, outside the pore
            assert_eq!(split(&mut x, &disks, r, r2), 0.0);
            assert!((split(&mut x, &disks, l0, l1) - wall).abs() < 1e-12);
            let e = split(&mut x, &disks, p, r);
            if faces {
                assert!((e - far).abs() < 1e-12, "{e}");
                assert!(x.on_crack(at(&disks, p), at(&disks, r)));
            } else {
                assert!((e - wall).abs() < 1e-12, "{e}");
                assert!(!x.on_crack(at(&disks, p), at(&disks, r)));
            }
            assert!(!x.on_crack(at(&disks, r), at(&disks, r2)));
        }
    }

    /// Two cracks that share a disk but no face stay two cracks; they join when a broken
    /// bond opens a face of each. Crack 1: the wall bond L0–L1 and L0–P (both bound the
    /// triangle L0-L1-P). Crack 2: P–Q, Q = (3.5, h), which touches P but bounds only
    /// the triangles P-Q-R and P-Q-(3, 2h). The bond P–R bounds L0-P-R (opened by
    /// crack 1) and P-Q-R (opened by crack 2): breaking it joins them.
    #[test]
    fn cracks_that_share_a_disk_but_no_face_are_not_joined() {
        let (l0, l1, p, q, r) = ([2.0, 0.0], [1.5, H], [2.5, H], [3.5, H], [3.0, 0.0]);
        let (disks, bonds, lining) = holed_lattice(&[]);
        let mut x = CrackExtent::new(disks.len(), &lining, [0.0; 2])
            .unwrap()
            .across_pores(&disks, &bonds)
            .unwrap();
        let wall = 1.75f64.hypot(0.5 * H);
        assert!((split(&mut x, &disks, l0, l1) - wall).abs() < 1e-12);
        let mouth = 2.25f64.hypot(0.5 * H);
        assert!((split(&mut x, &disks, l0, p) - mouth).abs() < 1e-12);
        assert!((split(&mut x, &disks, p, q) - mouth).abs() < 1e-12);
        assert!(x.on_crack(at(&disks, l0), at(&disks, p)));
        assert!(!x.on_crack(at(&disks, p), at(&disks, q)));
        let e = split(&mut x, &disks, p, r);
        assert!((e - 3.0f64.hypot(H)).abs() < 1e-12, "{e}");
        assert!(x.on_crack(at(&disks, p), at(&disks, q)));
        // a pair that is not a bond of the network is an error, not a crack
        let e = x.add(at(&disks, l0), at(&disks, q), [0.0; 2]).unwrap_err();
        assert!(e.to_string().starts_with("j = "), "{e}");
    }

    /// The dry wall's first break does not reach 2a: microcracks run radially out from
    /// the lining disk L0 at (2, 0) to (5, 0) (each shares a disk with the next, none a
    /// face), then the wall bond L0–L1 breaks. Through faces the crack is that one bond,
    /// 1.80 from the centre (2a = 3); through shared disks the microcracks are already
    /// the wall's crack, 4.5 from the centre.
    #[test]
    fn the_dry_walls_first_break_does_not_reach_2a() {
        let (disks, bonds, lining) = holed_lattice(&[]);
        let two_a = 3.0;
        for faces in [true, false] {
            let mut x = CrackExtent::new(disks.len(), &lining, [0.0; 2]).unwrap();
            if faces {
                x = x.across_pores(&disks, &bonds).unwrap();
            }
            let mut e = 0.0;
            for k in 2..5 {
                e = split(&mut x, &disks, [k as f64, 0.0], [k as f64 + 1.0, 0.0]);
            }
            assert_eq!(e, if faces { 0.0 } else { 4.5 });
            let first = split(&mut x, &disks, [2.0, 0.0], [1.5, H]);
            if faces {
                assert!((first - 1.75f64.hypot(0.5 * H)).abs() < 1e-12 && first < two_a);
            } else {
                assert!(first >= two_a, "{first}");
            }
        }
    }

    /// The centre must lie in a pore of the network.
    #[test]
    fn a_hole_outside_the_network_is_refused() {
        let (disks, bonds, lining) = holed_lattice(&[]);
        let e = CrackExtent::new(disks.len(), &lining, [40.0, 0.0])
            .unwrap()
            .across_pores(&disks, &bonds)
            .unwrap_err();
        assert!(e.to_string().starts_with("centre = 40"), "{e}");
        let e = CrackExtent::new(5, &[0], [0.0; 2])
            .unwrap()
            .across_pores(&disks, &bonds)
            .unwrap_err();
        assert!(e.to_string().starts_with("disks = "), "{e}");
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
