//! Fluid and heat in a lattice solid scene (Mora et al. (2015), §3 and Fig. 9): with
//! `[lbm]` the disks are carried by a lattice Boltzmann fluid
//! ([`porofrac_particle_fluid`]); `[thermal]` adds temperature (conjugate: the disks' nodes
//! carry `solid_diffusivity`), `[injection]` a ramped mass source at the borehole.
//!
//! - *build*: the lattice of `[lbm]` (as the `lbm` model builds it), one moving obstacle per
//!   disk; a disk of radius below two spacings is an error naming `lbm.spacing`;
//! - *step*: one fluid step of `Δt` (from spacing, viscosity and tau) per coupled step, the
//!   lattice solid sub-cycled within it at its own step (`[lsm] dt` or `dt_fraction`);
//! - *outputs*: `summary.json` `fluid` (lattice, steps, sub-steps, Mach number, time split
//!   between fluid and particles), `injection` (pressure, injected mass) and `heat` (the
//!   books, J per metre of depth); `heat.csv`; `plots/fluid_speed.png`,
//!   `plots/fluid_pressure.png`, `plots/temperature.png`, `plots/particles_temperature.png`.

use std::path::Path;

use crate::common::lattice::images::{LatticeImage, field_png};

use serde::Deserialize;

use porofrac_lbm::Lattice;
use porofrac_lsm::LatticeSolid;
use porofrac_particle_fluid::{
    CouplingError, CouplingOptions, InjectionControl, LoadAveraging, ParticleFluid, ThermalSetup,
};

use crate::common::lattice::{LatticeParts, VelocityExpr};
use crate::common::loaded::{LoadedScene, SceneError, k};
use crate::common::model::RunError;
use crate::common::output::write_atomic;

/// Top-level sections of model `lbm` that a lattice solid scene may have (its fluid);
/// `[injection]` is the model's own.
pub const SECTIONS: [&str; 2] = ["lbm", "thermal"];

/// `[injection]`: a mass source on the lattice nodes of a disk, ramped.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InjectionSection {
    /// Centre of the source (m; default the `[particles]` hole).
    #[schemars(extend("unit" = "m"))]
    pub center: Option<[f64; 2]>,
    /// Radius of the source (m; default half the hole radius).
    #[schemars(extend("unit" = "m"))]
    pub radius: Option<f64>,
    /// Final target gauge pressure of the source nodes (Pa), or
    #[schemars(extend("unit" = "Pa"))]
    pub pressure: Option<f64>,
    /// final mass rate per metre of depth (kg/(m·s)).
    #[schemars(extend("unit" = "kg/(m·s)"))]
    pub rate: Option<f64>,
    /// Ramp from 0 to the final value (s).
    #[schemars(extend("unit" = "s"))]
    pub ramp_time: f64,
    /// Pressure control: fraction of the density gap closed per step (default 0.5).
    pub gain: Option<f64>,
    /// Carry the fluid in the cracks narrower than the lattice: every broken bond is a
    /// cubic-law channel of the disks' gap between the pores on its two sides, joined to
    /// the lattice nodes at its mouths; its pressure pushes the two disks apart (default
    /// false).
    pub crack_flow: Option<bool>,
    /// Smallest aperture of a crack channel (m; default 1e-5): a broken bond whose disks
    /// still touch is a channel this wide.
    #[schemars(extend("unit" = "m"))]
    pub crack_min_aperture: Option<f64>,
    /// Kinematic viscosity of the fluid in the crack channels (m²/s; default
    /// `lbm.viscosity`): the fluid's own where the lattice's is raised to carry rock
    /// pressures.
    #[schemars(extend("unit" = "m²/s"))]
    pub crack_viscosity: Option<f64>,
}

fn positive(
    ls: &LoadedScene,
    key: &[crate::common::sections::KeyPart],
    v: f64,
) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ls.error(key, format!("= {v} must be a positive number")))
    }
}

/// Check `[lbm]`, `[thermal]` and `[injection]` of a lattice solid scene.
pub fn check(ls: &LoadedScene) -> Result<(), SceneError> {
    let s = &ls.scene;
    let Some(_) = &s.lbm else {
        for (name, set) in [
            ("thermal", s.thermal.is_some()),
            ("injection", super::own(ls).injection.is_some()),
        ] {
            if set {
                return Err(ls.error(&k(&[name]), "needs [lbm]: the fluid that carries it"));
            }
        }
        if super::own(ls)
            .lsm
            .as_ref()
            .is_some_and(|l| l.seal_bonds.is_some())
        {
            return Err(ls.error(
                &k(&["lsm", "seal_bonds"]),
                "needs [lbm]: it sets what the fluid sees",
            ));
        }
        return Ok(());
    };
    if let Some(i) = s.output.probe.iter().position(|p| p.obstacle.is_some()) {
        return Err(ls.error(
            &crate::common::loaded::ki("output.probe", i, &["obstacle"]),
            "belongs to model \"lbm\", not \"lsm\"",
        ));
    }
    let (units, seen) = crate::common::lattice::check::check_section(ls)?;
    if let Some(t) = &s.thermal {
        crate::common::lattice::check::check_thermal(ls, &units, seen)?;
        if let Some(c) = t.heat_capacity {
            positive(ls, &k(&["thermal", "heat_capacity"]), c)?;
        }
        if t.books.is_some() {
            return Err(ls.error(
                &k(&["thermal", "books"]),
                "belongs to model \"lbm\" (the lattice solid model writes heat.csv)",
            ));
        }
        if let Some(v) = t.particle_temperature
            && !v.is_finite()
        {
            return Err(ls.error(
                &k(&["thermal", "particle_temperature"]),
                format!("= {v} is not a finite number"),
            ));
        }
    }
    if let Some(inj) = &super::own(ls).injection {
        let key = |f: &str| k(&["injection", f]);
        let hole = s.particles.as_ref().and_then(|p| p.hole);
        if inj.center.is_none() && hole.is_none() {
            return Err(ls.error(&key("center"), "is required without a [particles] hole"));
        }
        if let Some(c) = inj.center
            && !(c[0].is_finite() && c[1].is_finite())
        {
            return Err(ls.error(&key("center"), "must be two finite numbers"));
        }
        if let Some(r) = inj.radius {
            positive(ls, &key("radius"), r)?;
        } else if hole.is_none() {
            return Err(ls.error(&key("radius"), "is required without a [particles] hole"));
        }
        match (inj.pressure, inj.rate) {
            (Some(p), None) => {
                if !p.is_finite() {
                    return Err(ls.error(&key("pressure"), format!("= {p} is not finite")));
                }
                let rho = units.pressure_density(p);
                if !(rho > 0.5 && rho < 1.5) {
                    return Err(ls.error(
                        &key("pressure"),
                        format!(
                            "= {p} Pa is a lattice density of {rho:.3}: keep it within 1 ± 0.5 \
                             (raise the lattice pressure scale ρ c_s² (Δx/Δt)² = {:.4e} Pa: \
                             lower lbm.viscosity or lbm.tau)",
                            units.pressure_si(2.0)
                        ),
                    ));
                }
            }
            (None, Some(q)) => {
                if !q.is_finite() {
                    return Err(ls.error(&key("rate"), format!("= {q} is not finite")));
                }
                if inj.gain.is_some() {
                    return Err(ls.error(&key("gain"), "applies to pressure control only"));
                }
            }
            _ => {
                return Err(ls.error(&key("pressure"), "give exactly one of pressure and rate"));
            }
        }
        if !(inj.ramp_time.is_finite() && inj.ramp_time >= 0.0) {
            return Err(ls.error(
                &key("ramp_time"),
                format!("= {} must be a number ≥ 0", inj.ramp_time),
            ));
        }
        if let Some(g) = inj.gain
            && !(g > 0.0 && g <= 1.0)
        {
            return Err(ls.error(&key("gain"), format!("= {g} must be in (0, 1]")));
        }
        super::crack_flow::check(ls, inj)?;
        if super::own(ls)
            .loading
            .as_ref()
            .is_some_and(|l| l.pressure_rate.is_some())
        {
            return Err(ls.error(
                &k(&["loading", "pressure_rate"]),
                "and [injection] both load the borehole: keep one",
            ));
        }
    }
    Ok(())
}

/// The fluid of a running lattice solid scene.
pub struct Fluid {
    pf: ParticleFluid,
    sides: Vec<(porofrac_lbm::Side, VelocityExpr)>,
    time_dependent: bool,
    max_mach: f64,
    /// `time, particles, fluid, side inflow, out of the particles, carried, defect, mean
    /// particle temperature`.
    heat_rows: Vec<[f64; 8]>,
}

fn coupling_error(ls: &LoadedScene, e: CouplingError) -> RunError {
    match e {
        CouplingError::TooSmall { .. } => {
            ls.error(&k(&["lbm", "spacing"]), format!(": {e}")).into()
        }
        CouplingError::Outside { .. } => ls.error(&k(&["lbm", "extent"]), format!(": {e}")).into(),
        CouplingError::Particles(p) => RunError::Flow(format!("lsm: {p}")),
        e => RunError::Flow(format!("lsm–lbm: {e}")),
    }
}

impl Fluid {
    /// The fluid of a checked scene, if it has `[lbm]`; `dt` is the lattice solid's step.
    pub fn build(
        ls: &LoadedScene,
        solid: &LatticeSolid,
        dt: f64,
    ) -> Result<Option<Self>, RunError> {
        let s = &ls.scene;
        if s.lbm.is_none() {
            return Ok(None);
        }
        let LatticeParts {
            mut lat,
            units,
            origin,
            sides,
        } = crate::common::lattice::lattice_of(ls)?;
        crate::common::lattice::set_side_velocities(&mut lat, &sides, &units, origin, 0.0);
        let options = CouplingOptions {
            particle_dt_fraction: (dt / solid.stable_dt()).clamp(1e-9, 1.0),
            heat_capacity: s
                .thermal
                .as_ref()
                .and_then(|t| t.heat_capacity)
                .unwrap_or(CouplingOptions::default().heat_capacity),
            loads: LoadAveraging::TwoSteps,
            fluid_radius_factor: if super::own(ls).lsm.as_ref().and_then(|l| l.seal_bonds)
                == Some(true)
            {
                1.0 + super::own(ls)
                    .bonds
                    .as_ref()
                    .and_then(|b| b.tolerance)
                    .unwrap_or(0.05)
            } else {
                1.0
            },
            ..CouplingOptions::default()
        };
        let mut pf = ParticleFluid::new(solid, lat, units, origin, options)
            .map_err(|e| coupling_error(ls, e))?;
        if let Some(t) = &s.thermal {
            let init = crate::common::lattice::thermal_initial(t);
            let setup = ThermalSetup {
                diffusivity: t.diffusivity,
                solid_diffusivity: t.solid_diffusivity.unwrap_or(t.diffusivity),
                sides: crate::common::lattice::thermal_sides(t, &units),
            };
            let d = solid.disks();
            let temps: Vec<f64> = (0..d.len())
                .map(|i| {
                    t.particle_temperature
                        .unwrap_or_else(|| init.eval(&d.x[i], 0.0))
                })
                .collect();
            pf = pf
                .with_thermal(setup, |x| init.eval(&x, 0.0), &temps)
                .map_err(|e| coupling_error(ls, e))?;
        }
        if let Some(inj) = &super::own(ls).injection {
            let hole = s.particles.as_ref().and_then(|p| p.hole);
            let center = inj.center.or(hole.map(|h| h.center)).expect("checked");
            let radius = inj
                .radius
                .or(hole.map(|h| 0.5 * h.radius))
                .expect("checked");
            let control = match (inj.pressure, inj.rate) {
                (Some(p), _) => InjectionControl::Pressure {
                    peak: p,
                    ramp_time: inj.ramp_time,
                    gain: inj.gain.unwrap_or(0.5),
                },
                (None, q) => InjectionControl::Rate {
                    peak: q.unwrap_or(0.0),
                    ramp_time: inj.ramp_time,
                },
            };
            pf = pf
                .with_injection(center, radius, control)
                .map_err(|e| ls.error(&k(&["injection", "radius"]), format!(": {e}")))?;
            pf = super::crack_flow::attach(ls, inj, pf, solid)?;
        }
        let time_dependent = sides.iter().any(|(_, v)| v.varies_in_time());
        let mut f = Fluid {
            pf,
            sides,
            time_dependent,
            max_mach: 0.0,
            heat_rows: Vec::new(),
        };
        f.record(0.0);
        Ok(Some(f))
    }

    /// Advance the fluid and the particles to time `t`: `round(t/Δt)` fluid steps in all.
    /// Returns the particle sub-steps done.
    pub fn advance(
        &mut self,
        ls: &LoadedScene,
        solid: &mut LatticeSolid,
        t: f64,
        mut crack: Option<&mut super::crack::CrackLog>,
        stop: &crate::common::driver::Stop,
    ) -> Result<usize, RunError> {
        let dt = self.pf.dt();
        let target = (t / dt).round() as u64;
        let before = self.pf.stats().substeps;
        while self.pf.stats().steps < target {
            if stop.requested() {
                return Err(RunError::Interrupted);
            }
            if self.time_dependent {
                let (u, o) = (*self.pf.units(), self.pf.origin());
                let time = self.pf.time();
                // side velocities only: the lattice is the coupling's
                set_sides(&mut self.pf, &self.sides, &u, o, time);
            }
            self.pf.step(solid).map_err(|e| coupling_error(ls, e))?;
            if let Some(c) = crack.as_deref_mut() {
                let p = self.pressure();
                c.sync(solid, p)
                    .map_err(|e| super::check::lsm_error(ls, &e))?;
            }
        }
        let speed = self
            .pf
            .lattice()
            .max_speed()
            .map_err(|e| RunError::Flow(format!("lbm: {e}")))?;
        let mach = speed / (1.0f64 / 3.0).sqrt();
        self.max_mach = self.max_mach.max(mach);
        if mach > porofrac_lbm::MAX_MACH {
            return Err(RunError::Flow(format!(
                "lbm: Mach number {mach:.3} above {} at t = {t:e} s (lower the injection \
                 pressure or its ramp rate, or the particle speeds)",
                porofrac_lbm::MAX_MACH
            )));
        }
        self.record(t);
        Ok((self.pf.stats().substeps - before) as usize)
    }

    /// Add the row of `heat.csv` of output time `t` (the driver's time of the step, the
    /// same value as in `probes.csv` and the `.pvd` series).
    fn record(&mut self, t: f64) {
        if self.pf.thermal().is_none() {
            return;
        }
        let h = *self.pf.heat();
        let n = self.pf_count();
        let mean = if n == 0 {
            0.0
        } else {
            (0..n)
                .filter_map(|i| self.pf.particle_temperature(i))
                .sum::<f64>()
                / n as f64
        };
        self.heat_rows.push([
            t,
            h.particles,
            h.fluid,
            h.sides_in,
            h.from_particles,
            h.carried,
            h.defect(),
            mean,
        ]);
    }

    fn pf_count(&self) -> usize {
        self.pf.fluid_loads().len()
    }

    /// Nodes of the lattice.
    pub fn lattice_nodes(&self) -> usize {
        let (nx, ny) = self.pf.lattice().size();
        nx * ny
    }

    /// Lattice steps of a run to `end` (s), for the run-time estimate of a check.
    pub fn lattice_steps(&self, end: f64) -> f64 {
        (end / self.pf.dt()).round()
    }

    /// Whether fluid is injected (an `[injection]` source).
    pub fn injects(&self) -> bool {
        self.pf.injection().is_some()
    }

    /// Gauge pressure at the injection (Pa), 0 without one.
    pub fn pressure(&self) -> f64 {
        self.pf
            .injection()
            .map_or(0.0, |i| i.pressure(self.pf.lattice(), self.pf.units()))
    }

    /// The fields of [`super::check::FLUID_FIELDS`] at SI point `x`: gauge pressure (Pa)
    /// and speed (m/s), bilinear between the four nodes around `x`, over the fluid ones
    /// only (weights renormalised); NaN when all four are covered by particles.
    pub fn point_values(&self, x: [f64; 2]) -> [f64; 2] {
        let (lat, u, o) = (self.pf.lattice(), self.pf.units(), self.pf.origin());
        let (nx, ny) = lat.size();
        let g = |a: usize, n: usize| ((x[a] - o[a]) / u.dx - 0.5).clamp(0.0, (n - 1) as f64);
        let (gx, gy) = (g(0, nx), g(1, ny));
        let (i0, j0) = (
            (gx.floor() as usize).min(nx - 2),
            (gy.floor() as usize).min(ny - 2),
        );
        let (fx, fy) = (gx - i0 as f64, gy - j0 as f64);
        let (mut rho, mut v, mut sum) = (0.0, [0.0; 2], 0.0);
        for (di, dj, w) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            if lat.is_solid(i0 + di, j0 + dj) {
                continue;
            }
            let (r, m) = lat.moments(i0 + di, j0 + dj);
            rho += w * r;
            v[0] += w * m[0];
            v[1] += w * m[1];
            sum += w;
        }
        if sum <= 0.0 {
            return [f64::NAN; 2];
        }
        [
            u.pressure_si(rho / sum),
            u.velocity_si(v[0].hypot(v[1]) / sum),
        ]
    }

    /// `summary.json` keys.
    pub fn summary(&self, m: &mut serde_json::Map<String, serde_json::Value>) {
        let u = self.pf.units();
        let lat = self.pf.lattice();
        let (nx, ny) = lat.size();
        let st = self.pf.stats();
        m.insert(
            "fluid".into(),
            serde_json::json!({
                "spacing": u.dx,
                "time_step": u.dt,
                "tau": u.tau,
                "nodes": [nx, ny],
                "fluid_nodes": lat.fluid_nodes(),
                "cut_links": lat.cut_links(),
                "fluid_steps": st.steps,
                "particle_substeps": st.substeps,
                "mach": self.max_mach,
                "pressure_unit": u.pressure_si(2.0),
                "fluid_seconds": st.fluid_seconds,
                "particle_seconds": st.particle_seconds,
                "particle_share": st.particle_seconds
                    / (st.fluid_seconds + st.particle_seconds).max(1e-300),
                "fluid_share": st.fluid_seconds
                    / (st.fluid_seconds + st.particle_seconds).max(1e-300),
                "visited_nodes": lat.visited_nodes(),
                "mlups_fluid_nodes": lat.fluid_nodes() as f64 * st.steps as f64
                    / st.fluid_seconds.max(1e-300) / 1e6,
                "mlups_all_nodes": (nx * ny) as f64 * st.steps as f64
                    / st.fluid_seconds.max(1e-300) / 1e6,
            }),
        );
        super::crack_flow::summary(&self.pf, m);
        if let Some(inj) = self.pf.injection() {
            m.insert(
                "injection".into(),
                serde_json::json!({
                    "pressure": self.pressure(),
                    "target_pressure": inj.target_pressure(self.pf.time()),
                    "injected_mass": (lat.injected_mass()
                        - self.pf.crack_flow().map_or(0.0, |c| c.exchanged_mass()))
                        * u.density * u.dx * u.dx,
                    "source_nodes": inj.nodes(),
                }),
            );
        }
        if self.pf.thermal().is_some() {
            let h = self.pf.heat();
            m.insert(
                "heat".into(),
                serde_json::json!({
                    "particles": h.particles,
                    "fluid": h.fluid,
                    "initial": h.initial,
                    "particles_initial": h.particles_initial,
                    "side_inflow": h.sides_in,
                    "extracted_from_particles": h.from_particles,
                    "carried_by_moving_particles": h.carried,
                    "defect": h.defect(),
                    "relative_defect": h.defect() / h.initial.abs().max(1e-300),
                    "particle_defect": h.particle_defect(),
                }),
            );
        }
    }

    /// Write `heat.csv` (with a temperature lattice).
    pub fn write_csv(&self, out: &Path) -> Result<(), RunError> {
        if self.heat_rows.is_empty() {
            return Ok(());
        }
        let mut text = String::from(
            "time [s],particle_heat [J/m],fluid_heat [J/m],side_inflow [J/m],\
             extracted_from_particles [J/m],carried [J/m],defect [J/m],\
             mean_particle_temperature [°C]\n",
        );
        for r in &self.heat_rows {
            let row: Vec<String> = r.iter().map(|v| format!("{v:e}")).collect();
            text.push_str(&row.join(","));
            text.push('\n');
        }
        write_atomic(&out.join("heat.csv"), text.as_bytes())?;
        Ok(())
    }

    /// Images of the fluid speed and pressure, of the temperature and of the disks coloured
    /// by temperature.
    pub fn plots(
        &self,
        dir: &Path,
        solid: &LatticeSolid,
        name: &str,
        t: f64,
    ) -> Result<(), RunError> {
        let lat = self.pf.lattice();
        let u = self.pf.units();
        let (nx, ny) = lat.size();
        let mut speed = Vec::with_capacity(nx * ny);
        let mut pressure = Vec::with_capacity(nx * ny);
        let mut solid_mask = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let (rho, v) = lat.moments(i, j);
                speed.push(u.velocity_si((v[0] * v[0] + v[1] * v[1]).sqrt()));
                pressure.push(u.pressure_si(rho));
                solid_mask.push(lat.is_solid(i, j));
            }
        }
        let stamp = format!("t = {} s", crate::common::plots::tick(t));
        let base = LatticeImage {
            title: "",
            bar: "",
            unit: "",
            origin: self.pf.origin(),
            dx: u.dx,
            symmetric: false,
        };
        let title = format!("{name}: fluid speed at {stamp}");
        field_png(
            &dir.join("fluid_speed.png"),
            [nx, ny],
            &speed,
            &solid_mask,
            &LatticeImage {
                title: &title,
                bar: "speed [m/s]",
                unit: "m/s",
                ..base
            },
        )?;
        let title = format!("{name}: fluid pressure (gauge) at {stamp}");
        field_png(
            &dir.join("fluid_pressure.png"),
            [nx, ny],
            &pressure,
            &solid_mask,
            &LatticeImage {
                title: &title,
                bar: "pressure [Pa]",
                unit: "Pa",
                ..base
            },
        )?;
        if let Some(th) = self.pf.thermal() {
            let temps_fluid: Vec<f64> = (0..ny)
                .flat_map(|j| (0..nx).map(move |i| (i, j)))
                .map(|(i, j)| th.temperature(i, j))
                .collect();
            let none = vec![false; nx * ny];
            let title = format!("{name}: temperature at {stamp}");
            field_png(
                &dir.join("temperature.png"),
                [nx, ny],
                &temps_fluid,
                &none,
                &LatticeImage {
                    title: &title,
                    bar: "temperature [°C]",
                    unit: "°C",
                    ..base
                },
            )?;
            let d = solid.disks();
            let temps: Vec<f64> = (0..d.len())
                .map(|i| self.pf.particle_temperature(i).unwrap_or(f64::NAN))
                .collect();
            let title = format!("{name}: disk temperature at {stamp}");
            crate::common::particle_output::draw_disks(
                &dir.join("particles_temperature.png"),
                d,
                &crate::common::particle_output::DiskPicture {
                    title: &title,
                    values: &temps,
                    bar: "temperature [°C]",
                    unit: "°C",
                    segments: &[],
                },
            )?;
        }
        Ok(())
    }
}

fn set_sides(
    pf: &mut ParticleFluid,
    sides: &[(porofrac_lbm::Side, VelocityExpr)],
    u: &porofrac_lbm::Units,
    o: [f64; 2],
    t: f64,
) {
    let lat: &mut Lattice = pf.lattice_mut();
    crate::common::lattice::set_side_velocities(lat, sides, u, o, t);
}
