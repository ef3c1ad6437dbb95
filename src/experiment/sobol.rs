//! Sobol' sensitivity indices from Saltelli's design ([`super::sample`]):
//! the estimators of Saltelli et al. 2010 ("Variance based sensitivity
//! analysis of model output. Design and estimator for the total sensitivity
//! index", Table 2): for `f(A)`, `f(B)` and `f(A_B^(i))` on `n` rows,
//!
//! - first order: `S_i = (1/n) sum_j f(B)_j (f(A_B^(i))_j - f(A)_j) / V`
//!   (Table 2, (b));
//! - total: `S_Ti = (1/2n) sum_j (f(A)_j - f(A_B^(i))_j)^2 / V`
//!   (Jansen 1999, Table 2, (f), the estimator the paper recommends);
//!
//! with `V` the variance of all `f(A)` and `f(B)` values. Confidence
//! intervals are percentile bootstrap intervals: the rows `j` are resampled
//! with replacement and both indices recomputed on each resample.

use rand::Rng;
use serde::Serialize;

use crate::engine::rng::RngStreams;
use crate::stats::quantile::quantile;

/// The indices of one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SobolIndex {
    /// First-order index `S_i`.
    pub first: f64,
    /// Its bootstrap interval `(low, high)`.
    pub first_ci: (f64, f64),
    /// Total index `S_Ti`.
    pub total: f64,
    /// Its bootstrap interval.
    pub total_ci: (f64, f64),
}

fn estimate(rows: &[usize], fa: &[f64], fb: &[f64], fab: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>) {
    let m = rows.len() as f64;
    let all = rows.iter().flat_map(|&j| [fa[j], fb[j]]);
    let mean = all.clone().sum::<f64>() / (2.0 * m);
    let var = all.map(|x| (x - mean) * (x - mean)).sum::<f64>() / (2.0 * m);
    let mut first = Vec::with_capacity(fab.len());
    let mut total = Vec::with_capacity(fab.len());
    for f in fab {
        let s: f64 = rows.iter().map(|&j| fb[j] * (f[j] - fa[j])).sum::<f64>() / m;
        let t: f64 = rows.iter().map(|&j| (fa[j] - f[j]).powi(2)).sum::<f64>() / (2.0 * m);
        first.push(s / var);
        total.push(t / var);
    }
    (first, total)
}

/// Sobol' indices of each parameter from `f(A)`, `f(B)` and `f(A_B^(i))`
/// (`fab[i]`), each `n` values in row order. Rows where any of the values
/// is not finite are left out. `bootstrap` resamples (seeded by `seed`)
/// give intervals at `level` (e.g. 0.95). `None` when fewer than two rows
/// remain or the outputs do not vary.
pub fn sobol_indices(
    fa: &[f64],
    fb: &[f64],
    fab: &[Vec<f64>],
    bootstrap: usize,
    level: f64,
    seed: u64,
) -> Option<Vec<SobolIndex>> {
    let n = fa.len().min(fb.len());
    let rows: Vec<usize> = (0..n)
        .filter(|&j| {
            fa[j].is_finite() && fb[j].is_finite() && fab.iter().all(|f| f.get(j).is_some_and(|x| x.is_finite()))
        })
        .collect();
    if rows.len() < 2 {
        return None;
    }
    let (first, total) = estimate(&rows, fa, fb, fab);
    if first.iter().chain(&total).any(|x| !x.is_finite()) {
        return None;
    }
    let k = fab.len();
    let mut boot_first = vec![Vec::with_capacity(bootstrap); k];
    let mut boot_total = vec![Vec::with_capacity(bootstrap); k];
    let mut rng = RngStreams::new(seed).stream("bootstrap");
    let mut resample = vec![0usize; rows.len()];
    for _ in 0..bootstrap {
        for r in resample.iter_mut() {
            *r = rows[rng.random_range(0..rows.len())];
        }
        let (f, t) = estimate(&resample, fa, fb, fab);
        for i in 0..k {
            if f[i].is_finite() && t[i].is_finite() {
                boot_first[i].push(f[i]);
                boot_total[i].push(t[i]);
            }
        }
    }
    let tail = (1.0 - level) / 2.0;
    let ci = |v: &mut Vec<f64>, point: f64| {
        if v.is_empty() {
            return (point, point);
        }
        v.sort_by(f64::total_cmp);
        (quantile(v, tail), quantile(v, 1.0 - tail))
    };
    Some(
        (0..k)
            .map(|i| SobolIndex {
                first: first[i],
                first_ci: ci(&mut boot_first[i], first[i]),
                total: total[i],
                total_ci: ci(&mut boot_total[i], total[i]),
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::sample::{Sample, SampleMethod, SampleParam, Scale};
    use std::f64::consts::PI;

    /// Ishigami and Homma (1990): `sin x1 + a sin^2 x2 + b x3^4 sin x1` on
    /// `[-pi, pi]^3`, whose indices are known in closed form.
    fn ishigami(x: &[f64]) -> f64 {
        let (a, b) = (7.0, 0.1);
        x[0].sin() + a * x[1].sin().powi(2) + b * x[2].powi(4) * x[0].sin()
    }

    fn ishigami_truth() -> ([f64; 3], [f64; 3]) {
        let (a, b) = (7.0f64, 0.1f64);
        let v1 = 0.5 * (1.0 + b * PI.powi(4) / 5.0).powi(2);
        let v2 = a * a / 8.0;
        let v13 = b * b * PI.powi(8) * (1.0 / 18.0 - 1.0 / 50.0);
        let v = v1 + v2 + v13;
        ([v1 / v, v2 / v, 0.0], [(v1 + v13) / v, v2 / v, v13 / v])
    }

    fn run(n: usize, seed: u64) -> Vec<SobolIndex> {
        let s = Sample {
            method: SampleMethod::Sobol,
            n,
            seed,
            bootstrap: 300,
            scramble: true,
            params: vec![
                SampleParam {
                    key: "x".into(),
                    from: -PI,
                    to: PI,
                    scale: Scale::Linear,
                    integer: false,
                    unit: None,
                };
                3
            ],
        };
        let f: Vec<f64> = s
            .unit_rows()
            .iter()
            .map(|r| ishigami(&r.iter().map(|&u| s.params[0].number(u)).collect::<Vec<_>>()))
            .collect();
        let fab: Vec<Vec<f64>> = (0..3).map(|i| f[(2 + i) * n..(3 + i) * n].to_vec()).collect();
        sobol_indices(&f[..n], &f[n..2 * n], &fab, s.bootstrap, 0.95, seed).unwrap()
    }

    #[test]
    fn ishigami_indices_are_recovered_with_intervals_that_cover_them() {
        let (s1, st) = ishigami_truth();
        // The closed forms: S = (0.3139, 0.4424, 0), ST = (0.5576, 0.4424, 0.2437).
        assert!((s1[0] - 0.3139).abs() < 1e-4 && (s1[1] - 0.4424).abs() < 1e-4);
        assert!((st[0] - 0.5576).abs() < 1e-4 && (st[2] - 0.2437).abs() < 1e-4);
        let idx = run(8192, 11);
        for i in 0..3 {
            assert!(
                (idx[i].first - s1[i]).abs() < 0.04,
                "S{} = {} vs {}",
                i + 1,
                idx[i].first,
                s1[i]
            );
            assert!(
                (idx[i].total - st[i]).abs() < 0.04,
                "ST{} = {} vs {}",
                i + 1,
                idx[i].total,
                st[i]
            );
            let (lo, hi) = idx[i].first_ci;
            assert!(lo <= s1[i] + 0.01 && s1[i] - 0.01 <= hi, "S{} CI {lo}..{hi}", i + 1);
            let (lo, hi) = idx[i].total_ci;
            assert!(lo <= st[i] + 0.01 && st[i] - 0.01 <= hi, "ST{} CI {lo}..{hi}", i + 1);
            assert!(idx[i].first_ci.0 <= idx[i].first && idx[i].first <= idx[i].first_ci.1);
        }
        // The ranking the function is known for: x2 first order, x1 total; x3 acts only with x1.
        assert!(idx[1].first > idx[0].first && idx[0].first > idx[2].first);
        assert!(idx[2].total > 0.15 && idx[2].first.abs() < 0.05);
    }

    #[test]
    fn intervals_narrow_with_more_rows() {
        let small = run(512, 3);
        let large = run(8192, 3);
        for i in 0..3 {
            let w = |c: (f64, f64)| c.1 - c.0;
            assert!(w(large[i].total_ci) < w(small[i].total_ci), "parameter {i}");
        }
    }

    #[test]
    fn degenerate_inputs_give_none() {
        assert!(sobol_indices(&[1.0], &[2.0], &[vec![1.0]], 10, 0.95, 1).is_none());
        assert!(sobol_indices(&[1.0, 1.0], &[1.0, 1.0], &[vec![1.0, 1.0]], 10, 0.95, 1).is_none());
        // Non-finite rows are left out.
        let r = sobol_indices(
            &[0.0, 1.0, f64::NAN],
            &[1.0, 0.0, 1.0],
            &[vec![1.0, 0.0, 2.0]],
            10,
            0.95,
            1,
        );
        assert!(r.is_some());
    }
}

/// The Sobol' analysis of one metric of a `[sample] method = "sobol"`
/// experiment.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensitivity {
    /// The metric's summary path.
    pub path: String,
    /// Its label.
    pub label: String,
    /// `(parameter key, indices)` in parameter order; `None` when the
    /// metric has fewer than two finite rows or does not vary.
    pub indices: Option<Vec<(String, SobolIndex)>>,
    /// The bar plot's base file name (`sensitivity-<metric number>`).
    pub plot: String,
}

/// The name of the indices of a metric labelled `label`: a unit the label
/// ends with (`mean display latency (ms)`) is the metric's, not the
/// indices' (shares of its variance, without a unit), and is said so.
///
/// ```
/// use rendersim::experiment::sobol::indices_title;
///
/// assert_eq!(indices_title("mean display latency (ms)"), "Sobol' indices of mean display latency (a metric in ms)");
/// assert_eq!(indices_title("repeated refresh fraction"), "Sobol' indices of repeated refresh fraction");
/// ```
pub fn indices_title(label: &str) -> String {
    match label.trim_end().strip_suffix(')').and_then(|l| l.rsplit_once(" (")) {
        Some((name, unit)) if !unit.contains('(') => format!("Sobol' indices of {name} (a metric in {unit})"),
        _ => format!("Sobol' indices of {label}"),
    }
}

/// Sobol' indices of every `[[metric]]` of `exp` from the replication means
/// of its points (empty unless `exp` samples with `method = "sobol"`).
pub(crate) fn analyse(exp: &super::spec::Experiment, results: &[super::results::PointResult]) -> Vec<Sensitivity> {
    use super::sample::SampleMethod;
    let Some(s) = exp.sample.as_ref().filter(|s| s.method == SampleMethod::Sobol) else {
        return Vec::new();
    };
    let (n, k) = (s.n, s.params.len());
    exp.metrics
        .iter()
        .enumerate()
        .map(|(mi, m)| {
            let v: Vec<f64> = results.iter().map(|r| r.mean(&m.path).unwrap_or(f64::NAN)).collect();
            let indices = (v.len() >= n * (k + 2))
                .then(|| {
                    let fab: Vec<Vec<f64>> = (0..k).map(|i| v[(2 + i) * n..(3 + i) * n].to_vec()).collect();
                    sobol_indices(&v[..n], &v[n..2 * n], &fab, s.bootstrap, exp.confidence, s.seed)
                })
                .flatten()
                .map(|idx| s.params.iter().map(|p| p.key.clone()).zip(idx).collect());
            Sensitivity {
                path: m.path.clone(),
                label: m.label.clone(),
                indices,
                plot: format!("sensitivity-{}", mi + 1),
            }
        })
        .collect()
}

/// `sensitivity.csv`: one row per metric and parameter, through the one
/// table writer ([`crate::output::table`]): a metric path or parameter key
/// holding a comma is quoted, and an index that could not be estimated
/// (NaN) is an empty cell, as in every other table.
pub(crate) fn csv(results: &[Sensitivity]) -> String {
    use crate::output::table::{number, write_table};
    const HEADER: [&str; 8] = [
        "metric",
        "parameter",
        "first_order",
        "first_order_ci_low",
        "first_order_ci_high",
        "total",
        "total_ci_low",
        "total_ci_high",
    ];
    let rows = results.iter().flat_map(|r| {
        r.indices.iter().flatten().map(|(key, i)| {
            let mut row = vec![r.path.clone(), key.clone()];
            row.extend([i.first, i.first_ci.0, i.first_ci.1, i.total, i.total_ci.0, i.total_ci.1].map(number));
            row
        })
    });
    let mut out = Vec::new();
    write_table(&mut out, &HEADER, rows).expect("writing to memory");
    String::from_utf8(out).expect("the table writer writes UTF-8")
}
