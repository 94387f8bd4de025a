//! End-of-run images of lattice fields (`plots/speed.png`, `vorticity.png`,
//! `temperature.png`, the fluid of particle scenes): one pixel block per node (nodes
//! sampled beyond the picture's size), x and y axes in metres, a title, and a colour bar
//! named with the field and its unit; colours span the 1st–99th percentile of the fluid
//! values (the true extrema under the picture, [`crate::common::plots::ColourRange`]),
//! solid nodes grey, y up.

use std::path::Path;

use plotters::prelude::*;

use crate::common::plots::{ColourRange, PlotError, axis_ticks, colour_bar};

/// What a lattice image shows besides the values.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LatticeImage<'a> {
    /// The title.
    pub title: &'a str,
    /// The colour bar's name: field and unit (`speed [m/s]`).
    pub bar: &'a str,
    /// The unit of the values (caption).
    pub unit: &'a str,
    /// The lower-left corner of the lattice (m): node `(i, j)` covers
    /// `[x0 + i dx, x0 + (i + 1) dx] × [y0 + j dx, y0 + (j + 1) dx]`.
    pub origin: [f64; 2],
    /// Node spacing (m).
    pub dx: f64,
    /// Colours symmetric about zero (signed fields such as vorticity).
    pub symmetric: bool,
}

/// Write `values` (x-fastest, `n[0] × n[1]`) as a PNG; `solid` nodes are drawn grey.
pub(crate) fn field_png(
    path: &Path,
    n: [usize; 2],
    values: &[f64],
    solid: &[bool],
    image: &LatticeImage<'_>,
) -> Result<(), PlotError> {
    crate::common::plots::register_font();
    let err = |e: String| PlotError {
        path: path.to_path_buf(),
        what: e,
    };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| err(e.to_string()))?;
    }
    let (nx, ny) = (n[0].max(1), n[1].max(1));
    let range = ColourRange::of(
        values
            .iter()
            .zip(solid)
            .filter(|(_, s)| !**s)
            .map(|(v, _)| *v),
        0.0,
        image.symmetric,
    );
    let (width, bar_w, footer) = (1000u32, 140u32, 26u32);
    let plot_w = (width - bar_w - 95) as f64;
    let height =
        (plot_w * ny as f64 / nx as f64 + 110.0 + footer as f64).clamp(300.0, 1400.0) as u32;
    let h = image.dx;
    let [x0, y0] = image.origin;
    let (x1, y1) = (x0 + nx as f64 * h, y0 + ny as f64 * h);
    crate::common::plots::atomic_png(
        path,
        |tmp| {
            let e = |e: DrawingAreaErrorKind<_>| err(e.to_string());
            let root = BitMapBackend::new(tmp, (width, height)).into_drawing_area();
            root.fill(&WHITE).map_err(e)?;
            let (top, foot) = root.split_vertically(height - footer);
            foot.draw(&Text::new(
                range.caption(image.unit),
                (12, 4),
                ("sans-serif", 15).into_font().color(&BLACK),
            ))
            .map_err(e)?;
            let (main, bar) = top.split_horizontally(width - bar_w);
            let mut chart = ChartBuilder::on(&main)
                .caption(image.title, ("sans-serif", 22))
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(60)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(e)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc("x [m]")
                .y_desc("y [m]")
                .x_label_formatter(&axis_ticks(x0, x1))
                .y_label_formatter(&axis_ticks(y0, y1))
                .draw()
                .map_err(e)?;
            let (xr, yr) = chart.plotting_area().get_pixel_range();
            let (pw, ph) = ((xr.end - xr.start).max(1), (yr.end - yr.start).max(1));
            for py in yr.clone() {
                let j = ny - 1 - (((py - yr.start) as usize * ny) / ph as usize).min(ny - 1);
                for px in xr.clone() {
                    let i = (((px - xr.start) as usize * nx) / pw as usize).min(nx - 1);
                    let k = j * nx + i;
                    let color = if solid[k] {
                        RGBColor(128, 128, 128)
                    } else {
                        range.colour(values[k])
                    };
                    root.draw_pixel((px, py), &color).map_err(e)?;
                }
            }
            colour_bar(&bar, &range, image.bar).map_err(err)?;
            root.present().map_err(e)?;
            Ok(())
        },
        err,
    )
}
