//! What a frame-pipeline model is refused for before it runs: values serde
//! cannot check (ranges, distributions, scene sizes), the memory its
//! results would take (`run.max_memory`), and expected per-frame terms
//! that are not finite or would carry the clock past its range.

use crate::components::swap_chain::PresentMode;
use crate::engine::PS_PER_MS;

use super::config::{FramePipelineConfig, WorkloadConfig};
use super::records::FrameRecord;
use super::summary::AnalyticTerms;
use crate::systems::error::{SystemError, invalid as bad};

/// Checks values serde cannot (ranges, distributions).
pub fn validate(cfg: &FramePipelineConfig) -> Result<(), SystemError> {
    if cfg.system != "frame_pipeline" {
        return Err(bad(
            "system",
            format!("expected \"frame_pipeline\", got {:?}", cfg.system),
        ));
    }
    if cfg.display.refresh.period.0 < crate::limits::MIN_REFRESH_PERIOD_PS {
        return Err(bad(
            "display.refresh",
            format!(
                "a refresh period of {} is shorter than the limit of 1us (1 MHz): every refresh is an event",
                cfg.display.refresh.period
            ),
        ));
    }
    if !(2..=16).contains(&cfg.display.buffers) {
        return Err(bad(
            "display.buffers",
            format!(
                "must be between 2 and 16 swap-chain images, got {}",
                cfg.display.buffers
            ),
        ));
    }
    cfg.gpu
        .check_architecture()
        .map_err(|(key, message)| bad(key, message))?;
    if cfg.cpu.max_frames_ahead == 0 {
        return Err(bad(
            "cpu.max_frames_ahead",
            "must be at least 1 (the frame being submitted)",
        ));
    }
    if cfg.run.frames > 0 && cfg.run.warmup_frames >= cfg.run.frames {
        return Err(bad(
            "run.warmup_frames|run.frames",
            format!(
                "run.warmup_frames ({}) must be less than run.frames ({})",
                cfg.run.warmup_frames, cfg.run.frames
            ),
        ));
    }
    cfg.cpu
        .non_render
        .validate()
        .map_err(|e| bad("cpu.non_render", e.to_string()))?;
    if let WorkloadConfig::Fixed(f) = &cfg.workload {
        f.cpu.validate().map_err(|e| bad("workload.cpu", e.to_string()))?;
        f.gpu.validate().map_err(|e| bad("workload.gpu", e.to_string()))?;
    }
    for (i, p) in cfg.noise.periodic.iter().enumerate() {
        p.duration
            .validate()
            .map_err(|e| bad(&format!("noise.periodic.{i}.duration"), e.to_string()))?;
        if p.period.0 == 0 {
            return Err(bad(&format!("noise.periodic.{i}.period"), "must be greater than zero"));
        }
    }
    for (i, r) in cfg.noise.random.iter().enumerate() {
        r.duration
            .validate()
            .map_err(|e| bad(&format!("noise.random.{i}.duration"), e.to_string()))?;
    }
    for (key, d) in [
        ("variation.cpu", &cfg.variation.cpu),
        ("variation.gpu", &cfg.variation.gpu),
    ] {
        if let Some(d) = d {
            d.validate().map_err(|e| bad(key, e.to_string()))?;
        }
    }
    if let WorkloadConfig::Scene(sc) = &cfg.workload {
        check_scene_sizes(sc)?;
    }
    Ok(())
}

/// Checks a scene's object counts and scale against [`crate::limits`]
/// before anything is compiled or allocated.
fn check_scene_sizes(sc: &crate::scene::config::SceneWorkload) -> Result<(), SystemError> {
    use crate::limits::{MAX_SCENE_OBJECTS, MAX_SCENE_SCALE};
    if sc.scale.is_finite() && sc.scale > MAX_SCENE_SCALE {
        return Err(bad(
            "workload.scale",
            format!(
                "{:?} is more than the limit of {MAX_SCENE_SCALE:?} (times the paper's scene)",
                sc.scale
            ),
        ));
    }
    let mut total = 0u64;
    if let Some(p) = &sc.preset
        && sc.scale.is_finite()
        && sc.scale > 0.0
        && let Some(groups) = crate::scene::presets::preset_groups(p, sc.scale)
    {
        total = groups.iter().fold(0u64, |t, g| t.saturating_add(g.count));
    }
    for (i, g) in sc.groups.iter().enumerate() {
        if g.count > MAX_SCENE_OBJECTS {
            return Err(bad(
                &format!("workload.groups.{i}.count"),
                format!(
                    "{} objects is more than the limit of {MAX_SCENE_OBJECTS} per scene",
                    g.count
                ),
            ));
        }
        total = total.saturating_add(g.count);
        if total > MAX_SCENE_OBJECTS {
            return Err(bad(
                &format!("workload.groups.{i}.count"),
                format!(
                    "the scene has {total} objects up to this group, more than the limit of {MAX_SCENE_OBJECTS} per scene"
                ),
            ));
        }
    }
    if total > MAX_SCENE_OBJECTS {
        return Err(bad(
            "workload.scale",
            format!(
                "preset {:?} at scale {} has {total} objects, more than the limit of {MAX_SCENE_OBJECTS} per scene",
                sc.preset.as_deref().unwrap_or(""),
                sc.scale
            ),
        ));
    }
    Ok(())
}

/// Bytes a frame's results take: its record, its table row and the metric
/// columns built from it.
const BYTES_PER_FRAME: usize = std::mem::size_of::<FrameRecord>() + 14 * 8 + 8 * 8;

/// Estimates the memory a run needs from its inputs, before simulating:
/// per-frame records, the scene's draws and generated index buffers (a
/// trace takes none: it streams to its file). Returns the bytes and a
/// description of the terms.
pub fn estimate_memory(cfg: &FramePipelineConfig) -> (u64, String) {
    use crate::limits::{add_bytes, show_bytes};
    let mut parts = Vec::new();
    let mut total = 0u64;
    let mut frames_bytes = 0u64;
    add_bytes(&mut frames_bytes, cfg.run.frames, BYTES_PER_FRAME);
    total = total.saturating_add(frames_bytes);
    parts.push(format!(
        "{} frames x {BYTES_PER_FRAME} bytes = {}",
        cfg.run.frames,
        show_bytes(frames_bytes)
    ));
    if let WorkloadConfig::Scene(sc) = &cfg.workload {
        let mut objects: u64 = sc.groups.iter().fold(0, |t, g| t.saturating_add(g.count));
        if let Some(p) = &sc.preset
            && sc.scale.is_finite()
            && sc.scale > 0.0
            && let Some(groups) = crate::scene::presets::preset_groups(p, sc.scale)
        {
            objects = groups.iter().fold(objects, |t, g| t.saturating_add(g.count));
        }
        let per_object = std::mem::size_of::<super::workload::DrawItem>() + 48;
        let mut b = 0u64;
        add_bytes(&mut b, objects, per_object);
        total = total.saturating_add(b);
        parts.push(format!("{objects} objects x {per_object} bytes = {}", show_bytes(b)));
        // A generated mesh: its 4-byte indices, a per-triangle count, and
        // the reordering's temporaries (about 4 more words per index).
        let mut mesh = 0u64;
        for g in &sc.groups {
            if let crate::scene::config::MeshRef::Spec(spec) = &g.mesh
                && let Some(n) = crate::scene::generators::spec_index_count(spec)
                && n <= crate::limits::MAX_MESH_INDICES
            {
                let per_index = if spec.contains("optimized") || spec.contains("shuffled") || spec.contains("local") {
                    20
                } else {
                    6
                };
                add_bytes(&mut mesh, n, per_index);
            }
        }
        if mesh > 0 {
            total = total.saturating_add(mesh);
            parts.push(format!("generated meshes {}", show_bytes(mesh)));
        }
    }
    (total, parts.join(", "))
}

/// Fails with an error naming `run.max_memory` when the estimate exceeds it.
pub(super) fn check_memory(cfg: &FramePipelineConfig) -> Result<(), SystemError> {
    let limit = cfg.run.max_memory.map_or(crate::limits::DEFAULT_MAX_MEMORY, |b| b.0);
    let (estimate, parts) = estimate_memory(cfg);
    if estimate > limit {
        return Err(bad(
            "run.max_memory",
            crate::limits::over_memory_message(estimate, &parts, limit),
        ));
    }
    Ok(())
}

/// Refuses, before simulating, expected per-frame terms that are not finite
/// numbers (naming the distribution), and a run whose simulated time certainly passes
/// the clock's range (`u64` picoseconds, about 213 days): `run.frames`
/// frames take at least the largest expected per-frame term each (the
/// units work in parallel, the slowest one bounds the frame rate; with a
/// vsynced FIFO swap chain a frame also takes at least a refresh). Such a
/// run would otherwise simulate, possibly for a long time (every refresh
/// of a vsynced display is an event), before failing at the overflow. Runs
/// with `run.until` or `run.max_events` may stop earlier and are left to the
/// clock's own checks.
pub(super) fn check_time_range(cfg: &FramePipelineConfig, a: &AnalyticTerms) -> Result<(), SystemError> {
    let (cpu_key, gpu_key) = match &cfg.workload {
        WorkloadConfig::Fixed(_) => ("workload.cpu", "workload.gpu"),
        WorkloadConfig::Scene(_) => ("workload", "workload"),
    };
    // An expected term that is not a finite number (a distribution whose
    // mean overflows or does not exist) would be written as null.
    for (value, is_cpu, what) in [
        (a.cpu_ms, true, "CPU time"),
        (a.gpu_front_end_ms, false, "GPU front-end time"),
        (a.geometry_ms, false, "geometry time"),
        (a.fragment_ms, false, "fragment time"),
    ] {
        if value.is_finite() {
            continue;
        }
        let mut keys = vec![];
        if !cfg.cpu.non_render.mean().is_finite() {
            keys.push("cpu.non_render".to_string());
        }
        match &cfg.workload {
            WorkloadConfig::Fixed(f) => {
                if !f.cpu.mean().is_finite() {
                    keys.push("workload.cpu".into());
                }
                if !f.gpu.mean().is_finite() {
                    keys.push("workload.gpu".into());
                }
            }
            WorkloadConfig::Scene(sc) => keys.extend(
                sc.groups
                    .iter()
                    .enumerate()
                    .filter(|(_, g)| !g.triangle_pixels.mean().is_finite())
                    .map(|(i, _)| format!("workload.groups.{i}.triangle_pixels")),
            ),
        }
        if keys.is_empty() {
            keys.push(if is_cpu { cpu_key } else { gpu_key }.to_string());
        }
        return Err(bad(
            &keys.join("|"),
            format!(
                "the expected {what} per frame is not a finite number: the mean of {} overflows or does not exist",
                keys.join(", ")
            ),
        ));
    }
    if cfg.run.until.is_some() || cfg.run.max_events.is_some() {
        return Ok(());
    }
    // (Every term is finite here: the loop above returned otherwise.)
    let term = |ms: f64| ms * PS_PER_MS as f64;
    let mut terms = vec![
        ("CPU work", cpu_key, term(a.cpu_ms)),
        ("GPU front end work", gpu_key, term(a.gpu_front_end_ms)),
        ("geometry work", gpu_key, term(a.geometry_ms)),
        ("fragment work", gpu_key, term(a.fragment_ms)),
    ];
    // A vsynced FIFO swap chain shows every frame for at least one refresh.
    if cfg.display.vsync && cfg.display.present_mode == PresentMode::Fifo {
        terms.push((
            "display refresh",
            "display.refresh",
            cfg.display.refresh.period.0 as f64,
        ));
    }
    let (what, source, per_frame) = terms.into_iter().max_by(|a, b| a.2.total_cmp(&b.2)).expect("terms");
    let total = per_frame * cfg.run.frames as f64;
    if total < u64::MAX as f64 {
        return Ok(());
    }
    Err(bad(
        &format!("{source}|run.frames"),
        format!(
            "run.frames = {} frames of at least {} s each ({what}, {source}) need about {:.3e} s of simulated time: \
             the simulated clock would overflow (64-bit picoseconds, about 213 days); lower {source} or run.frames, or set run.until",
            cfg.run.frames,
            per_frame / PS_PER_MS as f64 / 1000.0,
            total / PS_PER_MS as f64 / 1000.0,
        ),
    ))
}
