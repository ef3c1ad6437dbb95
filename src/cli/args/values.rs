//! The command line's value parsers: a closed choice refused in the
//! command's own words ([`Choice`]), a value read by a function whose error
//! is the whole message ([`Plain`]), `WxH` sizes and vertex-cache policies.

use std::ffi::OsStr;
use std::marker::PhantomData;

use clap::ValueEnum;
use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::ErrorKind;

use rendersim::components::vertex_cache::CachePolicy;

/// A render target size, `WxH`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
}

pub(super) fn parse_size(size: &str) -> anyhow::Result<Size> {
    size.split_once('x')
        .and_then(|(w, h)| {
            Some(Size {
                width: w.parse().ok()?,
                height: h.parse().ok()?,
            })
        })
        .ok_or_else(|| anyhow::anyhow!("--size {size:?}: expected WxH, e.g. 512x512"))
}

pub(super) fn parse_policy(policy: &str) -> anyhow::Result<CachePolicy> {
    policy.parse().map_err(|e| anyhow::anyhow!("--policy {policy:?}: {e}"))
}

/// `calibrate --vertex-cache`: the same policies as `--policy`, its errors
/// naming the option they came from.
pub(super) fn parse_vertex_cache(policy: &str) -> anyhow::Result<CachePolicy> {
    policy
        .parse()
        .map_err(|e| anyhow::anyhow!("--vertex-cache {policy:?}: {e}"))
}

/// `calibrate --holdout-max-median` and `--holdout-max-p90`: a bound in
/// percent, a finite number at least 0 (NaN or infinity would make the
/// check pass whatever the errors).
fn parse_percent_bound(flag: &str, pct: &str) -> anyhow::Result<f64> {
    match pct.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(anyhow::anyhow!(
            "{flag} {pct:?}: expected a percentage, a finite number at least 0 (e.g. 30)"
        )),
    }
}

pub(super) fn parse_max_median(pct: &str) -> anyhow::Result<f64> {
    parse_percent_bound("--holdout-max-median", pct)
}

pub(super) fn parse_max_p90(pct: &str) -> anyhow::Result<f64> {
    parse_percent_bound("--holdout-max-p90", pct)
}

/// A usage error with `message` as its whole text (`error: ` before it),
/// exit status 2.
fn invalid_value(cmd: &clap::Command, message: String) -> clap::Error {
    clap::Error::raw(ErrorKind::InvalidValue, format!("{message}\n")).with_cmd(cmd)
}

/// A value parser for a closed choice `E`, whose refusal reads `unknown(value)`.
#[derive(Clone)]
pub struct Choice<E> {
    unknown: fn(&str) -> String,
    choice: PhantomData<fn() -> E>,
}

impl<E> Choice<E> {
    pub(super) fn new(unknown: fn(&str) -> String) -> Self {
        Choice {
            unknown,
            choice: PhantomData,
        }
    }
}

impl<E: ValueEnum + Clone + Send + Sync + 'static> TypedValueParser for Choice<E> {
    type Value = E;

    fn parse_ref(&self, cmd: &clap::Command, _arg: Option<&clap::Arg>, value: &OsStr) -> Result<E, clap::Error> {
        let text = value.to_string_lossy();
        E::from_str(&text, false).map_err(|_| invalid_value(cmd, (self.unknown)(&text)))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(
            E::value_variants().iter().filter_map(|v| v.to_possible_value()),
        ))
    }
}

/// A value parser from a function whose error is the whole message.
#[derive(Clone)]
pub struct Plain<T> {
    parse: fn(&str) -> anyhow::Result<T>,
}

impl<T> Plain<T> {
    pub(super) fn new(parse: fn(&str) -> anyhow::Result<T>) -> Self {
        Plain { parse }
    }
}

impl<T: Clone + Send + Sync + 'static> TypedValueParser for Plain<T> {
    type Value = T;

    fn parse_ref(&self, cmd: &clap::Command, _arg: Option<&clap::Arg>, value: &OsStr) -> Result<T, clap::Error> {
        (self.parse)(&value.to_string_lossy()).map_err(|e| invalid_value(cmd, e.to_string()))
    }
}
