//! The lines the command line prints for results that are not a run's
//! report: benchmarks and measurements.

use rendersim::bench::spread::Spread;
use rendersim::bench::{HourBench, KernelBench, PipelineBench, PixelflowBench};

/// `(median, min-max)` of a spread in milliseconds: `2.41 ms (2.38-2.60)`.
fn ms(s: &Spread, decimals: usize) -> String {
    s.show(1e3, decimals, " ms")
}

/// Seconds: `1.103 s (1.090-1.150)`.
fn secs(s: &Spread) -> String {
    s.show(1.0, 3, " s")
}

/// A ratio: `1.87x (1.80-1.95)`.
fn times(s: &Spread, decimals: usize) -> String {
    s.show(1.0, decimals, "x")
}

/// How many repeats the figures of a line are over.
fn over(n: usize) -> String {
    format!("median (min-max) of {n}")
}

/// The PixelFlow benchmark's line.
pub fn pixelflow_bench(p: &PixelflowBench) -> String {
    let (counts, runs, events, target) = (p.counts, p.runs, p.events, p.target_s);
    let wall = p.wall_s.median;
    format!(
        "pixelflow Figures 3 and 4 at event fidelity, one thread, {}: {runs} runs ({counts} primitive counts x 3 architectures x 2 shader counts x 2 sample counts), {events} events, {} wall ({:.2} ms per run); target <= {target:.3} s: median {:.4} of the target ({}); closed forms (analytic fidelity, same runs) {}, event / closed form {}",
        over(p.repeats),
        secs(&p.wall_s),
        1e3 * wall / runs as f64,
        wall / target,
        if p.wall_s.max <= target {
            "met on every repeat"
        } else if wall <= target {
            "met at the median"
        } else {
            "MISSED"
        },
        secs(&p.closed_s),
        times(&p.ratio, 1)
    )
}

/// One kernel case's line.
pub fn kernel_bench(k: &KernelBench) -> String {
    let m = |s: &Spread| s.show(1e-6, 2, " M events/s");
    format!(
        "kernel {}, {} pending, {} slices of {} events: engine {}, {}; binary-heap queue {}; bare BinaryHeap {}; engine / bare {}",
        k.work.name(),
        k.population,
        over(k.repeats),
        k.events,
        m(&k.engine_events_per_s),
        k.engine_events_per_s.map(|r| 1e9 / r).show(1.0, 1, " ns/event"),
        m(&k.engine_binary_events_per_s),
        m(&k.bare_events_per_s),
        times(&k.ratio, 3)
    )
}

/// The pipeline benchmark's line.
pub fn pipeline_bench(p: &PipelineBench) -> String {
    let w = p.width;
    format!(
        "pipeline, one frame of grid:{w}x{w} ({} triangles), {}: triangle fidelity {} in total ({} event loop, {} events), draw fidelity {} in total ({} event loop, {} events); speed-up {} in total, {} in the event loop (the shared mesh build and cache simulation take {:.3} ms); GPU time {:.3} ms vs {:.3} ms ({:+.3}%)",
        p.triangles,
        over(p.repeats),
        ms(&p.triangle_total_s, 3),
        ms(&p.triangle_simulate_s, 3),
        p.triangle_events,
        ms(&p.draw_total_s, 3),
        ms(&p.draw_simulate_s, 4),
        p.draw_events,
        times(&p.speedup, 1),
        times(&p.simulate_speedup, 0),
        1e3 * (p.draw_total_s.median - p.draw_simulate_s.median),
        p.triangle_gpu_ms,
        p.draw_gpu_ms,
        100.0 * (p.draw_gpu_ms - p.triangle_gpu_ms) / p.triangle_gpu_ms
    )
}

/// The hour benchmark's line.
pub fn hour_bench(h: &HourBench) -> String {
    format!(
        "one {:.0}-second run of the default model at draw fidelity ({} frames, noise on), {}: {} wall, {} events ({}); yardstick beside each run (bare BinaryHeap hold loop, 1,000 pending): {}, so a run took as long as {} yardstick events",
        h.simulated_seconds,
        h.frames,
        over(h.repeats),
        secs(&h.wall_s),
        h.events,
        h.events_per_second.show(1e-6, 2, " M events/s"),
        h.yardstick_events_per_s.show(1e-6, 2, " M events/s"),
        h.yardstick_m_events.show(1.0, 1, " M")
    )
}

/// The replay benchmark's line: the replay against reading the CSV alone.
pub fn replay_bench(b: &rendersim::bench::replay::ReplayBench) -> String {
    format!(
        "replay: a {}-frame PresentMon 2 capture ({:.1} MB), {}: reading the CSV {}, replaying it {} (the frame pipeline's run {}), {} reading alone, {:.0} frames replayed per second at the median; agreement {:.1}%",
        b.frames,
        b.bytes as f64 / 1e6,
        over(b.reps),
        ms(&b.read_s, 2),
        ms(&b.replay_s, 2),
        ms(&b.simulate_s, 2),
        times(&b.ratio, 2),
        b.frames as f64 / b.replay_s.median,
        100.0 * b.agreement
    )
}

/// The build benchmark's lines: the reordering, fast against direct, then
/// each model's build, event loop and whole run at both fidelities.
pub fn build_bench(b: &rendersim::bench::build::BuildBench) -> String {
    let mut lines = Vec::new();
    for r in &b.reorders {
        lines.push(format!(
            "build: vertex-cache reordering of {} ({} triangles), {}: direct form {}, fast form {}, {} faster, same index buffer",
            r.spec,
            r.triangles,
            over(r.reps),
            ms(&r.reference_s, 3),
            ms(&r.fast_s, 3),
            times(&r.speedup, 1)
        ));
    }
    for m in &b.models {
        let (t, d) = (&m.triangle, &m.draw);
        lines.push(format!(
            "build: model {} (10 frames after 2 warm-up, no noise), {}: triangle fidelity build {} + event loop {} = {}; draw fidelity build {} + event loop {} = {}; whole run {} faster at draw fidelity (event loop {})",
            m.model,
            over(m.reps),
            ms(&t.build_s, 3),
            ms(&t.simulate_s, 3),
            ms(&t.wall_s, 3),
            ms(&d.build_s, 3),
            ms(&d.simulate_s, 3),
            ms(&d.wall_s, 3),
            times(&m.speedup, 1),
            times(&m.simulate_speedup, 0)
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
