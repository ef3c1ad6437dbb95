//! The multi-frame-rate system as a kernel model (paper 003 §3, Figure 4).
//!
//! Processes, each a loop of events:
//! - input events (Poisson arrivals): each is captured by the first tracker
//!   sample at or after it; sample `k` is taken at `k * P` and reaches every
//!   client at `k * P + L`;
//! - the slow client (SC): frame start (reads the newest delivered sample)
//!   -> render end -> read-back end, then the next frame starts at once;
//! - the link: carries one read-back buffer at a time; a buffer read back
//!   while the link is busy waits in a one-slot mailbox (a newer one
//!   replaces it: latest wins);
//! - the fast client (FC): frame start (newest delivered sample, newest
//!   arrived SC buffer) -> upload end -> frame end, then the next frame;
//! - the conventional client: one frame of `R_sc` per frame, its own loop.
//!
//! The clients free-run from start phases drawn from named RNG streams. The
//! run stops when every input event is visible on every path.

use rand::Rng;

use crate::engine::{
    Control, Duration, EngineError, EventKind, Model, RngStreams, Scheduler, StreamRng, Time, TimeError,
};

use super::analytic::Terms;

/// Errors of a multi-frame-rate run.
#[derive(Debug, thiserror::Error)]
pub enum MultiRateError {
    /// Kernel error (time overflow, event budget).
    #[error(transparent)]
    Engine(#[from] EngineError),
    /// A model value the simulator cannot use.
    #[error("{key}: {message}")]
    Invalid {
        /// Dotted key.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// The run ended before every input event was seen on every path.
    #[error("the run stopped at {at} before every input event was visible ({state})")]
    Unfinished {
        /// When.
        at: Time,
        /// What was still missing.
        state: String,
    },
}

impl From<TimeError> for MultiRateError {
    fn from(e: TimeError) -> Self {
        MultiRateError::Engine(EngineError::Time(e))
    }
}

/// The events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ev {
    /// A user input event happens.
    Input,
    /// SC starts a frame.
    ScFrameStart,
    /// SC finished rendering.
    ScRenderEnd,
    /// SC finished reading the frame buffer back.
    ScReadbackEnd,
    /// The link delivered a buffer to FC.
    TransferEnd,
    /// FC starts a frame.
    FcFrameStart,
    /// FC finished uploading SC's image.
    FcUploadEnd,
    /// FC finished its frame (visible).
    FcFrameEnd,
    /// The conventional client starts a frame.
    ConvFrameStart,
    /// The conventional client finished its frame (visible).
    ConvFrameEnd,
}

impl EventKind for Ev {
    const NAMES: &'static [&'static str] = &[
        "input",
        "sc_frame_start",
        "sc_render_end",
        "sc_readback_end",
        "transfer_end",
        "fc_frame_start",
        "fc_upload_end",
        "fc_frame_end",
        "conv_frame_start",
        "conv_frame_end",
    ];
    fn kind(&self) -> usize {
        *self as usize
    }
}

/// One SC frame and the fate of its buffer.
#[derive(Debug, Clone, Copy)]
pub struct ScFrame {
    /// Frame start (input read).
    pub start: Time,
    /// Newest tracker sample delivered at `start`.
    pub sample: Option<u64>,
    /// Render end.
    pub render_end: Time,
    /// Read-back end (buffer ready to send).
    pub readback_end: Time,
    /// When the link started sending it.
    pub send_start: Option<Time>,
    /// When it arrived at FC.
    pub arrived: Option<Time>,
    /// Replaced in the mailbox by a newer buffer before it was sent.
    pub replaced: bool,
}

/// One FC frame.
#[derive(Debug, Clone, Copy)]
pub struct FcFrame {
    /// Frame start (input read, SC buffer taken).
    pub start: Time,
    /// Newest tracker sample delivered at `start`.
    pub sample: Option<u64>,
    /// The SC frame whose image it uploaded.
    pub buffer: Option<usize>,
    /// Upload end.
    pub upload_end: Time,
    /// Frame end (visible, before the display's own latency).
    pub end: Time,
}

/// One conventional-client frame.
#[derive(Debug, Clone, Copy)]
pub struct ConvFrame {
    /// Frame start.
    pub start: Time,
    /// Newest tracker sample delivered at `start`.
    pub sample: Option<u64>,
    /// Frame end.
    pub end: Time,
}

/// All state of a run.
#[derive(Debug)]
pub struct MultiRate {
    /// Per-frame terms.
    pub terms: Terms,
    events_left: u64,
    conventional: bool,
    warmup: Duration,
    mean_interval: f64,
    arrivals: StreamRng,
    phases: [Duration; 3],
    /// Input event times.
    pub inputs: Vec<Time>,
    /// SC frames.
    pub sc: Vec<ScFrame>,
    /// FC frames.
    pub fc: Vec<FcFrame>,
    /// Conventional frames.
    pub conv: Vec<ConvFrame>,
    in_flight: Option<usize>,
    mailbox: Option<usize>,
    latest_arrived: Option<usize>,
    /// Buffers replaced in the mailbox before being sent.
    pub replaced: u64,
    /// FC frames that have ended (the last one may still be running).
    pub fc_done: usize,
    /// Conventional frames that have ended.
    pub conv_done: usize,
    /// The run goes on at least until FC has finished a frame after this.
    pub min_end: Time,
    /// Most bytes the frame and input records may take (`run.max_memory`);
    /// the run fails with an error naming that key beyond it.
    pub max_memory: u64,
}

impl MultiRate {
    /// A model ready to start.
    pub fn new(
        terms: Terms,
        events: u64,
        warmup: Duration,
        mean_interval: Duration,
        conventional: bool,
        seed: u64,
    ) -> Self {
        let rng = RngStreams::new(seed);
        let phase = |name: &str, frame: Duration| {
            let mut r = rng.stream(name);
            Duration::from_ps_f64(frame.0 as f64 * r.random::<f64>())
        };
        let phases = [
            phase("phase.slow_client", terms.sc_interval()),
            phase("phase.fast_client", terms.fc_interval()),
            phase("phase.conventional", terms.conventional_frame),
        ];
        MultiRate {
            terms,
            events_left: events,
            conventional,
            warmup,
            mean_interval: mean_interval.0 as f64,
            arrivals: rng.stream("input.arrivals"),
            phases,
            inputs: Vec::with_capacity(events.min(1 << 16) as usize),
            sc: Vec::new(),
            fc: Vec::new(),
            conv: Vec::new(),
            in_flight: None,
            mailbox: None,
            latest_arrived: None,
            replaced: 0,
            fc_done: 0,
            conv_done: 0,
            min_end: Time::ZERO,
            max_memory: u64::MAX,
        }
    }

    /// Bytes the input and frame records take now.
    pub fn record_bytes(&self) -> u64 {
        use std::mem::size_of;
        (self.inputs.len() * size_of::<Time>()
            + self.sc.len() * size_of::<ScFrame>()
            + self.fc.len() * size_of::<FcFrame>()
            + self.conv.len() * size_of::<ConvFrame>()) as u64
    }

    /// Fails once the records outgrow `run.max_memory`.
    fn check_growth(&self, now: Time) -> Result<(), MultiRateError> {
        let used = self.record_bytes();
        if used > self.max_memory {
            return Err(MultiRateError::Invalid {
                key: "run.max_memory".into(),
                message: crate::limits::over_memory_message(
                    used,
                    &format!(
                        "records of {} inputs, {} SC, {} FC and {} conventional frames after {now} of simulated time",
                        self.inputs.len(),
                        self.sc.len(),
                        self.fc.len(),
                        self.conv.len()
                    ),
                    self.max_memory,
                ),
            });
        }
        Ok(())
    }

    /// Schedules the first event of every process.
    pub fn start(&mut self, sched: &mut Scheduler<Ev>) -> Result<(), MultiRateError> {
        sched.at(
            Time::ZERO.add(self.phases[0], "slow client start phase")?,
            Ev::ScFrameStart,
        );
        sched.at(
            Time::ZERO.add(self.phases[1], "fast client start phase")?,
            Ev::FcFrameStart,
        );
        if self.conventional {
            sched.at(
                Time::ZERO.add(self.phases[2], "conventional client start phase")?,
                Ev::ConvFrameStart,
            );
        }
        if self.events_left > 0 {
            let first = Time::ZERO
                .add(self.warmup, "run.warmup")?
                .add(self.gap(), "first input event")?;
            sched.at(first, Ev::Input);
        }
        Ok(())
    }

    /// When a client whose last frame ended at `now` may start the next one:
    /// at once without a rate cap, else at the next tick of its rate (ticks
    /// at `phase + k * period`).
    fn next_start(now: Time, phase: Duration, period: Option<Duration>) -> Time {
        match period {
            Some(p) if p.0 > 0 && now.0 > phase.0 => {
                let k = (now.0 - phase.0).div_ceil(p.0);
                Time(phase.0.saturating_add(k.saturating_mul(p.0)))
            }
            _ => now,
        }
    }

    fn gap(&mut self) -> Duration {
        Duration::from_ps_f64(-self.mean_interval * (1.0 - self.arrivals.random::<f64>()).ln())
    }

    /// The newest tracker sample delivered to the clients at `now`.
    pub fn delivered_sample(&self, now: Time) -> Option<u64> {
        let l = self.terms.sensor_latency.0;
        let p = self.terms.tracker_period.0.max(1);
        now.0.checked_sub(l).map(|x| x / p)
    }

    /// The tracker sample that captures an input at `t` (the first at or after it).
    pub fn capturing_sample(&self, t: Time) -> u64 {
        t.0.div_ceil(self.terms.tracker_period.0.max(1))
    }

    /// Time tracker sample `k` is taken.
    pub fn sample_time(&self, k: u64) -> Time {
        Time(k.saturating_mul(self.terms.tracker_period.0))
    }

    /// Whether every input is visible on every path.
    pub fn done(&self) -> bool {
        if self.events_left > 0 {
            return false;
        }
        let Some(last) = self.inputs.last() else {
            return true;
        };
        let j = Some(self.capturing_sample(*last));
        let fc = self.fc_done.checked_sub(1).map(|i| &self.fc[i]);
        if fc.is_none_or(|f| f.end < self.min_end) {
            return false;
        }
        let fast = fc.is_some_and(|f| f.sample >= j);
        let slow = fc.and_then(|f| f.buffer).is_some_and(|b| self.sc[b].sample >= j);
        let conv = !self.conventional || self.conv_done.checked_sub(1).is_some_and(|i| self.conv[i].sample >= j);
        fast && slow && conv
    }

    /// What is still missing (for errors).
    pub fn describe(&self) -> String {
        format!(
            "{} inputs issued, {} left; {} SC, {} FC, {} conventional frames",
            self.inputs.len(),
            self.events_left,
            self.sc.len(),
            self.fc.len(),
            self.conv.len()
        )
    }

    fn send(&mut self, now: Time, idx: usize, sched: &mut Scheduler<Ev>) -> Result<(), MultiRateError> {
        self.in_flight = Some(idx);
        self.sc[idx].send_start = Some(now);
        sched.after(self.terms.transfer, Ev::TransferEnd, "SC -> FC transfer")?;
        Ok(())
    }
}

impl Model for MultiRate {
    type Event = Ev;
    type Error = MultiRateError;

    fn handle(&mut self, now: Time, ev: Ev, sched: &mut Scheduler<Ev>) -> Result<Control, MultiRateError> {
        let t = self.terms;
        if matches!(ev, Ev::Input | Ev::ScFrameStart | Ev::FcFrameStart | Ev::ConvFrameStart) {
            self.check_growth(now)?;
        }
        match ev {
            Ev::Input => {
                self.inputs.push(now);
                self.events_left -= 1;
                if self.events_left > 0 {
                    let g = self.gap();
                    sched.after(g, Ev::Input, "next input event")?;
                }
            }
            Ev::ScFrameStart => {
                self.sc.push(ScFrame {
                    start: now,
                    sample: self.delivered_sample(now),
                    render_end: now,
                    readback_end: now,
                    send_start: None,
                    arrived: None,
                    replaced: false,
                });
                sched.after(t.sc_render, Ev::ScRenderEnd, "SC render")?;
            }
            Ev::ScRenderEnd => {
                if let Some(f) = self.sc.last_mut() {
                    f.render_end = now;
                }
                sched.after(t.sc_readback, Ev::ScReadbackEnd, "SC read-back")?;
            }
            Ev::ScReadbackEnd => {
                let idx = self.sc.len() - 1;
                self.sc[idx].readback_end = now;
                if self.in_flight.is_some() {
                    if let Some(old) = self.mailbox.replace(idx) {
                        self.sc[old].replaced = true;
                        self.replaced += 1;
                    }
                } else {
                    self.send(now, idx, sched)?;
                }
                sched.at(Self::next_start(now, self.phases[0], t.sc_period), Ev::ScFrameStart);
            }
            Ev::TransferEnd => {
                if let Some(idx) = self.in_flight.take() {
                    self.sc[idx].arrived = Some(now);
                    self.latest_arrived = Some(idx);
                }
                if let Some(next) = self.mailbox.take() {
                    self.send(now, next, sched)?;
                }
            }
            Ev::FcFrameStart => {
                self.fc.push(FcFrame {
                    start: now,
                    sample: self.delivered_sample(now),
                    buffer: self.latest_arrived,
                    upload_end: now,
                    end: now,
                });
                sched.after(t.fc_upload, Ev::FcUploadEnd, "FC upload")?;
            }
            Ev::FcUploadEnd => {
                if let Some(f) = self.fc.last_mut() {
                    f.upload_end = now;
                }
                sched.after(t.fc_render, Ev::FcFrameEnd, "FC render")?;
            }
            Ev::FcFrameEnd => {
                if let Some(f) = self.fc.last_mut() {
                    f.end = now;
                }
                self.fc_done = self.fc.len();
                if self.done() {
                    return Ok(Control::Stop);
                }
                sched.at(Self::next_start(now, self.phases[1], t.fc_period), Ev::FcFrameStart);
            }
            Ev::ConvFrameStart => {
                self.conv.push(ConvFrame {
                    start: now,
                    sample: self.delivered_sample(now),
                    end: now,
                });
                sched.after(t.conventional_frame, Ev::ConvFrameEnd, "conventional frame")?;
            }
            Ev::ConvFrameEnd => {
                if let Some(f) = self.conv.last_mut() {
                    f.end = now;
                }
                self.conv_done = self.conv.len();
                if self.done() {
                    return Ok(Control::Stop);
                }
                sched.at(now, Ev::ConvFrameStart);
            }
        }
        Ok(Control::Continue)
    }
}
