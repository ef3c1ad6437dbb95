//! Frame captures read back as input: PresentMon's CSV as PresentMon,
//! OCAT, FrameView and CapFrameX write it ([`presentmon`]), the
//! per-present log that latency studies start from, and the display a
//! capture was taken on, inferred from the whole capture ([`display`]).
//! A capture is a user file like a model: a bad one is an error naming the
//! file, the line and the column.

pub mod display;
pub mod presentmon;
