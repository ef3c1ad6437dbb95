//! The human-readable report of a walkthrough (`rendersim run`), from its
//! summary.

use std::io::{self, Write};

use serde_json::Value;

use crate::output::text::fixed;

/// Writes the report of the run whose summary is `s`.
pub fn write_report(s: &Value, w: &mut dyn Write) -> io::Result<()> {
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    let m = &s["metrics"];
    let sc = &s["scene"];
    writeln!(
        w,
        "{} (walkthrough, {}), {} frames along a {} path of {} m, seed {}",
        s["model"].as_str().unwrap_or(""),
        s["fidelity"].as_str().unwrap_or(""),
        s["frames"],
        s["camera"]["path"].as_str().unwrap_or(""),
        fixed(f(&s["camera"]["length_m"]), 1),
        s["seed"]
    )?;
    writeln!(
        w,
        "scene: {} ({} objects, {} triangles, {} transformed vertices/triangle, {} view cells visited)",
        s["preset"].as_str().unwrap_or("listed objects"),
        sc["objects"],
        sc["triangles"],
        fixed(f(&sc["transformed_per_triangle"]), 2),
        s["camera"]["view_cells_visited"]
    )?;
    writeln!(
        w,
        "frame time: mean {} ms, p99 {} ms, max {} ms; budget {} ms, {} frames over budget; {} objects drawn per frame on average",
        fixed(f(&m["frame_time_ms"]["mean"]), 3),
        fixed(f(&m["frame_time_ms"]["p99"]), 3),
        fixed(f(&m["frame_time_ms"]["max"]), 3),
        fixed(f(&m["budget_ms"]), 3),
        m["frames_over_budget"],
        fixed(f(&m["visible_objects"]["mean"]), 1)
    )?;
    let e = &m["estimation"];
    writeln!(
        w,
        "estimation (empty frame {} ms, {} fit samples):",
        fixed(f(&e["empty_frame_ms"]), 3),
        e["fit_samples"]
    )?;
    writeln!(
        w,
        "  estimator   mse (ms^2)   mean error (ms)   underestimated   cost (us/frame)"
    )?;
    for name in super::estimators::ESTIMATORS {
        let x = &e[name];
        if x.is_null() {
            continue;
        }
        writeln!(
            w,
            "  {name:<9} {:>12} {:>17} {:>16} {:>17}",
            fixed(f(&x["mse_ms2"]), 4),
            fixed(f(&x["mean_error_ms"]), 4),
            fixed(f(&x["underestimated_fraction"]), 3),
            fixed(f(&x["cost_us_per_frame"]), 2)
        )?;
    }
    let v = &e["view_cells"];
    if !v.is_null() {
        writeln!(
            w,
            "view cells: {} of {} cells built (those the path visits), {} directions; vcs {} sample views ({} s), pvc {} object bounds ({} s)",
            v["cells"],
            v["cells_in_grid"],
            v["directions"],
            v["vcs_renders"],
            fixed(f(&v["vcs_preprocess_seconds"]), 3),
            v["pvc_bounds"],
            fixed(f(&v["pvc_preprocess_seconds"]), 3)
        )?;
    }
    let t = &e["timing"];
    if !t.is_null() {
        writeln!(
            w,
            "preprocess timed with a CPU clock around a finish: overhead {} ms, jitter {} ms, {} readings",
            fixed(f(&t["overhead_ms"]), 4),
            fixed(f(&t["noise_ms"]), 4),
            t["readings"]
        )?;
    }
    let l = &m["lod"];
    writeln!(
        w,
        "lod: policy {} (target {} ms); {} frame skips ({} per minute of {} s displayed); benefit {} per frame ({} of all finest); {} level switches per second; mean level {}, {} dropped per frame",
        l["policy"].as_str().unwrap_or(""),
        fixed(f(&l["target_ms"]), 3),
        m["frame_skips"],
        fixed(f(&m["frame_skips_per_minute"]), 2),
        fixed(f(&m["displayed_seconds"]), 2),
        fixed(f(&m["benefit_mean"]), 0),
        fixed(f(&m["benefit_fraction"]), 3),
        fixed(f(&m["lod_switches_per_second"]), 1),
        fixed(f(&l["mean_level"]), 2),
        fixed(f(&l["dropped_per_frame"]), 2)
    )?;
    if let Some(b) = l.get("branch") {
        writeln!(
            w,
            "  conditional branch: {} tokens per frame, {} objects switched in {} frames ({} prefix runs)",
            fixed(f(&b["tokens_per_frame"]), 2),
            b["switched_objects"],
            b["frames_with_switch"],
            b["prefix_runs"]
        )?;
    }
    if let Some(notes) = l["notes"].as_array() {
        for n in notes {
            writeln!(w, "  note: {}", n.as_str().unwrap_or(""))?;
        }
    }
    writeln!(
        w,
        "{} events in {} frame-pipeline runs, {} s wall ({} s preprocess, {} s frames)",
        s["events"]["total"],
        s["pipeline_runs"],
        fixed(f(&s["wall_seconds"]), 3),
        fixed(f(&s["build_seconds"]), 3),
        fixed(f(&s["simulate_seconds"]), 3)
    )
}
