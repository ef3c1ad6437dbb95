//! Order-statistic summaries: count, mean, quantiles, extremes, spread.
//!
//! Quantiles use linear interpolation between order statistics, which is
//! numpy's default (`method = "linear"`, type 7 of Hyndman and Fan).

use serde::Serialize;

/// A compact summary of a sample. Never contains NaN: an empty sample gives
/// `count = 0` and every other field `0.0`, which is not a measurement:
/// serialized (and through [`Summary::stat`]) those fields are `null`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Number of values used (NaN inputs are dropped).
    pub count: u64,
    /// Arithmetic mean.
    pub mean: f64,
    /// Median (0.5 quantile).
    pub p50: f64,
    /// 0.99 quantile.
    pub p99: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Sample standard deviation (divisor `n - 1`); `0.0` when `n < 2`.
    pub std: f64,
}

impl Serialize for Summary {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = serializer.serialize_struct("Summary", 7)?;
        st.serialize_field("count", &self.count)?;
        st.serialize_field("mean", &self.stat(self.mean))?;
        st.serialize_field("p50", &self.stat(self.p50))?;
        st.serialize_field("p99", &self.stat(self.p99))?;
        st.serialize_field("min", &self.stat(self.min))?;
        st.serialize_field("max", &self.stat(self.max))?;
        st.serialize_field("std", &self.stat(self.std))?;
        st.end()
    }
}

impl Summary {
    /// `x`, one of this summary's fields, for output: `None` (JSON `null`,
    /// "n/a" in reports) when the sample was empty, so that an empty
    /// statistic never reads as a measured 0.
    pub fn stat(&self, x: f64) -> Option<f64> {
        (self.count > 0).then_some(x)
    }

    /// Summarise `values`. NaN values are ignored; an empty (or all-NaN)
    /// sample gives the all-zero summary with `count = 0`.
    pub fn of(values: &[f64]) -> Summary {
        let mut sorted: Vec<f64> = values.iter().copied().filter(|v| !v.is_nan()).collect();
        if sorted.is_empty() {
            return Summary {
                count: 0,
                mean: 0.0,
                p50: 0.0,
                p99: 0.0,
                min: 0.0,
                max: 0.0,
                std: 0.0,
            };
        }
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        let mean = sorted.iter().sum::<f64>() / n as f64;
        let std = if n < 2 {
            0.0
        } else {
            let ss: f64 = sorted.iter().map(|v| (v - mean) * (v - mean)).sum();
            (ss / (n - 1) as f64).sqrt()
        };
        Summary {
            count: n as u64,
            mean,
            p50: quantile(&sorted, 0.5),
            p99: quantile(&sorted, 0.99),
            min: sorted[0],
            max: sorted[n - 1],
            std,
        }
    }
}

/// The `q` quantile of an ascending-sorted slice, interpolating linearly
/// between the order statistics at ranks `floor(h)` and `ceil(h)` with
/// `h = (n - 1) * q` (numpy's default).
///
/// `q` is clamped to `[0, 1]` (a NaN `q` counts as 0). An empty slice gives
/// `0.0`. The slice must already be sorted; this is not checked.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    let n = sorted.len();
    if n == 0 {
        return 0.0;
    }
    let q = if q.is_nan() { 0.0 } else { q.clamp(0.0, 1.0) };
    let h = (n - 1) as f64 * q;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(n - 1);
    let frac = h - lo as f64;
    let (a, b) = (sorted[lo], sorted[hi]);
    if frac == 0.0 || a == b { a } else { a + frac * (b - a) }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nearly_equal(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn quantile_matches_numpy_linear() {
        let s = [1.0, 2.0, 3.0, 4.0];
        // numpy.quantile([1,2,3,4], [0, .25, .5, .9, 1]) = 1, 1.75, 2.5, 3.7, 4
        assert!(nearly_equal(quantile(&s, 0.0), 1.0));
        assert!(nearly_equal(quantile(&s, 0.25), 1.75));
        assert!(nearly_equal(quantile(&s, 0.5), 2.5));
        assert!(nearly_equal(quantile(&s, 0.9), 3.7));
        assert!(nearly_equal(quantile(&s, 1.0), 4.0));
    }

    #[test]
    fn quantile_edge_cases() {
        assert_eq!(quantile(&[], 0.5), 0.0);
        assert_eq!(quantile(&[7.0], 0.99), 7.0);
        assert_eq!(quantile(&[1.0, 2.0], -1.0), 1.0);
        assert_eq!(quantile(&[1.0, 2.0], 2.0), 2.0);
        assert_eq!(quantile(&[1.0, 2.0], f64::NAN), 1.0);
    }

    #[test]
    fn summary_of_known_data() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = Summary::of(&v);
        assert_eq!(s.count, 100);
        assert!(nearly_equal(s.mean, 50.5));
        assert!(nearly_equal(s.p50, 50.5));
        // numpy.quantile(range(1,101), .99) = 99.01
        assert!(nearly_equal(s.p99, 99.01));
        assert_eq!((s.min, s.max), (1.0, 100.0));
        // sample std of 1..=100 = sqrt(841.666..)
        assert!(nearly_equal(s.std, (100.0f64 * 101.0 / 12.0).sqrt()));
    }

    #[test]
    fn summary_of_empty_is_zero_not_nan() {
        let s = Summary::of(&[]);
        assert_eq!(s.count, 0);
        for f in [s.mean, s.p50, s.p99, s.min, s.max, s.std] {
            assert_eq!(f, 0.0);
        }
        let s = Summary::of(&[f64::NAN]);
        assert_eq!(s.count, 0);
        assert_eq!(s.mean, 0.0);
    }

    #[test]
    fn summary_unsorted_input_and_single_value() {
        let s = Summary::of(&[3.0, 1.0, 2.0]);
        assert_eq!((s.min, s.p50, s.max), (1.0, 2.0, 3.0));
        let s = Summary::of(&[5.0]);
        assert_eq!((s.count, s.mean, s.std, s.p99), (1, 5.0, 0.0, 5.0));
    }

    #[test]
    fn an_empty_summary_serializes_its_statistics_as_null() {
        let v = serde_json::to_value(Summary::of(&[])).unwrap();
        assert_eq!(v["count"], 0);
        for k in ["mean", "p50", "p99", "min", "max", "std"] {
            assert!(v[k].is_null(), "{k}: {v}");
        }
        let s = Summary::of(&[1.0, 3.0]);
        let v = serde_json::to_value(s).unwrap();
        assert_eq!(v["mean"], 2.0);
        assert_eq!(v["min"], 1.0);
        assert_eq!(s.stat(s.max), Some(3.0));
        assert_eq!(Summary::of(&[f64::NAN]).stat(0.0), None);
    }
}
