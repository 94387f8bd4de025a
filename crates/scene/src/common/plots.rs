//! PNG plots a person looks at first: cell and nodal fields of 2D scenes (with fractured
//! cells outlined, optionally zoomed and with principal directions) and probe time series. Text uses the bundled DejaVu Sans font, so no system
//! font library is needed.

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use porofrac_grid::Grid;

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        // The bundled font is a valid TrueType file; failing here is a build defect.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../../assets/DejaVuSans.ttf"),
        );
    });
}

/// A plotting error (file and cause).
#[derive(Debug, thiserror::Error)]
#[error("{}: {what}", path.display())]
pub struct PlotError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong.
    pub what: String,
}

/// Draw a PNG at a temporary path beside `path` and move it over `path`
/// ([`porofrac_vtk::write_atomic_via`], the one atomic write of every output): a reader
/// sees the old picture or the new one, never a part of either. `fail` turns a failed
/// move into the caller's error; a drawing error is returned as it is.
pub(crate) fn atomic_png<E>(
    path: &Path,
    draw: impl FnOnce(&Path) -> Result<(), E>,
    fail: impl FnOnce(String) -> E,
) -> Result<(), E> {
    let mut drawing_error = None;
    let moved = porofrac_vtk::write_atomic_via(path, |tmp| {
        draw(tmp).map_err(|e| {
            drawing_error = Some(e);
            std::io::Error::other("drawing failed")
        })
    });
    match (drawing_error, moved) {
        (Some(e), _) => Err(e),
        (None, Ok(())) => Ok(()),
        (None, Err(porofrac_vtk::VtkError::Io { source, .. })) => Err(fail(source.to_string())),
        (None, Err(e)) => Err(fail(e.to_string())),
    }
}

fn perr<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError {
        path: path.to_path_buf(),
        what: e.to_string(),
    }
}

/// Values of a 2D field: constant per cell, or one per node (drawn as the node's share of
/// each cell: the quadrilateral between the node, its edge midpoints and the centroid).
#[derive(Clone, Copy, Debug)]
pub enum Values<'a> {
    /// One value per cell.
    Cell(&'a [f64]),
    /// One value per node.
    Nodal(&'a [f64]),
}

/// The polygons a field is drawn on: the cells of a 2D grid, or the cross-sections of
/// the cells of a 3D grid with a plane `z = const`.
#[derive(Clone, Debug)]
pub struct Canvas {
    polygons: Vec<Vec<(f64, f64)>>,
    /// The cell of each polygon.
    cells: Vec<usize>,
    /// The grid node of each polygon vertex (2D grids only; nodal values need it).
    nodes: Option<Vec<Vec<usize>>>,
}

impl Canvas {
    /// The cells of a 2D grid.
    pub fn of_grid(grid: &Grid<2>) -> Self {
        let xy = |n: usize| (grid.node(n)[0], grid.node(n)[1]);
        Self {
            polygons: (0..grid.num_cells())
                .map(|c| grid.cell_nodes(c).iter().map(|&n| xy(n)).collect())
                .collect(),
            cells: (0..grid.num_cells()).collect(),
            nodes: Some(
                (0..grid.num_cells())
                    .map(|c| grid.cell_nodes(c).to_vec())
                    .collect(),
            ),
        }
    }

    /// The cross-sections of the cells of a 3D grid with the plane `z = z0`: the points
    /// where the cells' edges cross the plane, ordered by angle about their mean (exact
    /// for convex cells).
    pub fn z_slice(grid: &Grid<3>, z0: f64) -> Self {
        let mut polygons = Vec::new();
        let mut cells = Vec::new();
        let mut pts: Vec<(f64, f64)> = Vec::new();
        for c in 0..grid.num_cells() {
            pts.clear();
            for &f in grid.cell_faces(c) {
                let loop_ = grid.face_nodes(f);
                let m = loop_.len();
                for i in 0..m {
                    let (a, b) = (grid.node(loop_[i]), grid.node(loop_[(i + 1) % m]));
                    let (da, db) = (a[2] - z0, b[2] - z0);
                    if da == 0.0 {
                        pts.push((a[0], a[1]));
                    } else if da * db < 0.0 {
                        let t = da / (da - db);
                        pts.push((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])));
                    }
                }
            }
            if pts.len() < 3 {
                continue;
            }
            let n = pts.len() as f64;
            let (mx, my) = (
                pts.iter().map(|p| p.0).sum::<f64>() / n,
                pts.iter().map(|p| p.1).sum::<f64>() / n,
            );
            pts.sort_by(|p, q| {
                (p.1 - my)
                    .atan2(p.0 - mx)
                    .total_cmp(&(q.1 - my).atan2(q.0 - mx))
            });
            let scale = pts
                .iter()
                .map(|p| (p.0 - mx).abs() + (p.1 - my).abs())
                .fold(0.0, f64::max);
            pts.dedup_by(|p, q| (p.0 - q.0).abs() + (p.1 - q.1).abs() <= 1e-12 * scale);
            if pts.len() >= 3 {
                polygons.push(pts.clone());
                cells.push(c);
            }
        }
        Self {
            polygons,
            cells,
            nodes: None,
        }
    }

    /// Whether the canvas has no polygon.
    pub fn is_empty(&self) -> bool {
        self.polygons.is_empty()
    }

    fn bounding_box(&self) -> ([f64; 2], [f64; 2]) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in self.polygons.iter().flatten() {
            lo = [lo[0].min(p.0), lo[1].min(p.1)];
            hi = [hi[0].max(p.0), hi[1].max(p.1)];
        }
        (lo, hi)
    }
}

/// Centroid and area of a polygon.
fn centroid_area(p: &[(f64, f64)]) -> ((f64, f64), f64) {
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for i in 0..p.len() {
        let (q, r) = (p[i], p[(i + 1) % p.len()]);
        let w = q.0 * r.1 - r.0 * q.1;
        a += w;
        cx += (q.0 + r.0) * w;
        cy += (q.1 + r.1) * w;
    }
    if a.abs() < f64::MIN_POSITIVE {
        return (p[0], 0.0);
    }
    ((cx / (3.0 * a), cy / (3.0 * a)), 0.5 * a.abs())
}

/// What a field plot shows besides the values.
#[derive(Clone, Copy, Debug)]
pub struct FieldPlot<'a> {
    /// The polygons.
    pub canvas: &'a Canvas,
    /// The title.
    pub title: &'a str,
    /// Cells outlined in red (fractured cells).
    pub marked: &'a [bool],
    /// The region shown (`[x0, y0]`, `[x1, y1]`); `None`: the whole canvas. The colour
    /// range is that of the cells shown.
    pub window: Option<([f64; 2], [f64; 2])>,
    /// A unit direction per cell drawn as a short black segment through its centroid
    /// (principal directions), for the cells shown when they are at most 10 000.
    pub directions: Option<&'a [[f64; 2]]>,
}

impl<'a> FieldPlot<'a> {
    /// The whole canvas with fractured cells outlined.
    pub fn new(canvas: &'a Canvas, title: &'a str, marked: &'a [bool]) -> Self {
        Self {
            canvas,
            title,
            marked,
            window: None,
            directions: None,
        }
    }
}

/// Plot a field, colour-mapped (see [`FieldPlot`]); nodal values need a 2D grid's canvas.
pub fn field(path: &Path, plot: &FieldPlot<'_>, values: Values<'_>) -> Result<(), PlotError> {
    register_font();
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(perr(path))?;
    }
    let canvas = plot.canvas;
    let (lo, hi) = plot.window.unwrap_or_else(|| canvas.bounding_box());
    let shown: Vec<usize> = (0..canvas.polygons.len())
        .filter(|&k| {
            plot.window.is_none()
                || canvas.polygons[k]
                    .iter()
                    .any(|p| (lo[0]..=hi[0]).contains(&p.0) && (lo[1]..=hi[1]).contains(&p.1))
        })
        .collect();
    // Coloured pieces: (polygon, value).
    let mut pieces: Vec<(Vec<(f64, f64)>, f64)> = Vec::new();
    for &k in &shown {
        let pts = &canvas.polygons[k];
        match values {
            Values::Cell(v) => pieces.push((pts.clone(), v[canvas.cells[k]])),
            Values::Nodal(v) => {
                let Some(nodes) = &canvas.nodes else {
                    return Err(PlotError {
                        path: path.to_path_buf(),
                        what: "nodal values are drawn on 2D grids only".into(),
                    });
                };
                let nodes = &nodes[k];
                let m = pts.len();
                let (g, _) = centroid_area(pts);
                let mid = |a: (f64, f64), b: (f64, f64)| (0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1));
                for i in 0..m {
                    let (prev, next) = (pts[(i + m - 1) % m], pts[(i + 1) % m]);
                    pieces.push((
                        vec![pts[i], mid(pts[i], next), g, mid(prev, pts[i])],
                        v[nodes[i]],
                    ));
                }
            }
        }
    }
    let finite = pieces.iter().map(|p| p.1).filter(|v| v.is_finite());
    let vmin = finite.clone().fold(f64::INFINITY, f64::min);
    let vmax = finite.fold(f64::NEG_INFINITY, f64::max);
    let (vmin, vmax) = if vmin.is_finite() && vmax > vmin {
        (vmin, vmax)
    } else {
        (vmin.min(0.0) - 0.5, vmax.max(0.0) + 0.5)
    };
    atomic_png(
        path,
        |tmp| {
            let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
            let px_w = 900u32;
            let px_h = ((px_w as f64 - 160.0) * h / w + 120.0).clamp(300.0, 1400.0) as u32;
            let root = BitMapBackend::new(tmp, (px_w, px_h)).into_drawing_area();
            root.fill(&WHITE).map_err(perr(path))?;
            let (main, bar) = root.split_horizontally(px_w - 110);
            let mut chart = ChartBuilder::on(&main)
                .caption(plot.title, ("sans-serif", 22))
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(55)
                .build_cartesian_2d(lo[0]..hi[0], lo[1]..hi[1])
                .map_err(perr(path))?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc("x (m)")
                .y_desc("y (m)")
                .draw()
                .map_err(perr(path))?;
            let polys = pieces.into_iter().map(|(pts, v)| {
                let color = if v.is_finite() {
                    ViridisRGB::get_color_normalized(v, vmin, vmax)
                } else {
                    RGBColor(255, 0, 255)
                };
                Polygon::new(pts, color.filled())
            });
            chart.draw_series(polys).map_err(perr(path))?;
            let outlines = shown
                .iter()
                .filter(|&&k| plot.marked.get(canvas.cells[k]).copied().unwrap_or(false))
                .map(|&k| {
                    let mut pts = canvas.polygons[k].clone();
                    pts.push(pts[0]);
                    PathElement::new(pts, RED.stroke_width(2))
                });
            chart.draw_series(outlines).map_err(perr(path))?;
            if let Some(dirs) = plot.directions
                && shown.len() <= 10_000
            {
                let segments = shown.iter().map(|&k| {
                    let (g, area) = centroid_area(&canvas.polygons[k]);
                    let half = 0.35 * area.sqrt();
                    let d = dirs[canvas.cells[k]];
                    PathElement::new(
                        vec![
                            (g.0 - half * d[0], g.1 - half * d[1]),
                            (g.0 + half * d[0], g.1 + half * d[1]),
                        ],
                        BLACK.stroke_width(1),
                    )
                });
                chart.draw_series(segments).map_err(perr(path))?;
            }
            // Colour bar.
            let mut cb = ChartBuilder::on(&bar)
                .margin_top(40)
                .margin_bottom(45)
                .margin_right(10)
                .y_label_area_size(70)
                .build_cartesian_2d(0.0..1.0, vmin..vmax)
                .map_err(perr(path))?;
            cb.configure_mesh()
                .disable_mesh()
                .disable_x_axis()
                .y_label_style(("sans-serif", 13))
                .y_label_formatter(&|v| format!("{v:.3e}"))
                .draw()
                .map_err(perr(path))?;
            let steps = 100;
            cb.draw_series((0..steps).map(|i| {
                let a = vmin + (vmax - vmin) * i as f64 / steps as f64;
                let b = vmin + (vmax - vmin) * (i + 1) as f64 / steps as f64;
                Rectangle::new(
                    [(0.0, a), (1.0, b)],
                    ViridisRGB::get_color_normalized(a, vmin, vmax).filled(),
                )
            }))
            .map_err(perr(path))?;
            root.present().map_err(perr(path))?;
            Ok(())
        },
        perr::<String>(path),
    )
}

/// Plot time series (one line per named column) against time.
pub fn time_series(
    path: &Path,
    times: &[f64],
    columns: &[(String, Vec<f64>)],
    title: &str,
) -> Result<(), PlotError> {
    register_font();
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(perr(path))?;
    }
    atomic_png(
        path,
        |tmp| {
            let root = BitMapBackend::new(tmp, (900, 560)).into_drawing_area();
            root.fill(&WHITE).map_err(perr(path))?;
            let t0 = times.first().copied().unwrap_or(0.0);
            let t1 = times.last().copied().unwrap_or(1.0).max(t0 + 1e-12);
            let all = columns
                .iter()
                .flat_map(|c| c.1.iter().copied())
                .filter(|v| v.is_finite());
            let lo = all.clone().fold(f64::INFINITY, f64::min);
            let hi = all.fold(f64::NEG_INFINITY, f64::max);
            let (lo, hi) = if lo.is_finite() && hi > lo {
                let pad = 0.05 * (hi - lo);
                (lo - pad, hi + pad)
            } else {
                let v = if lo.is_finite() { lo } else { 0.0 };
                (v - 0.5 * v.abs().max(1e-30), v + 0.5 * v.abs().max(1e-30))
            };
            let (t0, t1) = if t1 > t0 {
                (t0, t1)
            } else {
                (t0 - 0.5, t0 + 0.5)
            };
            let mut chart = ChartBuilder::on(&root)
                .caption(title, ("sans-serif", 22))
                .margin(15)
                .x_label_area_size(40)
                .y_label_area_size(90)
                .build_cartesian_2d(t0..t1, lo..hi)
                .map_err(perr(path))?;
            chart
                .configure_mesh()
                .x_desc("time (s)")
                .y_label_formatter(&|v| format!("{v:.3e}"))
                .draw()
                .map_err(perr(path))?;
            for (k, (name, vals)) in columns.iter().enumerate() {
                let color = Palette99::pick(k).to_rgba();
                let pts: Vec<(f64, f64)> =
                    times.iter().copied().zip(vals.iter().copied()).collect();
                if pts.len() == 1 {
                    chart
                        .draw_series(std::iter::once(Circle::new(pts[0], 4, color.filled())))
                        .map_err(perr(path))?;
                } else {
                    chart
                        .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                        .map_err(perr(path))?;
                }
                let label_series = chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                    .map_err(perr(path))?;
                label_series.label(name.clone()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(perr(path))?;
            root.present().map_err(perr(path))?;
            Ok(())
        },
        perr::<String>(path),
    )
}
