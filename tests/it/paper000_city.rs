//! Paper 000's city viewpoint on the calibrated GeForce3
//! (`models/city-geforce3.toml`, `models/hardware/geforce3.toml`): its two
//! load figures are each calibrated to one named cell of the paper, and
//! the shipped numbers are what the calibration finds; Table 3's
//! predictions (experiments/table3-depth-order.toml) follow from them.

use rendersim::config::{ModelSource, Overrides, prepare};
use rendersim::systems::run_model;

use crate::common::{num, shipped_table};

const MODEL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/models/city-geforce3.toml");

/// GPU time per frame (ms) of the shipped city viewpoint with `sets`.
fn gpu_ms(sets: &[String]) -> f64 {
    let src = ModelSource::from_file(std::path::Path::new(MODEL)).unwrap();
    let m = prepare(src, &Overrides::with_sets(sets)).unwrap();
    let run = run_model(&m.source, &m.table, None).unwrap();
    num(&run.summary(), "metrics.gpu_time_ms.mean")
}

/// Table 2's geometry-limited, presorted setting with `count` buildings.
fn table2_geometry_presorted(count: u64) -> f64 {
    gpu_ms(&[
        format!("workload.groups.0.count={count}"),
        "gpu.geometry.vertex_shader=\"79636ps\"".into(),
        "workload.state_order=\"sorted\"".into(),
    ])
}

/// Table 3's fill-limited setting with a triangle-area median and order.
fn table3_fill(median: f64, order: &str) -> f64 {
    gpu_ms(&[
        format!("workload.groups.0.triangle_pixels.median={median}"),
        "gpu.fragment.per_fragment=\"8123ps\"".into(),
        format!("workload.depth_order=\"{order}\""),
    ])
}

#[test]
fn the_city_viewpoint_is_calibrated_one_cell_per_figure() {
    let group = &shipped_table("models/city-geforce3.toml")["workload"]["groups"][0];
    let count = group["count"].as_integer().unwrap() as u64;
    let median = group["triangle_pixels"]["median"].as_float().unwrap();
    // The building count: the closest to Table 2's 14.138 ms (the time
    // grows with the count; the neighbours are farther).
    let target = 14.138;
    let off = |n| (table2_geometry_presorted(n) - target).abs();
    let here = off(count);
    assert!(
        here < 0.05,
        "{count} buildings: {} ms",
        table2_geometry_presorted(count)
    );
    assert!(
        off(count - 1) > here && off(count + 1) > here,
        "{count} is not the closest"
    );
    // The triangle-area median: bisection to Table 3's normal cell (10.7
    // ms), the fill growing with the median.
    let (mut lo, mut hi) = (1.0, 20.0);
    for _ in 0..30 {
        let mid: f64 = (lo + hi) / 2.0;
        if table3_fill(mid, "random") < 10.7 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let found = (lo + hi) / 2.0;
    assert!((found - median).abs() < 1e-3, "calibrated {found}, shipped {median}");
}

#[test]
fn table_3_front_to_back_falls_short_and_back_to_front_overshoots() {
    // The predictions of experiments/table3-depth-order.toml, neither
    // within 25% of the paper's change: front to back -10.5% against
    // -14.6% (the device's state-change stall adds time no order changes;
    // without it, -10.8%), back to front +26.4% against +17.3% (the split
    // pipeline is fragment-bound on every triangle once every fragment is
    // shaded).
    let median = shipped_table("models/city-geforce3.toml")["workload"]["groups"][0]["triangle_pixels"]["median"]
        .as_float()
        .unwrap();
    let normal = table3_fill(median, "random");
    let f2b = table3_fill(median, "front_to_back") / normal - 1.0;
    let b2f = table3_fill(median, "back_to_front") / normal - 1.0;
    let paper = (9.143 / 10.7 - 1.0, 12.552 / 10.7 - 1.0);
    assert!(
        (f2b / paper.0 - 1.0).abs() > 0.25,
        "front to back {f2b} now within 25%: make it a check"
    );
    assert!((-0.11..-0.10).contains(&f2b), "front to back {f2b}");
    assert!(
        b2f / paper.1 - 1.0 > 0.25,
        "back to front {b2f} now within 25%: make it a check"
    );
    assert!((0.25..0.30).contains(&b2f), "back to front {b2f}");
}

#[test]
fn the_docs_state_what_table_3s_inverse_what_ifs_give() {
    // docs/models.md, "Table 3 predicted": the two searches of
    // experiments/table3-depth-order.toml (from its golden searches.csv,
    // which the golden test holds to a fresh run), and the three orders at
    // the vertex cost the front-to-back search finds.
    let doc = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/models.md")).unwrap();
    let doc = doc.split_whitespace().collect::<Vec<_>>().join(" ");
    let searches = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/golden/experiments/table3-depth-order/searches.csv"),
    )
    .unwrap();
    let found = |name: &str| -> f64 {
        let line = searches
            .lines()
            .find(|l| l.starts_with(&format!("{name},")))
            .unwrap_or_else(|| panic!("no search {name}"));
        line.split(',').nth(6).unwrap().parse().unwrap()
    };
    let fill = found("fragment-cost-for-back-to-front");
    let vertex = found("vertex-cost-for-front-to-back");
    let median = shipped_table("models/city-geforce3.toml")["workload"]["groups"][0]["triangle_pixels"]["median"]
        .as_float()
        .unwrap();
    let at = |order: &str| {
        gpu_ms(&[
            format!("workload.groups.0.triangle_pixels.median={median}"),
            "gpu.fragment.per_fragment=\"8123ps\"".into(),
            format!("gpu.geometry.vertex_shader=\"{vertex}ps\""),
            format!("workload.depth_order=\"{order}\""),
        ])
    };
    let (normal, f2b, b2f) = (at("random"), at("front_to_back"), at("back_to_front"));
    for text in [
        format!("back to front would give 12.552 ms: {:.3} ns against", fill / 1000.0),
        format!("front to back would give 9.143 ms: {:.3} ns against", vertex / 1000.0),
        format!(
            "the normal view takes {normal:.2} ms, front to back {f2b:.3} ms and back to front {b2f:.2} ms, \
             changes of {:+.1}% and {:+.1}%",
            100.0 * (f2b / normal - 1.0),
            100.0 * (b2f / normal - 1.0)
        ),
    ] {
        assert!(doc.contains(&text), "docs/models.md should say {text:?}");
    }
}
