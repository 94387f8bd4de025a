//! Checkpoints: the state of a run after a step, written to `<out>/checkpoint/state.bin`
//! so that `porofrac run --resume <out>` continues it with the same results as a run
//! that was never stopped (docs/SCENE.md, `[output] checkpoint_every`).
//!
//! **Format.** A small binary file of named arrays, little-endian:
//!
//! ```text
//! magic      8 bytes  "PFCHKPT\n"
//! version    u32      FORMAT_VERSION
//! model      u32 length + UTF-8 bytes   ([scene] model)
//! scene hash u64      FNV-1a of the scene file's bytes
//! arrays     u64 count, then per array:
//!            u32 length + UTF-8 name, u8 kind (0 f64, 1 u64, 2 u8), u64 count, values
//! ```
//!
//! The driver's arrays are named `driver/…`, the scene's text and path `scene/…`; a model
//! names its own ([`crate::common::model::Model::save_state`]). A file whose magic,
//! version, model or scene hash does not match is refused with a message saying which;
//! sizes are checked against the bytes left before anything is allocated.
//!
//! The file is replaced atomically ([`crate::common::output::write_atomic`]): a run
//! killed while writing leaves the previous checkpoint.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use porofrac_grid::io::PvdWriter;

use crate::common::loaded::LoadedScene;
use crate::common::model::{Model, RunError};
use crate::common::output::{CsvTable, write_atomic};

/// First bytes of a checkpoint file.
pub const MAGIC: &[u8; 8] = b"PFCHKPT\n";
/// Version of the layout (and of the names the models use); a file of another version is
/// refused.
pub const FORMAT_VERSION: u32 = 1;
/// The folder of the checkpoint inside the output folder.
pub const DIR: &str = "checkpoint";
/// The checkpoint file inside [`DIR`].
pub const FILE: &str = "state.bin";

/// The checkpoint file of output folder `out`.
pub fn path(out: &Path) -> PathBuf {
    out.join(DIR).join(FILE)
}

/// The `--set` overrides of a scene, one `KEY=VALUE` per line, in command-line order.
fn override_lines(ls: &LoadedScene) -> String {
    ls.applied_overrides()
        .iter()
        .map(|o| format!("{}={}\n", o.key, o.value))
        .collect()
}

/// The overrides [`override_lines`] stored in a checkpoint.
pub(crate) fn stored_overrides(
    state: &State,
) -> Result<Vec<crate::common::overrides::Override>, RunError> {
    state
        .str("scene/overrides")?
        .lines()
        .map(|l| crate::common::overrides::Override::parse(l).map_err(RunError::Checkpoint))
        .collect()
}

/// The hash that ties a checkpoint to its scene: the file's text and the `--set`
/// overrides the run was started with.
fn scene_identity(ls: &LoadedScene) -> u64 {
    let mut bytes = ls.text.as_bytes().to_vec();
    for line in override_lines(ls).lines() {
        bytes.extend_from_slice(b"\n--set ");
        bytes.extend_from_slice(line.as_bytes());
    }
    scene_hash(&bytes)
}

/// FNV-1a (64 bit) of `bytes`: tells whether a scene file is the one a checkpoint was
/// written from.
pub fn scene_hash(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// One named array of a [`State`].
#[derive(Clone, Debug, PartialEq)]
pub enum Array {
    /// Floating-point numbers (bit-exact).
    F64(Vec<f64>),
    /// Counts, indices, flags.
    U64(Vec<u64>),
    /// Bytes (text, small flags).
    U8(Vec<u8>),
}

impl Array {
    fn kind(&self) -> u8 {
        match self {
            Array::F64(_) => 0,
            Array::U64(_) => 1,
            Array::U8(_) => 2,
        }
    }
    fn kind_name(&self) -> &'static str {
        match self {
            Array::F64(_) => "f64",
            Array::U64(_) => "u64",
            Array::U8(_) => "u8",
        }
    }
}

/// Named arrays: what a model and the driver save and read back.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct State {
    arrays: BTreeMap<String, Array>,
}

/// Why a checkpoint cannot be used (the text follows `checkpoint <file>: `).
fn bad(what: impl Into<String>) -> RunError {
    RunError::Checkpoint(what.into())
}

impl State {
    /// Store `values` under `name` (replacing an earlier array of that name).
    pub fn put_f64(&mut self, name: &str, values: impl Into<Vec<f64>>) {
        self.arrays
            .insert(name.to_string(), Array::F64(values.into()));
    }
    /// Store `values` under `name`.
    pub fn put_u64(&mut self, name: &str, values: impl Into<Vec<u64>>) {
        self.arrays
            .insert(name.to_string(), Array::U64(values.into()));
    }
    /// Store `values` under `name`.
    pub fn put_u8(&mut self, name: &str, values: impl Into<Vec<u8>>) {
        self.arrays
            .insert(name.to_string(), Array::U8(values.into()));
    }
    /// Store a text under `name` (as its UTF-8 bytes).
    pub fn put_str(&mut self, name: &str, text: &str) {
        self.put_u8(name, text.as_bytes());
    }
    /// Store 2-vectors under `name`, flattened.
    pub fn put_pairs(&mut self, name: &str, values: &[[f64; 2]]) {
        self.put_f64(name, values.iter().flatten().copied().collect::<Vec<_>>());
    }

    fn get(&self, name: &str) -> Result<&Array, RunError> {
        self.arrays.get(name).ok_or_else(|| {
            bad(format!(
                "it holds no array `{name}` (written by another version of porofrac?)"
            ))
        })
    }
    fn wrong_kind(name: &str, a: &Array, want: &str) -> RunError {
        bad(format!(
            "array `{name}` holds {} values, {want} expected",
            a.kind_name()
        ))
    }
    /// The `f64` array `name`.
    pub fn f64s(&self, name: &str) -> Result<&[f64], RunError> {
        match self.get(name)? {
            Array::F64(v) => Ok(v),
            a => Err(Self::wrong_kind(name, a, "f64")),
        }
    }
    /// The `u64` array `name`.
    pub fn u64s(&self, name: &str) -> Result<&[u64], RunError> {
        match self.get(name)? {
            Array::U64(v) => Ok(v),
            a => Err(Self::wrong_kind(name, a, "u64")),
        }
    }
    /// The `u8` array `name`.
    pub fn u8s(&self, name: &str) -> Result<&[u8], RunError> {
        match self.get(name)? {
            Array::U8(v) => Ok(v),
            a => Err(Self::wrong_kind(name, a, "u8")),
        }
    }
    /// The text `name`.
    pub fn str(&self, name: &str) -> Result<&str, RunError> {
        std::str::from_utf8(self.u8s(name)?)
            .map_err(|_| bad(format!("array `{name}` is not UTF-8 text")))
    }
    /// The `f64` array `name`, which must hold `len` values (the model was rebuilt from the
    /// same scene, so its sizes match the checkpoint's).
    pub fn f64s_len(&self, name: &str, len: usize) -> Result<&[f64], RunError> {
        let v = self.f64s(name)?;
        Self::check_len(name, v.len(), len)?;
        Ok(v)
    }
    /// The `u64` array `name` of `len` values.
    pub fn u64s_len(&self, name: &str, len: usize) -> Result<&[u64], RunError> {
        let v = self.u64s(name)?;
        Self::check_len(name, v.len(), len)?;
        Ok(v)
    }
    /// The 2-vectors `name`, `len` of them.
    pub fn pairs(&self, name: &str, len: usize) -> Result<Vec<[f64; 2]>, RunError> {
        let v = self.f64s_len(name, 2 * len)?;
        Ok(v.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    }
    /// The single number `name`.
    pub fn f64(&self, name: &str) -> Result<f64, RunError> {
        Ok(self.f64s_len(name, 1)?[0])
    }
    /// The single count `name`.
    pub fn u64(&self, name: &str) -> Result<u64, RunError> {
        Ok(self.u64s_len(name, 1)?[0])
    }
    /// The single count `name` as an index (refused when it does not fit).
    pub fn usize(&self, name: &str) -> Result<usize, RunError> {
        let v = self.u64(name)?;
        usize::try_from(v).map_err(|_| bad(format!("array `{name}`: {v} is too large")))
    }
    fn check_len(name: &str, found: usize, want: usize) -> Result<(), RunError> {
        if found == want {
            Ok(())
        } else {
            Err(bad(format!(
                "array `{name}` has {found} values, the rebuilt model needs {want} (the \
                 scene or porofrac changed since the checkpoint was written)"
            )))
        }
    }
}

/// A checkpoint: which model and scene it belongs to, and the state.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// `[scene] model` of the run.
    pub model: String,
    /// [`scene_hash`] of the scene file's text followed by its `--set` overrides.
    pub scene_hash: u64,
    /// The arrays.
    pub state: State,
}

impl Checkpoint {
    /// The file's bytes (see the module docs).
    pub fn encode(&self) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        b.extend_from_slice(&(self.model.len() as u32).to_le_bytes());
        b.extend_from_slice(self.model.as_bytes());
        b.extend_from_slice(&self.scene_hash.to_le_bytes());
        b.extend_from_slice(&(self.state.arrays.len() as u64).to_le_bytes());
        for (name, a) in &self.state.arrays {
            b.extend_from_slice(&(name.len() as u32).to_le_bytes());
            b.extend_from_slice(name.as_bytes());
            b.push(a.kind());
            match a {
                Array::F64(v) => {
                    b.extend_from_slice(&(v.len() as u64).to_le_bytes());
                    v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
                }
                Array::U64(v) => {
                    b.extend_from_slice(&(v.len() as u64).to_le_bytes());
                    v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
                }
                Array::U8(v) => {
                    b.extend_from_slice(&(v.len() as u64).to_le_bytes());
                    b.extend_from_slice(v);
                }
            }
        }
        b
    }

    /// Read the bytes of a checkpoint file; errors say what is wrong (not a checkpoint,
    /// another format version, a truncated or damaged file).
    pub fn decode(bytes: &[u8]) -> Result<Self, RunError> {
        let mut r = Reader { b: bytes, at: 0 };
        let (model, scene_hash) = read_head(&mut r)?;
        let count = r.u64()?;
        let mut state = State::default();
        for _ in 0..count {
            let name = r.text()?;
            let kind = r.take(1)?[0];
            let n = r.u64()?;
            let size = match kind {
                0 | 1 => 8u64,
                2 => 1,
                k => return Err(bad(format!("array `{name}` has unknown kind {k}"))),
            };
            // Checked against the bytes left before anything is allocated.
            let bytes = n
                .checked_mul(size)
                .filter(|&s| s <= (r.b.len() - r.at) as u64)
                .ok_or_else(|| bad(format!("array `{name}` runs past the end of the file")))?;
            let raw = r.take(bytes as usize)?;
            let a = match kind {
                0 => Array::F64(
                    raw.chunks_exact(8)
                        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                        .collect(),
                ),
                1 => Array::U64(
                    raw.chunks_exact(8)
                        .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")))
                        .collect(),
                ),
                _ => Array::U8(raw.to_vec()),
            };
            state.arrays.insert(name, a);
        }
        if r.at != bytes.len() {
            return Err(bad(format!(
                "{} bytes after the last array",
                bytes.len() - r.at
            )));
        }
        Ok(Self {
            model,
            scene_hash,
            state,
        })
    }

    /// Write the checkpoint of output folder `out` atomically.
    pub fn write(&self, out: &Path) -> Result<(), RunError> {
        write_atomic(&path(out), &self.encode())?;
        Ok(())
    }

    /// Read the checkpoint of output folder `out`; errors name the file.
    pub fn read(out: &Path) -> Result<Self, RunError> {
        let p = path(out);
        let named = |e: RunError| match e {
            RunError::Checkpoint(w) => RunError::Checkpoint(format!("{}: {w}", p.display())),
            e => e,
        };
        let bytes = std::fs::read(&p).map_err(|e| {
            RunError::Checkpoint(format!(
                "{}: {e} (write checkpoints with [output] checkpoint_every, or stop a run \
                 with Ctrl-C)",
                p.display()
            ))
        })?;
        Self::decode(&bytes).map_err(named)
    }
}

/// The model and scene hash of the checkpoint of `out`, read without the arrays (to refuse
/// a wrong scene before a model is built).
pub fn read_header(out: &Path) -> Result<(String, u64), RunError> {
    use std::io::Read as _;
    let p = path(out);
    let mut head = Vec::new();
    std::fs::File::open(&p)
        .and_then(|f| f.take(8 + 4 + 4 + 4096 + 8).read_to_end(&mut head))
        .map_err(|e| {
            RunError::Checkpoint(format!(
                "{}: {e} (write checkpoints with [output] checkpoint_every, or stop a run \
                 with Ctrl-C)",
                p.display()
            ))
        })?;
    let named = |e: RunError| match e {
        RunError::Checkpoint(w) => RunError::Checkpoint(format!("{}: {w}", p.display())),
        e => e,
    };
    let mut r = Reader { b: &head, at: 0 };
    let parse = |r: &mut Reader<'_>| -> Result<(String, u64), RunError> { read_head(r) };
    parse(&mut r).map_err(named)
}

/// The header of a checkpoint: magic bytes and format version checked; the model name
/// and the scene hash.
fn read_head(r: &mut Reader<'_>) -> Result<(String, u64), RunError> {
    if r.take(8)? != MAGIC {
        return Err(bad("not a porofrac checkpoint (wrong magic bytes)"));
    }
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(bad(format!(
            "format version {version}, this porofrac reads version {FORMAT_VERSION}"
        )));
    }
    Ok((r.text()?, r.u64()?))
}

/// Refuse the checkpoint of `out` for scene `ls` when it was written by another model or
/// from another scene file content.
pub(crate) fn check_matches(
    ls: &LoadedScene,
    out: &Path,
    model: &str,
    hash: u64,
) -> Result<(), RunError> {
    let p = path(out);
    if model != ls.model() {
        return Err(RunError::Checkpoint(format!(
            "{}: written by a run of model \"{model}\", the scene {} is model \"{}\"",
            p.display(),
            ls.path.display(),
            ls.model()
        )));
    }
    if hash != scene_identity(ls) {
        return Err(RunError::Checkpoint(format!(
            "{}: written from another scene file; {} is not the same content (resume \
             without naming the scene to use the copy the checkpoint holds)",
            p.display(),
            ls.path.display()
        )));
    }
    Ok(())
}

/// What the driver has written so far, saved with the model's state.
pub(crate) struct Progress<'a> {
    /// The step just finished.
    pub step: usize,
    /// The times the probes were sampled at.
    pub sampled: &'a [f64],
    /// The written times (VTK, lines).
    pub written: &'a [f64],
    /// The probe series at the sampled times.
    pub series: &'a [Vec<f64>],
    /// The field extrema of the last written step.
    pub extrema: &'a BTreeMap<String, [f64; 2]>,
    /// Solver iterations so far.
    pub total_iterations: usize,
    /// Steps after t = 0 so far.
    pub steps: usize,
    /// `probes.csv`.
    pub probes: &'a CsvTable,
    /// `lines/<name>.csv`.
    pub lines: &'a [CsvTable],
    /// `<name>.pvd`.
    pub pvd: Option<&'a PvdWriter>,
}

/// Save the driver's progress, the scene and the model's state into the checkpoint of
/// `out`.
pub(crate) fn save(
    ls: &LoadedScene,
    out: &Path,
    model: &dyn Model,
    p: &Progress<'_>,
) -> Result<(), RunError> {
    let mut state = State::default();
    model.save_state(&mut state)?;
    state.put_str("scene/text", &ls.text);
    state.put_str("scene/overrides", &override_lines(ls));
    state.put_str("scene/path", &ls.path.to_string_lossy());
    state.put_u64("driver/step", vec![p.step as u64]);
    state.put_f64("driver/sampled", p.sampled);
    state.put_f64("driver/written", p.written);
    state.put_f64(
        "driver/series",
        p.series.iter().flatten().copied().collect::<Vec<_>>(),
    );
    state.put_str(
        "driver/extrema_names",
        &p.extrema.keys().cloned().collect::<Vec<_>>().join("\n"),
    );
    state.put_f64(
        "driver/extrema",
        p.extrema.values().flatten().copied().collect::<Vec<_>>(),
    );
    state.put_u64(
        "driver/counts",
        vec![p.total_iterations as u64, p.steps as u64],
    );
    state.put_str("driver/probes_csv", p.probes.text());
    for (i, l) in p.lines.iter().enumerate() {
        state.put_str(&format!("driver/line_csv/{i}"), l.text());
    }
    if let Some(pvd) = p.pvd {
        save_pvd(&mut state, "driver/pvd", pvd);
    }
    Checkpoint {
        model: ls.model().to_string(),
        scene_hash: scene_identity(ls),
        state,
    }
    .write(out)
}

/// Save the entries of a `.pvd` series under `name/times` and `name/files`.
pub fn save_pvd(state: &mut State, name: &str, pvd: &PvdWriter) {
    let e = pvd.entries();
    state.put_f64(
        &format!("{name}/times"),
        e.iter().map(|(t, _)| *t).collect::<Vec<_>>(),
    );
    state.put_str(
        &format!("{name}/files"),
        &e.iter()
            .map(|(_, f)| f.as_str())
            .collect::<Vec<_>>()
            .join("\n"),
    );
}

/// The `.pvd` series at `path` rewritten with the entries [`save_pvd`] saved under `name`
/// (`None` when the checkpoint has none).
pub fn restore_pvd(state: &State, name: &str, path: &Path) -> Result<Option<PvdWriter>, RunError> {
    let Ok(times) = state.f64s(&format!("{name}/times")) else {
        return Ok(None);
    };
    let files = state.str(&format!("{name}/files"))?;
    let files: Vec<&str> = if times.is_empty() {
        Vec::new()
    } else {
        files.split('\n').collect()
    };
    if files.len() != times.len() {
        return Err(bad(format!(
            "`{name}`: {} times, {} files",
            times.len(),
            files.len()
        )));
    }
    let entries = times
        .iter()
        .zip(files)
        .map(|(t, f)| (*t, f.to_string()))
        .collect();
    Ok(Some(PvdWriter::with_entries(path, entries)?))
}

/// The driver's progress read back by [`resume`].
pub(crate) struct Resumed {
    /// The step the checkpoint was written after.
    pub step: usize,
    /// The times the probes were sampled at.
    pub sampled: Vec<f64>,
    /// The written times (VTK, lines).
    pub written: Vec<f64>,
    /// The probe series.
    pub series: Vec<Vec<f64>>,
    /// The field extrema of the last written step.
    pub extrema: BTreeMap<String, [f64; 2]>,
    /// Solver iterations so far.
    pub total_iterations: usize,
    /// Steps after t = 0 so far.
    pub steps: usize,
}

/// Read the checkpoint of `out`, check it belongs to `ls`, restore the model's state, the
/// tables and the `.pvd` series; returns the rest of the driver's progress.
pub(crate) fn resume(
    ls: &LoadedScene,
    out: &Path,
    model: &mut dyn Model,
    probes: &mut CsvTable,
    lines: &mut [CsvTable],
    pvd: &mut Option<PvdWriter>,
    probe_count: usize,
) -> Result<Resumed, RunError> {
    let c = Checkpoint::read(out)?;
    check_matches(ls, out, &c.model, c.scene_hash)?;
    let p = path(out);
    let named = |e: RunError| match e {
        RunError::Checkpoint(w) => RunError::Checkpoint(format!("{}: {w}", p.display())),
        e => e,
    };
    let st = &c.state;
    let mut run = || -> Result<Resumed, RunError> {
        let step = st.usize("driver/step")?;
        if step + 1 >= model.times().len() {
            return Err(bad(format!(
                "written after step {step}, the scene has {} steps: nothing is left to run",
                model.times().len().saturating_sub(1)
            )));
        }
        model.restore_state(st, out)?;
        let sampled = st.f64s("driver/sampled")?.to_vec();
        let written = st.f64s("driver/written")?.to_vec();
        let flat = st.f64s_len("driver/series", sampled.len() * probe_count)?;
        let series = (0..probe_count)
            .map(|j| {
                (0..sampled.len())
                    .map(|i| flat[j * sampled.len() + i])
                    .collect()
            })
            .collect();
        let names = st.str("driver/extrema_names")?;
        let names: Vec<&str> = if names.is_empty() {
            Vec::new()
        } else {
            names.split('\n').collect()
        };
        let values = st.f64s_len("driver/extrema", 2 * names.len())?;
        let extrema = names
            .iter()
            .zip(values.chunks_exact(2))
            .map(|(n, v)| (n.to_string(), [v[0], v[1]]))
            .collect();
        let counts = st.u64s_len("driver/counts", 2)?;
        probes.restore(st.str("driver/probes_csv")?.to_string());
        for (i, l) in lines.iter_mut().enumerate() {
            l.restore(st.str(&format!("driver/line_csv/{i}"))?.to_string());
        }
        if let Some(w) = pvd.as_ref() {
            let path = w.path().to_path_buf();
            *pvd = restore_pvd(st, "driver/pvd", &path)?;
            if pvd.is_none() {
                return Err(bad("it holds no VTK series but the scene writes one"));
            }
        }
        Ok(Resumed {
            step,
            sampled,
            written,
            series,
            extrema,
            total_iterations: counts[0] as usize,
            steps: counts[1] as usize,
        })
    };
    run().map_err(named)
}

/// Save the moving state of disks under `name/…`: positions, reference positions,
/// velocities, angles and spins (radii and masses come from the scene).
pub fn save_disks(state: &mut State, name: &str, d: &porofrac_particles::Disks) {
    state.put_pairs(&format!("{name}/x"), &d.x);
    state.put_pairs(&format!("{name}/x0"), &d.x0);
    state.put_pairs(&format!("{name}/v"), &d.v);
    state.put_f64(&format!("{name}/angle"), d.angle.clone());
    state.put_f64(&format!("{name}/omega"), d.omega.clone());
}

/// Put back what [`save_disks`] saved into disks rebuilt from the same scene.
pub fn restore_disks(
    state: &State,
    name: &str,
    d: &mut porofrac_particles::Disks,
) -> Result<(), RunError> {
    let n = d.len();
    d.x = state.pairs(&format!("{name}/x"), n)?;
    d.x0 = state.pairs(&format!("{name}/x0"), n)?;
    d.v = state.pairs(&format!("{name}/v"), n)?;
    d.angle = state.f64s_len(&format!("{name}/angle"), n)?.to_vec();
    d.omega = state.f64s_len(&format!("{name}/omega"), n)?.to_vec();
    Ok(())
}

/// A cursor over the bytes of a checkpoint.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], RunError> {
        if n > self.b.len() - self.at {
            return Err(bad("the file ends early (truncated)"));
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, RunError> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4")))
    }
    fn u64(&mut self) -> Result<u64, RunError> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().expect("8")))
    }
    fn text(&mut self) -> Result<String, RunError> {
        let n = self.u32()? as usize;
        let s = self.take(n)?;
        String::from_utf8(s.to_vec()).map_err(|_| bad("a name is not UTF-8 text"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Checkpoint {
        let mut state = State::default();
        state.put_f64("x", vec![0.1, -0.0, f64::MIN_POSITIVE, 1e300]);
        state.put_u64("n", vec![7, u64::MAX]);
        state.put_str("text", "time,a\n0,1\n");
        Checkpoint {
            model: "nscd".into(),
            scene_hash: scene_hash(b"[scene]\n"),
            state,
        }
    }

    /// Encoding and decoding give back the same arrays bit for bit.
    #[test]
    fn round_trip_is_exact() {
        let c = sample();
        let back = Checkpoint::decode(&c.encode()).unwrap();
        assert_eq!(back, c);
        let x = back.state.f64s("x").unwrap();
        assert_eq!(x[1].to_bits(), (-0.0f64).to_bits());
        assert_eq!(back.state.str("text").unwrap(), "time,a\n0,1\n");
        assert_eq!(back.state.u64s_len("n", 2).unwrap(), &[7, u64::MAX]);
    }

    /// Wrong magic, another version, every truncation, a huge declared count and a
    /// missing or mis-sized array are refused with a message saying which.
    #[test]
    fn damaged_files_are_refused() {
        let b = sample().encode();
        let e = |bytes: &[u8]| Checkpoint::decode(bytes).unwrap_err().to_string();
        let mut m = b.clone();
        m[0] = b'X';
        assert!(e(&m).contains("wrong magic"), "{}", e(&m));
        let mut v = b.clone();
        v[8] = 9;
        assert!(e(&v).contains("format version 9"), "{}", e(&v));
        for n in 0..b.len() {
            assert!(Checkpoint::decode(&b[..n]).is_err(), "truncated at {n}");
        }
        // The count of the first array ("n", u64) claims 2^60 values.
        let at = 8 + 4 + 4 + 4 + 8 + 8 + 4 + 1 + 1;
        let mut h = b.clone();
        h[at..at + 8].copy_from_slice(&(1u64 << 60).to_le_bytes());
        assert!(e(&h).contains("array `n` runs past the end"), "{}", e(&h));
        let s = sample().state;
        assert!(
            s.f64s("y")
                .unwrap_err()
                .to_string()
                .contains("no array `y`")
        );
        let w = s.f64s_len("x", 5).unwrap_err().to_string();
        assert!(
            w.contains("array `x` has 4 values") && w.contains("needs 5"),
            "{w}"
        );
        assert!(s.u64s("x").unwrap_err().to_string().contains("f64 values"));
    }
}
