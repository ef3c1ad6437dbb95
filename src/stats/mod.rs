//! stats
pub mod ci;
pub mod quantile;
