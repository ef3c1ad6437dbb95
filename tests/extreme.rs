//! Stiff and extreme cases: picosecond costs beside one-second periods, an
//! empty scene, a 10^8-triangle object, one- and zero-slot FIFOs, zero-cost
//! stages, time overflow. Nothing panics; no NaN reaches the output.

mod common;
use common::{FIXED, null_paths, run, scene_model, try_run};

fn no_nulls(r: &rendersim::systems::frame_pipeline::PipelineRun) {
    let mut n = vec![];
    null_paths(&r.summary, "", &mut n);
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
    let tv = r.summary["scene"]["transformed_vertices"].as_u64().unwrap();
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
