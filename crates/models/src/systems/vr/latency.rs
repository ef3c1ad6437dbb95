//! Per motion: when it became visible as head motion and as object motion,
//! and the stages it spent time in (they telescope: each is the gap between
//! two instants on the motion's own path, so they add up to its latency
//! exactly). Stage names from [`crate::systems::LATENCY_STAGES`].

use crate::engine::Time;

use super::config::VrConfig;
use super::model::{LoopFrame, WarpFrame};

/// Stages of a naive-loop motion (head and object alike).
pub const NAIVE_STAGES: [&str; 7] = [
    "input_sample",
    "sensor_transport",
    "simulation_wait",
    "simulation",
    "render",
    "swap_lock",
    "display",
];
/// Stages of a head motion in the warp scheme: the warping renderer reads
/// the newest pose at its frame start (`simulation_wait`, as a client's
/// frame start in the multi-frame-rate chain) and re-projects the newest
/// application frame (`composite_render`, as the fast client composites the
/// slow client's image). Names from [`crate::systems::LATENCY_STAGES`].
pub const WARP_HEAD_STAGES: [&str; 6] = [
    "input_sample",
    "sensor_transport",
    "simulation_wait",
    "composite_render",
    "swap_lock",
    "display",
];
/// Stages of an object motion in the warp scheme: after the simulation step,
/// the wait for the warping frame that takes its transforms is
/// `composite_wait` (as the fast client's wait for the slow client's image).
pub const WARP_OBJECT_STAGES: [&str; 8] = [
    "input_sample",
    "sensor_transport",
    "simulation_wait",
    "simulation",
    "composite_wait",
    "composite_render",
    "swap_lock",
    "display",
];

/// One motion's latencies (stage gaps, picoseconds).
#[derive(Debug, Clone)]
pub struct MotionRecord {
    /// When it happened.
    pub time: Time,
    /// Head motion stages.
    pub head: Option<Vec<u64>>,
    /// Object motion stages.
    pub object: Option<Vec<u64>>,
    /// Warp only: age of the re-projected application frame at the swap
    /// that showed the head motion (swap minus the application frame's start).
    pub app_age: Option<u64>,
}

/// Follows the motions through the frames as the frames swap.
///
/// A motion captured by tracker sample `j` shows as head motion in the
/// first frame to swap having read a camera pose at or after `j`, and as
/// object motion in the first whose simulation step read one (in the naive
/// loop both are the loop frame's one sample). Samples only grow from frame
/// to frame, so each path keeps a cursor into the records, and a frame is
/// not needed after it has swapped.
#[derive(Debug)]
pub struct Follower {
    tracker: super::config::TrackerConfig,
    display: u64,
    /// Every motion's fate so far.
    pub records: Vec<MotionRecord>,
    next_head: usize,
    next_object: usize,
    /// Stage values held in the records (kept as they are added, so that
    /// the memory check on every motion costs nothing).
    stage_values: usize,
}

impl Follower {
    /// A follower for the model's motions.
    pub fn new(cfg: &VrConfig) -> Self {
        Follower {
            tracker: cfg.tracker.clone(),
            display: cfg.display_latency().0,
            records: Vec::with_capacity(cfg.run.events.min(1 << 16) as usize),
            next_head: 0,
            next_object: 0,
            stage_values: 0,
        }
    }

    /// The sample that captures a motion at `t` (the first at or after it).
    pub fn capturing_sample(&self, t: Time) -> u64 {
        self.tracker.capturing_sample(t)
    }

    /// Bytes the records take now (their stage lists included).
    pub fn record_bytes(&self) -> u64 {
        (self.records.capacity() * std::mem::size_of::<MotionRecord>() + self.stage_values * 8) as u64
    }

    /// A motion happens at `time`.
    pub fn input(&mut self, time: Time) {
        self.records.push(MotionRecord {
            time,
            head: None,
            object: None,
            app_age: None,
        });
    }

    fn sample_of(&self, i: usize) -> u64 {
        self.capturing_sample(self.records[i].time)
    }

    /// Record `i`'s stages: from the motion to its sample, to the sample's
    /// delivery, then through `points`, then the display.
    fn stages(&self, i: usize, points: &[Time]) -> Vec<u64> {
        let t = self.records[i].time;
        let sampled = Time(self.sample_of(i).saturating_mul(self.tracker.period.0));
        // The simulation scheduled this delivery with checked time, so it fits.
        let delivered = Time(sampled.0.saturating_add(self.tracker.latency.0));
        let mut all = vec![t, sampled, delivered];
        all.extend_from_slice(points);
        let mut g: Vec<u64> = all.windows(2).map(|w| w[1].0.saturating_sub(w[0].0)).collect();
        g.push(self.display);
        g
    }

    /// A naive loop frame swapped: it shows the motions its sample captured,
    /// as head and as object motion alike.
    pub fn loop_swap(&mut self, f: &LoopFrame) {
        while self.next_head < self.records.len() && f.sample >= Some(self.sample_of(self.next_head)) {
            let g = self.stages(self.next_head, &[f.start, f.sim_end, f.render_end, f.swap]);
            let r = &mut self.records[self.next_head];
            self.stage_values += 2 * g.len();
            r.head = Some(g.clone());
            r.object = Some(g);
            self.next_head += 1;
        }
        self.next_object = self.next_head;
    }

    /// A warped frame swapped: head motions through its camera pose, object
    /// motions through its simulation step.
    pub fn warp_swap(&mut self, w: &WarpFrame) {
        while self.next_head < self.records.len() && w.camera >= Some(self.sample_of(self.next_head)) {
            let g = self.stages(self.next_head, &[w.start, w.render_end, w.swap]);
            self.stage_values += g.len();
            let r = &mut self.records[self.next_head];
            r.head = Some(g);
            r.app_age = w.app.map(|(_, a)| w.swap.0.saturating_sub(a.start.0));
            self.next_head += 1;
        }
        let Some((_, s)) = w.sim else { return };
        while self.next_object < self.records.len() && s.sample >= Some(self.sample_of(self.next_object)) {
            let g = self.stages(self.next_object, &[s.start, s.end, w.start, w.render_end, w.swap]);
            self.stage_values += g.len();
            self.records[self.next_object].object = Some(g);
            self.next_object += 1;
        }
    }

    /// Whether every motion so far is shown as head and as object motion.
    pub fn all_shown(&self) -> bool {
        let n = self.records.len();
        self.next_head == n && self.next_object == n
    }
}
