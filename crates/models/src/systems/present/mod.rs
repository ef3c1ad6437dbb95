//! The swap chain and display alone (`system = "present"`), a teaching
//! system: a renderer draws frames whose render times come from a
//! distribution and presents each into a swap chain of `buffers` images; a
//! display refreshing at `refresh` shows them in the present mode
//! (`fifo`, `mailbox` or `immediate`).
//!
//! It shows what paper 004 §4.2 teaches about vsync and double buffering: a
//! frame that misses a vertical blank waits for the next one, so with two
//! images the frame rate snaps to refresh/1, refresh/2, ...; a third image
//! lets the renderer go on while a finished frame waits (the mean interval
//! becomes the larger of the render time and the refresh); `mailbox`
//! drops the older of two waiting frames; `immediate` shows a frame at once.
//! The closed forms of those intervals are in the summary beside what the
//! simulation measured ([`run::analytic_interval_ms`]).
//!
//! It is also the smallest whole system, and its commit the worked example
//! of `docs/ARCHITECTURE.md`, "Adding a system": its config
//! ([`config`]), its kernel model ([`model`]), its run, summary, report and
//! registry entry ([`run`]), and one line in [`crate::systems::SYSTEMS`].
//!
//! ```
//! use rendersim_models::config::ModelSource;
//! use rendersim_models::systems::run_model;
//!
//! // 20 ms frames on a 60 Hz double-buffered vsynced display: each waits
//! // for the second vertical blank after it started, 33.3 ms apart.
//! let text = "system = \"present\"\n[run]\nframes = 30\n\
//!             [render]\ntime = { kind = \"const\", value = \"20ms\" }\n";
//! let src = ModelSource::from_text("present.toml", text);
//! let run = run_model(&src, &src.table().unwrap(), None).unwrap();
//! let interval = run.summary()["metrics"]["display_interval_ms"]["mean"].as_f64().unwrap();
//! assert!((interval - 1000.0 / 30.0).abs() < 1e-6, "{interval}");
//! ```

pub mod config;
pub mod model;
pub mod run;

pub use config::PresentConfig;
pub use run::{PresentRun, PresentSystem, run_present};
