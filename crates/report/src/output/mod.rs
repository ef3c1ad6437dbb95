//! Writing results without losing or damaging anything.
//!
//! - [`files`]: one output file. Special files (FIFOs, devices, `-` for
//!   standard output) are written in place; regular files are replaced
//!   atomically (temporary sibling, then rename); symbolic links are kept.
//! - [`result_set`]: a folder of results that belong together, staged beside
//!   its target and swapped in whole, so a kill leaves the old set or the
//!   new one, never a mix.
//! - [`pipe`]: a FIFO or socket written in place whose reader closes it
//!   gives a write error, not a SIGPIPE death.
//! - [`provenance`]: where a result came from (version, git revision,
//!   command line, date), for summaries, reports and model files.
//! - [`cleanup`]: temporary paths removed on SIGINT, SIGTERM and SIGHUP.
//! - [`table`]: per-row tables as CSV through the `csv` crate.
//! - [`text`]: numbers in human-readable reports.
//! - [`trace`]: Chrome/Perfetto trace JSON, streamed.
//! - [`span_collector`]: a trace kept in memory as merged spans per track,
//!   for pictures.

pub mod cleanup;
pub mod error;
pub mod files;
pub mod pipe;
pub mod provenance;
pub mod result_set;
pub mod span_collector;
pub mod table;
pub mod text;
pub mod timing;
pub mod trace;

pub use error::OutputError;
