//! One redraw of the page: the model with the page's `--set` list, run
//! exactly as `rendersim run MODEL --set ...` runs it, and the views drawn
//! from the run's typed results (paper 000 Figure 4's timeline, frame time
//! and display interval over frames, the latency distribution, each unit's
//! busy and waiting time, the critical path's shares, `isolate`'s verdict,
//! and the closed-form terms of paper 000 §4.1 beside the simulated ones).
//!
//! A run is held to an event budget (`run.max_events`, added only where
//! the model sets none): a run that reaches it is refused with a message
//! instead of shown cut short, so every number the page shows is the one
//! the command it prints gives.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::config::{ModelSource, Overrides, prepare};
use crate::engine::StopReason;
use crate::plot::{BarChart, BarSeries, Histogram, LinePlot, Series};
use crate::studies::isolate::{IsolateOptions, Isolation, isolate};
use crate::studies::timeline::{TimelineOptions, timeline_of};
use crate::systems::frame_pipeline::config::{FramePipelineConfig, WorkloadConfig};
use crate::systems::frame_pipeline::records::frame_figures;
use crate::systems::frame_pipeline::{PipelineRun, PipelineSummary};

use super::controls::{Shown, shown};
use super::presets::{PRESETS, Preset};

/// Frames the timeline draws unless the page asks for another count.
pub const TIMELINE_FRAMES: u64 = 4;

/// Most frames the page's timeline draws.
pub const MAX_TIMELINE_FRAMES: u64 = 12;

/// Most `--set` assignments one request may carry.
pub const MAX_SETS: usize = 64;

/// Why the page could not be redrawn; each is shown on the page.
#[derive(Debug, thiserror::Error)]
pub enum PageError {
    /// The request itself is malformed (HTTP 400).
    #[error("{0}")]
    Request(String),
    /// The model refused a value, with `--set`'s own message (HTTP 422).
    #[error("{0}")]
    Model(String),
    /// The run reached the page's event budget (HTTP 422).
    #[error("{0}")]
    Budget(String),
    /// A view could not be drawn (HTTP 500).
    #[error("{0}")]
    View(String),
}

impl PageError {
    /// The HTTP status the page gets.
    pub fn status(&self) -> u16 {
        match self {
            PageError::Request(_) => 400,
            PageError::Model(_) | PageError::Budget(_) => 422,
            PageError::View(_) => 500,
        }
    }
}

/// The model the page explores, and the limits it runs under.
#[derive(Debug, Clone)]
pub struct Explorer {
    source: ModelSource,
    model_path: Option<PathBuf>,
    /// Assignments the page starts from (the explorer's `--set`s).
    pub start_sets: Vec<String>,
    /// Most events one run may process.
    pub budget_events: u64,
}

/// What the page needs to build its controls.
#[derive(Debug, Clone, Serialize)]
pub struct PageModel {
    /// The model's name (its path, or the embedded default's name).
    pub model: String,
    /// Its description.
    pub description: String,
    /// The assignments the page starts from.
    pub start_sets: Vec<String>,
    /// The controls that apply, with the model's values (start sets applied).
    pub controls: Vec<Shown>,
    /// The lessons this model takes: they are written for a scene (the
    /// default model's), so a scene whose model takes each one's
    /// assignments; none for a fixed or replayed workload.
    pub presets: Vec<&'static Preset>,
    /// The event budget of one run.
    pub budget_events: u64,
}

/// One number the page shows, and where `rendersim run --json` prints it.
#[derive(Debug, Clone, Serialize)]
pub struct Number {
    /// What it is.
    pub label: &'static str,
    /// Its unit (`ms`, `frames`, or empty).
    pub unit: &'static str,
    /// The value; `None` where the run has none (no frame was shown).
    pub value: Option<f64>,
    /// Its path in `rendersim run --json`'s summary (`metrics.frame_time_ms.mean`).
    pub json: &'static str,
}

/// A closed-form term beside the simulated value it bounds or predicts.
#[derive(Debug, Clone, Serialize)]
pub struct ClosedForm {
    /// What it is.
    pub label: &'static str,
    /// Paper 000 §4.1's per-frame term (ms).
    pub closed_form_ms: f64,
    /// Its path in `rendersim run --json`'s summary.
    pub closed_form_json: &'static str,
    /// The simulated counterpart (ms).
    pub simulated_ms: Option<f64>,
    /// Where `rendersim run --json` gives it (a path, or how it is made
    /// from one).
    pub simulated_from: &'static str,
}

/// `isolate`'s verdict, as the page shows it.
#[derive(Debug, Clone, Serialize)]
pub struct Verdict {
    /// The unit whose halved work moves the frame time most (`raster`
    /// named `fragment`), `tie` or `none`.
    pub bottleneck: String,
    /// The units within the tie tolerance of the best.
    pub tied: Vec<String>,
    /// Each unit's halved work and the frame time's change.
    pub changes: Vec<(String, f64)>,
    /// One sentence: what to change.
    pub advice: String,
}

/// The SVG documents of the views.
#[derive(Debug, Clone, Serialize)]
pub struct Views {
    /// Paper 000 Figure 4's timeline.
    pub timeline: String,
    /// Frame time and display interval over frames.
    pub frames: String,
    /// The display latency's distribution.
    pub latency: String,
    /// Each unit's time per state.
    pub states: String,
}

/// Everything one redraw shows.
#[derive(Debug, Clone, Serialize)]
pub struct PageResult {
    /// The assignments run.
    pub sets: Vec<String>,
    /// The command that gives the same numbers.
    pub command: String,
    /// Notes the model loader made (a warm-up shortened).
    pub notes: Vec<String>,
    /// The headline numbers.
    pub numbers: Vec<Number>,
    /// The critical path's shares per unit.
    pub shares: Vec<(String, f64)>,
    /// Closed forms beside the simulation.
    pub closed_form: Vec<ClosedForm>,
    /// The bottleneck verdict.
    pub verdict: Verdict,
    /// The timeline's lanes, top to bottom.
    pub lanes: Vec<String>,
    /// The pictures.
    pub views: Views,
    /// Simulated seconds and events of the main run.
    pub simulated_seconds: f64,
    /// Events of the main run.
    pub events: u64,
}

/// `value` quoted for a POSIX shell where it needs it.
pub fn shell_quote(value: &str) -> String {
    let plain = !value.is_empty()
        && value
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    if plain {
        value.to_string()
    } else {
        format!("'{}'", value.replace('\'', "'\\''"))
    }
}

impl Explorer {
    /// The model at `model` (the embedded default without one), checked
    /// to be a frame pipeline that runs with `start_sets`.
    pub fn new(model: Option<&Path>, start_sets: Vec<String>, budget_events: u64) -> anyhow::Result<Explorer> {
        let source = ModelSource::open(model)?;
        let explorer = Explorer {
            source,
            model_path: model.map(Path::to_path_buf),
            start_sets,
            budget_events: budget_events.max(1),
        };
        let prepared = prepare(explorer.source.clone(), &Overrides::with_sets(&explorer.start_sets))?;
        let system = prepared
            .table
            .get("system")
            .and_then(|s| s.as_str())
            .unwrap_or("frame_pipeline");
        if system != "frame_pipeline" {
            anyhow::bail!(
                "{}: explore shows the frame pipeline's units; this model's system is {system:?} \
                 (explore a frame_pipeline model: the default, models/fixed.toml, models/city.toml, ...)",
                explorer.source.name
            );
        }
        FramePipelineConfig::from_table(&prepared.table, &prepared.source)?;
        Ok(explorer)
    }

    /// The model's name as messages give it.
    pub fn name(&self) -> &str {
        &self.source.name
    }

    /// The page's model: its controls with the values the start sets give.
    pub fn page_model(&self) -> Result<PageModel, PageError> {
        let (cfg, _) = self.config(&self.start_sets)?;
        let resolved: toml::Table = crate::systems::resolved_toml(&cfg)
            .parse()
            .map_err(|e| PageError::View(format!("reading the resolved model back: {e}")))?;
        Ok(PageModel {
            model: self.source.name.clone(),
            description: cfg.description.clone(),
            start_sets: self.start_sets.clone(),
            controls: shown(&resolved, matches!(cfg.workload, WorkloadConfig::Scene(_))),
            presets: PRESETS
                .iter()
                .filter(|_| matches!(cfg.workload, WorkloadConfig::Scene(_)))
                .filter(|p| {
                    let sets: Vec<String> = self
                        .start_sets
                        .iter()
                        .cloned()
                        .chain(p.sets.iter().map(|s| s.to_string()))
                        .collect();
                    self.model_toml(&sets).is_ok()
                })
                .collect(),
            budget_events: self.budget_events,
        })
    }

    /// The command line that runs what the page shows.
    pub fn command(&self, sets: &[String]) -> String {
        let mut words = vec!["rendersim".to_string(), "run".to_string()];
        if let Some(p) = &self.model_path {
            words.push(shell_quote(&p.display().to_string()));
        }
        for s in sets {
            words.push("--set".into());
            words.push(shell_quote(s));
        }
        words.join(" ")
    }

    /// The model with `sets` applied and checked, and the loader's notes.
    fn config(&self, sets: &[String]) -> Result<(FramePipelineConfig, Vec<String>), PageError> {
        if sets.len() > MAX_SETS {
            return Err(PageError::Request(format!(
                "{} assignments: at most {MAX_SETS} in one request",
                sets.len()
            )));
        }
        if let Some(s) = sets.iter().find(|s| s.trim_start().starts_with("system")) {
            return Err(PageError::Request(format!(
                "--set {s}: the page explores this frame pipeline; a system cannot be set"
            )));
        }
        let model = prepare(self.source.clone(), &Overrides::with_sets(sets))
            .map_err(|e| PageError::Model(crate::error_line(&e)))?;
        let cfg = FramePipelineConfig::from_table(&model.table, &model.source)
            .map_err(|e| PageError::Model(crate::error_line(&e)))?;
        Ok((cfg, model.notes))
    }

    /// The model's resolved `model.toml` with `sets` applied (what
    /// `rendersim run --out` writes).
    pub fn model_toml(&self, sets: &[String]) -> Result<String, PageError> {
        let (cfg, _) = self.config(sets)?;
        crate::systems::frame_pipeline::PipelinePlan::new(cfg.clone(), &self.source.base_dir)
            .map_err(|e| PageError::Model(format!("{}: {}", self.source.name, crate::error_line(&e))))?;
        Ok(format!(
            "# {}\n{}",
            self.command(sets),
            crate::systems::resolved_toml(&cfg)
        ))
    }

    /// Runs the model with `sets` and draws every view, `timeline_frames`
    /// frames in the timeline.
    pub fn run(&self, sets: &[String], timeline_frames: u64) -> Result<PageResult, PageError> {
        if timeline_frames == 0 || timeline_frames > MAX_TIMELINE_FRAMES {
            return Err(PageError::Request(format!(
                "timeline frames: {timeline_frames} is not in 1..={MAX_TIMELINE_FRAMES}"
            )));
        }
        let (mut cfg, notes) = self.config(sets)?;
        let budgeted = cfg.run.max_events.is_none();
        if budgeted {
            cfg.run.max_events = Some(self.budget_events);
        }
        let run = crate::systems::frame_pipeline::run_pipeline(cfg.clone(), &self.source.base_dir, None)
            .map_err(|e| PageError::Model(format!("{}: {}", self.source.name, crate::error_line(&e))))?;
        let r = &run.results;
        if budgeted && r.stopped_by == StopReason::EventLimit {
            return Err(PageError::Budget(format!(
                "the run reached the page's budget of {} events after {} of {} frames; \
                 fewer frames (run.frames), fidelity \"draw\" or a smaller scene redraw at once \
                 (`{}` has no such budget)",
                self.budget_events,
                r.frames_simulated,
                r.frames_requested,
                self.command(sets)
            )));
        }
        let (timeline, lanes) = self.timeline(sets, &cfg, timeline_frames)?;
        let verdict = self.verdict(&cfg)?;
        let views = Views {
            timeline,
            frames: frames_view(&run)?,
            latency: latency_view(&run)?,
            states: states_view(r)?,
        };
        Ok(PageResult {
            sets: sets.to_vec(),
            command: self.command(sets),
            notes,
            numbers: numbers(r),
            shares: r.metrics.bottleneck.iter().map(|(k, v)| (k.clone(), *v)).collect(),
            closed_form: closed_form(r),
            verdict,
            lanes,
            views,
            simulated_seconds: r.simulated_seconds,
            events: r.events.total,
        })
    }

    /// The timeline of `frames` frames after the warm-up, and its lanes.
    fn timeline(
        &self,
        sets: &[String],
        cfg: &FramePipelineConfig,
        frames: u64,
    ) -> Result<(String, Vec<String>), PageError> {
        let mut budgeted: Vec<String> = sets.to_vec();
        if cfg.run.max_events == Some(self.budget_events) {
            budgeted.push(format!("run.max_events={}", self.budget_events));
        }
        let model = prepare(self.source.clone(), &Overrides::with_sets(&budgeted))
            .map_err(|e| PageError::Model(crate::error_line(&e)))?;
        let last_first = cfg.run.frames.saturating_sub(frames);
        let opts = TimelineOptions {
            first: cfg.run.warmup_frames.min(last_first),
            frames: frames.min(cfg.run.frames.max(1)),
        };
        let (picture, _) =
            timeline_of(&model.source, &model.table, opts).map_err(|e| PageError::Model(crate::error_line(&e)))?;
        let lanes = picture.lanes.iter().map(|l| l.name.clone()).collect();
        let svg = crate::plot::timeline_svg(&picture).map_err(|e| PageError::View(e.to_string()))?;
        Ok((svg, lanes))
    }

    /// `isolate`'s verdict on the model (draw fidelity, vsync off but on a
    /// VRR panel, each unit's work halved in turn).
    fn verdict(&self, cfg: &FramePipelineConfig) -> Result<Verdict, PageError> {
        let iso: Isolation = isolate(cfg, &self.source.base_dir, IsolateOptions::default())
            .map_err(|e| PageError::Model(format!("{}: isolate: {}", self.source.name, crate::error_line(&e))))?;
        let unit = |n: &str| {
            if n == "raster" {
                "fragment".to_string()
            } else {
                n.to_string()
            }
        };
        let changes: Vec<(String, f64)> = iso.variants[1..].iter().map(|v| (unit(&v.name), v.change)).collect();
        let best = changes.iter().min_by(|a, b| a.1.total_cmp(&b.1));
        let advice = match (iso.bottleneck.as_str(), best) {
            ("none", _) | (_, None) => "halving any one unit's work leaves the frame time within 1%: \
                 the display (vsync) or a limiter sets the pace"
                .to_string(),
            (_, Some((name, change))) => format!(
                "halving the {name}'s work changes the frame time by {:+.1}% (vsync {}): make the {name} faster",
                change * 100.0,
                if iso.vsync { "on" } else { "off" }
            ),
        };
        Ok(Verdict {
            bottleneck: unit(&iso.bottleneck),
            tied: iso.tied.iter().map(|t| unit(t)).collect(),
            changes,
            advice,
        })
    }
}

/// The headline numbers, each where `rendersim run --json` prints it.
fn numbers(r: &PipelineSummary) -> Vec<Number> {
    let m = &r.metrics;
    let n = |label, unit, value, json| Number {
        label,
        unit,
        value,
        json,
    };
    let mut shown = vec![
        n(
            "frame time, mean",
            "ms",
            m.frame_time_ms.mean,
            "metrics.frame_time_ms.mean",
        ),
        n(
            "frame time, p99",
            "ms",
            m.frame_time_ms.p99,
            "metrics.frame_time_ms.p99",
        ),
        n(
            "display interval, mean",
            "ms",
            m.display_interval_ms.mean,
            "metrics.display_interval_ms.mean",
        ),
        n(
            "latency (input to screen), median",
            "ms",
            m.display_latency_ms.p50,
            "metrics.display_latency_ms.p50",
        ),
        n(
            "latency, p99",
            "ms",
            m.display_latency_ms.p99,
            "metrics.display_latency_ms.p99",
        ),
        n(
            "latency, worst",
            "ms",
            m.display_latency_ms.max,
            "metrics.display_latency_ms.max",
        ),
        n("GPU time, mean", "ms", m.gpu_time_ms.mean, "metrics.gpu_time_ms.mean"),
        n("CPU work, mean", "ms", m.cpu_busy_ms.mean, "metrics.cpu_busy_ms.mean"),
        n(
            "frames dropped",
            "frames",
            Some(m.dropped_frames as f64),
            "metrics.dropped_frames",
        ),
        n(
            "refreshes repeated",
            "",
            Some(m.repeated_refresh_fraction),
            "metrics.repeated_refresh_fraction",
        ),
    ];
    if let Some(g) = &m.frame_generation {
        shown.extend([
            n(
                "frames shown a second (rendered and generated)",
                "",
                Some(g.displayed_fps),
                "metrics.frame_generation.displayed_fps",
            ),
            n(
                "frames rendered a second",
                "",
                Some(g.rendered_fps),
                "metrics.frame_generation.rendered_fps",
            ),
            n(
                "hold-back of a rendered frame, median",
                "ms",
                g.hold_back_ms.p50,
                "metrics.frame_generation.hold_back_ms.p50",
            ),
        ]);
    }
    shown
}

/// Paper 000 §4.1's per-frame terms beside the simulation's.
fn closed_form(r: &PipelineSummary) -> Vec<ClosedForm> {
    let m = &r.metrics;
    let a = &m.analytic;
    // A unit's time per state covers the whole run, warm-up included.
    let frames = r.frames.max(1) as f64;
    let busy = |states: &std::collections::BTreeMap<String, f64>| states.get("busy").map(|b| b / frames);
    let c = |label, closed_form_ms, closed_form_json, simulated_ms, simulated_from| ClosedForm {
        label,
        closed_form_ms,
        closed_form_json,
        simulated_ms,
        simulated_from,
    };
    vec![
        c(
            "CPU work per frame",
            a.cpu_ms,
            "metrics.analytic.cpu_ms",
            m.cpu_busy_ms.mean,
            "metrics.cpu_busy_ms.mean",
        ),
        c(
            "geometry per frame",
            a.geometry_ms,
            "metrics.analytic.geometry_ms",
            busy(&m.states_ms.geometry),
            "metrics.states_ms.geometry.busy / frames_simulated",
        ),
        c(
            "fragment per frame",
            a.fragment_ms,
            "metrics.analytic.fragment_ms",
            busy(&m.states_ms.fragment),
            "metrics.states_ms.fragment.busy / frames_simulated",
        ),
        c(
            "GPU per frame (units added up)",
            a.gpu_sum_ms,
            "metrics.analytic.gpu_sum_ms",
            m.gpu_busy_ms.mean,
            "metrics.gpu_busy_ms.mean",
        ),
        c(
            "frame time, lower bound (slowest unit)",
            a.frame_max_ms,
            "metrics.analytic.frame_max_ms",
            m.frame_time_ms.mean,
            "metrics.frame_time_ms.mean",
        ),
    ]
}

fn view_err(e: crate::plot::PlotError) -> PageError {
    PageError::View(e.to_string())
}

/// Frame time and display interval over the frames after the warm-up.
fn frames_view(run: &PipelineRun) -> Result<String, PageError> {
    let warm = run.results.warmup_frames;
    let figures: Vec<_> = frame_figures(&run.records)
        .into_iter()
        .filter(|f| f.index >= warm)
        .collect();
    let series =
        |name: &str, pick: &dyn Fn(&crate::systems::frame_pipeline::records::FrameFigures) -> Option<f64>| Series {
            name: name.to_string(),
            points: figures
                .iter()
                .filter_map(|f| Some((f.index as f64, pick(f)?)))
                .collect(),
            ..Series::default()
        };
    crate::plot::line_plot_svg(&LinePlot {
        title: "Frame time and display interval".into(),
        x_label: "frame".into(),
        y_label: "ms".into(),
        series: vec![
            series("frame time", &|f| Some(f.frame_time_ms)),
            series("display interval", &|f| f.display_interval_ms),
        ],
        ..LinePlot::default()
    })
    .map_err(view_err)
}

/// The distribution of input-to-screen latency, median, p99 and worst marked.
fn latency_view(run: &PipelineRun) -> Result<String, PageError> {
    let warm = run.results.warmup_frames;
    let values: Vec<f64> = frame_figures(&run.records)
        .into_iter()
        .filter(|f| f.index >= warm)
        .filter_map(|f| f.display_latency_ms)
        .collect();
    let d = &run.results.metrics.display_latency_ms;
    let marks = [("median", d.p50), ("p99", d.p99), ("worst", d.max)]
        .into_iter()
        .filter_map(|(name, v)| {
            Some(crate::plot::Mark {
                at: v?,
                label: format!("{name} {:.2} ms", v?),
            })
        })
        .collect();
    crate::plot::histogram_svg(&Histogram {
        title: "Latency, input sampled to screen".into(),
        x_label: "ms".into(),
        values: vec![("frames".into(), values)],
        bins: 30,
        range: None,
        marks,
    })
    .map_err(view_err)
}

/// Each unit's time per state (ms over the run).
fn states_view(r: &PipelineSummary) -> Result<String, PageError> {
    let s = &r.metrics.states_ms;
    let units: [(&str, &std::collections::BTreeMap<String, f64>); 4] = [
        ("CPU", &s.cpu),
        ("GPU front end", &s.gpu_front_end),
        ("geometry", &s.geometry),
        ("fragment", &s.fragment),
    ];
    let mut states: Vec<String> = units.iter().flat_map(|(_, m)| m.keys().cloned()).collect();
    states.sort();
    states.dedup();
    let series = states
        .iter()
        .map(|state| BarSeries {
            name: state.clone(),
            values: units
                .iter()
                .map(|(_, m)| m.get(state).copied().unwrap_or(0.0))
                .collect(),
            ..BarSeries::default()
        })
        .collect();
    crate::plot::bar_chart_svg(&BarChart {
        title: "Where each unit's time went".into(),
        y_label: "ms over the run".into(),
        categories: units.iter().map(|(n, _)| n.to_string()).collect(),
        series,
        log_y: false,
    })
    .map_err(view_err)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_words_are_quoted_only_where_needed() {
        assert_eq!(shell_quote("display.buffers=3"), "display.buffers=3");
        assert_eq!(shell_quote("fidelity=\"draw\""), "'fidelity=\"draw\"'");
        assert_eq!(shell_quote("it's"), "'it'\\''s'");
    }
}
