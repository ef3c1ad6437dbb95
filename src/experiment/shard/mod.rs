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
//! wall clock, and the SHA-256 of its runs' text (`runs_sha256`). Running a
//! shard whose file is complete, made from the same experiment and version
//! and whose runs still match their checksum does nothing (a preempted array
//! can be resubmitted whole); any other file is redone.
//!
//! A shard file is read back like user input: [`merge_shards`] reads every
//! shard file, refuses when one is missing, duplicated, incomplete, edited
//! (its runs no longer match their checksum), holds a value that is not a
//! finite number, counts more shards than the experiment has runs, or was
//! made from another experiment or rendersim version (naming the file and
//! what differs), before it allocates anything sized by what the files
//! say; then it hands the runs in output order to the same code a single
//! process ends with. `--shard K/N` with more shards than runs is refused
//! before anything runs.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Instant;

use super::ExperimentError;
use super::cost::{process_cpu_seconds, unix_seconds};
use super::fingerprint::experiment_fingerprint;
use super::results::{ExperimentResult, ShardCost};
use super::run::{Plan, Timing, finish};
use super::runner::Runner;
use super::spec::Experiment;

mod file;

use file::{ShardFile, ShardRun, mismatch, read_shard, runs_checksum, shard_error};

/// Ascending indices as Slurm's `--array` list: `2,5-7,9`.
fn index_ranges(ks: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < ks.len() {
        let mut j = i;
        while j + 1 < ks.len() && ks[j + 1] == ks[j] + 1 {
            j += 1;
        }
        parts.push(if j > i {
            format!("{}-{}", ks[i], ks[j])
        } else {
            ks[i].to_string()
        });
        i = j + 1;
    }
    parts.join(",")
}

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
    /// More shards than the experiment has runs.
    #[error(
        "`--shard {id}`: {} shards for an experiment of {runs} runs; N can be at most {runs} (one run per shard)",
        id.n
    )]
    MoreShardsThanRuns {
        /// The shard asked for.
        id: ShardId,
        /// Runs of the experiment.
        runs: usize,
    },
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

    /// Refuses a split of `total` runs into more shards than runs (a shard
    /// with no run, and a merge that would look for files that can never
    /// hold anything).
    pub fn check_runs(&self, total: usize) -> Result<(), ShardIdError> {
        if self.n > total {
            return Err(ShardIdError::MoreShardsThanRuns { id: *self, runs: total });
        }
        Ok(())
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
    let all = plan.jobs(exp);
    id.check_runs(all.len())?;
    let hash = experiment_fingerprint(exp, base_model)?;
    let mine: Vec<(usize, u64)> = id.runs(all.len()).map(|i| all[i]).collect();
    let dir = out_dir.join(SHARDS_DIR);
    let path = dir.join(id.file_name());
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
    for r in plan.run(runner, &mine, &progress.into()) {
        outputs.push(r?);
    }
    let cpu = process_cpu_seconds();
    let runs: Vec<ShardRun> = outputs.iter().map(ShardRun::from_output).collect();
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
        runs_sha256: runs_checksum(&runs),
        runs,
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
            "no shard files to merge; run the shards first (`rendersim experiment FILE --out DIR --shard K/N`; \
             on Slurm, every task of the array failed: see DIR/logs, then `sbatch job.sbatch` again)"
                .into(),
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
    // What the files say is bounded by the experiment before anything is
    // sized by it.
    for (p, f) in &files {
        if f.total_runs != all.len() {
            return Err(shard_error(
                p,
                format!(
                    "says the experiment has {} runs; it has {}: damaged, or from another split; rerun the shard",
                    f.total_runs,
                    all.len()
                ),
            ));
        }
        if f.shards == 0 || f.shards > all.len() {
            return Err(shard_error(
                p,
                format!(
                    "says it is one of {} shards; an experiment of {} runs has 1 to {} shards: damaged; rerun the shard",
                    f.shards,
                    all.len(),
                    all.len()
                ),
            ));
        }
    }
    for (p, f) in &files {
        // (Every file's run count was checked against the experiment above.)
        if f.shards != n {
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
            "{} of {n} shards missing: {}{}; run them (`--shard K/{n}`; on Slurm `sbatch --array={} job.sbatch`, \
             their logs in DIR/logs) and merge again",
            missing.len(),
            list.join(", "),
            if missing.len() > 10 { ", ..." } else { "" },
            index_ranges(&missing.iter().map(|id| id.k).collect::<Vec<_>>())
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_shards_read_as_a_slurm_array_list() {
        assert_eq!(index_ranges(&[]), "");
        assert_eq!(index_ranges(&[3]), "3");
        assert_eq!(index_ranges(&[1, 2]), "1-2");
        assert_eq!(index_ranges(&[2, 5, 6, 7, 9, 11, 12]), "2,5-7,9,11-12");
    }

    fn run(values: &str, wall: &str, frames: &[&str]) -> ShardRun {
        ShardRun {
            point: 0,
            seed: 1,
            values: values.into(),
            wall_seconds: wall.into(),
            frames: frames.iter().map(|c| c.to_string()).collect(),
        }
    }

    #[test]
    fn values_read_back_are_finite_numbers() {
        let ok = run("1e0 null 2.5e1", "1e-3", &["1e0 NaN", "2e0 3e0"]);
        let o = ok.to_output(3, 2).unwrap();
        assert_eq!(o.record.values, vec![Some(1.0), None, Some(25.0)]);
        assert!(o.frames[0][1].is_nan(), "a frame's missing value stays missing");
        for bad in ["NaN", "inf", "-inf", "1e400", "infinity"] {
            let e = run(&format!("1e0 {bad} 2e0"), "1e-3", &[]).to_output(3, 0).unwrap_err();
            assert!(e.contains("not a finite number"), "{bad}: {e}");
            let e = run("1e0", bad, &[]).to_output(1, 0).unwrap_err();
            assert!(e.contains("not a finite number"), "{bad}: {e}");
            if bad != "NaN" {
                let e = run("1e0", "1e-3", &[&format!("1e0 {bad}")])
                    .to_output(1, 1)
                    .unwrap_err();
                assert!(e.contains("not a finite number"), "{bad}: {e}");
            }
        }
        let e = run("1e0", "-1e0", &[]).to_output(1, 0).unwrap_err();
        assert!(e.contains("negative"), "{e}");
        let e = run("1e0", "1e0", &["1e0 2e0", "1e0"]).to_output(1, 2).unwrap_err();
        assert!(e.contains("frame columns of 2 and 1 values"), "{e}");
        let e = run("x", "1e0", &[]).to_output(1, 0).unwrap_err();
        assert!(e.contains("`x` is not a number"), "{e}");
    }

    #[test]
    fn the_checksum_changes_with_any_run() {
        let a = vec![run("1e0", "1e-3", &["1e0"])];
        let mut b = a.clone();
        assert_eq!(runs_checksum(&a), runs_checksum(&b));
        b[0].values = "1.0000000000000002e0".into();
        assert_ne!(runs_checksum(&a), runs_checksum(&b));
        let mut c = a.clone();
        c[0].seed = 2;
        assert_ne!(runs_checksum(&a), runs_checksum(&c));
    }

    #[test]
    fn more_shards_than_runs_is_refused() {
        let id: ShardId = "1/4294967296".parse().unwrap();
        let e = id.check_runs(12).unwrap_err();
        assert!(e.to_string().contains("N can be at most 12"), "{e}");
        let id: ShardId = "12/12".parse().unwrap();
        id.check_runs(12).unwrap();
    }
}
