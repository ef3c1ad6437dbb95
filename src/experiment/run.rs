//! Running an experiment: patch the model per point, run every (point,
//! seed) job in parallel, aggregate, and write CSVs, plots and the report.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::stats::ci::{MeanCi, mean_ci};

use super::check::{Bound, CheckOutcome, evaluate, evaluate_between};
use super::derived::{DerivedInputs, compute};
use super::dotted::json_number;
use super::results::{ExperimentResult, JobOutput, PathStat, PointResult, RunRecord, ShardCost};
use super::runner::Runner;
use super::spec::{BoundRef, Expect, Experiment, MODEL_SWEEP_KEY, ModelSource};
use super::sweep::{Point, expand_points};
use super::{ExperimentError, figures, report, tables};
use crate::config::set_dotted;

/// The model for `point`: `base` (or the model file a `[[sweep]] key =
/// "model"` picks for the point) with `[set]` then the point's other sweep
/// values applied.
pub fn point_model(exp: &Experiment, base: &toml::Table, point: &Point) -> Result<toml::Table, ExperimentError> {
    let mut model = exp.point_base(point, base)?;
    let swept = point.assignments.iter().filter(|(k, _)| k != MODEL_SWEEP_KEY);
    for (k, v) in exp.set.iter().chain(swept) {
        set_dotted(&mut model, k, v.clone())?;
    }
    Ok(model)
}

/// The runs of an experiment, resolved: its points, the model of each
/// point, the tracked summary paths and the frame columns.
pub(crate) struct Plan {
    pub(crate) points: Vec<Point>,
    pub(crate) models: Vec<toml::Table>,
    /// Per point, the model file a model sweep picked (`None`: the
    /// experiment's base model).
    pub(crate) sources: Vec<Option<ModelSource>>,
    pub(crate) paths: Vec<String>,
    pub(crate) columns: Vec<String>,
}

impl Plan {
    /// Expands the points of `exp` and patches a model for each.
    pub(crate) fn new(exp: &Experiment, base_model: &toml::Table) -> Result<Plan, ExperimentError> {
        let points = expand_points(exp);
        let models = points
            .iter()
            .map(|p| point_model(exp, base_model, p))
            .collect::<Result<Vec<_>, _>>()?;
        let sources = points.iter().map(|p| exp.point_source(p)).collect();
        Ok(Plan {
            points,
            models,
            sources,
            paths: exp.tracked_paths(),
            columns: exp.frame_columns(),
        })
    }

    /// Every (point, seed) run, in output order: by point, then seed.
    pub(crate) fn jobs(&self, exp: &Experiment) -> Vec<(usize, u64)> {
        let seeds = exp.seeds();
        self.points
            .iter()
            .flat_map(|p| seeds.iter().map(move |&s| (p.index, s)))
            .collect()
    }

    /// Runs `jobs` in parallel, reporting to `progress` as each ends; the
    /// results are in the order of `jobs`. Once `progress` asks to stop,
    /// the jobs not yet started end in [`ExperimentError::Stopped`].
    pub(crate) fn run(
        &self,
        runner: &dyn Runner,
        jobs: &[(usize, u64)],
        progress: &Progress<'_>,
    ) -> Vec<Result<JobOutput, ExperimentError>> {
        let want_frames = !self.columns.is_empty();
        let total = jobs.len() as u64;
        let bar = progress_bar(total, matches!(progress, Progress::Bar));
        let done = AtomicU64::new(0);
        let stopped = AtomicBool::new(false);
        let results = jobs
            .par_iter()
            .map(|&(pi, seed)| {
                if stopped.load(Ordering::Relaxed) {
                    return Err(ExperimentError::Stopped {
                        done: done.load(Ordering::Relaxed),
                        total,
                    });
                }
                let r = run_job(
                    runner,
                    self.sources[pi].as_ref(),
                    &self.models[pi],
                    &self.points[pi],
                    seed,
                    &self.paths,
                    &self.columns,
                    want_frames,
                );
                bar.inc(1);
                let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                if let Progress::Observe(observe) = progress
                    && !observe(n, total)
                {
                    stopped.store(true, Ordering::Relaxed);
                }
                r
            })
            .collect();
        bar.finish_and_clear();
        results
    }
}

/// How an experiment reports its runs as they end.
///
/// ```
/// use rendersim::experiment::Progress;
///
/// let quiet: Progress = false.into(); // as `run_experiment(.., false)`
/// assert!(matches!(quiet, Progress::Hidden));
/// // A caller's own report; `false` stops the runs not yet started.
/// let report = |done: u64, total: u64| done * 2 < total;
/// let _half = Progress::Observe(&report);
/// ```
pub enum Progress<'a> {
    /// Nothing is shown.
    Hidden,
    /// A bar on standard error (the command line on a terminal).
    Bar,
    /// `f(done, total)` after each run, from the thread that ran it;
    /// returning `false` stops the runs not yet started, and the
    /// experiment then fails with [`ExperimentError::Stopped`] (the Python
    /// package's callbacks and its interrupt).
    Observe(&'a (dyn Fn(u64, u64) -> bool + Sync)),
}

impl From<bool> for Progress<'_> {
    /// `true`: a bar; `false`: nothing.
    fn from(bar: bool) -> Self {
        if bar { Progress::Bar } else { Progress::Hidden }
    }
}

/// Where the time of an experiment went, for the report.
pub(crate) enum Timing {
    /// One process, started at this instant.
    Single(Instant),
    /// Merged from shards.
    Shards(ShardCost),
}

/// Run `exp` on `base_model` through `runner`, writing `runs.csv`,
/// `points.csv`, the plots and `report.md` into `out_dir` (created if needed).
///
/// Jobs run in parallel; results are ordered by point and seed, so output
/// files do not depend on thread scheduling. If a run fails, the runs that
/// finished are still written to `runs.csv` and the first failure (in point,
/// seed order) is returned, naming the point and seed.
pub fn run_experiment<'a>(
    exp: &Experiment,
    base_model: &toml::Table,
    runner: &dyn Runner,
    out_dir: &Path,
    progress: impl Into<Progress<'a>>,
) -> Result<ExperimentResult, ExperimentError> {
    let started = Instant::now();
    let plan = Plan::new(exp, base_model)?;
    std::fs::create_dir_all(out_dir).map_err(|source| ExperimentError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let jobs = plan.jobs(exp);
    let results = plan.run(runner, &jobs, &progress.into());

    let mut outputs = Vec::with_capacity(results.len());
    let mut first_error = None;
    for r in results {
        match r {
            Ok(o) => outputs.push(o),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    if let Some(e) = first_error {
        let runs: Vec<RunRecord> = outputs.iter().map(|o| o.record.clone()).collect();
        tables::write_runs(&out_dir.join("runs.csv"), exp, &plan.points, &plan.paths, &runs)?;
        return Err(e);
    }
    finish(
        exp,
        base_model,
        runner,
        &plan,
        outputs,
        out_dir,
        Timing::Single(started),
    )
}

/// Everything after the runs: `runs.csv`, aggregation per point, derived
/// values, checks, plots, searches and `report.md`. `outputs` hold every
/// run of the plan, in point then seed order (what a single process and a
/// merge of shards both hand over, so both write the same files).
pub(crate) fn finish(
    exp: &Experiment,
    base_model: &toml::Table,
    runner: &dyn Runner,
    plan: &Plan,
    outputs: Vec<JobOutput>,
    out_dir: &Path,
    timing: Timing,
) -> Result<ExperimentResult, ExperimentError> {
    let (points, paths, columns) = (&plan.points, plan.paths.clone(), &plan.columns);
    let runs: Vec<RunRecord> = outputs.iter().map(|o| o.record.clone()).collect();
    tables::write_runs(&out_dir.join("runs.csv"), exp, points, &paths, &runs)?;

    let (point_stats, pooled) = aggregate(exp, plan, &outputs);
    let means: Vec<Vec<Option<f64>>> = point_stats
        .iter()
        .map(|s| s.iter().map(|c| (c.n > 0).then_some(c.mean)).collect())
        .collect();
    let derived = compute(
        exp,
        &DerivedInputs {
            points,
            means: &means,
            paths: &paths,
            frames: &pooled,
            frame_columns: columns,
        },
    );
    let point_results = point_results(exp, points, &paths, &point_stats, &derived);
    let mut files = vec![PathBuf::from("runs.csv")];
    tables::write_points(&out_dir.join("points.csv"), exp, points, &point_results)?;
    files.push(PathBuf::from("points.csv"));

    let checks = run_checks(exp, points, &point_results);
    // Verdicts on claims are reported, never counted as failures.
    let checks_failed = checks.iter().filter(|c| !c.passed && c.claim.is_none()).count();
    let plot_captions = draw_plots(exp, points, &point_results, &pooled, columns, out_dir, &mut files)?;
    let sensitivity = write_sensitivity(exp, &point_results, out_dir, &mut files)?;
    let searches = run_searches(exp, base_model, runner, out_dir, &mut files)?;

    let mut result = ExperimentResult {
        name: exp.name.clone(),
        paths,
        points: point_results,
        sim_wall_seconds: runs.iter().map(|r| r.wall_seconds).sum(),
        runs,
        checks,
        checks_failed,
        wall_seconds: 0.0,
        cpu_seconds: None,
        shards: None,
        files,
        plot_captions,
        searches,
        sensitivity,
    };
    match timing {
        Timing::Single(started) => result.wall_seconds = crate::output::timing::wall(started.elapsed().as_secs_f64()),
        Timing::Shards(cost) => {
            result.wall_seconds = cost.array_wall_seconds;
            result.shards = Some(cost);
        }
    }
    result.cpu_seconds = super::cost::process_cpu_seconds();
    write_report(exp, &mut result, out_dir)?;
    Ok(result)
}

/// Aggregation per point (`outputs` in point, seed order): each tracked
/// path's mean and interval over the point's runs, and each frame column
/// pooled over them.
fn aggregate(exp: &Experiment, plan: &Plan, outputs: &[JobOutput]) -> (Vec<Vec<MeanCi>>, Vec<Vec<Vec<f64>>>) {
    let (points, columns) = (&plan.points, &plan.columns);
    let n_paths = plan.paths.len();
    let mut point_stats: Vec<Vec<MeanCi>> = Vec::with_capacity(points.len());
    let mut pooled: Vec<Vec<Vec<f64>>> = vec![vec![Vec::new(); columns.len()]; points.len()];
    let mut by_point: Vec<Vec<&JobOutput>> = vec![Vec::new(); points.len()];
    for o in outputs {
        if let Some(v) = by_point.get_mut(o.record.point) {
            v.push(o);
        }
    }
    for p in points {
        let mine = &by_point[p.index];
        let stats = (0..n_paths)
            .map(|k| {
                let vals: Vec<f64> = mine.iter().filter_map(|o| o.record.values[k]).collect();
                mean_ci(&vals, exp.confidence)
            })
            .collect();
        point_stats.push(stats);
        for o in mine {
            for (c, col) in o.frames.iter().enumerate() {
                pooled[p.index][c].extend_from_slice(col);
            }
        }
    }
    (point_stats, pooled)
}

/// Each point's result: its label and assignments, its paths' statistics
/// and its derived values.
fn point_results(
    exp: &Experiment,
    points: &[Point],
    paths: &[String],
    point_stats: &[Vec<MeanCi>],
    derived: &[Vec<Option<f64>>],
) -> Vec<PointResult> {
    points
        .iter()
        .map(|p| PointResult {
            index: p.index,
            label: p.label(),
            assignments: p
                .assignments
                .iter()
                .map(|(k, v)| (k.clone(), super::sweep::value_text(v)))
                .collect(),
            stats: paths
                .iter()
                .zip(&point_stats[p.index])
                .map(|(path, ci)| PathStat {
                    path: path.clone(),
                    ci: *ci,
                })
                .collect(),
            derived: exp
                .derived
                .iter()
                .zip(&derived[p.index])
                .map(|(d, v)| (d.name.clone(), *v))
                .collect(),
        })
        .collect()
}

/// The experiment's checks (and claims), each at every point it filters.
fn run_checks(exp: &Experiment, points: &[Point], point_results: &[PointResult]) -> Vec<CheckOutcome> {
    let mut checks = Vec::new();
    for c in &exp.checks {
        for p in points.iter().filter(|p| p.matches(&c.filter)) {
            let pr = &point_results[p.index];
            checks.push(match &c.expect {
                Expect::Value(v) => evaluate(&c.path, &pr.label, pr.value(&c.path), *v, c.tolerance),
                Expect::Between { at_least, at_most } => {
                    fn bound<'a>(b: &'a BoundRef, pr: &PointResult) -> Bound<'a> {
                        match b {
                            BoundRef::Path(path) => Bound {
                                path: path.as_str(),
                                value: pr.value(path),
                            },
                            BoundRef::Value(v) => Bound {
                                path: "",
                                value: Some(*v),
                            },
                        }
                    }
                    let low = at_least.as_ref().map(|b| bound(b, pr));
                    let high = at_most.as_ref().map(|b| bound(b, pr));
                    evaluate_between(&c.path, &pr.label, pr.value(&c.path), low, high, c.tolerance)
                }
            });
            if let Some(last) = checks.last_mut() {
                last.claim = c.claim.clone();
            }
        }
    }
    checks
}

/// The experiment's plots into `out_dir` (their files added to `files`);
/// returns their captions as (plot file, caption).
fn draw_plots(
    exp: &Experiment,
    points: &[Point],
    point_results: &[PointResult],
    pooled: &[Vec<Vec<f64>>],
    columns: &[String],
    out_dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<Vec<(String, String)>, ExperimentError> {
    let mut plot_captions = Vec::new();
    for plot in &exp.plots {
        let captions = figures::draw(exp, plot, points, point_results, pooled, columns, out_dir).map_err(|source| {
            ExperimentError::Plot {
                file: plot.file.clone(),
                source,
            }
        })?;
        plot_captions.extend(captions.into_iter().map(|c| (plot.file.clone(), c)));
        files.push(PathBuf::from(format!("{}.svg", plot.file)));
        files.push(PathBuf::from(format!("{}.png", plot.file)));
    }
    Ok(plot_captions)
}

/// The Sobol' indices of a sampled experiment: `sensitivity.csv` and a
/// bar chart per metric into `out_dir` (their files added to `files`).
fn write_sensitivity(
    exp: &Experiment,
    point_results: &[PointResult],
    out_dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<Vec<super::sobol::Sensitivity>, ExperimentError> {
    let sensitivity = super::sobol::analyse(exp, point_results);
    if !sensitivity.is_empty() {
        let path = out_dir.join("sensitivity.csv");
        std::fs::write(&path, super::sobol::csv(&sensitivity)).map_err(|source| ExperimentError::Io {
            path: path.clone(),
            source,
        })?;
        files.push(PathBuf::from("sensitivity.csv"));
    }
    for s in &sensitivity {
        let Some(indices) = &s.indices else { continue };
        let series = |name: &str, v: fn(&super::sobol::SobolIndex) -> (f64, (f64, f64))| crate::plot::BarSeries {
            name: name.into(),
            values: indices.iter().map(|(_, i)| v(i).0).collect(),
            ci: Some(indices.iter().map(|(_, i)| v(i).1).collect()),
            tint_of_previous: false,
        };
        let chart = crate::plot::BarChart {
            title: super::sobol::indices_title(&s.label),
            y_label: "index (share of the output variance)".into(),
            categories: indices.iter().map(|(k, _)| k.clone()).collect(),
            series: vec![
                series("first order S_i", |i| (i.first, i.first_ci)),
                series("total S_Ti", |i| (i.total, i.total_ci)),
            ],
            log_y: false,
        };
        crate::plot::bar_chart(&out_dir.join(&s.plot), &chart).map_err(|source| ExperimentError::Plot {
            file: s.plot.clone(),
            source,
        })?;
        files.push(PathBuf::from(format!("{}.svg", s.plot)));
        files.push(PathBuf::from(format!("{}.png", s.plot)));
    }
    Ok(sensitivity)
}

/// The experiment's searches (in parallel, on the base model with `[set]`
/// applied, from the first seed), and `searches.csv` into `out_dir` (added
/// to `files`).
fn run_searches(
    exp: &Experiment,
    base_model: &toml::Table,
    runner: &dyn Runner,
    out_dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<Vec<super::inverse::SearchResult>, ExperimentError> {
    let mut search_base = base_model.clone();
    for (k, v) in &exp.set {
        set_dotted(&mut search_base, k, v.clone())?;
    }
    let search_seed = exp.seeds().first().copied().unwrap_or(1);
    let searches: Vec<super::inverse::SearchResult> = exp
        .searches
        .par_iter()
        .map(|sp| {
            sp.run(runner, &search_base, search_seed)
                .map_err(|source| ExperimentError::Search {
                    name: sp.name.clone(),
                    source: Box::new(source),
                })
        })
        .collect::<Result<_, _>>()?;
    if !searches.is_empty() {
        let path = out_dir.join("searches.csv");
        std::fs::write(&path, super::inverse::csv(&searches)).map_err(|source| ExperimentError::Io {
            path: path.clone(),
            source,
        })?;
        files.push(PathBuf::from("searches.csv"));
    }
    Ok(searches)
}

/// `report.md` into `out_dir` (the report, then the searches' section),
/// added to the result's files.
fn write_report(exp: &Experiment, result: &mut ExperimentResult, out_dir: &Path) -> Result<(), ExperimentError> {
    let report_path = out_dir.join("report.md");
    let report_text = report::render(exp, result) + &super::inverse::report_section(&exp.searches, &result.searches);
    std::fs::write(&report_path, report_text).map_err(|source| ExperimentError::Io {
        path: report_path,
        source,
    })?;
    result.files.push(PathBuf::from("report.md"));
    Ok(())
}

fn progress_bar(len: u64, show: bool) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} runs [{elapsed_precise} < {eta_precise}]") {
        bar.set_style(style);
    }
    bar
}

#[allow(clippy::too_many_arguments)]
fn run_job(
    runner: &dyn Runner,
    source: Option<&ModelSource>,
    model: &toml::Table,
    point: &Point,
    seed: u64,
    paths: &[String],
    columns: &[String],
    want_frames: bool,
) -> Result<JobOutput, ExperimentError> {
    let fail = |message: String| ExperimentError::Run {
        point: point.index,
        label: point.label(),
        seed,
        message,
    };
    let t0 = Instant::now();
    let out = match source {
        None => runner.run(model, seed, want_frames),
        Some(src) => runner.run_from(src, model, seed, want_frames),
    }
    .map_err(|e| fail(e.to_string()))?;
    let measured = crate::output::timing::wall(t0.elapsed().as_secs_f64());
    let wall_seconds = match json_number(&out.summary, "wall_seconds") {
        Ok(Some(w)) => w,
        _ => measured,
    };
    let values = paths
        .iter()
        .map(|p| match json_number(&out.summary, p) {
            Err(_) if p == "wall_seconds" => Ok(Some(wall_seconds)),
            r => r,
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| fail(e.to_string()))?;
    let mut frames = Vec::with_capacity(columns.len());
    if want_frames {
        let table = out
            .frames
            .as_ref()
            .ok_or_else(|| fail("the runner returned no per-frame data although it was requested".into()))?;
        for c in columns {
            frames.push(table.column(c).ok_or_else(|| {
                fail(format!(
                    "frame column `{c}` not found (columns: {})",
                    table.columns.join(", ")
                ))
            })?);
        }
    }
    Ok(JobOutput {
        record: RunRecord {
            point: point.index,
            seed,
            values,
            wall_seconds,
        },
        frames,
    })
}
