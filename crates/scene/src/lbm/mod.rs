//! The lattice Boltzmann model (P. Mora, Y. Wang, F. Alonso-Marroquin (2015), J. Earth Sci.
//! 26(1); `[scene] model = "lbm"`): a D2Q9 fluid with obstacles whose surfaces fall between
//! nodes ([`porofrac_lbm`]).
//!
//! - *build*: the SI inputs of `[lbm]` are converted to lattice units ([`Units`]: `Δt`
//!   from spacing, viscosity and tau), the sides of `[[lbm.boundary]]` and the
//!   `[[obstacle]]`s are placed on the lattice. Nodes sit at the centres of the `Δx` cells
//!   covering `extent`, so walls on the sides lie halfway between nodes;
//! - *step*: from one output time to the next, `t/Δt` lattice steps in total (output
//!   times are whole numbers of lattice steps, checked by [`check`](mod@check): an interval between
//!   two lattice steps is refused with the nearest valid values, as lbmpy and Palabos
//!   users expect outputs every N iterations); velocities given as expressions are
//!   evaluated at every lattice step; the stop request is polled between lattice steps;
//! - *fields*: `vx vy pressure density` (bilinear between nodes), obstacle forces and
//!   torques (momentum exchange, per metre of depth), `.vti` image data.
//!
//! `summary.json` gets a `lattice` block (spacing, time step, tau, collision, nodes, the
//! Mach number of the largest velocity seen) and `mlups` (million fluid-node updates per
//! second of stepping).

pub mod check;
#[cfg(feature = "mpi")]
mod distributed;
pub mod grains;

use crate::common::checkpoint::State;
use crate::common::laws::LawRegistry;
use crate::common::loaded::SceneError;
use crate::common::model::ModelKind;
use crate::common::model::{OwnSections, own_sections};
use crate::common::sections::KeyPart;

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use porofrac_lbm::{Lattice, MAX_MACH, Obstacle, ObstacleOverhang, Shape, Side, Thermal, Units};

pub use check::check;

use crate::common::driver::{Observer, SetupPoll, Stop};
use crate::common::expr::Expr;
use crate::common::lattice::images;
use crate::common::lattice::sections::{CollisionChoice, ShapeChoice};
use crate::common::lattice::{
    LatticeParts, VelocityExpr, set_side_velocities, thermal_initial, thermal_sides, thermal_tau,
    window_of,
};
use crate::common::loaded::{LoadedScene, k, ki};
use crate::common::model::{Built, Model, Purpose, RunError, Sizes, StepStats};
use crate::common::output::{OutputError, SolverStats, WallSeconds, write_atomic};
use crate::common::plots::{Column, tick};
use crate::common::sections::NumOrExpr;
use porofrac_vtk::{Attributes, DataArray, Encoding, ImageData};

/// What a probe reads.
enum ProbeKind {
    Field(FieldName, [f64; 2]),
    Obstacle(usize, usize),
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum FieldName {
    Vx,
    Vy,
    Pressure,
    Density,
    Temperature,
}

impl FieldName {
    fn parse(s: &str) -> Self {
        match s {
            "vx" => FieldName::Vx,
            "vy" => FieldName::Vy,
            "pressure" => FieldName::Pressure,
            "temperature" => FieldName::Temperature,
            _ => FieldName::Density,
        }
    }
}

/// The lattice Boltzmann model stepping through its output times.
struct LbmModel<'a> {
    ls: &'a LoadedScene,
    lat: Lattice,
    thermal: Option<Thermal>,
    units: Units,
    origin: [f64; 2],
    times: Vec<f64>,
    sides: Vec<(Side, VelocityExpr)>,
    motions: Vec<(Option<VelocityExpr>, Option<Expr>)>,
    probes: Vec<ProbeKind>,
    stepping_seconds: f64,
    fluid_updates: f64,
    max_mach: f64,
    name: String,
    /// Polled between the lattice steps of an output step.
    stop: Stop,
    /// The heat books of every lattice step so far (`thermal.books`, [`grains::row`]).
    books: Vec<[f64; 9]>,
    /// `ρ c_p Δx²`: lattice heat (temperature × nodes) → J per metre of depth.
    joules: f64,
    /// After every lattice step: what a distributed run exchanges between ranks (none in
    /// a serial run).
    halo: Option<Halo<'a>>,
}

/// The exchange of a distributed run after every lattice step.
type Halo<'a> = Box<dyn Fn(&mut Lattice, Option<&mut Thermal>) + 'a>;

/// Build a checked lattice Boltzmann scene's model and hand it to `purpose`.
pub(crate) fn build_for(
    ls: &LoadedScene,
    purpose: &Purpose<'_>,
    observer: &mut dyn Observer,
) -> Result<Built, RunError> {
    let start = Instant::now();
    let mut model = build(ls, &mut SetupPoll::new(observer), None)?;
    let build_seconds = start.elapsed().as_secs_f64();
    purpose.finish(ls, &mut model, observer, start, build_seconds, 2)
}

/// The obstacle's shape on the lattice (lattice units from the box's corner `origin`).
fn shape_of(
    o: &crate::common::lattice::sections::ObstacleSection,
    units: &Units,
    origin: [f64; 2],
) -> Shape {
    match &o.shape {
        ShapeChoice::Circle(c) => Shape::Circle {
            center: [
                units.length(c.center[0] - origin[0]),
                units.length(c.center[1] - origin[1]),
            ],
            radius: units.length(c.radius),
        },
        ShapeChoice::Box(b) => Shape::aligned_box(
            [
                units.length(b[0][0] - origin[0]),
                units.length(b[0][1] - origin[1]),
            ],
            [
                units.length(b[1][0] - origin[0]),
                units.length(b[1][1] - origin[1]),
            ],
        ),
    }
}

/// Build the model of a checked scene: the whole lattice, or (a distributed run) its
/// columns `window[0] .. window[1]`.
fn build<'a>(
    ls: &'a LoadedScene,
    setup: &mut SetupPoll<'_>,
    window: Option<[usize; 2]>,
) -> Result<LbmModel<'a>, RunError> {
    let s = &ls.scene;
    let l = s.lbm.as_ref().expect("checked");
    let LatticeParts {
        mut lat,
        units,
        origin,
        sides,
    } = window_of(ls, window)?;
    let mut motions = Vec::new();
    // a wall block may overhang a side that is not periodic: clipped to the lattice
    lat.set_obstacle_overhang(ObstacleOverhang::Clipped);
    for (i, o) in own(ls).obstacle.iter().enumerate() {
        let shape = shape_of(o, &units, origin);
        let v = o.velocity.as_ref().map(|v| VelocityExpr::new(v));
        let w = o.angular_velocity.as_ref().map(|w| match w {
            NumOrExpr::Num(x) => Expr::constant(*x),
            NumOrExpr::Expr(s) => Expr::parse(s).unwrap_or_else(|_| Expr::constant(f64::NAN)),
        });
        lat.add_obstacle(Obstacle {
            shape,
            velocity: [0.0, 0.0],
            angular_velocity: 0.0,
        })
        .map_err(|e| ls.error(&ki("obstacle", i, &["shape"]), e))?;
        motions.push((v, w));
    }
    let grain_nodes = match &own(ls).grains {
        Some(g) => grains::add(ls, g, &mut lat)?,
        None => Vec::new(),
    };
    let thermal = match &s.thermal {
        None => None,
        Some(t) => {
            let mut tsides = thermal_sides(t, &units);
            // a window's own sides inside the box (their columns are other ranks')
            let (w, (nx, _)) = (lat.origin(), lat.size());
            if w > 0 {
                tsides[Side::XMin.index()] = porofrac_lbm::ThermalSide::Adiabatic;
            }
            if w + nx < lat.box_size().0 {
                tsides[Side::XMax.index()] = porofrac_lbm::ThermalSide::Adiabatic;
            }
            let init = thermal_initial(t);
            let tau = thermal_tau(t.diffusivity, &units);
            let tau_s = thermal_tau(t.solid_diffusivity.unwrap_or(t.diffusivity), &units);
            let (dx, o) = (units.dx, origin);
            let mut th = Thermal::new(&lat, tau, tau_s, tsides, |p| {
                init.eval(&[o[0] + p[0] * dx, o[1] + p[1] * dx], 0.0)
            })
            .map_err(|e| ls.error(&k(&["thermal", "diffusivity"]), e))?;
            if let Some(g) = &own(ls).grains {
                grains::heat(g, &mut th, &grain_nodes);
            }
            if t.books == Some(true) {
                if window.is_some() {
                    return Err(ls
                        .error(
                            &k(&["thermal", "books"]),
                            "are kept in serial runs only (run without mpirun)",
                        )
                        .into());
                }
                th.keep_books();
            }
            Some(th)
        }
    };
    let heat_capacity = s.thermal.as_ref().and_then(|t| t.heat_capacity);
    let joules = heat_capacity.unwrap_or(4.18e6) * units.dx * units.dx;
    let mut model = LbmModel {
        ls,
        lat,
        thermal,
        units,
        origin,
        times: output_times(ls),
        sides,
        motions,
        probes: Vec::new(),
        stepping_seconds: 0.0,
        fluid_updates: 0.0,
        max_mach: 0.0,
        name: s.scene.name.clone(),
        stop: setup.stop_handle(),
        halo: None,
        books: Vec::new(),
        joules,
    };
    for p in &s.output.probe {
        model.probes.push(match &p.obstacle {
            Some(o) => {
                let idx = own(ls)
                    .obstacle
                    .iter()
                    .position(|x| &x.name == o)
                    .expect("checked");
                let f = check::OBSTACLE_FIELDS
                    .iter()
                    .position(|f| *f == p.field)
                    .expect("checked");
                ProbeKind::Obstacle(idx, f)
            }
            None => ProbeKind::Field(FieldName::parse(&p.field), [p.at[0], p.at[1]]),
        });
    }
    model.apply_motion(0.0)?;
    if let Some(v) = &l.initial_velocity {
        let v = VelocityExpr::new(v);
        let (dx, o, u) = (units.dx, origin, units);
        // Every node's value must be finite (and below the Mach limit) before the
        // lattice takes it: name the key and the first bad point.
        let (nx, ny) = model.lat.size();
        let key = k(&["lbm", "initial_velocity"]);
        for j in 0..ny {
            for i in 0..nx {
                let x = [o[0] + (i as f64 + 0.5) * dx, o[1] + (j as f64 + 0.5) * dx];
                let w = v.at(x, 0.0);
                let speed = (w[0] * w[0] + w[1] * w[1]).sqrt();
                if !speed.is_finite() {
                    return Err(ls
                        .error(
                            &key,
                            format!(
                                "is [{}, {}] at x = [{:e}, {:e}] m: not a finite velocity",
                                w[0], w[1], x[0], x[1]
                            ),
                        )
                        .into());
                }
                let ma = u.mach(speed);
                if ma > MAX_MACH {
                    return Err(ls
                        .error(
                            &key,
                            format!(
                                "is {speed:e} m/s at x = [{:e}, {:e}] m, Mach {ma:.3} on this \
                                 lattice (limit {MAX_MACH}): refine the spacing, lower tau or \
                                 the velocity",
                                x[0], x[1]
                            ),
                        )
                        .into());
                }
            }
            if setup.poll("initial velocity, row", j, ny) {
                return Err(RunError::Interrupted);
            }
        }
        model.lat.init(|p| {
            let x = [o[0] + p[0] * dx, o[1] + p[1] * dx];
            let w = v.at(x, 0.0);
            (1.0, [u.velocity(w[0]), u.velocity(w[1])])
        });
    }
    model.check_state()?;
    Ok(model)
}

fn output_times(ls: &LoadedScene) -> Vec<f64> {
    let mut t = vec![0.0];
    if let Some(sch) = &ls.scene.schedule {
        let n =
            crate::common::loaded::step_count(sch).min(crate::common::limits::MAX_STEPS) as usize;
        let dt = sch.dt.unwrap_or(sch.end_time / n as f64);
        for k in 1..=n {
            t.push((k as f64 * dt).min(sch.end_time));
        }
    }
    t
}

impl LbmModel<'_> {
    /// The node arrays of the VTK files and the in-memory snapshots, row after row:
    /// velocity (3 per node, m/s), pressure (Pa), density (kg/m³), solid (1 in a solid)
    /// and temperature (K; empty without heat).
    fn node_arrays(&self) -> [Vec<f64>; 5] {
        let (nx, ny) = self.lat.size();
        let mut velocity = Vec::with_capacity(3 * nx * ny);
        let mut pressure = Vec::with_capacity(nx * ny);
        let mut density = Vec::with_capacity(nx * ny);
        let mut solid = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let (rho, u) = self.lat.moments(i, j);
                velocity.extend([
                    self.units.velocity_si(u[0]),
                    self.units.velocity_si(u[1]),
                    0.0,
                ]);
                pressure.push(self.units.pressure_si(rho));
                density.push(rho * self.units.density);
                solid.push(if self.lat.is_solid(i, j) { 1.0 } else { 0.0 });
            }
        }
        let temperature: Vec<f64> = match &self.thermal {
            Some(th) => (0..ny)
                .flat_map(|j| (0..nx).map(move |i| th.temperature(i, j)))
                .collect(),
            None => Vec::new(),
        };
        [velocity, pressure, density, solid, temperature]
    }

    /// Lattice position → SI position.
    fn si(&self, p: [f64; 2]) -> [f64; 2] {
        [
            self.origin[0] + p[0] * self.units.dx,
            self.origin[1] + p[1] * self.units.dx,
        ]
    }

    /// Set side and obstacle velocities at time `t` (s).
    fn apply_motion(&mut self, t: f64) -> Result<(), RunError> {
        let u = self.units;
        set_side_velocities(&mut self.lat, &self.sides, &u, self.origin, t);
        for (kk, (v, w)) in self.motions.iter().enumerate() {
            let vel = v.as_ref().map_or([0.0, 0.0], |v| v.at([0.0, 0.0], t));
            let omega = w.as_ref().map_or(0.0, |w| w.eval(&[0.0, 0.0], t));
            if !(vel[0].is_finite() && vel[1].is_finite() && omega.is_finite()) {
                return Err(self
                    .ls
                    .error(
                        &ki("obstacle", kk, &["velocity"]),
                        format!("is not finite at t = {t}"),
                    )
                    .into());
            }
            self.lat.set_obstacle_motion(
                kk,
                [u.velocity(vel[0]), u.velocity(vel[1])],
                omega * u.dt,
            );
        }
        Ok(())
    }

    fn time_dependent(&self) -> bool {
        self.sides.iter().any(|(_, v)| v.varies_in_time())
            || self.motions.iter().any(|(v, w)| {
                v.as_ref().is_some_and(VelocityExpr::varies_in_time)
                    || w.as_ref().is_some_and(Expr::depends_on_time)
            })
    }

    /// The largest Mach number so far; an error when the flow diverged or exceeds the limit.
    fn check_state(&mut self) -> Result<(), RunError> {
        let speed = self.lat.max_speed().map_err(|e| {
            RunError::Flow(format!(
                "lbm: {e} (at t = {:.6e} s). The usual causes: lbm.tau too close to 0.5, a \
                 velocity (lbm.initial_velocity, a boundary or obstacle velocity) or \
                 lbm.body_force too large for the lattice (Mach), or too coarse an \
                 lbm.spacing",
                self.lat.steps() as f64 * self.units.dt
            ))
        })?;
        let ma = speed / (1.0f64 / 3.0).sqrt();
        self.max_mach = self.max_mach.max(ma);
        if ma > MAX_MACH {
            return Err(RunError::Flow(format!(
                "lbm: the flow reached Mach {ma:.3} (limit {MAX_MACH}) at t = {:.6e} s: refine lbm.spacing or lower lbm.tau",
                self.lat.steps() as f64 * self.units.dt
            )));
        }
        Ok(())
    }

    /// An error if a moving obstacle ran into another (they came to cover a common node):
    /// the check refuses obstacles that overlap at the start, and this is the same rule
    /// during the run.
    fn check_contacts(&self) -> Result<(), RunError> {
        for (kk, (v, w)) in self.motions.iter().enumerate() {
            if v.is_none() && w.is_none() {
                continue;
            }
            if let Some(j) = self.lat.contact(kk) {
                let obs = &own(self.ls).obstacle;
                let other = ki("obstacle", j, &["shape"]);
                return Err(self
                    .ls
                    .error(
                        &ki("obstacle", kk, &["velocity"]),
                        format!(
                            "carries obstacle[{kk}] (\"{}\") into obstacle[{j}] (\"{}\", \
                             line {}) at t = {:.6e} s: obstacles may not overlap (a node both \
                             cover would give its links, and the force, to one of them only)",
                            obs[kk].name,
                            obs[j].name,
                            self.ls.line_of(&other),
                            self.lat.steps() as f64 * self.units.dt
                        ),
                    )
                    .into());
            }
        }
        Ok(())
    }

    /// Density and velocity (lattice units) at an SI point, bilinear between nodes.
    fn sample(&self, x: [f64; 2]) -> (f64, [f64; 2]) {
        let ([i0, j0], [fx, fy]) = self.cell_of(x);
        let corners = [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ];
        // Fluid nodes only where there are any (solid nodes carry no pressure).
        let fluid = corners
            .iter()
            .any(|&(di, dj, w)| w > 0.0 && !self.lat.is_solid(i0 + di, j0 + dj));
        let (mut rho, mut u, mut sum) = (0.0, [0.0, 0.0], 0.0);
        for (di, dj, w) in corners {
            if fluid && self.lat.is_solid(i0 + di, j0 + dj) {
                continue;
            }
            let (r, v) = self.lat.moments(i0 + di, j0 + dj);
            rho += w * r;
            u[0] += w * v[0];
            u[1] += w * v[1];
            sum += w;
        }
        if sum > 0.0 {
            (rho / sum, [u[0] / sum, u[1] / sum])
        } else {
            self.lat.moments(i0, j0)
        }
    }

    /// `plots/speed.png`, `plots/vorticity.png` (`∂v_y/∂x − ∂v_x/∂y`, central differences
    /// between fluid nodes) and, with heat, `plots/temperature.png`.
    fn field_images(&self, dir: &Path) -> Result<(), RunError> {
        let (nx, ny) = self.lat.size();
        let mut speed = Vec::with_capacity(nx * ny);
        let mut vel = Vec::with_capacity(nx * ny);
        let mut solid = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let u = self.lat.moments(i, j).1;
                let v = [self.units.velocity_si(u[0]), self.units.velocity_si(u[1])];
                speed.push((v[0] * v[0] + v[1] * v[1]).sqrt());
                vel.push(v);
                solid.push(self.lat.is_solid(i, j));
            }
        }
        let h = 2.0 * self.units.dx;
        let mut vort = vec![0.0; nx * ny];
        for j in 1..ny.saturating_sub(1) {
            for i in 1..nx.saturating_sub(1) {
                let k = j * nx + i;
                vort[k] =
                    (vel[k + 1][1] - vel[k - 1][1]) / h - (vel[k + nx][0] - vel[k - nx][0]) / h;
            }
        }
        let t = self.times.last().copied().unwrap_or(0.0);
        let image = |title: &'static str, bar: &'static str, unit: &'static str| {
            let title = format!("{}: {title} at t = {} s", self.name, tick(t));
            (title, bar, unit)
        };
        for (file, (title, bar, unit), values, symmetric) in [
            (
                "speed.png",
                image("fluid speed", "speed [m/s]", "m/s"),
                &speed,
                false,
            ),
            (
                "vorticity.png",
                image("vorticity", "vorticity [1/s]", "1/s"),
                &vort,
                true,
            ),
        ] {
            images::field_png(
                &dir.join(file),
                [nx, ny],
                values,
                &solid,
                &images::LatticeImage {
                    title: &title,
                    bar,
                    unit,
                    origin: self.origin,
                    dx: self.units.dx,
                    symmetric,
                },
            )?;
        }
        if let Some(th) = &self.thermal {
            let temps: Vec<f64> = (0..ny)
                .flat_map(|j| (0..nx).map(move |i| th.temperature(i, j)))
                .collect();
            let (title, bar, unit) = image("temperature", "temperature [°C]", "°C");
            images::field_png(
                &dir.join("temperature.png"),
                [nx, ny],
                &temps,
                &vec![false; nx * ny],
                &images::LatticeImage {
                    title: &title,
                    bar,
                    unit,
                    origin: self.origin,
                    dx: self.units.dx,
                    symmetric: false,
                },
            )?;
        }
        Ok(())
    }

    /// Temperature at an SI point, bilinear between nodes (solid nodes included: heat
    /// crosses into obstacles).
    fn sample_temperature(&self, x: [f64; 2]) -> f64 {
        let Some(th) = &self.thermal else {
            return f64::NAN;
        };
        let ([i0, j0], [fx, fy]) = self.cell_of(x);
        (1.0 - fx) * (1.0 - fy) * th.temperature(i0, j0)
            + fx * (1.0 - fy) * th.temperature(i0 + 1, j0)
            + (1.0 - fx) * fy * th.temperature(i0, j0 + 1)
            + fx * fy * th.temperature(i0 + 1, j0 + 1)
    }

    /// The cell of nodes that holds SI point `x` (clamped to the box): its lower-left
    /// node (a column of the lattice, the box's column minus the window's origin) and
    /// the fractions of the bilinear interpolation.
    fn cell_of(&self, x: [f64; 2]) -> ([usize; 2], [f64; 2]) {
        let ([i0, j0], f) = self.box_cell_of(x);
        ([i0 - self.lat.origin(), j0], f)
    }

    /// [`LbmModel::cell_of`] in the box's columns.
    fn box_cell_of(&self, x: [f64; 2]) -> ([usize; 2], [f64; 2]) {
        let (nx, ny) = self.lat.box_size();
        let gx = ((x[0] - self.origin[0]) / self.units.dx - 0.5).clamp(0.0, (nx - 1) as f64);
        let gy = ((x[1] - self.origin[1]) / self.units.dx - 0.5).clamp(0.0, (ny - 1) as f64);
        let (i0, j0) = (
            (gx.floor() as usize).min(nx - 2),
            (gy.floor() as usize).min(ny - 2),
        );
        ([i0, j0], [gx - i0 as f64, gy - j0 as f64])
    }

    /// `plots/obstacle_forces.png` and `plots/probes.png`: the probe series.
    fn probe_plots(
        &self,
        dir: &Path,
        written: &[f64],
        series: &[Vec<f64>],
    ) -> Result<(), RunError> {
        let probes = &self.ls.scene.output.probe;
        if probes.is_empty() || written.is_empty() {
            return Ok(());
        }
        let column = |(p, s): (&crate::common::sections::Probe, &Vec<f64>)| {
            Column::new(p.name.clone(), check::unit(&p.field), s.clone())
        };
        let forces: Vec<Column> = probes
            .iter()
            .zip(series)
            .filter(|(p, _)| p.obstacle.is_some())
            .map(column)
            .collect();
        if !forces.is_empty() {
            crate::common::plots::time_series(
                &dir.join("obstacle_forces.png"),
                written,
                &forces,
                &format!(
                    "{}: obstacle forces and torques (per metre of depth)",
                    self.name
                ),
            )?;
        }
        let fields: Vec<Column> = probes
            .iter()
            .zip(series)
            .filter(|(p, _)| p.obstacle.is_none())
            .map(column)
            .collect();
        if !fields.is_empty() {
            crate::common::plots::time_series(
                &dir.join("probes.png"),
                written,
                &fields,
                &format!("{}: probes", self.name),
            )?;
        }
        Ok(())
    }

    fn value_at(&self, f: FieldName, x: [f64; 2]) -> f64 {
        if f == FieldName::Temperature {
            return self.sample_temperature(x);
        }
        let (rho, u) = self.sample(x);
        self.field_value(f, rho, u)
    }

    fn field_value(&self, f: FieldName, rho: f64, u: [f64; 2]) -> f64 {
        match f {
            FieldName::Temperature => f64::NAN,
            FieldName::Vx => self.units.velocity_si(u[0]),
            FieldName::Vy => self.units.velocity_si(u[1]),
            FieldName::Pressure => self.units.pressure_si(rho),
            FieldName::Density => rho * self.units.density,
        }
    }
}

impl Model for LbmModel<'_> {
    fn summary_extras(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut json = serde_json::Map::new();
        let l = self.ls.scene.lbm.as_ref().expect("checked");
        let (nx, ny) = self.lat.size();
        let rates = self.lat.rates();
        json.insert("lattice".into(), serde_json::json!({
        "spacing": self.units.dx,
        "time_step": self.units.dt,
        "tau": self.units.tau,
        "collision": match l.collision { CollisionChoice::Bgk => "bgk", CollisionChoice::Trt => "trt" },
        "omega_plus": rates.plus,
        "omega_minus": rates.minus,
        "lattice_viscosity": (self.units.tau - 0.5) / 3.0,
        "nodes": [nx, ny],
        "fluid_nodes": self.lat.fluid_nodes(),
        "lattice_steps": self.lat.steps(),
        "mach": self.max_mach,
        "mach_limit": MAX_MACH,
        "velocity_unit": self.units.dx / self.units.dt,
        "streaming": "aa (in place, one population array)",
        "population_bytes": self.lat.population_bytes(),
    }));
        let mlups = if self.stepping_seconds > 0.0 {
            self.fluid_updates / self.stepping_seconds / 1e6
        } else {
            0.0
        };
        json.insert("mlups".into(), serde_json::json!(mlups));
        if self.thermal.as_ref().is_some_and(|t| t.books().is_some()) {
            let sum = |c: usize| self.books.iter().map(|r| r[c]).sum::<f64>();
            let worst = self.books.iter().map(|r| r[8].abs()).fold(0.0, f64::max);
            let change = match (self.books.first(), self.books.last()) {
                (Some(a), Some(b)) => b[2] - a[1],
                _ => 0.0,
            };
            json.insert(
                "heat_books".into(),
                serde_json::json!({
                    "unit": "J/m",
                    "steps": self.books.len(),
                    "conduction_in": sum(3),
                    "advection_in": sum(4),
                    "advection_out": sum(5),
                    "solids": sum(6),
                    "stored_change": change,
                    "max_relative_defect": worst,
                    "file": "heat_books.csv",
                    "note": "over the fluid nodes of each lattice step; stored_change is the \
                             last step's stored heat after minus the first step's before \
                             (equal to the sum of the terms while no obstacle moves)",
                }),
            );
        }
        json
    }

    fn times(&self) -> &[f64] {
        &self.times
    }

    fn step(&mut self, step: usize) -> Result<StepStats, RunError> {
        if step == 0 {
            return Ok(StepStats::default());
        }
        let target = (self.times[step] / self.units.dt).round() as u64;
        let varies = self.time_dependent();
        let t0 = Instant::now();
        let mut n = 0;
        while self.lat.steps() < target {
            if self.stop.requested() {
                return Err(RunError::Interrupted);
            }
            if varies {
                self.apply_motion(self.lat.steps() as f64 * self.units.dt)?;
            }
            if let Some(th) = &mut self.thermal {
                th.step(&self.lat);
                if let Some(b) = th.books() {
                    self.books
                        .push(grains::row(self.lat.steps() + 1, &b, self.joules));
                }
            }
            self.lat
                .step()
                .map_err(|e| RunError::Flow(format!("lbm: {e}")))?;
            self.check_contacts()?;
            if let Some(halo) = &self.halo {
                halo(&mut self.lat, self.thermal.as_mut());
            }
            n += 1;
        }
        let dt = t0.elapsed().as_secs_f64();
        self.stepping_seconds += dt;
        self.fluid_updates += n as f64 * self.lat.fluid_nodes() as f64;
        self.check_state()?;
        Ok(StepStats {
            iterations: n,
            failed: 0,
        })
    }

    fn probes(&self, values: &mut Vec<f64>) {
        for p in &self.probes {
            values.push(match *p {
                ProbeKind::Field(f, x) => self.value_at(f, x),
                ProbeKind::Obstacle(o, c) => {
                    let f = self.lat.force(o);
                    if c == 2 {
                        self.units.torque_si(f[2])
                    } else {
                        self.units.force_si(f[c])
                    }
                }
            });
        }
    }

    fn line(&self, line: usize, rows: &mut Vec<Vec<f64>>) {
        let l = &self.ls.scene.output.line[line];
        let f = FieldName::parse(&l.field);
        let n = l.points.max(2) as usize;
        let len = ((l.to[0] - l.from[0]).powi(2) + (l.to[1] - l.from[1]).powi(2)).sqrt();
        for i in 0..n {
            let s = i as f64 / (n - 1) as f64;
            let x = [
                l.from[0] + s * (l.to[0] - l.from[0]),
                l.from[1] + s * (l.to[1] - l.from[1]),
            ];
            rows.push(vec![s * len, x[0], x[1], self.value_at(f, x)]);
        }
    }

    fn after_step(&mut self, out: &Path) -> Result<(), RunError> {
        if self.thermal.as_ref().is_some_and(|t| t.books().is_some()) {
            let mut text = String::from(grains::HEADER);
            text.push('\n');
            for r in &self.books {
                let cells: Vec<String> = r.iter().map(|v| format!("{v:e}")).collect();
                text.push_str(&cells.join(","));
                text.push('\n');
            }
            write_atomic(&out.join("heat_books.csv"), text.as_bytes())?;
        }
        Ok(())
    }

    fn checkpoints(&self) -> bool {
        // Obstacles that move change the lattice's geometry, which is not saved; the heat
        // books of the steps before a checkpoint are not saved either.
        self.motions.iter().all(|(v, w)| v.is_none() && w.is_none())
            && self.thermal.as_ref().is_none_or(|t| t.books().is_none())
    }

    fn save_state(&self, state: &mut State) -> Result<(), RunError> {
        let l = self.lat.raw_state();
        state.put_f64("lattice/populations", l.populations);
        state.put_u64("lattice/steps", vec![l.steps, u64::from(l.swapped)]);
        state.put_f64(
            "lattice/values",
            vec![
                l.injected,
                self.stepping_seconds,
                self.fluid_updates,
                self.max_mach,
            ],
        );
        state.put_f64("lattice/forces", l.forces.concat());
        state.put_f64("lattice/exchange", l.exchange.concat());
        if let Some(th) = &self.thermal {
            let t = th.raw_state();
            state.put_f64("thermal/g", t.g.concat());
            state.put_f64("thermal/post", t.post.concat());
            state.put_f64("thermal/side_heat", t.side_heat.to_vec());
            state.put_f64("thermal/obstacle_heat", t.obstacle_heat);
        }
        Ok(())
    }

    fn restore_state(&mut self, state: &State, _out: &Path) -> Result<(), RunError> {
        fn rows<const N: usize>(v: &[f64]) -> Vec<[f64; N]> {
            v.chunks_exact(N)
                .map(|c| std::array::from_fn(|k| c[k]))
                .collect()
        }
        let bad = |e: String| RunError::Checkpoint(format!("lattice: {e}"));
        let steps = state.u64s_len("lattice/steps", 2)?;
        let values = state.f64s_len("lattice/values", 4)?;
        let no = self.lat.obstacles().len();
        self.lat
            .restore_raw_state(porofrac_lbm::LatticeState {
                populations: state.f64s("lattice/populations")?.to_vec(),
                swapped: steps[1] != 0,
                steps: steps[0],
                injected: values[0],
                forces: rows(state.f64s_len("lattice/forces", 3 * no)?),
                exchange: rows(state.f64s_len("lattice/exchange", 3 * no)?),
            })
            .map_err(bad)?;
        (self.stepping_seconds, self.fluid_updates, self.max_mach) =
            (values[1], values[2], values[3]);
        if let Some(th) = &mut self.thermal {
            let side = state.f64s_len("thermal/side_heat", 4)?;
            th.restore_raw_state(porofrac_lbm::ThermalState {
                g: rows(state.f64s("thermal/g")?),
                post: rows(state.f64s("thermal/post")?),
                side_heat: [side[0], side[1], side[2], side[3]],
                obstacle_heat: state.f64s("thermal/obstacle_heat")?.to_vec(),
            })
            .map_err(bad)?;
        }
        Ok(())
    }

    fn write_vtk(&self, dir: &Path, index: usize) -> Result<String, RunError> {
        let name = format!("step_{index:04}.vti");
        let (nx, ny) = self.lat.size();
        let [velocity, pressure, density, solid, temperature] = self.node_arrays();
        let origin = self.si([0.5, 0.5]);
        let mut arrays = vec![
            DataArray::new("velocity", 3, &velocity[..]),
            DataArray::new("pressure", 1, &pressure[..]),
            DataArray::new("density", 1, &density[..]),
            DataArray::new("solid", 1, &solid[..]),
        ];
        if self.thermal.is_some() {
            arrays.push(DataArray::new("temperature", 1, &temperature[..]));
        }
        let image = ImageData {
            size: [nx, ny, 1],
            origin: [origin[0], origin[1], 0.0],
            spacing: [self.units.dx; 3],
            field_data: &[],
            point_data: Attributes::new(&arrays),
            cell_data: Attributes::default(),
        };
        let path = dir.join(&name);
        let bytes = image
            .to_bytes(Encoding::Appended)
            .map_err(|e| OutputError {
                path: path.clone(),
                source: std::io::Error::other(e.to_string()),
            })?;
        write_atomic(&path, &bytes)?;
        Ok(name)
    }

    fn snapshot(&self, _mesh: bool) -> Option<crate::common::snapshot::Snapshot> {
        use crate::common::snapshot::{Array, Lattice, Snapshot};
        let (nx, ny) = self.lat.size();
        let [velocity, pressure, density, solid, temperature] = self.node_arrays();
        let vx = velocity.iter().step_by(3).copied().collect();
        let vy = velocity.iter().skip(1).step_by(3).copied().collect();
        let mut fields = vec![
            Array::new("vx", 1, vx),
            Array::new("vy", 1, vy),
            Array::new("pressure", 1, pressure),
            Array::new("density", 1, density),
            Array::new("solid", 1, solid),
        ];
        if self.thermal.is_some() {
            fields.push(Array::new("temperature", 1, temperature));
        }
        Some(Snapshot {
            lattice: Some(Lattice {
                nx,
                ny,
                origin: self.si([0.5, 0.5]),
                spacing: self.units.dx,
                fields,
            }),
            ..Snapshot::default()
        })
    }

    fn field_extrema(&self) -> BTreeMap<String, [f64; 2]> {
        let (nx, ny) = self.lat.size();
        let names = ["vx", "vy", "pressure", "density", "speed"];
        let mut ext = [[f64::INFINITY, f64::NEG_INFINITY]; 5];
        for j in 0..ny {
            for i in 0..nx {
                if self.lat.is_solid(i, j) {
                    continue;
                }
                let (rho, u) = self.lat.moments(i, j);
                let vx = self.units.velocity_si(u[0]);
                let vy = self.units.velocity_si(u[1]);
                let v = [
                    vx,
                    vy,
                    self.units.pressure_si(rho),
                    rho * self.units.density,
                    (vx * vx + vy * vy).sqrt(),
                ];
                for (e, x) in ext.iter_mut().zip(v) {
                    e[0] = e[0].min(x);
                    e[1] = e[1].max(x);
                }
            }
        }
        let mut out: BTreeMap<String, [f64; 2]> = names
            .iter()
            .zip(ext)
            .filter(|(_, e)| e[0] <= e[1])
            .map(|(n, e)| (n.to_string(), e))
            .collect();
        if let Some(th) = &self.thermal {
            let mut e = [f64::INFINITY, f64::NEG_INFINITY];
            for j in 0..ny {
                for i in 0..nx {
                    let t = th.temperature(i, j);
                    e = [e[0].min(t), e[1].max(t)];
                }
            }
            out.insert("temperature".into(), e);
        }
        out
    }

    fn plots(&self, dir: &Path, written: &[f64], series: &[Vec<f64>]) -> Result<(), RunError> {
        self.field_images(dir)?;
        self.probe_plots(dir, written, series)
    }

    fn work(&self) -> crate::common::limits::Work {
        let (nx, ny) = self.lat.size();
        let end = self.times.last().copied().unwrap_or(0.0);
        crate::common::limits::Work {
            units: (nx * ny) as f64 * (end / self.units.dt).round(),
            seconds_per_unit: crate::common::limits::LBM_SECONDS_PER_NODE_STEP,
            unit: "node steps",
            factor: 3.0,
        }
    }

    fn peak_bytes(&self) -> f64 {
        let (nx, ny) = self.lat.size();
        crate::common::limits::lbm_bytes((nx * ny) as f64, self.thermal.is_some())
    }

    fn sizes(&self) -> Sizes {
        let (nx, ny) = self.lat.size();
        Sizes {
            counts: vec![
                ("lattice nodes", nx * ny),
                ("fluid nodes", self.lat.fluid_nodes()),
            ],
            ..Sizes::default()
        }
    }

    fn unit(&self, field: &str) -> &'static str {
        check::unit(field)
    }

    fn failed(&self) -> usize {
        0
    }

    fn solver_stats(&self) -> SolverStats {
        SolverStats {
            linear: "lbm-d2q9".into(),
            iterations: self.lat.steps() as usize,
            ..SolverStats::default()
        }
    }

    fn errors(&self) -> Result<BTreeMap<String, f64>, RunError> {
        Ok(BTreeMap::new())
    }

    fn wall_seconds(&self) -> WallSeconds {
        WallSeconds {
            stepping: self.stepping_seconds,
            ..WallSeconds::default()
        }
    }
}

/// The model `lbm` in the registry ([`crate::MODELS`]).
pub struct LbmKind;

/// The registry's value of the model.
pub static KIND: LbmKind = LbmKind;

impl ModelKind for LbmKind {
    fn name(&self) -> &'static str {
        "lbm"
    }
    fn sections(&self) -> &'static [&'static str] {
        &["lbm", "obstacle", "thermal", "grains"]
    }
    fn reads(&self) -> &'static [&'static str] {
        // Refused by `refuse` when they hold a key of the continuum model.
        &["material", "physics"]
    }
    fn refused_as(&self, section: &str) -> Vec<KeyPart> {
        if section == "obstacle" {
            ki("obstacle", 0, &[])
        } else {
            k(&[section])
        }
    }
    fn refuse(&self, ls: &LoadedScene) -> Result<(), SceneError> {
        check::refuse_continuum(ls)
    }
    fn sections_of(
        &self,
        doc: toml::Spanned<toml::de::DeTable<'_>>,
    ) -> Result<std::sync::Arc<dyn OwnSections>, toml::de::Error> {
        own_sections::<LbmSections>(doc)
    }
    fn own_schema(&self) -> Option<schemars::Schema> {
        Some(schemars::schema_for!(LbmSections))
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
        build_for(ls, purpose, observer)
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
        let _ = laws;
        distributed::run(ls, out, world, observer)
    }
}

/// The sections of model `lbm` read by the model itself (`[lbm]` and `[thermal]` are
/// shared with model `lsm`).
#[derive(Clone, Debug, Default, serde::Deserialize, schemars::JsonSchema)]
pub struct LbmSections {
    /// `[[obstacle]]`.
    #[serde(default)]
    pub obstacle: Vec<crate::common::lattice::sections::ObstacleSection>,
    /// `[grains]`: The lattice's solid map from an image of the rock.
    pub grains: Option<grains::GrainsSection>,
}

/// The axes `[lbm] periodic` names.
pub(crate) fn periodic_axes(l: &crate::common::lattice::sections::LbmSection) -> [bool; 2] {
    let mut p = [false; 2];
    for a in &l.periodic {
        p[match a {
            crate::common::lattice::sections::AxisChoice::X => 0,
            crate::common::lattice::sections::AxisChoice::Y => 1,
        }] = true;
    }
    p
}

/// The model's own sections of a checked scene.
pub(crate) fn own(ls: &LoadedScene) -> &LbmSections {
    ls.own::<LbmSections>()
}
