//! Study H4: what does one transformed vertex cost? Paper 000 prices the
//! geometry stage per actually transformed vertex (§2, §4.5). One mesh is
//! drawn in index orders of decreasing locality (cache-optimized, row by row,
//! triangles shuffled within windows of growing size, fully shuffled), so
//! the vertex-shader invocations change while the triangles and the pixels
//! stay the same. Each order is drawn twice: geometry only (every vertex at
//! one point, no fragments: the cost of the vertices alone) and as a full
//! pass. Both times are fitted against the measured invocations (least
//! squares, R^2); then each order's times are predicted from the simulator's
//! own count of transformed vertices (its cache policy for the device) with
//! lines fitted to the other orders only (leave-one-out), and the errors are
//! reported.

use serde::Serialize;

use super::fit::{LineFit, fit_line, leave_one_out, rel_error_pct};
use super::loops::LoopSearch;

/// What H4 draws.
#[derive(Debug, Clone, Serialize)]
pub struct H4Setup {
    /// Grid size W (the mesh is `grid:WxW` in every order).
    pub grid: u32,
    /// Render target, pixels.
    pub size: (u32, u32),
    /// Vertex-shader loop count (makes vertices expensive).
    pub vs_loops: u32,
    /// Vertex-cache policy the simulator uses.
    pub cache: String,
    /// When set, the vertex loop count is found on the device before
    /// measuring, so that the geometry-only pass of the cache-optimized order
    /// takes at least this long (ms).
    pub auto_target_ms: Option<f64>,
    /// Where the vertex shader's loop search ended (set by the search).
    pub vs_search: Option<LoopSearch>,
}

impl Default for H4Setup {
    fn default() -> Self {
        H4Setup {
            grid: 128,
            size: (256, 256),
            vs_loops: 300,
            cache: "lavapipe".into(),
            auto_target_ms: Some(10.0),
            vs_search: None,
        }
    }
}

impl H4Setup {
    /// The orders drawn, as mesh specs.
    pub fn orders(&self) -> Vec<String> {
        let w = self.grid;
        let mut v = vec![format!("grid:{w}x{w}:optimized"), format!("grid:{w}x{w}")];
        for window in [16u32, 64, 256, 1024, 4096] {
            v.push(format!("grid:{w}x{w}:local:{window}:1"));
        }
        v.push(format!("grid:{w}x{w}:shuffled:1"));
        v.push(format!("grid:{w}x{w}:shuffled:2"));
        v
    }
}

/// One order.
#[derive(Debug, Clone, Serialize)]
pub struct H4Row {
    /// Mesh spec.
    pub mesh: String,
    /// Measured vertex-shader invocations.
    pub measured_vs: u64,
    /// The simulator's transformed vertices.
    pub simulated_vs: u64,
    /// Fragment-shader invocations (the same for every order).
    pub fs_invocations: u64,
    /// Median time of the geometry-only pass, ms.
    pub geometry_ms: f64,
    /// Median time of the full pass, ms.
    pub measured_ms: f64,
    /// Geometry-only time predicted from the simulated count on a line fitted to the other orders, ms.
    pub predicted_geometry_ms: Option<f64>,
    /// Full-pass time predicted the same way, ms.
    pub predicted_ms: Option<f64>,
}

/// The study's result.
#[derive(Debug, Clone, Serialize)]
pub struct H4 {
    /// The setup.
    pub setup: H4Setup,
    /// Every order.
    pub rows: Vec<H4Row>,
    /// Geometry-only time (ms) against measured invocations.
    pub geometry_fit: Option<LineFit>,
    /// Full-pass time (ms) against measured invocations.
    pub fit: Option<LineFit>,
    /// Mean |error| of the leave-one-out geometry-only predictions, percent.
    pub geometry_error_pct: f64,
    /// Mean |error| of the leave-one-out full-pass predictions, percent.
    pub mean_abs_error_pct: f64,
    /// Seconds spent measuring.
    pub measure_seconds: f64,
    /// Seconds spent on the simulator's counts and the fits.
    pub simulate_seconds: f64,
}

/// Fits `y` against the measured counts and predicts every row from the
/// simulated count with the line through the other rows; returns the fit,
/// the predictions and their mean |error| in percent.
fn fit_and_predict(x: &[f64], sim_x: &[f64], y: &[f64]) -> (Option<LineFit>, Vec<Option<f64>>, f64) {
    let preds: Vec<Option<f64>> = leave_one_out(x, y)
        .iter()
        .zip(sim_x)
        .map(|(f, xs)| f.map(|f| f.at(*xs)))
        .collect();
    let errs: Vec<f64> = preds
        .iter()
        .zip(y)
        .filter_map(|(p, m)| p.map(|p| rel_error_pct(p, *m).abs()))
        .collect();
    let mean = if errs.is_empty() {
        f64::NAN
    } else {
        errs.iter().sum::<f64>() / errs.len() as f64
    };
    (fit_line(x, y), preds, mean)
}

/// Analyses H4's rows (with the predictions still empty).
pub fn analyze(setup: H4Setup, mut rows: Vec<H4Row>, measure_seconds: f64, simulate_seconds: f64) -> H4 {
    let t0 = std::time::Instant::now();
    let x: Vec<f64> = rows.iter().map(|r| r.measured_vs as f64).collect();
    let sim_x: Vec<f64> = rows.iter().map(|r| r.simulated_vs as f64).collect();
    let geo: Vec<f64> = rows.iter().map(|r| r.geometry_ms).collect();
    let full: Vec<f64> = rows.iter().map(|r| r.measured_ms).collect();
    let (geometry_fit, geo_pred, geometry_error_pct) = fit_and_predict(&x, &sim_x, &geo);
    let (fit, full_pred, mean_abs_error_pct) = fit_and_predict(&x, &sim_x, &full);
    for ((r, g), f) in rows.iter_mut().zip(geo_pred).zip(full_pred) {
        r.predicted_geometry_ms = g;
        r.predicted_ms = f;
    }
    H4 {
        setup,
        rows,
        geometry_fit,
        fit,
        geometry_error_pct,
        mean_abs_error_pct,
        measure_seconds,
        simulate_seconds: simulate_seconds + t0.elapsed().as_secs_f64(),
    }
}

impl H4 {
    /// One line: the cost per transformed vertex, alone and in full passes
    /// (and a loop search that fell short).
    pub fn verdict(&self) -> String {
        let mut v = self.fit_verdict();
        if let Some(f) = self.setup.vs_search.filter(|f| !f.reached()) {
            v += &format!("; vertex shader loop search {}", f.shortfall());
        }
        v
    }

    fn fit_verdict(&self) -> String {
        match (&self.geometry_fit, &self.fit) {
            (Some(g), Some(f)) => format!(
                "cost per transformed vertex: {:.1} ns alone (R^2 {:.3}, leave-one-out error {:.1}%), \
                 {:.1} ns in full passes (R^2 {:.3}, error {:.1}%)",
                g.slope * 1e6,
                g.r_squared,
                self.geometry_error_pct,
                f.slope * 1e6,
                f.r_squared,
                self.mean_abs_error_pct
            ),
            _ => "cost per transformed vertex: no line could be fitted".into(),
        }
    }

    /// The result as a Markdown section.
    pub fn markdown(&self) -> String {
        let s = &self.setup;
        let line = |f: &Option<LineFit>| match f {
            Some(f) => format!(
                "{:.1} ns per invocation, intercept {:.3} ms, R^2 = {:.4}",
                f.slope * 1e6,
                f.intercept,
                f.r_squared
            ),
            None => "no line could be fitted".to_string(),
        };
        let mut out = format!(
            "## H4: cost per transformed vertex\n\n\
             `grid:{w}x{w}` in {} index orders on a {}x{} target, vertex shader {} loop iterations{}. \
             Time against measured vertex-shader invocations: geometry only {}; full pass {}.\n\n\
             Predicted = the simulator's transformed vertices (policy `{}`) on a line fitted to the other orders (leave-one-out).\n\n\
             | order | measured VS | simulated VS | FS invocations | geometry-only ms | predicted (err) | full pass ms | predicted (err) |\n|---|---|---|---|---|---|---|---|\n",
            self.rows.len(),
            s.size.0,
            s.size.1,
            s.vs_loops,
            s.vs_search.map_or(String::new(), |f| format!(
                " (searched on this device: {})",
                f.outcome("the cache-optimized order's geometry-only pass")
            )),
            line(&self.geometry_fit),
            line(&self.fit),
            s.cache,
            w = s.grid,
        );
        let pred =
            |p: Option<f64>, m: f64| p.map_or("-".to_string(), |p| format!("{p:.3} ({:+.1}%)", rel_error_pct(p, m)));
        for r in &self.rows {
            out += &format!(
                "| `{}` | {} | {} | {} | {:.3} | {} | {:.3} | {} |\n",
                r.mesh,
                r.measured_vs,
                r.simulated_vs,
                r.fs_invocations,
                r.geometry_ms,
                pred(r.predicted_geometry_ms, r.geometry_ms),
                r.measured_ms,
                pred(r.predicted_ms, r.measured_ms)
            );
        }
        out += &format!(
            "\nMean |error| of the leave-one-out predictions: geometry only {:.1}%, full pass {:.1}%. \
             Measuring took {:.2} s; the simulator's counts and the fits took {:.3} s.\n",
            self.geometry_error_pct, self.mean_abs_error_pct, self.measure_seconds, self.simulate_seconds
        );
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_device_is_fitted_and_predicted_exactly() {
        let setup = H4Setup::default();
        let rows: Vec<H4Row> = [1000u64, 1500, 2400, 5000, 9000]
            .iter()
            .enumerate()
            .map(|(i, &vs)| H4Row {
                mesh: format!("order {i}"),
                measured_vs: vs,
                simulated_vs: vs,
                fs_invocations: 10,
                geometry_ms: 0.1 + 0.001 * vs as f64,
                measured_ms: 0.5 + 0.002 * vs as f64,
                predicted_geometry_ms: None,
                predicted_ms: None,
            })
            .collect();
        let h = analyze(setup, rows, 0.0, 0.0);
        let f = h.fit.unwrap();
        assert!((f.slope - 0.002).abs() < 1e-12 && (f.r_squared - 1.0).abs() < 1e-12);
        assert!(h.mean_abs_error_pct < 1e-9 && h.geometry_error_pct < 1e-9);
        assert!((h.geometry_fit.unwrap().slope - 0.001).abs() < 1e-12);
        let md = h.markdown();
        assert!(
            md.contains("2000.0 ns per invocation") && md.contains("1000.0 ns per invocation"),
            "{md}"
        );
    }

    #[test]
    fn the_loop_search_reports_the_time_it_measured_or_its_shortfall() {
        let rows = |setup: H4Setup| {
            let rows = [1000u64, 2000, 3000]
                .iter()
                .map(|&vs| H4Row {
                    mesh: "m".into(),
                    measured_vs: vs,
                    simulated_vs: vs,
                    fs_invocations: 0,
                    geometry_ms: 0.001 * vs as f64,
                    measured_ms: 0.001 * vs as f64,
                    predicted_geometry_ms: None,
                    predicted_ms: None,
                })
                .collect();
            analyze(setup, rows, 0.0, 0.0)
        };
        let search = |loops, reached_ms| LoopSearch {
            target_ms: 10.0,
            loops,
            reached_ms,
            tries: 2,
        };
        let h = rows(H4Setup {
            vs_loops: 23530,
            vs_search: Some(search(23530, 11.4)),
            ..H4Setup::default()
        });
        let md = h.markdown();
        assert!(md.contains("vertex shader 23530 loop iterations"), "{md}");
        assert!(
            md.contains(
                "vertex shader 23530 loop iterations (searched on this device: the cache-optimized order's \
                 geometry-only pass took 11.4 ms there, target at least 10 ms)"
            ),
            "{md}"
        );
        assert!(!h.verdict().contains("fell short"));
        let h = rows(H4Setup {
            vs_search: Some(search(300, 0.153)),
            ..H4Setup::default()
        });
        assert!(
            h.verdict()
                .ends_with("; vertex shader loop search fell short: reached 0.153 ms at 300 loops (target 10 ms)"),
            "{}",
            h.verdict()
        );
    }

    #[test]
    fn a_wrong_simulated_count_shows_as_error() {
        let rows: Vec<H4Row> = [1000u64, 2000, 3000, 4000]
            .iter()
            .map(|&vs| H4Row {
                mesh: "m".into(),
                measured_vs: vs,
                simulated_vs: vs * 2,
                fs_invocations: 0,
                geometry_ms: 0.001 * vs as f64,
                measured_ms: 0.001 * vs as f64,
                predicted_geometry_ms: None,
                predicted_ms: None,
            })
            .collect();
        let h = analyze(H4Setup::default(), rows, 0.0, 0.0);
        assert!((h.mean_abs_error_pct - 100.0).abs() < 1e-6, "{}", h.mean_abs_error_pct);
        assert!((h.geometry_error_pct - 100.0).abs() < 1e-6);
    }

    #[test]
    fn orders_are_valid_specs_of_one_mesh() {
        let s = H4Setup {
            grid: 8,
            ..H4Setup::default()
        };
        let base = crate::scene::generators::mesh_from_spec("grid:8x8", std::path::Path::new(".")).unwrap();
        for spec in s.orders() {
            let m = crate::scene::generators::mesh_from_spec(&spec, std::path::Path::new(".")).unwrap();
            assert_eq!(m.triangles(), base.triangles(), "{spec}");
        }
    }
}
