//! The human-readable report of a frame-pipeline run (`rendersim run`),
//! from its JSON summary.

use std::io::{self, Write};

use serde_json::Value;

use crate::output::text::fixed;

/// Writes the report of the run whose summary is `s`.
pub fn write_report(s: &Value, w: &mut dyn Write) -> io::Result<()> {
    let m = &s["metrics"];
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    let frames = match s["stopped_by"].as_str() {
        Some("time_limit") | Some("event_limit") => format!(
            "{} of {} frames completed (stopped early: {} reached at {} s simulated)",
            s["frames"],
            s["frames_requested"],
            if s["stopped_by"] == "time_limit" {
                "run.until"
            } else {
                "run.max_events"
            },
            fixed(f(&s["simulated_seconds"]), 3)
        ),
        _ => format!("{} frames", s["frames"]),
    };
    writeln!(
        w,
        "{} ({}), {frames}, seed {}",
        s["model"].as_str().unwrap_or(""),
        s["fidelity"].as_str().unwrap_or(""),
        s["seed"]
    )?;
    for (name, key) in [
        ("frame time", "frame_time_ms"),
        ("display interval", "display_interval_ms"),
        ("display latency", "display_latency_ms"),
        ("GPU time", "gpu_time_ms"),
    ] {
        let v = &m[key];
        writeln!(
            w,
            "  {name:<18} mean {:>8} ms   p50 {:>8}   p99 {:>8}   max {:>8}",
            fixed(f(&v["mean"]), 3),
            fixed(f(&v["p50"]), 3),
            fixed(f(&v["p99"]), 3),
            fixed(f(&v["max"]), 3)
        )?;
    }
    writeln!(
        w,
        "  CPU busy {}%   GPU busy {}%   repeated refreshes {}   dropped frames {}",
        fixed(100.0 * f(&m["cpu_busy_fraction"]), 1),
        fixed(100.0 * f(&m["gpu_busy_fraction"]), 1),
        m["repeated_refreshes"],
        m["dropped_frames"]
    )?;
    let g = &m["frame_generation"];
    if g.is_object() {
        writeln!(
            w,
            "  frame generation: {} generated frames shown ({} replaced unshown), {} frames shown per second ({} rendered), hold-back mean {} ms",
            g["generated_shown"],
            g["generated_dropped"],
            fixed(f(&g["displayed_fps"]), 1),
            fixed(f(&g["rendered_fps"]), 1),
            fixed(f(&g["hold_back_ms"]["mean"]), 3)
        )?;
    }
    let t = &m["tearing"];
    if t.is_object() {
        writeln!(
            w,
            "  tearing: {} frames torn ({} per second), tear line median {} of the height from the top",
            t["torn_frames"],
            fixed(f(&t["torn_per_second"]), 1),
            fixed(f(&t["tear_line"]["p50"]), 3)
        )?;
    }
    if let Some(b) = m["bottleneck"].as_object() {
        let mut v: Vec<(&String, f64)> = b.iter().map(|(k, v)| (k, f(v))).collect();
        v.sort_by(|a, b| b.1.total_cmp(&a.1));
        let parts: Vec<String> = v
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
    }
    let a = &m["analytic"];
    writeln!(
        w,
        "  analytic per frame: CPU {} ms, GPU front end {} ms, geometry {} ms, fragment {} ms",
        fixed(f(&a["cpu_ms"]), 3),
        fixed(f(&a["gpu_front_end_ms"]), 3),
        fixed(f(&a["geometry_ms"]), 3),
        fixed(f(&a["fragment_ms"]), 3)
    )?;
    writeln!(
        w,
        "  {} events in {} s wall ({} M events/s), {} s simulated",
        s["events"]["total"],
        fixed(f(&s["wall_seconds"]), 3),
        fixed(f(&s["events_per_second"]) / 1e6, 2),
        fixed(f(&s["simulated_seconds"]), 3)
    )?;
    Ok(())
}
