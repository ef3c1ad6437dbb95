//! Stiff and extreme cases: picosecond costs beside one-second periods, an
//! empty scene, a 10^8-triangle object, one- and zero-slot FIFOs, zero-cost
//! stages, time overflow. Nothing panics; no NaN reaches the output.

use crate::common;
use common::{FIXED, null_paths, run, scene_model, try_run};

fn no_nulls(r: &rendersim::systems::frame_pipeline::PipelineRun) {
    let mut n = vec![];
    null_paths(&r.summary(), "", &mut n);
    assert!(n.is_empty(), "{n:?}");
}

#[test]
fn picosecond_costs_beside_a_one_hertz_period_stay_exact() {
    let m = scene_model("name = \"g\"\nmesh = \"grid:8x8\"\ntriangle_pixels = 1.0")
        .replace("vertex_shader = \"1ns\"", "vertex_shader = \"1ps\"")
        .replace("per_fragment = \"1ns\"", "per_fragment = \"1ps\"")
        .replace("vsync = false", "vsync = true\nrefresh = \"1Hz\"");
    let r = run(&m, &["run.frames=30"]);
    // Each frame appears exactly on a whole second, 30 s in.
    let shown: Vec<u64> = r.records.iter().filter_map(|f| f.displayed.map(|t| t.0)).collect();
    assert_eq!(shown.len(), 30);
    for (i, t) in shown.iter().enumerate() {
        assert_eq!(*t, (i as u64 + 1) * 1_000_000_000_000, "frame {i}");
    }
    // Stage times are exact in picoseconds: 1 ps per transformed vertex and
    // 1 ps per triangle of fragments (128 triangles), over 30 frames.
    let tv = r.summary()["scene"]["transformed_vertices"].as_u64().unwrap();
    assert_eq!(r.clocks.geometry[0], 30 * tv);
    assert_eq!(r.clocks.fragment[0], 30 * 128);
    no_nulls(&r);
}

#[test]
fn an_empty_scene_still_clears_and_swaps() {
    let m = scene_model("name = \"g\"\ncount = 0\nmesh = \"grid:1x1\"\ntriangle_pixels = 1.0");
    let r = run(&m, &["run.frames=10", "gpu.clear=\"1ms\""]);
    assert_eq!(r.records.iter().filter(|f| f.displayed.is_some()).count(), 10);
    assert!((common::metric(&r, "metrics.gpu_time_ms.mean") - 1.0).abs() < 1e-12);
    no_nulls(&r);
}

#[test]
fn a_hundred_million_triangle_object_at_draw_fidelity() {
    let m = scene_model("name = \"huge\"\nmesh = { triangles = 100000000, acmr = 0.7 }\ntriangle_pixels = 0.5");
    let r = run(&m, &["fidelity=\"draw\"", "run.frames=2"]);
    let t = common::metric(&r, "metrics.gpu_time_ms.mean");
    // G = 7e7 ns = 70 ms, F = 5e7 ns = 50 ms: between max and sum.
    assert!((70.0..=120.0).contains(&t), "{t}");
    assert!(r.stats.events < 100);
    no_nulls(&r);
}

#[test]
fn one_slot_and_zero_slot_fifos_and_zero_cost_stages() {
    let m = scene_model("name = \"g\"\ncount = 5\nmesh = \"grid:6x6\"\ntriangle_pixels = 4.0");
    for cap in [0, 1] {
        for depth in [0, 1] {
            let r = run(
                &m,
                &[
                    &format!("command_fifo.capacity={cap}"),
                    &format!("gpu.fragment.fifo_depth={depth}"),
                    "run.frames=5",
                ],
            );
            assert_eq!(r.commands.0, r.commands.1);
            assert_eq!(r.records.iter().filter(|f| f.displayed.is_some()).count(), 5);
            no_nulls(&r);
        }
    }
    // Everything free: frames complete at time zero; nothing divides by zero.
    let free = run(
        FIXED,
        &["workload.cpu=\"0ms\"", "workload.gpu=\"0ms\"", "display.vsync=false"],
    );
    assert_eq!(free.clocks.elapsed, 0);
    no_nulls(&free);
    let free_vsync = run(FIXED, &["workload.cpu=\"0ms\"", "workload.gpu=\"0ms\""]);
    no_nulls(&free_vsync);
}

#[test]
fn a_run_past_the_picosecond_range_ends_with_a_clear_error() {
    // 10^6 s per refresh: the 64-bit range (about 1.8e7 s) ends within 20
    // frames; a vsynced FIFO shows each frame for a refresh at least, so this
    // is reported before simulating.
    let e = try_run(
        FIXED,
        &["display.refresh=\"1000000s\"", "run.frames=40", "run.warmup_frames=0"],
    )
    .unwrap_err();
    assert!(e.contains("overflow") && e.contains("213 days"), "{e}");
}

#[test]
fn frames_that_take_no_time_stop_at_run_max_events() {
    // vsync off, nothing costs time: every frame happens at t = 0. Past the
    // frames that could be in flight, each is one event of the run loop, so
    // run.max_events holds (it used to run every frame at once, unbounded).
    let free = [
        "workload.cpu=\"0ms\"",
        "workload.gpu=\"0ms\"",
        "display.vsync=false",
        "run.frames=10000000",
        "run.warmup_frames=0",
    ];
    let r = run(FIXED, &[&free[..], &["run.max_events=500"]].concat());
    assert_eq!(r.stats.stopped_by, rendersim::engine::StopReason::EventLimit);
    assert_eq!(r.stats.events, 500);
    assert!(r.records.len() < 600, "{}", r.records.len());
    assert_eq!(r.summary()["stopped_by"], "event_limit");
    assert_eq!(r.clocks.elapsed, 0);
    no_nulls(&r);
    // Without a limit, a run of such frames ends by itself (a few events
    // per frame past the first).
    let all = run(
        FIXED,
        &[&free[..3], &["run.frames=2000", "run.warmup_frames=0"]].concat(),
    );
    assert_eq!(all.records.len(), 2000);
    assert_eq!(all.stats.stopped_by, rendersim::engine::StopReason::Model);
    assert!(all.stats.events >= 1990, "{}", all.stats.events);
}

#[test]
fn frames_that_take_no_time_stop_at_run_until() {
    // Rendering costs nothing; vsync paces the frames, so simulated time
    // passes and run.until ends the run (10^7 frames requested).
    let r = run(
        FIXED,
        &[
            "workload.cpu=\"0ms\"",
            "workload.gpu=\"0ms\"",
            "run.frames=10000000",
            "run.warmup_frames=0",
            "run.until=\"1s\"",
        ],
    );
    assert_eq!(r.stats.stopped_by, rendersim::engine::StopReason::TimeLimit);
    assert_eq!(r.summary()["stopped_by"], "time_limit");
    assert!((55..=61).contains(&r.records.len()), "{}", r.records.len());
    // Without vsync no time passes, so run.until cannot end the run; the
    // frames' records are bounded by run.max_memory instead: 10^8 frames
    // need about 27 GiB, more than the 8 GiB default, and are refused up front.
    let e = common::try_run(
        FIXED,
        &[
            "workload.cpu=\"0ms\"",
            "workload.gpu=\"0ms\"",
            "display.vsync=false",
            "run.frames=100000000",
            "run.warmup_frames=0",
            "run.until=\"1s\"",
        ],
    )
    .unwrap_err();
    assert!(e.contains("run.max_memory"), "{e}");
}
