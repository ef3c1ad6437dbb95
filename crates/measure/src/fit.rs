//! Least-squares straight lines for the hypothesis studies: pass time
//! against a counter (H4: time per transformed vertex), with the coefficient
//! of determination and leave-one-out predictions, so a fitted cost is judged
//! on points it was not fitted to.
//!
//! ```
//! use rendersim_measure::fit::{fit_line, leave_one_out, rel_error_pct};
//!
//! // H4's question: what does a transformed vertex cost? Pass times (us)
//! // against transformed vertices, 2 ns a vertex over 40 us of fixed cost,
//! // with one pass measured 1% slow.
//! let vertices = [1.0e4, 2.0e4, 4.0e4, 8.0e4];
//! let time_us = [60.0, 80.0, 121.2, 200.0];
//! let f = fit_line(&vertices, &time_us).unwrap();
//! assert!((f.slope * 1e3 - 2.0).abs() < 0.02, "{} ns a vertex", f.slope * 1e3);
//! assert!(f.r_squared > 0.999);
//!
//! // Each pass predicted by the line through the other three: the error a
//! // user should expect on a pass the fit has not seen.
//! let loo = leave_one_out(&vertices, &time_us);
//! let errors: Vec<f64> = (0..4).map(|i| rel_error_pct(loo[i].unwrap().at(vertices[i]), time_us[i])).collect();
//! assert!(errors.iter().all(|e| e.abs() < 2.0), "{errors:?}");
//!
//! // All x equal: there is no slope to fit.
//! assert!(fit_line(&[3.0, 3.0], &[1.0, 2.0]).is_none());
//! ```

use serde::Serialize;

/// `y = intercept + slope * x`, fitted by ordinary least squares.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LineFit {
    /// Value at x = 0.
    pub intercept: f64,
    /// Change of y per unit of x.
    pub slope: f64,
    /// Coefficient of determination, 1 - SS_res / SS_tot (1 when y is constant
    /// and fitted exactly).
    pub r_squared: f64,
    /// Points fitted.
    pub n: usize,
}

impl LineFit {
    /// The fitted line at `x`.
    pub fn at(&self, x: f64) -> f64 {
        self.intercept + self.slope * x
    }
}

/// Fits a line through `(x[i], y[i])`. `None` with fewer than two points, a
/// length mismatch, a non-finite value, or all x equal (no slope to find).
pub fn fit_line(x: &[f64], y: &[f64]) -> Option<LineFit> {
    let n = x.len();
    if n < 2 || y.len() != n || x.iter().chain(y).any(|v| !v.is_finite()) {
        return None;
    }
    let nf = n as f64;
    let mx = x.iter().sum::<f64>() / nf;
    let my = y.iter().sum::<f64>() / nf;
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    if sxx <= f64::EPSILON * mx.abs().max(1.0) {
        return None;
    }
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let ss_tot: f64 = y.iter().map(|b| (b - my) * (b - my)).sum();
    let ss_res: f64 = x
        .iter()
        .zip(y)
        .map(|(a, b)| {
            let e = b - (intercept + slope * a);
            e * e
        })
        .sum();
    let r_squared = if ss_tot > 0.0 {
        1.0 - ss_res / ss_tot
    } else if ss_res == 0.0 {
        1.0
    } else {
        0.0
    };
    Some(LineFit {
        intercept,
        slope,
        r_squared,
        n,
    })
}

/// For every point, the line fitted to all other points (leave-one-out).
/// `None` where such a line cannot be fitted.
pub fn leave_one_out(x: &[f64], y: &[f64]) -> Vec<Option<LineFit>> {
    let others =
        |v: &[f64], i: usize| -> Vec<f64> { v.iter().enumerate().filter(|(j, _)| *j != i).map(|(_, a)| *a).collect() };
    (0..x.len().min(y.len()))
        .map(|i| fit_line(&others(x, i), &others(y, i)))
        .collect()
}

/// Relative error of `predicted` against `measured`, in percent.
pub fn rel_error_pct(predicted: f64, measured: f64) -> f64 {
    if measured == 0.0 {
        if predicted == 0.0 { 0.0 } else { f64::INFINITY }
    } else {
        100.0 * (predicted - measured) / measured
    }
}

/// Median of `v` (the upper middle for an even count); `None` when empty or
/// any value is NaN.
pub fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() || v.iter().any(|x| x.is_nan()) {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    Some(s[s.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_line_is_recovered() {
        let x = [1.0, 2.0, 4.0, 8.0];
        let y: Vec<f64> = x.iter().map(|v| 3.0 + 0.5 * v).collect();
        let f = fit_line(&x, &y).unwrap();
        assert!((f.intercept - 3.0).abs() < 1e-12 && (f.slope - 0.5).abs() < 1e-12);
        assert!((f.r_squared - 1.0).abs() < 1e-12);
        for ((f, want), xi) in leave_one_out(&x, &y).iter().zip(&y).zip(&x) {
            assert!((f.unwrap().at(*xi) - want).abs() < 1e-9);
        }
    }

    #[test]
    fn known_r_squared() {
        // By hand: mean x 1, mean y 4/3, Sxx 2, Sxy 3 -> slope 3/2, intercept -1/6;
        // residuals 1/6, -1/3, 1/6.
        let x = [0.0, 1.0, 2.0];
        let y = [0.0, 1.0, 3.0];
        let f = fit_line(&x, &y).unwrap();
        assert!((f.slope - 1.5).abs() < 1e-12);
        assert!((f.intercept - (-1.0 / 6.0)).abs() < 1e-12);
        // SS_tot = (−4/3)^2 + (−1/3)^2 + (5/3)^2 = 42/9; SS_res = 1/6.
        assert!((f.r_squared - (1.0 - (1.0 / 6.0) / (42.0 / 9.0))).abs() < 1e-12);
    }

    #[test]
    fn degenerate_inputs_give_none() {
        assert!(fit_line(&[1.0], &[2.0]).is_none());
        assert!(fit_line(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0]).is_none());
        assert!(fit_line(&[1.0, f64::NAN], &[1.0, 2.0]).is_none());
        assert!(fit_line(&[1.0, 2.0], &[1.0]).is_none());
        assert!(leave_one_out(&[1.0, 2.0], &[1.0, 2.0]).iter().all(|p| p.is_none()));
        assert_eq!(median(&[]), None);
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(rel_error_pct(0.0, 0.0), 0.0);
        assert!((rel_error_pct(11.0, 10.0) - 10.0).abs() < 1e-9);
        assert_eq!(rel_error_pct(1.0, 0.0), f64::INFINITY);
    }
}
