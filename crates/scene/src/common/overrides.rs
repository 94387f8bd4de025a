//! `--set KEY=VALUE`: a key of the scene file given on the command line.
//!
//! The key is dotted like a TOML key (`rock.E` is `[rock] E`; `material.rock.youngs_modulus`
//! is `[material.rock] youngs_modulus`); a part that is a number counts the tables of an
//! array of tables from 1 (`bc.2.value` is `value` in the second `[[bc]]`). The value is
//! read as a TOML value (`2e10`, `5`, `true`, `[40, 20]`, `"voronoi"`); a bare word that
//! is not TOML is taken as a string (`grid.kind=voronoi`). Overrides are applied in order
//! to the parsed document before the typed read, so every check of the scene applies to
//! them, and an error in one names `--set KEY` instead of a line of the file. A table on
//! the way that the file does not have is created (`schedule.dt=1` in a file without
//! `[schedule]`); an index past the tables the file has is an error.

use std::borrow::Cow;
use std::ops::Range;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use crate::common::sections::KeyPart;

/// Most `--set` overrides of one command.
pub const MAX_OVERRIDES: usize = 1000;

/// Deepest nesting of arrays and inline tables in an override value (as in a scene file,
/// [`crate::common::loaded::MAX_TOML_NESTING`]).
const MAX_VALUE_NESTING: usize = crate::common::loaded::MAX_TOML_NESTING;

/// One `--set KEY=VALUE` of the command line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Override {
    /// The dotted key as written.
    pub key: String,
    /// The value as written.
    pub value: String,
}

impl Override {
    /// Split `KEY=VALUE` at the first `=`; `Err` says what is wrong, in words.
    pub fn parse(arg: &str) -> Result<Self, String> {
        let Some((key, value)) = arg.split_once('=') else {
            return Err(format!(
                "--set {}: expected KEY=VALUE, e.g. --set material.rock.youngs_modulus=2e10",
                crate::common::loaded::echo(arg)
            ));
        };
        let key = key.trim();
        parts(key)?;
        Ok(Self {
            key: key.to_string(),
            value: value.trim().to_string(),
        })
    }
}

/// An override applied to a document.
#[derive(Clone, Debug, PartialEq)]
pub struct Applied {
    /// The key as written.
    pub key: String,
    /// Its key path in the document (array indices from 0).
    pub path: Vec<KeyPart>,
    /// The value's byte range in the parse source ([`source`]).
    pub span: Range<usize>,
    /// The value as written.
    pub value: String,
    /// The value as JSON, for `summary.json`.
    pub json: serde_json::Value,
}

/// The key path of a dotted key; numbers are 1-based indices of arrays of tables.
pub fn parts(key: &str) -> Result<Vec<KeyPart>, String> {
    let bad = |why: &str| format!("--set {}: {why}", crate::common::loaded::echo(key));
    if key.is_empty() {
        return Err(bad("the key is empty; write KEY=VALUE"));
    }
    key.split('.')
        .map(|p| {
            let p = p.trim();
            if p.is_empty() {
                Err(bad("a part of the key is empty"))
            } else if p.bytes().all(|b| b.is_ascii_digit()) {
                match p.parse::<usize>() {
                    Ok(n) if n >= 1 => Ok(KeyPart::Index(n - 1)),
                    _ => Err(bad(&format!(
                        "`{p}`: tables of an array of tables are counted from 1"
                    ))),
                }
            } else {
                Ok(KeyPart::Key(p.to_string()))
            }
        })
        .collect()
}

/// The text parsed for a scene with overrides: the file, then each override value on a
/// line of its own.
pub fn source(text: &str, overrides: &[Override]) -> String {
    let mut s = String::with_capacity(text.len() + overrides.len() * 16);
    s.push_str(text);
    for o in overrides {
        s.push('\n');
        s.push_str(&o.value);
    }
    s
}

/// The byte ranges of the override values in [`source`].
fn value_ranges(text_len: usize, overrides: &[Override]) -> Vec<Range<usize>> {
    let mut at = text_len;
    overrides
        .iter()
        .map(|o| {
            let start = at + 1;
            at = start + o.value.len();
            start..at
        })
        .collect()
}

/// Apply `overrides` in order to `doc`, parsed from `source[..text_len]`; `Err` is the
/// message of the first that cannot be applied.
pub fn apply<'a>(
    doc: &mut DeTable<'a>,
    source: &'a str,
    text_len: usize,
    overrides: &[Override],
) -> Result<Vec<Applied>, String> {
    if overrides.len() > MAX_OVERRIDES {
        return Err(format!(
            "{} --set options, more than the {MAX_OVERRIDES} a command may have",
            overrides.len()
        ));
    }
    let mut applied = Vec::with_capacity(overrides.len());
    for (o, span) in overrides.iter().zip(value_ranges(text_len, overrides)) {
        let path = parts(&o.key)?;
        let raw = &source[span.clone()];
        if nesting(raw) > MAX_VALUE_NESTING {
            return Err(format!(
                "--set {}: the value nests arrays and tables more than {MAX_VALUE_NESTING} levels deep",
                o.key
            ));
        }
        let value = match DeValue::parse(raw) {
            Ok(v) => respan(v.into_inner(), &span),
            Err(_) => Spanned::new(span.clone(), DeValue::String(Cow::Borrowed(raw))),
        };
        set(doc, &path, value, &span).map_err(|why| format!("--set {}: {why}", o.key))?;
        applied.push(Applied {
            key: o.key.clone(),
            path,
            span,
            value: o.value.clone(),
            json: json_of(&o.value),
        });
    }
    Ok(applied)
}

/// The value of an override as JSON: a TOML value converted, else the text as a string.
fn json_of(value: &str) -> serde_json::Value {
    toml::from_str::<toml::Table>(&format!("v = {value}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .and_then(|v| serde_json::to_value(v).ok())
        .unwrap_or_else(|| serde_json::Value::String(value.to_string()))
}

/// Depth of `[`/`{` nesting of a value (outside strings).
fn nesting(s: &str) -> usize {
    let (mut depth, mut most, mut quote) = (0usize, 0usize, None);
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        match (quote, c) {
            (Some('"'), '\\') => {
                chars.next();
            }
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quote = Some(c),
            (None, '[' | '{') => {
                depth += 1;
                most = most.max(depth);
            }
            (None, ']' | '}') => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    most
}

/// `v` with every span (of its elements and keys too) set to `span`: the whole value
/// of the override, where its errors point.
fn respan<'a>(v: DeValue<'a>, span: &Range<usize>) -> Spanned<DeValue<'a>> {
    let v = match v {
        DeValue::Array(mut items) => {
            for item in items.iter_mut() {
                let inner = std::mem::replace(item, Spanned::new(0..0, DeValue::Boolean(false)));
                *item = respan(inner.into_inner(), span);
            }
            DeValue::Array(items)
        }
        DeValue::Table(t) => {
            let mut out = DeTable::new();
            for (k, v) in t {
                out.insert(
                    Spanned::new(span.clone(), k.into_inner()),
                    respan(v.into_inner(), span),
                );
            }
            DeValue::Table(out)
        }
        other => other,
    };
    Spanned::new(span.clone(), v)
}

/// Set the key at `path` of `table` to `value`, creating the tables on the way.
fn set<'a>(
    table: &mut DeTable<'a>,
    path: &[KeyPart],
    value: Spanned<DeValue<'a>>,
    span: &Range<usize>,
) -> Result<(), String> {
    let Some((first, rest)) = path.split_first() else {
        return Err("the key is empty".into());
    };
    let KeyPart::Key(name) = first else {
        return Err("a number must follow the name of an array of tables".into());
    };
    if rest.is_empty() {
        let existing = table.iter().position(|(k, _)| k.get_ref() == name);
        match existing {
            Some(_) => {
                // Replace the value, keeping the key where the file wrote it.
                if let Some((_, v)) = table.iter_mut().find(|(k, _)| k.get_ref() == name) {
                    *v = value;
                }
            }
            None => {
                table.insert(Spanned::new(span.clone(), Cow::Owned(name.clone())), value);
            }
        }
        return Ok(());
    }
    if !table.iter().any(|(k, _)| k.get_ref() == name) {
        table.insert(
            Spanned::new(span.clone(), Cow::Owned(name.clone())),
            Spanned::new(span.clone(), DeValue::Table(DeTable::new())),
        );
    }
    let Some((_, v)) = table.iter_mut().find(|(k, _)| k.get_ref() == name) else {
        return Err(format!("cannot set `{name}`"));
    };
    match (v.get_mut(), rest) {
        (DeValue::Table(t), _) => set(t, rest, value, span),
        (DeValue::Array(items), [KeyPart::Index(i), tail @ ..]) => {
            let n = items.len();
            let Some(item) = items.get_mut(*i) else {
                return Err(format!("the scene has {n} `{name}` entries, not {}", i + 1));
            };
            if tail.is_empty() {
                *item = value;
                return Ok(());
            }
            match item.get_mut() {
                DeValue::Table(t) => set(t, tail, value, span),
                _ => Err(format!("element {} of `{name}` is not a table", i + 1)),
            }
        }
        (DeValue::Array(_), _) => Err(format!(
            "`{name}` is an array: give the 1-based number of an element, e.g. `{name}.1.…`"
        )),
        _ => Err(format!("`{name}` is a value, not a table")),
    }
}

/// The model `[scene] model` of a parsed document names (`"continuum"` when absent or
/// not a string).
pub fn model_of(doc: &DeTable<'_>) -> String {
    doc.iter()
        .find(|(k, _)| k.get_ref() == "scene")
        .and_then(|(_, v)| match v.get_ref() {
            DeValue::Table(t) => t.iter().find(|(k, _)| k.get_ref() == "model"),
            _ => None,
        })
        .and_then(|(_, v)| match v.get_ref() {
            DeValue::String(s) => Some(s.to_string()),
            _ => None,
        })
        .unwrap_or_else(|| "continuum".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_split_into_parts_with_one_based_indices() {
        assert_eq!(
            parts("bc.2.value").unwrap(),
            vec![
                KeyPart::Key("bc".into()),
                KeyPart::Index(1),
                KeyPart::Key("value".into())
            ]
        );
        assert_eq!(
            parts("bc.0.value").unwrap_err(),
            "--set bc.0.value: `0`: tables of an array of tables are counted from 1"
        );
        assert_eq!(
            Override::parse("rock.E").unwrap_err(),
            "--set rock.E: expected KEY=VALUE, e.g. --set material.rock.youngs_modulus=2e10"
        );
        assert_eq!(nesting("[[1], {a = \"[[[\"}]"), 2);
    }

    #[test]
    fn values_are_toml_or_else_strings() {
        assert_eq!(json_of("2e10"), serde_json::json!(2e10));
        assert_eq!(json_of("5"), serde_json::json!(5));
        assert_eq!(json_of("[40, 20]"), serde_json::json!([40, 20]));
        assert_eq!(json_of("voronoi"), serde_json::json!("voronoi"));
        assert_eq!(json_of("\"a b\""), serde_json::json!("a b"));
    }
}
