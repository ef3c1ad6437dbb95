//! Predicted against measured, per device (issue 10 item 3): a device
//! profile fitted to measured passes (`calibrate.rs`), every row predicted
//! by the profile fitted to the other rows (leave-one-out: the shared data
//! are few), and every row simulated with the full profile by the
//! frame-pipeline model as `rendersim predict` runs it
//! (`device_predict.rs`), with the device time measuring the row took
//! against this machine's wall time simulating it. Written as markdown by
//! `rendersim calibrate --report` and run as the `device_predictions`
//! system by `experiments/device-predictions.toml`.

use std::fmt::Write as _;
use std::time::Instant;

use serde::Serialize;

use super::calibrate::{CalibrateError, Invocations, LoadCache, fit, row_load};
use super::cross_validation::{MeshFolds, error_summary, k_fold_by_mesh, leave_one_out_ns, linear_baseline_loo};
use super::device_predict::{DevicePass, DevicePredictError, predict_on_device};
use super::device_profile::{DeviceCosts, PassLoad};
use super::device_profile::{DeviceInfo, DeviceProfile, FitAccuracy};
use super::fit::rel_error_pct;
use super::passes::PassRow;
use crate::components::vertex_cache::CachePolicy;

/// Passes a measurement records per row: 2 warm-ups and 5 repeats.
pub const PASSES_PER_ROW: f64 = 7.0;

/// Median, 90th percentile and worst of the absolute errors (percent).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ErrorStats {
    /// Median |error|, percent.
    pub median: f64,
    /// 90th percentile of |error|, percent.
    pub p90: f64,
    /// Worst |error|, percent.
    pub worst: f64,
}

impl ErrorStats {
    /// The statistics of `errors_pct` ([`error_summary`]).
    pub fn of(errors_pct: &[f64]) -> ErrorStats {
        let (median, p90, worst) = error_summary(errors_pct);
        ErrorStats { median, p90, worst }
    }
}

/// One measured row, predicted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RowPrediction {
    /// The measured pass.
    #[serde(skip)]
    pub row: PassRow,
    /// Leave-one-out prediction, ns.
    pub loo_ns: f64,
    /// Its relative error, percent.
    pub loo_error_pct: f64,
    /// The full profile's simulation of the pass, ns.
    pub simulated_ns: f64,
    /// Its relative error, percent.
    pub simulated_error_pct: f64,
    /// Device time the measurement took: [`PASSES_PER_ROW`] passes (a lower
    /// bound: setup and readback are not in the CSV), seconds.
    pub measuring_seconds: f64,
    /// Wall time of the simulation here, seconds.
    pub simulating_seconds: f64,
}

/// Every row of one device, predicted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DevicePredictions {
    /// The device.
    pub device: String,
    /// Per row, in file order.
    pub rows: Vec<RowPrediction>,
    /// Leave-one-out errors.
    pub loo: ErrorStats,
    /// A plain linear fit's leave-one-out errors (the baseline to beat).
    pub linear_loo: ErrorStats,
    /// Errors with whole meshes held out (k-fold by mesh), when computed:
    /// (folds, the statistics).
    pub kfold: Option<(usize, ErrorStats)>,
    /// The full profile's simulation's errors.
    pub simulated: ErrorStats,
    /// Sum of the rows' measuring times, seconds.
    pub measuring_seconds: f64,
    /// Sum of the rows' simulating times, seconds.
    pub simulating_seconds: f64,
}

/// Errors of a prediction report.
#[derive(Debug, thiserror::Error)]
pub enum PredictionsError {
    /// The calibration failed.
    #[error(transparent)]
    Calibrate(#[from] CalibrateError),
    /// A row could not be simulated.
    #[error(transparent)]
    Predict(#[from] DevicePredictError),
}

/// A calibration of measured rows: the full fit's profile and each row's
/// leave-one-out prediction.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The profile fitted to every row.
    pub profile: DeviceProfile,
    /// Per row, the prediction of the fit to the other rows, ns.
    pub loo_ns: Vec<f64>,
    /// Per row, a plain linear fit's leave-one-out error, percent.
    pub linear_loo_pct: Vec<f64>,
    /// Per row, the error of the prediction by a fit without any pass of
    /// its mesh ([`KFOLD`] folds by mesh, as `calibrate --kfold`); `None`
    /// with fewer than two meshes or a fold that leaves too few rows.
    pub kfold: Option<MeshFolds>,
    /// Wall time of the fits, seconds.
    pub seconds: f64,
}

/// Folds of the k-fold cross-validation by mesh a calibration reports (at
/// most one per distinct mesh).
pub const KFOLD: usize = 6;

/// The loads of `rows` as fitted (measured vertex invocations) and as
/// predicted (the cache policy's), and their pass times.
type RowLoads = (Vec<PassLoad>, Vec<PassLoad>, Vec<f64>);

fn row_loads(rows: &[PassRow], policy: &CachePolicy) -> Result<RowLoads, CalibrateError> {
    let mut cache = LoadCache::default();
    cache.prefetch(rows, policy)?;
    let mut fit_loads = Vec::with_capacity(rows.len());
    let mut predict_loads = Vec::with_capacity(rows.len());
    for r in rows {
        fit_loads.push(row_load(r, &mut cache, policy, Invocations::Measured)?);
        predict_loads.push(row_load(r, &mut cache, policy, Invocations::Predicted)?);
    }
    Ok((fit_loads, predict_loads, rows.iter().map(|r| r.pass_time_ns).collect()))
}

/// The costs fitted to `rows` alone: the fit of [`calibrate_rows`],
/// without its cross-validations.
pub fn fit_rows(rows: &[PassRow], policy: &CachePolicy) -> Result<DeviceCosts, CalibrateError> {
    let (fit_loads, _, y) = row_loads(rows, policy)?;
    Ok(fit(&fit_loads, &y)?.costs)
}

/// Fits a profile named `name` to `rows` (fit on the measured vertex
/// invocations, leave-one-out predictions on the cache policy's), as
/// `rendersim calibrate --loo` does.
pub fn calibrate_rows(
    rows: &[PassRow],
    name: &str,
    policy: &CachePolicy,
    shader_cores: u32,
) -> Result<Calibration, CalibrateError> {
    let start = Instant::now();
    let (fit_loads, predict_loads, y) = row_loads(rows, policy)?;
    let f = fit(&fit_loads, &y)?;
    let fitted: Vec<f64> = fit_loads.iter().map(|l| f.costs.cost(l).pass_ns).collect();
    let errors: Vec<f64> = fitted.iter().zip(&y).map(|(p, m)| rel_error_pct(*p, *m)).collect();
    let loo_ns = leave_one_out_ns(&fit_loads, &predict_loads, &y)?;
    let loo: Vec<f64> = loo_ns.iter().zip(&y).map(|(p, m)| rel_error_pct(*p, *m)).collect();
    let linear_loo_pct = linear_baseline_loo(&predict_loads, &y);
    let meshes: Vec<&str> = rows.iter().map(|r| r.mesh.as_str()).collect();
    let kfold = k_fold_by_mesh(&fit_loads, &predict_loads, &y, &meshes, KFOLD).ok();
    let (median, p90, worst) = error_summary(&errors);
    let (lm, lp, _) = error_summary(&loo);
    let kfold_summary = kfold.as_ref().map(|k| error_summary(&k.errors));
    let profile = DeviceProfile {
        device: DeviceInfo {
            name: name.to_string(),
            vertex_cache: policy.to_string(),
            shader_cores,
        },
        costs: f.costs,
        uncertainty: f.std_errors.iter().cloned().collect(),
        fit: FitAccuracy {
            rows: rows.len(),
            median_pct: median,
            p90_pct: p90,
            worst_pct: worst,
            loo_median_pct: Some(lm),
            loo_p90_pct: Some(lp),
            kfold_median_pct: kfold_summary.map(|k| k.0),
            kfold_p90_pct: kfold_summary.map(|k| k.1),
        },
    };
    if let Err(super::device_profile::ProfileError::Invalid { key, value, why }) = profile.validate() {
        return Err(CalibrateError::Profile { key, value, why });
    }
    Ok(Calibration {
        profile,
        loo_ns,
        linear_loo_pct,
        kfold,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Every row of `rows` with its leave-one-out prediction (`loo_ns`, from
/// [`calibrate_rows`]) and its simulation on `profile`; `kfold` the
/// cross-validation by mesh, when there is one.
pub fn predict_rows(
    profile: &DeviceProfile,
    rows: &[PassRow],
    loo_ns: &[f64],
    linear_loo_pct: &[f64],
    kfold: Option<&MeshFolds>,
) -> Result<DevicePredictions, PredictionsError> {
    let mut out = Vec::with_capacity(rows.len());
    for (r, &loo) in rows.iter().zip(loo_ns) {
        let p = predict_on_device(profile, &DevicePass::from(r))?;
        out.push(RowPrediction {
            row: r.clone(),
            loo_ns: loo,
            loo_error_pct: rel_error_pct(loo, r.pass_time_ns),
            simulated_ns: p.pass_time_ns,
            simulated_error_pct: rel_error_pct(p.pass_time_ns, r.pass_time_ns),
            measuring_seconds: PASSES_PER_ROW * r.pass_time_ns * 1e-9,
            simulating_seconds: p.sim_wall_seconds,
        });
    }
    let stats = |f: fn(&RowPrediction) -> f64| ErrorStats::of(&out.iter().map(f).collect::<Vec<_>>());
    Ok(DevicePredictions {
        device: profile.device.name.clone(),
        loo: stats(|r| r.loo_error_pct),
        simulated: stats(|r| r.simulated_error_pct),
        linear_loo: ErrorStats::of(linear_loo_pct),
        kfold: kfold.map(|k| (k.folds, ErrorStats::of(&k.errors))),
        measuring_seconds: out.iter().map(|r| r.measuring_seconds).sum(),
        simulating_seconds: out.iter().map(|r| r.simulating_seconds).sum(),
        rows: out,
    })
}

impl DevicePredictions {
    /// The report as markdown: one table row per measured row, then the
    /// error statistics and the time measuring against simulating took.
    /// `source` says what wrote it.
    pub fn markdown(&self, source: &str) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "# Predicted against measured: {}\n", self.device);
        let _ = writeln!(
            s,
            "Written by {source} (rendersim {}). `loo %`: the pass predicted by the \
             profile fitted to every other row (the cost formula of docs/models.md); `sim %`: the pass \
             simulated with the full profile by the frame-pipeline model at triangle fidelity, as \
             `rendersim predict` does. `measuring s`: the device time of the 7 passes a measurement \
             records (2 warm-ups, 5 repeats; a lower bound: setup and readback are not in the CSV); \
             `simulating s`: this machine's wall time for the simulation.\n",
            env!("CARGO_PKG_VERSION")
        );
        let _ = writeln!(
            s,
            "| mesh | size | vs loops | fs loops | geometry only | measured ms | loo % | simulated ms | sim % | measuring s | simulating s |"
        );
        let _ = writeln!(s, "|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|");
        for p in &self.rows {
            let r = &p.row;
            let _ = writeln!(
                s,
                "| {} | {}x{} | {} | {} | {} | {:.4} | {:+.1} | {:.4} | {:+.1} | {:.4} | {:.4} |",
                r.mesh,
                r.size.width,
                r.size.height,
                r.vs_loops,
                r.fs_loops,
                if r.geometry_only { "yes" } else { "" },
                r.pass_time_ns / 1e6,
                p.loo_error_pct,
                p.simulated_ns / 1e6,
                p.simulated_error_pct,
                p.measuring_seconds,
                p.simulating_seconds
            );
        }
        let (l, m) = (&self.loo, &self.simulated);
        let _ = writeln!(
            s,
            "\n{} rows. Leave-one-out |error|: median {:.1}%, 90th percentile {:.1}%, worst {:.1}% \
             (a plain linear fit: median {:.1}%, 90th percentile {:.1}%). \
             Simulated with the full profile: median {:.1}%, 90th percentile {:.1}%, worst {:.1}%. \
             Measuring took at least {:.2} s of device time; simulating took {:.2} s here.",
            self.rows.len(),
            l.median,
            l.p90,
            l.worst,
            self.linear_loo.median,
            self.linear_loo.p90,
            m.median,
            m.p90,
            m.worst,
            self.measuring_seconds,
            self.simulating_seconds
        );
        if let Some((k, e)) = &self.kfold {
            let _ = writeln!(
                s,
                "\nWhole meshes held out ({k} folds by mesh, each predicted by a fit to the others' meshes: \
                 what a new pass of an unseen mesh is): median {:.1}%, 90th percentile {:.1}%, worst {:.1}%.",
                e.median, e.p90, e.worst
            );
        }
        s
    }
}
