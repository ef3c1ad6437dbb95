//! Shards: an experiment split into deterministic parts that run as
//! separate processes (the tasks of a Slurm job array), then merged into
//! exactly the files one process writes.
//!
//! The runs of an experiment, in output order (by point, then seed), are
//! numbered `0..R`; shard `K` of `N` (`--shard K/N`, `1 <= K <= N`) holds the
//! runs `i` with `i % N == K - 1`. Striding rather than cutting blocks
//! spreads costly points (a sweep's slowest key varies slowest) over every
//! shard.
//!
//! A shard writes one file, `DIR/shards/shard-K-of-N.json` (`K` and `N`
//! padded to the same width), atomically ([`crate::output::files`]): a
//! temporary sibling renamed into place when every run of the shard has
//! finished, so a file that exists is whole. The file holds the rendersim
//! version, the [fingerprint](super::fingerprint) of the resolved
//! experiment, the shard's runs with their numbers (floats in Rust's
//! shortest round-trip text, so a merge reads back the very bits a single
//! process would have used), its CPU time and its start and end on the
//! wall clock. Running a shard whose file is complete and made from the
//! same experiment and version does nothing (a preempted array can be
//! resubmitted whole); any other file is redone.
//!
//! [`merge_shards`] reads every shard file, refuses when one is missing,
//! duplicated, incomplete, or made from another experiment or rendersim
//! version (naming the file and what differs), and hands the runs in
//! output order to the same code a single process ends with.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::ExperimentError;
use super::cost::{process_cpu_seconds, unix_seconds};
use super::fingerprint::experiment_fingerprint;
use super::run::{ExperimentResult, JobOutput, Plan, RunRecord, ShardCost, Timing, finish};
use super::runner::Runner;
use super::spec::Experiment;

/// The format tag of shard files.
pub const SHARD_FORMAT: &str = "rendersim-shard-1";

/// The folder of shard files inside an experiment's output folder.
pub const SHARDS_DIR: &str = "shards";

/// This rendersim's version, stored in every shard.
const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Shard `k` of `n` (1-based), as given to `--shard K/N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShardId {
    /// Which shard, `1..=n`.
    pub k: usize,
    /// How many shards.
    pub n: usize,
}

/// Why a `--shard` value was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShardIdError {
    /// Not of the form `K/N`.
    #[error("`{0}` is not K/N (e.g. 2/8: the second of eight shards)")]
    Form(String),
    /// `K` or `N` out of range.
    #[error("`{0}`: needs 1 <= K <= N (K counts from 1)")]
    Range(String),
}

impl FromStr for ShardId {
    type Err = ShardIdError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (k, n) = s.split_once('/').ok_or_else(|| ShardIdError::Form(s.into()))?;
        let parse = |t: &str| t.trim().parse::<usize>().map_err(|_| ShardIdError::Form(s.into()));
        let (k, n) = (parse(k)?, parse(n)?);
        if k == 0 || n == 0 || k > n {
            return Err(ShardIdError::Range(s.into()));
        }
        Ok(ShardId { k, n })
    }
}

impl fmt::Display for ShardId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

impl ShardId {
    /// The shard's file name, `shard-K-of-N.json`, `K` padded to `N`'s width.
    pub fn file_name(&self) -> String {
        let w = self.n.to_string().len();
        format!("shard-{:0w$}-of-{}.json", self.k, self.n)
    }

    /// Indices of this shard's runs among `total` runs in output order.
    pub fn runs(&self, total: usize) -> impl Iterator<Item = usize> + use<> {
        (self.k - 1..total).step_by(self.n)
    }
}

/// One shard file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ShardFile {
    format: String,
    rendersim_version: String,
    experiment: String,
    experiment_hash: String,
    shard: usize,
    shards: usize,
    /// Runs of the whole experiment.
    total_runs: usize,
    /// Wall clock at the shard's start and end, seconds since the Unix epoch.
    started_unix: f64,
    finished_unix: f64,
    /// CPU time of the shard's process (user + system), seconds.
    cpu_seconds: f64,
    runs: Vec<ShardRun>,
}

/// One run in a shard file. Floats are text (see the module documentation).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ShardRun {
    point: usize,
    seed: u64,
    /// Tracked path values, space-separated; `null` for a JSON null.
    values: String,
    wall_seconds: String,
    /// One space-separated column per frame column.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    frames: Vec<String>,
}

fn float_text(x: f64) -> String {
    format!("{x:e}")
}

fn floats_text(v: &[f64]) -> String {
    let mut s = String::with_capacity(v.len() * 12);
    for (i, x) in v.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        s.push_str(&float_text(*x));
    }
    s
}

fn parse_float(t: &str) -> Result<f64, String> {
    t.parse::<f64>().map_err(|_| format!("`{t}` is not a number"))
}

impl ShardRun {
    fn from_output(o: &JobOutput) -> ShardRun {
        let values = o
            .record
            .values
            .iter()
            .map(|v| v.map_or_else(|| "null".to_string(), float_text))
            .collect::<Vec<_>>()
            .join(" ");
        ShardRun {
            point: o.record.point,
            seed: o.record.seed,
            values,
            wall_seconds: float_text(o.record.wall_seconds),
            frames: o.frames.iter().map(|c| floats_text(c)).collect(),
        }
    }

    fn to_output(&self, paths: usize, columns: usize) -> Result<JobOutput, String> {
        let values = self
            .values
            .split_ascii_whitespace()
            .map(|t| {
                if t == "null" {
                    Ok(None)
                } else {
                    parse_float(t).map(Some)
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        if values.len() != paths {
            return Err(format!("{} values where the experiment tracks {paths}", values.len()));
        }
        if self.frames.len() != columns {
            return Err(format!(
                "{} frame columns where the experiment needs {columns}",
                self.frames.len()
            ));
        }
        let frames = self
            .frames
            .iter()
            .map(|c| c.split_ascii_whitespace().map(parse_float).collect())
            .collect::<Result<Vec<Vec<f64>>, _>>()?;
        Ok(JobOutput {
            record: RunRecord {
                point: self.point,
                seed: self.seed,
                values,
                wall_seconds: parse_float(&self.wall_seconds)?,
            },
            frames,
        })
    }
}

/// What [`run_shard`] did.
#[derive(Debug, Clone, PartialEq)]
pub enum ShardOutcome {
    /// The shard's file was already complete: nothing ran.
    Complete {
        /// The shard file.
        path: PathBuf,
        /// Runs in it.
        runs: usize,
    },
    /// The shard ran and its file was written.
    Ran {
        /// The shard file.
        path: PathBuf,
        /// Runs in it.
        runs: usize,
        /// Wall time of the shard, seconds.
        wall_seconds: f64,
        /// CPU time of the process, seconds (where known).
        cpu_seconds: Option<f64>,
        /// Why an existing file was not kept (`None`: there was none).
        redone: Option<String>,
    },
}

fn shard_error(file: &Path, message: impl Into<String>) -> ExperimentError {
    ExperimentError::Shard {
        file: file.to_path_buf(),
        message: message.into(),
    }
}

fn read_shard(path: &Path) -> Result<ShardFile, ExperimentError> {
    let text = std::fs::read(path).map_err(|source| ExperimentError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let file: ShardFile =
        serde_json::from_slice(&text).map_err(|e| shard_error(path, format!("not a readable shard file ({e})")))?;
    if file.format != SHARD_FORMAT {
        return Err(shard_error(
            path,
            format!("format `{}`, expected `{SHARD_FORMAT}`", file.format),
        ));
    }
    Ok(file)
}

/// Why `file` cannot stand for shard `id` of the experiment with `hash`
/// (`None`: it can). Runs are compared with `expected`.
fn mismatch(file: &ShardFile, hash: &str, id: Option<ShardId>, expected: Option<&[(usize, u64)]>) -> Option<String> {
    if file.rendersim_version != VERSION {
        return Some(format!(
            "made by rendersim {}, this is rendersim {VERSION}; rerun the shard with this version",
            file.rendersim_version
        ));
    }
    if file.experiment_hash != hash {
        return Some(format!(
            "made from a different experiment (fingerprint {}..., this experiment's is {}...): the \
             experiment file or its model changed since the shard ran; rerun the shard",
            &file.experiment_hash.get(..12).unwrap_or(&file.experiment_hash),
            &hash[..12]
        ));
    }
    if let Some(id) = id
        && (file.shard != id.k || file.shards != id.n)
    {
        return Some(format!("holds shard {}/{}, not {id}", file.shard, file.shards));
    }
    if let Some(expected) = expected {
        let got: Vec<(usize, u64)> = file.runs.iter().map(|r| (r.point, r.seed)).collect();
        if got != expected {
            return Some(format!(
                "holds {} runs where shard {}/{} has {} (or other runs): incomplete or damaged",
                got.len(),
                file.shard,
                file.shards,
                expected.len()
            ));
        }
    }
    None
}

/// Removes temporary files a killed writer of `name` left in `dir`.
fn remove_partial(dir: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".{name}.tmp-");
    let mine = format!("{prefix}{}", std::process::id());
    for e in entries.flatten() {
        let n = e.file_name().to_string_lossy().to_string();
        if n.starts_with(&prefix) && n != mine {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Runs shard `id` of `exp` and writes `out_dir/shards/shard-K-of-N.json`,
/// unless that file is already complete (see the module documentation).
/// A failed run is an error naming its point and seed; no file is written.
pub fn run_shard(
    exp: &Experiment,
    base_model: &toml::Table,
    runner: &dyn Runner,
    out_dir: &Path,
    id: ShardId,
    progress: bool,
) -> Result<ShardOutcome, ExperimentError> {
    let t0 = Instant::now();
    let started_unix = unix_seconds();
    let plan = Plan::new(exp, base_model)?;
    let hash = experiment_fingerprint(exp, base_model)?;
    let all = plan.jobs(exp);
    let mine: Vec<(usize, u64)> = id.runs(all.len()).map(|i| all[i]).collect();
    let dir = out_dir.join(SHARDS_DIR);
    let path = dir.join(id.file_name());
    remove_partial(&dir, &id.file_name());
    let redone = if path.exists() {
        let why = match read_shard(&path) {
            Ok(f) => mismatch(&f, &hash, Some(id), Some(&mine)),
            Err(e) => Some(e.to_string()),
        };
        match why {
            None => {
                return Ok(ShardOutcome::Complete { path, runs: mine.len() });
            }
            Some(why) => Some(why),
        }
    } else {
        None
    };
    let mut outputs = Vec::with_capacity(mine.len());
    for r in plan.run(runner, &mine, progress) {
        outputs.push(r?);
    }
    let cpu = process_cpu_seconds();
    let file = ShardFile {
        format: SHARD_FORMAT.into(),
        rendersim_version: VERSION.into(),
        experiment: exp.name.clone(),
        experiment_hash: hash,
        shard: id.k,
        shards: id.n,
        total_runs: all.len(),
        started_unix,
        finished_unix: unix_seconds(),
        cpu_seconds: cpu.unwrap_or(0.0),
        runs: outputs.iter().map(ShardRun::from_output).collect(),
    };
    crate::output::files::write_output(&path, |w| {
        serde_json::to_writer(&mut *w, &file).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })?;
    Ok(ShardOutcome::Ran {
        path,
        runs: mine.len(),
        wall_seconds: t0.elapsed().as_secs_f64(),
        cpu_seconds: cpu,
        redone,
    })
}

/// Merges the shard files in `out_dir/shards` into the outputs a single
/// process writes (`runs.csv`, `points.csv`, plots, `report.md`), written
/// into `write_dir` (a result set's staging folder; `out_dir` itself when
/// writing in place). Searches (`[[search]]`) run here, in the merge.
pub fn merge_shards(
    exp: &Experiment,
    base_model: &toml::Table,
    runner: &dyn Runner,
    out_dir: &Path,
    write_dir: &Path,
) -> Result<ExperimentResult, ExperimentError> {
    let plan = Plan::new(exp, base_model)?;
    let hash = experiment_fingerprint(exp, base_model)?;
    let all = plan.jobs(exp);
    let dir = out_dir.join(SHARDS_DIR);
    let shards_error = |message: String| ExperimentError::Shards {
        dir: dir.clone(),
        message,
    };
    let mut names: Vec<PathBuf> = match std::fs::read_dir(&dir) {
        Ok(entries) => entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                let n = p
                    .file_name()
                    .map(|n| n.to_string_lossy().to_string())
                    .unwrap_or_default();
                !n.starts_with('.') && n.ends_with(".json")
            })
            .collect(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(source) => return Err(ExperimentError::Io { path: dir, source }),
    };
    names.sort();
    if names.is_empty() {
        return Err(shards_error(
            "no shard files to merge; run the shards first (`rendersim experiment FILE --out DIR --shard K/N`)".into(),
        ));
    }
    let files = names
        .iter()
        .map(|p| read_shard(p).map(|f| (p.clone(), f)))
        .collect::<Result<Vec<_>, _>>()?;
    for (p, f) in &files {
        if let Some(why) = mismatch(f, &hash, None, None) {
            return Err(shard_error(p, why));
        }
    }
    let (first_path, first) = &files[0];
    let n = first.shards;
    for (p, f) in &files {
        if f.shards != n || f.total_runs != all.len() {
            return Err(shards_error(format!(
                "{} is one of {} shards ({} runs) but {} is one of {n} ({} runs): shards of two different \
                 splits; remove the files of one of them",
                p.display(),
                f.shards,
                f.total_runs,
                first_path.display(),
                first.total_runs
            )));
        }
        if f.shard == 0 || f.shard > n {
            return Err(shard_error(p, format!("shard number {} is not in 1..={n}", f.shard)));
        }
    }
    let mut by_k: Vec<Option<usize>> = vec![None; n];
    for (i, (p, f)) in files.iter().enumerate() {
        if let Some(j) = by_k[f.shard - 1] {
            return Err(shards_error(format!(
                "shard {}/{n} is there twice: {} and {}; remove one",
                f.shard,
                files[j].0.display(),
                p.display()
            )));
        }
        by_k[f.shard - 1] = Some(i);
    }
    let missing: Vec<ShardId> = (1..=n)
        .filter(|k| by_k[k - 1].is_none())
        .map(|k| ShardId { k, n })
        .collect();
    if !missing.is_empty() {
        let list: Vec<String> = missing.iter().take(10).map(|id| id.file_name()).collect();
        return Err(shards_error(format!(
            "{} of {n} shards missing: {}{}; run them (`--shard K/{n}`) and merge again",
            missing.len(),
            list.join(", "),
            if missing.len() > 10 { ", ..." } else { "" }
        )));
    }
    // Check every shard holds exactly its runs, then put the runs in order.
    for (k, slot) in by_k.iter().enumerate() {
        let (p, f) = &files[slot.unwrap_or_default()];
        let id = ShardId { k: k + 1, n };
        let expected: Vec<(usize, u64)> = id.runs(all.len()).map(|i| all[i]).collect();
        if let Some(why) = mismatch(f, &hash, Some(id), Some(&expected)) {
            return Err(shard_error(p, why));
        }
    }
    let mut outputs = Vec::with_capacity(all.len());
    for i in 0..all.len() {
        let (p, f) = &files[by_k[i % n].unwrap_or_default()];
        let run = &f.runs[i / n];
        outputs.push(
            run.to_output(plan.paths.len(), plan.columns.len())
                .map_err(|m| shard_error(p, format!("run at point {}, seed {}: {m}", run.point, run.seed)))?,
        );
    }
    let start = files.iter().map(|f| f.1.started_unix).fold(f64::INFINITY, f64::min);
    let end = files
        .iter()
        .map(|f| f.1.finished_unix)
        .fold(f64::NEG_INFINITY, f64::max);
    let cost = ShardCost {
        shards: n,
        cpu_seconds: files.iter().map(|f| f.1.cpu_seconds).sum(),
        array_wall_seconds: (end - start).max(0.0),
    };
    drop(files);
    finish(exp, base_model, runner, &plan, outputs, write_dir, Timing::Shards(cost))
}
