//! Pressure on the wall of a circular hole (a borehole), as forces and moments on the
//! particles that line it.
//!
//! **Faces seen from the centre** ([`WallFaces::Rays`], the default). The hole of centre
//! `c` and radius `a` is swept by `N = 3600` equally spaced rays from `c`; each ray of
//! direction `e_k` meets a first disk among those whose near side lies within
//! `a + 2 r_max` of `c`. The pressure on the arc `a Δφ` of the hole's circle, `Δφ = 2π/N`,
//! pushes along the ray: the disk receives the force `p a Δφ e_k` and, the line of action
//! passing through `c` and not through the disk's centre `x_i`, the moment
//! `(c − x_i) × p a Δφ e_k` (the lsm solid integrates spins). A ray that meets no disk
//! (it passes between the lining disks) gives half its arc to the disk met by the
//! nearest ray before it and half to the one after it, along its own line of action.
//! The arcs of all rays close the circle: the forces sum to `p a Δφ Σ_k e_k = 0` and
//! every line of action passes through `c`, so the loads have neither net force nor net
//! torque (about `c`, and so about any point), to round-off, on any packing and hole
//! position. A disk seen over the angles `±β` about its own direction receives
//! `p · 2a sin β` outwards (the hoop load of the smooth hole of radius `a`), so the
//! tangential stress at the wall is `σ_θθ(a) = p (b² + a²)/(b² − a²)` for a disk of outer
//! radius b (the closed-form breakdown check). The loads are taken once, in the reference
//! configuration (small strains).
//!
//! **Wetted faces** ([`WallFaces::Wetted`]). A fluid filling the hole does not stop at the
//! faces seen from the centre: it enters every notch between the lining disks and every
//! pocket of the pore space reached through gaps wider than its resolution, and there it
//! pushes the disks sideways as well (wedging). This variant loads exactly those faces.
//! The plane is rasterised in square cells of side `h`; a cell is solid when its centre
//! lies within `s R_i` of a disk centre (`s ≥ 1` enlarges the disks as a fluid with sealed
//! bonds sees them, so the gap of a bonded pair holds no fluid); the cells connected to
//! the hole centre through cells that share a side or a corner (the reach of a D2Q9
//! lattice of spacing `h`) are wet. On the circle of radius `s R_i` of every disk,
//! `M = 720` points at angles `θ_m` each carry the arc `s R_i Δθ`; a point is wet when a
//! wet cell touches its cell and no other enlarged disk contains it (the raster decides
//! what is connected, the circles where the seals are), and the disk receives
//! `−p s R_i Δθ Σ_wet n_m` (`n_m` the outward normal): the pressure integral over its
//! wetted arc, which is `p` times the chord between the arc's ends, normal to it, and
//! has no moment about the centre. A disk wet all round receives nothing; a disk wet
//! on one half receives `p · 2 s R`. If the wet cells reach the edge of the raster (the
//! pore space of the hole leaks out of the packing) the wall is refused.

use crate::LsmError;
use porofrac_particles::Disks;

/// Rays per wall.
const RAYS: usize = 3600;

/// Which faces of the particles lining a hole the hole pressure loads (see the module
/// docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum WallFaces {
    /// The faces seen from the hole centre (3600 rays; a ray passing between the disks
    /// loads its two neighbours).
    #[default]
    Rays,
    /// The faces a fluid filling the hole wets, notches and connected pockets included.
    Wetted {
        /// Raster cell side `h` (m), e.g. the lattice spacing of the fluid.
        spacing: f64,
        /// Radius factor `s ≥ 1` of the disks as the fluid sees them (1 + bond tolerance
        /// for sealed bonds).
        seal: f64,
    },
}

/// Sample points per disk circle of the wetted faces.
const ARC_POINTS: usize = 720;
/// Raster cell of no disk, not (yet) reached from the hole.
const OPEN: u32 = u32::MAX;
/// Raster cell reached from the hole.
const WET: u32 = u32::MAX - 1;

/// The particles lining a hole and the pressure on them.
#[derive(Clone, Debug, PartialEq)]
pub struct PressureWall {
    /// Centre of the hole (m).
    pub centre: [f64; 2],
    /// Radius of the hole (m).
    pub radius: f64,
    /// Each lining particle and its load per unit pressure `[f_x, f_y, m]` (m, m²): the
    /// force and the moment about the particle's centre.
    pub members: Vec<(u32, [f64; 3])>,
    /// Pressure (Pa).
    pub pressure: f64,
}

impl PressureWall {
    /// The wall of the hole of `centre` and `radius` in the configuration of `disks`,
    /// loading the faces seen from the centre ([`WallFaces::Rays`]).
    pub fn new(disks: &Disks, centre: [f64; 2], radius: f64) -> Result<Self, LsmError> {
        Self::with_faces(disks, centre, radius, WallFaces::Rays)
    }

    /// The wall of the hole of `centre` and `radius` loading `faces`.
    pub fn with_faces(
        disks: &Disks,
        centre: [f64; 2],
        radius: f64,
        faces: WallFaces,
    ) -> Result<Self, LsmError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(LsmError::bad("hole radius", radius, "must be positive"));
        }
        let load = match faces {
            WallFaces::Rays => ray_loads(disks, centre, radius)?,
            WallFaces::Wetted { spacing, seal } => wetted_loads(disks, centre, spacing, seal)?,
        };
        let members = load
            .iter()
            .enumerate()
            .filter(|(_, l)| l.iter().any(|&v| v != 0.0))
            .map(|(i, l)| (i as u32, *l))
            .collect();
        Ok(Self {
            centre,
            radius,
            members,
            pressure: 0.0,
        })
    }
}

/// Load per unit pressure `[f_x, f_y, m]` of every disk from the rays (see the module
/// docs).
fn ray_loads(disks: &Disks, centre: [f64; 2], radius: f64) -> Result<Vec<[f64; 3]>, LsmError> {
    let n = disks.len();
    let dphi = std::f64::consts::TAU / RAYS as f64;
    // Candidates: disks whose near side is within the largest diameter of the hole.
    let rmax = disks.radius_range()[1];
    let near: Vec<usize> = (0..n)
        .filter(|&i| {
            let d = crate::bond::dist(disks.x[i], centre);
            d - disks.r[i] < radius + 2.0 * rmax
        })
        .collect();
    let dir = |k: usize| {
        let phi = (k as f64 + 0.5) * dphi;
        [phi.cos(), phi.sin()]
    };
    let hits: Vec<Option<usize>> = (0..RAYS)
        .map(|k| first_hit(disks, &near, centre, dir(k)))
        .collect();
    let Some(last) = hits.iter().rev().find_map(|h| *h) else {
        return Err(LsmError::bad(
            "hole radius",
            radius,
            "no particle lines the hole",
        ));
    };
    // The disks met before and after each ray (cyclically), for the rays that meet none.
    let mut before = vec![last; RAYS];
    let mut prev = last;
    for k in 0..RAYS {
        prev = hits[k].unwrap_or(prev);
        before[k] = prev;
    }
    let first = hits.iter().find_map(|h| *h).unwrap_or(last);
    let mut after = vec![first; RAYS];
    let mut next = first;
    for k in (0..RAYS).rev() {
        next = hits[k].unwrap_or(next);
        after[k] = next;
    }
    // The arc `a Δφ` of each ray pushes along the ray: the force `a Δφ e_k` and its
    // moment about the disk's centre, the line of action passing through the hole centre.
    let mut load = vec![[0.0f64; 3]; n];
    let mut push = |i: usize, share: f64, e: [f64; 2]| {
        let f = [share * radius * dphi * e[0], share * radius * dphi * e[1]];
        let q = [disks.x[i][0] - centre[0], disks.x[i][1] - centre[1]];
        let l = &mut load[i];
        l[0] += f[0];
        l[1] += f[1];
        l[2] -= q[0] * f[1] - q[1] * f[0];
    };
    for (k, hit) in hits.iter().enumerate() {
        match hit {
            Some(i) => push(*i, 1.0, dir(k)),
            None => {
                push(before[k], 0.5, dir(k));
                push(after[k], 0.5, dir(k));
            }
        }
    }
    Ok(load)
}

/// The first of the disks `near` that the ray from `centre` in the unit direction `e`
/// meets.
fn first_hit(disks: &Disks, near: &[usize], centre: [f64; 2], e: [f64; 2]) -> Option<usize> {
    let mut best: Option<(f64, usize)> = None;
    for &i in near {
        let q = [disks.x[i][0] - centre[0], disks.x[i][1] - centre[1]];
        let along = q[0] * e[0] + q[1] * e[1];
        let perp2 = q[0] * q[0] + q[1] * q[1] - along * along;
        let r2 = disks.r[i] * disks.r[i];
        if along > 0.0 && perp2 < r2 {
            let s = along - (r2 - perp2).sqrt();
            if best.is_none_or(|(b, _)| s < b) {
                best = Some((s, i));
            }
        }
    }
    best.map(|(_, i)| i)
}

/// Load per unit pressure `[f_x, f_y, 0]` of every disk on its wetted faces (see the
/// module docs).
fn wetted_loads(
    disks: &Disks,
    centre: [f64; 2],
    h: f64,
    seal: f64,
) -> Result<Vec<[f64; 3]>, LsmError> {
    if !(h.is_finite() && h > 0.0) {
        return Err(LsmError::bad("wall spacing", h, "must be positive"));
    }
    if !(seal.is_finite() && (1.0..=2.0).contains(&seal)) {
        return Err(LsmError::bad("wall seal", seal, "must be in [1, 2]"));
    }
    let n = disks.len();
    // The raster: the disks' bounding box and the centre, with two cells of margin.
    let (mut lo, mut hi) = (centre, centre);
    for i in 0..n {
        let r = seal * disks.r[i];
        for a in 0..2 {
            lo[a] = lo[a].min(disks.x[i][a] - r);
            hi[a] = hi[a].max(disks.x[i][a] + r);
        }
    }
    let cells = |a: usize| (((hi[a] - lo[a]) / h).ceil() as usize).saturating_add(4);
    let (nx, ny) = (cells(0), cells(1));
    if nx.saturating_mul(ny) > 1 << 28 {
        return Err(LsmError::bad(
            "wall spacing",
            h,
            "gives more than 2^28 raster cells",
        ));
    }
    let origin = [lo[0] - 2.0 * h, lo[1] - 2.0 * h];
    let cell_of = |p: [f64; 2]| -> Option<usize> {
        let (i, j) = ((p[0] - origin[0]) / h, (p[1] - origin[1]) / h);
        let inside = i >= 0.0 && j >= 0.0 && (i as usize) < nx && (j as usize) < ny;
        inside.then(|| j as usize * nx + i as usize)
    };
    // Per cell: the disk covering it, OPEN or WET.
    let mut state = vec![OPEN; nx * ny];
    for i in 0..n {
        let (c, r) = (disks.x[i], seal * disks.r[i]);
        let i0 = (((c[0] - r - origin[0]) / h).floor().max(0.0)) as usize;
        let i1 = (((c[0] + r - origin[0]) / h).ceil() as usize).min(nx - 1);
        let j0 = (((c[1] - r - origin[1]) / h).floor().max(0.0)) as usize;
        let j1 = (((c[1] + r - origin[1]) / h).ceil() as usize).min(ny - 1);
        for j in j0..=j1 {
            for k in i0..=i1 {
                let p = [
                    origin[0] + (k as f64 + 0.5) * h - c[0],
                    origin[1] + (j as f64 + 0.5) * h - c[1],
                ];
                if p[0] * p[0] + p[1] * p[1] <= r * r {
                    state[j * nx + k] = i as u32;
                }
            }
        }
    }
    let start = cell_of(centre).expect("the centre lies in the raster");
    if state[start] != OPEN {
        return Err(LsmError::bad(
            "hole centre x",
            centre[0],
            "lies inside a particle",
        ));
    }
    state[start] = WET;
    let mut stack = vec![start];
    while let Some(c) = stack.pop() {
        let (i, j) = (c % nx, c / nx);
        if i == 0 || j == 0 || i + 1 == nx || j + 1 == ny {
            return Err(LsmError::bad(
                "wall spacing",
                h,
                "the space connected to the hole reaches the outside of the packing",
            ));
        }
        for dj in [-1isize, 0, 1] {
            for di in [-1isize, 0, 1] {
                let m = ((j as isize + dj) as usize) * nx + (i as isize + di) as usize;
                if state[m] == OPEN {
                    state[m] = WET;
                    stack.push(m);
                }
            }
        }
    }
    // A surface point is wet when a wet cell touches its cell and no other (enlarged)
    // disk contains it: the raster decides what is connected, the circles where the
    // seals are.
    let dth = std::f64::consts::TAU / ARC_POINTS as f64;
    let wet_at = |i: usize, q: [f64; 2]| -> bool {
        let (ci, cj) = (
            ((q[0] - origin[0]) / h).floor() as isize,
            ((q[1] - origin[1]) / h).floor() as isize,
        );
        let mut wet = false;
        for dj in -2isize..=2 {
            for di in -2isize..=2 {
                let (a, b) = (ci + di, cj + dj);
                if a < 0 || b < 0 || a >= nx as isize || b >= ny as isize {
                    continue;
                }
                let o = state[b as usize * nx + a as usize];
                if o == WET {
                    wet |= di.abs() <= 1 && dj.abs() <= 1;
                } else if o != OPEN && o as usize != i {
                    let (x, r) = (disks.x[o as usize], seal * disks.r[o as usize]);
                    if (q[0] - x[0]).powi(2) + (q[1] - x[1]).powi(2) < r * r {
                        return false;
                    }
                }
            }
        }
        wet
    };
    let load = (0..n)
        .map(|i| {
            let (c, r) = (disks.x[i], seal * disks.r[i]);
            let mut l = [0.0; 3];
            for m in 0..ARC_POINTS {
                let th = (m as f64 + 0.5) * dth;
                let e = [th.cos(), th.sin()];
                if wet_at(i, [c[0] + r * e[0], c[1] + r * e[1]]) {
                    l[0] -= r * dth * e[0];
                    l[1] -= r * dth * e[1];
                }
            }
            l
        })
        .collect();
    Ok(load)
}
