//! Corner-point decks shaped like real field decks: map coordinates in the millions
//! (UTM), layers millimetres thick, corners pinched at some pillars and not at others,
//! columns that do not match. Each small deck here reproduces what made a real deck
//! (Equinor's Drogon, Reek and Emerald grids) fail to load; every cell's volume is
//! checked against the volume its triangulated faces enclose (divergence theorem) and
//! every cell must be closed.
//!
//! `real_decks_load` (ignored) reads real decks named in `POROFRAC_REAL_DECKS`.

use porofrac_grid::Grid;
use porofrac_grid::io::grdecl::{Deck, corner_point_grid, read_deck};

/// A UTM-like origin of the map (m).
const ORIGIN: [f64; 2] = [465_000.0, 5_932_000.0];

/// A deck on vertical pillars `spacing` apart from [`ORIGIN`], the cells given in deck
/// order by their eight corner depths `[top c0..c3, bottom c0..c3]`, corner `c = di + 2
/// dj`.
fn corner_deck(dims: [usize; 3], spacing: f64, cells: &[[f64; 8]]) -> Deck {
    let [nx, ny, nz] = dims;
    assert_eq!(cells.len(), nx * ny * nz);
    let mut coord = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            let (x, y) = (
                ORIGIN[0] + i as f64 * spacing,
                ORIGIN[1] + j as f64 * spacing,
            );
            coord.extend([x, y, 1000.0, x, y, 2000.0]);
        }
    }
    let mut zcorn = vec![0.0; 8 * nx * ny * nz];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let cell = &cells[i + nx * (j + ny * k)];
                for dk in 0..2 {
                    for c in 0..4 {
                        let (di, dj) = (c % 2, c / 2);
                        let at = (2 * k + dk) * 4 * nx * ny + (2 * j + dj) * 2 * nx + 2 * i + di;
                        zcorn[at] = cell[4 * dk + c];
                    }
                }
            }
        }
    }
    Deck {
        dims,
        coord,
        zcorn,
        ..Deck::default()
    }
}

/// Every cell's volume is the volume its triangulated faces enclose, within rounding of
/// coordinates of size `scale` (a cell millimetres thin in a map of millions of metres
/// keeps about 10⁻¹⁰ m of its coordinates); every interior face has two cells seeing it
/// in opposite orientations (their area vectors, summed over the cell, vanish).
fn assert_exact_volumes(grid: &Grid<3>) {
    for c in 0..grid.num_cells() {
        let (v, got) = (grid.enclosed_volume(c), grid.cell_volume(c));
        let nodes = grid.cell_nodes(c);
        let size = nodes
            .iter()
            .map(|&n| (grid.node(n) - grid.node(nodes[0])).norm())
            .fold(0.0f64, f64::max);
        assert!(
            (v - got).abs() <= 1e-9 * got + 1e-9 * size * size,
            "cell {c}: volume {got}, its faces enclose {v}"
        );
        let mut sum = porofrac_grid::Point::<3>::zeros();
        for (&f, &out) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
            let a = grid.face_normal(f) * grid.face_area(f);
            sum += if out { a } else { -a };
        }
        assert!(
            sum.norm() <= 1e-9 * size * size,
            "cell {c}: area vectors sum to {sum:?}"
        );
    }
}

/// The volume of a cell alone in its column on vertical pillars `h` apart: its top and
/// bottom, split into four triangles about their vertex average, are piecewise linear
/// over the square, so the volume is `h²` times the mean of its four thicknesses.
fn column_volume(spacing: f64, cell: &[f64; 8]) -> f64 {
    spacing * spacing * (0..4).map(|c| cell[4 + c] - cell[c]).sum::<f64>() / 4.0
}

/// Drogon: two columns whose corners at a shared pillar are 6.5 mm apart (the top of
/// one cell, the top of its neighbour). With a tolerance taken from the map coordinates
/// (5.9 mm) the two depths were two nodes but the overlap of the two sides dropped a
/// vertex between them: a cell was left open.
#[test]
fn corners_millimetres_apart_at_map_coordinates() {
    let cells = [
        [
            1683.0, 1690.0, 1695.0, 1701.059, 1689.4, 1695.6, 1700.9, 1706.329,
        ],
        [
            1695.0 + 8.5,
            1701.0525,
            1712.9,
            1722.2,
            1709.6,
            1706.324,
            1718.5,
            1728.0,
        ],
    ];
    let deck = corner_deck([1, 2, 1], 100.0, &cells);
    let cp = corner_point_grid(&deck).unwrap();
    assert_eq!(cp.grid.num_cells(), 2);
    assert_exact_volumes(&cp.grid);
}

/// Reek: a column of three cells, millimetres thick at one pillar (the four depths
/// there within 7 mm) and decimetres at the others.
#[test]
fn a_column_of_cells_millimetres_thin_at_one_pillar() {
    let c0 = [1500.000, 1500.002, 1500.005, 1500.007];
    let c1 = [1490.0, 1490.15, 1490.3, 1490.45];
    let c2 = [1499.5, 1500.1, 1500.7, 1501.3];
    let c3 = [1495.0, 1495.6, 1496.2, 1496.8];
    let cells: Vec<[f64; 8]> = (0..3)
        .map(|k| {
            [
                c0[k],
                c1[k],
                c2[k],
                c3[k],
                c0[k + 1],
                c1[k + 1],
                c2[k + 1],
                c3[k + 1],
            ]
        })
        .collect();
    let deck = corner_deck([1, 1, 3], 100.0, &cells);
    let cp = corner_point_grid(&deck).unwrap();
    assert_eq!(cp.grid.num_cells(), 3);
    assert_exact_volumes(&cp.grid);
    for (c, cell) in cells.iter().enumerate() {
        let (got, want) = (cp.grid.cell_volume(c), column_volume(100.0, cell));
        assert!(
            (got - want).abs() < 1e-8 * want,
            "cell {c}: {got} m³, expected {want}"
        );
    }
}

/// Reek and Emerald: a cell pinched at two corners and a centimetre thick at the two
/// others, beside a column whose cells do not match: its faces were oriented from the
/// geometry (face normal against the cell centre), which a cell that thin gets wrong.
#[test]
fn a_partly_pinched_cell_beside_a_faulted_column() {
    let cells = [
        // Column (0, 0): a thick cell, then one pinched at corners 1 and 2.
        [
            1600.0, 1600.0, 1600.0, 1600.0, 1635.406, 1640.623, 1640.449, 1646.635,
        ],
        [
            1635.406, 1640.623, 1640.449, 1646.635, 1635.419, 1640.623, 1640.449, 1646.643,
        ],
        // Column (0, 1): two cells across the same depths, shifted.
        [
            1640.0, 1646.0, 1600.0, 1600.0, 1645.355, 1646.64, 1650.0, 1650.0,
        ],
        [
            1645.355, 1646.64, 1650.0, 1650.0, 1660.0, 1660.0, 1660.0, 1660.0,
        ],
    ];
    // Deck order: i fastest, then j, then k.
    let ordered = [cells[0], cells[2], cells[1], cells[3]];
    let deck = corner_deck([1, 2, 2], 100.0, &ordered);
    let cp = corner_point_grid(&deck).unwrap();
    assert_eq!(cp.grid.num_cells(), 4);
    assert_exact_volumes(&cp.grid);
}

/// A small xorshift generator: reproducible decks without a dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Decks of 4 × 3 × 6 cells at map coordinates, layers continuous from column to
/// column but each layer at each pillar pinched (zero), millimetres or metres thick at
/// random, and a fault between `i = 2` and `i = 3` with a random throw (so that thin and
/// pinched layers meet across it): all load, every cell closed and its volume that of
/// its faces.
#[test]
fn random_faulted_decks_with_pinched_and_thin_layers_load_exactly() {
    let (nx, ny, nz) = (4, 3, 6);
    for seed in 1..=100u64 {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ seed.wrapping_mul(0x1000_0000_01B3));
        // Depth of boundary k at pillar p.
        let mut depth = vec![[0.0; 7]; (nx + 1) * (ny + 1)];
        for d in &mut depth {
            d[0] = 1700.0 + 2.0 * rng.next();
            for k in 0..nz {
                let r = rng.next();
                d[k + 1] = d[k]
                    + if r < 0.3 {
                        0.0
                    } else if r < 0.6 {
                        0.001 + 0.01 * rng.next()
                    } else {
                        1.0 + 4.0 * rng.next()
                    };
            }
        }
        let throw = 0.5 + 3.0 * rng.next();
        let mut cells = vec![[0.0; 8]; nx * ny * nz];
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let cell = &mut cells[i + nx * (j + ny * k)];
                    for c in 0..4 {
                        let p = (i + c % 2) + (nx + 1) * (j + c / 2);
                        let shift = if i >= 2 { throw } else { 0.0 };
                        cell[c] = depth[p][k] + shift;
                        cell[4 + c] = depth[p][k + 1] + shift;
                    }
                }
            }
        }
        let deck = corner_deck([nx, ny, nz], 100.0, &cells);
        let cp = corner_point_grid(&deck).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_exact_volumes(&cp.grid);
    }
}

/// Real decks, paths in `POROFRAC_REAL_DECKS` (separated by `:`), converted to GRDECL
/// where needed (`xtgeo.grid_from_file(…).to_file(…, fformat="grdecl")`). Measured with
/// `cargo run --release -p porofrac-grid --example real_decks` (median of 5; 2 cores,
/// load average 5–7 from other builds):
///
/// | deck (equinor/xtgeo-testdata)               | size          | cells (pinched, inactive) | read + process  |
/// |---------------------------------------------|---------------|---------------------------|-----------------|
/// | drogon/4/simgrid_with_region_zone_attr.roff | 46 × 73 × 32  | 73 419 (41, 33 996)       | 0.05 + 0.18 s   |
/// | eme/2/emerald_hetero_grid.roff              | 70 × 100 × 46 | 120 842 (0, 201 158)      | 0.14 + 0.29 s   |
/// | eme/2/eme_small_w_hole_grid_params.grdecl   | 21 × 41 × 18  | 7 157 (0, 8 341)          | 0.007 + 0.015 s |
/// | reek/reek_sim_grid.grdecl                   | 40 × 64 × 14  | 35 838 (0, 2)             | 0.013 + 0.073 s |
/// | reek/REEK.EGRID                             | 40 × 64 × 14  | 35 838 (0, 2)             | 0.018 + 0.089 s |
/// | reek3/reek_sim.grdecl                       | 40 × 64 × 14  | 35 812 (0, 28)            | 0.013 + 0.077 s |
#[test]
#[ignore = "needs real decks: POROFRAC_REAL_DECKS=a.grdecl:b.grdecl"]
fn real_decks_load() {
    let paths = std::env::var("POROFRAC_REAL_DECKS").expect("POROFRAC_REAL_DECKS");
    for path in paths.split(':').filter(|p| !p.is_empty()) {
        let deck = read_deck(path).unwrap_or_else(|e| panic!("{e}"));
        let cp = corner_point_grid(&deck).unwrap_or_else(|e| panic!("{path}: {e}"));
        assert_exact_volumes(&cp.grid);
    }
}
