//! PixelFlow's frame latency: the `pixelflow` system (paper 002 §4 and §7).
//!
//! Runs the 20-node machine of `models/pixelflow-20.toml` (15 rasterizers,
//! 4 shaders, 8 samples) on fewer primitives than the paper's 200,000, at
//! both fidelities: `analytic` evaluates the paper's closed forms (front end
//! `t_front` = geometry and transfer of every primitive; back end = the
//! largest of rasterize, shade, composite and load over the screen
//! regions), and `event` simulates every primitive batch and every region
//! through the nodes. It prints both latencies per primitive count, checks
//! that the event simulation stays within 2% of the closed form, and that
//! the front end grows linearly in the primitives.
//!
//! Run it with `cargo run --release --example pixelflow`.

use rendersim::config::{ModelSource, apply_set};
use rendersim::systems::pixelflow::PixelFlowRun;
use rendersim::systems::run_model;

/// Runs the 20-node model with `primitives` at `fidelity`.
fn run(primitives: u64, fidelity: &str) -> PixelFlowRun {
    let src = ModelSource::from_text("models/pixelflow-20.toml", include_str!("../models/pixelflow-20.toml"));
    let mut table = src.table().expect("valid TOML");
    apply_set(&mut table, &format!("primitives={primitives}")).expect("a valid --set");
    apply_set(&mut table, &format!("fidelity=\"{fidelity}\"")).expect("a valid --set");
    let run = run_model(&src, &table, None).expect("the model runs");
    run.downcast::<PixelFlowRun>().expect("a pixelflow model")
}

fn main() {
    println!("primitives   closed form ms (front + back, back-end bound)   event simulation ms   difference");
    let mut fronts = Vec::new();
    for n in [10_000u64, 50_000, 100_000, 200_000] {
        let a = run(n, "analytic");
        let e = run(n, "event");
        // The summary, typed: `metrics` is what `summary.json` writes.
        let (am, em) = (&a.summary.metrics, &e.summary.metrics);
        let (closed, sim) = (am.analytic_latency_ms, em.latency_ms);
        let (front, back) = (am.analytic_front_end_ms, am.analytic_back_end_ms);
        // The back end is its slowest stage: loading the 40 regions into
        // the frame buffer (40 x 52 us) for few primitives, rasterizing for many.
        let bound = if back == am.analytic.t_load_ms {
            "load"
        } else {
            "rasterize"
        };
        println!(
            "{n:>10}   {closed:8.3} ({front:6.3} + {back:6.3}, {bound:>9})     {sim:8.3}             {:+.3} ms",
            sim - closed
        );
        // The analytic fidelity is the closed form.
        assert!((am.latency_ms - closed).abs() < 1e-9);
        assert!((front + back - closed).abs() < 1e-9);
        assert_eq!(e.records.len(), 40, "40 screen regions of 128 x 64");
        // The event simulation also sends the regions' colours to the
        // frame-buffer node (40 x 3 bytes x 1.28 us = 0.154 ms), which the
        // closed form leaves out, and drains the pipeline's last regions.
        let colour = em.stages_ms.color.expect("the event simulation sends colours");
        assert!((colour - 0.1536).abs() < 1e-9);
        assert!(
            sim > closed && sim - closed < colour + 0.06,
            "{n} primitives: {sim} vs {closed}"
        );
        fronts.push((n, front, bound));
    }
    assert_eq!((fronts[0].2, fronts[3].2), ("load", "rasterize"));
    // t_front = t_overhead + n t_trans / 15 rasterizers: linear in n, 0.1 ms
    // at no primitives, 1.85 / 15 = 0.123 us per primitive.
    let slope = (fronts[3].1 - fronts[0].1) / (fronts[3].0 - fronts[0].0) as f64;
    assert!((slope - 0.00185 / 15.0).abs() < 1e-12);
    assert!((fronts[0].1 - 10_000.0 * slope - 0.1).abs() < 1e-9);
    println!(
        "front end: 0.1 ms + {:.4} us per primitive (t_trans 1.85 us over 15 rasterizers)",
        1000.0 * slope
    );
}
