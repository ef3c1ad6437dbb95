//! Time accounting: after every event each unit's state is derived from the
//! model and its [`StateClock`] advanced, so CPU busy + wait and GPU busy +
//! idle each add up to the elapsed time exactly. The same transitions become
//! Perfetto spans when tracing.
//!
//! Bottleneck attribution follows the critical path
//! ([`super::critical_path`]): after every event each unit's mode (working,
//! or waiting for which unit) is derived here and the path carried forward,
//! so the bottleneck shares also add up to the elapsed time exactly and a
//! unit that works off the critical path is not blamed.

use crate::components::state_clock::StateClock;
use crate::engine::{Duration, Time};
use crate::output::trace::{TraceDetail, TraceWriter};

use super::cpu_thread::{CpuPhase, CpuThread};
use super::critical_path::{Blame, CriticalPath, Mode, Modes, Unit};
use super::fragment_stage::FragmentStage;
use super::front_end::{FrontEnd, FrontPhase};
use super::geometry_stage::GeometryStage;
use super::links::Links;
use super::pipeline_trace::{PipelineTrace, Track};
use super::records::FrameRecord;

use super::unit_states::FRONT_WAIT_GEOMETRY;

/// Clocks and per-frame attribution.
#[derive(Debug)]
pub struct Accounting {
    /// CPU clock.
    pub cpu: StateClock<9>,
    /// Front-end clock.
    pub front: StateClock<6>,
    /// Geometry clock.
    pub geom: StateClock<3>,
    /// Fragment clock.
    pub frag: StateClock<2>,
    /// GPU busy (index 0) / idle (1).
    pub gpu: StateClock<2>,
    /// Bottleneck attribution along the critical path.
    pub path: CriticalPath,
    cpu_frame: u64,
    gpu_frame: Option<u64>,
    /// The trace, when one with the units' states is written (`draw` or
    /// `triangle` detail): every event goes through the traced path.
    pub trace: Option<PipelineTrace>,
    /// A `frame`-detail trace: written from the records after the run
    /// alone, so the events take the untraced path.
    frame_trace: Option<PipelineTrace>,
    /// Traced: the geometry stage's draw as of the last accounted instant
    /// (the draw of the spans that close at the next one).
    trace_draw: Option<u32>,
}

/// The [`Units`] view of the pipeline `$p` (a [`super::model::FramePipeline`]),
/// built from its fields so that its accounting can be borrowed mutably
/// beside it.
macro_rules! units_of {
    ($p:ident) => {
        Units {
            cpu: &$p.cpu,
            front: &$p.front,
            geom: &$p.geom,
            frag: &$p.frag,
            links: &$p.env.links,
        }
    };
}
pub(super) use units_of;

impl Accounting {
    /// The trace, whichever detail it has, for its end ([`PipelineTrace::end`]).
    pub fn take_trace(&mut self) -> Option<PipelineTrace> {
        self.trace.take().or_else(|| self.frame_trace.take())
    }

    /// The CPU's frame as of the last accounted instant.
    #[inline]
    pub fn cpu_frame(&self) -> u64 {
        self.cpu_frame
    }

    /// Fresh clocks (everything idle at time zero); `pacing`: the refresh
    /// period when frames are shown at vertical blanks.
    pub fn new(trace: Option<TraceWriter>, pacing: Option<Duration>) -> Self {
        let trace = trace.map(PipelineTrace::new);
        let per_frame = trace.as_ref().is_some_and(|t| t.detail() == TraceDetail::Frame);
        let (trace, frame_trace) = if per_frame { (None, trace) } else { (trace, None) };
        Accounting {
            cpu: StateClock::new(4),
            front: StateClock::new(1),
            geom: StateClock::new(2),
            frag: StateClock::new(1),
            gpu: StateClock::new(1),
            path: CriticalPath::new(pacing),
            cpu_frame: 0,
            gpu_frame: None,
            trace,
            frame_trace,
            trace_draw: None,
        }
    }
}

/// Moves `clock` to `state` at `now`; when the state changes, the closing
/// interval (unless idle or empty) becomes a span on `track`.
fn set_traced<const N: usize>(
    clock: &mut StateClock<N>,
    now: Time,
    state: usize,
    track: Track,
    trace: &mut Option<PipelineTrace>,
    idle: usize,
    (frame, draw): (Option<u64>, Option<u32>),
) -> (usize, u64) {
    let old = clock.state();
    let since = clock.since();
    let spent = clock.set(now, state);
    if let Some(t) = trace
        && old != state
        && old != idle
        && spent.0 > 0
    {
        t.state(track, old, since, now, frame, draw);
    }
    (old, spent.0)
}

/// Adds `spent` picoseconds in CPU state `old` to frame `frame`'s busy or
/// waiting time.
#[inline]
fn attribute_cpu(records: &mut [FrameRecord], old: usize, spent: u64, frame: u64) {
    if let Some(r) = records.get_mut(frame as usize) {
        match old {
            0 | 1 => r.cpu_busy += spent,
            // Pacing before a frame (5) is between frames: the frame
            // starts when it ends.
            2 | 3 | 6 | 7 | 8 => r.cpu_wait += spent,
            _ => {}
        }
    }
}

/// The CPU state (index into [`CPU_STATES`](super::unit_states::CPU_STATES)) of a phase outside system tasks.
#[inline]
fn cpu_state_of(p: CpuPhase) -> usize {
    // A table, not a match: the phase changes from event to event, and a
    // jump table's indirect branch would often be mispredicted.
    const OF: [u8; 12] = {
        let mut of = [0u8; 12];
        of[CpuPhase::NextFrame as usize] = 0;
        of[CpuPhase::WaitFrames as usize] = 3;
        of[CpuPhase::Ready as usize] = 0;
        of[CpuPhase::Running as usize] = 0;
        of[CpuPhase::Push as usize] = 2;
        of[CpuPhase::Rendezvous as usize] = 2;
        of[CpuPhase::ZeroTimeWait as usize] = 0;
        of[CpuPhase::Finished as usize] = 4;
        of[CpuPhase::PaceStart as usize] = 5;
        of[CpuPhase::PacePresent as usize] = 6;
        of[CpuPhase::InPresent as usize] = 7;
        of[CpuPhase::PaceSubmit as usize] = 8;
        of
    };
    OF[p as usize] as usize
}

/// The front-end state (index into [`FRONT_STATES`](super::unit_states::FRONT_STATES)) of a phase outside
/// system tasks.
#[inline]
fn front_state_of(p: FrontPhase) -> usize {
    const OF: [u8; 6] = {
        let mut of = [0u8; 6];
        of[FrontPhase::Running as usize] = 0;
        of[FrontPhase::Idle as usize] = 1;
        of[FrontPhase::WaitImage as usize] = 2;
        of[FrontPhase::WaitDrain as usize] = 3;
        of[FrontPhase::Handoff as usize] = FRONT_WAIT_GEOMETRY as u8;
        // A replayed frame's GPU waits for the CPU's later submissions.
        of[FrontPhase::HoldFrame as usize] = 1;
        of
    };
    OF[p as usize] as usize
}

/// What the accounting reads of the units after an instant: each unit's
/// state, immutably (the clocks and the critical path are the accounting's
/// own; the per-frame records get the CPU's and the GPU's time).
#[derive(Clone, Copy)]
pub(super) struct Units<'a> {
    pub(super) cpu: &'a CpuThread,
    pub(super) front: &'a FrontEnd,
    pub(super) geom: &'a GeometryStage,
    pub(super) frag: &'a FragmentStage,
    pub(super) links: &'a Links,
}

impl Accounting {
    /// Derives every unit's state at `now` and advances the clocks. Inlined
    /// into the step after every event, so the view `u` is never built in
    /// memory; the traced path is a call of its own.
    #[inline(always)]
    pub(super) fn account(&mut self, now: Time, u: Units<'_>, records: &mut [FrameRecord]) {
        let cpu_state = cpu_state(u.cpu);
        let front_state = if u.front.in_system() {
            5
        } else {
            front_state_of(u.front.phase())
        };
        let geom_state = if u.geom.busy() {
            0
        } else if u.links.held_triangle.is_some() {
            1
        } else {
            2
        };
        let frag_state = if u.frag.busy() { 0 } else { 1 };
        let gpu_busy = front_state == 0 || geom_state == 0 || frag_state == 0;
        let modes = path_modes(u);
        self.path.update(now, modes);

        let gpu_state = if gpu_busy { 0 } else { 1 };

        let (cpu_frame, gpu_frame) = (u.cpu.frame(), u.front.frame());
        let a = self;
        if a.trace.is_none() {
            // Nothing changed since the last event (no state, no frame):
            // every step would add nothing.
            if cpu_state == a.cpu.state()
                && front_state == a.front.state()
                && geom_state == a.geom.state()
                && frag_state == a.frag.state()
                && gpu_state == a.gpu.state()
                && cpu_frame == a.cpu_frame
                && (gpu_frame.is_none() || gpu_frame == a.gpu_frame)
            {
                return;
            }
            a.account_untraced(
                now,
                [cpu_state, front_state, geom_state, frag_state, gpu_state],
                (cpu_frame, gpu_frame),
                records,
            );
            return;
        }
        // The FIFO levels are read here, so that the view is not built in
        // memory for the traced call.
        let levels = (u.links.commands.used(), u.links.triangles.len() as u64);
        let draw = u.geom.draw().map(|d| d.draw);
        a.account_traced(
            now,
            [cpu_state, front_state, geom_state, frag_state, gpu_state],
            (cpu_frame, gpu_frame),
            levels,
            draw,
            records,
        );
    }

    /// [`Accounting::account`] with a trace: every state change is a span.
    #[inline(never)]
    fn account_traced(
        &mut self,
        now: Time,
        states: [usize; 5],
        frames: (u64, Option<u64>),
        (commands, triangles): (u64, u64),
        draw: Option<u32>,
        records: &mut [FrameRecord],
    ) {
        let [cpu_state, front_state, geom_state, frag_state, gpu_state] = states;
        let (cpu_frame, gpu_frame) = frames;
        let a = self;
        // CPU: attribute the closing interval to the frame it belonged to.
        let (old, spent) = set_traced(
            &mut a.cpu,
            now,
            cpu_state,
            Track::Cpu,
            &mut a.trace,
            4,
            (Some(a.cpu_frame), None),
        );
        attribute_cpu(records, old, spent, a.cpu_frame);
        if cpu_frame != a.cpu_frame {
            let st = a.cpu.state();
            let since = a.cpu.since();
            let spent = a.cpu.split(now).0;
            attribute_cpu(records, st, spent, a.cpu_frame);
            // The CPU moved to the next frame in the same state: the trace
            // closes the old frame's span here.
            if let Some(t) = &mut a.trace
                && st != 4
                && spent > 0
            {
                t.state(Track::Cpu, st, since, now, Some(a.cpu_frame), None);
            }
            a.cpu_frame = cpu_frame;
        }
        // The GPU's spans carry the frame the front end is on (as of the
        // span's start) and the geometry stage's draw.
        let (f, d) = (a.gpu_frame, a.trace_draw);
        set_traced(&mut a.front, now, front_state, Track::Front, &mut a.trace, 1, (f, None));
        set_traced(&mut a.geom, now, geom_state, Track::Geometry, &mut a.trace, 2, (f, d));
        set_traced(&mut a.frag, now, frag_state, Track::Fragment, &mut a.trace, 1, (f, d));
        if draw.is_some() {
            a.trace_draw = draw;
        }
        a.gpu_per_frame(now, gpu_state, gpu_frame, records);
        if let Some(t) = &mut a.trace {
            t.fifo_levels(now, commands, triangles);
        }
    }

    /// GPU busy per frame (the frame the front end is on, `gpu_frame`).
    #[inline(always)]
    fn gpu_per_frame(&mut self, now: Time, gpu_state: usize, gpu_frame: Option<u64>, records: &mut [FrameRecord]) {
        let old = self.gpu.state();
        let spent = self.gpu.set(now, gpu_state).0;
        let frame_changed = gpu_frame != self.gpu_frame && gpu_frame.is_some();
        let spent = if frame_changed && old == gpu_state {
            spent + self.gpu.split(now).0
        } else {
            spent
        };
        if old == 0
            && let Some(r) = self.gpu_frame.and_then(|f| records.get_mut(f as usize))
        {
            r.gpu_busy += spent;
        }
        if gpu_frame.is_some() {
            self.gpu_frame = gpu_frame;
        }
    }

    /// [`Accounting::account`] without a trace (every long run): the
    /// same clock moves and per-frame attribution, with no trace checks
    /// between them. `states`: CPU, front end, geometry, fragment, GPU;
    /// `frames`: the CPU's and the front end's.
    #[inline]
    fn account_untraced(
        &mut self,
        now: Time,
        states: [usize; 5],
        (cpu_frame, gpu_frame): (u64, Option<u64>),
        records: &mut [FrameRecord],
    ) {
        let [cpu_state, front_state, geom_state, frag_state, gpu_state] = states;
        // CPU: attribute the closing interval to the frame it belonged to.
        let old = self.cpu.state();
        let spent = self.cpu.set(now, cpu_state).0;
        if spent > 0 {
            attribute_cpu(records, old, spent, self.cpu_frame);
        }
        if cpu_frame != self.cpu_frame {
            let st = self.cpu.state();
            let spent = self.cpu.split(now).0;
            attribute_cpu(records, st, spent, self.cpu_frame);
            self.cpu_frame = cpu_frame;
        }
        self.front.set(now, front_state);
        self.geom.set(now, geom_state);
        self.frag.set(now, frag_state);
        self.gpu_per_frame(now, gpu_state, gpu_frame, records);
    }

    /// [`Accounting::account`] after a draw ended, the next began and
    /// `settle` ran (`draw_done_alone`, [`super::quiet`]), when neither the
    /// CPU's frame nor the GPU's changed: the geometry and fragment stages
    /// and the GPU are busy as they were (with the draw that ended, now with
    /// the one that began), so of `account`'s clock moves only the CPU's and
    /// the front end's can do anything, and of the critical path only the
    /// CPU's and the front end's modes and the two stages' (the new draw's
    /// limiting stage) can change. Their old modes make carrying them to
    /// `now` one at a time, in this order, give what carrying them all under
    /// the old modes gives: the front end waited for geometry (it held a
    /// draw), and the stages worked, charged to themselves.
    ///
    /// `cpu_moved`: whether the CPU may have taken a step at this instant;
    /// when it did not, its state and mode are what the last accounted
    /// instant left, and its part is skipped.
    #[inline(always)]
    pub(super) fn account_draw_handoff(
        &mut self,
        now: Time,
        cpu_moved: bool,
        u: Units<'_>,
        records: &mut [FrameRecord],
    ) {
        debug_assert!(self.trace.is_none() && !u.front.in_system());
        debug_assert_eq!(self.geom.state(), 0);
        debug_assert_eq!(self.frag.state(), 0);
        debug_assert_eq!(self.gpu.state(), 0);
        debug_assert_eq!(self.cpu_frame, u.cpu.frame());
        debug_assert!(u.geom.fragment_limited().is_some() && u.geom.busy() && u.frag.busy());
        // The CPU first: its old mode is carried under everyone's old mode.
        if cpu_moved {
            self.account_cpu_alone(now, u.cpu, records);
        }
        let front_state = front_state_of(u.front.phase());
        let stages = match u.geom.fragment_limited() {
            Some(true) => Mode::work(Blame::Fragment),
            _ => Mode::work(Blame::Geometry),
        };
        let front_mode = front_mode(u);
        self.front.set(now, front_state);
        self.path.set_mode(Unit::Front, front_mode, now);
        self.path.set_mode(Unit::Geometry, stages, now);
        self.path.set_mode(Unit::Fragment, stages, now);
    }

    /// [`Accounting::account`] when only the CPU moved at this instant and
    /// stayed on its frame (the CPU thread's short cuts,
    /// [`Alone`](super::cpu_thread::Alone)): its
    /// clock (the closing interval credited to the frame) and its
    /// critical-path mode are all that can change.
    pub(super) fn account_cpu_alone(&mut self, now: Time, cpu: &CpuThread, records: &mut [FrameRecord]) {
        debug_assert!(self.trace.is_none());
        debug_assert_eq!(self.cpu_frame, cpu.frame());
        let cpu_state = cpu_state(cpu);
        let mode = cpu_mode(cpu);
        let old = self.cpu.state();
        let spent = self.cpu.set(now, cpu_state).0;
        if spent > 0 {
            attribute_cpu(records, old, spent, self.cpu_frame);
        }
        self.path.set_mode(Unit::Cpu, mode, now);
    }

    /// [`Accounting::account`] at a quiet front-end completion without a
    /// trace ([`super::quiet`]): only the front end moved (busy -> waiting
    /// for geometry, for the critical path too): the geometry and fragment
    /// stages are busy with the draw throughout (so the GPU stays busy),
    /// the CPU and the frames are as the last event left them.
    #[inline(always)]
    pub(super) fn front_waits_for_geometry(&mut self, at: Time) {
        self.front.set(at, FRONT_WAIT_GEOMETRY);
        self.path.set_mode(Unit::Front, Mode::wait(Unit::Geometry), at);
    }

    /// `draw` fidelity without a trace, at a draw's end: both stage clocks
    /// have been "busy" since the draw began; of its `(geometry, fragment,
    /// total)` times, keep G (resp. F) of it busy and move the rest to idle.
    #[inline(always)]
    pub(super) fn credit_draw_split(&mut self, (g, f, t): (Duration, Duration, Duration)) {
        self.geom.transfer(0, 2, t.0 - g.0.min(t.0));
        self.frag.transfer(0, 1, t.0 - f.0.min(t.0));
    }
}

/// The front end's mode for the critical path.
#[inline(always)]
fn front_mode(u: Units<'_>) -> Mode {
    match u.front.phase() {
        FrontPhase::Running if u.front.in_system() => Mode::work(Blame::System),
        FrontPhase::Running => Mode::work(Blame::FrontEnd),
        FrontPhase::Idle | FrontPhase::HoldFrame => Mode::wait(Unit::Cpu),
        FrontPhase::WaitImage => Mode::wait(Unit::Display),
        FrontPhase::WaitDrain => Mode::wait(Unit::Fragment),
        // Binning: no draw in geometry, the bins still being shaded.
        FrontPhase::Handoff if !u.geom.has_draw() => Mode::wait(Unit::Fragment),
        FrontPhase::Handoff => Mode::wait(Unit::Geometry),
    }
}

/// The CPU's state (index into [`CPU_STATES`](super::unit_states::CPU_STATES)).
#[inline]
fn cpu_state(cpu: &CpuThread) -> usize {
    if cpu.in_system() { 1 } else { cpu_state_of(cpu.phase()) }
}

/// The CPU's mode for the critical path.
#[inline]
fn cpu_mode(cpu: &CpuThread) -> Mode {
    match cpu.phase() {
        CpuPhase::WaitFrames | CpuPhase::Push | CpuPhase::Rendezvous => Mode::wait(Unit::Front),
        CpuPhase::Finished => Mode::wait(Unit::Display),
        // The low-latency pacer waits for the GPU to drain; a limiter's
        // wait is the CPU's own.
        CpuPhase::PaceStart if cpu.paced_for_gpu() => Mode::wait(Unit::Front),
        _ if cpu.in_system() => Mode::work(Blame::System),
        _ => Mode::work(Blame::Cpu),
    }
}

/// Each unit's mode for the critical path (see [`super::critical_path`]).
#[inline(always)]
fn path_modes(u: Units<'_>) -> Modes {
    let cpu = cpu_mode(u.cpu);
    let front = front_mode(u);
    let (geometry, fragment) = match u.geom.fragment_limited() {
        // `draw` fidelity: the running draw is the limiting stage's.
        Some(true) => (Mode::work(Blame::Fragment), Mode::work(Blame::Fragment)),
        Some(false) => (Mode::work(Blame::Geometry), Mode::work(Blame::Geometry)),
        None => (
            if u.geom.busy() {
                Mode::work(Blame::Geometry)
            } else if u.links.held_triangle.is_some() {
                Mode::wait(Unit::Fragment)
            } else {
                Mode::wait(Unit::Front)
            },
            if u.frag.busy() {
                Mode::work(Blame::Fragment)
            } else {
                Mode::wait(Unit::Geometry)
            },
        ),
    };
    [cpu, front, geometry, fragment]
}
