//! PLACEHOLDER (replaced by the scene branch's full version at merge).
use rand::Rng;
use serde::{Deserialize, Serialize};

/// Quantity.
pub trait Quantity: Copy + std::fmt::Debug + PartialEq + Serialize + for<'de> Deserialize<'de> {
    /// to f64
    fn to_f64(self) -> f64;
    /// from f64
    fn from_f64(x: f64) -> Self;
}
impl Quantity for f64 {
    fn to_f64(self) -> f64 { self }
    fn from_f64(x: f64) -> Self { x }
}
/// Dist.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
#[serde(bound(deserialize = "V: Quantity"))]
pub enum Dist<V: Quantity> {
    /// c
    Const { /** v */ value: V },
    /// u
    Uniform { /** a */ min: V, /** b */ max: V },
    /// ln
    Lognormal { /** m */ median: V, /** s */ sigma: f64 },
}
/// err
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct DistError(pub String);
impl<V: Quantity> Dist<V> {
    /// validate
    pub fn validate(&self) -> Result<(), DistError> { Ok(()) }
    /// sample
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        match self {
            Dist::Const { value } => value.to_f64(),
            Dist::Uniform { min, max } => min.to_f64() + (max.to_f64() - min.to_f64()) * rng.random::<f64>(),
            Dist::Lognormal { median, sigma } => {
                let z: f64 = rand_distr::Distribution::sample(&rand_distr::StandardNormal, rng);
                median.to_f64() * (sigma * z).exp()
            }
        }
    }
    /// mean
    pub fn mean(&self) -> f64 {
        match self {
            Dist::Const { value } => value.to_f64(),
            Dist::Uniform { min, max } => 0.5 * (min.to_f64() + max.to_f64()),
            Dist::Lognormal { median, sigma } => median.to_f64() * (0.5 * sigma * sigma).exp(),
        }
    }
    /// variance
    pub fn variance(&self) -> f64 {
        match self {
            Dist::Const { .. } => 0.0,
            Dist::Uniform { min, max } => (max.to_f64() - min.to_f64()).powi(2) / 12.0,
            Dist::Lognormal { median, sigma } => { let s2 = sigma * sigma; (s2.exp() - 1.0) * (2.0 * median.to_f64().ln() + s2).exp() }
        }
    }
    /// E max
    pub fn expected_max_with(&self, a: f64) -> f64 {
        match self {
            Dist::Const { value } => a.max(value.to_f64()),
            _ => a.max(self.mean()),
        }
    }
}
