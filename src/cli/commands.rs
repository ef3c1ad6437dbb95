//! What each command does: the library called with the parsed arguments,
//! its results written to files or printed.

use super::progress::{esay, say};
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde_json::json;

use rendersim::config::{ModelSource, load_model};
use rendersim::output::files::{check_distinct, open_output};
use rendersim::output::result_set::ResultSet;
use rendersim::output::text::fixed;
use rendersim::output::trace::{TraceDetail, TraceWriter};
use rendersim::studies::isolate::IsolateOptions;
use rendersim::systems::run_model;

use super::args::TimelineArgs;
use super::args::{BenchArgs, CalibrateArgs, ExperimentArgs, IsolateArgs, PredictArgs, RunArgs, VcacheArgs};
use super::{device, print};

pub use super::measuring::{measure, study};

/// An experiment ran, but some of its reference checks failed (exit
/// status 1).
#[derive(Debug, thiserror::Error)]
#[error("{failed} reference check(s) failed; see {report}")]
pub struct ChecksFailed {
    pub(crate) failed: usize,
    pub(crate) report: String,
}

/// The files `run --out` writes (a folder holding only these, written
/// before result sets were marked, may be replaced).
const RUN_FILES: [&str; 3] = ["summary.json", "frames.csv", "model.toml"];

/// `rendersim run`.
pub fn run(args: RunArgs) -> Result<()> {
    if let (Some(m), Some(t)) = (&args.model, &args.trace) {
        check_distinct(&[("MODEL", m), ("--trace", t)])?;
    }
    let model = load_model(args.model.as_deref(), &(&args).into())?;
    for note in &model.notes {
        esay!("note: {note}");
    }
    let src = &model.source;
    // A system that writes no trace events would leave an empty trace file
    // that looks like a broken one: refused before anything is written.
    if args.trace.is_some()
        && let Some(system) = rendersim::systems::traceless_system(&model.table)
    {
        anyhow::bail!(
            "--trace: {}: system {system:?} writes no trace events (traces come from {}); leave out --trace",
            src.name,
            rendersim::systems::tracing_systems()
        );
    }
    // Outputs are checked before simulating: a folder that cannot take the
    // results, or a trace path that is a folder, is reported at once.
    let set = match &args.out {
        Some(dir) => Some(ResultSet::begin_kind(
            dir,
            Some("run"),
            |name| RUN_FILES.contains(&name),
            args.force,
        )?),
        None => None,
    };
    // The trace is written while the simulation runs (memory stays flat).
    // A trace inside the --out folder belongs to the result set and goes
    // through its commit; one that names a file of the set is refused.
    let trace = match (args.trace, &set) {
        (Some(path), Some(set)) => Some(set.place(&path, &RUN_FILES)?.unwrap_or(path)),
        (trace, _) => trace,
    };
    // With the trace on standard output, the report goes to standard error.
    let trace_on_stdout = trace.as_deref().is_some_and(is_stdout);
    let detail = args.trace_detail;
    if trace.is_some()
        && let Some((bytes, frames)) = trace_size_estimate(src, &model.table, detail)
        && bytes > TRACE_WARN_BYTES
    {
        esay!(
            "warning: the trace will be about {} ({frames} frames at about {} each, --trace-detail {}); \
             traces this large load slowly or not at all in Perfetto's UI: --trace-detail {} or fewer frames \
             (--frames N) make it smaller",
            human_bytes(bytes),
            human_bytes(bytes / frames.max(1)),
            detail.name(),
            if detail == TraceDetail::Triangle {
                "draw or frame"
            } else {
                "frame"
            }
        );
    }
    let (trace_file, writer) = match &trace {
        Some(path) => {
            let (file, w) = open_output(path)?;
            (Some(file), Some(TraceWriter::new(w).with_detail(detail)))
        }
        None => (None, None),
    };
    let mut run = run_model(src, &model.table, writer)?;
    let provenance = command_provenance();
    // The summary as written (summary.json, --json): the run's typed summary
    // as JSON, with the model's name and the provenance; wall times fixed
    // when asked.
    let summary_text = {
        let mut summary = run.summary();
        summary["model"] = json!(src.name);
        summary["provenance"] = serde_json::to_value(&provenance)?;
        rendersim::output::timing::fix_wall_times(&mut summary);
        serde_json::to_string_pretty(&summary)?
    };
    if let Some(set) = &set {
        let dir = set.dir();
        std::fs::write(dir.join("summary.json"), &summary_text).context("writing summary.json")?;
        let mut frames = std::io::BufWriter::new(std::fs::File::create(dir.join("frames.csv"))?);
        run.write_frames_csv(&mut frames).context("writing frames.csv")?;
        frames.flush().context("writing frames.csv")?;
        drop(frames);
        let model_text = provenance.toml_comment() + &run.resolved_model(&src.base_dir);
        std::fs::write(dir.join("model.toml"), model_text).context("writing model.toml")?;
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
    if args.json {
        if trace_on_stdout {
            esay!("{summary_text}");
        } else {
            say!("{summary_text}");
        }
    } else if !trace_on_stdout {
        super::progress::suspend(|| run.write_report(&src.name, &mut std::io::stdout().lock()))?;
    }
    Ok(())
}

/// Traces estimated above this get a warning before they are written.
const TRACE_WARN_BYTES: u64 = 100_000_000;

/// The size of the trace a run of `table` would write at `detail`, and its
/// frames: the model's first frames (at most 3, no warm-up) traced into a
/// counter, scaled to `run.frames`. `None` where the model gives no
/// `run.frames` or the short run fails (the real run then says why).
fn trace_size_estimate(src: &ModelSource, table: &toml::Table, detail: TraceDetail) -> Option<(u64, u64)> {
    let frames = table.get("run")?.get("frames")?.as_integer()?;
    let frames = u64::try_from(frames).ok().filter(|&f| f > 0)?;
    let pilot = frames.min(3);
    let mut short = table.clone();
    let run = short.get_mut("run")?.as_table_mut()?;
    run.insert("frames".into(), toml::Value::Integer(pilot as i64));
    run.insert("warmup_frames".into(), toml::Value::Integer(0));
    let writer = TraceWriter::new(Box::new(std::io::sink())).with_detail(detail);
    let mut r = run_model(src, &short, Some(writer)).ok()?;
    let bytes = r.take_trace()?.bytes();
    Some((bytes.saturating_mul(frames) / pilot, frames))
}

/// `1.5 GB`, `120 MB`, `900 kB`.
fn human_bytes(b: u64) -> String {
    match b {
        b if b >= 1_000_000_000 => format!("{:.1} GB", b as f64 / 1e9),
        b if b >= 1_000_000 => format!("{:.0} MB", b as f64 / 1e6),
        b => format!("{:.0} kB", b as f64 / 1e3),
    }
}

/// Where this command's results come from: this build, this process's
/// command line, now.
pub(crate) fn command_provenance() -> rendersim::output::provenance::Provenance {
    rendersim::provenance(std::env::args().collect())
}

/// `report.md` in `dir` with its `## Provenance` section (this build, this
/// command, now) added at the end.
pub(crate) fn add_report_provenance(dir: &Path) -> Result<()> {
    Ok(rendersim::experiment::add_provenance(dir, &command_provenance())?)
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

/// `rendersim experiment`.
pub fn experiment(args: ExperimentArgs) -> Result<()> {
    use rendersim::experiment::{SimRunner, load_experiment, run_experiment};
    let exp = load_experiment(&args.file)?;
    let base = exp.resolve_model(&ModelSource::embedded_default().table()?)?;
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("out").join(&exp.name));
    if args.shard.is_some() || args.merge || args.slurm {
        return super::cluster::experiment(&args, &exp, &base, &out, experiment_file);
    }
    let set = ResultSet::begin_kind(&out, Some("experiment"), experiment_file, args.force)?;
    let runner = SimRunner::for_experiment(&exp);
    let result = match run_experiment(&exp, &base, &runner, set.dir(), !args.quiet) {
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
    add_report_provenance(set.dir())?;
    set.commit()?;
    if args.json {
        say!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "experiment": result,
                "out": out.display().to_string(),
            }))?
        );
    }
    // --quiet: the final line alone (with the checks' and claims' tally).
    if !args.quiet && !args.json {
        say!("{}", result.table(&exp));
    }
    if !args.json {
        say!(
            "experiment {:?}: {} points{}, {:.2} s wall ({:.2} s of simulation); results in {}",
            exp.name,
            result.points.len(),
            result.tally(),
            result.wall_seconds,
            result.sim_wall_seconds,
            out.display()
        );
    }
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

/// `rendersim isolate`.
pub fn isolate(args: IsolateArgs) -> Result<()> {
    let model = load_model(args.model.as_deref(), &(&args).into())?;
    let (src, table) = (&model.source, &model.table);
    let system = table.get("system").and_then(|v| v.as_str()).unwrap_or("frame_pipeline");
    if system != "frame_pipeline" {
        bail!(
            "isolate applies to the frame pipeline; {} is a {system} model (`system = {system:?}`)",
            src.name
        );
    }
    let cfg = rendersim::systems::frame_pipeline::FramePipelineConfig::from_table(table, src)?;
    let (factor, keep_vsync) = (args.factor, args.keep_vsync);
    let options = IsolateOptions {
        factor,
        keep_vsync,
        tie_tolerance: args.tie_tolerance,
        fidelity: args.fidelity.forced(),
    };
    let iso = rendersim::studies::isolate::isolate(&cfg, &src.base_dir, options)?;
    if args.json {
        say!("{}", serde_json::to_string_pretty(&iso)?);
        return Ok(());
    }
    if let Some(note) = &iso.note {
        esay!("note: {note}");
    }
    say!(
        "bottleneck isolation (load x{factor}, vsync {}, {} fidelity):",
        if keep_vsync { "on" } else { "off" },
        iso.fidelity
    );
    for v in &iso.variants {
        let change = fixed(100.0 * v.change, 1);
        say!(
            "  {:<9} frame time {:>9} ms  ({}{change}%)",
            v.name,
            fixed(v.frame_time_ms, 3),
            if change.starts_with('-') { "" } else { "+" }
        );
    }
    let verdict = if iso.tied.len() > 1 {
        format!(
            "tie: {} (within {}% of the best reduction)",
            iso.tied.join(", "),
            100.0 * iso.tie_tolerance
        )
    } else {
        iso.bottleneck.clone()
    };
    say!("  => bottleneck: {verdict}   ({:.2} s wall)", iso.wall_seconds);
    Ok(())
}

/// `rendersim vcache`.
pub fn vcache(args: VcacheArgs) -> Result<()> {
    let (mesh, policy) = (&args.mesh, &args.policy);
    let start = std::time::Instant::now();
    let m = rendersim::scene::generators::mesh_from_spec(mesh, Path::new("."))?;
    let s = m.cache_stats(policy);
    let secs = start.elapsed().as_secs_f64();
    let out = json!({
        "mesh": mesh, "policy": policy.to_string(), "indices": s.indices, "triangles": s.triangles,
        "unique_vertices": s.unique_vertices, "transformed": s.transformed, "acmr": s.acmr(), "atvr": s.atvr(),
        "wall_seconds": secs,
    });
    if args.json {
        say!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        say!(
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

/// `rendersim calibrate`.
pub fn calibrate(args: CalibrateArgs) -> Result<()> {
    let mut files: Vec<(&str, &Path)> = args.files.iter().map(|f| ("FILES", f.as_path())).collect();
    files.push(("--out", &args.out));
    if let Some(r) = &args.report {
        files.push(("--report", r));
    }
    check_distinct(&files)?;
    device::calibrate(&args)
}

/// `rendersim predict`.
pub fn predict(args: PredictArgs) -> Result<()> {
    device::predict(&args)
}

/// `rendersim bench`: each benchmark's line as soon as it is measured.
pub fn bench(args: BenchArgs) -> Result<()> {
    use super::args::BenchTarget;
    use rendersim::bench::{self, Bench, KERNEL_CASES};
    if args.plot.is_some() && args.which != BenchTarget::Kernel {
        bail!("--plot draws the kernel benchmark: use `rendersim bench kernel --plot FILE.png`");
    }
    let (scale, n) = (args.scale, args.repeats);
    bench::check_scale(scale)?;
    bench::check_repeats(n)?;
    // With --json, every result goes into one object printed at the end.
    let mut json = serde_json::Map::new();
    let mut show = |name: &str, text: String, value: serde_json::Value| {
        if args.json {
            json.insert(name.to_string(), value);
        } else {
            say!("{text}");
        }
    };
    for b in Vec::<Bench>::from(args.which) {
        match b {
            Bench::Pixelflow => {
                let r = bench::pixelflow_bench(scale, n)?;
                show("pixelflow", print::pixelflow_bench(&r), serde_json::to_value(&r)?);
            }
            Bench::Kernel => {
                let mut cases = Vec::new();
                for (work, pop) in KERNEL_CASES {
                    let k = bench::kernel_case(work, pop, bench::kernel_events(pop, scale, n), n);
                    if !args.json {
                        say!("{}", print::kernel_bench(&k));
                    }
                    cases.push(k);
                }
                if let Some(path) = &args.plot {
                    bench::plot_kernel(&cases, path)?;
                    if !args.json {
                        say!("kernel scaling plot (the lines above): {}", path.display());
                    }
                }
                show("kernel", String::new(), serde_json::to_value(&cases)?);
            }
            Bench::Pipeline => {
                let r = bench::pipeline_bench(scale, n)?;
                show("pipeline", print::pipeline_bench(&r), serde_json::to_value(&r)?);
            }
            Bench::Hour => {
                let r = bench::hour_bench(scale, n)?;
                show("hour", print::hour_bench(&r), serde_json::to_value(&r)?);
            }
            Bench::Build => {
                let r = bench::build::build_bench(scale, n)?;
                show("build", print::build_bench(&r), serde_json::to_value(&r)?);
            }
            Bench::Replay => {
                let r = bench::replay::replay_bench(scale, n)?;
                show("replay", print::replay_bench(&r), serde_json::to_value(&r)?);
            }
        }
    }
    if args.json {
        say!("{}", serde_json::to_string_pretty(&json)?);
    }
    Ok(())
}

/// `rendersim timeline`: the picture of paper 000 Figure 4 for a few frames.
pub fn timeline(args: TimelineArgs) -> Result<()> {
    use rendersim::studies::timeline::{TimelineOptions, timeline_of};
    // The extension and the place are checked before simulating.
    rendersim::plot::ImageFormat::of(&args.out)?;
    rendersim::output::result_set::check_outside_sets(&args.out)?;
    let model = load_model(
        args.model.as_deref(),
        &rendersim::config::Overrides::with_sets(&args.sets),
    )?;
    let opts = TimelineOptions {
        first: args.from,
        frames: args.frames,
    };
    let (picture, _run) = timeline_of(&model.source, &model.table, opts)?;
    rendersim::plot::timeline(&args.out, &picture)?;
    say!(
        "wrote {}: frames {}-{}, {:.3}-{:.3} ms",
        args.out.display(),
        opts.first,
        opts.first + opts.frames - 1,
        picture.range.0,
        picture.range.1
    );
    Ok(())
}

/// `rendersim explore`: serves the page until Ctrl-C.
pub fn explore(args: super::args::ExploreArgs) -> Result<()> {
    use rendersim::explore::{page_run::Explorer, server};
    let mut sets = args.sets.clone();
    if !sets
        .iter()
        .any(|s| s.split('=').next().is_some_and(|k| k.trim() == "fidelity"))
    {
        sets.insert(0, "fidelity=\"draw\"".to_string());
    }
    let explorer = Explorer::new(args.model.as_deref(), sets, args.budget_events)?;
    let ip = args
        .listen
        .unwrap_or(std::net::IpAddr::V4(std::net::Ipv4Addr::LOCALHOST));
    let addr = std::net::SocketAddr::new(ip, args.port).to_string();
    let name = explorer.name().to_string();
    server::serve(explorer, &addr, |at| {
        let url = format!("http://{at}/");
        say!("rendersim explore: {name} at {url} (Ctrl-C stops)");
        if args.open {
            open_in_browser(&url);
        }
    })?;
    say!("rendersim explore: stopped");
    Ok(())
}

/// Opens `url` with the system's opener, or says how to open it.
fn open_in_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") { "open" } else { "xdg-open" };
    let started = std::process::Command::new(opener)
        .arg(url)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
    if started.is_err() {
        esay!("note: --open: cannot start {opener}; open {url} in a browser");
    }
}

/// `rendersim lod-select`.
pub fn lod_select(args: super::args::LodSelectArgs) -> Result<()> {
    super::lod::lod_select(&args)
}

/// `rendersim sortbuf`.
pub fn sortbuf(args: super::args::SortbufArgs) -> Result<()> {
    super::lod::sortbuf(&args)
}

/// `rendersim perceived-speed`: paper 000 Figure 6 from a walkthrough.
pub fn perceived_speed(args: super::args::PerceivedSpeedArgs) -> Result<()> {
    use rendersim::systems::walkthrough::perceived::figure6;
    rendersim::plot::ImageFormat::of(&args.out)?;
    rendersim::output::result_set::check_outside_sets(&args.out)?;
    let model = load_model(
        Some(args.model.as_path()),
        &rendersim::config::Overrides::with_sets(&args.sets),
    )?;
    let fig = figure6(&model.source, &model.table, args.around, &args.out)?;
    match fig.first_skip {
        Some(r) => say!(
            "wrote {} (.png and .svg): refreshes {}-{}, centred on the frame skip at refresh {r}, {} skips in the run",
            args.out.with_extension("").display(),
            fig.range.0,
            fig.range.1,
            fig.skips
        ),
        None => say!(
            "wrote {} (.png and .svg): refreshes {}-{}, no frame skip in the run",
            args.out.with_extension("").display(),
            fig.range.0,
            fig.range.1
        ),
    }
    Ok(())
}

/// The files `replay --out` writes.
const REPLAY_FILES: [&str; 6] = [
    "replay.json",
    "frames.csv",
    "comparison.csv",
    "model.toml",
    "whatif-frames.csv",
    "whatif-model.toml",
];

/// The JSON document `replay` writes: its summary under `replay`, where it
/// came from under `provenance`.
#[derive(serde::Serialize)]
struct ReplayJson<'a> {
    replay: &'a rendersim::studies::replay::ReplaySummary,
    provenance: rendersim::output::provenance::Provenance,
}

/// Whether a file name is one a replay's validation report writes.
fn is_report_file(name: &str) -> bool {
    let chain = |rest: &str| {
        let stem = rest.split('-').next().unwrap_or_default();
        !stem.is_empty() && stem.bytes().all(|b| b.is_ascii_digit())
    };
    matches!(name, "report.md" | "chains.csv")
        || name.strip_prefix("chain-").is_some_and(|rest| {
            chain(rest) && (rest.ends_with(".csv") || rest.ends_with("-screen.png") || rest.ends_with("-screen.svg"))
        })
}

/// `rendersim replay`: a PresentMon capture through the frame pipeline.
pub fn replay(args: super::args::ReplayArgs) -> Result<()> {
    use rendersim::studies::replay::{ReplayOptions, replay};
    if let (Some(out), Some(report)) = (&args.out, &args.report)
        && std::path::absolute(out).ok() == std::path::absolute(report).ok()
    {
        anyhow::bail!(
            "--out and --report name the same folder {}: give each its own",
            out.display()
        );
    }
    let report_set = match &args.report {
        Some(dir) => Some(ResultSet::begin_kind(
            dir,
            Some("replay --report"),
            is_report_file,
            args.force,
        )?),
        None => None,
    };
    let set = match &args.out {
        Some(dir) => Some(ResultSet::begin_kind(
            dir,
            Some("replay"),
            |name| REPLAY_FILES.contains(&name),
            args.force,
        )?),
        None => None,
    };
    let opts = ReplayOptions {
        app: args.app.clone(),
        swap_chain: args.swapchain.clone(),
        sets: args.sets.clone(),
        assume: args.assume.clone(),
        from_tables: false,
    };
    let mut r = replay(&args.capture, &opts)?;
    if let Some(measured) = &args.compare {
        r.summary.compare = Some(rendersim::studies::replay::compare::compare(&r, measured)?);
    }
    if let Some(set) = report_set {
        let report = rendersim::studies::replay::validation::validate(&args.capture, &opts)?;
        report.write(set.dir()).context("writing the validation report")?;
        set.commit()?;
    }
    let provenance = command_provenance();
    let mut json = serde_json::to_value(ReplayJson {
        replay: &r.summary,
        provenance: provenance.clone(),
    })?;
    rendersim::output::timing::fix_wall_times(&mut json);
    let json = serde_json::to_string_pretty(&json)?;
    if let Some(set) = set {
        let dir = set.dir();
        std::fs::write(dir.join("replay.json"), &json).context("writing replay.json")?;
        let write = |name: &str, body: &dyn Fn(&mut dyn Write) -> std::io::Result<()>| -> Result<()> {
            let mut f = std::io::BufWriter::new(
                std::fs::File::create(dir.join(name)).with_context(|| format!("writing {name}"))?,
            );
            body(&mut f)
                .and_then(|()| f.flush())
                .with_context(|| format!("writing {name}"))
        };
        write("frames.csv", &|w| r.replayed.write_csv(w))?;
        if let Some(wf) = &r.whatif_replayed {
            write("whatif-frames.csv", &|w| wf.write_csv(w))?;
        }
        write("comparison.csv", &|w| {
            rendersim::output::table::write_number_table(w, &r.columns(), &r.rows())
        })?;
        let models = [
            ("model.toml", Some(&r.model)),
            ("whatif-model.toml", r.whatif_model.as_ref()),
        ];
        for (name, model) in models {
            let Some(model) = model else { continue };
            let text = model.to_toml().with_context(|| format!("writing {name}"))?;
            std::fs::write(
                dir.join(name),
                format!(
                    "{}# The replay's model; the workload lists (one value per frame) are left out.\n{text}",
                    provenance.toml_comment()
                ),
            )
            .with_context(|| format!("writing {name}"))?;
        }
        set.commit()?;
    }
    if args.json {
        say!("{json}");
        return Ok(());
    }
    super::progress::suspend(|| {
        rendersim::studies::replay::report::write_text(&r.summary, &mut std::io::stdout().lock())
    })?;
    Ok(())
}
