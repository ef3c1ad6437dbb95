//! Predicting a device's measured passes: the `device_predictions` system.
//!
//! Reads the H200's shared pass measurements (`docs/measurements/nvidia-h200/`:
//! 95 passes of grids, random meshes and strips at several sizes and shader
//! loads), calibrates a device profile on them (the vertex-cache policy
//! `nvidia` predicting the vertex-shader invocations), and predicts every
//! row twice: by a fit to the other rows (leave-one-out, the honest error)
//! and by simulating the pass with the full profile. It prints the median
//! and 90th-percentile errors, checks that the calibrated model beats a
//! plain linear fit's leave-one-out error, and that simulating the passes
//! is faster than measuring them (7 passes per row on the device).
//!
//! Run it with `cargo run --release --example device_predictions`.

use rendersim::config::ModelSource;
use rendersim::systems::device_predictions::system::DevicePredictionsRun;
use rendersim::systems::run_model;

fn main() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/measurements/nvidia-h200");
    let files = ["load-grid.csv", "load-sweep.csv"].map(|f| format!("{dir}/{f}"));
    let text = format!(
        "system = \"device_predictions\"\ndevice = \"nvidia-h200\"\nfiles = {files:?}\nvertex_cache = \"nvidia\"\n"
    );
    let src = ModelSource::from_text("example.toml", &text);
    let run = run_model(&src, &src.table().expect("valid TOML"), None).expect("the model runs");
    let s = run.summary().clone();
    let p = run
        .downcast::<DevicePredictionsRun>()
        .expect("a device_predictions model")
        .predictions;
    // One prediction per measured row (the CSVs' lines less their headers).
    let rows: usize = files
        .iter()
        .map(|f| std::fs::read_to_string(f).expect("a shipped CSV").lines().count() - 1)
        .sum();
    assert_eq!(p.rows.len(), rows);
    assert_eq!(s["metrics"]["rows"].as_u64(), Some(rows as u64));
    for (name, e) in [
        ("leave-one-out", &p.loo),
        ("linear baseline (leave-one-out)", &p.linear_loo),
        ("simulated, full profile", &p.simulated),
    ] {
        println!(
            "{name:>32}: median {:5.2}%, p90 {:5.2}%, worst {:6.2}%",
            e.median, e.p90, e.worst
        );
    }
    assert!(p.loo.median < p.linear_loo.median && p.loo.p90 < p.linear_loo.p90);
    // Measuring a row is 7 passes of its measured time.
    let measuring: f64 = p.rows.iter().map(|r| 7.0 * r.row.pass_time_ns * 1e-9).sum();
    assert!((p.measuring_seconds - measuring).abs() < 1e-9 * measuring);
    println!(
        "{rows} passes: {:.1} s of device time measured, {:.2} s simulated here",
        p.measuring_seconds, p.simulating_seconds
    );
    assert!(p.simulating_seconds < p.measuring_seconds);
}
