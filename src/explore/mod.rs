//! `rendersim explore`: the frame pipeline in a browser, on the real
//! simulator. A local web page (compiled into the binary, so it works
//! offline) with a control for each of the pipeline's main knobs and
//! lessons that each show one thing; every change runs the model as
//! `rendersim run --set ...` would and redraws paper 000 Figure 4's
//! timeline, frame time and display interval over frames, the latency
//! distribution, each unit's busy and waiting time, the bottleneck verdict
//! and the closed-form terms beside the simulated ones.
//!
//! - [`controls`]: the knobs (model keys, units, slider ranges) and their
//!   values in the model;
//! - [`presets`]: the lessons (`docs/teaching.md`);
//! - [`page_run`]: one redraw, from the `--set` list to typed results and
//!   SVG views;
//! - [`page_replay`]: a capture dropped on the page, replayed with the
//!   page's display and pacing as the what-if;
//! - [`server`]: the HTTP server (bounded runs, no file read, Ctrl-C).
//!
//! ```
//! use rendersim::explore::page_run::Explorer;
//!
//! // The embedded default model, at draw fidelity, under a budget of
//! // 50 million events a run.
//! let page = Explorer::new(None, vec!["fidelity=\"draw\"".into()], 50_000_000).unwrap();
//! let sets = vec!["fidelity=\"draw\"".to_string(), "run.frames=60".to_string()];
//! let shown = page.run(&sets, 4).unwrap();
//! assert_eq!(shown.command, "rendersim run --set 'fidelity=\"draw\"' --set run.frames=60");
//! assert!(shown.lanes.iter().any(|l| l == "fragment"));
//! assert!(shown.views.timeline.starts_with("<svg"));
//!
//! // A bad value is refused with `--set`'s own message.
//! let bad = vec!["display.buffers=\"two\"".to_string()];
//! let e = page.run(&bad, 4).err().expect("refused").to_string();
//! assert!(e.contains("display.buffers"), "{e}");
//! ```

pub mod controls;
pub mod page_replay;
pub mod page_run;
pub mod presets;
pub mod server;
