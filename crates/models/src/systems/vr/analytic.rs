//! Closed forms of the VR latency chains (paper 001).
//!
//! Naive (the slides' example, an event at a frame start and no wait at the
//! swap lock): `L + S + R + D` = 10 + 30 + 50 + 8.3 = 98.3 ms (the slides'
//! 10 + 30 + 50 + 8 = 98 ms). Head and object motion take the same path.
//! With real phases the loop is locked to stereo-pair boundaries: its period
//! is `F = ceil((S + R) / pair) * pair` (83.3 ms) and every frame waits
//! `W = F - S - R` (3.3 ms) at the swap lock.
//!
//! Warp: head motion needs only the tracker and one warped frame, `L + pair
//! + D` = 10 + 16.7 + 8.3 = 35 ms; object motion also needs a simulation
//! step, `L + S + pair + D` = 65 ms (best cases).

use serde::Serialize;

use super::config::{Scheme, VrConfig};

/// Bounds of one motion kind, milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Bounds {
    /// The event arrives at the start of every stage it needs.
    pub best: f64,
    /// It just misses the tracker sample, every loop start and the swap lock.
    pub worst: f64,
    /// Smallest latency any phase can give in steady state.
    pub phase_min: f64,
    /// Largest latency any phase can give in steady state.
    pub phase_max: f64,
    /// Mean over independent uniform phases.
    pub phase_mean: f64,
}

/// Closed forms for head and object motion.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Analytic {
    /// Head motion (camera pose).
    pub head: Bounds,
    /// Object motion (through the simulation).
    pub object: Bounds,
    /// Naive loop period locked to the display, ms (warp: the pair period).
    pub frame_ms: f64,
}

/// The closed forms of a model.
pub fn analytic(cfg: &VrConfig) -> Analytic {
    let ms = |ps: u64| ps as f64 / 1e9;
    let p = cfg.tracker.period.0;
    let l = cfg.tracker.latency.0;
    let s = cfg.simulation.step.0;
    let r = cfg.renderer.render.0;
    let d = cfg.display_latency().0;
    let pair = cfg.pair().0.max(1);
    match cfg.scheme {
        Scheme::Naive => {
            let f = (s + r).div_ceil(pair) * pair;
            let w = f - s - r;
            let b = Bounds {
                best: ms(l + s + r + d),
                worst: ms(p + l + f + s + r + pair + d),
                phase_min: ms(l + s + r + w + d),
                phase_max: ms(p + l + f + s + r + w + d),
                phase_mean: ms(l + s + r + w + d) + ms(p + f) / 2.0,
            };
            Analytic {
                head: b,
                object: b,
                frame_ms: ms(f),
            }
        }
        Scheme::Warp => Analytic {
            head: Bounds {
                best: ms(l + pair + d),
                worst: ms(p + l + 2 * pair + d),
                phase_min: ms(l + pair + d),
                phase_max: ms(p + l + 2 * pair + d),
                phase_mean: ms(l + pair + d) + ms(p + pair) / 2.0,
            },
            object: Bounds {
                best: ms(l + s + pair + d),
                worst: ms(p + l + 2 * s + 2 * pair + d),
                phase_min: ms(l + s + pair + d),
                phase_max: ms(p + l + 2 * s + 2 * pair + d),
                phase_mean: ms(l + s + pair + d) + ms(p + s + pair) / 2.0,
            },
            frame_ms: ms(pair),
        },
    }
}
