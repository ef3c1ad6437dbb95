//! The parts every system's summary shares: kernel event counts, the order
//! statistics of a sample (null when the sample is empty), and mean times
//! per stage. Each system's summary is a typed struct built from these and
//! serialized once ([`to_json`]); the keys a reader sees are the field names,
//! and each field's doc comment is its meaning.

use std::collections::BTreeMap;

use serde::Serialize;
use serde_json::Value;

use crate::engine::RunStats;
use crate::stats::quantile::Summary;

/// Kernel event counts (`events`).
#[derive(Debug, Clone, Serialize)]
pub struct EventCounts {
    /// Events handled.
    pub total: u64,
    /// Events handled, per kind (the model's event names).
    pub by_kind: BTreeMap<String, u64>,
}

impl EventCounts {
    /// The counts of a run.
    pub fn of(stats: &RunStats) -> Self {
        EventCounts {
            total: stats.events,
            by_kind: stats
                .kind_names
                .iter()
                .zip(&stats.by_kind)
                .map(|(n, c)| (n.to_string(), *c))
                .collect(),
        }
    }
}

/// Order statistics of a sample (milliseconds where the key says `_ms`);
/// every statistic is `null` when `count` is 0.
#[derive(Debug, Clone, Serialize)]
pub struct Dist {
    /// Values in the sample.
    pub count: u64,
    /// Smallest.
    pub min: Option<f64>,
    /// Mean.
    pub mean: Option<f64>,
    /// Median.
    pub p50: Option<f64>,
    /// 99th percentile.
    pub p99: Option<f64>,
    /// Largest.
    pub max: Option<f64>,
    /// Standard deviation.
    pub std: Option<f64>,
}

impl Dist {
    /// The statistics of `values` (NaN values are left out).
    pub fn of(values: &[f64]) -> Self {
        let s = Summary::of(values);
        let n = |x: f64| s.stat(x);
        Dist {
            count: s.count,
            min: n(s.min),
            mean: n(s.mean),
            p50: n(s.p50),
            p99: n(s.p99),
            max: n(s.max),
            std: n(s.std),
        }
    }

    /// `[min, mean, p99, max]`, as a report's latency line shows them
    /// ([`crate::output::text::latency_row`]).
    pub fn row(&self) -> [Option<f64>; 4] {
        [self.min, self.mean, self.p99, self.max]
    }

    /// The statistics of the finite values among `values`.
    pub fn of_finite(values: &[f64]) -> Self {
        let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        Dist::of(&v)
    }
}

/// Mean milliseconds per stage over `rows` (each a list of stage gaps in
/// picoseconds, in the order of `names`); every stage `null` when there
/// are no rows, like an empty [`Dist`].
pub fn mean_stages<'a>(names: &[&str], rows: impl Iterator<Item = &'a Vec<u64>>) -> BTreeMap<String, Option<f64>> {
    let mut sums = vec![0f64; names.len()];
    let mut n = 0usize;
    for r in rows {
        for (s, v) in sums.iter_mut().zip(r) {
            *s += *v as f64 / 1e9;
        }
        n += 1;
    }
    names
        .iter()
        .zip(sums)
        .map(|(k, s)| (k.to_string(), (n > 0).then(|| s / n as f64)))
        .collect()
}

/// Events handled per second of wall time (0 when no time was measured).
pub fn events_per_second(stats: &RunStats) -> f64 {
    if stats.wall_seconds > 0.0 {
        stats.events as f64 / stats.wall_seconds
    } else {
        0.0
    }
}

/// The name a unit enum value is written as in `summary.json` (its serde
/// name: `Scheme::Warp` -> `warp`), for the human reports.
pub fn name_of<T: Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(Value::String(s)) => s,
        Ok(v) => v.to_string(),
        Err(_) => String::new(),
    }
}

/// A summary as the JSON the CLI writes and experiments read by dotted path
/// (keys in sorted order).
pub fn to_json<T: Serialize>(summary: &T) -> Value {
    // A struct of numbers, strings and maps with string keys always serializes.
    serde_json::to_value(summary).expect("summaries serialize")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_sample_is_null_with_count_zero() {
        let v = to_json(&Dist::of(&[]));
        assert_eq!(v["count"], 0);
        assert!(v["mean"].is_null() && v["p99"].is_null());
        let v = to_json(&Dist::of_finite(&[1.0, f64::NAN, f64::INFINITY, 3.0]));
        assert_eq!((v["count"].as_u64(), v["mean"].as_f64()), (Some(2), Some(2.0)));
    }

    #[test]
    fn stage_means_divide_by_the_rows() {
        let rows = [vec![1_000_000_000u64, 0], vec![3_000_000_000, 2_000_000_000]];
        let m = mean_stages(&["a", "b"], rows.iter());
        assert_eq!((m["a"], m["b"]), (Some(2.0), Some(1.0)));
        assert_eq!(mean_stages(&["a"], std::iter::empty())["a"], None);
        assert!(to_json(&mean_stages(&["a"], std::iter::empty()))["a"].is_null());
    }
}
