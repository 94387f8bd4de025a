//! Where the fluid of the borehole reaches before any bond breaks, in the rock of
//! `scenes/lsm_hydrofrac.toml` (b = 22 m, a = 3 m, radii 0.1–1 m, Δx = 0.05 m, disks seen
//! enlarged by 1.05 for the sealed bonds): only through open gaps.
//!
//! Checks, on packing seed 1 rasterised by the lattice itself: every pair of neighbouring
//! fluid nodes the D2Q9 lattice links (straight or diagonal) is joined by a segment that
//! crosses no enlarged disk — no leak across a seal thinner than a spacing — so the
//! lattice's reach from the hole centre is the reach through the gaps between the
//! enlarged disks (the gaps of unbonded pairs); it extends to r = 5.56 m, 2.5 m behind
//! the wall; and with every gap narrowed by one spacing more it still reaches 5.50 m (two
//! spacings: 5.45 m), so those pockets are joined to the hole by throats wider than 2Δx
//! as the fluid sees them (wider still in the rock, by the 5 % seal): open pore space
//! that a fluid fills, resolved by the lattice, not an artefact of the raster. The first
//! break of the fluid runs (r = 6.58 m for seed 1) is in the bond behind such a pocket.

use porofrac_lbm::{Lattice, LatticeConfig, Obstacle, Shape, SideKind};
use porofrac_particles::{Disks, Hole, RandomPacking, Region};

const B: f64 = 22.0;
const A: f64 = 3.0;
const DX: f64 = 0.05;
const HALF: f64 = 22.5;
const SEAL: f64 = 1.05;

fn rock(seed: u64) -> Disks {
    let p = RandomPacking::new([-B, -B], [B, B], 0.1, 1.0, 0.8, seed)
        .generate_in(
            &Region::Disk {
                centre: [0.0; 2],
                radius: B,
            },
            &[Hole {
                centre: [0.0; 2],
                radius: A,
            }],
        )
        .unwrap();
    Disks::new(&p.centres, &p.radii, 2600.0).unwrap()
}

/// Disks near every point: a bucket grid of cell 2 s r_max.
struct Buckets {
    cell: f64,
    n: usize,
    lists: Vec<Vec<usize>>,
}

impl Buckets {
    fn new(d: &Disks) -> Self {
        let cell = 2.0 * SEAL * 1.0 + 0.2;
        let n = (2.0 * HALF / cell).ceil() as usize + 1;
        let mut lists = vec![Vec::new(); n * n];
        let b = Buckets {
            cell,
            n,
            lists: Vec::new(),
        };
        for k in 0..d.len() {
            let (i, j) = (b.index(d.x[k][0]), b.index(d.x[k][1]));
            lists[j * n + i].push(k);
        }
        Buckets { lists, ..b }
    }
    fn index(&self, x: f64) -> usize {
        (((x + HALF) / self.cell).floor().max(0.0) as usize).min(self.n - 1)
    }
    fn near(&self, p: [f64; 2]) -> impl Iterator<Item = usize> + '_ {
        let (i, j) = (self.index(p[0]), self.index(p[1]));
        (j.saturating_sub(1)..=(j + 1).min(self.n - 1)).flat_map(move |jj| {
            (i.saturating_sub(1)..=(i + 1).min(self.n - 1))
                .flat_map(move |ii| self.lists[jj * self.n + ii].iter().copied())
        })
    }
}

/// Whether the segment `p`–`q` enters the circle `(c, r)`.
fn crosses(p: [f64; 2], q: [f64; 2], c: [f64; 2], r: f64) -> bool {
    let e = [q[0] - p[0], q[1] - p[1]];
    let t = (((c[0] - p[0]) * e[0] + (c[1] - p[1]) * e[1]) / (e[0] * e[0] + e[1] * e[1]))
        .clamp(0.0, 1.0);
    let m = [p[0] + t * e[0] - c[0], p[1] + t * e[1] - c[1]];
    m[0] * m[0] + m[1] * m[1] < r * r
}

/// Nodes reached from the centre node through the links between fluid nodes
/// (`solid(i, j)`); with `refuse`, a link is not taken when it returns true. Returns the
/// reached flags and the largest distance reached (m).
fn flood(
    n: usize,
    solid: impl Fn(usize, usize) -> bool,
    refuse: impl Fn([f64; 2], [f64; 2]) -> bool,
) -> (Vec<bool>, f64) {
    let at = |i: usize| -HALF + (i as f64 + 0.5) * DX;
    let mut wet = vec![false; n * n];
    let start = (n / 2) * n + n / 2;
    assert!(!solid(n / 2, n / 2));
    wet[start] = true;
    let mut stack = vec![start];
    let mut r_max = 0.0f64;
    while let Some(c) = stack.pop() {
        let (i, j) = (c % n, c / n);
        r_max = r_max.max(at(i).hypot(at(j)));
        for (di, dj) in (-1isize..=1).flat_map(|a| (-1isize..=1).map(move |b| (a, b))) {
            let (ii, jj) = (i as isize + di, j as isize + dj);
            if ii < 0 || jj < 0 || ii >= n as isize || jj >= n as isize {
                continue;
            }
            let (ii, jj) = (ii as usize, jj as usize);
            let m = jj * n + ii;
            if wet[m] || solid(ii, jj) || refuse([at(i), at(j)], [at(ii), at(jj)]) {
                continue;
            }
            wet[m] = true;
            stack.push(m);
        }
    }
    (wet, r_max)
}

#[test]
fn the_hole_fluid_reaches_the_pockets_behind_the_lining_through_open_gaps_only() {
    let d = rock(1);
    let n = (2.0 * HALF / DX).round() as usize;
    let cfg = LatticeConfig {
        periodic: [false, false],
        sides: [SideKind::Wall; 4],
        ..LatticeConfig::periodic(n, n, 0.6)
    };
    let mut lat = Lattice::new(cfg).unwrap();
    for k in 0..d.len() {
        lat.add_obstacle(Obstacle {
            shape: Shape::Circle {
                center: [(d.x[k][0] + HALF) / DX, (d.x[k][1] + HALF) / DX],
                radius: SEAL * d.r[k] / DX,
            },
            velocity: [0.0; 2],
            angular_velocity: 0.0,
        })
        .unwrap();
    }
    let buckets = Buckets::new(&d);
    // links of the lattice that cross an enlarged disk: how many, and how many cross two
    // (a seal between two disks)
    let crossed = |p: [f64; 2], q: [f64; 2]| {
        buckets
            .near(p)
            .filter(|&k| crosses(p, q, d.x[k], SEAL * d.r[k]))
            .count()
    };
    let (lattice_reach, r_lattice) = flood(n, |i, j| lat.is_solid(i, j), |_, _| false);
    let (mut leaks, mut clips) = (0, 0);
    let at = |i: usize| -HALF + (i as f64 + 0.5) * DX;
    for j in 0..n - 1 {
        for i in 1..n - 1 {
            if !lattice_reach[j * n + i] {
                continue;
            }
            for (ii, jj) in [(i + 1, j), (i - 1, j + 1), (i, j + 1), (i + 1, j + 1)] {
                if lat.is_solid(ii, jj) {
                    continue;
                }
                match crossed([at(i), at(j)], [at(ii), at(jj)]) {
                    0 => {}
                    1 => clips += 1,
                    _ => leaks += 1,
                }
            }
        }
    }
    // the reach through links that cross no enlarged disk
    let (open_reach, r_open) = flood(n, |i, j| lat.is_solid(i, j), |p, q| crossed(p, q) > 0);
    let count = |w: &[bool]| w.iter().filter(|&&x| x).count();
    // the same with every disk one half spacing larger still: gaps narrower than Δx closed
    let r_narrow = |extra: f64| {
        flood(
            n,
            |i, j| {
                let p = [at(i), at(j)];
                buckets.near(p).any(|k| {
                    let r = SEAL * d.r[k] + extra;
                    (p[0] - d.x[k][0]).powi(2) + (p[1] - d.x[k][1]).powi(2) <= r * r
                })
            },
            |_, _| false,
        )
        .1
    };
    let (r_dx, r_2dx) = (r_narrow(0.5 * DX), r_narrow(DX));
    eprintln!(
        "{} disks: lattice reach {} nodes to r = {r_lattice:.2} m; through open gaps {} \
         nodes to r = {r_open:.2} m; links across two enlarged disks {leaks}, clipping one \
         {clips}; gaps narrowed by Δx: r = {r_dx:.2} m, by 2Δx: r = {r_2dx:.2} m",
        d.len(),
        count(&lattice_reach),
        count(&open_reach)
    );
    assert_eq!(leaks, 0, "lattice links across a seal");
    assert!(clips <= 5, "{clips} links clip a disk's rim");
    assert_eq!(open_reach, lattice_reach);
    assert!((5.5..5.65).contains(&r_lattice), "{r_lattice}");
    assert!(r_dx >= 5.5 && r_2dx >= 5.4, "{r_dx} {r_2dx}");
}
