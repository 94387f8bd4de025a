//! The loop every model runs in: step through the output times, write `probes.csv`,
//! `lines/<name>.csv`, the VTK series and `<name>.pvd` at the written steps, report
//! progress, honour interruption, and put together `summary.json`.
//!
//! Every file is rewritten atomically after each written step, so whatever stops a run
//! (an error, Ctrl-C, a killed process) leaves complete files of the finished steps.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use porofrac_grid::io::PvdWriter;

use crate::common::loaded::LoadedScene;
use crate::common::model::{Model, RunError};
use crate::common::output::{CsvTable, OutputError, Summary, WallSeconds, peak_memory_bytes};

/// Where a run is, after each step.
#[derive(Clone, Copy, Debug)]
pub struct StepReport {
    /// Index of the output time just computed (0: the initial state).
    pub step: usize,
    /// Number of output times, the initial one included.
    pub total: usize,
    /// The time reached (s).
    pub time: f64,
    /// Solver iterations of this step.
    pub iterations: usize,
    /// Solver iterations so far.
    pub total_iterations: usize,
    /// Failed cells (or broken bonds) so far.
    pub failed: usize,
}

/// Watches a run: progress after every step, and a way to stop it between steps.
pub trait Observer: Send {
    /// Called after every step.
    fn step(&mut self, report: &StepReport) {
        let _ = report;
    }
    /// Polled after every step: `true` ends the run there, with complete files and
    /// `"status": "interrupted at t = …"`.
    fn stop_requested(&self) -> bool {
        false
    }
}

/// An observer that reports nothing and never stops a run.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Observer for Silent {}

/// Drive `model` through its times, writing the shared outputs into `out`. `wall` holds
/// the time already spent (grid) and `start` the start of the run.
pub(crate) fn drive(
    ls: &LoadedScene,
    model: &mut dyn Model,
    out: &Path,
    observer: &mut dyn Observer,
    start: Instant,
    grid_seconds: f64,
    dim: usize,
) -> Result<Summary, RunError> {
    let s = &ls.scene;
    let mut output_seconds = 0.0;
    let mut header = vec!["time".to_string()];
    header.extend(s.output.probe.iter().map(|p| p.name.clone()));
    let mut probes = CsvTable::new(out.join("probes.csv"), &header);
    let axes = ["x", "y", "z"];
    let mut line_header = vec!["time".to_string(), "s".to_string()];
    line_header.extend(axes[..dim].iter().map(|a| a.to_string()));
    line_header.push("value".into());
    let mut lines: Vec<CsvTable> = s
        .output
        .line
        .iter()
        .map(|l| {
            CsvTable::new(
                out.join("lines").join(format!("{}.csv", l.name)),
                &line_header,
            )
        })
        .collect();
    let vtk_dir = out.join("vtk");
    let mut pvd = if s.output.vtk {
        std::fs::create_dir_all(&vtk_dir).map_err(|source| OutputError {
            path: vtk_dir.clone(),
            source,
        })?;
        Some(PvdWriter::create(
            out.join(format!("{}.pvd", s.scene.name)),
        )?)
    } else {
        None
    };

    let times = model.times().to_vec();
    let mut series: Vec<Vec<f64>> = vec![Vec::new(); s.output.probe.len()];
    let mut written: Vec<f64> = Vec::new();
    let mut extrema = BTreeMap::new();
    let mut total_iterations = 0;
    let mut steps = 0;
    let mut interrupted = None;
    let mut row = Vec::new();
    let mut rows = Vec::new();
    for (step, &t) in times.iter().enumerate() {
        let stats = model.step(step)?;
        model.after_step(out)?;
        let stop = step + 1 < times.len() && observer.stop_requested();
        let write =
            step == 0 || step % s.output.every as usize == 0 || step + 1 == times.len() || stop;
        if write {
            let t_out = Instant::now();
            row.clear();
            row.push(t);
            let first = row.len();
            model.probes(&mut row);
            for (j, v) in row[first..].iter().enumerate() {
                series[j].push(*v);
            }
            probes.push(&row)?;
            for (i, table) in lines.iter_mut().enumerate() {
                rows.clear();
                model.line(i, &mut rows);
                for r in &mut rows {
                    r.insert(0, t);
                }
                table.push_rows(&rows)?;
            }
            if let Some(pvd) = pvd.as_mut() {
                let name = model.write_vtk(&vtk_dir, written.len())?;
                pvd.add(t, format!("vtk/{name}"))?;
            }
            extrema = model.field_extrema();
            written.push(t);
            output_seconds += t_out.elapsed().as_secs_f64();
        }
        if step > 0 {
            steps += 1;
        }
        total_iterations += stats.iterations;
        observer.step(&StepReport {
            step,
            total: times.len(),
            time: t,
            iterations: stats.iterations,
            total_iterations,
            failed: stats.failed,
        });
        if stop {
            interrupted = Some(t);
            break;
        }
    }
    let t_out = Instant::now();
    let errors = model.errors()?;
    output_seconds += t_out.elapsed().as_secs_f64();
    if s.output.plots {
        let t_out = Instant::now();
        model.plots(&out.join("plots"), &written, &series)?;
        output_seconds += t_out.elapsed().as_secs_f64();
    }
    let sizes = model.sizes();
    let mut wall: WallSeconds = model.wall_seconds();
    wall.grid = grid_seconds;
    wall.output += output_seconds;
    wall.total = start.elapsed().as_secs_f64();
    Ok(Summary {
        scene: s.scene.name.clone(),
        model: ls.model().to_string(),
        dim,
        cells: sizes.cells,
        nodes: sizes.nodes,
        dofs: sizes.dofs,
        steps,
        status: match interrupted {
            Some(t) => format!("interrupted at t = {t}"),
            None => "ok".into(),
        },
        interrupted_at: interrupted,
        fractured_cells: model.failed(),
        wall_seconds: wall,
        peak_memory_bytes: peak_memory_bytes(),
        solver: model.solver_stats(),
        field_extrema: extrema,
        errors,
        version: env!("CARGO_PKG_VERSION").into(),
        extra: model.summary_extras(),
    })
}
