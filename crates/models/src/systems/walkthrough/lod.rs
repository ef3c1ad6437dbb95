//! Level-of-detail selection for the soft real-time walkthrough (paper 001,
//! slides "Reaktive LOD-Selektion" and "Prädiktive LOD-Selektion
//! [Funkhouser und Sequin]"; paper 000 §6.5).
//!
//! - `none`: every object at its finest level.
//! - `reactive`: a global detail level k (triangles allowed per pixel of an
//!   object's bounding disk; each object is drawn at its finest level with
//!   at most k x pixels triangles, else its coarsest) steered by a history
//!   of past frame times: the next frame's time is predicted as the mean of
//!   the last `history` rendering times and k is multiplied by
//!   `(target / predicted)^gain` (coarser when the prediction is over the
//!   target, finer when under), clamped to [`K_RANGE`].
//! - `predictive`: every frame a multiple-choice knapsack over the visible
//!   objects' levels, solved by [`crate::components::lod_select`] (the
//!   lecture's greedy on benefit / cost, or the incremental frame-to-frame
//!   variant), cost from the chosen estimator (h1-h4 or pos at that level),
//!   budget `refresh x (1 - margin)` less the empty frame's time. An object
//!   none of whose levels fits is not drawn (counted in the summary).
//! - `predictive+branch`: predictive plus paper 000 §6.4's conditional
//!   branch (`branch.rs`).
//!
//! Benefit after paper 001's slide "Benefit-Funktion":
//! `Size x Rendering x Importance x OffCenter x Vel x Hysteresis` with
//! Size the bounding sphere's disk in pixels (clipped to the viewport),
//! Rendering = max(0, 1 - c / triangles) (flat shading's form), Importance
//! 1 (no semantic weight in these scenes), OffCenter 1 within
//! `focus_angle` of the view axis and `exp(-(angle - b) / falloff)` beyond
//! (the slide's k1 with b1 = 15°), Vel = 1 / (1 + ω / ω½) for the object's
//! angular speed ω across the view, Hysteresis = (1 - h) + h / (1 + |L - L'|)
//! (the slide's c1 / (1 + |L - L'|) + c2 with one rendering algorithm,
//! c1 + c2 = 1; an object not drawn in the frame before has none). The
//! image benefit reported (`metrics.benefit_mean`) leaves hysteresis out:
//! it steers the selection against popping, it is not part of the image.

use crate::components::lod_select::{Algorithm, Instance, Level as KLevel, LodObject, Selection};
use crate::engine::Duration;
use crate::systems::error::{SystemError, invalid};

use super::config::LodConfig;
use super::estimators::PER_OBJECT_ESTIMATORS;

/// The policies by name.
pub const LOD_POLICIES: [&str; 4] = ["none", "reactive", "predictive", "predictive+branch"];

/// The reactive detail level's range (triangles per pixel of disk).
pub const K_RANGE: (f64, f64) = (1e-4, 1e3);

/// The reactive detail level's start (about every object at its finest
/// level in the presets).
pub const K_START: f64 = 1.0;

/// A validated policy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Policy {
    /// Finest levels.
    None,
    /// Feedback from past frame times.
    Reactive,
    /// Cost/benefit knapsack.
    Predictive,
    /// Knapsack plus the conditional branch.
    PredictiveBranch,
}

impl Policy {
    /// Whether the policy selects by the knapsack.
    pub fn predictive(self) -> bool {
        matches!(self, Policy::Predictive | Policy::PredictiveBranch)
    }
}

/// Checks the `[lod]` keys; returns the policy, the estimator index (into
/// [`PER_OBJECT_ESTIMATORS`]) and the knapsack algorithm.
pub fn validate(cfg: &LodConfig, estimators: &[String]) -> Result<(Policy, usize, Algorithm), SystemError> {
    let policy = match cfg.policy.as_str() {
        "none" => Policy::None,
        "reactive" => Policy::Reactive,
        "predictive" => Policy::Predictive,
        "predictive+branch" => Policy::PredictiveBranch,
        p => {
            return Err(invalid(
                "lod.policy",
                format!("unknown policy {p:?} (known: {})", LOD_POLICIES.join(", ")),
            ));
        }
    };
    // The per-object estimators (h1-h4, pos) price an (object, level);
    // vcs and pvc estimate whole frames per view cell and cannot.
    let per_object = &PER_OBJECT_ESTIMATORS;
    let est = per_object.iter().position(|e| *e == cfg.estimator).ok_or_else(|| {
        invalid(
            "lod.estimator",
            format!(
                "unknown or whole-frame estimator {:?} (a level's cost needs a per-object one: {})",
                cfg.estimator,
                per_object.join(", ")
            ),
        )
    })?;
    if policy.predictive() && !estimators.contains(&cfg.estimator) {
        return Err(invalid(
            "lod.estimator",
            format!(
                "{:?} is not in estimation.estimators ({}); the predictive policies take their costs from it",
                cfg.estimator,
                estimators.join(", ")
            ),
        ));
    }
    let algorithm = match cfg.algorithm.as_str() {
        "greedy" => Algorithm::Greedy,
        "incremental" => Algorithm::Incremental,
        a => {
            return Err(invalid(
                "lod.algorithm",
                format!("unknown algorithm {a:?} (known: greedy, incremental)"),
            ));
        }
    };
    let unit = |key: &str, v: f64, hi_open: bool| -> Result<(), SystemError> {
        let ok = v.is_finite() && v >= 0.0 && if hi_open { v < 1.0 } else { v <= 1.0 };
        if ok {
            Ok(())
        } else {
            Err(invalid(
                key,
                format!(
                    "must be between 0 and 1{}, got {v}",
                    if hi_open { " (below 1)" } else { "" }
                ),
            ))
        }
    };
    unit("lod.margin", cfg.margin, true)?;
    unit("lod.hysteresis", cfg.hysteresis, false)?;
    if !(1..=10_000).contains(&cfg.history) {
        return Err(invalid(
            "lod.history",
            format!("must be between 1 and 10000 frames, got {}", cfg.history),
        ));
    }
    if !(cfg.gain.is_finite() && cfg.gain > 0.0 && cfg.gain <= 10.0) {
        return Err(invalid(
            "lod.gain",
            format!("must be > 0 and at most 10, got {}", cfg.gain),
        ));
    }
    for (key, v, lo_excl) in [
        ("lod.accuracy_triangles", cfg.accuracy_triangles, false),
        ("lod.focus_angle", cfg.focus_angle, false),
        ("lod.focus_falloff", cfg.focus_falloff, true),
        ("lod.velocity_half", cfg.velocity_half, true),
        ("lod.branch_min_distance", cfg.branch_min_distance, false),
    ] {
        let ok = v.is_finite() && if lo_excl { v > 0.0 } else { v >= 0.0 };
        if !ok {
            return Err(invalid(
                key,
                format!(
                    "must be a finite number {}, got {v}",
                    if lo_excl { "> 0" } else { ">= 0" }
                ),
            ));
        }
    }
    if cfg.focus_angle > 180.0 {
        return Err(invalid(
            "lod.focus_angle",
            format!("must be at most 180 degrees, got {}", cfg.focus_angle),
        ));
    }
    if cfg.branch_objects > 1024 {
        return Err(invalid(
            "lod.branch_objects",
            format!("must be at most 1024, got {}", cfg.branch_objects),
        ));
    }
    if !(1..=15).contains(&cfg.branch_levels) {
        return Err(invalid(
            "lod.branch_levels",
            format!("must be between 1 and 15, got {}", cfg.branch_levels),
        ));
    }
    Ok((policy, est, algorithm))
}

/// The view-dependent terms of one object's benefit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BenefitTerms {
    /// Size: the bounding disk in pixels.
    pub size: f64,
    /// OffCenter x Vel (x Importance = 1).
    pub weight: f64,
}

impl BenefitTerms {
    /// The terms of an object whose centre is at `v` in view coordinates
    /// (x right, y up, z forward) now and was at `v_prev` one frame
    /// (`dt` seconds) before, with disk `pixels`.
    pub fn of(cfg: &LodConfig, pixels: f64, v: [f64; 3], v_prev: Option<[f64; 3]>, dt: f64) -> BenefitTerms {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let off = if n > 0.0 {
            (v[2] / n).clamp(-1.0, 1.0).acos().to_degrees()
        } else {
            0.0
        };
        let off_center = if off <= cfg.focus_angle {
            1.0
        } else {
            (-(off - cfg.focus_angle) / cfg.focus_falloff).exp()
        };
        let speed = match v_prev {
            Some(p) if n > 0.0 && dt > 0.0 => {
                let m = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                if m > 0.0 {
                    let c = (v[0] * p[0] + v[1] * p[1] + v[2] * p[2]) / (n * m);
                    c.clamp(-1.0, 1.0).acos().to_degrees() / dt
                } else {
                    0.0
                }
            }
            _ => 0.0,
        };
        let vel = 1.0 / (1.0 + speed / cfg.velocity_half);
        let size = if pixels.is_finite() { pixels.max(0.0) } else { 0.0 };
        BenefitTerms {
            size,
            weight: off_center * vel,
        }
    }

    /// The image benefit at a level of `triangles` (no hysteresis).
    pub fn image(&self, cfg: &LodConfig, triangles: u64) -> f64 {
        let t = triangles.max(1) as f64;
        let b = self.size * (1.0 - cfg.accuracy_triangles / t).max(0.0) * self.weight;
        if b.is_finite() { b.max(0.0) } else { 0.0 }
    }

    /// The selection benefit at `level` of `triangles`, with hysteresis
    /// against `previous` (the object's level in the frame before).
    pub fn selection(&self, cfg: &LodConfig, triangles: u64, level: u32, previous: Option<u32>) -> f64 {
        let h = match previous {
            Some(p) => (1.0 - cfg.hysteresis) + cfg.hysteresis / (1.0 + (level as f64 - p as f64).abs()),
            None => 1.0,
        };
        self.image(cfg, triangles) * h
    }
}

/// The reactive controller: the detail level k and the history.
#[derive(Debug, Clone)]
pub struct Reactive {
    /// Triangles allowed per pixel of disk.
    pub k: f64,
    history: std::collections::VecDeque<f64>,
    len: usize,
    gain: f64,
    target: f64,
}

impl Reactive {
    /// A controller aiming at `target` (any time unit, as the frame times).
    pub fn new(cfg: &LodConfig, target: f64) -> Reactive {
        Reactive {
            k: K_START,
            history: std::collections::VecDeque::with_capacity(cfg.history as usize),
            len: cfg.history as usize,
            gain: cfg.gain,
            target,
        }
    }

    /// The level of an object with `levels` triangle counts (finest first)
    /// and disk `pixels`: the finest with at most k x pixels triangles,
    /// else the coarsest.
    pub fn level(&self, triangles: impl Iterator<Item = u64>, pixels: f64) -> u32 {
        let allowed = self.k * pixels.max(0.0);
        let mut last = 0u32;
        for (i, t) in triangles.enumerate() {
            last = i as u32;
            if (t as f64) <= allowed {
                return last;
            }
        }
        last
    }

    /// Records a frame's rendering time and corrects k for the next frame.
    pub fn record(&mut self, frame_time: f64) {
        if self.history.len() == self.len {
            self.history.pop_front();
        }
        self.history.push_back(frame_time);
        let predicted = self.history.iter().sum::<f64>() / self.history.len() as f64;
        if predicted > 0.0 && self.target > 0.0 {
            self.k = (self.k * (self.target / predicted).powf(self.gain)).clamp(K_RANGE.0, K_RANGE.1);
        }
    }
}

/// One visible object offered to the knapsack: its cost (picoseconds) and
/// selection benefit per level.
#[derive(Debug, Clone)]
pub struct Offer {
    /// (cost ps, benefit) per level, finest first.
    pub levels: Vec<(f64, f64)>,
}

/// Solves one frame's knapsack with the lod_select component; `previous`
/// is the incremental algorithm's start (per offer). Returns the
/// selection and the number of offers none of whose levels fits alone.
pub fn select(
    offers: &[Offer],
    budget_ps: u64,
    algorithm: Algorithm,
    previous: &[Option<u32>],
) -> Result<(Selection, usize), SystemError> {
    let objects: Vec<LodObject> = offers
        .iter()
        .map(|o| LodObject {
            name: String::new(),
            levels: o
                .levels
                .iter()
                .map(|&(c, b)| KLevel {
                    cost: Duration(if c.is_finite() && c > 0.0 { c.round() as u64 } else { 0 }),
                    benefit: if b.is_finite() && b > 0.0 { b } else { 0.0 },
                })
                .collect(),
        })
        .collect();
    let inst = Instance::new(Duration(budget_ps), objects).map_err(|e| invalid("lod", e.to_string()))?;
    let unaffordable = inst.unaffordable().len();
    let sel = inst
        .select(algorithm, Some(previous))
        .map_err(|e| invalid("lod", e.to_string()))?;
    Ok((sel, unaffordable))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reactive_goes_coarser_over_target_and_finer_under() {
        let cfg = LodConfig {
            history: 1,
            ..LodConfig::default()
        };
        let mut r = Reactive::new(&cfg, 10.0);
        let k0 = r.k;
        r.record(20.0);
        assert!((r.k - k0 / 2.0).abs() < 1e-12, "{}", r.k);
        r.record(5.0);
        assert!((r.k - k0).abs() < 1e-12, "{}", r.k);
        // Finest level with at most k x pixels triangles, else the coarsest.
        r.k = 1.0;
        assert_eq!(r.level([1000u64, 500, 250].into_iter(), 600.0), 1);
        assert_eq!(r.level([1000u64, 500, 250].into_iter(), 5000.0), 0);
        assert_eq!(r.level([1000u64, 500, 250].into_iter(), 1.0), 2);
    }

    #[test]
    fn benefit_terms_follow_the_slide() {
        let cfg = LodConfig::default();
        // On the axis, standing still: size x accuracy.
        let t = BenefitTerms::of(&cfg, 1000.0, [0.0, 0.0, 10.0], Some([0.0, 0.0, 10.0]), 1.0 / 60.0);
        assert_eq!(t.weight, 1.0);
        assert!((t.image(&cfg, 64) - 1000.0 * 0.5).abs() < 1e-9);
        // 35 degrees off axis: exp(-(35 - 15) / 20) = exp(-1).
        let a = 35f64.to_radians();
        let t = BenefitTerms::of(&cfg, 1000.0, [a.sin(), 0.0, a.cos()], None, 1.0 / 60.0);
        assert!((t.weight - (-1f64).exp()).abs() < 1e-9, "{}", t.weight);
        // Moving at velocity_half: the velocity term halves.
        let step = (cfg.velocity_half / 60.0).to_radians();
        let t = BenefitTerms::of(
            &cfg,
            1000.0,
            [0.0, 0.0, 1.0],
            Some([step.sin(), 0.0, step.cos()]),
            1.0 / 60.0,
        );
        assert!((t.weight - 0.5).abs() < 1e-9, "{}", t.weight);
        // Hysteresis: two levels away from the previous costs 2/3 of h.
        let t = BenefitTerms::of(&cfg, 1000.0, [0.0, 0.0, 1.0], None, 1.0 / 60.0);
        let b = t.selection(&cfg, 1_000_000, 2, Some(0));
        let want = t.image(&cfg, 1_000_000) * (0.8 + 0.2 / 3.0);
        assert!((b - want).abs() < 1e-9);
        // Fewer triangles than c: no benefit.
        assert_eq!(t.image(&cfg, 16), 0.0);
    }
}
