//! `rendersim calibrate` and `rendersim predict`: device profiles fitted to
//! measured passes and passes predicted on them (the library's
//! `measure::calibrate`, `measure::device_profile`, `measure::device_predict`).

use super::progress::say;
use std::fmt::Write as _;
use std::time::Instant;

use anyhow::{Context, Result};
use serde_json::json;

use rendersim::measure::calibrate::{
    CalibrateError, Fit, Invocations, LoadCache, fit, read_rows_with_origins, row_load,
};
use rendersim::measure::cross_validation::{
    MeshFolds, error_summary, held_out_half, k_fold_by_mesh, leave_one_out, leave_one_out_ns, linear_baseline_loo,
};
use rendersim::measure::device_predict::{DevicePass, predict_on_device};
use rendersim::measure::device_profile::{DeviceInfo, DeviceProfile, FitAccuracy, PassLoad, ProfileError};
use rendersim::measure::fit::rel_error_pct;
use rendersim::measure::passes::PassRow;
use rendersim::measure::predictions::predict_rows;

use super::args::{CalibrateArgs, PredictArgs};

/// Today's date (UTC), `YYYY-MM-DD`.
fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    // Howard Hinnant's civil_from_days.
    let z = (secs / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

/// `rendersim calibrate`.
pub fn calibrate(args: &CalibrateArgs) -> Result<()> {
    let (mut rows, mut origins) = (Vec::new(), Vec::new());
    for f in &args.files {
        let (r, o) = read_rows_with_origins(f)?;
        rows.extend(r);
        origins.extend(o);
    }
    let start = Instant::now();
    let mut cache = LoadCache::default();
    // A mesh that cannot be built is reported at the first row naming it.
    cache
        .prefetch(&rows, &args.vertex_cache)
        .map_err(|e| e.at_row(&rows, &origins))?;
    let mut fit_loads = Vec::with_capacity(rows.len());
    let mut predict_loads = Vec::with_capacity(rows.len());
    for r in &rows {
        fit_loads.push(row_load(r, &mut cache, &args.vertex_cache, Invocations::Measured)?);
        predict_loads.push(row_load(r, &mut cache, &args.vertex_cache, Invocations::Predicted)?);
    }
    let y: Vec<f64> = rows.iter().map(|r| r.pass_time_ns).collect();
    // What the fit refuses is the data of every file together: named so.
    let inputs = args
        .files
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let of_inputs = |e: CalibrateError| anyhow::Error::new(e).context(format!("the passes of {inputs}"));
    let f = fit(&fit_loads, &y).map_err(of_inputs)?;
    let undetermined = (!f.undetermined.is_empty()).then(|| {
        format!(
            "these passes do not determine {} (no pass exercises a cost, or it moves with the others): such a \
             cost is whatever the fit left; measure passes that vary it",
            f.undetermined.join(", ")
        )
    });
    if let Some(u) = &undetermined {
        eprintln!("warning: {u}");
    }
    let fit_seconds = start.elapsed().as_secs_f64();
    let fitted: Vec<f64> = fit_loads.iter().map(|l| f.costs.cost(l).pass_ns).collect();
    let errors: Vec<f64> = fitted.iter().zip(&y).map(|(p, m)| rel_error_pct(*p, *m)).collect();
    let (median, p90, worst) = error_summary(&errors);
    let Checks { loo, kfold, half } =
        cross_validate(args, &rows, (&fit_loads, &predict_loads), &y).map_err(of_inputs)?;
    let kfold_summary = kfold.as_ref().map(|k| error_summary(&k.errors));
    let name = args.name.clone().unwrap_or_else(|| {
        args.out
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "device".into())
    });
    let loo_summary = loo.as_ref().map(|(e, b, _)| (error_summary(e), error_summary(b)));
    let profile = DeviceProfile {
        device: DeviceInfo {
            name: name.clone(),
            vertex_cache: args.vertex_cache.to_string(),
            shader_cores: args.shader_cores,
        },
        costs: f.costs,
        uncertainty: f.std_errors.iter().cloned().collect(),
        fit: FitAccuracy {
            rows: rows.len(),
            median_pct: median,
            p90_pct: p90,
            worst_pct: worst,
            loo_median_pct: loo_summary.map(|s| s.0.0),
            loo_p90_pct: loo_summary.map(|s| s.0.1),
            kfold_median_pct: kfold_summary.map(|s| s.0),
            kfold_p90_pct: kfold_summary.map(|s| s.1),
        },
    };
    // What is written must read back: the checks `predict` applies to a
    // profile file, before anything is written.
    if let Err(ProfileError::Invalid { key, value, why }) = profile.validate() {
        return Err(of_inputs(CalibrateError::Profile { key, value, why }));
    }
    let files: Vec<String> = args.files.iter().map(|p| p.display().to_string()).collect();
    let mut header = vec![
        format!(
            "Device profile {name}: fitted by rendersim calibrate (rendersim {}) on {}.",
            env!("CARGO_PKG_VERSION"),
            today()
        ),
        format!("Files: {}.", files.join(", ")),
        format!("Rows: {}. Vertex cache: {}.", rows.len(), args.vertex_cache),
        format!(
            "Fit (relative error over the fitted rows): median {median:.1}%, 90th percentile {p90:.1}%, worst {worst:.1}%."
        ),
    ];
    if let Some(((m, p, w), (bm, bp, _))) = loo_summary {
        header.push(format!(
            "Leave-one-out (each row predicted by a fit to the others, vertex invocations from the cache policy): median {m:.1}%, 90th percentile {p:.1}%, worst {w:.1}%; a plain linear fit: median {bm:.1}%, 90th percentile {bp:.1}%."
        ));
    }
    if let (Some((m, p, w)), Some(k)) = (kfold_summary, &kfold) {
        header.push(format!(
            "K-fold by mesh ({} folds over {} meshes, each fold's meshes held out whole): median {m:.1}%, 90th percentile {p:.1}%, worst {w:.1}%.",
            k.folds, k.meshes
        ));
    }
    if let Some(u) = &undetermined {
        header.push(format!("Not determined: {u}."));
    }
    header.push("Cost formula and keys: docs/models.md (Device profiles). Regenerate with the command in docs/measurements/README.md.".into());
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let text = profile.to_toml(&header);
    rendersim::output::files::write_output(&args.out, |w| w.write_all(text.as_bytes()))?;
    if let Some(path) = &args.report {
        let loo_ns = leave_one_out_ns(&fit_loads, &predict_loads, &y)?;
        let linear = match &loo {
            Some((_, b, _)) => b.clone(),
            None => linear_baseline_loo(&predict_loads, &y),
        };
        let md =
            predict_rows(&profile, &rows, &loo_ns, &linear, kfold.as_ref())?.markdown("`rendersim calibrate --report`");
        rendersim::output::files::write_output(path, |w| w.write_all(md.as_bytes()))?;
    }

    let calibration = Calibration {
        rows: &rows,
        files: &files,
        fit: &f,
        fit_seconds,
        fitted: &fitted,
        errors: &errors,
        summary: (median, p90, worst),
        loo: loo.as_ref(),
        loo_summary,
        kfold: kfold.as_ref().zip(kfold_summary),
        half,
    };
    if args.json {
        let v = calibration_json(&calibration, &profile, &args.out);
        say!("{}", serde_json::to_string_pretty(&v)?);
        return check_holdout(args, half.map(|h| h.0));
    }
    let text = calibration_text(&calibration, &args.out)?;
    super::progress::print_line(text.trim_end_matches('\n'));
    check_holdout(args, half.map(|h| h.0))
}

/// Median, 90th percentile and worst |error|, percent.
type ErrorSummary = (f64, f64, f64);

/// `calibrate --json`: the profile, each row fitted, and the validations
/// asked for (a key only when its option was given, never a null).
fn calibration_json(c: &Calibration, profile: &DeviceProfile, out: &std::path::Path) -> serde_json::Value {
    let rows: Vec<_> = c
        .rows
        .iter()
        .zip(c.fitted)
        .zip(c.errors)
        .enumerate()
        .map(|(i, ((r, p), e))| {
            let mut row = json!({"mesh": r.mesh, "size": format!("{}x{}", r.size.width, r.size.height),
                "vs_loops": r.vs_loops, "fs_loops": r.fs_loops, "geometry_only": r.geometry_only,
                "measured_ns": r.pass_time_ns, "fitted_ns": p, "error_pct": e,
                "loo_error_pct": c.loo.map(|l| l.0[i])});
            if let Some((k, _)) = c.kfold {
                row["kfold_error_pct"] = json!(k.errors[i]);
            }
            row
        })
        .collect();
    let mut v = json!({"profile": profile, "out": out, "fit_seconds": c.fit_seconds,
        "loo_seconds": c.loo.map(|l| l.2),
        "linear_baseline_loo": c.loo_summary.map(|s| json!({"median_pct": s.1.0, "p90_pct": s.1.1, "worst_pct": s.1.2})),
        "held_out_half": c.half.map(|((m, p, w), n)| json!({"rows": n, "median_pct": m, "p90_pct": p, "worst_pct": w})),
        "rows": rows});
    if let Some((k, (m, p, w))) = c.kfold {
        v["kfold_by_mesh"] =
            json!({"folds": k.folds, "meshes": k.meshes, "median_pct": m, "p90_pct": p, "worst_pct": w});
    }
    v
}

/// The cross-validations `calibrate` was asked for.
struct Checks {
    /// Leave-one-out errors, the linear baseline's, and the seconds taken.
    loo: Option<(Vec<f64>, Vec<f64>, f64)>,
    /// K-fold by mesh.
    kfold: Option<MeshFolds>,
    /// The held-out half's summary and its row count.
    half: Option<(ErrorSummary, usize)>,
}

/// `--loo`, `--kfold` and `--holdout` on the rows (`loads`: as fitted, from
/// measured invocations, and as predicted, from the cache policy).
fn cross_validate(
    args: &CalibrateArgs,
    rows: &[PassRow],
    (fit_loads, predict_loads): (&[PassLoad], &[PassLoad]),
    y: &[f64],
) -> Result<Checks, CalibrateError> {
    let loo = if args.loo {
        let t = Instant::now();
        let e = leave_one_out(fit_loads, predict_loads, y)?;
        let b = linear_baseline_loo(predict_loads, y);
        Some((e, b, t.elapsed().as_secs_f64()))
    } else {
        None
    };
    let meshes: Vec<&str> = rows.iter().map(|r| r.mesh.as_str()).collect();
    let kfold = match args.kfold {
        Some(k) => Some(k_fold_by_mesh(fit_loads, predict_loads, y, &meshes, k as usize)?),
        None => None,
    };
    let half = if args.holdout {
        let e = held_out_half(fit_loads, predict_loads, y)?;
        Some((error_summary(&e), e.len()))
    } else {
        None
    };
    Ok(Checks { loo, kfold, half })
}

/// What `calibrate` fitted, for its text report.
struct Calibration<'a> {
    rows: &'a [PassRow],
    files: &'a [String],
    fit: &'a Fit,
    fit_seconds: f64,
    fitted: &'a [f64],
    errors: &'a [f64],
    /// The fit's errors.
    summary: ErrorSummary,
    /// Leave-one-out errors, the linear baseline's, and the seconds taken.
    loo: Option<&'a (Vec<f64>, Vec<f64>, f64)>,
    /// Leave-one-out's errors and the linear baseline's.
    loo_summary: Option<(ErrorSummary, ErrorSummary)>,
    /// K-fold by mesh and its summary.
    kfold: Option<(&'a MeshFolds, ErrorSummary)>,
    /// The held-out half's summary and its row count.
    half: Option<(ErrorSummary, usize)>,
}

/// `calibrate`'s text report: the constants, every row fitted, the error
/// summaries, and where the profile went.
fn calibration_text(c: &Calibration, out: &std::path::Path) -> Result<String, std::fmt::Error> {
    let (median, p90, worst) = c.summary;
    let mut s = String::new();
    writeln!(
        s,
        "{} rows from {}; fit in {:.3} s",
        c.rows.len(),
        c.files.join(", "),
        c.fit_seconds
    )?;
    writeln!(s, "{:<28} {:>14} {:>12}", "constant", "value", "std error")?;
    for (k, v) in c.fit.costs.entries() {
        let se = c
            .fit
            .std_errors
            .iter()
            .find(|(n, _)| n == k)
            .map(|(_, s)| format!("{s:.4e}"))
            .unwrap_or_else(|| "-".into());
        writeln!(s, "{k:<28} {v:>14.6e} {se:>12}")?;
    }
    writeln!(
        s,
        "\n{:<24} {:>9} {:>6} {:>6} {:>4} {:>14} {:>14} {:>8}{}",
        "mesh",
        "size",
        "vs",
        "fs",
        "geo",
        "measured ns",
        "fitted ns",
        "err %",
        if c.loo.is_some() { "   loo %" } else { "" }
    )?;
    for (i, ((r, p), e)) in c.rows.iter().zip(c.fitted).zip(c.errors).enumerate() {
        let l = c.loo.map(|l| format!(" {:>7.1}", l.0[i])).unwrap_or_default();
        writeln!(
            s,
            "{:<24} {:>9} {:>6} {:>6} {:>4} {:>14.0} {:>14.0} {:>8.1}{l}",
            r.mesh,
            format!("{}x{}", r.size.width, r.size.height),
            r.vs_loops,
            r.fs_loops,
            if r.geometry_only { "yes" } else { "" },
            r.pass_time_ns,
            p,
            e
        )?;
    }
    writeln!(
        s,
        "\nfit |error|: median {median:.1}%, p90 {p90:.1}%, worst {worst:.1}%"
    )?;
    if let (Some(((m, p, w), (bm, bp, bw))), Some(l)) = (c.loo_summary, c.loo) {
        writeln!(
            s,
            "leave-one-out |error|: median {m:.1}%, p90 {p:.1}%, worst {w:.1}% ({:.2} s)",
            l.2
        )?;
        writeln!(
            s,
            "linear baseline leave-one-out: median {bm:.1}%, p90 {bp:.1}%, worst {bw:.1}%"
        )?;
    }
    if let Some((k, (m, p, w))) = c.kfold {
        writeln!(
            s,
            "k-fold by mesh ({} folds over {} meshes, each fold's meshes held out whole) |error|: median {m:.1}%, p90 {p:.1}%, worst {w:.1}%",
            k.folds, k.meshes
        )?;
    }
    if let Some(((m, p, w), n)) = c.half {
        writeln!(
            s,
            "held-out half (fit on a fixed pseudo-random half, the other {n} rows predicted) |error|: median {m:.1}%, p90 {p:.1}%, worst {w:.1}%"
        )?;
    }
    writeln!(s, "wrote {}", out.display())?;
    Ok(s)
}

/// `--holdout-max-median` and `--holdout-max-p90`: the held-out half's
/// median and 90th percentile |error| (`half`: median, p90, worst) against
/// their bounds; both are named when both are exceeded.
fn check_holdout(args: &CalibrateArgs, half: Option<(f64, f64, f64)>) -> Result<()> {
    let Some((median, p90, _)) = half else {
        return Ok(());
    };
    let over = |bound: Option<f64>, v: f64, what: &str, flag: &str| match bound {
        Some(b) if v > b || v.is_nan() => Some(format!("{what} |error| {v:.1}% exceeds {flag} {b}%")),
        _ => None,
    };
    let failed: Vec<String> = [
        over(args.holdout_max_median, median, "median", "--holdout-max-median"),
        over(args.holdout_max_p90, p90, "90th percentile", "--holdout-max-p90"),
    ]
    .into_iter()
    .flatten()
    .collect();
    if failed.is_empty() {
        return Ok(());
    }
    Err(HoldoutFailed {
        what: failed.join("; "),
        out: args.out.display().to_string(),
    }
    .into())
}

/// The held-out half missed a bound `calibrate` was given (exit status 1,
/// as for an experiment's failed checks; the profile is written).
#[derive(Debug, thiserror::Error)]
#[error("held-out half: {what} (profile written to {out})")]
pub struct HoldoutFailed {
    what: String,
    out: String,
}

/// `rendersim predict`.
pub fn predict(args: &PredictArgs) -> Result<()> {
    let profile = DeviceProfile::read(&args.device)?;
    let pass = DevicePass {
        mesh: args.mesh.clone(),
        size: (args.size.width, args.size.height),
        vs_loops: args.vs_loops,
        fs_loops: args.fs_loops,
        geometry_only: args.geometry_only,
        layers: args.layers,
        order: args.order.into(),
        depth_test: args.depth_test,
        draws: args.draws,
    };
    let p = predict_on_device(&profile, &pass)?;
    let measured = if args.measure { Some(measure_pass(args)?) } else { None };
    // The comparison: measured pass time and wall time of measuring
    // (opening the adapter, warm-ups, repeats) against the simulation's.
    // A profile of another device predicts that device, not this one: the
    // error then compares two devices, and says so.
    let other_device = measured
        .as_ref()
        .filter(|(_, _, adapter)| !profile.device.matches_adapter(adapter))
        .map(|(_, _, adapter)| {
            format!(
                "the profile {} is for the device `{}`, and the pass was measured on `{adapter}`: the error compares \
                 two devices; calibrate a profile for this adapter (`rendersim calibrate`) to predict it",
                args.device.display(),
                profile.device.name
            )
        });
    if let Some(w) = &other_device {
        eprintln!("warning: {w}");
    }
    let comparison = measured.as_ref().map(|(ns, wall, adapter)| {
        json!({"adapter": adapter, "pass_time_ns": ns, "error_pct": rel_error_pct(p.pass_time_ns, *ns),
            "measure_wall_seconds": wall, "simulate_wall_seconds": p.sim_wall_seconds,
            "speedup": wall / p.sim_wall_seconds.max(1e-9),
            "same_device": other_device.is_none(), "warning": other_device})
    });
    if args.json {
        let v = json!({
            "mesh": args.mesh, "device": args.device, "device_name": profile.device.name,
            "size": format!("{}x{}", args.size.width, args.size.height),
            "vs_loops": args.vs_loops, "fs_loops": args.fs_loops, "geometry_only": args.geometry_only,
            "layers": args.layers, "depth_test": args.depth_test,
            "predicted": p, "wall_seconds": p.sim_wall_seconds, "measured": comparison,
        });
        say!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        say!(
            "{} on {} at {}x{}: {:.4} ms predicted ({} vertex-shader, {} fragment-shader invocations; simulated in {:.3} s)",
            args.mesh,
            profile.device.name,
            args.size.width,
            args.size.height,
            p.pass_time_ns / 1e6,
            p.vs_invocations,
            p.fs_invocations,
            p.sim_wall_seconds
        );
        if let Some((ns, wall, adapter)) = &measured {
            say!(
                "measured on {adapter}: {:.4} ms (prediction {:+.1}%); measuring took {wall:.3} s, simulating {:.3} s: {:.1}x faster",
                ns / 1e6,
                rel_error_pct(p.pass_time_ns, *ns),
                p.sim_wall_seconds,
                wall / p.sim_wall_seconds.max(1e-9)
            );
        }
    }
    Ok(())
}

/// `predict --measure`: the pass measured on this machine's adapter:
/// (median pass time ns, wall seconds of the whole measurement, adapter).
#[cfg(feature = "wgpu")]
fn measure_pass(args: &PredictArgs) -> Result<(f64, f64, String)> {
    let m = rendersim::scene::generators::mesh_from_spec(&args.mesh, std::path::Path::new("."))?;
    let opts = rendersim::measure::MeasureOptions {
        vs_loops: args.vs_loops,
        fs_loops: args.fs_loops,
        depth_test: args.depth_test,
        layers: args.layers,
        order: args.order.into(),
        size: (args.size.width, args.size.height),
        repeats: args.repeats,
        geometry_only: args.geometry_only,
        draws: args.draws,
        ..Default::default()
    };
    let start = Instant::now();
    let r = rendersim::measure::measure(&m, &args.mesh, &opts)?;
    Ok((r.pass_time_ns, start.elapsed().as_secs_f64(), r.adapter.name))
}

/// `predict --measure` without the `wgpu` feature.
#[cfg(not(feature = "wgpu"))]
fn measure_pass(_args: &PredictArgs) -> Result<(f64, f64, String)> {
    anyhow::bail!("--measure needs a rendersim built with `--features wgpu`")
}
