//! Patching a model table: `--set key=value` ([`apply_set`]) and the one
//! dotted-key setter under it ([`set_dotted`]), used by the command line,
//! experiments (`[set]`, sweeps, searches), benchmarks and tests alike.

use super::load::ConfigError;

/// A dotted key that could not be set; the table is left unchanged.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cannot set `{key}`: {reason}")]
pub struct PatchError {
    /// The dotted key as given.
    pub key: String,
    /// Why it could not be set.
    pub reason: String,
}

/// Applies `key.path=value` to `table`. The value is read as TOML (numbers,
/// booleans, strings in quotes, arrays, inline tables); anything that is not
/// valid TOML is taken as a plain string, so `--set workload.gpu=17ms` works.
pub fn apply_set(table: &mut toml::Table, assignment: &str) -> Result<(), ConfigError> {
    let err = |reason: String| ConfigError::Set {
        assignment: assignment.to_string(),
        reason,
    };
    let (key, raw) = assignment
        .split_once('=')
        .ok_or_else(|| err("expected key=value".into()))?;
    let key = key.trim();
    if key.is_empty() || key.split('.').any(|p| p.trim().is_empty()) {
        return Err(err("empty key".into()));
    }
    let raw = raw.trim();
    let value = match format!("v = {raw}").parse::<toml::Table>() {
        Ok(mut t) => t.remove("v").unwrap_or(toml::Value::String(raw.to_string())),
        Err(_) => toml::Value::String(raw.to_string()),
    };
    set_dotted(table, key, value).map_err(|e| err(e.reason))
}

/// Sets `key` (dot-separated, e.g. `display.buffers`) in `table` to `value`,
/// creating intermediate tables as needed and replacing any existing value.
///
/// A segment that meets an array (an array of tables such as
/// `[[workload.groups]]`) is an index into it, counted from 0:
/// `workload.groups.0.triangle_pixels.median`. The entry must exist; arrays
/// are never created or extended.
///
/// Keys are split on every `.` (whitespace around a segment is ignored);
/// quoted segments are not supported. Fails when a segment is empty, an
/// intermediate key holds a non-table value, or an array index is not a
/// number or out of range; a rejected key leaves `table` unchanged.
pub fn set_dotted(table: &mut toml::Table, key: &str, value: toml::Value) -> Result<(), PatchError> {
    let err = |reason: String| PatchError {
        key: key.to_string(),
        reason,
    };
    let parts: Vec<&str> = key.split('.').map(str::trim).collect();
    if parts.iter().any(|p| p.is_empty()) {
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

/// Sets `parts[done..]` below `cur`, which sits at `parts[..done]`.
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
            if !t.contains_key(part)
                && let Ok(index) = parts[done + 1].parse::<usize>()
            {
                // An index below a missing key: arrays are not created.
                return Err(format!(
                    "`{}` is not an array (there is no such key); index {index} is out of range",
                    parts[..=done].join(".")
                ));
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

/// Flatten nested tables into `(dotted key, value)` pairs, in table order.
pub fn flatten(prefix: &str, t: &toml::Table, out: &mut Vec<(String, toml::Value)>) {
    flatten_until(prefix, t, &|_| false, out)
}

/// [`flatten`], except that a table under a dotted key for which `whole`
/// is true is one value (a sweep of tables, say), not more keys.
pub fn flatten_until(
    prefix: &str,
    t: &toml::Table,
    whole: &dyn Fn(&str) -> bool,
    out: &mut Vec<(String, toml::Value)>,
) {
    for (k, v) in t {
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(inner) if !whole(&key) => flatten_until(&key, inner, whole, out),
            other => out.push((key, other.clone())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_patches_nested_keys() {
        let mut t: toml::Table = "[display]\nvsync = true\n[[g]]\nn = 1\n".parse().unwrap();
        apply_set(&mut t, "display.vsync=false").unwrap();
        apply_set(&mut t, "display.refresh=60Hz").unwrap();
        apply_set(&mut t, "a.b.c=3").unwrap();
        apply_set(&mut t, "g.0.n=5").unwrap();
        apply_set(&mut t, " g . 0 . m = 6").unwrap();
        assert_eq!(t["display"]["vsync"], toml::Value::Boolean(false));
        assert_eq!(t["display"]["refresh"], toml::Value::String("60Hz".into()));
        assert_eq!(t["a"]["b"]["c"], toml::Value::Integer(3));
        assert_eq!(t["g"][0]["n"], toml::Value::Integer(5));
        assert_eq!(t["g"][0]["m"], toml::Value::Integer(6));
        let before = t.clone();
        assert!(apply_set(&mut t, "novalue").is_err());
        assert!(apply_set(&mut t, "g.3.n=1").is_err());
        assert!(apply_set(&mut t, "display.vsync.x=1").is_err());
        let e = apply_set(&mut t, "h.0.n=1").unwrap_err().to_string();
        assert!(e.starts_with("--set \"h.0.n=1\": `h` is not an array"), "{e}");
        assert_eq!(t, before, "rejected assignments change nothing");
    }

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
        assert_eq!(
            e.to_string(),
            "cannot set `a.b`: `a` is not a table (it is of type integer)"
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
}
