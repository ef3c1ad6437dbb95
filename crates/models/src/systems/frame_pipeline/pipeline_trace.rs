//! The frame pipeline's trace (Perfetto, `--trace`): the units' states as
//! spans on one track each, the FIFOs' levels as counters, and after the
//! run one slice a frame on the CPU, GPU and display tracks (paper 000
//! Figure 4's picture of CPU and GPU working in parallel). The accounting
//! ([`super::accounting`]) writes into it at every state change it closes.

use crate::engine::{Duration, Time};
use crate::output::trace::{FlowStep, TraceDetail, TraceWriter};

use super::records::FrameRecord;
use super::unit_states::{CPU_STATES, FRAG_STATES, FRONT_STATES, GEOM_STATES};

/// Trace tracks (their track numbers in the trace are these plus one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Track {
    /// CPU thread.
    Cpu = 0,
    /// GPU front end.
    Front = 1,
    /// Geometry stage.
    Geometry = 2,
    /// Fragment stage.
    Fragment = 3,
}

/// The frame pipeline's trace, written while it runs: one track per unit
/// (CPU, GPU front end, geometry, fragment, display), a span per state a
/// unit was in (the CPU's split per frame, so frame n+1's preparation is
/// seen beside the GPU drawing frame n, as in paper 000 Figure 4), and
/// counters for the command and triangle FIFOs; after the run, one slice a
/// frame on the tracks "CPU frames" (its work, CPU start to present), "GPU
/// frames" (GPU start to end) and "Display" (shown to replaced), joined by
/// a flow per frame. Every slice carries its frame number (on the GPU's
/// unit tracks: the frame the front end is on).
///
/// How much is written follows the writer's [`TraceDetail`]: `frame` keeps
/// the per-frame tracks and flows only; `draw` adds the units' states and
/// the command FIFO, with the geometry and fragment stages' work merged
/// into one slice a draw (first to last work on it, its busy time in
/// `busy_ns`); `triangle` writes every state change and the triangle FIFO.
#[derive(Debug)]
pub struct PipelineTrace {
    writer: TraceWriter,
    detail: TraceDetail,
    command_fifo: Option<u64>,
    triangle_fifo: Option<u64>,
    /// `draw` detail: the geometry and fragment stages' open merged slice.
    merged: [Option<Merged>; 2],
}

/// A stage's work on one draw, merged (`draw` detail).
#[derive(Debug, Clone, Copy)]
struct Merged {
    frame: Option<u64>,
    draw: Option<u32>,
    start: Time,
    end: Time,
    busy: u64,
}

const PID: u32 = 1;
const DISPLAY_TRACK: u32 = 5;
const CPU_FRAMES_TRACK: u32 = 6;
const GPU_FRAMES_TRACK: u32 = 7;

impl PipelineTrace {
    /// Names the process and the tracks on `writer`.
    pub fn new(mut writer: TraceWriter) -> Self {
        writer.process(PID, "frame pipeline");
        let detail = writer.detail();
        let units: &[(u32, &str)] = if detail == TraceDetail::Frame {
            &[]
        } else {
            &[
                (1, "CPU thread"),
                (2, "GPU front end"),
                (3, "GPU geometry"),
                (4, "GPU fragment"),
            ]
        };
        for &(tid, name) in units.iter().chain(&[
            (DISPLAY_TRACK, "Display"),
            (CPU_FRAMES_TRACK, "CPU frames"),
            (GPU_FRAMES_TRACK, "GPU frames"),
        ]) {
            writer.track(PID, tid, name);
        }
        PipelineTrace {
            writer,
            detail,
            command_fifo: None,
            triangle_fifo: None,
            merged: [None, None],
        }
    }

    /// A unit's state from `start` to `end` (`frame`: the CPU's frame on
    /// the CPU track, the front end's on the GPU's; `draw`: the draw on the
    /// geometry stage).
    pub(super) fn state(
        &mut self,
        track: Track,
        state: usize,
        start: Time,
        end: Time,
        frame: Option<u64>,
        draw: Option<u32>,
    ) {
        let names: &[&str] = match track {
            Track::Cpu => &CPU_STATES,
            Track::Front => &FRONT_STATES,
            Track::Geometry => &GEOM_STATES,
            Track::Fragment => &FRAG_STATES,
        };
        let tid = track as u32 + 1;
        if self.detail == TraceDetail::Draw && matches!(track, Track::Geometry | Track::Fragment) {
            // Busy spans of one draw merge; waits between them are inside.
            if state != 0 {
                return;
            }
            let i = track as usize - Track::Geometry as usize;
            match &mut self.merged[i] {
                Some(m) if m.frame == frame && (draw.is_none() || m.draw == draw) => {
                    m.end = end;
                    m.busy += end.0 - start.0;
                }
                slot => {
                    let old = slot.replace(Merged {
                        frame,
                        draw,
                        start,
                        end,
                        busy: end.0 - start.0,
                    });
                    if let Some(m) = old {
                        self.merged_span(tid, m);
                    }
                }
            }
            return;
        }
        match frame {
            Some(f) if track == Track::Cpu && state == 0 => {
                let name = format!("frame {f}");
                self.writer.span(PID, tid, &name, start, end, Some(("frame", f)));
            }
            Some(f) => self.writer.span(PID, tid, names[state], start, end, Some(("frame", f))),
            None => self.writer.span(PID, tid, names[state], start, end, None),
        }
    }

    fn merged_span(&mut self, tid: u32, m: Merged) {
        let name = match m.draw {
            Some(d) => format!("draw {d}"),
            None => "draw".to_string(),
        };
        let mut args: Vec<(&str, u64)> = Vec::with_capacity(3);
        if let Some(f) = m.frame {
            args.push(("frame", f));
        }
        if let Some(d) = m.draw {
            args.push(("draw", u64::from(d)));
        }
        args.push(("busy_ns", m.busy / 1000));
        self.writer.span_args(PID, tid, &name, m.start, m.end, &args);
    }

    pub(super) fn fifo_levels(&mut self, now: Time, commands: u64, triangles: u64) {
        if self.command_fifo != Some(commands) {
            self.writer.counter(PID, "command FIFO", "used", now, commands);
            self.command_fifo = Some(commands);
        }
        if self.detail == TraceDetail::Triangle && self.triangle_fifo != Some(triangles) {
            self.writer.counter(PID, "triangle FIFO", "triangles", now, triangles);
            self.triangle_fifo = Some(triangles);
        }
    }

    /// How much the trace holds.
    pub(super) fn detail(&self) -> TraceDetail {
        self.detail
    }

    /// After the run: the merged draws still open; each frame's input as an
    /// instant on the CPU track (the CPU frames track at `frame` detail);
    /// each frame's slices on the CPU frames and GPU frames tracks; each
    /// displayed frame from its appearance to the next one (the last for
    /// one refresh) on the display track; and a flow a frame from its CPU
    /// slice through its GPU slice to its display slice. Returns the
    /// writer, to be finished by whoever opened it.
    pub fn end(mut self, records: &[FrameRecord], refresh: Duration) -> TraceWriter {
        for (i, track) in [Track::Geometry, Track::Fragment].into_iter().enumerate() {
            if let Some(m) = self.merged[i].take() {
                self.merged_span(track as u32 + 1, m);
            }
        }
        let shown: Vec<(u64, Time)> = records
            .iter()
            .filter_map(|r| r.displayed.map(|d| (r.index, d)))
            .collect();
        let mut shown_span = std::collections::HashMap::with_capacity(shown.len());
        for (i, (frame, t)) in shown.iter().enumerate() {
            let end = shown
                .get(i + 1)
                .map(|n| n.1)
                .unwrap_or_else(|| Time(t.0.saturating_add(refresh.0)));
            let name = format!("frame {frame}");
            self.writer
                .span(PID, DISPLAY_TRACK, &name, *t, end, Some(("frame", *frame)));
            shown_span.insert(*frame, (*t, end));
        }
        let input_track = if self.detail == TraceDetail::Frame {
            CPU_FRAMES_TRACK
        } else {
            1
        };
        for r in records {
            let name = format!("frame {} input", r.index);
            self.writer.instant(PID, input_track, &name, r.input);
        }
        // A flow point inside its slice (the middle; the start of an empty one).
        let mid = |a: Time, b: Time| Time(a.0 + (b.0.saturating_sub(a.0)) / 2);
        for r in records {
            let name = format!("frame {}", r.index);
            let cpu = (r.begun, r.present.max(r.begun));
            self.writer
                .span(PID, CPU_FRAMES_TRACK, &name, cpu.0, cpu.1, Some(("frame", r.index)));
            let gpu = match (r.gpu_start, r.gpu_end) {
                (Some(a), Some(b)) => Some((a, b.max(a))),
                _ => None,
            };
            if let Some((a, b)) = gpu {
                self.writer
                    .span(PID, GPU_FRAMES_TRACK, &name, a, b, Some(("frame", r.index)));
            }
            let shown = shown_span.get(&r.index).copied();
            let id = r.index + 1;
            let points: Vec<(u32, Time)> = [
                Some((CPU_FRAMES_TRACK, mid(cpu.0, cpu.1))),
                gpu.map(|(a, b)| (GPU_FRAMES_TRACK, mid(a, b))),
                shown.map(|(a, b)| (DISPLAY_TRACK, mid(a, b))),
            ]
            .into_iter()
            .flatten()
            .collect();
            if points.len() < 2 {
                continue;
            }
            for (k, &(tid, at)) in points.iter().enumerate() {
                let step = if k == 0 {
                    FlowStep::Start
                } else if k + 1 == points.len() {
                    FlowStep::End
                } else {
                    FlowStep::Step
                };
                self.writer.flow(PID, tid, &name, id, at, step);
            }
        }
        self.writer
    }
}
