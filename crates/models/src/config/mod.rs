//! Model files: units, loading, `--set` patches and the other overrides,
//! validation.

pub mod hardware;
pub mod load;
pub mod overrides;
pub mod patch;
pub mod strict;
pub mod units;

pub use hardware::{HARDWARE_KEY, HARDWARE_SECTIONS};
pub use load::{ConfigError, ModelSource, deserialize, invalid};
pub use overrides::{DEFAULT_MODEL, DEFAULT_MODEL_NAME, Overrides, PreparedModel, apply_patches, load_model, prepare};
pub use patch::{PatchError, apply_set, flatten, flatten_until, set_dotted};
pub use units::{Bandwidth, Bytes, Rate, UnitError};
