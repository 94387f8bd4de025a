//! Outputs shared by the particle models (`nscd`, `lsm`): particle probe values, line
//! samples (the particle nearest each point), field extrema of the disks, the VTK
//! PolyData files (`vtk/particles_NNNN.vtp`, `vtk/contacts_NNNN.vtp` and
//! `<name>_contacts.pvd`) and a picture of the disks.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::Path;

use plotters::prelude::*;
use porofrac_grid::io::PvdWriter;
use porofrac_particles::Disks;
use porofrac_particles::vtk::{ContactLine, write_contacts_with, write_particles_with};

use crate::common::loaded::LoadedScene;
use crate::common::model::RunError;
use crate::common::plots::PlotError;

/// Fields of one particle (`particle = N` probes, lines).
pub const PARTICLE_FIELDS: [&str; 8] = ["x", "y", "vx", "vy", "omega", "fx", "fy", "radius"];

/// The unit of a particle field ([`PARTICLE_FIELDS`]) or a tracked-cell field (`p q`
/// Pa, `anisotropy_volume` 1/m², the other ratios and counts `"1"`); `None` for other
/// names. Forces are per metre of thickness (disks): N/m.
pub fn particle_unit(field: &str) -> Option<&'static str> {
    Some(match field {
        "x" | "y" | "radius" => "m",
        "vx" | "vy" => "m/s",
        "omega" => "rad/s",
        "fx" | "fy" => "N/m",
        "p" | "q" => "Pa",
        "anisotropy_volume" => "1/m²",
        "anisotropy" | "dilation_x" | "dilation_y" | "contacts" | "broken_bonds" => "1",
        _ => return None,
    })
}

/// Value of `PARTICLE_FIELDS[field]` for particle i (`forces`: `[f_x, f_y]` per particle).
pub fn particle_value(d: &Disks, i: usize, field: usize, forces: &[[f64; 2]]) -> f64 {
    match PARTICLE_FIELDS[field] {
        "x" => d.x[i][0],
        "y" => d.x[i][1],
        "vx" => d.v[i][0],
        "vy" => d.v[i][1],
        "omega" => d.omega[i],
        "fx" => forces[i][0],
        "fy" => forces[i][1],
        _ => d.r[i],
    }
}

/// Rows `s, x, y, value` of `[[output.line]]` number `line`: the value of the particle
/// nearest each point.
pub fn line_rows(
    ls: &LoadedScene,
    line: usize,
    d: &Disks,
    forces: &[[f64; 2]],
    rows: &mut Vec<Vec<f64>>,
) {
    let l = &ls.scene.output.line[line];
    let field = PARTICLE_FIELDS
        .iter()
        .position(|f| *f == l.field)
        .expect("checked");
    let x = &d.x;
    let n = l.points as usize;
    let len = ((l.to[0] - l.from[0]).powi(2) + (l.to[1] - l.from[1]).powi(2)).sqrt();
    for k in 0..n {
        let s = k as f64 / (n - 1) as f64;
        let p = [
            l.from[0] + s * (l.to[0] - l.from[0]),
            l.from[1] + s * (l.to[1] - l.from[1]),
        ];
        let nearest = (0..x.len())
            .min_by(|&a, &b| {
                let da = (x[a][0] - p[0]).powi(2) + (x[a][1] - p[1]).powi(2);
                let db = (x[b][0] - p[0]).powi(2) + (x[b][1] - p[1]).powi(2);
                da.total_cmp(&db)
            })
            .unwrap_or(0);
        rows.push(vec![
            s * len,
            p[0],
            p[1],
            particle_value(d, nearest, field, forces),
        ]);
    }
}

/// Insert `[min, max]` of `values` under `name` (nothing if empty).
pub fn put_extrema(
    out: &mut BTreeMap<String, [f64; 2]>,
    name: &str,
    values: impl Iterator<Item = f64>,
) {
    let mm = values.fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], v| {
        [a.min(v), b.max(v)]
    });
    if mm[0] <= mm[1] {
        out.insert(name.to_string(), mm);
    }
}

/// Extrema of the disk fields: `radius vx vy speed omega ux uy`.
pub fn disk_extrema(d: &Disks) -> BTreeMap<String, [f64; 2]> {
    let mut out = BTreeMap::new();
    put_extrema(&mut out, "radius", d.r.iter().copied());
    put_extrema(&mut out, "vx", d.v.iter().map(|v| v[0]));
    put_extrema(&mut out, "vy", d.v.iter().map(|v| v[1]));
    put_extrema(
        &mut out,
        "speed",
        d.v.iter().map(|v| (v[0] * v[0] + v[1] * v[1]).sqrt()),
    );
    put_extrema(&mut out, "omega", d.omega.iter().copied());
    put_extrema(&mut out, "ux", (0..d.len()).map(|i| d.displacement(i)[0]));
    put_extrema(&mut out, "uy", (0..d.len()).map(|i| d.displacement(i)[1]));
    out
}

/// `<name>_contacts.pvd` in output folder `out`.
pub fn contacts_pvd_path(ls: &LoadedScene, out: &Path) -> std::path::PathBuf {
    out.join(format!("{}_contacts.pvd", ls.scene.scene.name))
}

/// Write `particles_NNNN.vtp` (with the `extra` point data) and `contacts_NNNN.vtp`
/// into `dir`, and add the contacts file to `<name>_contacts.pvd` next to `dir`;
/// returns the particles file name.
pub fn write_vtk(
    ls: &LoadedScene,
    dir: &Path,
    index: usize,
    time: f64,
    d: &Disks,
    extra: &[(&str, &[f64])],
    lines: &[ContactLine],
    contacts_pvd: &RefCell<Option<PvdWriter>>,
) -> Result<String, RunError> {
    write_vtk_with(ls, dir, index, time, d, extra, lines, &[], contacts_pvd)
}

/// [`write_vtk`] with extra cell data of the contact lines (`line_extra`: name, one
/// value per line).
pub fn write_vtk_with(
    ls: &LoadedScene,
    dir: &Path,
    index: usize,
    time: f64,
    d: &Disks,
    extra: &[(&str, &[f64])],
    lines: &[ContactLine],
    line_extra: &[(&str, &[f64])],
    contacts_pvd: &RefCell<Option<PvdWriter>>,
) -> Result<String, RunError> {
    let io = |e: porofrac_particles::ParticleError| {
        RunError::Output(crate::common::output::OutputError {
            path: dir.to_path_buf(),
            source: std::io::Error::other(e.to_string()),
        })
    };
    let particles = format!("particles_{index:04}.vtp");
    let contacts = format!("contacts_{index:04}.vtp");
    write_particles_with(&dir.join(&particles), d, extra).map_err(io)?;
    write_contacts_with(&dir.join(&contacts), lines, line_extra).map_err(io)?;
    let mut pvd = contacts_pvd.borrow_mut();
    if pvd.is_none() {
        let parent = dir.parent().unwrap_or(Path::new("."));
        *pvd = Some(PvdWriter::create(contacts_pvd_path(ls, parent))?);
    }
    if let Some(pvd) = pvd.as_mut() {
        pvd.add(time, format!("vtk/{contacts}"))?;
    }
    Ok(particles)
}

fn perr<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError {
        path: path.to_path_buf(),
        what: e.to_string(),
    }
}

/// What a picture of disks shows: a title, a value per disk (coloured by the 1st–99th
/// percentile, [`crate::common::plots::ColourRange`]) and the colour bar's name (field
/// and unit), segments drawn over the disks in black (broken bonds).
#[derive(Clone, Copy, Debug)]
pub struct DiskPicture<'a> {
    /// The title.
    pub title: &'a str,
    /// One value per disk.
    pub values: &'a [f64],
    /// The colour bar's name (`displacement [m]`).
    pub bar: &'a str,
    /// The unit of the values (caption).
    pub unit: &'a str,
    /// Segments drawn over the disks.
    pub segments: &'a [([f64; 2], [f64; 2])],
}

/// A picture of the disks at their current position (x and y axes in metres), disk i
/// coloured by `picture.values[i]`, with a colour bar (written atomically).
pub fn draw_disks(path: &Path, d: &Disks, picture: &DiskPicture<'_>) -> Result<(), PlotError> {
    if d.is_empty() {
        return Ok(());
    }
    crate::common::plots::register_font();
    std::fs::create_dir_all(path.parent().unwrap_or(Path::new("."))).map_err(perr(path))?;
    let b = d.x.iter().zip(&d.r).fold(
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
    );
    let (w, h) = ((b[1] - b[0]).max(1e-9), (b[3] - b[2]).max(1e-9));
    let range = crate::common::plots::ColourRange::of(picture.values.iter().copied(), 0.0, false);
    let (width, bar_w, footer) = (1200u32, 140u32, 26u32);
    let plot_w = (width - bar_w - 95) as f64;
    let height = (plot_w * h / w + 110.0 + footer as f64).clamp(300.0, 2400.0) as u32;
    crate::common::plots::atomic_png(
        path,
        |tmp| {
            let root = BitMapBackend::new(tmp, (width, height)).into_drawing_area();
            root.fill(&WHITE).map_err(perr(path))?;
            let (top, foot) = root.split_vertically(height - footer);
            foot.draw(&Text::new(
                range.caption(picture.unit),
                (12, 4),
                ("sans-serif", 15).into_font().color(&BLACK),
            ))
            .map_err(perr(path))?;
            let (main, bar) = top.split_horizontally(width - bar_w);
            let mut chart = ChartBuilder::on(&main)
                .caption(picture.title, ("sans-serif", 22))
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(60)
                .build_cartesian_2d(b[0]..b[1], b[2]..b[3])
                .map_err(perr(path))?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc("x [m]")
                .y_desc("y [m]")
                .x_label_formatter(&crate::common::plots::axis_ticks(b[0], b[1]))
                .y_label_formatter(&crate::common::plots::axis_ticks(b[2], b[3]))
                .draw()
                .map_err(perr(path))?;
            let (xr, yr) = chart.plotting_area().get_pixel_range();
            // Pixels per metre (the smaller of the two axes, so disks stay round).
            let scale = ((xr.end - xr.start) as f64 / w).min((yr.end - yr.start) as f64 / h);
            let colour =
                |i: usize| range.colour(picture.values.get(i).copied().unwrap_or(f64::NAN));
            chart
                .draw_series((0..d.len()).map(|i| {
                    let r = ((d.r[i] * scale).round() as i32).max(1);
                    Circle::new((d.x[i][0], d.x[i][1]), r, colour(i).filled())
                }))
                .map_err(perr(path))?;
            chart
                .draw_series(picture.segments.iter().map(|(a, c)| {
                    PathElement::new(vec![(a[0], a[1]), (c[0], c[1])], BLACK.stroke_width(2))
                }))
                .map_err(perr(path))?;
            crate::common::plots::colour_bar(&bar, &range, picture.bar).map_err(perr(path))?;
            root.present().map_err(perr(path))?;
            Ok(())
        },
        perr::<String>(path),
    )
}
