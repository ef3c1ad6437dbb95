//! Statistics: summaries, quantiles, confidence intervals.
pub mod quantile;
