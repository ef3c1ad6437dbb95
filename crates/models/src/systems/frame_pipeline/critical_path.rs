//! Bottleneck attribution along the critical path (`metrics.bottleneck`).
//!
//! Paper 004 §4.1: "at any given time, one of these stages will be the
//! bottleneck", found by reducing each subsystem in turn and seeing whether
//! the frame rate improves (`isolate.rs`). A share of time per unit agrees
//! with that test only if a unit is charged for time that reducing its work
//! would save: a unit that is busy while the frame waits on another unit is
//! not the bottleneck (paper 000 §4.5.1: the stages overlap).
//!
//! So the time is charged along the run's critical path: the chain of work
//! that the end of the run waited for, traced back to time zero. Each unit
//! is, over every interval, either *working* (charged to itself, or to
//! `system` while a system task holds it with work to do) or *waiting for*
//! another unit:
//!
//! | unit | works when | waits for |
//! |---|---|---|
//! | CPU | running its frame program | the front end (command FIFO full, too many frames in flight); the display once all frames are submitted |
//! | front end | processing a command | the CPU (FIFO empty), the display (no free swap image), geometry (a draw waiting to be taken; fragment when binned bins block it), fragment (a swap waiting for the pipeline to drain) |
//! | geometry | transforming a triangle | fragment (triangle FIFO full), the front end (no draw) |
//! | fragment | shading a triangle | geometry (no triangle) |
//! | display | between shown frames | - |
//!
//! At `draw` fidelity a running draw is one closed form: both stages count
//! as working for the stage with the larger total (fragment if F >= G).
//!
//! Each unit carries the blame vector of the critical path to its latest
//! instant (six numbers: the time charged to each of
//! [`BOTTLENECKS`](super::unit_states::BOTTLENECKS)). When a unit works, its
//! own path grows by the time it worked; when it waits, its path is the
//! path of the unit it waits for, up to the instant the wait ends (that unit
//! is what ended it).
//!
//! The display: a shown frame continues the path of its present (the front
//! end finishing the swap) plus the wait for the vertical blank. For a unit
//! waiting for the display (a swap image), that is the display's path only
//! if the frame came late, after the display could have shown a new frame
//! (a refresh after the previous one shown, with vsync); otherwise the
//! display's refresh held the frame back and the display's own path runs
//! on. So a light load under vsync is display-bound, while a GPU that needs
//! 17 ms per frame at 60 Hz shares the 33 ms it gets with the display.
//!
//! The run's shares are the path to the last shown frame through its
//! present (the front end's path when a limit stopped the run early), so
//! they add up to the elapsed time exactly, and a unit whose work always
//! overlapped another unit's critical work gets nothing: shortening its
//! work would not shorten the run. This is the forward form of walking back
//! from the end along what each unit waited for; it keeps six numbers per
//! unit instead of the timeline.
//!
//! A wait cycle can only last an instant (the pipeline would be deadlocked);
//! if one is met, the unit met twice is charged itself.

use std::collections::VecDeque;

use crate::engine::{Duration, Time};

/// What time is charged to, in the order of
/// [`BOTTLENECKS`](super::unit_states::BOTTLENECKS).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blame {
    /// The CPU thread.
    Cpu = 0,
    /// A system task.
    System = 1,
    /// The GPU front end.
    FrontEnd = 2,
    /// The geometry stage.
    Geometry = 3,
    /// The fragment stage.
    Fragment = 4,
    /// The display (waiting for a vertical blank).
    Display = 5,
}

/// The units whose progress the path follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// The CPU thread.
    Cpu = 0,
    /// The GPU front end.
    Front = 1,
    /// The geometry stage.
    Geometry = 2,
    /// The fragment stage.
    Fragment = 3,
    /// The display.
    Display = 4,
}

const UNITS: [Unit; 5] = [Unit::Cpu, Unit::Front, Unit::Geometry, Unit::Fragment, Unit::Display];

impl Unit {
    /// What a unit's own work is charged to (used to break a wait cycle).
    fn own(self) -> Blame {
        match self {
            Unit::Cpu => Blame::Cpu,
            Unit::Front => Blame::FrontEnd,
            Unit::Geometry => Blame::Geometry,
            Unit::Fragment => Blame::Fragment,
            Unit::Display => Blame::Display,
        }
    }
}

/// What a unit does over an interval: works, the time charged to a
/// [`Blame`], or waits for another [`Unit`]. One byte (a blame below 8, else
/// 8 + the unit waited for), so four modes compare as one word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mode(u8);

impl Mode {
    /// Works; the time is charged to `b`.
    pub const fn work(b: Blame) -> Mode {
        Mode(b as u8)
    }

    /// Waits for `u`.
    pub const fn wait(u: Unit) -> Mode {
        Mode(8 + u as u8)
    }
}

/// Time (picoseconds) charged to each [`Blame`].
pub type Shares = [u64; 6];

/// Modes of the CPU, front end, geometry and fragment (the display always works).
pub type Modes = [Mode; 4];

/// The critical-path state: each unit's path as of its last update, the
/// frames presented but not yet shown, and the display events of the
/// current instant.
///
/// Only units whose mode changes are updated: a working unit's path grows
/// with the time since, and a waiting unit's path is its target's, so both
/// can be carried forward later as well as now.
#[derive(Debug)]
pub struct CriticalPath {
    path: [Shares; 5],
    since: [Time; 5],
    /// The modes of the CPU, front end, geometry, fragment.
    modes: Modes,
    /// Presented frames not yet shown: (frame, path at the present, when).
    presented: VecDeque<(u64, Shares, Time)>,
    /// When the display last showed a frame.
    last_show: Option<Time>,
    /// The refresh period when frames are shown at vertical blanks (`fifo`,
    /// `mailbox`); `None` when shown at once.
    pacing: Option<Duration>,
    /// The path to the last shown frame through its present.
    via_present: Shares,
    /// Frames presented at the current instant.
    pending_presents: Vec<u64>,
    /// The frame shown at the current instant.
    pending_show: Option<u64>,
    /// Whether a frame was presented or shown at the current instant.
    pending: bool,
}

impl CriticalPath {
    /// Everything at time zero, the CPU working, the rest waiting upstream;
    /// `pacing`: the refresh period when frames are shown at vertical blanks.
    pub fn new(pacing: Option<Duration>) -> Self {
        CriticalPath {
            path: [[0; 6]; 5],
            since: [Time::ZERO; 5],
            modes: [
                Mode::work(Blame::Cpu),
                Mode::wait(Unit::Cpu),
                Mode::wait(Unit::Front),
                Mode::wait(Unit::Geometry),
            ],
            presented: VecDeque::new(),
            last_show: None,
            pacing,
            via_present: [0; 6],
            pending_presents: Vec::new(),
            pending_show: None,
            pending: false,
        }
    }

    /// The front end presented `frame` at the current instant.
    pub fn presented(&mut self, frame: u64) {
        self.pending_presents.push(frame);
        self.pending = true;
    }

    /// The display showed `frame` at the current instant.
    pub fn shown(&mut self, frame: u64) {
        self.pending_show = Some(frame);
        self.pending = true;
    }

    /// Closes the instant `now`: the front end's path is recorded with the
    /// frames it presented, the display's path follows a shown frame, and
    /// the path of every unit whose mode changes is carried to `now` under
    /// the old modes; then the new modes hold.
    #[inline(always)]
    pub fn update(&mut self, now: Time, modes: Modes) {
        if modes == self.modes && !self.pending {
            return;
        }
        self.update_changed(now, modes);
    }

    #[inline(never)]
    fn update_changed(&mut self, now: Time, modes: Modes) {
        if self.pending {
            self.display_events(now);
        }
        // Carrying a unit to `now` under its old mode does not change what
        // the others see of it at `now`, so this can go unit by unit.
        for (i, mode) in modes.iter().enumerate() {
            if *mode != self.modes[i] {
                self.materialize(i, now);
            }
        }
        self.modes = modes;
    }

    /// [`CriticalPath::update`] when only `unit` (one of the four of
    /// [`Modes`]) may have changed its mode and no frame was presented or
    /// shown at this instant: the same result without comparing the others.
    #[inline]
    pub fn set_mode(&mut self, unit: Unit, mode: Mode, now: Time) {
        debug_assert!(!self.pending);
        let i = unit as usize;
        if self.modes[i] != mode {
            self.materialize(i, now);
            self.modes[i] = mode;
        }
    }

    /// Records the front end's path with the frames presented now, and
    /// moves the display's path to the frame shown now.
    #[cold]
    fn display_events(&mut self, now: Time) {
        if !self.pending_presents.is_empty() {
            self.materialize(Unit::Front as usize, now);
            let at_present = self.path[Unit::Front as usize];
            for f in std::mem::take(&mut self.pending_presents) {
                self.presented.push_back((f, at_present, now));
            }
        }
        if let Some(f) = self.pending_show.take() {
            self.show(f, now);
        }
        self.pending = false;
    }

    /// The shares of the critical path to `end`: through the last shown
    /// frame's present when every frame was shown (`done`), else through the
    /// front end.
    pub fn totals_at(&self, end: Time, done: bool) -> Shares {
        if done && let Some(at) = self.last_show {
            let mut p = self.via_present;
            p[Blame::Display as usize] += end.since(at).0;
            return p;
        }
        let (w, b) = self.source(Unit::Front as usize);
        let mut p = self.path[w];
        p[b] += end.since(self.since[w]).0;
        p
    }

    /// The working unit at the end of `u`'s chain of waits, and what its
    /// work is charged to (as indices): `u`'s path now is that unit's path
    /// carried to now. A cycle is closed by the unit met twice, charged for
    /// itself.
    #[inline(always)]
    fn source(&self, mut u: usize) -> (usize, usize) {
        let mut visiting = 0u8;
        loop {
            if visiting & (1 << u) != 0 {
                return (u, UNITS[u].own() as usize);
            }
            visiting |= 1 << u;
            let code = self.modes.get(u).map_or(Blame::Display as u8, |m| m.0);
            if code < 8 {
                return (u, code as usize);
            }
            u = (code - 8) as usize;
        }
    }

    /// Carries `u`'s path to `now` under its current mode.
    #[inline(always)]
    fn materialize(&mut self, u: usize, now: Time) {
        let (w, b) = self.source(u);
        let add = now.since(self.since[w]).0;
        if w != u {
            self.path[u] = self.path[w];
        }
        self.path[u][b] += add;
        self.since[u] = now;
    }

    /// The display shows `frame` at `now`. Through the frame's present, the
    /// path is the present's plus the wait for this vertical blank. The
    /// display's own path (what a unit waiting for a swap image waits on)
    /// takes that route only if the frame came late: after the display
    /// could have shown a new frame (a refresh after the last one shown,
    /// when frames are shown at vertical blanks). Otherwise the display's
    /// pacing held the frame back and the display's path runs on.
    fn show(&mut self, frame: u64, now: Time) {
        let d = Unit::Display as usize;
        self.materialize(d, now);
        let present = self.presented.iter().find(|e| e.0 == frame).map(|e| (e.1, e.2));
        if let Some((mut p, at)) = present {
            p[Blame::Display as usize] += now.since(at).0;
            self.via_present = p;
            let late = match (self.pacing, self.last_show) {
                (Some(refresh), Some(last)) => at.0 > last.0.saturating_add(refresh.0),
                // Shown at once, or the first frame shown.
                _ => true,
            };
            if late {
                self.path[d] = p;
            }
        } else {
            self.via_present = self.path[d];
        }
        while self.presented.front().is_some_and(|e| e.0 <= frame) {
            self.presented.pop_front();
        }
        self.last_show = Some(now);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(ps: u64) -> Time {
        Time(ps)
    }

    #[test]
    fn a_unit_that_works_beside_the_critical_one_is_not_charged() {
        let mut c = CriticalPath::new(None);
        // 0-10: CPU works, the front end waits for it.
        // 10-14: the front end works, the CPU works on (the next frame).
        let cpu = Mode::work(Blame::Cpu);
        let front_waits = Mode::wait(Unit::Cpu);
        let rest = [Mode::wait(Unit::Front), Mode::wait(Unit::Geometry)];
        c.update(t(0), [cpu, front_waits, rest[0], rest[1]]);
        c.update(t(10), [cpu, Mode::work(Blame::FrontEnd), rest[0], rest[1]]);
        // 14-20: the front end is starved again until the CPU's next push.
        c.update(t(14), [cpu, front_waits, rest[0], rest[1]]);
        let s = c.totals_at(t(20), false);
        assert_eq!(s, [20, 0, 0, 0, 0, 0]);
        assert_eq!(s.iter().sum::<u64>(), 20);
    }

    #[test]
    fn a_shown_frame_continues_its_present_plus_the_vblank_wait() {
        let mut c = CriticalPath::new(None);
        let m = [
            Mode::wait(Unit::Front),
            Mode::work(Blame::FrontEnd),
            Mode::wait(Unit::Front),
            Mode::wait(Unit::Geometry),
        ];
        c.update(t(0), m);
        // The front end presents frame 0 at 4 and waits for an image.
        c.presented(0);
        let waits = [m[0], Mode::wait(Unit::Display), m[2], m[3]];
        c.update(t(4), waits);
        // The vertical blank at 16 shows it and frees an image.
        c.shown(0);
        c.update(t(16), m);
        assert_eq!(c.totals_at(t(16), true), [0, 0, 4, 0, 0, 12]);
        assert_eq!(c.totals_at(t(20), false), [0, 0, 8, 0, 0, 12]);
    }

    #[test]
    fn a_frame_held_back_by_the_refresh_follows_the_display() {
        // Vertical blanks every 10: frame 0 (presented at 2) is shown at 10,
        // frame 1 (presented at 3) at 20, held back by frame 0's refresh.
        let mut c = CriticalPath::new(Some(Duration(10)));
        let busy = [
            Mode::wait(Unit::Front),
            Mode::work(Blame::FrontEnd),
            Mode::wait(Unit::Front),
            Mode::wait(Unit::Geometry),
        ];
        let waits = [busy[0], Mode::wait(Unit::Display), busy[2], busy[3]];
        c.update(t(0), busy);
        c.presented(0);
        c.update(t(2), busy);
        c.presented(1);
        c.update(t(3), waits);
        c.shown(0);
        c.update(t(10), waits);
        c.shown(1);
        c.update(t(20), busy);
        // The front end waited for the display from 3 to 20: the display's
        // path, through frame 0 (late: the first) then its own refresh.
        assert_eq!(c.totals_at(t(20), false), [0, 0, 2, 0, 0, 18]);
        // The run's end goes through the last frame's present.
        assert_eq!(c.totals_at(t(20), true), [0, 0, 3, 0, 0, 17]);
    }

    #[test]
    fn a_wait_cycle_charges_the_unit_that_closes_it() {
        let mut c = CriticalPath::new(None);
        let cycle = [
            Mode::work(Blame::Cpu),
            Mode::wait(Unit::Geometry),
            Mode::wait(Unit::Front),
            Mode::wait(Unit::Geometry),
        ];
        c.update(t(0), cycle);
        let s = c.totals_at(t(5), false);
        assert_eq!(s.iter().sum::<u64>(), 5);
    }
}
