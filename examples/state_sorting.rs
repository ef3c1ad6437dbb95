//! Sorting draw calls by render state with a small buffer: the
//! `state_sorting` system (paper 001's sorting buffer).
//!
//! A renderer that changes state (shader, texture) between consecutive
//! draws pays for each change; a buffer of K slots lets it reorder the
//! stream. The lecture's worst case for LRU (`lru-worst:M`) is a sequence
//! of M (M + 1) runs built so that LRU with M^2 + 1 slots gains nothing:
//! every run is sent alone, as without a buffer. The example runs it for
//! M = 2..6 and prints the state changes of every strategy beside the
//! sequence's runs and the lower bound, checking the construction's closed
//! form (LRU = M (M + 1) changes), that bounded-waste does better, and that
//! no strategy beats the lower bound.
//!
//! Run it with `cargo run --release --example state_sorting`.

use rendersim::config::ModelSource;
use rendersim::systems::run_model;
use rendersim::systems::state_sorting::system::StateSortingRun;

const STRATEGIES: [&str; 4] = ["lru", "bounded-waste", "random", "round-robin"];

fn main() {
    println!("  M   K   runs   bound   lru   bounded-waste   random   round-robin");
    for m in 2..=6u64 {
        let k = m * m + 1;
        let text = format!("system = \"state_sorting\"\nsequence = \"lru-worst:{m}\"\nbuffer = {k}\n[run]\nseed = 7\n");
        let src = ModelSource::from_text("example.toml", &text);
        let run = run_model(&src, &src.table().expect("valid TOML"), None).expect("the model runs");
        let s = run.summary().clone();
        run.downcast::<StateSortingRun>().expect("a state_sorting model");
        let metric = |k: &str| s["metrics"][k].as_f64().unwrap_or_else(|| panic!("{k} in {s}"));
        let changes: Vec<f64> = STRATEGIES
            .iter()
            .map(|st| s["metrics"]["state_changes"][st].as_f64().expect("every strategy ran"))
            .collect();
        let (runs, bound) = (metric("input_runs"), metric("lower_bound"));
        println!(
            "{m:>3} {k:>3} {runs:>6} {bound:>7} {:>5} {:>15} {:>8} {:>13}",
            changes[0], changes[1], changes[2], changes[3]
        );
        // The construction: M (M + 1) runs, and LRU sends every one alone.
        assert_eq!(runs, (m * (m + 1)) as f64);
        assert_eq!(changes[0], runs);
        assert!(changes[1] < changes[0], "bounded-waste beats LRU at M = {m}");
        assert!(changes.iter().all(|&c| c >= bound), "no strategy beats the bound");
    }
    println!("LRU gains nothing on its worst case; bounded-waste does better at every M");
}
