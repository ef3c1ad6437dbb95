//! Dotted paths into JSON run summaries (`metrics.frame_time_ms.mean`).
//! (Patching a model's dotted keys is [`crate::config::set_dotted`].)

/// The JSON value at dotted `path` in `root`, if present.
pub fn json_path<'a>(root: &'a serde_json::Value, path: &str) -> Option<&'a serde_json::Value> {
    path.split('.').try_fold(root, |v, part| v.get(part))
}

/// A metric path that does not lead to a number in a run summary.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MetricPathError {
    /// The lookup stopped at a missing key.
    #[error(
        "metric path `{path}` not found: {at} has no key `{part}`{}",
        if keys.is_empty() { String::new() } else { format!(" (it has: {keys})") }
    )]
    NotFound {
        /// The path asked for.
        path: String,
        /// Where the lookup stopped: `the summary` or a quoted dotted path.
        at: String,
        /// The missing key.
        part: String,
        /// The keys available there, comma-separated (empty: not a table).
        keys: String,
    },
    /// The path leads to a value that is not a number.
    #[error("metric path `{path}` is not a number: {value}")]
    NotANumber {
        /// The path asked for.
        path: String,
        /// The value found there, as JSON.
        value: String,
    },
}

/// The number at dotted `path` in a run summary.
///
/// `Ok(None)` for a JSON `null` (a metric with no value for this run); an
/// error naming the path, and the keys available where the lookup stopped,
/// when the path is missing or not a number. Booleans read as 0 and 1.
pub fn json_number(root: &serde_json::Value, path: &str) -> Result<Option<f64>, MetricPathError> {
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
                return Err(MetricPathError::NotFound {
                    path: path.to_string(),
                    at,
                    part: part.to_string(),
                    keys,
                });
            }
        }
    }
    match cur {
        serde_json::Value::Null => Ok(None),
        serde_json::Value::Bool(b) => Ok(Some(if *b { 1.0 } else { 0.0 })),
        serde_json::Value::Number(n) => Ok(n.as_f64()),
        other => Err(MetricPathError::NotANumber {
            path: path.to_string(),
            value: other.to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_number_paths() {
        let v = serde_json::json!({"wall_seconds": 0.5, "metrics": {"ft": {"mean": 2, "p99": null}, "ok": true}});
        assert_eq!(json_number(&v, "wall_seconds").unwrap(), Some(0.5));
        assert_eq!(json_number(&v, "metrics.ft.mean").unwrap(), Some(2.0));
        assert_eq!(json_number(&v, "metrics.ft.p99").unwrap(), None);
        assert_eq!(json_number(&v, "metrics.ok").unwrap(), Some(1.0));
        let e = json_number(&v, "metrics.ft.p50").unwrap_err().to_string();
        assert!(e.contains("`metrics.ft` has no key `p50`") && e.contains("mean"), "{e}");
        assert!(
            json_number(&v, "metrics")
                .unwrap_err()
                .to_string()
                .contains("not a number")
        );
        let e = json_number(&v, "wall_seconds.x").unwrap_err().to_string();
        assert_eq!(
            e,
            "metric path `wall_seconds.x` not found: `wall_seconds` has no key `x`"
        );
    }
}
