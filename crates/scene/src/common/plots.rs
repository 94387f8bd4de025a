//! PNG plots a person looks at first: cell and nodal fields of 2D scenes (with fractured
//! cells outlined, optionally zoomed and with principal directions), probe time series and
//! line profiles. Text uses the bundled DejaVu Sans font, so no system font library is
//! needed.
//!
//! How they read: every axis names its quantity and unit (`x [m]`, `time [ms]`,
//! `p_well [Pa]`); time series put each unit in its own panel; a colour bar names the
//! field and its unit; colours span the 1st to 99th percentile of the values shown
//! ([`ColourRange`]), so a few crack-tip cells do not wash out the rest, and the true
//! minimum and maximum are stated under the picture; a field whose values differ by
//! round-off only is drawn in one colour and said to be uniform.

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use porofrac_grid::Grid;

static FONT: Once = Once::new();

pub(crate) fn register_font() {
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

/// The colours of a field: the values mapped to the ends of the colour scale, and the
/// true extrema stated in the caption.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourRange {
    /// Value at the low end of the colour scale.
    pub lo: f64,
    /// Value at the high end of the colour scale.
    pub hi: f64,
    /// Smallest finite value.
    pub min: f64,
    /// Largest finite value.
    pub max: f64,
    /// Whether `lo..hi` are the 1st and 99th percentiles (values outside are clipped).
    pub clipped: bool,
    /// Whether the values differ by less than `noise` (drawn in one colour).
    pub uniform: bool,
}

impl ColourRange {
    /// The range of the finite `values`: the 1st–99th percentile, or all of them when
    /// that is narrower than `noise` or the values are few; uniform when even the
    /// extrema differ by no more than `noise` or by round-off (1e-9 of their size).
    /// `symmetric`: about zero (signed fields such as vorticity).
    pub fn of(values: impl Iterator<Item = f64>, noise: f64, symmetric: bool) -> Self {
        let mut v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return Self {
                lo: -0.5,
                hi: 0.5,
                min: 0.0,
                max: 0.0,
                clipped: false,
                uniform: true,
            };
        }
        v.sort_unstable_by(f64::total_cmp);
        let n = v.len();
        let (min, max) = (v[0], v[n - 1]);
        let floor = noise.max(1e-9 * min.abs().max(max.abs()));
        if max - min <= floor {
            let m = 0.5 * (min + max);
            let half = m.abs().max(1e-30) * 0.5;
            return Self {
                lo: m - half,
                hi: m + half,
                min,
                max,
                clipped: false,
                uniform: true,
            };
        }
        let (p1, p99) = (v[(n - 1) / 100], v[n - 1 - (n - 1) / 100]);
        let (mut lo, mut hi, mut clipped) = if p99 - p1 > floor && (p1 > min || p99 < max) {
            (p1, p99, true)
        } else {
            (min, max, false)
        };
        if symmetric {
            let m = lo.abs().max(hi.abs());
            (lo, hi) = (-m, m);
            clipped = clipped && (min < lo || max > hi);
        }
        Self {
            lo,
            hi,
            min,
            max,
            clipped,
            uniform: false,
        }
    }

    /// The colour of `v` (clipped to the scale; magenta for a value that is not finite).
    pub fn colour(&self, v: f64) -> RGBColor {
        if !v.is_finite() {
            return RGBColor(255, 0, 255);
        }
        if self.uniform {
            return ViridisRGB::get_color_normalized(0.5, 0.0, 1.0);
        }
        ViridisRGB::get_color_normalized(v.clamp(self.lo, self.hi), self.lo, self.hi)
    }

    /// `min -3.2e6 Pa, max 1.1e5 Pa (colours: 1st–99th percentile)`, or `uniform: 2 Pa`.
    pub fn caption(&self, unit: &str) -> String {
        let u = unit_suffix(unit);
        if self.uniform {
            return format!("uniform: {}{u}", tick(0.5 * (self.min + self.max)));
        }
        format!(
            "min {}{u}, max {}{u}{}",
            tick(self.min),
            tick(self.max),
            if self.clipped {
                "; colours span the 1st–99th percentile"
            } else {
                ""
            }
        )
    }
}

/// ` Pa` (nothing for `"1"`).
fn unit_suffix(unit: &str) -> String {
    if unit == "1" || unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    }
}

/// `name [unit]`, or `name` alone for a number without unit.
pub fn label(name: &str, unit: &str) -> String {
    if unit == "1" || unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} [{unit}]")
    }
}

/// A tick or caption number: plain for moderate sizes (`0.25`, `1500`), else
/// `1.5e6`, `-3.25e-9`; at most four significant digits.
pub fn tick(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 { "0".into() } else { v.to_string() };
    }
    let a = v.abs();
    let trim = |t: String| -> String {
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    };
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        trim(format!("{v:.decimals$}"))
    } else {
        let t = format!("{v:.3e}");
        let (m, e) = t.split_once('e').unwrap_or((&t, "0"));
        format!("{}e{e}", trim(m.to_string()))
    }
}

/// Tick labels for an axis from `lo` to `hi`, all in one form: plain decimals when the
/// largest magnitude is between 1e-3 and 1e5 (`0.0002`, `1500`), else a mantissa with
/// the axis's common exponent (`1.5e6`, `2e6`); as many decimals as the ticks need.
pub fn axis_ticks(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let m = lo.abs().max(hi.abs());
    let plain = m == 0.0 || !m.is_finite() || (1e-3..1e5).contains(&m);
    let e = if plain { 0 } else { m.log10().floor() as i32 };
    let scale = 10f64.powi(e);
    let step = ((hi - lo).abs() / 20.0 / scale).max(1e-12);
    let decimals = (-step.log10()).ceil().clamp(0.0, 9.0) as usize;
    move |v: &f64| {
        let x = *v / scale;
        let mut t = format!("{x:.decimals$}");
        if t.contains('.') {
            t = t.trim_end_matches('0').trim_end_matches('.').to_string();
        }
        if t == "-0" || t == "0" {
            return "0".into();
        }
        if e == 0 { t } else { format!("{t}e{e}") }
    }
}

/// The time unit that reads best for times up to `t_max` seconds: the factor to divide
/// by and its name (`ms` below a second, `min`, `h`, `d` for long runs).
pub fn time_unit(t_max: f64) -> (f64, &'static str) {
    let t = t_max.abs();
    if t >= 2.0 * 86400.0 {
        (86400.0, "d")
    } else if t >= 2.0 * 3600.0 {
        (3600.0, "h")
    } else if t >= 300.0 {
        (60.0, "min")
    } else if t >= 1.0 || t == 0.0 {
        (1.0, "s")
    } else if t >= 1e-3 {
        (1e-3, "ms")
    } else if t >= 1e-6 {
        (1e-6, "µs")
    } else {
        (1.0, "s")
    }
}

/// A vertical colour bar on `area` for `range`, named `name` (field and unit) above it.
pub(crate) fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    range: &ColourRange,
    name: &str,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    area.draw(&Text::new(
        name.to_string(),
        (4, 12),
        ("sans-serif", 15).into_font().color(&BLACK),
    ))
    .map_err(e)?;
    let (lo, hi) = (range.lo, range.hi);
    let mut cb = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(45)
        .margin_right(8)
        .y_label_area_size(72)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(e)?;
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(if range.uniform { 1 } else { 8 })
        .y_label_style(("sans-serif", 13))
        .y_label_formatter(&axis_ticks(lo, hi))
        .draw()
        .map_err(e)?;
    let steps = 100;
    cb.draw_series((0..steps).map(|i| {
        let a = lo + (hi - lo) * i as f64 / steps as f64;
        let b = lo + (hi - lo) * (i + 1) as f64 / steps as f64;
        Rectangle::new([(0.0, a), (1.0, b)], range.colour(0.5 * (a + b)).filled())
    }))
    .map_err(e)?;
    Ok(())
}

/// What a field plot shows besides the values.
#[derive(Clone, Copy, Debug)]
pub struct FieldPlot<'a> {
    /// The polygons.
    pub canvas: &'a Canvas,
    /// The title.
    pub title: &'a str,
    /// The colour bar's name: the field and its unit (`σ_yy [Pa]`).
    pub bar: &'a str,
    /// The unit of the values (for the caption's extrema; `"1"`: none).
    pub unit: &'a str,
    /// Values that differ by no more than this are drawn as uniform (the size of
    /// round-off for the field, e.g. 1e-9 of the largest stress of the scene).
    pub noise: f64,
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
    /// The whole canvas with fractured cells outlined; the colour bar named `bar`, the
    /// values in `unit`.
    pub fn new(
        canvas: &'a Canvas,
        title: &'a str,
        bar: &'a str,
        unit: &'a str,
        marked: &'a [bool],
    ) -> Self {
        Self {
            canvas,
            title,
            bar,
            unit,
            noise: 0.0,
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
    let range = ColourRange::of(pieces.iter().map(|p| p.1), plot.noise, false);
    atomic_png(
        path,
        |tmp| {
            let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
            let px_w = 900u32;
            let px_h = ((px_w as f64 - 190.0) * h / w + 150.0).clamp(300.0, 1400.0) as u32;
            let root = BitMapBackend::new(tmp, (px_w, px_h)).into_drawing_area();
            root.fill(&WHITE).map_err(perr(path))?;
            let (top, footer) = root.split_vertically(px_h - 26);
            footer
                .draw(&Text::new(
                    range.caption(plot.unit),
                    (12, 4),
                    ("sans-serif", 15).into_font().color(&BLACK),
                ))
                .map_err(perr(path))?;
            let (main, bar) = top.split_horizontally(px_w - 140);
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
                .x_desc("x [m]")
                .y_desc("y [m]")
                .x_label_formatter(&axis_ticks(lo[0], hi[0]))
                .y_label_formatter(&axis_ticks(lo[1], hi[1]))
                .draw()
                .map_err(perr(path))?;
            let polys = pieces
                .into_iter()
                .map(|(pts, v)| Polygon::new(pts, range.colour(v).filled()));
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
            colour_bar(&bar, &range, plot.bar).map_err(perr(path))?;
            root.present().map_err(perr(path))?;
            Ok(())
        },
        perr::<String>(path),
    )
}

/// One probe's series for [`time_series`]: its name, unit and values.
#[derive(Clone, Debug)]
pub struct Column {
    /// The probe's name.
    pub name: String,
    /// The unit of its values (`"1"`: none).
    pub unit: &'static str,
    /// The values at the times.
    pub values: Vec<f64>,
}

impl Column {
    /// A column.
    pub fn new(name: impl Into<String>, unit: &'static str, values: Vec<f64>) -> Self {
        Self {
            name: name.into(),
            unit,
            values,
        }
    }
}

/// Plot time series against time, one panel per unit (stacked, sharing the time axis,
/// each y axis named with its probes and unit); the time axis in s or the multiple that
/// reads best ([`time_unit`]). Nothing is drawn for fewer than two times (a static
/// solve: the values are in the CSV).
pub fn time_series(
    path: &Path,
    times: &[f64],
    columns: &[Column],
    title: &str,
) -> Result<(), PlotError> {
    if times.len() < 2 || columns.is_empty() {
        return Ok(());
    }
    register_font();
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(perr(path))?;
    }
    // Panels: the units in order of first appearance.
    let mut units: Vec<&str> = Vec::new();
    for c in columns {
        if !units.contains(&c.unit) {
            units.push(c.unit);
        }
    }
    let t_max = times.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let (scale, tu) = time_unit(t_max);
    let panel_h = if units.len() == 1 { 500 } else { 300 };
    let height = 50 + panel_h * units.len().max(1) as u32;
    atomic_png(
        path,
        |tmp| {
            let root = BitMapBackend::new(tmp, (1000, height)).into_drawing_area();
            root.fill(&WHITE).map_err(perr(path))?;
            let root = root.titled(title, ("sans-serif", 22)).map_err(perr(path))?;
            let panels = root.split_evenly((units.len().max(1), 1));
            let t0 = times.first().copied().unwrap_or(0.0) / scale;
            let t1 = times.last().copied().unwrap_or(1.0) / scale;
            let (t0, t1) = if t1 > t0 {
                (t0, t1)
            } else {
                (t0 - 0.5, t0 + 0.5)
            };
            for (panel, unit) in panels.iter().zip(&units) {
                let cols: Vec<(usize, &Column)> = columns
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| c.unit == *unit)
                    .collect();
                let all = cols
                    .iter()
                    .flat_map(|(_, c)| c.values.iter().copied())
                    .filter(|v| v.is_finite());
                let lo = all.clone().fold(f64::INFINITY, f64::min);
                let hi = all.fold(f64::NEG_INFINITY, f64::max);
                let (lo, hi) = if lo.is_finite() && hi - lo > 1e-12 * lo.abs().max(hi.abs()) {
                    let pad = 0.05 * (hi - lo);
                    (lo - pad, hi + pad)
                } else {
                    let v = if lo.is_finite() { lo } else { 0.0 };
                    (v - 0.5 * v.abs().max(1e-30), v + 0.5 * v.abs().max(1e-30))
                };
                let names: Vec<&str> = cols.iter().map(|(_, c)| c.name.as_str()).collect();
                let y_desc = if names.len() <= 3 {
                    label(&names.join(", "), unit)
                } else if *unit == "1" {
                    "value".to_string()
                } else {
                    format!("[{unit}]")
                };
                let (panel, key) = panel.split_horizontally(1000 - LEGEND_WIDTH);
                let mut chart = ChartBuilder::on(&panel)
                    .margin(12)
                    .x_label_area_size(40)
                    .y_label_area_size(95)
                    .build_cartesian_2d(t0..t1, lo..hi)
                    .map_err(perr(path))?;
                chart
                    .configure_mesh()
                    .x_desc(format!("time [{tu}]"))
                    .y_desc(y_desc)
                    .x_label_formatter(&axis_ticks(t0, t1))
                    .y_label_formatter(&axis_ticks(lo, hi))
                    .draw()
                    .map_err(perr(path))?;
                let mut entries = Vec::new();
                for (k, c) in &cols {
                    let color = Palette99::pick(*k).to_rgba();
                    entries.push((c.name.clone(), color));
                    let pts: Vec<(f64, f64)> = times
                        .iter()
                        .map(|t| t / scale)
                        .zip(c.values.iter().copied())
                        .filter(|p| p.1.is_finite())
                        .collect();
                    if pts.len() == 1 {
                        chart
                            .draw_series(std::iter::once(Circle::new(pts[0], 4, color.filled())))
                            .map_err(perr(path))?;
                    } else {
                        chart
                            .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                            .map_err(perr(path))?;
                    }
                }
                legend(&key, &entries).map_err(perr(path))?;
            }
            root.present().map_err(perr(path))?;
            Ok(())
        },
        perr::<String>(path),
    )
}

/// Width of the legend column beside a chart (pixels).
const LEGEND_WIDTH: u32 = 180;

/// A legend in its own column beside the chart (never over the curves): a short line of
/// each colour and its name, as many as fit.
fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    entries: &[(String, RGBAColor)],
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let rows = ((area.dim_in_pixel().1 as i32 - 30) / 20).max(1) as usize;
    for (k, (name, color)) in entries.iter().enumerate() {
        let y = 30 + 20 * k as i32;
        if k + 1 == rows && entries.len() > rows {
            area.draw(&Text::new(
                format!("… {} more", entries.len() - k),
                (8, y - 7),
                ("sans-serif", 14).into_font().color(&BLACK),
            ))
            .map_err(e)?;
            break;
        }
        area.draw(&PathElement::new(
            vec![(6, y), (30, y)],
            color.stroke_width(3),
        ))
        .map_err(e)?;
        let shown: String = name.chars().take(20).collect();
        area.draw(&Text::new(
            shown,
            (36, y - 7),
            ("sans-serif", 14).into_font().color(&BLACK),
        ))
        .map_err(e)?;
    }
    Ok(())
}

/// Plot a line's profiles: `field` (in `unit`) against arc length along the line, one
/// curve per snapshot `(time, rows s, x, y(, z), value)`, labelled with its time.
pub fn line_profiles(
    path: &Path,
    title: &str,
    field: &str,
    unit: &str,
    snapshots: &[(f64, Vec<Vec<f64>>)],
) -> Result<(), PlotError> {
    register_font();
    if snapshots.is_empty() {
        return Ok(());
    }
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(perr(path))?;
    }
    let t_max = snapshots.iter().fold(0.0f64, |m, s| m.max(s.0.abs()));
    let (scale, tu) = time_unit(t_max);
    let points = snapshots
        .iter()
        .flat_map(|s| s.1.iter())
        .filter_map(|r| Some((*r.first()?, *r.last()?)));
    let (s0, s1, lo, hi) = points.fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |(a, b, c, d), (s, v)| (a.min(s), b.max(s), c.min(v), d.max(v)),
    );
    let (s0, s1) = if s1 > s0 { (s0, s1) } else { (0.0, 1.0) };
    let (lo, hi) = if hi - lo > 1e-12 * lo.abs().max(hi.abs()) {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    } else {
        let v = if lo.is_finite() { lo } else { 0.0 };
        (v - 0.5 * v.abs().max(1e-30), v + 0.5 * v.abs().max(1e-30))
    };
    atomic_png(
        path,
        |tmp| {
            let root = BitMapBackend::new(tmp, (1000, 560)).into_drawing_area();
            root.fill(&WHITE).map_err(perr(path))?;
            let root = root.titled(title, ("sans-serif", 22)).map_err(perr(path))?;
            let (main, key) = root.split_horizontally(1000 - LEGEND_WIDTH);
            let mut chart = ChartBuilder::on(&main)
                .margin(15)
                .x_label_area_size(40)
                .y_label_area_size(95)
                .build_cartesian_2d(s0..s1, lo..hi)
                .map_err(perr(path))?;
            chart
                .configure_mesh()
                .x_desc("distance along the line [m]")
                .y_desc(label(field, unit))
                .x_label_formatter(&axis_ticks(s0, s1))
                .y_label_formatter(&axis_ticks(lo, hi))
                .draw()
                .map_err(perr(path))?;
            let n = snapshots.len();
            let mut entries = Vec::new();
            for (k, (t, rows)) in snapshots.iter().enumerate() {
                let color = if n == 1 {
                    BLUE.to_rgba()
                } else {
                    ViridisRGB::get_color_normalized(k as f64, 0.0, (n - 1) as f64).to_rgba()
                };
                let pts: Vec<(f64, f64)> = rows
                    .iter()
                    .filter_map(|r| Some((*r.first()?, *r.last()?)))
                    .collect();
                chart
                    .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                    .map_err(perr(path))?;
                entries.push((format!("t = {} {tu}", tick(t / scale)), color));
            }
            legend(&key, &entries).map_err(perr(path))?;
            root.present().map_err(perr(path))?;
            Ok(())
        },
        perr::<String>(path),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Percentile limits ignore a few outliers; the true extrema stay in the caption;
    /// round-off is uniform.
    #[test]
    fn colour_range_is_robust_and_states_the_extrema() {
        // 1000 values 0..=999 and one outlier at 1e6.
        let v: Vec<f64> = (0..1000).map(f64::from).chain([1e6]).collect();
        let r = ColourRange::of(v.iter().copied(), 0.0, false);
        assert_eq!((r.lo, r.hi), (10.0, 990.0));
        assert_eq!((r.min, r.max), (0.0, 1e6));
        assert!(r.clipped && !r.uniform);
        assert_eq!(
            r.caption("Pa"),
            "min 0 Pa, max 1e6 Pa; colours span the 1st–99th percentile"
        );
        // Few values: the extrema.
        let r = ColourRange::of([1.0, 2.0, 3.0].into_iter(), 0.0, false);
        assert_eq!((r.lo, r.hi, r.clipped), (1.0, 3.0, false));
        // Round-off about 5 (relative 1e-15) and noise below the stated floor.
        let r = ColourRange::of([5.0, 5.0 + 5e-15].into_iter(), 0.0, false);
        assert!(r.uniform, "{r:?}");
        assert_eq!(r.caption("m"), "uniform: 5 m");
        let r = ColourRange::of([1e-13, -2e-13].into_iter(), 1e-6, false);
        assert!(r.uniform);
        // Symmetric about 0.
        let r = ColourRange::of([-1.0, 3.0].into_iter(), 0.0, true);
        assert_eq!((r.lo, r.hi), (-3.0, 3.0));
    }

    #[test]
    fn numbers_and_time_units_read_well() {
        assert_eq!(tick(0.25), "0.25");
        assert_eq!(tick(1500.0), "1500");
        assert_eq!(tick(-1.5e6), "-1.5e6");
        assert_eq!(tick(3.25e-9), "3.25e-9");
        assert_eq!(tick(0.0), "0");
        let f = axis_ticks(0.0, 1e-3);
        assert_eq!([f(&0.0), f(&1e-4), f(&1e-3)], ["0", "0.0001", "0.001"]);
        let f = axis_ticks(-2e6, 4e6);
        assert_eq!([f(&-1.5e6), f(&4e6)], ["-1.5e6", "4e6"]);
        let f = axis_ticks(0.0, 40.0);
        assert_eq!([f(&5.0), f(&40.0)], ["5", "40"]);
        assert_eq!(time_unit(40.0), (1.0, "s"));
        assert_eq!(time_unit(0.02), (1e-3, "ms"));
        assert_eq!(time_unit(3e-5), (1e-6, "µs"));
        assert_eq!(time_unit(7200.0), (3600.0, "h"));
        assert_eq!(time_unit(1e6), (86400.0, "d"));
        assert_eq!(label("p_well", "Pa"), "p_well [Pa]");
        assert_eq!(label("fractured", "1"), "fractured");
    }
}
