//! What an experiment produces: the numbers read from each run, the
//! aggregates per point, the whole result with its checks, files and
//! searches, and the cost of a run split into shards.

use std::path::PathBuf;

use serde::Serialize;

use crate::stats::ci::MeanCi;

use super::check::CheckOutcome;
use super::report;
use super::spec::Experiment;

/// The numbers read from one run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunRecord {
    /// Point index.
    pub point: usize,
    /// Seed.
    pub seed: u64,
    /// One value per [`Experiment::tracked_paths`] entry (`None`: JSON null).
    pub values: Vec<Option<f64>>,
    /// The summary's `wall_seconds`, or the measured call time if absent.
    pub wall_seconds: f64,
}

/// Replication statistics of one summary path at one point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathStat {
    /// Dotted summary path.
    pub path: String,
    /// Mean and confidence interval over the replications.
    pub ci: MeanCi,
}

/// Aggregated results of one point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointResult {
    /// Position in expansion order.
    pub index: usize,
    /// `key=value, ...` label.
    pub label: String,
    /// `(sweep key, value as text)` pairs.
    pub assignments: Vec<(String, String)>,
    /// One entry per tracked path.
    pub stats: Vec<PathStat>,
    /// `(name, value)` per derived value (`None`: undefined here).
    pub derived: Vec<(String, Option<f64>)>,
}

impl PointResult {
    /// The replication statistics of `path`, if tracked.
    pub fn stat(&self, path: &str) -> Option<&MeanCi> {
        self.stats.iter().find(|s| s.path == path).map(|s| &s.ci)
    }

    /// The replication mean of `path` (`None` if untracked or no values).
    pub fn mean(&self, path: &str) -> Option<f64> {
        self.stat(path).filter(|c| c.n > 0).map(|c| c.mean)
    }

    /// A derived value by name.
    pub fn derived_value(&self, name: &str) -> Option<f64> {
        self.derived.iter().find(|d| d.0 == name).and_then(|d| d.1)
    }

    /// A derived value if `name` is one, else the mean of the path `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        if self.derived.iter().any(|d| d.0 == name) {
            self.derived_value(name)
        } else {
            self.mean(name)
        }
    }
}

/// Everything an experiment produced.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExperimentResult {
    /// Experiment name.
    pub name: String,
    /// The summary paths tracked, in the order of `PointResult::stats`.
    pub paths: Vec<String>,
    /// Per-point aggregates, in point order.
    pub points: Vec<PointResult>,
    /// Every run, sorted by point then seed.
    pub runs: Vec<RunRecord>,
    /// Check outcomes, in file order (one per matching point).
    pub checks: Vec<CheckOutcome>,
    /// How many checks failed (verdicts on claims never count).
    pub checks_failed: usize,
    /// Wall time of the whole experiment, in seconds.
    pub wall_seconds: f64,
    /// Sum of the runs' `wall_seconds`.
    pub sim_wall_seconds: f64,
    /// CPU time (user + system) of this process, in seconds, where the
    /// system reports it (for a merge: the merging process alone).
    pub cpu_seconds: Option<f64>,
    /// For outputs merged from shards: their count and cost
    /// (`wall_seconds` is then the array's wall time).
    pub shards: Option<ShardCost>,
    /// Files written, relative to the output directory.
    pub files: Vec<PathBuf>,
    /// Caption lines for the plots, as `(plot file, line)` in plot order
    /// (e.g. histogram values outside the plot's `range`).
    pub plot_captions: Vec<(String, String)>,
    /// Inverse what-ifs, in file order.
    pub searches: Vec<super::inverse::SearchResult>,
    /// Sobol' indices per metric (`[sample] method = "sobol"`; else empty).
    pub sensitivity: Vec<super::sobol::Sensitivity>,
}

impl ExperimentResult {
    /// The most points whose means [`ExperimentResult::table`] lists one
    /// line each; more are in `points.csv` and `report.md`.
    pub const POINT_LINES: usize = 12;

    /// What `rendersim experiment` prints at the end (issue 58 item 3: the
    /// answer, not a line per point): each point's means when there are at
    /// most [`Self::POINT_LINES`] points (else where they are), the
    /// checks' tally with each failed check measured against expected, the
    /// claims' verdicts, the Sobol' indices and the searches' values.
    pub fn table(&self, exp: &Experiment) -> String {
        let mut out = String::new();
        if self.points.len() <= Self::POINT_LINES {
            for p in &self.points {
                let cells: Vec<String> = exp
                    .metrics
                    .iter()
                    .map(|m| match p.stat(&m.path) {
                        Some(c) => format!("{} = {}", m.label, report::mean_pm(c)),
                        None => format!("{} = n/a", m.label),
                    })
                    .collect();
                out.push_str(&format!("{}: {}\n", p.label, cells.join("; ")));
            }
            let derived: Vec<String> = self
                .points
                .iter()
                .filter_map(|p| {
                    let cells: Vec<String> = p
                        .derived
                        .iter()
                        .filter_map(|(name, v)| v.map(|v| format!("{name} = {}", report::fmt_num(v))))
                        .collect();
                    (!cells.is_empty()).then(|| format!("  {}: {}\n", p.label, cells.join("; ")))
                })
                .collect();
            if !derived.is_empty() {
                out.push_str("derived values:\n");
                derived.iter().for_each(|l| out.push_str(l));
            }
        } else {
            out.push_str(&format!(
                "{} points: each point's means are in points.csv, the runs in runs.csv, the plots and tables in report.md\n",
                self.points.len()
            ));
        }
        let tests: Vec<&CheckOutcome> = self.checks.iter().filter(|c| c.claim.is_none()).collect();
        if !tests.is_empty() {
            out.push_str(&format!(
                "checks: {} passed, {} failed\n",
                tests.len() - self.checks_failed,
                self.checks_failed
            ));
            const FAILED_LINES: usize = 10;
            let failed: Vec<&&CheckOutcome> = tests.iter().filter(|c| !c.passed).collect();
            for c in failed.iter().take(FAILED_LINES) {
                out.push_str(&format!(
                    "  FAILED {} at {}: measured {}, expected {} ({}), error {}\n",
                    c.path,
                    c.point,
                    c.measured.map_or("n/a".into(), report::fmt_num),
                    c.expected_text,
                    c.tolerance_text,
                    c.error_text()
                ));
            }
            if failed.len() > FAILED_LINES {
                out.push_str(&format!("  ... and {} more (report.md)\n", failed.len() - FAILED_LINES));
            }
        }
        for (claim, holds, total) in self.claims() {
            let verdict = match holds {
                h if h == total => "HOLDS".to_string(),
                0 => "DOES NOT HOLD".to_string(),
                h => format!("HOLDS IN PART ({h} of {total})"),
            };
            out.push_str(&format!("claim {verdict}: {claim}\n"));
        }
        for s in &self.sensitivity {
            let Some(indices) = &s.indices else {
                out.push_str(&format!(
                    "{}: n/a (the metric does not vary)\n",
                    super::sobol::indices_title(&s.label)
                ));
                continue;
            };
            out.push_str(&format!(
                "{}, first order S1 and total ST with bootstrap 95% intervals:\n",
                super::sobol::indices_title(&s.label)
            ));
            for (key, i) in indices {
                out.push_str(&format!(
                    "  {key}: S1 {:.3} [{:.3}, {:.3}], ST {:.3} [{:.3}, {:.3}]\n",
                    i.first, i.first_ci.0, i.first_ci.1, i.total, i.total_ci.0, i.total_ci.1
                ));
            }
        }
        for r in &self.searches {
            out.push_str(&match r.value {
                Some(v) => format!(
                    "search {}: {} = {} gives {} = {}\n",
                    r.name,
                    r.vary,
                    report::fmt_num(v),
                    r.path,
                    report::fmt_num(r.target)
                ),
                None => format!(
                    "search {}: {} does not reach {} = {} over its bracket ({} to {})\n",
                    r.name,
                    r.vary,
                    r.path,
                    report::fmt_num(r.target),
                    report::fmt_num(r.at_ends.0),
                    report::fmt_num(r.at_ends.1)
                ),
            });
        }
        out
    }

    /// The checks' and claims' outcome for the final line: `, checks 2
    /// passed 0 failed, claims 1 of 2 hold` (empty without either).
    pub fn tally(&self) -> String {
        let mut out = String::new();
        let tests = self.checks.iter().filter(|c| c.claim.is_none()).count();
        if tests > 0 {
            out.push_str(&format!(
                ", checks {} passed {} failed",
                tests - self.checks_failed,
                self.checks_failed
            ));
        }
        let claims = self.claims();
        if !claims.is_empty() {
            let hold = claims.iter().filter(|(_, h, t)| h == t).count();
            out.push_str(&format!(", claims {hold} of {} hold", claims.len()));
        }
        out
    }

    /// Verdicts per claim, in file order: `(claim, outcomes that hold, outcomes)`.
    pub fn claims(&self) -> Vec<(String, usize, usize)> {
        let mut out: Vec<(String, usize, usize)> = Vec::new();
        for c in &self.checks {
            let Some(claim) = &c.claim else { continue };
            let i = match out.iter().position(|o| &o.0 == claim) {
                Some(i) => i,
                None => {
                    out.push((claim.clone(), 0, 0));
                    out.len() - 1
                }
            };
            out[i].1 += usize::from(c.passed);
            out[i].2 += 1;
        }
        out
    }
}

/// What one job returns.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JobOutput {
    pub(crate) record: RunRecord,
    /// Frame columns in `Experiment::frame_columns` order.
    pub(crate) frames: Vec<Vec<f64>>,
}

/// The cost of an experiment run as shards (`--shard K/N`, merged with
/// `--merge`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShardCost {
    /// Number of shards.
    pub shards: usize,
    /// CPU time (user + system) summed over the shard processes, in seconds.
    pub cpu_seconds: f64,
    /// From the start of the first shard to the end of the last, in seconds.
    pub array_wall_seconds: f64,
}
