//! frame pipeline
pub mod config;
