//! Closed forms against numbers worked by hand from paper 002, the event
//! simulation against the closed forms, determinism and bad input.

use crate::config::{ModelSource, Overrides, prepare};
use crate::systems::{SystemRun, run_model};

const MODEL: &str = include_str!("../../../../../models/pixelflow-20.toml");

fn run_with(sets: &[&str]) -> Result<SystemRun, crate::systems::SimError> {
    let m = prepare(
        ModelSource::from_text("pixelflow-20.toml", MODEL),
        &Overrides::with_sets(sets),
    )
    .unwrap();
    run_model(&m.source, &m.table, None)
}

fn metric(r: &SystemRun, key: &str) -> f64 {
    r.summary()["metrics"][key].as_f64().unwrap()
}

fn analytic(sets: &[&str]) -> serde_json::Value {
    let mut all = vec!["fidelity=\"analytic\""];
    all.extend_from_slice(sets);
    run_with(&all).unwrap().summary()["metrics"]["analytic"].clone()
}

fn assert_within(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol, "{a} vs {b} (tolerance {tol})");
}

#[test]
fn overlap_factors_are_the_papers() {
    // (10+128)(10+64)/(128 x 64) = 1.2466 ("1.25"); 20 x 20 footprint under
    // 8-sample antialiasing: (148 x 84)/8192 = 1.5176 ("1.52").
    let a1 = analytic(&["samples=1"]);
    assert_within(a1["overlap"].as_f64().unwrap(), 10212.0 / 8192.0, 1e-12);
    let a8 = analytic(&["samples=8"]);
    assert_within(a8["overlap"].as_f64().unwrap(), 12432.0 / 8192.0, 1e-12);
    assert_eq!(a8["regions"], 40);
}

#[test]
fn standard_closed_form_by_hand() {
    // 8 samples, 4 shaders -> 15 rasterizers, 200,000 primitives:
    // t_front = 0.1 + 1.85 us x 200000 / 15 = 24.766667 ms
    // t_rast = 0.83 us x 200000 x 1.517578125 / 15 = 16.794531 ms
    // t_comp = 40 x 26.88 us = 1.0752 ms; t_shade = 40 x 110.4 / 4 = 1.104 ms;
    // t_load = 40 x 52 us = 2.08 ms; latency = 41.561198 ms.
    let a = analytic(&[
        "architecture=\"standard\"",
        "shading_nodes=4",
        "samples=8",
        "primitives=200000",
    ]);
    let g = |k: &str| a[k].as_f64().unwrap();
    assert_within(g("t_front_ms"), 24.766_666_7, 1e-6);
    assert_within(g("t_rast_ms"), 16.794_531_25, 1e-6);
    assert_within(g("t_comp_ms"), 1.0752, 1e-9);
    assert_within(g("t_shade_ms"), 1.104, 1e-9);
    assert_within(g("t_load_ms"), 2.08, 1e-9);
    assert_within(g("latency_ms"), 41.561_197_9, 1e-6);
    // One shader: 18 rasterizers, shading 40 x 110.4 us = 4.416 ms.
    let a = analytic(&["shading_nodes=1", "primitives=0"]);
    assert_within(a["t_shade_ms"].as_f64().unwrap(), 4.416, 1e-9);
    assert_within(a["latency_ms"].as_f64().unwrap(), 0.1 + 4.416, 1e-9);
}

#[test]
fn presort_closed_form_by_hand() {
    // 1 sample, 1 shader -> 18 rasterizers, 100,000 primitives:
    // first pass 0.1 + 0.74 x 100000/18 us = 4.211111 ms;
    // t_gen = 1.45 x 100000/18 us = 8.055556 ms (the max: t_rast = 5.748 ms,
    // t_shade = 4.416 ms); latency = 12.266667 ms.
    let a = analytic(&[
        "architecture=\"presort\"",
        "shading_nodes=1",
        "samples=1",
        "primitives=100000",
    ]);
    let g = |k: &str| a[k].as_f64().unwrap();
    assert_within(g("t_front_ms"), 4.211_111_1, 1e-6);
    assert_within(g("t_gen_ms"), 8.055_555_6, 1e-6);
    assert_within(g("t_rast_ms"), 0.83e-3 * 1e5 * (10212.0 / 8192.0) / 18.0, 1e-9);
    assert_within(g("latency_ms"), 12.266_666_7, 1e-6);
}

#[test]
fn nontex_closed_form_by_hand() {
    // 1 sample, 19 rasterizers, 600,000 primitives:
    // t_front = 0.1 + 0.87 x 600000/19 us = 27.573684 ms > t_rast = 24.406 ms;
    // t_comp = 40 x 7 x 1.28 us = 0.3584 ms; latency = 27.573684 + 2.08.
    let a = analytic(&["architecture=\"nontex\"", "samples=1", "primitives=600000"]);
    let g = |k: &str| a[k].as_f64().unwrap();
    assert_within(g("t_comp_ms"), 0.3584, 1e-9);
    assert_within(g("t_front_ms"), 27.573_684_2, 1e-6);
    assert_within(g("latency_ms"), 29.653_684_2, 1e-6);
    assert_eq!(a["rasterizers"], 19);
    // 8 samples, 100,000 primitives: max(4.678947, 4.067) + 7 (4.067 + 0.3584) + 2.08.
    let a = analytic(&["architecture=\"nontex\"", "samples=8", "primitives=100000"]);
    let rast = 0.62e-3 * 1e5 * (10212.0 / 8192.0) / 19.0;
    let front: f64 = 0.1 + 0.87e-3 * 1e5 / 19.0;
    assert_within(
        a["latency_ms"].as_f64().unwrap(),
        front.max(rast) + 7.0 * (rast + 0.3584) + 2.08,
        1e-9,
    );
}

#[test]
fn event_simulation_agrees_with_closed_forms_for_many_primitives() {
    for arch in ["standard", "presort", "nontex"] {
        for shaders in [1, 4] {
            for samples in [1, 8] {
                for n in [200_000, 1_000_000] {
                    let a = format!("architecture=\"{arch}\"");
                    let sh = format!("shading_nodes={shaders}");
                    let sa = format!("samples={samples}");
                    let p = format!("primitives={n}");
                    let r = run_with(&[&a, &sh, &sa, &p]).unwrap();
                    let (ev, cf) = (metric(&r, "latency_ms"), metric(&r, "analytic_latency_ms"));
                    assert!(
                        ev >= cf * 0.999,
                        "{arch} {shaders} {samples} {n}: event {ev} below closed form {cf}"
                    );
                    assert!(
                        (ev - cf).abs() / cf < 0.01,
                        "{arch} {shaders} {samples} {n}: event {ev} vs closed form {cf}"
                    );
                }
            }
        }
    }
}

#[test]
fn few_primitives_show_pipeline_fill_and_drain() {
    // With no primitives the closed form is t_overhead + max(back-end
    // terms); the event simulation adds the fill of one region through
    // composition and shading (26.88 + 110.4 us per region before the first
    // load, for one shader then 40 x 110.4 us of shading + one load).
    let r = run_with(&[
        "architecture=\"standard\"",
        "shading_nodes=1",
        "samples=1",
        "primitives=0",
    ])
    .unwrap();
    let ev = metric(&r, "latency_ms");
    let cf = metric(&r, "analytic_latency_ms");
    assert_within(cf, 4.516, 1e-9);
    assert_within(ev, 0.1 + 0.02688 + 4.416 + 0.00384 + 0.052, 1e-9);
}

#[test]
fn runs_are_deterministic_and_seeded() {
    let sets = ["placement=\"random\"", "primitives=50000", "run.seed=7"];
    let a = run_with(&sets).unwrap();
    let b = run_with(&sets).unwrap();
    assert_eq!(metric(&a, "latency_ms"), metric(&b, "latency_ms"));
    assert_eq!(
        a.summary()["metrics"]["region_entries"],
        b.summary()["metrics"]["region_entries"]
    );
    let c = run_with(&["placement=\"random\"", "primitives=50000", "run.seed=8"]).unwrap();
    assert_ne!(
        a.summary()["metrics"]["region_entries"],
        c.summary()["metrics"]["region_entries"]
    );
}

#[test]
fn random_placement_realises_the_overlap_factor() {
    let r = run_with(&["placement=\"random\"", "primitives=200000", "samples=1"]).unwrap();
    let realised = metric(&r, "realised_overlap");
    assert_within(realised, 10212.0 / 8192.0, 0.005);
}

#[test]
fn clustered_primitives_are_slower_than_the_closed_form() {
    // Half the primitives in 4 of the 40 regions: every node still
    // rasterizes every region, so the cost is the regions' uneven pace
    // against composition and shading, about 3% here.
    let r = run_with(&[
        "placement=\"clustered\"",
        "cluster={x=0,y=0,width=256,height=128,fraction=0.5}",
        "primitives=200000",
    ])
    .unwrap();
    assert!(metric(&r, "latency_ms") > metric(&r, "analytic_latency_ms") * 1.02);
}

#[test]
fn node_skew_costs_what_the_busiest_node_would_alone() {
    // skew 0.5 over 15 (or 19) rasterizers: the first node takes 1.5 times the
    // mean share, so with many primitives the frame costs what a balanced
    // machine needs for 1.5 times the primitives. The closed form itself
    // assumes balance and does not change.
    for (arch, shaders) in [("standard", 4), ("presort", 4), ("nontex", 4), ("standard", 1)] {
        let a = format!("architecture=\"{arch}\"");
        let s = format!("shading_nodes={shaders}");
        let skewed = run_with(&[&a, &s, "primitives=1140000", "node_skew=0.5"]).unwrap();
        let heavier = run_with(&[&a, &s, "primitives=1710000", "fidelity=\"analytic\""]).unwrap();
        let balanced = run_with(&[&a, &s, "primitives=1140000", "fidelity=\"analytic\""]).unwrap();
        let lat = metric(&skewed, "latency_ms");
        let want = metric(&heavier, "analytic_latency_ms");
        assert!((lat - want).abs() <= 0.01 * want, "{arch}/{shaders}: {lat} vs {want}");
        assert_within(
            metric(&skewed, "analytic_latency_ms"),
            metric(&balanced, "analytic_latency_ms"),
            1e-9,
        );
        assert!(lat > 1.3 * metric(&skewed, "analytic_latency_ms"), "{arch}: {lat}");
    }
    // Random placement with skew: every node's primitives are placed, the total is kept.
    let r = run_with(&["placement=\"random\"", "primitives=20000", "node_skew=0.5"]).unwrap();
    assert!(metric(&r, "latency_ms") > metric(&r, "analytic_latency_ms"));
    let e = run_with(&["node_skew=1.0"]).unwrap_err().to_string();
    assert!(e.contains("node_skew"), "{e}");
}

#[test]
fn bad_input_gives_clear_errors() {
    let e = run_with(&["deferred.t_tran=\"1us\""]).unwrap_err().to_string();
    assert!(e.contains("t_tran"), "{e}");
    let e = run_with(&["deferred.t_load=\"-52us\""]).unwrap_err().to_string();
    assert!(e.contains("t_load"), "{e}");
    let e = run_with(&["nodes=3", "shading_nodes=4"]).unwrap_err().to_string();
    assert!(e.contains("nodes") && e.contains("rasterizer"), "{e}");
    let e = run_with(&["samples=0"]).unwrap_err().to_string();
    assert!(e.contains("samples"), "{e}");
    let e = run_with(&["primitive.width=-10"]).unwrap_err().to_string();
    assert!(e.contains("primitive.width"), "{e}");
    let e = run_with(&["architecture=\"deferred\""]).unwrap_err().to_string();
    assert!(e.contains("architecture"), "{e}");
}

#[test]
fn every_region_is_loaded_once_and_in_order_of_its_steps() {
    let r = run_with(&["primitives=20000", "samples=1"]).unwrap();
    let (cols, rows) = r.frame_table();
    assert_eq!(cols[1], "Region");
    assert_eq!(rows.len(), 40);
    for row in rows {
        // rasterized <= composite start <= composite done <= shade start <= shade done <= loaded
        for w in row[3..].windows(2) {
            assert!(w[0] <= w[1], "{row:?}");
        }
    }
    let file = tempfile::NamedTempFile::new().unwrap();
    let src = ModelSource::from_text("m", MODEL);
    let t = src.table().unwrap();
    let writer = crate::output::trace::TraceWriter::new(Box::new(file.reopen().unwrap()));
    let mut traced = run_model(&src, &t, Some(writer)).unwrap();
    assert!(traced.take_trace().unwrap().finish().unwrap() > 0);
    assert!(
        std::fs::read_to_string(file.path())
            .unwrap()
            .contains("composition network")
    );
}

#[test]
fn standard_pipelines_frames_with_two_instruction_buffers() {
    // Front end (24.77 ms) slower than back end (16.8 ms): frames follow one
    // another at the front end's pace and every frame has the first one's
    // latency (the back end is free when each frame's geometry ends).
    let r = run_with(&["frames=5", "primitives=200000"]).unwrap();
    let m = &r.summary()["metrics"];
    let first = m["frame_latency_ms"]["first"].as_f64().unwrap();
    let last = m["frame_latency_ms"]["last"].as_f64().unwrap();
    assert_within(first, metric(&r, "latency_ms"), 1e-12);
    assert_within(last, first, 1e-6);
    // (the slowest node has 13,334 primitives: 0.1 ms + 13334 x 1.85 us)
    assert_within(
        m["frame_interval_ms"]["mean"].as_f64().unwrap(),
        0.1 + 1.85e-3 * 13_334.0,
        1e-6,
    );
    // One shader, few primitives: the back end (4.4 ms of shading) is slower
    // than the front end (0.8 ms); frame k+2 waits for frame k's buffer and
    // the latency grows to include waiting for the back end.
    let r = run_with(&["frames=6", "primitives=10000", "shading_nodes=1"]).unwrap();
    let m = &r.summary()["metrics"];
    let first = m["frame_latency_ms"]["first"].as_f64().unwrap();
    let last = m["frame_latency_ms"]["last"].as_f64().unwrap();
    assert!(last > first + 1.0, "{first} {last}");
    // Steady state: one frame per back end (40 x 110.4 us of shading).
    assert_within(m["frame_interval_ms"]["last"].as_f64().unwrap(), 4.416, 0.01);
    let (_, rows) = r.frame_table();
    assert_eq!(rows.len(), 6 * 40);
    // Presort does not pipeline frames: each frame's sorting pass follows the
    // previous frame's instruction generation.
    let r = run_with(&["architecture=\"presort\"", "frames=3", "primitives=200000"]).unwrap();
    let iv = r.summary()["metrics"]["frame_interval_ms"]["mean"].as_f64().unwrap();
    assert!(iv > 0.1 + (0.74e-3 + 1.45e-3) * 200_000.0 / 15.0 - 0.01, "{iv}");
    assert!(run_with(&["architecture=\"nontex\"", "frames=2"]).is_err());
}
