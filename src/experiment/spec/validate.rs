//! Loading and validating an experiment file: cross-references between
//! sweeps, plots, derived values and checks, reported by entry.

use std::path::Path;

use super::raw::*;
use super::*;
use crate::config::flatten;
use crate::experiment::ExperimentError;
use crate::experiment::sweep::expand_range;

/// Read and validate the experiment file at `path`.
pub fn load_experiment(path: &Path) -> Result<Experiment, ExperimentError> {
    let text = crate::limits::read_input_string(path, crate::limits::InputKind::Text).map_err(|source| {
        ExperimentError::Io {
            path: path.to_path_buf(),
            source,
        }
    })?;
    parse_experiment(&text, path)
}

/// Parse and validate experiment TOML `text`; `source` names the file in
/// messages and anchors a relative `model` path.
///
/// The text is read as model files are ([`crate::config::ModelSource`],
/// [`crate::config::deserialize`]): a misspelt key or a value of the wrong
/// type is reported with the file, its line, the key and, for a misspelt
/// key, the closest valid one, in the same form as a model's errors.
pub fn parse_experiment(text: &str, source: &Path) -> Result<Experiment, ExperimentError> {
    let src = crate::config::ModelSource::from_text(&source.display().to_string(), text);
    let raw: RawExperiment = src
        .table()
        .and_then(|table| crate::config::deserialize(&table, &src))
        .map_err(|e| from_config_error(e, source))?;
    Validator { file: source, text }.experiment(raw)
}

/// A loader error of the experiment file, in the experiment's own terms:
/// keys of `[[tables]]` as `sweep[1].range`, as the validator names them.
fn from_config_error(e: crate::config::ConfigError, source: &Path) -> ExperimentError {
    use crate::config::ConfigError;
    match e {
        ConfigError::Invalid {
            key,
            line,
            message,
            suggestion,
            ..
        } => ExperimentError::Invalid {
            file: source.to_path_buf(),
            line,
            key: indexed_key(&key),
            message: match suggestion {
                Some(s) => format!("{message} (did you mean `{s}`?)"),
                None => message,
            },
        },
        other => ExperimentError::Parse {
            file: source.to_path_buf(),
            message: match other {
                ConfigError::Syntax { message, .. } => message,
                e => e.to_string(),
            },
        },
    }
}

/// `sweep.1.range` as `sweep[1].range`.
fn indexed_key(dotted: &str) -> String {
    let mut out = String::with_capacity(dotted.len() + 2);
    for part in dotted.split('.') {
        if !out.is_empty() && part.bytes().all(|b| b.is_ascii_digit()) && !part.is_empty() {
            out.push('[');
            out.push_str(part);
            out.push(']');
        } else {
            if !out.is_empty() {
                out.push('.');
            }
            out.push_str(part);
        }
    }
    out
}

pub(super) struct Validator<'a> {
    file: &'a Path,
    text: &'a str,
}

impl Validator<'_> {
    pub(super) fn err(&self, key: impl Into<String>, message: impl Into<String>) -> ExperimentError {
        let key = key.into();
        ExperimentError::Invalid {
            file: self.file.to_path_buf(),
            line: self.line_of(&key),
            key,
            message: message.into(),
        }
    }

    /// The line of the entry an error `key` names (`check[2] (path).expect`
    /// is `expect` of the third `[[check]]`), or of the nearest enclosing
    /// entry that stands in the file.
    fn line_of(&self, key: &str) -> Option<usize> {
        let mut plain = String::with_capacity(key.len());
        let mut depth = 0usize;
        for c in key.chars() {
            match c {
                '(' => depth += 1,
                ')' => depth = depth.saturating_sub(1),
                c if depth == 0 => plain.push(c),
                _ => {}
            }
        }
        let plain = plain.replace(' ', "");
        let dotted = crate::config::load::dotted_path(&plain);
        let src = crate::config::ModelSource::from_text("", self.text);
        let parts: Vec<&str> = dotted.split('.').collect();
        (1..=parts.len()).rev().find_map(|n| src.line_of(&parts[..n].join(".")))
    }

    /// The whole file, checked in the order its errors are reported: the
    /// header, the model and its `[set]`, the sweeps or the sample, the
    /// number of runs, then what the experiment reports (`outputs.rs`).
    fn experiment(&self, raw: RawExperiment) -> Result<Experiment, ExperimentError> {
        if raw.name.trim().is_empty() {
            return Err(self.err("name", "must not be empty"));
        }
        if raw.replications < 1 {
            return Err(self.err("replications", format!("must be at least 1, got {}", raw.replications)));
        }
        if raw.replications > crate::limits::MAX_REPLICATIONS {
            return Err(self.err(
                "replications",
                format!(
                    "{} is more than the limit of {} replications per point",
                    raw.replications,
                    crate::limits::MAX_REPLICATIONS
                ),
            ));
        }
        // Each run's seed is written into its model as a TOML integer,
        // which holds at most i64::MAX.
        let last_seed = raw.base_seed.checked_add(raw.replications as u64 - 1);
        if last_seed.is_none_or(|s| s > i64::MAX as u64) {
            return Err(self.err(
                "base_seed",
                format!(
                    "{} with {} replications runs seeds up to {}, past the largest a model's run.seed can hold ({}): lower base_seed",
                    raw.base_seed,
                    raw.replications,
                    last_seed.map_or_else(|| "beyond 2^64".to_string(), |s| s.to_string()),
                    i64::MAX
                ),
            ));
        }
        if !(raw.confidence > 0.0 && raw.confidence < 1.0) {
            return Err(self.err("confidence", format!("must be in (0, 1), got {}", raw.confidence)));
        }
        let model = if raw.model == "default" {
            ModelSource::Default
        } else if raw.model.trim().is_empty() {
            return Err(self.err("model", "must be \"default\" or a file path"));
        } else {
            let dir = self.file.parent().unwrap_or(Path::new(""));
            let path = dir.join(&raw.model);
            if !path.is_file() {
                return Err(self.err(
                    "model",
                    format!(
                        "model file {:?} {} (looked for {}; paths are relative to the experiment file)",
                        raw.model,
                        missing_or_not_a_file(&path),
                        path.display()
                    ),
                ));
            }
            ModelSource::File(path)
        };
        let mut set = Vec::new();
        flatten("", &raw.set, &mut set);

        let sweeps = self.sweeps(raw.sweep, &raw.model)?;
        if sweeps.iter().any(|s| s.key == MODEL_SWEEP_KEY) && !raw.search.is_empty() {
            return Err(self.err(
                "search[0]",
                "searches run on one base model; an experiment that sweeps `model` cannot have them",
            ));
        }
        let sample = match raw.sample {
            None => None,
            Some(s) => {
                if !sweeps.is_empty() {
                    return Err(self.err("sample", "give either `[[sweep]]`s or `[sample]`, not both"));
                }
                Some(self.sample(s)?)
            }
        };
        // Runs = points (the product of the sweeps' sizes, or the sample's
        // points) x replications, checked before the points are expanded.
        let points = match &sample {
            Some(s) => s.points() as u64,
            None => sweeps
                .iter()
                .try_fold(1u64, |n, s| n.checked_mul(s.values.len() as u64))
                .unwrap_or(u64::MAX),
        };
        let runs = points.saturating_mul(raw.replications as u64);
        if runs > crate::limits::MAX_EXPERIMENT_RUNS {
            let sizes: Vec<String> = sweeps.iter().map(|s| s.values.len().to_string()).collect();
            return Err(self.err(
                "sweep",
                format!(
                    "{} points ({}) x {} replications = {runs} runs is more than the limit of {}",
                    points,
                    if sizes.is_empty() {
                        "no sweep".to_string()
                    } else {
                        sizes.join(" x ")
                    },
                    raw.replications,
                    crate::limits::MAX_EXPERIMENT_RUNS
                ),
            ));
        }
        let metrics = self.metrics(raw.metric)?;
        let derived = self.derived(raw.derived, &sweeps, &metrics)?;
        let plots = self.plots(raw.plot, &sweeps, &metrics, &raw.name)?;
        let checks = self.checks(raw.check, &sweeps)?;
        let searches = self.searches(raw.search, &derived)?;

        Ok(Experiment {
            source: self.file.to_path_buf(),
            name: raw.name,
            description: raw.description,
            model,
            replications: raw.replications as u32,
            base_seed: raw.base_seed,
            confidence: raw.confidence,
            set,
            sweeps,
            metrics,
            plots,
            derived,
            checks,
            searches,
            sample,
        })
    }

    /// The `[[sweep]]`s: dotted keys, each swept once, `values` or a
    /// `range` (with optional labels); a swept `model` checked as such.
    fn sweeps(&self, raw: Vec<RawSweep>, model: &str) -> Result<Vec<Sweep>, ExperimentError> {
        let mut sweeps: Vec<Sweep> = Vec::new();
        for (i, s) in raw.into_iter().enumerate() {
            let key = format!("sweep[{i}]");
            if s.key.split('.').any(|p| p.trim().is_empty()) {
                return Err(self.err(format!("{key}.key"), format!("`{}` is not a dotted key", s.key)));
            }
            if sweeps.iter().any(|o| o.key == s.key) {
                return Err(self.err(format!("{key}.key"), format!("`{}` is swept twice", s.key)));
            }
            let sweep = match (s.values, s.range) {
                (Some(_), Some(_)) => {
                    return Err(self.err(key, "give either `values` or `range`, not both"));
                }
                (None, None) => return Err(self.err(key, "needs `values` or `range`")),
                (Some(values), None) => {
                    if values.is_empty() {
                        return Err(self.err(format!("{key}.values"), "must not be empty"));
                    }
                    Sweep::from_values(s.key, values)
                }
                (None, Some(r)) => expand_range(s.key, &r).map_err(|m| self.err(format!("{key}.range"), m))?,
            };
            let sweep = match s.labels {
                Some(l) => sweep
                    .with_labels(l)
                    .map_err(|m| self.err(format!("{key}.labels"), m.to_string()))?,
                None => sweep,
            };
            if sweep.key == MODEL_SWEEP_KEY {
                self.model_sweep(&key, &sweep, model)?;
            }
            sweeps.push(sweep);
        }
        Ok(sweeps)
    }

    /// A `[[sweep]] key = "model"`: every value a model file relative to
    /// the experiment file (that exists) or `"default"`, and no top-level
    /// `model` beside it.
    fn model_sweep(&self, key: &str, sweep: &Sweep, model: &str) -> Result<(), ExperimentError> {
        if model != "default" {
            return Err(self.err(
                "model",
                format!("`{key}` sweeps `model` (the model file of each point); leave out the top-level `model`"),
            ));
        }
        let dir = self.file.parent().unwrap_or(Path::new(""));
        for v in &sweep.values {
            let Some(name) = v.as_str().filter(|n| !n.trim().is_empty()) else {
                return Err(self.err(
                    format!("{key}.values"),
                    format!("a `model` sweep takes model file paths or \"default\", got {v}"),
                ));
            };
            if name != "default" && !dir.join(name).is_file() {
                return Err(self.err(
                    format!("{key}.values"),
                    format!(
                        "model file {name:?} {} (looked for {}; paths are relative to the experiment file)",
                        missing_or_not_a_file(&dir.join(name)),
                        dir.join(name).display()
                    ),
                ));
            }
        }
        Ok(())
    }

    fn sample(&self, s: RawSample) -> Result<crate::experiment::sample::Sample, ExperimentError> {
        use crate::experiment::sample::{Sample, SampleMethod, SampleParam, Scale};
        let method = match s.method.as_str() {
            "latin_hypercube" => SampleMethod::LatinHypercube,
            "sobol" => SampleMethod::Sobol,
            other => {
                return Err(self.err(
                    "sample.method",
                    format!("unknown method `{other}` (expected latin_hypercube or sobol)"),
                ));
            }
        };
        if !(2..=1_000_000).contains(&s.n) {
            return Err(self.err("sample.n", format!("must be between 2 and 1000000, got {}", s.n)));
        }
        let bootstrap = s.bootstrap.unwrap_or(1000);
        if !(0..=100_000).contains(&bootstrap) {
            return Err(self.err(
                "sample.bootstrap",
                format!("must be between 0 and 100000, got {bootstrap}"),
            ));
        }
        if s.param.is_empty() {
            return Err(self.err("sample", "needs at least one `[[sample.param]]`"));
        }
        let max = crate::experiment::sample::MAX_SOBOL_PARAMS;
        if method == SampleMethod::Sobol && s.param.len() > max {
            return Err(self.err(
                "sample.param",
                format!(
                    "{} parameters; a sobol sample takes at most {max} (its sequence has {} dimensions, two a \
                     parameter); use latin_hypercube or fewer parameters",
                    s.param.len(),
                    2 * max
                ),
            ));
        }
        if s.scramble.is_some() && method != SampleMethod::Sobol {
            return Err(self.err(
                "sample.scramble",
                "belongs to method = \"sobol\" (the sequence's digital shift)",
            ));
        }
        let mut params: Vec<SampleParam> = Vec::new();
        for (i, p) in s.param.into_iter().enumerate() {
            let key = format!("sample.param[{i}]");
            if p.key.split('.').any(|x| x.trim().is_empty()) {
                return Err(self.err(format!("{key}.key"), format!("`{}` is not a dotted key", p.key)));
            }
            if params.iter().any(|o| o.key == p.key) {
                return Err(self.err(format!("{key}.key"), format!("`{}` is sampled twice", p.key)));
            }
            if !(p.from.is_finite() && p.to.is_finite() && p.from < p.to) {
                return Err(self.err(
                    &key,
                    format!("needs finite `from` < `to`, got from = {}, to = {}", p.from, p.to),
                ));
            }
            let scale = match p.scale.as_deref().unwrap_or("linear") {
                "linear" => Scale::Linear,
                "log" if p.from > 0.0 => Scale::Log,
                "log" => {
                    return Err(self.err(format!("{key}.scale"), "`log` needs `from` > 0"));
                }
                other => {
                    return Err(self.err(
                        format!("{key}.scale"),
                        format!("unknown scale `{other}` (expected linear or log)"),
                    ));
                }
            };
            if p.integer && (p.from.fract() != 0.0 || p.to.fract() != 0.0) {
                return Err(self.err(&key, "`integer = true` needs whole numbers for `from` and `to`"));
            }
            if let Some(u) = &p.unit
                && (u.is_empty() || !u.chars().all(|c| c.is_ascii_alphabetic() || c == '/'))
            {
                return Err(self.err(
                    format!("{key}.unit"),
                    format!("`{u}` is not a unit (letters, e.g. ms, us, Hz)"),
                ));
            }
            params.push(SampleParam {
                key: p.key,
                from: p.from,
                to: p.to,
                scale,
                integer: p.integer,
                unit: p.unit,
            });
        }
        Ok(Sample {
            method,
            n: s.n as usize,
            seed: s.seed,
            bootstrap: bootstrap as usize,
            scramble: s.scramble.unwrap_or(true),
            params,
        })
    }
}

/// Why `path`, which is not a regular file, cannot be a model: it is not
/// there, or it is a folder, a device, a FIFO or a socket.
fn missing_or_not_a_file(path: &Path) -> &'static str {
    match std::fs::metadata(path) {
        Err(_) => "not found",
        Ok(m) if m.is_dir() => "is a folder, not a file",
        Ok(_) => "is not a regular file (a device, FIFO or socket)",
    }
}
