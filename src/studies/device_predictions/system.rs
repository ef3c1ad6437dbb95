//! The `device_predictions` run, its summary (`metrics.loo_error_pct`,
//! `metrics.kfold_error_pct` (whole meshes held out),
//! `metrics.simulated_error_pct`, ... as median / p90 / worst), its table
//! (one row per measured pass) and its report (the markdown table
//! `rendersim calibrate --report` writes), in the system registry
//! ([`crate::systems::STUDIES`]).

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use serde_json::Value;

use crate::components::vertex_cache::CachePolicy;
use crate::measure::calibrate::read_rows;
use crate::measure::predictions::{DevicePredictions, ErrorStats, calibrate_rows, predict_rows};
use crate::output::trace::TraceWriter;
use crate::systems::error::invalid;
use crate::systems::{Outcome, SystemError, SystemModel, resolved_toml};

use super::config::DevicePredictionsConfig;

/// `system = "device_predictions"`.
pub struct DevicePredictionsSystem;

/// The summary's numbers.
#[derive(Debug, Serialize)]
struct Metrics {
    rows: usize,
    loo_error_pct: ErrorStats,
    /// Whole meshes held out (`KFOLD` folds by mesh): what a new pass is.
    #[serde(skip_serializing_if = "Option::is_none")]
    kfold_error_pct: Option<ErrorStats>,
    linear_baseline_loo_pct: ErrorStats,
    simulated_error_pct: ErrorStats,
    fit_error_pct: ErrorStats,
    measuring_seconds: f64,
    simulating_seconds: f64,
    measuring_over_simulating: f64,
    calibrate_seconds: f64,
    /// Study H2's ratio, measured and predicted (`[sum_vs_max]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    sum_vs_max: Option<super::sum_vs_max::SumVsMax>,
}

/// The summary.
#[derive(Debug, Serialize)]
struct Summary {
    system: &'static str,
    device: String,
    files: Vec<String>,
    vertex_cache: String,
    seed: u64,
    wall_seconds: f64,
    simulate_seconds: f64,
    metrics: Metrics,
}

/// A finished run.
#[derive(Debug)]
pub struct DevicePredictionsRun {
    summary: Summary,
    config: DevicePredictionsConfig,
    /// Every row predicted.
    pub predictions: DevicePredictions,
    trace: Option<TraceWriter>,
}

/// Columns of the per-row table.
const COLUMNS: [&str; 12] = [
    "Row",
    "Width",
    "Height",
    "VsLoops",
    "FsLoops",
    "GeometryOnly",
    "MeasuredMs",
    "LooErrorPct",
    "SimulatedMs",
    "SimulatedErrorPct",
    "MeasuringSeconds",
    "SimulatingSeconds",
];

/// Reads the rows, calibrates, predicts every row.
pub fn run_device_predictions(
    cfg: DevicePredictionsConfig,
    base_dir: &Path,
) -> Result<DevicePredictionsRun, SystemError> {
    let start = Instant::now();
    if cfg.files.is_empty() {
        return Err(invalid("files", "names no pass CSV"));
    }
    if cfg.shader_cores == 0 {
        return Err(invalid("shader_cores", "must be at least 1"));
    }
    let policy: CachePolicy = cfg
        .vertex_cache
        .parse()
        .map_err(|e| invalid("vertex_cache", format!("{e}")))?;
    let mut rows = Vec::new();
    for (i, f) in cfg.files.iter().enumerate() {
        let path = base_dir.join(f);
        rows.extend(read_rows(&path).map_err(|e| invalid(&format!("files[{i}]"), e.to_string()))?);
    }
    let cal =
        calibrate_rows(&rows, &cfg.device, &policy, cfg.shader_cores).map_err(|e| invalid("files", e.to_string()))?;
    let predictions = predict_rows(
        &cal.profile,
        &rows,
        &cal.loo_ns,
        &cal.linear_loo_pct,
        cal.kfold.as_ref(),
    )
    .map_err(|e| invalid("files", e.to_string()))?;
    let sum_vs_max = cfg
        .sum_vs_max
        .as_ref()
        .map(|s| s.evaluate(&cal.profile, &rows, &policy))
        .transpose()?;
    let fit = &cal.profile.fit;
    let metrics = Metrics {
        rows: rows.len(),
        loo_error_pct: predictions.loo,
        kfold_error_pct: predictions.kfold.map(|(_, e)| e),
        linear_baseline_loo_pct: predictions.linear_loo,
        simulated_error_pct: predictions.simulated,
        fit_error_pct: ErrorStats {
            median: fit.median_pct,
            p90: fit.p90_pct,
            worst: fit.worst_pct,
        },
        measuring_seconds: predictions.measuring_seconds,
        simulating_seconds: predictions.simulating_seconds,
        measuring_over_simulating: predictions.measuring_seconds / predictions.simulating_seconds,
        calibrate_seconds: cal.seconds,
        sum_vs_max,
    };
    let summary = Summary {
        system: "device_predictions",
        device: cfg.device.clone(),
        files: cfg.files.iter().map(|f| f.display().to_string()).collect(),
        vertex_cache: policy.to_string(),
        seed: cfg.run.seed,
        wall_seconds: start.elapsed().as_secs_f64(),
        simulate_seconds: predictions.simulating_seconds,
        metrics,
    };
    Ok(DevicePredictionsRun {
        summary,
        config: cfg,
        predictions,
        trace: None,
    })
}

impl SystemModel for DevicePredictionsSystem {
    const NAME: &'static str = "device_predictions";
    const WRITES_TRACE: bool = false;
    type Config = DevicePredictionsConfig;
    type Run = DevicePredictionsRun;

    fn run(
        cfg: DevicePredictionsConfig,
        base_dir: &Path,
        trace: Option<TraceWriter>,
    ) -> Result<DevicePredictionsRun, SystemError> {
        let mut run = run_device_predictions(cfg, base_dir)?;
        // No trace of its own (`rendersim run --trace` refuses the model): a
        // trace writer handed in through the library is closed empty.
        run.trace = trace;
        Ok(run)
    }
}

impl Outcome for DevicePredictionsRun {
    fn summary(&self) -> Value {
        crate::systems::summary::to_json(&self.summary)
    }

    fn write_report(&self, _model: &str, w: &mut dyn Write) -> std::io::Result<()> {
        w.write_all(
            self.predictions
                .markdown("the `device_predictions` system (`rendersim run`, `experiments/device-predictions.toml`)")
                .as_bytes(),
        )
    }

    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        let rows = self
            .predictions
            .rows
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let r = &p.row;
                vec![
                    i as f64,
                    f64::from(r.size.width),
                    f64::from(r.size.height),
                    f64::from(r.vs_loops),
                    f64::from(r.fs_loops),
                    f64::from(u8::from(r.geometry_only)),
                    r.pass_time_ns / 1e6,
                    p.loo_error_pct,
                    p.simulated_ns / 1e6,
                    p.simulated_error_pct,
                    p.measuring_seconds,
                    p.simulating_seconds,
                ]
            })
            .collect();
        (COLUMNS.iter().map(|c| c.to_string()).collect(), rows)
    }

    fn write_table(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let (columns, rows) = self.table();
        crate::output::table::write_number_table(std::io::BufWriter::new(w), &columns, &rows)
    }

    fn resolved_model(&self, base_dir: &Path) -> String {
        let mut cfg = self.config.clone();
        cfg.files = cfg.files.iter().map(|f| base_dir.join(f)).collect();
        resolved_toml(&cfg)
    }

    fn take_trace(&mut self) -> Option<TraceWriter> {
        self.trace.take()
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn into_any(self: Box<Self>) -> Box<dyn std::any::Any> {
        self
    }
}
