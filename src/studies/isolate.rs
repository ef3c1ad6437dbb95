//! Bottleneck isolation as paper 004 §4.1 teaches: reduce one subsystem's
//! load at a time (CPU work; the GPU front end's command processing: per
//! command, per state change, clear and swap; geometry work per vertex and
//! triangle; raster work per fragment) and see which reduction moves the
//! frame time. Vsync is switched off by default, as §4.2 advises, so refresh
//! quantization does not hide a change.
//!
//! The verdict: a reduction counts when it moves the mean frame time down by
//! more than [`MIN_CHANGE`] (1%); the one that moves it most is the
//! bottleneck, unless others come within the tie tolerance of it (by
//! default [`DEFAULT_TIE_TOLERANCE`]: reductions within 2% of the best
//! frame-time reduction, relative to it) — then the result is a tie listing
//! them all, since one run cannot tell them apart (two stages in series,
//! say, with equal loads).
//!
//! The variants run in parallel, at `draw` fidelity by default (the closed
//! form per draw call; [`IsolateOptions::default`] says why), or at the
//! model's own or `triangle` fidelity when asked.

use std::path::Path;

use crate::components::distribution::Dist;
use crate::engine::Duration;

use crate::systems::error::SystemError;
use crate::systems::frame_pipeline::config::{Fidelity, FramePipelineConfig, StateCosts, WorkloadConfig};
use crate::systems::frame_pipeline::run::run_pipeline;

/// One variant's result.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Variant {
    /// `baseline`, `cpu`, `front_end`, `geometry`, `raster` (scenes);
    /// `baseline`, `cpu`, `front_end`, `gpu` (fixed workloads).
    pub name: String,
    /// Mean frame time (ms).
    pub frame_time_ms: f64,
    /// Mean display interval (ms).
    pub display_interval_ms: f64,
    /// Relative change of the frame time against the baseline.
    pub change: f64,
}

/// The isolation report.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Isolation {
    /// Load factor applied to the reduced subsystem.
    pub factor: f64,
    /// Whether vsync stayed on.
    pub vsync: bool,
    /// Baseline and the reductions.
    pub variants: Vec<Variant>,
    /// The subsystem whose reduction moved the frame time most; `tie` when
    /// several are tied (see `tied`); `none` if no reduction moved it by
    /// more than 1%.
    pub bottleneck: String,
    /// Every subsystem whose reduction came within the tie tolerance of the
    /// best (the bottleneck alone when there is no tie; empty for `none`).
    pub tied: Vec<String>,
    /// Reductions of the frame time within this fraction of the best
    /// reduction are tied.
    pub tie_tolerance: f64,
    /// The fidelity the variants ran at (`triangle` or `draw`).
    pub fidelity: String,
    /// Frames each variant simulated (warm-up included).
    pub frames: u64,
    /// Set when the model's run was too short to judge from: that it was
    /// lengthened, or (a `frames` workload) that it could not be.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// Wall time of all runs, seconds.
    pub wall_seconds: f64,
}

/// A reduction must lower the mean frame time by more than this fraction
/// to count.
pub const MIN_CHANGE: f64 = 0.01;
/// The default tie tolerance: reductions within 2% of the best one are tied.
pub const DEFAULT_TIE_TOLERANCE: f64 = 0.02;

/// How to isolate.
#[derive(Debug, Clone, Copy)]
pub struct IsolateOptions {
    /// Load factor of the reduced subsystem, in (0, 1).
    pub factor: f64,
    /// Keep vsync on.
    pub keep_vsync: bool,
    /// Reductions within this fraction of the best reduction are tied, in [0, 1).
    pub tie_tolerance: f64,
    /// The fidelity to run the variants at; `None`: the model's own.
    pub fidelity: Option<Fidelity>,
}

impl Default for IsolateOptions {
    /// Factor 0.5, vsync off, the default tie tolerance, at `draw`
    /// fidelity: on every shipped frame-pipeline model `draw` gives the
    /// verdict `triangle` gives, with frame-time changes within 0.002, in
    /// a small fraction of the time (the default model: 0.03 s against
    /// 7.5 s; `models/single-view.toml`: 0.2 s against 269 s).
    fn default() -> Self {
        IsolateOptions {
            factor: 0.5,
            keep_vsync: false,
            tie_tolerance: DEFAULT_TIE_TOLERANCE,
            fidelity: Some(Fidelity::Draw),
        }
    }
}

fn scale(d: Duration, k: f64) -> Duration {
    Duration::from_ps_f64(d.0 as f64 * k)
}

fn scale_states(s: &mut StateCosts, k: f64) {
    for d in [
        &mut s.shader,
        &mut s.texture,
        &mut s.material,
        &mut s.matrix,
        &mut s.alpha,
    ] {
        *d = scale(*d, k);
    }
}

fn scale_dist(d: &Dist<Duration>, k: f64) -> Dist<Duration> {
    d.scaled_as(k)
}

/// The model with one subsystem's load multiplied by `k`.
pub fn reduced(cfg: &FramePipelineConfig, which: &str, k: f64) -> FramePipelineConfig {
    let mut c = cfg.clone();
    match which {
        "cpu" => {
            let p = &mut c.cpu;
            p.input_sampling = scale(p.input_sampling, k);
            p.non_render = scale_dist(&p.non_render, k);
            p.per_object = scale(p.per_object, k);
            p.per_draw = scale(p.per_draw, k);
            p.sort_per_draw = scale(p.sort_per_draw, k);
            p.clear = scale(p.clear, k);
            p.swap = scale(p.swap, k);
            scale_states(&mut p.state_change, k);
            match &mut c.workload {
                WorkloadConfig::Fixed(f) => f.cpu = scale_dist(&f.cpu, k),
                WorkloadConfig::Frames(f) => {
                    for d in f.cpu.iter_mut().chain(f.submit.iter_mut()).chain(f.present.iter_mut()) {
                        *d = scale(*d, k);
                    }
                }
                WorkloadConfig::Scene(_) => {}
            }
        }
        "front_end" => {
            // Everything the front end executes itself (the clear and swap
            // run there in this model, see docs/models.md).
            let g = &mut c.gpu;
            g.command = scale(g.command, k);
            g.clear = scale(g.clear, k);
            g.swap = scale(g.swap, k);
            scale_states(&mut g.state_change, k);
        }
        "geometry" => {
            let g = &mut c.gpu.geometry;
            g.index_fetch = scale(g.index_fetch, k);
            g.vertex_shader = scale(g.vertex_shader, k);
            g.triangle_setup = scale(g.triangle_setup, k);
        }
        "raster" => {
            let f = &mut c.gpu.fragment;
            f.per_fragment = scale(f.per_fragment, k);
            f.per_rejected_fragment = scale(f.per_rejected_fragment, k);
        }
        "gpu" => match &mut c.workload {
            WorkloadConfig::Fixed(f) => f.gpu = scale_dist(&f.gpu, k),
            WorkloadConfig::Frames(f) => {
                for d in f.gpu.iter_mut() {
                    *d = scale(*d, k);
                }
            }
            WorkloadConfig::Scene(_) => {}
        },
        _ => {}
    }
    c
}

/// The verdict over the reductions (`variants` without the baseline):
/// (bottleneck, tied subsystems), see the module docs.
pub fn verdict(reductions: &[Variant], tie_tolerance: f64) -> (String, Vec<String>) {
    let best = reductions
        .iter()
        .map(|v| v.change)
        .filter(|c| *c < -MIN_CHANGE)
        .min_by(f64::total_cmp);
    let Some(best) = best else {
        return ("none".to_string(), Vec::new());
    };
    let tied: Vec<String> = reductions
        .iter()
        .filter(|v| v.change < -MIN_CHANGE && v.change - best <= tie_tolerance * best.abs())
        .map(|v| v.name.clone())
        .collect();
    let bottleneck = match tied.as_slice() {
        [one] => one.clone(),
        _ => "tie".to_string(),
    };
    (bottleneck, tied)
}

fn check_options(o: &IsolateOptions) -> Result<(), SystemError> {
    if !(o.factor.is_finite() && o.factor > 0.0 && o.factor < 1.0) {
        return Err(SystemError::Invalid {
            key: "--factor".into(),
            message: format!("must be between 0 and 1 (exclusive), got {}", o.factor),
        });
    }
    if !(o.tie_tolerance.is_finite() && (0.0..1.0).contains(&o.tie_tolerance)) {
        return Err(SystemError::Invalid {
            key: "--tie-tolerance".into(),
            message: format!("must be at least 0 and less than 1, got {}", o.tie_tolerance),
        });
    }
    Ok(())
}

/// Runs the baseline and each reduction.
pub fn isolate(cfg: &FramePipelineConfig, base_dir: &Path, options: IsolateOptions) -> Result<Isolation, SystemError> {
    check_options(&options)?;
    let IsolateOptions {
        factor,
        keep_vsync,
        tie_tolerance,
        fidelity,
    } = options;
    let start = std::time::Instant::now();
    let mut base = cfg.clone();
    if let Some(f) = fidelity {
        base.fidelity = f;
    }
    // A variable-refresh panel does not quantise frames within its range,
    // and it needs vsync: it keeps it.
    let keep_vsync = keep_vsync || base.display.vrr.is_some();
    if !keep_vsync {
        base.display.vsync = false;
    }
    let note = lengthen_to_steady_state(&mut base);
    let names: &[&str] = match base.workload {
        WorkloadConfig::Fixed(_) | WorkloadConfig::Frames(_) => &["baseline", "cpu", "front_end", "gpu"],
        WorkloadConfig::Scene(_) => &["baseline", "cpu", "front_end", "geometry", "raster"],
    };
    // The variants are independent runs: all at once, on as many cores as
    // there are (each run is deterministic, so the order does not matter).
    use rayon::prelude::*;
    let runs: Vec<(f64, f64)> = names
        .par_iter()
        .map(|name| {
            let c = if *name == "baseline" {
                base.clone()
            } else {
                reduced(&base, name, factor)
            };
            let r = run_pipeline(c, base_dir, None)?;
            let m = &r.results.metrics;
            Ok((
                m.frame_time_ms.mean.unwrap_or(0.0),
                m.display_interval_ms.mean.unwrap_or(0.0),
            ))
        })
        .collect::<Result<_, SystemError>>()?;
    let base_ft = runs[0].0;
    let variants: Vec<Variant> = names
        .iter()
        .zip(&runs)
        .map(|(name, &(ft, interval))| Variant {
            name: name.to_string(),
            frame_time_ms: ft,
            display_interval_ms: interval,
            change: if base_ft > 0.0 { (ft - base_ft) / base_ft } else { 0.0 },
        })
        .collect();
    let (bottleneck, tied) = verdict(&variants[1..], tie_tolerance);
    Ok(Isolation {
        factor,
        vsync: keep_vsync,
        variants,
        bottleneck,
        tied,
        tie_tolerance,
        fidelity: match base.fidelity {
            Fidelity::Triangle => "triangle",
            Fidelity::Draw => "draw",
        }
        .to_string(),
        frames: base.run.frames,
        note,
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}

/// Measured frames (after the warm-up) a verdict needs: the CPU may run
/// `max_frames_ahead` frames ahead before it waits for a slow GPU, so
/// fewer frames measure the pipeline filling, not its steady state (a
/// GPU-bound model of one measured frame looks CPU-bound).
pub fn steady_frames(cfg: &FramePipelineConfig) -> u64 {
    u64::from(cfg.cpu.max_frames_ahead) + 1
}

/// Lengthens `cfg`'s run to [`steady_frames`] measured frames when it is
/// shorter (a run bounded by `run.until` is left as it is; a `frames`
/// workload, whose lists fix its length, only gets the warning), and says
/// so.
fn lengthen_to_steady_state(cfg: &mut FramePipelineConfig) -> Option<String> {
    let need = steady_frames(cfg);
    let measured = cfg.run.frames.saturating_sub(cfg.run.warmup_frames);
    if measured >= need || cfg.run.until.is_some() {
        return None;
    }
    if matches!(cfg.workload, WorkloadConfig::Frames(_)) {
        // One value per frame in its lists: a replay cannot run longer.
        return Some(format!(
            "only {measured} measured frame(s) after the warm-up, and a `kind = \"frames\"` workload cannot run \
             longer than its lists: the verdict may show the pipeline filling (the CPU runs up to {} frames ahead), \
             not its steady state",
            cfg.cpu.max_frames_ahead
        ));
    }
    let from = cfg.run.frames;
    cfg.run.frames = cfg.run.warmup_frames + need;
    Some(format!(
        "run.frames raised from {from} to {} for every variant: {measured} measured frame(s) after the warm-up \
         show the pipeline filling (the CPU runs up to {} frames ahead), not its steady state",
        cfg.run.frames, cfg.cpu.max_frames_ahead
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reductions(changes: &[(&str, f64)]) -> Vec<Variant> {
        changes
            .iter()
            .map(|(n, c)| Variant {
                name: n.to_string(),
                frame_time_ms: 10.0 * (1.0 + c),
                display_interval_ms: 0.0,
                change: *c,
            })
            .collect()
    }

    #[test]
    fn one_winner_a_tie_or_none() {
        let v = reductions(&[("cpu", -0.40), ("front_end", 0.0), ("geometry", -0.05)]);
        assert_eq!(verdict(&v, 0.02), ("cpu".into(), vec!["cpu".into()]));
        // -0.395 is within 2% of -0.40 (0.008); -0.39 is not.
        let v = reductions(&[("cpu", -0.40), ("geometry", -0.395), ("raster", -0.39)]);
        assert_eq!(verdict(&v, 0.02), ("tie".into(), vec!["cpu".into(), "geometry".into()]));
        assert_eq!(verdict(&v, 0.0).0, "cpu");
        assert_eq!(verdict(&v, 0.05).1.len(), 3);
        // Changes of 1% or less do not count, tied or not.
        let v = reductions(&[("cpu", -0.01), ("raster", -0.005), ("geometry", 0.02)]);
        assert_eq!(verdict(&v, 0.5), ("none".into(), vec![]));
    }
}
