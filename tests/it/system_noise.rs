//! Paper 000 Figure 3 (§4.2): what the paper's own description of its
//! system task gives under the paper's own timing. `models/single-view.toml`
//! has the task the paper suspects (0.5 ms every 2-3 frames) and small
//! random background tasks. Timed as the paper timed each rendering (§7.1:
//! a synchronising finish, the cycle counter read before and after), a
//! frame's time runs from its CPU start to its GPU end, and the density is
//! two spikes 0.5 ms apart: 99% of frames within 0.5 ms of the fastest,
//! against the paper's 1.52 ms. Timed present to present
//! (`MsBetweenPresents`, what `experiments/figure3-system-noise.toml` plots) a task
//! that hides the wait for the previous frame's GPU tail adds a third
//! spike, 0.5 ms below, and the width is 1.27 ms (docs/models.md,
//! "Per-frame variation").

use std::process::Command;

/// The single view's 10,000 frames, as `experiments/figure3-system-noise.toml`
/// runs them: each frame's time from its CPU start to its GPU end, and
/// from present to present (ms).
fn frames() -> (Vec<f64>, Vec<f64>) {
    let dir = tempfile::tempdir().unwrap();
    let model = concat!(env!("CARGO_MANIFEST_DIR"), "/models/single-view.toml");
    let out = dir.path().join("run");
    let o = Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args([
            "run",
            model,
            "--set",
            "run.frames=10000",
            "--set",
            "run.warmup_frames=20",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut r = csv::Reader::from_path(out.join("frames.csv")).unwrap();
    let h = r.headers().unwrap().clone();
    let at = |name: &str| h.iter().position(|c| c == name).unwrap();
    let (lat, gpu, between) = (at("MsGPULatency"), at("MsGPUTime"), at("MsBetweenPresents"));
    let (mut rt, mut bp) = (Vec::new(), Vec::new());
    for row in r.records() {
        let row = row.unwrap();
        rt.push(row[lat].parse::<f64>().unwrap() + row[gpu].parse::<f64>().unwrap());
        if let Ok(v) = row[between].parse::<f64>() {
            bp.push(v);
        }
    }
    (rt, bp)
}

/// The 99% quantile less the minimum (the paper's c), and the share of
/// values within 0.01 ms of the `k` most common values (to 0.01 ms).
fn c99_and_modes(v: &[f64], k: usize) -> (f64, f64, Vec<f64>) {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let c = s[((s.len() - 1) as f64 * 0.99) as usize] - s[0];
    let mut counts = std::collections::BTreeMap::new();
    for x in &s {
        *counts.entry((x * 100.0).round() as i64).or_insert(0usize) += 1;
    }
    let mut by: Vec<(i64, usize)> = counts.into_iter().collect();
    by.sort_by_key(|p| std::cmp::Reverse(p.1));
    let top: Vec<f64> = by.iter().take(k).map(|(x, _)| *x as f64 / 100.0).collect();
    let share = by.iter().take(k).map(|(_, n)| n).sum::<usize>() as f64 / s.len() as f64;
    (c, share, top)
}

#[test]
fn the_papers_task_under_the_papers_timing_gives_two_spikes_and_half_a_millisecond() {
    let (rt, bp) = frames();
    let (c, share, mut top) = c99_and_modes(&rt, 2);
    top.sort_by(f64::total_cmp);
    assert!((0.45..=0.55).contains(&c), "c from CPU start to GPU end: {c}");
    assert!(share > 0.95, "two values hold {share} of the frames");
    assert!((top[1] - top[0] - 0.5).abs() < 0.02, "modes {top:?}");
    let (c, share, _) = c99_and_modes(&bp, 3);
    assert!((1.2..=1.35).contains(&c), "c present to present: {c}");
    assert!(share > 0.9, "three values hold {share} of the frames");
}
