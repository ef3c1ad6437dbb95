//! PresentMon 2 output read back (issue 26 item 4): a frame-pipeline run's
//! `frames.csv` is a PresentMon capture, and `rendersim replay` reproduces
//! the run from it exactly, picosecond for picosecond: the CPU's starts and
//! presents, the GPU's start and end, every frame's fate and screen time.
//! What a capture cannot say (swap-chain images, frames in flight, a
//! variable refresh) is given as assumptions; without them, the replay's
//! DXGI defaults (three of each) still reproduce the CPU, the display and
//! the GPU's end of every shipped model, which all use at most three.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rendersim::config::{Overrides, load_model};
use rendersim::studies::replay::{ReplayOptions, replay};
use rendersim::systems::frame_pipeline::PipelineRun;
use rendersim::systems::run_model;

/// rendersim's own columns, which a PresentMon capture does not carry
/// (input sampling, the model's accounting of CPU work and blocking).
const OWN: [&str; 4] = [
    "MsBetweenSimulationStart",
    "MsInputLatency",
    "MsCPUWork",
    "MsCPUBlocked",
];

/// The columns that depend on when the GPU began a frame, which the number
/// of swap-chain images decides.
const GPU_START: [&str; 4] = ["MsGPULatency", "MsGPUTime", "MsGPUBusy", "MsGPUWait"];

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The shipped models of the frame pipeline (a model without `system` is one).
fn shipped() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(repo().join("models"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter(|p| {
            let t: toml::Table = std::fs::read_to_string(p).unwrap().parse().unwrap();
            t.get("system")
                .and_then(|s| s.as_str())
                .is_none_or(|s| s == "frame_pipeline")
        })
        .collect();
    v.sort();
    v
}

/// Runs `model` with `sets` and writes its frames.csv into `dir`.
fn run_to_csv(model: &Path, sets: &[&str], dir: &Path) -> (PipelineRun, PathBuf) {
    let m = load_model(Some(model), &Overrides::with_sets(sets)).unwrap();
    let run = run_model(&m.source, &m.table, None)
        .unwrap()
        .downcast::<PipelineRun>()
        .unwrap_or_else(|_| panic!("{}: not a frame-pipeline run", model.display()));
    let path = dir.join("frames.csv");
    run.write_frames_csv(std::fs::File::create(&path).unwrap()).unwrap();
    (run, path)
}

/// A CSV as columns of text cells.
fn columns(text: &str) -> BTreeMap<String, Vec<String>> {
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let names: Vec<String> = r.headers().unwrap().iter().map(str::to_string).collect();
    let mut cols: BTreeMap<String, Vec<String>> = names.iter().map(|n| (n.clone(), vec![])).collect();
    for rec in r.records() {
        for (n, v) in names.iter().zip(rec.unwrap().iter()) {
            cols.get_mut(n).unwrap().push(v.to_string());
        }
    }
    cols
}

/// Replays `csv` with `assume` and returns the columns that differ from
/// the run's, beside the first differing row of each.
fn replay_differs(csv: &Path, assume: &[String], skip: &[&str]) -> Vec<String> {
    let r = replay(
        csv,
        &ReplayOptions {
            assume: assume.to_vec(),
            ..ReplayOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    let mut back = Vec::new();
    r.replayed.write_csv(&mut back).unwrap();
    let (a, b) = (
        columns(&std::fs::read_to_string(csv).unwrap()),
        columns(&String::from_utf8(back).unwrap()),
    );
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    a.iter()
        .filter(|(name, _)| !OWN.contains(&name.as_str()) && !skip.contains(&name.as_str()))
        .filter_map(|(name, va)| {
            let vb = &b[name];
            assert_eq!(va.len(), vb.len(), "{name}");
            let i = va.iter().zip(vb).position(|(x, y)| x != y)?;
            Some(format!("{name} (row {i}: {} against {})", va[i], vb[i]))
        })
        .collect()
}

/// The assumptions that make the replay's model the run's: its swap-chain
/// images and frames in flight.
fn assumptions(run: &PipelineRun) -> Vec<String> {
    vec![
        format!("display.buffers={}", run.config.display.buffers),
        format!("cpu.max_frames_ahead={}", run.config.cpu.max_frames_ahead),
    ]
}

#[test]
fn every_shipped_frame_pipeline_model_replays_exactly_from_its_frames_csv() {
    let models = shipped();
    assert!(models.len() >= 8, "{models:?}");
    for model in models {
        let dir = tempfile::tempdir().unwrap();
        let (run, csv) = run_to_csv(&model, &[], dir.path());
        let d = replay_differs(&csv, &assumptions(&run), &[]);
        assert!(d.is_empty(), "{}: {d:?}", model.display());
        // The DXGI defaults (three images, three frames in flight) hold every
        // shipped model, so only when the GPU began a frame can differ.
        let d = replay_differs(&csv, &[], &GPU_START);
        assert!(d.is_empty(), "{} without assumptions: {d:?}", model.display());
    }
}

#[test]
fn present_modes_composition_pacing_variable_refresh_and_frame_generation_replay_exactly() {
    let fixed = repo().join("models/fixed.toml");
    let cases: [(&[&str], &[&str]); 13] = [
        (&["display.present_mode=\"mailbox\"", "display.buffers=3"], &[]),
        // Composed, every frame of this GPU-bound model is shown two refreshes
        // after the one before: its screen times fit 30 Hz as well as 60 Hz,
        // so the capture cannot tell the refresh, and the test gives it.
        (&["display.composition=\"composed\""], &["display.refresh=\"60Hz\""]),
        // The compositor's timing, not assumed: inferred from the frames,
        // from their screen times and (mailbox, skipping) their fates.
        (
            &[
                "display.composition=\"composed\"",
                "display.present_mode=\"mailbox\"",
                "display.buffers=3",
                "workload.gpu=\"6ms\"",
                "workload.cpu=\"2ms\"",
                "display.compositor.wake=\"2.5ms\"",
                "display.compositor.refreshes=2",
            ],
            &[],
        ),
        (
            &[
                "display.composition=\"composed\"",
                "display.buffers=3",
                // Slower than the refresh, so frames are ready at every
                // phase; a GPU faster than the refresh would wait for the
                // images the compositor frees at its wake, every frame ready
                // at one phase, and the wake would not show (docs/replay.md).
                "workload.gpu=\"20.3ms\"",
                "display.compositor.wake=\"5ms\"",
                "display.compositor.refreshes=3",
            ],
            &[],
        ),
        (&["display.vsync=false", "workload.gpu=\"9ms\""], &[]),
        (&["cpu.max_frames_ahead=1", "workload.cpu=\"4ms\""], &[]),
        (&["pacing.low_latency=true", "display.vsync=false"], &[]),
        (&["pacing.limit=\"40Hz\"", "pacing.limit_from=\"present\""], &[]),
        (&["pacing.limit=\"40Hz\"", "pacing.limit_from=\"submit\""], &[]),
        (&["pacing.limit=\"50Hz\"", "display.refresh=\"144Hz\""], &[]),
        (
            &["display.refresh=\"144Hz\"", "display.vrr.min_refresh=\"48Hz\""],
            &["display.refresh=\"144Hz\"", "display.vrr.min_refresh=\"48Hz\""],
        ),
        // Frame generation (assumed: a capture does not say it), with its
        // generated rows in the capture, which the replay skips and makes
        // again.
        (
            &[
                "display.vsync=false",
                "display.buffers=3",
                "frame_generation.enabled=true",
            ],
            &["frame_generation.enabled=true"],
        ),
        (
            &[
                "display.buffers=4",
                "frame_generation.enabled=true",
                "frame_generation.cost=\"2ms\"",
            ],
            // Rendered frames every other refresh: the refresh (fitted to the
            // rendered frames alone) is given.
            &[
                "frame_generation.enabled=true",
                "frame_generation.cost=\"2ms\"",
                "display.refresh=\"60Hz\"",
            ],
        ),
    ];
    for (sets, extra) in cases {
        let dir = tempfile::tempdir().unwrap();
        let (run, csv) = run_to_csv(&fixed, sets, dir.path());
        let mut assume = assumptions(&run);
        assume.extend(extra.iter().map(|s| s.to_string()));
        let d = replay_differs(&csv, &assume, &[]);
        assert!(d.is_empty(), "{sets:?}: {d:?}");
    }
}

#[test]
fn a_replayed_capture_replays_again_to_the_same_frames() {
    // The replay's own frames.csv (on the capture's clock and swap chain) is
    // a capture too: replaying it gives it back.
    let dir = tempfile::tempdir().unwrap();
    let capture = repo().join("tests/fixtures/presentmon/test_case_0.csv");
    let first = replay(&capture, &ReplayOptions::default()).unwrap();
    let path = dir.path().join("frames.csv");
    first.replayed.write_csv(std::fs::File::create(&path).unwrap()).unwrap();
    assert_eq!(replay_differs(&path, &[], &[]), Vec::<String>::new());
}
