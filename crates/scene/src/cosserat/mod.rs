//! `model = "cosserat"`: the variational DEM for Cosserat media (crate
//! `porofrac-cosserat`) driven by a scene (docs/models/cosserat.md).
//!
//! * *build*: the simplex grid (`triangles` with `diagonals = "structured" | "crossed"`,
//!   `tetrahedra`, or a file), the material of the one region, the `[[bc]]` conditions
//!   (displacement and rotation components fixed weakly by the Nitsche terms, traction and
//!   couple traction loaded), `[loads]` body force and couple, `[solver] penalty`;
//! * *step*: without `[schedule]` one static solve (sparse LU); with one, Newmark average
//!   acceleration (one factorisation for the run) or explicit leapfrog with sub-steps
//!   below the computed stable step, from rest;
//! * *fields*: probes and lines (`ux`, `phi`, … P1-reconstructed at the point; stresses
//!   and couple stresses of the containing cell; `energy`, `kinetic`, `work` totals), the
//!   VTK cell data `displacement`, `rotation`, `stress`, `couple_stress` ([`vtk`]), and
//!   plots of σ_yy (whole grid and around its peak) and φ (2D) and of the probe series.

pub mod check;
pub mod fields;
pub mod vtk;

#[cfg(test)]
mod tests;

use crate::common::laws::LawRegistry;
use crate::common::loaded::SceneError;
use crate::common::model::ModelKind;

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use porofrac_cosserat::dynamics::Dynamics;
use porofrac_cosserat::{
    BodyLoads, Condition, Cosserat, CosseratError, GmresOptions, Integrator, Linear, LinearOptions,
    LinearSolver, Material, Options, StencilRule, components,
};
use porofrac_grid::{Grid, Point};

use crate::common::driver::{Observer, Stop};
use crate::common::grid::{AnyGrid, build_grid, point};
use crate::common::loaded::{LoadedScene, k, ki};
use crate::common::model::{Built, Model, Purpose, RunError, Sizes, StepStats};
use crate::common::output::{SolverStats, WallSeconds};
use crate::common::plots::{Canvas, Column, FieldPlot, Values, tick};
use crate::common::sections::{DiagonalsChoice, GridKind, KeyPart, LinearChoice, NumOrExpr};

use crate::common::rotation_keys::{Stencil, TimeIntegration};
use fields::Field;

/// Build a checked cosserat scene's model and hand it to `purpose`.
pub(crate) fn build(
    ls: &LoadedScene,
    purpose: &Purpose<'_>,
    observer: &mut dyn Observer,
) -> Result<Built, RunError> {
    let start = Instant::now();
    let g = &ls.scene.grid;
    let grid = if g.kind == GridKind::Triangles && g.diagonals == Some(DiagonalsChoice::Crossed) {
        let ext = g.extent.clone().expect("checked");
        let n = match &g.cells {
            Some(crate::common::sections::CellCount::PerAxis(v)) => [v[0] as usize, v[1] as usize],
            _ => unreachable!("checked"),
        };
        let (lo, hi) = (point(&ext[0]), point(&ext[1]));
        let amp = g.perturb.unwrap_or(0.0);
        AnyGrid::Two(if amp > 0.0 {
            // The crossed mesh's own jitter: valid triangles up to the documented maximum
            // whatever the aspect ratio of the squares.
            porofrac_cosserat::mesh::crossed_perturbed(lo, hi, n, amp, g.seed.unwrap_or(0))
                .map_err(|e| ls.error(&k(&["grid", "perturb"]), e))?
        } else {
            porofrac_cosserat::mesh::crossed(lo, hi, n)
                .map_err(|e| ls.error(&k(&["grid", "cells"]), e))?
        })
    } else {
        build_grid(ls)?.0
    };
    let grid_seconds = start.elapsed().as_secs_f64();
    match grid {
        AnyGrid::Two(g) => build_dim(ls, g, purpose, observer, start, grid_seconds),
        AnyGrid::Three(g) => build_dim(ls, g, purpose, observer, start, grid_seconds),
    }
}

/// A library error as a scene error at the key it comes from.
fn scene_error(ls: &LoadedScene, e: CosseratError) -> RunError {
    let material = ls.scene.region[0].material.clone().unwrap_or_default();
    let key = match &e {
        CosseratError::Material { name, .. } => {
            let field = name.split(['[', ' ']).next().unwrap_or(name);
            k(&["material", &material, field])
        }
        CosseratError::NotSimplex { .. } | CosseratError::NoStencil { .. } => k(&["grid", "kind"]),
        CosseratError::Condition { index, .. } => ki("bc", *index, &[]),
        CosseratError::Grid(_) => k(&["grid"]),
        CosseratError::NotConverged { .. } => k(&["solver", "linear"]),
        CosseratError::Input { .. } | CosseratError::Solve(_) => k(&["scene", "model"]),
        CosseratError::Interrupted => return RunError::Interrupted,
    };
    RunError::Scene(ls.error(&key, format!(": {e}")))
}

/// The error of a state that overflowed (`what`: which value), naming the loads and the
/// moduli of the scene with their lines.
fn overflow(ls: &LoadedScene, what: &str) -> RunError {
    let s = &ls.scene;
    let at = |path: &[KeyPart]| {
        format!(
            "{} (line {})",
            crate::common::sections::key_text(path),
            ls.error(path, "").line
        )
    };
    let mut loads = Vec::new();
    for (i, bc) in s.bc.iter().enumerate() {
        for (f, set) in [
            ("displacement", bc.displacement.is_some()),
            ("traction", bc.traction.is_some()),
            ("rotation", bc.rotation.is_some()),
            ("couple_traction", bc.couple_traction.is_some()),
        ] {
            if set {
                loads.push(at(&ki("bc", i, &[f])));
            }
        }
    }
    if let Some(l) = &s.loads {
        if l.body_force.is_some() {
            loads.push(at(&k(&["loads", "body_force"])));
        }
        if l.body_couple.is_some() {
            loads.push(at(&k(&["loads", "body_couple"])));
        }
    }
    let mut moduli = Vec::new();
    for (name, m) in &s.material {
        let f = if m.shear_modulus.is_some() {
            "shear_modulus"
        } else {
            "youngs_modulus"
        };
        moduli.push(at(&k(&["material", name, f])));
        moduli.push(at(&k(&["material", name, "cosserat_shear_modulus"])));
    }
    ls.error(
        &k(&["loads"]),
        format!(
            "— the solution overflowed ({what}): the loads are too large for the moduli of the \
             scene. Look at the loads: {}; and at the moduli: {}",
            loads.join(", "),
            moduli.join(", ")
        ),
    )
    .into()
}

/// The first `[loads]` value (`body_force` or `body_couple` component) that is not a
/// finite number at a cell centre at one of `times`, as an error at its key: a run error
/// of the library (a non-finite right-hand side or state) is reported there rather than
/// against the model. At most about 10⁷ evaluations (on an error path only).
fn load_not_finite<const D: usize>(
    ls: &LoadedScene,
    grid: &Grid<D>,
    times: &[f64],
) -> Option<SceneError> {
    let l = ls.scene.loads.as_ref()?;
    let mut values: Vec<(&str, usize, &NumOrExpr)> = Vec::new();
    if let Some(f) = &l.body_force {
        values.extend(f.iter().enumerate().map(|(a, v)| ("body_force", a, v)));
    }
    if let Some(c) = &l.body_couple {
        values.extend(
            c.values()
                .into_iter()
                .enumerate()
                .map(|(a, v)| ("body_couple", a, v)),
        );
    }
    let cells = grid.num_cells().max(1);
    let stride = (cells * times.len() * values.len().max(1) / 10_000_000).max(1);
    for (key, a, v) in values {
        let f = v.to_field();
        for &t in times {
            for c in (0..grid.num_cells()).step_by(stride) {
                let x = grid.cell_centroid(c);
                let y = f.eval(x.as_slice(), t);
                if !y.is_finite() {
                    let text = match v {
                        NumOrExpr::Num(n) => n.to_string(),
                        NumOrExpr::Expr(e) => format!("\"{}\"", crate::common::loaded::echo(e)),
                    };
                    return Some(ls.error(
                        &k(&["loads", key]),
                        format!(
                            "[{a}] = {text} is {y} at x = {:?}, t = {t} (cell {}): a load must \
                             be a finite number everywhere in the grid",
                            x.as_slice(),
                            c + 1
                        ),
                    ));
                }
            }
        }
    }
    None
}

fn to_field<const D: usize>(v: &NumOrExpr) -> porofrac_cosserat::Field<D> {
    let f = v.to_field();
    Arc::new(move |x: &Point<D>, t: f64| f.eval(x.as_slice(), t))
}

fn is_free(v: &NumOrExpr) -> bool {
    matches!(v, NumOrExpr::Expr(s) if s == "free")
}

/// The material of the scene's one region.
fn material(ls: &LoadedScene, d: usize) -> Result<Material, RunError> {
    let name = ls.scene.region[0].material.clone().expect("checked");
    let m = &ls.scene.material[&name];
    let nu = m.poisson_ratio;
    let g = m
        .shear_modulus
        .unwrap_or_else(|| m.youngs_modulus / (2.0 * (1.0 + nu)));
    let gc = m.cosserat_shear_modulus.unwrap_or(0.0);
    let mat = match (&m.couple_moduli, m.characteristic_length) {
        (Some(c), _) if d == 3 => Material::with_couple_moduli(g, nu, gc, [c[0], c[1], c[2]]),
        (_, Some(l)) => Material::with_length(g, nu, gc, l),
        _ => unreachable!("checked: a length scale is present"),
    }
    .map_err(|e| scene_error(ls, e))?;
    match (m.density, m.micro_inertia) {
        (Some(rho), Some(j)) => mat.with_inertia(rho, j).map_err(|e| scene_error(ls, e)),
        (Some(rho), None) => {
            let j = mat.micro_inertia;
            mat.with_inertia(rho, j).map_err(|e| scene_error(ls, e))
        }
        _ => Ok(mat),
    }
}

fn conditions<const D: usize>(
    ls: &LoadedScene,
    grid: &Grid<D>,
) -> Result<Vec<Condition<D>>, RunError> {
    let mut out = Vec::new();
    for (i, bc) in ls.scene.bc.iter().enumerate() {
        let faces = grid.boundary(&bc.boundary).map_err(|e| {
            ls.error(
                &ki("bc", i, &["boundary"]),
                format!("= \"{}\": {e}", bc.boundary),
            )
        })?;
        let mut c = Condition::new(faces);
        if let Some(u) = &bc.displacement {
            for (a, v) in u.iter().enumerate().filter(|(_, v)| !is_free(v)) {
                c = c.fix(a, to_field(v));
            }
        }
        if let Some(t) = &bc.traction {
            for (a, v) in t.iter().enumerate() {
                c = c.load(a, to_field(v));
            }
        }
        if let Some(r) = &bc.rotation {
            for (kk, v) in r
                .values()
                .into_iter()
                .enumerate()
                .filter(|(_, v)| !is_free(v))
            {
                c = c.fix(D + kk, to_field(v));
            }
        }
        if let Some(m) = &bc.couple_traction {
            for (kk, v) in m.values().into_iter().enumerate() {
                c = c.load(D + kk, to_field(v));
            }
        }
        out.push(c);
    }
    Ok(out)
}

fn body_loads<const D: usize>(ls: &LoadedScene) -> BodyLoads<D> {
    let mut b = BodyLoads::none();
    if let Some(l) = &ls.scene.loads {
        if let Some(f) = &l.body_force {
            for (a, v) in f.iter().enumerate() {
                b = b.with(a, to_field(v));
            }
        }
        if let Some(c) = &l.body_couple {
            for (kk, v) in c.values().into_iter().enumerate() {
                b = b.with(D + kk, to_field(v));
            }
        }
    }
    b
}

/// `[solver] linear` and `tolerance` as the library's options.
fn linear_options(ls: &LoadedScene) -> LinearOptions {
    let s = &ls.scene.solver;
    let solver = match s.linear.unwrap_or_default() {
        LinearChoice::Lu => LinearSolver::Lu,
        LinearChoice::GmresAmg => LinearSolver::GmresAmg,
        // cholesky and cg-amg are refused by the check.
        _ => LinearSolver::Auto,
    };
    let mut gmres = GmresOptions::default();
    if let Some(t) = s.tolerance {
        gmres.tolerance = t;
    }
    LinearOptions { solver, gmres }
}

/// How the run advances (one value per run: the size of the variants does not matter).
#[allow(clippy::large_enum_variant)]
enum Stepping {
    /// One static solve (an LU factored once, or GMRES with its preconditioner).
    Static(Linear),
    /// Dynamics with `substeps` integrator steps per output step.
    Dynamic { state: Dynamics, substeps: usize },
}

/// Sample points of a line: arc length, position, cell.
type LinePoints<const D: usize> = Vec<(f64, Point<D>, usize)>;

struct Run<'a, const D: usize> {
    ls: &'a LoadedScene,
    model: Cosserat<D>,
    times: Vec<f64>,
    stepping: Stepping,
    /// Generalised displacements of the current state.
    w: Vec<f64>,
    /// Cell generalised stresses of the current state.
    stress: Vec<[f64; 18]>,
    probes: Vec<(Field, Point<D>, usize)>,
    lines: Vec<(Field, LinePoints<D>)>,
    wall: WallSeconds,
    stats: SolverStats,
    /// The observer's stop request, polled between the sub-steps of a step.
    stop: Stop,
}

fn build_dim<const D: usize>(
    ls: &LoadedScene,
    grid: Grid<D>,
    purpose: &Purpose<'_>,
    observer: &mut dyn Observer,
    start: Instant,
    grid_seconds: f64,
) -> Result<Built, RunError> {
    let t_asm = Instant::now();
    let mat = material(ls, D)?;
    let cond = conditions(ls, &grid)?;
    let body = body_loads::<D>(ls);
    let options = Options {
        penalty: ls.scene.solver.penalty.unwrap_or(1.0),
        stencil: match ls.scene.solver.stencil.unwrap_or_default() {
            Stencil::SmallestBoundaryWeight => StencilRule::SmallestBoundaryWeight,
            Stencil::FirstInterpolating => StencilRule::FirstInterpolating,
            Stencil::SmallestWeight => StencilRule::SmallestWeight,
        },
        ..Options::default()
    };
    let model = Cosserat::new(grid, mat, options, &cond, body).map_err(|e| scene_error(ls, e))?;
    let n_eq = model.equations();
    let linear_options = linear_options(ls);
    let stop = observer.stop_handle();
    let mut times = vec![0.0];
    let stepping = match &ls.scene.schedule {
        None => {
            let solver = model
                .linear(
                    model.system_values(),
                    model.preconditioner_values(),
                    &linear_options,
                )
                .map_err(|e| scene_error(ls, e))?;
            let mut solver = solver;
            solver.set_interrupt(stop.flag());
            Stepping::Static(solver)
        }
        Some(sch) => {
            // Uniform output steps (a dt that does not divide end_time is shortened).
            let n = crate::common::loaded::step_count(sch) as usize;
            let dt_out = sch.end_time / n as f64;
            times.extend((1..=n).map(|i| i as f64 * dt_out));
            let integ = ls.scene.solver.time_integration.unwrap_or_default();
            let (integrator, substeps) = match integ {
                TimeIntegration::Newmark => (Integrator::Newmark, 1),
                TimeIntegration::Explicit => {
                    let stable = Dynamics::stable_step(&model);
                    (
                        Integrator::Explicit,
                        (dt_out / stable).ceil().max(1.0) as usize,
                    )
                }
            };
            let state = Dynamics::with_solver(
                &model,
                integrator,
                dt_out / substeps as f64,
                0.0,
                vec![0.0; n_eq],
                vec![0.0; n_eq],
                &linear_options,
            )
            .map_err(|e| scene_error(ls, e))?;
            let mut state = state;
            state.set_interrupt(stop.flag());
            Stepping::Dynamic { state, substeps }
        }
    };
    let grid = model.grid();
    let locate = |x: &Point<D>| crate::common::sample::locate(grid, x).map(|l| l.cell);
    let mut probes = Vec::new();
    for (i, p) in ls.scene.output.probe.iter().enumerate() {
        let x = point::<D>(&p.at);
        let cell = locate(&x)
            .ok_or_else(|| ls.error(&ki("output.probe", i, &["at"]), "lies outside the grid"))?;
        probes.push((Field::parse(&p.field, D).expect("checked"), x, cell));
    }
    let mut lines = Vec::new();
    for (i, l) in ls.scene.output.line.iter().enumerate() {
        let (a, b) = (point::<D>(&l.from), point::<D>(&l.to));
        let mut pts = Vec::new();
        for j in 0..l.points as usize {
            let s = j as f64 / (l.points as f64 - 1.0);
            let x = a + (b - a) * s;
            let cell = locate(&x).ok_or_else(|| {
                ls.error(
                    &ki("output.line", i, &[]),
                    format!("point {x:?} lies outside the grid"),
                )
            })?;
            pts.push(((b - a).norm() * s, x, cell));
        }
        lines.push((Field::parse(&l.field, D).expect("checked"), pts));
    }
    let solver = match &stepping {
        Stepping::Static(l) => Some(l),
        Stepping::Dynamic { state, .. } => state.solver(),
    };
    let (linear, factorizations) = match solver.map(Linear::solver) {
        None => ("explicit", 0),
        Some(LinearSolver::GmresAmg) => ("gmres-amg", 0),
        Some(LinearSolver::GmresLdlt) => ("gmres-ldlt", 1),
        Some(LinearSolver::LdltSchur) => ("ldlt-schur", 1),
        Some(_) => ("sparse-lu", 1),
    };
    let mut run = Run {
        ls,
        times,
        stepping,
        w: vec![0.0; n_eq],
        stress: vec![[0.0; 18]; model.grid().num_cells()],
        probes,
        lines,
        wall: WallSeconds {
            assembly: t_asm.elapsed().as_secs_f64(),
            ..WallSeconds::default()
        },
        stats: SolverStats {
            linear: linear.into(),
            factorizations,
            symbolic_factorizations: usize::from(factorizations > 0),
            ..SolverStats::default()
        },
        model,
        stop,
    };
    purpose.finish(ls, &mut run, observer, start, grid_seconds, D)
}

impl<const D: usize> Run<'_, D> {
    fn refresh_stress(&mut self) {
        for c in 0..self.model.grid().num_cells() {
            self.stress[c] = self.model.cell_stress(c, &self.w);
        }
    }

    /// `Err` naming the loads and moduli of the scene when the state at `t` overflowed:
    /// a generalised displacement that is not finite, a stress beyond
    /// [`crate::common::bounds::MAX_STRESS`], or an energy that is not finite.
    fn check_state(&self, t: f64) -> Result<(), RunError> {
        let max = crate::common::bounds::MAX_STRESS;
        let what = if let Some(i) = self.w.iter().position(|v| !v.is_finite()) {
            format!(
                "unknown {} of cell {} is {} at t = {t:e} s",
                i % components(D),
                i / components(D),
                self.w[i]
            )
        } else if let Some(c) = self
            .stress
            .iter()
            .position(|s| s.iter().any(|v| !v.is_finite() || v.abs() > max))
        {
            format!("a stress of cell {c} is beyond {max:e} Pa at t = {t:e} s")
        } else {
            let e = self.value(Field::Energy, self.model.grid().cell_centroid(0), 0);
            let kin = self.value(Field::Kinetic, self.model.grid().cell_centroid(0), 0);
            if e.is_finite() && kin.is_finite() {
                return Ok(());
            }
            format!("the energy is {e} and the kinetic energy {kin} at t = {t:e} s")
        };
        Err(overflow(self.ls, &what))
    }

    fn value(&self, f: Field, x: &Point<D>, cell: usize) -> f64 {
        match f {
            Field::Dof(a) => self.model.reconstruction().p1_value(
                self.model.grid(),
                cell,
                x,
                &self.w,
                components(D),
                a,
            ),
            Field::Stress(i) => self.stress[cell][i],
            Field::Energy => self.model.energy(&self.w),
            Field::Kinetic => match &self.stepping {
                Stepping::Dynamic { state, .. } => state.kinetic(),
                Stepping::Static(_) => 0.0,
            },
            Field::Work => match &self.stepping {
                Stepping::Dynamic { state, .. } => state.external_work,
                Stepping::Static(_) => {
                    let mut f = vec![0.0; self.w.len()];
                    self.model.rhs(0.0, &mut f);
                    f.iter().zip(&self.w).map(|(a, b)| a * b).sum()
                }
            },
        }
    }

    fn cell_value(&self, f: Field, c: usize) -> f64 {
        match f {
            Field::Dof(a) => self.w[c * components(D) + a],
            Field::Stress(i) => self.stress[c][i],
            _ => 0.0,
        }
    }
}

impl<const D: usize> Model for Run<'_, D> {
    fn times(&self) -> &[f64] {
        &self.times
    }

    fn step(&mut self, step: usize) -> Result<StepStats, RunError> {
        let t_solve = Instant::now();
        let ls = self.ls;
        match &mut self.stepping {
            Stepping::Static(solver) => {
                let mut x = vec![0.0; self.w.len()];
                let t = self.times[step];
                self.model.rhs(t, &mut x);
                let grid = self.model.grid();
                solver.solve(&mut x, Some(&self.w)).map_err(|e| {
                    load_not_finite(ls, grid, &[t]).map_or_else(|| scene_error(ls, e), Into::into)
                })?;
                self.w = x;
            }
            Stepping::Dynamic { state, substeps } => {
                if step > 0 {
                    let (t0, t1) = (self.times[step - 1], self.times[step]);
                    let n = *substeps;
                    for _ in 0..n {
                        if self.stop.requested() {
                            return Err(RunError::Interrupted);
                        }
                        state.step(&self.model).map_err(|e| {
                            // The loads at the times the integrator evaluated them.
                            let times: Vec<f64> = (0..=n.min(1000))
                                .map(|i| t0 + (t1 - t0) * i as f64 / n.min(1000) as f64)
                                .collect();
                            load_not_finite(ls, self.model.grid(), &times)
                                .map_or_else(|| scene_error(ls, e), Into::into)
                        })?;
                    }
                }
                self.w.clone_from(&state.u);
            }
        }
        self.wall.solve += t_solve.elapsed().as_secs_f64();
        self.refresh_stress();
        self.check_state(self.times[step])?;
        Ok(StepStats {
            iterations: 0,
            failed: 0,
        })
    }

    fn probes(&self, values: &mut Vec<f64>) {
        values.extend(self.probes.iter().map(|(f, x, c)| self.value(*f, x, *c)));
    }

    fn line(&self, line: usize, rows: &mut Vec<Vec<f64>>) {
        let (field, points) = &self.lines[line];
        for (s, x, c) in points {
            let mut r = Vec::with_capacity(D + 2);
            r.push(*s);
            r.extend(x.iter().copied());
            r.push(self.value(*field, x, *c));
            rows.push(r);
        }
    }

    fn after_step(&mut self, _out: &Path) -> Result<(), RunError> {
        Ok(())
    }

    fn checkpoints(&self) -> bool {
        true
    }

    fn save_state(&self, state: &mut crate::common::checkpoint::State) -> Result<(), RunError> {
        state.put_f64("w", self.w.clone());
        state.put_f64(
            "stats",
            vec![
                self.stats.iterations as f64,
                self.stats.max_relative_residual,
                self.wall.solve,
            ],
        );
        let linear = match &self.stepping {
            Stepping::Static(l) => Some(l.stats()),
            Stepping::Dynamic { state, .. } => state.solver().map(Linear::stats),
        };
        if let Some(l) = linear {
            state.put_u64(
                "linear/counts",
                vec![
                    l.solves as u64,
                    l.iterations as u64,
                    l.max_iterations as u64,
                ],
            );
            state.put_f64("linear/max_residual", vec![l.max_residual]);
        }
        if let Stepping::Dynamic { state: d, .. } = &self.stepping {
            state.put_f64("dynamics/t", vec![d.t, d.external_work]);
            state.put_f64("dynamics/u", d.u.clone());
            state.put_f64("dynamics/v", d.v.clone());
            state.put_f64("dynamics/a", d.a.clone());
            state.put_f64("dynamics/f_prev", d.previous_load().to_vec());
        }
        Ok(())
    }

    fn restore_state(
        &mut self,
        state: &crate::common::checkpoint::State,
        _out: &Path,
    ) -> Result<(), RunError> {
        let n = self.w.len();
        self.w = state.f64s_len("w", n)?.to_vec();
        let s = state.f64s_len("stats", 3)?;
        self.stats.iterations = s[0] as usize;
        self.stats.max_relative_residual = s[1];
        self.wall.solve = s[2];
        if let Stepping::Dynamic { state: d, .. } = &mut self.stepping {
            let t = state.f64s_len("dynamics/t", 2)?;
            (d.t, d.external_work) = (t[0], t[1]);
            d.u = state.f64s_len("dynamics/u", n)?.to_vec();
            d.v = state.f64s_len("dynamics/v", n)?.to_vec();
            d.a = state.f64s_len("dynamics/a", n)?.to_vec();
            d.set_previous_load(state.f64s("dynamics/f_prev")?.to_vec())
                .map_err(|(a, b)| {
                    RunError::Checkpoint(format!(
                        "array `dynamics/f_prev` has {a} values, the rebuilt model needs {b}"
                    ))
                })?;
        }
        let linear = match &mut self.stepping {
            Stepping::Static(l) => Some(l),
            Stepping::Dynamic { state, .. } => state.solver_mut(),
        };
        if let Some(l) = linear {
            let c = state.u64s_len("linear/counts", 3)?;
            let mut s = l.stats();
            s.solves = c[0] as usize;
            s.iterations = c[1] as usize;
            s.max_iterations = c[2] as usize;
            s.max_residual = state.f64("linear/max_residual")?;
            l.restore_counts(&s);
        }
        self.refresh_stress();
        Ok(())
    }

    fn write_vtk(&self, dir: &Path, index: usize) -> Result<String, RunError> {
        let name = format!("step_{index:04}.vtu");
        vtk::write(&dir.join(&name), self.model.grid(), &self.w, &self.stress)?;
        Ok(name)
    }

    fn snapshot(&self, mesh: bool) -> Option<crate::common::snapshot::Snapshot> {
        use crate::common::snapshot::{Array, Mesh, Snapshot};
        let grid = self.model.grid();
        let [displacement, rotation, stress, couple_stress] =
            vtk::cell_arrays(grid, &self.w, &self.stress);
        Some(Snapshot {
            mesh: mesh.then(|| std::sync::Arc::new(Mesh::of(grid))),
            cell_data: vec![
                Array::new("displacement", 3, displacement),
                Array::new("rotation", 3, rotation),
                Array::new("stress", 9, stress),
                Array::new("couple_stress", 9, couple_stress),
            ],
            ..Default::default()
        })
    }

    fn field_extrema(&self) -> BTreeMap<String, [f64; 2]> {
        let mut out = BTreeMap::new();
        let nc = self.model.grid().num_cells();
        for name in Field::names(D) {
            let f = Field::parse(&name, D).expect("listed");
            let r = match f {
                Field::Dof(_) | Field::Stress(_) => {
                    (0..nc).fold([f64::INFINITY, f64::NEG_INFINITY], |r, c| {
                        let v = self.cell_value(f, c);
                        [r[0].min(v), r[1].max(v)]
                    })
                }
                _ => {
                    let v = self.value(f, self.model.grid().cell_centroid(0), 0);
                    [v, v]
                }
            };
            out.insert(name, r);
        }
        out
    }

    fn plots(&self, dir: &Path, written: &[f64], series: &[Vec<f64>]) -> Result<(), RunError> {
        if !self.ls.scene.output.plots {
            return Ok(());
        }
        if let Some(g2) = (self.model.grid() as &dyn std::any::Any).downcast_ref::<Grid<2>>() {
            let canvas = Canvas::of_grid(g2);
            let nc = g2.num_cells();
            let scene = &self.ls.scene.scene.name;
            let t = written.last().copied().unwrap_or(0.0);
            for (name, what, bar, unit) in [
                ("syy", "σ_yy, cell values", "σ_yy [Pa]", "Pa"),
                ("phi", "rotation φ, cell values", "φ [rad]", "rad"),
            ] {
                let f = Field::parse(name, 2).expect("2D field");
                let v: Vec<f64> = (0..nc).map(|c| self.cell_value(f, c)).collect();
                let title = format!("{scene}: {what} at t = {} s", tick(t));
                crate::common::plots::field(
                    &dir.join(format!("{name}.png")),
                    &FieldPlot::new(&canvas, &title, bar, unit, &[]),
                    Values::Cell(&v),
                )?;
            }
            // σ_yy around its peak cell (a stress concentration is small on the whole
            // grid): a window of 40 peak-cell diameters.
            let f = Field::parse("syy", 2).expect("2D field");
            let v: Vec<f64> = (0..nc).map(|c| self.cell_value(f, c)).collect();
            let peak = (0..nc).max_by(|&a, &b| v[a].total_cmp(&v[b])).unwrap_or(0);
            let h = 20.0 * self.model.reconstruction().diameter[peak];
            let x = g2.cell_centroid(peak);
            let title = format!("{scene}: σ_yy near its peak at t = {} s", tick(t));
            let mut plot = FieldPlot::new(&canvas, &title, "σ_yy [Pa]", "Pa", &[]);
            plot.window = Some(([x[0] - h, x[1] - h], [x[0] + h, x[1] + h]));
            crate::common::plots::field(&dir.join("syy_peak.png"), &plot, Values::Cell(&v))?;
        }
        if written.len() > 1 && !self.probes.is_empty() {
            let columns: Vec<Column> = self
                .ls
                .scene
                .output
                .probe
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    Column::new(p.name.clone(), Field::unit(&p.field, D), series[i].clone())
                })
                .collect();
            crate::common::plots::time_series(
                &dir.join("probes.png"),
                written,
                &columns,
                &format!("{}: probes", self.ls.scene.scene.name),
            )?;
        }
        Ok(())
    }

    fn sizes(&self) -> Sizes {
        let (cells, dofs) = (self.model.grid().num_cells(), self.model.equations());
        Sizes {
            cells: Some(cells),
            nodes: None,
            dofs: Some(dofs),
            counts: vec![("cells", cells), ("unknowns", dofs)],
            failed: None,
        }
    }

    fn work(&self) -> crate::common::limits::Work {
        // One static solve, or every (sub-)step of the dynamics.
        let steps = match &self.stepping {
            Stepping::Static(_) => 1,
            Stepping::Dynamic { substeps, .. } => substeps * self.times.len().saturating_sub(1),
        };
        crate::common::limits::Work {
            units: self.model.equations() as f64 * steps as f64,
            seconds_per_unit: crate::common::limits::COSSERAT_SECONDS_PER_UNKNOWN_STEP,
            unit: "unknown steps",
            factor: 5.0,
        }
    }

    fn peak_bytes(&self) -> f64 {
        crate::common::limits::cosserat_bytes(self.model.equations() as f64)
    }

    fn unit(&self, field: &str) -> &'static str {
        Field::unit(field, D)
    }

    fn failed(&self) -> usize {
        0
    }

    fn solver_stats(&self) -> SolverStats {
        let linear = match &self.stepping {
            Stepping::Static(l) => Some(l.stats()),
            Stepping::Dynamic { state, .. } => state.solver().map(Linear::stats),
        };
        let mut stats = self.stats.clone();
        if let Some(l) = linear {
            stats.iterations = l.iterations;
            stats.max_relative_residual = l.max_residual;
        }
        stats
    }

    fn errors(&self) -> Result<BTreeMap<String, f64>, RunError> {
        Ok(BTreeMap::new())
    }

    fn wall_seconds(&self) -> WallSeconds {
        self.wall
    }
}

/// The model `cosserat` in the registry ([`crate::MODELS`]).
pub struct CosseratKind;

/// The registry's value of the model.
pub static KIND: CosseratKind = CosseratKind;

impl ModelKind for CosseratKind {
    fn name(&self) -> &'static str {
        "cosserat"
    }
    fn sections(&self) -> &'static [&'static str] {
        &[]
    }
    fn reads(&self) -> &'static [&'static str] {
        &[
            "grid", "region", "material", "fluid", "bc", "loads", "source", "well", "initial",
            "physics",
        ]
    }
    fn check(&self, ls: &LoadedScene, laws: &LawRegistry) -> Result<(), SceneError> {
        let _ = laws;
        check::check(ls)
    }
    fn build(
        &self,
        ls: &LoadedScene,
        laws: &LawRegistry,
        purpose: &Purpose<'_>,
        observer: &mut dyn Observer,
    ) -> Result<Built, RunError> {
        let _ = laws;
        build(ls, purpose, observer)
    }
}
