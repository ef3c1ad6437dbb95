//! Per-frame records and the frames table, with PresentMon's v2 column names
//! where the meaning matches:
//!
//! - `FrameTime`: from this frame's CPU start to the next one's (the CPU
//!   start is when the thread finished the previous frame's swap; it
//!   includes any wait for frames in flight);
//! - `MsCPUBusy` / `MsCPUWait`: CPU time working (system tasks included) /
//!   blocked (full command FIFO, frames in flight) within the frame; they add
//!   up to `FrameTime`;
//! - `MsGPULatency`: CPU start to the GPU starting the frame (its clear);
//! - `MsGPUTime`: GPU start to GPU end (the swap); `MsGPUBusy` the part of it
//!   with any GPU unit busy; `MsGPUWait` the rest;
//! - `MsUntilDisplayed`: the swap call (present) to the frame appearing;
//! - `DisplayLatency`: input sampling to the frame appearing;
//! - `MsBetweenDisplayChange`: this frame's appearance to the previous one's;
//! - `Dropped`: 1 if the frame was never shown.

use crate::engine::{PS_PER_MS, Time};

/// One frame's timeline.
#[derive(Debug, Clone)]
pub struct FrameRecord {
    /// Frame index.
    pub index: u64,
    /// CPU start (end of the previous frame's swap call).
    pub start: Time,
    /// Input sampled.
    pub input: Time,
    /// Swap command pushed (end of the CPU frame).
    pub present: Time,
    /// CPU busy picoseconds (work and system tasks).
    pub cpu_busy: u64,
    /// CPU blocked picoseconds.
    pub cpu_wait: u64,
    /// GPU began the frame.
    pub gpu_start: Option<Time>,
    /// GPU finished the frame.
    pub gpu_end: Option<Time>,
    /// GPU busy picoseconds.
    pub gpu_busy: u64,
    /// Shown on screen.
    pub displayed: Option<Time>,
    /// Discarded without being shown.
    pub dropped: bool,
}

impl FrameRecord {
    /// A frame starting at `start`.
    pub fn new(index: u64, start: Time) -> Self {
        FrameRecord {
            index,
            start,
            input: start,
            present: start,
            cpu_busy: 0,
            cpu_wait: 0,
            gpu_start: None,
            gpu_end: None,
            gpu_busy: 0,
            displayed: None,
            dropped: false,
        }
    }
}

/// Columns of `frames.csv`.
pub const COLUMNS: [&str; 14] = [
    "Frame",
    "TimeInSeconds",
    "FrameTime",
    "MsCPUBusy",
    "MsCPUWait",
    "MsGPULatency",
    "MsGPUTime",
    "MsGPUBusy",
    "MsGPUWait",
    "MsUntilDisplayed",
    "DisplayLatency",
    "MsBetweenDisplayChange",
    "Displayed",
    "Dropped",
];

fn ms(ps: u64) -> f64 {
    ps as f64 / PS_PER_MS as f64
}

/// The frames table: one row per frame, [`COLUMNS`] in order. Values that do
/// not exist for a frame (never displayed) are NaN here and empty in CSV.
pub fn frame_rows(records: &[FrameRecord]) -> Vec<[f64; 14]> {
    let mut rows = Vec::with_capacity(records.len());
    let mut prev_display: Option<Time> = None;
    for (i, r) in records.iter().enumerate() {
        let end = records.get(i + 1).map(|n| n.start).unwrap_or(r.present);
        let gpu_time = match (r.gpu_start, r.gpu_end) {
            (Some(a), Some(b)) => ms(b.since(a).0),
            _ => f64::NAN,
        };
        let (until, latency, between) = match r.displayed {
            Some(d) => {
                let between = prev_display.map(|p| ms(d.since(p).0)).unwrap_or(f64::NAN);
                prev_display = Some(d);
                (ms(d.since(r.present).0), ms(d.since(r.input).0), between)
            }
            None => (f64::NAN, f64::NAN, f64::NAN),
        };
        rows.push([
            r.index as f64,
            r.start.0 as f64 / 1e12,
            ms(end.since(r.start).0),
            ms(r.cpu_busy),
            ms(r.cpu_wait),
            r.gpu_start.map(|g| ms(g.since(r.start).0)).unwrap_or(f64::NAN),
            gpu_time,
            ms(r.gpu_busy),
            if gpu_time.is_nan() {
                f64::NAN
            } else {
                gpu_time - ms(r.gpu_busy)
            },
            until,
            latency,
            between,
            r.displayed.is_some() as u8 as f64,
            r.dropped as u8 as f64,
        ]);
    }
    rows
}

/// Writes the frames table as CSV (exact decimal text; empty for missing).
pub fn write_frames_csv<W: std::io::Write>(records: &[FrameRecord], w: W) -> std::io::Result<()> {
    let rows = frame_rows(records).into_iter().map(|row| {
        row.iter()
            .enumerate()
            .map(|(i, v)| {
                if v.is_nan() {
                    String::new()
                } else if i == 0 || i >= 12 {
                    format!("{}", *v as u64)
                } else {
                    let t = format!("{v:.9}");
                    // A tiny negative difference (MsGPUWait) must not print as "-0.000000000".
                    match t.strip_prefix('-') {
                        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
                        _ => t,
                    }
                }
            })
            .collect()
    });
    crate::output::table::write_table(std::io::BufWriter::new(w), &COLUMNS, rows)
}
