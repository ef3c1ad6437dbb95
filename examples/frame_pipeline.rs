//! A system driven from the library: the frame pipeline of paper 000 §4.
//!
//! Loads a model from TOML text, patches it like `--set` does, runs it, and
//! reads the typed results: the JSON summary, per-frame records and the
//! exact per-state clocks. It then shows the vsync quantization of paper 004
//! §4.2: a GPU frame a little longer than one 60 Hz refresh is shown for two.
//!
//! Run it with `cargo run --release --example frame_pipeline`.

use rendersim::config::{ModelSource, apply_set};
use rendersim::systems::frame_pipeline::PipelineRun;
use rendersim::systems::run_model;

const MODEL: &str = r#"
[run]
frames = 120
warmup_frames = 10
[noise]
enabled = false
[display]
refresh = "60Hz"
vsync = true
buffers = 2
[workload]
kind = "fixed"
cpu = "5ms"
gpu = "16ms"
"#;

/// Mean display interval (ms) for a GPU cost per frame.
fn display_interval(gpu: &str) -> f64 {
    let src = ModelSource::from_text("example.toml", MODEL);
    let mut table = src.table().expect("valid TOML");
    apply_set(&mut table, &format!("workload.gpu=\"{gpu}\"")).expect("a valid --set");
    let run = run_model(&src, &table, None).expect("the model runs");
    let Ok(r) = run.downcast::<PipelineRun>() else {
        unreachable!("a model without `system` is a frame pipeline")
    };
    // Conservation: every unit's states add up to the elapsed time exactly.
    assert_eq!(r.clocks.cpu.iter().sum::<u64>(), r.clocks.elapsed);
    assert_eq!(r.clocks.gpu.iter().sum::<u64>(), r.clocks.elapsed);
    assert_eq!(r.records.len(), 120);
    // The typed summary (`summary.json` writes the same fields).
    r.results
        .metrics
        .display_interval_ms
        .mean
        .expect("a mean display interval")
}

fn main() {
    let fast = display_interval("16ms");
    let slow = display_interval("17ms");
    println!("GPU 16 ms per frame: a new image every {fast:.3} ms");
    println!("GPU 17 ms per frame: a new image every {slow:.3} ms");
    // 60 Hz becomes 30 Hz just past one refresh (16.667 ms).
    assert!((fast - 16.667).abs() < 0.01, "{fast}");
    assert!((slow - 33.333).abs() < 0.01, "{slow}");
}
