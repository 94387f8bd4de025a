//! The continuum model (H. M. Nilsen, I. Larsen, X. Raynaud (2017), arXiv:1702.01552;
//! `[scene] model = "continuum"`): VEM, MDEM and DEM cell laws, TPFA flow, Biot coupling and
//! fracturing on a polyhedral grid.
//!
//! - *build*: the grid ([`crate::common::grid`]), the law and material of every cell and the conditions
//!   ([`mod@compose`]), the flow model ([`mod@flow`]), the dof map, the stiffness pattern and the
//!   solver;
//! - *step*: one of three drivers, chosen by the scene: static mechanics at every output
//!   time (direct or damped explicit relaxation; conditions may depend on `t`), flow on a
//!   fixed skeleton after it, or the coupled poroelastic step
//!   ([`porofrac_sim::Fracturing`]). Failures are resolved within a step by
//!   [`porofrac_sim::FailureResolution`] in all of them, with the same settings;
//! - *fields*: displacement, stress, principal stresses, pressure and the failure flag
//!   ([`fields`]) for probes, lines, VTK and `field_extrema`, and the plots ([`plots`]);
//! - *on MPI ranks* (feature `mpi`): static linear elasticity distributed over the ranks
//!   (`distributed`, with `porofrac-dist`).

pub mod check;
mod checkpoint;
pub mod compose;
#[cfg(feature = "mpi")]
mod distributed;
mod explain;
pub mod fields;
pub mod flow;
#[cfg(test)]
mod kgd_tests;
#[cfg(test)]
mod penny_tests;
pub mod plots;

use crate::common::loaded::SceneError;
use crate::common::model::ModelKind;

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use porofrac_frac::FailureState;
use porofrac_grid::io::{Field as VtkField, write_vtu};
use porofrac_grid::{Grid, Point};
use porofrac_law::{CellLaw, Tensor};
use porofrac_sim::{
    BiotState, Body, DofMap, ExplicitOptions, ExplicitPressure, FailureResolution, FixedStress,
    FractureFlow, FractureLaws, FracturePermeability, FractureSettings, Fracturing, LawMap,
    LinearSolver, Monolithic, Pattern, Scheme, StaticOptions, StaticProblem, StaticSolver,
    StressMeasure, cell_stresses, drained_bulk_modulus, solve_explicit, solve_static,
};

use crate::common::driver::{Observer, Stop};
use crate::common::laws::LawRegistry;
use crate::common::loaded::{LoadedScene, k, ki};
use crate::common::model::{Built, Model, Purpose, RunError, Sizes, StepStats};
use crate::common::output::{CsvTable, SolverStats, WallSeconds};
use crate::common::sample::{Location, locate};
use crate::common::sections::{
    CouplingChoice, CrackFlow, FailureStress, InitialMechanics, LinearChoice, MechanicsSolver,
    Plane,
};

use crate::common::grid::{AnyGrid, DeckCells, build_grid, point};
use compose::{Composition, compose, conditions, material_stiffness};
use fields::Field;
use flow::{FlowSetup, flow_setup};

/// Build a checked continuum scene's model and hand it to `purpose`.
pub(crate) fn build(
    ls: &LoadedScene,
    registry: &LawRegistry,
    purpose: &Purpose<'_>,
    observer: &mut dyn Observer,
) -> Result<Built, RunError> {
    let start = Instant::now();
    check_supported(ls)?;
    let (grid, deck) = build_grid(ls)?;
    let grid_seconds = start.elapsed().as_secs_f64();
    match grid {
        AnyGrid::Two(g) => build_dim(
            ls,
            registry,
            &g,
            &deck,
            purpose,
            observer,
            start,
            grid_seconds,
        ),
        AnyGrid::Three(g) => build_dim(
            ls,
            registry,
            &g,
            &deck,
            purpose,
            observer,
            start,
            grid_seconds,
        ),
    }
}

#[allow(clippy::too_many_arguments)]
fn build_dim<const D: usize>(
    ls: &LoadedScene,
    registry: &LawRegistry,
    grid: &Grid<D>,
    deck: &DeckCells,
    purpose: &Purpose<'_>,
    observer: &mut dyn Observer,
    start: Instant,
    grid_seconds: f64,
) -> Result<Built, RunError> {
    // Mesh files are counted only once read: bound the run before assembling it.
    let flow_on = ls.scene.physics.flow == Some(true);
    let unknowns = (D * grid.num_nodes() + if flow_on { grid.num_cells() } else { 0 }) as f64;
    let cells = grid.num_cells() as f64;
    let (bytes, factor) =
        crate::common::limits::run_bytes_of(D, cells, unknowns, check::factors(ls, D, unknowns));
    crate::common::limits::fits_in_memory(
        bytes,
        &format!("holds {}", crate::common::limits::run_text(cells, unknowns)),
    )
    .map_err(|e| {
        ls.error(
            &k(&["grid"]),
            format!("{e}{}", crate::common::limits::factor_note(factor)),
        )
    })?;
    let t_asm = Instant::now();
    let comp = compose(ls, registry, grid, deck)?;
    let cond = conditions(ls, grid, &comp)?;
    let law_refs: Vec<&dyn CellLaw<D>> = comp.laws.iter().map(|l| l.as_ref()).collect();
    // Checks every cell against its law once (e.g. MDEM on a polygon is an error).
    LawMap::new(grid, law_refs.clone(), comp.law_of_cell.clone())?;
    let dofs = DofMap::new(grid, &cond.displacements, &cond.platens)
        .map_err(|e| explain::conditions(ls, e))?;
    // An island of cells left free (a deck's active cells cut off by inactive ones) is
    // named by its deck (i, j, k) where there is one.
    dofs.check_rigid_modes(grid).map_err(|e| match e {
        porofrac_sim::SimError::FloatingPart {
            cells,
            total,
            cell_index,
            modes,
            ..
        } if cell_index < deck.ijk.len() => {
            let [i, j, k] = deck.ijk[cell_index];
            porofrac_sim::SimError::FloatingPart {
                cells,
                total,
                cell: format!("the cell (i, j, k) = ({}, {}, {})", i + 1, j + 1, k + 1),
                cell_index,
                modes,
            }
        }
        e => e,
    })?;
    let pattern = Pattern::new(grid, &dofs)?;
    let assembly = t_asm.elapsed().as_secs_f64();
    let body = Body {
        grid,
        dofs: &dofs,
        pattern: &pattern,
        loads: &cond.loads,
    };
    let mut stepper = Stepper::new(
        ls,
        body,
        deck,
        &comp,
        law_refs,
        purpose.out(),
        observer.stop_handle(),
    )
    .map_err(|e| explain::explain(ls, grid.num_cells(), e))?;
    stepper.wall.assembly += assembly;
    let coupled = flow_on && ls.scene.physics.coupling.unwrap_or_default() != CouplingChoice::None;
    stepper.peak_bytes = crate::common::limits::continuum_bytes(
        D,
        cells,
        unknowns,
        check::factors(ls, D, unknowns),
        coupled,
    );
    stepper.unknowns = unknowns;
    purpose.finish(ls, &mut stepper, observer, start, grid_seconds, D)
}

/// Physics this version does not model yet is an error, not silently ignored.
fn check_supported(ls: &LoadedScene) -> Result<(), RunError> {
    let s = &ls.scene;
    let flow = s.physics.flow == Some(true);
    let coupling = s.physics.coupling.unwrap_or_default();
    let explicit = s.solver.mechanics == Some(MechanicsSolver::Explicit);
    // CG-AMG solves the static mechanics (SPD); the Biot system is indefinite.
    if s.solver.linear == Some(LinearChoice::CgAmg) {
        let coupled = flow && coupling != CouplingChoice::None;
        if coupled || explicit {
            return Err(ls
                .error(
                    &k(&["solver", "linear"]),
                    "= \"cg-amg\" solves static mechanics only; coupled flow (an indefinite \
                     Biot system) and explicit mechanics need \"cholesky\" or \"auto\"",
                )
                .into());
        }
    }
    for (i, bc) in s.bc.iter().enumerate() {
        if !flow && (bc.pressure.is_some() || bc.flux.is_some()) {
            return Err(ls
                .error(
                    &ki("bc", i, &["pressure"]),
                    "is a flow condition: set [physics] flow = true",
                )
                .into());
        }
    }
    if !flow && !s.source.is_empty() {
        return Err(ls
            .error(&ki("source", 0, &[]), "needs [physics] flow = true")
            .into());
    }
    if !flow && !s.well.is_empty() {
        return Err(ls
            .error(&ki("well", 0, &[]), "needs [physics] flow = true")
            .into());
    }
    if flow && coupling != CouplingChoice::None && explicit {
        return Err(ls
            .error(
                &k(&["solver", "mechanics"]),
                "= \"explicit\" with coupled flow is not available in this version of porofrac",
            )
            .into());
    }
    Ok(())
}

/// The output times: 0, then every step of the schedule (bounded by the checks).
fn output_times(ls: &LoadedScene) -> Vec<f64> {
    let mut t = vec![0.0];
    if let Some(sch) = &ls.scene.schedule {
        let n =
            crate::common::loaded::step_count(sch).min(crate::common::limits::MAX_STEPS) as usize;
        let dt = sch.dt.unwrap_or(sch.end_time / n as f64);
        t.reserve(n);
        for k in 1..=n {
            t.push((k as f64 * dt).min(sch.end_time));
        }
    }
    t
}

/// How the mechanics advances (one value per run: the size of the variants does not
/// matter).
#[allow(clippy::large_enum_variant)]
enum Driver<'a, const D: usize> {
    /// Static (or damped explicit) mechanics at every output time.
    Static {
        solver: StaticSolver,
        /// Density per cell for damped explicit relaxation.
        explicit: Option<Vec<f64>>,
        resolution: FailureResolution<D>,
    },
    /// Coupled poroelasticity with fracturing.
    Coupled {
        frac: Box<Fracturing<'a, D>>,
        state: Option<BiotState>,
    },
}

/// Sample points along an output line: arc length from its start, position, location.
type LinePoints<const D: usize> = Vec<(f64, Point<D>, Location)>;

/// The continuum model stepping through its output times.
struct Stepper<'a, const D: usize> {
    ls: &'a LoadedScene,
    body: Body<'a, D>,
    /// Each cell's (i, j, k) when the grid is a corner-point deck.
    deck: &'a DeckCells,
    comp: &'a Composition<D>,
    law_refs: Vec<&'a dyn CellLaw<D>>,
    times: Vec<f64>,
    driver: Driver<'a, D>,
    /// Flow on a fixed skeleton (`coupling = "none"`).
    fixed_flow: Option<FlowSetup<D>>,
    zero_start: bool,
    static_options: StaticOptions,
    // The state at the current time.
    u: Vec<f64>,
    stress: Vec<Tensor<D>>,
    pressure: Option<Vec<f64>>,
    failures: FailureState,
    // Outputs.
    probes: Vec<(Field, Location)>,
    lines: Vec<(Field, LinePoints<D>)>,
    /// `fracture.csv` (none in a check, which writes nothing).
    fracture_csv: Option<CsvTable>,
    logged: usize,
    nu_of_cell: Vec<f64>,
    plane_strain: bool,
    law_ids: Vec<i32>,
    stats: SolverStats,
    wall: WallSeconds,
    /// Index of the last computed output time.
    done: usize,
    /// The static step left the stresses to be recovered after it (nothing could fail).
    stress_stale: bool,
    /// The observer's stop request, polled before every solve of a step.
    stop: Stop,
    /// The estimated peak memory of the run ([`crate::common::limits::continuum_bytes`]).
    peak_bytes: f64,
    /// Unknowns of the run: displacements and, with flow, pressures.
    unknowns: f64,
    /// Numeric factorizations of the run before its solver was built (a resumed run).
    count_base: usize,
}

impl<'a, const D: usize> Stepper<'a, D> {
    /// Every cell's stress as `[xx, yy, zz, xy, yz, xz]` (Pa), for the VTK files and
    /// the in-memory snapshots.
    fn stress_xyz(&self) -> Vec<[f64; 6]> {
        self.stress
            .iter()
            .zip(&self.nu_of_cell)
            .map(|(s, &nu)| {
                let c = |i, j| {
                    Field::Stress(i, j)
                        .of_stress(s, nu, self.plane_strain)
                        .unwrap_or(0.0)
                };
                [c(0, 0), c(1, 1), c(2, 2), c(0, 1), c(1, 2), c(0, 2)]
            })
            .collect()
    }

    fn new(
        ls: &'a LoadedScene,
        body: Body<'a, D>,
        deck: &'a DeckCells,
        comp: &'a Composition<D>,
        law_refs: Vec<&'a dyn CellLaw<D>>,
        out: Option<&Path>,
        stop: Stop,
    ) -> Result<Self, RunError> {
        let s = &ls.scene;
        let grid = body.grid;
        let mut wall = WallSeconds::default();
        let flow_on = s.physics.flow == Some(true);
        let coupling = s.physics.coupling.unwrap_or_default();
        let tolerance = s.solver.tolerance;
        let mut flow = if flow_on {
            let t_flow = Instant::now();
            let f = flow_setup(ls, grid, deck, &comp.material_of_cell())?;
            wall.flow += t_flow.elapsed().as_secs_f64();
            Some(f)
        } else {
            None
        };
        let pressure = flow.as_ref().map(|f| f.p0.clone());
        let settings = fracture_settings(ls, comp);
        let t_asm = Instant::now();
        let (driver, linear_name) = match flow.take_if(|_| coupling != CouplingChoice::None) {
            Some(f) => {
                let mut frac = coupled(ls, body, comp, &law_refs, f, settings)?;
                frac.set_interrupt(stop.flag());
                (
                    Driver::Coupled {
                        frac: Box::new(frac),
                        state: None,
                    },
                    "ldlt",
                )
            }
            None => {
                let explicit = match s.solver.mechanics.unwrap_or_default() {
                    MechanicsSolver::Explicit => Some(densities(ls, comp)?),
                    MechanicsSolver::Direct => None,
                };
                let cg = LinearSolver::CgAmg {
                    tolerance: tolerance.unwrap_or(1e-8),
                };
                // Cholesky with nested dissection in 3D and AMD in 2D, or CG-AMG; "auto"
                // picks by size (docs/BENCHMARKS.md).
                let linear = match s.solver.linear.unwrap_or_default() {
                    LinearChoice::Cholesky => LinearSolver::Cholesky,
                    LinearChoice::CgAmg => cg,
                    LinearChoice::Lu | LinearChoice::GmresAmg => {
                        unreachable!("refused by check: cosserat solvers")
                    }
                    LinearChoice::Auto => {
                        match LinearSolver::Auto.resolve(D, body.dofs.num_equations()) {
                            LinearSolver::CgAmg { .. } => cg,
                            other => other,
                        }
                    }
                };
                let solver = StaticSolver::new(grid, body.dofs, body.pattern, linear)?;
                let name = if explicit.is_some() {
                    "explicit"
                } else {
                    solver.name()
                };
                let resolution = FailureResolution::new(grid, settings)
                    .map_err(|e| ls.error(&k(&["physics", "crack_tracking"]), e))?;
                (
                    Driver::Static {
                        solver,
                        explicit,
                        resolution,
                    },
                    name,
                )
            }
        };
        wall.assembly += t_asm.elapsed().as_secs_f64();
        // Flow on a fixed skeleton: `linear = "cg-amg"` solves the pressure systems with
        // CG-AMG too ("auto" keeps Cholesky for them).
        if let (Some(f), Some(LinearChoice::CgAmg)) = (flow.as_mut(), s.solver.linear) {
            f.model
                .set_linear_solver(porofrac_flow::FlowLinearSolver::CgAmg {
                    tolerance: tolerance.unwrap_or(1e-8),
                })
                .map_err(|e| ls.error(&k(&["solver", "tolerance"]), e.to_string()))?;
        }
        let (probes, lines) = locate_outputs(ls, grid)?;
        let axes = ["x", "y", "z"];
        let mut header = vec!["cell".to_string()];
        header.extend(axes[..D].iter().map(|a| format!("{a} [m]")));
        header.extend(["time [s]".to_string(), "mode".to_string()]);
        let fracture_csv = match out {
            Some(out) => {
                let mut t = CsvTable::new(out.join("fracture.csv"), &header);
                t.flush()?;
                Some(t)
            }
            None => None,
        };
        let nu_of_cell = comp
            .material_of_cell()
            .into_iter()
            .map(|m| s.material[m].poisson_ratio)
            .collect();
        Ok(Self {
            ls,
            body,
            deck,
            comp,
            law_refs,
            times: output_times(ls),
            driver,
            fixed_flow: flow,
            zero_start: s.initial.as_ref().and_then(|i| i.mechanics)
                == Some(InitialMechanics::Zero),
            static_options: StaticOptions {
                tolerance: tolerance.unwrap_or(1e-10),
                ..StaticOptions::default()
            },
            u: vec![0.0; D * grid.num_nodes()],
            stress: vec![Tensor::<D>::zeros(); grid.num_cells()],
            pressure,
            failures: FailureState::new(grid.num_cells()),
            probes,
            lines,
            fracture_csv,
            logged: 0,
            nu_of_cell,
            plane_strain: D == 2 && s.scene.plane.unwrap_or_default() == Plane::Strain,
            law_ids: comp.law_of_cell.iter().map(|&l| l as i32).collect(),
            stats: SolverStats {
                linear: linear_name.into(),
                ..SolverStats::default()
            },
            wall,
            done: 0,
            stress_stale: false,
            stop,
            peak_bytes: 0.0,
            unknowns: 0.0,
            count_base: 0,
        })
    }

    /// The static (or explicit) mechanics at time `t` with failures resolved.
    fn static_step(&mut self, t: f64) -> Result<usize, RunError> {
        let Driver::Static {
            solver,
            explicit,
            resolution,
        } = &mut self.driver
        else {
            return Ok(0);
        };
        let (grid, comp, body) = (self.body.grid, self.comp, self.body);
        let (ls, options, law_refs) = (self.ls, &self.static_options, &self.law_refs);
        let previous = explicit.is_some().then(|| self.u.clone());
        let can_fail = resolution.can_fail();
        let mut iterations = 0;
        let mut worst = 0.0f64;
        let mut solve_seconds = 0.0;
        let stop = &self.stop;
        let mut solve = |failed: &[bool]| -> Result<(Vec<f64>, Vec<Tensor<D>>), RunError> {
            if stop.requested() {
                return Err(RunError::Interrupted);
            }
            let laws = LawMap::new(grid, law_refs.clone(), comp.law_of_cell_after(failed))?;
            let problem = StaticProblem {
                grid,
                laws: &laws,
                dofs: body.dofs,
                pattern: body.pattern,
                loads: body.loads,
            };
            let t_solve = Instant::now();
            let u = match explicit.as_ref() {
                None => {
                    let sol = solve_static(&problem, solver, t, options)?;
                    worst = worst.max(sol.residual);
                    iterations += sol.linear_iterations;
                    sol.displacement
                }
                Some(density) => {
                    // Damped dynamic relaxation from the previous state.
                    let opts = ExplicitOptions {
                        tolerance: ls.scene.solver.tolerance.unwrap_or(1e-8),
                        density_scaling: Some(1.0),
                        ..ExplicitOptions::default()
                    };
                    let sol = solve_explicit(&problem, density, t, &opts, previous.as_deref())?;
                    iterations += sol.steps;
                    worst = worst.max(sol.unbalanced_ratio);
                    sol.displacement
                }
            };
            solve_seconds += t_solve.elapsed().as_secs_f64();
            // Without failure criteria the stresses are for the outputs only: they are
            // recovered after the step ([`Model::after_step`]), as output work.
            let stress = if can_fail {
                cell_stresses(grid, &laws, &u)?
            } else {
                Vec::new()
            };
            Ok((u, stress))
        };
        let t0 = Instant::now();
        let done = resolution
            .resolve(grid, &mut self.failures, t, |fs| solve(fs.flags()))
            .map_err(|e| match e {
                porofrac_sim::ResolutionError::Solve(e) => e,
                other => RunError::Fracture(other.to_string()),
            })?;
        let total = t0.elapsed().as_secs_f64();
        self.wall.solve += solve_seconds;
        self.wall.assembly += total - solve_seconds;
        let stress;
        (self.u, stress) = done.solution;
        self.stress_stale = stress.is_empty();
        if !self.stress_stale {
            self.stress = stress;
        }
        self.stats.iterations += iterations;
        self.stats.max_relative_residual = self.stats.max_relative_residual.max(worst);
        self.stats.factorizations = self.count_base + solver.numeric_factorizations();
        self.stats.symbolic_factorizations = solver.symbolic_factorizations();
        self.stats.factor_nnz = solver.factor_nnz();
        Ok(iterations)
    }

    /// The coupled step to `times[step]`.
    fn coupled_step(&mut self, step: usize) -> Result<usize, RunError> {
        let Driver::Coupled { frac, state } = &mut self.driver else {
            return Ok(0);
        };
        let t = self.times[step];
        let t_solve = Instant::now();
        let next = match state.as_ref() {
            None if self.zero_start => {
                *state = Some(BiotState {
                    displacement: vec![0.0; self.u.len()],
                    pressure: frac.initial_pressure().to_vec(),
                });
                self.pressure = state.as_ref().map(|s| s.pressure.clone());
                return Ok(0);
            }
            None => frac.initial_state(t)?,
            Some(st) => {
                let t_prev = self.times[step - 1];
                frac.step(st, t_prev, t - t_prev)?
            }
        };
        self.wall.solve += t_solve.elapsed().as_secs_f64();
        self.stats.iterations += next.solves;
        self.stats.max_relative_residual = self.stats.max_relative_residual.max(next.residual);
        let coupling = frac.stats();
        self.stats.linear = coupling.linear.into();
        self.stats.factorizations = self.count_base + coupling.numeric_factorizations;
        self.stats.symbolic_factorizations = coupling.symbolic_factorizations;
        self.stats.factor_nnz = coupling.factor_nnz;
        self.stats.low_rank_updates = coupling.low_rank_updates;
        self.failures = frac.failures().clone();
        self.pressure = Some(next.state.pressure.clone());
        self.u.clone_from(&next.state.displacement);
        self.stress = next.stress;
        *state = Some(next.state);
        Ok(next.solves)
    }

    /// The step to `times[step]` (the [`Model::step`] before its errors are explained).
    fn step_at(&mut self, step: usize) -> Result<StepStats, RunError> {
        let t = self.times[step];
        self.done = step;
        let iterations = if matches!(self.driver, Driver::Coupled { .. }) {
            self.coupled_step(step)?
        } else if step == 0 && self.zero_start {
            0
        } else {
            self.static_step(t)?
        };
        if let (Some(f), Some(p), true) =
            (self.fixed_flow.as_mut(), self.pressure.as_mut(), step > 0)
        {
            let t_flow = Instant::now();
            let t_prev = self.times[step - 1];
            let res = f
                .model
                .step(p, t - t_prev, t_prev)
                .map_err(|e| RunError::Flow(e.to_string()))?;
            *p = res.pressure;
            self.wall.flow += t_flow.elapsed().as_secs_f64();
        }
        Ok(StepStats {
            iterations,
            failed: self.failures.count(),
        })
    }

    /// The value of `field` at a located point.
    fn sample(&self, field: Field, loc: &Location) -> f64 {
        let c = loc.cell;
        match field {
            Field::Displacement(a) => loc.nodal(&self.u, D, a),
            Field::Pressure => self.pressure.as_ref().map_or(f64::NAN, |p| p[c]),
            Field::Fractured => f64::from(u8::from(self.failures.flags()[c])),
            f => f
                .of_stress(&self.stress[c], self.nu_of_cell[c], self.plane_strain)
                .unwrap_or(f64::NAN),
        }
    }
}

impl<const D: usize> Model for Stepper<'_, D> {
    fn times(&self) -> &[f64] {
        &self.times
    }

    fn step(&mut self, step: usize) -> Result<StepStats, RunError> {
        let cells = self.body.grid.num_cells();
        let stats = self
            .step_at(step)
            .map_err(|e| explain::explain(self.ls, cells, e))?;
        let stress: &[Tensor<D>] = if self.stress_stale { &[] } else { &self.stress };
        explain::check_state(
            self.ls,
            self.times[step],
            &self.u,
            self.pressure.as_deref(),
            stress,
        )?;
        Ok(stats)
    }

    fn probes(&self, values: &mut Vec<f64>) {
        values.extend(self.probes.iter().map(|(f, loc)| self.sample(*f, loc)));
    }

    fn line(&self, line: usize, rows: &mut Vec<Vec<f64>>) {
        let (field, points) = &self.lines[line];
        for (s, x, loc) in points {
            let mut r = Vec::with_capacity(D + 2);
            r.push(*s);
            r.extend(x.iter().copied());
            r.push(self.sample(*field, loc));
            rows.push(r);
        }
    }

    fn after_step(&mut self, _out: &Path) -> Result<(), RunError> {
        let grid = self.body.grid;
        if self.stress_stale {
            let t_out = Instant::now();
            let laws = LawMap::new(
                grid,
                self.law_refs.clone(),
                self.comp.law_of_cell_after(self.failures.flags()),
            )?;
            self.stress = cell_stresses(grid, &laws, &self.u)?;
            self.stress_stale = false;
            explain::check_state::<D>(self.ls, self.times[self.done], &[], None, &self.stress)?;
            self.wall.output += t_out.elapsed().as_secs_f64();
        }
        for f in &self.failures.log()[self.logged..] {
            let Some(csv) = self.fracture_csv.as_mut() else {
                break;
            };
            let x = grid.cell_centroid(f.cell);
            let mut row = vec![f.cell.to_string()];
            row.extend(x.iter().map(|v| v.to_string()));
            row.push(f.time.to_string());
            row.push(f.mode.as_str().to_string());
            csv.push_text(&row)?;
        }
        self.logged = self.failures.count();
        Ok(())
    }

    fn write_vtk(&self, dir: &Path, index: usize) -> Result<String, RunError> {
        let grid = self.body.grid;
        let name = format!("step_{index:04}.vtu");
        let disp: Vec<Point<D>> = (0..grid.num_nodes())
            .map(|n| Point::<D>::from_column_slice(&self.u[D * n..D * n + D]))
            .collect();
        let sym = self.stress_xyz();
        let fractured: Vec<i32> = self.failures.flags().iter().map(|&f| f as i32).collect();
        let mut cell_data = vec![
            ("stress", VtkField::SymTensors(&sym)),
            ("law", VtkField::Ints(&self.law_ids)),
            ("fractured", VtkField::Ints(&fractured)),
        ];
        if let Some(p) = self.pressure.as_deref() {
            cell_data.push(("pressure", VtkField::Scalars(p)));
        }
        // Corner-point grids: each cell's 1-based (i, j, k) and its volume.
        let ijk: Vec<Point<D>> = self
            .deck
            .ijk
            .iter()
            .map(|c| Point::<D>::from_fn(|a, _| (c[a] + 1) as f64))
            .collect();
        if !ijk.is_empty() {
            cell_data.push(("ijk", VtkField::Vectors(&ijk)));
            cell_data.push(("volume", VtkField::Scalars(grid.cell_volumes())));
        }
        write_vtu(
            dir.join(&name),
            grid,
            &[("displacement", VtkField::Vectors(&disp))],
            &cell_data,
        )?;
        Ok(name)
    }

    fn after_step_in_memory(&mut self) -> Result<(), RunError> {
        // Without an output folder there is no fracture log: this only brings the
        // stresses up to date.
        self.after_step(Path::new(""))
    }

    fn snapshot(&self, mesh: bool) -> Option<crate::common::snapshot::Snapshot> {
        use crate::common::snapshot::{Array, Mesh, Snapshot};
        let grid = self.body.grid;
        let mut cell_data = vec![
            Array::new(
                "stress",
                6,
                self.stress_xyz().into_iter().flatten().collect(),
            ),
            Array::new(
                "law",
                1,
                self.law_ids.iter().map(|&l| f64::from(l)).collect(),
            ),
            Array::new(
                "fractured",
                1,
                self.failures
                    .flags()
                    .iter()
                    .map(|&f| f64::from(u8::from(f)))
                    .collect(),
            ),
        ];
        if let Some(p) = self.pressure.as_deref() {
            cell_data.push(Array::new("pressure", 1, p.to_vec()));
        }
        Some(Snapshot {
            time: 0.0,
            mesh: mesh.then(|| std::sync::Arc::new(Mesh::of(grid))),
            point_data: vec![Array::new(
                "displacement",
                D,
                self.u[..D * grid.num_nodes()].to_vec(),
            )],
            cell_data,
            particles: None,
            lattice: None,
        })
    }

    fn field_extrema(&self) -> BTreeMap<String, [f64; 2]> {
        let grid = self.body.grid;
        let mut out = BTreeMap::new();
        let mut put = |name: &str, values: &mut dyn Iterator<Item = f64>| {
            let mut r = [f64::INFINITY, f64::NEG_INFINITY];
            for v in values {
                r[0] = r[0].min(v);
                r[1] = r[1].max(v);
            }
            if r[0] <= r[1] {
                out.insert(name.to_string(), r);
            }
        };
        for (a, name) in ["ux", "uy", "uz"].iter().enumerate().take(D) {
            put(name, &mut (0..grid.num_nodes()).map(|n| self.u[D * n + a]));
        }
        // Principal stresses once per cell for both extrema.
        let principal: Vec<[f64; 2]> = self
            .stress
            .iter()
            .map(|s| {
                let p = porofrac_law::principal(s);
                [p.values[0], p.values[D - 1]]
            })
            .collect();
        put("smax", &mut principal.iter().map(|p| p[0]));
        put("smin", &mut principal.iter().map(|p| p[1]));
        for name in ["sxx", "syy", "szz", "sxy", "syz", "sxz"] {
            let Ok(f) = Field::parse(name, D, false) else {
                continue;
            };
            put(
                name,
                &mut self
                    .stress
                    .iter()
                    .zip(&self.nu_of_cell)
                    .filter_map(|(s, &nu)| f.of_stress(s, nu, self.plane_strain)),
            );
        }
        if let Some(p) = &self.pressure {
            put("pressure", &mut p.iter().copied());
        }
        put(
            "fractured",
            &mut self
                .failures
                .flags()
                .iter()
                .map(|&f| f64::from(u8::from(f))),
        );
        out
    }

    fn plots(&self, dir: &Path, written: &[f64], series: &[Vec<f64>]) -> Result<(), RunError> {
        plots::write_plots(
            self.ls,
            dir,
            self.body.grid,
            plots::PlotInputs {
                series,
                written_times: written,
                u: &self.u,
                stress: &self.stress,
                failures: &self.failures,
                pressure: self.pressure.as_deref(),
            },
        )
    }

    fn sizes(&self) -> Sizes {
        let (cells, nodes, dofs) = (
            self.body.grid.num_cells(),
            self.body.grid.num_nodes(),
            self.body.dofs.num_equations(),
        );
        let mut counts = vec![("cells", cells), ("nodes", nodes), ("unknowns", dofs)];
        if self.pressure.is_some() {
            counts.push(("pressure unknowns", cells));
        }
        Sizes {
            cells: Some(cells),
            nodes: Some(nodes),
            dofs: Some(dofs),
            counts,
            failed: Some("fractured cells"),
        }
    }

    fn unit(&self, field: &str) -> &'static str {
        fields::unit(field)
    }

    fn failed(&self) -> usize {
        self.failures.count()
    }

    fn solver_stats(&self) -> SolverStats {
        self.stats.clone()
    }

    fn errors(&self) -> Result<BTreeMap<String, f64>, RunError> {
        let mut out = BTreeMap::new();
        let Some(exact) = &self.ls.scene.output.exact_displacement else {
            return Ok(out);
        };
        let t = self.times.get(self.done).copied().unwrap_or(0.0);
        let exact = crate::common::sections::vector_field::<D>(exact);
        let l2 = porofrac_sim::norms::l2_error_p1_field(self.body.grid, &self.u, &exact, t)
            .ok_or_else(|| {
                self.ls.error(
                    &k(&["output", "exact_displacement"]),
                    "needs a grid of triangles or tetrahedra (the error is that of the P1 \
                 interpolant of the nodal displacement)",
                )
            })?;
        out.insert("l2_displacement".into(), l2);
        Ok(out)
    }

    fn wall_seconds(&self) -> WallSeconds {
        self.wall
    }

    fn work(&self) -> crate::common::limits::Work {
        use crate::common::limits as l;
        // A solve with the factor per output time, the initial one included; failures
        // resolved within a step cost more.
        let seconds_per_unit = match (self.comp.can_fail(), D) {
            (false, _) => l::CONTINUUM_SECONDS_PER_ENTRY,
            (true, 2) => l::CONTINUUM_SECONDS_PER_ENTRY_FAILING_2D,
            (true, _) => l::CONTINUUM_SECONDS_PER_ENTRY_FAILING_3D,
        };
        l::Work {
            units: l::factor_entries(D, self.unknowns) * self.times.len() as f64,
            seconds_per_unit,
            unit: "factor-entry steps",
            factor: 5.0,
        }
    }

    fn peak_bytes(&self) -> f64 {
        self.peak_bytes
    }

    fn checkpoints(&self) -> bool {
        checkpoint::supported(self)
    }

    fn save_state(&self, state: &mut crate::common::checkpoint::State) -> Result<(), RunError> {
        checkpoint::save(self, state);
        Ok(())
    }

    fn restore_state(
        &mut self,
        state: &crate::common::checkpoint::State,
        _out: &Path,
    ) -> Result<(), RunError> {
        checkpoint::restore(self, state)
    }
}

/// Failure criteria, stress measure, tracking and limits of the scene: the same for the
/// static and the coupled drivers.
fn fracture_settings<const D: usize>(ls: &LoadedScene, comp: &Composition<D>) -> FractureSettings {
    let s = &ls.scene;
    let mut settings = FractureSettings::new(comp.criteria.clone(), comp.law_of_cell.clone());
    if comp.can_fail() {
        if s.physics.failure_stress == Some(FailureStress::Recovered) {
            settings.stress = StressMeasure::Recovered;
        }
        settings.tracking_angle = s.physics.crack_tracking;
        settings.exclusion_radius = s.physics.crack_exclusion.unwrap_or(0.0);
        if let Some(
            rule @ (crate::common::sections::TipRuleChoice::Opening
            | crate::common::sections::TipRuleChoice::Asymptote),
        ) = s.physics.tip_rule
        {
            let plane_stress =
                D == 2 && s.scene.plane == Some(crate::common::sections::Plane::Stress);
            let e_prime: Vec<f64> = comp
                .material_of_cell()
                .into_iter()
                .map(|m| {
                    let mat = &s.material[m];
                    let nu = mat.poisson_ratio;
                    if plane_stress {
                        mat.youngs_modulus
                    } else {
                        mat.youngs_modulus / (1.0 - nu * nu)
                    }
                })
                .collect();
            settings.tip = if rule == crate::common::sections::TipRuleChoice::Asymptote {
                porofrac_sim::TipRule::Asymptote {
                    e_prime,
                    mu_prime: 12.0 * s.fluid.as_ref().map_or(0.0, |f| f.viscosity),
                }
            } else if let Some(distance) = s.physics.tip_sample_distance {
                porofrac_sim::TipRule::OpeningAt { e_prime, distance }
            } else {
                porofrac_sim::TipRule::Opening(e_prime)
            };
        }
    }
    settings
}

/// Density of every cell, for explicit mechanics.
fn densities<const D: usize>(
    ls: &LoadedScene,
    comp: &Composition<D>,
) -> Result<Vec<f64>, RunError> {
    comp.material_of_cell()
        .into_iter()
        .map(|mat| {
            ls.scene.material[mat].density.ok_or_else(|| {
                ls.error(
                    &k(&["material", mat, "density"]),
                    "is required by solver.mechanics = \"explicit\"",
                )
                .into()
            })
        })
        .collect()
}

/// The coupled flow–mechanics driver of a scene ([`Fracturing`]: with failure criteria
/// when a material has a strength, without them it is plain poroelasticity).
fn coupled<'a, const D: usize>(
    ls: &LoadedScene,
    body: Body<'a, D>,
    comp: &Composition<D>,
    law_refs: &[&'a dyn CellLaw<D>],
    f: FlowSetup<D>,
    settings: FractureSettings,
) -> Result<Fracturing<'a, D>, RunError> {
    let s = &ls.scene;
    let coupling = s.physics.coupling.unwrap_or_default();
    let laws = FractureLaws {
        laws: law_refs.to_vec(),
        law_of_cell: comp.law_of_cell.clone(),
        post_failure: comp.post_failure.clone(),
    };
    let source_cells = f.source_cells.clone();
    let flow = FractureFlow {
        model: f.model,
        permeability: f.permeability,
        fracture_permeability: comp.can_fail().then(|| {
            match (
                s.physics.fracture_transmissivity,
                s.physics.fracture_permeability,
            ) {
                _ if s.physics.crack_flow == Some(CrackFlow::CubicLaw) => {
                    FracturePermeability::CubicLaw(
                        s.physics.fracture_transmissivity.unwrap_or(1e-13),
                    )
                }
                (Some(t), _) => FracturePermeability::Transmissivity(t),
                (None, k) => FracturePermeability::Fixed(k.unwrap_or(1e-12)),
            }
        }),
        zero_lag: s.physics.fluid_lag == Some(false),
        alpha: f.alpha,
        p0: f.p0,
    };
    let mut k_dr = Vec::new();
    if coupling == CouplingChoice::FixedStress {
        for mat in comp.material_of_cell() {
            let st = material_stiffness::<D>(ls, mat, &s.material[mat])?;
            k_dr.push(drained_bulk_modulus(&st));
        }
    }
    let tolerance = s.solver.tolerance.unwrap_or(1e-10);
    let mut run = Fracturing::new(body, laws, settings, flow, |sys| {
        let sys: &porofrac_sim::BiotSystem<'_, D> = sys;
        Ok(match coupling {
            CouplingChoice::FixedStress => {
                Scheme::FixedStress(FixedStress::new(tolerance, 500), k_dr)
            }
            CouplingChoice::ExplicitPressure => {
                Scheme::ExplicitPressure(ExplicitPressure::new(source_cells.clone()), source_cells)
            }
            _ => Scheme::Monolithic(Monolithic::new(sys, None)?),
        })
    })?;
    run.set_cavitation_pressure(s.physics.cavitation_pressure)?;
    Ok(run)
}

/// The cells holding the probes and the points of the output lines, with their fields;
/// errors name the probe or line that lies outside the grid.
#[allow(clippy::type_complexity)]
fn locate_outputs<const D: usize>(
    ls: &LoadedScene,
    grid: &Grid<D>,
) -> Result<(Vec<(Field, Location)>, Vec<(Field, LinePoints<D>)>), RunError> {
    let s = &ls.scene;
    let flow = s.physics.flow == Some(true);
    let field = |name: &str, key: Vec<crate::common::sections::KeyPart>| {
        Field::parse(name, D, flow).map_err(|e| RunError::from(ls.error(&key, e)))
    };
    let mut probes = Vec::new();
    for (i, p) in s.output.probe.iter().enumerate() {
        let f = field(&p.field, ki("output.probe", i, &["field"]))?;
        let loc = locate(grid, &point(&p.at)).ok_or_else(|| {
            ls.error(
                &ki("output.probe", i, &["at"]),
                format!("= {:?} is outside the grid", p.at),
            )
        })?;
        probes.push((f, loc));
    }
    let mut lines = Vec::new();
    for (i, l) in s.output.line.iter().enumerate() {
        let f = field(&l.field, ki("output.line", i, &["field"]))?;
        let (a, b): (Point<D>, Point<D>) = (point(&l.from), point(&l.to));
        let mut pts = Vec::new();
        for j in 0..l.points as usize {
            let frac = j as f64 / (l.points as f64 - 1.0);
            let x = a + (b - a) * frac;
            let loc = locate(grid, &x).ok_or_else(|| {
                ls.error(
                    &ki("output.line", i, &["from"]),
                    format!("point {:?} of the line is outside the grid", x.as_slice()),
                )
            })?;
            pts.push(((b - a).norm() * frac, x, loc));
        }
        lines.push((f, pts));
    }
    Ok((probes, lines))
}

/// The model `continuum` in the registry ([`crate::MODELS`]).
pub struct ContinuumKind;

/// The registry's value of the model.
pub static KIND: ContinuumKind = ContinuumKind;

impl ModelKind for ContinuumKind {
    fn name(&self) -> &'static str {
        "continuum"
    }
    fn sections(&self) -> &'static [&'static str] {
        &[
            "grid", "region", "material", "fluid", "bc", "loads", "source", "well", "initial",
            "physics",
        ]
    }
    fn check(&self, ls: &LoadedScene, laws: &LawRegistry) -> Result<(), SceneError> {
        check::check(ls, laws)
    }
    fn build(
        &self,
        ls: &LoadedScene,
        laws: &LawRegistry,
        purpose: &Purpose<'_>,
        observer: &mut dyn Observer,
    ) -> Result<Built, RunError> {
        build(ls, laws, purpose, observer)
    }
    #[cfg(feature = "mpi")]
    fn run_distributed(
        &self,
        ls: &LoadedScene,
        laws: &LawRegistry,
        out: &Path,
        world: &mpi::topology::SimpleCommunicator,
        observer: &mut dyn Observer,
    ) -> Result<crate::common::output::Summary, RunError> {
        distributed::run_distributed(ls, laws, out, world, observer)
    }
}
