//! The loop every model runs in: step through the output times, sample the probes into
//! `probes.csv` every `[output] probe_every` steps (default: every step), write
//! `lines/<name>.csv`, the VTK series and `<name>.pvd` at the written steps (every
//! `[output] every` steps, the first and the last), report progress, honour
//! interruption, plot the probes and lines, and put together `summary.json`.
//!
//! CSV headers carry units: `time [s]`, `p_well [Pa]` ([`column()`]).
//!
//! Every file is rewritten atomically after each written step, so whatever stops a run
//! (an error, Ctrl-C, a killed process) leaves complete files of the finished steps.
//!
//! **Stopping inside long phases.** The loop polls [`Observer::stop_requested`] between
//! steps. Phases that can take long on their own — building a model (packing, settling,
//! calibration, lattice set-up) and the inner sub-steps of one output step — poll too:
//! a model's build gets a [`SetupPoll`] (progress lines such as
//! `packing: placing disks 1.2 M / 6.5 M` through [`Observer::setup`], and the stop
//! request), and keeps the observer's [`Stop`] handle for its steps. The model crates
//! below know neither: they take a callback that returns `true` to stop. A phase that
//! stops returns [`RunError::Interrupted`]: during the build the run ends with
//! `"status": "interrupted at t = 0"` and no step; during a step the loop ends at the
//! last written time, as an interruption between steps does.
//!
//! **No inf or NaN in the files.** Before a step is written, its probe values, line
//! values and the extrema of its fields are checked: a value that is not finite ends the
//! run with an error naming the probe, line (or field) and the time, instead of a file
//! holding it. The one exception is a probe the model declares possibly undefined
//! ([`Model::probe_may_be_undefined`]: a fluid probe inside a solid disk is NaN).

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use porofrac_grid::io::PvdWriter;

use crate::common::loaded::{LoadedScene, k, ki};
use crate::common::model::{Model, RunError};
use crate::common::output::{CsvTable, OutputError, Summary, WallSeconds, peak_memory_bytes};
use crate::common::snapshot::Snapshot;

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
    /// What has failed so far, in the model's terms (`failed_name`).
    pub failed: usize,
    /// What `failed` counts (`"fractured cells"`, `"broken bonds"`); `None` for a model
    /// in which nothing fails (the progress line then leaves the count out).
    pub failed_name: Option<&'static str>,
}

/// Where the build of a model is: `done` of `total` units of a phase (see
/// [`Observer::setup`]).
#[derive(Clone, Copy, Debug)]
pub struct SetupReport<'a> {
    /// The phase and what it counts, e.g. `"packing: placing disks"`.
    pub what: &'a str,
    /// Units done.
    pub done: usize,
    /// Units in all (an estimate where the end is not known in advance).
    pub total: usize,
}

impl std::fmt::Display for SetupReport<'_> {
    /// `packing: placing disks 1.2 M / 6.5 M`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} {} / {}",
            self.what,
            count_text(self.done),
            count_text(self.total)
        )
    }
}

/// `950`, `12.3 k`, `1.2 M`.
fn count_text(n: usize) -> String {
    let x = n as f64;
    if x >= 1e6 {
        format!("{:.1} M", x / 1e6)
    } else if x >= 1e4 {
        format!("{:.1} k", x / 1e3)
    } else {
        n.to_string()
    }
}

/// Watches a run: progress after every step and during set-up, and a way to stop it.
pub trait Observer: Send {
    /// Called after every step.
    fn step(&mut self, report: &StepReport) {
        let _ = report;
    }
    /// Called now and then (at most a few times a second) while a model is built.
    fn setup(&mut self, report: &SetupReport<'_>) {
        let _ = report;
    }
    /// Polled after every step and during set-up: `true` ends the run there, with
    /// complete files and `"status": "interrupted at t = …"`.
    fn stop_requested(&self) -> bool {
        false
    }
    /// A handle a model keeps to poll the same request inside a long step (never stops
    /// by default: an observer whose [`Observer::stop_requested`] can become `true`
    /// should return a handle that reads the same flag, [`Stop::from_flag`]).
    fn stop_handle(&self) -> Stop {
        Stop::never()
    }
    /// Whether the observer keeps the results of a run kept in memory
    /// ([`crate::Scene::run_in_memory`]): only then are [`Observer::columns`],
    /// [`Observer::sampled`] and [`Observer::written`] called and snapshots made. No by
    /// default.
    fn records(&self) -> bool {
        false
    }
    /// Whether a recording observer wants the model's state at the written steps
    /// ([`Observer::written`] gets `None` otherwise); as [`Observer::records`] by default.
    fn snapshots(&self) -> bool {
        self.records()
    }
    /// Before the first step: the probe columns and, per line, its columns, with units
    /// (`p_well [Pa]`), as the CSV headers have them (`time [s]` first).
    fn columns(&mut self, probes: &[String], lines: &[Vec<String>]) {
        let _ = (probes, lines);
    }
    /// The probe values at time `time` (s), in scene order, at every sampled step.
    fn sampled(&mut self, time: f64, probes: &[f64]) {
        let _ = (time, probes);
    }
    /// A written step: its time (s), the rows of every line (`s, x, y(, z), value`) and
    /// the model's state.
    fn written(&mut self, time: f64, lines: &[Vec<Vec<f64>>], snapshot: Option<Snapshot>) {
        let _ = (time, lines, snapshot);
    }
}

/// A cheap, clonable handle on a run's stop request, polled by the inner loops of long
/// steps (see the module docs).
#[derive(Clone, Default)]
pub struct Stop(Option<Arc<AtomicBool>>);

impl std::fmt::Debug for Stop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Stop({})", self.requested())
    }
}

impl Stop {
    /// A handle that never asks to stop.
    pub fn never() -> Self {
        Self(None)
    }

    /// A handle that asks to stop once `flag` is set (e.g. by a Ctrl-C handler).
    pub fn from_flag(flag: Arc<AtomicBool>) -> Self {
        Self(Some(flag))
    }

    /// The flag itself, for the model crates that take one (`None`: never stops).
    pub fn flag(&self) -> Option<Arc<AtomicBool>> {
        self.0.clone()
    }

    /// Whether the run should stop now.
    pub fn requested(&self) -> bool {
        self.0.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
    }
}

/// What a model's build polls: it reports progress to the observer (at most five times
/// a second) and says whether to stop. Made by the driver's caller from the observer;
/// [`SetupPoll::callback`] gives the `FnMut(Progress) -> bool` the particle crates take.
pub struct SetupPoll<'o> {
    observer: &'o mut dyn Observer,
    phase: &'static str,
    last: Option<Instant>,
}

impl<'o> SetupPoll<'o> {
    /// Poll `observer` during a build.
    pub fn new(observer: &'o mut dyn Observer) -> Self {
        Self {
            observer,
            phase: "",
            last: None,
        }
    }

    /// Name the phase that follows (`"packing"`, `"settling"`, ...), shown before the
    /// unit of each report.
    pub fn phase(&mut self, phase: &'static str) -> &mut Self {
        self.phase = phase;
        self
    }

    /// Report `done` of `total` units of `what` (throttled); `true` when the run should
    /// stop.
    pub fn poll(&mut self, what: &str, done: usize, total: usize) -> bool {
        let now = Instant::now();
        if self
            .last
            .is_none_or(|t| now.duration_since(t) >= Duration::from_millis(200))
        {
            self.last = Some(now);
            let what = if self.phase.is_empty() {
                what.to_string()
            } else {
                format!("{}: {what}", self.phase)
            };
            self.observer.setup(&SetupReport {
                what: &what,
                done,
                total,
            });
        }
        self.observer.stop_requested()
    }

    /// The poll as the callback of the particle crates.
    pub fn callback(&mut self) -> impl FnMut(porofrac_particles::Progress) -> bool + '_ {
        |p| self.poll(p.what, p.done, p.total)
    }

    /// `Err(RunError::Interrupted)` when the run should stop (between two phases).
    pub fn check(&mut self) -> Result<(), RunError> {
        if self.observer.stop_requested() {
            Err(RunError::Interrupted)
        } else {
            Ok(())
        }
    }

    /// The observer's handle for the steps of the model.
    pub fn stop_handle(&self) -> Stop {
        self.observer.stop_handle()
    }
}

/// The summary of a run stopped while its model was being built: no step,
/// `"status": "interrupted at t = 0"`.
pub(crate) fn interrupted_in_setup(ls: &LoadedScene, start: Instant, dim: usize) -> Summary {
    let wall = WallSeconds {
        total: start.elapsed().as_secs_f64(),
        ..WallSeconds::default()
    };
    Summary {
        scene: ls.scene.scene.name.clone(),
        model: ls.model().to_string(),
        dim,
        cells: None,
        nodes: None,
        dofs: None,
        sizes_text: String::new(),
        steps: 0,
        status: "interrupted at t = 0".into(),
        interrupted_at: Some(0.0),
        fractured_cells: None,
        wall_seconds: wall,
        peak_memory_bytes: peak_memory_bytes(),
        solver: Default::default(),
        field_extrema: BTreeMap::new(),
        errors: BTreeMap::new(),
        version: env!("CARGO_PKG_VERSION").into(),
        overrides: ls.overrides(),
        extra: serde_json::Map::new(),
    }
}

/// `Err` naming the probe (or field) when a value about to be written is not finite.
fn check_finite(
    ls: &LoadedScene,
    t: f64,
    probes: &[f64],
    extrema: &BTreeMap<String, [f64; 2]>,
    may_be_undefined: &dyn Fn(usize) -> bool,
) -> Result<(), RunError> {
    let s = &ls.scene;
    if let Some((i, v)) = probes
        .iter()
        .enumerate()
        .find(|(i, v)| v.is_infinite() || (v.is_nan() && !may_be_undefined(*i)))
    {
        let key = ki("output.probe", i, &["field"]);
        return Err(ls
            .error(
                &key,
                format!(
                    "= \"{}\" is {v} at t = {t:e} s: the run diverged or the value is \
                     undefined there; nothing of this step was written",
                    s.output.probe[i].field
                ),
            )
            .into());
    }
    if let Some((name, [lo, hi])) = extrema
        .iter()
        .find(|(_, [lo, hi])| !(lo.is_finite() && hi.is_finite()))
    {
        return Err(ls
            .error(
                &k(&["schedule"]),
                format!(
                    ": field {name} reaches [{lo}, {hi}] at t = {t:e} s: the run diverged \
                     (lower the time step); nothing of this step was written"
                ),
            )
            .into());
    }
    Ok(())
}

/// A CSV column header: the name and the unit in brackets, `p_well [Pa]`, `time [s]`;
/// the name alone for numbers without a unit (`"1"`: ratios, counts, flags, indices).
/// A reader takes the name as what comes before ` [`.
pub fn column(name: &str, unit: &str) -> String {
    if unit == "1" || unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} [{unit}]")
    }
}

/// An observer that reports nothing and never stops a run.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Observer for Silent {}

/// Drive `model` through its times, writing the shared outputs into `out` (nothing
/// without it: a run kept in memory for the observer, [`Observer::records`]). `wall`
/// holds the time already spent (grid) and `start` the start of the run.
pub(crate) fn drive(
    ls: &LoadedScene,
    model: &mut dyn Model,
    out: Option<&Path>,
    observer: &mut dyn Observer,
    start: Instant,
    grid_seconds: f64,
    dim: usize,
) -> Result<Summary, RunError> {
    let s = &ls.scene;
    let mut output_seconds = 0.0;
    let mut header = vec![column("time", "s")];
    header.extend(
        s.output
            .probe
            .iter()
            .map(|p| column(&p.name, model.unit(&p.field))),
    );
    let axes = ["x", "y", "z"];
    let line_headers: Vec<Vec<String>> = s
        .output
        .line
        .iter()
        .map(|l| {
            let mut line_header = vec![column("time", "s"), column("s", "m")];
            line_header.extend(axes[..dim].iter().map(|a| column(a, "m")));
            line_header.push(column(&l.field, model.unit(&l.field)));
            line_header
        })
        .collect();
    let records = observer.records();
    if records {
        observer.columns(&header, &line_headers);
    }
    // A run kept in memory (no `out`) writes nothing: no tables, VTK, plots or
    // checkpoints.
    let mut probes = out.map(|out| CsvTable::new(out.join("probes.csv"), &header));
    let mut lines: Vec<CsvTable> = s
        .output
        .line
        .iter()
        .zip(line_headers)
        .filter_map(|(l, line_header)| {
            let out = out?;
            Some(CsvTable::new(
                out.join("lines").join(format!("{}.csv", l.name)),
                &line_header,
            ))
        })
        .collect();
    // Snapshots of every line for its end-of-run plot: the rows at (up to) six of the
    // written times, spread over the run, and the last one.
    let mut line_snapshots: Vec<Vec<(f64, Vec<Vec<f64>>)>> = vec![Vec::new(); lines.len()];
    let vtk_dir = out.map(|out| out.join("vtk")).unwrap_or_default();
    let mut pvd = match out {
        Some(out) if s.output.vtk => {
            std::fs::create_dir_all(&vtk_dir).map_err(|source| OutputError {
                path: vtk_dir.clone(),
                source,
            })?;
            Some(PvdWriter::create(
                out.join(format!("{}.pvd", s.scene.name)),
            )?)
        }
        _ => None,
    };

    let times = model.times().to_vec();
    let probe_every = s.output.probe_every.max(1) as usize;
    let write_every = s.output.every.max(1) as usize;
    // The written steps a complete run has, and the ones whose lines are plotted.
    let planned_writes = (times.len().saturating_sub(1)).div_ceil(write_every) + 1;
    let snapshot_stride = planned_writes.div_ceil(6).max(1);
    let failed_name = model.sizes().failed;
    let mut series: Vec<Vec<f64>> = vec![Vec::new(); s.output.probe.len()];
    let mut sampled: Vec<f64> = Vec::new();
    let mut written: Vec<f64> = Vec::new();
    let mut extrema = BTreeMap::new();
    let mut total_iterations = 0;
    let mut steps = 0;
    let mut interrupted = None;
    let mut row = Vec::new();
    // Checkpoints and resuming (crate::common::checkpoint).
    let checkpoint_every = s.output.checkpoint_every as usize;
    let checkpoint_every = if out.is_some() { checkpoint_every } else { 0 };
    if (checkpoint_every > 0 || ls.resume) && !model.checkpoints() {
        return Err(ls
            .error(
                &k(&["output", "checkpoint_every"]),
                format!(
                    ": model \"{}\" cannot write or resume from checkpoints",
                    ls.model()
                ),
            )
            .into());
    }
    let mut first = 0;
    if let (true, Some(out), Some(probes)) = (ls.resume, out, probes.as_mut()) {
        let r = crate::common::checkpoint::resume(
            ls,
            out,
            model,
            probes,
            &mut lines,
            &mut pvd,
            series.len(),
        )?;
        first = r.step + 1;
        sampled = r.sampled;
        written = r.written;
        series = r.series;
        extrema = r.extrema;
        total_iterations = r.total_iterations;
        steps = r.steps;
    }
    for (step, &t) in times.iter().enumerate().skip(first) {
        let stats = match model.step(step) {
            Err(RunError::Interrupted) => {
                // Stopped inside the step: its state is partial, the files end at the
                // last written step.
                interrupted = Some(written.last().copied().unwrap_or(0.0));
                break;
            }
            r => r?,
        };
        match out {
            Some(out) => model.after_step(out)?,
            None => model.after_step_in_memory()?,
        }
        let stop = step + 1 < times.len() && observer.stop_requested();
        let last = step + 1 == times.len();
        // Written steps (VTK, lines) of a run that goes on, and its probe samples
        // (sampling only reads the state).
        let regular = step == 0 || step.is_multiple_of(write_every) || last;
        let sampled_here = regular || step.is_multiple_of(probe_every);
        // Sample the probes (`probe`) and write the lines and VTK file (`write`) of this
        // step; every value is checked before anything of the step is written.
        macro_rules! output_step {
            ($probe:expr, $write:expr) => {{
                let (probe, write): (bool, bool) = ($probe, $write);
                let t_out = Instant::now();
                row.clear();
                row.push(t);
                let first = row.len();
                model.probes(&mut row);
                let step_extrema = if write {
                    model.field_extrema()
                } else {
                    BTreeMap::new()
                };
                check_finite(ls, t, &row[first..], &step_extrema, &|i| {
                    model.probe_may_be_undefined(i)
                })?;
                let n_lines = s.output.line.len();
                let mut line_rows: Vec<Vec<Vec<f64>>> = Vec::with_capacity(n_lines);
                for i in (0..n_lines).filter(|_| write) {
                    let mut rows = Vec::new();
                    model.line(i, &mut rows);
                    if let Some(v) = rows.iter().flatten().find(|v| !v.is_finite()) {
                        return Err(ls
                            .error(
                                &ki("output.line", i, &["field"]),
                                format!(
                                    "= \"{}\" is {v} at a point of the line at t = {t:e} s: \
                                     the run diverged or the value is undefined there",
                                    s.output.line[i].field
                                ),
                            )
                            .into());
                    }
                    line_rows.push(rows);
                }
                if probe {
                    for (j, v) in row[first..].iter().enumerate() {
                        series[j].push(*v);
                    }
                    if let Some(probes) = probes.as_mut() {
                        probes.push(&row)?;
                    }
                    if records {
                        observer.sampled(t, &row[first..]);
                    }
                    sampled.push(t);
                }
                if write && records {
                    let state = observer
                        .snapshots()
                        .then(|| model.snapshot(written.is_empty()))
                        .flatten()
                        .map(|mut state| {
                            state.time = t;
                            state
                        });
                    observer.written(t, &line_rows, state);
                }
                if write {
                    let snapshot = last || stop || written.len().is_multiple_of(snapshot_stride);
                    for ((table, mut rows), snaps) in
                        lines.iter_mut().zip(line_rows).zip(&mut line_snapshots)
                    {
                        if snapshot && s.output.plots {
                            snaps.push((t, rows.clone()));
                        }
                        for r in &mut rows {
                            r.insert(0, t);
                        }
                        table.push_rows(&rows)?;
                    }
                    if let Some(pvd) = pvd.as_mut() {
                        let name = model.write_vtk(&vtk_dir, written.len())?;
                        pvd.add(t, format!("vtk/{name}"))?;
                    }
                    extrema = step_extrema;
                    written.push(t);
                }
                output_seconds += t_out.elapsed().as_secs_f64();
            }};
        }
        if sampled_here {
            output_step!(true, regular);
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
            failed_name,
        });
        // A checkpoint after this step: every `checkpoint_every` steps, and when stopped.
        // It holds the files as a run that goes on has them: what is written only because
        // the run stops comes after it, so a resumed run does not keep it.
        if let (Some(out), Some(probes)) = (out, probes.as_ref())
            && !last
            && ((checkpoint_every > 0 && step > 0 && step.is_multiple_of(checkpoint_every))
                || (stop && model.checkpoints()))
        {
            let t_out = Instant::now();
            crate::common::checkpoint::save(
                ls,
                out,
                model,
                &crate::common::checkpoint::Progress {
                    step,
                    sampled: &sampled,
                    written: &written,
                    series: &series,
                    extrema: &extrema,
                    total_iterations,
                    steps,
                    probes,
                    lines: &lines,
                    pvd: pvd.as_ref(),
                },
            )?;
            output_seconds += t_out.elapsed().as_secs_f64();
        }
        if stop {
            // The state where the run stopped, written in full.
            if !regular {
                output_step!(!sampled_here, true);
            }
            interrupted = Some(t);
            break;
        }
    }
    let t_out = Instant::now();
    let errors = model.errors()?;
    output_seconds += t_out.elapsed().as_secs_f64();
    if let Some(out) = out.filter(|_| s.output.plots) {
        let t_out = Instant::now();
        model.plots(&out.join("plots"), &sampled, &series)?;
        for (l, snaps) in s.output.line.iter().zip(&line_snapshots) {
            crate::common::plots::line_profiles(
                &out.join("plots").join(format!("line_{}.png", l.name)),
                &format!("{}: {} along line {}", s.scene.name, l.field, l.name),
                &l.field,
                model.unit(&l.field),
                snaps,
            )?;
        }
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
        sizes_text: sizes.counts_text(),
        steps,
        status: match interrupted {
            Some(t) => format!("interrupted at t = {t}"),
            None => "ok".into(),
        },
        interrupted_at: interrupted,
        fractured_cells: (sizes.failed == Some("fractured cells")).then(|| model.failed()),
        wall_seconds: wall,
        peak_memory_bytes: peak_memory_bytes(),
        solver: model.solver_stats(),
        field_extrema: extrema,
        errors,
        version: env!("CARGO_PKG_VERSION").into(),
        overrides: ls.overrides(),
        extra: model.summary_extras(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A value that is not finite names its probe (and its line in the file) or the
    /// field; finite values pass.
    #[test]
    fn values_that_are_not_finite_name_their_probe_or_field() {
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/nscd/column.toml"),
        )
        .unwrap();
        let ls = crate::common::loaded::parse(&text, Path::new("c.toml"), crate::MODELS).unwrap();
        let mut ext = BTreeMap::new();
        ext.insert("vx".to_string(), [-1.0, 1.0]);
        assert!(check_finite(&ls, 0.1, &[1.0, 2.0, 3.0], &ext, &|_| false).is_ok());
        let e = check_finite(&ls, 0.1, &[1.0, f64::INFINITY, 3.0], &ext, &|_| true)
            .unwrap_err()
            .to_string();
        let line = text
            .lines()
            .position(|l| l.contains("field = \"y\""))
            .unwrap()
            + 1;
        assert!(e.contains(&format!("c.toml:{line}:")), "{e}");
        assert!(
            e.contains("output.probe[1]") && e.contains("is inf at t = 1e-1 s"),
            "{e}"
        );
        // NaN passes where the model says the value may be undefined, not elsewhere.
        assert!(check_finite(&ls, 0.1, &[f64::NAN, 2.0, 3.0], &ext, &|i| i == 0).is_ok());
        assert!(check_finite(&ls, 0.1, &[1.0, 2.0, f64::NAN], &ext, &|i| i == 0).is_err());
        ext.insert("speed".to_string(), [0.0, f64::NAN]);
        let e = check_finite(&ls, 0.1, &[1.0, 2.0, 3.0], &ext, &|_| false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("field speed reaches [0, NaN]"), "{e}");
    }
}
