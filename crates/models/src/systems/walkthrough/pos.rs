//! Per-object sampling (pos, paper 000 §5.2): for each object (here each
//! prototype and level; instances share shape and mesh, and the table is in
//! the object's frame), the rendering time is sampled in a preprocess on a
//! regular grid of the three angles α (size), γ (azimuth) and φ
//! (elevation), rendering the object alone in each sample view. α runs
//! log-spaced from a disk of one pixel's diameter to a disk the size of
//! the viewport; α is clipped to the frustum at lookup (the clipped disk's
//! equal-area angle). Sampling goes from the largest α down; once the
//! renders of one α differ by less than `prune_tolerance` over all
//! directions, the object is geometry-limited there and every smaller α is
//! sampled in one direction only (the pruned measurements). Lookups
//! interpolate linearly in ln α, γ (periodic) and φ (clamped), reading up
//! to eight entries.

use super::config::PosConfig;
use super::culling::{alpha_of_disk, sample_projection};
use super::estimators::Features;
use super::scene::Prototype;

/// One prototype-level table.
#[derive(Debug, Clone)]
pub struct PosTable {
    ln_alpha: Vec<f64>,
    gamma_steps: usize,
    phis: Vec<f64>,
    /// Per α: the grid (γ-major) or one value when pruned; picoseconds.
    values: Vec<Vec<f64>>,
}

/// The sampling grid's α values (ascending) for a viewport.
pub fn alphas(cfg: &PosConfig, focal: f64, w: f64, h: f64) -> Vec<f64> {
    let lo = alpha_of_disk(std::f64::consts::PI * 0.25, focal).ln();
    let hi = alpha_of_disk(w * h, focal).ln();
    let n = cfg.alpha_steps.max(2) as usize;
    (0..n)
        .map(|i| (lo + (hi - lo) * i as f64 / (n - 1) as f64).exp())
        .collect()
}

fn phis(cfg: &PosConfig) -> Vec<f64> {
    let n = cfg.phi_steps.max(1) as usize;
    if n == 1 {
        return vec![0.5 * (cfg.phi_min + cfg.phi_max).to_radians()];
    }
    (0..n)
        .map(|i| (cfg.phi_min + (cfg.phi_max - cfg.phi_min) * i as f64 / (n - 1) as f64).to_radians())
        .collect()
}

/// Builds the table of one prototype at one level, timing each sample view
/// with `render(features, covered pixels)` (picoseconds). Returns the table
/// and the renders made.
pub fn build(
    cfg: &PosConfig,
    proto: &Prototype,
    level: usize,
    view: (f64, f64, f64),
    mut render: impl FnMut(&Features, f64) -> Result<f64, crate::systems::SystemError>,
) -> Result<(PosTable, u64), crate::systems::SystemError> {
    let (focal, w, h) = view;
    let a = alphas(cfg, focal, w, h);
    let ph = phis(cfg);
    let gs = cfg.gamma_steps.max(1) as usize;
    let lv = proto.levels[level];
    let mut values = vec![Vec::new(); a.len()];
    let mut renders = 0u64;
    let mut pruned = false;
    let mut sample = |alpha: f64, gamma: f64, phi: f64, renders: &mut u64| {
        let p = sample_projection(proto, alpha, gamma, phi, focal, w, h);
        let f = Features {
            triangles: lv.triangles as f64,
            transformed: lv.transformed as f64,
            vertices: lv.vertices as f64,
            pixels: p.disk_pixels,
        };
        *renders += 1;
        render(&f, p.covered_pixels)
    };
    for i in (0..a.len()).rev() {
        if pruned {
            values[i] = vec![sample(a[i], 0.0, ph[ph.len() / 2], &mut renders)?];
            continue;
        }
        let mut grid = Vec::with_capacity(gs * ph.len());
        for g in 0..gs {
            let gamma = std::f64::consts::TAU * g as f64 / gs as f64;
            for &phi in &ph {
                grid.push(sample(a[i], gamma, phi, &mut renders)?);
            }
        }
        let (lo, hi) = grid
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, u), v| (l.min(*v), u.max(*v)));
        if hi <= 0.0 || (hi - lo) / hi < cfg.prune_tolerance {
            pruned = true;
        }
        values[i] = grid;
    }
    Ok((
        PosTable {
            ln_alpha: a.iter().map(|x| x.ln()).collect(),
            gamma_steps: gs,
            phis: ph,
            values,
        },
        renders,
    ))
}

impl PosTable {
    /// Renders a full table would take (α x γ x φ).
    pub fn full_size(&self) -> u64 {
        (self.ln_alpha.len() * self.gamma_steps * self.phis.len()) as u64
    }

    fn at_level(&self, i: usize, gamma: f64, phi: f64, reads: &mut u64) -> f64 {
        let v = &self.values[i];
        if v.len() == 1 {
            *reads += 1;
            return v[0];
        }
        let gs = self.gamma_steps;
        let gpos = gamma.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU * gs as f64;
        let g0 = (gpos.floor() as usize) % gs;
        let g1 = (g0 + 1) % gs;
        let tg = gpos - gpos.floor();
        let np = self.phis.len();
        let (p0, p1, tp) = if np == 1 || phi <= self.phis[0] {
            (0, 0, 0.0)
        } else if phi >= self.phis[np - 1] {
            (np - 1, np - 1, 0.0)
        } else {
            let step = self.phis[1] - self.phis[0];
            let x = (phi - self.phis[0]) / step;
            let k = (x.floor() as usize).min(np - 2);
            (k, k + 1, x - k as f64)
        };
        let e = |g: usize, p: usize| v[g * np + p];
        *reads += 4;
        let a = e(g0, p0) * (1.0 - tp) + e(g0, p1) * tp;
        let b = e(g1, p0) * (1.0 - tp) + e(g1, p1) * tp;
        a * (1.0 - tg) + b * tg
    }

    /// The estimate for clipped angle `alpha` and direction (`gamma`,
    /// `phi`), picoseconds; `reads` counts the entries read.
    pub fn lookup(&self, alpha: f64, gamma: f64, phi: f64, reads: &mut u64) -> f64 {
        let n = self.ln_alpha.len();
        let la = alpha.max(1e-300).ln();
        if la <= self.ln_alpha[0] {
            return self.at_level(0, gamma, phi, reads);
        }
        if la >= self.ln_alpha[n - 1] {
            return self.at_level(n - 1, gamma, phi, reads);
        }
        let step = self.ln_alpha[1] - self.ln_alpha[0];
        let x = (la - self.ln_alpha[0]) / step;
        let k = (x.floor() as usize).min(n - 2);
        let t = x - k as f64;
        self.at_level(k, gamma, phi, reads) * (1.0 - t) + self.at_level(k + 1, gamma, phi, reads) * t
    }
}

/// Bounds for per-view-cell estimation (`view_cells.rs`).
impl PosTable {
    /// The largest entry of α level `i` over azimuths `gamma` (an interval
    /// `[lo, hi]`, radians, `hi - lo >= 2π` for all) and elevations `phi`
    /// (`[lo, hi]`): every entry an interpolated lookup in that region could
    /// read.
    fn level_max(&self, i: usize, gamma: (f64, f64), phi: (f64, f64), reads: &mut u64) -> f64 {
        let v = &self.values[i];
        if v.len() == 1 {
            *reads += 1;
            return v[0];
        }
        let gs = self.gamma_steps;
        let g: Vec<usize> = if gamma.1 - gamma.0 >= std::f64::consts::TAU {
            (0..gs).collect()
        } else {
            let lo = (gamma.0.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU * gs as f64).floor() as usize;
            let span = ((gamma.1 - gamma.0) / std::f64::consts::TAU * gs as f64).ceil() as usize + 1;
            (lo..=lo + span.min(gs)).map(|k| k % gs).collect()
        };
        let np = self.phis.len();
        let idx = |x: f64, up: bool| -> usize {
            if np == 1 || x <= self.phis[0] {
                return 0;
            }
            if x >= self.phis[np - 1] {
                return np - 1;
            }
            let step = self.phis[1] - self.phis[0];
            let t = (x - self.phis[0]) / step;
            (if up { t.ceil() } else { t.floor() } as usize).min(np - 1)
        };
        let (p0, p1) = (idx(phi.0, false), idx(phi.1.max(phi.0), true));
        let mut best = 0.0f64;
        for &gi in &g {
            for p in p0..=p1 {
                *reads += 1;
                best = best.max(v[gi * np + p]);
            }
        }
        best
    }

    /// An upper bound of [`PosTable::lookup`] over every α up to `alpha`
    /// and every direction in the given azimuth and elevation intervals:
    /// the interpolation in ln α of the levels' maxima at `alpha`, or the
    /// largest maximum of any level below, whichever is larger (so the bound
    /// holds even where the table does not grow with α).
    pub fn lookup_max(&self, alpha: f64, gamma: (f64, f64), phi: (f64, f64), reads: &mut u64) -> f64 {
        let n = self.ln_alpha.len();
        let la = alpha.max(1e-300).ln();
        let (k, t) = if la <= self.ln_alpha[0] {
            (0, 0.0)
        } else if la >= self.ln_alpha[n - 1] {
            (n - 1, 0.0)
        } else {
            let step = self.ln_alpha[1] - self.ln_alpha[0];
            let x = (la - self.ln_alpha[0]) / step;
            let k = (x.floor() as usize).min(n - 2);
            (k, x - k as f64)
        };
        let mut below = 0.0f64;
        let mut at_k = 0.0;
        for i in 0..=k {
            let m = self.level_max(i, gamma, phi, reads);
            below = below.max(m);
            at_k = m;
        }
        if t > 0.0 && k + 1 < n {
            let next = self.level_max(k + 1, gamma, phi, reads);
            below.max(at_k * (1.0 - t) + next * t)
        } else {
            below
        }
    }
}
