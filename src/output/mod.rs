//! Writing results: Chrome/Perfetto traces and files written safely (to a
//! temporary name, then renamed, so a failed run never truncates earlier
//! results).

pub mod files;
pub mod trace;
