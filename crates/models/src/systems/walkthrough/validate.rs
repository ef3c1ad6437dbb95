//! The walkthrough model's checks that serde cannot make: known and unique
//! estimators, the limits on frames, fit samples and table sizes (paper 000
//! §6.2's pos tables, §5.1-5.2's view cells), the clock and the LOD keys,
//! and the memory the run would take.

use crate::systems::error::{SystemError, invalid};

use super::config::WalkthroughConfig;
use super::estimators::ESTIMATORS;

/// Most frames and fit samples a run may ask for.
pub const MAX_FRAMES: u64 = 10_000_000;

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
