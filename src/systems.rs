//! Every system the tool runs: the models' systems
//! ([`rendersim_models::systems`], re-exported here whole) and the studies
//! registered as systems ([`STUDIES`]). [`systems`], [`run_model`],
//! [`read_model`], [`traceless_system`] and [`tracing_systems`] here know both; the models'
//! own functions of the same names, and [`SYSTEMS`], know only the models'
//! systems (a study that runs a system cannot be below it).

pub use rendersim_models::systems::*;

pub use crate::studies::device_predictions;
pub use crate::studies::replay::system::ReplaySystem;

use crate::config::ModelSource;
use crate::output::trace::TraceWriter;

/// The studies that are also systems (a model file names them in `system`).
pub const STUDIES: &[&dyn System] = &[
    &Registered::<device_predictions::system::DevicePredictionsSystem>::new(),
    &Registered::<ReplaySystem>::new(),
];

/// Every system: the models' ([`rendersim_models::systems::SYSTEMS`]) and
/// the studies', gathered once.
pub fn systems() -> &'static [&'static dyn System] {
    static ALL: std::sync::LazyLock<Vec<&'static dyn System>> = std::sync::LazyLock::new(|| {
        rendersim_models::systems::SYSTEMS
            .iter()
            .chain(STUDIES)
            .copied()
            .collect()
    });
    &ALL
}

/// Builds and runs the system a model describes, among every system
/// ([`systems`]); see [`rendersim_models::systems::run_model`].
pub fn run_model(src: &ModelSource, table: &toml::Table, trace: Option<TraceWriter>) -> Result<SystemRun, SimError> {
    run_among(systems(), src, table, trace)
}

/// Reads a model without running it, among every system; see
/// [`rendersim_models::systems::read_model`]. Returns the system's name.
pub fn read_model(src: &ModelSource, table: &toml::Table) -> Result<&'static str, SimError> {
    read_among(systems(), src, table)
}

/// The name of the model's system when that system writes no trace events,
/// among every system; see [`rendersim_models::systems::traceless_system`].
pub fn traceless_system(table: &toml::Table) -> Option<&'static str> {
    traceless_among(systems(), table)
}

/// The systems whose runs write trace events, comma separated, among every system.
pub fn tracing_systems() -> String {
    tracing_among(systems())
}
