//! The PyO3 extension of the `porofrac` Python package (`porofrac._porofrac`): scenes read,
//! changed and checked as the `porofrac` command does, runs that release the GIL while
//! they step and keep their results in memory, and results as numpy arrays that own the
//! buffers the run filled (no copy). The pure-Python package `python/porofrac/` re-exports
//! these names and adds the helpers that need optional packages (pandas, meshio, pyvista,
//! tqdm).

mod lower;

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use numpy::{PyArray1, PyArrayMethods};
use porofrac_scene::common::overrides::{Override, parts};
use porofrac_scene::common::sections::KeyPart;
use porofrac_scene::common::snapshot::{Array, Mesh, Snapshot};
use porofrac_scene::{LawRegistry, Observer, RunError as SceneRunError, StepReport, Stop};
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

create_exception!(
    _porofrac,
    SceneError,
    PyValueError,
    "A problem in a scene: the message the `porofrac` command prints, with the attributes \
     `key` (the dotted key, or None), `file` (the scene file) and `line` (1-based; 0 when \
     the error is not at a line of the file, e.g. in a `Scene.set`)."
);
create_exception!(
    _porofrac,
    RunError,
    PyRuntimeError,
    "A run that failed (the grid, the solvers, the output): the message the `porofrac` \
     command prints; `result` holds what the run computed before it failed, when anything."
);

/// The key a scene error names: the message's first word (`material.rock.E`), or the
/// key after `--set`.
fn key_of(message: &str) -> Option<String> {
    let m = message.strip_prefix("--set ").unwrap_or(message);
    let key: String = m
        .chars()
        .take_while(|c| !c.is_whitespace() && *c != '=' && *c != ':')
        .collect();
    let looks_like_key = !key.is_empty()
        && key
            .chars()
            .all(|c| c.is_alphanumeric() || matches!(c, '_' | '.' | '[' | ']' | '-'));
    looks_like_key.then_some(key)
}

/// A `porofrac.SceneError` for `e`.
fn scene_error(py: Python<'_>, e: &porofrac_scene::SceneError) -> PyErr {
    let err = SceneError::new_err(e.to_string());
    let v = err.value(py);
    let _ = v.setattr("key", key_of(&e.message));
    let _ = v.setattr("file", e.file.display().to_string());
    let _ = v.setattr("line", e.line);
    let _ = v.setattr("message", e.message.clone());
    err
}

/// The Python exception for a run error: scene problems are `SceneError`, the rest
/// `RunError`.
fn run_error(py: Python<'_>, e: &SceneRunError) -> PyErr {
    match e {
        SceneRunError::Scene(s) => scene_error(py, s),
        e => RunError::new_err(e.to_string()),
    }
}

/// A Python value as a TOML value.
fn toml_value(v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract()?));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let k: String = k
                .extract()
                .map_err(|_| PyValueError::new_err("scene table keys must be strings"))?;
            t.insert(k, toml_value(&x)?);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .map(|x| toml_value(&x?))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    // numpy scalars and other numbers.
    if let Ok(x) = v.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    Err(PyValueError::new_err(format!(
        "cannot write {} as a scene value: use a bool, int, float, str, list or dict",
        v.get_type().name()?
    )))
}

/// An override value as written (TOML text, or a bare word) as a TOML value, as the
/// scene parser reads it.
fn parse_value(text: &str) -> toml::Value {
    toml::from_str::<toml::Table>(&format!("v = {text}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(text.to_string()))
}

/// Put `value` at `path` in `table`, creating the tables on the way.
fn put(table: &mut toml::Table, key: &str, path: &[KeyPart], value: toml::Value) -> PyResult<()> {
    let mut root = toml::Value::Table(std::mem::take(table));
    let r = put_in(&mut root, key, path, value);
    if let toml::Value::Table(t) = root {
        *table = t;
    }
    r
}

fn put_in(here: &mut toml::Value, key: &str, path: &[KeyPart], value: toml::Value) -> PyResult<()> {
    let bad = |why: String| PyValueError::new_err(format!("{key}: {why}"));
    match path.split_first() {
        None => {
            *here = value;
            Ok(())
        }
        Some((KeyPart::Key(k), rest)) => {
            let t = here
                .as_table_mut()
                .ok_or_else(|| bad(format!("`{k}` is inside a value, not a table")))?;
            let next = t
                .entry(k.clone())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            put_in(next, key, rest, value)
        }
        Some((KeyPart::Index(n), rest)) => {
            let a = here
                .as_array_mut()
                .ok_or_else(|| bad(format!("{} counts the tables of an array", n + 1)))?;
            let len = a.len();
            let next = a.get_mut(*n).ok_or_else(|| {
                bad(format!(
                    "there are {len} tables in the array, not {}",
                    n + 1
                ))
            })?;
            put_in(next, key, rest, value)
        }
    }
}

/// A scene file: its text, where it came from (errors name it, relative paths start
/// there) and the keys changed with `Scene.set`, applied in order as the command's
/// `--set` does.
#[pyclass(module = "porofrac._porofrac", name = "_Scene", from_py_object)]
#[derive(Clone)]
struct PyScene {
    text: String,
    path: PathBuf,
    overrides: Vec<Override>,
}

impl PyScene {
    fn build(&self, py: Python<'_>) -> PyResult<porofrac_scene::Scene> {
        porofrac_scene::Scene::parse_with_overrides(
            &self.text,
            &self.path,
            LawRegistry::default(),
            &self.overrides,
        )
        .map_err(|e| scene_error(py, &e))
    }

    /// The document with the overrides applied.
    fn table(&self) -> PyResult<toml::Table> {
        let mut t: toml::Table = toml::from_str(&self.text)
            .map_err(|e| PyValueError::new_err(format!("{}: {e}", self.path.display())))?;
        for o in &self.overrides {
            let p = parts(&o.key).map_err(PyValueError::new_err)?;
            put(&mut t, &o.key, &p, parse_value(&o.value))?;
        }
        Ok(t)
    }
}

#[pymethods]
impl PyScene {
    /// Read the scene file `path` (errors: `SceneError`).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let text = porofrac_scene::common::loaded::read_bounded(
            &path,
            porofrac_scene::common::loaded::MAX_SCENE_BYTES,
            "a scene file",
        )
        .map_err(|e| {
            scene_error(
                py,
                &porofrac_scene::SceneError {
                    file: path.clone(),
                    line: 0,
                    message: format!("cannot read the scene file: {e}"),
                },
            )
        })?;
        let s = Self {
            text,
            path,
            overrides: Vec::new(),
        };
        s.build(py)?;
        Ok(s)
    }

    /// A scene from TOML text; `path` names it in errors and anchors relative paths.
    #[staticmethod]
    #[pyo3(signature = (text, path = None))]
    fn from_toml(py: Python<'_>, text: String, path: Option<PathBuf>) -> PyResult<Self> {
        let s = Self {
            text,
            path: path.unwrap_or_else(|| PathBuf::from("<scene>.toml")),
            overrides: Vec::new(),
        };
        s.build(py)?;
        Ok(s)
    }

    /// TOML text for a dict of the scene's tables (`{"scene": {"name": ...}, ...}`).
    #[staticmethod]
    fn dict_to_toml(d: &Bound<'_, PyDict>) -> PyResult<String> {
        match toml_value(d.as_any())? {
            toml::Value::Table(t) => {
                toml::to_string(&t).map_err(|e| PyValueError::new_err(e.to_string()))
            }
            _ => Err(PyValueError::new_err("a scene is a dict of tables")),
        }
    }

    /// Set the dotted key `key` (`material.rock.youngs_modulus`, `bc.2.value`: tables of
    /// an array counted from 1) to `value`, as `porofrac run --set KEY=VALUE` does.
    fn set(&mut self, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = toml_value(value)?;
        let text = v.to_string();
        let o = Override::parse(&format!("{key}={text}")).map_err(PyValueError::new_err)?;
        if self.overrides.len() >= porofrac_scene::common::overrides::MAX_OVERRIDES {
            return Err(PyValueError::new_err(format!(
                "more than {} keys set on one scene",
                porofrac_scene::common::overrides::MAX_OVERRIDES
            )));
        }
        self.overrides.push(o);
        Ok(())
    }

    /// A copy (`copy.copy`).
    fn __copy__(&self) -> Self {
        self.clone()
    }

    /// A copy (`copy.deepcopy`).
    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }

    /// The keys set so far, as `(key, value as TOML text)`.
    fn overrides(&self) -> Vec<(String, String)> {
        self.overrides
            .iter()
            .map(|o| (o.key.clone(), o.value.clone()))
            .collect()
    }

    /// The scene file's text as read.
    fn text(&self) -> String {
        self.text.clone()
    }

    /// The scene file's path.
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// The scene as TOML with the keys set applied (comments and layout are not kept).
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.table()?).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The scene's tables as JSON text (keys set applied).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.table()?).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Validate the scene and build its model as a run would, writing nothing; returns
    /// what a run would do.
    fn check<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let scene = self.build(py)?;
        let mut obs = PyObserver::new(None, false);
        let plan = py.detach(|| scene.check(&mut obs));
        if let Some(e) = obs.take_pending() {
            return Err(e);
        }
        let plan = plan.map_err(|e| run_error(py, &e))?;
        let d = PyDict::new(py);
        d.set_item("model", &plan.model)?;
        d.set_item("dim", plan.dim)?;
        let counts = PyDict::new(py);
        for (k, v) in &plan.counts {
            counts.set_item(*k, *v)?;
        }
        d.set_item("counts", counts)?;
        d.set_item("steps", plan.steps)?;
        d.set_item("written", plan.written)?;
        d.set_item("sampled", plan.sampled)?;
        d.set_item("vtk_files", plan.vtk_files)?;
        d.set_item("peak_bytes", plan.peak_bytes)?;
        d.set_item("build_seconds", plan.build_seconds)?;
        d.set_item("text", plan.lines_text().join("\n"))?;
        Ok(d)
    }

    /// Run the scene: into the folder `out` (the files of `porofrac run`), or in memory
    /// when `out` is None. `progress(step, total, time)` is called after every step. The
    /// GIL is released while the model steps. Ctrl-C (a pending KeyboardInterrupt)
    /// stops the run after the step in progress and raises KeyboardInterrupt with the
    /// partial result as its `result` attribute. `fields=False` keeps probes and lines
    /// only, not the state (grid, fields, particles, lattice) of the written steps.
    #[pyo3(signature = (out = None, progress = None, fields = true))]
    fn run(
        &self,
        py: Python<'_>,
        out: Option<PathBuf>,
        progress: Option<Py<PyAny>>,
        fields: bool,
    ) -> PyResult<PyResult_> {
        let scene = self.build(py)?;
        let line_names: Vec<String> = scene
            .file()
            .output
            .line
            .iter()
            .map(|l| l.name.clone())
            .collect();
        let mut obs = PyObserver::new(progress, true);
        obs.fields = fields;
        let summary = py.detach(|| match &out {
            Some(out) => scene.run(out, &mut obs),
            None => scene.run_in_memory(&mut obs),
        });
        // An interrupt that arrived after the run's last check is taken now, as Ctrl-C
        // during the last step would be: it stops nothing more but is raised with the result.
        if let Err(e) = py.check_signals() {
            obs.fail(e);
        }
        let pending = obs.take_pending();
        let summary = match summary {
            Ok(s) => s,
            Err(e) => {
                if let Some(p) = pending {
                    return Err(p);
                }
                let err = run_error(py, &e);
                let partial = PyResult_::new(py, obs, None, out, line_names)?;
                let _ = err.value(py).setattr("result", Py::new(py, partial)?);
                return Err(err);
            }
        };
        let json = serde_json::to_string(&summary).expect("the summary serializes");
        let result = PyResult_::new(py, obs, Some(json), out, line_names)?;
        if let Some(p) = pending {
            if p.is_instance_of::<PyKeyboardInterrupt>(py) {
                let _ = p.value(py).setattr("result", Py::new(py, result)?);
            }
            return Err(p);
        }
        Ok(result)
    }
}

/// The observer of a run from Python: records probes, lines and snapshots, calls the
/// progress callback and turns a pending KeyboardInterrupt into a stop request.
struct PyObserver {
    callback: Option<Py<PyAny>>,
    stop: Arc<AtomicBool>,
    pending: Arc<Mutex<Option<PyErr>>>,
    records: bool,
    fields: bool,
    probe_columns: Vec<String>,
    line_columns: Vec<Vec<String>>,
    sampled: Vec<f64>,
    probes: Vec<Vec<f64>>,
    written: Vec<f64>,
    lines: Vec<Vec<f64>>,
    snapshots: Vec<Snapshot>,
    mesh: Option<Arc<Mesh>>,
}

impl PyObserver {
    fn new(callback: Option<Py<PyAny>>, records: bool) -> Self {
        Self {
            callback,
            stop: Arc::new(AtomicBool::new(false)),
            pending: Arc::new(Mutex::new(None)),
            records,
            fields: true,
            probe_columns: Vec::new(),
            line_columns: Vec::new(),
            sampled: Vec::new(),
            probes: Vec::new(),
            written: Vec::new(),
            lines: Vec::new(),
            snapshots: Vec::new(),
            mesh: None,
        }
    }

    fn take_pending(&mut self) -> Option<PyErr> {
        self.pending.lock().ok().and_then(|mut p| p.take())
    }

    /// Check for signals (Ctrl-C) with the GIL; a pending exception stops the run.
    fn poll_signals(&self) {
        if self.stop.load(Ordering::Relaxed) {
            return;
        }
        Python::attach(|py| {
            if let Err(e) = py.check_signals() {
                self.fail(e);
            }
        });
    }

    fn fail(&self, e: PyErr) {
        if let Ok(mut p) = self.pending.lock()
            && p.is_none()
        {
            *p = Some(e);
        }
        self.stop.store(true, Ordering::Relaxed);
    }
}

impl Observer for PyObserver {
    fn step(&mut self, report: &StepReport) {
        self.poll_signals();
        if let Some(cb) = &self.callback
            && !self.stop.load(Ordering::Relaxed)
        {
            let r = Python::attach(|py| {
                cb.call1(py, (report.step, report.total, report.time))
                    .map(|_| ())
            });
            if let Err(e) = r {
                self.fail(e);
            }
        }
    }

    fn setup(&mut self, _report: &porofrac_scene::SetupReport<'_>) {
        self.poll_signals();
    }

    fn stop_requested(&self) -> bool {
        self.poll_signals();
        self.stop.load(Ordering::Relaxed)
    }

    fn stop_handle(&self) -> Stop {
        Stop::from_flag(self.stop.clone())
    }

    fn records(&self) -> bool {
        self.records
    }

    fn snapshots(&self) -> bool {
        self.records && self.fields
    }

    fn columns(&mut self, probes: &[String], lines: &[Vec<String>]) {
        self.probe_columns = probes.to_vec();
        self.line_columns = lines.to_vec();
        self.probes = vec![Vec::new(); probes.len().saturating_sub(1)];
        self.lines = vec![Vec::new(); lines.len()];
    }

    fn sampled(&mut self, time: f64, probes: &[f64]) {
        self.sampled.push(time);
        for (s, v) in self.probes.iter_mut().zip(probes) {
            s.push(*v);
        }
    }

    fn written(&mut self, time: f64, lines: &[Vec<Vec<f64>>], snapshot: Option<Snapshot>) {
        self.written.push(time);
        for (acc, rows) in self.lines.iter_mut().zip(lines) {
            for r in rows {
                acc.push(time);
                acc.extend_from_slice(r);
            }
        }
        if let Some(mut s) = snapshot {
            if let Some(m) = s.mesh.take() {
                self.mesh.get_or_insert(m);
            }
            self.snapshots.push(s);
        }
    }
}

/// The name of a CSV column without its unit (`p_well [Pa]` → `p_well`) and the unit.
fn split_column(c: &str) -> (String, String) {
    match c.split_once(" [") {
        Some((n, u)) => (n.to_string(), u.trim_end_matches(']').to_string()),
        None => (c.to_string(), "1".to_string()),
    }
}

/// A flat Rust vector as a numpy array of shape `(len / components, components)` (or
/// `(len,)` for one component) that owns the vector's buffer: no copy.
fn array<'py>(py: Python<'py>, values: Vec<f64>, components: usize) -> PyResult<Bound<'py, PyAny>> {
    let n = values.len();
    let a = PyArray1::from_vec(py, values);
    if components <= 1 {
        Ok(a.into_any())
    } else {
        Ok(a.reshape([n / components, components])?.into_any())
    }
}

fn int_array(py: Python<'_>, values: Vec<i64>) -> Bound<'_, PyAny> {
    PyArray1::from_vec(py, values).into_any()
}

/// A grid in VTK terms as the dict `porofrac.Grid` is made from (numpy arrays that own
/// the mesh's buffers).
fn mesh_dict(py: Python<'_>, m: Mesh) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("dim", m.dim)?;
    d.set_item("points", array(py, m.points, 3)?)?;
    d.set_item("connectivity", int_array(py, m.connectivity))?;
    d.set_item("offsets", int_array(py, m.offsets))?;
    d.set_item("cell_types", PyArray1::from_vec(py, m.cell_types))?;
    d.set_item("faces", int_array(py, m.faces))?;
    d.set_item("face_offsets", int_array(py, m.face_offsets))?;
    let tags = PyDict::new(py);
    for (name, cells) in m.tags {
        tags.set_item(name, int_array(py, cells))?;
    }
    d.set_item("tags", tags)?;
    Ok(d)
}

/// The result of a run (see `porofrac.Result`).
#[pyclass(module = "porofrac._porofrac", name = "_Result")]
struct PyResult_ {
    #[pyo3(get)]
    summary_json: Option<String>,
    #[pyo3(get)]
    out: Option<PathBuf>,
    #[pyo3(get)]
    probes: Py<PyDict>,
    #[pyo3(get)]
    units: Py<PyDict>,
    #[pyo3(get)]
    lines: Py<PyDict>,
    #[pyo3(get)]
    times: Py<PyAny>,
    /// Per written step: `{"point": {...}, "cell": {...}, "particles": {...},
    /// "lattice": {...}}`.
    #[pyo3(get)]
    steps: Py<PyList>,
    #[pyo3(get)]
    grid: Option<Py<PyDict>>,
    /// The addresses of the Rust buffers behind the field arrays, per step and name
    /// (`point:displacement`), for the test that nothing was copied.
    #[pyo3(get)]
    buffer_addresses: Py<PyList>,
}

impl PyResult_ {
    fn new(
        py: Python<'_>,
        obs: PyObserver,
        summary_json: Option<String>,
        out: Option<PathBuf>,
        line_names: Vec<String>,
    ) -> PyResult<Self> {
        let probes = PyDict::new(py);
        let units = PyDict::new(py);
        if !obs.probe_columns.is_empty() {
            let (n, u) = split_column(&obs.probe_columns[0]);
            units.set_item(&n, u)?;
            probes.set_item(n, array(py, obs.sampled, 1)?)?;
        }
        for (c, s) in obs.probe_columns.iter().skip(1).zip(obs.probes) {
            let (n, u) = split_column(c);
            units.set_item(&n, u)?;
            probes.set_item(n, array(py, s, 1)?)?;
        }
        let lines = PyDict::new(py);
        for ((cols, rows), name) in obs.line_columns.iter().zip(obs.lines).zip(line_names) {
            let names: Vec<String> = cols.iter().map(|c| split_column(c).0).collect();
            let d = PyDict::new(py);
            d.set_item("columns", names)?;
            d.set_item("rows", array(py, rows, cols.len())?)?;
            lines.set_item(name, d)?;
        }
        let steps = PyList::empty(py);
        let addresses = PyList::empty(py);
        for s in obs.snapshots {
            let step = PyDict::new(py);
            let addr = PyDict::new(py);
            step.set_item("time", s.time)?;
            let fields = |arrays: Vec<Array>, prefix: &str| -> PyResult<Bound<'_, PyDict>> {
                let d = PyDict::new(py);
                for a in arrays {
                    addr.set_item(format!("{prefix}:{}", a.name), a.values.as_ptr() as usize)?;
                    d.set_item(&a.name, array(py, a.values, a.components)?)?;
                }
                Ok(d)
            };
            step.set_item("point", fields(s.point_data, "point")?)?;
            step.set_item("cell", fields(s.cell_data, "cell")?)?;
            if let Some(p) = s.particles {
                let d = PyDict::new(py);
                d.set_item("positions", array(py, p.positions, 2)?)?;
                d.set_item("radii", array(py, p.radii, 1)?)?;
                d.set_item("velocities", array(py, p.velocities, 2)?)?;
                d.set_item("angles", array(py, p.angles, 1)?)?;
                d.set_item("angular_velocities", array(py, p.angular_velocities, 1)?)?;
                d.set_item("links", array(py, p.links, 4)?)?;
                d.set_item("normal_force", array(py, p.normal_force, 1)?)?;
                d.set_item("tangential_force", array(py, p.tangential_force, 1)?)?;
                d.set_item("bonded", array(py, p.bonded, 1)?)?;
                for a in p.fields {
                    d.set_item(&a.name, array(py, a.values, a.components)?)?;
                }
                step.set_item("particles", d)?;
            }
            if let Some(l) = s.lattice {
                let d = PyDict::new(py);
                for a in l.fields {
                    addr.set_item(format!("lattice:{}", a.name), a.values.as_ptr() as usize)?;
                    let arr = PyArray1::from_vec(py, a.values).reshape([l.ny, l.nx])?;
                    d.set_item(&a.name, arr)?;
                }
                d.set_item("origin", (l.origin[0], l.origin[1]))?;
                d.set_item("spacing", l.spacing)?;
                step.set_item("lattice", d)?;
            }
            steps.append(step)?;
            addresses.append(addr)?;
        }
        let grid = match obs.mesh {
            Some(m) => {
                let m = Arc::try_unwrap(m).unwrap_or_else(|m| (*m).clone());
                Some(mesh_dict(py, m)?.unbind())
            }
            None => None,
        };
        Ok(Self {
            summary_json,
            out,
            probes: probes.unbind(),
            units: units.unbind(),
            lines: lines.unbind(),
            times: array(py, obs.written, 1)?.unbind(),
            steps: steps.unbind(),
            grid,
            buffer_addresses: addresses.unbind(),
        })
    }
}

/// Keep freed heap memory in this process for reuse, as the `porofrac` command does
/// (glibc's `malloc` then serves large blocks from the heap instead of fresh `mmap`s that
/// fault in again, and does not trim; faster solves, a resident size that stays at its
/// peak). Process-wide and not undone; returns whether it was applied (Linux with glibc).
#[pyfunction]
fn retain_freed_memory() -> bool {
    porofrac_scene::common::heap::retain_freed_memory()
}

/// The extension module.
#[pymodule]
fn _porofrac(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<PyScene>()?;
    m.add_function(wrap_pyfunction!(retain_freed_memory, m)?)?;
    m.add_class::<PyResult_>()?;
    m.add_function(wrap_pyfunction!(lower::grid_read, m)?)?;
    m.add_function(wrap_pyfunction!(lower::grid_box, m)?)?;
    m.add_function(wrap_pyfunction!(lower::grid_voronoi, m)?)?;
    m.add_function(wrap_pyfunction!(lower::vem_stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(lower::simplex_stiffness, m)?)?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("RunError", py.get_type::<RunError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
