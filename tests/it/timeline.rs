//! `rendersim timeline` (issue 13 item 2): the picture of paper 000
//! Figure 4 is written as SVG or PNG by the file's extension, shows every
//! lane and the frames drawn, and bad requests end with a clear error
//! (exit 2, no file written, no panic).

use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

#[test]
fn writes_svg_and_png_with_every_lane() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("t.svg");
    let o = bin()
        .current_dir(ROOT)
        .args(["timeline", "models/fixed.toml", "--frames", "4", "--from", "2", "--out"])
        .arg(&svg)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("frames 2-5"));
    let text = std::fs::read_to_string(&svg).unwrap();
    for lane in [
        "CPU thread",
        "command FIFO fill",
        "GPU front end",
        "geometry",
        "fragment",
        "display",
    ] {
        assert!(text.contains(lane), "lane {lane} missing");
    }
    assert!(text.contains("vertical blank"), "vsync on: vertical blanks marked");
    // Frames are labelled by number in their bars: every drawn frame appears.
    let texts: Vec<&str> = text
        .split("<text")
        .skip(1)
        .filter_map(|t| t.split('>').nth(1)?.split('<').next())
        .map(str::trim)
        .collect();
    for f in 2..=5 {
        assert!(
            texts.contains(&f.to_string().as_str()),
            "frame {f} not labelled: {texts:?}"
        );
    }
    let png = dir.path().join("t.png");
    let o = bin()
        .args(["timeline", "--frames", "3", "--set", "display.vsync=false", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(&std::fs::read(&png).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
}

/// Runs and expects exit 2 and no file; returns stderr.
fn refused(args: &[&str], out: &std::path::Path) -> String {
    let o = bin()
        .current_dir(ROOT)
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
    err
}

#[test]
fn bad_requests_are_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let jpg = dir.path().join("t.jpg");
    let err = refused(&["timeline", "--frames", "3"], &jpg);
    assert!(err.contains("t.jpg") && err.contains(".png or .svg"), "{err}");
    let svg = dir.path().join("t.svg");
    let err = refused(&["timeline", "--frames", "0"], &svg);
    assert!(err.contains("--frames") && err.contains("1..=120"), "{err}");
    let err = refused(&["timeline", "--frames", "500"], &svg);
    assert!(err.contains("--frames"), "{err}");
    let err = refused(&["timeline", "models/mfr-cluster.toml", "--frames", "3"], &svg);
    assert!(err.contains("frame pipeline") && err.contains("multi_rate"), "{err}");
    let err = refused(&["timeline", "--frames", "3", "--set", "cpu.per_draw=\"fast\""], &svg);
    assert!(err.contains("cpu.per_draw"), "{err}");
    let err = refused(&["timeline", "--frames", "3", "--from", "100001"], &svg);
    assert!(err.contains("100000"), "{err}");
}

#[test]
fn a_replayed_capture_is_drawn_as_the_run_its_replay_makes() {
    // A `system = "replay"` model: the capture's frames on the pipeline's
    // lanes, with the model file's what-if applied.
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("capture.toml");
    let capture = std::path::Path::new(ROOT).join("tests/fixtures/presentmon/test_case_0.csv");
    std::fs::write(
        &model,
        format!(
            "system = \"replay\"\ncapture = {:?}\n[whatif]\ncpu.max_frames_ahead = 1\n",
            capture.display().to_string()
        ),
    )
    .unwrap();
    let svg = dir.path().join("t.svg");
    let o = bin()
        .args([
            "timeline",
            model.to_str().unwrap(),
            "--frames",
            "8",
            "--from",
            "20",
            "--out",
        ])
        .arg(&svg)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("Frames 20-27") && text.contains("display"),
        "{}",
        &text[..200.min(text.len())]
    );
    // Past the capture's frames, and a capture that is not there: clear errors.
    let err = refused(
        &["timeline", model.to_str().unwrap(), "--frames", "10", "--from", "195"],
        &svg.with_extension("png"),
    );
    assert!(err.contains("workload.cpu") && err.contains("197 frames"), "{err}");
    std::fs::write(&model, "system = \"replay\"\ncapture = \"none.csv\"\n").unwrap();
    let err = refused(
        &["timeline", model.to_str().unwrap(), "--frames", "3"],
        &svg.with_extension("png"),
    );
    assert!(
        err.contains("capture.toml") && err.contains("cannot read capture"),
        "{err}"
    );
}
