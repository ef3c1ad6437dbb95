//! Real measurements through wgpu (feature `wgpu`). On a machine without any
//! Vulkan adapter these tests say so and pass without measuring; CI installs
//! Mesa's lavapipe so they run there.
#![cfg(feature = "wgpu")]

use rendersim::components::vertex_cache::CachePolicy;
use rendersim::measure::{MeasureError, MeasureOptions, measure};
use rendersim::scene::generators::mesh_from_spec;

fn measured(spec: &str, opts: &MeasureOptions) -> Option<rendersim::measure::Measurement> {
    let m = mesh_from_spec(spec, std::path::Path::new(".")).unwrap();
    match measure(&m, spec, opts) {
        Ok(r) => Some(r),
        Err(MeasureError::NoAdapter(e)) => {
            eprintln!("SKIPPED: no Vulkan adapter on this machine ({e})");
            None
        }
        Err(e) => panic!("measurement failed: {e}"),
    }
}

#[test]
fn a_grid_is_measured_with_plausible_counters() {
    let opts = MeasureOptions {
        repeats: 3,
        warmup: 1,
        size: (128, 128),
        ..Default::default()
    };
    let Some(r) = measured("grid:32x32", &opts) else { return };
    assert!(r.stable_counters, "{r:?}");
    assert_eq!(r.clipper_invocations, 2 * 32 * 32);
    assert!(
        r.vs_invocations >= 33 * 33 && r.vs_invocations <= 6 * 32 * 32,
        "{}",
        r.vs_invocations
    );
    assert!(r.fs_invocations >= 128 * 128, "{}", r.fs_invocations);
    assert!(r.pass_time_ns > 0.0 && r.pass_times_ns.len() == 3);
    if r.adapter.driver == "llvmpipe" {
        // Study H1's policy predicts lavapipe exactly.
        let m = mesh_from_spec("grid:32x32", std::path::Path::new(".")).unwrap();
        assert_eq!(m.cache_stats(&CachePolicy::Lavapipe).transformed, r.vs_invocations);
    }
}

#[test]
fn depth_order_changes_shaded_fragments_only_with_the_depth_test() {
    let base = MeasureOptions {
        repeats: 1,
        warmup: 0,
        size: (64, 64),
        layers: 4,
        depth_test: true,
        ..Default::default()
    };
    let f2b = MeasureOptions {
        order: rendersim::measure::DepthOrder::FrontToBack,
        ..base.clone()
    };
    let b2f = MeasureOptions {
        order: rendersim::measure::DepthOrder::BackToFront,
        ..base.clone()
    };
    let (Some(a), Some(b)) = (measured("grid:8x8", &f2b), measured("grid:8x8", &b2f)) else {
        return;
    };
    // Same geometry work either way.
    assert_eq!(a.vs_invocations, b.vs_invocations);
    // Front to back, later layers fail the depth test; back to front, none do.
    // (Fragment-shader invocations count only passing fragments when early-z applies.)
    assert!(
        a.fs_invocations <= b.fs_invocations,
        "f2b {} vs b2f {}",
        a.fs_invocations,
        b.fs_invocations
    );
}

fn gpu() -> Option<rendersim::measure::Gpu> {
    match rendersim::measure::Gpu::open() {
        Ok(g) => Some(g),
        Err(MeasureError::NoAdapter(e)) => {
            eprintln!("SKIPPED: no Vulkan adapter on this machine ({e})");
            None
        }
        Err(e) => panic!("opening the adapter failed: {e}"),
    }
}

#[test]
fn geometry_only_passes_shade_the_vertices_but_no_fragments() {
    let Some(g) = gpu() else { return };
    let m = mesh_from_spec("grid:24x24", std::path::Path::new(".")).unwrap();
    let opts = MeasureOptions {
        repeats: 1,
        warmup: 0,
        size: (96, 96),
        ..Default::default()
    };
    let full = g.measure(&m, "grid:24x24", &opts).unwrap();
    let geo = g
        .measure(
            &m,
            "grid:24x24",
            &MeasureOptions {
                geometry_only: true,
                ..opts
            },
        )
        .unwrap();
    assert_eq!(geo.fs_invocations, 0, "{geo:?}");
    assert!(full.fs_invocations > 0);
    assert_eq!(geo.vs_invocations, full.vs_invocations);
    assert_eq!(geo.clipper_invocations, full.clipper_invocations);
}

#[test]
fn studies_h2_to_h4_run_and_their_counters_match_the_simulator() {
    use rendersim::measure::{h2::H2Setup, h3::H3Setup, h4::H4Setup, studies};
    let Some(g) = gpu() else { return };
    let lavapipe = g.adapter.driver == "llvmpipe";
    let h2 = studies::run_h2(
        &g,
        H2Setup {
            mesh: "grid:24x24:optimized".into(),
            size: (96, 96),
            vs_loops: [0, 50],
            fs_loops: [0, 5],
            auto_target_ms: None,
            ..H2Setup::default()
        },
        1,
    )
    .unwrap();
    assert_eq!(h2.measured.fs_invocations_geometry_only, 0);
    assert_eq!(h2.measured.triangles, 2 * 24 * 24);
    assert_eq!(h2.cells.len(), 4);
    assert_eq!(h2.scores.len(), 5);
    assert!(
        h2.cells
            .iter()
            .all(|c| c.measured_ms > 0.0 && c.max_ms <= c.sum_ms + 1e-12)
    );
    assert!(h2.markdown().contains("## H2"));

    let h3 = studies::run_h3(
        &g,
        H3Setup {
            mesh: "grid:4x4".into(),
            size: (64, 64),
            layers: 4,
            fs_loops: 2,
            auto_target_ms: None,
            ..H3Setup::default()
        },
        1,
    )
    .unwrap();
    assert_eq!(h3.rows.len(), 3);
    assert_eq!(h3.rows[0].layers_shaded, 1.0);
    assert_eq!(h3.rows[1].layers_shaded, 4.0);
    // Four layers, no depth test: four times the fragments of one.
    assert_eq!(
        h3.measured.all_layers.fs_invocations,
        4 * h3.measured.one_layer.fs_invocations
    );
    if lavapipe {
        // lavapipe counts fragment invocations before the early depth test.
        assert!(!h3.counter_sees_early_z, "{}", h3.markdown());
    }

    let h4 = studies::run_h4(
        &g,
        H4Setup {
            grid: 24,
            size: (64, 64),
            vs_loops: 10,
            auto_target_ms: None,
            ..H4Setup::default()
        },
        1,
    )
    .unwrap();
    assert_eq!(h4.rows.len(), H4Setup::default().orders().len());
    let fs0 = h4.rows[0].fs_invocations;
    for r in &h4.rows {
        // Same triangles, same pixels: only the vertex work changes.
        assert_eq!(r.fs_invocations, fs0, "{}", r.mesh);
        if lavapipe {
            assert_eq!(r.simulated_vs, r.measured_vs, "{}", r.mesh);
        }
    }
}

#[test]
fn study_cli_rejects_unknown_names_and_zero_repeats() {
    let run = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        err
    };
    let e = run(&["study", "h9"]);
    assert!(
        e.contains("unknown study \"h9\"") && e.contains("h1, h2, h3, h4, all"),
        "{e}"
    );
    let e = run(&["study", "h2", "--repeats", "0"]);
    assert!(e.contains("--repeats must be at least 1"), "{e}");
}
