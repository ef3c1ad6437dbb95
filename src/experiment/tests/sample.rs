//! Sampled experiments (`[sample]`: Latin hypercube, Sobol' with Saltelli's
//! design) run against the fake simulator of `tests.rs`.

use super::*;

const SOBOL: &str = r#"
name = "sampled"
[sample]
method = "sobol"
n = 64
seed = 3
bootstrap = 200
[[sample.param]]
key = "workload.gpu"
from = 5
to = 40
unit = "ms"
[[sample.param]]
key = "display.buffers"
from = 2
to = 3
integer = true
[[sample.param]]
key = "workload.kind"
from = 1
to = 100
scale = "log"
[[metric]]
path = "metrics.frame_time_ms.mean"
[[metric]]
path = "metrics.display_interval_ms.mean"
"#;

#[test]
fn a_sobol_sample_runs_saltellis_points_and_ranks_the_parameters() {
    let exp = parse(SOBOL);
    let pts = expand_points(&exp);
    assert_eq!(pts.len(), 64 * 5);
    assert_eq!(pts[0].assignments.len(), 3);
    assert!(
        pts.iter()
            .all(|p| p.assignments[0].1.as_str().is_some_and(|s| s.ends_with("ms")))
    );
    assert!(
        pts.iter()
            .all(|p| matches!(p.assignments[1].1.as_integer(), Some(2 | 3)))
    );
    let dir = tempfile::tempdir().unwrap();
    let res = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    let runs = read(dir.path(), "runs.csv");
    assert!(
        runs.starts_with("point,workload.gpu,display.buffers,workload.kind,seed,"),
        "{runs}"
    );
    // The fake's frame time is the GPU cost (plus noise of the seed only):
    // workload.gpu explains it all, the others nothing.
    let ft = &res.sensitivity[0];
    let idx = ft.indices.as_ref().unwrap();
    assert_eq!(idx[0].0, "workload.gpu");
    assert!(idx[0].1.first > 0.8 && idx[0].1.total > 0.9, "{idx:?}");
    assert!(idx[1].1.total < 0.01 && idx[2].1.total < 0.01, "{idx:?}");
    // The display interval depends on the GPU cost and the buffers (and the
    // unused key has no effect).
    let di = res.sensitivity[1].indices.as_ref().unwrap();
    assert!(
        di[0].1.total > 0.5 && di[1].1.total > 0.001 && di[2].1.total < 1e-9,
        "{di:?}"
    );
    let report = read(dir.path(), "report.md");
    assert!(report.contains("## Sensitivity (Sobol' indices)"), "{report}");
    assert!(report.contains("Sampled parameters (Saltelli's design"), "{report}");
    assert!(report.contains("Over the 320 sampled points with a value"), "{report}");
    assert!(report.contains("![Sobol' indices of metrics.frame_time_ms.mean](sensitivity-1.svg)"));
    assert!(dir.path().join("sensitivity-2.png").is_file());
    let csv = read(dir.path(), "sensitivity.csv");
    assert_eq!(csv.lines().count(), 1 + 2 * 3);
    // The same file gives the same points and indices.
    let again = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    assert_eq!(again.sensitivity, res.sensitivity);
}

#[test]
fn a_latin_hypercube_has_n_points_and_no_indices() {
    let text = SOBOL.replace("\"sobol\"", "\"latin_hypercube\"");
    let exp = parse(&text);
    assert_eq!(expand_points(&exp).len(), 64);
    let dir = tempfile::tempdir().unwrap();
    let res = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    assert!(res.sensitivity.is_empty());
    assert!(!dir.path().join("sensitivity.csv").exists());
    // Every stratum of the GPU range holds one point.
    let mut strata: Vec<usize> = expand_points(&exp)
        .iter()
        .map(|p| {
            let ms = numeric_coord(&p.assignments[0].1).unwrap();
            ((ms - 5.0) / 35.0 * 64.0).floor() as usize
        })
        .collect();
    strata.sort();
    assert_eq!(strata, (0..64).collect::<Vec<_>>());
}

#[test]
fn sample_errors_name_the_entry() {
    let cases = [
        (
            SOBOL.replace("\"sobol\"", "\"morris\""),
            "`sample.method`: unknown method `morris`",
        ),
        (
            SOBOL.replace("n = 64", "n = 1"),
            "`sample.n`: must be between 2 and 1000000",
        ),
        (
            SOBOL.replace("from = 1\nto = 100", "from = 0\nto = 100"),
            "`sample.param[2].scale`: `log` needs `from` > 0",
        ),
        (
            SOBOL.replace("from = 2\nto = 3", "from = 2.5\nto = 3"),
            "`sample.param[1]`: `integer = true` needs whole numbers",
        ),
        (
            SOBOL.replace("from = 5\nto = 40", "from = 40\nto = 5"),
            "`sample.param[0]`: needs finite `from` < `to`",
        ),
        (
            SOBOL.replace("unit = \"ms\"", "unit = \"m s\""),
            "`sample.param[0].unit`: `m s` is not a unit",
        ),
        (
            SOBOL.replace("key = \"display.buffers\"", "key = \"workload.gpu\""),
            "is sampled twice",
        ),
        (SOBOL.replace("bootstrap = 200", "bootstrap = -1"), "`sample.bootstrap`"),
        (
            SOBOL.replace("[sample]", "[[sweep]]\nkey = \"x\"\nvalues = [1]\n[sample]"),
            "give either `[[sweep]]`s or `[sample]`, not both",
        ),
        (SOBOL.replace("seed = 3", "seed = 3\nsize = 4"), "unknown field `size`"),
        (
            SOBOL
                .replace("\"sobol\"", "\"latin_hypercube\"")
                .replace("seed = 3", "seed = 3\nscramble = false"),
            "`sample.scramble`: belongs to method = \"sobol\"",
        ),
        (SOBOL.replace("seed = 3", "seed = 3\nscramble = 1"), "scramble"),
        (
            SOBOL.to_string()
                + &(0..62)
                    .map(|i| format!("[[sample.param]]\nkey = \"extra.k{i}\"\nfrom = 0\nto = 1\n"))
                    .collect::<String>(),
            "`sample.param`: 65 parameters; a sobol sample takes at most 64",
        ),
    ];
    for (text, says) in cases {
        let e = parse_err(&text);
        assert!(e.contains(says), "expected {says:?} in {e}");
        assert!(e.starts_with("experiments/bad.toml"), "{e}");
    }
}
