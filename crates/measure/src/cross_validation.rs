//! How well a device profile predicts passes it was not fitted to, the
//! figures `rendersim calibrate` reports beside the fit (`calibrate.rs`):
//! leave-one-out (each row predicted by a fit to the others), a fixed
//! pseudo-random half held out, k-fold cross-validation with whole meshes
//! held out (what a new user's pass is: a mesh the fit has not seen), and
//! the plain linear fit the profile must beat. Each prediction takes its
//! vertex invocations from the profile's cache policy (`predict_loads`),
//! as `rendersim predict` would; the fits take the measured ones.

use super::calibrate::{CalibrateError, MIN_ROWS, fit, nnls};
use super::device_profile::{COSTS as P, PassLoad};
use super::fit::rel_error_pct;

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
    let p = leave_one_out_ns(fit_loads, predict_loads, y)?;
    Ok(p.iter().zip(y).map(|(p, m)| rel_error_pct(*p, *m)).collect())
}

/// Leave-one-out as [`leave_one_out`], the predicted pass times (ns).
pub fn leave_one_out_ns(
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
            Ok(f.costs.cost(&predict_loads[i]).pass_ns)
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

/// Cross-validation by mesh: what a new user's pass is, a mesh the fit
/// has not seen.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFolds {
    /// Folds (at most the number of distinct meshes).
    pub folds: usize,
    /// Distinct meshes.
    pub meshes: usize,
    /// Each row's relative error (percent) when predicted by a fit to the
    /// rows of the other folds, in row order.
    pub errors: Vec<f64>,
}

/// The fold of each row for [`k_fold_by_mesh`]: the distinct meshes in
/// name order dealt round-robin into `k` folds (so the variants of one
/// mesh, which sort together, land in different folds), every row of a
/// mesh in its mesh's fold. Returns the folds used and each row's fold.
pub fn mesh_folds(meshes: &[&str], k: usize) -> (usize, Vec<usize>) {
    let names = distinct(meshes);
    let k = k.min(names.len()).max(1);
    let fold_of = |m: &str| names.binary_search(&m).map_or(0, |i| i % k);
    (k, meshes.iter().map(|m| fold_of(m)).collect())
}

/// The distinct names of `meshes`, sorted.
fn distinct<'a>(meshes: &[&'a str]) -> Vec<&'a str> {
    let mut names = meshes.to_vec();
    names.sort_unstable();
    names.dedup();
    names
}

/// K-fold cross-validation with whole meshes held out ([`mesh_folds`]):
/// each fold's rows are predicted (from `predict_loads`, the vertex counts
/// under the profile's cache policy) by a fit to the other folds' rows.
/// Needs at least two distinct meshes; a fold whose complement has too few
/// rows to fit is an error.
pub fn k_fold_by_mesh(
    fit_loads: &[PassLoad],
    predict_loads: &[PassLoad],
    y: &[f64],
    meshes: &[&str],
    k: usize,
) -> Result<MeshFolds, CalibrateError> {
    let (folds, fold) = mesh_folds(meshes, k);
    let names = distinct(meshes).len();
    if folds < 2 {
        return Err(CalibrateError::TooFewMeshes(names));
    }
    let mut errors = vec![f64::NAN; y.len()];
    for f in 0..folds {
        let (l, t): (Vec<PassLoad>, Vec<f64>) = fit_loads
            .iter()
            .zip(y)
            .zip(&fold)
            .filter(|(_, g)| **g != f)
            .map(|((l, t), _)| (*l, *t))
            .unzip();
        if l.len() < MIN_ROWS {
            let held: Vec<&str> = meshes
                .iter()
                .zip(&fold)
                .filter(|(_, g)| **g == f)
                .map(|(m, _)| *m)
                .collect();
            return Err(CalibrateError::FoldTooSmall {
                fold: f + 1,
                meshes: distinct(&held).join(", "),
                rows: l.len(),
            });
        }
        let fitted = fit(&l, &t)?;
        for i in (0..y.len()).filter(|&i| fold[i] == f) {
            errors[i] = rel_error_pct(fitted.costs.cost(&predict_loads[i]).pass_ns, y[i]);
        }
    }
    Ok(MeshFolds {
        folds,
        meshes: names,
        errors,
    })
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
    fn error_summary_orders() {
        let (m, p, w) = error_summary(&[-1.0, 2.0, -3.0, 4.0, 10.0]);
        assert_eq!((m, w), (3.0, 10.0));
        assert!(p >= 4.0);
    }

    #[test]
    fn meshes_are_dealt_into_folds_in_name_order_every_row_with_its_mesh() {
        let meshes = ["grid:8x8", "strip:4x4", "grid:8x8", "grid:2x2", "strip:4x4"];
        let (k, fold) = mesh_folds(&meshes, 2);
        assert_eq!(k, 2);
        // Sorted: grid:2x2 (fold 0), grid:8x8 (fold 1), strip:4x4 (fold 0).
        assert_eq!(fold, [1, 0, 1, 0, 0]);
        // More folds than meshes: one fold a mesh.
        assert_eq!(mesh_folds(&meshes, 10).0, 3);
    }

    #[test]
    fn the_fitted_half_is_about_half_and_fixed() {
        let n = (0..1000).filter(|&i| in_fitted_half(i)).count();
        assert!((450..=550).contains(&n), "{n}");
        assert_eq!(
            (0..16).map(in_fitted_half).collect::<Vec<_>>(),
            (0..16).map(in_fitted_half).collect::<Vec<_>>()
        );
    }
}
