//! The one error type of building and running any system: a model value the
//! simulator cannot use, a kernel error (simulated time overflow, event
//! budget), or a run that ended before its work was done.

use crate::engine::{EngineError, Time, TimeError};

/// Errors of building or running a system.
#[derive(Debug, thiserror::Error)]
pub enum SystemError {
    /// Kernel error (simulated time overflow, event budget).
    #[error(transparent)]
    Engine(#[from] EngineError),
    /// A model value the simulator cannot use (the loader adds the file,
    /// line and `--set` that gave it).
    #[error("{key}: {message}")]
    Invalid {
        /// Dotted key.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// The run ended before its work was done: stopped by `run.max_events`,
    /// or stalled (a model bug, reported rather than hung).
    #[error("the run stopped at {at} before {missing} ({state})")]
    Unfinished {
        /// When.
        at: Time,
        /// What was not done, e.g. "every input event was visible".
        missing: String,
        /// A description of the state: what was done, what was left.
        state: String,
    },
}

impl From<TimeError> for SystemError {
    fn from(e: TimeError) -> Self {
        SystemError::Engine(EngineError::Time(e))
    }
}

/// A [`SystemError::Invalid`] naming `key`.
pub fn invalid(key: &str, message: impl Into<String>) -> SystemError {
    SystemError::Invalid {
        key: key.to_string(),
        message: message.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_key_and_what_is_missing() {
        assert_eq!(
            invalid("run.events", "must be at least 1").to_string(),
            "run.events: must be at least 1"
        );
        let e = SystemError::Unfinished {
            at: Time(2_000_000_000),
            missing: "every frame was done".into(),
            state: "3 of 5 frames".into(),
        };
        assert!(
            e.to_string().contains("before every frame was done (3 of 5 frames)"),
            "{e}"
        );
    }
}
