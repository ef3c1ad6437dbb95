//! `rendersim study estimation` (issue 11 item 8): the fit and the scores
//! on synthetic passes with known costs (closed forms), the CLI's errors,
//! and a small study on this machine's adapter (skipped without one).

use rendersim::components::vertex_cache::CachePolicy;
use rendersim::measure::estimation::{EstimationSetup, EstimationStudy, PassKind, PassMeasurement, Plan, analyze};

fn setup() -> EstimationSetup {
    EstimationSetup {
        single: 300,
        multi: 60,
        prototypes: 7,
        repeats: 1,
        ..EstimationSetup::default()
    }
}

const OVERHEAD_NS: f64 = 300.0;
/// The synthetic device's cost: ns per transformed vertex, ns per pixel.
const PER_VERTEX_NS: f64 = 0.5;
const PER_PIXEL_NS: f64 = 0.02;

/// Passes measured on a synthetic device whose object time is exactly h4's
/// formula; `extra_multi_ns` is added to every multi-object pass.
fn synthetic(plan: &Plan, extra_multi_ns: f64) -> (Vec<PassMeasurement>, Vec<u64>) {
    let transformed: Vec<u64> = plan
        .meshes
        .iter()
        .map(|m| m.cache_stats(&CachePolicy::Lavapipe).transformed)
        .collect();
    let measured = plan
        .passes
        .iter()
        .map(|p| {
            let mut t = OVERHEAD_NS;
            let mut vs = 0;
            for o in &p.objects {
                let tv = transformed[o.prototype];
                vs += tv;
                t += PER_VERTEX_NS * tv as f64 + PER_PIXEL_NS * o.pixels(plan.setup.target);
            }
            if p.kind == PassKind::Multi {
                t += extra_multi_ns;
            }
            PassMeasurement {
                time_ns: t,
                times_ns: vec![t],
                vs_invocations: vs,
                fs_invocations: 0,
                stable: true,
                wall_s: 1e-4,
            }
        })
        .collect();
    (measured, transformed)
}

fn study(extra_multi_ns: f64) -> (Plan, EstimationStudy, Vec<u64>) {
    let plan = Plan::new(&setup()).unwrap();
    let (m, tv) = synthetic(&plan, extra_multi_ns);
    let s = analyze(&plan, &m, "synthetic", "test", 0.1).unwrap();
    (plan, s, tv)
}

fn within_rel(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-12)
}

#[test]
fn the_fit_recovers_known_constants_from_synthetic_passes() {
    let (plan, s, tv) = study(0.0);
    assert_eq!(s.overhead_ms, OVERHEAD_NS / 1e6);
    // h4's formula is the device's: its constants come back (ps per unit).
    let [a, b] = s.constants.h4_ps;
    assert!(
        within_rel(a, PER_VERTEX_NS * 1e3, 1e-6) && within_rel(b, PER_PIXEL_NS * 1e3, 1e-6),
        "{:?}",
        s.constants
    );
    // h1 and h2 are one-variable least squares without intercept:
    // c = sum(x y) / sum(x x) over the single-object passes (y in ps).
    let (mut xy1, mut xx1, mut xy2, mut xx2) = (0.0, 0.0, 0.0, 0.0);
    for p in plan.passes.iter().filter(|p| p.kind == PassKind::Single) {
        let o = &p.objects[0];
        let y = (PER_VERTEX_NS * tv[o.prototype] as f64 + PER_PIXEL_NS * o.pixels(plan.setup.target)) * 1e3;
        let t = plan.prototypes[o.prototype].triangles as f64;
        let v = tv[o.prototype] as f64;
        xy1 += t * y;
        xx1 += t * t;
        xy2 += v * y;
        xx2 += v * v;
    }
    assert!(
        within_rel(s.constants.h1_per_triangle_ps, xy1 / xx1, 1e-9),
        "{:?}",
        s.constants
    );
    assert!(
        within_rel(s.constants.h2_per_transformed_vertex_ps, xy2 / xx2, 1e-9),
        "{:?}",
        s.constants
    );
    // Fitted exactly, h4 and pos (linear in pixels between its samples)
    // predict the multi-object passes without error; h1 does not.
    for name in ["h4", "pos"] {
        let mse = s.scores[name].mse_ms2.unwrap();
        assert!(mse < 1e-18, "{name}: {mse}");
        assert!(s.fit[name].mse_ms2.unwrap() < 1e-18, "{name}");
    }
    assert!(s.scores["h1"].mse_ms2.unwrap() > 1e-9);
    assert!(!s.best.is_empty());
    assert_eq!(s.checks.transformed_sum_mismatches, 0);
    assert_eq!(s.checks.transformed_table_mismatches, 0);
    for (p, want) in s.prototypes.iter().zip(&tv) {
        assert_eq!(p.transformed, *want);
        assert_eq!(p.pos_table.len(), plan.setup.pos_sizes);
    }
}

#[test]
fn the_scores_of_a_constructed_case_follow_by_hand() {
    // Every multi-object pass takes 0.25 ms more than the device's formula.
    let delta_ms = 0.25;
    let (plan, s, tv) = study(delta_ms * 1e6);
    for name in ["h4", "pos"] {
        let x = &s.scores[name];
        assert!(
            within_rel(x.mse_ms2.unwrap(), delta_ms * delta_ms, 1e-9),
            "{name}: {x:?}"
        );
        assert!(within_rel(x.mean_error_ms.unwrap(), -delta_ms, 1e-9), "{name}: {x:?}");
        assert!(
            within_rel(x.mean_abs_error_ms.unwrap(), delta_ms, 1e-9),
            "{name}: {x:?}"
        );
        assert_eq!(x.underestimated_fraction, Some(1.0), "{name}");
    }
    // h1 by hand: overhead + c1 * triangles summed over each pass's objects.
    let c1_ns = s.constants.h1_per_triangle_ps / 1e3;
    let (mut se, mut e, mut under, mut n) = (0.0, 0.0, 0, 0);
    for p in plan.passes.iter().filter(|p| p.kind == PassKind::Multi) {
        let mut est = OVERHEAD_NS;
        let mut actual = OVERHEAD_NS + delta_ms * 1e6;
        for o in &p.objects {
            est += c1_ns * plan.prototypes[o.prototype].triangles as f64;
            actual += PER_VERTEX_NS * tv[o.prototype] as f64 + PER_PIXEL_NS * o.pixels(plan.setup.target);
        }
        let err = (est - actual) / 1e6;
        se += err * err;
        e += err;
        under += usize::from(err < 0.0);
        n += 1;
    }
    let h1 = &s.scores["h1"];
    assert_eq!(n, 60);
    assert!(within_rel(h1.mse_ms2.unwrap(), se / n as f64, 1e-9), "{h1:?}");
    assert!(within_rel(h1.mean_error_ms.unwrap(), e / n as f64, 1e-9), "{h1:?}");
    assert_eq!(h1.underestimated_fraction, Some(under as f64 / n as f64));
    // Operations per pass: one per object for h1-h4, two table reads for pos.
    let objects = s.passes.multi_objects as f64 / n as f64;
    assert!(
        within_rel(h1.ops_per_frame, objects, 1e-12) && within_rel(s.scores["pos"].ops_per_frame, 2.0 * objects, 1e-12)
    );
    assert!(s.best == "h4" || s.best == "pos", "{}", s.best);
}

#[test]
fn a_counter_that_does_not_add_up_is_reported() {
    let plan = Plan::new(&setup()).unwrap();
    let (mut m, _) = synthetic(&plan, 0.0);
    let i = plan.passes.iter().position(|p| p.kind == PassKind::Multi).unwrap();
    m[i].vs_invocations += 1;
    let s = analyze(&plan, &m, "synthetic", "test", 0.1).unwrap();
    assert_eq!(s.checks.transformed_sum_mismatches, 1);
    m.pop();
    let e = analyze(&plan, &m, "synthetic", "test", 0.1).unwrap_err().to_string();
    assert!(e.contains("measurements for") && e.contains("planned passes"), "{e}");
}

#[cfg(feature = "wgpu")]
mod cli {
    fn bin(args: &[&str]) -> std::process::Output {
        std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(args)
            .output()
            .unwrap()
    }

    #[test]
    fn bad_flags_are_refused_before_anything_is_measured() {
        for (args, want) in [
            (
                vec!["study", "estimation", "--single", "0"],
                "--single must be at least 1",
            ),
            (
                vec!["study", "estimation", "--multi", "0"],
                "--multi must be at least 1",
            ),
            (
                vec!["study", "estimation", "--repeats", "0"],
                "--repeats must be at least 1",
            ),
            (
                vec!["study", "estimation", "--load-scale", "0"],
                "--load-scale must be a positive number",
            ),
            (
                vec!["study", "estimation", "--require-exact"],
                "--require-exact belongs to study H1",
            ),
            (
                vec!["study", "h2", "--single", "10"],
                "belong to `rendersim study estimation`",
            ),
            (vec!["study", "estimation", "--single", "many"], "invalid value 'many'"),
            (vec!["study", "estimations"], "h1, h2, h3, h4, all, estimation"),
        ] {
            let o = bin(&args);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
            assert!(err.contains(want) && !err.contains("panicked"), "{args:?}: {err}");
            assert!(o.stdout.is_empty(), "{args:?}");
        }
    }

    #[test]
    fn a_small_study_runs_on_the_adapter() {
        let dir = tempfile::tempdir().unwrap();
        let (csv, md) = (dir.path().join("passes.csv"), dir.path().join("estimation.md"));
        let o = bin(&[
            "study",
            "estimation",
            "--single",
            "40",
            "--multi",
            "12",
            "--repeats",
            "1",
            "--json",
            "--csv",
            csv.to_str().unwrap(),
            "--markdown",
            md.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        if err.contains("no Vulkan adapter found") {
            eprintln!("SKIPPED: no Vulkan adapter on this machine ({})", err.trim());
            return;
        }
        assert!(o.status.success(), "{err}");
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(v["passes"]["single"], 40);
        assert_eq!(v["passes"]["multi"], 12);
        for name in ["h1", "h2", "h3", "h4", "pos"] {
            let mse = v["scores"][name]["mse_ms2"].as_f64().unwrap();
            assert!(mse.is_finite() && mse >= 0.0, "{name}: {v}");
            assert!(v["scores"][name]["cost_us_per_frame"].as_f64().unwrap() > 0.0);
        }
        // Vertex-shader invocations of separate draws add up.
        assert_eq!(v["checks"]["transformed_sum_mismatches"], 0, "{v}");
        assert_eq!(v["checks"]["transformed_table_mismatches"], 0, "{v}");
        assert!(v["overhead_ms"].as_f64().unwrap() > 0.0);
        // One CSV row per object drawn, one per empty pass.
        let text = std::fs::read_to_string(&csv).unwrap();
        let s = &v["setup"];
        let n = |k: &str| s[k].as_u64().unwrap();
        let multi_objects = v["passes"]["multi_objects"].as_u64().unwrap();
        let rows = n("overhead_passes") + n("prototypes") * n("pos_sizes") + 40 + multi_objects;
        assert_eq!(text.lines().count() as u64, 1 + rows, "{text}");
        assert!(text.starts_with("pass,kind,objects,pass_time_ns,vs_invocations"));
        let doc = std::fs::read_to_string(&md).unwrap();
        assert!(doc.starts_with("# Rendering-time estimation measured:"), "{doc}");
        assert!(doc.contains("Produced by `rendersim study estimation --single 40 --multi 12 --repeats 1"));
    }
}
