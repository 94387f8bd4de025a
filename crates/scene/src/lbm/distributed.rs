//! The lattice Boltzmann model on MPI ranks (`mpirun -n P porofrac run`, the `mpi`
//! feature): the lattice cut into slabs of columns ([`porofrac_lbm::slab`]), each rank
//! stepping its window of the box and exchanging columns after every lattice step, so
//! that the numbers are those of the serial run, bit for bit.
//!
//! Every rank runs the loop of [`crate::common::driver`]; rank 0 writes the shared files
//! (`probes.csv`, `lines/`, `summary.json`, the `.pvd` and the `.pvti` of every written
//! step), every rank writes its piece of each written step (`vtk/step_NNNN_pR.vti`: the
//! columns it owns and the first of the next slab, so the pieces meet). After each output
//! step the ranks agree on what the loop reads: the probe and line values (each from
//! the rank owning the cell of its point), the obstacle forces (from the rank holding the
//! obstacle whole), the extrema of the fields (minimum and maximum over the ranks: exact),
//! and whether to stop (Ctrl-C is seen between output steps, on every rank at once).
//!
//! Refused, by key: moving obstacles, slabs along a periodic x axis, checkpoints.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use porofrac_lbm::slab::{Exchange, Plan};
use porofrac_vtk::{Attributes, DataArray, Encoding, ImageData, ImagePiece, PImageData};

use super::{FieldName, LbmModel, ProbeKind, build, own, shape_of};
use crate::common::distributed::{agree, any};
use crate::common::driver::{Observer, SetupPoll, Stop};
use crate::common::lattice::nodes;
use crate::common::lattice::sections::AxisChoice;
use crate::common::loaded::{LoadedScene, k, ki};
use crate::common::model::{Model, RunError, Sizes, StepStats};
use crate::common::output::{OutputError, SolverStats, Summary, WallSeconds};

/// Refuse what the distributed path does not do, by key (the same answer on every rank).
fn refuse(ls: &LoadedScene) -> Result<(), RunError> {
    let why = "has no distributed path yet: run the scene without mpirun (or with -n 1)";
    for (i, o) in own(ls).obstacle.iter().enumerate() {
        if o.velocity.is_some() {
            return Err(ls
                .error(
                    &ki("obstacle", i, &["velocity"]),
                    format!("is given: a moving obstacle {why}"),
                )
                .into());
        }
        if o.angular_velocity.is_some() {
            return Err(ls
                .error(
                    &ki("obstacle", i, &["angular_velocity"]),
                    format!("is given: a turning obstacle {why}"),
                )
                .into());
        }
    }
    let l = ls.scene.lbm.as_ref().expect("checked");
    if l.periodic.iter().any(|a| matches!(a, AxisChoice::X)) {
        return Err(ls
            .error(
                &k(&["lbm", "periodic"]),
                format!(
                    "includes \"x\": a lattice periodic along x {why} (the slabs are cut \
                     along x; a lattice periodic along y only is distributed)"
                ),
            )
            .into());
    }
    if ls.scene.output.checkpoint_every > 0 {
        return Err(ls
            .error(
                &k(&["output", "checkpoint_every"]),
                format!(
                    "= {}: checkpoints of a distributed run {why}",
                    ls.scene.output.checkpoint_every
                ),
            )
            .into());
    }
    Ok(())
}

/// Run a checked lattice Boltzmann scene on the ranks of `world` (see the module docs).
pub(crate) fn run(
    ls: &LoadedScene,
    out: &Path,
    world: &SimpleCommunicator,
    observer: &mut dyn Observer,
) -> Result<Summary, RunError> {
    let start = Instant::now();
    refuse(ls)?;
    let l = ls.scene.lbm.as_ref().expect("checked");
    let (nx, _) = nodes(l);
    let ranks = world.size() as usize;
    // The obstacles' shapes decide the windows; the units are those of the build.
    let units = porofrac_lbm::Units::from_viscosity(l.spacing, l.viscosity, l.density, l.tau)
        .map_err(|e| ls.error(&k(&["lbm", "tau"]), e))?;
    let origin = [l.extent[0][0], l.extent[0][1]];
    let shapes: Vec<_> = own(ls)
        .obstacle
        .iter()
        .map(|o| shape_of(o, &units, origin))
        .collect();
    let plan = Plan::new(nx as usize, ranks, &shapes).map_err(|_| {
        ls.error(
            &k(&["lbm", "spacing"]),
            format!(
                "= {}: {nx} columns of nodes cannot be cut into {ranks} slabs of at least 2 \
                 columns: run on fewer ranks",
                l.spacing
            ),
        )
    })?;
    let ex = Exchange::new(world, plan);
    // A stop request counts between output steps, on every rank at once.
    let raw_stop = observer.stop_handle();
    let agreed = Arc::new(AtomicBool::new(false));
    let built = {
        let mut setup = SetupPoll::new(observer);
        build(ls, &mut setup, Some(ex.slab().window))
    };
    let mut inner = agree(world, built)?;
    inner.stop = Stop::never();
    let ex = &ex;
    inner.halo = Some(Box::new(move |lat, th| {
        ex.lattice(lat);
        if let Some(th) = th {
            ex.thermal(th);
        }
    }));
    let root = world.rank() == 0;
    let mut model = Distributed {
        inner,
        ex,
        world,
        root,
        out: out.to_path_buf(),
        raw_stop,
        agreed: Arc::clone(&agreed),
        forces: Vec::new(),
        probes: Vec::new(),
        lines: Vec::new(),
        extrema: BTreeMap::new(),
        written: 0,
        fluid_nodes: 0,
        agreed_error: false,
    };
    model.fluid_nodes = model.owned_fluid_nodes();
    let mut shared = Agreed {
        inner: observer,
        agreed,
    };
    let build_seconds = start.elapsed().as_secs_f64();
    let result = crate::common::driver::drive(
        ls,
        &mut model,
        root.then_some(out),
        &mut shared,
        start,
        build_seconds,
        2,
    );
    match result {
        // An error of rank 0 alone (its files; the others write none) while the others
        // step on: they wait on rank 0 in the middle of a step, so the run ends on every
        // rank here, with a non-zero exit status.
        Err(e) if root && !model.agreed_error => {
            let text = e.to_string();
            crate::common::output::write_failed_summary(ls, out, &text, start);
            eprintln!("error: {text}");
            world.abort(1)
        }
        r => agree(world, r),
    }
}

/// The observer of the loop: its stop request is the one the ranks agreed on.
struct Agreed<'o> {
    inner: &'o mut dyn Observer,
    agreed: Arc<AtomicBool>,
}

impl Observer for Agreed<'_> {
    fn step(&mut self, report: &crate::common::driver::StepReport) {
        self.inner.step(report);
    }
    fn setup(&mut self, report: &crate::common::driver::SetupReport<'_>) {
        self.inner.setup(report);
    }
    fn stop_requested(&self) -> bool {
        self.agreed.load(Ordering::Relaxed)
    }
    fn stop_handle(&self) -> Stop {
        Stop::from_flag(Arc::clone(&self.agreed))
    }
}

/// One rank's model: its window of the lattice and what the ranks agreed on at the last
/// output step.
struct Distributed<'a> {
    inner: LbmModel<'a>,
    ex: &'a Exchange<'a>,
    world: &'a SimpleCommunicator,
    root: bool,
    out: PathBuf,
    raw_stop: Stop,
    agreed: Arc<AtomicBool>,
    forces: Vec<[f64; 3]>,
    probes: Vec<f64>,
    lines: Vec<Vec<Vec<f64>>>,
    extrema: BTreeMap<String, [f64; 2]>,
    /// VTK steps written so far (the index of the next).
    written: usize,
    /// Fluid nodes of the box.
    fluid_nodes: usize,
    /// Whether a step ended with an error every rank returned.
    agreed_error: bool,
}

impl Distributed<'_> {
    fn owned(&self) -> [usize; 2] {
        self.ex.slab().owned
    }

    /// Whether the cell of SI point `x` is this rank's.
    fn owns(&self, x: [f64; 2]) -> bool {
        let i0 = self.inner.box_cell_of(x).0[0];
        let o = self.owned();
        (o[0]..o[1]).contains(&i0)
    }

    /// Fluid nodes of the box (a sum of counts: exact).
    fn owned_fluid_nodes(&self) -> usize {
        let (o, w0, ny) = (
            self.owned(),
            self.ex.slab().window[0],
            self.inner.lat.size().1,
        );
        let mine = (o[0]..o[1])
            .flat_map(|c| (0..ny).map(move |j| (c - w0, j)))
            .filter(|&(i, j)| !self.inner.lat.is_solid(i, j))
            .count() as u64;
        let mut all = 0u64;
        self.world
            .all_reduce_into(&mine, &mut all, SystemOperation::sum());
        all as usize
    }

    /// Probe values, from the rank owning each point's cell (obstacle probes from the
    /// agreed forces); on rank 0, in scene order.
    fn gather_probes(&mut self) {
        let mut mine = Vec::new();
        let mut owner = Vec::new();
        for p in &self.inner.probes {
            match *p {
                ProbeKind::Field(f, x) => {
                    owner.push(Some(x));
                    if self.owns(x) {
                        mine.push(self.inner.value_at(f, x));
                    }
                }
                ProbeKind::Obstacle(..) => owner.push(None),
            }
        }
        let theirs = self.collect(mine);
        if !self.root {
            return;
        }
        let mut from: Vec<std::vec::IntoIter<f64>> =
            theirs.into_iter().map(|v| v.into_iter()).collect();
        self.probes.clear();
        for (p, at) in self.inner.probes.iter().zip(owner) {
            self.probes.push(match (p, at) {
                (&ProbeKind::Obstacle(o, c), _) => {
                    let f = self.forces[o];
                    if c == 2 {
                        self.inner.units.torque_si(f[2])
                    } else {
                        self.inner.units.force_si(f[c])
                    }
                }
                (ProbeKind::Field(..), Some(x)) => {
                    let r = self.rank_of(x);
                    from[r].next().expect("the owner sent it")
                }
                (ProbeKind::Field(..), None) => unreachable!("field probes have a point"),
            });
        }
    }

    /// The rank owning the cell of SI point `x`.
    fn rank_of(&self, x: [f64; 2]) -> usize {
        let i0 = self.inner.box_cell_of(x).0[0];
        self.ex
            .plan()
            .slabs
            .iter()
            .position(|s| (s.owned[0]..s.owned[1]).contains(&i0))
            .expect("the slabs tile the box")
    }

    /// Every rank's `mine`, on rank 0 in rank order (empty elsewhere). Collective.
    fn collect(&self, mine: Vec<f64>) -> Vec<Vec<f64>> {
        if !self.root {
            self.world.process_at_rank(0).send(&mine[..]);
            return Vec::new();
        }
        let mut all = vec![mine];
        for r in 1..self.world.size() {
            all.push(self.world.process_at_rank(r).receive_vec::<f64>().0);
        }
        all
    }

    /// The rows of every line, each point from the rank owning its cell; on rank 0.
    fn gather_lines(&mut self) {
        let lines = &self.inner.ls.scene.output.line;
        let mut mine = Vec::new();
        let mut rows_all = Vec::new();
        for (n, l) in lines.iter().enumerate() {
            let mut rows = Vec::new();
            // the points and their values where this rank owns them (NaN elsewhere)
            let f = FieldName::parse(&l.field);
            let np = l.points.max(2) as usize;
            let len = ((l.to[0] - l.from[0]).powi(2) + (l.to[1] - l.from[1]).powi(2)).sqrt();
            for i in 0..np {
                let s = i as f64 / (np - 1) as f64;
                let x = [
                    l.from[0] + s * (l.to[0] - l.from[0]),
                    l.from[1] + s * (l.to[1] - l.from[1]),
                ];
                if self.owns(x) {
                    mine.push(self.inner.value_at(f, x));
                }
                rows.push(vec![s * len, x[0], x[1], f64::NAN]);
            }
            let _ = n;
            rows_all.push(rows);
        }
        let theirs = self.collect(mine);
        if !self.root {
            return;
        }
        let mut from: Vec<std::vec::IntoIter<f64>> =
            theirs.into_iter().map(|v| v.into_iter()).collect();
        for rows in &mut rows_all {
            for row in rows.iter_mut() {
                let r = self.rank_of([row[1], row[2]]);
                row[3] = from[r].next().expect("the owner sent it");
            }
        }
        self.lines = rows_all;
    }

    /// The extrema of the fields over the owned nodes, then over the ranks.
    fn reduce_extrema(&mut self) {
        let names = ["vx", "vy", "pressure", "density", "speed", "temperature"];
        let (o, w0, ny) = (
            self.owned(),
            self.ex.slab().window[0],
            self.inner.lat.size().1,
        );
        let (lat, u) = (&self.inner.lat, self.inner.units);
        let mut lo = [f64::INFINITY; 6];
        let mut hi = [f64::NEG_INFINITY; 6];
        for c in o[0]..o[1] {
            let i = c - w0;
            for j in 0..ny {
                if let Some(th) = &self.inner.thermal {
                    let t = th.temperature(i, j);
                    lo[5] = lo[5].min(t);
                    hi[5] = hi[5].max(t);
                }
                if lat.is_solid(i, j) {
                    continue;
                }
                let (rho, v) = lat.moments(i, j);
                let vx = u.velocity_si(v[0]);
                let vy = u.velocity_si(v[1]);
                let x = [
                    vx,
                    vy,
                    u.pressure_si(rho),
                    rho * u.density,
                    (vx * vx + vy * vy).sqrt(),
                ];
                for a in 0..5 {
                    lo[a] = lo[a].min(x[a]);
                    hi[a] = hi[a].max(x[a]);
                }
            }
        }
        let (mut glo, mut ghi) = ([0.0; 6], [0.0; 6]);
        self.world
            .all_reduce_into(&lo[..], &mut glo[..], SystemOperation::min());
        self.world
            .all_reduce_into(&hi[..], &mut ghi[..], SystemOperation::max());
        self.extrema = names
            .iter()
            .enumerate()
            .filter(|&(a, _)| a < 5 || self.inner.thermal.is_some())
            .filter(|&(a, _)| glo[a] <= ghi[a])
            .map(|(a, n)| (n.to_string(), [glo[a], ghi[a]]))
            .collect();
    }

    /// This rank's piece of VTK step `index`: its columns and the first of the next slab.
    fn write_piece(&self, index: usize) -> Result<(), RunError> {
        let dir = self.out.join("vtk");
        std::fs::create_dir_all(&dir).map_err(|source| OutputError {
            path: dir.clone(),
            source,
        })?;
        let (cols, w0) = self.piece_columns(self.world.rank() as usize);
        let (lat, u) = (&self.inner.lat, self.inner.units);
        let ny = lat.size().1;
        let mut velocity = Vec::new();
        let (mut pressure, mut density, mut solid, mut temperature) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for j in 0..ny {
            for c in cols[0]..cols[1] {
                let i = c - w0;
                let (rho, v) = lat.moments(i, j);
                velocity.extend([u.velocity_si(v[0]), u.velocity_si(v[1]), 0.0]);
                pressure.push(u.pressure_si(rho));
                density.push(rho * u.density);
                solid.push(if lat.is_solid(i, j) { 1.0 } else { 0.0 });
                if let Some(th) = &self.inner.thermal {
                    temperature.push(th.temperature(i, j));
                }
            }
        }
        let arrays = node_arrays(&velocity, &pressure, &density, &solid, &temperature);
        let origin = self.inner.si([0.5, 0.5]);
        let piece = ImagePiece {
            image: ImageData {
                size: [cols[1] - cols[0], ny, 1],
                origin: [origin[0], origin[1], 0.0],
                spacing: [u.dx; 3],
                field_data: &[],
                point_data: Attributes::new(&arrays),
                cell_data: Attributes::default(),
            },
            offset: [cols[0], 0, 0],
            whole: [lat.box_size().0, ny, 1],
        };
        let path = dir.join(piece_name(index, self.world.rank() as usize));
        piece.write(&path, Encoding::Appended).map_err(|e| {
            RunError::from(OutputError {
                path,
                source: std::io::Error::other(e.to_string()),
            })
        })
    }

    /// Columns of the piece of rank `r` (its own and the first of the next slab) and the
    /// first column of this rank's window.
    fn piece_columns(&self, r: usize) -> ([usize; 2], usize) {
        let o = self.ex.plan().slabs[r].owned;
        let nx = self.ex.plan().nx;
        ([o[0], (o[1] + 1).min(nx)], self.ex.slab().window[0])
    }
}

/// The point arrays of a piece (and their names and components for the `.pvti`).
fn node_arrays<'v>(
    velocity: &'v [f64],
    pressure: &'v [f64],
    density: &'v [f64],
    solid: &'v [f64],
    temperature: &'v [f64],
) -> Vec<DataArray<'v>> {
    let mut arrays = vec![
        DataArray::new("velocity", 3, velocity),
        DataArray::new("pressure", 1, pressure),
        DataArray::new("density", 1, density),
        DataArray::new("solid", 1, solid),
    ];
    if !temperature.is_empty() {
        arrays.push(DataArray::new("temperature", 1, temperature));
    }
    arrays
}

fn piece_name(index: usize, rank: usize) -> String {
    format!("step_{index:04}_p{rank}.vti")
}

impl Model for Distributed<'_> {
    fn times(&self) -> &[f64] {
        self.inner.times()
    }

    fn step(&mut self, step: usize) -> Result<StepStats, RunError> {
        let stats = self.inner.step(step);
        let stats = agree(self.world, stats).inspect_err(|_| self.agreed_error = true)?;
        let times = self.inner.times.len();
        let last = step + 1 == times;
        let stop = !last && any(self.world, self.raw_stop.requested());
        self.agreed.store(stop, Ordering::Relaxed);
        // what the loop reads of this step (its rule: crate::common::driver::drive)
        let o = &self.inner.ls.scene.output;
        let write_every = o.every.max(1) as usize;
        let probe_every = o.probe_every.max(1) as usize;
        let regular = step == 0 || step.is_multiple_of(write_every) || last;
        let write = regular || stop;
        let sampled = write || step.is_multiple_of(probe_every);
        self.forces = self.ex.forces(&self.inner.lat);
        if sampled {
            self.gather_probes();
        }
        if write {
            self.gather_lines();
            self.reduce_extrema();
            if o.vtk {
                let r = self.write_piece(self.written);
                agree(self.world, r).inspect_err(|_| self.agreed_error = true)?;
                self.written += 1;
            }
        }
        Ok(stats)
    }

    fn probes(&self, values: &mut Vec<f64>) {
        if self.root {
            values.extend_from_slice(&self.probes);
        } else {
            values.extend(std::iter::repeat_n(0.0, self.inner.probes.len()));
        }
    }

    fn line(&self, line: usize, rows: &mut Vec<Vec<f64>>) {
        if self.root {
            rows.extend(self.lines[line].iter().cloned());
        }
    }

    fn after_step(&mut self, out: &Path) -> Result<(), RunError> {
        self.inner.after_step(out)
    }

    fn write_vtk(&self, dir: &Path, index: usize) -> Result<String, RunError> {
        let name = format!("step_{index:04}.pvti");
        let ny = self.inner.lat.size().1;
        let nx = self.ex.plan().nx;
        let none: [f64; 0] = [];
        let t: &[f64] = if self.inner.thermal.is_some() {
            &[0.0]
        } else {
            &none
        };
        let arrays = node_arrays(&none, &none, &none, &none, t);
        let origin = self.inner.si([0.5, 0.5]);
        let pvti = PImageData {
            whole: [nx, ny, 1],
            origin: [origin[0], origin[1], 0.0],
            spacing: [self.inner.units.dx; 3],
            point_data: &arrays,
            pieces: (0..self.ex.plan().slabs.len())
                .map(|r| {
                    let c = self.piece_columns(r).0;
                    ([c[0], 0, 0], [c[1] - c[0], ny, 1], piece_name(index, r))
                })
                .collect(),
        };
        let path = dir.join(&name);
        pvti.write(&path).map_err(|e| {
            RunError::from(OutputError {
                path,
                source: std::io::Error::other(e.to_string()),
            })
        })?;
        Ok(name)
    }

    fn field_extrema(&self) -> BTreeMap<String, [f64; 2]> {
        self.extrema.clone()
    }

    fn plots(&self, dir: &Path, written: &[f64], series: &[Vec<f64>]) -> Result<(), RunError> {
        // the field images need the whole lattice on one rank: the probe plots only
        self.inner.probe_plots(dir, written, series)
    }

    fn sizes(&self) -> Sizes {
        let (nx, ny) = self.inner.lat.box_size();
        Sizes {
            counts: vec![
                ("lattice nodes", nx * ny),
                ("fluid nodes", self.fluid_nodes),
                ("ranks", self.world.size() as usize),
            ],
            ..Sizes::default()
        }
    }

    fn failed(&self) -> usize {
        0
    }

    fn unit(&self, field: &str) -> &'static str {
        self.inner.unit(field)
    }

    fn solver_stats(&self) -> SolverStats {
        self.inner.solver_stats()
    }

    fn errors(&self) -> Result<BTreeMap<String, f64>, RunError> {
        Ok(BTreeMap::new())
    }

    fn wall_seconds(&self) -> WallSeconds {
        self.inner.wall_seconds()
    }

    fn summary_extras(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut json = self.inner.summary_extras();
        let (nx, ny) = self.inner.lat.box_size();
        if let Some(serde_json::Value::Object(l)) = json.get_mut("lattice") {
            l.insert("nodes".into(), serde_json::json!([nx, ny]));
            l.insert("fluid_nodes".into(), serde_json::json!(self.fluid_nodes));
            // every window is the whole lattice's numbers after its exchange: the largest
            // over the ranks is the serial run's
            let mut mach = 0.0;
            self.world
                .all_reduce_into(&self.inner.max_mach, &mut mach, SystemOperation::max());
            l.insert("mach".into(), serde_json::json!(mach));
        }
        // MLUPS of this rank's window (rank 0's), and the decomposition
        let slabs: Vec<_> = self
            .ex
            .plan()
            .slabs
            .iter()
            .map(|s| serde_json::json!({"owned": s.owned, "window": s.window}))
            .collect();
        json.insert(
            "mpi".into(),
            serde_json::json!({
                "ranks": self.world.size(),
                "slabs": slabs,
                "halo_bytes_per_step": self.ex.bytes_per_step(ny, self.inner.thermal.is_some()),
            }),
        );
        json
    }

    fn work(&self) -> crate::common::limits::Work {
        self.inner.work()
    }

    fn peak_bytes(&self) -> f64 {
        self.inner.peak_bytes()
    }
}
