//! End-of-run images of lattice fields (`plots/speed.png`, `vorticity.png`,
//! `temperature.png`): one pixel block per node (nodes sampled beyond 1600 pixels),
//! viridis colours between the field's extrema, obstacles grey, y up.

use std::path::Path;

use plotters::prelude::*;

use crate::common::plots::PlotError;

/// Write `values` (x-fastest, `n[0] × n[1]`) as a PNG; `solid` nodes are drawn grey.
pub(crate) fn field_png(
    path: &Path,
    n: [usize; 2],
    values: &[f64],
    solid: &[bool],
    symmetric: bool,
) -> Result<(), PlotError> {
    let err = |e: String| PlotError {
        path: path.to_path_buf(),
        what: e,
    };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| err(e.to_string()))?;
    }
    let (nx, ny) = (n[0], n[1]);
    let scale = (800 / nx).max(1);
    let width = (nx * scale).min(1600);
    let height = ((ny * width) / nx).max(1);
    let finite = values
        .iter()
        .zip(solid)
        .filter(|(v, s)| !**s && v.is_finite())
        .map(|(v, _)| *v);
    let (mut lo, mut hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if symmetric {
        let m = lo.abs().max(hi.abs());
        (lo, hi) = (-m, m);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        (lo, hi) = (0.0, 1.0);
    } else if hi <= lo {
        (lo, hi) = (lo - 0.5, lo + 0.5);
    }
    crate::common::plots::atomic_png(
        path,
        |tmp| {
            let root = BitMapBackend::new(tmp, (width as u32, height as u32)).into_drawing_area();
            for py in 0..height {
                let j = ((height - 1 - py) * ny / height).min(ny - 1);
                for px in 0..width {
                    let i = (px * nx / width).min(nx - 1);
                    let k = j * nx + i;
                    let color = if solid[k] || !values[k].is_finite() {
                        RGBColor(128, 128, 128)
                    } else {
                        ViridisRGB::get_color_normalized(values[k], lo, hi)
                    };
                    root.draw_pixel((px as i32, py as i32), &color)
                        .map_err(|e| err(e.to_string()))?;
                }
            }
            root.present().map_err(|e| err(e.to_string()))?;
            Ok(())
        },
        err,
    )
}
