//! The compositor's timing inferred from a composed swap chain's own frames
//! (issue 54, item 3): when it wakes after each vertical blank to take the
//! newest ready frame, and how many blanks later its composition is seen
//! ([`crate::components::compositor`]).
//!
//! A frame whose GPU work ended at `r` is taken at the first wake at or
//! after `r` (wake `φ` after each blank: the wake `W_k = V_k + φ`), and,
//! under the rule, is on screen at `V_{k+n}`. Two things in a capture show
//! `φ` and `n`:
//!
//! - each shown frame's screen time: `n` is the screen's blank less the
//!   wake's index, which must be the same for every frame;
//! - which frames were shown at all, where the compositor skipped frames:
//!   it shows the newest frame ready by a wake, so a frame is skipped when
//!   the next one was ready by the same wake.
//!
//! The fit tries every wake on a grid of [`WAKE_STEP_MS`] across the
//! refresh, and keeps the one whose timing explains the most frames, both
//! ways (the fates only where the swap chain skipped frames; a queue that
//! shows every frame says nothing of them). Among equals it keeps the
//! earliest wake: a compositor wakes shortly after the vertical blank.
//!
//! The compositor's own presents (`dwm.exe`), where the capture has them,
//! are reported beside it: the median time after a vertical blank at which
//! it presented, the end of its CPU work on each composition, which a wake
//! must precede.

use serde::Serialize;

use super::grid::Grid;
use crate::capture::presentmon::Present;
use crate::components::compositor::MAX_COMPOSITOR_REFRESHES;
use rendersim_report::stats::quantile::quantile;

/// The fewest shown frames with a GPU completion the fit needs.
const MIN_FRAMES: usize = 20;
/// The wakes tried are this far apart, ms.
pub const WAKE_STEP_MS: f64 = 0.05;
/// The share of frames skipped above which the fates count.
const SKIPPING: f64 = 0.01;

/// The compositor's timing inferred from a swap chain's frames.
#[derive(Debug, Clone, Serialize)]
pub struct CompositorInference {
    /// When it wakes after each vertical blank and takes the newest ready
    /// frame, ms.
    pub wake_ms: f64,
    /// Vertical blanks from the one before its wake to the frame on screen.
    pub refreshes: u32,
    /// The shown frames with a GPU completion the fit used.
    pub frames: usize,
    /// The share of them the timing explains exactly (to the refresh).
    pub explained: f64,
    /// The median time after a vertical blank at which the compositor's
    /// own swap chains presented, ms, where the capture has their rows.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compositor_present_ms: Option<f64>,
}

impl CompositorInference {
    /// One line a person reads.
    pub fn describe(&self) -> String {
        let own = self.compositor_present_ms.map_or(String::new(), |p| {
            format!("; its own presents {p:.2} ms after the blank")
        });
        format!(
            "the compositor takes frames {:.2} ms after each vertical blank and shows them {} blank{} after the one before \
             (explains {:.1}% of {} frames{own})",
            self.wake_ms,
            self.refreshes,
            if self.refreshes == 1 { "" } else { "s" },
            100.0 * self.explained,
            self.frames
        )
    }
}

/// The phase of `t` after the blank before it on `grid`, ms, in `[0, T)`.
fn phase(grid: &Grid, t: f64) -> f64 {
    (t - grid.phase_ms).rem_euclid(grid.period_ms)
}

/// A composed frame: when its GPU work ended, and when it was seen
/// (`None`: skipped).
struct Composed {
    ready: f64,
    screen: Option<f64>,
}

/// How well the wake `wake` after each blank explains `frames`: the most
/// frames one number of refreshes explains, that number, and the frames
/// whose fate the newest-ready rule gets right (when `fates`).
fn explain(frames: &[Composed], grid: &Grid, wake: f64, fates: bool) -> (usize, i64, usize) {
    let t = grid.period_ms;
    let wake_index = |r: f64| ((r - grid.phase_ms - wake) / t).ceil() as i64;
    // The wake that takes each shown frame: the first after it is ready;
    // in a queue that shows every frame, also after the one that took the
    // frame before (one frame per wake).
    let mut last: Option<i64> = None;
    // Frames per level 0..=MAX (the only levels a timing can have).
    let mut counts = [0usize; MAX_COMPOSITOR_REFRESHES as usize + 1];
    for f in frames {
        let Some(s) = f.screen else { continue };
        let mut k = wake_index(f.ready);
        if !fates && let Some(l) = last {
            k = k.max(l + 1);
        }
        last = Some(k);
        let blank = ((s - grid.phase_ms) / t).round() as i64;
        if let Some(c) = usize::try_from(blank - k).ok().and_then(|l| counts.get_mut(l)) {
            *c += 1;
        }
    }
    let (n, most) = counts.iter().enumerate().fold(
        (0i64, 0usize),
        |best, (l, &c)| if c > best.1 { (l as i64, c) } else { best },
    );
    let right_fates = if fates {
        frames
            .windows(2)
            .filter(|w| (wake_index(w[1].ready) > wake_index(w[0].ready)) == w[0].screen.is_some())
            .count()
    } else {
        0
    };
    (most, n, right_fates)
}

/// Infers the compositor's timing from the composed frames among `rows`
/// (one swap chain's presents, in order) on the refresh `grid`;
/// `compositor` are the compositor's own presents on that monitor, for the
/// report. `None` with fewer than 20 shown frames that say
/// when their GPU work ended.
pub fn infer_compositor(rows: &[&Present], grid: &Grid, compositor: &[&Present]) -> Option<CompositorInference> {
    let t = grid.period_ms;
    let frames: Vec<Composed> = rows
        .iter()
        .filter(|p| p.present_mode.starts_with("Composed") && p.fate_known)
        .filter_map(|p| {
            Some(Composed {
                ready: p.present + p.render_complete?.max(0.0),
                screen: p.screen_time(),
            })
        })
        .filter(|f| f.ready.is_finite() && f.screen.is_none_or(f64::is_finite))
        .collect();
    let shown = frames.iter().filter(|f| f.screen.is_some()).count();
    if shown < MIN_FRAMES || t.is_nan() || t <= 0.0 {
        return None;
    }
    let fates = (frames.len() - shown) as f64 > SKIPPING * frames.len() as f64;
    let steps = (t / WAKE_STEP_MS).floor() as usize;
    let mut best: Option<(usize, f64, i64, usize)> = None; // (score, wake, n, explained)
    for i in 0..steps.max(1) {
        let wake = i as f64 * WAKE_STEP_MS;
        let (explained, n, right) = explain(&frames, grid, wake, fates);
        let score = explained + right;
        if best.is_none_or(|b| score > b.0) {
            best = Some((score, wake, n, explained));
        }
    }
    let (_, wake_ms, n, explained) = best?;
    if !(1..=i64::from(MAX_COMPOSITOR_REFRESHES)).contains(&n) {
        return None;
    }
    let own: Vec<f64> = {
        let mut v: Vec<f64> = compositor.iter().map(|p| phase(grid, p.present)).collect();
        v.sort_by(f64::total_cmp);
        v
    };
    Some(CompositorInference {
        wake_ms,
        refreshes: n as u32,
        frames: shown,
        explained: explained as f64 / shown as f64,
        compositor_present_ms: (!own.is_empty()).then(|| quantile(&own, 0.5)),
    })
}
