//! Real measurements through wgpu (feature `wgpu`). On a machine without any
//! Vulkan adapter these tests say so and pass without measuring; CI installs
//! Mesa's lavapipe so they run there.
#![cfg(feature = "wgpu")]

use std::path::Path;

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

/// Runs the binary; `None` (and a SKIPPED line) when it reports that this
/// machine has no Vulkan adapter.
fn rendersim(args: &[&str]) -> Option<std::process::Output> {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    if err.contains("no Vulkan adapter found") {
        eprintln!("SKIPPED: no Vulkan adapter on this machine ({})", err.trim());
        return None;
    }
    Some(o)
}

#[test]
fn measure_csv_appends_one_row_per_pass_and_the_header_once() {
    use rendersim::measure::passes::{PASS_HEADER, read_passes};
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("passes.csv");
    let csv_arg = csv.to_str().unwrap();
    for fs_loops in ["0", "3"] {
        let args = [
            "measure",
            "grid:8x8",
            "--size",
            "32x32",
            "--repeats",
            "1",
            "--warmup",
            "0",
            "--fs-loops",
            fs_loops,
            "--csv",
            csv_arg,
        ];
        let Some(o) = rendersim(&args) else { return };
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(text.lines().next(), Some(PASS_HEADER), "{text}");
    assert_eq!(text.matches(PASS_HEADER).count(), 1, "{text}");
    let rows = read_passes(&csv).unwrap();
    assert_eq!(rows.len(), 2, "{text}");
    assert_eq!((rows[0].fs_loops, rows[1].fs_loops), (0, 3));
    for r in &rows {
        assert_eq!(r.mesh, "grid:8x8");
        assert_eq!(r.size.to_string(), "32x32");
        assert!(!r.geometry_only && r.vs_invocations > 0 && r.fs_invocations > 0 && r.pass_time_ns > 0.0);
    }
}

#[test]
fn passes_split_into_draws_count_their_vertex_work_draw_by_draw() {
    // `measure --draws N` splits the triangles into N draw calls; each draw
    // starts with an empty vertex cache, as `predict` counts it; 0 draws
    // nothing. Rows carry the draws, and read back with them.
    use rendersim::measure::passes::read_passes;
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("draws.csv");
    let csv_arg = csv.to_str().unwrap();
    for draws in ["0", "1", "4", "64"] {
        let args = [
            "measure",
            "grid:16x16",
            "--size",
            "64x64",
            "--repeats",
            "1",
            "--warmup",
            "0",
            "--draws",
            draws,
            "--csv",
            csv_arg,
        ];
        let Some(o) = rendersim(&args) else { return };
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let rows = read_passes(&csv).unwrap();
    assert_eq!(rows.iter().map(|r| r.draws).collect::<Vec<_>>(), [0, 1, 4, 64]);
    assert_eq!((rows[0].vs_invocations, rows[0].fs_invocations), (0, 0));
    let device = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/devices/llvmpipe.toml");
    for r in &rows {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(["predict", "grid:16x16", "--size", "64x64", "--json", "--draws"])
            .arg(r.draws.to_string())
            .arg("--device")
            .arg(&device)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(v["predicted"]["vs_invocations"], r.vs_invocations, "{} draws", r.draws);
    }
    // Too many draws, and a pass of several draws for a file of the header
    // before the column: refused before measuring, the file untouched.
    let old = dir.path().join("old.csv");
    let before = "mesh,size,vs_loops,fs_loops,geometry_only,vs_invocations,fs_invocations,pass_time_ns\n";
    std::fs::write(&old, before).unwrap();
    for (args, want) in [
        (vec!["measure", "grid:4x4", "--draws", "4097"], "--draws"),
        (
            vec!["predict", "grid:4x4", "--draws=-1", "--device", "x.toml"],
            "--draws",
        ),
        (
            vec!["measure", "grid:4x4", "--draws", "4", "--csv", old.to_str().unwrap()],
            "written before the `draws` column",
        ),
    ] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want) && !err.contains("panicked"), "{args:?}: {err}");
    }
    assert_eq!(std::fs::read_to_string(&old).unwrap(), before);
}

#[test]
fn csv_with_another_header_is_refused_untouched_before_measuring() {
    // Refused before the adapter is opened: no device needed.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("other.csv");
    std::fs::write(&csv, "a,b\n1,2\n").unwrap();
    for args in [
        vec!["measure", "grid:4x4", "--csv", csv.to_str().unwrap()],
        vec!["study", "h1", "--csv", csv.to_str().unwrap()],
    ] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(&format!("{} has the header \"a,b\"", csv.display())) && err.contains("mesh,size,vs_loops"),
            "{err}"
        );
        assert_eq!(std::fs::read_to_string(&csv).unwrap(), "a,b\n1,2\n");
    }
    // A layered pass has no row in the format.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(["measure", "grid:4x4", "--layers", "2", "--csv", csv.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no column for layers"));
}

#[test]
fn study_takes_require_exact_and_csv() {
    let help = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(["study", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("--require-exact") && help.contains("--csv <FILE>"),
        "{help}"
    );
    // On an adapter whose reuse H1 predicts exactly (lavapipe) the flag
    // passes; the validation meshes' passes are written, the probes are not.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("h1.csv");
    let Some(o) = rendersim(&[
        "study",
        "h1",
        "--require-exact",
        "--json",
        "--csv",
        csv.to_str().unwrap(),
    ]) else {
        return;
    };
    let err = String::from_utf8_lossy(&o.stderr);
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let exact = json["h1"]["exact"].as_bool().unwrap();
    assert_eq!(o.status.success(), exact, "{err}");
    if !exact {
        assert!(err.contains("residuals") && err.contains("--require-exact"), "{err}");
    }
    let rows = rendersim::measure::passes::read_passes(&csv).unwrap();
    let validation = json["h1"]["validation"].as_array().unwrap();
    assert_eq!(rows.len(), validation.len(), "{rows:?}");
    for (r, v) in rows.iter().zip(validation) {
        assert_eq!(r.mesh, v["mesh"].as_str().unwrap());
        assert_eq!(r.vs_invocations, v["measured"].as_u64().unwrap());
    }
    assert!(err.contains("probes or of layered"), "{err}");
}

#[test]
fn h4_searches_its_loop_count_and_reports_what_it_measured() {
    use rendersim::measure::{h4::H4Setup, studies};
    let Some(g) = gpu() else { return };
    let h4 = studies::run_h4(
        &g,
        H4Setup {
            grid: 16,
            size: (64, 64),
            vs_loops: 10,
            auto_target_ms: Some(1.0),
            ..H4Setup::default()
        },
        1,
    )
    .unwrap();
    let found = h4.setup.vs_search.expect("H4 searched its loop count");
    assert_eq!(found.loops, h4.setup.vs_loops);
    assert!(found.tries >= 1 && found.reached_ms > 0.0, "{found:?}");
    let md = h4.markdown();
    assert!(
        md.contains(&format!("vertex shader {} loop iterations", found.loops)),
        "{md}"
    );
    assert!(
        md.contains(&found.outcome("the cache-optimized order's geometry-only pass")),
        "{md}"
    );
    // The search's passes are kept for --csv, one row per distinct pass.
    let passes = g.measured_passes();
    assert!(passes.rows.iter().any(|r| r.vs_loops == found.loops && r.geometry_only));
}

/// Mesa's device-selection layer made libwayland print `error:
/// XDG_RUNTIME_DIR is invalid or not set` on every wgpu command without a
/// runtime folder; the binary switches the layer off there (src/main.rs).
#[test]
fn no_stray_loader_errors_without_a_runtime_folder() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args([
            "measure",
            "grid:4x4",
            "--size",
            "16x16",
            "--repeats",
            "1",
            "--warmup",
            "0",
        ])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("NODEVICE_SELECT")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    if err.contains("no Vulkan adapter found") {
        eprintln!("SKIPPED: no Vulkan adapter on this machine ({})", err.trim());
        return;
    }
    assert!(o.status.success(), "{err}");
    assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
    assert!(!err.lines().any(|l| l.starts_with("error:")), "{err}");
}

#[test]
fn interleaved_rounds_keep_every_round_and_pool_one_row_per_pass() {
    use rendersim::measure::Gpu;
    let gpu = match Gpu::open() {
        Ok(g) => g,
        Err(MeasureError::NoAdapter(e)) => {
            eprintln!("SKIPPED: no Vulkan adapter on this machine ({e})");
            return;
        }
        Err(e) => panic!("{e}"),
    };
    let a = mesh_from_spec("grid:8x8", Path::new(".")).unwrap();
    let b = mesh_from_spec("strip:8x8", Path::new(".")).unwrap();
    let opts = |geometry_only| MeasureOptions {
        size: (64, 64),
        warmup: 1,
        repeats: 99, // ignored: the rounds argument counts
        geometry_only,
        ..Default::default()
    };
    let conds = [
        ("grid:8x8", &a, opts(false)),
        ("strip:8x8", &b, opts(false)),
        ("grid:8x8", &a, opts(true)),
    ];
    let r = gpu.measure_interleaved(&conds, 4).unwrap();
    assert_eq!(r.len(), 3);
    for m in &r {
        assert_eq!(m.pass_times_ns.len(), 4, "{m:?}");
        assert!(m.stable_counters, "{m:?}");
        let mut t = m.pass_times_ns.clone();
        t.sort_by(f64::total_cmp);
        assert_eq!(m.pass_time_ns, t[2], "the (upper) median of the rounds");
    }
    assert_eq!(r[0].clipper_invocations, 2 * 8 * 8);
    assert_eq!(r[2].fs_invocations, 0, "geometry only shades nothing");
    // One pass-CSV row per condition, each with its four rounds pooled.
    let rows = gpu.measured_passes().rows;
    assert_eq!(rows.len(), 3);
}

#[test]
fn predict_measure_says_when_the_profile_is_for_another_device() {
    // Issue 58: the H200's profile measured against this machine's adapter
    // (lavapipe in CI) printed "-97.6%" as if it were the profile's error.
    let h200 = concat!(env!("CARGO_MANIFEST_DIR"), "/models/devices/nvidia-h200.toml");
    let Some(o) = rendersim(&[
        "predict",
        "grid:8x8",
        "--size",
        "64x64",
        "--device",
        h200,
        "--measure",
        "--json",
    ]) else {
        return;
    };
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let adapter = v["measured"]["adapter"].as_str().unwrap().to_lowercase();
    if adapter.contains("h200") {
        return; // on the profile's own device there is nothing to say
    }
    assert_eq!(v["measured"]["same_device"], false);
    assert!(
        err.contains("warning: the profile") && err.contains("nvidia-h200"),
        "{err}"
    );
    assert!(v["measured"]["warning"].as_str().unwrap().contains("two devices"));
}
