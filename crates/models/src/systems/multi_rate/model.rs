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

use crate::engine::{Control, Duration, EventKind, Model, RngStreams, Scheduler, StreamRng, Time};
use crate::systems::checked::Checked;
use crate::systems::error::SystemError;

use crate::output::trace::TraceWriter;

use super::analytic::Terms;
use super::config::MultiRateConfig;
use super::latency::Follower;
use super::migration::Artifacts;

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
}

/// One FC frame.
#[derive(Debug, Clone, Copy)]
pub struct FcFrame {
    /// Frame start (input read, SC buffer taken).
    pub start: Time,
    /// Newest tracker sample delivered at `start`.
    pub sample: Option<u64>,
    /// The SC frame whose image it uploaded: its number and a copy of its
    /// record (final: the image had arrived when FC took it).
    pub buffer: Option<(usize, ScFrame)>,
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

/// All state of a run. Memory is bounded by the input events, not by the
/// simulated span: a frame is folded into the events it shows when it ends
/// ([`Follower`]) and its trace spans are written then, so only the frames
/// in flight are held (SC's current frame, the buffers on the link and in
/// the mailbox, the newest arrived image, FC's and the conventional
/// client's current frames).
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
    /// Every input event's fate, filled in as frames end.
    pub follower: Follower,
    sc_current: Option<(usize, ScFrame)>,
    in_flight: Option<(usize, ScFrame)>,
    mailbox: Option<(usize, ScFrame)>,
    latest_arrived: Option<(usize, ScFrame)>,
    fc_current: Option<FcFrame>,
    fc_last: Option<FcFrame>,
    conv_current: Option<ConvFrame>,
    /// SC frames started.
    pub sc_frames: usize,
    /// SC buffers that reached FC.
    pub sent: u64,
    /// Buffers replaced in the mailbox before being sent.
    pub replaced: u64,
    /// FC frames that have ended.
    pub fc_done: usize,
    /// Conventional frames that have ended.
    pub conv_done: usize,
    /// The run goes on at least until FC has finished a frame after this.
    pub min_end: Time,
    /// Migration artifacts, counted as FC frames end (when the model has a
    /// migration script).
    pub migration: Option<Artifacts>,
    /// The trace, written as the run goes.
    pub trace: Option<TraceWriter>,
    /// Most bytes the input records may take (`run.max_memory`); the run
    /// fails with an error naming that key beyond it.
    pub max_memory: u64,
}

impl MultiRate {
    /// A model ready to start, from a checked config (its terms, input
    /// events, warm-up, arrival rate, conventional path and seed).
    pub fn new(cfg: &Checked<MultiRateConfig>) -> Self {
        let terms = Terms::of(cfg);
        let (events, warmup) = (cfg.run.events, cfg.run.warmup);
        let (mean_interval, conventional, seed) = (cfg.input.mean_interval, cfg.conventional.enabled, cfg.run.seed);
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
            follower: Follower::new(terms, events),
            sc_current: None,
            in_flight: None,
            mailbox: None,
            latest_arrived: None,
            fc_current: None,
            fc_last: None,
            conv_current: None,
            sc_frames: 0,
            sent: 0,
            replaced: 0,
            fc_done: 0,
            conv_done: 0,
            min_end: Time::ZERO,
            migration: None,
            trace: None,
            max_memory: u64::MAX,
        }
    }

    /// Fails once the input records outgrow `run.max_memory`.
    fn check_growth(&self, now: Time) -> Result<(), SystemError> {
        let records = &self.follower.records;
        crate::systems::tracked_input::check_records(self.follower.record_bytes(), self.max_memory, || {
            format!(
                "records of {} input events after {now} of simulated time",
                records.len()
            )
        })
    }

    /// Schedules the first event of every process and writes the trace's
    /// tracks.
    pub fn start(&mut self, sched: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if let Some(t) = &mut self.trace {
            t.process(1, "multi-frame-rate");
            for (tid, name) in [
                (1, "master (input events)"),
                (2, "slow client"),
                (3, "transfer link"),
                (4, "fast client"),
                (5, "conventional client"),
            ] {
                t.track(1, tid, name);
            }
        }
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

    /// Whether every input is visible on every path.
    pub fn done(&self) -> bool {
        if self.events_left > 0 {
            return false;
        }
        if self.follower.records.is_empty() {
            return true;
        }
        if self.fc_last.is_none_or(|f| f.end < self.min_end) {
            return false;
        }
        self.follower.all_shown(self.conventional)
    }

    /// What is still missing (for errors).
    pub fn describe(&self) -> String {
        format!(
            "{} inputs issued, {} left; {} SC, {} FC, {} conventional frames",
            self.follower.records.len(),
            self.events_left,
            self.sc_frames,
            self.fc_done + usize::from(self.fc_current.is_some()),
            self.conv_done + usize::from(self.conv_current.is_some())
        )
    }

    fn send(&mut self, now: Time, mut buffer: (usize, ScFrame), sched: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        buffer.1.send_start = Some(now);
        self.in_flight = Some(buffer);
        sched.after(self.terms.transfer, Ev::TransferEnd, "SC -> FC transfer")?;
        Ok(())
    }
}

impl Model for MultiRate {
    type Event = Ev;
    type Error = SystemError;

    fn handle(&mut self, now: Time, ev: Ev, sched: &mut Scheduler<Ev>) -> Result<Control, SystemError> {
        let t = self.terms;
        match ev {
            Ev::Input => {
                self.check_growth(now)?;
                if let Some(tr) = &mut self.trace {
                    tr.instant(1, 1, &format!("input {}", self.follower.records.len()), now);
                }
                self.follower.input(now);
                self.events_left -= 1;
                if self.events_left > 0 {
                    let g = self.gap();
                    sched.after(g, Ev::Input, "next input event")?;
                }
            }
            Ev::ScFrameStart => {
                self.sc_current = Some((
                    self.sc_frames,
                    ScFrame {
                        start: now,
                        sample: self.delivered_sample(now),
                        render_end: now,
                        readback_end: now,
                        send_start: None,
                        arrived: None,
                    },
                ));
                self.sc_frames += 1;
                sched.after(t.sc_render, Ev::ScRenderEnd, "SC render")?;
            }
            Ev::ScRenderEnd => {
                if let Some((_, f)) = &mut self.sc_current {
                    f.render_end = now;
                }
                sched.after(t.sc_readback, Ev::ScReadbackEnd, "SC read-back")?;
            }
            Ev::ScReadbackEnd => {
                if let Some((i, mut f)) = self.sc_current.take() {
                    f.readback_end = now;
                    if let Some(tr) = &mut self.trace {
                        tr.span(1, 2, &format!("SC {i} render"), f.start, f.render_end, None);
                        tr.span(1, 2, &format!("SC {i} read-back"), f.render_end, f.readback_end, None);
                    }
                    if self.in_flight.is_some() {
                        if self.mailbox.replace((i, f)).is_some() {
                            self.replaced += 1;
                        }
                    } else {
                        self.send(now, (i, f), sched)?;
                    }
                }
                sched.at(Self::next_start(now, self.phases[0], t.sc_period), Ev::ScFrameStart);
            }
            Ev::TransferEnd => {
                if let Some((i, mut f)) = self.in_flight.take() {
                    f.arrived = Some(now);
                    if let (Some(tr), Some(s)) = (&mut self.trace, f.send_start) {
                        tr.span(1, 3, &format!("SC {i} transfer"), s, now, None);
                    }
                    self.sent += 1;
                    self.latest_arrived = Some((i, f));
                }
                if let Some(next) = self.mailbox.take() {
                    self.send(now, next, sched)?;
                }
            }
            Ev::FcFrameStart => {
                self.fc_current = Some(FcFrame {
                    start: now,
                    sample: self.delivered_sample(now),
                    buffer: self.latest_arrived,
                    upload_end: now,
                    end: now,
                });
                sched.after(t.fc_upload, Ev::FcUploadEnd, "FC upload")?;
            }
            Ev::FcUploadEnd => {
                if let Some(f) = &mut self.fc_current {
                    f.upload_end = now;
                }
                sched.after(t.fc_render, Ev::FcFrameEnd, "FC render")?;
            }
            Ev::FcFrameEnd => {
                if let Some(mut f) = self.fc_current.take() {
                    f.end = now;
                    let i = self.fc_done;
                    if let Some(tr) = &mut self.trace {
                        tr.span(1, 4, &format!("FC {i} upload"), f.start, f.upload_end, None);
                        tr.span(1, 4, &format!("FC {i} render"), f.upload_end, f.end, None);
                    }
                    self.follower.fc_frame_end(i, &f);
                    if let Some(m) = &mut self.migration {
                        m.fc_frame_end(&f, t.tracker_period.0);
                    }
                    self.fc_last = Some(f);
                    self.fc_done += 1;
                }
                if self.done() {
                    return Ok(Control::Stop);
                }
                sched.at(Self::next_start(now, self.phases[1], t.fc_period), Ev::FcFrameStart);
            }
            Ev::ConvFrameStart => {
                self.conv_current = Some(ConvFrame {
                    start: now,
                    sample: self.delivered_sample(now),
                    end: now,
                });
                sched.after(t.conventional_frame, Ev::ConvFrameEnd, "conventional frame")?;
            }
            Ev::ConvFrameEnd => {
                if let Some(mut f) = self.conv_current.take() {
                    f.end = now;
                    let i = self.conv_done;
                    if let Some(tr) = &mut self.trace {
                        tr.span(1, 5, &format!("frame {i}"), f.start, f.end, None);
                    }
                    self.follower.conv_frame_end(i, &f);
                    self.conv_done += 1;
                }
                if self.done() {
                    return Ok(Control::Stop);
                }
                sched.at(now, Ev::ConvFrameStart);
            }
        }
        Ok(Control::Continue)
    }
}
