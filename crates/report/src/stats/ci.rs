//! Confidence intervals for a mean, from Student's t distribution.

use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// A two-sided confidence interval for the mean of a sample.
///
/// Never contains NaN. With fewer than two values (or a `level` outside
/// `(0, 1)`) no interval can be formed: `half_width` is `0.0`,
/// `low == high == mean` and `has_interval` is `false`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeanCi {
    /// Sample mean (`0.0` for an empty sample).
    pub mean: f64,
    /// `t * s / sqrt(n)` with `t` the `(1 + level) / 2` quantile of Student's t
    /// with `n - 1` degrees of freedom.
    pub half_width: f64,
    /// `mean - half_width`.
    pub low: f64,
    /// `mean + half_width`.
    pub high: f64,
    /// Number of values used (NaN inputs are dropped).
    pub n: u64,
    /// Whether a real interval was computed (`n >= 2` and a valid level).
    pub has_interval: bool,
}

/// The two-sided Student's t critical value for `level` (e.g. 0.95) and
/// `df` degrees of freedom, or `None` when it is undefined.
pub fn t_critical(level: f64, df: f64) -> Option<f64> {
    let valid = level > 0.0 && level < 1.0 && df > 0.0 && df.is_finite();
    if !valid {
        return None;
    }
    let t = StudentsT::new(0.0, 1.0, df).ok()?;
    let v = t.inverse_cdf(0.5 + level / 2.0);
    v.is_finite().then_some(v)
}

/// Mean of `values` with a Student's t confidence interval at `level`
/// (e.g. `0.95`). NaN values are ignored. See [`MeanCi`] for the degenerate
/// cases.
pub fn mean_ci(values: &[f64], level: f64) -> MeanCi {
    let v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
    let n = v.len();
    let mean = if n == 0 { 0.0 } else { v.iter().sum::<f64>() / n as f64 };
    let point = MeanCi {
        mean,
        half_width: 0.0,
        low: mean,
        high: mean,
        n: n as u64,
        has_interval: false,
    };
    if n < 2 || !mean.is_finite() {
        return point;
    }
    let Some(t) = t_critical(level, (n - 1) as f64) else {
        return point;
    };
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64;
    let half_width = t * (var / n as f64).sqrt();
    if !half_width.is_finite() {
        return point;
    }
    MeanCi {
        mean,
        half_width,
        low: mean - half_width,
        high: mean + half_width,
        n: n as u64,
        has_interval: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_t_values() {
        assert!((t_critical(0.95, 4.0).unwrap() - 2.776).abs() < 1e-3);
        assert!((t_critical(0.95, 1.0).unwrap() - 12.706).abs() < 1e-3);
        assert!((t_critical(0.99, 9.0).unwrap() - 3.250).abs() < 1e-3);
        assert!(t_critical(1.0, 4.0).is_none());
        assert!(t_critical(0.95, 0.0).is_none());
    }

    #[test]
    fn ci_of_five_values() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        let ci = mean_ci(&v, 0.95);
        // s = sqrt(2.5), half = 2.776 * s / sqrt(5)
        let expect = 2.776_445 * (2.5f64).sqrt() / 5f64.sqrt();
        assert_eq!(ci.n, 5);
        assert!(ci.has_interval);
        assert!((ci.mean - 3.0).abs() < 1e-12);
        assert!((ci.half_width - expect).abs() < 1e-4);
        assert!((ci.low - (3.0 - ci.half_width)).abs() < 1e-12);
        assert!((ci.high - (3.0 + ci.half_width)).abs() < 1e-12);
    }

    #[test]
    fn degenerate_samples_are_nan_free() {
        let one = mean_ci(&[4.0], 0.95);
        assert_eq!((one.mean, one.half_width, one.n), (4.0, 0.0, 1));
        assert!(!one.has_interval);
        let none = mean_ci(&[], 0.95);
        assert_eq!((none.mean, none.low, none.high, none.n), (0.0, 0.0, 0.0, 0));
        let same = mean_ci(&[2.0, 2.0, 2.0], 0.95);
        assert_eq!(same.half_width, 0.0);
        assert!(same.has_interval);
        let bad_level = mean_ci(&[1.0, 2.0], 1.5);
        assert!(!bad_level.has_interval);
        assert_eq!(bad_level.mean, 1.5);
    }
}
