//! The unified shader architecture (`gpu.architecture = "unified"`, the
//! default): vertex and fragment shading share one pool of cores, so a
//! heavier vertex shader still costs time under a heavy fragment shader
//! (paper 000 Table 1's direction; the H200's load grid), the `draw`
//! fidelity's closed form follows the triangle simulation, and the keys of
//! the two architectures are checked against each other.

use crate::common;
use common::{DEFAULT, metric, run, scene_model, try_run};

/// Mean GPU time per frame (ms) of the default model with these shader costs.
fn gpu_ms(arch: &str, vertex: &str, fragment: &str) -> f64 {
    let r = run(
        DEFAULT,
        &[
            &format!("gpu.architecture=\"{arch}\""),
            &format!("gpu.geometry.vertex_shader=\"{vertex}\""),
            &format!("gpu.fragment.per_fragment=\"{fragment}\""),
            "run.frames=3",
            "run.warmup_frames=1",
            "display.vsync=false",
            "noise.enabled=false",
        ],
    );
    metric(&r, "metrics.gpu_time_ms.mean")
}

/// What a heavier vertex shader adds under a heavy fragment shader, as a
/// share of what it adds under a light one (paper 000 Table 1: 1.997 / 2.381
/// = 0.84; the H200: 0.94; a single bottleneck: 0).
fn table1_ratio(arch: &str) -> f64 {
    let (v0, v1, f0, f1) = ("40ns", "120ns", "2ns", "6ns");
    let light = gpu_ms(arch, v1, f0) - gpu_ms(arch, v0, f0);
    let heavy = gpu_ms(arch, v1, f1) - gpu_ms(arch, v0, f1);
    assert!(light > 0.0, "{arch}: the heavier vertex shader adds nothing");
    heavy / light
}

#[test]
fn the_default_model_reproduces_table_1s_direction() {
    let unified = table1_ratio("unified");
    assert!(unified >= 0.6, "unified ratio {unified}");
    // The pool is work-conserving and the default model has no
    // fixed-function shading costs: the vertex work adds in full.
    assert!((unified - 1.0).abs() < 0.02, "unified ratio {unified}");
    // The split pipeline overlaps part of it (the default scene's triangle
    // sizes vary, so the bottleneck moves inside draws, paper 000 §4.5.1):
    // about 0.8 (0.794 measured), as docs/models.md says.
    let split = table1_ratio("split");
    assert!(
        split < unified - 0.05 && (0.7..0.9).contains(&split),
        "split ratio {split}"
    );
}

/// A scene on the unified pool without fixed-function costs.
fn pool_scene(depth: u32) -> String {
    scene_model(
        r#"name = "mix"
mesh = "grid:16x16"
triangle_pixels = { kind = "lognormal", median = 20.0, sigma = 1.2 }"#,
    )
    .replace("architecture = \"split\"", "architecture = \"unified\"")
    .replace("fifo_depth = 16", &format!("fifo_depth = {depth}"))
}

#[test]
fn the_pool_never_idles_while_either_stream_has_shader_work() {
    // With no fixed-function time, a frame's GPU busy time is exactly its
    // vertex plus fragment shader work, whatever the FIFO depth: the same
    // work as the split pipeline's two stage totals, added up.
    for depth in [0u32, 1, 16, 1000] {
        let u = run(&pool_scene(depth), &["run.frames=2"]);
        let s = run(
            &pool_scene(depth).replace("architecture = \"unified\"", "architecture = \"split\""),
            &["run.frames=2"],
        );
        let work = s.clocks.geometry[0] + s.clocks.fragment[0];
        let busy = u.clocks.gpu[0];
        // Each rescheduled item rounds its end up by at most 1 ps.
        let triangles = 2 * 2 * 16 * 16;
        assert!(
            busy >= work && busy <= work + 2 * triangles,
            "depth {depth}: busy {busy} vs work {work}"
        );
        assert!(s.clocks.gpu[0] < work, "depth {depth}: split overlaps the stages");
    }
}

#[test]
fn fixed_function_time_runs_beside_the_shader_work() {
    // Fragment shading (1 ps per pixel) is tiny next to the fixed-function
    // time (1 ns per pixel), so each triangle's fragments take the
    // fixed-function time: the fragment stream is busy as long as a split
    // fragment unit at 1 ns per pixel with the same triangle sizes.
    let m = pool_scene(16)
        .replace(
            "per_fragment = \"1ns\"",
            "per_fragment = \"1ps\"\nfixed_per_fragment = \"1ns\"",
        )
        .replace("vertex_shader = \"1ns\"", "vertex_shader = \"1ps\"");
    let u = run(&m, &["run.frames=2"]);
    let s = run(
        &pool_scene(16).replace("architecture = \"unified\"", "architecture = \"split\""),
        &["run.frames=2", "gpu.geometry.vertex_shader=\"1ps\""],
    );
    let (uf, sf) = (u.clocks.fragment[0] as f64, s.clocks.fragment[0] as f64);
    assert!((uf - sf).abs() / sf < 0.01, "unified {uf} ps vs split {sf} ps");
}

#[test]
fn reserved_cores_are_slower_than_sharing() {
    let fair = run(&pool_scene(16), &["run.frames=2"]);
    let reserved = run(
        &pool_scene(16),
        &[
            "run.frames=2",
            "gpu.scheduling=\"reserved\"",
            "gpu.shader_cores=4",
            "gpu.vertex_cores=1",
        ],
    );
    assert!(reserved.clocks.gpu[0] > fair.clocks.gpu[0]);
    for policy in ["vertex_first", "fragment_first"] {
        let r = run(
            &pool_scene(16),
            &["run.frames=2", &format!("gpu.scheduling=\"{policy}\"")],
        );
        // Priorities reorder the work but the pool stays busy: same total.
        let d = r.clocks.gpu[0].abs_diff(fair.clocks.gpu[0]) as f64;
        assert!(d / (fair.clocks.gpu[0] as f64) < 1e-3, "{policy}");
    }
}

/// The shipped models that name a hardware file.
const HARDWARE_MODELS: [&str; 3] = ["terrain-geforce3", "city-geforce3", "city-table2-geforce3"];

#[test]
fn draw_fidelity_follows_the_triangle_simulation_within_two_percent() {
    let models = [
        ("default", DEFAULT),
        ("city", include_str!("../../models/city.toml")),
        ("one-mesh", include_str!("../../models/one-mesh.toml")),
        ("single-view", include_str!("../../models/single-view.toml")),
        ("terrain", include_str!("../../models/terrain.toml")),
        ("h2-pass", include_str!("../../models/h2-pass.toml")),
    ];
    // Every shipped frame-pipeline model with a scene is in the list (a
    // new one must be added here; `fixed` has no scene, so no fidelity).
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        if text.contains("system = \"frame_pipeline\"") && text.contains("kind = \"scene\"") {
            assert!(
                models.iter().any(|(n, _)| *n == stem) || HARDWARE_MODELS.contains(&stem.as_str()),
                "{stem} is not checked here"
            );
        }
    }
    let sets = ["run.frames=4", "run.warmup_frames=1", "noise.enabled=false"];
    for (name, text) in models {
        let tri = run(text, &[&sets[..], &["fidelity=\"triangle\""]].concat());
        let draw = run(text, &[&sets[..], &["fidelity=\"draw\""]].concat());
        let (t, d) = (
            metric(&tri, "metrics.gpu_time_ms.mean"),
            metric(&draw, "metrics.gpu_time_ms.mean"),
        );
        assert!((d - t).abs() / t < 0.02, "{name}: draw {d} ms vs triangle {t} ms");
    }
    // The models on the GeForce3 name a hardware file, so they are read
    // from their folder.
    for name in HARDWARE_MODELS {
        let gpu_ms = |fidelity: &str| {
            let src = rendersim::config::ModelSource::from_file(&dir.join(format!("{name}.toml"))).unwrap();
            let sets: Vec<String> = sets
                .iter()
                .map(|s| s.to_string())
                .chain([format!("fidelity=\"{fidelity}\"")])
                .collect();
            let m = rendersim::config::prepare(src, &rendersim::config::Overrides::with_sets(&sets)).unwrap();
            let r = rendersim::systems::run_model(&m.source, &m.table, None).unwrap();
            crate::common::num(&r.summary(), "metrics.gpu_time_ms.mean")
        };
        let (t, d) = (gpu_ms("triangle"), gpu_ms("draw"));
        assert!((d - t).abs() / t < 0.02, "{name}: draw {d} ms vs triangle {t} ms");
    }
}

#[test]
fn architecture_keys_are_checked_against_each_other() {
    let split = scene_model("name = \"g\"\nmesh = \"grid:2x2\"\ntriangle_pixels = 1.0");
    let e = try_run(&split, &["gpu.shader_cores=8"]).unwrap_err();
    assert!(e.contains("gpu.shader_cores") && e.contains("unified"), "{e}");
    let unified = split.replace("architecture = \"split\"", "architecture = \"unified\"");
    let e = try_run(&unified, &["gpu.vertex_cores=2"]).unwrap_err();
    assert!(e.contains("gpu.vertex_cores") && e.contains("reserved"), "{e}");
    let e = try_run(
        &unified,
        &[
            "gpu.scheduling=\"reserved\"",
            "gpu.shader_cores=4",
            "gpu.vertex_cores=4",
        ],
    )
    .unwrap_err();
    assert!(e.contains("gpu.vertex_cores") && e.contains("between 1 and"), "{e}");
    let e = try_run(&unified, &["gpu.shader_cores=0"]).unwrap_err();
    assert!(e.contains("gpu.shader_cores"), "{e}");
    let e = try_run(&unified, &["gpu.scheduling=\"greedy\""]).unwrap_err();
    assert!(e.contains("gpu.scheduling"), "{e}");
}
