//! Closed forms for the geometry -> triangle FIFO -> fragment pipeline of one
//! draw call (the `draw` fidelity), from the same parameters the `triangle`
//! fidelity simulates.
//!
//! Paper 000 §4.5.1: because the FIFO between the stages is small, the
//! stages overlap only when neighbouring triangles are balanced; the draw's
//! time lies between max(G, F) and G + F. The approximation used here: a
//! FIFO of depth D lets the stages balance work over windows of w = D + 1
//! triangles, so
//!
//!   T = (n / w) * E[max(w * g, F_w)]
//!
//! with g the mean geometry time per triangle and F_w the fragment time of w
//! triangles. For w = 1 the expectation is exact for the size distribution
//! (E[max(g, c X)]); for w > 1, F_w is taken as normal (central limit). T is
//! then kept inside [max(G + f, g + F), G + F] (the first triangle's geometry
//! and the last one's fragments cannot overlap anything). Draws are
//! simulated back to back; overlap between draws is not modelled, which is
//! part of the error the fidelity experiment measures.

use crate::components::distribution::Dist;
use crate::engine::Duration;

/// Times of one draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DrawTimes {
    /// Geometry-stage busy time.
    pub geometry: Duration,
    /// Fragment-stage busy time.
    pub fragment: Duration,
    /// Time from the draw's start to its last fragment.
    pub total: Duration,
}

fn normal_pdf(z: f64) -> f64 {
    (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

fn normal_cdf(z: f64) -> f64 {
    0.5 * statrs::function::erf::erfc(-z / std::f64::consts::SQRT_2)
}

/// E[max(a, X)] for X ~ Normal(m, s^2).
pub fn expected_max_normal(a: f64, m: f64, s: f64) -> f64 {
    if s <= 0.0 || !s.is_finite() {
        return a.max(m);
    }
    let z = (a - m) / s;
    a * normal_cdf(z) + m * (1.0 - normal_cdf(z)) + s * normal_pdf(z)
}

/// The draw's times: `n` triangles, total geometry time `geometry`, triangle
/// areas from `pixels`, `cost_per_pixel` picoseconds, FIFO depth `depth`, or
/// `depth = None` for a sort-middle (binning) pipeline, where the stages run
/// one after the other and the draw takes exactly G + F.
pub fn draw_times(
    n: u64,
    geometry: Duration,
    pixels: &Dist<f64>,
    cost_per_pixel: f64,
    depth: Option<u32>,
) -> DrawTimes {
    if n == 0 {
        return DrawTimes {
            geometry,
            fragment: Duration::ZERO,
            total: geometry,
        };
    }
    let g_total = geometry.0 as f64;
    let mean_px = pixels.mean();
    let f_mean = mean_px * cost_per_pixel;
    let f_total = n as f64 * f_mean;
    let g = g_total / n as f64;
    let Some(depth) = depth else {
        let fragment = Duration::from_ps_f64(f_total);
        return DrawTimes {
            geometry,
            fragment,
            total: Duration(geometry.0.saturating_add(fragment.0)),
        };
    };
    let w = (depth as u64 + 1).min(n) as f64;
    let windowed = if cost_per_pixel <= 0.0 {
        g_total
    } else if w <= 1.0 {
        n as f64 * cost_per_pixel * pixels.expected_max_with(g / cost_per_pixel)
    } else {
        let var = pixels.variance();
        let s = cost_per_pixel * (w * var).sqrt();
        (n as f64 / w) * expected_max_normal(w * g, w * f_mean, s)
    };
    let lower = (g_total + f_mean).max(g + f_total).min(g_total + f_total);
    let upper = g_total + f_total;
    let total = if windowed.is_finite() {
        windowed.clamp(lower, upper)
    } else {
        upper
    };
    let fragment = Duration::from_ps_f64(f_total);
    let total = Duration::from_ps_f64(total).max(geometry).max(fragment);
    DrawTimes {
        geometry,
        fragment,
        total,
    }
}

/// The draw's times on a unified shader pool (`gpu.architecture =
/// "unified"`): geometry shader work `g_shader` and fixed-function time
/// `g_fixed` (fetch and setup), fragment shader work `shade_per_pixel` and
/// fixed-function time `fixed_per_pixel` per covered pixel.
///
/// Each stream's item takes the longer of its fixed-function and shader
/// parts, so per stream the draw's busy times are G = n max(g_x, g_s) (from
/// the means) and F = the fragments at max(shade, fixed) per pixel; the
/// triangle FIFO couples the two streams as in [`draw_times`]. The pool is
/// work-conserving, so the draw also takes at least all of its shader work,
/// G_s + F_s: T = max(T_fifo(G, F), G_s + F_s). With no fixed-function
/// time this is the sum of the shader terms, which is what the triangle
/// fidelity simulates (the pool never idles while either stream has work).
pub fn draw_times_unified(
    n: u64,
    g_shader: Duration,
    g_fixed: Duration,
    pixels: &Dist<f64>,
    shade_per_pixel: f64,
    fixed_per_pixel: f64,
    depth: Option<u32>,
) -> DrawTimes {
    let geometry = g_shader.max(g_fixed);
    let per_pixel = shade_per_pixel.max(fixed_per_pixel);
    let streams = draw_times(n, geometry, pixels, per_pixel, depth);
    let f_shader = n as f64 * pixels.mean() * shade_per_pixel;
    let pool = Duration::from_ps_f64(g_shader.0 as f64 + f_shader);
    DrawTimes {
        total: streams.total.max(pool),
        ..streams
    }
}

/// The draw's time when its triangles come in a given order: `geometry`
/// picoseconds of geometry per triangle and `fragment[i]` of fragments for
/// triangle `i`,
/// through a FIFO of `depth` triangles (`None`: binning, the sum). This is
/// the exact recursion of the two-stage pipeline the `triangle` fidelity
/// simulates: triangle i leaves the geometry stage when its geometry is done
/// and triangle i - depth - 1 has left the fragment stage (the FIFO and the
/// fragment stage hold depth + 1 triangles), and its fragments start when it
/// has left geometry and triangle i - 1's fragments are done. Used for sizes
/// sorted within a draw (`size_order`), where the window approximation of
/// [`draw_times`] does not apply.
pub fn ordered_draw_total(geometry: f64, fragment: &[f64], depth: Option<u32>) -> f64 {
    let Some(depth) = depth else {
        return geometry * fragment.len() as f64 + fragment.iter().sum::<f64>();
    };
    let d = depth as usize + 1;
    // Fragment completion times, a ring of the last d.
    let mut done = vec![0.0f64; d];
    let (mut left_geometry, mut last_done) = (0.0f64, 0.0f64);
    for (i, f) in fragment.iter().enumerate() {
        let geometry_done = left_geometry + geometry;
        let room = if i >= d { done[i % d] } else { 0.0 };
        left_geometry = geometry_done.max(room);
        let start = left_geometry.max(last_done);
        last_done = start + f;
        done[i % d] = last_done;
    }
    last_done
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn balanced_constant_triangles_overlap() {
        // 1000 triangles, g = 10 ps, f = 10 ps each: deep FIFO -> max + fill.
        let t = draw_times(1000, Duration(10_000), &Dist::Const { value: 10.0 }, 1.0, Some(1000));
        assert_eq!(t.total, Duration(10_010));
        // Binned, the same draw takes the sum.
        let b = draw_times(1000, Duration(10_000), &Dist::Const { value: 10.0 }, 1.0, None);
        assert_eq!(
            (b.geometry, b.fragment, b.total),
            (Duration(10_000), Duration(10_000), Duration(20_000))
        );
    }

    #[test]
    fn bimodal_triangles_with_one_slot_tend_to_sum() {
        // Half the triangles tiny, half huge: with w = 1, T = sum of max per triangle.
        let px = Dist::Uniform { min: 0.0, max: 0.0 };
        let t = draw_times(10, Duration(100), &px, 1.0, Some(0));
        assert_eq!(t.total, Duration(100));
    }

    #[test]
    fn between_max_and_sum() {
        let px = Dist::Lognormal {
            median: 10.0,
            sigma: 1.5,
        };
        for depth in [0, 1, 4, 16, 256] {
            let t = draw_times(5000, Duration(5000 * 30), &px, 3.0, Some(depth));
            let lo = t.geometry.max(t.fragment);
            let hi = Duration(t.geometry.0 + t.fragment.0);
            assert!(t.total >= lo && t.total <= hi, "{depth}: {t:?}");
        }
    }

    #[test]
    fn unified_pool_sums_the_shader_terms() {
        // Balanced constant triangles, deep FIFO: split overlaps (max + fill),
        // the unified pool adds the shader work up.
        let px = Dist::Const { value: 10.0 };
        let u = draw_times_unified(1000, Duration(10_000), Duration::ZERO, &px, 1.0, 0.0, Some(16));
        assert_eq!(u.total, Duration(20_000));
        // Fixed-function time beyond the shader work bounds the draw instead.
        let u = draw_times_unified(1000, Duration(1_000), Duration(50_000), &px, 0.1, 0.0, Some(16));
        assert!(u.total >= Duration(50_000) && u.total < Duration(52_000), "{u:?}");
    }

    #[test]
    fn ordered_recursion_matches_the_window_cases() {
        // Balanced constant triangles with a deep FIFO: max plus fill.
        let g = 10.0;
        assert_eq!(ordered_draw_total(g, &[10.0; 1000], Some(1000)), 10_010.0);
        // Direct hand-off, alternating sizes: the sum of per-triangle maxima plus fill.
        let f: Vec<f64> = (0..1000).map(|i| if i % 2 == 0 { 0.0 } else { 20.0 }).collect();
        let t = ordered_draw_total(g, &f, Some(0));
        assert!((10_000.0..=20_000.0).contains(&t), "{t}");
        // Sorted: all small then all large, the regimes do not overlap.
        let mut sorted = f.clone();
        sorted.sort_by(f64::total_cmp);
        let t = ordered_draw_total(g, &sorted, Some(16));
        assert!(t > 14_500.0, "{t}");
        assert_eq!(ordered_draw_total(g, &f, None), 20_000.0);
    }

    #[test]
    fn expected_max_normal_limits() {
        assert!((expected_max_normal(0.0, 0.0, 1.0) - normal_pdf(0.0)).abs() < 1e-12);
        assert_eq!(expected_max_normal(5.0, 1.0, 0.0), 5.0);
        assert!((expected_max_normal(-100.0, 3.0, 1.0) - 3.0).abs() < 1e-9);
    }
}
