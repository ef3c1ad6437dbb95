//! Fitting a device profile (`device_profile.rs`) to measured passes: the
//! CSV rows `rendersim measure` produces (`mesh,size,vs_loops,fs_loops,
//! geometry_only,vs_invocations,fs_invocations,pass_time_ns`), each turned
//! into a [`PassLoad`] (measured vertex invocations, coverage counted from
//! the mesh and target size), then weighted least squares on the relative
//! error: the nine costs are linear once the two lane weights (a grid search,
//! coarse then fine) and which side of `max(clear, geometry)` each row is on
//! (iterated to a fixed point) are fixed; a cost that comes out negative is
//! pinned to zero and the rest refitted. Standard errors come from the
//! covariance of the final linear fit. Leave-one-out predicts each row from a
//! fit to the others, with vertex invocations from the profile's vertex-cache
//! policy, as `rendersim predict` would.

use std::collections::HashMap;
use std::path::Path;

use serde::Serialize;

use super::coverage::{Coverage, coverage};
use super::device_profile::{DeviceCosts, PassLoad};
use super::fit::rel_error_pct;
use crate::components::vertex_cache::CachePolicy;
use crate::scene::generators::mesh_from_spec;

pub use super::passes::PassRow;

/// Errors of a calibration.
#[derive(Debug, thiserror::Error)]
pub enum CalibrateError {
    /// A pass CSV cannot be read or does not parse (names file, line and column).
    #[error(transparent)]
    Csv(#[from] super::passes::PassCsvError),
    /// A mesh spec the generators do not know.
    #[error("mesh {spec:?}: {message}")]
    Mesh {
        /// The spec.
        spec: String,
        /// The generator's error.
        message: String,
    },
    /// Not enough rows to fit the costs.
    #[error("{0} rows are too few to fit a device profile (at least 12)")]
    TooFewRows(usize),
}

/// Reads the rows of one CSV file (the one pass-CSV reader,
/// [`super::passes::read_passes`]).
pub fn read_rows(path: &Path) -> Result<Vec<PassRow>, CalibrateError> {
    Ok(super::passes::read_passes(path)?)
}

/// Coverage and predicted vertex invocations, computed once per mesh and size.
#[derive(Default)]
pub struct LoadCache {
    coverage: HashMap<(String, u32, u32), Coverage>,
    vertices: HashMap<String, u64>,
}

impl LoadCache {
    /// Coverage of `spec` at `w` x `h`.
    pub fn coverage(&mut self, spec: &str, w: u32, h: u32) -> Result<Coverage, CalibrateError> {
        let key = (spec.to_string(), w, h);
        if let Some(c) = self.coverage.get(&key) {
            return Ok(*c);
        }
        let m = mesh(spec)?;
        let c = coverage(&m, spec, w, h);
        self.coverage.insert(key, c);
        Ok(c)
    }

    /// Vertex invocations of one draw of `spec` under `policy`.
    pub fn vertices(&mut self, spec: &str, policy: &CachePolicy) -> Result<u64, CalibrateError> {
        if let Some(v) = self.vertices.get(spec) {
            return Ok(*v);
        }
        let v = mesh(spec)?.cache_stats(policy).transformed;
        self.vertices.insert(spec.to_string(), v);
        Ok(v)
    }
}

fn mesh(spec: &str) -> Result<crate::scene::mesh::Mesh, CalibrateError> {
    mesh_from_spec(spec, Path::new(".")).map_err(|e| CalibrateError::Mesh {
        spec: spec.to_string(),
        message: e.to_string(),
    })
}

/// The load of a row; `vertices` overrides the measured invocations.
pub fn row_load(row: &PassRow, cache: &mut LoadCache, vertices: Option<u64>) -> Result<PassLoad, CalibrateError> {
    Ok(PassLoad {
        pixels: f64::from(row.size.width) * f64::from(row.size.height),
        vertices: vertices.unwrap_or(row.vs_invocations) as f64,
        vs_loops: f64::from(row.vs_loops),
        fs_loops: f64::from(row.fs_loops),
        coverage: if row.geometry_only {
            Coverage::default()
        } else {
            cache.coverage(&row.mesh, row.size.width, row.size.height)?
        },
    })
}

/// A fitted profile's costs with their standard errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fit {
    /// The costs.
    pub costs: DeviceCosts,
    /// Standard error per cost key (the fitted linear ones).
    pub std_errors: Vec<(String, f64)>,
    /// Sum of squared relative errors.
    pub objective: f64,
}

const P: usize = 9;
const KEYS: [&str; P] = [
    "pass_overhead_ns",
    "clear_store_per_pixel_ns",
    "vertex_ns",
    "vertex_per_loop_ns",
    "vertex_loop_latency_ns",
    "triangle_ns",
    "lane_ns",
    "lane_per_loop_ns",
    "fragment_loop_latency_ns",
];

fn costs_of(b: &[f64; P], helper: f64, waste: f64) -> DeviceCosts {
    DeviceCosts {
        pass_overhead_ns: b[0],
        clear_store_per_pixel_ns: b[1],
        vertex_ns: b[2],
        vertex_per_loop_ns: b[3],
        vertex_loop_latency_ns: b[4],
        triangle_ns: b[5],
        lane_ns: b[6],
        lane_per_loop_ns: b[7],
        fragment_loop_latency_ns: b[8],
        helper_lane_weight: helper,
        warp_waste_weight: waste,
    }
}

/// Design row; `side`: 0 both terms (the first pass), 1 clear, 2 geometry.
fn design(l: &PassLoad, lanes: f64, side: u8) -> [f64; P] {
    let (c, g) = (side != 2, side != 1);
    let gz = |v: f64| if g { v } else { 0.0 };
    let frag = l.coverage.fragments > 0;
    [
        1.0,
        if c { l.pixels } else { 0.0 },
        gz(l.vertices),
        gz(l.vertices * l.vs_loops),
        gz(l.vs_loops),
        gz(l.coverage.triangles as f64),
        if frag { lanes } else { 0.0 },
        if frag { lanes * l.fs_loops } else { 0.0 },
        if frag { l.fs_loops } else { 0.0 },
    ]
}

/// Solves `a x = b` (n x n, row-major) by Gaussian elimination with partial
/// pivoting; `None` when singular.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Option<Vec<f64>> {
    for k in 0..n {
        let piv = (k..n).max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))?;
        if a[piv * n + k].abs() < 1e-12 {
            return None;
        }
        for j in 0..n {
            a.swap(k * n + j, piv * n + j);
        }
        b.swap(k, piv);
        for i in k + 1..n {
            let f = a[i * n + k] / a[k * n + k];
            for j in k..n {
                a[i * n + j] -= f * a[k * n + j];
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = vec![0.0; n];
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|j| a[k * n + j] * x[j]).sum();
        x[k] = (b[k] - s) / a[k * n + k];
    }
    Some(x)
}

/// Non-negative weighted least squares of `1 = x_i . b / y_i`; returns the
/// coefficients, the standard errors and the objective.
fn nnls(rows: &[[f64; P]], y: &[f64]) -> ([f64; P], [f64; P], f64) {
    // Scale columns to unit norm for conditioning.
    let mut scale = [0.0f64; P];
    for (r, yi) in rows.iter().zip(y) {
        for (s, v) in scale.iter_mut().zip(r) {
            *s += (v / yi).powi(2);
        }
    }
    let mut active: Vec<usize> = (0..P).filter(|&j| scale[j] > 0.0).collect();
    for s in &mut scale {
        *s = if *s > 0.0 { s.sqrt() } else { 1.0 };
    }
    loop {
        let n = active.len();
        let (mut a, mut b) = (vec![0.0; n * n], vec![0.0; n]);
        for (r, yi) in rows.iter().zip(y) {
            let x: Vec<f64> = active.iter().map(|&j| r[j] / yi / scale[j]).collect();
            for i in 0..n {
                b[i] += x[i];
                for k in 0..n {
                    a[i * n + k] += x[i] * x[k];
                }
            }
        }
        let sol = solve(a.clone(), b, n);
        let Some(sol) = sol else {
            // Singular: drop the last active column and retry.
            active.pop();
            continue;
        };
        if let Some(worst) = (0..n)
            .filter(|&i| sol[i] < 0.0)
            .min_by(|&i, &j| sol[i].total_cmp(&sol[j]))
        {
            active.remove(worst);
            continue;
        }
        let mut beta = [0.0; P];
        for (i, &j) in active.iter().enumerate() {
            beta[j] = sol[i] / scale[j];
        }
        let obj: f64 = rows
            .iter()
            .zip(y)
            .map(|(r, yi)| {
                let p: f64 = r.iter().zip(&beta).map(|(a, b)| a * b).sum();
                (p / yi - 1.0).powi(2)
            })
            .sum();
        let dof = rows.len().saturating_sub(n).max(1) as f64;
        let s2 = obj / dof;
        let mut se = [0.0; P];
        for (i, &j) in active.iter().enumerate() {
            let mut e = vec![0.0; n];
            e[i] = 1.0;
            if let Some(col) = solve(a.clone(), e, n) {
                se[j] = (s2 * col[i]).max(0.0).sqrt() / scale[j];
            }
        }
        return (beta, se, obj);
    }
}

/// Fits the linear costs for fixed lane weights.
fn fit_linear(loads: &[PassLoad], y: &[f64], helper: f64, waste: f64) -> ([f64; P], [f64; P], f64) {
    let lanes: Vec<f64> = loads.iter().map(|l| l.lanes(helper, waste)).collect();
    let mut side = vec![0u8; loads.len()];
    let mut best = None;
    for _ in 0..12 {
        let rows: Vec<[f64; P]> = loads
            .iter()
            .zip(&lanes)
            .zip(&side)
            .map(|((l, n), s)| design(l, *n, *s))
            .collect();
        let (b, se, obj) = nnls(&rows, y);
        let c = costs_of(&b, helper, waste);
        let next: Vec<u8> = loads
            .iter()
            .map(|l| {
                let k = c.cost(l);
                if k.clear_ns > k.geometry_ns { 1 } else { 2 }
            })
            .collect();
        let done = next == side;
        // Keep the best objective among the fixed points visited (side 0 is
        // only a start: it sums both terms).
        if !side.contains(&0) && best.as_ref().is_none_or(|(_, _, o)| obj < *o) {
            best = Some((b, se, obj));
        }
        side = next;
        if done {
            break;
        }
    }
    best.unwrap_or(([0.0; P], [0.0; P], f64::INFINITY))
}

/// Fits a profile's costs to `loads` measured at `y` ns.
pub fn fit(loads: &[PassLoad], y: &[f64]) -> Result<Fit, CalibrateError> {
    if loads.len() < 12 {
        return Err(CalibrateError::TooFewRows(loads.len()));
    }
    let mut best = (f64::INFINITY, 0.0, 0.0, [0.0; P], [0.0; P]);
    let try_w = |h: f64, w: f64, best: &mut (f64, f64, f64, [f64; P], [f64; P])| {
        let (b, se, obj) = fit_linear(loads, y, h, w);
        if obj < best.0 {
            *best = (obj, h, w, b, se);
        }
    };
    for i in 0..=10 {
        for j in 0..=10 {
            try_w(f64::from(i) / 10.0, f64::from(j) / 10.0, &mut best);
        }
    }
    let (h0, w0) = (best.1, best.2);
    for i in -5..=5 {
        for j in -5..=5 {
            let (h, w) = (h0 + f64::from(i) * 0.02, w0 + f64::from(j) * 0.02);
            if (0.0..=1.0).contains(&h) && (0.0..=1.0).contains(&w) {
                try_w(h, w, &mut best);
            }
        }
    }
    let (objective, h, w, b, se) = best;
    Ok(Fit {
        costs: costs_of(&b, h, w),
        std_errors: KEYS.iter().zip(se).map(|(k, s)| (k.to_string(), s)).collect(),
        objective,
    })
}

/// Median, 90th percentile and worst of |errors|.
pub fn error_summary(errors_pct: &[f64]) -> (f64, f64, f64) {
    let mut a: Vec<f64> = errors_pct.iter().map(|e| e.abs()).collect();
    a.sort_by(f64::total_cmp);
    if a.is_empty() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    let q = |p: f64| a[((p * (a.len() - 1) as f64).round() as usize).min(a.len() - 1)];
    (q(0.5), q(0.9), a[a.len() - 1])
}

/// Leave-one-out: row i predicted (with `predict_loads[i]`) by the fit to
/// all other rows (`fit_loads`); relative errors in percent.
pub fn leave_one_out(
    fit_loads: &[PassLoad],
    predict_loads: &[PassLoad],
    y: &[f64],
) -> Result<Vec<f64>, CalibrateError> {
    (0..y.len())
        .map(|i| {
            let (l, t): (Vec<PassLoad>, Vec<f64>) = fit_loads
                .iter()
                .zip(y)
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, (l, t))| (*l, *t))
                .unzip();
            let f = fit(&l, &t)?;
            Ok(rel_error_pct(f.costs.cost(&predict_loads[i]).pass_ns, y[i]))
        })
        .collect()
}

/// Whether row `i` is in the fitted half of [`held_out_half`]: a fixed
/// pseudo-random half (splitmix64 of the row's position), so passes
/// measured in pairs or in a sweep's order fall on both sides.
pub fn in_fitted_half(i: usize) -> bool {
    let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    (z ^ (z >> 31)) & 1 == 0
}

/// Fits on one half of the rows ([`in_fitted_half`]) and predicts the
/// others, each from its mesh's vertex count under the profile's cache
/// policy (`predict_loads`): the held-out rows' relative errors in percent,
/// in row order.
pub fn held_out_half(
    fit_loads: &[PassLoad],
    predict_loads: &[PassLoad],
    y: &[f64],
) -> Result<Vec<f64>, CalibrateError> {
    let (l, t): (Vec<PassLoad>, Vec<f64>) = fit_loads
        .iter()
        .zip(y)
        .enumerate()
        .filter(|(i, _)| in_fitted_half(*i))
        .map(|(_, (l, t))| (*l, *t))
        .unzip();
    let f = fit(&l, &t)?;
    Ok(predict_loads
        .iter()
        .zip(y)
        .enumerate()
        .filter(|(i, _)| !in_fitted_half(*i))
        .map(|(_, (l, t))| rel_error_pct(f.costs.cost(l).pass_ns, *t))
        .collect())
}

/// The baseline the profile must beat: time linear in vertex invocations,
/// invocations x loops, fragments and fragments x loops (weighted by
/// 1 / time, no structure); leave-one-out relative errors in percent.
pub fn linear_baseline_loo(loads: &[PassLoad], y: &[f64]) -> Vec<f64> {
    let x = |l: &PassLoad| {
        let f = l.coverage.fragments as f64;
        let mut r = [0.0; P];
        r[..5].copy_from_slice(&[1.0, l.vertices, l.vertices * l.vs_loops, f, f * l.fs_loops]);
        r
    };
    (0..y.len())
        .map(|i| {
            let (rows, t): (Vec<[f64; P]>, Vec<f64>) = loads
                .iter()
                .zip(y)
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, (l, t))| (x(l), *t))
                .unzip();
            let (b, _, _) = nnls(&rows, &t);
            let p: f64 = x(&loads[i]).iter().zip(&b).map(|(a, b)| a * b).sum();
            rel_error_pct(p, y[i])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_and_nnls_recover_a_line() {
        let x = solve(vec![2.0, 1.0, 1.0, 3.0], vec![3.0, 5.0], 2).unwrap();
        assert!((x[0] - 0.8).abs() < 1e-12 && (x[1] - 1.4).abs() < 1e-12);
        let rows: Vec<[f64; P]> = (1..20)
            .map(|i| {
                let mut r = [0.0; P];
                r[0] = 1.0;
                r[2] = f64::from(i);
                r
            })
            .collect();
        let y: Vec<f64> = (1..20).map(|i| 5.0 + 2.0 * f64::from(i)).collect();
        let (b, _, obj) = nnls(&rows, &y);
        assert!(
            (b[0] - 5.0).abs() < 1e-9 && (b[2] - 2.0).abs() < 1e-9 && obj < 1e-20,
            "{b:?}"
        );
    }

    #[test]
    fn error_summary_orders() {
        let (m, p, w) = error_summary(&[-1.0, 2.0, -3.0, 4.0, 10.0]);
        assert_eq!((m, w), (3.0, 10.0));
        assert!(p >= 4.0);
    }
}
