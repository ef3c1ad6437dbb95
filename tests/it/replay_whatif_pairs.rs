//! What-ifs checked against reality (issue 56, item 4): each shared game's
//! unlimited FrameView capture replayed under a scenario of
//! `experiments/replay-whatif/scenarios.toml` and compared with the same
//! game's capture measured under that setting (`--compare`), read in place
//! from `../shared` (the data set states no licence).
//!
//! The targets (displayed fps within 3% on every pair, PC latency
//! median within 15% on 80% of them) are checked where they hold; the
//! rest of the table is printed and is a finding (docs/replay.md,
//! "What-ifs against measured captures").

use std::path::PathBuf;

use rendersim::studies::replay::compare::compare;
use rendersim::studies::replay::{ReplayOptions, replay};

fn shared() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/measurements/presentmon/whatif")
}

/// The scenarios' --set strings by name.
fn scenarios() -> toml::Table {
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/replay-whatif/scenarios.toml"),
    )
    .unwrap();
    let t: toml::Table = toml::from_str(&text).unwrap();
    t["scenarios"].as_table().unwrap().clone()
}

/// (base, scenario, measured) for every shared pair.
pub const PAIRS: [(&str, &str, &str); 9] = [
    ("cyberpunk-1080p-unlimited", "cap30", "cyberpunk-1080p-cap30"),
    ("cyberpunk-1080p-unlimited", "cap60", "cyberpunk-1080p-cap60"),
    ("cyberpunk-1080p-unlimited", "fg", "cyberpunk-1080p-fg-unlimited"),
    ("cyberpunk-1080p-unlimited", "fg-cap30", "cyberpunk-1080p-fg-cap30"),
    (
        "alanwake2-1080p-dlaa-unlimited",
        "drivercap30",
        "alanwake2-1080p-dlaa-drivercap30",
    ),
    (
        "alanwake2-1080p-dlaa-unlimited",
        "drivercap60",
        "alanwake2-1080p-dlaa-drivercap60",
    ),
    (
        "alanwake2-1080p-dlaa-unlimited",
        "fg",
        "alanwake2-1080p-dlaa-fg-unlimited",
    ),
    ("talos2-1080p-unlimited", "cap30", "talos2-1080p-cap30"),
    ("talos2-1080p-unlimited", "cap60", "talos2-1080p-cap60"),
];

#[test]
fn every_shared_pair_puts_the_measured_figures_beside_the_prediction() {
    let dir = shared();
    let sc = scenarios();
    let mut table = String::new();
    for (base, scenario, measured) in PAIRS {
        let sets: Vec<String> = sc[scenario]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect();
        let opts = ReplayOptions {
            sets,
            ..ReplayOptions::default()
        };
        let r = replay(&dir.join(format!("{base}.csv")), &opts).unwrap();
        let c = compare(&r, &dir.join(format!("{measured}.csv"))).unwrap();
        assert_eq!(c.application, r.summary.application);
        table += &format!("{base} + {scenario} vs {measured}:");
        for (name, m) in c.rows() {
            table += &format!(
                " {name} {:.2}/{:.2} ({:.3});",
                m.predicted.unwrap_or(f64::NAN),
                m.measured.unwrap_or(f64::NAN),
                m.ratio.unwrap_or(f64::NAN)
            );
            // Every figure exists on both sides (every capture here has
            // MsPCLatency) and the ratio is theirs.
            let (p, me, ra) = (m.predicted.unwrap(), m.measured.unwrap(), m.ratio.unwrap());
            assert!(
                p.is_finite() && me > 0.0 && (ra - p / me).abs() < 1e-12,
                "{base} {scenario} {name}"
            );
        }
        table += "\n";
        // Checks that hold today (the displayed-fps target on every
        // pair but Alan Wake 2's frame generation; the game's own limiter's
        // and the driver's display latency, PresentMon's CPU start to the
        // screen, within 10%). The rest is docs/replay.md's table of findings.
        let ratio = |m: &rendersim::studies::replay::compare::Compared| m.ratio.unwrap();
        if (base, scenario) != ("alanwake2-1080p-dlaa-unlimited", "fg") {
            let r = ratio(&c.displayed_fps);
            assert!(
                (r - 1.0).abs() <= 0.03,
                "{base} {scenario}: displayed fps ratio {r}\n{table}"
            );
        }
        if scenario.contains("cap") && !scenario.starts_with("fg") {
            let r = ratio(&c.display_latency_ms_median);
            assert!(
                (r - 1.0).abs() <= 0.10,
                "{base} {scenario}: display latency ratio {r}\n{table}"
            );
        }
        // PC latency with the input lead the base capture measured (in
        // frames): within the 15% on Cyberpunk's own limiter and
        // frame generation and on Alan Wake 2's frame generation; not on
        // the driver's cap (1.27) or Talos 2's limiter, which samples input
        // after its sleep (2.5-3.0): docs/replay.md's findings.
        if matches!(
            (base, scenario),
            ("cyberpunk-1080p-unlimited", "cap30" | "cap60" | "fg") | ("alanwake2-1080p-dlaa-unlimited", "fg")
        ) {
            let r = ratio(&c.pc_latency_ms_median);
            assert!(
                (r - 1.0).abs() <= 0.15,
                "{base} {scenario}: PC latency ratio {r}\n{table}"
            );
        }
        // Frame generation's present thread, predicted on Cyberpunk 2077
        // (its cost calibrated on Alan Wake 2's pair): the presents a
        // second within 5%, the display latency PresentMon measures over
        // them within 10% (it was 2-3x with the frame held back in the
        // game's own swap chain), the time from a present to the screen
        // within 20%.
        if base.starts_with("cyberpunk") && scenario.starts_with("fg") {
            let fps = ratio(&c.fps);
            let latency = ratio(&c.display_latency_ms_median);
            let until = ratio(&c.until_displayed_ms_median);
            assert!(
                (fps - 1.0).abs() <= 0.05 && (latency - 1.0).abs() <= 0.10 && (until - 1.0).abs() <= 0.20,
                "{base} {scenario}: presents {fps}, display latency {latency}, until displayed {until}\n{table}"
            );
        }
    }
    eprintln!("{table}");
}

#[test]
fn compare_names_a_missing_capture_and_one_without_the_game() {
    let bin = env!("CARGO_BIN_EXE_rendersim");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let base = root.join("tests/fixtures/presentmon/test_case_0.csv");
    let other = shared().join("../games/carhol-csgo-composed-copy.csv");
    for (measured, says) in [
        (root.join("no-such-capture.csv"), "no-such-capture.csv"),
        (other, "no swap chain of application \"dwm.exe\""),
    ] {
        let o = std::process::Command::new(bin)
            .arg("replay")
            .arg(&base)
            .arg("--compare")
            .arg(&measured)
            .output()
            .unwrap();
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(e.contains(says) && !e.contains("panicked"), "{e}");
    }
    // A capture of the same application compares; its figures are its own.
    let o = std::process::Command::new(bin)
        .arg("replay")
        .arg(&base)
        .args(["--compare"])
        .arg(root.join("tests/fixtures/presentmon/test_case_2.csv"))
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let c = &v["replay"]["compare"];
    assert_eq!(c["application"], "dwm.exe");
    assert_eq!(c["frames"], 56);
    let fps = &c["displayed_fps"];
    let ratio = fps["predicted"].as_f64().unwrap() / fps["measured"].as_f64().unwrap();
    assert!((fps["ratio"].as_f64().unwrap() - ratio).abs() < 1e-12);
    assert!(c["pc_latency_ms_median"]["measured"].is_null());
}

#[test]
fn the_pairs_experiment_replays_each_pair_under_its_scenario_s_own_keys() {
    // experiments/replay-whatif-pairs.toml sweeps one replay model per
    // pair (experiments/replay-whatif/pairs/): each names the base and the
    // measured capture of PAIRS and the scenario's keys, no others.
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/replay-whatif/pairs");
    let sc = scenarios();
    let game = |base: &str| base.split('-').next().unwrap().to_string();
    let mut seen = 0;
    for (base, scenario, measured) in PAIRS {
        let file = root.join(format!("{}-{scenario}.toml", game(base)));
        let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let m: rendersim::studies::replay::config::ReplayConfig = toml::from_str(&text).unwrap();
        assert!(m.capture.ends_with(format!("{base}.csv")), "{}", file.display());
        assert!(
            m.compare.unwrap().ends_with(format!("{measured}.csv")),
            "{}",
            file.display()
        );
        let mut keys = rendersim::studies::replay::config::whatif_sets(&m.whatif);
        let mut want: Vec<String> = sc[scenario]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().replace(' ', ""))
            .collect();
        keys.sort();
        want.sort();
        assert_eq!(keys, want, "{}", file.display());
        seen += 1;
    }
    assert_eq!(
        seen,
        std::fs::read_dir(&root).unwrap().count(),
        "a pair model without a pair"
    );
}
