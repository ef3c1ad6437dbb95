//! The present system as a kernel [`Model`]: a renderer, a swap chain and a
//! display (paper 004 §4.2). The renderer holds one image while it draws a
//! frame, presents it and acquires the next image (waiting when none is
//! free); each vertical blank shows the next queued frame and frees the
//! image that was on screen; `immediate` shows a frame when it is
//! presented and has no vertical blanks.

use crate::components::distribution::Dist;
use crate::components::swap_chain::{Flip, PresentMode, SwapChain};
use crate::engine::{Control, Duration, EventKind, Model, RngStreams, Scheduler, StreamRng, Time};
use crate::output::trace::TraceWriter;
use crate::systems::SystemError;
use crate::systems::checked::Checked;

use super::config::PresentConfig;

/// Events of the present system.
#[derive(Debug, Clone, Copy)]
pub enum Ev {
    /// The renderer finished its frame.
    RenderDone,
    /// Vertical blank.
    Vblank,
}

impl EventKind for Ev {
    const NAMES: &'static [&'static str] = &["render_done", "vblank"];
    fn kind(&self) -> usize {
        match self {
            Ev::RenderDone => 0,
            Ev::Vblank => 1,
        }
    }
}

/// One frame's life.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameTimes {
    /// The renderer started it (it held an image).
    pub start: Time,
    /// It was presented (rendering done).
    pub present: Time,
    /// It reached the screen; `None` when dropped (mailbox) or never shown.
    pub shown: Option<Time>,
}

/// Trace lanes: the renderer's frames and the frames on screen.
const PID: u32 = 1;
const RENDERER: u32 = 1;
const SCREEN: u32 = 2;

/// The renderer, swap chain and display.
pub struct Present {
    chain: SwapChain,
    render: Dist<Duration>,
    rng: StreamRng,
    refresh: Duration,
    frames_total: u64,
    /// The frame being rendered.
    rendering: Option<u64>,
    /// The renderer waits for a free image since this time.
    waiting_since: Option<Time>,
    /// Time the renderer spent waiting for an image.
    waited: Duration,
    frames: Vec<FrameTimes>,
    /// Frames shown or dropped.
    resolved: u64,
    vblanks: u64,
    /// Vertical blanks, after the first frame was shown, that brought no
    /// new frame (the screen showed the same frame again).
    repeated: u64,
    /// The frame on screen and since when.
    on_screen: Option<(u64, Time)>,
    trace: Option<TraceWriter>,
}

/// What a finished model hands back.
#[derive(Debug)]
pub struct Finished {
    /// Every frame, in order.
    pub frames: Vec<FrameTimes>,
    /// Vertical blanks.
    pub vblanks: u64,
    /// Vertical blanks that showed the previous frame again.
    pub repeated: u64,
    /// Time the renderer waited for a free image.
    pub waited: Duration,
    /// The trace writer, if one was given.
    pub trace: Option<TraceWriter>,
}

impl Present {
    /// The checked model's renderer: `run.frames` frames with render times
    /// from `render.time` (drawn from the `render` stream of `run.seed`),
    /// presenting into `display.buffers` images shown in the display's
    /// present mode at every refresh.
    pub fn new(cfg: &Checked<PresentConfig>, trace: Option<TraceWriter>) -> Present {
        let frames = cfg.run.frames;
        let render = cfg.render.time.clone();
        let rng = RngStreams::new(cfg.run.seed).stream("render");
        let buffers = cfg.display.buffers;
        let mode = cfg.display.effective_mode();
        let refresh = cfg.display.refresh.period;
        let mut trace = trace;
        if let Some(t) = trace.as_mut() {
            t.process(PID, "present");
            t.thread(PID, RENDERER, "renderer");
            t.thread(PID, SCREEN, "screen");
        }
        Present {
            chain: SwapChain::new(buffers, mode),
            render,
            rng,
            refresh,
            frames_total: frames,
            rendering: None,
            waiting_since: None,
            waited: Duration::ZERO,
            frames: Vec::with_capacity(frames.min(1 << 20) as usize),
            resolved: 0,
            vblanks: 0,
            repeated: 0,
            on_screen: None,
            trace,
        }
    }

    /// Schedules the first frame and the first vertical blank.
    pub fn start(&mut self, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if self.frames_total == 0 {
            return Ok(());
        }
        if self.chain.mode() != PresentMode::Immediate {
            s.after(self.refresh, Ev::Vblank, "the first vertical blank")?;
        }
        self.next_frame(Time::ZERO, s)
    }

    /// Whether every frame was shown or dropped.
    pub fn done(&self) -> bool {
        self.resolved == self.frames_total
    }

    /// What the run left: "N of M frames shown or dropped".
    pub fn describe(&self) -> String {
        format!(
            "{} of {} frames shown or dropped, {} started",
            self.resolved,
            self.frames_total,
            self.frames.len()
        )
    }

    /// The frames and counts, once the run is over (the frame still on
    /// screen is written to the trace up to `end`).
    pub fn finish(mut self, end: Time) -> Finished {
        if let (Some((f, from)), Some(t)) = (self.on_screen, self.trace.as_mut()) {
            t.span(
                PID,
                SCREEN,
                &format!("frame {f}"),
                from,
                end.max(from),
                Some(("frame", f)),
            );
        }
        Finished {
            frames: self.frames,
            vblanks: self.vblanks,
            repeated: self.repeated,
            waited: self.waited,
            trace: self.trace,
        }
    }

    /// Starts the next frame if one is left and an image is free, else
    /// waits for one.
    fn next_frame(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        let id = self.frames.len() as u64;
        if self.rendering.is_some() || id == self.frames_total {
            return Ok(());
        }
        if !self.chain.acquire() {
            self.waiting_since.get_or_insert(now);
            return Ok(());
        }
        if let Some(since) = self.waiting_since.take() {
            self.waited = self.waited.saturating_add(now.since(since));
        }
        let time = Duration::from_ps_f64(self.render.sample(&mut self.rng));
        self.frames.push(FrameTimes {
            start: now,
            present: now,
            shown: None,
        });
        self.rendering = Some(id);
        s.after(time, Ev::RenderDone, "a frame's render time")?;
        Ok(())
    }

    /// What a present or a vertical blank did to the frames.
    fn apply(&mut self, now: Time, flip: Flip) {
        if let Some(f) = flip.dropped {
            self.resolved += 1;
            if let Some(t) = self.trace.as_mut() {
                let fr = self.frames[f as usize];
                t.instant(PID, SCREEN, &format!("frame {f} dropped"), fr.present.max(now));
            }
        }
        if let Some(f) = flip.shown {
            self.frames[f as usize].shown = Some(now);
            self.resolved += 1;
            // The frame on screen before leaves it now.
            if let (Some((prev, from)), Some(t)) = (self.on_screen.replace((f, now)), self.trace.as_mut()) {
                t.span(PID, SCREEN, &format!("frame {prev}"), from, now, Some(("frame", prev)));
            }
        }
    }
}

impl Model for Present {
    type Event = Ev;
    type Error = SystemError;

    fn handle(&mut self, now: Time, ev: Ev, s: &mut Scheduler<Ev>) -> Result<Control, SystemError> {
        match ev {
            Ev::RenderDone => {
                let f = self
                    .rendering
                    .take()
                    .expect("a frame renders when its RenderDone is due");
                self.frames[f as usize].present = now;
                if let Some(t) = self.trace.as_mut() {
                    let start = self.frames[f as usize].start;
                    t.span(PID, RENDERER, &format!("frame {f}"), start, now, Some(("frame", f)));
                }
                let flip = self.chain.present(f);
                self.apply(now, flip);
                self.next_frame(now, s)?;
            }
            Ev::Vblank => {
                self.vblanks += 1;
                // `fifo_latest_ready`: the frames a newer one overtook leave unshown.
                while let Some(stale) = self.chain.release_stale() {
                    let drop = Flip {
                        shown: None,
                        dropped: Some(stale),
                        freed: true,
                    };
                    self.apply(now, drop);
                }
                let flip = self.chain.vblank();
                if flip.shown.is_none() && self.on_screen.is_some() {
                    self.repeated += 1;
                }
                self.apply(now, flip);
                if flip.freed {
                    self.next_frame(now, s)?;
                }
                if !self.done() {
                    s.after(self.refresh, Ev::Vblank, "the next vertical blank")?;
                }
            }
        }
        Ok(if self.done() { Control::Stop } else { Control::Continue })
    }
}
