//! Sort-middle binning (`gpu.fragment.binning = "draw"`): a draw's fragments
//! start only after all of its geometry, and the next draw waits for the bins
//! to drain, so the GPU time is exactly the sum of the stage terms (what study
//! H2 measures on Mesa's llvmpipe), at both fidelities.

use crate::common;
use common::{metric, run, scene_model};

fn model(count: u32, binning: &str, depth: u32) -> String {
    scene_model(&format!(
        r#"name = "g"
count = {count}
mesh = "grid:32x32"
triangle_pixels = 3.0"#
    ))
    .replace(
        "fifo_depth = 16",
        &format!("fifo_depth = {depth}\nbinning = \"{binning}\""),
    )
}

#[test]
fn binned_draws_cost_exactly_geometry_plus_fragments() {
    for count in [1, 4] {
        let r = run(&model(count, "draw", 16), &[]);
        let (g, f, busy) = (r.clocks.geometry[0], r.clocks.fragment[0], r.clocks.gpu[0]);
        assert!(g > 0 && f > 0);
        assert_eq!(busy, g + f, "{count} objects: the stages never overlap");
        // Immediate mode overlaps them.
        let i = run(&model(count, "off", 16), &[]);
        assert_eq!((i.clocks.geometry[0], i.clocks.fragment[0]), (g, f));
        assert!(
            i.clocks.gpu[0] < g + f,
            "immediate {} vs sum {}",
            i.clocks.gpu[0],
            g + f
        );
    }
}

#[test]
fn draw_fidelity_equals_triangle_fidelity_when_binned() {
    let m = model(3, "draw", 16);
    let tri = run(&m, &["fidelity=\"triangle\""]);
    let draw = run(&m, &["fidelity=\"draw\""]);
    let (a, b) = (
        metric(&tri, "metrics.gpu_time_ms.mean"),
        metric(&draw, "metrics.gpu_time_ms.mean"),
    );
    assert!((a - b).abs() < 1e-9, "triangle {a} vs draw {b}");
    assert!(draw.stats.events < tri.stats.events / 100);
}

#[test]
fn binning_ignores_the_fifo_depth_and_keeps_conservation() {
    let a = run(&model(2, "draw", 0), &[]);
    let b = run(&model(2, "draw", 100_000), &[]);
    assert_eq!(a.clocks.gpu, b.clocks.gpu);
    let e = a.clocks.elapsed;
    assert_eq!(a.clocks.gpu.iter().sum::<u64>(), e);
    assert_eq!(a.clocks.geometry.iter().sum::<u64>(), e);
    assert_eq!(a.clocks.fragment.iter().sum::<u64>(), e);
    assert_eq!(a.commands.0, a.commands.1);
}

#[test]
fn bad_binning_value_is_an_error_naming_the_key() {
    let e = common::try_run(&model(1, "tiles", 16), &[]).unwrap_err();
    assert!(e.contains("binning") && e.contains("tiles"), "{e}");
}
