//! The `rendersim` command line: glue over the library. Arguments are parsed
//! (`cli::args`), the library is called (`cli::commands`), results are
//! printed; all logic lives in the library.

mod cli;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use cli::args::TimelineArgs;
use cli::args::{
    BenchArgs, CalibrateArgs, ExperimentArgs, IsolateArgs, MeasureArgs, PredictArgs, RunArgs, StudyArgs, VcacheArgs,
};
use cli::commands::{self, ChecksFailed};

/// `--version`: the package's version and the git revision it was built
/// from (`-dirty` where tracked files differed), as the provenance beside
/// every result names it.
fn version() -> &'static str {
    static VERSION: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    VERSION.get_or_init(|| match option_env!("RENDERSIM_GIT_REVISION") {
        Some(rev) => format!("{} ({rev})", env!("CARGO_PKG_VERSION")),
        None => env!("CARGO_PKG_VERSION").to_string(),
    })
}

#[derive(Parser)]
#[command(
    name = "rendersim",
    version = version(),
    about = "Discrete-event simulator of GPU rendering pipelines and latency"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
    /// Largest input file to read, in bytes, for every kind of input (default 64 MiB for models, experiments, profiles, instance and shard files; 4 GiB for captures, measurement CSVs, meshes and sequences; or RENDERSIM_MAX_INPUT_BYTES)
    #[arg(long, global = true, value_name = "BYTES", value_parser = clap::value_parser!(u64).range(1..))]
    max_input_bytes: Option<u64>,
    /// Write every wall time (seconds building and simulating, events a second, an experiment's wall time) as 0, so that two result sets of one command compare byte for byte (as SOURCE_DATE_EPOCH does, which also fixes the date)
    #[arg(long, global = true)]
    no_timing: bool,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run one model (the embedded default when MODEL is omitted).
    Run(RunArgs),
    /// Run an experiment file: sweeps, replications, plots, report.
    Experiment(ExperimentArgs),
    /// Isolate the bottleneck (paper 004 §4.1): reduce CPU, GPU front-end, geometry and raster load in turn.
    Isolate(IsolateArgs),
    /// Simulate a post-transform vertex cache over a mesh's index buffer.
    Vcache(VcacheArgs),
    /// Measure a mesh on a real adapter through wgpu (build with `--features wgpu`).
    Measure(MeasureArgs),
    /// Hypothesis studies against real measurements (build with `--features wgpu`):
    /// h1 vertex reuse, h2 sum vs max, h3 draw order, h4 cost per vertex, or all;
    /// estimation (paper 000 §5 on the device); profile (passes for `calibrate`).
    Study(StudyArgs),
    /// Fit a device profile (models/devices/NAME.toml) to measured passes (CSV).
    Calibrate(CalibrateArgs),
    /// Predict one pass on a calibrated device with the frame-pipeline model.
    Predict(PredictArgs),
    /// Speed benchmarks, printed as ratios against baselines measured in the same run.
    Bench(BenchArgs),
    /// Draw a few frames as a timeline (paper 000 Figure 4): one lane per unit, frames by colour, vertical blanks marked.
    Timeline(TimelineArgs),
    /// Explore a model in the browser: a local page with its main knobs, lessons, and the timeline, latency and bottleneck redrawn on every change.
    Explore(cli::args::ExploreArgs),
    /// Replay a PresentMon capture through the frame pipeline: predicted against measured display times (--set for a what-if).
    Replay(cli::args::ReplayArgs),
    /// Level-of-detail selection on one knapsack instance (paper 001, Funkhouser & Sequin): greedy, incremental, optimal.
    LodSelect(cli::args::LodSelectArgs),
    /// State sorting with a small buffer (paper 001): state changes of LRU, bounded-waste, random, round-robin.
    Sortbuf(cli::args::SortbufArgs),
    /// Perceived movement speed per displayed refresh around a walkthrough's first frame skip (paper 000 Figure 6).
    PerceivedSpeed(cli::args::PerceivedSpeedArgs),
    /// Print a shell's completion script: `rendersim completions bash > /etc/bash_completion.d/rendersim` (or zsh, fish, elvish, powershell).
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff): `rendersim man > rendersim.1; man ./rendersim.1`.
    Man,
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`| head`) would
    // panic; take the default action instead: end quietly, like `cat`.
    #[cfg(unix)]
    // SAFETY: called once at start-up, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    #[cfg(all(unix, feature = "wgpu"))]
    quiet_vulkan_device_select();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return parse_failure(e),
    };
    // An interrupt removes the temporary files and staging folders of
    // outputs being written; finished outputs are never touched. `explore`
    // writes no file and handles Ctrl-C itself (it stops serving).
    if !matches!(cli.cmd, Cmd::Explore(_)) {
        rendersim::output::cleanup::remove_on_signals();
    }
    if let Some(bytes) = cli.max_input_bytes {
        rendersim::limits::set_max_input_bytes(bytes);
    }
    if cli.no_timing {
        // SAFETY: at start-up, before any other thread exists.
        unsafe { std::env::set_var("RENDERSIM_NO_TIMING", "1") };
    }
    // A spinner on a terminal once a command has worked for two seconds
    // (`experiment` draws its own bar over its runs).
    let _activity = (!matches!(cli.cmd, Cmd::Experiment(_) | Cmd::Explore(_)))
        .then(|| cli::progress::Activity::start(activity_label()));
    let result = match cli.cmd {
        Cmd::Run(a) => commands::run(a),
        Cmd::Experiment(a) => commands::experiment(a),
        Cmd::Isolate(a) => commands::isolate(a),
        Cmd::Vcache(a) => commands::vcache(a),
        Cmd::Measure(a) => commands::measure(a),
        Cmd::Study(a) => commands::study(a),
        Cmd::Calibrate(a) => commands::calibrate(a),
        Cmd::Predict(a) => commands::predict(a),
        Cmd::Bench(a) => commands::bench(a),
        Cmd::Timeline(a) => commands::timeline(a),
        Cmd::Replay(a) => commands::replay(a),
        Cmd::Explore(a) => commands::explore(a),
        Cmd::LodSelect(a) => commands::lod_select(a),
        Cmd::Sortbuf(a) => commands::sortbuf(a),
        Cmd::PerceivedSpeed(a) => commands::perceived_speed(a),
        Cmd::Completions { shell } => completions(shell),
        Cmd::Man => man_page(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", rendersim::error_line(e.as_ref()));
            ExitCode::from(if e.is::<ChecksFailed>() || e.is::<cli::device::HoldoutFailed>() {
                EXIT_CHECKS_FAILED
            } else {
                EXIT_ERROR
            })
        }
    }
}

/// Mesa's Vulkan device-selection layer (`VK_LAYER_MESA_device_select`, an
/// implicit layer installed with Mesa's drivers) asks a Wayland compositor
/// which GPU drives the screen. Without `XDG_RUNTIME_DIR` libwayland cannot
/// look for one and prints `error: XDG_RUNTIME_DIR is invalid or not set in
/// the environment.` on every instance, in the form of rendersim's own
/// errors, though nothing failed. Where no Wayland display can exist (no
/// `WAYLAND_DISPLAY`, no `WAYLAND_SOCKET`, no usable `XDG_RUNTIME_DIR`) the
/// layer is switched off with its own switch, `NODEVICE_SELECT=1`; it only
/// orders the adapters, and rendersim picks its adapter by power preference
/// itself. A `NODEVICE_SELECT` the user set is left as it is.
#[cfg(all(unix, feature = "wgpu"))]
fn quiet_vulkan_device_select() {
    let set = |k: &str| std::env::var_os(k).is_some_and(|v| !v.is_empty());
    let runtime_dir = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
    if !set("WAYLAND_DISPLAY")
        && !set("WAYLAND_SOCKET")
        && !runtime_dir
        && std::env::var_os("NODEVICE_SELECT").is_none()
    {
        // SAFETY: called at start-up, before any other thread exists.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

/// `rendersim completions SHELL`: the completion script clap_complete
/// writes from the command line's own definition, on standard output.
fn completions(shell: clap_complete::Shell) -> anyhow::Result<()> {
    use clap::CommandFactory;
    let mut out = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), "rendersim", &mut out);
    print_bytes(&out)
}

/// `rendersim man`: the man page clap_mangen writes from the command
/// line's own definition (the commands and global options; each command's
/// options are in its `--help`), on standard output.
fn man_page() -> anyhow::Result<()> {
    use clap::CommandFactory;
    let mut out = Vec::new();
    clap_mangen::Man::new(Cli::command()).render(&mut out)?;
    print_bytes(&out)
}

/// Ends a command line that did not parse, or that asked for `--help` or
/// `--version`: the help and version go to standard output, where a full
/// disk is an error (exit 2), as for every other output; clap's own
/// printing would drop it and exit 0.
fn parse_failure(e: clap::Error) -> ExitCode {
    if e.use_stderr() {
        let _ = e.print();
        return ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
    }
    use std::io::IsTerminal;
    let text = e.render();
    let text = if std::io::stdout().is_terminal() {
        text.ansi().to_string()
    } else {
        text.to_string()
    };
    match print_bytes(text.as_bytes()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err}");
            ExitCode::from(2)
        }
    }
}

/// Writes `bytes` to standard output (a full disk is an error, not a panic).
fn print_bytes(bytes: &[u8]) -> anyhow::Result<()> {
    use std::io::Write;
    let mut o = std::io::stdout().lock();
    o.write_all(bytes)
        .and_then(|()| o.flush())
        .map_err(|e| anyhow::anyhow!("cannot write to standard output: {e}"))
}

/// What the spinner says: the command line, shortened to fit a terminal.
fn activity_label() -> String {
    let mut line = std::env::args().skip(1).collect::<Vec<_>>().join(" ");
    if line.chars().count() > 60 {
        line = line.chars().take(59).collect::<String>() + "…";
    }
    format!("rendersim {line}")
}

/// Exit status of an error: a file, key or value that is wrong, an option
/// that does not parse, a run that cannot finish, output that cannot be
/// written (clap's own usage errors exit 2 as well).
const EXIT_ERROR: u8 = 2;

/// Exit status of `rendersim experiment` when it ran to the end but a
/// reference check (a `[[check]]` without `claim`) failed.
const EXIT_CHECKS_FAILED: u8 = 1;
