//! Statistics: summaries, quantiles, confidence intervals.

pub mod ci;
pub mod quantile;
