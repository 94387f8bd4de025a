//! The errors of the typed read of a scene in the user's words: the parser's messages
//! ("invalid type: string \"1 GPa\", expected f64", "data did not match any variant of
//! untagged enum CellCount", "unknown field `shedule`") rewritten to name the key,
//! what it accepts (with its unit, from the key reference of [`crate::common::keys`]),
//! and for an unknown key the nearest key valid at that place for the scene's model
//! ("did you mean `schedule`?"), or the model the key belongs to.

use std::path::Path;

use crate::common::keys::{self, Key, Section};
use crate::common::loaded::{KeyLines, SceneError, bound_echoes, echo};
use crate::common::model::ModelKind;
use crate::common::overrides::Applied;
use crate::common::sections::{KeyPart, key_text, line_of_offset};

/// Where an error of the typed read happened: the file, its text, the parse source
/// (the text and the `--set` values), the keys' spans, the overrides and the models.
pub struct Place<'a> {
    /// The scene file.
    pub file: &'a Path,
    /// Its text.
    pub text: &'a str,
    /// The parse source: the text, then the override values.
    pub source: &'a str,
    /// Lines and spans of the keys.
    pub(crate) lines: &'a KeyLines,
    /// The overrides applied.
    pub overrides: &'a [Applied],
    /// The models of the registry.
    pub models: &'a [&'static dyn ModelKind],
    /// The scene's model (`[scene] model`).
    pub model: &'a str,
}

impl Place<'_> {
    /// The key path at byte range `span` (a key or a value; the innermost), and whether
    /// the span is a key's.
    fn path_at(&self, span: &std::ops::Range<usize>) -> Option<(Vec<KeyPart>, bool)> {
        let mut best: Option<(&std::ops::Range<usize>, &Vec<KeyPart>)> = None;
        for (r, p) in &self.lines.spans {
            if r.start <= span.start && span.end <= r.end.max(r.start + 1) {
                let better = best.is_none_or(|(b, bp)| {
                    (r.end - r.start) < (b.end - b.start)
                        || ((r.end - r.start) == (b.end - b.start) && p.len() > bp.len())
                });
                if better {
                    best = Some((r, p));
                }
            }
        }
        best.map(|(r, p)| (p.clone(), *r == *span))
    }

    /// The error at key path `path` (or the override the span lies in).
    fn at(
        &self,
        span: Option<&std::ops::Range<usize>>,
        path: &[KeyPart],
        message: String,
    ) -> SceneError {
        if let Some(o) = span
            .filter(|s| s.start > self.text.len())
            .and_then(|s| {
                self.overrides
                    .iter()
                    .find(|o| o.span.start <= s.start && s.start <= o.span.end)
            })
            .or_else(|| {
                self.overrides.iter().find(|o| {
                    !path.is_empty()
                        && (path.starts_with(&o.path)
                            || (o.path.starts_with(path)
                                && !self.lines.in_file(path, self.text.len())))
                })
            })
        {
            return SceneError {
                file: self.file.to_path_buf(),
                line: 0,
                message: bound_echoes(&format!("--set {}: {message}", o.key)),
            };
        }
        let line = match span {
            Some(s) if s.start <= self.text.len() => line_of_offset(self.text, s.start),
            _ => self.lines.line(path),
        };
        SceneError {
            file: self.file.to_path_buf(),
            line,
            message: bound_echoes(&message),
        }
    }

    /// The sections the scene's model reads (all when it names no model of the registry).
    fn sections(&self) -> Vec<Section> {
        let known = self.models.iter().any(|m| m.name() == self.model);
        keys::sections(self.models, known.then_some(self.model))
    }
}

/// An unknown top-level section `key`: the nearest section of the scene's model, or the
/// model it belongs to is said later by the check; `all` lists every section known.
pub fn unknown_section(key: &str, place: &Place<'_>, all: &[&str]) -> SceneError {
    let path = vec![KeyPart::Key(key.to_string())];
    let own: Vec<String> = match place.models.iter().find(|m| m.name() == place.model) {
        Some(m) => all
            .iter()
            .filter(|s| keys::model_reads(*m, s))
            .map(|s| s.to_string())
            .collect(),
        None => all.iter().map(|s| s.to_string()).collect(),
    };
    let message = match keys::nearest(key, &own) {
        Some(near) => format!("unknown section `{}`; did you mean `{near}`?", echo(key)),
        None => format!(
            "unknown section `{}`; the sections of model \"{}\" are {}",
            echo(key),
            place.model,
            quoted(&own)
        ),
    };
    place.at(None, &path, message)
}

/// The parser's error `e` in the user's words (see the module docs).
pub fn explain(e: &toml::de::Error, place: &Place<'_>) -> SceneError {
    let raw = e.message().trim().replace('\n', " ");
    let span = e.span();
    let located = span.as_ref().and_then(|s| place.path_at(s));
    let Some((path, is_key)) = located else {
        return place.at(span.as_ref(), &[], raw);
    };
    let sections = place.sections();
    if let Some(field) = between(&raw, "unknown field `", "`") {
        let parent: Vec<KeyPart> = if is_key {
            path[..path.len().saturating_sub(1)].to_vec()
        } else {
            path.clone()
        };
        return place.at(
            span.as_ref(),
            &parent,
            unknown_key(field, &parent, &sections, place),
        );
    }
    let shown = value_text(place, span.as_ref());
    let key = keys::find(&sections, &path).map(|(_, k)| k.clone());
    let name = key_text(&path);
    if let Some(field) = between(&raw, "missing field `", "`") {
        let what = keys::find(
            &sections,
            &[path.clone(), vec![KeyPart::Key(field.into())]].concat(),
        )
        .map(|(_, k)| format!(" ({})", k.meaning.trim_end_matches('.')))
        .unwrap_or_default();
        let message = if path.is_empty() {
            format!("the scene needs the section `[{field}]`{what}")
        } else {
            format!("{name} needs the key `{field}`{what}")
        };
        return place.at(span.as_ref(), &path, message);
    }
    let Some(key) = key else {
        return place.at(span.as_ref(), &path, format!("{name}: {raw}"));
    };
    if let Some(word) = between(&raw, "unknown variant `", "`")
        && !key.ty.starts_with("table")
    {
        let words: Vec<String> = key
            .allowed
            .iter()
            .map(|(w, _)| w.trim_matches('"').to_string())
            .collect();
        let hint = keys::nearest(word, &words)
            .map(|n| format!("; did you mean \"{n}\"?"))
            .unwrap_or_default();
        return place.at(
            span.as_ref(),
            &path,
            format!(
                "{name} = \"{}\": expected one of {}{hint}",
                echo(word),
                quoted_words(&words)
            ),
        );
    }
    if raw.starts_with("invalid type")
        || raw.starts_with("data did not match any variant")
        || raw.starts_with("invalid value")
        || raw.starts_with("invalid length")
    {
        let hint = hint(&shown, &key);
        return place.at(
            span.as_ref(),
            &path,
            format!(
                "{name} = {}: expected {}{hint}",
                echo(&shown),
                expected(&key)
            ),
        );
    }
    place.at(span.as_ref(), &path, format!("{name}: {raw}"))
}

/// The message of an unknown key `field` in the table at `parent`.
fn unknown_key(field: &str, parent: &[KeyPart], sections: &[Section], place: &Place<'_>) -> String {
    let full = key_text(&[parent.to_vec(), vec![KeyPart::Key(field.into())]].concat());
    // A key of another model at this place.
    let all = keys::sections(place.models, None);
    let path = [parent.to_vec(), vec![KeyPart::Key(field.into())]].concat();
    let in_all = keys::keys_at(&all, parent).iter().any(|k| k == field);
    let here = keys::keys_at(sections, parent);
    if in_all && !here.iter().any(|k| k == field) {
        let owner = keys::find(&all, &path)
            .map(|(s, k)| {
                if k.models.is_empty() {
                    s.models.clone()
                } else {
                    k.models.clone()
                }
            })
            .unwrap_or_default();
        if !owner.is_empty() {
            return format!(
                "{full} belongs to model \"{}\", not \"{}\"",
                owner.join("\", \""),
                place.model
            );
        }
    }
    let table = if parent.is_empty() {
        "the scene".to_string()
    } else {
        format!("[{}]", key_text(parent))
    };
    match keys::nearest(field, &here) {
        Some(near) => format!(
            "unknown key `{}` in {table}; did you mean `{near}`?",
            echo(field)
        ),
        None => format!(
            "unknown key `{}` in {table}; its keys are {}",
            echo(field),
            quoted(&here)
        ),
    }
}

/// What a key accepts, in words, with its unit.
fn expected(key: &Key) -> String {
    if let Some(e) = &key.expected {
        return match &key.unit {
            Some(u) => format!("{e} (in {u})"),
            None => e.clone(),
        };
    }
    let words: Vec<String> = key
        .allowed
        .iter()
        .map(|(w, _)| w.trim_matches('"').to_string())
        .collect();
    let what = match key.ty.as_str() {
        "number" => "a number".to_string(),
        "integer" => "an integer".to_string(),
        "integer ≥ 0" => "an integer ≥ 0".to_string(),
        "bool" => "true or false".to_string(),
        "string" => "a string".to_string(),
        "word" => format!("one of {}", quoted_words(&words)),
        "expr" => "a number or an expression in x, y, z, t".to_string(),
        t if t.starts_with("table") => format!("one of the tables {}", words.join(", ")),
        t if t.starts_with("list of") => format!("a {t}"),
        t => t.to_string(),
    };
    match &key.unit {
        Some(u) => format!("{what} in {u}"),
        None => what,
    }
}

/// A hint for a value written as text: a number in quotes, or a number with a prefixed
/// unit (`"1 GPa"` for a key in Pa is `1e9`).
fn hint(shown: &str, key: &Key) -> String {
    let Some(inner) = shown.strip_prefix('"').and_then(|s| s.strip_suffix('"')) else {
        return String::new();
    };
    let inner = inner.trim();
    if inner.parse::<f64>().is_ok() && !key.ty.contains("expr") {
        return format!(" (write {inner} without quotes)");
    }
    let Some(unit) = &key.unit else {
        return String::new();
    };
    let split = inner
        .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '-' | '+')))
        .unwrap_or(inner.len());
    let (num, rest) = inner.split_at(split);
    let (Ok(x), rest) = (num.trim().parse::<f64>(), rest.trim()) else {
        return String::new();
    };
    let scale = if rest == unit {
        Some(1.0)
    } else {
        rest.strip_suffix(unit.as_str())
            .and_then(|prefix| match prefix {
                "k" => Some(1e3),
                "M" => Some(1e6),
                "G" => Some(1e9),
                "T" => Some(1e12),
                "m" => Some(1e-3),
                "µ" | "u" => Some(1e-6),
                "n" => Some(1e-9),
                "c" => Some(1e-2),
                _ => None,
            })
    };
    match scale {
        Some(s) => format!(" (write {:e})", x * s),
        None => String::new(),
    }
}

/// The text of the value at `span` (the file's or an override's), as written.
fn value_text(place: &Place<'_>, span: Option<&std::ops::Range<usize>>) -> String {
    let Some(s) = span else {
        return String::new();
    };
    if let Some(o) = place
        .overrides
        .iter()
        .find(|o| o.span.start <= s.start && s.start <= o.span.end)
    {
        // A bare word was read as a string.
        return if o.value.starts_with(['"', '\'', '[', '{'])
            || o.json.is_number()
            || o.json.is_boolean()
        {
            o.value.clone()
        } else {
            format!("\"{}\"", o.value)
        };
    }
    place.source.get(s.clone()).unwrap_or("").trim().to_string()
}

fn between<'a>(s: &'a str, open: &str, close: &str) -> Option<&'a str> {
    let start = s.find(open)? + open.len();
    let len = s[start..].find(close)?;
    Some(&s[start..start + len])
}

fn quoted(v: &[String]) -> String {
    v.iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn quoted_words(v: &[String]) -> String {
    v.iter()
        .map(|s| format!("\"{s}\""))
        .collect::<Vec<_>>()
        .join(", ")
}
