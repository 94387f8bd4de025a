//! The grid of a continuum scene: generated from `[grid]` or read from a mesh file, and
//! the cell selections of `[[region]]`.

use porofrac_grid::generate::tetrahedralize;
use porofrac_grid::generate::{
    CompositeSpec, Diagonals, RoundWellSpec, cartesian, composite, extrude, perturb, round_well,
    simplices, voronoi,
};
use porofrac_grid::io::grdecl::{CornerPointGrid, DeckLimit, check_cell_properties, fault_faces};
use porofrac_grid::io::{read_grdecl_with, read_msh, read_vtu};
use porofrac_grid::{Grid, GridError, Point};

use crate::common::loaded::{LoadedScene, k};
use crate::common::model::RunError;
use crate::common::sections::{CellCount, DiagonalsChoice, GridKind, Select};

/// What a grid read from a corner-point deck brings besides its cells: each cell's
/// `(i, j, k)` (0-based) and the deck's rock properties, per grid cell.
#[derive(Clone, Debug, Default)]
pub struct DeckCells {
    /// `(i, j, k)` of every cell; empty for other grids.
    pub ijk: Vec<[usize; 3]>,
    /// Porosity from `PORO`, times `NTG` and `MULTPV` where given (the pore volume).
    pub porosity: Option<Vec<f64>>,
    /// `[PERMX, PERMY, PERMZ]` (m²); `NTG` multiplies the horizontal ones. `PERMY`
    /// defaults to `PERMX`, `PERMZ` to `PERMX` too.
    pub permeability: Option<Vec<[f64; 3]>>,
    /// Transmissibility multipliers of the deck's faults (`FAULTS` + `MULTFLT`): the
    /// faces of each fault and its multiplier.
    pub fault_multipliers: Vec<(Vec<usize>, f64)>,
}

impl DeckCells {
    fn from_deck(deck: &porofrac_grid::io::grdecl::Deck, cp: &CornerPointGrid) -> Self {
        let p = &deck.properties;
        let at =
            |v: &Option<Vec<f64>>, d: usize, default: f64| v.as_ref().map_or(default, |v| v[d]);
        let porosity = p.poro.as_ref().map(|poro| {
            cp.deck_cell
                .iter()
                .map(|&d| poro[d] * at(&p.ntg, d, 1.0) * at(&p.multpv, d, 1.0))
                .collect()
        });
        let permeability = p.perm[0].as_ref().map(|kx| {
            cp.deck_cell
                .iter()
                .map(|&d| {
                    let ntg = at(&p.ntg, d, 1.0);
                    let ky = at(&p.perm[1], d, kx[d]);
                    let kz = at(&p.perm[2], d, kx[d]);
                    [kx[d] * ntg, ky * ntg, kz]
                })
                .collect()
        });
        Self {
            ijk: cp.ijk.clone(),
            porosity,
            permeability,
            fault_multipliers: Vec::new(),
        }
    }
}

/// A grid of either dimension.
pub enum AnyGrid {
    /// 2D.
    Two(Grid<2>),
    /// 3D.
    Three(Grid<3>),
}

/// A point from a checked slice of D coordinates.
pub(crate) fn point<const D: usize>(v: &[f64]) -> Point<D> {
    Point::<D>::from_fn(|i, _| v[i])
}

/// Build (or read) the grid of a checked scene.
pub fn build_grid(ls: &LoadedScene) -> Result<(AnyGrid, DeckCells), RunError> {
    let g = &ls.scene.grid;
    if g.kind == GridKind::File {
        let path = ls.resolve(g.path.as_deref().unwrap_or(""));
        let is_deck = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("grdecl") || e.eq_ignore_ascii_case("data"));
        if is_deck {
            let at_path = |e: GridError| {
                RunError::Scene(ls.error(
                    &k(&["grid", "path"]),
                    format!("= \"{}\": {e}", path.display()),
                ))
            };
            if ls.scene.scene.dim != 3 {
                return Err(ls
                    .error(&k(&["grid", "path"]), "a corner-point deck needs dim = 3")
                    .into());
            }
            let limit =
                crate::common::limits::machine_memory().map_or_else(DeckLimit::default, |m| {
                    DeckLimit {
                        cells: (m / crate::common::limits::BYTES_PER_DECK_CELL) as usize,
                        why: format!(
                            "a corner-point grid and its run need about {} kB per deck cell; this \
                         machine has {} for a run",
                            crate::common::limits::BYTES_PER_DECK_CELL / 1000,
                            crate::common::limits::bytes_text(m as f64)
                        ),
                    }
                });
            let (deck, cp) = read_grdecl_with(&path, &limit).map_err(at_path)?;
            if ls.scene.physics.flow == Some(true) {
                check_cell_properties(&deck, &cp).map_err(at_path)?;
            }
            let cells = DeckCells::from_deck(&deck, &cp);
            let (grid, mut cells) = with_mdem_zone(ls, cp.grid, cells)?;
            if let AnyGrid::Three(g3) = &grid {
                // Fault faces of the grid as it is now (zone faces split).
                cells.fault_multipliers = deck
                    .fault_multipliers
                    .iter()
                    .map(|(name, m)| (fault_faces(g3, &cells.ijk, &deck.faults, name), *m))
                    .collect();
            }
            return Ok((grid, cells));
        }
    }
    let grid = build_plain_grid(ls)?;
    match (grid, &g.mdem_zone) {
        (AnyGrid::Three(g3), Some(_)) => with_mdem_zone(ls, g3, DeckCells::default()),
        (grid, _) => Ok((grid, DeckCells::default())),
    }
}

/// Replace the cells of `[grid] mdem_zone` by conforming tetrahedra (refined `refine`
/// times, tagged `refined`), tag those within `well_radius` of `well_path` `well`, and
/// give the new cells their parents' deck data.
fn with_mdem_zone(
    ls: &LoadedScene,
    grid: Grid<3>,
    deck: DeckCells,
) -> Result<(AnyGrid, DeckCells), RunError> {
    let g = &ls.scene.grid;
    let Some(sel) = &g.mdem_zone else {
        return Ok((AnyGrid::Three(grid), deck));
    };
    let zone = select_cells(ls, &k(&["grid", "mdem_zone"]), &grid, &deck, sel)?;
    let levels = g.refine.unwrap_or(0).max(0) as usize;
    let t = tetrahedralize(&grid, &zone, levels)
        .map_err(|e| RunError::Scene(ls.error(&k(&["grid", "mdem_zone"]), e.to_string())))?;
    let mut out = t.grid;
    if let (Some(path), Some(r)) = (&g.well_path, g.well_radius) {
        let path: Vec<Point<3>> = path.iter().map(|p| point(p)).collect();
        let well: Vec<usize> = out.cell_tags()[porofrac_grid::generate::REFINED_TAG]
            .iter()
            .copied()
            .filter(|&c| distance_to_path(out.cell_centroid(c), &path) <= r)
            .collect();
        if well.is_empty() {
            return Err(ls
                .error(
                    &k(&["grid", "well_radius"]),
                    format!(
                        "= {r}: no tetrahedron of the zone has its centroid that close to well_path"
                    ),
                )
                .into());
        }
        let tag = g.well_tag.clone().unwrap_or_else(|| "well".into());
        out.set_cell_tag(tag, well).map_err(RunError::Grid)?;
    }
    let by_parent = |v: &[[usize; 3]]| t.parent.iter().map(|&p| v[p]).collect::<Vec<_>>();
    let deck = DeckCells {
        ijk: if deck.ijk.is_empty() {
            Vec::new()
        } else {
            by_parent(&deck.ijk)
        },
        porosity: deck
            .porosity
            .map(|v| t.parent.iter().map(|&p| v[p]).collect()),
        permeability: deck
            .permeability
            .map(|v| t.parent.iter().map(|&p| v[p]).collect()),
        fault_multipliers: Vec::new(),
    };
    Ok((AnyGrid::Three(out), deck))
}

/// Build (or read) a grid that is not a corner-point deck.
fn build_plain_grid(ls: &LoadedScene) -> Result<AnyGrid, RunError> {
    let g = &ls.scene.grid;
    let d = ls.scene.scene.dim as usize;
    let seed = g.seed.unwrap_or(0);
    let per_axis = || match &g.cells {
        Some(CellCount::PerAxis(v)) => v.iter().map(|&n| n as usize).collect::<Vec<_>>(),
        _ => vec![],
    };
    let ext = g
        .extent
        .clone()
        .unwrap_or_else(|| [vec![0.0; d], vec![1.0; d]]);
    let at_grid = |e: GridError| {
        RunError::Scene(ls.error(
            &k(&["grid", "kind"]),
            format!("= \"{}\": {e}", g.kind.as_str()),
        ))
    };
    let grid = match (d, g.kind) {
        (2, GridKind::Cartesian) => {
            let n = per_axis();
            AnyGrid::Two(cartesian(point(&ext[0]), point(&ext[1]), [n[0], n[1]]).map_err(at_grid)?)
        }
        (3, GridKind::Cartesian) => {
            let n = per_axis();
            AnyGrid::Three(
                cartesian(point(&ext[0]), point(&ext[1]), [n[0], n[1], n[2]]).map_err(at_grid)?,
            )
        }
        (2, GridKind::Triangles) => {
            let n = per_axis();
            AnyGrid::Two(simplices(point(&ext[0]), point(&ext[1]), [n[0], n[1]]).map_err(at_grid)?)
        }
        (3, GridKind::Tetrahedra) => {
            let n = per_axis();
            AnyGrid::Three(
                simplices(point(&ext[0]), point(&ext[1]), [n[0], n[1], n[2]]).map_err(at_grid)?,
            )
        }
        (2, GridKind::Voronoi) => {
            let n = match &g.cells {
                Some(CellCount::One(n)) => *n as usize,
                _ => 0,
            };
            let lloyd = g.lloyd.map_or(porofrac_grid::generate::DEFAULT_LLOYD, |l| {
                l.max(0) as usize
            });
            AnyGrid::Two(voronoi(point(&ext[0]), point(&ext[1]), n, seed, lloyd).map_err(at_grid)?)
        }
        (_, GridKind::Composite) => {
            // 2D: the composite grid; 3D: the same in x, y, extruded over cells[2] layers
            // (tetrahedra from the triangles, polygonal prisms from the far field).
            let n = per_axis();
            let c = g.center.clone().unwrap_or_default();
            if c.len() != 2 {
                return Err(ls
                    .error(&k(&["grid", "center"]), "must have 2 components")
                    .into());
            }
            let mut spec = CompositeSpec::new(
                point(&ext[0][..2]),
                point(&ext[1][..2]),
                [n[0], n[1]],
                point(&c),
                g.zone_half_width.unwrap_or(0.0),
                g.refine.unwrap_or(0).max(0) as usize,
                g.well_radius.unwrap_or(0.0),
            );
            if let Some(t) = &g.well_tag {
                spec.well_tag = t.clone();
            }
            if g.diagonals == Some(DiagonalsChoice::Alternating) {
                spec.diagonals = Diagonals::Alternating;
            }
            spec.perturb = g.perturb.unwrap_or(0.0);
            spec.seed = seed;
            // The jitter applies to the refined zone only; see docs/grid.md.
            let g2 = composite(&spec).map_err(at_grid)?;
            if d == 2 {
                return Ok(AnyGrid::Two(g2));
            }
            return Ok(AnyGrid::Three(
                extrude(&g2, &z_levels(ext[0][2], ext[1][2], n[2])).map_err(at_grid)?,
            ));
        }
        (_, GridKind::RoundWell) => {
            // 2D: the round-well grid; 3D: the same in x, y, extruded over cells[2] layers
            // (a vertical cylinder of tetrahedra in polygonal prisms).
            let n = per_axis();
            let c = g.center.clone().unwrap_or_default();
            let mut spec = RoundWellSpec::new(
                point(&ext[0][..2]),
                point(&ext[1][..2]),
                [n[0], n[1]],
                point(&c),
                g.zone_half_width.unwrap_or(0.0),
                g.refine.unwrap_or(0).max(0) as usize,
                g.well_radius.unwrap_or(0.0),
            );
            spec.well_size = g.well_size;
            if let Some(t) = &g.well_tag {
                spec.well_tag = t.clone();
            }
            let g2 = round_well(&spec).map_err(at_grid)?;
            return Ok(if d == 2 {
                AnyGrid::Two(g2)
            } else {
                AnyGrid::Three(
                    extrude(&g2, &z_levels(ext[0][2], ext[1][2], n[2])).map_err(at_grid)?,
                )
            });
        }
        (_, GridKind::File) => {
            let path = ls.resolve(g.path.as_deref().unwrap_or(""));
            let is_vtu = path.extension().is_some_and(|e| e == "vtu");
            let at_path = |e: GridError| {
                RunError::Scene(ls.error(
                    &k(&["grid", "path"]),
                    format!("= \"{}\": {e}", path.display()),
                ))
            };
            return Ok(match (d, is_vtu) {
                (2, true) => AnyGrid::Two(read_vtu(&path).map_err(at_path)?),
                (2, false) => AnyGrid::Two(read_msh(&path).map_err(at_path)?),
                (_, true) => AnyGrid::Three(read_vtu(&path).map_err(at_path)?),
                (_, false) => AnyGrid::Three(read_msh(&path).map_err(at_path)?),
            });
        }
        (_, kind) => {
            return Err(ls
                .error(
                    &k(&["grid", "kind"]),
                    format!("= \"{}\" is not available in {d}D", kind.as_str()),
                )
                .into());
        }
    };
    let amp = g.perturb.unwrap_or(0.0);
    if amp > 0.0 {
        let at_perturb = |e: GridError| {
            RunError::Scene(ls.error(&k(&["grid", "perturb"]), format!("= {amp}: {e}")))
        };
        return Ok(match grid {
            AnyGrid::Two(gr) => AnyGrid::Two(perturb(&gr, amp, seed).map_err(at_perturb)?),
            AnyGrid::Three(gr) => AnyGrid::Three(perturb(&gr, amp, seed).map_err(at_perturb)?),
        });
    }
    Ok(grid)
}

/// Distance from `x` to the polyline through `path`.
pub(crate) fn distance_to_path<const D: usize>(x: &Point<D>, path: &[Point<D>]) -> f64 {
    if path.len() == 1 {
        return (x - path[0]).norm();
    }
    path.windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let ab = b - a;
            let t = if ab.norm_squared() > 0.0 {
                ((x - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (x - (a + ab * t)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Which cells a selection picks (by centroid).
pub(crate) fn select_cells<const D: usize>(
    ls: &LoadedScene,
    key: &[crate::common::sections::KeyPart],
    grid: &Grid<D>,
    deck: &DeckCells,
    sel: &Select,
) -> Result<Vec<usize>, RunError> {
    let centroids = grid.cell_centroids();
    let pick = |f: &dyn Fn(&Point<D>) -> bool| -> Vec<usize> {
        (0..grid.num_cells())
            .filter(|&c| f(&centroids[c]))
            .collect()
    };
    let cells = match sel {
        Select::All(_) => (0..grid.num_cells()).collect(),
        Select::Box(b) => pick(&|x| (0..D).all(|a| x[a] >= b[0][a] && x[a] <= b[1][a])),
        Select::Circle(ball) | Select::Sphere(ball) => {
            let c: Point<D> = point(&ball.center);
            pick(&|x| (x - c).norm() <= ball.radius)
        }
        Select::Ijk(r) => {
            if deck.ijk.is_empty() {
                return Err(ls
                    .error(
                        key,
                        "= { ijk = … } needs a grid read from a corner-point deck",
                    )
                    .into());
            }
            let inside =
                |c: &[usize; 3]| (0..3).all(|a| (r[a][0]..=r[a][1]).contains(&(c[a] as u64 + 1)));
            (0..grid.num_cells())
                .filter(|&c| inside(&deck.ijk[c]))
                .collect()
        }
        Select::Around(pb) => {
            let path: Vec<Point<D>> = pb.path.iter().map(|p| point(p)).collect();
            pick(&|x| distance_to_path(x, &path) <= pb.radius)
        }
        Select::Tag(name) => {
            match grid.cell_tags().get(name) {
                Some(v) => v.clone(),
                None => {
                    let known: Vec<_> = grid.cell_tags().keys().cloned().collect();
                    return Err(ls
                    .error(key, format!("= {{ tag = \"{name}\" }}: the grid has no such cell tag (known: {})", if known.is_empty() { "none".into() } else { known.join(", ") }))
                    .into());
                }
            }
        }
    };
    if cells.is_empty() {
        return Err(ls
            .error(
                key,
                "selects no cell (cells are selected by their centroid)",
            )
            .into());
    }
    Ok(cells)
}

/// `nz + 1` equally spaced z levels from `z0` to exactly `z1`.
fn z_levels(z0: f64, z1: f64, nz: usize) -> Vec<f64> {
    (0..=nz)
        .map(|i| {
            if i == nz {
                z1
            } else {
                z0 + (z1 - z0) * i as f64 / nz as f64
            }
        })
        .collect()
}
