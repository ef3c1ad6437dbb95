//! The rendering-time heuristics of paper 000 §5.3, their constants fitted
//! by least squares to single-object renders of the simulator (§7.2: linear
//! regression on 10,000 measurements of different objects):
//!
//! - h1 = c · triangles;
//! - h2 = c · transformed vertices;
//! - h3 = max(c1 · polygons + c2 · vertices, c3 · pixels) (Funkhouser);
//! - h4 = c1 · transformed vertices + c2 · pixels.
//!
//! Pixels are the bounding sphere's projected disk clipped to the viewport
//! (what an estimator can compute per object; see `culling.rs`). The fits
//! have no intercept, as the paper's formulas; the frame's own terms (the
//! CPU's input sampling and frame calls, clear and swap) are the measured
//! time of an empty frame, added to every estimate ("the other terms of RT
//! estimated separately", §5). Negative constants are not kept: a variable
//! whose constant comes out negative is dropped and the rest refitted. h3's
//! maximum is fitted by alternation: each sample is assigned to the branch
//! that is larger under the current constants, each branch refitted on its
//! samples, until the assignment stops changing (at most 50 rounds).

use serde::Serialize;

/// The estimators by name, in report order: the per-viewpoint five, then
/// the view-cell estimators (`view_cells.rs`): view-cell sampling and
/// per-view-cell estimation.
pub const ESTIMATORS: [&str; 7] = ["h1", "h2", "h3", "h4", "pos", "vcs", "pvc"];

/// The estimators that price one object in one view (h1-h4, pos): the
/// first five of [`ESTIMATORS`]. vcs and pvc estimate whole frames per view
/// cell, so the LOD policies and the measured estimation study use these.
pub const PER_OBJECT_ESTIMATORS: [&str; 5] = ["h1", "h2", "h3", "h4", "pos"];

/// What the heuristics read of an object in a view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Features {
    /// Triangles (h3's polygons).
    pub triangles: f64,
    /// Actually transformed vertices.
    pub transformed: f64,
    /// Distinct vertices.
    pub vertices: f64,
    /// Projected pixels (bounding disk clipped to the viewport).
    pub pixels: f64,
}

/// The fitted constants, picoseconds per unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct Constants {
    /// h1: per triangle.
    pub h1_per_triangle_ps: f64,
    /// h2: per transformed vertex.
    pub h2_per_transformed_vertex_ps: f64,
    /// h3: per polygon, per vertex, per pixel.
    pub h3_ps: [f64; 3],
    /// h4: per transformed vertex, per pixel.
    pub h4_ps: [f64; 2],
}

impl Constants {
    /// The estimate of `which` (h1..h4) for one object, picoseconds.
    #[inline]
    pub fn object(&self, which: usize, f: &Features) -> f64 {
        match which {
            0 => self.h1_per_triangle_ps * f.triangles,
            1 => self.h2_per_transformed_vertex_ps * f.transformed,
            2 => (self.h3_ps[0] * f.triangles + self.h3_ps[1] * f.vertices).max(self.h3_ps[2] * f.pixels),
            _ => self.h4_ps[0] * f.transformed + self.h4_ps[1] * f.pixels,
        }
    }
}

/// Least squares without intercept, `y ≈ X c`, with non-negative
/// constants (a variable whose constant would be negative is dropped and
/// the rest refitted). Columns of `x` are the variables. All-zero result
/// when nothing can be fitted.
pub fn nonnegative_least_squares(x: &[Vec<f64>], y: &[f64]) -> Vec<f64> {
    let k = x.len();
    let mut active: Vec<usize> = (0..k).collect();
    loop {
        let c = solve(x, y, &active);
        let mut out = vec![0.0; k];
        let mut worst: Option<(usize, f64)> = None;
        for (j, &a) in active.iter().enumerate() {
            out[a] = c[j];
            if c[j] < 0.0 && worst.is_none_or(|(_, w)| c[j] < w) {
                worst = Some((j, c[j]));
            }
        }
        match worst {
            None => return out,
            Some((j, _)) => {
                active.remove(j);
            }
        }
    }
}

/// Normal equations on the `active` columns, Gaussian elimination with
/// partial pivoting; a singular system gives zeros for the dependent
/// variables.
fn solve(x: &[Vec<f64>], y: &[f64], active: &[usize]) -> Vec<f64> {
    let k = active.len();
    let mut a = vec![vec![0.0f64; k + 1]; k];
    for (r, &i) in active.iter().enumerate() {
        for (c, &j) in active.iter().enumerate() {
            a[r][c] = x[i].iter().zip(&x[j]).map(|(p, q)| p * q).sum();
        }
        a[r][k] = x[i].iter().zip(y).map(|(p, q)| p * q).sum();
    }
    for col in 0..k {
        let piv = (col..k)
            .max_by(|&p, &q| a[p][col].abs().total_cmp(&a[q][col].abs()))
            .unwrap_or(col);
        a.swap(col, piv);
        let d = a[col][col];
        if d.abs() <= 1e-300 {
            continue;
        }
        let pivot_row = a[col].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != col {
                let f = row[col] / d;
                if f != 0.0 {
                    for (x, p) in row.iter_mut().zip(&pivot_row).skip(col) {
                        *x -= f * p;
                    }
                }
            }
        }
    }
    (0..k)
        .map(|r| if a[r][r].abs() > 1e-300 { a[r][k] / a[r][r] } else { 0.0 })
        .collect()
}

/// Fits every heuristic's constants to `samples` (features, measured
/// picoseconds).
pub fn fit(samples: &[(Features, f64)]) -> Constants {
    let col = |f: fn(&Features) -> f64| -> Vec<f64> { samples.iter().map(|(s, _)| f(s)).collect() };
    let y: Vec<f64> = samples.iter().map(|(_, y)| *y).collect();
    let tris = col(|f| f.triangles);
    let tv = col(|f| f.transformed);
    let verts = col(|f| f.vertices);
    let pix = col(|f| f.pixels);
    let h1 = nonnegative_least_squares(std::slice::from_ref(&tris), &y)[0];
    let h2 = nonnegative_least_squares(std::slice::from_ref(&tv), &y)[0];
    let h4 = nonnegative_least_squares(&[tv.clone(), pix.clone()], &y);
    // h3 by alternation.
    let g0 = nonnegative_least_squares(&[tris.clone(), verts.clone()], &y);
    let mut c = [
        g0[0],
        g0[1],
        nonnegative_least_squares(std::slice::from_ref(&pix), &y)[0],
    ];
    let mut assign: Vec<bool> = Vec::new();
    for _ in 0..50 {
        let next: Vec<bool> = (0..y.len())
            .map(|i| c[0] * tris[i] + c[1] * verts[i] >= c[2] * pix[i])
            .collect();
        if next == assign {
            break;
        }
        assign = next;
        let pick = |v: &[f64], geo: bool| -> Vec<f64> {
            v.iter()
                .zip(&assign)
                .filter(|(_, a)| **a == geo)
                .map(|(x, _)| *x)
                .collect()
        };
        if assign.iter().any(|a| *a) {
            let g = nonnegative_least_squares(&[pick(&tris, true), pick(&verts, true)], &pick(&y, true));
            c[0] = g[0];
            c[1] = g[1];
        }
        if assign.iter().any(|a| !*a) {
            c[2] = nonnegative_least_squares(&[pick(&pix, false)], &pick(&y, false))[0];
        }
    }
    Constants {
        h1_per_triangle_ps: h1,
        h2_per_transformed_vertex_ps: h2,
        h3_ps: c,
        h4_ps: [h4[0], h4[1]],
    }
}

/// How an estimator did over the walkthrough (summary
/// `metrics.estimation.<name>`).
#[derive(Debug, Clone, Serialize)]
pub struct Score {
    /// Mean of (estimate - actual)² over the frames, ms² (Table 6's value).
    pub mse_ms2: Option<f64>,
    /// Mean of estimate - actual, ms (positive: overestimates).
    pub mean_error_ms: Option<f64>,
    /// Mean of |estimate - actual|, ms.
    pub mean_abs_error_ms: Option<f64>,
    /// Share of frames whose estimate is below the actual time.
    pub underestimated_fraction: Option<f64>,
    /// Wall time to compute the estimate, microseconds per frame (machine
    /// dependent; left out of golden comparisons).
    pub cost_us_per_frame: f64,
    /// Operations per frame (objects evaluated; for pos, table entries
    /// read), deterministic.
    pub ops_per_frame: f64,
}

impl Score {
    /// The score of estimates against actual times (both ms), with the
    /// estimator's total wall seconds and operations.
    pub fn of(est: &[f64], actual: &[f64], wall_seconds: f64, ops: u64) -> Score {
        let n = est.len().min(actual.len());
        let frames = n.max(1) as f64;
        let err: Vec<f64> = est.iter().zip(actual).map(|(e, a)| e - a).collect();
        let some = |v: f64| (n > 0).then_some(v);
        Score {
            mse_ms2: some(err.iter().map(|e| e * e).sum::<f64>() / frames),
            mean_error_ms: some(err.iter().sum::<f64>() / frames),
            mean_abs_error_ms: some(err.iter().map(|e| e.abs()).sum::<f64>() / frames),
            underestimated_fraction: some(err.iter().filter(|e| **e < 0.0).count() as f64 / frames),
            cost_us_per_frame: wall_seconds * 1e6 / frames,
            ops_per_frame: ops as f64 / frames,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_recovers_constants_and_drops_negative_ones() {
        let x1: Vec<f64> = (0..50).map(|i| i as f64).collect();
        let x2: Vec<f64> = (0..50).map(|i| ((i * 7) % 13) as f64).collect();
        let y: Vec<f64> = x1.iter().zip(&x2).map(|(a, b)| 3.0 * a + 0.5 * b).collect();
        let c = nonnegative_least_squares(&[x1.clone(), x2.clone()], &y);
        assert!((c[0] - 3.0).abs() < 1e-9 && (c[1] - 0.5).abs() < 1e-9, "{c:?}");
        let y: Vec<f64> = x1.iter().zip(&x2).map(|(a, b)| 3.0 * a - 0.5 * b).collect();
        let c = nonnegative_least_squares(&[x1, x2], &y);
        assert_eq!(c[1], 0.0);
        assert!(c[0] > 0.0);
    }

    #[test]
    fn h3_alternation_recovers_a_maximum() {
        let samples: Vec<(Features, f64)> = (0..400)
            .map(|i| {
                let f = Features {
                    triangles: (i % 20 + 1) as f64 * 100.0,
                    transformed: 0.0,
                    vertices: (i % 20 + 1) as f64 * 50.0,
                    pixels: ((i * 37) % 400) as f64 * 100.0,
                };
                let y = (2.0 * f.triangles + 1.0 * f.vertices).max(0.5 * f.pixels);
                (f, y)
            })
            .collect();
        let c = fit(&samples);
        let worst = samples
            .iter()
            .map(|(f, y)| (c.object(2, f) - y).abs() / y)
            .fold(0.0f64, f64::max);
        assert!(worst < 1e-6, "{c:?} {worst}");
    }
}
