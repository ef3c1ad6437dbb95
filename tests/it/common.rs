//! Helpers shared by the integration tests.
#![allow(dead_code)]

use rendersim::config::{ModelSource, Overrides, prepare};
use rendersim::systems::frame_pipeline::PipelineRun;
use rendersim::systems::{SystemRun, run_model};
use serde_json::Value;

/// A shipped TOML file (a model, a hardware file, an experiment) as a
/// table, by its path from the repository root.
pub fn shipped_table(rel: &str) -> toml::Table {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .parse()
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Runs a model of any system given as TOML text with `--set` patches (the
/// command line's way, [`rendersim::config::prepare`]).
pub fn try_run_any(text: &str, sets: &[&str]) -> Result<SystemRun, String> {
    let m =
        prepare(ModelSource::from_text("test.toml", text), &Overrides::with_sets(sets)).map_err(|e| e.to_string())?;
    run_model(&m.source, &m.table, None).map_err(|e| e.to_string())
}

/// Runs a shipped model file (its path from the repository root, so that
/// its `hardware` file resolves) with `--set` patches; panics on failure.
pub fn run_shipped<S: AsRef<str>>(rel: &str, sets: &[S]) -> SystemRun {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    let src = ModelSource::from_file(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let m = prepare(src, &Overrides::with_sets(sets)).unwrap_or_else(|e| panic!("{rel}: {e}"));
    run_model(&m.source, &m.table, None).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The summary of a run of any system; panics with the error on failure.
pub fn summary_of(text: &str, sets: &[&str]) -> Value {
    try_run_any(text, sets)
        .unwrap_or_else(|e| panic!("run failed: {e}"))
        .summary()
        .clone()
}

/// A number in a summary by dotted path.
pub fn num(v: &Value, path: &str) -> f64 {
    let mut x = v;
    for p in path.split('.') {
        x = &x[p];
    }
    x.as_f64().unwrap_or_else(|| panic!("{path} is not a number: {x}"))
}

/// Runs a frame-pipeline model given as TOML text with `--set` patches.
pub fn try_run(text: &str, sets: &[&str]) -> Result<PipelineRun, String> {
    try_run_any(text, sets)?
        .downcast::<PipelineRun>()
        .map_err(|other| format!("not a frame-pipeline run: {}", other.summary()["system"]))
}

/// Runs and panics with the error on failure.
pub fn run(text: &str, sets: &[&str]) -> PipelineRun {
    try_run(text, sets).unwrap_or_else(|e| panic!("run failed: {e}"))
}

/// A metric by dotted path.
pub fn metric(r: &PipelineRun, path: &str) -> f64 {
    num(&r.summary(), path)
}

/// The fixed teaching model.
pub const FIXED: &str = include_str!("../../models/fixed.toml");
/// The default model.
pub const DEFAULT: &str = include_str!("../../models/default.toml");

/// A scene model with one group, no noise, vsync off, plain costs, on the
/// split architecture (dedicated geometry and fragment units, whose busy
/// times the oracles below reason about; `tests/it/unified.rs` covers the
/// unified pool).
pub fn scene_model(group: &str) -> String {
    format!(
        r#"
fidelity = "triangle"
[run]
frames = 3
[display]
vsync = false
[noise]
enabled = false
[gpu]
architecture = "split"
[gpu.geometry]
vertex_shader = "1ns"
[gpu.fragment]
per_fragment = "1ns"
fifo_depth = 16
[workload]
kind = "scene"
depth_order = "back_to_front"
[[workload.groups]]
{group}
"#
    )
}

/// Walks a JSON value and returns the paths of nulls (NaN becomes null).
/// The statistics of an empty distribution (`count: 0`) are null by design
/// (no measurement, not a 0) and are not reported.
pub fn null_paths(v: &Value, path: &str, out: &mut Vec<String>) {
    const STATS: [&str; 6] = ["mean", "p50", "p99", "min", "max", "std"];
    match v {
        Value::Null => out.push(path.to_string()),
        Value::Object(m) if m.get("count") == Some(&Value::from(0)) => m
            .iter()
            .filter(|(k, x)| !(x.is_null() && STATS.contains(&k.as_str())))
            .for_each(|(k, x)| null_paths(x, &format!("{path}.{k}"), out)),
        Value::Object(m) => m.iter().for_each(|(k, x)| null_paths(x, &format!("{path}.{k}"), out)),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| null_paths(x, &format!("{path}[{i}]"), out)),
        _ => {}
    }
}

/// A triangle-list probe mesh of `indices` (vertices 0 ..= the largest index).
pub fn list(indices: Vec<u32>) -> rendersim::scene::mesh::Mesh {
    let vertex_count = indices.iter().copied().max().unwrap_or(0) + 1;
    rendersim::scene::mesh::Mesh {
        name: "probe".into(),
        topology: rendersim::scene::mesh::Topology::TriangleList,
        indices,
        vertex_count,
    }
}

/// A simulated latency distribution (`{dist}.min/mean/max`) lies inside its
/// closed-form bounds over all start phases (`{bounds}.phase_min/phase_max`),
/// its extremes come within `touch` of the bounds' width of them, and its
/// mean is within `mean_tol` (relative) of the closed-form mean over
/// independent uniform phases (`{bounds}.phase_mean`). Returns the mean.
pub fn check_within_phase_bounds(s: &Value, dist: &str, bounds: &str, touch: f64, mean_tol: f64) -> f64 {
    let (min, mean, max) = (
        num(s, &format!("{dist}.min")),
        num(s, &format!("{dist}.mean")),
        num(s, &format!("{dist}.max")),
    );
    let (lo, hi, mu) = (
        num(s, &format!("{bounds}.phase_min")),
        num(s, &format!("{bounds}.phase_max")),
        num(s, &format!("{bounds}.phase_mean")),
    );
    assert!(
        min >= lo - 1e-6 && max <= hi + 1e-6,
        "{dist}: [{min}, {max}] outside [{lo}, {hi}]"
    );
    let width = hi - lo;
    assert!(
        min - lo <= touch * width && hi - max <= touch * width,
        "{dist}: [{min}, {max}] vs [{lo}, {hi}]"
    );
    assert!(
        (mean - mu).abs() <= mean_tol * mu,
        "{dist}: mean {mean} vs closed form {mu}"
    );
    mean
}
