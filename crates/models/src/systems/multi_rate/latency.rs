//! Per input event: when it became visible through each path, and the
//! stages it spent time in. Stage names follow NVIDIA Reflex's latency
//! markers where the meaning matches (input sample, simulation, render
//! submission, render, display); the multi-frame-rate chain adds read-back,
//! transfer and the wait for FC to pick SC's image up (composite wait).
//!
//! The stages of one event telescope: each is the gap between two instants
//! on the event's own path, so they add up to its latency exactly.

use crate::engine::Time;

use super::analytic::Terms;
use super::model::{ConvFrame, FcFrame};

/// Stages of the fast path (input visible in FC's own rendering).
pub const FAST_STAGES: [&str; 6] = [
    "input_sample",
    "sensor_transport",
    "simulation_wait",
    "render_submission",
    "render",
    "display",
];

/// Stages of the slow path (input visible in SC's image, shown by FC).
pub const SLOW_STAGES: [&str; 10] = [
    "input_sample",
    "sensor_transport",
    "simulation_wait",
    "render",
    "readback",
    "transfer",
    "composite_wait",
    "render_submission",
    "composite_render",
    "display",
];

/// Stages of the conventional single client.
pub const CONV_STAGES: [&str; 5] = [
    "input_sample",
    "sensor_transport",
    "simulation_wait",
    "render",
    "display",
];

/// One input event's fate.
#[derive(Debug, Clone)]
pub struct EventRecord {
    /// When it happened.
    pub time: Time,
    /// The tracker sample that captured it.
    pub sample: u64,
    /// Fast path stages (picoseconds), with the FC frame that showed it.
    pub fast: Option<(usize, Vec<u64>)>,
    /// Slow path stages, with the FC frame that showed SC's image and the SC frame.
    pub slow: Option<(usize, usize, Vec<u64>)>,
    /// Conventional stages, with the frame.
    pub conventional: Option<(usize, Vec<u64>)>,
}

fn gaps(points: &[Time]) -> Vec<u64> {
    points.windows(2).map(|w| w[1].0.saturating_sub(w[0].0)).collect()
}

/// Follows the input events through the frames as the frames end.
///
/// Every path shows the events in their order: an event captured by
/// tracker sample `j` is shown by the first frame of the path that ends
/// having read a sample at or after `j` (for the slow path: whose SC image
/// read one). Samples only grow from frame to frame, so each path keeps a
/// cursor into the records: a frame that ends shows the waiting events from
/// the cursor on while their sample is within its own, and is not needed
/// after that. The records are those of the whole run; no frame is kept.
#[derive(Debug)]
pub struct Follower {
    terms: Terms,
    /// Every input event's fate so far.
    pub records: Vec<EventRecord>,
    next_fast: usize,
    next_slow: usize,
    next_conv: usize,
    /// Stage values held in the records (kept as they are added, so that
    /// the memory check on every input costs nothing).
    stage_values: usize,
}

impl Follower {
    /// A follower for up to `events` input events.
    pub fn new(terms: Terms, events: u64) -> Self {
        Follower {
            terms,
            records: Vec::with_capacity(events.min(1 << 16) as usize),
            next_fast: 0,
            next_slow: 0,
            next_conv: 0,
            stage_values: 0,
        }
    }

    /// The tracker sample that captures an input at `t` (the first at or after it).
    pub fn capturing_sample(&self, t: Time) -> u64 {
        t.0.div_ceil(self.terms.tracker_period.0.max(1))
    }

    /// Bytes the records take now (their stage lists included).
    pub fn record_bytes(&self) -> u64 {
        (self.records.capacity() * std::mem::size_of::<EventRecord>() + self.stage_values * 8) as u64
    }

    /// An input event happens at `time`.
    pub fn input(&mut self, time: Time) {
        let sample = self.capturing_sample(time);
        self.records.push(EventRecord {
            time,
            sample,
            fast: None,
            slow: None,
            conventional: None,
        });
    }

    /// The instants every path starts from: the event, its sample, and the
    /// sample's delivery. (The simulation scheduled that delivery with
    /// checked time, so it fits.)
    fn opening(&self, r: &EventRecord) -> [Time; 3] {
        let sampled = Time(r.sample.saturating_mul(self.terms.tracker_period.0));
        [
            r.time,
            sampled,
            Time(sampled.0.saturating_add(self.terms.sensor_latency.0)),
        ]
    }

    /// FC frame number `index` ended: it shows the events its sample has
    /// captured (fast path), and those its SC image's sample has (slow path).
    pub fn fc_frame_end(&mut self, index: usize, f: &FcFrame) {
        let disp = self.terms.display.0;
        while self.next_fast < self.records.len() && f.sample >= Some(self.records[self.next_fast].sample) {
            let [te, sampled, delivered] = self.opening(&self.records[self.next_fast]);
            let mut g = gaps(&[te, sampled, delivered, f.start, f.upload_end, f.end]);
            g.push(disp);
            self.stage_values += g.len();
            self.records[self.next_fast].fast = Some((index, g));
            self.next_fast += 1;
        }
        let Some((b, s)) = f.buffer else { return };
        let Some(arrived) = s.arrived else { return };
        while self.next_slow < self.records.len() && s.sample >= Some(self.records[self.next_slow].sample) {
            let [te, sampled, delivered] = self.opening(&self.records[self.next_slow]);
            let mut g = gaps(&[
                te,
                sampled,
                delivered,
                s.start,
                s.render_end,
                s.readback_end,
                arrived,
                f.start,
                f.upload_end,
                f.end,
            ]);
            g.push(disp);
            self.stage_values += g.len();
            self.records[self.next_slow].slow = Some((index, b, g));
            self.next_slow += 1;
        }
    }

    /// Conventional frame number `index` ended.
    pub fn conv_frame_end(&mut self, index: usize, c: &ConvFrame) {
        let disp = self.terms.display.0;
        while self.next_conv < self.records.len() && c.sample >= Some(self.records[self.next_conv].sample) {
            let [te, sampled, delivered] = self.opening(&self.records[self.next_conv]);
            let mut g = gaps(&[te, sampled, delivered, c.start, c.end]);
            g.push(disp);
            self.stage_values += g.len();
            self.records[self.next_conv].conventional = Some((index, g));
            self.next_conv += 1;
        }
    }

    /// Whether every event so far is shown on every path (the conventional
    /// one only when it runs).
    pub fn all_shown(&self, conventional: bool) -> bool {
        let n = self.records.len();
        self.next_fast == n && self.next_slow == n && (!conventional || self.next_conv == n)
    }
}

/// Total latency in milliseconds from stage gaps.
pub fn total_ms(stages: &[u64]) -> f64 {
    stages.iter().sum::<u64>() as f64 / 1e9
}

/// Columns of the per-event table.
pub const COLUMNS: [&str; 7] = [
    "event",
    "input_ms",
    "tracker_sample",
    "fast_latency_ms",
    "slow_latency_ms",
    "conventional_latency_ms",
    "sc_frame",
];

/// The per-event table (NaN where a path did not show the event).
pub fn event_rows(events: &[EventRecord]) -> Vec<Vec<f64>> {
    events
        .iter()
        .enumerate()
        .map(|(i, e)| {
            vec![
                i as f64,
                e.time.as_ms_f64(),
                e.sample as f64,
                e.fast.as_ref().map_or(f64::NAN, |f| total_ms(&f.1)),
                e.slow.as_ref().map_or(f64::NAN, |s| total_ms(&s.2)),
                e.conventional.as_ref().map_or(f64::NAN, |c| total_ms(&c.1)),
                e.slow.as_ref().map_or(f64::NAN, |s| s.1 as f64),
            ]
        })
        .collect()
}
