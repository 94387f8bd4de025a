//! The key reference of scene files, generated from the types the parser reads.
//!
//! Every section type of the scene derives [`schemars::JsonSchema`] beside
//! `Deserialize`, so the JSON Schema of [`SceneFile`] and of each model's own sections
//! ([`ModelKind::own_schema`]) lists exactly the keys the parser accepts, with their
//! types, the words of every choice, the defaults serde computes and the doc comments.
//! Three extensions of the schema carry what Rust types do not: `"unit"` (the SI unit
//! of a physical key, `#[schemars(extend("unit" = "Pa"))]`), `"models"` (the models that
//! read a key of a shared section, when not all do) and `"expected"` (what a key of an
//! untagged type accepts, in words, for error messages). A default written in a doc
//! comment as `(default X)` or `default X` is shown as the default.
//!
//! [`sections`] walks the schemas into [`Section`]s and [`Key`]s; [`text`] and
//! [`markdown`] render them (`porofrac keys`, docs/SCENE.md); [`find`] and
//! [`keys_at`] answer the error messages of [`crate::common::loaded`] (the key's
//! expected type and unit, and the keys valid where an unknown one was written).
//!
//! Keys of a table inside a section (`[loading] platens = { velocity, thickness }`) are
//! listed dotted (`platens.velocity`); an array of tables inside a section is a section
//! of its own (`[[output.probe]]`); the tables of `[material.<name>]` are one section.

use std::fmt::Write as _;

use serde_json::{Map, Value};

use crate::common::model::ModelKind;
use crate::common::sections::{KeyPart, SHARED_SECTIONS, SceneFile};

/// One key of a section.
#[derive(Clone, Debug, PartialEq)]
pub struct Key {
    /// The key within its section, dotted for keys of an inline table (`platens.velocity`).
    pub name: String,
    /// The type in words: `number`, `integer`, `bool`, `string`, `word`, `expr`,
    /// `list of number`, `[number, number]`, ...
    pub ty: String,
    /// SI unit of a physical key.
    pub unit: Option<String>,
    /// The default, when the key may be left out and has one.
    pub default: Option<String>,
    /// Whether the section must have the key.
    pub required: bool,
    /// The words (or table forms) the key accepts, each with its meaning.
    pub allowed: Vec<(String, String)>,
    /// The meaning (the doc comment of the field that parses it).
    pub meaning: String,
    /// What the key accepts in words (untagged types), for errors.
    pub expected: Option<String>,
    /// The models that read the key, when not every model reading the section does.
    pub models: Vec<String>,
}

/// One section of a scene file: a table, an array of tables or the tables of a map.
#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    /// The dotted path: `grid`, `output.probe`, `material.<name>`.
    pub path: String,
    /// An array of tables (`[[bc]]`).
    pub array: bool,
    /// The meaning of the section (the doc comment of its type).
    pub meaning: String,
    /// The models that read it.
    pub models: Vec<String>,
    /// Its keys, sorted by name.
    pub keys: Vec<Key>,
}

impl Section {
    /// The header as written in a scene file: `[grid]`, `[[bc]]`, `[material.<name>]`.
    pub fn header(&self) -> String {
        if self.array {
            format!("[[{}]]", self.path)
        } else {
            format!("[{}]", self.path)
        }
    }
    /// The top-level section it belongs to (`output` for `output.probe`).
    pub fn top(&self) -> &str {
        self.path.split('.').next().unwrap_or("")
    }
}

/// The top-level sections every model reads (the others are read by the models that
/// declare or read them, [`ModelKind::sections`], [`ModelKind::reads`]).
pub const ALWAYS: [&str; 4] = ["scene", "schedule", "output", "solver"];

/// Whether model `m` reads the top-level section `top`.
pub fn model_reads(m: &dyn ModelKind, top: &str) -> bool {
    ALWAYS.contains(&top) || m.sections().contains(&top) || m.reads().contains(&top)
}

/// Every section of the scene files of `models`: the shared sections (each with the
/// models that read it) and then each model's own, in registry order. With `only`, the
/// sections model `only` reads, without the keys of other models.
pub fn sections(models: &[&'static dyn ModelKind], only: Option<&str>) -> Vec<Section> {
    let shared = schemars::schema_for!(SceneFile).to_value();
    let mut out = Vec::new();
    let mut seen = Vec::new();
    for s in walk_root(&shared) {
        let readers: Vec<String> = models
            .iter()
            .filter(|m| model_reads(**m, s.top()))
            .map(|m| m.name().to_string())
            .collect();
        seen.push(s.path.clone());
        out.push(Section {
            models: readers,
            ..s
        });
    }
    for m in models {
        let Some(schema) = m.own_schema() else {
            continue;
        };
        for s in walk_root(&schema.to_value()) {
            if seen.contains(&s.path) {
                continue;
            }
            out.push(Section {
                models: vec![m.name().to_string()],
                ..s
            });
        }
    }
    // The shared sections in the order of [`SHARED_SECTIONS`], then each model's in the
    // order it declares them (the sort is stable: subsections stay after their section).
    let rank = |s: &Section| -> (usize, usize) {
        let top = s.top();
        if let Some(i) = SHARED_SECTIONS.iter().position(|x| *x == top) {
            return (0, i);
        }
        models
            .iter()
            .enumerate()
            .find_map(|(mi, m)| {
                m.sections()
                    .iter()
                    .position(|x| *x == top)
                    .map(|i| (mi + 1, i))
            })
            .unwrap_or((usize::MAX, 0))
    };
    out.sort_by_key(rank);
    if let Some(name) = only {
        out.retain(|s| s.models.iter().any(|m| m == name));
        for s in &mut out {
            s.keys
                .retain(|k| k.models.is_empty() || k.models.iter().any(|m| m == name));
        }
    }
    out
}

/// The sections whose path is `name` or lies under it (`output` gives `[output]`,
/// `[[output.probe]]` and `[[output.line]]`); brackets around `name` are ignored.
pub fn select(sections: Vec<Section>, name: &str) -> Vec<Section> {
    let name = name.trim_matches(|c| c == '[' || c == ']');
    sections
        .into_iter()
        .filter(|s| {
            s.path == name
                || s.path.starts_with(&format!("{name}."))
                || (name == "material" && s.path == "material.<name>")
        })
        .collect()
}

/// The key a path of a scene file names (indices of arrays of tables and names of
/// `[material.<name>]` tables are matched as such), among `sections`.
pub fn find<'a>(sections: &'a [Section], path: &[KeyPart]) -> Option<(&'a Section, &'a Key)> {
    let parts: Vec<&str> = keys_only(path);
    for s in sections {
        let sp: Vec<&str> = s.path.split('.').collect();
        if parts.len() <= sp.len() || !matches(&sp, &parts[..sp.len()]) {
            continue;
        }
        let rest = parts[sp.len()..].join(".");
        if let Some(k) = s.keys.iter().find(|k| k.name == rest) {
            return Some((s, k));
        }
    }
    None
}

/// The keys that may be written in the table at `table` (a section, or an inline table
/// of one): the first part of its keys and the arrays of tables under it. At the top
/// level (`table` empty), the top-level sections.
pub fn keys_at(sections: &[Section], table: &[KeyPart]) -> Vec<String> {
    let parts = keys_only(table);
    let mut out: Vec<String> = Vec::new();
    let mut push = |k: &str| {
        if !out.iter().any(|o| o == k) {
            out.push(k.to_string());
        }
    };
    for s in sections {
        let sp: Vec<&str> = s.path.split('.').collect();
        // Arrays of tables and sections directly under `table`.
        if sp.len() == parts.len() + 1 && matches(&sp[..parts.len()], &parts) {
            push(sp[parts.len()]);
        }
        if parts.len() < sp.len() || !matches(&sp, &parts[..sp.len()]) {
            continue;
        }
        let inner = &parts[sp.len()..];
        for k in &s.keys {
            let kp: Vec<&str> = k.name.split('.').collect();
            if kp.len() > inner.len() && kp[..inner.len()] == *inner {
                push(kp[inner.len()]);
            }
        }
    }
    out
}

/// The key of `candidates` nearest to `word` by edit distance, if near enough to be a
/// slip of the keyboard (at most a third of the word's length, and at most 3), else the
/// first that begins with `word` (of 4 characters or more).
pub fn nearest<'a>(word: &str, candidates: &'a [String]) -> Option<&'a str> {
    let limit = (word.chars().count() / 3).clamp(1, 3);
    candidates
        .iter()
        .map(|c| (edit_distance(word, c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c.as_str())
        .or_else(|| {
            // A key written short (`poisson` for `poisson_ratio`).
            (word.chars().count() >= 4)
                .then(|| candidates.iter().find(|c| c.starts_with(word)))
                .flatten()
                .map(String::as_str)
        })
}

/// Levenshtein distance between two strings, by characters.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=b.len() {
            let sub = prev[j - 1] + usize::from(a[i - 1] != b[j - 1]);
            cur[j] = sub.min(prev[j] + 1).min(cur[j - 1] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

fn keys_only(path: &[KeyPart]) -> Vec<&str> {
    path.iter()
        .filter_map(|p| match p {
            KeyPart::Key(k) => Some(k.as_str()),
            KeyPart::Index(_) => None,
        })
        .collect()
}

/// Section path parts against key parts, `<name>` matching any part.
fn matches(section: &[&str], parts: &[&str]) -> bool {
    section.len() == parts.len()
        && section
            .iter()
            .zip(parts)
            .all(|(s, p)| *s == "<name>" || s == p)
}

/// Named types shown by a short name rather than by their structure.
fn short_name(def: &str) -> Option<&'static str> {
    match def {
        "NumOrExpr" => Some("expr"),
        _ => None,
    }
}

struct Walker<'a> {
    defs: &'a Map<String, Value>,
}

fn walk_root(root: &Value) -> Vec<Section> {
    let empty = Map::new();
    let defs = root
        .get("$defs")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
    let w = Walker { defs };
    let mut out = Vec::new();
    if let Some(props) = root.get("properties").and_then(Value::as_object) {
        for (name, p) in props {
            w.section(name, p, &mut out);
        }
    }
    out
}

impl Walker<'_> {
    /// `v` with a `$ref` replaced by its definition and an `Option` by its inner type;
    /// the name of the definition if there was one.
    fn resolve<'v>(&'v self, v: &'v Value) -> (&'v Value, Option<&'v str>) {
        let mut v = v;
        let mut name = None;
        for _ in 0..8 {
            if let Some(r) = v.get("$ref").and_then(Value::as_str) {
                let n = r.trim_start_matches("#/$defs/");
                match self.defs.get(n) {
                    Some(d) => {
                        v = d;
                        name = Some(n);
                        continue;
                    }
                    None => break,
                }
            }
            if let Some(any) = v.get("anyOf").and_then(Value::as_array) {
                let non_null: Vec<&Value> = any.iter().filter(|a| !is_null(a)).collect();
                if non_null.len() == 1 && any.len() == 2 {
                    v = non_null[0];
                    continue;
                }
            }
            break;
        }
        (v, name)
    }

    fn is_struct(&self, v: &Value) -> bool {
        v.get("properties").is_some()
    }

    /// Section `path` of schema `v`: a table, an array of tables or a map of tables.
    fn section(&self, path: &str, v: &Value, out: &mut Vec<Section>) {
        let meaning = without_header(&description(v));
        let (r, _) = self.resolve(v);
        if let Some(items) = array_items(r) {
            let (item, _) = self.resolve(items);
            if self.is_struct(item) {
                self.table(path, true, &meaning, item, out);
            }
        } else if self.is_struct(r) {
            self.table(path, false, &meaning, r, out);
        } else if let Some(inner) = r.get("additionalProperties").filter(|a| a.is_object()) {
            let (item, _) = self.resolve(inner);
            if self.is_struct(item) {
                self.table(&format!("{path}.<name>"), false, &meaning, item, out);
            }
        }
    }

    fn table(&self, path: &str, array: bool, meaning: &str, v: &Value, out: &mut Vec<Section>) {
        let at = out.len();
        out.push(Section {
            path: path.to_string(),
            array,
            meaning: if meaning.is_empty() {
                without_header(&description(v))
            } else {
                meaning.to_string()
            },
            models: Vec::new(),
            keys: Vec::new(),
        });
        let mut keys = Vec::new();
        self.keys("", "", true, v, &mut keys, path, out);
        out[at].keys = keys;
    }

    /// The keys of struct `v`, prefixed by `prefix` (dotted keys of inline tables); arrays
    /// of tables become sections under `path`.
    #[allow(clippy::too_many_arguments)]
    fn keys(
        &self,
        prefix: &str,
        context: &str,
        parent_required: bool,
        v: &Value,
        keys: &mut Vec<Key>,
        path: &str,
        out: &mut Vec<Section>,
    ) {
        let required: Vec<&str> = v
            .get("required")
            .and_then(Value::as_array)
            .map(|a| a.iter().filter_map(Value::as_str).collect())
            .unwrap_or_default();
        let Some(props) = v.get("properties").and_then(Value::as_object) else {
            return;
        };
        for (name, p) in props {
            let full = format!("{prefix}{name}");
            let (r, _) = self.resolve(p);
            if let Some(items) = array_items(r) {
                let (item, _) = self.resolve(items);
                if self.is_struct(item) {
                    self.table(
                        &format!("{path}.{full}"),
                        true,
                        &without_header(&description(p)),
                        item,
                        out,
                    );
                    continue;
                }
            }
            let required = parent_required && required.contains(&name.as_str());
            if self.is_struct(r) {
                let meaning = description(p);
                let context = format!(
                    "{context}{}",
                    if meaning.is_empty() {
                        String::new()
                    } else {
                        format!("{meaning} ")
                    }
                );
                self.keys(&format!("{full}."), &context, required, r, keys, path, out);
                continue;
            }
            let mut key = self.key(&full, p, required);
            key.meaning = format!("{context}{}", key.meaning);
            keys.push(key);
        }
    }

    fn key(&self, name: &str, p: &Value, required: bool) -> Key {
        let (r, def) = self.resolve(p);
        let meaning = description(p);
        let mut allowed = Vec::new();
        let ty = self.ty(p, &mut allowed);
        // A default serde computes as NaN (a required value refused by the checks when
        // absent) serializes as null: no default.
        let default = p
            .get("default")
            .filter(|d| !d.is_null())
            .map(toml_text)
            .or_else(|| default_in(&meaning));
        let text = |k: &str| {
            p.get(k)
                .or_else(|| r.get(k))
                .and_then(Value::as_str)
                .map(str::to_string)
        };
        let models = p
            .get("models")
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .filter_map(|m| m.as_str().map(String::from))
                    .collect()
            })
            .unwrap_or_default();
        let expected = text("expected").or_else(|| {
            def.and_then(|d| self.defs.get(d))
                .and_then(|d| d.get("expected"))
                .and_then(Value::as_str)
                .map(String::from)
        });
        Key {
            name: name.to_string(),
            ty,
            unit: text("unit"),
            default,
            required,
            allowed,
            meaning,
            expected,
            models,
        }
    }

    /// The type of `v` in words; the words of a choice (and the forms of a tagged table)
    /// go to `allowed`.
    fn ty(&self, v: &Value, allowed: &mut Vec<(String, String)>) -> String {
        if let Some(any) = v.get("anyOf").and_then(Value::as_array)
            && any.len() == 2
            && let Some(inner) = any.iter().find(|a| !is_null(a))
            && any.iter().any(is_null)
        {
            return self.ty(inner, allowed);
        }
        if let Some(n) = v
            .get("$ref")
            .and_then(Value::as_str)
            .and_then(|r| short_name(r.trim_start_matches("#/$defs/")))
        {
            return n.to_string();
        }
        let (r, _) = self.resolve(v);
        if !std::ptr::eq(r, v) {
            return self.ty(r, allowed);
        }
        if let Some(c) = r.get("const") {
            allowed.push((
                toml_text(c),
                description(r).trim_end_matches('.').to_string(),
            ));
            return "word".into();
        }
        if let Some(e) = r.get("enum").and_then(Value::as_array) {
            allowed.extend(e.iter().map(|c| (toml_text(c), String::new())));
            return "word".into();
        }
        for key in ["oneOf", "anyOf"] {
            if let Some(vs) = r.get(key).and_then(Value::as_array) {
                let vs: Vec<&Value> = vs.iter().filter(|a| !is_null(a)).collect();
                if vs.iter().all(|a| a.get("const").is_some()) {
                    for a in vs {
                        self.ty(a, allowed);
                    }
                    return "word".into();
                }
                if vs.iter().all(|a| self.is_struct(a)) {
                    // An externally tagged enum: one key naming the form.
                    for a in vs {
                        allowed.push((description(a), String::new()));
                    }
                    return "table (one of the forms below)".into();
                }
                let mut parts: Vec<String> = Vec::new();
                for a in vs {
                    let t = self.ty(a, &mut Vec::new());
                    if !parts.contains(&t) {
                        parts.push(t);
                    }
                }
                return parts.join(" or ");
            }
        }
        let types: Vec<&str> = match r.get("type") {
            Some(Value::String(s)) => vec![s.as_str()],
            Some(Value::Array(a)) => a.iter().filter_map(Value::as_str).collect(),
            _ => Vec::new(),
        };
        let t = types.into_iter().find(|t| *t != "null").unwrap_or("");
        match t {
            "number" => "number".into(),
            "integer" => {
                if r.get("minimum").and_then(Value::as_f64) == Some(0.0) {
                    "integer ≥ 0".into()
                } else {
                    "integer".into()
                }
            }
            "boolean" => "bool".into(),
            "string" => "string".into(),
            "array" => {
                let item = r
                    .get("items")
                    .map(|i| self.ty(i, allowed))
                    .unwrap_or_else(|| "value".into());
                let n = |k: &str| r.get(k).and_then(Value::as_u64);
                match (n("minItems"), n("maxItems")) {
                    (Some(a), Some(b)) if a == b && a <= 3 => {
                        format!("[{}]", vec![item; a as usize].join(", "))
                    }
                    _ => format!("list of {item}"),
                }
            }
            "object" => "table".into(),
            _ => "value".into(),
        }
    }
}

/// A section's doc comment without the header it starts with (`` `[[bc]]`: `` …).
fn without_header(d: &str) -> String {
    let t = d.trim_start();
    if t.starts_with("`[")
        && let Some(end) = t[1..].find('`')
    {
        let rest = t[end + 2..].trim_start_matches(['.', ':']).trim();
        return rest.to_string();
    }
    d.to_string()
}

fn is_null(v: &Value) -> bool {
    v.get("type").and_then(Value::as_str) == Some("null")
}

fn array_items(v: &Value) -> Option<&Value> {
    let is_array = match v.get("type") {
        Some(Value::String(s)) => s == "array",
        Some(Value::Array(a)) => a.iter().any(|t| t == "array"),
        _ => false,
    };
    if is_array { v.get("items") } else { None }
}

/// The doc comment of a schema, on one line, without rustdoc links.
fn description(v: &Value) -> String {
    let d = v.get("description").and_then(Value::as_str).unwrap_or("");
    let one_line = d.split_whitespace().collect::<Vec<_>>().join(" ");
    // `[`name`]` and `[text](path)` links of rustdoc: keep the text.
    let mut out = String::with_capacity(one_line.len());
    let mut rest = one_line.as_str();
    while let Some(open) = rest.find("[`") {
        let Some(close) = rest[open..].find("`]") else {
            break;
        };
        out.push_str(&rest[..open]);
        out.push_str(&rest[open + 1..open + close + 1]);
        rest = &rest[open + close + 2..];
        if let Some(stripped) = rest.strip_prefix('(')
            && let Some(end) = stripped.find(')')
        {
            rest = &stripped[end + 1..];
        }
    }
    out.push_str(rest);
    out
}

/// A default stated in a doc comment: the text after `default ` up to `)`, `;` or the
/// end of the sentence.
fn default_in(meaning: &str) -> Option<String> {
    let at = meaning.find("default ")?;
    let rest = &meaning[at + "default ".len()..];
    let mut end = rest.len();
    for (i, c) in rest.char_indices() {
        let stop = match c {
            ')' | ';' => true,
            '.' => rest[i + 1..].is_empty() || rest[i + 1..].starts_with(' '),
            _ => false,
        };
        if stop {
            end = i;
            break;
        }
    }
    let d = rest[..end].trim();
    (!d.is_empty()).then(|| d.to_string())
}

/// A JSON value as it is written in TOML.
fn toml_text(v: &Value) -> String {
    match v {
        Value::String(s) => format!("\"{s}\""),
        Value::Array(a) => format!(
            "[{}]",
            a.iter().map(toml_text).collect::<Vec<_>>().join(", ")
        ),
        other => other.to_string(),
    }
}

/// The sections as text for a terminal: one block per section, one per key.
pub fn text(sections: &[Section]) -> String {
    let mut s = String::new();
    for sec in sections {
        let _ = writeln!(s, "{}  (models: {})", sec.header(), sec.models.join(", "));
        if !sec.meaning.is_empty() {
            let _ = writeln!(s, "  {}", sec.meaning);
        }
        let width = sec
            .keys
            .iter()
            .map(|k| k.name.chars().count())
            .max()
            .unwrap_or(0);
        for k in &sec.keys {
            let mut head = format!("  {:width$}  {}", k.name, k.ty);
            if let Some(u) = &k.unit {
                let _ = write!(head, ", {u}");
            }
            if k.required {
                head.push_str(", required");
            } else if let Some(d) = &k.default {
                let _ = write!(head, ", default {d}");
            }
            if !k.models.is_empty() {
                let _ = write!(head, " (model {})", k.models.join(", "));
            }
            let _ = writeln!(s, "{head}");
            let pad = " ".repeat(width + 4);
            if !k.meaning.is_empty() {
                let _ = writeln!(s, "{pad}{}", k.meaning);
            }
            for (word, meaning) in &k.allowed {
                if meaning.is_empty() {
                    let _ = writeln!(s, "{pad}  {word}");
                } else {
                    let _ = writeln!(s, "{pad}  {word}: {meaning}");
                }
            }
        }
        s.push('\n');
    }
    s
}

/// The command that writes docs/SCENE.md.
pub const MARKDOWN_COMMAND: &str = "porofrac keys --markdown > docs/SCENE.md";

/// The sections as the Markdown of docs/SCENE.md: one table per section.
pub fn markdown(sections: &[Section]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Scene files: the key reference\n\n\
         <!-- Generated from the types the parser reads by `{MARKDOWN_COMMAND}`; \
         do not edit. -->\n\n\
         Every key the parser accepts, one table per section: the key, its type, its unit, \
         its default and what it means. The same list is printed by `porofrac keys [MODEL] \
         [SECTION]`. Concepts, expressions, outputs, fields and examples are in \
         [SCENE-GUIDE.md](SCENE-GUIDE.md); each model's method and validation in \
         [models/](models/continuum.md).\n\n\
         Types: *number* (TOML float or integer), *integer*, *bool*, *string*, *word* (one \
         of the listed strings), *expr* (a number or a string expression in x, y, z (m) and \
         t (s), e.g. `\"-1e6*min(t/60, 1)\"`), *list of T*, `[T, T]` (exactly that many). \
         \"required\" in the default column: the section must have the key; \"—\": absence \
         has the meaning given. A key marked with a model is read by that model only.\n"
    );
    for sec in sections {
        let _ = writeln!(s, "## `{}`\n", sec.header());
        let _ = writeln!(s, "Models: {}.\n", sec.models.join(", "));
        if !sec.meaning.is_empty() {
            let _ = writeln!(s, "{}\n", cell(&sec.meaning));
        }
        s.push_str("| key | type | unit | default | meaning |\n|---|---|---|---|---|\n");
        for k in &sec.keys {
            let mut meaning = k.meaning.clone();
            if !k.models.is_empty() {
                meaning = format!("(model {}) {meaning}", k.models.join(", "));
            }
            if !k.allowed.is_empty() {
                let words: Vec<String> = k
                    .allowed
                    .iter()
                    .map(|(w, m)| {
                        if w.contains('`') {
                            w.trim_end_matches('.').to_string()
                        } else if m.is_empty() {
                            format!("`{w}`")
                        } else {
                            format!("`{w}`: {m}")
                        }
                    })
                    .collect();
                let _ = write!(meaning, " One of: {}", words.join("; "));
            }
            let default = if k.required {
                "required".to_string()
            } else {
                k.default.clone().map_or("—".into(), |d| {
                    if d.contains('`') { d } else { format!("`{d}`") }
                })
            };
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {} | {} |",
                k.name,
                cell(&k.ty),
                k.unit.as_deref().unwrap_or("—"),
                cell(&default),
                cell(&meaning)
            );
        }
        s.push('\n');
    }
    s
}

/// Text for a Markdown table cell (`|` escaped).
fn cell(t: &str) -> String {
    t.replace('|', "\\|")
}

/// The command that writes docs/summary.schema.json.
pub const SUMMARY_SCHEMA_COMMAND: &str =
    "porofrac keys --summary-schema > docs/summary.schema.json";

/// The JSON Schema of `summary.json`, from [`crate::common::output::Summary`]: the keys
/// every model writes, each model's own keys allowed beside them. A number may be
/// `null` (`serde_json` writes a NaN or an infinity so).
pub fn summary_schema() -> String {
    // The schema of what serializing writes: keys skipped when empty are optional.
    let mut generator = schemars::generate::SchemaSettings::draft2020_12()
        .for_serialize()
        .into_generator();
    // Each model's own keys: a model that publishes them is one form of `anyOf`, the
    // other models another, told apart by `model`.
    let (mut forms, mut others) = (Vec::new(), Vec::new());
    for m in crate::MODELS {
        match m.summary_schema(&mut generator) {
            Some(s) => {
                let mut form = s.to_value();
                if let Some(o) = form.as_object_mut() {
                    o.insert(
                        "properties".into(),
                        serde_json::json!({ "model": { "const": m.name() } }),
                    );
                    o.insert("required".into(), serde_json::json!(["model"]));
                }
                forms.push(form);
            }
            None => others.push(m.name()),
        }
    }
    let mut v = generator
        .into_root_schema_for::<crate::common::output::Summary>()
        .to_value();
    if !forms.is_empty() {
        // A run that stops before its model is built writes none of the model's keys:
        // they are described, not required.
        for f in &forms {
            if let Some(name) = f["$ref"].as_str().and_then(|r| r.strip_prefix("#/$defs/"))
                && let Some(def) = v.pointer_mut(&format!("/$defs/{name}"))
                && let Some(o) = def.as_object_mut()
            {
                o.remove("required");
            }
        }
        forms.push(serde_json::json!({ "properties": { "model": { "enum": others } } }));
        if let Some(o) = v.as_object_mut() {
            o.insert("anyOf".into(), Value::Array(forms));
        }
    }
    if let Some(o) = v.as_object_mut() {
        o.insert(
            "$comment".into(),
            Value::String(format!(
                "Generated from the Summary type by `{SUMMARY_SCHEMA_COMMAND}`; do not edit."
            )),
        );
    }
    nullable_numbers(&mut v);
    let mut s = serde_json::to_string_pretty(&v).unwrap_or_default();
    s.push('\n');
    s
}

/// Every `"type": "number"` of a schema becomes `["number", "null"]`.
fn nullable_numbers(v: &mut Value) {
    match v {
        Value::Object(o) => {
            if o.get("type").and_then(Value::as_str) == Some("number") {
                o.insert("type".into(), serde_json::json!(["number", "null"]));
            }
            for x in o.values_mut() {
                nullable_numbers(x);
            }
        }
        Value::Array(a) => a.iter_mut().for_each(nullable_numbers),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_counts_single_edits() {
        assert_eq!(edit_distance("shedule", "schedule"), 1);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        let keys = vec!["schedule".to_string(), "scene".to_string()];
        assert_eq!(nearest("shedule", &keys), Some("schedule"));
        assert_eq!(nearest("zzzzzz", &keys), None);
    }

    #[test]
    fn defaults_are_read_from_doc_comments() {
        assert_eq!(
            default_in("Coulomb friction μ (default 0.6)."),
            Some("0.6".into())
        );
        assert_eq!(
            default_in("Alert distance (m, default half the smallest radius)."),
            Some("half the smallest radius".into())
        );
        assert_eq!(
            default_in("θ in [0.5, 1] (default 1.666e-4)."),
            Some("1.666e-4".into())
        );
        assert_eq!(default_in("Equilibrium (default) or rest."), None);
    }

    #[test]
    fn every_section_of_the_parser_is_listed() {
        let all = sections(crate::MODELS, None);
        let paths: Vec<&str> = all.iter().map(|s| s.path.as_str()).collect();
        for p in [
            "scene",
            "grid",
            "bc",
            "source",
            "output",
            "output.probe",
            "material.<name>",
            "lbm.boundary",
            "nscd",
            "wall",
            "bonds",
            "obstacle",
            "injection",
        ] {
            assert!(paths.contains(&p), "{p} missing from {paths:?}");
        }
        let bc = all.iter().find(|s| s.path == "bc").unwrap();
        assert!(bc.array);
        let names: Vec<&str> = bc.keys.iter().map(|k| k.name.as_str()).collect();
        for k in ["boundary", "flux", "pressure", "platen.force", "traction"] {
            assert!(names.contains(&k), "[[bc]] {k} missing: {names:?}");
        }
        let (_, e) = find(
            &all,
            &crate::common::loaded::k(&["material", "rock", "youngs_modulus"]),
        )
        .unwrap();
        assert_eq!(e.unit.as_deref(), Some("Pa"));
        assert_eq!(e.ty, "number");
        let (_, every) = find(&all, &crate::common::loaded::k(&["output", "every"])).unwrap();
        assert_eq!(every.default.as_deref(), Some("1"));
    }

    #[test]
    fn a_model_sees_its_sections_and_its_keys_only() {
        let cont = sections(crate::MODELS, Some("continuum"));
        assert!(
            cont.iter()
                .all(|s| s.path != "nscd" && s.path != "particles")
        );
        let mat = cont.iter().find(|s| s.path == "material.<name>").unwrap();
        assert!(mat.keys.iter().all(|k| k.name != "shear_modulus"));
        let cos = sections(crate::MODELS, Some("cosserat"));
        let mat = cos.iter().find(|s| s.path == "material.<name>").unwrap();
        assert!(mat.keys.iter().any(|k| k.name == "shear_modulus"));
        assert_eq!(
            keys_at(&cont, &[])
                .iter()
                .filter(|k| *k == "schedule")
                .count(),
            1
        );
        assert!(keys_at(&cont, &crate::common::loaded::k(&["output"])).contains(&"probe".into()));
    }
}
