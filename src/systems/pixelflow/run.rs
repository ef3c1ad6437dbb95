//! Validating, running and summarizing a PixelFlow model.

use serde_json::{Value, json};

use crate::engine::{Duration, Limits, PS_PER_MS, RunStats, Scheduler, run};
use crate::output::trace::TraceWriter;

use super::analytic::{Analytic, closed_form};
use super::config::{Fidelity, PixelFlowConfig, Placement, Size};
use super::layout::{Layout, build};
use super::model::{PixelFlow, RegionRecord, Span};
use crate::systems::error::SystemError;

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
    /// The JSON summary.
    pub summary: Value,
    /// Timeline, when asked for.
    pub spans: Option<Vec<Span>>,
    /// The trace, when one was asked for: written, not yet closed.
    pub trace: Option<TraceWriter>,
}

fn bad(key: &str, message: impl Into<String>) -> SystemError {
    SystemError::Invalid {
        key: key.to_string(),
        message: message.into(),
    }
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

/// Checks what serde cannot.
pub fn validate(cfg: &PixelFlowConfig) -> Result<(), SystemError> {
    if cfg.system != "pixelflow" {
        return Err(bad("system", format!("expected \"pixelflow\", got {:?}", cfg.system)));
    }
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
    validate(&cfg)?;
    let t0 = std::time::Instant::now();
    let analytic = closed_form(&cfg);
    finite_closed_form(&cfg, &analytic)?;
    if cfg.fidelity == Fidelity::Analytic {
        let wall = t0.elapsed().as_secs_f64();
        let a = &analytic;
        let stages = json!({
            "geometry": a.t_front_ms, "generate": a.t_gen_ms, "rasterize": a.t_rast_ms,
            "composite": a.t_comp_ms, "shade": a.t_shade_ms, "load": a.t_load_ms,
        });
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
            config: cfg,
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
    let stages = json!({
        "geometry": max_ms(&b.geometry),
        "generate": max_ms(&b.generate),
        "rasterize": max_ms(&b.rasterize),
        "composite": ms(b.composite),
        "shade": max_ms(&b.shade),
        "color": ms(b.color),
        "load": ms(b.load),
    });
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

#[allow(clippy::too_many_arguments)]
fn summary(
    cfg: &PixelFlowConfig,
    a: &Analytic,
    stats: Option<&RunStats>,
    latency: f64,
    front: f64,
    stages: Value,
    layout: Option<(&Layout, &Vec<u64>)>,
    wall: f64,
    simulate: f64,
    frames: &[(f64, f64, f64)],
) -> Value {
    let (events, by_kind) = match stats {
        Some(s) => (
            s.events,
            Value::Object(
                s.kind_names
                    .iter()
                    .zip(&s.by_kind)
                    .map(|(n, c)| (n.to_string(), json!(c)))
                    .collect(),
            ),
        ),
        None => (0, json!({})),
    };
    let (realised, entries) = match layout {
        Some((l, e)) => {
            let max = e.iter().copied().max().unwrap_or(0);
            let min = e.iter().copied().min().unwrap_or(0);
            let mean = e.iter().sum::<u64>() as f64 / e.len().max(1) as f64;
            (l.realised_overlap(), json!({"min": min, "max": max, "mean": mean}))
        }
        None => (a.overlap, Value::Null),
    };
    let rel = if a.latency_ms > 0.0 {
        (latency - a.latency_ms) / a.latency_ms
    } else {
        0.0
    };
    let lat: Vec<f64> = frames.iter().map(|f| f.2 - f.0).collect();
    let intervals: Vec<f64> = frames.windows(2).map(|w| w[1].2 - w[0].2).collect();
    // Like every summary's statistics: `count`, and with no values (one
    // frame has no interval) the other fields null.
    let stat = |v: &[f64]| -> Value {
        if v.is_empty() {
            return json!({"count": 0, "first": null, "last": null, "mean": null, "max": null});
        }
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let max = v.iter().copied().fold(f64::MIN, f64::max);
        json!({"count": v.len(), "first": v[0], "last": v[v.len() - 1], "mean": mean, "max": max})
    };
    let frame_rows: Vec<Value> = frames
        .iter()
        .map(|f| json!({"start_ms": f.0, "front_end_done_ms": f.1, "done_ms": f.2, "latency_ms": f.2 - f.0}))
        .collect();
    json!({
        "system": "pixelflow",
        "description": cfg.description,
        "fidelity": cfg.fidelity,
        "architecture": cfg.architecture,
        "nodes": cfg.nodes,
        "rasterizers": cfg.rasterizers(),
        "shaders": cfg.shaders(),
        "samples": cfg.samples,
        "primitives": cfg.primitives,
        "placement": cfg.placement,
        "node_skew": cfg.node_skew,
        "seed": cfg.run.seed,
        "frames": cfg.frames,
        "warmup_frames": 0,
        "events": {"total": events, "by_kind": by_kind},
        "wall_seconds": wall,
        "simulate_seconds": simulate,
        "metrics": {
            "latency_ms": latency,
            "analytic_latency_ms": a.latency_ms,
            "relative_error": rel,
            "difference_pct": 100.0 * rel,
            "front_end_ms": front,
            "back_end_ms": latency - front,
            "analytic_front_end_ms": a.front_end_ms,
            "analytic_back_end_ms": a.back_end_ms,
            "stages_ms": stages,
            "regions": a.regions,
            "overlap": a.overlap,
            "realised_overlap": realised,
            "region_entries": entries,
            "analytic": a,
            "frame_latency_ms": stat(&lat),
            "frame_interval_ms": stat(&intervals),
            "per_frame": frame_rows,
            "analytic_primitives_at_30ms": super::analytic::primitives_at(cfg, 30.0),
            "analytic_primitives_at_40ms": super::analytic::primitives_at(cfg, 40.0),
        },
    })
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
    use crate::output::table::{number, write_table};
    let rows = region_rows(run)
        .into_iter()
        .map(|r| r.iter().map(|&v| number(v)).collect());
    write_table(std::io::BufWriter::new(w), &COLUMNS, rows)
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
