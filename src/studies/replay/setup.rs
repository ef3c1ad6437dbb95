//! A PresentMon capture's swap chain made ready to simulate (issue 26): its
//! frames, present mode, refresh and time origin turned into the replay's
//! frame-pipeline model (`models/replay.toml` with `kind = "frames"`), with
//! the assumptions (`--assume`) patched on, before any what-if. The module
//! documentation of `replay` says how a captured frame becomes the model's.

use crate::capture::display::{DisplayInference, Flips, fit_grid, infer_display};
use crate::capture::presentmon::{Capture, CaptureError, Present};
use crate::config::patch::set_dotted;
use crate::config::{ModelSource, apply_patches};
use crate::engine::Duration;
use crate::systems::frame_pipeline::FramePipelineConfig;
use crate::systems::frame_pipeline::config::FramesWorkload;
use crate::systems::frame_pipeline::records::ChainInfo;

use super::{REPLAY_MODEL, RefreshFrom, ReplayError, ReplayOptions, fit_phase};

/// The model's present mode, vsync and composition for a captured present.
/// A hardware flip (`Hardware: Legacy Flip`, `Hardware: Independent Flip`,
/// `Hardware Composed: Independent Flip`) is an independent flip; a
/// `Composed: ...` present is shown by the compositor (its timing inferred
/// from the swap chain's frames, [`crate::capture::display::infer_compositor`]).
/// Sync interval 1 or more is `fifo`; 0 is `mailbox`, or `immediate` when
/// the present allows tearing on a hardware flip (the compositor never
/// tears). A composed present without a sync interval (-1, PresentMon's
/// value for a blit, D3D9's among them) says nothing of waiting: a swap
/// chain whose frames the compositor skipped (`dropped_share` of its
/// frames never shown, over 5%) did not wait for a vertical blank and is
/// `mailbox` (CS:GO's blits at 119 presents a second on a 60 Hz panel);
/// one that showed its frames is `fifo` (PresentMon's test app, its
/// frames queued three refreshes deep).
fn model_mode(p: &Present, dropped_share: f64, file: &str) -> Result<(&'static str, bool, bool), CaptureError> {
    let mode: &str = &p.present_mode;
    let composed = mode.starts_with("Composed");
    if !composed && !mode.starts_with("Hardware") {
        return Err(CaptureError::Row {
            file: file.to_string(),
            line: p.line,
            message: format!(
                "unknown present mode `{mode}` (replayed: `Hardware: Legacy Flip`, `Hardware: Independent Flip`, \
                 `Hardware Composed: Independent Flip`, `Composed: Flip`, `Composed: Copy with GPU GDI`, \
                 `Composed: Copy with CPU GDI`)"
            ),
        });
    }
    let sync = p.sync_interval.unwrap_or(1);
    Ok(match (sync, p.allows_tearing, composed) {
        (s, _, true) if s < 0 && dropped_share > 0.05 => ("mailbox", true, true),
        (s, _, true) if s != 0 => ("fifo", true, true),
        (_, _, true) => ("mailbox", true, true),
        (s, _, false) if s >= 1 => ("fifo", true, false),
        (_, true, false) => ("immediate", false, false),
        (_, false, false) => ("mailbox", true, false),
    })
}

/// Milliseconds as whole picoseconds (the capture's decimals, exactly where
/// it has no more than nine).
fn to_ps(ms: f64) -> i64 {
    (ms * 1e9).round() as i64
}

/// A capture's non-negative milliseconds as the model's duration (a
/// negative or missing time is none).
fn duration(ms: f64) -> Duration {
    Duration(to_ps(ms.max(0.0)).max(0) as u64)
}

/// The capture's swap chain made ready to simulate: the base model with the
/// captured frames, refresh and present mode and the assumptions, before
/// any what-if.
pub(super) struct Setup {
    pub(super) rows: Vec<Present>,
    /// The present mode most frames use, and the model's for it.
    pub(super) common: Present,
    pub(super) mode: &'static str,
    /// Whether the compositor shows its frames (a `Composed: ...` mode).
    pub(super) composed: bool,
    /// The refresh period of the replay as captured, ms, and where it comes from.
    pub(super) period: f64,
    pub(super) refresh_from: RefreshFrom,
    /// The display inferred from the whole capture.
    pub(super) display: DisplayInference,
    /// The capture's time of the model's time zero, ps.
    pub(super) origin_ps: i64,
    /// The capture's swap chain, for the replayed frames.
    pub(super) chain: ChainInfo,
    /// What errors call the what-if's patches.
    pub(super) whatif_option: &'static str,
    pub(super) src: ModelSource,
    /// The model's table without the captured frames' lists (empty), which
    /// [`Setup::frames`] holds typed.
    pub(super) table: toml::Table,
    /// The captured frames as the model's per-frame workload.
    pub(super) frames: FramesWorkload,
}

impl Setup {
    /// The capture's time of the model's time zero, ms.
    pub(super) fn origin(&self) -> f64 {
        self.origin_ps as f64 / 1e9
    }
}

/// Whether the assumptions (`--assume K=V` patches) set `key`, or, with
/// `key` ending in `.`, a key under it.
pub(super) fn assumes(assume: &[String], key: &str) -> bool {
    assume.iter().any(|a| {
        a.split_once('=').is_some_and(|(k, _)| {
            let k = k.trim();
            k == key || (key.ends_with('.') && k.starts_with(key)) || format!("{k}.") == key
        })
    })
}

pub(super) fn setup(capture: &Capture, opts: &ReplayOptions) -> Result<Setup, ReplayError> {
    let (chain, rows) = capture.select(opts.app.as_deref(), opts.swap_chain.as_deref())?;
    let file = capture.file.as_str();
    // The mode most of its frames use (a swap chain may switch, e.g. from
    // a composed to an independent flip after its first frame).
    let common = rows
        .iter()
        .find(|p| *p.present_mode == *chain.present_mode)
        .unwrap_or(&rows[0])
        .clone();
    let dropped_share = rows.iter().filter(|p| !p.displayed()).count() as f64 / rows.len() as f64;
    let (mode, vsync, composed) = model_mode(&common, dropped_share, file)?;
    let display = infer_display(capture, &rows[0]);
    // A flip at sync interval 0 off every grid the capture shows, that may
    // not tear, was shown by a variable-refresh panel; one that may tear
    // is `immediate` whatever its `Hardware:` mode says.
    let mode = if display.flips == Flips::Tearing {
        "immediate"
    } else {
        mode
    };
    let vsync = vsync && mode != "immediate";

    // The base model with the assumptions (they may give the refresh).
    let mut src = ModelSource::from_text("the replay model (models/replay.toml)", REPLAY_MODEL);
    let mut table = src.table()?;
    apply_patches(opts.option_names().1, &opts.assume, &mut src, &mut table).map_err(ReplayError::Assume)?;
    let assumed_cfg = FramePipelineConfig::from_table(&table, &src).map_err(ReplayError::Assume)?;
    let model_period = assumed_cfg.display.refresh.period.as_ms_f64();
    // A capture taken with frame generation (assumed) measured the
    // interpolation in each frame's GPU busy time; the model adds it again.
    let generation_ms = |i: usize| assumed_cfg.frame_generation.cost_before_present(i as u64).as_ms_f64();
    let given_period = assumes(&opts.assume, "display.refresh").then_some(model_period);

    let (period, phase, refresh_from) = refresh(&rows, &display, given_period, model_period, mode);
    // The run starts at a vertical blank at or before the first CPU start
    // (in whole picoseconds, so a capture written by rendersim lands
    // exactly on its own grid); with tearing, at the first CPU start.
    let period_ps = to_ps(period).max(1);
    let c0_ps = to_ps(rows[0].cpu_start);
    let origin_ps = match phase {
        Some(phase) => {
            let phase_ps = to_ps(phase);
            phase_ps + (c0_ps - phase_ps).div_euclid(period_ps) * period_ps
        }
        None => c0_ps,
    };

    let vrr = display
        .vrr
        .as_ref()
        .filter(|_| display.flips == Flips::VariableRefresh && !assumes(&opts.assume, "display.vrr."));
    let frames = workload(&rows, Duration((c0_ps - origin_ps).max(0) as u64), &generation_ms);
    let mut sets: Vec<(&str, toml::Value)> = vec![
        ("run.frames", toml::Value::Integer(rows.len() as i64)),
        ("workload.start", toml::Value::String(format!("{}ps", frames.start.0))),
    ];
    // The lists are the typed `frames`, not TOML text (a what-if that
    // patches one keeps its own).
    for (key, _) in frames.lists() {
        sets.push((key, toml::Value::Array(Vec::new())));
    }
    // What the capture says of its display, unless assumed otherwise.
    let display_keys: [(&str, toml::Value); 4] = [
        ("display.refresh", toml::Value::String(format!("{period_ps}ps"))),
        ("display.present_mode", toml::Value::String(mode.into())),
        ("display.vsync", toml::Value::Boolean(vsync)),
        (
            "display.composition",
            toml::Value::String(if composed { "composed" } else { "independent" }.into()),
        ),
    ];
    for (key, value) in display_keys {
        if !assumes(&opts.assume, key) {
            sets.push((key, value));
        }
    }
    // The compositor's timing inferred from the swap chain's composed frames.
    if let Some(c) = display
        .compositor
        .as_ref()
        .filter(|_| composed && !assumes(&opts.assume, "display.compositor."))
    {
        sets.push((
            "display.compositor.wake",
            toml::Value::String(format!("{}ps", to_ps(c.wake_ms).clamp(0, period_ps - 1))),
        ));
        sets.push((
            "display.compositor.refreshes",
            toml::Value::Integer(i64::from(c.refreshes)),
        ));
    }
    if let Some(v) = vrr {
        let rate = |hz: f64| toml::Value::String(format!("{}ps", to_ps(1000.0 / hz)));
        sets.push(("display.vrr.min_refresh", rate(v.min_hz)));
        sets.push(("display.vrr.max_refresh", rate(v.max_hz)));
    }
    for (key, value) in sets {
        set_dotted(&mut table, key, value).map_err(|e| CaptureError::Format {
            file: file.to_string(),
            message: format!("building the replay model: {}", e.reason),
        })?;
    }
    let chain = ChainInfo {
        application: common.application.to_string(),
        process_id: common.process_id.to_string(),
        swap_chain: common.swap_chain.to_string(),
        runtime: "Other".into(),
        sync_interval: common.sync_interval.unwrap_or(1),
        allows_tearing: common.allows_tearing,
        present_mode: common.present_mode.to_string(),
    };
    Ok(Setup {
        rows,
        common,
        mode,
        composed,
        period,
        refresh_from,
        display,
        origin_ps,
        chain,
        whatif_option: opts.option_names().0,
        src,
        table,
        frames,
    })
}

/// The replay's refresh period (ms), the phase of its vertical blanks (none
/// for a tearing swap chain on no grid) and where they come from: the
/// assumed period (`given`) on the inferred grid's phase where the two
/// agree, else the phase fitted to this swap chain's screen times; else the
/// inferred refresh; else, nothing on a grid by the inference's measure,
/// the swap chain's own display changes however scattered (where it waits
/// for blanks), or the base model's period (`model_period`).
fn refresh(
    rows: &[Present],
    display: &DisplayInference,
    given: Option<f64>,
    model_period: f64,
    mode: &str,
) -> (f64, Option<f64>, RefreshFrom) {
    let screen: Vec<f64> = rows.iter().filter_map(|p| p.screen_time()).collect();
    match (given, &display.refresh) {
        (Some(p), Some(r)) if (r.grid.period_ms / p - 1.0).abs() < 0.005 => {
            (p, Some(r.grid.phase_ms), RefreshFrom::Assumed)
        }
        (Some(p), _) if mode == "immediate" => (p, None, RefreshFrom::Assumed),
        (Some(p), _) => (p, Some(fit_phase(&screen, p)), RefreshFrom::Assumed),
        (None, Some(r)) => (r.grid.period_ms, Some(r.grid.phase_ms), r.from.into()),
        (None, None) => match fit_grid(&screen).filter(|_| mode != "immediate") {
            Some(g) => (g.period_ms, Some(g.phase_ms), RefreshFrom::DisplayChanges),
            None => (model_period, None, RefreshFrom::Default),
        },
    }
}

/// The captured frames as the model's per-frame workload (`kind =
/// "frames"`), the first frame starting `start` after the run's time zero;
/// `generation_ms(i)`, an assumed frame generation's cost in frame `i`'s
/// GPU time, is taken out of it.
///
/// The GPU's busy time per frame: PresentMon 2 measures it; PresentMon 1
/// gives only when the GPU finished (present plus `MsUntilRenderComplete`),
/// which includes the wait behind the frames before: a frame's work then
/// runs from its present, or from the end of the frame before if that is
/// later, to its completion, and the GPU does not finish it earlier than
/// the capture says.
fn workload(rows: &[Present], start: Duration, generation_ms: &dyn Fn(usize) -> f64) -> FramesWorkload {
    let from_completions = rows.iter().all(|p| p.gpu_busy.is_none());
    let gpu_busy: Vec<f64> = if from_completions {
        let mut last_done = f64::NEG_INFINITY;
        rows.iter()
            .map(|p| match p.render_complete {
                Some(rc) => {
                    let done = p.present + rc;
                    let busy = (done - p.present.max(last_done)).max(0.0);
                    last_done = last_done.max(done);
                    busy
                }
                None => 0.0,
            })
            .collect()
    } else {
        rows.iter().map(|p| p.gpu_busy.unwrap_or(0.0)).collect()
    };
    let list = |f: &dyn Fn(usize, &Present) -> f64| -> Vec<Duration> {
        rows.iter().enumerate().map(|(i, p)| duration(f(i, p))).collect()
    };
    let gpu_end = if from_completions {
        list(&|_, p| p.render_complete.map_or(0.0, |rc| p.cpu_busy + rc))
    } else if rows.iter().any(|p| p.gpu_latency.is_some() && p.gpu_time.is_some()) {
        // The frame's GPU end after its CPU start, where the capture has it
        // (0: no floor).
        list(&|_, p| match (p.gpu_latency, p.gpu_time) {
            (Some(l), Some(t)) => l.max(0.0) + t,
            _ => 0.0,
        })
    } else {
        Vec::new()
    };
    FramesWorkload {
        cpu: list(&|_, p| p.cpu_busy),
        submit: list(&|_, p| p.gpu_latency.unwrap_or(p.cpu_busy).clamp(0.0, p.cpu_busy)),
        gpu: list(&|i, _| (gpu_busy[i] - generation_ms(i)).max(0.0)),
        present: list(&|_, p| p.cpu_wait),
        gpu_end,
        start,
    }
}

/// `workload`'s lists that a patch left empty, filled with the captured
/// frames' (a what-if that gives a list keeps it).
pub(super) fn fill_frames(w: &mut FramesWorkload, captured: &FramesWorkload) {
    for (list, from) in [
        (&mut w.cpu, &captured.cpu),
        (&mut w.submit, &captured.submit),
        (&mut w.gpu, &captured.gpu),
        (&mut w.present, &captured.present),
        (&mut w.gpu_end, &captured.gpu_end),
    ] {
        if list.is_empty() {
            list.clone_from(from);
        }
    }
}

/// The captured frames' lists written into a model `table` where it holds
/// none (a model file of the replay, which `rendersim timeline` runs).
pub(super) fn frames_into(table: &mut toml::Table, frames: &FramesWorkload) {
    let Some(toml::Value::Table(w)) = table.get_mut("workload") else {
        return;
    };
    let text = |list: &[Duration]| {
        toml::Value::Array(list.iter().map(|d| toml::Value::String(format!("{}ps", d.0))).collect())
    };
    for (key, list) in [
        ("cpu", &frames.cpu),
        ("submit", &frames.submit),
        ("gpu", &frames.gpu),
        ("present", &frames.present),
        ("gpu_end", &frames.gpu_end),
    ] {
        let empty = match w.get(key) {
            None => true,
            Some(toml::Value::Array(a)) => a.is_empty(),
            Some(_) => false,
        };
        if empty && !list.is_empty() {
            w.insert(key.to_string(), text(list));
        }
    }
}

/// The frame-pipeline model of the set-up frames with `sets` patched on.
pub(super) fn model_of(s: &Setup, sets: &[String]) -> Result<(ModelSource, toml::Table), ReplayError> {
    let (mut src, mut table) = (s.src.clone(), s.table.clone());
    apply_patches(s.whatif_option, sets, &mut src, &mut table)?;
    Ok((src, table))
}
