//! Study H3: draw order and early-z (paper 000 §4.5.2 and Table 3). A
//! screen-filling grid drawn as `L` layers at different depths, with the depth
//! test, front to back, back to front and in a fixed random order; fragment
//! invocations and pass time for each.
//!
//! Calibration (no depth test, so every layer is shaded): one layer `T1` and
//! `L` layers `Tall`, and front to back with the depth test `Tf2b`, which
//! shades one layer and rejects `L - 1`. Per layer, shading costs
//! `P = (Tall - Tf2b) / (L - 1)`, rasterizing and testing `R = (Tall - T1) /
//! (L - 1) - P`, and the rest is overhead `o = T1 - R - P`. Predicted, not
//! fitted: back to front `o + L (R + P)`, and the random order
//! `o + L R + S P`, with `S` the layers that pass (the records of the drawn
//! permutation: a layer passes when it is nearer than every layer before it).
//! The simulator prices the same passes with its early-z model (paper 000: a
//! fragment passes with probability 1/d front to back, 1 back to front, and
//! H(d)/d in random order), which for the random order is an expectation over
//! orders, not the one permutation drawn.

use serde::Serialize;

use super::fit::rel_error_pct;
use super::geometry::DepthOrder;
use super::loops::LoopSearch;
use super::predict::{PassModel, PredictError, duration_ps, simulate_pass};
use crate::engine::Duration;

/// What H3 draws.
#[derive(Debug, Clone, Serialize)]
pub struct H3Setup {
    /// The mesh of every layer (covering the target).
    pub mesh: String,
    /// Render target, pixels.
    pub size: (u32, u32),
    /// Layers (depth complexity).
    pub layers: u32,
    /// Fragment-shader loop count.
    pub fs_loops: u32,
    /// Vertex-cache policy the simulator uses.
    pub cache: String,
    /// When set, the fragment loop count is found on the device before
    /// measuring, so that shading one layer takes at least this long (ms).
    pub auto_target_ms: Option<f64>,
    /// Where the fragment shader's loop search ended (set by the search).
    pub fs_search: Option<LoopSearch>,
}

impl Default for H3Setup {
    fn default() -> Self {
        H3Setup {
            mesh: "grid:16x16".into(),
            size: (384, 384),
            layers: 8,
            fs_loops: 40,
            cache: "lavapipe".into(),
            auto_target_ms: Some(5.0),
            fs_search: None,
        }
    }
}

/// One measured pass.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct H3Pass {
    /// Median pass time, ns.
    pub time_ns: f64,
    /// Fragment-shader invocations.
    pub fs_invocations: u64,
}

/// H3's measurements.
#[derive(Debug, Clone, Serialize)]
pub struct H3Measured {
    /// One layer, no depth test.
    pub one_layer: H3Pass,
    /// All layers, no depth test.
    pub all_layers: H3Pass,
    /// With the depth test: front to back, back to front, random.
    pub ordered: [H3Pass; 3],
    /// Triangles per layer.
    pub triangles: u64,
}

/// One order: measured and predicted.
#[derive(Debug, Clone, Serialize)]
pub struct H3Row {
    /// The order.
    pub order: &'static str,
    /// Whether it calibrated the costs.
    pub calibration: bool,
    /// Layers shaded per pixel in the drawn order.
    pub layers_shaded: f64,
    /// Measured fragment invocations.
    pub fs_invocations: u64,
    /// Measured time, ms.
    pub measured_ms: f64,
    /// Predicted from the calibrated costs and the drawn order, ms.
    pub predicted_ms: f64,
    /// The simulator's early-z model, ms.
    pub simulator_ms: f64,
    /// Layers the simulator expects shaded per pixel.
    pub simulator_layers_shaded: f64,
}

/// The study's result.
#[derive(Debug, Clone, Serialize)]
pub struct H3 {
    /// The setup.
    pub setup: H3Setup,
    /// The measurements.
    pub measured: H3Measured,
    /// Overhead, rasterize-and-test per layer, shade per layer, ms.
    pub costs_ms: [f64; 3],
    /// The three orders.
    pub rows: Vec<H3Row>,
    /// Whether the fragment counter saw the depth test (differs by order).
    pub counter_sees_early_z: bool,
    /// Seconds spent measuring.
    pub measure_seconds: f64,
    /// Seconds spent simulating.
    pub simulate_seconds: f64,
}

/// Layers that pass a `Less` depth test per pixel when layers are drawn with
/// these depth slots (0 = nearest) in this order: the running-minimum records.
pub fn layers_passing(slots: &[u32]) -> u32 {
    let mut best = u32::MAX;
    let mut n = 0;
    for &s in slots {
        if s < best {
            best = s;
            n += 1;
        }
    }
    n
}

const ORDERS: [(DepthOrder, &str, &str); 3] = [
    (DepthOrder::FrontToBack, "front to back", "front_to_back"),
    (DepthOrder::BackToFront, "back to front", "back_to_front"),
    (DepthOrder::Random, "random", "random"),
];

/// Analyses H3's measurements.
pub fn analyze(setup: H3Setup, m: H3Measured, measure_seconds: f64) -> Result<H3, PredictError> {
    let t0 = std::time::Instant::now();
    let l = f64::from(setup.layers.max(2));
    let ms = |ns: f64| ns / 1e6;
    let (t1, tall, tf2b) = (
        ms(m.one_layer.time_ns),
        ms(m.all_layers.time_ns),
        ms(m.ordered[0].time_ns),
    );
    let p = (tall - tf2b) / (l - 1.0);
    let r = (tall - t1) / (l - 1.0) - p;
    let o = t1 - r - p;
    let frags_per_layer = m.one_layer.fs_invocations.max(1) as f64;
    let tris = m.triangles.max(1) as f64;
    let mut rows = Vec::new();
    for (i, (order, name, key)) in ORDERS.iter().enumerate() {
        let shaded = f64::from(layers_passing(&order.slots(setup.layers)));
        let sim = simulate_pass(&PassModel {
            mesh: setup.mesh.clone(),
            cache: setup.cache.clone(),
            layers: setup.layers,
            per_vertex: Duration::ZERO,
            per_fragment: duration_ps((r + p) * 1e9 / frags_per_layer),
            per_rejected_fragment: duration_ps(r * 1e9 / frags_per_layer),
            fragments_per_triangle: frags_per_layer / tris,
            depth_order: (*key).into(),
            fifo_depth: 16,
            binning: false,
            unified: false,
        })?;
        let pass = crate::systems::frame_pipeline::workload::early_z_pass(scene_order(*order), l);
        rows.push(H3Row {
            order: name,
            calibration: i == 0,
            layers_shaded: shaded,
            fs_invocations: m.ordered[i].fs_invocations,
            measured_ms: ms(m.ordered[i].time_ns),
            predicted_ms: o + l * r + shaded * p,
            simulator_ms: o + sim.gpu_ms,
            simulator_layers_shaded: pass * l,
        });
    }
    let counter_sees_early_z = m
        .ordered
        .iter()
        .any(|x| x.fs_invocations != m.ordered[0].fs_invocations);
    Ok(H3 {
        setup,
        measured: m,
        costs_ms: [o, r, p],
        rows,
        counter_sees_early_z,
        measure_seconds,
        simulate_seconds: t0.elapsed().as_secs_f64(),
    })
}

fn scene_order(o: DepthOrder) -> crate::scene::config::DepthOrder {
    match o {
        DepthOrder::FrontToBack => crate::scene::config::DepthOrder::FrontToBack,
        DepthOrder::BackToFront => crate::scene::config::DepthOrder::BackToFront,
        DepthOrder::Random => crate::scene::config::DepthOrder::Random,
    }
}

impl H3 {
    /// Mean |error| of the calibrated prediction on the predicted orders, percent.
    pub fn prediction_error_pct(&self) -> f64 {
        let e: Vec<f64> = self
            .rows
            .iter()
            .filter(|r| !r.calibration)
            .map(|r| rel_error_pct(r.predicted_ms, r.measured_ms).abs())
            .collect();
        e.iter().sum::<f64>() / e.len().max(1) as f64
    }

    /// One line: how well the calibrated costs predict the other orders
    /// (and a loop search that fell short).
    pub fn verdict(&self) -> String {
        let mut v = format!(
            "draw order: calibrated early-z costs predict the other orders within {:.1}% (mean)",
            self.prediction_error_pct()
        );
        if let Some(f) = self.setup.fs_search.filter(|f| !f.reached()) {
            v += &format!("; fragment shader loop search {}", f.shortfall());
        }
        v
    }

    /// The result as a Markdown section.
    pub fn markdown(&self) -> String {
        let s = &self.setup;
        let m = &self.measured;
        let [o, r, p] = self.costs_ms;
        let mut out = format!(
            "## H3: draw order and early-z (paper 000 §4.5.2, Table 3)\n\n\
             `{}` as {} layers on a {}x{} target, fragment shader {} loop iterations{}, depth test on. \
             Calibration without the depth test: one layer {:.3} ms ({} fragment invocations), all layers {:.3} ms ({}). \
             Costs: overhead {o:.3} ms, rasterize and test {r:.3} ms per layer, shade {p:.3} ms per layer.\n\n\
             | order | layers shaded | fragment invocations | measured ms | predicted ms (err) | simulator ms (err; expects layers shaded) | |\n|---|---|---|---|---|---|---|\n",
            s.mesh,
            s.layers,
            s.size.0,
            s.size.1,
            s.fs_loops,
            s.fs_search.map_or(String::new(), |f| format!(
                " (searched on this device: {})",
                f.outcome("shading one layer")
            )),
            m.one_layer.time_ns / 1e6,
            m.one_layer.fs_invocations,
            m.all_layers.time_ns / 1e6,
            m.all_layers.fs_invocations,
        );
        for row in &self.rows {
            out += &format!(
                "| {} | {} | {} | {:.3} | {:.3} ({:+.1}%) | {:.3} ({:+.1}%; {:.2}) | {} |\n",
                row.order,
                row.layers_shaded,
                row.fs_invocations,
                row.measured_ms,
                row.predicted_ms,
                rel_error_pct(row.predicted_ms, row.measured_ms),
                row.simulator_ms,
                rel_error_pct(row.simulator_ms, row.measured_ms),
                row.simulator_layers_shaded,
                if row.calibration { "calibration" } else { "test" }
            );
        }
        out += &format!(
            "\nMean error of the calibrated prediction on the orders not used for calibration: {:.1}%. \
             The fragment-invocation counter {} the depth test{}.\n\n\
             Measuring took {:.2} s; simulating took {:.3} s.\n",
            self.prediction_error_pct(),
            if self.counter_sees_early_z {
                "sees"
            } else {
                "does not see"
            },
            if self.counter_sees_early_z {
                ""
            } else {
                " (it counts before the early depth test, so only the time shows the saving)"
            },
            self.measure_seconds,
            self.simulate_seconds
        );
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_of_permutations() {
        assert_eq!(layers_passing(&[0, 1, 2, 3]), 1);
        assert_eq!(layers_passing(&[3, 2, 1, 0]), 4);
        assert_eq!(layers_passing(&[2, 3, 0, 1]), 2);
        assert_eq!(layers_passing(&[]), 0);
    }

    #[test]
    fn a_device_that_follows_the_model_is_predicted_exactly() {
        let setup = H3Setup::default();
        let l = f64::from(setup.layers);
        let (o, r, p) = (0.5e6, 0.2e6, 1.5e6);
        let random = f64::from(layers_passing(&DepthOrder::Random.slots(setup.layers)));
        let pass = |shaded: f64| H3Pass {
            time_ns: o + l * r + shaded * p,
            fs_invocations: 1000,
        };
        let m = H3Measured {
            one_layer: H3Pass {
                time_ns: o + r + p,
                fs_invocations: 1000,
            },
            all_layers: pass(l),
            ordered: [pass(1.0), pass(l), pass(random)],
            triangles: 512,
        };
        let h = analyze(setup, m, 0.0).unwrap();
        assert!(h.prediction_error_pct() < 1e-9, "{}", h.markdown());
        let [co, cr, cp] = h.costs_ms;
        assert!((co - 0.5).abs() < 1e-9 && (cr - 0.2).abs() < 1e-9 && (cp - 1.5).abs() < 1e-9);
        // The simulator's early-z model agrees on the sorted orders.
        for row in &h.rows[..2] {
            assert!(rel_error_pct(row.simulator_ms, row.measured_ms).abs() < 0.01, "{row:?}");
        }
        assert!(!h.counter_sees_early_z);
    }
}
