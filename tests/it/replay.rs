//! `rendersim replay`: real PresentMon captures (tests/fixtures/presentmon)
//! through the frame pipeline, predicted against measured, and clear
//! errors for captures that cannot be replayed.

use std::path::{Path, PathBuf};
use std::process::Command;

use rendersim::components::swap_chain::Composition;
use rendersim::studies::replay::{ReplayOptions, replay};

fn capture(i: usize) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/fixtures/presentmon/test_case_{i}.csv"))
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

#[test]
fn the_main_swap_chain_of_each_shared_capture_meets_the_accuracy_targets() {
    for i in 0..3 {
        let r = replay(&capture(i), &ReplayOptions::default()).unwrap();
        let s = &r.summary;
        assert_eq!(s.application, "dwm.exe", "capture {i}");
        assert_eq!(s.model_present_mode, "fifo");
        assert!((s.refresh_hz - 59.95).abs() < 0.1, "capture {i}: {} Hz", s.refresh_hz);
        let e = &s.error_ms;
        assert!(s.agreement.displayed >= 0.95, "capture {i}: {}", s.agreement.displayed);
        assert!(
            e.until_displayed.median.unwrap() <= 0.5,
            "capture {i}: {:?}",
            e.until_displayed
        );
        assert!(
            e.until_displayed.p90.unwrap() <= 2.0,
            "capture {i}: {:?}",
            e.until_displayed
        );
        assert!(
            e.render_complete.median.unwrap() <= 0.5,
            "capture {i}: {:?}",
            e.render_complete
        );
        // The CPU replays as measured: presents where the capture has them.
        assert!(e.present.max.unwrap() < 1e-6, "capture {i}: {:?}", e.present);
        assert_eq!(r.frames.len(), s.frames);
    }
}

fn chain(i: usize, swap_chain: &str) -> rendersim::studies::replay::Replay {
    let opts = ReplayOptions {
        swap_chain: Some(swap_chain.into()),
        ..ReplayOptions::default()
    };
    replay(&capture(i), &opts).unwrap()
}

#[test]
fn composed_flips_are_shown_one_refresh_after_the_first_vertical_blank() {
    // `Composed: Flip` at sync interval 0: mailbox, shown by the compositor
    // one refresh later. Both shared chains land within 0.05 ms.
    for (i, sc) in [(0, "0x20DBB4358B0"), (1, "0x2019D7777C0")] {
        let r = chain(i, sc);
        let s = &r.summary;
        assert_eq!(s.present_mode, "Composed: Flip");
        assert_eq!(
            (s.model_present_mode.as_str(), s.model_composition),
            ("mailbox", Composition::Composed)
        );
        let e = &s.error_ms.until_displayed;
        assert!(e.median.unwrap() <= 0.05 && e.p90.unwrap() <= 0.05, "{i} {sc}: {e:?}");
    }
    // `Composed: Copy with GPU GDI` (a blit, sync interval -1): fifo plus
    // the compositor's refresh. Every displayed frame is on the capture's
    // vertical-blank grid; where the model misses, it misses by exactly
    // one refresh, on one side of the frame the compositor dropped (the
    // compositor's queue at the capture's start is not in the capture).
    for (i, sc) in [
        (0, "0x20979A6D5F8"),
        (0, "0x0"),
        (0, "0x29A5884FF18"),
        (2, "0x1BA6DC82C58"),
    ] {
        let r = chain(i, sc);
        let refresh = 1000.0 / r.summary.refresh_hz;
        assert_eq!(r.summary.model_composition, Composition::Composed);
        for f in &r.frames {
            if let (Some(m), Some(p)) = f.until_displayed {
                let off = (p - m).abs();
                assert!(
                    off < 0.3 || (off - refresh).abs() < 0.3,
                    "{i} {sc} line {}: {p} vs {m}",
                    f.line
                );
            }
        }
    }
    // Without composition the rule misses these chains by a refresh more.
    let opts = ReplayOptions {
        swap_chain: Some("0x20DBB4358B0".into()),
        sets: vec!["display.composition=\"independent\"".into()],
        ..ReplayOptions::default()
    };
    let flip = replay(&capture(0), &opts).unwrap();
    let shown: Vec<f64> = flip
        .whatif_frames
        .as_ref()
        .unwrap()
        .iter()
        .filter_map(|f| f.until_displayed.1)
        .collect();
    let captured: Vec<f64> = flip.frames.iter().filter_map(|f| f.until_displayed.1).collect();
    let refresh = 1000.0 / flip.summary.refresh_hz;
    for (a, b) in captured.iter().zip(&shown) {
        assert!((a - b - refresh).abs() < 1e-6, "{a} vs {b}");
    }
}

#[test]
fn a_what_if_is_reported_beside_the_measured_and_the_as_captured_figures() {
    let base = replay(&capture(0), &ReplayOptions::default()).unwrap();
    assert!(base.whatif_frames.is_none() && base.summary.whatif.sets.is_empty());
    // Without patches the what-if is the replay as captured.
    assert_eq!(base.summary.whatif.stats, base.summary.as_captured);
    let opts = ReplayOptions {
        sets: vec!["display.refresh=\"30Hz\"".into()],
        ..ReplayOptions::default()
    };
    let slow = replay(&capture(0), &opts).unwrap();
    let (b, s) = (&base.summary, &slow.summary);
    // The measurement and the as-captured replay do not move.
    assert_eq!(s.measured, b.measured);
    assert_eq!(s.as_captured, b.as_captured);
    assert_eq!(s.error_ms.until_displayed.median, b.error_ms.until_displayed.median);
    assert_eq!(s.model_present_mode, "fifo");
    assert_eq!(slow.whatif_model.as_ref().unwrap().display.refresh.text, "30Hz");
    // Half the refresh rate: frames wait longer for their vertical blank.
    // Repeats are counted on the what-if's own 30 Hz grid: at about 27
    // frames a second, fewer of its refreshes repeat a frame than of 60 Hz's.
    let (w, a) = (&s.whatif.stats, &s.as_captured);
    assert!(
        w.display_latency_ms.median.unwrap() > a.display_latency_ms.median.unwrap() + 8.0,
        "{w:?} vs {a:?}"
    );
    let screens: Vec<f64> = slow
        .whatif_frames
        .as_ref()
        .unwrap()
        .iter()
        .filter_map(|f| f.predicted_times().screen)
        .collect();
    let on_30hz: u64 = screens
        .windows(2)
        .map(|p| (((p[1] - p[0]) / (1000.0 / 30.0)).round() as u64).saturating_sub(1))
        .sum();
    assert_eq!(w.repeated_refreshes, on_30hz);
    assert!(w.repeated_refreshes < a.repeated_refreshes, "{w:?} vs {a:?}");
    // The as-captured replay's figures are the measured ones, near enough.
    let m = &b.measured;
    assert_eq!((m.frames, m.displayed), (a.frames, a.displayed));
    assert!((m.display_latency_ms.median.unwrap() - a.display_latency_ms.median.unwrap()).abs() < 0.5);
    assert_eq!(m.repeated_refreshes, a.repeated_refreshes);
    let frames = slow.whatif_frames.as_ref().unwrap();
    assert_eq!(frames.len(), slow.frames.len());
    assert_eq!(slow.columns().len(), slow.rows()[0].len());
}

#[test]
fn a_variable_refresh_what_if_shows_most_frames_when_the_gpu_finishes_them() {
    let opts = ReplayOptions {
        sets: vec![
            "display.vrr.min_refresh=\"48Hz\"".into(),
            "display.vrr.max_refresh=\"144Hz\"".into(),
        ],
        ..ReplayOptions::default()
    };
    let r = replay(&capture(0), &opts).unwrap();
    let frames = r.whatif_frames.as_ref().unwrap();
    // Never two scan-outs closer than the fastest refresh.
    let changes: Vec<f64> = frames.iter().filter_map(|f| f.between_display_change.1).collect();
    assert!(changes.len() > 150);
    assert!(changes.iter().all(|&d| d >= 1000.0 / 144.0 - 1e-6), "{changes:?}");
    // Most frames (about 41 a second, inside the window) go on screen the
    // moment the GPU finishes; none waits longer than a scan-out.
    let waits: Vec<f64> = frames
        .iter()
        .filter_map(|f| Some(f.until_displayed.1? - f.render_complete.1?))
        .collect();
    let at_once = waits.iter().filter(|&&w| w.abs() < 1e-6).count();
    assert!(at_once * 10 >= waits.len() * 7, "{at_once} of {}", waits.len());
    assert!(
        waits.iter().all(|&w| w > -1e-6 && w <= 1000.0 / 144.0 + 1e-6),
        "{waits:?}"
    );
    // Against the fixed 60 Hz panel as captured: no wait for a vertical
    // blank, so a lower median latency.
    let (w, a) = (&r.summary.whatif.stats, &r.summary.as_captured);
    assert!(
        w.display_latency_ms.median.unwrap() < a.display_latency_ms.median.unwrap() - 5.0,
        "{w:?} vs {a:?}"
    );
}

#[test]
fn the_replay_system_runs_a_what_if_from_a_model_file_as_the_command_does() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("m.toml");
    std::fs::write(
        &model,
        format!(
            "system = \"replay\"\ncapture = {:?}\n[whatif]\ncpu.max_frames_ahead = 1\ndisplay.present_mode = \"mailbox\"\n",
            capture(2)
        ),
    )
    .unwrap();
    let src = rendersim::config::ModelSource::from_file(&model).unwrap();
    let table = src.table().unwrap();
    let run = rendersim::systems::run_model(&src, &table, None).unwrap();
    let s = run.summary();
    assert_eq!(s["system"], "replay");
    let opts = ReplayOptions {
        sets: vec![
            "cpu.max_frames_ahead=1".into(),
            "display.present_mode=\"mailbox\"".into(),
        ],
        ..ReplayOptions::default()
    };
    let direct = replay(&capture(2), &opts).unwrap();
    let direct = serde_json::to_value(&direct.summary.whatif).unwrap();
    assert_eq!(s["replay"]["whatif"], direct);
    // A wrong key in the what-if names it.
    std::fs::write(
        &model,
        format!(
            "system = \"replay\"\ncapture = {:?}\n[whatif]\ndisplay.bufers = 2\n",
            capture(2)
        ),
    )
    .unwrap();
    let src = rendersim::config::ModelSource::from_file(&model).unwrap();
    let e = rendersim::systems::run_model(&src, &src.table().unwrap(), None)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("whatif") && e.contains("bufers"), "{e}");
    // ... as coming from the table, not from a command-line option.
    assert!(e.contains("`[whatif] display.bufers=2`") && !e.contains("--set"), "{e}");
    std::fs::write(
        &model,
        format!(
            "system = \"replay\"\ncapture = {:?}\n[assume]\ndisplay.buffers = 40\n",
            capture(2)
        ),
    )
    .unwrap();
    let src = rendersim::config::ModelSource::from_file(&model).unwrap();
    let e = rendersim::systems::run_model(&src, &src.table().unwrap(), None)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`[assume] display.buffers=40`") && e.contains("between 2 and 16"),
        "{e}"
    );
}

#[test]
fn cli_prints_json_writes_its_folder_and_names_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let o = bin()
        .args([
            "replay",
            capture(1).to_str().unwrap(),
            "--json",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for key in ["frames", "swapchain", "present_mode", "refresh_hz"] {
        assert!(
            v["replay"][key].is_number() || v["replay"][key].is_string(),
            "{key}: {v}"
        );
    }
    assert!(v["replay"]["agreement"]["displayed"].as_f64().unwrap() >= 0.95);
    assert!(v["replay"]["error_ms"]["until_displayed"]["median"].is_number());
    for f in ["replay.json", "frames.csv", "comparison.csv", "model.toml"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert!(!out.join("whatif-model.toml").exists() && !out.join("whatif-frames.csv").exists());
    // A what-if adds its model and its columns; the text shows three columns.
    let o = bin()
        .args([
            "replay",
            capture(1).to_str().unwrap(),
            "--set",
            "display.buffers=2",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("what-if: display.buffers=2") && text.contains("as captured      what-if"),
        "{text}"
    );
    assert!(
        std::fs::read_to_string(out.join("whatif-model.toml"))
            .unwrap()
            .contains("buffers = 2")
    );
    let header = std::fs::read_to_string(out.join("comparison.csv")).unwrap();
    assert!(
        header.lines().next().unwrap().ends_with("WhatIfMsBetweenDisplayChange"),
        "{header}"
    );
    // The replayed runs as PresentMon frames, on the capture's swap chain.
    for f in ["frames.csv", "whatif-frames.csv"] {
        let frames = std::fs::read_to_string(out.join(f)).unwrap();
        assert_eq!(frames.lines().count(), 26, "{f}: a header and 25 frames");
        let first = frames.lines().nth(1).unwrap();
        assert!(first.starts_with("dwm.exe,1564,0x2408E0B7CA0,"), "{f}: {first}");
        assert!(frames.lines().next().unwrap().contains(",CPUStartTime,"), "{f}");
    }

    let err = |args: &[&str]| {
        let o = bin().args(args).output().unwrap();
        let e = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(!e.contains("panicked"), "{e}");
        e
    };
    let c0 = capture(0);
    let c0 = c0.to_str().unwrap();
    let odd = dir.path().join("odd-mode.csv");
    let text = std::fs::read_to_string(capture(1))
        .unwrap()
        .replace("Hardware: Legacy Flip", "Overlay: Mystery");
    std::fs::write(&odd, text).unwrap();
    let e = err(&["replay", odd.to_str().unwrap()]);
    assert!(
        e.contains("odd-mode.csv:") && e.contains("unknown present mode `Overlay: Mystery`"),
        "{e}"
    );
    let e = err(&["replay", c0, "--swapchain", "0x1"]);
    assert!(
        e.contains("no swap chain 0x1; the capture has: dwm.exe (process 1268) 0x224B280A1C0"),
        "{e}"
    );
    let e = err(&["replay", c0, "--set", "display.bufers=3"]);
    assert!(
        e.contains("display.bufers") && e.contains("did you mean `buffers`"),
        "{e}"
    );
    let bad = dir.path().join("bad.csv");
    let text = std::fs::read_to_string(capture(1)).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let col = lines[0].split(',').position(|h| h == "MsUntilDisplayed").unwrap();
    let mut cells: Vec<&str> = lines[3].split(',').collect();
    cells[col] = "garbage";
    lines[3] = cells.join(",");
    std::fs::write(&bad, lines.join("\n")).unwrap();
    let e = err(&["replay", bad.to_str().unwrap()]);
    assert!(
        e.contains("bad.csv:4: column `MsUntilDisplayed`: \"garbage\" is not a number"),
        "{e}"
    );
    std::fs::write(&bad, "hello,world\n1,2\n").unwrap();
    let e = err(&["replay", bad.to_str().unwrap()]);
    assert!(e.contains("bad.csv: not a PresentMon capture"), "{e}");
    let e = err(&["replay", dir.path().join("none.csv").to_str().unwrap()]);
    assert!(e.contains("cannot read capture"), "{e}");
}

#[test]
fn assumptions_patch_the_replay_as_captured_and_their_errors_name_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let c = capture(0);
    let c = c.to_str().unwrap();
    let o = bin()
        .args(["replay", c, "--assume", "display.buffers=2", "--json", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["replay"]["assume"], serde_json::json!(["display.buffers=2"]));
    assert_eq!(v["replay"]["refresh_from"], "compositor");
    assert_eq!(v["replay"]["display"]["refresh"]["from"], "compositor");
    assert_eq!(v["replay"]["display"]["flips"], "on_grid");
    // The as-captured model is the one with the assumption, not a what-if.
    let model = std::fs::read_to_string(out.join("model.toml")).unwrap();
    assert!(model.contains("buffers = 2"), "{model}");
    assert!(!out.join("whatif-model.toml").exists());

    // An assumed refresh replaces the fit (the phase is still fitted).
    let r = replay(
        &capture(0),
        &ReplayOptions {
            assume: vec!["display.refresh=\"59.95Hz\"".into()],
            ..ReplayOptions::default()
        },
    )
    .unwrap();
    assert_eq!(
        serde_json::to_value(r.summary.refresh_from).unwrap(),
        serde_json::json!("assumed")
    );
    assert!((r.summary.refresh_hz - 59.95).abs() < 1e-6, "{}", r.summary.refresh_hz);

    let err = |args: &[&str]| {
        let o = bin().args(args).output().unwrap();
        let e = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(!e.contains("panicked"), "{e}");
        e
    };
    let e = err(&["replay", c, "--assume", "display.bufers=2"]);
    assert!(
        e.contains("`--assume display.bufers=2`") && e.contains("did you mean `buffers`"),
        "{e}"
    );
    let e = err(&["replay", c, "--assume", "display.buffers=40"]);
    assert!(
        e.contains("`--assume display.buffers=40`") && e.contains("between 2 and 16"),
        "{e}"
    );
    let e = err(&["replay", c, "--assume", "display.buffers"]);
    assert!(e.contains("--assume \"display.buffers\": expected key=value"), "{e}");
}

#[test]
fn a_tearing_swap_chain_takes_the_refresh_the_rest_of_the_capture_shows_and_alone_the_base_one() {
    // Tearing (`immediate`): screen times follow the GPU. The other swap
    // chains' composed frames still show the panel's vertical blanks.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(capture(0))
        .unwrap()
        .replace(",1,0,0,Hardware: Legacy Flip,", ",0,0,1,Hardware: Legacy Flip,");
    let path = dir.path().join("tearing.csv");
    std::fs::write(&path, &text).unwrap();
    let r = replay(&path, &ReplayOptions::default()).unwrap();
    assert_eq!(r.summary.model_present_mode, "immediate");
    assert_eq!(
        serde_json::to_value(r.summary.refresh_from).unwrap(),
        serde_json::json!("display_changes")
    );
    assert!((r.summary.refresh_hz - 59.95).abs() < 0.05, "{}", r.summary.refresh_hz);
    // Alone, nothing lies on a grid: the base model's 60 Hz, and the run
    // starts at the first CPU start.
    let alone: String = text
        .lines()
        .enumerate()
        .filter(|(i, l)| *i == 0 || l.starts_with("dwm.exe,1268,0x224B280A1C0"))
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    std::fs::write(&path, alone).unwrap();
    let r = replay(&path, &ReplayOptions::default()).unwrap();
    assert_eq!(r.summary.model_present_mode, "immediate");
    assert_eq!(
        serde_json::to_value(r.summary.refresh_from).unwrap(),
        serde_json::json!("default")
    );
    assert!((r.summary.refresh_hz - 60.0).abs() < 1e-6, "{}", r.summary.refresh_hz);
    let first = &r.frames[0];
    assert!(
        (first.cpu_start.0 - first.cpu_start.1).abs() < 1e-6,
        "{:?}",
        first.cpu_start
    );
}

#[test]
fn the_validation_report_lists_every_swap_chain_with_its_accuracy_and_why_frames_disagree() {
    let dir = tempfile::tempdir().unwrap();
    let rep = dir.path().join("report");
    let o = bin()
        .args(["replay", capture(0).to_str().unwrap(), "--report"])
        .arg(&rep)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let chains = std::fs::read_to_string(rep.join("chains.csv")).unwrap();
    // A header and test_case_0's ten swap chains.
    assert_eq!(chains.lines().count(), 11, "{chains}");
    assert!(chains.lines().nth(1).unwrap().starts_with("0,\"dwm.exe\""), "{chains}");
    assert!(
        chains.starts_with("chain,application,")
            && chains
                .lines()
                .next()
                .unwrap()
                .contains(",gpu_done_to_screen_refreshes_median,")
    );
    let md = std::fs::read_to_string(rep.join("report.md")).unwrap();
    assert!(md.contains("8 of 10 meet the accuracy targets"), "{md}");
    // The independent flip that tears misses whole refreshes and lands off
    // the grid; the reasons are counted and listed.
    assert!(md.contains("1 refresh(es) earlier than measured"), "{md}");
    assert!(md.contains("ms off the refresh grid"), "{md}");
    assert!(md.contains("replaced in the queue before its refresh"), "{md}");
    assert!(
        md.contains("Measured, from the GPU finishing a shown frame to the frame on screen: "),
        "{md}"
    );
    for i in 0..10 {
        assert!(rep.join(format!("chain-{i}.csv")).is_file(), "chain-{i}.csv");
        assert!(
            rep.join(format!("chain-{i}-screen.png")).is_file(),
            "chain-{i}-screen.png"
        );
    }
    let c3 = std::fs::read_to_string(rep.join("chain-3.csv")).unwrap();
    assert!(
        c3.starts_with("Line,PresentTime,MsUntilDisplayed,ReplayedMsUntilDisplayed,Reason\n"),
        "{c3}"
    );
    // --out and --report in one folder, and a report over another
    // command's results, are refused.
    let e = bin()
        .args(["replay", capture(0).to_str().unwrap(), "--report"])
        .arg(&rep)
        .arg("--out")
        .arg(&rep)
        .output()
        .unwrap();
    assert_eq!(e.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&e.stderr).contains("--out and --report name the same folder"));
    let out = dir.path().join("out");
    assert!(
        bin()
            .args(["replay", capture(0).to_str().unwrap(), "--out"])
            .arg(&out)
            .output()
            .unwrap()
            .status
            .success()
    );
    let e = bin()
        .args(["replay", capture(0).to_str().unwrap(), "--report"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(e.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&e.stderr).contains("holds the results of `rendersim replay`"),
        "{}",
        String::from_utf8_lossy(&e.stderr)
    );
    assert!(
        out.join("replay.json").is_file(),
        "the other command's results are kept"
    );
}

#[test]
fn a_what_if_that_ends_early_writes_its_folder_without_a_panic() {
    // issue 60 item 4: the what-if's frames end before the capture's.
    let dir = tempfile::tempdir().unwrap();
    for (i, set) in ["run.frames=5", "run.until=\"300ms\""].iter().enumerate() {
        let out = dir.path().join(format!("r{i}"));
        let o = bin()
            .args(["replay", capture(0).to_str().unwrap(), "--set", set, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success() && !err.contains("panicked"), "{set}: {err}");
        let cmp = std::fs::read_to_string(out.join("comparison.csv")).unwrap();
        // A header and the replayed swap chain's 197 frames.
        assert_eq!(cmp.lines().count(), 198, "{set}");
        assert!(out.join("whatif-frames.csv").is_file());
    }
}
