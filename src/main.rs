//! The `rendersim` command line: glue over the library. Arguments are turned
//! into a model table here; all logic lives in the library.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use serde_json::json;

use rendersim::config::{ModelSource, apply_set};
use rendersim::output::files::{open_output, write_output};
use rendersim::output::result_set::ResultSet;
use rendersim::output::trace::TraceWriter;
use rendersim::systems::{DEFAULT_MODEL, SystemRun, run_model};

#[derive(Parser)]
#[command(
    name = "rendersim",
    version,
    about = "Discrete-event simulator of GPU rendering pipelines and latency"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run one model (the embedded default when MODEL is omitted).
    Run {
        /// Model file (TOML).
        model: Option<PathBuf>,
        /// Override a model key: --set display.buffers=3 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Master seed (overrides run.seed).
        #[arg(long)]
        seed: Option<u64>,
        /// Frames to simulate (overrides run.frames).
        #[arg(long)]
        frames: Option<u64>,
        /// Print the JSON summary.
        #[arg(long)]
        json: bool,
        /// Write summary.json, frames.csv and model.toml into DIR.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Write a Chrome/Perfetto trace to FILE.
        #[arg(long, value_name = "FILE")]
        trace: Option<PathBuf>,
    },
    /// Run an experiment file: sweeps, replications, plots, report.
    Experiment {
        /// Experiment file (TOML).
        file: PathBuf,
        /// Output directory (default out/<experiment name>).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Hide the progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Isolate the bottleneck (paper 004 §4.1): reduce CPU, GPU front-end, geometry and raster load in turn.
    Isolate {
        /// Model file (TOML); the default model when omitted.
        model: Option<PathBuf>,
        /// Override a model key (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Load factor for the reduced subsystem.
        #[arg(long, default_value_t = 0.5)]
        factor: f64,
        /// Keep vsync on (by default it is switched off so quantization does not hide changes).
        #[arg(long)]
        keep_vsync: bool,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Simulate a post-transform vertex cache over a mesh's index buffer.
    Vcache {
        /// Mesh: grid:WxH[:shuffled:SEED|:optimized], strip:WxH, random:T:V:SEED, FILE.obj, FILE.idx.
        mesh: String,
        /// Cache policy: none, fifo:N, lru:N, meshopt:CACHE,WARP,PRIMGROUP, batch:V,T, direct:SLOTS,SEGMENT, lavapipe.
        #[arg(long)]
        policy: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Measure a mesh on a real adapter through wgpu (build with `--features wgpu`).
    Measure {
        /// Mesh spec (as for `vcache`).
        mesh: String,
        /// Extra vertex-shader ALU loop iterations.
        #[arg(long, default_value_t = 0)]
        vs_loops: u32,
        /// Extra fragment-shader ALU loop iterations.
        #[arg(long, default_value_t = 0)]
        fs_loops: u32,
        /// Depth test on.
        #[arg(long)]
        depth_test: bool,
        /// Copies of the mesh at different depths.
        #[arg(long, default_value_t = 1)]
        layers: u32,
        /// Depth order of the layers: front_to_back, back_to_front, random.
        #[arg(long, default_value = "front_to_back")]
        order: String,
        /// Render target size, WxH.
        #[arg(long, default_value = "512x512")]
        size: String,
        /// Unrecorded warm-up passes.
        #[arg(long, default_value_t = 2)]
        warmup: u32,
        /// Recorded passes (the median is reported).
        #[arg(long, default_value_t = 5)]
        repeats: u32,
        /// Collapse every vertex to one point: no fragments, the geometry stage alone.
        #[arg(long)]
        geometry_only: bool,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Hypothesis studies against real measurements (build with `--features wgpu`):
    /// h1 vertex reuse, h2 sum vs max, h3 draw order, h4 cost per vertex, or all.
    Study {
        /// Study name: h1, h2, h3, h4 or all.
        name: String,
        /// Recorded passes per timed measurement, interleaved across a study's
        /// passes (the median is used).
        #[arg(long, default_value_t = 5)]
        repeats: u32,
        /// Also write the device's Markdown document to FILE (e.g. docs/measurements/<adapter>.md).
        #[arg(long, value_name = "FILE")]
        markdown: Option<PathBuf>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Speed benchmarks, printed as ratios against baselines measured in the same run.
    Bench {
        /// Which: kernel, pipeline, hour, pixelflow, all.
        #[arg(default_value = "all")]
        which: String,
        /// Scale the work down (0.01 .. 1) for a quick check.
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        /// With `kernel`: also draw ns per event against the number pending
        /// (1e3 .. 1e6, log axes) for the engine and the bare heap, hold and
        /// stiff, into FILE (.png; an .svg beside it).
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`| head`) would
    // panic; take the default action instead: end quietly, like `cat`.
    #[cfg(unix)]
    // SAFETY: called once at start-up, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // An interrupt removes the temporary files and staging folders of
    // outputs being written; finished outputs are never touched.
    rendersim::output::cleanup::remove_on_signals();
    let cli = Cli::parse();
    match dispatch(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_line(&e));
            ExitCode::from(if e.is::<ChecksFailed>() {
                EXIT_CHECKS_FAILED
            } else {
                EXIT_ERROR
            })
        }
    }
}

/// Exit status of an error: a file, key or value that is wrong, an option
/// that does not parse, a run that cannot finish, output that cannot be
/// written (clap's own usage errors exit 2 as well).
const EXIT_ERROR: u8 = 2;

/// Exit status of `rendersim experiment` when it ran to the end but a
/// reference check (a `[[check]]` without `claim`) failed.
const EXIT_CHECKS_FAILED: u8 = 1;

/// An experiment ran, but some of its reference checks failed
/// ([`EXIT_CHECKS_FAILED`]).
#[derive(Debug, thiserror::Error)]
#[error("{failed} reference check(s) failed; see {report}")]
struct ChecksFailed {
    failed: usize,
    report: String,
}

/// The error and its causes on one line, like `{:#}`, but a cause whose text
/// the line already holds (a library error that prints its source, e.g. the
/// OS error of a file that cannot be read) is not repeated.
fn error_line(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

fn dispatch(cli: Cli) -> Result<()> {
    match cli.cmd {
        Cmd::Run {
            model,
            sets,
            seed,
            frames,
            json,
            out,
            trace,
        } => cmd_run(model, sets, seed, frames, json, out, trace),
        Cmd::Experiment { file, out, quiet } => cmd_experiment(&file, out, quiet),
        Cmd::Isolate {
            model,
            sets,
            factor,
            keep_vsync,
            json,
        } => cmd_isolate(model, sets, factor, keep_vsync, json),
        Cmd::Vcache { mesh, policy, json } => cmd_vcache(&mesh, &policy, json),
        Cmd::Measure {
            mesh,
            vs_loops,
            fs_loops,
            depth_test,
            layers,
            order,
            size,
            warmup,
            repeats,
            geometry_only,
            json,
        } => cmd_measure(
            &mesh,
            vs_loops,
            fs_loops,
            depth_test,
            layers,
            &order,
            &size,
            warmup,
            repeats,
            geometry_only,
            json,
        ),
        Cmd::Study {
            name,
            repeats,
            markdown,
            json,
        } => cmd_study(&name, repeats, markdown, json),
        Cmd::Bench { which, scale, plot } => {
            if plot.is_some() && which != "kernel" {
                bail!("--plot draws the kernel benchmark: use `rendersim bench kernel --plot FILE.png`");
            }
            rendersim::bench::run_cli(&which, scale).map_err(anyhow::Error::msg)?;
            if let Some(path) = plot {
                let cases = rendersim::bench::kernel_scaling(scale);
                rendersim::bench::plot_kernel(&cases, &path)?;
                println!("kernel scaling plot: {}", path.display());
            }
            Ok(())
        }
    }
}

fn load_source(model: Option<&Path>) -> Result<ModelSource> {
    Ok(match model {
        Some(p) => ModelSource::from_file(p)?,
        None => ModelSource::from_text("<embedded default model>", DEFAULT_MODEL),
    })
}

/// Applies `key=value` to the table and records where the value came from
/// (`origin`), so an error in it names the option rather than the file.
fn set_noted(src: &mut ModelSource, t: &mut toml::Table, assignment: &str, origin: String) -> Result<()> {
    apply_set(t, assignment)?;
    if let Some((key, _)) = assignment.split_once('=') {
        src.note_override(key.trim(), origin);
    }
    Ok(())
}

fn model_table(src: &mut ModelSource, sets: &[String], seed: Option<u64>, frames: Option<u64>) -> Result<toml::Table> {
    let mut t = src.table()?;
    for s in sets {
        set_noted(src, &mut t, s, format!("--set {s}"))?;
    }
    if let Some(seed) = seed {
        if seed > i64::MAX as u64 {
            bail!(
                "--seed {seed}: must be at most {} (model files hold 64-bit signed integers)",
                i64::MAX
            );
        }
        set_noted(src, &mut t, &format!("run.seed={seed}"), format!("--seed {seed}"))?;
    }
    if let Some(f) = frames {
        set_noted(src, &mut t, &format!("run.frames={f}"), format!("--frames {f}"))?;
        let warm = t
            .get("run")
            .and_then(|r| r.get("warmup_frames"))
            .and_then(|w| w.as_integer())
            .unwrap_or(0);
        if f > 0 && warm as u64 >= f {
            eprintln!(
                "note: run.warmup_frames = {warm} is not less than --frames {f}; using {} warm-up frames",
                f / 10
            );
            set_noted(
                src,
                &mut t,
                &format!("run.warmup_frames={}", f / 10),
                format!("--frames {f}"),
            )?;
        }
    }
    Ok(t)
}

#[allow(clippy::too_many_arguments)]
fn cmd_run(
    model: Option<PathBuf>,
    sets: Vec<String>,
    seed: Option<u64>,
    frames: Option<u64>,
    json: bool,
    out: Option<PathBuf>,
    trace: Option<PathBuf>,
) -> Result<()> {
    let mut src = load_source(model.as_deref())?;
    let table = model_table(&mut src, &sets, seed, frames)?;
    // Outputs are checked before simulating: a folder that cannot take the
    // results, or a trace path that is a folder, is reported at once.
    let set = match &out {
        Some(dir) => Some(ResultSet::begin(dir, |name| RUN_FILES.contains(&name))?),
        None => None,
    };
    // The trace is written while the simulation runs (memory stays flat).
    // A trace inside the --out folder belongs to the result set.
    let trace = trace.map(|path| match &set {
        Some(set)
            if path.file_name().is_some()
                && path.parent().and_then(|p| std::path::absolute(p).ok()).as_deref() == Some(set.target()) =>
        {
            set.dir().join(path.file_name().unwrap_or_default())
        }
        _ => path,
    });
    // With the trace on standard output, the report goes to standard error.
    let trace_on_stdout = trace.as_deref().is_some_and(is_stdout);
    let (trace_file, writer) = match &trace {
        Some(path) => {
            let (file, w) = open_output(path)?;
            (Some(file), Some(TraceWriter::new(w)))
        }
        None => (None, None),
    };
    let mut run = run_model(&src, &table, writer)?;
    run.summary_mut()["model"] = json!(src.name);
    if let Some(set) = &set {
        let dir = set.dir();
        let summary = serde_json::to_string_pretty(run.summary())?;
        std::fs::write(dir.join("summary.json"), summary).context("writing summary.json")?;
        let mut frames = std::io::BufWriter::new(std::fs::File::create(dir.join("frames.csv"))?);
        run.write_frames_csv(&mut frames).context("writing frames.csv")?;
        std::io::Write::flush(&mut frames).context("writing frames.csv")?;
        drop(frames);
        std::fs::write(dir.join("model.toml"), run.resolved_model(&src.base_dir)).context("writing model.toml")?;
    }
    // The trace first, then the folder is swapped in: a run whose trace
    // could not be written leaves the earlier results as they were.
    if let (Some(file), Some(writer), Some(path)) = (trace_file, run.take_trace(), &trace) {
        writer
            .finish()
            .with_context(|| format!("writing trace {}", path.display()))?;
        file.commit()?;
    }
    if let Some(set) = set {
        set.commit()?;
    }
    if json {
        let text = serde_json::to_string_pretty(run.summary())?;
        if trace_on_stdout {
            eprintln!("{text}");
        } else {
            println!("{text}");
        }
    } else if !trace_on_stdout {
        print_human(&run);
    }
    Ok(())
}

/// Whether `path` is this process's standard output: `-`, or the same file
/// (`/dev/stdout`, `/proc/self/fd/1`, or the file stdout is redirected to).
fn is_stdout(path: &Path) -> bool {
    if path.as_os_str() == "-" {
        return true;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(a), Ok(b)) = (std::fs::metadata(path), std::fs::metadata("/proc/self/fd/1")) {
            return a.dev() == b.dev() && a.ino() == b.ino();
        }
    }
    false
}

/// The files `run --out` writes (a folder holding only these, written
/// before result sets were marked, may be replaced).
const RUN_FILES: [&str; 3] = ["summary.json", "frames.csv", "model.toml"];

fn print_human(run: &SystemRun) {
    let s = run.summary();
    if s["system"] == "multi_rate" {
        return print_latency(s);
    }
    if s["system"] == "vr" {
        return print_vr(s);
    }
    let m = &s["metrics"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    if s["system"] == "pixelflow" {
        println!(
            "{} ({}, {}), {} nodes ({} rasterizing, {} shading), {} samples, {} primitives",
            s["model"].as_str().unwrap_or(""),
            s["architecture"].as_str().unwrap_or(""),
            s["fidelity"].as_str().unwrap_or(""),
            s["nodes"],
            s["rasterizers"],
            s["shaders"],
            s["samples"],
            s["primitives"]
        );
        println!(
            "  latency {:.3} ms (front end {:.3} + back end {:.3}); closed form {:.3} ms ({:+.2}%)",
            f(&m["latency_ms"]),
            f(&m["front_end_ms"]),
            f(&m["back_end_ms"]),
            f(&m["analytic_latency_ms"]),
            100.0 * f(&m["relative_error"])
        );
        if let Some(st) = m["stages_ms"].as_object() {
            let parts: Vec<String> = st.iter().map(|(k, v)| format!("{k} {:.3}", f(v))).collect();
            println!("  busy per unit (ms): {}", parts.join(", "));
        }
        println!(
            "  {} events in {:.4} s wall",
            s["events"]["total"],
            f(&s["wall_seconds"])
        );
        return;
    }
    let frames = match s["stopped_by"].as_str() {
        Some("time_limit") | Some("event_limit") => format!(
            "{} of {} frames completed (stopped early: {} reached at {} s simulated)",
            s["frames"],
            s["frames_requested"],
            if s["stopped_by"] == "time_limit" {
                "run.until"
            } else {
                "run.max_events"
            },
            fixed(f(&s["simulated_seconds"]), 3)
        ),
        _ => format!("{} frames", s["frames"]),
    };
    println!(
        "{} ({}), {frames}, seed {}",
        s["model"].as_str().unwrap_or(""),
        s["fidelity"].as_str().unwrap_or(""),
        s["seed"]
    );
    for (name, key) in [
        ("frame time", "frame_time_ms"),
        ("display interval", "display_interval_ms"),
        ("display latency", "display_latency_ms"),
        ("GPU time", "gpu_time_ms"),
    ] {
        let v = &m[key];
        println!(
            "  {name:<18} mean {:>8} ms   p50 {:>8}   p99 {:>8}   max {:>8}",
            fixed(f(&v["mean"]), 3),
            fixed(f(&v["p50"]), 3),
            fixed(f(&v["p99"]), 3),
            fixed(f(&v["max"]), 3)
        );
    }
    println!(
        "  CPU busy {}%   GPU busy {}%   repeated refreshes {}   dropped frames {}",
        fixed(100.0 * f(&m["cpu_busy_fraction"]), 1),
        fixed(100.0 * f(&m["gpu_busy_fraction"]), 1),
        m["repeated_refreshes"],
        m["dropped_frames"]
    );
    if let Some(b) = m["bottleneck"].as_object() {
        let mut v: Vec<(&String, f64)> = b.iter().map(|(k, v)| (k, f(v))).collect();
        v.sort_by(|a, b| b.1.total_cmp(&a.1));
        let parts: Vec<String> = v
            .iter()
            .filter(|x| x.1 > 0.0005)
            .map(|(k, x)| format!("{k} {}%", fixed(100.0 * x, 1)))
            .collect();
        println!(
            "  bottleneck: {}",
            if parts.is_empty() {
                "none (no simulated time)".to_string()
            } else {
                parts.join(", ")
            }
        );
    }
    let a = &m["analytic"];
    println!(
        "  analytic per frame: CPU {} ms, GPU front end {} ms, geometry {} ms, fragment {} ms",
        fixed(f(&a["cpu_ms"]), 3),
        fixed(f(&a["gpu_front_end_ms"]), 3),
        fixed(f(&a["geometry_ms"]), 3),
        fixed(f(&a["fragment_ms"]), 3)
    );
    println!(
        "  {} events in {} s wall ({} M events/s), {} s simulated",
        s["events"]["total"],
        fixed(f(&s["wall_seconds"]), 3),
        fixed(f(&s["events_per_second"]) / 1e6, 2),
        fixed(f(&s["simulated_seconds"]), 3)
    );
}

/// `x` with `decimals` decimals, never as a negative zero ("-0.000" for
/// -0.0 or a tiny negative rounding error reads like a negative time);
/// "n/a" for a missing number (a `null` statistic of an empty sample reads
/// as NaN here).
fn fixed(x: f64, decimals: usize) -> String {
    if x.is_nan() {
        return "n/a".to_string();
    }
    let t = format!("{x:.decimals$}");
    match t.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => t,
    }
}

fn print_latency(s: &serde_json::Value) {
    let m = &s["metrics"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    println!(
        "{} (multi_rate, {} path), {} input events, seed {}",
        s["model"].as_str().unwrap_or(""),
        s["transfer_path"].as_str().unwrap_or(""),
        s["input_events"],
        s["seed"]
    );
    for path in ["fast", "slow", "conventional"] {
        let v = &m["event_latency_ms"][path];
        if v.is_null() {
            continue;
        }
        let a = &m["analytic_latency_ms"][path];
        println!(
            "  {path:<13} latency min {:>7} mean {:>7} p99 {:>7} max {:>7} ms   paper best {:>6} worst {:>6}",
            fixed(f(&v["min"]), 1),
            fixed(f(&v["mean"]), 1),
            fixed(f(&v["p99"]), 1),
            fixed(f(&v["max"]), 1),
            fixed(f(&a["best"]), 1),
            fixed(f(&a["worst"]), 1)
        );
    }
    println!(
        "  {} events in {:.3} s wall, {:.3} s simulated",
        s["events"]["total"],
        f(&s["wall_seconds"]),
        f(&s["simulated_seconds"])
    );
}

fn print_vr(s: &serde_json::Value) {
    let m = &s["metrics"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    println!(
        "{} (vr, {} scheme), {} motion events, seed {}",
        s["model"].as_str().unwrap_or(""),
        s["scheme"].as_str().unwrap_or(""),
        s["input_events"],
        s["seed"]
    );
    for kind in ["head", "object"] {
        let v = &m["motion_to_photon_ms"][kind];
        let a = &m["analytic_latency_ms"][kind];
        println!(
            "  {kind:<7} motion-to-photon min {:>6} mean {:>6} p99 {:>6} max {:>6} ms   closed form best {:>6} worst {:>6}",
            fixed(f(&v["min"]), 1),
            fixed(f(&v["mean"]), 1),
            fixed(f(&v["p99"]), 1),
            fixed(f(&v["max"]), 1),
            fixed(f(&a["best"]), 1),
            fixed(f(&a["worst"]), 1)
        );
    }
    println!(
        "  {} events in {:.3} s wall, {:.3} s simulated",
        s["events"]["total"],
        f(&s["wall_seconds"]),
        f(&s["simulated_seconds"])
    );
}

fn cmd_experiment(file: &Path, out: Option<PathBuf>, quiet: bool) -> Result<()> {
    use rendersim::experiment::{ModelSource as ExpModel, SimRunner, load_experiment, run_experiment};
    let exp = load_experiment(file)?;
    let default = ModelSource::from_text("<embedded default model>", DEFAULT_MODEL).table()?;
    let base = exp.resolve_model(&default)?;
    let (name, base_dir, text) = match &exp.model {
        ExpModel::Default => (
            "<embedded default model>".to_string(),
            PathBuf::from("."),
            DEFAULT_MODEL.to_string(),
        ),
        ExpModel::File(p) => (
            p.display().to_string(),
            p.parent().map(Path::to_path_buf).unwrap_or_default(),
            std::fs::read_to_string(p).unwrap_or_default(),
        ),
    };
    let out = out.unwrap_or_else(|| PathBuf::from("out").join(&exp.name));
    let set = ResultSet::begin(&out, experiment_file)?;
    let runner = SimRunner {
        name,
        base_dir,
        text,
        origins: exp.value_origins(),
    };
    let result = match run_experiment(&exp, &base, &runner, set.dir(), !quiet) {
        Ok(r) => r,
        Err(e) => {
            // Keep the runs that finished beside the earlier results, which
            // stay as they were.
            let failed = sibling(&out, "failed");
            let finished =
                std::fs::read_to_string(set.dir().join("runs.csv")).map_or(0, |t| t.lines().count().saturating_sub(1));
            let kept = finished > 0 && set.commit_to(&failed).is_ok();
            let mut msg = format!("{e}\nearlier results in {} are unchanged", out.display());
            if kept {
                msg.push_str(&format!(
                    "; the {finished} run(s) that finished are in {}",
                    failed.display()
                ));
            }
            bail!(msg);
        }
    };
    set.commit()?;
    println!("{}", result.table(&exp));
    println!(
        "experiment {:?}: {} points, {:.2} s wall ({:.2} s of simulation); results in {}",
        exp.name,
        result.points.len(),
        result.wall_seconds,
        result.sim_wall_seconds,
        out.display()
    );
    if result.checks_failed > 0 {
        return Err(ChecksFailed {
            failed: result.checks_failed,
            report: out.join("report.md").display().to_string(),
        }
        .into());
    }
    Ok(())
}

/// Whether an experiment's output folder from before result sets were
/// marked holds this file (tables, report, plots).
fn experiment_file(name: &str) -> bool {
    [".csv", ".md", ".svg", ".png"].iter().any(|ext| name.ends_with(ext))
}

/// `DIR.suffix` beside `DIR`.
fn sibling(dir: &Path, suffix: &str) -> PathBuf {
    let dir = std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf());
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    dir.with_file_name(format!("{name}.{suffix}"))
}

fn cmd_isolate(model: Option<PathBuf>, sets: Vec<String>, factor: f64, keep_vsync: bool, json: bool) -> Result<()> {
    let mut src = load_source(model.as_deref())?;
    let table = model_table(&mut src, &sets, None, None)?;
    let system = table.get("system").and_then(|v| v.as_str()).unwrap_or("frame_pipeline");
    if system != "frame_pipeline" {
        bail!(
            "isolate applies to the frame pipeline; {} is a {system} model (`system = {system:?}`)",
            src.name
        );
    }
    let cfg: rendersim::systems::frame_pipeline::FramePipelineConfig = rendersim::config::deserialize(&table, &src)?;
    let iso = rendersim::systems::frame_pipeline::isolate::isolate(&cfg, &src.base_dir, factor, keep_vsync)?;
    if json {
        println!("{}", serde_json::to_string_pretty(&iso)?);
        return Ok(());
    }
    println!(
        "bottleneck isolation (load x{factor}, vsync {}):",
        if keep_vsync { "on" } else { "off" }
    );
    for v in &iso.variants {
        let change = fixed(100.0 * v.change, 1);
        println!(
            "  {:<9} frame time {:>9} ms  ({}{change}%)",
            v.name,
            fixed(v.frame_time_ms, 3),
            if change.starts_with('-') { "" } else { "+" }
        );
    }
    println!("  => bottleneck: {}   ({:.2} s wall)", iso.bottleneck, iso.wall_seconds);
    Ok(())
}

fn cmd_vcache(mesh: &str, policy: &str, json: bool) -> Result<()> {
    let policy: rendersim::components::vertex_cache::CachePolicy = policy
        .parse()
        .map_err(|e| anyhow::anyhow!("--policy {policy:?}: {e}"))?;
    let start = std::time::Instant::now();
    let m = rendersim::scene::generators::mesh_from_spec(mesh, Path::new("."))?;
    let s = m.cache_stats(&policy);
    let secs = start.elapsed().as_secs_f64();
    let out = json!({
        "mesh": mesh, "policy": policy.to_string(), "indices": s.indices, "triangles": s.triangles,
        "unique_vertices": s.unique_vertices, "transformed": s.transformed, "acmr": s.acmr(), "atvr": s.atvr(),
        "wall_seconds": secs,
    });
    if json {
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!(
            "{mesh} under {policy}: {} triangles, {} indices, {} unique vertices, {} transformed; ACMR {:.4}, ATVR {:.4}",
            s.triangles,
            s.indices,
            s.unique_vertices,
            s.transformed,
            s.acmr(),
            s.atvr()
        );
    }
    Ok(())
}

#[cfg(feature = "wgpu")]
#[allow(clippy::too_many_arguments)]
fn cmd_measure(
    mesh: &str,
    vs_loops: u32,
    fs_loops: u32,
    depth_test: bool,
    layers: u32,
    order: &str,
    size: &str,
    warmup: u32,
    repeats: u32,
    geometry_only: bool,
    json: bool,
) -> Result<()> {
    use rendersim::measure::{MeasureOptions, measure};
    let (w, h) = size
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
        .ok_or_else(|| anyhow::anyhow!("--size {size:?}: expected WxH, e.g. 512x512"))?;
    let order = order.parse().map_err(|e: String| anyhow::anyhow!("--order: {e}"))?;
    let m = rendersim::scene::generators::mesh_from_spec(mesh, Path::new("."))?;
    let opts = MeasureOptions {
        vs_loops,
        fs_loops,
        depth_test,
        layers,
        order,
        size: (w, h),
        warmup,
        repeats,
        geometry_only,
    };
    let r = measure(&m, mesh, &opts)?;
    let mut v = serde_json::to_value(&r)?;
    v["mesh"] = json!({"spec": mesh, "triangles": m.triangles(), "indices": m.index_count(), "unique_vertices": m.unique_vertices()});
    if json {
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        println!(
            "{mesh} on {} ({}, {}): VS invocations {}, clipper invocations {}, FS invocations {}, pass {:.3} ms (median of {}){}",
            r.adapter.name,
            r.adapter.driver,
            r.adapter.device_type,
            r.vs_invocations,
            r.clipper_invocations,
            r.fs_invocations,
            r.pass_time_ns / 1e6,
            r.pass_times_ns.len(),
            if r.stable_counters {
                ""
            } else {
                "; counters varied between repeats"
            }
        );
    }
    Ok(())
}

#[cfg(not(feature = "wgpu"))]
#[allow(clippy::too_many_arguments)]
fn cmd_measure(
    _mesh: &str,
    _vs_loops: u32,
    _fs_loops: u32,
    _depth_test: bool,
    _layers: u32,
    _order: &str,
    _size: &str,
    _warmup: u32,
    _repeats: u32,
    _geometry_only: bool,
    _json: bool,
) -> Result<()> {
    bail!(
        "this rendersim was built without the `wgpu` feature; rebuild with `cargo build --release --features wgpu` (and, without a GPU, install Debian's mesa-vulkan-drivers for lavapipe)"
    )
}

#[cfg(feature = "wgpu")]
fn cmd_study(name: &str, repeats: u32, markdown: Option<PathBuf>, json: bool) -> Result<()> {
    use rendersim::measure::{Gpu, studies};
    let names = studies::study_names(name).map_err(anyhow::Error::msg)?;
    if repeats == 0 {
        bail!("--repeats must be at least 1");
    }
    let gpu = Gpu::open()?;
    let command = format!("rendersim study {name} --repeats {repeats}");
    let r = studies::run_studies(&gpu, &names, repeats, &command, |s| {
        if !json {
            println!("{}: {}", s.name, s.verdict);
        }
    })?;
    if let Some(path) = markdown {
        write_output(&path, |w| w.write_all(r.document.as_bytes()))?;
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&r.json)?);
    } else {
        println!("\n{}", r.document);
    }
    if let Some(chosen) = r.h1_inexact {
        bail!("the fitted policy {chosen} does not predict every validation mesh exactly");
    }
    Ok(())
}

#[cfg(not(feature = "wgpu"))]
fn cmd_study(_name: &str, _repeats: u32, _markdown: Option<PathBuf>, _json: bool) -> Result<()> {
    bail!("this rendersim was built without the `wgpu` feature; rebuild with `cargo build --release --features wgpu`")
}
