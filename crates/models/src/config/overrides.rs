//! The one way a model is made ready to run, for the command line,
//! experiments, benchmarks and tests alike: read the model (a file or the
//! embedded default), apply `--set` patches, then the seed and the frame
//! count, shortening the warm-up when it would not leave a frame to measure.
//! Every key set this way is noted on the [`ModelSource`], so an error in
//! its value names the option rather than a line of the file.
//!
//! ```
//! use std::path::Path;
//! use rendersim_models::config::{Overrides, deserialize, load_model};
//! use rendersim_models::systems::frame_pipeline::FramePipelineConfig;
//!
//! // A model file with two `--set`s, the seed and the frame count.
//! let overrides = Overrides {
//!     sets: vec!["display.buffers=3".into(), "cpu.max_frames_ahead=1".into()],
//!     seed: Some(7),
//!     frames: Some(50),
//! };
//! let m = load_model(Some(Path::new("../../models/fixed.toml")), &overrides).unwrap();
//! let cfg: FramePipelineConfig = deserialize(&m.table, &m.source).unwrap();
//! assert_eq!((cfg.display.buffers, cfg.cpu.max_frames_ahead), (3, 1));
//! assert_eq!((cfg.run.seed, cfg.run.frames), (7, 50));
//!
//! // A misspelt key is refused where it came from: the option, not a line.
//! let m = load_model(None, &Overrides::with_sets(&["display.bufers=3"])).unwrap();
//! let e = deserialize::<FramePipelineConfig>(&m.table, &m.source).unwrap_err().to_string();
//! assert!(e.contains("--set display.bufers=3"), "{e}");
//!
//! // A file that is not there says so, with its path.
//! let e = load_model(Some(Path::new("no-such-model.toml")), &Overrides::default()).unwrap_err();
//! assert!(e.to_string().contains("no-such-model.toml"), "{e}");
//! ```

use std::path::Path;

use super::load::{ConfigError, ModelSource};
use super::patch::apply_set;

/// The embedded default model (`models/default.toml`).
pub const DEFAULT_MODEL: &str = include_str!("../../../../models/default.toml");

/// The name the embedded default model goes by in messages.
pub const DEFAULT_MODEL_NAME: &str = "<embedded default model>";

/// Changes to a model beyond its file, applied in this order: the `--set`
/// patches, the seed (`run.seed`), the frame count (`run.frames`). Errors
/// and notes name them as the command line does (`--set k=v`, `--seed N`,
/// `--frames N`).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Overrides {
    /// `key=value` assignments, as for `--set`.
    pub sets: Vec<String>,
    /// The master seed.
    pub seed: Option<u64>,
    /// Frames to simulate.
    pub frames: Option<u64>,
}

/// A model ready to run.
#[derive(Debug, Clone)]
pub struct PreparedModel {
    /// Where it came from, with the keys the overrides set.
    pub source: ModelSource,
    /// The patched table, for [`crate::systems::run_model`].
    pub table: toml::Table,
    /// Adjustments made on the user's behalf, one sentence each (a warm-up
    /// shortened to fit `--frames`), for the caller to show.
    pub notes: Vec<String>,
}

impl ModelSource {
    /// The embedded default model ([`DEFAULT_MODEL`]).
    pub fn embedded_default() -> ModelSource {
        ModelSource::from_text(DEFAULT_MODEL_NAME, DEFAULT_MODEL)
    }

    /// The model file at `path`, or the embedded default without one.
    pub fn open(path: Option<&Path>) -> Result<ModelSource, ConfigError> {
        match path {
            Some(p) => ModelSource::from_file(p),
            None => Ok(ModelSource::embedded_default()),
        }
    }
}

impl Overrides {
    /// Only `--set` patches.
    pub fn with_sets<S: AsRef<str>>(sets: &[S]) -> Overrides {
        Overrides {
            sets: sets.iter().map(|s| s.as_ref().to_string()).collect(),
            ..Overrides::default()
        }
    }

    /// Applies the overrides to `table` (parsed from `src`), noting on
    /// `src` where each value came from. Returns the notes for the user.
    pub fn apply(&self, src: &mut ModelSource, table: &mut toml::Table) -> Result<Vec<String>, ConfigError> {
        let mut notes = Vec::new();
        for s in &self.sets {
            set_noted(src, table, s, format!("--set {s}"))?;
        }
        // A `--set` of a key that `--seed` or `--frames` then replaces is
        // still checked: a wrong value is an error, not silently dropped.
        for (key, given) in [("seed", self.seed.is_some()), ("frames", self.frames.is_some())] {
            let value = table.get("run").and_then(|r| r.get(key));
            if given
                && let Some(v) = value
                && v.as_integer().is_none_or(|n| n < 0)
                && let Some(option) = src.override_of(&format!("run.{key}"))
            {
                return Err(ConfigError::Override {
                    option: option.to_string(),
                    reason: format!(
                        "run.{key} must be a whole number >= 0, got {v} (--{key} replaces it, but a wrong value is still an error)"
                    ),
                });
            }
        }
        if let Some(seed) = self.seed {
            if seed > i64::MAX as u64 {
                return Err(ConfigError::Override {
                    option: format!("--seed {seed}"),
                    reason: format!("must be at most {} (model files hold 64-bit signed integers)", i64::MAX),
                });
            }
            set_noted(src, table, &format!("run.seed={seed}"), format!("--seed {seed}"))?;
        }
        if let Some(f) = self.frames {
            set_noted(src, table, &format!("run.frames={f}"), format!("--frames {f}"))?;
            let warm = table
                .get("run")
                .and_then(|r| r.get("warmup_frames"))
                .and_then(|w| w.as_integer())
                .unwrap_or(0);
            if f > 0 && warm as u64 >= f {
                notes.push(format!(
                    "run.warmup_frames = {warm} is not less than --frames {f}; using {} warm-up frame{}",
                    f / 10,
                    if f / 10 == 1 { "" } else { "s" }
                ));
                set_noted(
                    src,
                    table,
                    &format!("run.warmup_frames={}", f / 10),
                    format!("--frames {f}"),
                )?;
            }
        }
        Ok(notes)
    }
}

/// Applies `key=value` patches that an option other than `--set` gave
/// (`option`, e.g. `--assume`), noting each on `src` so that an error in
/// its value names that option.
pub fn apply_patches(
    option: &str,
    patches: &[String],
    src: &mut ModelSource,
    table: &mut toml::Table,
) -> Result<(), ConfigError> {
    for p in patches {
        set_noted(src, table, p, format!("{option} {p}")).map_err(|e| match e {
            ConfigError::Set { assignment, reason } => ConfigError::Override {
                option: format!("{option} {assignment:?}"),
                reason,
            },
            e => e,
        })?;
    }
    Ok(())
}

/// Applies `key=value` to the table and records where the value came from
/// (`origin`), so an error in it names the option rather than the file.
fn set_noted(src: &mut ModelSource, t: &mut toml::Table, assignment: &str, origin: String) -> Result<(), ConfigError> {
    apply_set(t, assignment)?;
    if let Some((key, _)) = assignment.split_once('=') {
        src.note_override(key.trim(), origin);
    }
    Ok(())
}

/// `source` parsed, with `overrides` applied.
pub fn prepare(mut source: ModelSource, overrides: &Overrides) -> Result<PreparedModel, ConfigError> {
    let mut table = source.table()?;
    let notes = overrides.apply(&mut source, &mut table)?;
    Ok(PreparedModel { source, table, notes })
}

/// The model file at `path` (the embedded default without one), parsed,
/// with `overrides` applied.
pub fn load_model(path: Option<&Path>, overrides: &Overrides) -> Result<PreparedModel, ConfigError> {
    prepare(ModelSource::open(path)?, overrides)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_apply_in_order_and_are_noted() {
        let src = ModelSource::from_text("m.toml", "[run]\nframes = 100\nwarmup_frames = 60\n");
        let o = Overrides {
            sets: vec!["run.frames=7".into()],
            seed: Some(3),
            frames: Some(20),
        };
        let m = prepare(src, &o).unwrap();
        assert_eq!(m.table["run"]["frames"].as_integer(), Some(20));
        assert_eq!(m.table["run"]["seed"].as_integer(), Some(3));
        assert_eq!(m.table["run"]["warmup_frames"].as_integer(), Some(2));
        assert_eq!(
            m.notes,
            ["run.warmup_frames = 60 is not less than --frames 20; using 2 warm-up frames"]
        );
        assert_eq!(m.source.override_of("run.seed"), Some("--seed 3"));
        assert_eq!(m.source.override_of("run.frames"), Some("--frames 20"));
        // A wrong `--set` of a key `--frames` replaces is still an error.
        let bad = Overrides {
            sets: vec!["run.frames=\"abc\"".into()],
            frames: Some(5),
            ..Overrides::default()
        };
        let e = prepare(ModelSource::embedded_default(), &bad).unwrap_err().to_string();
        assert!(
            e.contains("--set run.frames=\"abc\"") && e.contains("whole number"),
            "{e}"
        );
        // One warm-up frame is one frame.
        let src = ModelSource::from_text("m.toml", "[run]\nwarmup_frames = 60\n");
        let one = Overrides {
            frames: Some(10),
            ..Overrides::default()
        };
        assert_eq!(
            prepare(src, &one).unwrap().notes,
            ["run.warmup_frames = 60 is not less than --frames 10; using 1 warm-up frame"]
        );
        let e = prepare(
            ModelSource::embedded_default(),
            &Overrides {
                seed: Some(u64::MAX),
                ..Overrides::default()
            },
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "--seed {}: must be at most {} (model files hold 64-bit signed integers)",
                u64::MAX,
                i64::MAX
            )
        );
    }
}
