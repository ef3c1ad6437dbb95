//! The walkthrough model's checks that serde cannot make: known and unique
//! estimators, the limits on frames, fit samples and table sizes (paper 000
//! §6.2's pos tables, §5.1-5.2's view cells), the clock and the LOD keys,
//! and the memory the run would take.

use crate::limits::EventPart;
use crate::systems::checked::Check;
use crate::systems::error::{SystemError, invalid};
use crate::systems::frame_pipeline::CheckedPipeline;

use super::config::WalkthroughConfig;
use super::estimators::ESTIMATORS;
use super::scene::Scene;

/// Most frames and fit samples a run may ask for.
pub const MAX_FRAMES: u64 = 10_000_000;

impl Check for WalkthroughConfig {
    fn check(&self) -> Result<(), SystemError> {
        validate(self)
    }
}

/// Checks the keys serde cannot.
pub fn validate(cfg: &WalkthroughConfig) -> Result<(), SystemError> {
    for (i, e) in cfg.estimation.estimators.iter().enumerate() {
        if !ESTIMATORS.contains(&e.as_str()) {
            return Err(invalid(
                &format!("estimation.estimators.{i}"),
                format!("unknown estimator {e:?} (known: {})", ESTIMATORS.join(", ")),
            ));
        }
        if cfg.estimation.estimators[..i].contains(e) {
            return Err(invalid(
                &format!("estimation.estimators.{i}"),
                format!("{e:?} is listed twice"),
            ));
        }
    }
    cfg.display.check().map_err(|(key, message)| invalid(key, message))?;
    if let Some((key, what)) = cfg.display.beyond_fixed_refresh() {
        return Err(invalid(
            key,
            format!(
                "the walkthrough's frame budget is one fixed refresh; {what} is modelled by the frame \
                 pipeline (`system = \"frame_pipeline\"`)"
            ),
        ));
    }
    if cfg.run.frames > MAX_FRAMES {
        return Err(invalid(
            "run.frames",
            format!("{} frames is more than the limit of {MAX_FRAMES}", cfg.run.frames),
        ));
    }
    let heuristics = cfg
        .estimation
        .estimators
        .iter()
        .any(|e| ESTIMATORS[..4].contains(&e.as_str()));
    if cfg.estimation.fit_samples > MAX_FRAMES {
        return Err(invalid(
            "estimation.fit_samples",
            format!("{} is more than the limit of {MAX_FRAMES}", cfg.estimation.fit_samples),
        ));
    }
    if heuristics && cfg.estimation.fit_samples == 0 {
        return Err(invalid(
            "estimation.fit_samples",
            "must be at least 1 when h1-h4 are estimated (their constants are fitted to these renders)",
        ));
    }
    if !(1..=1024).contains(&cfg.estimation.repeats) {
        return Err(invalid(
            "estimation.repeats",
            format!("must be between 1 and 1024, got {}", cfg.estimation.repeats),
        ));
    }
    let p = &cfg.estimation.pos;
    for (key, v, lo) in [
        ("estimation.pos.alpha_steps", p.alpha_steps, 2),
        ("estimation.pos.gamma_steps", p.gamma_steps, 1),
        ("estimation.pos.phi_steps", p.phi_steps, 1),
    ] {
        if !(lo..=256).contains(&v) {
            return Err(invalid(key, format!("must be between {lo} and 256, got {v}")));
        }
    }
    if !(p.phi_min.is_finite()
        && p.phi_max.is_finite()
        && -90.0 <= p.phi_min
        && p.phi_min <= p.phi_max
        && p.phi_max <= 90.0)
    {
        return Err(invalid(
            "estimation.pos.phi_min|estimation.pos.phi_max",
            format!(
                "need -90 <= phi_min <= phi_max <= 90 degrees, got {} and {}",
                p.phi_min, p.phi_max
            ),
        ));
    }
    if !(p.prune_tolerance.is_finite() && (0.0..=1.0).contains(&p.prune_tolerance)) {
        return Err(invalid(
            "estimation.pos.prune_tolerance",
            format!("must be between 0 and 1, got {}", p.prune_tolerance),
        ));
    }
    let v = &cfg.estimation.view_cells;
    if !(1..=360).contains(&v.directions) {
        return Err(invalid(
            "estimation.view_cells.directions",
            format!("must be between 1 and 360, got {}", v.directions),
        ));
    }
    if !(1..=4096).contains(&v.samples) {
        return Err(invalid(
            "estimation.view_cells.samples",
            format!("must be between 1 and 4096, got {}", v.samples),
        ));
    }
    super::timing::validate(cfg.estimation.clock_overhead, cfg.estimation.clock_noise)?;
    super::lod::validate(&cfg.lod, &cfg.estimation.estimators)?;
    check_memory(cfg)
}

/// The one-frame pipeline runs a walkthrough certainly makes, each with
/// the lower bound of its events ([`CheckedPipeline::events_floor`]).
pub struct Runs<'a> {
    /// The preprocess's exact renders known up front: the empty frame,
    /// one per fit sample when h1-h4 are fitted, and the fewest a pos
    /// table can take per prototype drawn (pruning, further levels and
    /// view cells add more, found as they are built).
    pub preprocess: u64,
    /// The frames along the path (one render each at least).
    pub frames: u64,
    /// The exact renderer's model (no system tasks).
    pub exact: &'a CheckedPipeline,
    /// The actual renderer's model (the frames).
    pub actual: &'a CheckedPipeline,
}

impl<'a> Runs<'a> {
    /// The runs of a walk of `frames` frames through `scene` with the
    /// estimators in `wants` (indexed as [`ESTIMATORS`]).
    pub fn of(
        cfg: &WalkthroughConfig,
        scene: &Scene,
        frames: u64,
        wants: &[bool],
        exact: &'a CheckedPipeline,
        actual: &'a CheckedPipeline,
    ) -> Runs<'a> {
        let fitted = wants[..4].iter().any(|w| *w) && !scene.objects.is_empty();
        // A pos table (one at least per prototype drawn) renders its
        // largest size over the whole grid of directions and every smaller
        // size once at least (`pos::build`).
        let pos = if wants[4] || wants[super::view_cells::PVC] {
            let p = &cfg.estimation.pos;
            let mut used = vec![false; scene.protos.len()];
            for o in &scene.objects {
                used[o.proto as usize] = true;
            }
            let per_table =
                u64::from(p.gamma_steps.max(1)) * u64::from(p.phi_steps.max(1)) + u64::from(p.alpha_steps.max(2)) - 1;
            used.iter().filter(|u| **u).count() as u64 * per_table
        } else {
            0
        };
        Runs {
            preprocess: 1 + pos + if fitted { cfg.estimation.fit_samples } else { 0 },
            frames,
            exact,
            actual,
        }
    }

    /// The lower bound of the runs' events, in parts (each part's key
    /// names the largest per-frame fixed cost first), and that cost's key
    /// and value.
    fn events_floor(&self) -> (Vec<EventPart>, &'static str, u64) {
        let cfg = self.actual.config();
        let (largest, ps) = [
            ("cpu.input_sampling", cfg.cpu.input_sampling.0),
            ("cpu.clear", cfg.cpu.clear.0),
            ("cpu.swap", cfg.cpu.swap.0),
            ("gpu.clear", cfg.gpu.clear.0),
            ("gpu.swap", cfg.gpu.swap.0),
        ]
        .into_iter()
        .max_by_key(|&(_, ps)| ps)
        .expect("five costs");
        let mut parts: Vec<EventPart> = Vec::new();
        for (n, what, key, model) in [
            (
                self.preprocess,
                "the preprocess's renders",
                "estimation.fit_samples",
                self.exact,
            ),
            (self.frames, "the frames", "run.frames", self.actual),
        ] {
            for (k, w, v) in model.events_floor() {
                let k = k.replace("run.frames", key);
                parts.push((format!("{largest}|{k}"), format!("{w} of {what}"), v * n as f64));
            }
        }
        (parts, largest, ps)
    }
}

/// Refuses, before the preprocess, a walkthrough whose pipeline runs
/// certainly need more events than [`crate::limits::DEFAULT_MAX_EVENTS`]
/// (as the frame pipeline refuses a run before simulating it): every run
/// starts from an idle pipeline and takes at least its per-frame fixed
/// costs, over which the display refreshes and the system tasks run.
pub fn check_events(runs: &Runs) -> Result<(), SystemError> {
    let (parts, largest, ps) = runs.events_floor();
    let advice = format!(
        "the walkthrough draws every frame and every preprocess render ({} preprocess renders at least, then {} \
         frames) as a pipeline run of its own, each at least {} ({largest}, the largest \
         per-frame fixed cost); lower {largest}, run.frames, estimation.fit_samples or the \
         estimation.pos steps",
        runs.preprocess,
        runs.frames,
        crate::engine::Duration(ps),
    );
    match crate::limits::events_check(&parts, None, &advice) {
        // (The walkthrough has no `run.max_events`: its runs cannot stop early.)
        Some((key, message)) => Err(invalid(
            &key,
            message.replace(" for a run without run.max_events", " for a walkthrough"),
        )),
        None => Ok(()),
    }
}

fn check_memory(cfg: &WalkthroughConfig) -> Result<(), SystemError> {
    use crate::limits::{DEFAULT_MAX_MEMORY, add_bytes, over_memory_message, show_bytes};
    let mut total = 0u64;
    add_bytes(&mut total, cfg.run.frames, 512);
    let mut fit = 0u64;
    add_bytes(&mut fit, cfg.estimation.fit_samples, 48);
    let parts = format!(
        "{} frames x 512 bytes = {}, {} fit samples x 48 bytes = {}",
        cfg.run.frames,
        show_bytes(total),
        cfg.estimation.fit_samples,
        show_bytes(fit)
    );
    total = total.saturating_add(fit);
    let limit = cfg.run.max_memory.map_or(DEFAULT_MAX_MEMORY, |b| b.0);
    if total > limit {
        return Err(invalid("run.max_memory", over_memory_message(total, &parts, limit)));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Overrides, deserialize, load_model};
    use crate::systems::walkthrough::render::Renderer;
    use crate::systems::walkthrough::run::run_walkthrough;
    use crate::systems::walkthrough::scene::build_scene;

    /// The floor the up-front check uses is below what real walks take,
    /// with short and long per-frame fixed costs, with and without system
    /// tasks in the frames.
    #[test]
    fn the_event_floor_is_a_lower_bound_of_real_walks() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/walkthrough-city.toml");
        for extra in [
            &[][..],
            &["gpu.swap=\"70ms\""][..],
            &["cpu.swap=\"40ms\"", "noise.periodic.0.period=\"5ms\""][..],
        ] {
            let mut sets = vec!["run.frames=6", "estimation.fit_samples=200"];
            sets.extend_from_slice(extra);
            let m = load_model(Some(&path), &Overrides::with_sets(&sets)).unwrap();
            let cfg: WalkthroughConfig = deserialize(&m.table, &m.source).unwrap();
            let scene = build_scene(&cfg.scene, cfg.run.seed).unwrap();
            let checked = crate::systems::checked::Checked::new(cfg.clone()).unwrap();
            let (actual, exact) = (
                Renderer::new(&checked, &scene, true).unwrap(),
                Renderer::new(&checked, &scene, false).unwrap(),
            );
            let wants: Vec<bool> = ESTIMATORS
                .iter()
                .map(|e| cfg.estimation.estimators.iter().any(|x| x == e))
                .collect();
            let runs = Runs::of(&cfg, &scene, cfg.run.frames, &wants, exact.model(), actual.model());
            let floor: f64 = runs.events_floor().0.iter().map(|p| p.2).sum();
            let run = run_walkthrough(cfg).unwrap();
            let events = run.summary.events.total as f64;
            assert!(
                floor <= events,
                "{sets:?}: floor {floor} above the {events} events taken"
            );
            eprintln!("{sets:?}: floor {floor:.0}, taken {events}");
        }
    }
}
