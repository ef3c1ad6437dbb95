//! Slurm batch scripts for an experiment split into shards: `job.sbatch`,
//! a job array with one task per shard (each runs `rendersim experiment
//! FILE --out DIR --shard $SLURM_ARRAY_TASK_ID/N`), and `merge.sbatch`,
//! which merges the shards (`--merge`) once every task has succeeded
//! (submitted with `--dependency=afterok:<array job id>`).
//!
//! The scripts name the rendersim binary, the experiment file and the
//! output folder by absolute paths, so they run from any folder of a
//! cluster whose nodes share that file system. Each task sets
//! `RAYON_NUM_THREADS` to its `--cpus-per-task`, so a shard uses the cores
//! Slurm gave it and no more.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::spec::Experiment;

/// What `--slurm` was asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct SlurmOptions {
    /// Shards, one array task each.
    pub shards: usize,
    /// `--partition`, if any (else the cluster's default).
    pub partition: Option<String>,
    /// `--time` limit per task, if any (Slurm's formats: `MM`, `MM:SS`,
    /// `HH:MM:SS`, `D-HH`, `D-HH:MM`, `D-HH:MM:SS`).
    pub time: Option<String>,
    /// CPUs per task (and rayon threads per shard).
    pub cpus_per_task: u32,
    /// The rendersim binary the tasks run (absolute).
    pub binary: PathBuf,
    /// The experiment file (absolute).
    pub experiment: PathBuf,
    /// The output folder (absolute).
    pub out_dir: PathBuf,
}

/// The two scripts.
#[derive(Debug, Clone, PartialEq)]
pub struct SlurmScripts {
    /// `job.sbatch`: the array of shards.
    pub job: String,
    /// `merge.sbatch`: the merge, to run after the array.
    pub merge: String,
}

/// Why the scripts could not be written or submitted.
#[derive(Debug, thiserror::Error)]
pub enum SlurmError {
    /// An option value Slurm would not take.
    #[error("--{option} {value:?}: {message}")]
    Option {
        /// The option.
        option: &'static str,
        /// Its value.
        value: String,
        /// What is wrong.
        message: String,
    },
    /// A path an `#SBATCH` line or the scripts cannot hold.
    #[error("{}: {message}", path.display())]
    Path {
        /// The path.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// `sbatch` could not be run or refused a script.
    #[error("sbatch {script}: {message}")]
    Submit {
        /// The script submitted.
        script: String,
        /// What went wrong (sbatch's own words where it gave some).
        message: String,
    },
}

/// `s` quoted for a POSIX shell.
fn shell_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

fn path_text(p: &Path, in_sbatch_line: bool) -> Result<String, SlurmError> {
    let s = p.to_str().ok_or_else(|| SlurmError::Path {
        path: p.to_path_buf(),
        message: "is not valid UTF-8".into(),
    })?;
    if s.contains(['\n', '\r']) || (in_sbatch_line && s.contains(|c: char| c.is_whitespace() || c == '%')) {
        return Err(SlurmError::Path {
            path: p.to_path_buf(),
            message: "Slurm's #SBATCH --output lines cannot hold white space, `%` or line breaks in the output \
                      folder; give another --out"
                .into(),
        });
    }
    Ok(s.to_string())
}

/// Whether `t` is one of Slurm's time formats.
fn valid_time(t: &str) -> bool {
    let num = |s: &str| !s.is_empty() && s.len() <= 6 && s.bytes().all(|b| b.is_ascii_digit());
    let (days, rest) = match t.split_once('-') {
        Some((d, r)) => (Some(d), r),
        None => (None, t),
    };
    if days.is_some_and(|d| !num(d)) {
        return false;
    }
    let parts: Vec<&str> = rest.split(':').collect();
    parts.iter().all(|p| num(p)) && (1..=3).contains(&parts.len())
}

/// The scripts for `exp` with `opts` (see the module documentation).
pub fn slurm_scripts(exp: &Experiment, opts: &SlurmOptions) -> Result<SlurmScripts, SlurmError> {
    if opts.shards == 0 {
        return Err(SlurmError::Option {
            option: "shards",
            value: "0".into(),
            message: "needs at least 1".into(),
        });
    }
    if opts.cpus_per_task == 0 {
        return Err(SlurmError::Option {
            option: "cpus-per-task",
            value: "0".into(),
            message: "needs at least 1".into(),
        });
    }
    if let Some(p) = &opts.partition
        && (p.is_empty() || !p.chars().all(|c| c.is_ascii_alphanumeric() || "_.,-".contains(c)))
    {
        return Err(SlurmError::Option {
            option: "partition",
            value: p.clone(),
            message: "a partition name (letters, digits, `_`, `-`, `.`; a comma-separated list for several)".into(),
        });
    }
    if let Some(t) = &opts.time
        && !valid_time(t)
    {
        return Err(SlurmError::Option {
            option: "time",
            value: t.clone(),
            message: "Slurm's time formats are MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM and D-HH:MM:SS".into(),
        });
    }
    let bin = shell_quote(&path_text(&opts.binary, false)?);
    let file = shell_quote(&path_text(&opts.experiment, false)?);
    let out_raw = path_text(&opts.out_dir, true)?;
    let out = shell_quote(&out_raw);
    let name: String = exp
        .name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .take(48)
        .collect();
    let n = opts.shards;
    let c = opts.cpus_per_task;
    let mut common = format!("#SBATCH --cpus-per-task={c}\n");
    if let Some(p) = &opts.partition {
        common.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    if let Some(t) = &opts.time {
        common.push_str(&format!("#SBATCH --time={t}\n"));
    }
    let version = env!("CARGO_PKG_VERSION");
    let job = format!(
        "#!/bin/bash\n\
         # Written by rendersim {version} (`rendersim experiment --slurm`) for experiment {name:?}:\n\
         # one array task per shard; each runs its share of the runs and writes\n\
         # {out_raw}/shards/shard-K-of-{n}.json. A task whose shard file is complete\n\
         # does nothing, so a preempted or failed array can be submitted again.\n\
         # Submit with the merge after it:\n\
         #   jid=$(sbatch --parsable job.sbatch) && sbatch --dependency=afterok:${{jid%%;*}} merge.sbatch\n\
         #SBATCH --job-name=rendersim-{name}\n\
         #SBATCH --array=1-{n}\n\
         #SBATCH --output={out_raw}/logs/shard-%a.out\n\
         {common}\
         set -eu\n\
         export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{c}}}\"\n\
         exec {bin} experiment {file} --out {out} --shard \"${{SLURM_ARRAY_TASK_ID}}/{n}\"\n"
    );
    let merge = format!(
        "#!/bin/bash\n\
         # Written by rendersim {version} (`rendersim experiment --slurm`) for experiment {name:?}:\n\
         # merges the {n} shards in {out_raw}/shards into runs.csv, points.csv, the\n\
         # plots and report.md, as one process would have written them. Submit it\n\
         # after the array job: sbatch --dependency=afterok:<array job id> merge.sbatch\n\
         #SBATCH --job-name=rendersim-{name}-merge\n\
         #SBATCH --output={out_raw}/logs/merge.out\n\
         {common}\
         set -eu\n\
         export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{c}}}\"\n\
         exec {bin} experiment {file} --out {out} --merge --quiet\n"
    );
    Ok(SlurmScripts { job, merge })
}

/// The job id `sbatch --parsable` printed (`ID` or `ID;CLUSTER`).
fn parse_job_id(stdout: &str) -> Option<String> {
    let line = stdout.lines().map(str::trim).rfind(|l| !l.is_empty())?;
    let id = line.split(';').next()?.trim();
    (!id.is_empty() && id.bytes().all(|b| b.is_ascii_digit())).then(|| id.to_string())
}

/// Runs `sbatch --parsable [--dependency=afterok:ID] SCRIPT` and returns
/// the job id. `sbatch` is taken from `RENDERSIM_SBATCH` if set (a wrapper,
/// or a stand-in in tests), else from `PATH`.
pub fn sbatch(script: &Path, after_ok: Option<&str>) -> Result<String, SlurmError> {
    let program = std::env::var_os("RENDERSIM_SBATCH").unwrap_or_else(|| "sbatch".into());
    let mut cmd = Command::new(&program);
    cmd.arg("--parsable");
    if let Some(id) = after_ok {
        cmd.arg(format!("--dependency=afterok:{id}"));
    }
    cmd.arg(script);
    let shown = script.display().to_string();
    let out = cmd.output().map_err(|e| SlurmError::Submit {
        script: shown.clone(),
        message: format!(
            "cannot run {}: {e} (is Slurm installed here? the scripts are written; submit them by hand)",
            Path::new(&program).display()
        ),
    })?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(SlurmError::Submit {
            script: shown,
            message: format!("{} ({})", String::from_utf8_lossy(&out.stderr).trim(), out.status),
        });
    }
    parse_job_id(&stdout).ok_or_else(|| SlurmError::Submit {
        script: shown,
        message: format!("no job id in sbatch's output {:?}", stdout.trim()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_formats() {
        for ok in ["30", "30:00", "1:00:00", "2-0", "2-12:00", "2-12:00:00"] {
            assert!(valid_time(ok), "{ok}");
        }
        for bad in ["", "1h", "1:2:3:4", "-5", "a-1", "1-", "1:00;rm"] {
            assert!(!valid_time(bad), "{bad}");
        }
    }

    #[test]
    fn job_ids_and_quotes() {
        assert_eq!(parse_job_id("123\n"), Some("123".into()));
        assert_eq!(parse_job_id("123;cluster\n"), Some("123".into()));
        assert_eq!(parse_job_id("Submitted batch job 5\n"), None);
        assert_eq!(shell_quote("a'b"), r"'a'\''b'");
    }
}
