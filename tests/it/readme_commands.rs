//! Every command the README's "Using it" shows runs (issue 28 item 3, issue
//! 25 item 4): each `rendersim ...` line of that block is matched to a
//! concrete form of it here (placeholders filled with shipped inputs,
//! outputs into a temporary folder, sizes cut where a run is long), which
//! must exit 0. A line of the README this table does not cover fails the
//! test, so a command added to the README gets a run here. `measure` and
//! `study` need a build with `--features wgpu` and a Vulkan adapter; CI
//! runs them in their own steps (scripts/test-all.sh), and they are only
//! named here. The commands the README's prose shows (`` `rendersim run
//! models/fixed.toml --set workload.gpu=17ms` ``, ...) run too, as written
//! where they can be.

use std::path::Path;
use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The README's "Using it" commands: each line starting `rendersim `.
fn readme_commands() -> Vec<String> {
    let readme = std::fs::read_to_string(Path::new(ROOT).join("README.md")).unwrap();
    let using = readme.split("## Using it").nth(1).expect("a \"Using it\" section");
    let block = using.split("```sh").nth(1).unwrap().split("```").next().unwrap();
    block
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("rendersim "))
        .map(|l| l.split("  #").next().unwrap().trim().to_string())
        .collect()
}

/// A README line's start, and the arguments it runs with here (`{out}` is a
/// fresh temporary folder). `None`: named only (needs a GPU build).
type Case = (&'static str, Option<&'static [&'static str]>);

const CASES: &[Case] = &[
    (
        "rendersim run [MODEL]",
        Some(&[
            "run",
            "models/fixed.toml",
            "--set",
            "display.buffers=3",
            "--seed",
            "2",
            "--frames",
            "20",
            "--json",
            "--out",
            "{out}/run",
            "--trace",
            "{out}/trace.json",
        ]),
    ),
    (
        "rendersim experiment experiments/vsync-quantization.toml",
        Some(&[
            "experiment",
            "experiments/vsync-quantization.toml",
            "--out",
            "{out}/vq",
            "--quiet",
        ]),
    ),
    // A server that runs until Ctrl-C: here its options are checked;
    // `tests/it/explore.rs` serves it, asks it and stops it.
    ("rendersim explore", Some(&["explore", "--help"])),
    (
        "rendersim timeline",
        Some(&[
            "timeline",
            "models/fixed.toml",
            "--frames",
            "4",
            "--from",
            "2",
            "--out",
            "{out}/t.svg",
        ]),
    ),
    (
        "rendersim replay CAPTURE.csv",
        Some(&[
            "replay",
            "tests/fixtures/presentmon/test_case_1.csv",
            "--assume",
            "display.buffers=2",
            "--set",
            "cpu.max_frames_ahead=1",
            "--compare",
            "tests/fixtures/presentmon/test_case_0.csv",
            "--json",
            "--out",
            "{out}/replay",
            "--report",
            "{out}/replay-report",
        ]),
    ),
    ("rendersim isolate", Some(&["isolate", "models/fixed.toml", "--json"])),
    (
        "rendersim vcache",
        Some(&["vcache", "grid:64x64:shuffled:1", "--policy", "fifo:24", "--json"]),
    ),
    ("rendersim bench [", Some(&["bench", "hour", "--scale", "0.001"])),
    (
        "rendersim bench kernel --plot",
        Some(&["bench", "kernel", "--scale", "0.001", "--plot", "{out}/kernel.png"]),
    ),
    ("rendersim measure", None),
    ("rendersim study all", None),
    ("rendersim study estimation", None),
    ("rendersim study profile", None),
    (
        "rendersim calibrate",
        Some(&[
            "calibrate",
            "docs/measurements/nvidia-h200/load-sweep.csv",
            "--out",
            "{out}/h200.toml",
            "--vertex-cache",
            "nvidia",
            "--loo",
            "--report",
            "{out}/predictions.md",
        ]),
    ),
    (
        "rendersim predict",
        Some(&[
            "predict",
            "grid:64x64",
            "--device",
            "models/devices/nvidia-h200.toml",
            "--json",
        ]),
    ),
    (
        "rendersim lod-select INSTANCE.toml",
        Some(&[
            "lod-select",
            "examples/inputs/lod-instance.toml",
            "--algorithm",
            "optimal",
            "--json",
        ]),
    ),
    (
        "rendersim sortbuf SEQUENCE",
        Some(&[
            "sortbuf",
            "examples/inputs/states.txt",
            "--buffer",
            "4",
            "--strategy",
            "lru",
            "--json",
        ]),
    ),
    (
        "rendersim sortbuf lru-worst:8",
        Some(&["sortbuf", "lru-worst:8", "--sweep", "1,17,65,257"]),
    ),
    (
        "rendersim experiment experiments/state-sorting.toml",
        Some(&[
            "experiment",
            "experiments/state-sorting.toml",
            "--out",
            "{out}/ss",
            "--quiet",
        ]),
    ),
    (
        "rendersim run models/walkthrough-forest.toml",
        Some(&[
            "run",
            "models/walkthrough-forest.toml",
            "--set",
            "lod.policy=\"predictive+branch\"",
        ]),
    ),
    (
        "rendersim perceived-speed",
        Some(&[
            "perceived-speed",
            "models/walkthrough-forest.toml",
            "--set",
            "gpu.fragment.per_fragment=\"1.5ns\"",
            "--out",
            "{out}/speed.png",
        ]),
    ),
    (
        "rendersim experiment experiments/lod-policies.toml",
        Some(&[
            "experiment",
            "experiments/lod-policies.toml",
            "--out",
            "{out}/lod",
            "--quiet",
        ]),
    ),
    ("rendersim completions bash", Some(&["completions", "bash"])),
    ("rendersim man", Some(&["man"])),
];

#[test]
fn every_command_the_readme_shows_runs() {
    let lines = readme_commands();
    assert!(lines.len() >= 15, "{lines:?}");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let mut ran = 0;
    for line in &lines {
        // The longest matching start names the case.
        let case = CASES
            .iter()
            .filter(|(start, _)| line.starts_with(start))
            .max_by_key(|(start, _)| start.len())
            .unwrap_or_else(|| panic!("README command not run by this test: {line}"));
        let Some(args) = case.1 else { continue };
        let args: Vec<String> = args.iter().map(|a| a.replace("{out}", out)).collect();
        runs_ok(line, &args);
        ran += 1;
    }
    assert!(ran >= 15, "{ran}");
    // Every case matches a README line: none is left over from a command
    // the README no longer shows.
    for (start, _) in CASES {
        assert!(
            lines.iter().any(|l| l.starts_with(start)),
            "no README line starts {start:?}"
        );
    }
}

/// Runs `rendersim ARGS` from the repository root; it must exit 0 (the
/// failure names the README's `line`, what ran and its error output).
fn runs_ok(line: &str, args: &[String]) {
    let o = Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .current_dir(ROOT)
        .args(args)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "README: {line}\nran: rendersim {}\nexit {:?}: {}",
        args.join(" "),
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The README's prose commands: each `` `rendersim ...` `` span outside the
/// fenced blocks with arguments past its subcommand (`` `rendersim vcache` ``
/// alone names a command; it does not show one to run).
fn readme_prose_commands() -> Vec<String> {
    let readme = std::fs::read_to_string(Path::new(ROOT).join("README.md")).unwrap();
    // Outside fences: the even-numbered parts between ``` marks.
    let prose: String = readme.split("```").step_by(2).collect::<Vec<_>>().join("\n");
    prose
        .split('`')
        .skip(1)
        .step_by(2)
        .map(|span| span.split_whitespace().collect::<Vec<_>>().join(" "))
        .filter(|span| span.starts_with("rendersim ") && span.split(' ').count() >= 3)
        .collect()
}

/// A word that stands for an input: `DIR`, `FILE`, `DIR/model.toml`,
/// `experiments/NAME.toml` (a path part, before its extension, in capitals).
fn placeholder(word: &str) -> bool {
    word.split('/').any(|part| {
        let stem = part.split('.').next().unwrap_or_default();
        stem.len() >= 3 && stem.chars().all(|c| c.is_ascii_uppercase() || c == '_')
    })
}

#[test]
fn every_command_the_readmes_prose_shows_runs() {
    // The prose's commands run as written (from the repository root; none
    // writes a file), except those with a placeholder or a long run, which
    // run in the concrete form given here (outputs in a temporary folder).
    // A prose command with a placeholder and no form here fails the test.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap().to_string();
    let forms: &[(&str, &[&[&str]])] = &[
        // The hour at a thousandth of its length.
        ("rendersim bench hour", &[&["bench", "hour", "--scale", "0.001"]]),
        (
            "rendersim run DIR/model.toml",
            &[
                &["run", "models/fixed.toml", "--frames", "20", "--out", "{out}/run"],
                &["run", "{out}/run/model.toml", "--frames", "20"],
            ],
        ),
        (
            "rendersim experiment experiments/NAME.toml",
            &[&[
                "experiment",
                "experiments/vsync-quantization.toml",
                "--quiet",
                "--out",
                "{out}/named",
            ]],
        ),
        (
            "rendersim experiment FILE --quiet",
            &[&[
                "experiment",
                "experiments/vsync-quantization.toml",
                "--quiet",
                "--out",
                "{out}/exp",
            ]],
        ),
    ];
    let commands = readme_prose_commands();
    assert!(
        commands
            .iter()
            .any(|c| c == "rendersim run models/fixed.toml --set workload.gpu=17ms"),
        "{commands:?}"
    );
    for command in &commands {
        let runs: Vec<Vec<String>> = match forms.iter().find(|(c, _)| c == command) {
            Some((_, runs)) => runs
                .iter()
                .map(|r| r.iter().map(|a| a.replace("{out}", &out)).collect())
                .collect(),
            None => {
                let words: Vec<String> = command.split(' ').skip(1).map(str::to_string).collect();
                assert!(
                    !words.iter().any(|w| placeholder(w)),
                    "README prose command with a placeholder and no concrete form here: {command}"
                );
                vec![words]
            }
        };
        for args in runs {
            runs_ok(command, &args);
        }
    }
    assert!(placeholder("DIR/model.toml") && placeholder("FILE") && placeholder("experiments/NAME.toml"));
    assert!(!placeholder("models/fixed.toml") && !placeholder("workload.gpu=17ms") && !placeholder("--quiet"));
}
