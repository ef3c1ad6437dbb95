//! `rendersim experiment` beyond one process: `--shard K/N` (one part of
//! the runs), `--merge` (the parts into the outputs of one process) and
//! `--slurm` (batch scripts for a Slurm job array, `--submit` to submit
//! them). The work is in [`rendersim::experiment`]'s shard and slurm
//! modules; this is the glue.

use super::progress::{esay, say};
use std::path::Path;

use anyhow::{Context, Result, bail};

use rendersim::experiment::{
    Experiment, SHARDS_DIR, ShardOutcome, SimRunner, SlurmOptions, expand_points, merge_shards, run_shard, sbatch,
    slurm_scripts,
};
use rendersim::output::files::write_output;
use rendersim::output::result_set::{ResultSet, claim_folder};

use super::args::ExperimentArgs;
use super::commands::ChecksFailed;

/// What `--slurm` and the shards write into the output folder besides the
/// shard files; a merge keeps them.
const SLURM_FILES: [&str; 3] = ["job.sbatch", "merge.sbatch", "logs"];

/// `rendersim experiment` with `--shard`, `--merge` or `--slurm`.
pub fn experiment(
    args: &ExperimentArgs,
    exp: &Experiment,
    base: &toml::Table,
    out: &Path,
    legacy: fn(&str) -> bool,
) -> Result<()> {
    let ours = move |name: &str| legacy(name) || name.ends_with(".sbatch");
    let runner = SimRunner::for_experiment(exp);
    if let Some(id) = args.shard {
        // Refused before the folder is claimed (run_shard checks it too).
        id.check_runs(expand_points(exp).len() * exp.seeds().len())?;
        let dir = claim_folder(out, Some("experiment"), ours, args.force)?;
        match run_shard(exp, base, &runner, &dir, id, !args.quiet)? {
            ShardOutcome::Complete { path, runs } => {
                say!(
                    "shard {id}: already complete ({runs} runs in {}); nothing to do",
                    path.display()
                );
            }
            ShardOutcome::Ran {
                path,
                runs,
                wall_seconds,
                cpu_seconds,
                redone,
            } => {
                if let Some(why) = redone {
                    esay!("shard {id}: the earlier file was redone: {why}");
                }
                let cpu = cpu_seconds.map(|c| format!(", {c:.2} s CPU")).unwrap_or_default();
                say!(
                    "shard {id}: {runs} runs in {wall_seconds:.2} s wall{cpu}; wrote {}",
                    path.display()
                );
            }
        }
        return Ok(());
    }
    if args.merge {
        let set = ResultSet::begin_kind(out, Some("experiment"), ours, args.force)?;
        let result = merge_shards(exp, base, &runner, set.target(), set.dir())?;
        for name in std::iter::once(SHARDS_DIR).chain(SLURM_FILES) {
            set.keep(name)?;
        }
        super::commands::add_report_provenance(set.dir())?;
        set.commit()?;
        if !args.quiet {
            say!("{}", result.table(exp));
        }
        let cost = result.shards.as_ref();
        say!(
            "experiment {:?}: {} points from {} shards{}; array wall time {:.2} s, CPU time {:.2} s over all shards; results in {}",
            exp.name,
            result.points.len(),
            cost.map_or(0, |c| c.shards),
            result.tally(),
            result.wall_seconds,
            cost.map_or(0.0, |c| c.cpu_seconds),
            out.display()
        );
        if result.checks_failed > 0 {
            return Err(ChecksFailed {
                failed: result.checks_failed,
                report: out.join("report.md").display().to_string(),
            }
            .into());
        }
        return Ok(());
    }
    slurm(args, exp, out, ours)
}

/// `--slurm`: the batch scripts, submitted with `--submit`.
fn slurm(args: &ExperimentArgs, exp: &Experiment, out: &Path, ours: impl Fn(&str) -> bool) -> Result<()> {
    let runs = expand_points(exp).len() * exp.seeds().len();
    let shards = args.shards.unwrap_or(runs.min(16));
    if shards == 0 {
        bail!("--shards 0: needs at least one shard");
    }
    if shards > runs {
        bail!("--shards {shards}: more shards than the experiment's {runs} runs; give at most {runs}");
    }
    let mut opts = SlurmOptions {
        shards,
        partition: args.partition.clone(),
        time: args.time.clone(),
        cpus_per_task: args.cpus_per_task.unwrap_or(1),
        throttle: args.throttle,
        extra: args.slurm_opt.clone(),
        binary: std::env::current_exe().context("finding the rendersim binary")?,
        experiment: std::path::absolute(&args.file).with_context(|| format!("{}", args.file.display()))?,
        out_dir: std::path::absolute(out).with_context(|| format!("{}", out.display()))?,
    };
    // Options checked before the folder is made: a bad one leaves nothing.
    slurm_scripts(exp, &opts)?;
    let dir = claim_folder(out, Some("experiment"), ours, args.force)?;
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs).with_context(|| format!("creating folder {}", logs.display()))?;
    opts.out_dir = dir.clone();
    let scripts = slurm_scripts(exp, &opts)?;
    let job = dir.join("job.sbatch");
    let merge = dir.join("merge.sbatch");
    write_output(&job, |w| w.write_all(scripts.job.as_bytes()))?;
    write_output(&merge, |w| w.write_all(scripts.merge.as_bytes()))?;
    say!(
        "wrote {} (a job array of {shards} shards, {runs} runs) and {}",
        job.display(),
        merge.display()
    );
    if !args.submit {
        say!(
            "submit with: jid=$(sbatch --parsable {}) && sbatch --dependency=afterany:${{jid%%;*}} {}",
            rendersim::experiment::shell_quote(&job.to_string_lossy()),
            rendersim::experiment::shell_quote(&merge.to_string_lossy())
        );
        return Ok(());
    }
    let array = sbatch(&job, None)?;
    let merged = sbatch(&merge, Some(&array))?;
    say!(
        "submitted array job {array} ({shards} tasks) and merge job {merged} (runs once every task has ended, \
         whatever its outcome, and names any shard that is missing)"
    );
    say!("results in {} once job {merged} ends", dir.display());
    Ok(())
}
