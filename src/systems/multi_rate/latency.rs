//! Per input event: when it became visible through each path, and the
//! stages it spent time in. Stage names follow NVIDIA Reflex's latency
//! markers where the meaning matches (input sample, simulation, render
//! submission, render, display); the multi-frame-rate chain adds read-back,
//! transfer and the wait for FC to pick SC's image up (composite wait).
//!
//! The stages of one event telescope: each is the gap between two instants
//! on the event's own path, so they add up to its latency exactly.

use crate::engine::Time;

use super::model::MultiRate;

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

/// Follows every input event through the recorded frames.
pub fn follow_events(m: &MultiRate) -> Vec<EventRecord> {
    let t = &m.terms;
    let disp = t.display.0;
    let fcs = &m.fc[..m.fc_done];
    let convs = &m.conv[..m.conv_done];
    let (mut fi, mut si, mut ci) = (0usize, 0usize, 0usize);
    let mut out = Vec::with_capacity(m.inputs.len());
    for &te in &m.inputs {
        let j = m.capturing_sample(te);
        let sampled = m.sample_time(j);
        // The simulation scheduled this delivery with checked time, so it fits.
        let delivered = Time(sampled.0.saturating_add(t.sensor_latency.0));
        while fi < fcs.len() && fcs[fi].sample < Some(j) {
            fi += 1;
        }
        let fast = fcs.get(fi).map(|f| {
            let mut g = gaps(&[te, sampled, delivered, f.start, f.upload_end, f.end]);
            g.push(disp);
            (fi, g)
        });
        while si < fcs.len() && fcs[si].buffer.and_then(|b| m.sc[b].sample) < Some(j) {
            si += 1;
        }
        let slow = fcs.get(si).and_then(|f| {
            let b = f.buffer?;
            let s = &m.sc[b];
            let mut g = gaps(&[
                te,
                sampled,
                delivered,
                s.start,
                s.render_end,
                s.readback_end,
                s.arrived?,
                f.start,
                f.upload_end,
                f.end,
            ]);
            g.push(disp);
            Some((si, b, g))
        });
        while ci < convs.len() && convs[ci].sample < Some(j) {
            ci += 1;
        }
        let conventional = convs.get(ci).map(|c| {
            let mut g = gaps(&[te, sampled, delivered, c.start, c.end]);
            g.push(disp);
            (ci, g)
        });
        out.push(EventRecord {
            time: te,
            sample: j,
            fast,
            slow,
            conventional,
        });
    }
    out
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
