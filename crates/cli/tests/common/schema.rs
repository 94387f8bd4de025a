//! A validator of the JSON Schema keywords docs/summary.schema.json uses (`type`,
//! `properties`, `required`, `additionalProperties`, `items`, `minItems`, `maxItems`,
//! `minimum`, `enum`, `const`, `anyOf`, `oneOf`, `$ref` into `$defs`), so every
//! `summary.json` the tests read is checked against the published schema.

use serde_json::Value;

/// The schema of `summary.json` (docs/summary.schema.json).
pub fn summary_schema() -> Value {
    let path = super::root().join("docs/summary.schema.json");
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// `Err` names the first place where `v` does not match `schema`, and why.
pub fn validate(schema: &Value, v: &Value) -> Result<(), String> {
    check(schema, schema, v, "$")
}

fn check(root: &Value, s: &Value, v: &Value, at: &str) -> Result<(), String> {
    if let Some(b) = s.as_bool() {
        return if b {
            Ok(())
        } else {
            Err(format!("{at}: no value is allowed here"))
        };
    }
    if let Some(r) = s.get("$ref").and_then(Value::as_str) {
        let name = r.trim_start_matches("#/$defs/");
        let def = root
            .get("$defs")
            .and_then(|d| d.get(name))
            .ok_or_else(|| format!("{at}: the schema has no definition {r}"))?;
        check(root, def, v, at)?;
    }
    if let Some(t) = s.get("type") {
        let types: Vec<&str> = match t {
            Value::String(t) => vec![t.as_str()],
            Value::Array(a) => a.iter().filter_map(Value::as_str).collect(),
            _ => Vec::new(),
        };
        if !types.iter().any(|t| is_type(v, t)) {
            return Err(format!("{at}: {v} is not of type {types:?}"));
        }
    }
    if let Some(c) = s.get("const")
        && c != v
    {
        return Err(format!("{at}: {v} is not {c}"));
    }
    if let Some(e) = s.get("enum").and_then(Value::as_array)
        && !e.contains(v)
    {
        return Err(format!("{at}: {v} is not one of {e:?}"));
    }
    if let Some(any) = s.get("anyOf").and_then(Value::as_array)
        && !any.iter().any(|a| check(root, a, v, at).is_ok())
    {
        return Err(format!("{at}: {v} matches none of the forms of anyOf"));
    }
    if let Some(one) = s.get("oneOf").and_then(Value::as_array) {
        let n = one.iter().filter(|a| check(root, a, v, at).is_ok()).count();
        if n != 1 {
            return Err(format!("{at}: {v} matches {n} forms of oneOf, not 1"));
        }
    }
    if let (Some(min), Some(x)) = (s.get("minimum").and_then(Value::as_f64), v.as_f64())
        && x < min
    {
        return Err(format!("{at}: {x} < minimum {min}"));
    }
    if let Value::Object(o) = v {
        let props = s.get("properties").and_then(Value::as_object);
        if let Some(req) = s.get("required").and_then(Value::as_array) {
            for r in req.iter().filter_map(Value::as_str) {
                if !o.contains_key(r) {
                    return Err(format!("{at}: the required key `{r}` is missing"));
                }
            }
        }
        for (k, x) in o {
            let here = format!("{at}.{k}");
            match props.and_then(|p| p.get(k)) {
                Some(ps) => check(root, ps, x, &here)?,
                None => match s.get("additionalProperties") {
                    Some(Value::Bool(false)) => {
                        return Err(format!("{here}: the schema does not allow this key"));
                    }
                    Some(extra) if extra.is_object() => check(root, extra, x, &here)?,
                    _ => {}
                },
            }
        }
    }
    if let Value::Array(a) = v {
        let n = |k: &str| s.get(k).and_then(Value::as_u64);
        if let Some(min) = n("minItems")
            && (a.len() as u64) < min
        {
            return Err(format!("{at}: {} items, fewer than {min}", a.len()));
        }
        if let Some(max) = n("maxItems")
            && (a.len() as u64) > max
        {
            return Err(format!("{at}: {} items, more than {max}", a.len()));
        }
        if let Some(items) = s.get("items") {
            for (i, x) in a.iter().enumerate() {
                check(root, items, x, &format!("{at}[{i}]"))?;
            }
        }
    }
    Ok(())
}

fn is_type(v: &Value, t: &str) -> bool {
    match t {
        "object" => v.is_object(),
        "array" => v.is_array(),
        "string" => v.is_string(),
        "number" => v.is_number(),
        "integer" => v.is_i64() || v.is_u64(),
        "boolean" => v.is_boolean(),
        "null" => v.is_null(),
        _ => false,
    }
}
