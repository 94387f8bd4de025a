//! Checks of the particle crate: cell-list neighbours equal the brute-force ones, the
//! packings do not overlap and are reproducible, the tracked cell and VTK files.

use porofrac_particles::cells::{CellList, brute_force_pairs, max_radius};
use porofrac_particles::packing::hexagonal;
use porofrac_particles::{CellContact, Disks, RandomPacking, TrackedCell, vtk};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Every pair with gap below the alert distance, no other, for random clouds of disks
    /// (some of them far away, which makes the cell side grow).
    #[test]
    fn cell_list_pairs_equal_brute_force(
        pts in prop::collection::vec((-5.0f64..5.0, -5.0f64..5.0, 0.05f64..0.6), 0..200),
        alert in 0.0f64..0.5,
        far in prop::bool::ANY,
    ) {
        let mut x: Vec<[f64; 2]> = pts.iter().map(|p| [p.0, p.1]).collect();
        let r: Vec<f64> = pts.iter().map(|p| p.2).collect();
        if far && !x.is_empty() {
            x[0] = [1e6, -3e5];
        }
        let mut cells = CellList::new();
        cells.build(&x, 2.0 * max_radius(&r) + alert);
        let mut got = Vec::new();
        cells.pairs(&x, &r, alert, &mut got);
        prop_assert_eq!(got, brute_force_pairs(&x, &r, alert));
    }
}

#[test]
fn hexagonal_packing_touches_without_overlap() {
    let p = hexagonal([0.0, 0.0], [10.0, 10.0], 0.5).unwrap();
    let (o, _) = p.max_overlap();
    assert!(o < 1e-12, "overlap {o}");
    // Interior disks of a triangular lattice touch six neighbours.
    let z = p.coordination(1e-9);
    assert!(z > 5.0 && z < 6.0, "coordination {z}");
    // Ten per even row, nine per odd row, rows √3/2 apart.
    assert_eq!(p.len(), 6 * 10 + 5 * 9);
}

#[test]
fn random_packing_is_dense_without_overlap_and_reproducible() {
    let spec = RandomPacking::new([0.0, 0.0], [20.0, 10.0], 0.13, 0.26, 0.8, 7);
    let a = spec.generate().unwrap();
    let b = spec.generate().unwrap();
    assert_eq!(a, b, "same seed, same packing");
    let tol = spec.tolerance * spec.r_min;
    a.check_overlap(tol).unwrap();
    let phi = a.packing_fraction([0.0, 0.0], [20.0, 10.0]);
    assert!(phi > 0.79 && phi <= 0.8, "packing fraction {phi}");
    // Every disk inside the box.
    for (c, r) in a.centres.iter().zip(&a.radii) {
        assert!(c[0] - r >= -1e-12 && c[0] + r <= 20.0 + 1e-12);
        assert!(c[1] - r >= -1e-12 && c[1] + r <= 10.0 + 1e-12);
    }
    // A jammed-like packing: most disks touch (within 1 % of r_min) three or more.
    let z = a.coordination(0.01 * spec.r_min);
    assert!(z > 3.0, "coordination {z}");
    let c = RandomPacking { seed: 8, ..spec }.generate().unwrap();
    assert_ne!(a, c, "another seed, another packing");
}

#[test]
fn random_packing_refuses_impossible_fraction() {
    let spec = RandomPacking::new([0.0, 0.0], [5.0, 5.0], 0.1, 0.2, 0.9, 1);
    assert!(spec.generate().is_err());
    let spec = RandomPacking::new([0.0, 0.0], [5.0, 5.0], 0.0, 0.2, 0.5, 1);
    assert!(spec.generate().is_err());
}

#[test]
fn disks_refuse_zero_radius() {
    let e = Disks::new(&[[0.0, 0.0]], &[0.0], 1.0).unwrap_err();
    assert!(e.to_string().contains("particle 0"), "{e}");
}

/// Eq. 7 on a hand-computed case: two contacts of a pair along x and along y.
#[test]
fn tracked_cell_stress_and_fabric() {
    let x = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [50.0, 50.0]];
    let cell = TrackedCell::new(&x, [0.0, 0.0], 3.0);
    assert_eq!(cell.count, 3);
    let contacts = [
        // Disk 1 pushed by 0 along +x with 10 N, branch 2 m.
        CellContact {
            i: 1,
            j: Some(0),
            normal: [1.0, 0.0],
            branch: [2.0, 0.0],
            force: [10.0, 0.0],
        },
        CellContact {
            i: 2,
            j: Some(0),
            normal: [0.0, 1.0],
            branch: [0.0, 2.0],
            force: [0.0, 4.0],
        },
        // Not counted: 3 is outside.
        CellContact {
            i: 3,
            j: Some(0),
            normal: [1.0, 0.0],
            branch: [1.0, 0.0],
            force: [1e9, 0.0],
        },
    ];
    let s = cell.measure(&x, &contacts);
    let v = std::f64::consts::PI * 9.0;
    assert!((s.sigma[0][0] - 20.0 / v).abs() < 1e-14);
    assert!((s.sigma[1][1] - 8.0 / v).abs() < 1e-14);
    assert!((s.p - 14.0 / v).abs() < 1e-14);
    assert!((s.q - 6.0 / v).abs() < 1e-14);
    assert_eq!(s.contacts, 2);
    // One contact along x, one along y: isotropic fabric.
    assert!(s.anisotropy.abs() < 1e-15);
    assert_eq!(s.dilation_x, 1.0);
}

/// The values of the binary `DataArray` `name` of a `.vtp` text: the `UInt64` byte count
/// checked against the payload, then the little-endian values.
fn vtp_array(text: &str, name: &str) -> Vec<[u8; 8]> {
    use base64::Engine as _;
    let tag = format!("Name=\"{name}\"");
    let at = text.find(&tag).unwrap_or_else(|| panic!("{name} missing"));
    let body = &text[at..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(body.trim())
        .unwrap();
    let count = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    assert_eq!(count, bytes.len() - 8, "{name}: byte count header");
    bytes[8..]
        .chunks_exact(8)
        .map(|c| c.try_into().unwrap())
        .collect()
}

#[test]
fn vtk_files_are_written() {
    let dir = std::env::temp_dir().join(format!("porofrac-particles-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut d = Disks::new(&[[0.0, 0.0], [1.0, 0.0]], &[0.5, 0.25], 1000.0).unwrap();
    d.v[1] = [0.125, -3.5];
    vtk::write_particles(&dir.join("p.vtp"), &d).unwrap();
    let text = std::fs::read_to_string(dir.join("p.vtp")).unwrap();
    for name in ["radius", "velocity", "omega", "displacement", "id"] {
        assert!(text.contains(&format!("Name=\"{name}\"")), "{name}");
    }
    let f = |v: Vec<[u8; 8]>| v.into_iter().map(f64::from_le_bytes).collect::<Vec<_>>();
    let i = |v: Vec<[u8; 8]>| v.into_iter().map(i64::from_le_bytes).collect::<Vec<_>>();
    assert_eq!(f(vtp_array(&text, "radius")), [0.5, 0.25]);
    assert_eq!(
        f(vtp_array(&text, "velocity")),
        [0.0, 0.0, 0.0, 0.125, -3.5, 0.0]
    );
    assert_eq!(
        f(vtp_array(&text, "Points")),
        [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]
    );
    assert_eq!(i(vtp_array(&text, "offsets")), [1, 2]);
    let line = vtk::ContactLine {
        a: [0.0, 1.0],
        b: [2.0, 3.0],
        normal_force: 7.5,
        tangential_force: -1.0,
        bonded: true,
    };
    vtk::write_contacts(&dir.join("c.vtp"), &[line, vtk::ContactLine::default()]).unwrap();
    let text = std::fs::read_to_string(dir.join("c.vtp")).unwrap();
    assert_eq!(f(vtp_array(&text, "normal_force")), [7.5, 0.0]);
    assert_eq!(f(vtp_array(&text, "tangential_force")), [-1.0, 0.0]);
    assert_eq!(i(vtp_array(&text, "bonded")), [1, 0]);
    assert_eq!(i(vtp_array(&text, "connectivity")), [0, 1, 2, 3]);
    assert_eq!(i(vtp_array(&text, "offsets")), [2, 4]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The trishear field: rigid above, fixed below, divergence-free and continuous in the
/// triangle (central differences, h = 1e-5 m: error O(h²) of a smooth field).
#[test]
fn trishear_field_is_incompressible_and_continuous() {
    use porofrac_particles::trishear::Trishear;
    let t = Trishear {
        tip: [75.0, 0.0],
        dip: 30f64.to_radians(),
        half_apex: 30f64.to_radians(),
        v0: 0.325,
    };
    let e = [t.dip.cos(), t.dip.sin()];
    let n = [-e[1], e[0]];
    let at = |x: f64, y: f64| {
        [
            t.tip[0] + x * e[0] + y * n[0],
            t.tip[1] + x * e[1] + y * n[1],
        ]
    };
    let tan = t.half_apex.tan();
    // Zones I and III.
    let v = t.velocity(at(-3.0, 1.0));
    assert!((v[0] - t.v0 * e[0]).abs() < 1e-15 && (v[1] - t.v0 * e[1]).abs() < 1e-15);
    assert_eq!(t.velocity(at(-3.0, -1.0)), [0.0, 0.0]);
    assert_eq!(t.velocity(at(5.0, -5.0 * tan - 0.1)), [0.0, 0.0]);
    // Continuity across both sides of zone II.
    for x in [1.0, 4.0, 10.0] {
        let up = t.velocity(at(x, x * tan * (1.0 - 1e-12)));
        let above = t.velocity(at(x, x * tan * (1.0 + 1e-12)));
        let low = t.velocity(at(x, -x * tan * (1.0 - 1e-12)));
        for a in 0..2 {
            assert!((up[a] - above[a]).abs() < 1e-11, "upper side at x′ = {x}");
            assert!(low[a].abs() < 1e-11, "lower side at x′ = {x}");
        }
    }
    // Divergence-free inside.
    let h = 1e-5;
    for (x, y) in [(2.0, 0.3), (5.0, -1.0), (8.0, 2.0)] {
        let p = at(x, y);
        let vx1 = t.velocity([p[0] + h, p[1]])[0];
        let vx0 = t.velocity([p[0] - h, p[1]])[0];
        let vy1 = t.velocity([p[0], p[1] + h])[1];
        let vy0 = t.velocity([p[0], p[1] - h])[1];
        let div = (vx1 - vx0 + vy1 - vy0) / (2.0 * h);
        assert!(div.abs() < 1e-8, "div v = {div} at ({x}, {y})");
    }
    // The mismatch of the field with itself is 0, with a field at rest 1.
    let pts = [at(2.0, 0.3), at(-1.0, 1.0)];
    let v: Vec<[f64; 2]> = pts.iter().map(|p| t.velocity(*p)).collect();
    assert_eq!(t.l2_mismatch(&pts, &v), 0.0);
    assert!((t.l2_mismatch(&pts, &[[0.0; 2]; 2]) - 1.0).abs() < 1e-15);
}

#[test]
fn packings_in_a_disk_with_a_hole_and_in_a_polygon() {
    use porofrac_particles::packing::{Hole, Region, hexagonal_in};
    let disk = Region::Disk {
        centre: [0.0, 0.0],
        radius: 10.0,
    };
    let hole = Hole {
        centre: [0.0, 0.0],
        radius: 2.0,
    };
    let spec = RandomPacking::new([-10.0, -10.0], [10.0, 10.0], 0.2, 0.5, 0.8, 3);
    let a = spec.generate_in(&disk, &[hole]).unwrap();
    assert_eq!(a, spec.generate_in(&disk, &[hole]).unwrap(), "reproducible");
    a.check_overlap(spec.tolerance * spec.r_min).unwrap();
    for (c, r) in a.centres.iter().zip(&a.radii) {
        let d = (c[0] * c[0] + c[1] * c[1]).sqrt();
        assert!(
            d + r <= 10.0 + 1e-9 && d - r >= 2.0 - 1e-9,
            "disk at {c:?} r {r}"
        );
    }
    // Carving loses the disks cut by the two circles only: the fraction stays near 0.8.
    let phi = a.packing_fraction_in(&disk, &[hole]);
    assert!(phi > 0.7 && phi < 0.8, "packing fraction {phi}");
    assert!(a.coordination(0.01 * spec.r_min) > 3.0);
    // A triangle: every hexagonal disk inside it, the area fraction near π/(2√3) inside.
    let tri = Region::Polygon(vec![[0.0, 0.0], [20.0, 0.0], [0.0, 20.0]]);
    let h = hexagonal_in(&tri, &[], 0.25).unwrap();
    for (c, r) in h.centres.iter().zip(&h.radii) {
        assert!(
            c[0] >= *r - 1e-9 && c[1] >= *r - 1e-9 && c[0] + c[1] + r * 2f64.sqrt() <= 20.0 + 1e-9
        );
    }
    let phi = h.packing_fraction_in(&tri, &[]);
    assert!(
        phi > 0.8 && phi < std::f64::consts::PI / 12f64.sqrt(),
        "hexagonal fraction {phi}"
    );
    // Radii from a list: only listed values appear.
    let listed = RandomPacking::new([0.0, 0.0], [10.0, 10.0], 0.0, 0.0, 0.7, 9)
        .with_radii(&[0.2, 0.3, 0.45])
        .generate()
        .unwrap();
    assert!(listed.radii.iter().all(|r| [0.2, 0.3, 0.45].contains(r)));
    for r in [0.2, 0.3, 0.45] {
        assert!(listed.radii.contains(&r));
    }
}

/// Centres at 1e20, ±f64::MAX, infinity and NaN: the cell list stays within `4 n + 16`
/// cells and in bounds, and the pairs among the ordinary disks equal the brute-force
/// ones (a centre that is not finite pairs with nothing).
#[test]
fn cell_list_survives_centres_far_away_or_not_finite() {
    let base: Vec<[f64; 2]> = (0..30)
        .map(|i| [(i % 6) as f64 * 0.9, (i / 6) as f64 * 0.9])
        .collect();
    for outlier in [
        [1e20, 0.5],
        [f64::MAX, -f64::MAX],
        [-f64::MAX, f64::MAX],
        [f64::INFINITY, 0.0],
        [f64::NAN, 1.0],
        [0.0, f64::NEG_INFINITY],
    ] {
        let mut x = base.clone();
        x.push(outlier);
        let r = vec![0.5; x.len()];
        let mut cells = CellList::new();
        cells.build(&x, 1.2);
        let mut pairs = Vec::new();
        cells.pairs(&x, &r, 0.1, &mut pairs);
        let expected = brute_force_pairs(&base, &r[..base.len()], 0.1);
        let far = pairs.iter().filter(|p| p.1 as usize == base.len()).count();
        assert_eq!(far, 0, "{outlier:?}");
        // With one disk far away every ordinary disk sits in one cell: same pairs.
        assert_eq!(pairs, expected, "{outlier:?}");
    }
}

/// `pairs_at_most` stops past its bound with the count found, and equals `pairs` below.
#[test]
fn bounded_pair_search_stops_past_its_bound() {
    let p = hexagonal([0.0; 2], [10.0; 2], 0.25).unwrap();
    let mut cells = CellList::new();
    cells.build(&p.centres, 2.0 * 0.25 + 5.0);
    let mut all = Vec::new();
    cells.pairs(&p.centres, &p.radii, 5.0, &mut all);
    assert!(all.len() > 1000);
    let mut some = Vec::new();
    assert_eq!(
        cells.pairs_at_most(&p.centres, &p.radii, 5.0, 1000, &mut some),
        Err(1001)
    );
    assert!(some.len() <= 1001);
    assert_eq!(
        cells.pairs_at_most(&p.centres, &p.radii, 5.0, all.len(), &mut some),
        Ok(())
    );
    assert_eq!(some, all);
}

/// The progress callback sees the placement and the sweeps, does not change the
/// packing, and stops it with `Interrupted` when it returns `true`.
#[test]
fn packing_progress_is_reported_and_interrupts() {
    let spec = RandomPacking::new([0.0; 2], [30.0; 2], 0.4, 0.6, 0.8, 3);
    let plain = spec.generate().unwrap();
    let mut seen = Vec::new();
    let polled = spec
        .generate_polled(&mut |p| {
            seen.push(p);
            false
        })
        .unwrap();
    assert_eq!(plain, polled);
    assert_eq!(seen[0].what, "placing disks");
    assert!(seen.iter().any(|p| p.what.starts_with("relaxing")));
    let mut calls = 0;
    let stopped = spec.generate_polled(&mut |_| {
        calls += 1;
        calls == 2
    });
    assert_eq!(stopped, Err(porofrac_particles::ParticleError::Interrupted));
    assert_eq!(calls, 2);
}
