//! Paper 000 Table 1 on the split architecture (§4.5.1, "the myth of the
//! single bottleneck"): three cells calibrated on the terrain, the fourth
//! predicted, for each share of the simple/simple cell's shader time that
//! is geometry (`src/studies/table1.rs`,
//! `examples/table1_split.rs`, docs/models.md). The findings: random sizes
//! through the 16-triangle FIFO give the max bound; a direct hand-off or
//! sizes sorted along the draw give the per-triangle max, about 8% short
//! with the preset's spread and a ratio under 0.5; the paper's ratio needs
//! sizes spread far wider.

use crate::common::{metric, run, shipped_table};
use rendersim::scene::config::SizeOrder;
use rendersim::studies::table1::{
    Calibration, CalibrationError, CellModel, Cells, PAPER, SplitTerrain, TERRAIN, terrain_variant,
};
use rendersim::systems::frame_pipeline::Fidelity;

/// One picosecond more per fragment moves a cell by 0.00095 ms on the
/// terrain's 952k pixels; the searches stop within 0.0001 ms or at one
/// picosecond of cost.
const CELL_TOLERANCE_MS: f64 = 0.001;

fn setup(order: SizeOrder, fifo_depth: u32, sigma: f64) -> SplitTerrain {
    SplitTerrain {
        order,
        fifo_depth,
        sigma,
    }
}

/// Calibrations of `s` at `fidelity` for each share, each checked: the
/// three cells match the paper, the prediction lies between the max and
/// the sum of the simulated cells.
fn calibrate(s: SplitTerrain, fidelity: Fidelity, shares: &[f64]) -> Vec<Calibration> {
    let src = s.source();
    let mut m = CellModel::new(&src, s.table(&src, fidelity).unwrap());
    shares
        .iter()
        .map(|&share| {
            let c = m.calibrate(share, &PAPER).unwrap();
            let what = format!("{} at share {share} ({fidelity:?})", s.label());
            assert!(c.max_calibration_error(&PAPER) <= CELL_TOLERANCE_MS, "{what}: {c:?}");
            let d = c.cells.complex_complex;
            assert!(d >= c.cells.max_prediction(), "{what}: {d} below the max bound");
            assert!(d <= c.cells.sum_prediction() + 1e-3, "{what}: {d} above the sum bound");
            // The geometry share is the one asked for (to the rounding of
            // the costs to whole picoseconds).
            let g = c.geometry_ms / (c.geometry_ms + c.fragment_ms);
            assert!((g - share).abs() < 1e-3, "{what}: share {g}");
            c
        })
        .collect()
}

fn predictions(cs: &[Calibration]) -> Vec<f64> {
    cs.iter().map(|c| c.cells.complex_complex).collect()
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b
}

const SPLIT_ONE_FRAME: [&str; 3] = ["gpu.architecture=\"split\"", "run.frames=1", "run.warmup_frames=0"];

#[test]
fn the_written_out_terrain_is_the_preset() {
    let preset = run(TERRAIN, &SPLIT_ONE_FRAME);
    let group = run(&terrain_variant(SizeOrder::Random, 0.8), &SPLIT_ONE_FRAME);
    let path = "metrics.gpu_time_ms.mean";
    assert_eq!(metric(&preset, path), metric(&group, path));
    assert_eq!(preset.summary()["scene"], group.summary()["scene"]);
}

#[test]
fn the_shipped_terrain_calibrates_to_a_single_bottleneck() {
    // Random sizes (lognormal, sigma 0.8) through a 16-triangle FIFO: the
    // FIFO evens neighbouring triangles out and the frame is max(G, F), so
    // whatever the share the prediction is the max bound, 16.8% short.
    let s = setup(SizeOrder::Random, 16, 0.8);
    let tri = calibrate(s, Fidelity::Triangle, &[0.1, 0.5, 0.9]);
    for d in predictions(&tri) {
        assert!(relative(d, PAPER.max_prediction()) < 0.005, "{d}");
        assert!(d < 0.9 * PAPER.complex_complex, "{d} within 10% of the paper");
    }
    // `draw` fidelity's window approximation is within 2% here.
    let draw = calibrate(s, Fidelity::Draw, &[0.1, 0.5, 0.9]);
    for (t, d) in predictions(&tri).into_iter().zip(predictions(&draw)) {
        assert!(relative(d, t) < 0.02, "draw {d} vs triangle {t}");
    }
}

#[test]
fn a_shallower_fifo_moves_the_prediction_towards_the_sum() {
    // Random sizes, balanced stages: the prediction grows as the FIFO
    // shrinks, from the max bound (16) to the per-triangle max (0: each
    // triangle's geometry overlaps only the previous triangle's fragments),
    // which sorted sizes give at any depth.
    let by_depth: Vec<f64> = [16, 4, 1, 0]
        .iter()
        .map(|&depth| {
            predictions(&calibrate(
                setup(SizeOrder::Random, depth, 0.8),
                Fidelity::Triangle,
                &[0.5],
            ))[0]
        })
        .collect();
    assert!(
        by_depth.windows(2).all(|w| w[1] > w[0]),
        "FIFO 16, 4, 1, 0: {by_depth:?}"
    );
    assert!(by_depth[3] - by_depth[0] > 0.5, "FIFO 16, 4, 1, 0: {by_depth:?}");
    let fifo_zero = by_depth[3];
    let sorted = predictions(&calibrate(
        setup(SizeOrder::Ascending, 16, 0.8),
        Fidelity::Triangle,
        &[0.5],
    ))[0];
    assert!(
        relative(fifo_zero, sorted) < 0.005,
        "FIFO 0 {fifo_zero} vs sorted {sorted}"
    );
    // At a direct hand-off `draw` fidelity is exact in expectation.
    let draw = predictions(&calibrate(setup(SizeOrder::Random, 0, 0.8), Fidelity::Draw, &[0.5]))[0];
    assert!(relative(draw, fifo_zero) < 0.005, "draw {draw} vs triangle {fifo_zero}");
}

#[test]
fn sorted_sizes_make_the_fifo_depth_irrelevant() {
    // Smallest first: the bottleneck moves once, from geometry to
    // fragments, over tens of thousands of triangles, which no FIFO of a
    // few triangles can smooth.
    let at = |depth| {
        predictions(&calibrate(
            setup(SizeOrder::Ascending, depth, 0.8),
            Fidelity::Draw,
            &[0.5],
        ))[0]
    };
    let deep = at(64);
    for depth in [16, 4, 0] {
        let d = at(depth);
        assert!(relative(d, deep) < 0.001, "FIFO {depth}: {d} vs FIFO 64: {deep}");
    }
    let tri = predictions(&calibrate(
        setup(SizeOrder::Ascending, 16, 0.8),
        Fidelity::Triangle,
        &[0.5],
    ))[0];
    assert!(relative(tri, deep) < 0.01, "triangle {tri} vs draw {deep}");
}

#[test]
fn the_preset_spread_comes_within_ten_percent_but_not_to_the_ratio() {
    // The per-triangle max with the preset's sizes (sigma 0.8): 8% short
    // of the paper's 11.856 ms at every share, ratio under 0.5 (paper 0.84).
    let cs = calibrate(
        setup(SizeOrder::Ascending, 16, 0.8),
        Fidelity::Draw,
        &[0.1, 0.3, 0.5, 0.7, 0.9],
    );
    for c in &cs {
        let (d, r) = (c.cells.complex_complex, c.cells.ratio());
        assert!(
            d > 0.9 * PAPER.complex_complex && d < 0.95 * PAPER.complex_complex,
            "{d}"
        );
        assert!(r > 0.35 && r < 0.5, "ratio {r}");
    }
}

#[test]
fn the_papers_ratio_needs_sizes_spread_far_wider() {
    // The ratio grows with the spread of the triangle sizes at every share;
    // sigma 2.4 (areas over four orders of magnitude, as a terrain seen at
    // a grazing angle has) reaches the paper's 0.84 and its fourth cell
    // within 2%.
    let shares = [0.1, 0.5, 0.9];
    let spreads = [0.8, 1.6, 2.4];
    let by_spread: Vec<Vec<Calibration>> = spreads
        .iter()
        .map(|&sigma| calibrate(setup(SizeOrder::Ascending, 16, sigma), Fidelity::Draw, &shares))
        .collect();
    for i in 0..shares.len() {
        let r: Vec<f64> = by_spread.iter().map(|cs| cs[i].cells.ratio()).collect();
        assert!(
            r[0] + 0.1 < r[1] && r[1] + 0.05 < r[2],
            "share {}: ratios {r:?}",
            shares[i]
        );
    }
    for c in &by_spread[2] {
        assert!(c.cells.ratio() >= 0.84, "{c:?}");
        assert!(relative(c.cells.complex_complex, PAPER.complex_complex) < 0.02, "{c:?}");
    }
    // Triangle fidelity (its own sample of the sizes, calibrated afresh)
    // agrees.
    let tri = calibrate(setup(SizeOrder::Ascending, 16, 2.4), Fidelity::Triangle, &[0.5]);
    let (t, d) = (tri[0].cells.complex_complex, by_spread[2][1].cells.complex_complex);
    assert!(relative(t, d) < 0.01, "triangle {t} vs draw {d}");
}

#[test]
fn unreachable_targets_are_errors_naming_the_cell() {
    // The fixed part of the frame (clear, swap: 0.32 ms) is above a 0.1 ms
    // target.
    let s = setup(SizeOrder::Random, 16, 0.8);
    let src = s.source();
    let mut m = CellModel::new(&src, s.table(&src, Fidelity::Draw).unwrap());
    let targets = Cells {
        simple_simple: 0.1,
        ..PAPER
    };
    let e = m.calibrate(0.5, &targets).unwrap_err();
    assert!(matches!(e, CalibrationError::Unreachable { .. }), "{e}");
    assert!(e.to_string().contains("simple/simple"), "{e}");
}

/// The shipped file at `rel` (from the repository root) as a table.
#[test]
fn the_geforce3_costs_are_table_1s_calibration() {
    // The simple vertex shader from Table 4 Test 1 (19.73 M transformed
    // vertices per second), the rest from Table 1's three cells on the
    // shipped terrain: the numbers in models/hardware/geforce3.toml and
    // experiments/table1-split.toml are exactly what the calibration finds.
    let vertex_ps = (1e12 / 19.73e6_f64).round() as u64;
    assert_eq!(vertex_ps, 50_684);
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/terrain-geforce3.toml");
    let src = rendersim::config::ModelSource::from_file(&path).unwrap();
    let table = src.table().unwrap();
    let c = CellModel::new(&src, table)
        .calibrate_with_vertex(vertex_ps, &PAPER)
        .unwrap();
    assert!(c.max_calibration_error(&PAPER) <= CELL_TOLERANCE_MS, "{c:?}");
    let k = c.costs;
    let ps = |v: u64| format!("{v}ps");
    let hw = shipped_table("models/hardware/geforce3.toml");
    assert_eq!(
        hw["gpu"]["geometry"]["vertex_shader"].as_str(),
        Some(ps(vertex_ps).as_str())
    );
    assert_eq!(
        hw["gpu"]["fragment"]["per_fragment"].as_str(),
        Some(ps(k.fragment_simple_ps).as_str())
    );
    assert_eq!(hw["gpu"]["architecture"].as_str(), Some("split"));
    let exp = shipped_table("experiments/table1-split.toml");
    let values = |i: usize| -> Vec<String> {
        exp["sweep"][i]["values"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(values(0), [ps(k.vertex_simple_ps), ps(k.vertex_complex_ps)]);
    assert_eq!(values(1), [ps(k.fragment_simple_ps), ps(k.fragment_complex_ps)]);
    // The prediction: between the bounds, within 5% of the paper (-2.2%),
    // with a ratio of 0.73 (paper 0.84).
    let d = c.cells.complex_complex;
    assert!(d > c.cells.max_prediction() && d < c.cells.sum_prediction(), "{c:?}");
    assert!(relative(d, PAPER.complex_complex) < 0.05, "{d}");
    assert!((0.65..0.84).contains(&c.cells.ratio()), "ratio {}", c.cells.ratio());
}
