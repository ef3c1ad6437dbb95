//! The lines the command line prints for results that are not a run's
//! report: benchmarks and measurements.

use rendersim::bench::{HourBench, KernelBench, PipelineBench, PixelflowBench};

/// The PixelFlow benchmark's line.
pub fn pixelflow_bench(p: &PixelflowBench) -> String {
    let (counts, runs, events, wall, target, closed) = (p.counts, p.runs, p.events, p.wall_s, p.target_s, p.closed_s);
    format!(
        "pixelflow Figures 3 and 4 at event fidelity, one thread: {runs} runs ({counts} primitive counts x 3 architectures x 2 shader counts x 2 sample counts), {events} events, {wall:.3} s wall ({:.2} ms per run); target <= {target:.3} s: ratio {:.4} of the target ({}); closed forms (analytic fidelity, same runs) {closed:.3} s, event / closed form {:.1}x",
        1e3 * wall / runs as f64,
        wall / target,
        if wall <= target { "met" } else { "MISSED" },
        wall / closed.max(1e-9)
    )
}

/// One kernel case's line.
pub fn kernel_bench(k: &KernelBench) -> String {
    format!(
        "kernel {}, {} pending: engine {:.2} M events/s ({:.1} ns/event; binary-heap queue {:.2} M events/s), bare BinaryHeap {:.2} M events/s, ratio {:.3}",
        k.work.name(),
        k.population,
        k.engine_events_per_s / 1e6,
        1e9 / k.engine_events_per_s,
        k.engine_binary_events_per_s / 1e6,
        k.bare_events_per_s / 1e6,
        k.ratio
    )
}

/// The pipeline benchmark's line.
pub fn pipeline_bench(p: &PipelineBench) -> String {
    let w = p.width;
    format!(
        "pipeline, one frame of grid:{w}x{w} ({} triangles): triangle fidelity {:.3} s in total ({:.3} s event loop, {} events), draw fidelity {:.3} s in total ({:.6} s event loop, {} events); speed-up {:.1}x in total, {:.0}x in the event loop (the shared mesh build and cache simulation take {:.3} s); GPU time {:.3} ms vs {:.3} ms ({:+.3}%)",
        p.triangles,
        p.triangle_total_s,
        p.triangle_simulate_s,
        p.triangle_events,
        p.draw_total_s,
        p.draw_simulate_s,
        p.draw_events,
        p.triangle_total_s / p.draw_total_s,
        p.triangle_simulate_s / p.draw_simulate_s,
        p.draw_total_s - p.draw_simulate_s,
        p.triangle_gpu_ms,
        p.draw_gpu_ms,
        100.0 * (p.draw_gpu_ms - p.triangle_gpu_ms) / p.triangle_gpu_ms
    )
}

/// The hour benchmark's line.
pub fn hour_bench(h: &HourBench) -> String {
    format!(
        "one {:.0}-second run of the default model at draw fidelity ({} frames, noise on): {:.3} s wall, {} events ({:.2} M events/s); yardstick beside it (bare BinaryHeap hold loop, 1,000 pending): {:.2} M events/s, so the run took as long as {:.1} M yardstick events",
        h.simulated_seconds,
        h.frames,
        h.wall_s,
        h.events,
        h.events_per_second / 1e6,
        h.yardstick_events_per_s / 1e6,
        h.yardstick_m_events
    )
}

/// The replay benchmark's line: the replay against reading the CSV alone.
pub fn replay_bench(b: &rendersim::bench::replay::ReplayBench) -> String {
    let ms = |s: f64| format!("{:.2} ms", s * 1e3);
    format!(
        "replay: a {}-frame PresentMon 2 capture ({:.1} MB), median of {}: reading the CSV {}, replaying it {} (the frame pipeline's run {}), {:.2}x reading alone, {:.0} frames replayed per second; agreement {:.1}%",
        b.frames,
        b.bytes as f64 / 1e6,
        b.reps,
        ms(b.read_s),
        ms(b.replay_s),
        ms(b.simulate_s),
        b.replay_s / b.read_s,
        b.frames as f64 / b.replay_s,
        100.0 * b.agreement
    )
}

/// The build benchmark's lines: the reordering, fast against direct, then
/// each model's build, event loop and whole run at both fidelities.
pub fn build_bench(b: &rendersim::bench::build::BuildBench) -> String {
    let ms = |s: f64| format!("{:.3} ms", s * 1e3);
    let mut lines = Vec::new();
    for r in &b.reorders {
        lines.push(format!(
            "build: vertex-cache reordering of {} ({} triangles), median of {}: direct form {}, fast form {}, {:.1}x faster, same index buffer",
            r.spec,
            r.triangles,
            r.reps,
            ms(r.reference_s),
            ms(r.fast_s),
            r.reference_s / r.fast_s
        ));
    }
    for m in &b.models {
        let (t, d) = (&m.triangle, &m.draw);
        lines.push(format!(
            "build: model {} (10 frames after 2 warm-up, no noise), median of {}: triangle fidelity build {} + event loop {} = {}; draw fidelity build {} + event loop {} = {}; whole run {:.1}x faster at draw fidelity (event loop {:.0}x)",
            m.model,
            m.reps,
            ms(t.build_s),
            ms(t.simulate_s),
            ms(t.wall_s),
            ms(d.build_s),
            ms(d.simulate_s),
            ms(d.wall_s),
            t.wall_s / d.wall_s,
            t.simulate_s / d.simulate_s
        ));
    }
    lines.join("\n")
}

/// A measurement's line.
#[cfg(feature = "wgpu")]
pub fn measurement(mesh: &str, r: &rendersim::measure::Measurement) -> String {
    format!(
        "{mesh} on {} ({}, {}): VS invocations {}, clipper invocations {}, FS invocations {}, pass {:.3} ms (median of {}){}",
        r.adapter.name,
        r.adapter.driver,
        r.adapter.device_type,
        r.vs_invocations,
        r.clipper_invocations,
        r.fs_invocations,
        r.pass_time_ns / 1e6,
        r.pass_times_ns.len(),
        if r.stable_counters {
            ""
        } else {
            "; counters varied between repeats"
        }
    )
}
