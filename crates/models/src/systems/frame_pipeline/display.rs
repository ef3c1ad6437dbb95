//! The display (paper 004 §4.2): frames the front end presents into the
//! swap chain are shown at a vertical blank (`fifo`, `mailbox`) or at once
//! (`immediate` / vsync off); repeated refreshes and dropped frames are
//! counted. A composed display (`display.composition = "composed"`) is
//! served by the desktop compositor ([`crate::components::compositor`]):
//! the swap chain's frames are taken at its wake, a set time after each
//! vertical blank, instead of at the blank, and are seen its delay later. A variable-refresh
//! display (`display.vrr`) has no fixed vertical blank: a flipped frame
//! starts a scan-out at once when the panel is idle, or when the scan-out
//! under way ends; a panel that got no new frame within its slowest period
//! repeats the old one ([`crate::components::swap_chain::VrrConfig`]). A
//! frame flipped at once (`immediate`) tears the picture where the scan-out
//! is ([`crate::components::tearing`]): its record keeps the tear line.
//! With frame generation (`[frame_generation]`,
//! [`crate::components::frame_generation`]) the game renders into the
//! proxy's images, and a present thread presents a generated frame before
//! each rendered one after the first, paced half a rendered interval
//! apart, each into an image of this swap chain ([`Display::present_rendered`]).
//!
//! [`Display`] owns the display's counters (vertical blanks, repeated
//! refreshes, the mark where refresh metrics start after warm-up, frames
//! shown or dropped), the swap chain and its transitions; the records are
//! an argument. What it did at an instant that the critical path observes
//! (the rendered frames presented, the frame shown) it keeps as
//! [`DisplayNews`], which the accounting takes after the instant's steps:
//! the display never writes the critical path.

use crate::components::frame_generation::{FrameGenerationConfig, Next, PresentThread, generated_before};
use crate::components::swap_chain::{Flip, PresentMode, SwapChain, VrrWindow};
use crate::components::tearing::ScanOut;
use crate::engine::{Duration, Scheduler, Time};
use crate::systems::error::SystemError;

use super::events::Ev;
use super::plan::DisplaySpec;
use super::records::{FrameRecord, GeneratedRecord};

/// The display.
#[derive(Debug)]
pub struct Display {
    /// The swap chain the front end presents into (its present mode
    /// resolved once, by the plan).
    chain: SwapChain,
    refresh: Duration,
    /// When the swap chain's frames are taken after each vertical blank
    /// (the compositor's wake when composed).
    latch_phase: Duration,
    /// From a frame's being taken to its being on screen (the compositor's
    /// delay when composed).
    compositor_delay: Duration,
    frames_total: u64,
    warmup_frames: u64,
    vblanks: u64,
    repeated_refreshes: u64,
    /// (vertical blanks, repeated refreshes, time) when the first frame after
    /// warm-up was shown; refresh metrics count from there.
    refresh_mark: Option<(u64, u64, Time)>,
    last_display: Option<Time>,
    /// Frames shown or dropped.
    resolved: u64,
    /// The variable-refresh window and the panel's scan-outs, when `vrr`.
    vrr: Option<Vrr>,
    /// The scan-out a flip tears, when flips do not wait for a vertical blank.
    scan: Option<ScanOut>,
    /// Frame generation's state, when it is on.
    generation: Option<Generation>,
    /// What it did at the current instant, for the critical path.
    news: DisplayNews,
}

/// What the display did at the current instant that the critical path
/// observes ([`super::critical_path::CriticalPath::presented`] and
/// `shown`).
#[derive(Debug, Default)]
pub(super) struct DisplayNews {
    /// The rendered frames presented, in order.
    pub(super) presented: Vec<u64>,
    /// The last frame shown.
    pub(super) shown: Option<u64>,
}

/// Frame generation at the display: its present thread (the proxy's
/// images, the frames waiting, the pacing), the generated frames and the
/// rendered frames' hold-backs.
#[derive(Debug)]
struct Generation {
    /// Its keys (`[frame_generation]`: the GPU time of an interpolation).
    config: FrameGenerationConfig,
    /// The proxy swap chain and its present thread.
    thread: PresentThread,
    /// The tag of the one [`Ev::HeldPresent`] event that is not stale, and
    /// when it is due.
    tag: u32,
    due: Option<Time>,
    /// The frames generated and presented, in order.
    frames: Vec<GeneratedRecord>,
    /// Per rendered frame presented: (frame, GPU end to its present).
    hold_backs: Vec<(u64, Duration)>,
}

/// What frame generation did in a run (for the summary).
#[derive(Debug, Clone, Copy)]
pub struct GenerationView<'a> {
    /// The generated frames presented.
    pub frames: &'a [GeneratedRecord],
    /// (frame, hold-back) per rendered frame presented.
    pub hold_backs: &'a [(u64, Duration)],
}

/// A variable-refresh panel's state: its window, the start of its last
/// scan-out, and the tag of the one display event that is not stale.
#[derive(Debug)]
struct Vrr {
    window: VrrWindow,
    scan_start: Option<Time>,
    tag: u32,
}

impl Display {
    /// A display refreshing every `refresh` that shows a flipped frame
    /// `compositor_delay` later, for a run of `frames_total` frames whose
    /// first `warmup_frames` are warm-up.
    /// `vrr`: a variable-refresh window (then `refresh` is its shortest
    /// period); `scan`: the scan-out an `immediate` flip tears;
    /// `generation`: whether frames are generated between rendered ones.
    pub(super) fn new(spec: &DisplaySpec) -> Self {
        Display {
            chain: SwapChain::new(spec.buffers, spec.mode),
            refresh: spec.refresh,
            latch_phase: spec.latch_phase,
            compositor_delay: spec.compositor_delay,
            frames_total: spec.frames_total,
            warmup_frames: spec.warmup_frames,
            vblanks: 0,
            repeated_refreshes: 0,
            refresh_mark: None,
            last_display: None,
            resolved: 0,
            vrr: spec.vrr.map(|window| Vrr {
                window,
                scan_start: None,
                tag: 0,
            }),
            scan: spec.scan,
            generation: spec.generation.clone().map(|config| Generation {
                thread: PresentThread::new(spec.buffers, &config),
                config,
                tag: 0,
                due: None,
                frames: Vec::new(),
                hold_backs: Vec::new(),
            }),
            news: DisplayNews::default(),
        }
    }

    /// The front end takes a free swap-chain image for a frame it clears
    /// (false: none is free, it waits): with frame generation, an image of
    /// its proxy.
    #[inline(always)]
    pub(super) fn acquire(&mut self) -> bool {
        match &mut self.generation {
            None => self.chain.acquire(),
            Some(g) => g.thread.acquire(),
        }
    }

    /// Whether a swap-chain image is free for [`Display::acquire`].
    #[inline]
    pub(super) fn can_acquire(&self) -> bool {
        match &self.generation {
            None => self.chain.can_acquire(),
            Some(g) => g.thread.can_acquire(),
        }
    }

    /// Frames presented and waiting to be shown.
    pub(super) fn queued(&self) -> usize {
        self.chain.queued()
    }

    /// The present mode the display follows (`immediate` without vsync).
    #[inline]
    pub(super) fn mode(&self) -> PresentMode {
        self.chain.mode()
    }

    /// What frame generation did (`None` when it is off).
    pub(super) fn generation(&self) -> Option<GenerationView<'_>> {
        self.generation.as_ref().map(|g| GenerationView {
            frames: &g.frames,
            hold_backs: &g.hold_backs,
        })
    }

    /// Whether it presented or showed a frame at the current instant.
    #[inline(always)]
    pub(super) fn has_news(&self) -> bool {
        self.news.shown.is_some() || !self.news.presented.is_empty()
    }

    /// What it did at the current instant, for the critical path to take.
    pub(super) fn news_mut(&mut self) -> &mut DisplayNews {
        &mut self.news
    }

    /// The generated frames, taken out at the end of a run.
    pub(super) fn take_generated(&mut self) -> Vec<GeneratedRecord> {
        self.generation
            .as_mut()
            .map_or_else(Vec::new, |g| std::mem::take(&mut g.frames))
    }

    /// The rendered frames' hold-backs (GPU end to present), taken out at
    /// the end of a run.
    pub(super) fn take_hold_backs(&mut self) -> Vec<(u64, Duration)> {
        self.generation
            .as_mut()
            .map_or_else(Vec::new, |g| std::mem::take(&mut g.hold_backs))
    }

    /// The GPU time frame generation adds before rendered frame `frame`'s
    /// present: its interpolation (none for frame 0, or without frame
    /// generation). The front end runs it as part of the frame's swap.
    #[inline]
    pub(super) fn generation_cost(&self, frame: u64) -> Duration {
        self.generation
            .as_ref()
            .map_or(Duration::ZERO, |g| g.config.cost_before_present(frame))
    }

    /// The GPU finished rendered frame `frame` at `now`. Without frame
    /// generation it is presented now. With it, the frame (and the one
    /// generated before it, for frames after the first) joins the present
    /// thread's queue, which presents what is due ([`Display::pump`]).
    pub(super) fn present_rendered(
        &mut self,
        now: Time,
        frame: u64,
        records: &mut [FrameRecord],
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        match &mut self.generation {
            None => self.present(now, frame, records, s),
            Some(g) => {
                g.thread.rendered(frame, now);
                self.pump(now, records, s)
            }
        }
    }

    /// Frame generation's present thread presents every frame due by
    /// `now` for which this swap chain has a free image, in order; the
    /// next one due later gets its [`Ev::HeldPresent`] event. A frame
    /// waiting for an image goes out at the refresh that frees one.
    #[inline(never)]
    fn pump(&mut self, now: Time, records: &mut [FrameRecord], s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        loop {
            let Some(g) = self.generation.as_mut() else {
                return Ok(());
            };
            match g.thread.next(now) {
                None => return Ok(()),
                Some(Next::At(due)) => {
                    if g.due != Some(due) {
                        g.due = Some(due);
                        g.tag = g.tag.wrapping_add(1);
                        s.at(due, Ev::HeldPresent { tag: g.tag });
                    }
                    return Ok(());
                }
                Some(Next::Now(_)) => {
                    if !self.chain.acquire() {
                        return Ok(());
                    }
                    let (id, ready) = g.thread.presented(now).expect("a frame is due");
                    match generated_before(id) {
                        Some(before) => g.frames.push(GeneratedRecord {
                            before,
                            present: now,
                            displayed: None,
                            dropped: false,
                            tear_line: None,
                        }),
                        None => g.hold_backs.push((id, now.since(ready))),
                    }
                    self.present(now, id, records, s)?;
                }
            }
        }
    }

    /// The [`Ev::HeldPresent`] event tagged `tag`: the present thread's
    /// next present is due (a stale tag does nothing).
    pub(super) fn held_present(
        &mut self,
        now: Time,
        tag: u32,
        records: &mut [FrameRecord],
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        let Some(g) = self.generation.as_mut().filter(|g| g.tag == tag) else {
            return Ok(());
        };
        g.due = None;
        self.pump(now, records, s)
    }

    /// Whether the display refreshes at fixed vertical blanks from time
    /// zero (vsync without variable refresh).
    pub(super) fn fixed_vblanks(&self) -> bool {
        self.mode() != PresentMode::Immediate && self.vrr.is_none()
    }

    /// When the first fixed refresh takes the swap chain's frames: at time
    /// zero, a vertical blank, or the compositor's first wake after it.
    pub(super) fn first_latch(&self) -> Time {
        Time(self.latch_phase.0)
    }

    /// The refresh period.
    pub(super) fn refresh(&self) -> Duration {
        self.refresh
    }

    /// Vertical blanks so far.
    pub(super) fn vblanks(&self) -> u64 {
        self.vblanks
    }

    /// Refreshes that showed no new frame so far.
    pub(super) fn repeated_refreshes(&self) -> u64 {
        self.repeated_refreshes
    }

    /// (vertical blanks, repeated refreshes, time) when the first frame
    /// after warm-up was shown.
    pub(super) fn refresh_mark(&self) -> Option<(u64, u64, Time)> {
        self.refresh_mark
    }

    /// Frames shown or dropped so far.
    #[inline(always)]
    pub(super) fn resolved(&self) -> u64 {
        self.resolved
    }

    /// Whether every frame of the run was shown or dropped.
    #[inline(always)]
    pub(super) fn done(&self) -> bool {
        self.resolved >= self.frames_total
    }

    /// `frame` (a rendered frame, or a generated frame's id) goes to the
    /// swap chain now. A variable-refresh panel that is idle starts its
    /// scan-out now.
    fn present(
        &mut self,
        now: Time,
        frame: u64,
        records: &mut [FrameRecord],
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        if generated_before(frame).is_none() {
            self.news.presented.push(frame);
        }
        let flip = self.chain.present(frame);
        self.apply_flip(now, flip, self.chain.mode(), records);
        if let Some(v) = &self.vrr {
            let idle = v
                .scan_start
                .is_none_or(|t| now.0 >= t.0.saturating_add(v.window.shortest.0));
            if idle {
                self.scan_out(now, records, s)?;
            }
        }
        Ok(())
    }

    fn apply_flip(&mut self, now: Time, flip: Flip, mode: PresentMode, records: &mut [FrameRecord]) {
        if let Some(d) = flip.dropped {
            match self.generated_mut(d) {
                Some(g) => g.dropped = true,
                None => {
                    records[d as usize].dropped = true;
                    self.resolved += 1;
                }
            }
        }
        if let Some(f) = flip.shown
            && generated_before(f).is_some()
        {
            let shown = Time(now.0.saturating_add(self.compositor_delay.0));
            let tear = self.scan.as_ref().and_then(|scan| scan.tear_line(now));
            if let Some(g) = self.generated_mut(f) {
                (g.displayed, g.tear_line) = (Some(shown), tear);
            }
            self.count_repeats(now, mode);
            self.last_display = Some(now);
            return;
        }
        if let Some(f) = flip.shown {
            self.count_repeats(now, mode);
            records[f as usize].displayed = Some(Time(now.0.saturating_add(self.compositor_delay.0)));
            if let Some(scan) = &self.scan {
                records[f as usize].tear_line = scan.tear_line(now);
            }
            self.news.shown = Some(f);
            self.last_display = Some(now);
            self.resolved += 1;
            let warm = self.warmup_frames;
            if warm > 0 && f >= warm && self.refresh_mark.is_none() {
                // Refresh counts after warm-up start at the first later frame shown.
                self.refresh_mark = Some((self.vblanks, self.repeated_refreshes, now));
            }
        }
    }

    /// The generated frame with swap-chain id `id` (`None` for a rendered
    /// frame's id).
    fn generated_mut(&mut self, id: u64) -> Option<&mut GeneratedRecord> {
        let before = generated_before(id)?;
        let g = self.generation.as_mut()?;
        let i = g.frames.binary_search_by_key(&before, |x| x.before).ok()?;
        Some(&mut g.frames[i])
    }

    /// An `immediate` display change at `now`: the refresh boundaries it
    /// crossed without a new frame are repeated refreshes.
    fn count_repeats(&mut self, now: Time, mode: PresentMode) {
        if mode == PresentMode::Immediate
            && let Some(prev) = self.last_display
        {
            let p = self.refresh.0;
            let crossed = now.0 / p - prev.0 / p;
            self.repeated_refreshes += crossed.saturating_sub(1);
        }
    }

    /// A vertical blank (fixed refresh; when composed, the compositor's wake
    /// that follows each blank), or the display event of a
    /// variable-refresh panel tagged `tag`: the end of a scan-out or the
    /// deadline of the slowest refresh. A stale tag (the panel started a
    /// scan-out at a present since) does nothing.
    pub(super) fn vblank(
        &mut self,
        now: Time,
        tag: u32,
        records: &mut [FrameRecord],
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        let queued = self.chain.queued();
        let Some(v) = &mut self.vrr else {
            return self.fixed_vblank(now, records, s);
        };
        if tag != v.tag {
            return Ok(());
        }
        let start = v.scan_start.expect("a variable-refresh event follows a scan-out");
        let deadline = Time(start.0.saturating_add(v.window.longest.0));
        if queued > 0 || now >= deadline {
            // A frame waits for this scan-out's end, or the old image must
            // be refreshed (scanned out again).
            self.scan_out(now, records, s)?;
            return self.after_refresh(now, records, s);
        }
        // The scan-out ended with nothing to show: the panel waits, up to
        // the slowest refresh's deadline.
        v.tag = v.tag.wrapping_add(1);
        s.at(deadline, Ev::Vblank { tag: v.tag });
        Ok(())
    }

    /// A fixed refresh's vertical blank; the next one is one refresh later.
    fn fixed_vblank(
        &mut self,
        now: Time,
        records: &mut [FrameRecord],
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        self.refresh_now(now, records);
        self.after_refresh(now, records, s)?;
        if !self.done() {
            s.after(
                self.refresh,
                Ev::Vblank { tag: 0 },
                "scheduling the next vertical blank",
            )?;
        }
        Ok(())
    }

    /// A variable-refresh panel starts a scan-out now (of the oldest queued
    /// frame, or again of the image on screen); its end is the next event.
    fn scan_out(&mut self, now: Time, records: &mut [FrameRecord], s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        self.refresh_now(now, records);
        let done = self.done();
        let v = self.vrr.as_mut().expect("a variable-refresh panel");
        v.scan_start = Some(now);
        v.tag = v.tag.wrapping_add(1);
        if !done {
            let tag = v.tag;
            s.after(
                v.window.shortest,
                Ev::Vblank { tag },
                "scheduling the end of a scan-out",
            )?;
        }
        Ok(())
    }

    /// A refresh at `now`: the swap chain flips its oldest queued frame, if
    /// any; one with nothing new repeats the image on screen.
    fn refresh_now(&mut self, now: Time, records: &mut [FrameRecord]) {
        self.vblanks += 1;
        // `fifo_latest_ready`: the frames a newer one overtook leave unshown.
        while let Some(stale) = self.chain.release_stale() {
            let drop = Flip {
                shown: None,
                dropped: Some(stale),
                freed: true,
            };
            self.apply_flip(now, drop, self.chain.mode(), records);
        }
        let flip = self.chain.vblank();
        if flip.shown.is_none() && self.last_display.is_some() {
            self.repeated_refreshes += 1;
        }
        self.apply_flip(now, flip, self.chain.mode(), records);
    }

    /// After a refresh: frame generation's present thread may have waited
    /// for the image it freed.
    fn after_refresh(
        &mut self,
        now: Time,
        records: &mut [FrameRecord],
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        if self.generation.is_some() {
            self.pump(now, records, s)?;
        }
        Ok(())
    }
}
