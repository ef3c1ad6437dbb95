//! Copies and vertex fetch from AGP memory sharing one bus (paper 000
//! §4.5.3, Table 4; `crates/models/src/components/shared_bus.rs`,
//! `crates/models/src/systems/frame_pipeline/bus_copy.rs`). Closed forms as
//! oracles: a draw fetching from AGP memory alone is the longer of its
//! vertex work and its bytes over the bus; beside a copy, both saturate the
//! bus and a frame is all their bytes over the bandwidth; a copy beside
//! nothing on the bus keeps its time exactly and its place in the draw's
//! CPU time.

use crate::common::{metric, run, try_run};

/// A vertex-bound terrain, one draw of 10,000 triangles, each transforming
/// one vertex at 50 ns, one pixel each: 0.5 ms of geometry a frame.
fn terrain(extra: &str) -> String {
    format!(
        r#"system = "frame_pipeline"
fidelity = "triangle"
[run]
frames = 10
warmup_frames = 2
[display]
vsync = false
present_mode = "immediate"
[noise]
enabled = false
[bus]
bandwidth = "1GB/s"
video_copy = "500MB/s"
[gpu]
architecture = "split"
[gpu.geometry]
vertex_shader = "50ns"
[gpu.fragment]
per_fragment = "1ns"
[workload]
kind = "scene"
[[workload.groups]]
name = "terrain"
mesh = {{ triangles = 10000, acmr = 1.0 }}
triangle_pixels = 1.0
{extra}
"#
    )
}

fn p50(path: &str, r: &rendersim::systems::frame_pipeline::PipelineRun) -> f64 {
    metric(r, &format!("metrics.{path}.p50"))
}

#[test]
fn agp_fetch_alone_is_the_longer_of_vertex_work_and_bytes_over_the_bus() {
    // 10,000 vertices x 40 B = 400 kB at 1 GB/s: 0.4 ms, under the 0.5 ms
    // of vertex work; 80 B: 0.8 ms, over it.
    let video = run(&terrain(""), &[]);
    let agp40 = run(&terrain("geometry_memory = \"agp\"\nvertex_bytes = 40"), &[]);
    let agp80 = run(&terrain("geometry_memory = \"agp\"\nvertex_bytes = 80"), &[]);
    let gpu = |r| p50("gpu_time_ms", r);
    assert!((gpu(&video) - 0.5).abs() < 1e-3, "{}", gpu(&video));
    assert!((gpu(&agp40) - gpu(&video)).abs() < 1e-9, "{}", gpu(&agp40));
    assert!((gpu(&agp80) - 0.8).abs() < 1e-3, "{}", gpu(&agp80));
    assert_eq!(agp80.summary()["scene"]["agp_fetch_bytes"], 800_000);
    // The closed-form geometry term is the longer one too.
    assert!((metric(&agp80, "metrics.analytic.geometry_ms") - 0.8).abs() < 1e-9);
    assert!((metric(&agp40, "metrics.analytic.geometry_ms") - 0.5).abs() < 1e-9);
    // No upload: no copy.
    assert_eq!(p50("copy_ms", &agp80), 0.0);
}

#[test]
fn a_copy_beside_agp_fetch_halves_both_and_the_frame_is_all_bytes_over_the_bus() {
    // Fetch 800 kB a frame (asks 80 B / 50 ns = 1.6 GB/s), copy 200 kB
    // (asks the whole 1 GB/s): half the bus each while both run, so the
    // copy takes 0.4 ms, and a GPU-bound frame carries 1 MB over the bus:
    // 1.0 ms (the per-triangle granularity of the fetch's share costs at
    // most a triangle's time).
    let r = run(
        &terrain("geometry_memory = \"agp\"\nvertex_bytes = 80\ngeometry_upload = 200000"),
        &[],
    );
    assert!((p50("copy_ms", &r) - 0.4).abs() < 1e-3, "copy {}", p50("copy_ms", &r));
    let frame = p50("gpu_time_ms", &r);
    assert!((frame - 1.0).abs() < 0.002, "frame {frame}");
    // The copy is not inside the draw's CPU time: the CPU's work per frame
    // is its costs plus the copy as it ran.
    let alone = run(&terrain("geometry_memory = \"agp\"\nvertex_bytes = 80"), &[]);
    let extra = p50("cpu_busy_ms", &r) - p50("cpu_busy_ms", &alone);
    assert!((extra - 0.4).abs() < 1e-3, "cpu extra {extra}");
    // The closed-form CPU term counts the copy at its rate alone (0.2 ms).
    let analytic = metric(&r, "metrics.analytic.cpu_ms") - metric(&alone, "metrics.analytic.cpu_ms");
    assert!((analytic - 0.2).abs() < 1e-9, "analytic copy {analytic}");
}

#[test]
fn a_copy_into_video_memory_runs_at_its_own_rate_beside_rendering() {
    // No AGP geometry: the copy has its rate alone (500 MB/s: 0.4 ms for
    // 200 kB) and rendering is untouched.
    let r = run(&terrain("geometry_upload = 200000"), &[]);
    assert_eq!(p50("copy_ms", &r), 0.4);
    assert!((p50("gpu_time_ms", &r) - 0.5).abs() < 1e-3);
    // Without `video_copy`, the bus's bandwidth (1 GB/s: 0.2 ms).
    let text = terrain("geometry_upload = 200000").replace("video_copy = \"500MB/s\"\n", "");
    assert_eq!(p50("copy_ms", &run(&text, &[])), 0.2);
}

#[test]
fn draw_fidelity_takes_the_bus_share_at_the_draws_start() {
    // Alone, draw fidelity gives the same closed form as the triangles.
    let agp = terrain("geometry_memory = \"agp\"\nvertex_bytes = 80");
    let tri = p50("gpu_time_ms", &run(&agp, &[]));
    let draw = p50("gpu_time_ms", &run(&agp, &["fidelity=\"draw\""]));
    assert!((tri - draw).abs() < 1e-3, "triangle {tri} draw {draw}");
    // Beside a copy it stays between the fetch alone and all bytes at half the bus.
    let up = terrain("geometry_memory = \"agp\"\nvertex_bytes = 80\ngeometry_upload = 200000");
    let d = p50("gpu_time_ms", &run(&up, &["fidelity=\"draw\""]));
    assert!((0.8 - 1e-3..=1.6 + 1e-3).contains(&d), "{d}");
}

#[test]
fn agp_geometry_needs_bytes_per_vertex() {
    let e = try_run(&terrain("geometry_memory = \"agp\"\nvertex_bytes = 0"), &[]).unwrap_err();
    assert!(
        e.contains("workload.groups[0].vertex_bytes") || e.contains("vertex_bytes"),
        "{e}"
    );
    assert!(e.contains("at least 1 byte"), "{e}");
    let e = try_run(&terrain("geometry_memory = \"pci\""), &[]).unwrap_err();
    assert!(e.contains("geometry_memory"), "{e}");
}

#[test]
fn a_shared_bus_under_system_tasks_is_deterministic_and_never_copies_faster() {
    // System tasks on the CPU suspend its copy (and the copy's rest is
    // retimed while it is suspended): the same seed gives the same run, and
    // a copy never beats its time with the whole bus to itself.
    let text = terrain("geometry_memory = \"agp\"\nvertex_bytes = 80\ngeometry_upload = 200000").replace(
        "[noise]\nenabled = false",
        "[noise]\nenabled = true\n[[noise.random]]\nname = \"os\"\ntarget = \"cpu\"\nrate = \"5kHz\"\nduration = { kind = \"lognormal\", median = \"50us\", sigma = 0.5 }",
    );
    let a = run(&text, &[]);
    let b = run(&text, &[]);
    assert_eq!(a.summary()["metrics"], b.summary()["metrics"]);
    let copy = metric(&a, "metrics.copy_ms.min");
    assert!(copy >= 0.2 - 1e-9, "copy {copy}");
    assert!(
        metric(&a, "metrics.copy_ms.max") > 0.4,
        "system tasks lengthen some copies"
    );
}
