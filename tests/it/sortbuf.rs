//! The state-sorting buffer (paper 001): the lower bound against an
//! exhaustive offline search on tiny sequences, the lecture's worst case for
//! LRU, the command line and its errors.

use std::path::Path;
use std::process::Command;

use proptest::prelude::*;
use rendersim::components::sorting_buffer::sequence::lru_worst;
use rendersim::components::sorting_buffer::{StateId, Strategy, lower_bound, offline_optimum, simulate};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// The fewest state changes of any strategy, by plain exhaustive search
/// (no memo; written apart from the library's): at each step either write
/// the next element (if the buffer is not full) or send all buffered
/// elements of one state.
fn brute(seq: &[StateId], k: usize) -> u64 {
    fn go(seq: &[StateId], k: usize, i: usize, buf: &mut Vec<StateId>, last: Option<StateId>) -> u64 {
        if i == seq.len() && buf.is_empty() {
            return 0;
        }
        let mut best = u64::MAX;
        if i < seq.len() && buf.len() < k {
            buf.push(seq[i]);
            best = best.min(go(seq, k, i + 1, buf, last));
            buf.pop();
        }
        let mut states = buf.clone();
        states.sort_unstable();
        states.dedup();
        for s in states {
            let kept: Vec<StateId> = buf.iter().copied().filter(|&x| x != s).collect();
            let mut rest = kept;
            let c = u64::from(last != Some(s)) + go(seq, k, i, &mut rest, Some(s));
            best = best.min(c);
        }
        best
    }
    go(seq, k, 0, &mut Vec::new(), None)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn lower_bound_never_exceeds_the_offline_optimum(
        seq in prop::collection::vec(0u64..4, 1..9), k in 1usize..5,
    ) {
        let opt = brute(&seq, k);
        prop_assert_eq!(offline_optimum(&seq, k).unwrap(), opt);
        let lb = lower_bound(&seq, k);
        prop_assert!(lb <= opt, "lower bound {} > optimum {}", lb, opt);
        for s in Strategy::ALL {
            let c = simulate(&seq, k, s, 7, false).unwrap().state_changes;
            prop_assert!(c >= opt, "{:?} {} beats the optimum {}", s, c, opt);
        }
    }

    #[test]
    fn online_strategies_never_beat_the_bound(
        seq in prop::collection::vec(0u64..12, 1..300), k in 1usize..40, seed in any::<u64>(),
    ) {
        let lb = lower_bound(&seq, k);
        for s in Strategy::ALL {
            let r = simulate(&seq, k, s, seed, true).unwrap();
            prop_assert!(r.state_changes >= lb);
            let sent: u64 = r.output.unwrap().iter().map(|x| x.1).sum();
            prop_assert_eq!(sent, seq.len() as u64);
        }
    }
}

#[test]
fn the_bound_is_tight_somewhere_and_not_trivial() {
    // Cases where the bound is above the number of distinct states, and
    // where it equals the optimum.
    let mut above = 0;
    let mut tight = 0;
    for n in 1..=8u64 {
        for code in 0..3u64.pow(n as u32) {
            let seq: Vec<StateId> = (0..n).map(|i| (code / 3u64.pow(i as u32)) % 3).collect();
            for k in 1..=3 {
                let lb = lower_bound(&seq, k);
                let opt = brute(&seq, k);
                assert!(lb <= opt, "{seq:?} k={k}: {lb} > {opt}");
                let mut d = seq.clone();
                d.sort_unstable();
                d.dedup();
                above += usize::from(lb > d.len() as u64);
                tight += usize::from(lb == opt);
            }
        }
    }
    assert!(above > 100 && tight > 1000, "above {above}, tight {tight}");
}

#[test]
fn lru_worst_case_ratio_grows_with_the_buffer() {
    // Offline: 2m (the lower bound, reached by keeping the thin states);
    // LRU: m (m + 1).
    for m in [2u64, 4, 8, 16] {
        let seq = lru_worst(m).unwrap();
        let k = (m * m + 1) as usize;
        assert_eq!(lower_bound(&seq, k), 2 * m);
        let lru = simulate(&seq, k, Strategy::Lru, 1, false).unwrap().state_changes;
        assert_eq!(lru, m * (m + 1), "m={m}");
        // Bounded waste is not fooled by the fresh stamps of the fat runs.
        let bw = simulate(&seq, k, Strategy::BoundedWaste, 1, false)
            .unwrap()
            .state_changes;
        assert!(bw < lru, "m={m}: bounded waste {bw}, lru {lru}");
    }
    // m = 1 is small enough for the exhaustive search: optimum 2m = 2.
    assert_eq!(offline_optimum(&lru_worst(1).unwrap(), 2).unwrap(), 2);
}

#[test]
fn cli_single_run_and_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "seq.txt", "# states\n1 2 1 2\n3 1\n");
    let o = bin()
        .args(["sortbuf", &f, "--buffer", "2", "--strategy", "lru", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["strategy"], "lru");
    assert_eq!(v["buffer"], 2);
    assert_eq!(v["sequence_length"], 6);
    let expect = simulate(&[1, 2, 1, 2, 3, 1], 2, Strategy::Lru, 1, false)
        .unwrap()
        .state_changes;
    assert_eq!(v["state_changes"], expect);
    assert_eq!(v["lower_bound"], lower_bound(&[1, 2, 1, 2, 3, 1], 2));
    assert_eq!(v["offline_optimum"], offline_optimum(&[1, 2, 1, 2, 3, 1], 2).unwrap());
    let o = bin()
        .args(["sortbuf", "lru-worst:4", "--sweep", "1,17", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["rows"][1]["buffer"], 17);
    assert_eq!(v["rows"][1]["lower_bound"], 8);
    assert_eq!(v["rows"][1]["state_changes"]["lru"], 20);
    assert_eq!(v["rows"][0]["state_changes"]["round-robin"], v["input_runs"]);
}

#[test]
fn cli_errors_name_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let err = |args: &[&str], want: &[&str]| {
        let o = bin().args(args).output().unwrap();
        let e = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(!e.contains("panicked"), "{e}");
        for w in want {
            assert!(e.contains(w), "{w:?} not in {e:?}");
        }
    };
    let good = write(dir.path(), "good.txt", "1 2 3\n");
    let bad = write(dir.path(), "bad.txt", "1 2\n3 red 4\n");
    let empty = write(dir.path(), "empty.txt", "# nothing here\n\n");
    err(
        &["sortbuf", &good, "--buffer", "0", "--strategy", "lru"],
        &["at least 1 slot"],
    );
    err(
        &["sortbuf", &bad, "--buffer", "2", "--strategy", "lru"],
        &["bad.txt:2:3", "\"red\""],
    );
    err(
        &["sortbuf", &empty, "--buffer", "2", "--strategy", "lru"],
        &["no state ids"],
    );
    err(&["sortbuf", &good, "--buffer", "2"], &["--strategy"]);
    err(&["sortbuf", &good, "--buffer", "2", "--strategy", "fifo"], &["fifo"]);
    err(
        &["sortbuf", &good, "--buffer", "2", "--strategy", "lru,random"],
        &["one strategy"],
    );
    err(&["sortbuf", &good, "--sweep", "1,0"], &["at least 1 slot"]);
    err(
        &["sortbuf", "/nonexistent/seq.txt", "--buffer", "2", "--strategy", "lru"],
        &["/nonexistent/seq.txt"],
    );
    err(
        &["sortbuf", "lru-worst:0", "--buffer", "2", "--strategy", "lru"],
        &["lru-worst:0"],
    );
    err(
        &["sortbuf", "lru-worst:x", "--buffer", "2", "--strategy", "lru"],
        &["lru-worst:M"],
    );
    err(
        &[
            "sortbuf",
            dir.path().to_str().unwrap(),
            "--buffer",
            "2",
            "--strategy",
            "lru",
        ],
        &["folder"],
    );
}

#[test]
fn scene_sequences_match_the_pipelines_state_changes() {
    // With one slot nothing is reordered: the changes of each attribute's
    // sequence are the frame pipeline's own counts for the same scene.
    let dir = tempfile::tempdir().unwrap();
    let city = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/models/city.toml")).unwrap();
    let mixed = format!(
        "{city}\n[[workload.groups]]\nname = \"extra\"\ncount = 40\nmesh = {{ triangles = 10, acmr = 1.0 }}\ntriangle_pixels = 4.0\nshaders = 3\ntextures = 5\nmaterials = 2\n"
    );
    let sorted = mixed.replace("state_order = \"as_listed\"", "state_order = \"sorted\"");
    assert_ne!(sorted, mixed);
    for (name, text) in [("city.toml", &city), ("mixed.toml", &mixed), ("sorted.toml", &sorted)] {
        let path = write(dir.path(), name, text);
        let summary = crate::common::summary_of(text, &["run.frames=1", "run.warmup_frames=0", "fidelity=\"draw\""]);
        for attr in ["shader", "texture", "material"] {
            let spec = format!("scene:{path}:{attr}");
            let o = bin()
                .args(["sortbuf", &spec, "--buffer", "1", "--strategy", "lru", "--json"])
                .output()
                .unwrap();
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            assert_eq!(
                v["state_changes"],
                summary["scene"][format!("{attr}_changes")],
                "{name} {attr}"
            );
            assert_eq!(v["sequence_length"], summary["scene"]["objects"], "{name}");
        }
    }
    let o = bin()
        .args([
            "sortbuf",
            "scene:models/fixed.toml",
            "--buffer",
            "1",
            "--strategy",
            "lru",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("not \"scene\""),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
