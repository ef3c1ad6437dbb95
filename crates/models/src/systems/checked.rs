//! A system's model, checked once (issue 55 item 1): a [`Checked`] config
//! has passed every check serde cannot make (each system's [`Check`]:
//! cross-field rules, spans and event bounds), and each system builds its
//! model from a `Checked` config only, so no run can start from one that
//! was not checked. The frame pipeline's fuller form of the same idea is
//! its plan ([`super::frame_pipeline::PipelinePlan`]: per-unit specs).
//!
//! ```
//! use rendersim_models::systems::checked::Checked;
//! use rendersim_models::systems::vr::VrConfig;
//!
//! let text = "system = \"vr\"\nscheme = \"naive\"";
//! let good: VrConfig = toml::from_str(text).unwrap();
//! // Read through `Deref`: a checked config is the config.
//! let checked = Checked::new(good).unwrap();
//! assert_eq!(checked.scheme, rendersim_models::systems::vr::config::Scheme::Naive);
//!
//! // A zero tracker period parses, but is no model.
//! let bad: VrConfig = toml::from_str(&format!("{text}\n[tracker]\nperiod = \"0ms\"")).unwrap();
//! let e = Checked::new(bad).unwrap_err().to_string();
//! assert!(e.contains("tracker.period"), "{e}");
//! ```

use super::error::SystemError;

/// The checks of a system's config that serde cannot make.
pub trait Check {
    /// Ok when the config is a model this system can run; else the error
    /// names the key.
    fn check(&self) -> Result<(), SystemError>;
}

/// A config that passed its [`Check`]; read it through `Deref`.
#[derive(Debug, Clone)]
pub struct Checked<C>(C);

impl<C: Check> Checked<C> {
    /// Checks `config`.
    pub fn new(config: C) -> Result<Self, SystemError> {
        config.check()?;
        Ok(Checked(config))
    }
}

impl<C> Checked<C> {
    /// The config, to keep beside a run's results.
    pub fn into_inner(self) -> C {
        self.0
    }
}

impl<C> std::ops::Deref for Checked<C> {
    type Target = C;

    fn deref(&self) -> &C {
        &self.0
    }
}
