//! `rendersim._native`: the library calls behind the Python package
//! (`python/rendersim/__init__.py`), each returning JSON or TOML text for
//! dicts and tables of numbers as bytes (no CSV in between) that the
//! package turns into dicts and pandas DataFrames. The simulation
//! runs with the GIL released, so Python threads go on meanwhile.
//!
//! Every error is raised as `_native.ModelError` with the message the
//! command line prints after `error: `, `file`, `line` and `key` where the
//! error names them, and `kind`: `"model"`, `"missing"` (a file that does
//! not exist; `filename` names it) or `"simulation"` (a run that failed
//! while running). The package turns it into Python's own terms
//! (`rendersim.errors`).

use std::error::Error;
use std::path::{Path, PathBuf};

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes};

use rendersim::config::{ConfigError, ModelSource, Overrides, PreparedModel, load_model, prepare};
use rendersim::output::result_set::ResultSet;
use rendersim::systems::run_model;

create_exception!(
    _native,
    ModelError,
    PyValueError,
    "A model, experiment, mesh or capture rendersim cannot use, or a run that cannot finish."
);

/// The error as a `ModelError`, with the file, line and key of the first
/// model-file error in its chain.
fn model_error(e: &(dyn Error + 'static)) -> PyErr {
    let (mut file, mut line, mut key): (Option<String>, Option<usize>, Option<String>) = (None, None, None);
    let mut cause: Option<&(dyn Error + 'static)> = Some(e);
    while let Some(c) = cause {
        if let Some(ce) = config_error(c) {
            match ce {
                ConfigError::Invalid {
                    file: f,
                    key: k,
                    line: l,
                    ..
                } => {
                    (file, line, key) = (Some(f.clone()), *l, Some(k.clone()));
                }
                ConfigError::Syntax { file: f, .. } => file = Some(f.clone()),
                ConfigError::Io { path, .. } => file = Some(path.clone()),
                ConfigError::Set { assignment, .. } => key = assignment.split('=').next().map(str::to_string),
                ConfigError::Override { .. } => {}
            }
            break;
        }
        cause = c.source();
    }
    let (kind, filename) = kind_of(e);
    let msg = rendersim::error_line(e);
    Python::attach(|py| {
        let err = ModelError::new_err(msg);
        let v = err.value(py);
        let _ = v.setattr("file", file);
        let _ = v.setattr("line", line);
        let _ = v.setattr("key", key);
        let _ = v.setattr("kind", kind);
        let _ = v.setattr("filename", filename);
        err
    })
}

/// What kind of error `e` is for Python: a file that does not exist
/// (`"missing"`, with its path where the error holds it), a run that failed
/// while running (`"simulation"`), or anything else a model, a file or an
/// argument is wrong in (`"model"`). A key whose value names a missing file
/// (a model's `hardware = `) stays a model error: the key is what to change.
fn kind_of(e: &(dyn Error + 'static)) -> (&'static str, Option<String>) {
    use rendersim::systems::SimError;
    let mut cause: Option<&(dyn Error + 'static)> = Some(e);
    while let Some(c) = cause {
        match config_error(c) {
            Some(ConfigError::Io { path, source }) if source.kind() == std::io::ErrorKind::NotFound => {
                return ("missing", Some(path.clone()));
            }
            Some(_) => return ("model", None),
            None => {}
        }
        if matches!(c.downcast_ref::<SimError>(), Some(SimError::Run { .. })) {
            return ("simulation", None);
        }
        if let Some(io) = c.downcast_ref::<std::io::Error>()
            && io.kind() == std::io::ErrorKind::NotFound
        {
            return ("missing", None);
        }
        cause = c.source();
    }
    ("model", None)
}

/// The model-file error `c` is or wraps without a cause of its own (the
/// errors that forward to a `ConfigError` transparently hide it from the
/// chain).
fn config_error<'a>(c: &'a (dyn Error + 'static)) -> Option<&'a ConfigError> {
    use rendersim::studies::replay::ReplayError;
    use rendersim::systems::SimError;
    if let Some(ce) = c.downcast_ref::<ConfigError>() {
        return Some(ce);
    }
    match c.downcast_ref::<SimError>() {
        Some(SimError::Config(ce)) => return Some(ce),
        Some(_) => return None,
        None => {}
    }
    match c.downcast_ref::<ReplayError>() {
        Some(ReplayError::Config(ce) | ReplayError::Assume(ce)) => Some(ce),
        _ => None,
    }
}

fn err<E: Error + 'static>(e: E) -> PyErr {
    model_error(&e)
}

/// An error of the package's own (an argument it cannot use).
fn usage(msg: String) -> PyErr {
    model_error(&*Box::<dyn Error + Send + Sync>::from(msg))
}

/// The model a call names: TOML text (`text`, its relative paths read
/// from the working folder), a file (`path`), or the embedded default;
/// `overrides` applied.
fn prepared(path: Option<PathBuf>, text: Option<String>, overrides: &Overrides) -> Result<PreparedModel, ConfigError> {
    match text {
        Some(t) => prepare(ModelSource::from_text("<model text>", &t), overrides),
        None => load_model(path.as_deref(), overrides),
    }
}

/// `rendersim.Model`'s view of a model: (name, system, the table as TOML,
/// the table as JSON), with `sets` applied and the whole read as its
/// system's config (a misspelt key is an error here, not at the run).
#[pyfunction]
#[pyo3(signature = (model, text, sets))]
fn resolve(
    model: Option<PathBuf>,
    text: Option<String>,
    sets: Vec<String>,
) -> PyResult<(String, String, String, String)> {
    let p = prepared(model, text, &Overrides::with_sets(&sets)).map_err(err)?;
    let system = rendersim::systems::read_model(&p.source, &p.table)
        .map_err(err)?
        .to_string();
    let toml_text = toml::to_string(&p.table).map_err(err)?;
    let json = serde_json::to_string(&p.table).map_err(err)?;
    Ok((p.source.name.clone(), system, toml_text, json))
}

/// `rendersim.run(...)`: (summary JSON, the finished run, resolved model
/// TOML, notes).
#[pyfunction]
#[pyo3(signature = (model, text, sets, seed, frames, command))]
fn run(
    py: Python<'_>,
    model: Option<PathBuf>,
    text: Option<String>,
    sets: Vec<String>,
    seed: Option<u64>,
    frames: Option<u64>,
    command: Vec<String>,
) -> PyResult<(String, RunFrames, String, Vec<String>)> {
    py.detach(move || {
        let overrides = Overrides { sets, seed, frames };
        let prepared = prepared(model, text, &overrides).map_err(err)?;
        let src = &prepared.source;
        let run = run_model(src, &prepared.table, None).map_err(err)?;
        let mut summary = run.summary();
        summary["model"] = serde_json::Value::String(src.name.clone());
        let provenance = rendersim::provenance(command);
        summary["provenance"] = serde_json::to_value(&provenance).map_err(err)?;
        let summary = serde_json::to_string_pretty(&summary).map_err(err)?;
        let model_text = provenance.toml_comment() + &run.resolved_model(&src.base_dir);
        Ok((
            summary,
            RunFrames(std::sync::Mutex::new(run)),
            model_text,
            prepared.notes.clone(),
        ))
    })
}

/// A finished run's frames, kept in Rust until Python asks: as numbers
/// (`table`, no text in between: a 200,000-frame run's 66 MB of CSV is
/// never written) or as the `frames.csv` the command line writes (`csv`,
/// for `Run.save()`).
#[pyclass(frozen, module = "rendersim._native")]
struct RunFrames(std::sync::Mutex<rendersim::systems::SystemRun>);

#[pymethods]
impl RunFrames {
    /// The frame pipeline's frames as a [`FramesTable`]; `None` for
    /// another system (read `csv`).
    fn table<'py>(&self, py: Python<'py>) -> PyResult<Option<FramesTable<'py>>> {
        use rendersim::systems::frame_pipeline::PipelineRun;
        let lock = || {
            self.0
                .lock()
                .map_err(|_| usage("the run's frames are unreadable (a panic)".into()))
        };
        let Some(rows) = lock()?
            .as_any()
            .downcast_ref::<PipelineRun>()
            .map(PipelineRun::table_rows)
        else {
            return Ok(None);
        };
        frames_table(py, rows, |put| {
            let run = lock()?;
            let run = run
                .as_any()
                .downcast_ref::<PipelineRun>()
                .ok_or_else(|| usage("the run changed while read".into()))?;
            Ok(run.frame_values_with(put))
        })
        .map(Some)
    }

    /// The frames as the command line's `frames.csv`.
    fn csv(&self, py: Python<'_>) -> PyResult<String> {
        py.detach(|| {
            let run = self
                .0
                .lock()
                .map_err(|_| usage("the run's frames are unreadable (a panic)".into()))?;
            let mut csv = Vec::new();
            run.write_frames_csv(&mut csv).map_err(err)?;
            String::from_utf8(csv).map_err(err)
        })
    }

    /// Writes the run into the folder `out` as `rendersim run --out`
    /// does: `summary.json` (`summary`), `frames.csv` and `model.toml`
    /// (`model`), staged beside it and swapped in whole, with the marker
    /// that lets the command line (and this) write there again. A folder
    /// holding files rendersim did not write is refused, and another
    /// kind's result set unless `force`. Returns the folder.
    #[pyo3(signature = (out, summary, model, force=false))]
    fn save(&self, py: Python<'_>, out: PathBuf, summary: String, model: String, force: bool) -> PyResult<String> {
        const RUN_FILES: [&str; 3] = ["summary.json", "frames.csv", "model.toml"];
        py.detach(|| {
            let run = self
                .0
                .lock()
                .map_err(|_| usage("the run's frames are unreadable (a panic)".into()))?;
            let set = ResultSet::begin_kind(&out, Some("run"), |name| RUN_FILES.contains(&name), force).map_err(err)?;
            let dir = set.dir();
            let io = |what: &str, e: std::io::Error| usage(format!("writing {what} into {}: {e}", out.display()));
            std::fs::write(dir.join("summary.json"), &summary).map_err(|e| io("summary.json", e))?;
            let mut frames = std::fs::File::create(dir.join("frames.csv")).map_err(|e| io("frames.csv", e))?;
            run.write_frames_csv(&mut frames).map_err(|e| io("frames.csv", e))?;
            drop(frames);
            std::fs::write(dir.join("model.toml"), &model).map_err(|e| io("model.toml", e))?;
            set.commit().map_err(err)?;
            Ok(out.display().to_string())
        })
    }
}

/// A frames table for Python, with no text in between: (the text columns
/// as (name, value), the same on every row; one byte a row, 1 for a
/// generated frame; the numeric column names; their values column by
/// column as little-endian `f64` bytes, NaN where `frames.csv` has `NA`, in
/// a `bytearray` so that NumPy's views of it are writable; the rows).
type FramesTable<'py> = (
    Vec<(String, String)>,
    Bound<'py, PyBytes>,
    Vec<String>,
    Bound<'py, PyByteArray>,
    usize,
);

/// A [`FramesTable`] of `rows` rows (a pipeline run's or a replay's):
/// `fill` hands every number to `put(k, value)` and returns the text
/// columns and the generated-frame flags; the numbers go straight into the
/// `bytearray` NumPy then views, without the GIL.
fn frames_table<'py, F>(py: Python<'py>, rows: usize, fill: F) -> PyResult<FramesTable<'py>>
where
    F: FnOnce(&mut dyn FnMut(usize, f64)) -> PyResult<([String; 8], Vec<bool>)> + Send,
{
    use rendersim::systems::frame_pipeline::records::COLUMNS;
    let mut parts = None;
    let values = PyByteArray::new_with(py, rows * COLUMNS.len() * 8, |buf| {
        py.detach(|| {
            parts = Some(fill(&mut |k, v| {
                buf[8 * k..8 * k + 8].copy_from_slice(&v.to_le_bytes())
            })?);
            Ok(())
        })
    })?;
    let (text, kinds) = parts.ok_or_else(|| usage("the frames were not read".into()))?;
    let (text, kinds, columns) = table_parts(text, &kinds);
    Ok((text, PyBytes::new(py, &kinds), columns, values, rows))
}

/// A frames table's text columns named, its generated-frame flags as
/// bytes, and its numeric column names.
fn table_parts(text: [String; 8], kinds: &[bool]) -> (Vec<(String, String)>, Vec<u8>, Vec<String>) {
    use rendersim::systems::frame_pipeline::records::{COLUMNS, TEXT_COLUMNS};
    let text = TEXT_COLUMNS.iter().map(|n| n.to_string()).zip(text).collect();
    let kinds = kinds.iter().map(|&g| u8::from(g)).collect();
    let columns = COLUMNS.iter().map(|c| c.to_string()).collect();
    (text, kinds, columns)
}

/// Numbers as little-endian `f64` bytes, for `numpy.frombuffer` (a
/// `bytearray`: the arrays over it are writable, no copy needed).
fn f64_bytes<'py>(py: Python<'py>, values: &[f64]) -> PyResult<Bound<'py, PyByteArray>> {
    PyByteArray::new_with(py, values.len() * 8, |buf| {
        for (cell, v) in buf.chunks_exact_mut(8).zip(values) {
            cell.copy_from_slice(&v.to_le_bytes());
        }
        Ok(())
    })
}

/// A table of numbers (the replay's comparison): (column names, values
/// column by column as little-endian `f64` bytes in a `bytearray`, NaN
/// where a value does not exist, the rows).
type NumberTable<'py> = (Vec<String>, Bound<'py, PyByteArray>, usize);

/// `(key, TOML literal)` pairs as an experiment's `[set]` entries.
fn set_entries(sets: &[String]) -> PyResult<Vec<(String, toml::Value)>> {
    sets.iter()
        .map(|s| {
            let (k, v) = s
                .split_once('=')
                .ok_or_else(|| usage(format!("set {s:?}: needs key=value")))?;
            // As `--set`: a value that is not TOML is a string.
            let value = match toml::from_str::<toml::Table>(&format!("v = {v}")) {
                Ok(t) => t["v"].clone(),
                Err(_) => toml::Value::String(v.trim().to_string()),
            };
            Ok((k.trim().to_string(), value))
        })
        .collect()
}

/// `rendersim.experiment(...)`: runs the experiment file into `out` (a
/// result set, as `rendersim experiment --out`); returns (out, the result
/// as JSON: checks failed, wall seconds, files). `progress(done, total)` is
/// called after each run; an exception it raises, or an interrupt
/// (Ctrl-C, a notebook's stop), stops the runs not yet started and is
/// raised here, the folder left as it was.
#[pyfunction]
#[pyo3(signature = (path, sets, out, force, command, progress=None))]
fn experiment(
    py: Python<'_>,
    path: PathBuf,
    sets: Vec<String>,
    out: Option<PathBuf>,
    force: bool,
    command: Vec<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(String, String)> {
    use rendersim::experiment::{Progress, SimRunner, load_experiment, run_experiment};
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicBool, Ordering};
    let entries = set_entries(&sets)?;
    let stop = AtomicBool::new(false);
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let keep = |e: PyErr| {
        if let Ok(mut r) = raised.lock() {
            r.get_or_insert(e);
        }
        stop.store(true, Ordering::Relaxed);
    };
    let observe = |done: u64, total: u64| {
        if let Some(cb) = &progress
            && !stop.load(Ordering::Relaxed)
            && let Err(e) = Python::attach(|py| cb.call1(py, (done, total)).map(drop))
        {
            keep(e);
        }
        !stop.load(Ordering::Relaxed)
    };
    let body = || {
        let mut exp = load_experiment(&path).map_err(err)?;
        exp.set.extend(entries);
        let default = ModelSource::embedded_default().table().map_err(err)?;
        let base = exp.resolve_model(&default).map_err(err)?;
        let out = out.unwrap_or_else(|| PathBuf::from("out").join(&exp.name));
        let ours = |n: &str| [".csv", ".md", ".svg", ".png"].iter().any(|e| n.ends_with(e));
        let set = ResultSet::begin_kind(&out, Some("experiment"), ours, force).map_err(err)?;
        let runner = SimRunner::for_experiment(&exp);
        let result = run_experiment(&exp, &base, &runner, set.dir(), Progress::Observe(&observe)).map_err(err)?;
        rendersim::experiment::add_provenance(set.dir(), &rendersim::provenance(command)).map_err(err)?;
        set.commit().map_err(err)?;
        let json = serde_json::json!({
            "name": exp.name,
            "points": result.points.len(),
            "checks_failed": result.checks_failed,
            "wall_seconds": result.wall_seconds,
            "sim_wall_seconds": result.sim_wall_seconds,
            "swept": exp.point_keys(),
            "files": result.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>(),
        });
        Ok::<_, PyErr>((out.display().to_string(), json.to_string()))
    };
    // The experiment runs on a thread of its own; this one waits without
    // the GIL and looks for Python's signals between waits (only the main
    // thread sees them), so Ctrl-C stops it.
    let result = std::thread::scope(|s| {
        let worker = s.spawn(body);
        while !worker.is_finished() {
            py.detach(|| std::thread::sleep(std::time::Duration::from_millis(20)));
            if let Err(e) = py.check_signals() {
                keep(e);
            }
        }
        worker.join()
    });
    let result = result.map_err(|_| usage("the experiment panicked".into()))?;
    match raised.into_inner().ok().flatten() {
        Some(e) => Err(e),
        None => result,
    }
}

/// `rendersim.vcache(mesh, policy)`: the cache statistics as JSON.
#[pyfunction]
fn vcache(py: Python<'_>, mesh: String, policy: String) -> PyResult<String> {
    py.detach(move || {
        let p: rendersim::components::vertex_cache::CachePolicy =
            policy
                .parse()
                .map_err(|e: rendersim::components::vertex_cache::CachePolicyError| {
                    usage(format!("policy {policy:?}: {e}"))
                })?;
        let start = std::time::Instant::now();
        let m = rendersim::scene::generators::mesh_from_spec(&mesh, Path::new(".")).map_err(err)?;
        let s = m.cache_stats(&p);
        Ok(serde_json::json!({
            "mesh": mesh, "policy": p.to_string(), "indices": s.indices, "triangles": s.triangles,
            "unique_vertices": s.unique_vertices, "transformed": s.transformed, "acmr": s.acmr(), "atvr": s.atvr(),
            "wall_seconds": start.elapsed().as_secs_f64(),
        })
        .to_string())
    })
}

/// `rendersim.isolate(...)`: the isolation as JSON.
#[pyfunction]
#[pyo3(signature = (model, text, sets, factor, keep_vsync, tie_tolerance, fidelity))]
#[allow(clippy::too_many_arguments)]
fn isolate(
    py: Python<'_>,
    model: Option<PathBuf>,
    text: Option<String>,
    sets: Vec<String>,
    factor: f64,
    keep_vsync: bool,
    tie_tolerance: f64,
    fidelity: String,
) -> PyResult<String> {
    use rendersim::systems::frame_pipeline::config::Fidelity;
    let fidelity = match fidelity.as_str() {
        "draw" => Some(Fidelity::Draw),
        "triangle" => Some(Fidelity::Triangle),
        "model" => None,
        other => return Err(usage(format!("fidelity {other:?}: expected draw, triangle or model"))),
    };
    py.detach(move || {
        let prepared = prepared(model, text, &Overrides::with_sets(&sets)).map_err(err)?;
        let (src, table) = (&prepared.source, &prepared.table);
        let system = table.get("system").and_then(|v| v.as_str()).unwrap_or("frame_pipeline");
        if system != "frame_pipeline" {
            return Err(usage(format!(
                "isolate applies to the frame pipeline; {} is a {system} model (`system = {system:?}`)",
                src.name
            )));
        }
        let cfg: rendersim::systems::frame_pipeline::FramePipelineConfig =
            rendersim::config::deserialize(table, src).map_err(err)?;
        let options = rendersim::studies::isolate::IsolateOptions {
            factor,
            keep_vsync,
            tie_tolerance,
            fidelity,
        };
        let iso = rendersim::studies::isolate::isolate(&cfg, &src.base_dir, options)
            .map_err(|e| err(rendersim::systems::SimError::of(src, e)))?;
        serde_json::to_string(&iso).map_err(err)
    })
}

/// `rendersim.replay(...)`: (summary JSON, the comparison as a
/// [`NumberTable`], the replayed frames and the what-if's frames (or
/// `None`) as [`FramesTable`]s; no CSV text in between).
#[pyfunction]
#[pyo3(signature = (capture, app, swapchain, sets, assume))]
fn replay<'py>(
    py: Python<'py>,
    capture: PathBuf,
    app: Option<String>,
    swapchain: Option<String>,
    sets: Vec<String>,
    assume: Vec<String>,
) -> PyResult<(String, NumberTable<'py>, FramesTable<'py>, Option<FramesTable<'py>>)> {
    let (r, summary) = py.detach(move || {
        use rendersim::studies::replay::{ReplayOptions, replay};
        let opts = ReplayOptions {
            app,
            swap_chain: swapchain,
            sets,
            assume,
            from_tables: false,
        };
        let r = replay(&capture, &opts).map_err(err)?;
        let summary = serde_json::to_string(&r.summary).map_err(err)?;
        Ok::<_, PyErr>((r, summary))
    })?;
    let (names, table) = (r.columns(), r.rows());
    // Column by column, as the frames.
    let values: Vec<f64> = (0..names.len())
        .flat_map(|c| table.iter().map(move |row| row.get(c).copied().unwrap_or(f64::NAN)))
        .collect();
    let comparison = (names, f64_bytes(py, &values)?, table.len());
    let frames_of = |f: &rendersim::studies::replay::ReplayedFrames| {
        frames_table(py, f.table_rows(), |put| Ok(f.frame_values_with(put)))
    };
    let frames = frames_of(&r.replayed)?;
    let whatif = r.whatif_replayed.as_ref().map(frames_of).transpose()?;
    Ok((summary, comparison, frames, whatif))
}

/// `rendersim.timeline(...)`: paper 000 Figure 4 for a few frames, drawn
/// to `out` (.png or .svg); returns (first frame, last frame, start ms, end
/// ms).
#[pyfunction]
#[pyo3(signature = (model, text, sets, first, frames, out))]
fn timeline(
    py: Python<'_>,
    model: Option<PathBuf>,
    text: Option<String>,
    sets: Vec<String>,
    first: u64,
    frames: u64,
    out: PathBuf,
) -> PyResult<(u64, u64, f64, f64)> {
    py.detach(move || {
        use rendersim::studies::timeline::{TimelineOptions, timeline_of};
        let max = rendersim::studies::timeline::MAX_TIMELINE_FRAMES;
        if !(1..=max).contains(&frames) {
            return Err(usage(format!("frames: draws 1 to {max} frames, got {frames}")));
        }
        rendersim::plot::ImageFormat::of(&out).map_err(err)?;
        let prepared = prepared(model, text, &Overrides::with_sets(&sets)).map_err(err)?;
        let opts = TimelineOptions { first, frames };
        let (picture, _run) = timeline_of(&prepared.source, &prepared.table, opts).map_err(err)?;
        rendersim::plot::timeline(&out, &picture).map_err(err)?;
        Ok((
            first,
            first + frames.saturating_sub(1),
            picture.range.0,
            picture.range.1,
        ))
    })
}

/// `rendersim.perceived_speed(...)`: paper 000 Figure 6 from a walkthrough,
/// drawn to `out` (.png and .svg); returns (first skip, first refresh, last
/// refresh, skips).
#[pyfunction]
#[pyo3(signature = (model, sets, around, out))]
fn perceived_speed(
    py: Python<'_>,
    model: PathBuf,
    sets: Vec<String>,
    around: u64,
    out: PathBuf,
) -> PyResult<(Option<u64>, u64, u64, u64)> {
    py.detach(move || {
        use rendersim::systems::walkthrough::perceived::figure6;
        rendersim::plot::ImageFormat::of(&out).map_err(err)?;
        let prepared = load_model(Some(&model), &Overrides::with_sets(&sets)).map_err(err)?;
        let fig = figure6(&prepared.source, &prepared.table, around, &out).map_err(err)?;
        Ok((fig.first_skip, fig.range.0, fig.range.1, fig.skips))
    })
}

/// The rendersim version and the git revision this module was built from.
#[pyfunction]
fn version() -> (String, Option<String>) {
    let p = rendersim::provenance(Vec::new());
    (p.program, p.git_revision)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("ModelError", m.py().get_type::<ModelError>())?;
    m.add_class::<RunFrames>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(resolve, m)?)?;
    m.add_function(wrap_pyfunction!(experiment, m)?)?;
    m.add_function(wrap_pyfunction!(vcache, m)?)?;
    m.add_function(wrap_pyfunction!(isolate, m)?)?;
    m.add_function(wrap_pyfunction!(replay, m)?)?;
    m.add_function(wrap_pyfunction!(timeline, m)?)?;
    m.add_function(wrap_pyfunction!(perceived_speed, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    Ok(())
}
