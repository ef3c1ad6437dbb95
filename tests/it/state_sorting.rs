//! The `state_sorting` system (paper 001's sorting buffer as a model an
//! experiment sweeps): the lecture's worst case for LRU against its closed
//! form, sequences whose changes are known for every strategy, the exact
//! optimum between the lower bound and every strategy, the city scene's
//! sequence, and bad keys naming themselves.

use serde_json::Value;

use crate::common::{num, summary_of, try_run_any};

fn model(sequence: &str, buffer: usize) -> String {
    format!("system = \"state_sorting\"\nsequence = {sequence:?}\nbuffer = {buffer}\n[run]\nseed = 7\n")
}

const STRATEGIES: [&str; 4] = ["lru", "bounded-waste", "random", "round-robin"];

fn changes(s: &Value, strategy: &str) -> f64 {
    s["metrics"]["state_changes"][strategy]
        .as_f64()
        .unwrap_or_else(|| panic!("no state_changes.{strategy}: {s}"))
}

#[test]
fn lru_gains_nothing_on_the_lectures_worst_case() {
    for m in 2..=6u64 {
        let k = (m * m + 1) as usize;
        let s = summary_of(&model(&format!("lru-worst:{m}"), k), &[]);
        // The construction: m (m + 1) changes without a buffer, and LRU
        // with m^2 + 1 slots sends every element of every run alone.
        assert_eq!(num(&s, "metrics.input_runs"), (m * (m + 1)) as f64, "m = {m}");
        assert_eq!(changes(&s, "lru"), (m * (m + 1)) as f64, "m = {m}");
        for st in STRATEGIES {
            assert!(
                changes(&s, st) >= num(&s, "metrics.lower_bound"),
                "{st} below the bound, m = {m}"
            );
        }
        assert!(changes(&s, "bounded-waste") < changes(&s, "lru"), "m = {m}");
    }
}

#[test]
fn sequences_with_known_changes() {
    let dir = tempfile::tempdir().unwrap();
    // One state throughout: one change whatever the buffer; every state
    // once: one change each.
    for (text, expect) in [("5 5 5 5 5 5 5 5", 1.0), ("0 1 2 3 4 5 6 7 8 9", 10.0)] {
        let path = dir.path().join("seq.txt");
        std::fs::write(&path, text).unwrap();
        for k in [1, 3, 64] {
            let s = summary_of(&model(path.to_str().unwrap(), k), &[]);
            for st in STRATEGIES {
                assert_eq!(changes(&s, st), expect, "{text:?}, K = {k}, {st}");
            }
        }
    }
}

#[test]
fn the_exact_optimum_lies_between_the_bound_and_every_strategy() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("seq.txt");
    std::fs::write(&path, "0 1 0 2 1 0 3 2 1 0 # short enough for the exact optimum\n").unwrap();
    for k in 1..=4 {
        let s = summary_of(&model(path.to_str().unwrap(), k), &[]);
        let opt = num(&s, "metrics.offline_optimum");
        assert!(opt >= num(&s, "metrics.lower_bound"), "K = {k}");
        for st in STRATEGIES {
            assert!(changes(&s, st) >= opt, "{st} beats the optimum at K = {k}");
        }
    }
}

#[test]
fn the_city_scene_cycles_its_states() {
    let s = summary_of(&model("scene:models/city.toml", 256), &[]);
    assert_eq!(num(&s, "metrics.sequence_length"), 280.0);
    assert_eq!(num(&s, "metrics.distinct_states"), 264.0);
    // Below one period no deterministic strategy gains anything.
    for st in ["lru", "bounded-waste", "round-robin"] {
        assert_eq!(changes(&s, st), 280.0, "{st}");
    }
    let all = summary_of(&model("scene:models/city.toml", 1024), &[]);
    for st in STRATEGIES {
        assert_eq!(changes(&all, st), 264.0, "{st} with the whole sequence buffered");
    }
}

#[test]
fn bad_keys_name_the_key() {
    let cases = [
        (model("lru-worst:4", 0), "buffer", "at least 1 slot"),
        (model("lru-worst:x", 4), "sequence", "lru-worst:M"),
        (model("no/such/file.txt", 4), "sequence", "reading sequence file"),
        (model("scene:no/such/model.toml", 4), "sequence", "cannot read"),
        (
            model("scene:models/walkthrough-city.toml", 4),
            "sequence",
            "no [workload] table",
        ),
        (
            format!(
                "{}strategies = [\"lru\", \"fifo\"]\n",
                model("lru-worst:4", 4).replace("[run]\nseed = 7\n", "")
            ),
            "strategies[1]",
            "unknown strategy",
        ),
        (
            format!(
                "{}strategies = [\"lru\", \"lru\"]\n",
                model("lru-worst:4", 4).replace("[run]\nseed = 7\n", "")
            ),
            "strategies[1]",
            "listed twice",
        ),
        (
            format!(
                "{}strategies = []\n",
                model("lru-worst:4", 4).replace("[run]\nseed = 7\n", "")
            ),
            "strategies",
            "names no strategy",
        ),
    ];
    for (text, key, words) in cases {
        let e = try_run_any(&text, &[]).expect_err(&text);
        assert!(e.contains(key) && e.contains(words), "{text}\n-> {e}");
    }
}
