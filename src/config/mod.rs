//! Model files: units, loading, `--set` patches and validation.

pub mod load;
pub mod units;

pub use load::{ConfigError, ModelSource, apply_set, deserialize, invalid, set_dotted};
pub use units::{Bandwidth, Bytes, Rate, UnitError};
