//! The force and moment that the disks outside a selection exert on the disks inside it
//! through the intact bonds and the touching contacts that cross its boundary: the
//! reactions of the platens (`wall = "top" | "bottom"` probes `fx fy torque`) and the
//! moment on a tracked cell (`torque` with `cell`).
//!
//! A link between `i` (inside) and `j` (outside) puts the force `F_i` and the moment
//! `M_i` on `i`; about a point `c` the link's moment is `(x_i − c) × F_i + M_i`. The
//! links inside the selection are left out: their forces and moments cancel pairwise
//! (each bond and contact balances its own moment about any point, the bond shear
//! moments being the work-conjugates of the rotations), so the sum is the resultant of
//! the rest of the solid on the selection, by Newton's third law the opposite of what
//! the selection exerts on the rest.

use porofrac_lsm::LatticeSolid;

/// `[F_x, F_y, M]`: force (N/m) and moment about `about` (N·m/m) that the disks with
/// `!inside[k]` exert on the disks with `inside[k]`.
pub fn exerted_on(solid: &LatticeSolid, inside: &[bool], about: [f64; 2]) -> [f64; 3] {
    let x = &solid.disks().x;
    let mut out = [0.0; 3];
    let mut add = |k: usize, f: [f64; 2], m: f64| {
        let r = [x[k][0] - about[0], x[k][1] - about[1]];
        out[0] += f[0];
        out[1] += f[1];
        out[2] += r[0] * f[1] - r[1] * f[0] + m;
    };
    let mut link = |i: usize, j: usize, f: [f64; 2], mi: f64, mj: f64| match (inside[i], inside[j])
    {
        (true, false) => add(i, f, mi),
        (false, true) => add(j, [-f[0], -f[1]], mj),
        _ => {}
    };
    for (b, f) in solid.bonds().iter().zip(solid.bond_forces()) {
        if b.intact {
            link(b.i as usize, b.j as usize, f.f, f.mi, f.mj);
        }
    }
    let (pairs, forces) = solid.contacts();
    for (p, f) in pairs.iter().zip(forces) {
        if f.fn_ > 0.0 {
            link(p.i as usize, p.j as usize, f.f, f.mi, f.mj);
        }
    }
    out
}

/// `[F_x, F_y, M]` of the pressure of wall `w` on the lining disks: force (N/m) and
/// moment about the hole centre (N·m/m).
pub fn wall_load(solid: &LatticeSolid, w: usize) -> [f64; 3] {
    let wall = &solid.walls()[w];
    let x = &solid.disks().x;
    let p = wall.pressure;
    let mut out = [0.0; 3];
    for &(i, a) in &wall.members {
        let r = [
            x[i as usize][0] - wall.centre[0],
            x[i as usize][1] - wall.centre[1],
        ];
        let f = [p * a[0], p * a[1]];
        out[0] += f[0];
        out[1] += f[1];
        out[2] += r[0] * f[1] - r[1] * f[0] + p * a[2];
    }
    out
}

/// The mean of the centres of the disks with `inside[k]` (m).
pub fn centroid(solid: &LatticeSolid, inside: &[bool]) -> [f64; 2] {
    let (mut c, mut n) = ([0.0; 2], 0usize);
    for (p, _) in solid.disks().x.iter().zip(inside).filter(|(_, m)| **m) {
        c[0] += p[0];
        c[1] += p[1];
        n += 1;
    }
    let n = n.max(1) as f64;
    [c[0] / n, c[1] / n]
}
