//! Generators: reproducibility, counts, hanging nodes, tags, and errors on bad input.

use porofrac_grid::generate::{
    CompositeSpec, Diagonals, MAX_PERTURB, MIN_ANGLE_DEG, MIN_WELL_NODES, REFINED_TAG,
    RoundWellSpec, cartesian, composite, extrude, perturb, round_well, simplices, voronoi,
};
use porofrac_grid::{Grid, GridError, Point};

type P2 = Point<2>;

fn total_volume<const D: usize>(g: &Grid<D>) -> f64 {
    g.cell_volumes().iter().sum()
}

#[test]
fn perturb_is_reproducible_and_keeps_the_boundary() {
    let g = simplices(P2::new(0.0, 0.0), P2::new(2.0, 1.0), [8, 5]).unwrap();
    let a = perturb(&g, 0.3, 7).unwrap();
    let b = perturb(&g, 0.3, 7).unwrap();
    let c = perturb(&g, 0.3, 8).unwrap();
    assert_eq!(a, b, "same seed, same grid");
    assert_ne!(a.nodes(), c.nodes(), "different seed, different nodes");
    // Boundary nodes fixed exactly; interior nodes moved by at most 0.3 h, h = 0.2 (the
    // shortest incident edge: the x spacing is 0.25, the y spacing 0.2).
    let boundary = g.nodes_of_faces(&g.boundary_faces());
    let mut moved = 0;
    for n in 0..g.num_nodes() {
        let d = (a.node(n) - g.node(n)).norm();
        if boundary.binary_search(&n).is_ok() {
            assert_eq!(d, 0.0, "boundary node {n} moved");
        } else {
            assert!(d <= 0.3 * 0.2 + 1e-15, "node {n} moved {d}");
            moved += usize::from(d > 0.0);
        }
    }
    assert_eq!(moved, 7 * 4, "every interior node moves");
    // Same domain: |Ω| = 2 to 1e-14.
    assert!((total_volume(&a) - 2.0).abs() < 1e-14);
    // Tags and topology unchanged.
    assert_eq!(a.num_faces(), g.num_faces());
    assert_eq!(a.cell_faces(17), g.cell_faces(17));

    // 3D hexahedra (non-planar faces after the jitter).
    let h = cartesian(
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(1.0, 1.0, 1.0),
        [3, 3, 3],
    )
    .unwrap();
    let p = perturb(&h, MAX_PERTURB, 1).unwrap();
    assert_eq!(p, perturb(&h, MAX_PERTURB, 1).unwrap());
    assert!((total_volume(&p) - 1.0).abs() < 1e-14);
}

#[test]
fn perturb_rejects_bad_amplitude_and_reports_inverted_cells() {
    let g = cartesian(P2::new(0.0, 0.0), P2::new(1.0, 1.0), [2, 2]).unwrap();
    for a in [-0.1, 0.31, f64::NAN] {
        assert!(matches!(perturb(&g, a, 0), Err(GridError::Input(_))), "{a}");
    }
    // A fan of 4 triangles around node 4 = (0.5, 0.01): its shortest edge is ≈ 0.5, so a
    // jitter of up to 0.15 can push it through the bottom edge (height 0.01).
    let nodes = vec![
        P2::new(0.0, 0.0),
        P2::new(1.0, 0.0),
        P2::new(1.0, 1.0),
        P2::new(0.0, 1.0),
        P2::new(0.5, 0.01),
    ];
    let fan = Grid::from_polygons(
        nodes,
        &[0, 3, 6, 9, 12],
        &[0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4],
    )
    .unwrap();
    let mut errors = 0;
    for seed in 0..20 {
        match perturb(&fan, 0.3, seed) {
            Ok(p) => assert!((total_volume(&p) - 1.0).abs() < 1e-15),
            Err(GridError::Cell { cell, .. }) => {
                assert!(cell < 4);
                errors += 1;
            }
            Err(e) => panic!("unexpected error {e}"),
        }
    }
    assert!(errors > 0, "some seed must invert the flat triangle");
}

#[test]
fn voronoi_counts_and_reproducibility() {
    let (lo, hi) = (P2::new(-1.0, 2.0), P2::new(3.0, 4.0));
    for n in [1, 2, 3, 10, 257, 2000] {
        let g = voronoi(lo, hi, n, 42, 3).unwrap();
        assert_eq!(g.num_cells(), n);
        assert!((total_volume(&g) - 8.0).abs() < 1e-12 * 8.0, "n = {n}");
        for p in g.nodes() {
            assert!(p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1]);
        }
    }
    let a = voronoi(lo, hi, 300, 5, 2).unwrap();
    assert_eq!(a, voronoi(lo, hi, 300, 5, 2).unwrap());
    assert_ne!(a.nodes(), voronoi(lo, hi, 300, 6, 2).unwrap().nodes());
    // Without Lloyd iterations too.
    let b = voronoi(lo, hi, 300, 5, 0).unwrap();
    assert_eq!(b.num_cells(), 300);
    assert_ne!(a.nodes(), b.nodes());
    // Euler's formula for a planar subdivision of a disc: V − E + F = 1.
    let euler = a.num_nodes() as i64 - a.num_faces() as i64 + a.num_cells() as i64;
    assert_eq!(euler, 1);
    // Bad input.
    assert!(matches!(voronoi(lo, hi, 0, 1, 0), Err(GridError::Input(_))));
    assert!(matches!(
        voronoi(hi, lo, 10, 1, 0),
        Err(GridError::Input(_))
    ));
}

fn seed_scene(refine: usize) -> CompositeSpec {
    CompositeSpec::new(
        P2::new(0.0, 0.0),
        P2::new(30.0, 30.0),
        [30, 30],
        P2::new(15.0, 15.0),
        3.0,
        refine,
        0.25,
    )
}

#[test]
fn composite_counts_and_hanging_nodes() {
    for (refine, diag) in [
        (1, Diagonals::Structured),
        (6, Diagonals::Structured),
        (8, Diagonals::Alternating),
    ] {
        let mut spec = seed_scene(refine);
        spec.diagonals = diag;
        if refine == 1 {
            // Triangle centroids are ≥ √5/3 ≈ 0.75 from the centre: a wider well.
            spec.well_radius = 1.0;
        }
        let ([i0, i1], [j0, j1]) = spec.zone_cells().unwrap();
        // Centroids 12.5 … 17.5 lie in [12, 18]: cells 12..=17.
        assert_eq!(([i0, i1], [j0, j1]), ([12, 17], [12, 17]));
        let g = composite(&spec).unwrap();
        let zone = 36;
        let coarse = 900 - zone;
        assert_eq!(g.num_cells(), coarse + zone * 2 * refine * refine);
        assert!((total_volume(&g) - 900.0).abs() < 1e-12 * 900.0);
        assert_eq!(
            g.cell_tags()[REFINED_TAG],
            (coarse..g.num_cells()).collect::<Vec<_>>()
        );
        // Coarse cells: 4 corners + (refine − 1) per edge shared with the zone, all on the
        // cell's edges (collinear with the corners).
        let mut hanging_total = 0;
        for c in 0..coarse {
            let x = g.cell_centroid(c);
            let (i, j) = ((x[0] - 0.5).round() as i64, (x[1] - 0.5).round() as i64);
            let inside = |a: i64, b: i64| (12..=17).contains(&a) && (12..=17).contains(&b);
            assert!(!inside(i, j));
            let shared = [(i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)]
                .iter()
                .filter(|&&(a, b)| inside(a, b))
                .count();
            assert_eq!(g.cell_nodes(c).len(), 4 + shared * (refine - 1), "cell {c}");
            hanging_total += shared * (refine - 1);
            for &n in g.cell_nodes(c) {
                let p = g.node(n);
                let on_x = (p[0] - i as f64).abs() < 1e-12 || (p[0] - (i + 1) as f64).abs() < 1e-12;
                let on_y = (p[1] - j as f64).abs() < 1e-12 || (p[1] - (j + 1) as f64).abs() < 1e-12;
                assert!(on_x || on_y, "cell {c}: node {n} off the cell's edges");
            }
            assert!((g.cell_volume(c) - 1.0).abs() < 1e-13);
        }
        assert_eq!(hanging_total, 24 * (refine - 1), "4 sides × 6 coarse edges");
    }
}

#[test]
fn composite_well_tag_matches_the_fine_triangle_centroids() {
    for diag in [Diagonals::Structured, Diagonals::Alternating] {
        let mut spec = seed_scene(8);
        spec.diagonals = diag;
        let g = composite(&spec).unwrap();
        let well = &g.cell_tags()["well"];
        // Independent enumeration: fine squares of side hf = 1/8 with lower-left corner
        // (12 + I hf, 12 + J hf); the two triangles' centroids are at offsets
        // (2/3, 1/3) hf and (1/3, 2/3) hf (structured) or, flipped, (1/3, 1/3) hf and
        // (2/3, 2/3) hf.
        let hf = 0.125;
        let mut expect: Vec<P2> = Vec::new();
        for jj in 0..48 {
            for ii in 0..48 {
                let flip = diag == Diagonals::Alternating && (ii + jj) % 2 == 1;
                let offs: [(f64, f64); 2] = if flip {
                    [(1.0 / 3.0, 1.0 / 3.0), (2.0 / 3.0, 2.0 / 3.0)]
                } else {
                    [(2.0 / 3.0, 1.0 / 3.0), (1.0 / 3.0, 2.0 / 3.0)]
                };
                for (ox, oy) in offs {
                    let p = P2::new(12.0 + (ii as f64 + ox) * hf, 12.0 + (jj as f64 + oy) * hf);
                    if (p - spec.center).norm() <= 0.25 {
                        expect.push(p);
                    }
                }
            }
        }
        assert!(!expect.is_empty());
        assert_eq!(well.len(), expect.len());
        for &c in well {
            assert!(
                expect
                    .iter()
                    .any(|p| (p - g.cell_centroid(c)).norm() < 1e-12),
                "cell {c}"
            );
            assert!(g.cell_tags()[REFINED_TAG].binary_search(&c).is_ok());
        }
        for c in 0..g.num_cells() {
            let inside = (g.cell_centroid(c) - spec.center).norm() <= 0.25;
            assert_eq!(inside, well.binary_search(&c).is_ok(), "cell {c}");
        }
    }
    let mut spec = seed_scene(6);
    spec.well_tag = "injector".into();
    assert!(
        composite(&spec)
            .unwrap()
            .cell_tags()
            .contains_key("injector")
    );
}

#[test]
fn composite_perturbed_is_reproducible() {
    let mut spec = seed_scene(6);
    spec.perturb = 0.3;
    spec.seed = 3;
    let a = composite(&spec).unwrap();
    assert_eq!(a, composite(&spec).unwrap());
    spec.seed = 4;
    let b = composite(&spec).unwrap();
    assert_ne!(a.nodes(), b.nodes());
    assert!((total_volume(&b) - 900.0).abs() < 1e-12 * 900.0);
    // Far field and zone boundary stay exact: coarse cells keep unit area.
    for c in 0..864 {
        assert!((a.cell_volume(c) - 1.0).abs() < 1e-13);
    }
}

#[test]
fn composite_rejects_bad_specs() {
    let ok = seed_scene(6);
    let cases: Vec<(&str, CompositeSpec)> = vec![
        (
            "zone outside",
            CompositeSpec {
                center: P2::new(1.0, 15.0),
                ..ok.clone()
            },
        ),
        (
            "refine 0",
            CompositeSpec {
                refine: 0,
                ..ok.clone()
            },
        ),
        (
            "radius 0",
            CompositeSpec {
                well_radius: 0.0,
                ..ok.clone()
            },
        ),
        (
            "radius < 0",
            CompositeSpec {
                well_radius: -1.0,
                ..ok.clone()
            },
        ),
        (
            "radius > zone",
            CompositeSpec {
                well_radius: 3.5,
                ..ok.clone()
            },
        ),
        (
            "zone width 0",
            CompositeSpec {
                zone_half_width: 0.0,
                ..ok.clone()
            },
        ),
        (
            "no coarse centroid",
            CompositeSpec {
                zone_half_width: 0.2,
                well_radius: 0.1,
                ..ok.clone()
            },
        ),
        (
            "cells 0",
            CompositeSpec {
                cells: [0, 30],
                ..ok.clone()
            },
        ),
        (
            "perturb",
            CompositeSpec {
                perturb: 0.5,
                ..ok.clone()
            },
        ),
        (
            "well empty",
            CompositeSpec {
                well_radius: 0.01,
                ..ok.clone()
            },
        ),
    ];
    for (what, spec) in cases {
        assert!(
            matches!(composite(&spec), Err(GridError::Input(_))),
            "{what}"
        );
    }
    assert!(composite(&ok).is_ok());
}

fn round_seed_scene(refine: usize) -> RoundWellSpec {
    RoundWellSpec::new(
        P2::new(0.0, 0.0),
        P2::new(30.0, 30.0),
        [30, 30],
        P2::new(15.0, 15.0),
        3.0,
        refine,
        0.25,
    )
}

/// Nodes of `g` on the circle |x − c| = r (to 1e-12 relative).
fn on_circle(g: &Grid<2>, c: P2, r: f64) -> usize {
    g.nodes()
        .iter()
        .filter(|p| ((*p - c).norm() - r).abs() < 1e-12 * r)
        .count()
}

#[test]
fn round_well_resolves_the_circle_and_refines_with_the_zone() {
    let mut last = 0;
    for refine in [12, 17, 24] {
        let spec = round_seed_scene(refine);
        let g = round_well(&spec).unwrap();
        let n = on_circle(&g, spec.center, 0.25);
        // Default wall size: half the interface spacing 1/refine, n a multiple of 4.
        let want = (4 * (std::f64::consts::TAU * 0.25 * refine as f64 * 2.0 / 4.0).ceil() as usize)
            .max(MIN_WELL_NODES);
        assert_eq!(n, want, "refine {refine}");
        assert!(
            n >= MIN_WELL_NODES && n > last,
            "refine {refine}: {n} nodes"
        );
        last = n;
        // Nodes on both axes through the centre (where the hoop stress is extreme).
        for d in [
            P2::new(0.25, 0.0),
            P2::new(0.0, 0.25),
            P2::new(-0.25, 0.0),
            P2::new(0.0, -0.25),
        ] {
            let q = spec.center + d;
            assert!(
                g.nodes().iter().any(|p| (p - q).norm() < 1e-12),
                "node at {q:?}"
            );
        }
    }
    // An explicit wall size: 2πR / s rounded up to a multiple of 4.
    let mut spec = round_seed_scene(12);
    spec.well_size = Some(0.01);
    let g = round_well(&spec).unwrap();
    assert_eq!(on_circle(&g, spec.center, 0.25), 160);
}

#[test]
fn round_well_areas_tags_hanging_nodes_and_grading() {
    let refine = 12;
    let spec = round_seed_scene(refine);
    let g = round_well(&spec).unwrap();
    // The box, the zone and the well polygon keep their areas.
    assert!((total_volume(&g) - 900.0).abs() < 1e-10 * 900.0);
    let zone = &g.cell_tags()[REFINED_TAG];
    let coarse = 900 - 36;
    assert_eq!(zone, &(coarse..g.num_cells()).collect::<Vec<_>>());
    let zone_area: f64 = zone.iter().map(|&c| g.cell_volume(c)).sum();
    assert!(
        (zone_area - 36.0).abs() < 1e-10 * 36.0,
        "zone area {zone_area}"
    );
    let n = on_circle(&g, spec.center, 0.25) as f64;
    let polygon = 0.5 * n * 0.25f64.powi(2) * (std::f64::consts::TAU / n).sin();
    let well = &g.cell_tags()["well"];
    let well_area: f64 = well.iter().map(|&c| g.cell_volume(c)).sum();
    assert!(
        (well_area - polygon).abs() < 1e-10 * polygon,
        "{well_area} vs {polygon}"
    );
    for &c in well {
        assert!((g.cell_centroid(c) - spec.center).norm() < 0.25);
    }
    // Coarse cells: 4 corners + (refine − 1) hanging nodes per edge shared with the zone.
    let mut hanging = 0;
    for c in 0..coarse {
        assert!((g.cell_volume(c) - 1.0).abs() < 1e-12);
        hanging += g.cell_nodes(c).len() - 4;
    }
    assert_eq!(hanging, 24 * (refine - 1));
    // Quality and grading: the smallest angle stays near the refinement's limit (the
    // constraint loops may keep a few smaller ones), triangles are finer at the wall than at
    // the interface, and none is larger than the interface triangle.
    let s = 1.0 / refine as f64;
    let mut min_angle = f64::INFINITY;
    let mut max_area = 0.0f64;
    let (mut near, mut far) = (Vec::new(), Vec::new());
    for &c in zone {
        let v = g.cell_nodes(c);
        assert_eq!(v.len(), 3);
        let p = [g.node(v[0]), g.node(v[1]), g.node(v[2])];
        for k in 0..3 {
            let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            min_angle = min_angle.min(a.angle(&b).to_degrees());
        }
        let area = g.cell_volume(c);
        // Refinement never splits the kept interface edges: the bound holds away from them.
        let on_interface = p
            .iter()
            .any(|q| (0..2).any(|a| (q[a] - 12.0).abs() < 1e-12 || (q[a] - 18.0).abs() < 1e-12));
        if !on_interface {
            max_area = max_area.max(area / (0.25 * 3f64.sqrt() * s * s));
        }
        let d = (g.cell_centroid(c) - spec.center).norm();
        if (0.25..0.3).contains(&d) {
            near.push(area);
        } else if d > 2.0 {
            far.push(area);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    eprintln!("smallest angle {min_angle}°, largest area / equilateral {max_area}");
    assert!(
        min_angle > 0.7 * MIN_ANGLE_DEG,
        "smallest angle {min_angle}°"
    );
    assert!(
        max_area <= 1.0 + 1e-9,
        "largest triangle {max_area} × the equilateral of side s"
    );
    assert!(
        mean(&near) < 0.75 * mean(&far),
        "{} vs {}",
        mean(&near),
        mean(&far)
    );
    // Deterministic.
    let again = round_well(&spec).unwrap();
    assert_eq!(g.nodes(), again.nodes());
    // Extruded: a vertical cylinder of tetrahedra in the polygon prisms' far field.
    let g3 = extrude(&g, &[0.0, 1.0, 2.0]).unwrap();
    assert!((g3.cell_volumes().iter().sum::<f64>() - 1800.0).abs() < 1e-9 * 1800.0);
    let well3: f64 = g3.cell_tags()["well"]
        .iter()
        .map(|&c| g3.cell_volume(c))
        .sum();
    assert!((well3 - 2.0 * polygon).abs() < 1e-9 * polygon);
}

#[test]
fn round_well_bad_specs_are_errors() {
    let err = |spec: RoundWellSpec| match round_well(&spec) {
        Err(GridError::Input(m)) => m,
        other => panic!("expected an input error, got {other:?}"),
    };
    let mut s = round_seed_scene(12);
    s.well_radius = 4.0;
    assert!(err(s).contains("bigger than the refined zone"));
    let mut s = round_seed_scene(12);
    s.well_radius = 2.95;
    assert!(err(s).contains("no room for the well"));
    let mut s = round_seed_scene(12);
    s.well_size = Some(0.0);
    assert!(err(s).contains("well_size"));
    let mut s = round_seed_scene(12);
    s.well_radius = -1.0;
    assert!(err(s).contains("well_radius"));
    let mut s = round_seed_scene(0);
    s.refine = 0;
    assert!(err(s).contains("refine"));
    let mut s = round_seed_scene(12);
    s.zone_half_width = 0.0;
    assert!(err(s).contains("zone_half_width"));
}
