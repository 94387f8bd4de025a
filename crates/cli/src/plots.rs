//! PNG plots a person looks at first: cell fields of 2D scenes (with fractured cells
//! outlined) and probe time series. Text uses the bundled DejaVu Sans font, so no system
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
            include_bytes!("../assets/DejaVuSans.ttf"),
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

fn tmp_path(path: &Path) -> PathBuf {
    path.with_extension("tmp.png")
}

fn finish(path: &Path, tmp: &Path) -> Result<(), PlotError> {
    std::fs::rename(tmp, path).map_err(|e| PlotError {
        path: path.to_path_buf(),
        what: e.to_string(),
    })
}

fn perr<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError {
        path: path.to_path_buf(),
        what: e.to_string(),
    }
}

/// Plot a cell field of a 2D grid, colour-mapped, with the cells where `marked` is true
/// outlined in red (fractured cells).
pub fn cell_field(
    path: &Path,
    grid: &Grid<2>,
    values: &[f64],
    title: &str,
    marked: &[bool],
) -> Result<(), PlotError> {
    register_font();
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(perr(path))?;
    }
    let tmp = tmp_path(path);
    {
        let (lo, hi) = grid.bounding_box();
        let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
        let px_w = 900u32;
        let px_h = ((px_w as f64 - 160.0) * h / w + 120.0).clamp(300.0, 1400.0) as u32;
        let root = BitMapBackend::new(&tmp, (px_w, px_h)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        let (main, bar) = root.split_horizontally(px_w - 110);
        let finite = values.iter().copied().filter(|v| v.is_finite());
        let vmin = finite.clone().fold(f64::INFINITY, f64::min);
        let vmax = finite.fold(f64::NEG_INFINITY, f64::max);
        let (vmin, vmax) = if vmin.is_finite() && vmax > vmin {
            (vmin, vmax)
        } else {
            (vmin.min(0.0) - 0.5, vmax.max(0.0) + 0.5)
        };
        let mut chart = ChartBuilder::on(&main)
            .caption(title, ("sans-serif", 22))
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
        let polys = (0..grid.num_cells()).map(|c| {
            let pts: Vec<(f64, f64)> = grid
                .cell_nodes(c)
                .iter()
                .map(|&n| (grid.node(n)[0], grid.node(n)[1]))
                .collect();
            let v = values[c];
            let color = if v.is_finite() {
                ViridisRGB::get_color_normalized(v, vmin, vmax)
            } else {
                RGBColor(255, 0, 255)
            };
            Polygon::new(pts, color.filled())
        });
        chart.draw_series(polys).map_err(perr(path))?;
        let outlines = (0..grid.num_cells())
            .filter(|&c| marked.get(c).copied().unwrap_or(false))
            .map(|c| {
                let mut pts: Vec<(f64, f64)> = grid
                    .cell_nodes(c)
                    .iter()
                    .map(|&n| (grid.node(n)[0], grid.node(n)[1]))
                    .collect();
                pts.push(pts[0]);
                PathElement::new(pts, RED.stroke_width(2))
            });
        chart.draw_series(outlines).map_err(perr(path))?;
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
    }
    finish(path, &tmp)
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
    let tmp = tmp_path(path);
    {
        let root = BitMapBackend::new(&tmp, (900, 560)).into_drawing_area();
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
            let pts: Vec<(f64, f64)> = times.iter().copied().zip(vals.iter().copied()).collect();
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
    }
    finish(path, &tmp)
}
