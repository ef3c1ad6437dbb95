//! The human-readable report of a frame-pipeline run (`rendersim run`),
//! from its typed summary.

use std::io::{self, Write};

use crate::engine::StopReason;
use crate::output::text::{fixed, number};
use crate::systems::summary::name_of;

use super::summary::PipelineSummary;

/// Writes the report of the run of the model named `model` whose summary is `s`.
pub fn write_report(s: &PipelineSummary, model: &str, w: &mut dyn Write) -> io::Result<()> {
    let m = &s.metrics;
    let frames = match s.stopped_by {
        StopReason::TimeLimit | StopReason::EventLimit => format!(
            "{} of {} frames completed (stopped early: {} reached at {} s simulated)",
            s.frames,
            s.frames_requested,
            if s.stopped_by == StopReason::TimeLimit {
                "run.until"
            } else {
                "run.max_events"
            },
            fixed(s.simulated_seconds, 3)
        ),
        StopReason::Model | StopReason::Exhausted => format!("{} frames", s.frames),
    };
    writeln!(w, "{model} ({}), {frames}, seed {}", name_of(&s.fidelity), s.seed)?;
    for (name, v) in [
        ("frame time", &m.frame_time_ms),
        ("display interval", &m.display_interval_ms),
        ("display latency", &m.display_latency_ms),
        ("GPU time", &m.gpu_time_ms),
    ] {
        writeln!(
            w,
            "  {name:<18} mean {:>8} ms   p50 {:>8}   p99 {:>8}   max {:>8}",
            fixed(number(v.mean), 3),
            fixed(number(v.p50), 3),
            fixed(number(v.p99), 3),
            fixed(number(v.max), 3)
        )?;
    }
    writeln!(
        w,
        "  CPU busy {}%   GPU busy {}%   repeated refreshes {}   dropped frames {}",
        fixed(100.0 * m.cpu_busy_fraction, 1),
        fixed(100.0 * m.gpu_busy_fraction, 1),
        m.repeated_refreshes,
        m.dropped_frames
    )?;
    if let Some(g) = &m.frame_generation {
        writeln!(
            w,
            "  frame generation: {} generated frames shown ({} replaced unshown), {} frames shown per second ({} rendered), hold-back mean {} ms",
            g.generated_shown,
            g.generated_dropped,
            fixed(g.displayed_fps, 1),
            fixed(g.rendered_fps, 1),
            fixed(number(g.hold_back_ms.mean), 3)
        )?;
    }
    if let Some(t) = &m.tearing {
        writeln!(
            w,
            "  tearing: {} frames torn ({} per second), tear line median {} of the height from the top",
            t.torn_frames,
            fixed(t.torn_per_second, 1),
            fixed(number(t.tear_line.p50), 3)
        )?;
    }
    let mut shares: Vec<(&String, f64)> = m.bottleneck.iter().map(|(k, v)| (k, *v)).collect();
    shares.sort_by(|a, b| b.1.total_cmp(&a.1));
    let parts: Vec<String> = shares
        .iter()
        .filter(|x| x.1 > 0.0005)
        .map(|(k, x)| format!("{k} {}%", fixed(100.0 * x, 1)))
        .collect();
    writeln!(
        w,
        "  bottleneck: {}",
        if parts.is_empty() {
            "none (no simulated time)".to_string()
        } else {
            parts.join(", ")
        }
    )?;
    let a = &m.analytic;
    writeln!(
        w,
        "  analytic per frame: CPU {} ms, GPU front end {} ms, geometry {} ms, fragment {} ms",
        fixed(a.cpu_ms, 3),
        fixed(a.gpu_front_end_ms, 3),
        fixed(a.geometry_ms, 3),
        fixed(a.fragment_ms, 3)
    )?;
    writeln!(
        w,
        "  {} events in {} s wall ({} M events/s), {} s simulated",
        s.events.total,
        fixed(s.wall_seconds, 3),
        fixed(s.events_per_second / 1e6, 2),
        fixed(s.simulated_seconds, 3)
    )?;
    Ok(())
}
