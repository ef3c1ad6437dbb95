//! Bottleneck isolation as paper 004 §4.1 teaches: reduce one subsystem's
//! load at a time (CPU work; the GPU front end's command processing: per
//! command, per state change, clear and swap; geometry work per vertex and
//! triangle; raster work per fragment) and see which reduction moves the
//! frame time. Vsync is switched off by default, as §4.2 advises, so refresh
//! quantization does not hide a change.

use std::path::Path;

use crate::components::distribution::Dist;
use crate::engine::Duration;

use super::config::{FramePipelineConfig, StateCosts, WorkloadConfig};
use super::run::run_pipeline;
use crate::systems::error::SystemError;

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
    /// The subsystem whose reduction moved the frame time most (`none` if
    /// no reduction moved it by more than 1%).
    pub bottleneck: String,
    /// Wall time of all runs, seconds.
    pub wall_seconds: f64,
}

fn scale(d: Duration, k: f64) -> Duration {
    Duration::from_ps_f64(d.0 as f64 * k)
}

fn scale_states(s: &mut StateCosts, k: f64) {
    for d in [&mut s.shader, &mut s.texture, &mut s.material, &mut s.matrix] {
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
            p.clear = scale(p.clear, k);
            p.swap = scale(p.swap, k);
            scale_states(&mut p.state_change, k);
            if let WorkloadConfig::Fixed(f) = &mut c.workload {
                f.cpu = scale_dist(&f.cpu, k);
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
        "gpu" => {
            if let WorkloadConfig::Fixed(f) = &mut c.workload {
                f.gpu = scale_dist(&f.gpu, k);
            }
        }
        _ => {}
    }
    c
}

/// Runs the baseline and each reduction.
pub fn isolate(
    cfg: &FramePipelineConfig,
    base_dir: &Path,
    factor: f64,
    keep_vsync: bool,
) -> Result<Isolation, SystemError> {
    if !(factor.is_finite() && factor > 0.0 && factor < 1.0) {
        return Err(SystemError::Invalid {
            key: "--factor".into(),
            message: format!("must be between 0 and 1 (exclusive), got {factor}"),
        });
    }
    let start = std::time::Instant::now();
    let mut base = cfg.clone();
    if !keep_vsync {
        base.display.vsync = false;
    }
    let names: &[&str] = match base.workload {
        WorkloadConfig::Fixed(_) => &["baseline", "cpu", "front_end", "gpu"],
        WorkloadConfig::Scene(_) => &["baseline", "cpu", "front_end", "geometry", "raster"],
    };
    let mut variants = Vec::new();
    let mut base_ft = 0.0;
    for name in names {
        let c = if *name == "baseline" {
            base.clone()
        } else {
            reduced(&base, name, factor)
        };
        let r = run_pipeline(c, base_dir, None)?;
        let m = &r.summary["metrics"];
        let ft = m["frame_time_ms"]["mean"].as_f64().unwrap_or(0.0);
        if *name == "baseline" {
            base_ft = ft;
        }
        variants.push(Variant {
            name: name.to_string(),
            frame_time_ms: ft,
            display_interval_ms: m["display_interval_ms"]["mean"].as_f64().unwrap_or(0.0),
            change: if base_ft > 0.0 { (ft - base_ft) / base_ft } else { 0.0 },
        });
    }
    let best = variants.iter().skip(1).min_by(|a, b| a.change.total_cmp(&b.change));
    let bottleneck = match best {
        Some(v) if v.change < -0.01 => v.name.clone(),
        _ => "none".to_string(),
    };
    Ok(Isolation {
        factor,
        vsync: keep_vsync,
        variants,
        bottleneck,
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}
