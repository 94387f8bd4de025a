//! End-of-run plots of an NSCD scene (`plots/`): the probe series grouped as the figures of
//! Renouf et al. (2006) group them (cell stresses p and q; dilatations; the rest), and a picture of
//! the disks coloured by nine horizontal layers of their initial height, as that paper
//! colours its layers (Figs. 5, 11).

use std::path::Path;

use plotters::prelude::*;
use porofrac_particles::Disks;

use crate::common::plots::{PlotError, time_series};

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
    let (lo, hi) =
        d.x0.iter()
            .zip(&d.r)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (p, r)| {
                (a.min(p[1] - r), b.max(p[1] + r))
            });
    let band = (hi - lo).max(1e-9) / palette.len() as f64;
    crate::common::particle_output::draw_disks(
        path,
        d,
        |i| palette[(((d.x0[i][1] - lo) / band) as usize).min(palette.len() - 1)],
        &[],
    )
}
