//! Simulated time: integer picoseconds in a `u64` (about 213 days of range).
//!
//! All simulation state uses [`Time`] (an instant) and [`Duration`] (a span).
//! Arithmetic that could overflow is checked and returns [`TimeError`] with
//! context instead of wrapping or panicking. Floats appear only when a value is
//! printed ([`Duration::as_ms_f64`]) or when a distribution is sampled and
//! rounded back to whole picoseconds.

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Picoseconds per second.
pub const PS_PER_S: u64 = 1_000_000_000_000;
/// Picoseconds per millisecond.
pub const PS_PER_MS: u64 = 1_000_000_000;
/// Picoseconds per microsecond.
pub const PS_PER_US: u64 = 1_000_000;
/// Picoseconds per nanosecond.
pub const PS_PER_NS: u64 = 1_000;

/// An instant of simulated time, in picoseconds since the start of the run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Time(pub u64);

/// A span of simulated time, in picoseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Duration(pub u64);

/// The order of the picosecond counts, written out: the derived `<=` goes
/// through a comparison helper that the release profile (opt-level "s")
/// does not inline, a call on every step of the queue's insertion.
macro_rules! order_by_picoseconds {
    ($t:ty) => {
        impl PartialOrd for $t {
            #[inline(always)]
            fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
                Some(self.cmp(other))
            }
            #[inline(always)]
            fn lt(&self, other: &Self) -> bool {
                self.0 < other.0
            }
            #[inline(always)]
            fn le(&self, other: &Self) -> bool {
                self.0 <= other.0
            }
            #[inline(always)]
            fn gt(&self, other: &Self) -> bool {
                self.0 > other.0
            }
            #[inline(always)]
            fn ge(&self, other: &Self) -> bool {
                self.0 >= other.0
            }
        }
        impl Ord for $t {
            #[inline(always)]
            fn cmp(&self, other: &Self) -> std::cmp::Ordering {
                self.0.cmp(&other.0)
            }
        }
    };
}
order_by_picoseconds!(Time);
order_by_picoseconds!(Duration);

/// Errors of time arithmetic and of parsing durations.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TimeError {
    /// `at + by` does not fit in 64-bit picoseconds.
    #[error(
        "simulated time overflow while {context}: {at} + {by} exceeds the 64-bit picosecond range (about 213 days)"
    )]
    Overflow {
        /// What the simulator was doing.
        context: String,
        /// The instant the addition started from.
        at: Time,
        /// The span that was added.
        by: Duration,
    },
    /// A duration string could not be read.
    #[error("invalid duration {text:?}: {reason}")]
    Parse {
        /// The text as given.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
}

impl Time {
    /// Time zero.
    pub const ZERO: Time = Time(0);

    /// `self + d`, or an overflow error naming `context`.
    #[inline]
    pub fn add(self, d: Duration, context: &str) -> Result<Time, TimeError> {
        match self.0.checked_add(d.0) {
            Some(t) => Ok(Time(t)),
            None => Err(Self::overflow(self, d, context)),
        }
    }

    /// The error of [`Time::add`], out of line: every event's scheduling
    /// inlines the addition, not the error's construction.
    #[cold]
    #[inline(never)]
    fn overflow(at: Time, by: Duration, context: &str) -> TimeError {
        TimeError::Overflow {
            context: context.to_string(),
            at,
            by,
        }
    }

    /// The span from `earlier` to `self` (zero if `earlier` is later).
    #[inline]
    pub fn since(self, earlier: Time) -> Duration {
        Duration(self.0.saturating_sub(earlier.0))
    }

    /// Milliseconds as a float, for printing only.
    pub fn as_ms_f64(self) -> f64 {
        self.0 as f64 / PS_PER_MS as f64
    }
}

impl Duration {
    /// The empty span.
    pub const ZERO: Duration = Duration(0);

    /// Whether the span is empty.
    pub const fn is_zero(&self) -> bool {
        self.0 == 0
    }

    /// From whole picoseconds.
    pub const fn ps(v: u64) -> Self {
        Duration(v)
    }
    /// From whole nanoseconds.
    pub const fn ns(v: u64) -> Self {
        Duration(v * PS_PER_NS)
    }
    /// From whole microseconds.
    pub const fn us(v: u64) -> Self {
        Duration(v * PS_PER_US)
    }
    /// From whole milliseconds.
    pub const fn ms(v: u64) -> Self {
        Duration(v * PS_PER_MS)
    }

    /// Checked sum.
    #[inline]
    pub fn checked_add(self, o: Duration) -> Option<Duration> {
        self.0.checked_add(o.0).map(Duration)
    }

    /// Saturating sum: the longest span instead of an overflow (for
    /// totals and waits that only need to stay ordered).
    #[inline]
    pub fn saturating_add(self, o: Duration) -> Duration {
        Duration(self.0.saturating_add(o.0))
    }

    /// `self * n`, checked.
    #[inline]
    pub fn checked_mul(self, n: u64) -> Option<Duration> {
        self.0.checked_mul(n).map(Duration)
    }

    /// Saturating difference.
    #[inline]
    pub fn saturating_sub(self, o: Duration) -> Duration {
        Duration(self.0.saturating_sub(o.0))
    }

    /// Milliseconds as a float, for printing only.
    pub fn as_ms_f64(self) -> f64 {
        self.0 as f64 / PS_PER_MS as f64
    }

    /// Rounds a non-negative float number of picoseconds to a duration,
    /// saturating at `u64::MAX` (NaN and negatives give zero).
    pub fn from_ps_f64(x: f64) -> Duration {
        if x.is_nan() || x <= 0.0 {
            Duration(0)
        } else if x >= u64::MAX as f64 {
            Duration(u64::MAX)
        } else {
            Duration(x.round() as u64)
        }
    }

    /// Parses `"<decimal><unit>"` with unit `s`, `ms`, `us` (or `µs`), `ns`,
    /// `ps`, exactly (decimal digits are not rounded through a float where the
    /// result is a whole number of picoseconds; finer digits are rounded to
    /// the nearest picosecond). A bare `0` is accepted.
    ///
    /// ```
    /// use rendersim_engine::{Duration, Time};
    ///
    /// assert_eq!(Duration::parse("16.7ms").unwrap(), Duration(16_700_000_000));
    /// assert_eq!(Duration::parse("1.85us").unwrap(), Duration(1_850_000));
    /// assert_eq!(Duration::parse("0").unwrap(), Duration(0));
    /// // Exact: a million microseconds is one second, to the picosecond.
    /// assert_eq!(Duration::parse("1000000us").unwrap(), Duration::parse("1s").unwrap());
    /// // Units are required; NaN, infinities and negatives are errors.
    /// assert!(Duration::parse("16.7").is_err());
    /// assert!(Duration::parse("NaNms").is_err());
    /// assert!(Duration::parse("-1ms").is_err());
    /// // Time arithmetic is checked: an overflow names what was scheduled.
    /// let e = Time(u64::MAX - 1).add(Duration(2), "vertical blank").unwrap_err();
    /// assert!(e.to_string().contains("vertical blank"));
    /// ```
    pub fn parse(text: &str) -> Result<Duration, TimeError> {
        let err = |reason: &str| TimeError::Parse {
            text: text.to_string(),
            reason: reason.to_string(),
        };
        let t = text.trim();
        if t == "0" {
            return Ok(Duration(0));
        }
        let lower = t.to_ascii_lowercase();
        if lower.contains("nan") {
            return Err(err("NaN is not a duration"));
        }
        if lower.contains("inf") {
            return Err(err("an infinite duration is not allowed"));
        }
        let split = t
            .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+' || c == '_'))
            .ok_or_else(|| err("missing unit (use s, ms, us, ns or ps, e.g. \"16.7ms\")"))?;
        let (num, unit) = t.split_at(split);
        let unit = unit.trim();
        let scale = match unit {
            "s" => PS_PER_S,
            "ms" => PS_PER_MS,
            "us" | "µs" | "μs" => PS_PER_US,
            "ns" => PS_PER_NS,
            "ps" => 1,
            _ => {
                return Err(err(&format!("unknown unit {unit:?} (use s, ms, us, ns or ps)")));
            }
        };
        let ps = parse_scaled_decimal(num, scale).map_err(|r| err(&r.to_string()))?;
        Ok(Duration(ps))
    }
}

/// Why a decimal number could not be read by [`parse_scaled_decimal`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DecimalError {
    /// No digits were given.
    #[error("missing number")]
    Missing,
    /// The number had a minus sign.
    #[error("negative values are not allowed")]
    Negative,
    /// Something other than digits and one decimal point.
    #[error("{0:?} is not a decimal number")]
    NotDecimal(String),
    /// The scaled value does not fit in 64 bits.
    #[error("value too large for 64-bit picoseconds")]
    TooLarge,
}

/// Parses a non-negative decimal number (`_` separators allowed) and
/// multiplies it by `scale`, in integer arithmetic, rounding to the nearest
/// whole unit: the one reader of numbers with units (durations here, rates,
/// bandwidths and sizes in the models' `config::units`).
///
/// ```
/// use rendersim_engine::time::{DecimalError, parse_scaled_decimal};
/// assert_eq!(parse_scaled_decimal("1.5", 1000), Ok(1500));
/// assert_eq!(parse_scaled_decimal("0.0005", 1000), Ok(1)); // rounded
/// assert_eq!(parse_scaled_decimal("-1", 1000), Err(DecimalError::Negative));
/// ```
pub fn parse_scaled_decimal(num: &str, scale: u64) -> Result<u64, DecimalError> {
    let num = num.trim().replace('_', "");
    if num.is_empty() {
        return Err(DecimalError::Missing);
    }
    if num.starts_with('-') {
        return Err(DecimalError::Negative);
    }
    let num = num.strip_prefix('+').unwrap_or(&num);
    let (int_part, frac_part) = match num.split_once('.') {
        Some((a, b)) => (a, b),
        None => (num, ""),
    };
    if int_part.is_empty() && frac_part.is_empty() {
        return Err(DecimalError::Missing);
    }
    if !int_part.chars().all(|c| c.is_ascii_digit()) || !frac_part.chars().all(|c| c.is_ascii_digit()) {
        return Err(DecimalError::NotDecimal(num.to_string()));
    }
    let overflow = || DecimalError::TooLarge;
    let int: u128 = if int_part.is_empty() {
        0
    } else {
        int_part.parse::<u128>().map_err(|_| overflow())?
    };
    let mut total: u128 = int.checked_mul(scale as u128).ok_or_else(overflow)?;
    // Fraction: digits d1 d2 ... -> sum d_k * scale / 10^k, rounded at the end.
    let frac_digits: Vec<u32> = frac_part.chars().map(|c| c.to_digit(10).unwrap_or(0)).collect();
    if !frac_digits.is_empty() {
        let take = frac_digits.len().min(30);
        let mut num_f: u128 = 0;
        let mut den: u128 = 1;
        for &d in &frac_digits[..take] {
            num_f = num_f * 10 + d as u128;
            den *= 10;
            if den > 1_000_000_000_000_000_000_000_000 {
                break;
            }
        }
        let scaled = num_f.checked_mul(scale as u128).ok_or_else(overflow)?;
        let q = scaled / den;
        let r = scaled % den;
        let rounded = if r * 2 >= den { q + 1 } else { q };
        total = total.checked_add(rounded).ok_or_else(overflow)?;
    }
    u64::try_from(total).map_err(|_| overflow())
}

impl fmt::Display for Time {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "t={}", Duration(self.0))
    }
}

impl fmt::Display for Duration {
    /// Exact text that [`Duration::parse`] reads back to the same value.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let units = [(PS_PER_S, "s"), (PS_PER_MS, "ms"), (PS_PER_US, "us"), (PS_PER_NS, "ns")];
        if v == 0 {
            return write!(f, "0s");
        }
        for (scale, name) in units {
            if v >= scale {
                let int = v / scale;
                let frac = v % scale;
                if frac == 0 {
                    return write!(f, "{int}{name}");
                }
                let width = scale.ilog10() as usize;
                let s = format!("{frac:0width$}");
                return write!(f, "{int}.{}{name}", s.trim_end_matches('0'));
            }
        }
        write!(f, "{v}ps")
    }
}

impl Serialize for Duration {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}

impl<'de> Deserialize<'de> for Duration {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = Duration;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "a duration string with a unit, like \"16.7ms\" or \"2us\"")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Duration, E> {
                Duration::parse(v).map_err(E::custom)
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Duration, E> {
                if v == 0 {
                    Ok(Duration(0))
                } else if v < 0 {
                    Err(E::custom(format!("{v} is negative; durations must be >= 0")))
                } else {
                    Err(E::custom(format!(
                        "a duration needs a unit: write \"{v}ms\" (or s, us, ns, ps), not {v}"
                    )))
                }
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Duration, E> {
                self.visit_i64(v.min(i64::MAX as u64) as i64)
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Duration, E> {
                if v.is_nan() {
                    Err(E::custom("NaN is not a duration"))
                } else if v == 0.0 {
                    Ok(Duration(0))
                } else if v < 0.0 {
                    Err(E::custom(format!("{v} is negative; durations must be >= 0")))
                } else {
                    Err(E::custom(format!(
                        "a duration needs a unit: write \"{v}ms\" (or s, us, ns, ps), not {v}"
                    )))
                }
            }
        }
        d.deserialize_any(V)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// The written-out comparisons order as the picosecond counts do
        /// (what the derived ones did), every operator and `cmp` alike.
        #[test]
        fn times_and_spans_order_as_their_picoseconds(a in proptest::prelude::any::<u64>(), b in proptest::prelude::any::<u64>(), near in 0u64..3) {
            for (x, y) in [(a, b), (a, a.wrapping_add(near))] {
                let (t, u) = (Time(x), Time(y));
                let (d, e) = (Duration(x), Duration(y));
                proptest::prop_assert_eq!(t.cmp(&u), x.cmp(&y));
                proptest::prop_assert_eq!(t.partial_cmp(&u), Some(x.cmp(&y)));
                proptest::prop_assert_eq!((t < u, t <= u, t > u, t >= u), (x < y, x <= y, x > y, x >= y));
                proptest::prop_assert_eq!(d.cmp(&e), x.cmp(&y));
                proptest::prop_assert_eq!((d < e, d <= e, d > e, d >= e), (x < y, x <= y, x > y, x >= y));
                proptest::prop_assert_eq!(t.max(u), Time(x.max(y)));
            }
        }
    }

    #[test]
    fn saturating_sums_stop_at_the_longest_span() {
        assert_eq!(Duration(3).saturating_add(Duration(4)), Duration(7));
        assert_eq!(Duration(u64::MAX - 1).saturating_add(Duration(5)), Duration(u64::MAX));
        assert_eq!(
            Duration(u64::MAX - 1).saturating_add(Duration(5)),
            Duration(u64::MAX - 1)
                .checked_add(Duration(5))
                .unwrap_or(Duration(u64::MAX))
        );
    }

    #[test]
    fn parses_units_exactly() {
        assert_eq!(Duration::parse("1.85us").unwrap(), Duration(1_850_000));
        assert_eq!(Duration::parse("16.7ms").unwrap(), Duration(16_700_000_000));
        assert_eq!(Duration::parse("1s").unwrap(), Duration(PS_PER_S));
        assert_eq!(Duration::parse("0.5ps").unwrap(), Duration(1));
        assert_eq!(Duration::parse("3ps").unwrap(), Duration(3));
        assert_eq!(Duration::parse(".5ms").unwrap(), Duration(500_000_000));
        assert_eq!(Duration::parse("0").unwrap(), Duration(0));
    }

    #[test]
    fn rejects_bad_text() {
        for bad in [
            "-1ms",
            "NaNms",
            "nan",
            "1",
            "1 parsec",
            "ms",
            "1.2.3ms",
            "infms",
            "99999999999s",
        ] {
            assert!(Duration::parse(bad).is_err(), "{bad} should fail");
        }
        let e = Duration::parse("-2ms").unwrap_err().to_string();
        assert!(e.contains("negative"), "{e}");
    }

    #[test]
    fn display_round_trips() {
        for v in [0u64, 1, 999, 1000, 1_850_000, 16_666_666_667, PS_PER_S * 3600, u64::MAX] {
            let d = Duration(v);
            assert_eq!(Duration::parse(&d.to_string()).unwrap(), d, "{d}");
        }
    }

    #[test]
    fn overflow_is_an_error_with_context() {
        let e = Time(u64::MAX - 1).add(Duration(5), "scheduling vblank").unwrap_err();
        assert!(e.to_string().contains("scheduling vblank"));
    }
}
