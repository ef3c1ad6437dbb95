//! The timeline picture of a run, in the manner of paper 000 Figure 4: one
//! lane per unit (CPU thread, command FIFO fill, GPU front end, geometry,
//! fragment, display), each unit's work coloured by the frame it belongs
//! to, so that a reader sees the CPU preparing frame n+1 while the GPU draws
//! frame n, with the vertical blanks marked (paper 004 §4.2).
//!
//! A replayed capture (a `system = "replay"` model file) is drawn as the
//! frame-pipeline run its replay makes (as captured, or under the file's
//! what-if): the capture's frames on the pipeline's lanes.
//!
//! The picture is built from the run's own trace (the frame pipeline's accounting),
//! kept as merged spans while the run makes it ([`crate::output::span_collector`]): the CPU's
//! and the display's spans carry their frame; GPU work is given the frame
//! whose GPU interval (its clear to its swap, [`crate::systems::frame_pipeline::records`]) contains
//! it. Spans of one unit less than [`MERGE_GAP_US`] apart are merged (a
//! frame's per-triangle work becomes a few bars a picture can show).

use crate::config::{ModelSource, deserialize};
use crate::engine::PS_PER_MS;
use crate::output::span_collector::{ReadSpan, SpanCollector};
use crate::output::trace::TraceWriter;
use crate::plot::{Bar, Fill, Lane, Level, Timeline};
use crate::systems::SimError;

use crate::systems::frame_pipeline::config::FramePipelineConfig;
use crate::systems::frame_pipeline::run::{PipelineRun, run_pipeline};

/// Spans of one unit closer than this (microseconds) are drawn as one bar.
pub const MERGE_GAP_US: f64 = 1.0;

/// Most frames one timeline draws (a picture for a slide: beyond this the
/// bars are thinner than their labels).
pub const MAX_TIMELINE_FRAMES: u64 = 120;

/// Most frames simulated before the first one drawn.
pub const MAX_TIMELINE_FIRST: u64 = 100_000;

/// Which frames a timeline draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TimelineOptions {
    /// The first frame drawn (frames before it are simulated, not drawn).
    pub first: u64,
    /// Frames drawn, 1 to [`MAX_TIMELINE_FRAMES`].
    pub frames: u64,
}

/// Why a timeline could not be made.
#[derive(Debug, thiserror::Error)]
pub enum TimelineError {
    /// The frames asked for are out of range.
    #[error("{0}")]
    Frames(String),
    /// The model is not a frame pipeline.
    #[error("{model}: a timeline draws the frame pipeline's units; this model's system is {system:?}")]
    NotFramePipeline {
        /// The model's name.
        model: String,
        /// Its `system` key.
        system: String,
    },
    /// The model could not be loaded or run.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// A replayed capture (`system = "replay"`) could not be replayed.
    #[error("{model}: {source}")]
    Replay {
        /// The model's name.
        model: String,
        /// What went wrong.
        source: Box<crate::studies::replay::ReplayError>,
    },
    /// The run's trace could not be read back.
    #[error("{0}")]
    Trace(String),
}

/// Tracks of the frame pipeline's trace (see `pipeline_trace::PipelineTrace`).
const CPU: u32 = 1;
const FRONT: u32 = 2;
const GEOMETRY: u32 = 3;
const FRAGMENT: u32 = 4;
const DISPLAY: u32 = 5;

fn ms(us: f64) -> f64 {
    us / 1000.0
}

/// `frame N` spans name their frame.
fn frame_of_name(name: &str) -> Option<u64> {
    name.strip_prefix("frame ")?.parse().ok()
}

/// Bars of the units whose spans name their frame (CPU, display).
fn named_bars(spans: &[&ReadSpan]) -> Vec<Bar> {
    spans
        .iter()
        .map(|s| Bar {
            start: ms(s.start_us),
            end: ms(s.end_us),
            fill: match (frame_of_name(&s.name), s.name.as_str()) {
                (Some(f), _) => Fill::Frame(f),
                (None, "system task") => Fill::System,
                _ => Fill::Wait,
            },
        })
        .collect()
}

/// The display lane of a run with frame generation: every frame on screen
/// until the next, the generated ones (`gN`, before frame N) among them.
fn generated_screen_bars(run: &crate::systems::frame_pipeline::PipelineRun, end: f64) -> Vec<Bar> {
    let to_ms = |t: crate::engine::Time| t.0 as f64 / PS_PER_MS as f64;
    let shown: Vec<(f64, Fill)> = run
        .records
        .iter()
        .filter_map(|r| Some((to_ms(r.displayed?), Fill::Frame(r.index))))
        .chain(
            run.generated
                .iter()
                .filter_map(|g| Some((to_ms(g.displayed?), Fill::Generated(g.before)))),
        )
        .collect();
    screen_bars(shown, end)
}

/// The display lane from the frames shown, `(when, which)`: each on screen
/// until the next one, the last until `end`.
fn screen_bars(mut shown: Vec<(f64, Fill)>, end: f64) -> Vec<Bar> {
    shown.sort_by(|a, b| a.0.total_cmp(&b.0));
    (0..shown.len())
        .map(|i| Bar {
            start: shown[i].0,
            end: shown.get(i + 1).map_or(end.max(shown[i].0), |n| n.0),
            fill: shown[i].1,
        })
        .collect()
}

/// Bars of a GPU unit: its busy spans split by the frames' GPU intervals
/// (`windows`: `(start ms, end ms, frame)`, ascending and disjoint); work
/// outside every interval goes to the frame before it.
fn gpu_bars(spans: &[&ReadSpan], windows: &[(f64, f64, u64)]) -> Vec<Bar> {
    let mut bars = Vec::new();
    for s in spans {
        let (start, end) = (ms(s.start_us), ms(s.end_us));
        let fill = match s.name.as_str() {
            "busy" => None,
            "system task" => Some(Fill::System),
            _ => Some(Fill::Wait),
        };
        if let Some(fill) = fill {
            bars.push(Bar { start, end, fill });
            continue;
        }
        // The frame in whose interval `t` lies, or the last one before it.
        let owner = |t: f64| {
            let i = windows.partition_point(|w| w.0 <= t);
            i.checked_sub(1).map(|i| (i, windows[i]))
        };
        let mut at = start;
        while at < end {
            let (upto, frame) = match owner(at) {
                Some((i, w)) => {
                    let next = windows.get(i + 1).map_or(f64::INFINITY, |n| n.0);
                    (if at < w.1 { w.1 } else { next }.min(end), Some(w.2))
                }
                None => (windows.first().map_or(end, |w| w.0).min(end), None),
            };
            let upto = if upto > at { upto } else { end };
            bars.push(Bar {
                start: at,
                end: upto,
                fill: frame.map_or(Fill::Wait, Fill::Frame),
            });
            at = upto;
        }
    }
    bars
}

/// The timeline of a replayed capture (`system = "replay"` model): the
/// frame-pipeline model its replay runs, with the file's assumptions and
/// what-if.
fn replay_timeline(
    src: &ModelSource,
    table: &toml::Table,
    opts: TimelineOptions,
) -> Result<(Timeline, PipelineRun), TimelineError> {
    use crate::studies::replay::config::{ReplayConfig, whatif_sets};
    let r: ReplayConfig = deserialize(table, src).map_err(SimError::from)?;
    let ropts = crate::studies::replay::ReplayOptions {
        app: r.app.clone(),
        swap_chain: r.swapchain.clone(),
        sets: whatif_sets(&r.whatif),
        assume: whatif_sets(&r.assume),
        from_tables: true,
    };
    let (rsrc, rtable) =
        crate::studies::replay::replay_model(&src.base_dir.join(&r.capture), &ropts).map_err(|source| {
            TimelineError::Replay {
                model: src.name.clone(),
                source: Box::new(source),
            }
        })?;
    timeline_of(&rsrc, &rtable, opts)
}

/// Runs the frame-pipeline model `src`/`table` for `opts.first +
/// opts.frames` frames (no warm-up) with its trace read back, and lays out
/// the timeline of the frames drawn.
pub fn timeline_of(
    src: &ModelSource,
    table: &toml::Table,
    opts: TimelineOptions,
) -> Result<(Timeline, PipelineRun), TimelineError> {
    if opts.frames == 0 || opts.frames > MAX_TIMELINE_FRAMES {
        return Err(TimelineError::Frames(format!(
            "frames to draw: {} is not in 1..={MAX_TIMELINE_FRAMES}",
            opts.frames
        )));
    }
    if opts.first > MAX_TIMELINE_FIRST {
        return Err(TimelineError::Frames(format!(
            "first frame drawn: {} is over the limit of {MAX_TIMELINE_FIRST}",
            opts.first
        )));
    }
    let system = match table.get("system") {
        None => "frame_pipeline".to_string(),
        Some(toml::Value::String(s)) => s.clone(),
        Some(other) => other.to_string(),
    };
    if system == "replay" {
        return replay_timeline(src, table, opts);
    }
    if system != "frame_pipeline" {
        return Err(TimelineError::NotFramePipeline {
            model: src.name.clone(),
            system,
        });
    }
    let mut cfg = FramePipelineConfig::from_table(table, src).map_err(SimError::from)?;
    cfg.run.frames = opts.first + opts.frames;
    cfg.run.warmup_frames = 0;
    let vsync = cfg.display.waits_for_vblank();
    let capacity = cfg.command_fifo.capacity;
    let unit = format!("{:?}", cfg.command_fifo.unit).to_lowercase();
    let collector = SpanCollector::new(MERGE_GAP_US, &["command FIFO"]);
    let writer = TraceWriter::collecting(collector.clone()).with_detail(crate::output::trace::TraceDetail::Triangle);
    let mut run = run_pipeline(cfg, &src.base_dir, Some(writer)).map_err(|e| SimError::of(src, e))?;
    if let Some(w) = run.trace.take() {
        w.finish()
            .map_err(|e| TimelineError::Trace(format!("tracing the run: {e}")))?;
    }
    let read = collector.take().map_err(|e| TimelineError::Trace(e.to_string()))?;
    let to_ms = |t: crate::engine::Time| t.0 as f64 / PS_PER_MS as f64;
    let refresh_ms = run.refresh.0 as f64 / PS_PER_MS as f64;
    let drawn: Vec<_> = run.records.iter().filter(|r| r.index >= opts.first).collect();
    let x0 = drawn.first().map_or(0.0, |r| to_ms(r.start));
    let x1 = drawn
        .iter()
        .flat_map(|r| {
            [
                r.gpu_end.map(to_ms),
                r.displayed.map(|d| to_ms(d) + refresh_ms),
                Some(to_ms(r.present)),
            ]
        })
        .flatten()
        .fold(x0, f64::max);
    let pad = (x1 - x0) * 0.01;
    let range = (x0, x1 + pad.max(1e-6));
    let windows: Vec<(f64, f64, u64)> = run
        .records
        .iter()
        .filter_map(|r| Some((to_ms(r.gpu_start?), to_ms(r.gpu_end?), r.index)))
        .collect();
    let on = |tid: u32| read.spans.iter().filter(|s| s.tid == tid).collect::<Vec<_>>();
    let fifo = read.counters.get("command FIFO").cloned().unwrap_or_default();
    let lanes = vec![
        Lane {
            name: "CPU thread".into(),
            bars: named_bars(&on(CPU)),
            level: None,
        },
        Lane {
            name: format!("command FIFO fill (0-{capacity})"),
            bars: Vec::new(),
            level: Some(Level {
                steps: fifo.iter().map(|&(t, v)| (ms(t), v)).collect(),
                max: capacity.max(1) as f64,
            }),
        },
        Lane {
            name: "GPU front end".into(),
            bars: gpu_bars(&on(FRONT), &windows),
            level: None,
        },
        Lane {
            name: "geometry".into(),
            bars: gpu_bars(&on(GEOMETRY), &windows),
            level: None,
        },
        Lane {
            name: "fragment".into(),
            bars: gpu_bars(&on(FRAGMENT), &windows),
            level: None,
        },
        Lane {
            name: "display".into(),
            bars: if run.generated.is_empty() {
                named_bars(&on(DISPLAY))
            } else {
                generated_screen_bars(&run, range.1)
            },
            level: None,
        },
    ];
    let marks = if refresh_ms > 0.0 {
        let first = (range.0 / refresh_ms).ceil() as u64;
        let last = (range.1 / refresh_ms).floor() as u64;
        (first..=last.min(first + 10_000))
            .map(|k| k as f64 * refresh_ms)
            .collect()
    } else {
        Vec::new()
    };
    let last = opts.first + opts.frames - 1;
    let timeline = Timeline {
        title: format!(
            "Frames {}-{last}: who works on which frame (cf. paper 000 Figure 4)",
            opts.first
        ),
        x_label: "simulated time (ms)".into(),
        range,
        lanes,
        marks,
        mark_label: if vsync {
            "vertical blank".into()
        } else {
            "refresh (vsync off: frames shown at once)".into()
        },
        notes: vec![format!(
            "command FIFO fill in {unit}; work less than {MERGE_GAP_US} us apart drawn as one bar; {} Hz display{}",
            crate::output::text::fixed(1000.0 / refresh_ms, 1),
            if run.generated.is_empty() {
                ""
            } else {
                "; gN: the frame generated before frame N"
            }
        )],
    };
    Ok((timeline, run))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn span(name: &str, a: f64, b: f64) -> ReadSpan {
        ReadSpan {
            tid: GEOMETRY,
            name: name.into(),
            arg: None,
            start_us: a * 1000.0,
            end_us: b * 1000.0,
        }
    }

    #[test]
    fn generated_frames_take_the_screen_between_rendered_ones() {
        let bars = screen_bars(
            vec![
                (20.0, Fill::Frame(1)),
                (2.0, Fill::Frame(0)),
                (11.0, Fill::Generated(1)),
            ],
            25.0,
        );
        let got: Vec<(f64, f64, Fill)> = bars.iter().map(|b| (b.start, b.end, b.fill)).collect();
        assert_eq!(
            got,
            vec![
                (2.0, 11.0, Fill::Frame(0)),
                (11.0, 20.0, Fill::Generated(1)),
                (20.0, 25.0, Fill::Frame(1)),
            ]
        );
    }

    #[test]
    fn gpu_work_is_split_by_the_frames_intervals() {
        let windows = [(1.0, 3.0, 0), (4.0, 6.0, 1)];
        let s = [
            span("busy", 2.0, 5.0),
            span("busy", 0.5, 1.5),
            span("blocked", 2.0, 2.5),
        ];
        let refs: Vec<&ReadSpan> = s.iter().collect();
        let bars = gpu_bars(&refs, &windows);
        let got: Vec<(f64, f64, Fill)> = bars.iter().map(|b| (b.start, b.end, b.fill)).collect();
        assert_eq!(
            got,
            vec![
                (2.0, 3.0, Fill::Frame(0)),
                (3.0, 4.0, Fill::Frame(0)),
                (4.0, 5.0, Fill::Frame(1)),
                (0.5, 1.0, Fill::Wait),
                (1.0, 1.5, Fill::Frame(0)),
                (2.0, 2.5, Fill::Wait),
            ]
        );
    }
}
