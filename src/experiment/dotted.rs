//! Dotted keys: patching TOML models (`display.buffers = 3`) and reading
//! numbers out of JSON run summaries (`metrics.frame_time_ms.mean`).

use super::ExperimentError;

/// Set `key` (dot-separated, e.g. `display.buffers`) in `table` to `value`,
/// creating intermediate tables as needed and replacing any existing value.
///
/// A segment that meets an array (an array of tables such as
/// `[[workload.groups]]`) is an index into it, counted from 0:
/// `workload.groups.0.triangle_pixels.median`. The entry must exist; arrays
/// are never extended.
///
/// Keys are split on every `.`; quoted segments are not supported. Fails
/// when a segment is empty, an intermediate key holds a non-table value, or
/// an array index is not a number or out of range.
pub fn set_dotted(table: &mut toml::Table, key: &str, value: toml::Value) -> Result<(), ExperimentError> {
    let err = |message: String| ExperimentError::Patch {
        key: key.to_string(),
        message,
    };
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.trim().is_empty()) {
        return Err(err("empty key segment".into()));
    }
    // Failures happen only at existing values, before anything new is
    // created below them, so a rejected key leaves `table` unchanged.
    let mut root = toml::Value::Table(std::mem::take(table));
    let result = set_in(&mut root, &parts, 0, value);
    if let toml::Value::Table(t) = root {
        *table = t;
    }
    result.map_err(err)
}

/// Set `parts[done..]` below `cur`, which sits at `parts[..done]`.
fn set_in(cur: &mut toml::Value, parts: &[&str], done: usize, value: toml::Value) -> Result<(), String> {
    let part = parts[done];
    let last = done + 1 == parts.len();
    let here = || parts[..done].join(".");
    match cur {
        toml::Value::Table(t) => {
            if last {
                t.insert(part.to_string(), value);
                return Ok(());
            }
            let next = t
                .entry(part.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            set_in(next, parts, done + 1, value)
        }
        toml::Value::Array(items) => {
            let len = items.len();
            let index: usize = part.parse().map_err(|_| {
                format!(
                    "`{}` is an array; `{part}` is not an index (0 to {})",
                    here(),
                    len.saturating_sub(1)
                )
            })?;
            let slot = items
                .get_mut(index)
                .ok_or_else(|| format!("`{}` has {len} entries; index {index} is out of range", here()))?;
            if last {
                *slot = value;
                return Ok(());
            }
            set_in(slot, parts, done + 1, value)
        }
        other => Err(format!(
            "`{}` is not a table (it is of type {})",
            here(),
            other.type_str()
        )),
    }
}

/// The JSON value at dotted `path` in `root`, if present.
pub fn json_path<'a>(root: &'a serde_json::Value, path: &str) -> Option<&'a serde_json::Value> {
    path.split('.').try_fold(root, |v, part| v.get(part))
}

/// The number at dotted `path` in a run summary.
///
/// `Ok(None)` for a JSON `null` (a metric with no value for this run); an
/// error naming the path, and the keys available where the lookup stopped,
/// when the path is missing or not a number. Booleans read as 0 and 1.
pub fn json_number(root: &serde_json::Value, path: &str) -> Result<Option<f64>, String> {
    let mut cur = root;
    let mut walked = Vec::new();
    for part in path.split('.') {
        match cur.get(part) {
            Some(v) => {
                cur = v;
                walked.push(part);
            }
            None => {
                let at = if walked.is_empty() {
                    "the summary".to_string()
                } else {
                    format!("`{}`", walked.join("."))
                };
                let keys = match cur {
                    serde_json::Value::Object(m) => m.keys().cloned().collect::<Vec<_>>().join(", "),
                    _ => String::new(),
                };
                return Err(if keys.is_empty() {
                    format!("metric path `{path}` not found: {at} has no key `{part}`")
                } else {
                    format!("metric path `{path}` not found: {at} has no key `{part}` (it has: {keys})")
                });
            }
        }
    }
    match cur {
        serde_json::Value::Null => Ok(None),
        serde_json::Value::Bool(b) => Ok(Some(if *b { 1.0 } else { 0.0 })),
        serde_json::Value::Number(n) => Ok(n.as_f64()),
        other => Err(format!("metric path `{path}` is not a number: {other}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_dotted_creates_and_replaces() {
        let mut t: toml::Table = "[display]\nbuffers = 2\nvsync = true\n".parse().unwrap();
        set_dotted(&mut t, "display.buffers", toml::Value::Integer(3)).unwrap();
        set_dotted(&mut t, "workload.gpu.mean", toml::Value::String("10ms".into())).unwrap();
        set_dotted(&mut t, "top", toml::Value::Float(1.5)).unwrap();
        assert_eq!(t["display"]["buffers"].as_integer(), Some(3));
        assert_eq!(t["display"]["vsync"].as_bool(), Some(true));
        assert_eq!(t["workload"]["gpu"]["mean"].as_str(), Some("10ms"));
        assert_eq!(t["top"].as_float(), Some(1.5));
    }

    #[test]
    fn set_dotted_rejects_bad_keys() {
        let mut t: toml::Table = "a = 1\n".parse().unwrap();
        let e = set_dotted(&mut t, "a.b", toml::Value::Integer(1)).unwrap_err();
        assert!(
            e.to_string().contains("`a` is not a table (it is of type integer)"),
            "{e}"
        );
        assert!(set_dotted(&mut t, "x..y", toml::Value::Integer(1)).is_err());
        assert!(set_dotted(&mut t, "", toml::Value::Integer(1)).is_err());
        // Nothing half-applied for the rejected keys.
        assert_eq!(t.len(), 1);
    }

    #[test]
    fn set_dotted_indexes_arrays_of_tables() {
        let mut t: toml::Table = "[[workload.groups]]\nname = \"a\"\n\
             triangle_pixels = { kind = \"lognormal\", median = 8.0, sigma = 0.8 }\n\
             [[workload.groups]]\nname = \"b\"\nlist = [1, 2]\n"
            .parse()
            .unwrap();
        set_dotted(
            &mut t,
            "workload.groups.0.triangle_pixels.median",
            toml::Value::Float(0.5),
        )
        .unwrap();
        set_dotted(&mut t, "workload.groups.1.count", toml::Value::Integer(4)).unwrap();
        set_dotted(&mut t, "workload.groups.1.list.1", toml::Value::Integer(7)).unwrap();
        let groups = t["workload"]["groups"].as_array().unwrap();
        assert_eq!(groups[0]["triangle_pixels"]["median"].as_float(), Some(0.5));
        assert_eq!(groups[0]["triangle_pixels"]["sigma"].as_float(), Some(0.8));
        assert_eq!(groups[0]["name"].as_str(), Some("a"));
        assert_eq!(groups[1]["count"].as_integer(), Some(4));
        assert_eq!(groups[1]["list"].as_array().unwrap()[1].as_integer(), Some(7));
        let before = t.clone();
        let e = set_dotted(&mut t, "workload.groups.2.count", toml::Value::Integer(1))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`workload.groups` has 2 entries; index 2 is out of range"),
            "{e}"
        );
        let e = set_dotted(&mut t, "workload.groups.first.count", toml::Value::Integer(1))
            .unwrap_err()
            .to_string();
        assert!(e.contains("`first` is not an index"), "{e}");
        assert_eq!(t, before, "rejected keys change nothing");
    }

    #[test]
    fn json_number_paths() {
        let v = serde_json::json!({"wall_seconds": 0.5, "metrics": {"ft": {"mean": 2, "p99": null}, "ok": true}});
        assert_eq!(json_number(&v, "wall_seconds").unwrap(), Some(0.5));
        assert_eq!(json_number(&v, "metrics.ft.mean").unwrap(), Some(2.0));
        assert_eq!(json_number(&v, "metrics.ft.p99").unwrap(), None);
        assert_eq!(json_number(&v, "metrics.ok").unwrap(), Some(1.0));
        let e = json_number(&v, "metrics.ft.p50").unwrap_err();
        assert!(e.contains("`metrics.ft` has no key `p50`") && e.contains("mean"), "{e}");
        assert!(json_number(&v, "metrics").unwrap_err().contains("not a number"));
    }
}
