//! Study H2: is the time of a pass the sum or the maximum of its geometry and
//! fragment terms (paper 000 §4.5.1, "the myth of the single bottleneck", and
//! Table 1)? A 2x2 of simple/complex vertex and fragment shaders on a
//! terrain-like grid, next to passes that isolate each term:
//!
//! - overhead `o`: a two-triangle grid with every vertex at one point;
//! - geometry `G(v)`: the grid with every vertex at one point (all triangles
//!   degenerate: vertex shading and setup, no fragments), minus `o`;
//! - fragments `F(f)`: the extra time the grid's real triangles take over its
//!   geometry-only pass, both with the simple vertex shader. This term is
//!   calibrated on the simple-vertex-shader cells, so those two cells fit every
//!   hypothesis by construction (up to the simple geometry term `G(s)`); the
//!   complex-vertex-shader cells are the test.
//!
//! Predictions per cell: `max` = o + max(G, F), `sum` = o + G + F, and the
//! simulator at `triangle` fidelity (costs per transformed vertex and per
//! fragment from the same terms), both as an immediate-mode pipeline with the
//! default triangle FIFO of 16 entries and with sort-middle binning
//! (`gpu.fragment.binning = "draw"`).
//! A model-free check beside them, as the paper reads its Table 1: the time a
//! complex vertex shader adds with the simple fragment shader and with the
//! complex one (equal under `sum`, smaller under `max`).

use serde::Serialize;

use super::fit::rel_error_pct;
use super::loops::LoopSearch;
use super::predict::{PassModel, PredictError, duration_ps, simulate_pass};

/// What H2 draws.
#[derive(Debug, Clone, Serialize)]
pub struct H2Setup {
    /// The terrain-like mesh.
    pub mesh: String,
    /// Render target, pixels.
    pub size: (u32, u32),
    /// Vertex-shader loop counts: simple, complex.
    pub vs_loops: [u32; 2],
    /// Fragment-shader loop counts: simple, complex.
    pub fs_loops: [u32; 2],
    /// Vertex-cache policy the simulator uses for this device.
    pub cache: String,
    /// Triangle-FIFO depth of the simulator's prediction.
    pub fifo_depth: u32,
    /// When set, the complex loop counts are found on the device before
    /// measuring: the vertex shader's so that the geometry-only pass takes
    /// at least this long (ms), then the fragment shader's so that F(complex)
    /// reaches G(complex), where sum and max differ most. Any device then
    /// gets a balanced, measurable 2x2.
    pub auto_target_ms: Option<f64>,
    /// Where the vertex shader's loop search ended (set by the search).
    pub vs_search: Option<LoopSearch>,
    /// Where the fragment shader's loop search ended (set by the search).
    pub fs_search: Option<LoopSearch>,
}

impl Default for H2Setup {
    fn default() -> Self {
        H2Setup {
            mesh: "grid:96x96:optimized".into(),
            size: (384, 384),
            vs_loops: [0, 1000],
            fs_loops: [0, 40],
            cache: "lavapipe".into(),
            fifo_depth: 16,
            auto_target_ms: Some(15.0),
            vs_search: None,
            fs_search: None,
        }
    }
}

/// Medians of the measured passes, nanoseconds, and the counters.
#[derive(Debug, Clone, Serialize)]
pub struct H2Measured {
    /// Overhead pass.
    pub overhead_ns: f64,
    /// Geometry-only passes: simple, complex vertex shader.
    pub geometry_ns: [f64; 2],
    /// Full passes, `[vertex][fragment]`, 0 = simple, 1 = complex.
    pub cells_ns: [[f64; 2]; 2],
    /// Vertex-shader invocations of one pass.
    pub vs_invocations: u64,
    /// Fragment-shader invocations of one full pass.
    pub fs_invocations: u64,
    /// Fragment-shader invocations of the geometry-only pass (should be 0).
    pub fs_invocations_geometry_only: u64,
    /// Triangles drawn.
    pub triangles: u64,
}

/// One cell: measured and predicted, milliseconds.
#[derive(Debug, Clone, Serialize)]
pub struct H2Cell {
    /// `simple` or `complex`.
    pub vertex: &'static str,
    /// `simple` or `complex`.
    pub fragment: &'static str,
    /// Whether the fragment term was calibrated on this cell.
    pub calibration: bool,
    /// Measured pass.
    pub measured_ms: f64,
    /// o + max(G, F).
    pub max_ms: f64,
    /// o + G + F.
    pub sum_ms: f64,
    /// o + the simulator's GPU time (immediate mode, triangle FIFO).
    pub simulator_ms: f64,
    /// o + the simulator's GPU time with sort-middle binning.
    pub simulator_binned_ms: f64,
    /// o + the simulator's GPU time on a unified shader pool (the default
    /// architecture; immediate mode, triangle FIFO).
    pub simulator_unified_ms: f64,
}

/// A hypothesis's errors on the cells it did not see.
#[derive(Debug, Clone, Serialize)]
pub struct H2Score {
    /// `max`, `sum`, or `simulator (fifo N)`.
    pub hypothesis: String,
    /// Mean |relative error| over the test cells, percent.
    pub mean_abs_error_pct: f64,
    /// Worst |relative error| over the test cells, percent.
    pub max_abs_error_pct: f64,
}

/// The study's result.
#[derive(Debug, Clone, Serialize)]
pub struct H2 {
    /// The setup.
    pub setup: H2Setup,
    /// The measurements.
    pub measured: H2Measured,
    /// Geometry terms G(simple), G(complex), ms.
    pub geometry_ms: [f64; 2],
    /// Fragment terms F(simple), F(complex), ms.
    pub fragment_ms: [f64; 2],
    /// The four cells.
    pub cells: Vec<H2Cell>,
    /// Hypotheses ranked by mean error on the test cells (best first).
    pub scores: Vec<H2Score>,
    /// Time the complex vertex shader adds with the simple and with the
    /// complex fragment shader, ms (equal under `sum`).
    pub vs_increase_ms: [f64; 2],
    /// The simulator's error on the complex/complex cell for triangle-FIFO
    /// depths (depth, error %).
    pub fifo_scan: Vec<(u32, f64)>,
    /// Seconds spent measuring.
    pub measure_seconds: f64,
    /// Seconds spent simulating (all cells and the FIFO scan).
    pub simulate_seconds: f64,
}

const LEVEL: [&str; 2] = ["simple", "complex"];

/// Analyses H2's measurements.
pub fn analyze(setup: H2Setup, m: H2Measured, measure_seconds: f64) -> Result<H2, PredictError> {
    let t0 = std::time::Instant::now();
    let ms = |ns: f64| ns / 1e6;
    let o = ms(m.overhead_ns);
    let g = [ms(m.geometry_ns[0]) - o, ms(m.geometry_ns[1]) - o].map(|x| x.max(0.0));
    let f = [
        ms(m.cells_ns[0][0] - m.geometry_ns[0]),
        ms(m.cells_ns[0][1] - m.geometry_ns[0]),
    ]
    .map(|x| x.max(0.0));
    let tris = m.triangles.max(1) as f64;
    let vs = m.vs_invocations.max(1) as f64;
    let fs = m.fs_invocations.max(1) as f64;
    let pass = |v: usize, fi: usize, depth: u32, binning: bool, unified: bool| -> Result<f64, PredictError> {
        let p = simulate_pass(&PassModel {
            mesh: setup.mesh.clone(),
            cache: setup.cache.clone(),
            layers: 1,
            per_vertex: duration_ps(g[v] * 1e9 / vs),
            per_fragment: duration_ps(f[fi] * 1e9 / fs),
            per_rejected_fragment: crate::engine::Duration::ZERO,
            fragments_per_triangle: fs / tris,
            depth_order: "front_to_back".into(),
            fifo_depth: depth,
            binning,
            unified,
        })?;
        Ok(o + p.gpu_ms)
    };
    let mut cells = Vec::new();
    for v in 0..2 {
        for fi in 0..2 {
            cells.push(H2Cell {
                vertex: LEVEL[v],
                fragment: LEVEL[fi],
                calibration: v == 0,
                measured_ms: ms(m.cells_ns[v][fi]),
                max_ms: o + g[v].max(f[fi]),
                sum_ms: o + g[v] + f[fi],
                simulator_ms: pass(v, fi, setup.fifo_depth, false, false)?,
                simulator_binned_ms: pass(v, fi, setup.fifo_depth, true, false)?,
                simulator_unified_ms: pass(v, fi, setup.fifo_depth, false, true)?,
            });
        }
    }
    let score = |name: String, pick: &dyn Fn(&H2Cell) -> f64| -> H2Score {
        let errs: Vec<f64> = cells
            .iter()
            .filter(|c| !c.calibration)
            .map(|c| rel_error_pct(pick(c), c.measured_ms).abs())
            .collect();
        H2Score {
            hypothesis: name,
            mean_abs_error_pct: errs.iter().sum::<f64>() / errs.len().max(1) as f64,
            max_abs_error_pct: errs.iter().copied().fold(0.0, f64::max),
        }
    };
    let mut scores = vec![
        score("max".into(), &|c| c.max_ms),
        score("sum".into(), &|c| c.sum_ms),
        score(format!("simulator (triangle FIFO {})", setup.fifo_depth), &|c| {
            c.simulator_ms
        }),
        score("simulator (binning = draw)".into(), &|c| c.simulator_binned_ms),
        score("simulator (unified pool)".into(), &|c| c.simulator_unified_ms),
    ];
    scores.sort_by(|a, b| a.mean_abs_error_pct.total_cmp(&b.mean_abs_error_pct));
    let measured_cc = ms(m.cells_ns[1][1]);
    let mut fifo_scan = Vec::new();
    for depth in [0u32, 1, 4, 16, 64, 256, 1024, 4096, 1 << 20] {
        fifo_scan.push((depth, rel_error_pct(pass(1, 1, depth, false, false)?, measured_cc)));
    }
    let vs_increase_ms = [
        ms(m.cells_ns[1][0] - m.cells_ns[0][0]),
        ms(m.cells_ns[1][1] - m.cells_ns[0][1]),
    ];
    Ok(H2 {
        setup,
        measured: m,
        geometry_ms: g,
        fragment_ms: f,
        cells,
        scores,
        vs_increase_ms,
        fifo_scan,
        measure_seconds,
        simulate_seconds: t0.elapsed().as_secs_f64(),
    })
}

impl H2 {
    /// The hypothesis that fits best.
    pub fn best(&self) -> &str {
        self.scores.first().map_or("none", |s| s.hypothesis.as_str())
    }

    /// One line: the best hypothesis and its error (and a loop search that
    /// fell short).
    pub fn verdict(&self) -> String {
        let mut v = match self.scores.first() {
            Some(b) => format!(
                "sum vs max: **{}** fits best ({:.1}% mean error on the test cells)",
                b.hypothesis, b.mean_abs_error_pct
            ),
            None => "sum vs max: no hypothesis scored".into(),
        };
        let s = &self.setup;
        for (shader, search) in [("vertex", &s.vs_search), ("fragment", &s.fs_search)] {
            if let Some(f) = search.filter(|f| !f.reached()) {
                v += &format!("; {shader} shader loop search {}", f.shortfall());
            }
        }
        v
    }

    /// The result as a Markdown section.
    pub fn markdown(&self) -> String {
        let s = &self.setup;
        let m = &self.measured;
        let mut out = format!(
            "## H2: sum vs max of the geometry and fragment terms (paper 000 §4.5.1, Table 1)\n\n\
             Mesh `{}` on a {}x{} target ({} triangles, {} vertex-shader and {} fragment-shader invocations per pass); \
             vertex shader {} / {} loop iterations, fragment shader {} / {}. \
             {}Terms from isolating passes: overhead {:.3} ms; geometry G = {:.3} / {:.3} ms (geometry-only passes, {} fragment invocations); \
             fragments F = {:.3} / {:.3} ms (full minus geometry-only pass, simple vertex shader).\n\n",
            s.mesh,
            s.size.0,
            s.size.1,
            m.triangles,
            m.vs_invocations,
            m.fs_invocations,
            s.vs_loops[0],
            s.vs_loops[1],
            s.fs_loops[0],
            s.fs_loops[1],
            match (&s.vs_search, &s.fs_search) {
                (Some(v), Some(f)) => format!(
                    "The complex loop counts were searched on this device: the vertex shader's, {}; \
                     then the fragment shader's so that F(complex) reaches G(complex), where sum and max differ most, {}. ",
                    v.describe("geometry alone"),
                    f.describe("F(complex)")
                ),
                _ => String::new(),
            },
            m.overhead_ns / 1e6,
            self.geometry_ms[0],
            self.geometry_ms[1],
            m.fs_invocations_geometry_only,
            self.fragment_ms[0],
            self.fragment_ms[1],
        );
        out += "| vertex | fragment | measured ms | max ms (err) | sum ms (err) | simulator, split FIFO ms (err) | simulator, split binning ms (err) | simulator, unified ms (err) | |\n|---|---|---|---|---|---|---|---|---|\n";
        for c in &self.cells {
            let e = |x: f64| format!("{x:.3} ({:+.1}%)", rel_error_pct(x, c.measured_ms));
            out += &format!(
                "| {} | {} | {:.3} | {} | {} | {} | {} | {} | {} |\n",
                c.vertex,
                c.fragment,
                c.measured_ms,
                e(c.max_ms),
                e(c.sum_ms),
                e(c.simulator_ms),
                e(c.simulator_binned_ms),
                e(c.simulator_unified_ms),
                if c.calibration { "calibration" } else { "test" }
            );
        }
        out += "\nOn the test cells (complex vertex shader), best first:\n\n| hypothesis | mean abs error | worst |\n|---|---|---|\n";
        for sc in &self.scores {
            out += &format!(
                "| {} | {:.1}% | {:.1}% |\n",
                sc.hypothesis, sc.mean_abs_error_pct, sc.max_abs_error_pct
            );
        }
        let [a, b] = self.vs_increase_ms;
        out += &format!(
            "\nBest: **{}**. Model-free, as the paper reads Table 1: the complex vertex shader adds {a:.3} ms with the simple \
             fragment shader and {b:.3} ms with the complex one (ratio {:.2}; 1 under `sum`, {:.2} under `max`).\n\n",
            self.best(),
            if a != 0.0 { b / a } else { f64::NAN },
            {
                let (g, f) = (self.geometry_ms, self.fragment_ms);
                let under_max_a = g[1].max(f[0]) - g[0].max(f[0]);
                let under_max_b = g[1].max(f[1]) - g[0].max(f[1]);
                if under_max_a != 0.0 {
                    under_max_b / under_max_a
                } else {
                    f64::NAN
                }
            }
        );
        out += "The simulator's error on the complex/complex cell by triangle-FIFO depth (immediate mode; 0 = direct hand-off):\n\n| depth | error |\n|---|---|\n";
        for (d, e) in &self.fifo_scan {
            out += &format!("| {d} | {e:+.1}% |\n");
        }
        out += &format!(
            "\nMeasuring took {:.2} s; simulating {} passes took {:.3} s.\n",
            self.measure_seconds,
            self.cells.len() + self.fifo_scan.len(),
            self.simulate_seconds
        );
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measured(combine: fn(f64, f64) -> f64) -> H2Measured {
        // Terms in ns: overhead 1 ms, G = 2 / 10 ms, F = 8 / 20 ms.
        let (o, g, f) = (1e6, [2e6, 10e6], [8e6, 20e6]);
        let cell = |v: usize, fi: usize| o + combine(g[v], f[fi]);
        H2Measured {
            overhead_ns: o,
            geometry_ns: [o + g[0], o + g[1]],
            cells_ns: [[cell(0, 0), cell(0, 1)], [cell(1, 0), cell(1, 1)]],
            // grid:64x64 under lavapipe's policy (study H1): the simulator's
            // count must match the device's for the costs to carry over.
            vs_invocations: 5737,
            fs_invocations: 200_000,
            fs_invocations_geometry_only: 0,
            triangles: 8192,
        }
    }

    fn setup() -> H2Setup {
        H2Setup {
            mesh: "grid:64x64".into(),
            ..H2Setup::default()
        }
    }

    #[test]
    fn a_device_that_adds_is_called_sum() {
        let r = analyze(setup(), measured(|a, b| a + b), 0.0).unwrap();
        // Sum and the binning simulator both fit exactly.
        assert!(
            ["sum", "simulator (binning = draw)", "simulator (unified pool)"].contains(&r.best()),
            "{:?}",
            r.scores
        );
        assert!(
            r.scores[0].mean_abs_error_pct < 1e-3 && r.scores[2].mean_abs_error_pct < 1e-3,
            "{:?}",
            r.scores
        );
        assert!((r.vs_increase_ms[0] - r.vs_increase_ms[1]).abs() < 1e-9);
        assert!(r.markdown().contains("Best: **"));
    }

    #[test]
    fn the_loop_search_is_reported_as_measured_and_a_shortfall_in_the_verdict() {
        let found = |loops, target_ms, reached_ms| LoopSearch {
            target_ms,
            loops,
            reached_ms,
            tries: 3,
        };
        let s = H2Setup {
            vs_search: Some(found(67390, 15.0, 19.01)),
            fs_search: Some(found(7681, 19.01, 22.84)),
            ..setup()
        };
        let r = analyze(s, measured(|a, b| a + b), 0.0).unwrap();
        let md = r.markdown();
        assert!(
            md.contains("the vertex shader's, 67390 loops (geometry alone took 19.01 ms there, target at least 15 ms)"),
            "{md}"
        );
        assert!(
            md.contains("7681 loops (F(complex) took 22.84 ms there, target at least 19.01 ms)"),
            "{md}"
        );
        assert!(!r.verdict().contains("fell short"));
        let s = H2Setup {
            vs_search: Some(found(4194304, 15.0, 3.5)),
            fs_search: Some(found(10, 3.5, 3.6)),
            ..setup()
        };
        let r = analyze(s, measured(|a, b| a + b), 0.0).unwrap();
        assert!(
            r.verdict()
                .contains("vertex shader loop search fell short: reached 3.5 ms at 4194304 loops (target 15 ms)"),
            "{}",
            r.verdict()
        );
        assert!(r.markdown().contains("fell short: reached 3.5 ms at 4194304 loops"));
    }

    #[test]
    fn a_device_that_overlaps_is_not_called_sum() {
        // Under max the calibrated F(f) absorbs -G(s); the test cells then
        // favour max or the pipelined simulator, never sum.
        let r = analyze(setup(), measured(f64::max), 0.0).unwrap();
        assert_ne!(r.best(), "sum", "{:?}", r.scores);
        for name in ["sum", "simulator (binning = draw)", "simulator (unified pool)"] {
            let sc = r.scores.iter().find(|s| s.hypothesis == name).unwrap();
            assert!(sc.mean_abs_error_pct > 10.0, "{sc:?}");
        }
        // The complex vertex shader adds less once the fragments dominate.
        assert!(r.vs_increase_ms[1] < r.vs_increase_ms[0]);
    }

    #[test]
    fn the_simulator_lies_between_max_and_sum_and_tracks_max_for_uniform_triangles() {
        // Every triangle here costs the same in each stage, so the two stages
        // overlap triangle by triangle at any FIFO depth: the pipelined
        // simulator stays near o + max(G, F) = 21 ms, never the sum (31 ms).
        let r = analyze(setup(), measured(|a, b| a + b), 0.0).unwrap();
        let cc = &r.cells[3];
        assert!(
            cc.simulator_ms >= cc.max_ms - 1e-9 && cc.simulator_ms <= cc.sum_ms + 1e-9,
            "{cc:?}"
        );
        assert!(rel_error_pct(cc.simulator_ms, cc.max_ms) < 5.0, "{cc:?}");
        let (max_err, sum_err) = (rel_error_pct(cc.max_ms, 31.0), 0.0);
        for (depth, e) in &r.fifo_scan {
            assert!(*e >= max_err - 1e-9 && *e <= sum_err + 1e-9, "depth {depth}: {e}");
        }
        // Deeper FIFOs never make it slower.
        assert!(
            r.fifo_scan.windows(2).all(|w| w[1].1 <= w[0].1 + 1e-9),
            "{:?}",
            r.fifo_scan
        );
    }
}
