//! Reading and checking a scene file: every problem is a [`SceneError`] with the file,
//! line and key.

use std::fmt;
use std::path::{Path, PathBuf};

use std::collections::BTreeMap;
use std::sync::Arc;

use serde::Deserialize;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use crate::common::expr::Expr;
use crate::common::laws::LawRegistry;
use crate::common::model::{ModelKind, OwnSections};
use crate::common::sections::{
    KeyPart, NumOrExpr, SHARED_SECTIONS, SceneFile, key_text, line_of_offset,
};

/// A problem in a scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// The scene file.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// What is wrong, starting with the key (`material.rock.poisson_ratio = 0.5 must be < 0.5`).
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = self.file.file_name().map_or_else(
            || self.file.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        if self.line == 0 {
            // Not at a line of the file: it cannot be read, or the error is in a `--set`.
            write!(f, "{name}: {}", bound_echoes(&self.message))
        } else {
            write!(f, "{name}:{}: {}", self.line, bound_echoes(&self.message))
        }
    }
}

impl std::error::Error for SceneError {}

/// A parsed scene: the shared sections, the model's own sections, and the line of every
/// key of the file (from the spans of the TOML parser), for the errors of later checks.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The sections every model reads.
    pub scene: SceneFile,
    /// The file it came from.
    pub path: PathBuf,
    /// Its text.
    pub text: String,
    /// The model of `[scene] model` (`None`: a name no model of the registry has).
    kind: Option<Kind>,
    /// The model's own sections, as its [`ModelKind::sections_of`] read them.
    own: Option<Arc<dyn OwnSections>>,
    /// Line of every key path of the file.
    lines: KeyLines,
    /// The `--set` overrides applied to the file, in command-line order.
    overrides: Vec<crate::common::overrides::Applied>,
    /// Continue the run from the checkpoint of its output folder
    /// ([`crate::common::checkpoint`]).
    pub(crate) resume: bool,
}

impl LoadedScene {
    /// An error at a key path: the line is that of the deepest part of the path written
    /// in the file (1 if none is).
    pub fn error(&self, path: &[KeyPart], message: impl fmt::Display) -> SceneError {
        if let Some(o) = self.overrides.iter().find(|o| {
            path.starts_with(&o.path)
                || (!path.is_empty()
                    && o.path.starts_with(path)
                    && !self.lines.in_file(path, self.text.len()))
        }) {
            return SceneError {
                file: self.path.clone(),
                line: 0,
                message: bound_echoes(&format!("--set {}: {} {}", o.key, key_text(path), message)),
            };
        }
        SceneError {
            file: self.path.clone(),
            line: self.lines.line(path),
            message: bound_echoes(&format!("{} {}", key_text(path), message)),
        }
    }
    /// The line of `path` in the file (that of its deepest part written there; 1 if none
    /// is), to point at a second key in a message.
    pub(crate) fn line_of(&self, path: &[KeyPart]) -> usize {
        self.lines.line(path)
    }
    /// The model of the scene (`[scene] model`, default `"continuum"`).
    pub fn model(&self) -> &str {
        self.scene.scene.model.as_deref().unwrap_or("continuum")
    }
    /// The model of the registry the scene names, if there is one.
    pub fn kind(&self) -> Option<&'static dyn ModelKind> {
        self.kind.map(|k| k.0)
    }
    /// The model's own sections. Panics if `T` is not the type the scene's model reads
    /// (a model asks for its own type only).
    pub fn own<T: OwnSections>(&self) -> &T {
        let own: &dyn std::any::Any = self.own.as_deref().expect("the model's sections are read");
        own.downcast_ref::<T>()
            .expect("a model reads its own sections")
    }
    /// The `--set` overrides applied to the scene, in command-line order.
    pub(crate) fn applied_overrides(&self) -> &[crate::common::overrides::Applied] {
        &self.overrides
    }

    /// The `--set` overrides of the scene: each key as written on the command line and its
    /// value (for `summary.json`).
    pub fn overrides(&self) -> BTreeMap<String, serde_json::Value> {
        self.overrides
            .iter()
            .map(|o| (o.key.clone(), o.json.clone()))
            .collect()
    }
    /// The top-level keys of the file, in the parser's order.
    pub fn top_level(&self) -> &[String] {
        &self.lines.top
    }
    /// Whether the file has the top-level section `name`.
    pub fn has_section(&self, name: &str) -> bool {
        self.lines.top.iter().any(|s| s == name)
    }
    /// Resolve a path written in the scene (relative to the scene file's directory).
    pub fn resolve(&self, p: &str) -> PathBuf {
        let p = Path::new(p);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.path.parent().unwrap_or(Path::new(".")).join(p)
        }
    }
}

/// A model of the registry, shown by its name.
#[derive(Clone, Copy)]
struct Kind(&'static dyn ModelKind);

impl fmt::Debug for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0.name())
    }
}

/// The 1-based line of every key path of a file, from the spans of the parsed document: a
/// table key's line is where the key is written (for `[a.b]`, the header), an element of
/// an array of tables is at its `[[...]]` header.
#[derive(Clone, Debug, Default)]
pub(crate) struct KeyLines {
    lines: BTreeMap<Vec<KeyPart>, usize>,
    top: Vec<String>,
    /// The byte range of every key and of every value, with its key path (for the errors
    /// of the parser, which carry a byte range).
    pub(crate) spans: Vec<(std::ops::Range<usize>, Vec<KeyPart>)>,
}

impl KeyLines {
    fn of(doc: &DeTable<'_>, text: &str) -> Self {
        let mut lines = BTreeMap::new();
        let mut path = Vec::new();
        let mut spans = Vec::new();
        Self::walk(doc, text, &mut path, &mut lines, &mut spans);
        let top = doc.keys().map(|k| k.get_ref().to_string()).collect();
        Self { lines, top, spans }
    }

    fn walk(
        table: &DeTable<'_>,
        text: &str,
        path: &mut Vec<KeyPart>,
        lines: &mut BTreeMap<Vec<KeyPart>, usize>,
        spans: &mut Vec<(std::ops::Range<usize>, Vec<KeyPart>)>,
    ) {
        for (key, value) in table {
            path.push(KeyPart::Key(key.get_ref().to_string()));
            lines.insert(path.clone(), line_of_offset(text, key.span().start));
            spans.push((key.span(), path.clone()));
            spans.push((value.span(), path.clone()));
            match value.get_ref() {
                DeValue::Table(t) => Self::walk(t, text, path, lines, spans),
                DeValue::Array(items) => {
                    for (i, item) in items.into_iter().enumerate() {
                        if let DeValue::Table(t) = item.get_ref() {
                            path.push(KeyPart::Index(i));
                            lines.insert(path.clone(), line_of_offset(text, item.span().start));
                            spans.push((item.span(), path.clone()));
                            Self::walk(t, text, path, lines, spans);
                            path.pop();
                        }
                    }
                }
                _ => {}
            }
            path.pop();
        }
    }

    /// Whether the file writes `path` (a key or a table that only a `--set` made is not
    /// written in it: its spans lie past the file's `text_len` bytes).
    pub(crate) fn in_file(&self, path: &[KeyPart], text_len: usize) -> bool {
        self.spans
            .iter()
            .any(|(r, p)| p.as_slice() == path && r.start < text_len)
    }

    /// The line of the longest prefix of `path` written in the file; 1 if none is.
    pub(crate) fn line(&self, path: &[KeyPart]) -> usize {
        (1..=path.len())
            .rev()
            .find_map(|n| self.lines.get(&path[..n]).copied())
            .unwrap_or(1)
    }
}

/// Key path helper: `k(&["material", "rock", "poisson_ratio"])`.
pub fn k(parts: &[&str]) -> Vec<KeyPart> {
    parts.iter().map(|p| KeyPart::Key(p.to_string())).collect()
}

/// Key path with an index: `ki("bc", 2, &["traction"])`.
pub fn ki(table: &str, index: usize, rest: &[&str]) -> Vec<KeyPart> {
    let mut v = k(&table.split('.').collect::<Vec<_>>());
    v.push(KeyPart::Index(index));
    v.extend(rest.iter().map(|p| KeyPart::Key(p.to_string())));
    v
}

/// Largest scene file read (bytes): a scene is a page of text, not data.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

/// Read and parse a scene file (syntax, types, unknown keys).
/// Models are those of `models`, as for [`parse`].
pub fn load(path: &Path, models: &[&'static dyn ModelKind]) -> Result<LoadedScene, SceneError> {
    load_with(path, models, &[])
}

/// Read the text of the regular file `path`, refusing more than `limit` bytes while
/// reading (at most `limit + 1` bytes are read, so a device or a file that grows is never
/// read whole) and anything that is not a regular file (a directory, `/dev/zero`, a FIFO):
/// `Err` says why, in words for an error after "cannot read …: ". `what` names the kind of
/// file (`"a scene file"`).
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<String, String> {
    use std::io::Read as _;
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err(format!(
            "it is not a regular file ({}); {what} must be one",
            file_type_text(&meta.file_type())
        ));
    }
    let too_big =
        |n: u64| format!("it has {n} bytes or more, more than the {limit} {what} may have");
    if meta.len() > limit {
        return Err(too_big(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > limit {
        return Err(too_big(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "it is not UTF-8 text (invalid byte at offset {})",
            e.utf8_error().valid_up_to()
        )
    })
}

/// What kind of file system object a non-regular file is, in words.
fn file_type_text(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a named pipe";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a file"
    }
}

/// Longest user text (characters) an error message repeats whole.
pub const MAX_ECHO_CHARS: usize = 60;

/// User text for an error message: whole if it has at most [`MAX_ECHO_CHARS`]
/// characters, else its first ones followed by `… (N characters)`.
pub fn echo(s: &str) -> String {
    let n = s.chars().count();
    // Short text, or text this function already shortened, stays as it is.
    if n <= MAX_ECHO_CHARS
        || (s.chars().nth(MAX_ECHO_CHARS) == Some('…') && s.ends_with(" characters)"))
    {
        return s.to_string();
    }
    let head: String = s.chars().take(MAX_ECHO_CHARS).collect();
    format!("{head}… ({n} characters)")
}

/// `message` with every quoted part (between `"` or between backticks) longer than
/// [`MAX_ECHO_CHARS`] shortened by [`echo`], so no error repeats a long text of the user
/// whole (a 200 kB expression in a terminal or in `summary.json`).
pub fn bound_echoes(message: &str) -> String {
    if message.chars().count() <= MAX_ECHO_CHARS {
        return message.to_string();
    }
    let mut out = String::with_capacity(message.len().min(4096));
    let mut rest = message;
    while let Some(open) = rest.find(['"', '`']) {
        let q = rest[open..].chars().next().unwrap_or('"');
        out.push_str(&rest[..=open]);
        let after = &rest[open + 1..];
        match after.find(q) {
            Some(close) => {
                out.push_str(&echo(&after[..close]));
                out.push(q);
                rest = &after[close + 1..];
            }
            None => {
                out.push_str(&echo(after));
                rest = "";
            }
        }
    }
    out.push_str(rest);
    out
}

/// Deepest nesting of TOML arrays and tables in a scene file. The TOML parser recurses
/// per level, so deeper text is refused before it is parsed.
pub const MAX_TOML_NESTING: usize = 32;

/// Parse scene text once (syntax, types, unknown keys): the shared sections, and the
/// own sections of the model of `[scene] model` found in `models`; `path` names the file
/// in errors.
pub fn parse(
    text: &str,
    path: &Path,
    models: &[&'static dyn ModelKind],
) -> Result<LoadedScene, SceneError> {
    parse_with(text, path, models, &[])
}

/// Read and parse a scene file as [`load`] does, with the `--set` overrides applied to
/// the parsed document before the typed read ([`crate::common::overrides`]).
pub fn load_with(
    path: &Path,
    models: &[&'static dyn ModelKind],
    overrides: &[crate::common::overrides::Override],
) -> Result<LoadedScene, SceneError> {
    let cannot = |e: String| SceneError {
        file: path.to_path_buf(),
        line: 0,
        message: format!("cannot read the scene file: {e}"),
    };
    let text = read_bounded(path, MAX_SCENE_BYTES, "a scene file").map_err(cannot)?;
    parse_with(&text, path, models, overrides)
}

/// Parse scene text as [`parse`] does, with the `--set` overrides applied to the parsed
/// document before the typed read, so every check applies to them; an error in an
/// override names `--set KEY`.
pub fn parse_with(
    text: &str,
    path: &Path,
    models: &[&'static dyn ModelKind],
    overrides: &[crate::common::overrides::Override],
) -> Result<LoadedScene, SceneError> {
    use crate::common::overrides;
    if let Some((offset, depth)) = too_deep(text) {
        return Err(SceneError {
            file: path.to_path_buf(),
            line: line_of_offset(text, offset),
            message: format!(
                "arrays and tables nest {depth} levels deep here, more than the \
                 {MAX_TOML_NESTING} a scene may use"
            ),
        });
    }
    let text = text.to_string();
    let toml_error = |e: toml::de::Error| SceneError {
        file: path.to_path_buf(),
        line: e.span().map_or(1, |s| line_of_offset(&text, s.start)),
        message: bound_echoes(&e.message().trim().replace('\n', " ")),
    };
    // The file and then the override values: the document is parsed from the file's part,
    // so its spans are the file's offsets; a span past the file is in an override.
    let source = overrides::source(&text, overrides);
    let mut doc = DeTable::parse(&source[..text.len()]).map_err(toml_error)?;
    let applied =
        overrides::apply(doc.get_mut(), &source, text.len(), overrides).map_err(|message| {
            SceneError {
                file: path.to_path_buf(),
                line: 0,
                message: bound_echoes(&message),
            }
        })?;
    let lines = KeyLines::of(doc.get_ref(), &text);
    let model_name = overrides::model_of(doc.get_ref());
    let place = crate::common::scene_errors::Place {
        file: path,
        text: &text,
        source: &source,
        lines: &lines,
        overrides: &applied,
        models,
        model: &model_name,
    };
    let explain = |e: toml::de::Error| crate::common::scene_errors::explain(&e, &place);
    // Top-level keys: the shared sections, or a section some model declares.
    let owned = |key: &str| models.iter().any(|m| m.sections().contains(&key));
    for key in &lines.top {
        if !SHARED_SECTIONS.contains(&key.as_str()) && !owned(key) {
            let mut known: Vec<&str> = SHARED_SECTIONS.to_vec();
            for m in models {
                for s in m.sections() {
                    if !known.contains(s) {
                        known.push(s);
                    }
                }
            }
            return Err(crate::common::scene_errors::unknown_section(
                key, &place, &known,
            ));
        }
    }
    let (shared, own) = split_document(doc);
    let scene = SceneFile::deserialize(toml::de::Deserializer::from(shared)).map_err(explain)?;
    let name = scene.scene.model.as_deref().unwrap_or("continuum");
    let kind = models.iter().copied().find(|m| m.name() == name);
    let own = match kind {
        Some(m) => Some(m.sections_of(own).map_err(explain)?),
        None => None,
    };
    Ok(LoadedScene {
        scene,
        path: path.to_path_buf(),
        text,
        kind: kind.map(Kind),
        own,
        lines,
        overrides: applied,
        resume: false,
    })
}

/// Split a document into the shared sections ([`SHARED_SECTIONS`]) and the rest (the
/// sections of the models).
fn split_document(doc: Spanned<DeTable<'_>>) -> (Spanned<DeTable<'_>>, Spanned<DeTable<'_>>) {
    let span = doc.span();
    let (mut shared, mut own) = (DeTable::new(), DeTable::new());
    for (key, value) in doc.into_inner() {
        if SHARED_SECTIONS.contains(&key.get_ref().as_ref()) {
            shared.insert(key, value);
        } else {
            own.insert(key, value);
        }
    }
    (Spanned::new(span.clone(), shared), Spanned::new(span, own))
}

/// The offset and depth where `[`/`{` nesting (outside strings and comments) first
/// exceeds [`MAX_TOML_NESTING`].
fn too_deep(text: &str) -> Option<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    let mut at_line_start = true;
    while i < bytes.len() {
        let b = bytes[i];
        match b {
            b'#' => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'"' | b'\'' => {
                // Skip a string (basic strings honour backslash escapes; triple quotes
                // are three empty-or-not strings in a row, which skips the same way).
                let quote = b;
                i += 1;
                while i < bytes.len() && bytes[i] != quote {
                    if quote == b'"' && bytes[i] == b'\\' {
                        i += 1;
                    }
                    i += 1;
                }
            }
            b'[' | b'{' if depth > 0 || !(at_line_start && b == b'[') => {
                depth += 1;
                if depth > MAX_TOML_NESTING {
                    return Some((i, depth));
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            b'\n' => {
                at_line_start = true;
                i += 1;
                continue;
            }
            _ => {}
        }
        if !b.is_ascii_whitespace() {
            at_line_start = false;
        }
        i += 1;
    }
    None
}

/// `v` is a finite number > 0.
pub(crate) fn positive(ls: &LoadedScene, path: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if !(v.is_finite() && v > 0.0) {
        return Err(ls.error(path, format!("= {v} must be > 0")));
    }
    Ok(())
}

/// A vector has as many components as the scene has dimensions.
pub(crate) fn len_is(
    ls: &LoadedScene,
    path: &[KeyPart],
    got: usize,
    want: usize,
) -> Result<(), SceneError> {
    if got != want {
        return Err(ls.error(path, format!("has {got} components, the scene is {want}D")));
    }
    Ok(())
}

/// The part of `[[output.line]]` number `i` every model checks alike: `points` in
/// `2..=MAX_LINE_POINTS` and a name that is a file name.
pub(crate) fn line_points_and_name(
    ls: &LoadedScene,
    i: usize,
    l: &crate::common::sections::Line,
) -> Result<(), SceneError> {
    if !(2..=crate::common::limits::MAX_LINE_POINTS as i64).contains(&l.points) {
        return Err(ls.error(
            &ki("output.line", i, &["points"]),
            format!(
                "= {} must be in 2..={}",
                l.points,
                crate::common::limits::MAX_LINE_POINTS
            ),
        ));
    }
    if l.name.is_empty() || l.name.contains(['/', '\\']) {
        return Err(ls.error(
            &ki("output.line", i, &["name"]),
            "must be a non-empty file name",
        ));
    }
    Ok(())
}

/// A number (finite) or an expression that parses (or `"free"` where allowed).
pub(crate) fn expr_ok(
    ls: &LoadedScene,
    path: &[KeyPart],
    v: &NumOrExpr,
    allow_free: bool,
) -> Result<(), SceneError> {
    match v {
        NumOrExpr::Num(x) if !x.is_finite() => {
            Err(ls.error(path, format!("= {x} is not a finite number")))
        }
        NumOrExpr::Num(_) => Ok(()),
        NumOrExpr::Expr(s) if allow_free && s == "free" => Ok(()),
        NumOrExpr::Expr(s) => Expr::parse(s)
            .map(|_| ())
            .map_err(|e| ls.error(path, format!("= \"{s}\": bad expression at {e}"))),
    }
}

/// Number of steps of a schedule (before the [`crate::common::limits::MAX_STEPS`] bound; as
/// a float so absurd requests do not overflow).
pub fn step_count_f64(sch: &crate::common::sections::Schedule) -> f64 {
    match (sch.dt, sch.steps) {
        (Some(dt), _) => (sch.end_time / dt - 1e-9).ceil().max(1.0),
        (None, Some(n)) => n.max(1) as f64,
        _ => 1.0,
    }
}

/// Number of steps of a checked schedule.
pub fn step_count(sch: &crate::common::sections::Schedule) -> u64 {
    step_count_f64(sch) as u64
}

/// The top-level keys every model may have: `[scene]`, `[schedule]`, `[output]`,
/// `[solver]`.
use crate::common::keys::ALWAYS;

/// Check a parsed scene: the keys of `[scene]`, the sections of other models (refused
/// with the model they belong to, from the sections every model of `models` declares),
/// then the model's own checks. Returns the first problem found.
pub fn check(
    ls: &LoadedScene,
    laws: &LawRegistry,
    models: &[&'static dyn ModelKind],
) -> Result<(), SceneError> {
    let s = &ls.scene;
    let dim = s.scene.dim;
    if dim != 2 && dim != 3 {
        return Err(ls.error(&k(&["scene", "dim"]), format!("= {dim} must be 2 or 3")));
    }
    let d = dim as usize;
    if s.scene.name.is_empty() || s.scene.name.contains(['/', '\\']) {
        return Err(ls.error(
            &k(&["scene", "name"]),
            "must be a non-empty name without slashes",
        ));
    }
    if s.scene.plane.is_some() && d == 3 {
        return Err(ls.error(&k(&["scene", "plane"]), "applies to 2D scenes only"));
    }
    let Some(kind) = ls.kind() else {
        let names: Vec<&str> = models.iter().map(|m| m.name()).collect();
        return Err(ls.error(
            &k(&["scene", "model"]),
            format!(
                "= \"{}\" is not available in this version of porofrac (available: {})",
                ls.model(),
                names.join(", ")
            ),
        ));
    };
    kind.refuse(ls)?;
    for key in ls.top_level() {
        let key = key.as_str();
        if ALWAYS.contains(&key) || kind.sections().contains(&key) || kind.reads().contains(&key) {
            continue;
        }
        let owner = models.iter().find(|m| m.sections().contains(&key));
        let path = owner.map_or_else(|| k(&[key]), |m| m.refused_as(key));
        let owner = owner.map_or("another model", |m| m.name());
        return Err(ls.error(
            &path,
            format!("belongs to model \"{owner}\", not \"{}\"", kind.name()),
        ));
    }
    // Keys of a shared section that other models read only (`[material.*]
    // shear_modulus` is the Cosserat model's), from the key reference.
    let all = crate::common::keys::sections(models, None);
    let of_some_models: Vec<&str> = all
        .iter()
        .flat_map(|s| &s.keys)
        .filter(|k| !k.models.is_empty())
        .filter_map(|k| k.name.rsplit('.').next())
        .collect();
    // The first such key in the file's order.
    let mut first: Option<(usize, &Vec<KeyPart>, String)> = None;
    for (path, line) in &ls.lines.lines {
        let named = matches!(path.last(), Some(KeyPart::Key(last)) if of_some_models.contains(&last.as_str()));
        if named
            && first.as_ref().is_none_or(|(l, _, _)| line < l)
            && let Some((_, key)) = crate::common::keys::find(&all, path)
            && !key.models.is_empty()
            && !key.models.iter().any(|m| m == kind.name())
        {
            first = Some((*line, path, key.models.join("\", \"")));
        }
    }
    if let Some((_, path, owners)) = first {
        return Err(ls.error(
            path,
            format!("belongs to model \"{owners}\", not \"{}\"", kind.name()),
        ));
    }
    if s.output.probe_every < 1 {
        return Err(ls.error(
            &k(&["output", "probe_every"]),
            format!("= {} must be ≥ 1", s.output.probe_every),
        ));
    }
    kind.check(ls, laws)
}
