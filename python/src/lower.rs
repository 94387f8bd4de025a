//! Lower-level access for people who extend porofrac: grids read or generated without a
//! scene (`porofrac.grid`) and the local stiffness matrices of the cell laws
//! (`porofrac.laws`). Grids come back in the same VTK terms as a run's grid (the
//! scene crate's [`Mesh`] conversion) plus cell volumes and centroids; matrices come
//! back in the caller's node order, `D` rows per node (x, y[, z]).

use std::path::PathBuf;

use nalgebra::DMatrix;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use porofrac_grid::generate::{DEFAULT_LLOYD, cartesian, simplices, voronoi};
use porofrac_grid::io::grdecl::DeckLimit;
use porofrac_grid::io::{read_grdecl_with, read_msh, read_vtu};
use porofrac_grid::{CellFaceLoops, Grid, Point};
use porofrac_law::{CellLaw, GeometryBuffer, Scratch, Stiffness};
use porofrac_mdem::{DemLaw, DemMode, MdemLaw};
use porofrac_scene::common::limits;
use porofrac_scene::common::snapshot::Mesh;
use porofrac_vem::VemLaw;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::mesh_dict;

/// Most nodes of one cell whose local matrix is built (a `3n × 3n` matrix of 1024 nodes
/// is 75 MB).
const MAX_CELL_NODES: usize = 1024;

fn value_error(what: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(what.to_string())
}

/// The grid dict of `grid`: the run grid's keys plus `volumes` and `centroids`.
fn grid_dict<'py, const D: usize>(py: Python<'py>, grid: &Grid<D>) -> PyResult<Bound<'py, PyDict>> {
    let d = mesh_dict(py, Mesh::of(grid))?;
    d.set_item("volumes", PyArray1::from_slice(py, grid.cell_volumes()))?;
    let centroids: Vec<f64> = grid
        .cell_centroids()
        .iter()
        .flat_map(|c| c.iter().copied().collect::<Vec<_>>())
        .collect();
    let n = centroids.len() / D;
    d.set_item(
        "centroids",
        PyArray1::from_vec(py, centroids).reshape([n, D])?,
    )?;
    Ok(d)
}

/// Read a grid file as a `[grid] kind = "file"` scene does: Gmsh `.msh` and VTK `.vtu`
/// meshes (of dimension `dim`), corner-point decks (`.grdecl`, `.data`; 3D).
#[pyfunction]
#[pyo3(signature = (path, dim = None))]
pub fn grid_read(py: Python<'_>, path: PathBuf, dim: Option<usize>) -> PyResult<Py<PyDict>> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let shown = path.display().to_string();
    // The readers name the file (and the line) in most of their errors.
    let at = |e: porofrac_grid::GridError| {
        let m = e.to_string();
        value_error(if m.contains(&shown) {
            m
        } else {
            format!("grid file \"{shown}\": {m}")
        })
    };
    let deck = ext == "grdecl" || ext == "data";
    let dim = match (dim, deck) {
        (None | Some(3), true) => 3,
        (Some(d), true) => {
            return Err(value_error(format!(
                "dim = {d}: a corner-point deck (\"{shown}\") is 3D"
            )));
        }
        (Some(d @ (2 | 3)), false) => d,
        (Some(d), false) => return Err(value_error(format!("dim = {d}: must be 2 or 3"))),
        (None, false) => {
            return Err(value_error(format!(
                "dim: give 2 or 3 for the mesh \"{shown}\" (the scene's `scene.dim`)"
            )));
        }
    };
    if deck {
        let limit = limits::machine_memory().map_or_else(DeckLimit::default, |m| DeckLimit {
            cells: (m / limits::BYTES_PER_DECK_CELL) as usize,
            why: format!(
                "a corner-point grid needs about {} kB per deck cell; this machine has {}",
                limits::BYTES_PER_DECK_CELL / 1000,
                limits::bytes_text(m as f64)
            ),
        });
        let (_, cp) = py.detach(|| read_grdecl_with(&path, &limit)).map_err(at)?;
        return Ok(grid_dict(py, &cp.grid)?.unbind());
    }
    let vtu = ext == "vtu";
    let d = match (dim, vtu) {
        (2, true) => grid_dict(py, &py.detach(|| read_vtu::<2>(&path)).map_err(at)?)?,
        (2, false) => grid_dict(py, &py.detach(|| read_msh::<2>(&path)).map_err(at)?)?,
        (_, true) => grid_dict(py, &py.detach(|| read_vtu::<3>(&path)).map_err(at)?)?,
        (_, false) => grid_dict(py, &py.detach(|| read_msh::<3>(&path)).map_err(at)?)?,
    };
    Ok(d.unbind())
}

/// Refuse a generated grid of more cells than a run could hold, before allocating it.
fn check_count(what: &str, cells: &[usize]) -> PyResult<()> {
    let total = cells
        .iter()
        .try_fold(1u64, |a, &n| a.checked_mul(n as u64))
        .filter(|&t| t <= limits::MAX_CELLS);
    let Some(total) = total else {
        return Err(value_error(format!(
            "{what}: {cells:?} cells is more than the {} a grid may have",
            limits::MAX_CELLS
        )));
    };
    let per_cell = if cells.len() == 3 {
        limits::BYTES_PER_ITEM_3D
    } else {
        limits::BYTES_PER_ITEM
    };
    if let Some(m) = limits::machine_memory()
        && total.saturating_mul(per_cell) > m
    {
        return Err(value_error(format!(
            "{what}: {total} cells need about {}; this machine has {}",
            limits::bytes_text(total as f64 * per_cell as f64),
            limits::bytes_text(m as f64)
        )));
    }
    Ok(())
}

/// A box's corners and cell counts, checked: `D` finite coordinates each, `lo < hi`,
/// `D` counts ≥ 1.
fn box_of<const D: usize>(
    lo: &[f64],
    hi: &[f64],
    cells: &[usize],
) -> PyResult<(Point<D>, Point<D>, [usize; D])> {
    if lo.len() != D || hi.len() != D {
        return Err(value_error(format!(
            "lo, hi: need {D} coordinates each (m), got {} and {}",
            lo.len(),
            hi.len()
        )));
    }
    if lo.iter().chain(hi).any(|x| !x.is_finite()) || lo.iter().zip(hi).any(|(a, b)| a >= b) {
        return Err(value_error(format!(
            "lo = {lo:?}, hi = {hi:?}: need finite coordinates with lo < hi on every axis"
        )));
    }
    if cells.contains(&0) {
        return Err(value_error(format!(
            "cells = {cells:?}: need at least 1 cell on every axis"
        )));
    }
    let mut n = [0; D];
    n.copy_from_slice(cells);
    Ok((
        Point::<D>::from_column_slice(lo),
        Point::<D>::from_column_slice(hi),
        n,
    ))
}

/// The box grid of [`grid_box`] in `D` dimensions, generated without the GIL.
fn box_grid<'py, const D: usize>(
    py: Python<'py>,
    lo: &[f64],
    hi: &[f64],
    cells: &[usize],
    simplex: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (lo, hi, n) = box_of::<D>(lo, hi, cells)?;
    let g = py
        .detach(|| {
            if simplex {
                simplices(lo, hi, n)
            } else {
                cartesian(lo, hi, n)
            }
        })
        .map_err(|e| value_error(format!("grid: {e}")))?;
    grid_dict(py, &g)
}

/// A generated box grid: `kind` `cartesian` (squares/cubes) or `simplices`
/// (triangles/tetrahedra), of `cells` cells per axis (2 or 3 axes).
#[pyfunction]
pub fn grid_box(
    py: Python<'_>,
    kind: &str,
    lo: Vec<f64>,
    hi: Vec<f64>,
    cells: Vec<usize>,
) -> PyResult<Py<PyDict>> {
    check_count("cells", &cells)?;
    let simplex = match kind {
        "cartesian" => false,
        "simplices" => true,
        k => return Err(value_error(format!("kind = {k:?}: not a box grid"))),
    };
    let d = match cells.len() {
        2 => box_grid::<2>(py, &lo, &hi, &cells, simplex)?,
        3 => box_grid::<3>(py, &lo, &hi, &cells, simplex)?,
        n => {
            return Err(value_error(format!(
                "cells: give 2 or 3 counts (one per axis), got {n}"
            )));
        }
    };
    Ok(d.unbind())
}

/// A 2D centroidal Voronoi grid of `cells` cells on the box `[lo, hi]` (random seeds
/// from `seed`, `lloyd` Lloyd iterations).
#[pyfunction]
#[pyo3(signature = (lo, hi, cells, seed = 0, lloyd = DEFAULT_LLOYD))]
pub fn grid_voronoi(
    py: Python<'_>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    cells: usize,
    seed: u64,
    lloyd: usize,
) -> PyResult<Py<PyDict>> {
    check_count("cells", &[cells])?;
    let (lo, hi, _) = box_of::<2>(&lo, &hi, &[1, 1])?;
    let g = py
        .detach(|| voronoi(lo, hi, cells, seed, lloyd))
        .map_err(|e| value_error(format!("grid: {e}")))?;
    Ok(grid_dict(py, &g)?.unbind())
}

/// Node coordinates from an `(n, D)` array, checked: finite, at most [`MAX_CELL_NODES`].
fn points_of<const D: usize>(points: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<Point<D>>> {
    let n = points.shape()[0];
    if n > MAX_CELL_NODES {
        return Err(value_error(format!(
            "points: {n} nodes; a cell may have at most {MAX_CELL_NODES}"
        )));
    }
    let a = points.as_array();
    let p: Vec<Point<D>> = (0..n)
        .map(|i| Point::<D>::from_fn(|k, _| a[[i, k]]))
        .collect();
    if p.iter().any(|x| x.iter().any(|v| !v.is_finite())) {
        return Err(value_error("points: every coordinate must be finite"));
    }
    Ok(p)
}

/// The stiffness of `law` on the one cell of `grid`, rows and columns in the order of
/// the grid's nodes (the caller's points), `D` per node, as an `(n·D, n·D)` array.
fn local_matrix<'py, const D: usize>(
    py: Python<'py>,
    grid: &Grid<D>,
    law: &dyn CellLaw<D>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut buf = GeometryBuffer::<D>::default();
    let cell = buf.load(grid, 0);
    let order = grid.cell_nodes(0).to_vec();
    let m = D * order.len();
    let mut k = DMatrix::<f64>::zeros(m, m);
    law.stiffness(&cell, &vec![0.0; m], &mut k, &mut Scratch::default())
        .map_err(|e| value_error(format!("cell law {}: {e}", law.name())))?;
    let nn = grid.num_nodes();
    let mut out = vec![0.0; D * nn * D * nn];
    for (p, &a) in order.iter().enumerate() {
        for (q, &b) in order.iter().enumerate() {
            for i in 0..D {
                for j in 0..D {
                    out[(D * a + i) * D * nn + D * b + j] = k[(D * p + i, D * q + j)];
                }
            }
        }
    }
    Ok(PyArray1::from_vec(py, out)
        .reshape([D * nn, D * nn])?
        .into_any())
}

/// The isotropic 2D material of `E` (Pa) and `nu`: plane strain unless `plane_stress`.
fn material_2(e: f64, nu: f64, plane_stress: bool) -> PyResult<Stiffness<2>> {
    let m = if plane_stress {
        Stiffness::<2>::isotropic_plane_stress(e, nu)
    } else {
        Stiffness::<2>::isotropic(e, nu)
    };
    m.map_err(|err| value_error(format!("E = {e}, nu = {nu}: {err}")))
}

/// The isotropic 3D material of `E` (Pa) and `nu`.
fn material_3(e: f64, nu: f64, plane_stress: bool) -> PyResult<Stiffness<3>> {
    if plane_stress {
        return Err(value_error("plane_stress: only for 2D cells"));
    }
    Stiffness::<3>::isotropic(e, nu)
        .map_err(|err| value_error(format!("E = {e}, nu = {nu}: {err}")))
}

/// The one-cell grid of a polygon (2D: `cell` the counter-clockwise node order, or all
/// points in order) or a polyhedron (3D: `faces`, outward loops).
fn one_cell_2(points: Vec<Point<2>>, polygon: Option<Vec<usize>>) -> PyResult<Grid<2>> {
    let n = points.len();
    let poly = polygon.unwrap_or_else(|| (0..n).collect());
    Grid::<2>::from_polygons(points, &[0, poly.len()], &poly)
        .map_err(|e| value_error(format!("cell: {e}")))
}

fn one_cell_3(points: Vec<Point<3>>, faces: &[Vec<usize>]) -> PyResult<Grid<3>> {
    let mut loops = CellFaceLoops::new();
    for f in faces {
        loops.push_face(f);
    }
    loops.finish_cell();
    Grid::<3>::from_cell_faces(points, &loops).map_err(|e| value_error(format!("cell: {e}")))
}

/// The local VEM stiffness of one cell (MRST's stabilization, scale 1).
#[pyfunction]
#[pyo3(signature = (points, cell, e, nu, plane_stress))]
pub fn vem_stiffness<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    cell: Option<Vec<Vec<usize>>>,
    e: f64,
    nu: f64,
    plane_stress: bool,
) -> PyResult<Bound<'py, PyAny>> {
    match points.shape()[1] {
        2 => {
            let polygon = match cell {
                None => None,
                Some(mut c) if c.len() == 1 => Some(c.remove(0)),
                Some(_) => return Err(value_error("cell: a 2D cell is one polygon")),
            };
            let g = one_cell_2(points_of::<2>(&points)?, polygon)?;
            let law = VemLaw::new(material_2(e, nu, plane_stress)?);
            local_matrix(py, &g, &law)
        }
        3 => {
            let Some(faces) = cell else {
                return Err(value_error(
                    "faces: a 3D cell needs its faces (outward loops of node indices)",
                ));
            };
            let g = one_cell_3(points_of::<3>(&points)?, &faces)?;
            let law = VemLaw::new(material_3(e, nu, plane_stress)?);
            local_matrix(py, &g, &law)
        }
        d => Err(value_error(format!(
            "points: need shape (n, 2) or (n, 3), got (n, {d})"
        ))),
    }
}

/// The one-cell grid of the simplex `points` (any order and orientation).
fn simplex_2(points: Vec<Point<2>>) -> PyResult<Grid<2>> {
    let (a, b, c) = (points[0], points[1], points[2]);
    let ccw = (b - a).perp(&(c - a)) > 0.0;
    one_cell_2(
        points,
        Some(if ccw { vec![0, 1, 2] } else { vec![0, 2, 1] }),
    )
}

fn simplex_3(points: Vec<Point<3>>) -> PyResult<Grid<3>> {
    let p = &points;
    let positive = (p[1] - p[0]).cross(&(p[2] - p[0])).dot(&(p[3] - p[0])) > 0.0;
    let mut faces = vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]];
    if !positive {
        faces.iter_mut().for_each(|f| f.reverse());
    }
    one_cell_3(points, &faces)
}

/// The local stiffness of the MDEM law (`dem = false`) or the central-force DEM law
/// (`dem = true`, all edges acting) on a simplex.
#[pyfunction]
#[pyo3(signature = (points, e, nu, plane_stress, dem))]
pub fn simplex_stiffness<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    e: f64,
    nu: f64,
    plane_stress: bool,
    dem: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let [n, d] = [points.shape()[0], points.shape()[1]];
    if !(d == 2 || d == 3) || n != d + 1 {
        return Err(value_error(format!(
            "points: a simplex needs shape (3, 2) or (4, 3), got ({n}, {d})"
        )));
    }
    let at = |e: porofrac_mdem::MdemError| value_error(e.to_string());
    if d == 2 {
        let g = simplex_2(points_of::<2>(&points)?)?;
        let m = material_2(e, nu, plane_stress)?;
        if dem {
            local_matrix(py, &g, &DemLaw::new(&m, DemMode::Elastic).map_err(at)?)
        } else {
            local_matrix(py, &g, &MdemLaw::new(&m).map_err(at)?)
        }
    } else {
        let g = simplex_3(points_of::<3>(&points)?)?;
        let m = material_3(e, nu, plane_stress)?;
        if dem {
            local_matrix(py, &g, &DemLaw::new(&m, DemMode::Elastic).map_err(at)?)
        } else {
            local_matrix(py, &g, &MdemLaw::new(&m).map_err(at)?)
        }
    }
}
