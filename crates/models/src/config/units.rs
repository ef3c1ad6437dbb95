//! Units a user writes in model files: rates (`"60Hz"`, or a period like
//! `"16.7ms"`), bandwidths (`"4GB/s"`, `"90MiB/s"`, `"2Gbit/s"`) and sizes
//! (`4096`, `"64KiB"`). All are parsed exactly in integer arithmetic.

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::engine::time::parse_scaled_decimal;
use crate::engine::{Duration, PS_PER_S};

/// A rate given as a frequency or a period; kept as its period in picoseconds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rate {
    /// The period (rounded to the nearest picosecond for frequencies).
    pub period: Duration,
    /// The text as written (printed back in resolved models).
    pub text: String,
}

/// Errors of unit parsing.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid {what} {text:?}: {reason}")]
pub struct UnitError {
    /// Which kind of value.
    pub what: &'static str,
    /// The text.
    pub text: String,
    /// Why.
    pub reason: String,
}

fn unit_err(what: &'static str, text: &str, reason: impl Into<String>) -> UnitError {
    UnitError {
        what,
        text: text.to_string(),
        reason: reason.into(),
    }
}

fn split_number(t: &str) -> (&str, &str) {
    let i = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+' || c == '_'))
        .unwrap_or(t.len());
    (&t[..i], t[i..].trim())
}

impl Rate {
    /// Parses `"60Hz"`, `"1kHz"`, `"0.5Hz"`, or a period such as `"16.7ms"`.
    pub fn parse(text: &str) -> Result<Rate, UnitError> {
        let t = text.trim();
        if t.to_ascii_lowercase().contains("nan") {
            return Err(unit_err("rate", text, "NaN is not a rate"));
        }
        let (num, unit) = split_number(t);
        let mult: u64 = match unit {
            "Hz" | "hz" => 1,
            "kHz" | "khz" => 1_000,
            "MHz" => 1_000_000,
            _ => {
                return Duration::parse(t)
                    .map_err(|_| {
                        unit_err(
                            "rate",
                            text,
                            "use a frequency like \"60Hz\" or a period like \"16.7ms\"",
                        )
                    })
                    .and_then(|p| {
                        if p.0 == 0 {
                            Err(unit_err("rate", text, "the period must be greater than zero"))
                        } else {
                            Ok(Rate {
                                period: p,
                                text: t.to_string(),
                            })
                        }
                    });
            }
        };
        // f = num * mult Hz; period = 1e12 / f ps. Work in milli-hertz.
        let milli_hz = parse_scaled_decimal(num, 1000 * mult).map_err(|r| unit_err("rate", text, r.to_string()))?;
        if milli_hz == 0 {
            return Err(unit_err("rate", text, "the frequency must be greater than zero"));
        }
        let num = PS_PER_S as u128 * 1000;
        let period = (num + milli_hz as u128 / 2) / milli_hz as u128;
        if period == 0 {
            return Err(unit_err("rate", text, "frequency too high for picosecond resolution"));
        }
        Ok(Rate {
            period: Duration(period as u64),
            text: t.to_string(),
        })
    }

    /// Frequency in Hz, for printing.
    pub fn hz(&self) -> f64 {
        PS_PER_S as f64 / self.period.0 as f64
    }
}

/// A transfer rate in bytes per second (kept in milli-bytes per second).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bandwidth {
    milli_bytes_per_s: u128,
    /// The text as written.
    pub text: String,
}

impl Bandwidth {
    /// Parses `"4GB/s"`, `"90MiB/s"`, `"2Gbit/s"`, `"500kB/s"`, `"1B/s"`.
    pub fn parse(text: &str) -> Result<Bandwidth, UnitError> {
        let t = text.trim();
        let (num, unit) = split_number(t);
        let Some(unit) = unit.strip_suffix("/s") else {
            return Err(unit_err(
                "bandwidth",
                text,
                "use bytes or bits per second, e.g. \"4GB/s\" or \"2Gbit/s\"",
            ));
        };
        let (scale_num, scale_den): (u128, u128) = match unit {
            "B" => (1, 1),
            "kB" | "KB" => (1_000, 1),
            "MB" => (1_000_000, 1),
            "GB" => (1_000_000_000, 1),
            "TB" => (1_000_000_000_000, 1),
            "KiB" => (1 << 10, 1),
            "MiB" => (1 << 20, 1),
            "GiB" => (1 << 30, 1),
            "bit" => (1, 8),
            "kbit" => (1_000, 8),
            "Mbit" => (1_000_000, 8),
            "Gbit" => (1_000_000_000, 8),
            _ => {
                return Err(unit_err(
                    "bandwidth",
                    text,
                    format!("unknown unit {unit:?}/s (use B, kB, MB, GB, KiB, MiB, GiB, bit, Mbit or Gbit per second)"),
                ));
            }
        };
        let milli = parse_scaled_decimal(num, 1000).map_err(|r| unit_err("bandwidth", text, r.to_string()))? as u128;
        let v = milli
            .checked_mul(scale_num)
            .ok_or_else(|| unit_err("bandwidth", text, "too large"))?
            / scale_den;
        if v == 0 {
            return Err(unit_err("bandwidth", text, "must be greater than zero"));
        }
        Ok(Bandwidth {
            milli_bytes_per_s: v,
            text: t.to_string(),
        })
    }

    /// Time to move `bytes` (rounded to the nearest picosecond; saturates).
    pub fn transfer_time(&self, bytes: u64) -> Duration {
        let num = bytes as u128 * PS_PER_S as u128 * 1000;
        let ps = (num + self.milli_bytes_per_s / 2) / self.milli_bytes_per_s;
        Duration(u64::try_from(ps).unwrap_or(u64::MAX))
    }

    /// Bytes per second, for printing.
    pub fn bytes_per_s(&self) -> f64 {
        self.milli_bytes_per_s as f64 / 1000.0
    }

    /// Bytes per picosecond, the simulation's rate unit.
    pub fn bytes_per_ps(&self) -> f64 {
        self.bytes_per_s() / 1e12
    }
}

/// A size in bytes: an integer, or a string with a unit (`"64KiB"`, `"2MB"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Bytes(pub u64);

impl Bytes {
    /// Parses `"123"`, `"64KiB"`, `"1.5MB"`.
    pub fn parse(text: &str) -> Result<Bytes, UnitError> {
        let t = text.trim();
        let (num, unit) = split_number(t);
        let scale: u64 = match unit {
            "" | "B" => 1,
            "kB" | "KB" => 1_000,
            "MB" => 1_000_000,
            "GB" => 1_000_000_000,
            "KiB" => 1 << 10,
            "MiB" => 1 << 20,
            "GiB" => 1 << 30,
            "TB" => 1_000_000_000_000,
            "TiB" => 1 << 40,
            _ => {
                return Err(unit_err(
                    "size",
                    text,
                    format!("unknown unit {unit:?} (use B, kB, MB, GB, TB, KiB, MiB, GiB, TiB)"),
                ));
            }
        };
        parse_scaled_decimal(num, scale)
            .map(Bytes)
            .map_err(|r| unit_err("size", text, r.to_string()))
    }
}

macro_rules! string_serde {
    ($t:ty, $what:literal, $parse:expr, $show:expr) => {
        impl Serialize for $t {
            fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                #[allow(clippy::redundant_closure_call)]
                ($show)(self, s)
            }
        }
        impl<'de> Deserialize<'de> for $t {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                struct V;
                impl serde::de::Visitor<'_> for V {
                    type Value = $t;
                    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                        f.write_str($what)
                    }
                    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<$t, E> {
                        #[allow(clippy::redundant_closure_call)]
                        ($parse)(v).map_err(E::custom)
                    }
                    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<$t, E> {
                        if v < 0 {
                            return Err(E::custom(format!("{v} is negative")));
                        }
                        #[allow(clippy::redundant_closure_call)]
                        ($parse)(&v.to_string()).map_err(E::custom)
                    }
                    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<$t, E> {
                        #[allow(clippy::redundant_closure_call)]
                        ($parse)(&v.to_string()).map_err(E::custom)
                    }
                    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<$t, E> {
                        Err(E::custom(format!("{v} needs a unit: expected {}", $what)))
                    }
                }
                d.deserialize_any(V)
            }
        }
    };
}

string_serde!(
    Rate,
    "a rate like \"60Hz\" or a period like \"16.7ms\"",
    Rate::parse,
    |r: &Rate, s: S| s.serialize_str(&r.text)
);
string_serde!(
    Bandwidth,
    "a bandwidth like \"4GB/s\"",
    Bandwidth::parse,
    |b: &Bandwidth, s: S| s.serialize_str(&b.text)
);
string_serde!(
    Bytes,
    "a size in bytes like 4096 or \"64KiB\"",
    Bytes::parse,
    |b: &Bytes, s: S| s.serialize_u64(b.0)
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates() {
        assert_eq!(Rate::parse("60Hz").unwrap().period, Duration(16_666_666_667));
        assert_eq!(Rate::parse("1Hz").unwrap().period, Duration(PS_PER_S));
        assert_eq!(Rate::parse("1kHz").unwrap().period, Duration::ms(1));
        assert_eq!(Rate::parse("16.7ms").unwrap().period, Duration(16_700_000_000));
        for bad in ["0Hz", "-60Hz", "60", "fast", "NaNHz", "0ms"] {
            assert!(Rate::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn bandwidths() {
        let b = Bandwidth::parse("1GB/s").unwrap();
        assert_eq!(b.transfer_time(1_000), Duration::us(1));
        let m = Bandwidth::parse("90MiB/s").unwrap();
        // 10 MiB at 90 MiB/s = 111.1 ms (paper 003's network example)
        let t = m.transfer_time(10 << 20).as_ms_f64();
        assert!((t - 111.111).abs() < 0.001, "{t}");
        assert_eq!(Bandwidth::parse("8Gbit/s").unwrap().bytes_per_s(), 1e9);
        for bad in ["4GB", "0GB/s", "-1GB/s", "4XB/s"] {
            assert!(Bandwidth::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn sizes() {
        assert_eq!(Bytes::parse("64KiB").unwrap(), Bytes(65536));
        assert_eq!(Bytes::parse("12").unwrap(), Bytes(12));
        assert!(Bytes::parse("12 parsecs").is_err());
        assert_eq!(Bytes::parse("8GiB").unwrap(), Bytes(8 << 30));
        assert_eq!(Bytes::parse("2TiB").unwrap(), Bytes(2 << 40));
        assert!(Bytes::parse("99999999TiB").is_err());
    }
}
