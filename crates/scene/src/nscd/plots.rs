//! End-of-run plots of an NSCD scene (`plots/`): the probe series grouped as the seed's
//! figures group them (cell stresses p and q; dilatations; the rest), and a picture of
//! the disks coloured by nine horizontal layers of their initial height, as the seed
//! colours its layers (Figs. 5, 11).

use std::path::Path;

use plotters::prelude::*;
use porofrac_particles::Disks;

use crate::plots::{PlotError, time_series};

fn perr<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError {
        path: path.to_path_buf(),
        what: e.to_string(),
    }
}

/// Probe series: `stress.png` (p, q), `dilation.png`, `probes.png` (the others).
pub fn probe_plots(
    dir: &Path,
    name: &str,
    times: &[f64],
    probes: &[(String, String, Vec<f64>)],
) -> Result<(), PlotError> {
    let groups: [(&str, &[&str], &str); 3] = [
        (
            "stress.png",
            &["p", "q"],
            "cell stress p, q (Pa, compression positive)",
        ),
        (
            "dilation.png",
            &["dilation_x", "dilation_y"],
            "cell dilatations",
        ),
        ("probes.png", &[], "probes"),
    ];
    for (file, fields, title) in groups {
        let columns: Vec<(String, Vec<f64>)> = probes
            .iter()
            .filter(|(_, f, _)| {
                if fields.is_empty() {
                    !groups[..2].iter().any(|g| g.1.contains(&f.as_str()))
                } else {
                    fields.contains(&f.as_str())
                }
            })
            .map(|(n, _, v)| (n.clone(), v.clone()))
            .collect();
        if !columns.is_empty() {
            time_series(
                &dir.join(file),
                times,
                &columns,
                &format!("{name}: {title}"),
            )?;
        }
    }
    Ok(())
}

/// The disks at their current position, coloured by the layer (one of nine bands of
/// equal height) their centre started in.
pub fn layers(path: &Path, d: &Disks) -> Result<(), PlotError> {
    if d.is_empty() {
        return Ok(());
    }
    std::fs::create_dir_all(path.parent().unwrap_or(Path::new("."))).map_err(perr(path))?;
    let bounds = |x: &[[f64; 2]]| {
        x.iter().zip(&d.r).fold(
            [
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ],
            |b, (p, r)| {
                [
                    b[0].min(p[0] - r),
                    b[1].max(p[0] + r),
                    b[2].min(p[1] - r),
                    b[3].max(p[1] + r),
                ]
            },
        )
    };
    let b = bounds(&d.x);
    let b0 = bounds(&d.x0);
    let (w, h) = ((b[1] - b[0]).max(1e-9), (b[3] - b[2]).max(1e-9));
    let width = 1600u32;
    let height = ((width as f64 * h / w).ceil() as u32).clamp(50, 4000);
    let scale = (width as f64 / w).min(height as f64 / h);
    let tmp = path.with_extension("tmp.png");
    {
        let root = BitMapBackend::new(&tmp, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        let palette = [
            RGBColor(68, 1, 84),
            RGBColor(72, 40, 120),
            RGBColor(62, 74, 137),
            RGBColor(49, 104, 142),
            RGBColor(38, 130, 142),
            RGBColor(31, 158, 137),
            RGBColor(53, 183, 121),
            RGBColor(109, 205, 89),
            RGBColor(180, 222, 44),
        ];
        let band = (b0[3] - b0[2]).max(1e-9) / palette.len() as f64;
        for i in 0..d.len() {
            let layer = (((d.x0[i][1] - b0[2]) / band) as usize).min(palette.len() - 1);
            let px = ((d.x[i][0] - b[0]) * scale) as i32;
            let py = height as i32 - ((d.x[i][1] - b[2]) * scale) as i32;
            let r = ((d.r[i] * scale).round() as i32).max(1);
            root.draw(&Circle::new((px, py), r, palette[layer].filled()))
                .map_err(perr(path))?;
        }
        root.present().map_err(perr(path))?;
    }
    std::fs::rename(&tmp, path).map_err(perr(path))
}
