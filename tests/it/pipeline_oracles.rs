//! Pipeline oracles: geometry and fragment stages with a small FIFO between
//! them (paper 000 §4.5.1: time between max and sum of the two terms), the
//! draw-fidelity closed form against the triangle simulation, early-z draw
//! orders, and "build only what a scene uses".

use crate::common;
use common::{DEFAULT, FIXED, metric, run, scene_model};

/// 20,000 triangles, 1 ns of geometry each; 1% of them cover 100 px (100 ns
/// of fragments), the rest 0.001 px. G = 20 us, F = 20.02 us.
fn bimodal(depth: u32) -> String {
    scene_model(
        r#"name = "mix"
mesh = { triangles = 20000, acmr = 1.0 }
triangle_pixels = { kind = "mixture", parts = [ { weight = 0.99, dist = 0.001 }, { weight = 0.01, dist = 100.0 } ] }"#,
    )
    .replace("fifo_depth = 16", &format!("fifo_depth = {depth}"))
}

#[test]
fn fifo_depth_moves_frame_time_from_sum_to_max_monotonically() {
    // Totals over the run, in picoseconds: the realized geometry and
    // fragment busy times (the sampled sizes, not their expectation).
    let mut times = vec![];
    let mut bounds = (0.0, 0.0);
    let mut realized = (0.0, 0.0);
    for depth in [0u32, 1, 2, 4, 16, 64, 256, 1024, 100_000] {
        let r = run(&bimodal(depth), &["run.frames=2"]);
        let g = r.clocks.geometry[0] as f64;
        let f = r.clocks.fragment[0] as f64;
        bounds = (g.max(f), g + f);
        realized = (g, f);
        times.push(r.clocks.gpu[0] as f64);
    }
    let (max, sum) = bounds;
    assert!(
        times.windows(2).all(|w| w[1] <= w[0] + 1e-12),
        "not monotone: {times:?}"
    );
    assert!(
        (times[0] - sum).abs() / sum < 0.03,
        "one-slot time {} vs sum {sum}",
        times[0]
    );
    // Closed form for small depths D (the static view gives every depth the
    // same sizes): 2 frames x 20,000 triangles, g = 1 ns each; a big triangle
    // (100 ns of fragments) lets geometry run ahead by the D FIFO slots plus
    // the triangle it holds, so (D + 1) g per big triangle overlaps, and every
    // tiny triangle's 1 ps of fragments hides behind the next geometry step:
    //   T(D) = G + F - (D + 1) g n_big - n_tiny f_tiny.
    // It is exact while big triangles are more than D + 1 apart; the few
    // closer pairs (about 2 p n_big = 8 at D = 1) overlap less, a few ns in
    // all, so 0.1% of the sum (78 ns) bounds the gap. With D = 1 the time is
    // about 1% below the sum (0.8 us of 78 us), twice the D = 0 overlap.
    let (g_total, f_total) = realized;
    let (n, g, f_big, f_tiny) = (40_000.0, 1_000.0, 100_000.0, 1.0);
    let n_big = ((f_total - n * f_tiny) / (f_big - f_tiny)).round();
    assert!(
        (n_big * f_big + (n - n_big) * f_tiny - f_total).abs() < 0.5,
        "{n_big} {f_total}"
    );
    for (depth, t) in [(0.0, times[0]), (1.0, times[1])] {
        let closed = g_total + f_total - (depth + 1.0) * g * n_big - (n - n_big) * f_tiny;
        assert!(
            (t - closed).abs() < 1e-3 * sum,
            "depth {depth}: time {t} ps vs closed form {closed} ps (sum {sum})"
        );
    }
    assert!(
        times[1] < times[0] && times[1] > 0.985 * sum,
        "one-slot FIFO: {} not just below the sum {sum} (depth 0: {})",
        times[1],
        times[0]
    );
    let last = *times.last().unwrap();
    assert!((last - max).abs() / max < 0.03, "deep-FIFO time {last} vs max {max}");
    for t in &times {
        assert!(*t >= max * 0.999 && *t <= sum * 1.001, "{t} outside [{max}, {sum}]");
    }
}

#[test]
fn draw_fidelity_matches_triangle_fidelity_where_its_assumptions_hold() {
    // Uniform triangles, deep FIFO: both give max(G, F) plus fill.
    let m = scene_model(
        r#"name = "g"
mesh = "grid:64x64"
triangle_pixels = 3.0"#,
    );
    let tri = run(&m, &["fidelity=\"triangle\""]);
    let draw = run(&m, &["fidelity=\"draw\""]);
    let (a, b) = (
        metric(&tri, "metrics.gpu_time_ms.mean"),
        metric(&draw, "metrics.gpu_time_ms.mean"),
    );
    assert!((a - b).abs() / a < 0.01, "triangle {a} vs draw {b}");
    // The draw fidelity schedules no per-triangle events.
    let k = |r: &rendersim::systems::frame_pipeline::PipelineRun, name: &str| {
        r.stats.by_kind[r.stats.kind_names.iter().position(|n| *n == name).unwrap()]
    };
    assert_eq!(k(&draw, "geometry_triangle"), 0);
    assert_eq!(k(&tri, "geometry_triangle"), 3 * 64 * 64 * 2);
    assert!(draw.stats.events * 100 < tri.stats.events);
}

#[test]
fn draw_fidelity_also_lies_between_max_and_sum() {
    for depth in [0u32, 1, 8, 64] {
        let r = run(&bimodal(depth), &["fidelity=\"draw\"", "run.frames=2"]);
        let g = metric(&r, "metrics.analytic.geometry_ms");
        let f = metric(&r, "metrics.analytic.fragment_ms");
        let t = metric(&r, "metrics.gpu_time_ms.mean");
        assert!(
            t >= g.max(f) * 0.999 && t <= (g + f) * 1.001,
            "depth {depth}: {t} not in [{}, {}]",
            g.max(f),
            g + f
        );
    }
}

#[test]
fn front_to_back_shades_fewer_fragments_than_back_to_front() {
    let m = |order: &str| {
        scene_model(
            r#"name = "g"
mesh = "grid:32x32"
triangle_pixels = 50.0"#,
        )
        .replace(
            "depth_order = \"back_to_front\"",
            &format!("depth_order = \"{order}\"\ndepth_complexity = 4.0"),
        )
    };
    let t = |o: &str| metric(&run(&m(o), &[]), "metrics.analytic.fragment_ms");
    let (f2b, rnd, b2f) = (t("front_to_back"), t("random"), t("back_to_front"));
    assert!((f2b / b2f - 0.25).abs() < 1e-9, "{f2b} {b2f}");
    assert!((rnd / b2f - (1.0 + 0.5 + 1.0 / 3.0 + 0.25) / 4.0).abs() < 1e-9);
}

fn csv(r: &rendersim::systems::frame_pipeline::PipelineRun) -> String {
    let mut v = vec![];
    r.write_frames_csv(&mut v).unwrap();
    String::from_utf8(v).unwrap()
}

#[test]
fn unused_parts_are_not_built_and_zero_cost_parts_change_nothing() {
    // Noise off: no noise events. Zero-length tasks: identical frames.
    let off = run(
        DEFAULT,
        &[
            "noise.enabled=false",
            "run.frames=20",
            "run.warmup_frames=0",
            "fidelity=\"draw\"",
        ],
    );
    assert_eq!(
        off.stats.by_kind[8] + off.stats.by_kind[9],
        0,
        "{:?}",
        off.stats.by_kind
    );
    let zero = run(
        DEFAULT,
        &[
            "noise.periodic.0.duration=\"0ms\"",
            "noise.random.0.duration=\"0ms\"",
            "run.frames=20",
            "run.warmup_frames=0",
            "fidelity=\"draw\"",
        ],
    );
    assert!(zero.stats.by_kind[8] > 0);
    assert_eq!(csv(&off), csv(&zero));
    // Uploads that take no time and no GPU time: same frames as none.
    let base = [
        "noise.enabled=false",
        "run.frames=5",
        "run.warmup_frames=0",
        "gpu.command=\"0ms\"",
        "command_fifo.capacity=100000",
    ];
    let plain = run(DEFAULT, &base);
    let mut with_up = base.to_vec();
    with_up.extend(["workload.groups.1.geometry_upload=1", "bus.bandwidth=\"1000TB/s\""]);
    let up = run(DEFAULT, &with_up);
    assert_eq!(csv(&plain), csv(&up));
    assert!(up.commands.0 > plain.commands.0, "upload commands are issued");
    // Non-indexed draws skip the cache: same as an indexed draw with no cache and free index fetch.
    let g = |extra: &str| {
        scene_model(&format!(
            "name = \"g\"\nmesh = \"grid:16x16\"\ntriangle_pixels = 2.0\n{extra}"
        ))
    };
    let ni = run(&g("indexed = false"), &[]);
    let none = run(&g(""), &["gpu.geometry.vertex_cache=\"none\""]);
    assert_eq!(csv(&ni), csv(&none));
    // A fixed workload has no geometry or fragment events at all.
    let f = run(FIXED, &[]);
    assert_eq!(f.stats.by_kind[2..7].iter().sum::<u64>(), 0);
}

#[test]
fn vertex_cache_changes_geometry_time_by_actually_transformed_vertices() {
    let g = |mesh: &str| scene_model(&format!("name = \"g\"\nmesh = \"{mesh}\"\ntriangle_pixels = 0.0"));
    let shuffled = run(&g("grid:32x32:shuffled:3"), &[]);
    let optimized = run(&g("grid:32x32:optimized"), &[]);
    let tv = |r: &rendersim::systems::frame_pipeline::PipelineRun| {
        r.summary()["scene"]["transformed_vertices"].as_u64().unwrap() as f64
    };
    let geo = |r: &rendersim::systems::frame_pipeline::PipelineRun| metric(r, "metrics.analytic.geometry_ms");
    assert!(tv(&optimized) < 0.5 * tv(&shuffled));
    // 1 ns per transformed vertex, nothing else.
    assert!((geo(&shuffled) - tv(&shuffled) * 1e-6).abs() < 1e-9);
    assert!((geo(&optimized) - tv(&optimized) * 1e-6).abs() < 1e-9);
}

/// A traced run accounts every instant in full; an untraced one takes the
/// short cuts (a quiet front-end completion's accounting, a CPU step that
/// skips `settle` and `account`, a draw's end that accounts only the units
/// that can have moved): both must give the same results, also with system
/// tasks preempting the front end (stale quiet completions), a command FIFO
/// small enough to block the CPU (or a rendezvous), one frame in flight,
/// vsync off and mailbox presentation.
#[test]
fn tracing_does_not_change_results_at_either_fidelity() {
    use rendersim::config::ModelSource;
    use rendersim::systems::run_model;
    let stressed: &[&str] = &[
        "noise.periodic.0.target=\"gpu\"",
        "noise.random.0.target=\"gpu\"",
        "noise.random.0.rate=\"300Hz\"",
        "command_fifo.capacity=8",
    ];
    let draw_variants: &[&[&str]] = &[
        &["cpu.max_frames_ahead=1"],
        &["command_fifo.capacity=0"],
        &["command_fifo.capacity=1", "display.vsync=false"],
        &["display.present_mode=\"mailbox\"", "display.buffers=3"],
        // State changes that wait for the geometry stage (a setup job on
        // the front end once the stage is free; the draw's quick hand-off
        // steps aside), alone and under the stressed settings.
        &["gpu.state_change_stalls=true"],
        &[
            "gpu.state_change_stalls=true",
            "noise.periodic.0.target=\"gpu\"",
            "noise.random.0.target=\"gpu\"",
            "noise.random.0.rate=\"300Hz\"",
            "command_fifo.capacity=8",
        ],
        // Pacing and the display's other paths, traced and untraced alike.
        // (A short cut both take once skipped the limiter before the
        // present; tests/it/pacing.rs holds each place to its interval.)
        &[
            "display.vsync=false",
            "pacing.limit=\"40Hz\"",
            "pacing.limit_from=\"start\"",
        ],
        &[
            "display.vsync=false",
            "pacing.limit=\"40Hz\"",
            "pacing.limit_from=\"present\"",
        ],
        &[
            "display.vsync=false",
            "pacing.limit=\"40Hz\"",
            "pacing.limit_from=\"submit\"",
        ],
        &[
            "pacing.limit=\"40Hz\"",
            "pacing.limit_from=\"present\"",
            "command_fifo.capacity=8",
        ],
        &["display.vsync=false", "pacing.low_latency=true"],
        &[
            "display.vsync=false",
            "display.buffers=3",
            "frame_generation.enabled=true",
        ],
        &["display.present_mode=\"fifo_latest_ready\"", "display.buffers=3"],
        &["display.composition=\"composed\""],
        &["display.refresh=\"144Hz\"", "display.vrr.min_refresh=\"48Hz\""],
    ];
    for (fid, extra) in [
        ("triangle", &[][..]),
        ("draw", &[][..]),
        ("draw", stressed),
        ("triangle", &stressed[3..]),
        ("triangle", &["gpu.state_change_stalls=true"][..]),
    ]
    .into_iter()
    .chain(draw_variants.iter().map(|v| ("draw", *v)))
    {
        let src = ModelSource::from_text("d.toml", DEFAULT);
        let mut t = src.table().unwrap();
        for s in [
            format!("fidelity=\"{fid}\""),
            "run.frames=8".into(),
            "run.warmup_frames=0".into(),
        ]
        .into_iter()
        .chain(extra.iter().map(|s| s.to_string()))
        {
            rendersim::config::apply_set(&mut t, &s).unwrap();
        }
        let get = |trace: bool| {
            run_model(
                &src,
                &t,
                trace.then(|| rendersim::output::trace::TraceWriter::new(Box::new(std::io::sink()))),
            )
            .unwrap()
            .downcast::<rendersim::systems::frame_pipeline::PipelineRun>()
            .expect("a frame-pipeline run")
        };
        let (a, b) = (get(false), get(true));
        assert!(a.trace.is_none() && b.trace.is_some());
        assert_eq!(csv(&a), csv(&b), "{fid} {extra:?}");
        assert_eq!(a.clocks.geometry, b.clocks.geometry, "{fid}");
        assert_eq!(a.clocks.fragment, b.clocks.fragment, "{fid}");
        assert_eq!(a.clocks.bottleneck, b.clocks.bottleneck, "{fid}");
        assert_eq!(a.summary()["metrics"], b.summary()["metrics"], "{fid}");
        assert_eq!(a.clocks.cpu, b.clocks.cpu, "{fid}");
        assert_eq!(a.clocks.front, b.clocks.front, "{fid}");
        assert_eq!(a.clocks.gpu, b.clocks.gpu, "{fid}");
    }
}

#[test]
fn a_static_view_repeats_its_triangle_sizes_every_frame() {
    let m = scene_model(
        "name = \"g\"\nmesh = \"grid:20x20\"\ntriangle_pixels = { kind = \"lognormal\", median = 5.0, sigma = 1.0 }",
    );
    let gpu_ms = |view: &str| {
        let r = run(&m, &["run.frames=6", &format!("workload.view=\"{view}\"")]);
        r.records
            .iter()
            .map(|f| f.gpu_end.unwrap().0 - f.gpu_start.unwrap().0)
            .collect::<Vec<u64>>()
    };
    let s = gpu_ms("static");
    assert!(s.windows(2).all(|w| w[0] == w[1]), "{s:?}");
    let v = gpu_ms("varying");
    assert!(v.windows(2).any(|w| w[0] != w[1]), "{v:?}");
}

// ---- CPU cost model (paper 000 §4.3: per object, per draw, per state change
// by kind, memory management over the bus), against closed forms in
// picoseconds. Everything else costs nothing, so the CPU's work per frame is
// exactly the sum of the configured terms.

const US: u64 = 1_000_000;

/// CPU work (ps) of each frame and over the run.
fn cpu_work(r: &rendersim::systems::frame_pipeline::PipelineRun) -> (Vec<u64>, u64) {
    (r.records.iter().map(|f| f.cpu_busy).collect(), r.clocks.cpu[0])
}

#[test]
fn per_object_and_per_draw_costs_add_exactly_to_cpu_busy_time() {
    let m = scene_model("name = \"g\"\ncount = 10\nmesh = \"grid:1x1\"\ntriangle_pixels = 0.0");
    let sets = [
        "cpu.input_sampling=\"7us\"",
        "cpu.clear=\"3us\"",
        "cpu.swap=\"11us\"",
        "cpu.per_object=\"5us\"",
        "cpu.per_draw=\"2us\"",
    ];
    let r = run(&m, &sets);
    // 7 + 3 + 11 + 10 objects x (5 + 2) = 91 us per frame, exactly.
    let per_frame = (7 + 3 + 11 + 10 * (5 + 2)) * US;
    let (frames, total) = cpu_work(&r);
    assert_eq!(frames, vec![per_frame; 3]);
    assert_eq!(total, 3 * per_frame);
    assert!((metric(&r, "metrics.analytic.cpu_ms") - 0.091).abs() < 1e-12);
    // Each term counts: one more object adds exactly per_object + per_draw.
    let r11 = run(&m.replace("count = 10", "count = 11"), &sets);
    assert_eq!(cpu_work(&r11).0, vec![per_frame + 7 * US; 3]);
    // per_draw alone: 10 x 2 us.
    let only_draw = run(&m, &["cpu.per_draw=\"2us\""]);
    assert_eq!(cpu_work(&only_draw).0, vec![20 * US; 3]);
}

#[test]
fn state_changes_cost_per_kind_and_sorting_reduces_their_count() {
    // 8 instances cycling over 2 shaders and 2 textures, 1 material, no
    // per-object matrix. As listed the states go (0,0),(1,1),(0,0),(1,1)...:
    // every object changes shader and texture (8 + 8), the material is set
    // once. Sorted by (shader, texture, material): (0,0) x 4, (1,1) x 4, so
    // 2 shader and 2 texture changes.
    let m = scene_model(
        "name = \"g\"\ncount = 8\nshaders = 2\ntextures = 2\nmatrix_per_object = false\nmesh = \"grid:1x1\"\ntriangle_pixels = 0.0",
    );
    let costs = [
        "cpu.state_change.shader=\"40us\"",
        "cpu.state_change.texture=\"15us\"",
        "cpu.state_change.material=\"5us\"",
        "cpu.state_change.matrix=\"1us\"",
        "gpu.state_change.shader=\"20us\"",
        "gpu.state_change.texture=\"5us\"",
        "gpu.state_change.material=\"1us\"",
        "gpu.state_change.matrix=\"0.2us\"",
    ];
    let run_order = |order: &str, extra: &[&str]| {
        let mut s = costs.to_vec();
        let o = format!("workload.state_order=\"{order}\"");
        s.push(&o);
        s.extend_from_slice(extra);
        run(&m, &s)
    };
    let changes = |r: &rendersim::systems::frame_pipeline::PipelineRun| {
        ["shader", "texture", "material", "matrix"]
            .map(|k| r.summary()["scene"][format!("{k}_changes")].as_u64().unwrap())
    };
    // Front-end busy time over the run (ps); gpu.command, clear and swap cost nothing here.
    let front_busy = |r: &rendersim::systems::frame_pipeline::PipelineRun| r.clocks.front[0];

    let listed = run_order("as_listed", &[]);
    assert_eq!(changes(&listed), [8, 8, 1, 0]);
    let cpu_listed = (8 * 40 + 8 * 15 + 5) * US;
    assert_eq!(cpu_work(&listed).0, vec![cpu_listed; 3]);
    assert_eq!(front_busy(&listed), 3 * (8 * 20 + 8 * 5 + 1) * US);

    let sorted = run_order("sorted", &[]);
    assert_eq!(changes(&sorted), [2, 2, 1, 0]);
    let cpu_sorted = (2 * 40 + 2 * 15 + 5) * US;
    assert_eq!(cpu_work(&sorted).0, vec![cpu_sorted; 3]);
    assert_eq!(front_busy(&sorted), 3 * (2 * 20 + 2 * 5 + 1) * US);

    // A matrix per object: one more change of that kind per object.
    let mat = run_order("sorted", &["workload.groups.0.matrix_per_object=true"]);
    assert_eq!(changes(&mat), [2, 2, 1, 8]);
    assert_eq!(cpu_work(&mat).0, vec![cpu_sorted + 8 * US; 3]);
    assert_eq!(front_busy(&mat), 3 * ((2 * 20 + 2 * 5 + 1) * US + 8 * 200_000));
}

#[test]
fn upload_time_is_bytes_over_bus_bandwidth_exactly() {
    let m = scene_model("name = \"g\"\nmesh = \"grid:1x1\"\ntriangle_pixels = 0.0");
    let base = ["cpu.per_draw=\"10us\""];
    let none = run(&m, &base);
    assert_eq!(cpu_work(&none).0, vec![10 * US; 3]);
    // 4 MB (3 MB of geometry + 1 MB of texture) at 4 GB/s: 1.000 ms per frame.
    let with = |bw: &str| {
        let mut s = base.to_vec();
        let b = format!("bus.bandwidth=\"{bw}\"");
        s.extend([
            "workload.groups.0.geometry_upload=\"3MB\"",
            "workload.groups.0.texture_upload=\"1MB\"",
        ]);
        s.push(&b);
        run(&m, &s)
    };
    let up = with("4GB/s");
    assert_eq!(up.summary()["scene"]["upload_bytes"], 4_000_000);
    assert_eq!(cpu_work(&up).0, vec![10 * US + 1_000 * US; 3]);
    assert!((metric(&up, "metrics.analytic.cpu_ms") - metric(&none, "metrics.analytic.cpu_ms") - 1.0).abs() < 1e-12);
    // Half the bandwidth, twice the time; binary units are exact too (4 MiB at 4 GiB/s = 0.9765625 ms).
    assert_eq!(cpu_work(&with("2GB/s")).0, vec![10 * US + 2_000 * US; 3]);
    let mib = {
        let mut s = base.to_vec();
        s.extend(["workload.groups.0.geometry_upload=\"4MiB\"", "bus.bandwidth=\"4GiB/s\""]);
        run(&m, &s)
    };
    assert_eq!(cpu_work(&mib).0, vec![10 * US + 976_562_500; 3]);
}

/// A terrain-like draw whose triangle sizes are sorted (`size_order`).
fn sorted_sizes(order: &str) -> String {
    scene_model(&format!(
        r#"name = "terrain"
mesh = {{ triangles = 20000, acmr = 1.0 }}
triangle_pixels = {{ kind = "lognormal", median = 8.0, sigma = 0.8 }}
size_order = "{order}""#
    ))
    .replace("vertex_shader = \"1ns\"", "vertex_shader = \"11ns\"")
}

#[test]
fn sorted_triangle_sizes_move_the_split_bottleneck_inside_a_draw() {
    // Paper 000 §4.5.1: with the small triangles first and the large ones
    // last, geometry limits the first part of the draw and fragments the
    // rest, so the split pipeline overlaps less than with the same sizes in
    // random order (where a 16-triangle FIFO evens them out).
    let gpu = |order: &str, fid: &str| {
        let r = run(&sorted_sizes(order), &["run.frames=2", &format!("fidelity=\"{fid}\"")]);
        (
            r.clocks.gpu[0] as f64,
            r.clocks.geometry[0] as f64,
            r.clocks.fragment[0] as f64,
        )
    };
    let (random, g, f) = gpu("random", "triangle");
    let (ascending, ga, fa) = gpu("ascending", "triangle");
    let (descending, _, _) = gpu("descending", "triangle");
    assert!(random < 1.05 * g.max(f), "random {random} vs max {}", g.max(f));
    assert!(ascending > 1.1 * random, "ascending {ascending} vs random {random}");
    assert!(ascending <= ga + fa && descending > 1.1 * random);
    // The draw fidelity runs the same pipeline recursion on its own sample.
    for order in ["ascending", "descending"] {
        let (t, _, _) = gpu(order, "triangle");
        let (d, _, _) = gpu(order, "draw");
        assert!((d - t).abs() / t < 0.02, "{order}: draw {d} vs triangle {t}");
    }
}

#[test]
fn sorting_huge_draws_is_refused_naming_the_key() {
    let m = sorted_sizes("ascending").replace("triangles = 20000", "triangles = 100000000");
    let e = common::try_run(&m, &["run.frames=1"]).unwrap_err();
    assert!(e.contains("workload.groups.0.size_order"), "{e}");
}
