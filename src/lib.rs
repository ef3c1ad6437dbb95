//! rendersim: a discrete-event simulator of GPU rendering pipelines and latency.
//!
//! The workspace's crates are its layers, from the bottom up (see
//! `docs/ARCHITECTURE.md`); this crate re-exports each under its old name,
//! so `rendersim::engine`, `rendersim::systems`, ... name the same items
//! whichever crate holds them:
//! - [`engine`] (`rendersim-engine`): integer-picosecond time, the event
//!   queue, the run loop, RNG streams. Knows nothing of GPUs.
//! - [`output`], [`stats`], [`plot`] (`rendersim-report`): tables, traces,
//!   result sets, statistics and plots, shared by every system.
//! - [`config`], [`components`], [`scene`], [`systems`], [`limits`]
//!   (`rendersim-models`): model files, reusable parts, workloads, the
//!   simulated systems.
//! - [`measure`] (`rendersim-measure`): real measurements through wgpu,
//!   device profiles, calibration and predictions.
//! - here: [`explore`] (the page `rendersim explore` serves), [`studies`] that run whole models (isolation, paper 000 Table 1,
//!   the Figure 4 timeline, device predictions), [`experiment`],
//!   [`bench`](mod@bench), and the command-line tool (`src/main.rs`, `src/cli`).
#![warn(missing_docs)]

pub use rendersim_engine as engine;
pub use rendersim_measure as measure;
pub use rendersim_models::{capture, components, config, limits, scene};
pub use rendersim_report::{output, plot, stats};

pub mod bench;
pub mod experiment;
pub mod explore;
pub mod studies;
pub mod systems;

/// Where a result made now comes from: this build of rendersim (its
/// version and git revision) and `command`, dated now (see
/// [`output::provenance`]).
pub fn provenance(command: Vec<String>) -> output::provenance::Provenance {
    output::provenance::Provenance::now(
        concat!("rendersim ", env!("CARGO_PKG_VERSION")),
        option_env!("RENDERSIM_GIT_REVISION").map(str::to_string),
        command,
    )
}

/// An error and its causes on one line, `: ` between them, leaving out a
/// cause whose text the line already holds (a library error that prints
/// its source, e.g. the OS error of a file that cannot be read): what the
/// command line prints after `error: `, and the Python package's message.
pub fn error_line(e: &(dyn std::error::Error + 'static)) -> String {
    let mut line = String::new();
    let mut cause = Some(e);
    while let Some(c) = cause {
        let text = c.to_string();
        if !line.contains(&text) {
            if !line.is_empty() {
                line.push_str(": ");
            }
            line.push_str(&text);
        }
        cause = c.source();
    }
    line
}
