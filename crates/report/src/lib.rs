//! rendersim's outputs, shared by every system and study: the one CSV
//! writer (`output::table`), traces and their reader, result sets and output
//! files (`output`), summary statistics and confidence intervals (`stats`),
//! and plots (`plot`).
//!
//! Layer: above `rendersim-engine` (trace times), below the models; it knows
//! no system.
#![warn(missing_docs)]

use rendersim_engine as engine;

pub mod output;
pub mod plot;
pub mod stats;
