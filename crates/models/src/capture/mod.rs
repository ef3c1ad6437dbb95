//! Frame captures read back as input: PresentMon's CSV
//! ([`presentmon`]), the per-present log that latency studies start from.
//! A capture is a user file like a model: a bad one is an error naming the
//! file, the line and the column.

pub mod presentmon;
