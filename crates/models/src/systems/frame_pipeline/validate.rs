//! What a frame-pipeline model is refused for before it runs: values serde
//! cannot check (ranges, distributions, scene sizes), the memory its
//! results would take (`run.max_memory`), and expected per-frame terms
//! that are not finite or would carry the clock past its range.

use crate::components::swap_chain::PresentMode;
use crate::engine::PS_PER_MS;

use super::analytic::AnalyticTerms;
use super::config::{FramePipelineConfig, WorkloadConfig};
use super::records::FrameRecord;
use crate::systems::error::{SystemError, invalid as bad};

/// Checks values serde cannot (ranges, distributions); run through
/// [`super::checked::CheckedPipeline::new`].
pub(super) fn validate(cfg: &FramePipelineConfig) -> Result<(), SystemError> {
    if cfg.system != "frame_pipeline" {
        return Err(bad(
            "system",
            format!("expected \"frame_pipeline\", got {:?}", cfg.system),
        ));
    }
    cfg.display.check().map_err(|(key, message)| bad(key, message))?;
    cfg.frame_generation
        .check()
        .map_err(|(key, message)| bad(key, message))?;
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
    if let WorkloadConfig::Frames(f) = &cfg.workload {
        for (key, list) in f.lists() {
            if (list.len() as u64) < cfg.run.frames {
                return Err(bad(
                    key,
                    format!(
                        "holds {} frames, but run.frames is {}: every list gives one value per frame",
                        list.len(),
                        cfg.run.frames
                    ),
                ));
            }
        }
        if !f.gpu_end.is_empty() && (f.gpu_end.len() as u64) < cfg.run.frames {
            return Err(bad(
                "workload.gpu_end",
                format!(
                    "holds {} frames, but run.frames is {}: give one value per frame, or leave the list out",
                    f.gpu_end.len(),
                    cfg.run.frames
                ),
            ));
        }
        if let Some(i) = (0..f.cpu.len().min(f.submit.len())).find(|&i| f.submit[i] > f.cpu[i]) {
            return Err(bad(
                &format!("workload.submit[{i}]"),
                format!(
                    "{} is after the frame's CPU work of {} (`workload.cpu[{i}]`): the GPU work is submitted during it",
                    f.submit[i], f.cpu[i]
                ),
            ));
        }
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
    check_noise_share(cfg)?;
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

/// The system tasks that preempt one unit: their share of its time on
/// average (mean duration over mean gap, added up), the keys of their
/// durations and a description of each.
struct NoiseLoad {
    share: f64,
    keys: Vec<String>,
    tasks: Vec<String>,
}

/// The enabled system tasks' load on the CPU thread and on the GPU front
/// end, in that order.
fn noise_loads(cfg: &FramePipelineConfig) -> [NoiseLoad; 2] {
    use crate::components::noise::NoiseTarget;
    let mut loads = [(); 2].map(|()| NoiseLoad {
        share: 0.0,
        keys: vec![],
        tasks: vec![],
    });
    if !cfg.noise.enabled {
        return loads;
    }
    let unit = |t: NoiseTarget| usize::from(t == NoiseTarget::Gpu);
    // Milliseconds to four decimals, trailing zeros dropped.
    let ms = |ps: f64| {
        let t = format!("{:.4}", ps / PS_PER_MS as f64);
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    for (i, p) in cfg.noise.periodic.iter().enumerate().filter(|(_, p)| p.enabled) {
        let l = &mut loads[unit(p.target)];
        let mean = p.duration.mean();
        l.share += mean / p.period.0 as f64;
        l.keys.push(format!("noise.periodic.{i}.duration"));
        l.tasks.push(format!(
            "noise.periodic.{i} {:?}: {} ms every {} ms",
            p.name,
            ms(mean),
            ms(p.period.0 as f64)
        ));
    }
    for (i, r) in cfg.noise.random.iter().enumerate().filter(|(_, r)| r.enabled) {
        let l = &mut loads[unit(r.target)];
        let mean = r.duration.mean();
        l.share += mean / r.rate.period.0 as f64;
        l.keys.push(format!("noise.random.{i}.duration"));
        l.tasks.push(format!(
            "noise.random.{i} {:?}: mean {} ms at {}",
            r.name,
            ms(mean),
            r.rate.text
        ));
    }
    loads
}

/// Refuses system tasks that leave a unit less than
/// [`crate::limits::MIN_FREE_SHARE`] of its time (a task whose mean duration
/// is not less than its own gap is refused by its source, naming it).
fn check_noise_share(cfg: &FramePipelineConfig) -> Result<(), SystemError> {
    use crate::limits::MIN_FREE_SHARE;
    for (l, unit) in noise_loads(cfg).iter().zip(["CPU thread", "GPU front end"]) {
        if l.keys.is_empty() || l.share <= 1.0 - MIN_FREE_SHARE {
            continue;
        }
        // A single task over its own gap gets its source's own error.
        if l.keys.len() == 1 && (l.share >= 1.0 || l.share.is_nan()) {
            continue;
        }
        return Err(bad(
            &l.keys.join("|"),
            format!(
                "the system tasks on the {unit} ({}) take {:.2}% of it on average, leaving less than the {}% \
                 a unit must keep free: each frame's work there would take more than {} times as long, and \
                 far longer as the waiting tasks pile up; shorten the tasks or make them rarer",
                l.tasks.join("; "),
                100.0 * l.share,
                100.0 * MIN_FREE_SHARE,
                (1.0 / MIN_FREE_SHARE).round()
            ),
        ));
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
const BYTES_PER_FRAME: usize =
    std::mem::size_of::<FrameRecord>() + super::records::COLUMNS.len() * 8 + super::records::metric::N * 8;

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
        WorkloadConfig::Fixed(_) | WorkloadConfig::Frames(_) => ("workload.cpu", "workload.gpu"),
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
            // Every listed duration is finite.
            WorkloadConfig::Frames(_) => {}
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
    // (A variable-refresh panel's fastest refresh.)
    if cfg.display.effective_mode() == PresentMode::Fifo {
        terms.push((
            "display refresh",
            if cfg.display.vrr.is_some() {
                "display.vrr.max_refresh"
            } else {
                "display.refresh"
            },
            cfg.display.shortest_period().0 as f64,
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

/// A lower bound of the events a run needs, from its inputs, in parts (the
/// key to blame, what, how many): one event per frame; over the least span
/// the frames take (each at least its slowest unit's expected work, the
/// CPU's and the front end's divided by the share the system tasks leave
/// them, and a refresh with a vsynced FIFO swap chain), one event per
/// display refresh (none in immediate mode; with variable refresh, one per
/// slowest period) and one per system task; at
/// `triangle` fidelity one per triangle drawn (`triangles`: the scene's
/// per frame). (Over a few frames the tasks' phase can make the span a
/// task period shorter than its long-run bound.)
pub fn estimate_events(
    cfg: &FramePipelineConfig,
    a: &AnalyticTerms,
    triangles: Option<u64>,
) -> Vec<crate::limits::EventPart> {
    let frames = cfg.run.frames as f64;
    let [cpu, gpu] = noise_loads(cfg);
    let free = |l: &NoiseLoad| (1.0 - l.share).max(crate::limits::MIN_FREE_SHARE);
    let ps = |ms: f64| ms * PS_PER_MS as f64;
    let mode = cfg.display.effective_mode();
    let refresh = cfg.display.shortest_period().0 as f64;
    let mut per_frame = [
        ps(a.cpu_ms) / free(&cpu),
        ps(a.gpu_front_end_ms) / free(&gpu),
        ps(a.geometry_ms),
        ps(a.fragment_ms),
    ]
    .into_iter()
    .filter(|v| v.is_finite())
    .fold(0.0, f64::max);
    if mode == PresentMode::Fifo {
        per_frame = per_frame.max(refresh);
    }
    let span = frames * per_frame;
    let mut parts: Vec<crate::limits::EventPart> = vec![("run.frames".into(), "frames".into(), frames)];
    if let Some(w) = cfg.display.vrr_window().filter(|_| mode != PresentMode::Immediate) {
        // A variable-refresh panel refreshes at least once per slowest period.
        parts.push((
            "display.vrr.min_refresh|run.frames".into(),
            "display refreshes".into(),
            span / w.longest.0 as f64,
        ));
    } else if mode != PresentMode::Immediate {
        parts.push((
            "display.refresh|run.frames".into(),
            "display refreshes".into(),
            span / refresh,
        ));
    }
    if cfg.noise.enabled {
        for (i, p) in cfg.noise.periodic.iter().enumerate().filter(|(_, p)| p.enabled) {
            parts.push((
                format!("noise.periodic.{i}.period|run.frames"),
                format!("system task {:?}", p.name),
                span / p.period.0.max(1) as f64,
            ));
        }
        for (i, r) in cfg.noise.random.iter().enumerate().filter(|(_, r)| r.enabled) {
            parts.push((
                format!("noise.random.{i}.rate|run.frames"),
                format!("system task {:?}", r.name),
                span / r.rate.period.0.max(1) as f64,
            ));
        }
    }
    if cfg.fidelity == super::config::Fidelity::Triangle
        && let Some(t) = triangles
    {
        parts.push((
            "workload|run.frames".into(),
            "triangles at triangle fidelity".into(),
            frames * t as f64,
        ));
    }
    parts
}

/// Refuses, before simulating, a run whose [`estimate_events`] exceeds
/// [`crate::limits::DEFAULT_MAX_EVENTS`]; runs with `run.max_events` or
/// `run.until` are bounded by them (they stop there, reporting the frames
/// they completed) and are left alone.
pub(super) fn check_events(
    cfg: &FramePipelineConfig,
    a: &AnalyticTerms,
    triangles: Option<u64>,
) -> Result<(), SystemError> {
    if cfg.run.until.is_some() || cfg.run.max_events.is_some() {
        return Ok(());
    }
    let parts = estimate_events(cfg, a, triangles);
    match crate::limits::events_check(
        &parts,
        None,
        "lower that key or run.frames, use fidelity = \"draw\" for big scenes, or set run.max_events or run.until \
         to stop the run early (it reports the frames it completed)",
    ) {
        Some((key, message)) => Err(bad(&key, message)),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Overrides, deserialize, load_model};

    #[test]
    fn system_tasks_must_leave_a_share_of_their_unit() {
        // The default model with one `--set`.
        let with = |set: &str| -> FramePipelineConfig {
            let m = load_model(
                None,
                &Overrides {
                    sets: vec![set.into()],
                    ..Overrides::default()
                },
            )
            .unwrap();
            deserialize(&m.table, &m.source).unwrap()
        };
        let cfg = with("noise.periodic.0.duration=\"34.99ms\"");
        let e = validate(&cfg).unwrap_err().to_string();
        assert!(
            e.contains("noise.periodic.0.duration|noise.random.0.duration")
                && e.contains("CPU thread")
                && e.contains("5%")
                && e.contains("34.99 ms every 35 ms"),
            "{e}"
        );
        // At 90% of the CPU the model runs.
        validate(&with("noise.periodic.0.duration=\"31ms\"")).unwrap();
    }
}
