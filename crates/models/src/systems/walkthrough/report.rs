//! The human-readable report of a walkthrough (`rendersim run`), from its
//! typed summary.

use std::io::{self, Write};

use crate::output::text::{fixed, number};
use crate::systems::summary::name_of;

use super::summary::WalkthroughSummary;

/// Writes the report of the run of the model named `model` whose summary is `s`.
pub fn write_report(s: &WalkthroughSummary, model: &str, w: &mut dyn Write) -> io::Result<()> {
    let m = &s.metrics;
    let sc = &s.scene;
    writeln!(
        w,
        "{model} (walkthrough, {}), {} frames along a {} path of {} m, seed {}",
        name_of(&s.fidelity),
        s.frames,
        s.camera.path,
        fixed(s.camera.length_m, 1),
        s.seed
    )?;
    writeln!(
        w,
        "scene: {} ({} objects, {} triangles, {} transformed vertices/triangle, {} view cells visited)",
        s.preset.as_deref().unwrap_or("listed objects"),
        sc.objects,
        sc.triangles,
        fixed(sc.transformed_per_triangle, 2),
        s.camera.view_cells_visited
    )?;
    writeln!(
        w,
        "frame time: mean {} ms, p99 {} ms, max {} ms; budget {} ms, {} frames over budget; {} objects drawn per frame on average",
        fixed(number(m.frame_time_ms.mean), 3),
        fixed(number(m.frame_time_ms.p99), 3),
        fixed(number(m.frame_time_ms.max), 3),
        fixed(m.budget_ms, 3),
        m.frames_over_budget,
        fixed(number(m.visible_objects.mean), 1)
    )?;
    write_estimation(s, w)?;
    let l = &m.lod;
    writeln!(
        w,
        "lod: policy {} (target {} ms); {} frame skips ({} per minute of {} s displayed); benefit {} per frame ({} of all finest); {} level switches per second; mean level {}, {} dropped per frame",
        l.policy,
        fixed(l.target_ms, 3),
        m.frame_skips,
        fixed(m.frame_skips_per_minute, 2),
        fixed(m.displayed_seconds, 2),
        fixed(m.benefit_mean, 0),
        fixed(m.benefit_fraction, 3),
        fixed(m.lod_switches_per_second, 1),
        fixed(l.mean_level, 2),
        fixed(l.dropped_per_frame, 2)
    )?;
    if let Some(b) = &l.branch {
        writeln!(
            w,
            "  conditional branch: {} tokens per frame, {} objects switched in {} frames ({} prefix runs)",
            fixed(b.tokens_per_frame, 2),
            b.switched_objects,
            b.frames_with_switch,
            b.prefix_runs
        )?;
    }
    for n in &l.notes {
        writeln!(w, "  note: {n}")?;
    }
    writeln!(
        w,
        "{} events in {} frame-pipeline runs, {} s wall ({} s preprocess, {} s frames)",
        s.events.total,
        s.pipeline_runs,
        fixed(s.wall_seconds, 3),
        fixed(s.build_seconds, 3),
        fixed(s.simulate_seconds, 3)
    )
}

/// The estimators' table, the view-cell preprocess and the clock it was
/// timed with.
fn write_estimation(s: &WalkthroughSummary, w: &mut dyn Write) -> io::Result<()> {
    let e = &s.metrics.estimation;
    writeln!(
        w,
        "estimation (empty frame {} ms, {} fit samples):",
        fixed(e.empty_frame_ms, 3),
        e.fit_samples
    )?;
    writeln!(
        w,
        "  estimator   mse (ms^2)   mean error (ms)   underestimated   cost (us/frame)"
    )?;
    for (name, x) in e.scores() {
        let Some(x) = x else {
            continue;
        };
        writeln!(
            w,
            "  {name:<9} {:>12} {:>17} {:>16} {:>17}",
            fixed(number(x.mse_ms2), 4),
            fixed(number(x.mean_error_ms), 4),
            fixed(number(x.underestimated_fraction), 3),
            fixed(x.cost_us_per_frame, 2)
        )?;
    }
    if let Some(v) = &e.view_cells {
        writeln!(
            w,
            "view cells: {} of {} cells built (those the path visits), {} directions; vcs {} sample views ({} s), pvc {} object bounds ({} s)",
            v.cells,
            v.cells_in_grid,
            v.directions,
            v.vcs_renders,
            fixed(v.vcs_preprocess_seconds, 3),
            v.pvc_bounds,
            fixed(v.pvc_preprocess_seconds, 3)
        )?;
    }
    if let Some(t) = &e.timing {
        writeln!(
            w,
            "preprocess timed with a CPU clock around a finish: overhead {} ms, jitter {} ms, {} readings",
            fixed(t.overhead_ms, 4),
            fixed(t.noise_ms, 4),
            t.readings
        )?;
    }
    Ok(())
}
