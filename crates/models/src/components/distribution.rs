//! Random variables for costs and sizes.
//!
//! A [`Dist`] models a non-negative random quantity: a per-draw cost, a
//! per-object pixel count, the length of a system task. Its location and scale
//! parameters are given in a [`Quantity`] (unit-free `f64`, or the simulator's
//! duration type), while every method works in that quantity's base unit as
//! `f64`.
//!
//! Besides sampling, the module gives closed forms for the mean, the variance
//! and `E[max(a, X)]`. The latter prices two stages that run side by side and
//! wait for each other, in the spirit of Wimmer & Wonka's
//! `RT = ETsystem + max(ETcpu, ETgpu)` (paper 000, section 3): with one side
//! known (`a`) and the other random (`X`), the expected frame time is
//! `E[max(a, X)]`.
//!
//! In a model file a distribution is written either as a bare scalar (a
//! constant) or as a table such as
//! `{ kind = "lognormal", median = "0.4ms", sigma = 0.3 }`.

use std::fmt;
use std::marker::PhantomData;

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::de::{self, IntoDeserializer, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};
use statrs::function::erf::erfc;

/// A quantity a distribution's location/scale parameters are given in. f64 for
/// unit-free values (pixels); the simulator implements it for its picosecond
/// Duration type (deserialized from strings like "0.5ms").
pub trait Quantity: Copy + fmt::Debug + PartialEq + Serialize + for<'de> Deserialize<'de> {
    /// The value in the quantity's base unit.
    fn to_f64(self) -> f64;
    /// The quantity for a value in its base unit.
    fn from_f64(x: f64) -> Self;
    /// A value as a model file writes it (with its unit), for messages.
    fn show(self) -> String {
        format!("{}", self.to_f64())
    }
}

impl Quantity for f64 {
    fn to_f64(self) -> f64 {
        self
    }
    fn from_f64(x: f64) -> Self {
        x
    }
}

/// Picoseconds: the kernel's [`Duration`](crate::engine::Duration) knows
/// nothing of distributions, so the component layer implements this here.
impl Quantity for crate::engine::Duration {
    fn to_f64(self) -> f64 {
        self.0 as f64
    }
    fn from_f64(x: f64) -> Self {
        crate::engine::Duration::from_ps_f64(x)
    }
    fn show(self) -> String {
        self.to_string()
    }
}

/// One weighted component of a [`Dist::Mixture`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, bound = "V: Quantity")]
pub struct MixturePart<V: Quantity> {
    /// Relative weight (> 0); weights are normalized by their sum.
    pub weight: f64,
    /// The component distribution.
    pub dist: Dist<V>,
}

/// A non-negative random variable with parameters in quantity `V`.
///
/// Uniform on [0, 10]: mean 5, variance 100 / 12, P(X > 4) = 0.6, and
/// `E[max(4, X)]` = 4 P(X < 4) + `E[X; X > 4]` = 1.6 + (100 - 16) / 20 = 5.8;
/// samples average to the mean. A duration's parameters are in picoseconds.
///
/// ```
/// use rendersim_models::components::distribution::Dist;
/// use rendersim_engine::{Duration, RngStreams};
///
/// let x: Dist<f64> = Dist::Uniform { min: 0.0, max: 10.0 };
/// assert_eq!(x.mean(), 5.0);
/// assert!((x.variance() - 100.0 / 12.0).abs() < 1e-12);
/// assert!((x.survival(4.0) - 0.6).abs() < 1e-12);
/// assert!((x.expected_max_with(4.0) - 5.8).abs() < 1e-12);
/// let mut rng = RngStreams::new(1).stream("example");
/// let n = 100_000;
/// let avg = (0..n).map(|_| x.sample(&mut rng)).sum::<f64>() / n as f64;
/// assert!((avg - 5.0).abs() < 0.05);
///
/// // A lognormal render time, median 14 ms: mean 14 exp(sigma^2 / 2) ms.
/// let t: Dist<Duration> = Dist::Lognormal { median: Duration::ms(14), sigma: 0.4 };
/// let mean_ms = t.mean() / Duration::ms(1).0 as f64;
/// assert!((mean_ms - 14.0 * 0.08_f64.exp()).abs() < 1e-9);
/// assert_eq!(Dist::constant(Duration::ms(3)).mean(), 3e9);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", bound = "V: Quantity")]
pub enum Dist<V: Quantity> {
    /// Always `value`.
    Const {
        /// The constant value.
        value: V,
    },
    /// Uniform on `[min, max]`.
    Uniform {
        /// Lower bound.
        min: V,
        /// Upper bound.
        max: V,
    },
    /// Exponential with the given mean.
    Exponential {
        /// The mean (= the standard deviation).
        mean: V,
    },
    /// Lognormal: `median * exp(sigma * Z)` with `Z` standard normal.
    Lognormal {
        /// The median, `exp(mu)`.
        median: V,
        /// Standard deviation of the logarithm.
        sigma: f64,
    },
    /// Pareto (type I) with support `[scale, inf)`.
    Pareto {
        /// The minimum value `x_m`.
        scale: V,
        /// The tail index `alpha` (> 0); the mean exists for `shape > 1`.
        shape: f64,
    },
    /// A weighted mixture of distributions.
    Mixture {
        /// The components.
        parts: Vec<MixturePart<V>>,
    },
}

/// An invalid distribution parameter; `param` names it (with a path inside
/// mixtures, e.g. `parts[1].dist.sigma`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DistError {
    /// A parameter is NaN or infinite.
    #[error("distribution parameter `{param}` must be finite, got {value}")]
    NotFinite {
        /// The parameter's name.
        param: String,
        /// Its value.
        value: f64,
    },
    /// A parameter that must be `>= 0` is negative.
    #[error("distribution parameter `{param}` must not be negative, got {value}")]
    Negative {
        /// The parameter's name.
        param: String,
        /// Its value.
        value: f64,
    },
    /// A parameter that must be `> 0` is not.
    #[error("distribution parameter `{param}` must be greater than 0, got {value}")]
    NotPositive {
        /// The parameter's name.
        param: String,
        /// Its value.
        value: f64,
    },
    /// A uniform distribution with `min > max`.
    #[error("distribution parameter `{prefix}min` ({min}) must not exceed `{prefix}max` ({max})")]
    MinAboveMax {
        /// Path prefix inside a mixture ("" at the top level).
        prefix: String,
        /// The lower bound, as a model file writes it (`30ms`).
        min: String,
        /// The upper bound, as a model file writes it.
        max: String,
    },
    /// A mixture without parts.
    #[error("distribution parameter `{prefix}parts` must not be empty")]
    EmptyMixture {
        /// Path prefix inside a mixture ("" at the top level).
        prefix: String,
    },
}

/// The standard normal CDF.
fn phi(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

fn check(prefix: &str, name: &str, value: f64, positive: bool) -> Result<(), DistError> {
    let param = || format!("{prefix}{name}");
    if !value.is_finite() {
        Err(DistError::NotFinite { param: param(), value })
    } else if positive && value <= 0.0 {
        Err(DistError::NotPositive { param: param(), value })
    } else if value < 0.0 {
        Err(DistError::Negative { param: param(), value })
    } else {
        Ok(())
    }
}

impl<V: Quantity> Dist<V> {
    /// A constant distribution.
    pub fn constant(value: V) -> Self {
        Dist::Const { value }
    }

    /// The kind's name as written in model files.
    pub fn kind(&self) -> &'static str {
        match self {
            Dist::Const { .. } => "const",
            Dist::Uniform { .. } => "uniform",
            Dist::Exponential { .. } => "exponential",
            Dist::Lognormal { .. } => "lognormal",
            Dist::Pareto { .. } => "pareto",
            Dist::Mixture { .. } => "mixture",
        }
    }

    /// Checks the parameters: all finite, none negative, `min <= max`,
    /// `sigma >= 0`, `median > 0`, Pareto `scale > 0` and `shape > 0`,
    /// mixture weights `> 0` and at least one part.
    pub fn validate(&self) -> Result<(), DistError> {
        self.validate_at("")
    }

    fn validate_at(&self, prefix: &str) -> Result<(), DistError> {
        match self {
            Dist::Const { value } => check(prefix, "value", value.to_f64(), false),
            Dist::Uniform { min, max } => {
                let (lo, hi) = (min.to_f64(), max.to_f64());
                check(prefix, "min", lo, false)?;
                check(prefix, "max", hi, false)?;
                if lo > hi {
                    return Err(DistError::MinAboveMax {
                        prefix: prefix.to_string(),
                        min: min.show(),
                        max: max.show(),
                    });
                }
                Ok(())
            }
            Dist::Exponential { mean } => check(prefix, "mean", mean.to_f64(), false),
            Dist::Lognormal { median, sigma } => {
                check(prefix, "median", median.to_f64(), true)?;
                check(prefix, "sigma", *sigma, false)
            }
            Dist::Pareto { scale, shape } => {
                check(prefix, "scale", scale.to_f64(), true)?;
                check(prefix, "shape", *shape, true)
            }
            Dist::Mixture { parts } => {
                if parts.is_empty() {
                    return Err(DistError::EmptyMixture {
                        prefix: prefix.to_string(),
                    });
                }
                for (i, part) in parts.iter().enumerate() {
                    let p = format!("{prefix}parts[{i}].");
                    check(&p, "weight", part.weight, true)?;
                    part.dist.validate_at(&format!("{p}dist."))?;
                }
                Ok(())
            }
        }
    }

    /// Draws one value (base unit). Never negative, never NaN, never infinite
    /// (an extreme Pareto draw is clamped to `f64::MAX`).
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        let x = match self {
            Dist::Const { value } => value.to_f64(),
            Dist::Uniform { min, max } => {
                let (lo, hi) = (min.to_f64(), max.to_f64());
                lo + (hi - lo) * rng.random::<f64>()
            }
            Dist::Exponential { mean } => {
                // 1 - u lies in (0, 1], so the logarithm is finite.
                -mean.to_f64() * (1.0 - rng.random::<f64>()).ln()
            }
            Dist::Lognormal { median, sigma } => {
                let z: f64 = StandardNormal.sample(rng);
                median.to_f64() * (sigma * z).exp()
            }
            Dist::Pareto { scale, shape } => {
                let u = 1.0 - rng.random::<f64>();
                scale.to_f64() * u.powf(-1.0 / shape)
            }
            Dist::Mixture { parts } => {
                let total: f64 = parts.iter().map(|p| p.weight).sum();
                let mut pick = rng.random::<f64>() * total;
                let mut chosen = parts.last();
                for part in parts {
                    if pick < part.weight {
                        chosen = Some(part);
                        break;
                    }
                    pick -= part.weight;
                }
                chosen.map_or(0.0, |p| p.dist.sample(rng))
            }
        };
        // Guards against NaN from unvalidated parameters; the clamp keeps
        // heavy tails finite.
        if x.is_nan() { 0.0 } else { x.clamp(0.0, f64::MAX) }
    }

    /// The mean (base unit); infinite where it does not exist (Pareto with
    /// `shape <= 1`).
    pub fn mean(&self) -> f64 {
        match self {
            Dist::Const { value } => value.to_f64(),
            Dist::Uniform { min, max } => 0.5 * (min.to_f64() + max.to_f64()),
            Dist::Exponential { mean } => mean.to_f64(),
            Dist::Lognormal { median, sigma } => median.to_f64() * (0.5 * sigma * sigma).exp(),
            Dist::Pareto { scale, shape } => {
                if *shape <= 1.0 {
                    f64::INFINITY
                } else {
                    shape * scale.to_f64() / (shape - 1.0)
                }
            }
            Dist::Mixture { parts } => weighted(parts, |d| d.mean()),
        }
    }

    /// The variance (base unit squared); infinite where it does not exist
    /// (Pareto with `shape <= 2`).
    pub fn variance(&self) -> f64 {
        match self {
            Dist::Const { .. } => 0.0,
            Dist::Uniform { min, max } => (max.to_f64() - min.to_f64()).powi(2) / 12.0,
            Dist::Exponential { mean } => mean.to_f64().powi(2),
            Dist::Lognormal { median, sigma } => {
                let s2 = sigma * sigma;
                median.to_f64().powi(2) * s2.exp() * s2.exp_m1()
            }
            Dist::Pareto { scale, shape } => {
                if *shape <= 2.0 {
                    f64::INFINITY
                } else {
                    scale.to_f64().powi(2) * shape / ((shape - 1.0).powi(2) * (shape - 2.0))
                }
            }
            Dist::Mixture { parts } => {
                let mean = self.mean();
                if !mean.is_finite() {
                    return f64::INFINITY;
                }
                // Law of total variance: E[Var + mean^2] - mean^2.
                let second = weighted(parts, |d| d.variance() + d.mean().powi(2));
                (second - mean * mean).max(0.0)
            }
        }
    }

    /// `P(X > x)` in closed form (`x` in the base unit): the survival
    /// function, 1 below the support and 0 above it.
    pub fn survival(&self, x: f64) -> f64 {
        match self {
            Dist::Const { value } => {
                if x < value.to_f64() {
                    1.0
                } else {
                    0.0
                }
            }
            Dist::Uniform { min, max } => {
                let (lo, hi) = (min.to_f64(), max.to_f64());
                if x < lo {
                    1.0
                } else if x >= hi {
                    0.0
                } else {
                    (hi - x) / (hi - lo)
                }
            }
            Dist::Exponential { mean } => {
                let m = mean.to_f64();
                if x < 0.0 {
                    1.0
                } else if m <= 0.0 {
                    0.0
                } else {
                    (-x / m).exp()
                }
            }
            Dist::Lognormal { median, sigma } => {
                let m = median.to_f64();
                if x <= 0.0 {
                    1.0
                } else if *sigma == 0.0 {
                    if x < m { 1.0 } else { 0.0 }
                } else {
                    1.0 - phi((x.ln() - m.ln()) / sigma)
                }
            }
            Dist::Pareto { scale, shape } => {
                let xm = scale.to_f64();
                if x < xm { 1.0 } else { (xm / x).powf(*shape) }
            }
            Dist::Mixture { parts } => weighted(parts, |d| d.survival(x)),
        }
    }

    /// `E[max(a, X)]` in closed form (base unit). Infinite for a Pareto with
    /// `shape <= 1` (the mean does not exist).
    pub fn expected_max_with(&self, a: f64) -> f64 {
        match self {
            Dist::Const { value } => a.max(value.to_f64()),
            Dist::Uniform { min, max } => {
                let (lo, hi) = (min.to_f64(), max.to_f64());
                if a <= lo {
                    self.mean()
                } else if a >= hi {
                    a
                } else {
                    // a * P(X <= a) + E[X; X > a]
                    (a * (a - lo) + 0.5 * (hi * hi - a * a)) / (hi - lo)
                }
            }
            Dist::Exponential { mean } => {
                let m = mean.to_f64();
                if a <= 0.0 {
                    m
                } else if m <= 0.0 {
                    a
                } else {
                    // a + E[(X - a)+] and the memoryless tail.
                    a + m * (-a / m).exp()
                }
            }
            Dist::Lognormal { median, sigma } => {
                let m = median.to_f64();
                if a <= 0.0 {
                    self.mean()
                } else if *sigma == 0.0 || m <= 0.0 {
                    a.max(m)
                } else {
                    let mu = m.ln();
                    let s = *sigma;
                    let z = (a.ln() - mu) / s;
                    // a * P(X <= a) + E[X; X > a]
                    a * phi(z) + self.mean() * phi(s - z)
                }
            }
            Dist::Pareto { scale, shape } => {
                let xm = scale.to_f64();
                if a <= xm {
                    self.mean()
                } else if *shape <= 1.0 {
                    f64::INFINITY
                } else {
                    // a + E[(X - a)+] = a + a (xm/a)^alpha / (alpha - 1)
                    a + a * (xm / a).powf(*shape) / (shape - 1.0)
                }
            }
            Dist::Mixture { parts } => weighted(parts, |d| d.expected_max_with(a)),
        }
    }

    /// The distribution of `k * X` as a unit-free `f64` distribution
    /// (`k >= 0` expected; a negative `k` yields a distribution that fails
    /// [`validate`](Self::validate)).
    pub fn scaled(&self, k: f64) -> Dist<f64> {
        self.scaled_as(k)
    }

    /// The distribution of `k * X` in another quantity type (for example a
    /// duration distribution scaled by a factor stays a duration one).
    pub fn scaled_as<W: Quantity>(&self, k: f64) -> Dist<W> {
        match self {
            Dist::Const { value } => Dist::Const {
                value: W::from_f64(k * value.to_f64()),
            },
            Dist::Uniform { min, max } => Dist::Uniform {
                min: W::from_f64(k * min.to_f64()),
                max: W::from_f64(k * max.to_f64()),
            },
            Dist::Exponential { mean } => Dist::Exponential {
                mean: W::from_f64(k * mean.to_f64()),
            },
            Dist::Lognormal { median, sigma } => Dist::Lognormal {
                median: W::from_f64(k * median.to_f64()),
                sigma: *sigma,
            },
            Dist::Pareto { scale, shape } => Dist::Pareto {
                scale: W::from_f64(k * scale.to_f64()),
                shape: *shape,
            },
            Dist::Mixture { parts } => Dist::Mixture {
                parts: parts
                    .iter()
                    .map(|p| MixturePart {
                        weight: p.weight,
                        dist: p.dist.scaled_as(k),
                    })
                    .collect(),
            },
        }
    }
}

/// Weight-normalized sum of `f` over mixture parts (0 for no parts).
fn weighted<V: Quantity>(parts: &[MixturePart<V>], f: impl Fn(&Dist<V>) -> f64) -> f64 {
    let total: f64 = parts.iter().map(|p| p.weight).sum();
    if total <= 0.0 {
        return 0.0;
    }
    parts.iter().map(|p| p.weight * f(&p.dist)).sum::<f64>() / total
}

// ---------------------------------------------------------------------------
// Deserialization: a bare scalar (Const) or a table with `kind`.

const KINDS: &[&str] = &["const", "uniform", "exponential", "lognormal", "pareto", "mixture"];
const FIELDS: &[&str] = &[
    "kind", "value", "min", "max", "mean", "median", "sigma", "scale", "shape", "parts",
];

/// The fields each kind takes (besides `kind`).
fn fields_of(kind: &str) -> Option<&'static [&'static str]> {
    Some(match kind {
        "const" => &["value"],
        "uniform" => &["min", "max"],
        "exponential" => &["mean"],
        "lognormal" => &["median", "sigma"],
        "pareto" => &["scale", "shape"],
        "mixture" => &["parts"],
        _ => return None,
    })
}

impl<'de, V: Quantity> Deserialize<'de> for Dist<V> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(DistVisitor(PhantomData))
    }
}

struct DistVisitor<V>(PhantomData<V>);

impl<V: Quantity> DistVisitor<V> {
    fn scalar<'de, E, D>(d: D) -> Result<Dist<V>, E>
    where
        E: de::Error,
        D: Deserializer<'de, Error = E>,
    {
        V::deserialize(d).map(|value| Dist::Const { value })
    }
}

/// Takes a field's value, rejecting duplicates.
fn put<T>(slot: &mut Option<T>, name: &'static str, value: T) -> Result<(), String> {
    if slot.is_some() {
        return Err(format!("duplicate field `{name}`"));
    }
    *slot = Some(value);
    Ok(())
}

impl<'de, V: Quantity> Visitor<'de> for DistVisitor<V> {
    type Value = Dist<V>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "a constant or a table with `kind` = one of {}", KINDS.join(", "))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
        Self::scalar(v.into_deserializer())
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        Self::scalar(v.into_deserializer())
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        Self::scalar(v.into_deserializer())
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
        Self::scalar(v.into_deserializer())
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut kind: Option<String> = None;
        let (mut value, mut min, mut max, mut mean, mut median, mut scale) =
            (None::<V>, None::<V>, None::<V>, None::<V>, None::<V>, None::<V>);
        let (mut sigma, mut shape) = (None::<f64>, None::<f64>);
        let mut parts: Option<Vec<MixturePart<V>>> = None;
        let mut seen: Vec<&'static str> = Vec::new();
        let mut unknown: Option<String> = None;
        while let Some(key) = map.next_key::<String>()? {
            let r = match key.as_str() {
                "kind" => put(&mut kind, "kind", map.next_value()?),
                "value" => put(&mut value, "value", map.next_value()?),
                "min" => put(&mut min, "min", map.next_value()?),
                "max" => put(&mut max, "max", map.next_value()?),
                "mean" => put(&mut mean, "mean", map.next_value()?),
                "median" => put(&mut median, "median", map.next_value()?),
                "sigma" => put(&mut sigma, "sigma", map.next_value()?),
                "scale" => put(&mut scale, "scale", map.next_value()?),
                "shape" => put(&mut shape, "shape", map.next_value()?),
                "parts" => put(&mut parts, "parts", map.next_value()?),
                other => {
                    // Reported once the kind is known, with that kind's fields.
                    map.next_value::<de::IgnoredAny>()?;
                    if unknown.is_none() {
                        unknown = Some(other.to_string());
                    }
                    Ok(())
                }
            };
            r.map_err(de::Error::custom)?;
            if let Some(name) = FIELDS.iter().find(|f| **f == key)
                && *name != "kind"
            {
                seen.push(name);
            }
        }
        let kind =
            kind.ok_or_else(|| de::Error::custom(format!("missing field `kind` (one of {})", KINDS.join(", "))))?;
        let allowed = fields_of(&kind).ok_or_else(|| de::Error::unknown_variant(&kind, KINDS))?;
        let extra = unknown
            .as_deref()
            .or_else(|| seen.iter().find(|f| !allowed.contains(f)).copied());
        if let Some(extra) = extra {
            return Err(de::Error::custom(format!(
                "unknown field `{extra}` for kind `{kind}`, expected {}",
                allowed.iter().map(|f| format!("`{f}`")).collect::<Vec<_>>().join(", ")
            )));
        }
        fn need<T, E: de::Error>(x: Option<T>, kind: &str, f: &'static str) -> Result<T, E> {
            x.ok_or_else(|| E::custom(format!("missing field `{f}` for kind `{kind}`")))
        }
        Ok(match kind.as_str() {
            "const" => Dist::Const {
                value: need(value, &kind, "value")?,
            },
            "uniform" => Dist::Uniform {
                min: need(min, &kind, "min")?,
                max: need(max, &kind, "max")?,
            },
            "exponential" => Dist::Exponential {
                mean: need(mean, &kind, "mean")?,
            },
            "lognormal" => Dist::Lognormal {
                median: need(median, &kind, "median")?,
                sigma: need(sigma, &kind, "sigma")?,
            },
            "pareto" => Dist::Pareto {
                scale: need(scale, &kind, "scale")?,
                shape: need(shape, &kind, "shape")?,
            },
            _ => Dist::Mixture {
                parts: need(parts, &kind, "parts")?,
            },
        })
    }
}

#[cfg(test)]
mod tests;
