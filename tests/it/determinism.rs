//! Same seed, same bytes; another seed, other noise.

use crate::common;
use common::{DEFAULT, run};

fn outputs(seed: u64) -> (String, String) {
    let r = run(
        DEFAULT,
        &[&format!("run.seed={seed}"), "run.frames=12", "run.warmup_frames=2"],
    );
    let mut csv = vec![];
    r.write_frames_csv(&mut csv).unwrap();
    let mut s = r.summary();
    // Wall time is the one field that may differ.
    for k in ["wall_seconds", "events_per_second", "build_seconds", "simulate_seconds"] {
        s[k] = 0.into();
    }
    (String::from_utf8(csv).unwrap(), serde_json::to_string(&s).unwrap())
}

#[test]
fn same_seed_gives_identical_frames_and_summary() {
    let a = outputs(11);
    let b = outputs(11);
    assert_eq!(a.0, b.0);
    assert_eq!(a.1, b.1);
}

#[test]
fn another_seed_gives_other_noise() {
    let a = outputs(11);
    let c = outputs(12);
    assert_ne!(a.0, c.0);
}
