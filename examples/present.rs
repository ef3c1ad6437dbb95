//! The swap chain and display alone: the `present` system (paper 004 §4.2).
//!
//! Sweeps a constant render time from 5 to 40 ms on a 60 Hz display and
//! prints the mean interval between displayed frames for double and triple
//! buffering with `fifo`, each beside its closed form: double buffering
//! snaps the frame rate to 60, 30, 20 Hz; a third image lets the renderer
//! run at its own rate. Then it runs random render times, where the closed
//! form is an expectation over the distribution, and checks the simulation
//! against it.
//!
//! Run it with `cargo run --release --example present`.

use rendersim::config::ModelSource;
use rendersim::systems::present::PresentRun;
use rendersim::systems::run_model;

/// Runs a present model and returns its typed run.
fn run(text: &str) -> PresentRun {
    let src = ModelSource::from_text("example.toml", text);
    let run = run_model(&src, &src.table().expect("valid TOML"), None).expect("the model runs");
    run.downcast::<PresentRun>().expect("a present model")
}

/// (simulated, closed form) mean display interval in ms.
fn interval(r: &PresentRun) -> (f64, f64) {
    // The typed summary (`summary.json` writes the same fields).
    let m = &r.summary.metrics;
    (
        m.display_interval_ms.mean.expect("frames were shown"),
        m.analytic_interval_ms,
    )
}

fn model(time: &str, buffers: u32, frames: u64) -> String {
    format!(
        "system = \"present\"\n[run]\nframes = {frames}\n[render]\ntime = {time}\n\
         [display]\nrefresh = \"60Hz\"\nbuffers = {buffers}\npresent_mode = \"fifo\"\n"
    )
}

fn main() {
    println!("render ms   double buffered (sim / closed form)   triple buffered (sim / closed form)");
    for t in [5, 10, 15, 17, 20, 25, 30, 34, 40] {
        let (d, dc) = interval(&run(&model(&format!("\"{t}ms\""), 2, 300)));
        let (tr, tc) = interval(&run(&model(&format!("\"{t}ms\""), 3, 300)));
        println!("{t:>9}   {d:>15.3} / {dc:<15.3}      {tr:>15.3} / {tc:<15.3}");
        // Double buffering is exact frame by frame; triple in the long run.
        assert!((d - dc).abs() < 1e-6);
        assert!((tr - tc).abs() < 1000.0 / 60.0 / 299.0 + 1e-9);
    }
    let r = run(&model(
        "{ kind = \"lognormal\", median = \"14ms\", sigma = 0.4 }",
        2,
        20_000,
    ));
    let (sim, closed) = interval(&r);
    let d = &r.summary.metrics.display_interval_ms;
    let se = d.std.expect("frames were shown") / (d.count as f64).sqrt();
    println!(
        "lognormal render times (median 14 ms, sigma 0.4), double buffered: {sim:.3} ms simulated, \
         {closed:.3} ms closed form ({:.1} standard errors apart)",
        (sim - closed).abs() / se
    );
    assert!((sim - closed).abs() < 4.0 * se);
    println!("{} frames, every one shown or dropped", r.frames.len());
}
