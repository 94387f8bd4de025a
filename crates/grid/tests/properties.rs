//! Property tests of the grid invariants on random perturbed, Voronoi and composite grids.
//!
//! Per cell: `Σ_f A_f n_f = 0` (closure) to 1e-12 of `Σ_f A_f`; the discrete divergence
//! theorem `Σ_f A_f (c_f · n_f) = D |K|` for planar faces, to 1e-12 of `Σ_f A_f |c_f|`
//! (the rounding scale of the sum); `Σ_i N_i ⊗ x_i = |K| I` from
//! `Grid::cell_node_normals` (exact for non-planar faces too) to 1e-12 of
//! `Σ_i |N_i| |x_i|`. Globally: volumes add up to the box (1e-12 relative); every face's
//! first cell sees it outward and the second inward; each named side's boundary faces
//! add up to the side's length/area (1e-12 relative), and every boundary face is on one
//! side.

use porofrac_grid::generate::{
    CompositeSpec, Diagonals, cartesian, composite, perturb, simplices, voronoi,
};
use porofrac_grid::{Grid, Point, SIDE_NAMES};
use proptest::prelude::*;

fn check<const D: usize>(g: &Grid<D>, lo: Point<D>, hi: Point<D>, planar_faces: bool) {
    let mut q = vec![Point::<D>::zeros(); g.max_cell_nodes()];
    for c in 0..g.num_cells() {
        let mut closure = Point::<D>::zeros();
        let mut div = 0.0;
        let mut area_scale = 0.0;
        let mut div_scale = 0.0;
        for (&f, &out) in g.cell_faces(c).iter().zip(g.cell_face_outward(c)) {
            let s = if out { 1.0 } else { -1.0 };
            closure += g.face_normal(f) * (s * g.face_area(f));
            div += s * g.face_area(f) * g.face_centroid(f).dot(g.face_normal(f));
            area_scale += g.face_area(f);
            div_scale += g.face_area(f) * g.face_centroid(f).norm();
        }
        assert!(
            closure.norm() <= 1e-12 * area_scale,
            "cell {c}: closure {closure}"
        );
        let vol = g.cell_volume(c);
        if planar_faces {
            assert!(
                (div - D as f64 * vol).abs() <= 1e-12 * div_scale,
                "cell {c}: Σ A c·n = {div}, D|K| = {}",
                D as f64 * vol
            );
        }
        let nodes = g.cell_nodes(c);
        let q = &mut q[..nodes.len()];
        g.cell_node_normals(c, q);
        let scale: f64 = nodes
            .iter()
            .zip(q.iter())
            .map(|(&n, qi)| qi.norm() * g.node(n).norm())
            .sum();
        for a in 0..D {
            for b in 0..D {
                let s: f64 = nodes
                    .iter()
                    .zip(q.iter())
                    .map(|(&n, qi)| qi[a] * g.node(n)[b])
                    .sum();
                let expect = if a == b { vol } else { 0.0 };
                assert!(
                    (s - expect).abs() <= 1e-12 * scale,
                    "cell {c}: (Σ N⊗x)[{a}{b}] = {s}, expected {expect}"
                );
            }
        }
    }
    let ext = hi - lo;
    let box_vol: f64 = ext.iter().product();
    let total: f64 = g.cell_volumes().iter().sum();
    assert!(
        (total - box_vol).abs() <= 1e-12 * box_vol,
        "Σ|K| = {total}, box {box_vol}"
    );
    for f in 0..g.num_faces() {
        let (c0, c1) = g.face_cells(f);
        let k = g.cell_faces(c0).iter().position(|&x| x == f).unwrap();
        assert!(
            g.cell_face_outward(c0)[k],
            "face {f}: first cell sees it inward"
        );
        if let Some(c1) = c1 {
            let k = g.cell_faces(c1).iter().position(|&x| x == f).unwrap();
            assert!(
                !g.cell_face_outward(c1)[k],
                "face {f}: both cells see it outward"
            );
        }
    }
    let mut on_sides = 0;
    for (k, name) in SIDE_NAMES[..2 * D].iter().enumerate() {
        let faces = g.boundary(name).unwrap();
        on_sides += faces.len();
        let axis = k / 2;
        let side: f64 = (0..D).filter(|&a| a != axis).map(|a| ext[a]).product();
        let sum: f64 = faces.iter().map(|&f| g.face_area(f)).sum();
        assert!(
            (sum - side).abs() <= 1e-12 * side,
            "side {name}: Σ A = {sum}, expected {side}"
        );
        let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
        for &f in &faces {
            assert!(
                (g.face_normal(f)[axis] - sign).abs() < 1e-12,
                "face {f} on {name}"
            );
        }
    }
    assert_eq!(on_sides, g.boundary_faces().len());
}

fn box_strategy<const D: usize>() -> impl Strategy<Value = (Point<D>, Point<D>)> {
    (
        prop::array::uniform3(-5.0..5.0f64),
        prop::array::uniform3(0.1..10.0f64),
    )
        .prop_map(|(o, e)| {
            let lo = Point::<D>::from_fn(|a, _| o[a]);
            (lo, lo + Point::<D>::from_fn(|a, _| e[a]))
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn perturbed_2d(
        (lo, hi) in box_strategy::<2>(),
        n in prop::array::uniform2(1usize..9),
        amp in 0.0..=0.3f64,
        seed in any::<u64>(),
        tri in any::<bool>(),
    ) {
        let g = if tri { simplices(lo, hi, n) } else { cartesian(lo, hi, n) }.unwrap();
        let p = perturb(&g, amp, seed).unwrap();
        check(&p, lo, hi, true);
    }

    #[test]
    fn perturbed_3d(
        (lo, hi) in box_strategy::<3>(),
        n in prop::array::uniform3(1usize..5),
        amp in 0.0..=0.3f64,
        seed in any::<u64>(),
        tet in any::<bool>(),
    ) {
        let g = if tet { simplices(lo, hi, n) } else { cartesian(lo, hi, n) }.unwrap();
        let p = perturb(&g, amp, seed).unwrap();
        // Jittered hexahedra have non-planar faces: only the N ⊗ x identity is exact.
        check(&p, lo, hi, tet);
    }

    #[test]
    fn voronoi_grids(
        (lo, hi) in box_strategy::<2>(),
        n in 1usize..400,
        lloyd in 0usize..4,
        seed in any::<u64>(),
    ) {
        let g = voronoi(lo, hi, n, seed, lloyd).unwrap();
        prop_assert_eq!(g.num_cells(), n);
        check(&g, lo, hi, true);
    }

    #[test]
    fn composite_grids(
        cells in prop::array::uniform2(4usize..16),
        extent in prop::array::uniform2(1.0..20.0f64),
        centre in prop::array::uniform2(0.3..0.7f64),
        width in 0.05..0.2f64,
        refine in 1usize..7,
        alternating in any::<bool>(),
        amp in 0.0..=0.3f64,
        seed in any::<u64>(),
    ) {
        let lo = Point::<2>::new(-1.0, 2.0);
        let hi = lo + Point::<2>::new(extent[0], extent[1]);
        let center = lo + Point::<2>::new(centre[0] * extent[0], centre[1] * extent[1]);
        // At least one coarse centroid on each axis: w ≥ h/2.
        let w = (width * extent[0].min(extent[1]))
            .max(0.51 * (extent[0] / cells[0] as f64).max(extent[1] / cells[1] as f64));
        let mut spec = CompositeSpec::new(lo, hi, cells, center, w, refine, 1.0);
        // A well radius that fits the snapped zone and holds at least one fine centroid.
        let (ri, rj) = spec.zone_cells().map_err(|e| TestCaseError::reject(e.to_string()))?;
        let z0 = Point::<2>::new(
            lo[0] + extent[0] * ri[0] as f64 / cells[0] as f64,
            lo[1] + extent[1] * rj[0] as f64 / cells[1] as f64,
        );
        let z1 = Point::<2>::new(
            lo[0] + extent[0] * (ri[1] + 1) as f64 / cells[0] as f64,
            lo[1] + extent[1] * (rj[1] + 1) as f64 / cells[1] as f64,
        );
        spec.well_radius = 0.999 * (center - z0).amin().min((z1 - center).amin());
        prop_assume!(spec.well_radius > 0.0);
        spec.diagonals = if alternating { Diagonals::Alternating } else { Diagonals::Structured };
        spec.perturb = amp;
        spec.seed = seed;
        match composite(&spec) {
            Ok(g) => check(&g, lo, hi, true),
            Err(e) => {
                // Only an empty well is acceptable here.
                prop_assert!(e.to_string().contains("no cell centroid"), "{}", e);
            }
        }
    }
}
