//! Checks of an experiment's results (`[[check]]`): bounds taken from
//! other metric paths, claims reported as verdicts rather than failures, and
//! the errors for bad labels, bounds and claims; run against the fake
//! simulator of `tests.rs`.

use super::*;

#[test]
fn checks_against_bounds_from_other_paths() {
    // Fake: frame_time mean = gpu + noise; display interval = ceil(gpu / 16.67) * 16.67.
    let exp = parse(
        r#"
name = "bounds"
replications = 2
[[sweep]]
key = "workload.gpu"
values = ["10ms", "20ms"]
[[derived]]
name = "frame_err"
kind = "relative_error"
path = "metrics.frame_time_ms.mean"
reference = { "workload.gpu" = "10ms" }
[[check]]
path = "metrics.frame_time_ms.mean"
at_most_path = "metrics.display_interval_ms.mean"
tolerance = 0.0
[[check]]
path = "metrics.display_interval_ms.mean"
at_least_path = "metrics.frame_time_ms.mean"
at_most_path = "frame_err"
rel_tolerance = 0.01
"#,
    );
    assert!(
        exp.tracked_paths()
            .contains(&"metrics.display_interval_ms.mean".to_string())
    );
    let dir = tempfile::tempdir().unwrap();
    let res = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    assert_eq!(res.checks.len(), 4);
    // frame time (10, 20) <= interval (16.67, 33.33): both pass.
    assert!(res.checks[0].passed && res.checks[1].passed);
    assert_eq!(res.checks[0].expect, None);
    // interval >= frame time, but not <= frame_err (0 and 1): both fail.
    assert!(!res.checks[2].passed && !res.checks[3].passed);
    assert_eq!(res.checks_failed, 2);
    assert!(
        res.checks[2]
            .expected_text
            .starts_with("between `metrics.frame_time_ms.mean` = 9.995 and `frame_err` = 0"),
        "{}",
        res.checks[2].expected_text
    );
    let report = read(dir.path(), "report.md");
    assert!(
        report.contains("at most `metrics.display_interval_ms.mean` = 16.6617"),
        "{report}"
    );
}

#[test]
fn claims_are_verdicts_not_failures() {
    let exp = parse(
        r#"
name = "claims"
[[sweep]]
key = "display.buffers"
values = [2, 3]
labels = ["double buffering", "triple buffering"]
[[sweep]]
key = "workload.gpu"
values = ["10ms", "20ms"]
[[derived]]
name = "vs_double"
kind = "ratio"
path = "metrics.display_interval_ms.mean"
reference = { "display.buffers" = 2 }
[[plot]]
file = "by-buffers"
kind = "line"
x = "display.buffers"
y = "metrics.display_interval_ms.mean"
[[check]]
path = "vs_double"
where = { "display.buffers" = 3 }
at_most = 0.95
tolerance = 0
claim = "triple buffering shortens the interval by at least 5%"
[[check]]
path = "vs_double"
where = { "display.buffers" = 3 }
at_least = 1.0
tolerance = 0
claim = "triple buffering never helps"
[[check]]
path = "metrics.frame_time_ms.mean"
where = { "workload.gpu" = "10ms" }
at_least = 9.0
at_most = 11.0
tolerance = 0
"#,
    );
    assert!(exp.sweeps[0].categorical);
    assert_eq!(exp.sweeps[0].labels, vec!["double buffering", "triple buffering"]);
    let dir = tempfile::tempdir().unwrap();
    let res = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    assert_eq!(res.checks.len(), 6);
    // The second claim does not hold, yet nothing failed.
    assert_eq!(res.checks_failed, 0);
    assert_eq!(
        res.claims(),
        vec![
            (
                "triple buffering shortens the interval by at least 5%".to_string(),
                2,
                2
            ),
            ("triple buffering never helps".to_string(), 0, 2),
        ]
    );
    let ratio = res.points[2].derived_value("vs_double").unwrap();
    assert!((ratio - 0.9).abs() < 1e-3, "{ratio}");
    let not_holding = &res.checks[2];
    assert!(!not_holding.passed);
    assert_eq!(not_holding.expected_text, "at least 1");
    assert!((not_holding.error.unwrap() - (ratio - 1.0)).abs() < 1e-12);
    let report = read(dir.path(), "report.md");
    assert!(report.contains("## Claims"), "{report}");
    assert!(
        report.contains("- **HOLDS**: triple buffering shortens the interval by at least 5%"),
        "{report}"
    );
    assert!(
        report.contains("- **DOES NOT HOLD**: triple buffering never helps"),
        "{report}"
    );
    assert!(report.contains("2 of 2 passed"), "{report}");
    assert!(report.contains("0 (inside the bounds)"), "{report}");
    let table = res.table(&exp);
    assert!(
        table.contains("claim DOES NOT HOLD: triple buffering never helps"),
        "{table}"
    );
    // The categorical x axis is labelled with the sweep's labels.
    let svg = read(dir.path(), "by-buffers.svg");
    assert!(
        svg.contains("double buffering") && svg.contains("triple buffering"),
        "{svg}"
    );
}

#[test]
fn bad_labels_bounds_and_claims() {
    let e = parse_err("name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\nlabels = [\"one\"]\n");
    assert!(
        e.contains("sweep[0].labels") && e.contains("one label per value"),
        "{e}"
    );
    let e = parse_err("name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\nlabels = [\"one\", \"one\"]\n");
    assert!(e.contains("used twice"), "{e}");
    let e = parse_err("name = \"x\"\n[[check]]\npath = \"m\"\nat_least = 2.0\nat_most = 1.0\ntolerance = 0\n");
    assert!(e.contains("is above"), "{e}");
    let e = parse_err("name = \"x\"\n[[check]]\npath = \"m\"\nat_least = 2.0\nat_least_path = \"n\"\ntolerance = 0\n");
    assert!(e.contains("not both"), "{e}");
    let e = parse_err("name = \"x\"\n[[check]]\npath = \"m\"\nexpect = 1.0\ntolerance = 0\nclaim = \" \"\n");
    assert!(e.contains("claim"), "{e}");
    let e = parse_err("name = \"x\"\n[[derived]]\nname = \"r\"\nkind = \"ratio\"\n");
    assert!(e.contains("needs `path`"), "{e}");
}
