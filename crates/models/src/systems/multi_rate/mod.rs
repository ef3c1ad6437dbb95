//! Multi-frame-rate rendering (Springer et al., paper 003 §3): a master with
//! a tracker, a slow client rendering the whole scene, a fast client
//! rendering the interactive parts over the slow client's latest image, and
//! the transfer path between them; each input event is followed until it is
//! visible through the fast and through the slow client.
//!
//! - `config`: the model file;
//! - `analytic`: the paper's closed forms and the bounds over all phases;
//! - `model`: the kernel model (clients, link, input events);
//! - `latency`: per-event latencies and their stage breakdown;
//! - `migration`: selection and release artifacts (paper 003 §4, Table 3);
//! - `run`: validate, run, summarize, CSV, trace.

pub mod analytic;
pub mod config;
pub mod latency;
pub mod migration;
pub mod model;
pub mod report;
pub mod run;
pub mod system;

pub use config::MultiRateConfig;
pub use model::MultiRate;
pub use run::{MultiRateRun, run_multi_rate, validate};
