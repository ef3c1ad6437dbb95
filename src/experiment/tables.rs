//! `runs.csv` (one row per point and seed) and `points.csv` (one row per point).

use std::path::Path;

use super::ExperimentError;
use super::results::{PointResult, RunRecord};
use super::spec::Experiment;
use super::sweep::{Point, value_text};

fn num(v: Option<f64>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

fn write_rows(path: &Path, header: Vec<String>, rows: Vec<Vec<String>>) -> Result<(), ExperimentError> {
    let io = |source| ExperimentError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    crate::output::table::write_table(std::io::BufWriter::new(file), &header, rows).map_err(io)
}

/// Write `runs.csv`: `point`, the sweep keys, `seed`, every tracked path
/// (except `wall_seconds`), and `wall_seconds`. Empty cells are JSON nulls.
pub(crate) fn write_runs(
    path: &Path,
    exp: &Experiment,
    points: &[Point],
    paths: &[String],
    runs: &[RunRecord],
) -> Result<(), ExperimentError> {
    let mut header = vec!["point".to_string()];
    header.extend(exp.point_keys());
    header.push("seed".into());
    let shown: Vec<usize> = (0..paths.len()).filter(|&k| paths[k] != "wall_seconds").collect();
    header.extend(shown.iter().map(|&k| paths[k].clone()));
    header.push("wall_seconds".into());
    let rows = runs
        .iter()
        .map(|r| {
            let mut row = vec![r.point.to_string()];
            row.extend(points[r.point].assignments.iter().map(|(_, v)| value_text(v)));
            row.push(r.seed.to_string());
            row.extend(shown.iter().map(|&k| num(r.values[k])));
            row.push(r.wall_seconds.to_string());
            row
        })
        .collect();
    write_rows(path, header, rows)
}

/// Write `points.csv`: `point`, the sweep keys, then for every tracked path
/// `<path>:mean`, `<path>:ci_low`, `<path>:ci_high`, `<path>:n`, then one
/// column per derived value. Empty cells are undefined values.
pub(crate) fn write_points(
    path: &Path,
    exp: &Experiment,
    points: &[Point],
    results: &[PointResult],
) -> Result<(), ExperimentError> {
    let mut header = vec!["point".to_string()];
    header.extend(exp.point_keys());
    if let Some(first) = results.first() {
        for s in &first.stats {
            for suffix in ["mean", "ci_low", "ci_high", "n"] {
                header.push(format!("{}:{suffix}", s.path));
            }
        }
    }
    header.extend(exp.derived.iter().map(|d| d.name.clone()));
    let rows = results
        .iter()
        .map(|r| {
            let mut row = vec![r.index.to_string()];
            row.extend(points[r.index].assignments.iter().map(|(_, v)| value_text(v)));
            for s in &r.stats {
                let has = s.ci.n > 0;
                row.push(num(has.then_some(s.ci.mean)));
                row.push(num(has.then_some(s.ci.low)));
                row.push(num(has.then_some(s.ci.high)));
                row.push(s.ci.n.to_string());
            }
            row.extend(r.derived.iter().map(|d| num(d.1)));
            row
        })
        .collect();
    write_rows(path, header, rows)
}
