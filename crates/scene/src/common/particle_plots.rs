//! End-of-run plots of an NSCD scene (`plots/`): the probe series grouped as the figures of
//! Renouf et al. (2006) group them (cell stresses p and q; dilatations; the rest), and a picture of
//! the disks coloured by nine horizontal layers of their initial height, as that paper
//! colours its layers (Figs. 5, 11).

use std::path::Path;

use porofrac_particles::Disks;

use crate::common::particle_output::{DiskPicture, draw_disks};
use crate::common::plots::{Column, PlotError, time_series};

/// Probe series: `stress.png` (p, q), `dilation.png`, `probes.png` (the others); `unit`
/// gives the unit of a field.
pub fn probe_plots(
    dir: &Path,
    name: &str,
    times: &[f64],
    probes: &[(String, String, Vec<f64>)],
    unit: impl Fn(&str) -> &'static str,
) -> Result<(), PlotError> {
    let groups: [(&str, &[&str], &str); 3] = [
        (
            "stress.png",
            &["p", "q"],
            "cell stress p, q (compression positive)",
        ),
        (
            "dilation.png",
            &["dilation_x", "dilation_y"],
            "cell dilatations",
        ),
        ("probes.png", &[], "probes"),
    ];
    for (file, fields, title) in groups {
        let columns: Vec<Column> = probes
            .iter()
            .filter(|(_, f, _)| {
                if fields.is_empty() {
                    !groups[..2].iter().any(|g| g.1.contains(&f.as_str()))
                } else {
                    fields.contains(&f.as_str())
                }
            })
            .map(|(n, f, v)| Column::new(n.clone(), unit(f), v.clone()))
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
/// equal height, 1 at the bottom) their centre started in.
pub fn layers(path: &Path, name: &str, t: f64, d: &Disks) -> Result<(), PlotError> {
    if d.is_empty() {
        return Ok(());
    }
    let bands = 9.0;
    let (lo, hi) =
        d.x0.iter()
            .zip(&d.r)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (p, r)| {
                (a.min(p[1] - r), b.max(p[1] + r))
            });
    let band = (hi - lo).max(1e-9) / bands;
    let layer: Vec<f64> =
        d.x0.iter()
            .map(|p| (((p[1] - lo) / band).floor() + 1.0).min(bands))
            .collect();
    let title = format!(
        "{name}: disks by initial layer at t = {} s",
        crate::common::plots::tick(t)
    );
    draw_disks(
        path,
        d,
        &DiskPicture {
            title: &title,
            values: &layer,
            bar: "layer (1: bottom)",
            unit: "1",
            segments: &[],
        },
    )
}
