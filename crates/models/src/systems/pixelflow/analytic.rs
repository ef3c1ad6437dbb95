//! The closed forms of paper 002 §4-6 (the `analytic` fidelity and the
//! oracle of the event simulation). All terms in milliseconds, as `f64`:
//! they are printed, never fed back into simulated time.
//!
//! - standard (§4): `t_front + max(t_rast, t_comp, t_shade, t_load)` with
//!   `t_front = t_overhead + t_trans n / n_rast`;
//! - presort (§5): `t_first_pass + max(t_gen, t_rast, t_comp, t_shade, t_load)`
//!   with `t_first_pass = t_overhead + t_first n / n_rast`,
//!   `t_gen = t_gen_each n / n_rast`;
//! - nontex (§6): `max(t_front, t_rast) + (samples - 1)(t_rast + t_comp) +
//!   max(t_comp, t_load)`.
//!
//! `t_rast = t_rast_per_prim n Overlap / n_rast`, `t_comp = regions
//! t_comp_byte bytes`, `t_shade = regions (t_address + t_texture) / n_shaders`,
//! `t_load = regions t_load_region`.

use serde::Serialize;

use super::config::{Architecture, PixelFlowConfig};
use crate::engine::Duration;

fn ms(d: Duration) -> f64 {
    d.as_ms_f64()
}

/// Every term of the closed form, in milliseconds.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Analytic {
    /// The latency the closed form gives.
    pub latency_ms: f64,
    /// Front end: geometry (standard, nontex) or the sorting pass (presort).
    pub front_end_ms: f64,
    /// Back end: what follows the front end in the latency sum.
    pub back_end_ms: f64,
    /// Geometry (standard, nontex) or first sorting pass (presort).
    pub t_front_ms: f64,
    /// Presort's second-pass instruction generation (0 otherwise).
    pub t_gen_ms: f64,
    /// Rasterization of all primitives (one sample pass for nontex).
    pub t_rast_ms: f64,
    /// Composition of the whole screen.
    pub t_comp_ms: f64,
    /// Shading of the whole screen (0 for nontex).
    pub t_shade_ms: f64,
    /// Copy of the whole screen to frame-buffer memory.
    pub t_load_ms: f64,
    /// The overlap factor used.
    pub overlap: f64,
    /// Screen regions.
    pub regions: u32,
    /// Rasterizing nodes.
    pub rasterizers: u32,
    /// Shading nodes.
    pub shaders: u32,
}

/// Evaluates the closed form of the configured architecture.
pub fn closed_form(cfg: &PixelFlowConfig) -> Analytic {
    let n = cfg.primitives as f64;
    let nr = cfg.rasterizers().max(1) as f64;
    let regions = cfg.regions();
    let r = regions as f64;
    let overlap = cfg.overlap();
    let mut a = Analytic {
        latency_ms: 0.0,
        front_end_ms: 0.0,
        back_end_ms: 0.0,
        t_front_ms: 0.0,
        t_gen_ms: 0.0,
        t_rast_ms: 0.0,
        t_comp_ms: 0.0,
        t_shade_ms: 0.0,
        t_load_ms: 0.0,
        overlap,
        regions,
        rasterizers: cfg.rasterizers(),
        shaders: cfg.shaders(),
    };
    match cfg.architecture {
        Architecture::Standard | Architecture::Presort => {
            let c = &cfg.deferred;
            a.t_rast_ms = ms(c.t_rast_per_prim) * n * overlap / nr;
            a.t_comp_ms = r * ms(c.t_comp_byte) * c.appearance_bytes as f64;
            a.t_shade_ms = r * (ms(c.t_shade_address) + ms(c.t_shade_texture)) / cfg.shaders().max(1) as f64;
            a.t_load_ms = r * ms(c.t_load);
            let back = a.t_rast_ms.max(a.t_comp_ms).max(a.t_shade_ms).max(a.t_load_ms);
            if cfg.architecture == Architecture::Standard {
                a.t_front_ms = ms(c.t_overhead) + ms(c.t_trans) * n / nr;
                a.back_end_ms = back;
            } else {
                a.t_front_ms = ms(c.t_overhead) + ms(c.t_first_pass) * n / nr;
                a.t_gen_ms = ms(c.t_gen_each) * n / nr;
                a.back_end_ms = back.max(a.t_gen_ms);
            }
            a.front_end_ms = a.t_front_ms;
        }
        Architecture::Nontex => {
            let c = &cfg.nontex;
            a.t_front_ms = ms(c.t_overhead) + ms(c.t_trans) * n / nr;
            a.t_rast_ms = ms(c.t_rast_per_prim) * n * overlap / nr;
            a.t_comp_ms = r * ms(c.t_comp_byte) * c.composite_bytes as f64;
            a.t_load_ms = r * ms(c.t_load);
            let s = cfg.samples.max(1) as f64;
            a.front_end_ms = a.t_front_ms.max(a.t_rast_ms);
            a.back_end_ms = (s - 1.0) * (a.t_rast_ms + a.t_comp_ms) + a.t_comp_ms.max(a.t_load_ms);
        }
    }
    a.latency_ms = a.front_end_ms + a.back_end_ms;
    a
}

/// The largest primitive count whose closed-form latency is at most
/// `target_ms` (bisection; the closed forms are nondecreasing in n), or 0
/// if even an empty frame takes longer. Capped at 10^10 primitives.
pub fn primitives_at(cfg: &PixelFlowConfig, target_ms: f64) -> f64 {
    let mut c = cfg.clone();
    let mut lat = |n: u64| {
        c.primitives = n;
        closed_form(&c).latency_ms
    };
    if lat(0) > target_ms {
        return 0.0;
    }
    let (mut lo, mut hi) = (0u64, 10_000_000_000u64);
    if lat(hi) <= target_ms {
        return hi as f64;
    }
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if lat(mid) <= target_ms { lo = mid } else { hi = mid }
    }
    lo as f64
}
