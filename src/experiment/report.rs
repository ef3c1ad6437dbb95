//! `report.md`: setup, per-metric tables, derived values, checks, timing
//! and links to the plots.

use std::fmt::Write;

use crate::stats::ci::MeanCi;

use super::results::{ExperimentResult, PointResult};
use super::sample::Sample;
use super::spec::{DerivedKind, Experiment, ModelSource, PlotKind};
use super::sweep::value_text;

/// A number with about four significant digits.
pub(crate) fn fmt_num(v: f64) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e6).contains(&a) {
        return format!("{v:.3e}");
    }
    let digits = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
    format!("{v:.digits$}")
}

/// A number with up to six significant digits, for checks.
pub(crate) fn fmt_precise(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return fmt_num(v);
    }
    let a = v.abs();
    if !(1e-3..1e9).contains(&a) {
        return format!("{v:.5e}");
    }
    let digits = (5 - a.log10().floor() as i32).clamp(0, 8) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// `mean ± half-width` (just the mean when no interval exists).
pub(crate) fn mean_pm(c: &MeanCi) -> String {
    if c.n == 0 {
        "n/a".into()
    } else if c.has_interval {
        format!("{} ± {}", fmt_num(c.mean), fmt_num(c.half_width))
    } else {
        format!("{} (n={})", fmt_num(c.mean), c.n)
    }
}

fn opt(v: Option<f64>) -> String {
    v.map(fmt_num).unwrap_or_else(|| "n/a".into())
}

fn filter_text(f: &[(String, toml::Value)]) -> String {
    f.iter()
        .map(|(k, v)| format!("{k}={}", value_text(v)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Escape `|` so text fits in a Markdown table cell.
pub(crate) fn cell(s: &str) -> String {
    s.replace('|', "\\|")
}

/// Render the report of a finished experiment.
pub(crate) fn render(exp: &Experiment, r: &ExperimentResult) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {}\n", exp.name);
    if !exp.description.trim().is_empty() {
        let _ = writeln!(s, "{}\n", exp.description.trim());
    }

    setup(&mut s, exp, r);
    if let Some(sample) = &exp.sample {
        sampled_parameters(&mut s, sample);
    }
    let point_keys = exp.point_keys();
    let keys: Vec<&str> = point_keys.iter().map(|s| s.as_str()).collect();
    results(&mut s, exp, r, &keys);
    derived(&mut s, exp, r, &keys);
    sensitivity(&mut s, exp, r);
    super::beside_paper::section(&mut s, exp, r);
    claims(&mut s, r);
    checks(&mut s, r);
    timing(&mut s, r);
    plots(&mut s, exp, r);
    s
}

/// The header row (and rule) of a per-point table: the point's `keys`,
/// then the `extra` columns.
fn head(keys: &[&str], extra: &[String]) -> String {
    let cols: Vec<String> = keys
        .iter()
        .map(|k| format!("`{k}`"))
        .chain(extra.iter().cloned())
        .collect();
    let cols = if cols.is_empty() {
        vec!["point".to_string()]
    } else {
        cols
    };
    format!("| {} |\n|{}\n", cols.join(" | "), "---|".repeat(cols.len()))
}

/// A per-point table row's first cells: the point's assignments (or its label).
fn key_cells(p: &PointResult) -> Vec<String> {
    if p.assignments.is_empty() {
        vec![cell(&p.label)]
    } else {
        p.assignments.iter().map(|(_, v)| cell(v)).collect()
    }
}

/// `p` with `name/..` pairs and `.` parts taken out, without asking the
/// file system (`experiments/../models/fixed.toml` is `models/fixed.toml`;
/// a leading `..` stays).
///
/// ```
/// use std::path::Path;
/// use rendersim::experiment::lexically_normal;
///
/// assert_eq!(lexically_normal(Path::new("experiments/../models/./fixed.toml")), Path::new("models/fixed.toml"));
/// assert_eq!(lexically_normal(Path::new("../shared/a.csv")), Path::new("../shared/a.csv"));
/// ```
pub fn lexically_normal(p: &std::path::Path) -> std::path::PathBuf {
    use std::path::Component;
    let mut out: Vec<Component<'_>> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out.iter().collect()
}

/// `## Setup`: the model, replications, confidence, points, fixed settings
/// and sweeps.
fn setup(s: &mut String, exp: &Experiment, r: &ExperimentResult) {
    let _ = writeln!(s, "## Setup\n");
    let model = match &exp.model {
        ModelSource::Default => "the embedded default model".to_string(),
        ModelSource::File(p) => format!("`{}`", lexically_normal(p).display()),
    };
    let _ = writeln!(s, "- model: {model}");
    let seeds = exp.seeds();
    let _ = writeln!(
        s,
        "- replications: {} per point (seeds {}..={})",
        exp.replications,
        seeds.first().copied().unwrap_or(exp.base_seed),
        seeds.last().copied().unwrap_or(exp.base_seed)
    );
    let _ = writeln!(s, "- confidence: {}% (Student's t)", exp.confidence * 100.0);
    let _ = writeln!(s, "- points: {}, runs: {}", r.points.len(), r.runs.len());
    if !exp.set.is_empty() {
        let _ = writeln!(s, "\nFixed settings:\n\n| key | value |\n|---|---|");
        for (k, v) in &exp.set {
            let _ = writeln!(s, "| `{k}` | {} |", cell(&v.to_string()));
        }
    }
    if !exp.sweeps.is_empty() {
        let _ = writeln!(
            s,
            "\nSweeps (cartesian product, first varies slowest):\n\n| key | values |\n|---|---|"
        );
        for sw in &exp.sweeps {
            let vals: Vec<String> = sw.values.iter().map(value_text).collect();
            let _ = writeln!(s, "| `{}` | {} |", sw.key, cell(&vals.join(", ")));
        }
    }
}

/// The sampled parameters' table (with the sampling design).
fn sampled_parameters(s: &mut String, sample: &Sample) {
    use super::sample::{SampleMethod, Scale};
    let how = match sample.method {
        SampleMethod::LatinHypercube => format!("Latin hypercube of {} points", sample.n),
        SampleMethod::Sobol => format!(
            "Saltelli's design for Sobol' indices: n = {} rows of A and B (one Latin hypercube in {} dimensions) \
             and A_B^(i) per parameter, n (k + 2) = {} points; {} bootstrap resamples",
            sample.n,
            2 * sample.params.len(),
            sample.points(),
            sample.bootstrap
        ),
    };
    let _ = writeln!(
        s,
        "\nSampled parameters ({how}; seed {}):\n\n| key | from | to | scale | values |\n|---|---|---|---|---|",
        sample.seed
    );
    for p in &sample.params {
        let scale = match p.scale {
            Scale::Linear => "linear",
            Scale::Log => "log",
        };
        let kind = match (&p.unit, p.integer) {
            (Some(u), true) => format!("integers, in {u}"),
            (Some(u), false) => format!("real, in {u}"),
            (None, true) => "integers".into(),
            (None, false) => "real".into(),
        };
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {scale} | {kind} |",
            p.key,
            fmt_num(p.from),
            fmt_num(p.to)
        );
    }
}

/// `## Results`: a table per metric (a summary over sampled points).
fn results(s: &mut String, exp: &Experiment, r: &ExperimentResult, keys: &[&str]) {
    let _ = writeln!(s, "\n## Results\n");
    let level = format!("{}%", exp.confidence * 100.0);
    for m in &exp.metrics {
        let _ = writeln!(s, "### {} (`{}`)\n", m.label, m.path);
        if exp.sample.is_some() {
            // Sampled points are many and unordered: a summary here, every
            // point in points.csv.
            let means: Vec<f64> = r.points.iter().filter_map(|p| p.mean(&m.path)).collect();
            if means.is_empty() {
                let _ = writeln!(s, "No values.\n");
            } else {
                let (lo, hi) = means
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
                let _ = writeln!(
                    s,
                    "Over the {} sampled points with a value (replication means; each point in `points.csv`): \
                     min {}, mean {}, max {}.\n",
                    means.len(),
                    fmt_num(lo),
                    fmt_num(means.iter().sum::<f64>() / means.len() as f64),
                    fmt_num(hi)
                );
            }
            continue;
        }
        s.push_str(&head(keys, &[format!("mean ± {level} CI"), "n".into()]));
        for p in &r.points {
            let mut row = key_cells(p);
            match p.stat(&m.path) {
                Some(c) => {
                    row.push(mean_pm(c));
                    row.push(c.n.to_string());
                }
                None => row.extend(["n/a".to_string(), "0".to_string()]),
            }
            let _ = writeln!(s, "| {} |", row.join(" | "));
        }
        s.push('\n');
    }
}

/// `## Derived values`: what each derived value is, and their table.
fn derived(s: &mut String, exp: &Experiment, r: &ExperimentResult, keys: &[&str]) {
    if !exp.derived.is_empty() {
        let _ = writeln!(s, "## Derived values\n");
        for d in &exp.derived {
            let what = match &d.kind {
                DerivedKind::IntervalWidth { column, level } => format!(
                    "width of the central {}% interval of per-frame `{column}` (pooled over replications)",
                    level * 100.0
                ),
                DerivedKind::QuantileWidthFromMin { column, level } => format!(
                    "{}% quantile minus minimum of per-frame `{column}` (pooled over replications)",
                    level * 100.0
                ),
                DerivedKind::Modes {
                    column,
                    bin,
                    prominence,
                } => format!(
                    "modes of per-frame `{column}` (pooled over replications) in bins of {bin}: local maxima standing at least {}% of the tallest bin above the lowest bin towards any taller one",
                    prominence * 100.0
                ),
                DerivedKind::LargestBinShare { column, bin } => {
                    format!("share of per-frame `{column}` (pooled over replications) in its fullest bin of {bin}")
                }
                DerivedKind::RelativeError { path, reference } => format!(
                    "|mean `{path}` − reference| / |reference|, reference at {}",
                    filter_text(reference)
                ),
                DerivedKind::Ratio { path, reference } => {
                    format!("mean `{path}` / reference, reference at {}", filter_text(reference))
                }
                DerivedKind::Speedup { path, reference } => format!(
                    "reference `{path}` / this `{path}`, reference at {}",
                    filter_text(reference)
                ),
            };
            let _ = writeln!(s, "- `{}`: {what}", d.name);
        }
        s.push('\n');
        let names: Vec<String> = exp.derived.iter().map(|d| format!("`{}`", d.name)).collect();
        s.push_str(&head(keys, &names));
        for p in &r.points {
            let mut row = key_cells(p);
            row.extend(p.derived.iter().map(|d| opt(d.1)));
            let _ = writeln!(s, "| {} |", row.join(" | "));
        }
        s.push('\n');
    }
}

/// `## Sensitivity (Sobol' indices)`: each metric's indices.
fn sensitivity(s: &mut String, exp: &Experiment, r: &ExperimentResult) {
    if !r.sensitivity.is_empty() {
        let _ = writeln!(
            s,
            "## Sensitivity (Sobol' indices)\n\nWhich parameters drive each metric: the first-order index S_i is the share of \
             the metric's variance (over the sampled ranges, of the replication means) that parameter i explains alone; the \
             total index S_Ti adds its interactions with the others. Estimators of Saltelli et al. (2010): S_i from \
             f(B)·(f(A_B^(i)) − f(A)), S_Ti from Jansen's (f(A) − f(A_B^(i)))²; {}% percentile bootstrap intervals. \
             Small negative values are estimation noise around 0.\n",
            exp.confidence * 100.0
        );
        for sens in &r.sensitivity {
            let _ = writeln!(s, "### {} (`{}`)\n", sens.label, sens.path);
            let Some(indices) = &sens.indices else {
                let _ = writeln!(
                    s,
                    "Not computed: fewer than two complete rows, or the metric does not vary.\n"
                );
                continue;
            };
            let _ = writeln!(
                s,
                "| parameter | first order S_i | CI | total S_Ti | CI |\n|---|---|---|---|---|"
            );
            for (key, i) in indices {
                let _ = writeln!(
                    s,
                    "| `{key}` | {} | [{}, {}] | {} | [{}, {}] |",
                    fmt_num(i.first),
                    fmt_num(i.first_ci.0),
                    fmt_num(i.first_ci.1),
                    fmt_num(i.total),
                    fmt_num(i.total_ci.0),
                    fmt_num(i.total_ci.1)
                );
            }
            let _ = writeln!(
                s,
                "\n![{}]({f}.svg)\n",
                super::sobol::indices_title(&sens.label),
                f = sens.plot
            );
        }
    }
}

/// `## Claims`: each claim's verdict and its checks.
fn claims(s: &mut String, r: &ExperimentResult) {
    let claims = r.claims();
    if !claims.is_empty() {
        let _ = writeln!(
            s,
            "## Claims\n\nVerdicts, not tests: each claim is checked like a reference check, and the \
             outcome says whether it holds here. A claim that does not hold does not fail the experiment.\n"
        );
        for (claim, holds, total) in &claims {
            let verdict = match *holds {
                h if h == *total => "**HOLDS**".to_string(),
                0 => "**DOES NOT HOLD**".to_string(),
                h => format!("**HOLDS IN PART** ({h} of {total})"),
            };
            let _ = writeln!(s, "- {verdict}: {claim}");
        }
        let _ = writeln!(
            s,
            "\n| claim | value | point | measured | expected | measured / expected | tolerance | error | verdict |\n|---|---|---|---|---|---|---|---|---|"
        );
        for c in r.checks.iter().filter(|c| c.claim.is_some()) {
            let _ = writeln!(
                s,
                "| {} | `{}` | {} | {} | {} | {} | {} | {} | {} |",
                cell(c.claim.as_deref().unwrap_or_default()),
                c.path,
                cell(&c.point),
                c.measured.map(fmt_precise).unwrap_or_else(|| "n/a".into()),
                cell(&c.expected_text),
                c.ratio_text(),
                c.tolerance_text,
                cell(&c.error_text()),
                if c.passed { "holds" } else { "does not hold" }
            );
        }
        s.push('\n');
    }
}

/// `## Checks`: the reference checks that are not claims.
fn checks(s: &mut String, r: &ExperimentResult) {
    let tests: Vec<_> = r.checks.iter().filter(|c| c.claim.is_none()).collect();
    if !tests.is_empty() {
        let _ = writeln!(
            s,
            "## Checks\n\n{} of {} passed. `error` is measured minus expected (for bounds: the distance \
             beyond the bound, 0 inside), relative to the expected value or bound.\n\n\
             | value | point | measured | expected | measured / expected | tolerance | error | result |\n|---|---|---|---|---|---|---|---|",
            tests.len() - r.checks_failed,
            tests.len()
        );
        for c in tests {
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {} | {} | {} | {} | {} |",
                c.path,
                cell(&c.point),
                c.measured.map(fmt_precise).unwrap_or_else(|| "n/a".into()),
                cell(&c.expected_text),
                c.ratio_text(),
                c.tolerance_text,
                cell(&c.error_text()),
                if c.passed { "PASS" } else { "**FAIL**" }
            );
        }
        s.push('\n');
    }
}

/// `## Timing`: wall and CPU times.
fn timing(s: &mut String, r: &ExperimentResult) {
    let _ = writeln!(s, "## Timing\n");
    if crate::output::timing::timing_fixed() {
        let _ = writeln!(
            s,
            "Wall and CPU times are written as 0 (`SOURCE_DATE_EPOCH` or `--no-timing`: outputs comparable byte for byte).\n"
        );
    }
    match &r.shards {
        None => {
            let _ = writeln!(s, "- experiment wall time: {:.3} s", r.wall_seconds);
            if let Some(cpu) = r.cpu_seconds {
                let _ = writeln!(s, "- CPU time: {cpu:.3} s (user + system, one process)");
            }
        }
        Some(c) => {
            let _ = writeln!(
                s,
                "- array wall time: {:.3} s ({} shards, from the first shard's start to the last shard's end)",
                c.array_wall_seconds, c.shards
            );
            let _ = write!(
                s,
                "- total CPU time over all shards: {:.3} s (user + system)",
                c.cpu_seconds
            );
            match r.cpu_seconds {
                Some(m) => {
                    let _ = writeln!(s, ", plus {m:.3} s to merge");
                }
                None => s.push('\n'),
            }
        }
    }
    let _ = writeln!(
        s,
        "- summed simulation wall time: {:.3} s over {} runs\n",
        r.sim_wall_seconds,
        r.runs.len()
    );
}

/// `## Plots`: each plot with its links and notes.
fn plots(s: &mut String, exp: &Experiment, r: &ExperimentResult) {
    if !exp.plots.is_empty() {
        let _ = writeln!(s, "## Plots\n");
        for p in &exp.plots {
            let kind = match p.kind {
                PlotKind::Line { .. } => "line",
                PlotKind::Histogram { .. } => "histogram",
                PlotKind::Scatter { .. } => "scatter",
                PlotKind::Bars { .. } => "bar",
            };
            let _ = writeln!(
                s,
                "### {}\n\n![{}]({f}.svg)\n\n{kind} plot: [{f}.svg]({f}.svg), [{f}.png]({f}.png)\n",
                p.title,
                p.title,
                f = p.file
            );
            for (_, caption) in r.plot_captions.iter().filter(|c| c.0 == p.file) {
                let _ = writeln!(s, "Note: {caption}.\n");
            }
        }
    }
}

/// Ends `out_dir/report.md` with its `## Provenance` section (who wrote
/// the results, how, when): added after the report is written, by the
/// command line and the Python package alike.
pub fn add_provenance(
    out_dir: &std::path::Path,
    provenance: &crate::output::provenance::Provenance,
) -> Result<(), super::ExperimentError> {
    let path = out_dir.join("report.md");
    let io = |source| super::ExperimentError::Io {
        path: path.clone(),
        source,
    };
    let mut text = std::fs::read_to_string(&path).map_err(io)?;
    if !text.ends_with("\n\n") {
        text.push('\n');
    }
    text.push_str(&provenance.markdown_section());
    std::fs::write(&path, text).map_err(io)
}
