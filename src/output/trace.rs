//! Chrome / Perfetto trace JSON (the "Trace Event Format"): one track per
//! unit (CPU, GPU front end, geometry, fragment, display), spans as complete
//! (`"X"`) events that never overlap on a track, and counter tracks for the
//! FIFO depths. Open it in ui.perfetto.dev or chrome://tracing.

use std::io::Write;

use serde_json::{Value, json};

use crate::engine::Time;
use crate::systems::frame_pipeline::PipelineRun;
use crate::systems::frame_pipeline::accounting::{CPU_STATES, FRAG_STATES, FRONT_STATES, GEOM_STATES, Track};

fn us(t: Time) -> f64 {
    t.0 as f64 / 1e6
}

/// Writes the frame pipeline's trace; false if the run recorded none.
pub fn write_pipeline_trace(run: &PipelineRun, w: &mut dyn Write) -> std::io::Result<bool> {
    let Some(log) = &run.trace else {
        return Ok(false);
    };
    let tracks = [
        (1, "CPU thread"),
        (2, "GPU front end"),
        (3, "GPU geometry"),
        (4, "GPU fragment"),
        (5, "Display"),
    ];
    let mut events: Vec<Value> =
        vec![json!({"ph": "M", "pid": 1, "name": "process_name", "args": {"name": "frame pipeline"}})];
    for (tid, name) in tracks {
        events.push(json!({"ph": "M", "pid": 1, "tid": tid, "name": "thread_name", "args": {"name": name}}));
        events.push(json!({"ph": "M", "pid": 1, "tid": tid, "name": "thread_sort_index", "args": {"sort_index": tid}}));
    }
    for s in &log.spans {
        let (tid, names): (u32, &[&str]) = match s.track {
            Track::Cpu => (1, &CPU_STATES),
            Track::Front => (2, &FRONT_STATES),
            Track::Geometry => (3, &GEOM_STATES),
            Track::Fragment => (4, &FRAG_STATES),
        };
        events.push(json!({
            "ph": "X", "pid": 1, "tid": tid, "name": names[s.state as usize],
            "ts": us(s.start), "dur": us(s.end) - us(s.start),
        }));
    }
    // Display: each shown frame from its appearance to the next change.
    let shown: Vec<(u64, Time)> = run
        .records
        .iter()
        .filter_map(|r| r.displayed.map(|d| (r.index, d)))
        .collect();
    for (i, (frame, t)) in shown.iter().enumerate() {
        let end = shown.get(i + 1).map(|n| n.1).unwrap_or(Time(t.0 + run.refresh.0));
        events.push(json!({"ph": "X", "pid": 1, "tid": 5, "name": format!("frame {frame}"), "ts": us(*t), "dur": us(end) - us(*t)}));
    }
    for r in &run.records {
        events.push(json!({"ph": "i", "pid": 1, "tid": 1, "s": "t", "name": format!("frame {} input", r.index), "ts": us(r.input)}));
    }
    for (t, v) in &log.command_fifo {
        events.push(json!({"ph": "C", "pid": 1, "name": "command FIFO", "ts": us(*t), "args": {"used": v}}));
    }
    for (t, v) in &log.triangle_fifo {
        events.push(json!({"ph": "C", "pid": 1, "name": "triangle FIFO", "ts": us(*t), "args": {"triangles": v}}));
    }
    let doc = json!({"traceEvents": events, "displayTimeUnit": "ms"});
    serde_json::to_writer(&mut *w, &doc)?;
    Ok(true)
}
