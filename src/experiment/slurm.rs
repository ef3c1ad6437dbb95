//! Slurm batch scripts for an experiment split into shards: `job.sbatch`,
//! a job array with one task per shard (each runs `rendersim experiment
//! FILE --out DIR --shard $SLURM_ARRAY_TASK_ID/N`; `--throttle` caps how
//! many run at once), and `merge.sbatch`, which merges the shards
//! (`--merge`) once every task has ended, whatever its outcome (submitted
//! with `--dependency=afterany:<array job id>`): with all shards there it
//! writes the results; with some missing (a task failed, timed out or was
//! cancelled) it fails naming them and the `sbatch --array=...` that runs
//! them again. Options rendersim has no flag for (`--account`, `--mem`,
//! `--qos`, ...) pass through `--slurm-opt` into both scripts.
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
    /// At most this many array tasks at once (Slurm's `--array=1-N%T`).
    pub throttle: Option<usize>,
    /// Further `#SBATCH` options for both scripts, each as given
    /// (`--account=proj`, `--mem=4G`, `--qos=short`, `-A proj`).
    pub extra: Vec<String>,
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

/// `s` quoted for a POSIX shell (a command line a user pastes, such as
/// the `submit with:` line, runs nothing a folder name holds).
///
/// ```
/// assert_eq!(rendersim::experiment::shell_quote("/x/a$(id)'b"), r"'/x/a$(id)'\''b'");
/// ```
pub fn shell_quote(s: &str) -> String {
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
    if opts.throttle == Some(0) {
        return Err(SlurmError::Option {
            option: "throttle",
            value: "0".into(),
            message: "needs at least 1 (tasks at once)".into(),
        });
    }
    for o in &opts.extra {
        check_extra(o)?;
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
    for o in &opts.extra {
        common.push_str(&format!("#SBATCH {o}\n"));
    }
    let throttle = opts.throttle.map_or(String::new(), |t| format!("%{t}"));
    let version = env!("CARGO_PKG_VERSION");
    let job = format!(
        "#!/bin/bash\n\
         # Written by rendersim {version} (`rendersim experiment --slurm`) for experiment {name:?}:\n\
         # one array task per shard; each runs its share of the runs and writes\n\
         # {out_raw}/shards/shard-K-of-{n}.json. A task whose shard file is complete\n\
         # does nothing, so a preempted or failed array can be submitted again.\n\
         # Submit with the merge after it:\n\
         #   jid=$(sbatch --parsable job.sbatch) && sbatch --dependency=afterany:${{jid%%;*}} merge.sbatch\n\
         #SBATCH --job-name=rendersim-{name}\n\
         #SBATCH --array=1-{n}{throttle}\n\
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
         # after the array job, whatever its tasks' outcome:\n\
         #   sbatch --dependency=afterany:<array job id> merge.sbatch\n\
         # With a shard missing it fails, naming the shards and the sbatch --array\n\
         # that runs them again; merge.sbatch can then be submitted again.\n\
         #SBATCH --job-name=rendersim-{name}-merge\n\
         #SBATCH --output={out_raw}/logs/merge.out\n\
         {common}\
         set -eu\n\
         export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{c}}}\"\n\
         exec {bin} experiment {file} --out {out} --merge --quiet\n"
    );
    Ok(SlurmScripts { job, merge })
}

/// Options the scripts set themselves, each with the flag that sets it.
const OWN_OPTIONS: [(&str, &str); 9] = [
    ("array", "--shards and --throttle"),
    ("output", "--out (the logs go to DIR/logs)"),
    ("job-name", "the experiment's name"),
    ("dependency", "--submit (the merge runs after the array)"),
    ("cpus-per-task", "--cpus-per-task"),
    ("partition", "--partition"),
    ("time", "--time"),
    ("parsable", "--submit"),
    ("wrap", "the scripts themselves"),
];

/// One `--slurm-opt`: an option (`-x ...` or `--name[=value]`) on one line,
/// not one the scripts set themselves.
fn check_extra(o: &str) -> Result<(), SlurmError> {
    let bad = |message: String| SlurmError::Option {
        option: "slurm-opt",
        value: o.to_string(),
        message,
    };
    if !o.starts_with('-') || o.trim() != o || o.len() < 2 {
        return Err(bad(
            "an sbatch option as it would follow #SBATCH, e.g. --account=proj, --mem=4G, --qos=short or \"-A proj\""
                .into(),
        ));
    }
    if o.contains(['\n', '\r', '#']) {
        return Err(bad("line breaks and `#` cannot go into an #SBATCH line".into()));
    }
    let long = o.strip_prefix("--").map(|r| r.split(['=', ' ']).next().unwrap_or(""));
    let short = match o.as_bytes().get(1) {
        Some(b'a') if !o.starts_with("--") => Some("array"),
        Some(b'o') if !o.starts_with("--") => Some("output"),
        Some(b'J') if !o.starts_with("--") => Some("job-name"),
        Some(b'd') if !o.starts_with("--") => Some("dependency"),
        Some(b'c') if !o.starts_with("--") => Some("cpus-per-task"),
        Some(b'p') if !o.starts_with("--") => Some("partition"),
        Some(b't') if !o.starts_with("--") => Some("time"),
        _ => None,
    };
    if let Some(name) = long.or(short)
        && let Some((_, instead)) = OWN_OPTIONS.iter().find(|(n, _)| *n == name)
    {
        return Err(bad(format!("the scripts set --{name} themselves; use {instead}")));
    }
    Ok(())
}

/// The job id `sbatch --parsable` printed (`ID` or `ID;CLUSTER`).
fn parse_job_id(stdout: &str) -> Option<String> {
    let line = stdout.lines().map(str::trim).rfind(|l| !l.is_empty())?;
    let id = line.split(';').next()?.trim();
    (!id.is_empty() && id.bytes().all(|b| b.is_ascii_digit())).then(|| id.to_string())
}

/// Runs `sbatch --parsable [--dependency=afterany:ID] SCRIPT` and returns
/// the job id. `sbatch` is taken from `RENDERSIM_SBATCH` if set (a wrapper,
/// or a stand-in in tests), else from `PATH`.
pub fn sbatch(script: &Path, after: Option<&str>) -> Result<String, SlurmError> {
    let program = std::env::var_os("RENDERSIM_SBATCH").unwrap_or_else(|| "sbatch".into());
    let mut cmd = Command::new(&program);
    cmd.arg("--parsable");
    if let Some(id) = after {
        cmd.arg(format!("--dependency=afterany:{id}"));
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
    fn extra_options_are_single_sbatch_options_not_ours() {
        for ok in [
            "--account=proj",
            "--mem=4G",
            "--qos=short",
            "-A proj",
            "--exclusive",
            "--mail-type=END,FAIL",
        ] {
            assert!(check_extra(ok).is_ok(), "{ok}");
        }
        for (bad, says) in [
            ("account=proj", "an sbatch option"),
            ("", "an sbatch option"),
            (" --mem=4G", "an sbatch option"),
            ("--mem=4G\n#SBATCH --x", "line breaks"),
            ("--comment=a#b", "line breaks"),
            ("--array=1-3", "use --shards and --throttle"),
            ("--time=10", "use --time"),
            ("-t 10", "use --time"),
            ("--dependency=afterok:1", "use --submit"),
            ("--output=/tmp/x", "use --out"),
            ("-J name", "the experiment's name"),
        ] {
            let e = check_extra(bad).unwrap_err().to_string();
            assert!(e.contains(says) && e.starts_with("--slurm-opt "), "{bad}: {e}");
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
