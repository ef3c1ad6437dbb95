//! Frame completion, presentation and the display's vertical blanks
//! (paper 004 §4.2). Frames are shown at a vertical blank (`fifo`,
//! `mailbox`) or at once (`immediate` / vsync off); repeated refreshes and
//! dropped frames are counted.

use crate::components::swap_chain::{Flip, PresentMode};
use crate::engine::{Scheduler, Time};

use super::model::{Ev, FramePipeline};
use crate::systems::error::SystemError;

impl FramePipeline {
    /// The GPU finished frame `frame` (its swap): present it.
    pub(super) fn frame_completed(&mut self, now: Time, frame: u64) -> Result<(), SystemError> {
        self.gpu_completed += 1;
        self.records[frame as usize].gpu_end = Some(now);
        self.gpu_frame = None;
        self.acct.path.presented(frame);
        let flip = self.chain.present(frame);
        self.apply_flip(now, flip);
        Ok(())
    }

    fn apply_flip(&mut self, now: Time, flip: Flip) {
        if let Some(d) = flip.dropped {
            self.records[d as usize].dropped = true;
            self.resolved += 1;
        }
        if let Some(f) = flip.shown {
            if self.chain.mode() == PresentMode::Immediate
                && let Some(prev) = self.last_display
            {
                // Refresh boundaries crossed without a new frame.
                let p = self.refresh.0;
                let crossed = now.0 / p - prev.0 / p;
                self.repeated_refreshes += crossed.saturating_sub(1);
            }
            self.records[f as usize].displayed = Some(now);
            self.acct.path.shown(f);
            self.last_display = Some(now);
            self.resolved += 1;
            let warm = self.cfg.run.warmup_frames;
            if warm > 0 && f >= warm && self.refresh_mark.is_none() {
                // Refresh counts after warm-up start at the first later frame shown.
                self.refresh_mark = Some((self.vblanks, self.repeated_refreshes, now));
            }
        }
    }

    /// A vertical blank.
    pub(super) fn vblank(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        self.vblanks += 1;
        let flip = self.chain.vblank();
        if flip.shown.is_none() && self.last_display.is_some() {
            self.repeated_refreshes += 1;
        }
        self.apply_flip(now, flip);
        if !self.done() {
            s.after(self.refresh, Ev::Vblank, "scheduling the next vertical blank")?;
        }
        Ok(())
    }
}
