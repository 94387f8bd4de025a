//! End-of-run plots of a continuum scene: the probe time series, the last state's fields
//! (2D: the grid; 3D: the mid-height section) and, after fracturing in 2D, Figs. 4 and 5 of
//! Nilsen et al. (2017).

use std::path::Path;

use porofrac_frac::FailureState;
use porofrac_frac::recovery::{NodeCells, recover_nodal};
use porofrac_grid::{Grid, Point};
use porofrac_law::{Tensor, principal};

use crate::common::loaded::LoadedScene;
use crate::common::model::RunError;
use crate::common::plots::{Column, FieldPlot, label, tick};
use crate::continuum::fields;

/// What the end-of-run plots show: the probe series at the written times, the last
/// displacement and cell stresses, the failures and the pressure.
pub(crate) struct PlotInputs<'a, const D: usize> {
    /// Probe values at the written times, one series per probe.
    pub series: &'a [Vec<f64>],
    /// The written times.
    pub written_times: &'a [f64],
    /// The last displacement.
    pub u: &'a [f64],
    /// The last cell stresses.
    pub stress: &'a [Tensor<D>],
    /// The failures.
    pub failures: &'a FailureState,
    /// The last pressure, with flow.
    pub pressure: Option<&'a [f64]>,
}

/// `plots/`: the probe time series, the last state's fields (2D: the grid; 3D: the
/// mid-height section) and, after fracturing in 2D, Figs. 4 and 5 of Nilsen et al. (2017).
pub(crate) fn write_plots<const D: usize>(
    ls: &LoadedScene,
    dir: &Path,
    grid: &Grid<D>,
    inputs: PlotInputs<'_, D>,
) -> Result<(), RunError> {
    let s = &ls.scene;
    let PlotInputs {
        series,
        written_times,
        u,
        stress,
        failures,
        pressure,
    } = inputs;
    let columns: Vec<Column> = s
        .output
        .probe
        .iter()
        .zip(series)
        .map(|(p, v)| Column::new(p.name.clone(), fields::unit(&p.field), v.clone()))
        .collect();
    if !columns.is_empty() {
        crate::common::plots::time_series(
            &dir.join("probes.png"),
            written_times,
            &columns,
            &format!("{}: probes", s.scene.name),
        )?;
    }
    {
        // 2D: the grid; 3D: its cross-section at mid-height (shifted off a layer of
        // nodes by 1e-4 of the height, so extruded grids are cut inside a layer).
        let (canvas, where_) = match (as_2d(grid), as_3d(grid)) {
            (Some(g2), _) => (crate::common::plots::Canvas::of_grid(g2), String::new()),
            (_, Some(g3)) => {
                let (lo, hi) = g3.bounding_box();
                let z = lo[2] + (0.5 + 1e-4) * (hi[2] - lo[2]);
                (
                    crate::common::plots::Canvas::z_slice(g3, z),
                    format!(" on z = {} m", tick(0.5 * (lo[2] + hi[2]))),
                )
            }
            _ => unreachable!("grids are 2D or 3D"),
        };
        let marked = failures.flags().to_vec();
        let cell_mean = |a: usize| -> Vec<f64> {
            (0..grid.num_cells())
                .map(|c| {
                    let nodes = grid.cell_nodes(c);
                    nodes.iter().map(|&p| u[D * p + a]).sum::<f64>() / nodes.len() as f64
                })
                .collect()
        };
        let comp = |i: usize, j: usize| -> Vec<f64> { stress.iter().map(|s| s[(i, j)]).collect() };
        let (smax, smin): (Vec<f64>, Vec<f64>) = stress
            .iter()
            .map(|s| {
                let p = principal(s);
                (p.values[0], p.values[D - 1])
            })
            .unzip();
        let mut plots: Vec<(&str, Vec<f64>)> = vec![("ux", cell_mean(0)), ("uy", cell_mean(1))];
        if D == 3 {
            plots.push(("uz", cell_mean(2)));
        }
        plots.extend([("sxx", comp(0, 0)), ("syy", comp(1, 1))]);
        if D == 3 {
            plots.push(("szz", comp(2, 2)));
        }
        plots.extend([
            ("sxy", comp(0, 1)),
            ("smax", smax),
            ("smin", smin),
            ("divergence", cell_divergence(grid, u)),
        ]);
        if let Some(p) = &pressure {
            plots.push(("pressure", p.to_vec()));
        }
        let t_last = written_times.last().copied().unwrap_or(0.0);
        let noise = noise_floors(&plots);
        for (name, vals) in &plots {
            let (long, short, unit) = quantity(name);
            let title = format!("{}: {long} at t = {} s{where_}", s.scene.name, tick(t_last));
            let bar = label(short, unit);
            let mut plot = FieldPlot::new(&canvas, &title, &bar, unit, &marked);
            plot.noise = noise(name);
            crate::common::plots::field(
                &dir.join(format!("{name}.png")),
                &plot,
                crate::common::plots::Values::Cell(vals),
            )?;
        }
        if let (Some(g2), true) = (as_2d(grid), failures.count() > 0) {
            // Figs. 4 and 5 of Nilsen et al. (2017).
            let stress2: Vec<Tensor<2>> = stress
                .iter()
                .map(|s| Tensor::<2>::from_fn(|i, j| s[(i, j)]))
                .collect();
            fracture_plots(
                dir,
                g2,
                &canvas,
                &plots,
                &stress2,
                &marked,
                failures.log().iter().map(|f| f.cell),
                t_last,
            )?;
        }
    }
    Ok(())
}

/// What a field plot is called in its title, in its colour bar, and its unit:
/// `("σ_max (largest principal)", "σ_max", "Pa")`.
fn quantity(name: &str) -> (&'static str, &'static str, &'static str) {
    match name {
        "ux" => ("u_x", "u_x", "m"),
        "uy" => ("u_y", "u_y", "m"),
        "uz" => ("u_z", "u_z", "m"),
        "sxx" => ("σ_xx", "σ_xx", "Pa"),
        "syy" => ("σ_yy", "σ_yy", "Pa"),
        "szz" => ("σ_zz", "σ_zz", "Pa"),
        "sxy" => ("σ_xy", "σ_xy", "Pa"),
        "smax" => ("σ_max (largest principal stress)", "σ_max", "Pa"),
        "smin" => ("σ_min (smallest principal stress)", "σ_min", "Pa"),
        "divergence" => ("div u (volume strain)", "div u", "1"),
        "pressure" => ("pore pressure", "p", "Pa"),
        _ => ("value", "value", "1"),
    }
}

/// The round-off level of each plotted field: 1e-9 of the largest displacement for
/// displacements, of the largest stress component for stresses (a shear stress that is
/// zero up to round-off is then drawn uniform), of its own largest value otherwise.
fn noise_floors<'a>(plots: &'a [(&str, Vec<f64>)]) -> impl Fn(&str) -> f64 + 'a {
    let largest = |pred: &dyn Fn(&str) -> bool| {
        plots
            .iter()
            .filter(|(n, _)| pred(n))
            .flat_map(|(_, v)| v.iter())
            .filter(|x| x.is_finite())
            .fold(0.0f64, |m, x| m.max(x.abs()))
    };
    let u = largest(&|n| n.starts_with('u'));
    let stress = largest(&|n| n.starts_with('s'));
    move |name: &str| {
        1e-9 * if name.starts_with('u') {
            u
        } else if name.starts_with('s') {
            stress
        } else {
            0.0
        }
    }
}

/// Cell divergence of the displacement, `div u = Σ_i N_i · u_i / |K|`
/// ([`porofrac_vem::volumetric_strain`]: the exact volume change of the VEM projection per
/// unit volume; Nilsen et al. (2017) Fig. 4, upper right).
fn cell_divergence<const D: usize>(grid: &Grid<D>, u: &[f64]) -> Vec<f64> {
    let mut geometry = porofrac_law::GeometryBuffer::<D>::default();
    let mut local = Vec::new();
    (0..grid.num_cells())
        .map(|c| {
            local.clear();
            for &n in grid.cell_nodes(c) {
                local.extend_from_slice(&u[D * n..D * n + D]);
            }
            porofrac_vem::volumetric_strain(&geometry.load(grid, c), &local)
        })
        .collect()
}

/// Principal directions (unit, of the largest and the smallest principal stress).
fn principal_directions(s: &Tensor<2>) -> ([f64; 2], [f64; 2]) {
    let d = principal(s).directions;
    ([d[0][0], d[0][1]], [d[1][0], d[1][1]])
}

/// A square window around the points, padded by 30 % and half a metre, inside the grid.
fn window_around(grid: &Grid<2>, pts: &[Point<2>], pad: f64) -> ([f64; 2], [f64; 2]) {
    let (glo, ghi) = grid.bounding_box();
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in pts {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let half = 0.5 * (hi[0] - lo[0]).max(hi[1] - lo[1]) * 1.3 + pad;
    let mut w = ([0.0; 2], [0.0; 2]);
    for a in 0..2 {
        let m = 0.5 * (lo[a] + hi[a]);
        w.0[a] = (m - half).max(glo[a]);
        w.1[a] = (m + half).min(ghi[a]);
    }
    w
}

/// Plots of a fractured 2D scene, like Figs. 4 and 5 of Nilsen et al. (2017), in
/// `plots/fracture/`: the fields of `plots` zoomed on the fractured cells (principal
/// directions on `smax` and `smin`), and near the crack tip (the last cell to fail) the
/// largest principal stress of the cells next to the Zienkiewicz–Zhu recovered one (Fig. 5).
#[allow(clippy::too_many_arguments)]
fn fracture_plots(
    dir: &Path,
    grid: &Grid<2>,
    canvas: &crate::common::plots::Canvas,
    plots: &[(&str, Vec<f64>)],
    stress: &[Tensor<2>],
    marked: &[bool],
    failed_in_order: impl Iterator<Item = usize>,
    t: f64,
) -> Result<(), RunError> {
    let dir = dir.join("fracture");
    let order: Vec<usize> = failed_in_order.collect();
    let centroids: Vec<Point<2>> = order.iter().map(|&c| *grid.cell_centroid(c)).collect();
    let window = window_around(grid, &centroids, 0.5);
    let (dmax, dmin): (Vec<[f64; 2]>, Vec<[f64; 2]>) =
        stress.iter().map(principal_directions).unzip();
    let noise = noise_floors(plots);
    for (name, vals) in plots {
        let (long, short, unit) = quantity(name);
        let title = format!("{long} at t = {} s, near the fracture", tick(t));
        let bar = label(short, unit);
        let mut plot = FieldPlot::new(canvas, &title, &bar, unit, marked);
        plot.noise = noise(name);
        plot.window = Some(window);
        plot.directions = match *name {
            "smax" => Some(&dmax),
            "smin" => Some(&dmin),
            _ => None,
        };
        crate::common::plots::field(
            &dir.join(format!("{name}.png")),
            &plot,
            crate::common::plots::Values::Cell(vals),
        )?;
    }
    // Fig. 5: cell stress against recovered stress at the tip.
    let Some(&tip) = order.last() else {
        return Ok(());
    };
    let h = grid.cell_volume(tip).sqrt();
    let tip_window = window_around(grid, &[*grid.cell_centroid(tip)], 6.0 * h);
    let nodal = recover_nodal(grid, &NodeCells::new(grid), stress);
    let smax_cell: Vec<f64> = stress.iter().map(|s| principal(s).values[0]).collect();
    let smax_nodal: Vec<f64> = nodal.iter().map(|s| principal(s).values[0]).collect();
    for (file, title, values) in [
        (
            "tip_smax_cell.png",
            format!("σ_max of the cells near the tip, t = {} s", tick(t)),
            crate::common::plots::Values::Cell(&smax_cell),
        ),
        (
            "tip_smax_recovered.png",
            format!("σ_max recovered (ZZ patch) near the tip, t = {} s", tick(t)),
            crate::common::plots::Values::Nodal(&smax_nodal),
        ),
    ] {
        let mut plot = FieldPlot::new(canvas, &title, "σ_max [Pa]", "Pa", marked);
        plot.window = Some(tip_window);
        crate::common::plots::field(&dir.join(file), &plot, values)?;
    }
    Ok(())
}

/// The grid as a 2D grid, if it is one (plots are 2D only).
fn as_2d<const D: usize>(grid: &Grid<D>) -> Option<&Grid<2>> {
    (grid as &dyn std::any::Any).downcast_ref::<Grid<2>>()
}

/// The grid as a 3D grid, if it is one.
fn as_3d<const D: usize>(grid: &Grid<D>) -> Option<&Grid<3>> {
    (grid as &dyn std::any::Any).downcast_ref::<Grid<3>>()
}
