//! The bond network of the borehole scenes' rock is a plane graph, so its faces (the
//! pores) are well defined for the crack rule of [`porofrac_lsm::CrackExtent::across_pores`]:
//! on the packings of `scenes/lsm/borehole_flooded.toml` (radii 0.1–1 m, packing fraction
//! 0.8, a disk of radius 22 m and one of 12 m, a hole of radius 3 m at the centre, bond
//! tolerance 5 %), seeds 1–5, no two bonds cross (the segments between bonded centres
//! meet only at shared disks), and the hole's centre lies in one pore of the network.

use porofrac_lsm::calibrate::scene_rock;
use porofrac_lsm::{CrackExtent, LatticeSolid, PressureWall};
use porofrac_particles::{Disks, Hole, RandomPacking, Region};

/// Whether the open segments `a–b` and `c–d` cross (a shared end point is not a crossing).
fn cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let orient = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    o1 * o2 < 0.0 && o3 * o4 < 0.0
}

#[test]
fn the_scene_rocks_bond_network_is_planar() {
    for b in [22.0, 12.0] {
        for seed in 1..=5u64 {
            let p = RandomPacking::new([-b; 2], [b; 2], 0.1, 1.0, 0.8, seed)
                .generate_in(
                    &Region::Disk {
                        centre: [0.0; 2],
                        radius: b,
                    },
                    &[Hole {
                        centre: [0.0; 2],
                        radius: 3.0,
                    }],
                )
                .unwrap();
            let disks = Disks::new(&p.centres, &p.radii, 2600.0).unwrap();
            let solid = LatticeSolid::new(disks, scene_rock(0.2).unwrap()).unwrap();
            let (d, bonds) = (solid.disks(), solid.bonds());
            let mut crossings = 0;
            for (k, p) in bonds.iter().enumerate() {
                let (a, b2) = (d.x[p.i as usize], d.x[p.j as usize]);
                for q in &bonds[k + 1..] {
                    if [q.i, q.j].iter().any(|&v| v == p.i || v == p.j) {
                        continue;
                    }
                    if cross(a, b2, d.x[q.i as usize], d.x[q.j as usize]) {
                        crossings += 1;
                    }
                }
            }
            assert_eq!(
                crossings, 0,
                "b = {b} m, seed {seed}: {crossings} crossings"
            );
            let lining: Vec<usize> = PressureWall::new(d, [0.0; 2], 3.0)
                .unwrap()
                .members
                .iter()
                .map(|m| m.0 as usize)
                .collect();
            let x = CrackExtent::new(d.len(), &lining, [0.0; 2])
                .unwrap()
                .across_pores(d, bonds)
                .unwrap();
            let pore = x.hole_pore();
            let reach = pore
                .iter()
                .flat_map(|&(i, j)| [i, j])
                .map(|k| d.x[k][0].hypot(d.x[k][1]) + d.r[k])
                .fold(0.0, f64::max);
            eprintln!(
                "b = {b} m, seed {seed}: {} disks, {} bonds, planar; the hole's pore: {} bonds, \
                 reach {reach:.2} m, {} lining disks",
                d.len(),
                bonds.len(),
                pore.len(),
                lining.len()
            );
        }
    }
}
