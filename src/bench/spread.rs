//! The minimum, median and maximum of a benchmark's repeats: every line
//! `rendersim bench` prints carries all three, so that one lucky or one slow
//! repeat is seen for what it is, and the median is the figure to quote.

/// The spread of `n` repeated measurements of one figure.
///
/// ```
/// use rendersim::bench::spread::Spread;
/// let s = Spread::of(&[3.0, 1.0, 2.0, 10.0]);
/// assert_eq!((s.min, s.median, s.max, s.n), (1.0, 2.5, 10.0, 4));
/// // A decreasing transform (seconds to a rate) swaps the ends.
/// let r = s.map(|x| 1.0 / x);
/// assert_eq!((r.min, r.max), (0.1, 1.0));
/// assert_eq!(r.median, 1.0 / 2.5);
/// assert_eq!(s.show(1.0, 1, " s"), "2.5 s (1.0-10.0)");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Spread {
    /// The smallest.
    pub min: f64,
    /// The middle one (the mean of the two middle ones for an even count).
    pub median: f64,
    /// The largest.
    pub max: f64,
    /// How many measurements.
    pub n: usize,
}

impl Spread {
    /// The spread of `samples`; NaN throughout for none.
    pub fn of(samples: &[f64]) -> Spread {
        let mut v = samples.to_vec();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n == 0 {
            return Spread {
                min: f64::NAN,
                median: f64::NAN,
                max: f64::NAN,
                n,
            };
        }
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        };
        Spread {
            min: v[0],
            median,
            max: v[n - 1],
            n,
        }
    }

    /// The spread of `f` of each measurement, for a monotone `f` (the
    /// median of an odd count maps exactly; of an even count, `f` of the
    /// mean of the middle two). A decreasing `f` swaps the ends.
    pub fn map(self, f: impl Fn(f64) -> f64) -> Spread {
        let (a, b) = (f(self.min), f(self.max));
        Spread {
            min: a.min(b),
            median: f(self.median),
            max: a.max(b),
            n: self.n,
        }
    }

    /// `median (min-max)` in `unit`, each value times `scale` with
    /// `decimals` places: `"2.50 ms (2.41-2.93)"`.
    pub fn show(&self, scale: f64, decimals: usize, unit: &str) -> String {
        format!(
            "{:.d$}{unit} ({:.d$}-{:.d$})",
            self.median * scale,
            self.min * scale,
            self.max * scale,
            d = decimals
        )
    }
}

/// The spread of `a[i] / b[i]`, pair by pair (each ratio of two figures
/// measured one after the other, so that a drift of the machine's speed
/// cancels).
pub fn paired_ratio(a: &[f64], b: &[f64]) -> Spread {
    let r: Vec<f64> = a.iter().zip(b).map(|(x, y)| x / y).collect();
    Spread::of(&r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odd_even_empty_and_paired() {
        let s = Spread::of(&[5.0]);
        assert_eq!((s.min, s.median, s.max, s.n), (5.0, 5.0, 5.0, 1));
        let s = Spread::of(&[4.0, 1.0, 3.0]);
        assert_eq!((s.min, s.median, s.max), (1.0, 3.0, 4.0));
        assert!(Spread::of(&[]).median.is_nan());
        let r = paired_ratio(&[2.0, 9.0, 4.0], &[1.0, 3.0, 4.0]);
        assert_eq!((r.min, r.median, r.max, r.n), (1.0, 2.0, 3.0, 3));
    }
}
