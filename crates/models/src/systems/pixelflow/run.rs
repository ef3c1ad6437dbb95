//! Validating, running and summarizing a PixelFlow model.

use serde::Serialize;

use crate::engine::{Duration, Limits, PS_PER_MS, RunStats, Scheduler, run};
use crate::output::trace::TraceWriter;

use super::analytic::{Analytic, closed_form};
use super::config::{Architecture, Fidelity, PixelFlowConfig, Placement, Size};
use super::layout::{Layout, build};
use super::model::{PixelFlow, RegionRecord, Span};
use crate::systems::checked::{Check, Checked};
use crate::systems::error::{SystemError, invalid as bad};
use crate::systems::summary::EventCounts;

/// Everything a run produced.
#[derive(Debug)]
pub struct PixelFlowRun {
    /// The model as run.
    pub config: PixelFlowConfig,
    /// The closed form.
    pub analytic: Analytic,
    /// Kernel statistics (event fidelity).
    pub stats: Option<RunStats>,
    /// Per-region records (event fidelity).
    pub records: Vec<RegionRecord>,
    /// Region entries per region.
    pub region_entries: Vec<u64>,
    /// The summary, typed (`summary.json` is made from it where it is written).
    pub summary: PixelFlowSummary,
    /// Timeline, when asked for.
    pub spans: Option<Vec<Span>>,
    /// The trace, when one was asked for: written, not yet closed.
    pub trace: Option<TraceWriter>,
}

fn check_size(key: &str, s: &Size) -> Result<(), SystemError> {
    for (k, v) in [("width", s.width), ("height", s.height)] {
        if !v.is_finite() || v < 0.0 {
            return Err(bad(
                &format!("{key}.{k}"),
                format!("must be a finite size >= 0 pixels, got {v}"),
            ));
        }
    }
    Ok(())
}

impl Check for PixelFlowConfig {
    fn check(&self) -> Result<(), SystemError> {
        validate(self)
    }
}

/// Checks what serde cannot.
pub fn validate(cfg: &PixelFlowConfig) -> Result<(), SystemError> {
    check_counts(cfg)?;
    check_sizes(cfg)?;
    check_regions(cfg)?;
    check_options(cfg)
}

/// The node, frame and sample counts, and the nodes' roles: a frame
/// buffer, at least one rasterizer and (texturing) at least one shader.
fn check_counts(cfg: &PixelFlowConfig) -> Result<(), SystemError> {
    if cfg.nodes > crate::limits::MAX_PIXELFLOW_NODES {
        return Err(bad(
            "nodes",
            format!(
                "{} nodes is more than the limit of {}",
                cfg.nodes,
                crate::limits::MAX_PIXELFLOW_NODES
            ),
        ));
    }
    if cfg.frames == 0 || cfg.frames > 10_000 {
        return Err(bad(
            "frames",
            format!("must be between 1 and 10000, got {}", cfg.frames),
        ));
    }
    if cfg.frames > 1 && cfg.architecture == super::Architecture::Nontex {
        return Err(bad(
            "frames",
            "the non-texturing system is simulated one frame at a time (frames = 1)",
        ));
    }
    if cfg.samples == 0 {
        return Err(bad("samples", "must be at least 1 (1 = no antialiasing)"));
    }
    if cfg.architecture != super::Architecture::Nontex && cfg.shading_nodes >= cfg.nodes {
        return Err(bad(
            "shading_nodes|nodes",
            format!(
                "{} shading nodes among {} nodes leave no rasterizer (one node is the frame buffer, at least one must rasterize)",
                cfg.shading_nodes, cfg.nodes
            ),
        ));
    }
    if cfg.rasterizers() == 0 {
        return Err(bad(
            "nodes|shading_nodes",
            format!(
                "{} nodes leave no rasterizer (one frame-buffer node and {} shading nodes)",
                cfg.nodes,
                cfg.shaders()
            ),
        ));
    }
    if cfg.architecture != super::Architecture::Nontex && cfg.shading_nodes == 0 {
        return Err(bad(
            "shading_nodes",
            "the texturing architectures need at least one shading node",
        ));
    }
    Ok(())
}

/// The display, primitive and region sizes: finite, at least a pixel
/// where needed, with finite areas and a finite overlap factor.
fn check_sizes(cfg: &PixelFlowConfig) -> Result<(), SystemError> {
    check_size("display", &cfg.display)?;
    check_size("primitive", &cfg.primitive)?;
    check_size("aa_primitive", &cfg.aa_primitive)?;
    check_size("region", &cfg.region)?;
    if cfg.region.width < 1.0 || cfg.region.height < 1.0 || cfg.display.width < 1.0 || cfg.display.height < 1.0 {
        return Err(bad("region", "display and region must be at least 1 x 1 pixel"));
    }
    // Sizes whose products are not finite numbers (an area, the overlap
    // factor) would turn the closed forms and the layout into NaN or
    // infinity; name the size that does it.
    let footprint_key = if cfg.samples > 1 && cfg.architecture != super::Architecture::Nontex {
        "aa_primitive"
    } else {
        "primitive"
    };
    for (key, size) in [
        ("display", &cfg.display),
        ("region", &cfg.region),
        (footprint_key, &cfg.footprint()),
    ] {
        if !size.area().is_finite() {
            return Err(bad(
                &format!("{key}.{}", if size.width >= size.height { "width" } else { "height" }),
                format!(
                    "{key} {:?} x {:?} pixels is too large: its area is not a finite number",
                    size.width, size.height
                ),
            ));
        }
    }
    let overlap = cfg.overlap();
    if !overlap.is_finite() || !(overlap * cfg.primitives as f64).is_finite() {
        let f = cfg.footprint();
        return Err(bad(
            footprint_key,
            format!(
                "the overlap factor (w+W)(h+H)/(W H) of a {:?} x {:?} primitive in {:?} x {:?} regions is not a finite number",
                f.width, f.height, cfg.region.width, cfg.region.height
            ),
        ));
    }
    Ok(())
}

/// The regions, and the bins and region records they make, within limits.
fn check_regions(cfg: &PixelFlowConfig) -> Result<(), SystemError> {
    if cfg.regions() > 1_000_000 {
        return Err(bad(
            "region",
            format!("{} regions is more than 1,000,000", cfg.regions()),
        ));
    }
    let regions = cfg.regions() as u64;
    let bins = u64::from(cfg.nodes).saturating_mul(regions);
    if bins > crate::limits::MAX_PIXELFLOW_BINS {
        return Err(bad(
            "nodes",
            format!(
                "{} nodes x {regions} regions = {bins} bins is more than the limit of {}",
                cfg.nodes,
                crate::limits::MAX_PIXELFLOW_BINS
            ),
        ));
    }
    let records = u64::from(cfg.frames).saturating_mul(regions);
    if records > crate::limits::MAX_PIXELFLOW_REGION_RECORDS {
        return Err(bad(
            "frames",
            format!(
                "{} frames x {regions} regions = {records} region records is more than the limit of {}",
                cfg.frames,
                crate::limits::MAX_PIXELFLOW_REGION_RECORDS
            ),
        ));
    }
    Ok(())
}

/// The non-texturing batch, the node skew and the clustered placement's table.
fn check_options(cfg: &PixelFlowConfig) -> Result<(), SystemError> {
    if cfg.nontex.batch_primitives == 0 {
        return Err(bad("nontex.batch_primitives", "must be at least 1"));
    }
    if !(cfg.node_skew.is_finite() && (0.0..1.0).contains(&cfg.node_skew)) {
        return Err(bad(
            "node_skew",
            format!("must be within [0, 1), got {}", cfg.node_skew),
        ));
    }
    if cfg.placement == Placement::Clustered {
        let Some(c) = &cfg.cluster else {
            return Err(bad("cluster", "placement = \"clustered\" needs a [cluster] table"));
        };
        if !(0.0..=1.0).contains(&c.fraction) {
            return Err(bad(
                "cluster.fraction",
                format!("must be within 0..1, got {}", c.fraction),
            ));
        }
        for (k, v) in [("x", c.x), ("y", c.y), ("width", c.width), ("height", c.height)] {
            if !v.is_finite() || v < 0.0 {
                return Err(bad(
                    &format!("cluster.{k}"),
                    format!("must be finite and >= 0, got {v}"),
                ));
            }
        }
    }
    Ok(())
}

/// The last guard: no closed-form term may be NaN or infinite (`max`
/// would hide a NaN term behind a finite one), whatever [`validate`] let
/// through, and at event fidelity none may pass the clock's range. The
/// error names the inputs the term is made of.
fn finite_closed_form(cfg: &PixelFlowConfig, a: &Analytic) -> Result<(), SystemError> {
    let frames = cfg.frames;
    let costs = match cfg.architecture {
        super::Architecture::Nontex => "nontex",
        _ => "deferred",
    };
    let fp = if cfg.samples > 1 && cfg.architecture != super::Architecture::Nontex {
        "aa_primitive"
    } else {
        "primitive"
    };
    // The inputs of each term, most likely culprit first; the error blames
    // the first one set on the command line or by an experiment.
    let sizes = "display.width|display.height|region.width|region.height";
    let front = format!("primitives|nodes|{costs}.t_overhead|{costs}.t_trans|deferred.t_first_pass");
    let rast = format!("primitives|{fp}.width|{fp}.height|region.width|region.height|nodes|{costs}.t_rast_per_prim");
    let comp = format!("{sizes}|{costs}.t_comp_byte|deferred.appearance_bytes|nontex.composite_bytes");
    let shade = format!("{sizes}|shading_nodes|deferred.t_shade_address|deferred.t_shade_texture");
    let load = format!("{sizes}|{costs}.t_load");
    let overlap = format!("{fp}.width|{fp}.height|region.width|region.height");
    let all = format!("{rast}|{front}|{comp}|{shade}|{load}|samples");
    for (term, v, keys) in [
        ("overlap", a.overlap, overlap.as_str()),
        ("t_front", a.t_front_ms, front.as_str()),
        ("t_gen", a.t_gen_ms, "primitives|nodes|deferred.t_gen_each"),
        ("t_rast", a.t_rast_ms, rast.as_str()),
        ("t_comp", a.t_comp_ms, comp.as_str()),
        ("t_shade", a.t_shade_ms, shade.as_str()),
        ("t_load", a.t_load_ms, load.as_str()),
        ("latency", a.latency_ms, all.as_str()),
    ] {
        let inputs = keys.replace('|', ", ");
        if !v.is_finite() {
            return Err(bad(
                keys,
                format!("the closed-form term {term} is not a finite number ({v}); it is computed from {inputs}"),
            ));
        }
        // Predictable overflow of the simulated clock (u64 picoseconds):
        // report it before simulating, not when the event is scheduled.
        // (The analytic fidelity computes in floating point, no clock.)
        let ps = v * PS_PER_MS as f64 * f64::from(frames);
        if cfg.fidelity == Fidelity::Event && term != "overlap" && ps >= u64::MAX as f64 {
            return Err(bad(
                keys,
                format!(
                    "the closed-form term {term} is {v:.6e} ms per frame ({frames} frame(s)), more than the simulated clock can count (about 213 days in picoseconds); it is computed from {inputs}"
                ),
            ));
        }
    }
    Ok(())
}

fn ms(d: Duration) -> f64 {
    d.as_ms_f64()
}

fn max_ms(v: &[Duration]) -> f64 {
    v.iter().map(|d| ms(*d)).fold(0.0, f64::max)
}

/// Validates, builds and runs the model at its fidelity.
pub fn run_pixelflow(cfg: PixelFlowConfig, trace: bool) -> Result<PixelFlowRun, SystemError> {
    let cfg = Checked::new(cfg)?;
    let t0 = std::time::Instant::now();
    let analytic = closed_form(&cfg);
    finite_closed_form(&cfg, &analytic)?;
    if cfg.fidelity == Fidelity::Analytic {
        let wall = t0.elapsed().as_secs_f64();
        let a = &analytic;
        let stages = StagesMs {
            geometry: a.t_front_ms,
            generate: a.t_gen_ms,
            rasterize: a.t_rast_ms,
            composite: a.t_comp_ms,
            shade: a.t_shade_ms,
            color: None,
            load: a.t_load_ms,
        };
        let summary = summary(
            &cfg,
            &analytic,
            None,
            a.latency_ms,
            a.front_end_ms,
            stages,
            None,
            wall,
            0.0,
            &[(0.0, a.front_end_ms, a.latency_ms)],
        );
        return Ok(PixelFlowRun {
            config: cfg.into_inner(),
            analytic,
            stats: None,
            records: Vec::new(),
            region_entries: Vec::new(),
            summary,
            spans: None,
            trace: None,
        });
    }
    let layout = build(&cfg);
    let region_entries = layout.region_entries();
    let build_seconds = t0.elapsed().as_secs_f64();
    let mut model = PixelFlow::new(cfg, layout, trace);
    let mut sched = Scheduler::new();
    model.start(&mut sched)?;
    let stats = run(&mut model, &mut sched, Limits::default())?;
    let Some(done) = model.finished else {
        return Err(SystemError::Unfinished {
            at: stats.end_time,
            missing: "the frame was complete".into(),
            state: format!("{} of {} regions loaded", model.loaded(), model.records.len()),
        });
    };
    let b = &model.busy;
    let stages = StagesMs {
        geometry: max_ms(&b.geometry),
        generate: max_ms(&b.generate),
        rasterize: max_ms(&b.rasterize),
        composite: ms(b.composite),
        shade: max_ms(&b.shade),
        color: Some(ms(b.color)),
        load: ms(b.load),
    };
    let _ = done;
    let frames: Vec<(f64, f64, f64)> = model
        .frame_times
        .iter()
        .map(|(s, f, d)| {
            let s = s.map_or(f64::NAN, |t| t.as_ms_f64());
            (s, f.as_ms_f64(), d.map_or(f64::NAN, |t| t.as_ms_f64()))
        })
        .collect();
    let latency = frames[0].2 - frames[0].0;
    let front = frames[0].1 - frames[0].0;
    for (what, v) in [("latency", latency), ("front end time", front)] {
        if !v.is_finite() {
            return Err(bad(
                "primitives|display.width|display.height|region.width|region.height",
                format!(
                    "the simulated frame's {what} is not a finite number ({v}); check the sizes (display, region, primitive) and the costs"
                ),
            ));
        }
    }
    let summary = summary(
        &model.cfg,
        &analytic,
        Some(&stats),
        latency,
        front,
        stages,
        Some((&model.layout, &region_entries)),
        build_seconds + stats.wall_seconds,
        stats.wall_seconds,
        &frames,
    );
    Ok(PixelFlowRun {
        analytic,
        stats: Some(stats),
        records: std::mem::take(&mut model.records),
        region_entries,
        summary,
        spans: model.trace.take(),
        trace: None,
        config: model.cfg,
    })
}

/// Busy time per pipeline stage, milliseconds (the busiest unit of a stage
/// with several; the closed form's terms at `analytic` fidelity).
#[derive(Debug, Clone, Serialize)]
pub struct StagesMs {
    /// Geometry (the front end).
    pub geometry: f64,
    /// Generating region entries.
    pub generate: f64,
    /// Rasterizing.
    pub rasterize: f64,
    /// Composition network.
    pub composite: f64,
    /// Shading.
    pub shade: f64,
    /// Color transfer to the frame buffer (event simulation only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub color: Option<f64>,
    /// Loading the frame buffer.
    pub load: f64,
}

/// Region entries per screen region (a primitive counts once per region it
/// touches); each `null` when there are no regions.
#[derive(Debug, Clone, Serialize)]
pub struct EntryCounts {
    /// Fewest.
    pub min: Option<u64>,
    /// Most.
    pub max: Option<u64>,
    /// Mean.
    pub mean: Option<f64>,
}

/// A few statistics over frames; `null` with `count: 0` when there are no
/// values (one frame has no interval).
#[derive(Debug, Clone, Serialize)]
pub struct FrameStats {
    /// Values.
    pub count: usize,
    /// The first frame's.
    pub first: Option<f64>,
    /// The last frame's.
    pub last: Option<f64>,
    /// Mean.
    pub mean: Option<f64>,
    /// Largest.
    pub max: Option<f64>,
}

impl FrameStats {
    fn of(v: &[f64]) -> Self {
        let (first, last) = (v.first().copied(), v.last().copied());
        let mean = (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
        let max = (!v.is_empty()).then(|| v.iter().copied().fold(f64::MIN, f64::max));
        FrameStats {
            count: v.len(),
            first,
            last,
            mean,
            max,
        }
    }
}

/// One frame's instants, milliseconds.
#[derive(Debug, Clone, Serialize)]
pub struct FrameTimes {
    /// The frame started (its first primitive entered geometry).
    pub start_ms: f64,
    /// The front end finished it.
    pub front_end_done_ms: f64,
    /// Its last region was loaded.
    pub done_ms: f64,
    /// `done_ms - start_ms`.
    pub latency_ms: f64,
}

/// `metrics` of a PixelFlow summary.
#[derive(Debug, Clone, Serialize)]
pub struct PixelFlowMetrics {
    /// The first frame's latency (start to last region loaded).
    pub latency_ms: f64,
    /// The closed form's latency (paper 002 §4-6).
    pub analytic_latency_ms: f64,
    /// `(latency - analytic) / analytic` (0 when the closed form is 0).
    pub relative_error: f64,
    /// `relative_error` in percent.
    pub difference_pct: f64,
    /// The first frame's front end.
    pub front_end_ms: f64,
    /// The first frame's back end (`latency - front end`).
    pub back_end_ms: f64,
    /// The closed form's front end.
    pub analytic_front_end_ms: f64,
    /// The closed form's back end.
    pub analytic_back_end_ms: f64,
    /// Busy time per stage.
    pub stages_ms: StagesMs,
    /// Screen regions.
    pub regions: u32,
    /// The closed form's overlap factor.
    pub overlap: f64,
    /// The overlap of the simulated placement (the closed form's at
    /// `analytic` fidelity).
    pub realised_overlap: f64,
    /// Region entries per region (null at `analytic` fidelity).
    pub region_entries: Option<EntryCounts>,
    /// Every term of the closed form.
    pub analytic: Analytic,
    /// Latency over the frames.
    pub frame_latency_ms: FrameStats,
    /// Intervals between frames' ends.
    pub frame_interval_ms: FrameStats,
    /// Every frame's instants.
    pub per_frame: Vec<FrameTimes>,
    /// Primitives the closed form fits in 30 ms.
    pub analytic_primitives_at_30ms: f64,
    /// Primitives the closed form fits in 40 ms.
    pub analytic_primitives_at_40ms: f64,
}

/// The summary of a PixelFlow run (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct PixelFlowSummary {
    /// `"pixelflow"`.
    pub system: &'static str,
    /// The model's description.
    pub description: String,
    /// `analytic` or `event`.
    pub fidelity: Fidelity,
    /// The architecture.
    pub architecture: Architecture,
    /// Nodes.
    pub nodes: u32,
    /// Nodes that rasterize.
    pub rasterizers: u32,
    /// Nodes that shade.
    pub shaders: u32,
    /// Samples per pixel.
    pub samples: u32,
    /// Primitives per frame.
    pub primitives: u64,
    /// How primitives are placed on the screen.
    pub placement: Placement,
    /// Load imbalance between nodes.
    pub node_skew: f64,
    /// Master seed.
    pub seed: u64,
    /// Frames simulated.
    pub frames: u32,
    /// Always 0 (every frame is reported).
    pub warmup_frames: u32,
    /// Kernel events (none at `analytic` fidelity).
    pub events: EventCounts,
    /// Wall time of the run.
    pub wall_seconds: f64,
    /// Wall time of the simulation alone.
    pub simulate_seconds: f64,
    /// The results.
    pub metrics: PixelFlowMetrics,
}

#[allow(clippy::too_many_arguments)]
fn summary(
    cfg: &PixelFlowConfig,
    a: &Analytic,
    stats: Option<&RunStats>,
    latency: f64,
    front: f64,
    stages: StagesMs,
    layout: Option<(&Layout, &Vec<u64>)>,
    wall: f64,
    simulate: f64,
    frames: &[(f64, f64, f64)],
) -> PixelFlowSummary {
    let events = match stats {
        Some(s) => EventCounts::of(s),
        None => EventCounts {
            total: 0,
            by_kind: Default::default(),
        },
    };
    let (realised, entries) = match layout {
        Some((l, e)) => (
            l.realised_overlap(),
            Some(EntryCounts {
                min: e.iter().copied().min(),
                max: e.iter().copied().max(),
                mean: (!e.is_empty()).then(|| e.iter().sum::<u64>() as f64 / e.len() as f64),
            }),
        ),
        None => (a.overlap, None),
    };
    let rel = if a.latency_ms > 0.0 {
        (latency - a.latency_ms) / a.latency_ms
    } else {
        0.0
    };
    let lat: Vec<f64> = frames.iter().map(|f| f.2 - f.0).collect();
    let intervals: Vec<f64> = frames.windows(2).map(|w| w[1].2 - w[0].2).collect();
    PixelFlowSummary {
        system: "pixelflow",
        description: cfg.description.clone(),
        fidelity: cfg.fidelity,
        architecture: cfg.architecture,
        nodes: cfg.nodes,
        rasterizers: cfg.rasterizers(),
        shaders: cfg.shaders(),
        samples: cfg.samples,
        primitives: cfg.primitives,
        placement: cfg.placement,
        node_skew: cfg.node_skew,
        seed: cfg.run.seed,
        frames: cfg.frames,
        warmup_frames: 0,
        events,
        wall_seconds: wall,
        simulate_seconds: simulate,
        metrics: PixelFlowMetrics {
            latency_ms: latency,
            analytic_latency_ms: a.latency_ms,
            relative_error: rel,
            difference_pct: 100.0 * rel,
            front_end_ms: front,
            back_end_ms: latency - front,
            analytic_front_end_ms: a.front_end_ms,
            analytic_back_end_ms: a.back_end_ms,
            stages_ms: stages,
            regions: a.regions,
            overlap: a.overlap,
            realised_overlap: realised,
            region_entries: entries,
            analytic: a.clone(),
            frame_latency_ms: FrameStats::of(&lat),
            frame_interval_ms: FrameStats::of(&intervals),
            per_frame: frames
                .iter()
                .map(|f| FrameTimes {
                    start_ms: f.0,
                    front_end_done_ms: f.1,
                    done_ms: f.2,
                    latency_ms: f.2 - f.0,
                })
                .collect(),
            analytic_primitives_at_30ms: super::analytic::primitives_at(cfg, 30.0),
            analytic_primitives_at_40ms: super::analytic::primitives_at(cfg, 40.0),
        },
    }
}

/// Columns of the per-region table.
pub const COLUMNS: [&str; 9] = [
    "Frame",
    "Region",
    "Entries",
    "RasterizedMs",
    "CompositeStartMs",
    "CompositeDoneMs",
    "ShadeStartMs",
    "ShadeDoneMs",
    "LoadedMs",
];

/// The per-region table (NaN where a step does not apply).
pub fn region_rows(run: &PixelFlowRun) -> Vec<Vec<f64>> {
    let t = |x: Option<crate::engine::Time>| x.map_or(f64::NAN, |t| t.as_ms_f64());
    run.records
        .iter()
        .enumerate()
        .map(|(g, r)| {
            let n = run.region_entries.len().max(1);
            let j = g % n;
            vec![
                (g / n) as f64,
                j as f64,
                run.region_entries.get(j).copied().unwrap_or(0) as f64,
                t(r.rasterized),
                t(r.comp_start),
                t(r.comp_done),
                t(r.shade_start),
                t(r.shade_done),
                t(r.loaded),
            ]
        })
        .collect()
}

/// Writes the per-region table as CSV.
pub fn write_regions_csv(run: &PixelFlowRun, w: &mut dyn std::io::Write) -> std::io::Result<()> {
    crate::output::table::write_number_table(std::io::BufWriter::new(w), &COLUMNS, &region_rows(run))
}

/// Writes a Chrome/Perfetto trace: one process per node role, one thread
/// per node (or network direction); false if none was recorded.
pub fn write_trace(run: &PixelFlowRun, t: &mut TraceWriter) {
    let Some(spans) = &run.spans else {
        return;
    };
    for (i, role) in super::model::ROLES.iter().enumerate() {
        let pid = i as u32 + 1;
        t.process(pid, role);
        t.process_order(pid, pid);
    }
    let mut named = std::collections::BTreeSet::new();
    for s in spans {
        let pid = s.role as u32 + 1;
        let tid = s.unit;
        if named.insert((pid, tid)) {
            let name = match s.role {
                0 | 1 => format!("rasterizer {}", s.unit),
                2 => format!("shader {}", s.unit),
                3 => if s.unit == 0 {
                    "composition"
                } else {
                    "color to frame buffer"
                }
                .to_string(),
                _ => "frame-buffer memory".to_string(),
            };
            t.thread(pid, tid, &name);
        }
        t.span(pid, tid, s.name, s.start, s.end, Some(("index", s.arg as u64)));
    }
}
