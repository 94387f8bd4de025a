//! The grid of a continuum scene: generated from `[grid]` or read from a mesh file, and
//! the cell selections of `[[region]]`.

use porofrac_grid::generate::{
    CompositeSpec, Diagonals, cartesian, composite, extrude, perturb, simplices, voronoi,
};
use porofrac_grid::io::{read_msh, read_vtu};
use porofrac_grid::{Grid, GridError, Point};

use crate::check::{LoadedScene, k, ki};
use crate::file::{CellCount, DiagonalsChoice, GridKind, Select};
use crate::model::RunError;

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
pub fn build_grid(ls: &LoadedScene) -> Result<AnyGrid, RunError> {
    let g = ls.scene.grid.as_ref().expect("checked: [grid] is required");
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
            let (z0, z1, nz) = (ext[0][2], ext[1][2], n[2]);
            let levels: Vec<f64> = (0..=nz)
                .map(|i| {
                    if i == nz {
                        z1
                    } else {
                        z0 + (z1 - z0) * i as f64 / nz as f64
                    }
                })
                .collect();
            return Ok(AnyGrid::Three(extrude(&g2, &levels).map_err(at_grid)?));
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

/// Which cells a selection picks (by centroid).
pub(crate) fn select_cells<const D: usize>(
    ls: &LoadedScene,
    i: usize,
    grid: &Grid<D>,
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
        Select::Tag(name) => {
            match grid.cell_tags().get(name) {
                Some(v) => v.clone(),
                None => {
                    let known: Vec<_> = grid.cell_tags().keys().cloned().collect();
                    return Err(ls
                    .error(&ki("region", i, &["select"]), format!("= {{ tag = \"{name}\" }}: the grid has no such cell tag (known: {})", if known.is_empty() { "none".into() } else { known.join(", ") }))
                    .into());
                }
            }
        }
    };
    if cells.is_empty() {
        return Err(ls
            .error(
                &ki("region", i, &["select"]),
                "selects no cell (cells are selected by their centroid)",
            )
            .into());
    }
    Ok(cells)
}
