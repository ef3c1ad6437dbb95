//! Estimating rendering time in a walkthrough: the `walkthrough` system
//! (paper 000 §5-7).
//!
//! Walks a small copy of the paper's city (`models/walkthrough-city.toml` at
//! 5% of its 5609 buildings, 60 frames, 300 fit renders) along a street,
//! drawing every frame's visible objects through the frame pipeline's GPU
//! model. Before the walk, the estimators of §5 are fitted to single-object
//! renders: h1 (time per triangle), h2 (per transformed vertex), h3
//! (Funkhouser's: the larger of a geometry term and a pixel term), h4 (per
//! transformed vertex plus per pixel) and pos (measured tables per object,
//! direction and size). During the walk each one
//! predicts every frame's time, and the summary holds each estimator's
//! error against the simulated frame. The example prints them and checks
//! the paper's finding: estimators that count pixels beat those that count
//! only geometry, h3 best of all.
//!
//! Run it with `cargo run --release --example walkthrough`.

use rendersim::config::{ModelSource, apply_set};
use rendersim::systems::run_model;
use rendersim::systems::walkthrough::WalkthroughRun;

fn main() {
    let src = ModelSource::from_text(
        "models/walkthrough-city.toml",
        include_str!("../models/walkthrough-city.toml"),
    );
    let mut table = src.table().expect("valid TOML");
    for set in [
        "scene.scale=0.05",
        "run.frames=60",
        "estimation.fit_samples=300",
        "estimation.pos.alpha_steps=5",
    ] {
        apply_set(&mut table, set).expect("a valid --set");
    }
    let run = run_model(&src, &table, None).expect("the model runs");
    let r = run.downcast::<WalkthroughRun>().expect("a walkthrough model");
    // The typed summary: its fields are what `summary.json` writes.
    let s = &r.summary;
    let objects = s.scene.objects;
    let frame_ms = s.metrics.gpu_time_ms.mean.expect("60 frames were measured");
    println!(
        "{objects} buildings, {} triangles, {} frames of {frame_ms:.3} ms of GPU time on average",
        s.scene.triangles, s.frames
    );
    // 5% of the city's 5609 buildings (Table 5), one table row per frame.
    assert_eq!(objects as f64, (5609.0_f64 * 0.05).round());
    assert_eq!(r.rows.len(), 60);
    // h1-h4 and pos, the first five of the estimators' scores.
    let mse: Vec<f64> = s.metrics.estimation.scores()[..5]
        .iter()
        .map(|&(e, score)| {
            let score = score.expect("the model asks for every estimator");
            let m = score.mse_ms2.expect("frames were estimated");
            println!(
                "{e:>4}: mean squared error {m:8.5} ms^2, mean error {:+.3} ms",
                score.mean_error_ms.expect("frames were estimated")
            );
            m
        })
        .collect();
    // Counting pixels pays: h4 beats h2 (the same vertex term plus pixels),
    // h3 beats h1.
    assert!(mse[3] < mse[1] && mse[2] < mse[0], "{mse:?}");
    // h3 best of all.
    assert!(mse.iter().all(|&m| m >= mse[2]));
    println!("best estimator: h3, {:.0}x lower error than h1", mse[0] / mse[2]);
}
