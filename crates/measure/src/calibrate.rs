//! Fitting a device profile (`device_profile.rs`) to measured passes: the
//! CSV rows `rendersim measure` produces (`mesh,size,vs_loops,fs_loops,
//! geometry_only,vs_invocations,fs_invocations,pass_time_ns`), each turned
//! into a [`PassLoad`] (measured vertex invocations; vertex batches from
//! the profile's cache policy; coverage counted from the mesh and target
//! size), then non-negative least squares on the relative error (Lawson and
//! Hanson's active-set method): every cost is linear once it is fixed which
//! side of `max(clear, geometry)` each row is on, and that is iterated to a
//! fixed point. Standard errors come from the covariance of the final fit.
//! How well the fit predicts rows it was not fitted to (leave-one-out, a
//! held-out half, whole meshes held out) is `cross_validation.rs`.

use std::collections::HashMap;
use std::path::Path;

use serde::Serialize;

use super::coverage::{Coverage, coverage};
use super::device_profile::{COSTS as P, DeviceCosts, FITTED as Q, PassLoad, shared_work};
use crate::components::vertex_cache::{CachePolicy, VertexCache};
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
    #[error("{0} rows are too few to fit a device profile (at least {MIN_ROWS})")]
    TooFewRows(usize),
    /// The rows repeat too few distinct passes to fit the costs.
    #[error(
        "the {rows} rows hold {distinct} distinct pass(es) (a pass measured again, with the same mesh, size, loops \
         and draws, is one pass); a fit of the profile's costs needs at least {MIN_ROWS} distinct passes"
    )]
    TooFewDistinct {
        /// Rows given.
        rows: usize,
        /// Distinct passes among them.
        distinct: usize,
    },
    /// Cross-validation by mesh needs two meshes at least.
    #[error("cross-validation by mesh needs passes of at least 2 distinct meshes; these have {0}")]
    TooFewMeshes(usize),
    /// A fold held out leaves too few rows to fit.
    #[error(
        "k-fold by mesh: holding out fold {fold} ({meshes}) leaves {rows} rows to fit, and a fit needs at least {MIN_ROWS}: measure more passes of the other meshes, or leave --kfold out"
    )]
    FoldTooSmall {
        /// The fold, 1-based.
        fold: usize,
        /// Its meshes, comma-separated.
        meshes: String,
        /// The rows left.
        rows: usize,
    },
    /// The fit gave a number that is not finite (no profile is made of it).
    #[error("the fit of {rows} rows gives {what} = {value}, not a finite number; no profile is written")]
    NotFinite {
        /// Rows fitted.
        rows: usize,
        /// What is not finite (`costs.vertex_ns`, `uncertainty.vertex_ns`, `objective`).
        what: String,
        /// Its value.
        value: f64,
    },
    /// A pass time given to the fit that is not a finite number of
    /// nanoseconds above 0.
    #[error("row {row} (0-based) has the pass time {value} ns; a fit needs finite times above 0")]
    BadTime {
        /// The row, 0-based.
        row: usize,
        /// Its time.
        value: f64,
    },
    /// The profile made of the fit breaks a rule a profile file must keep
    /// ([`super::device_profile::DeviceProfile::validate`]).
    #[error("the fitted profile has {key} = {value}: {why}; no profile is written")]
    Profile {
        /// The profile key.
        key: String,
        /// Its value.
        value: String,
        /// What it must be.
        why: String,
    },
}

pub use super::device_profile::MIN_ROWS;

/// Reads the rows of one CSV file (the one pass-CSV reader,
/// [`super::passes::read_passes`]).
pub fn read_rows(path: &Path) -> Result<Vec<PassRow>, CalibrateError> {
    Ok(super::passes::read_passes(path)?)
}

/// Where a row was read: its file and 1-based line.
pub type RowOrigin = (std::path::PathBuf, u64);

/// [`read_rows`], each row's file and line beside it, so that an error
/// found later (a mesh that cannot be built) names the row
/// ([`CalibrateError::at_row`]).
pub fn read_rows_with_origins(path: &Path) -> Result<(Vec<PassRow>, Vec<RowOrigin>), CalibrateError> {
    Ok(super::passes::read_passes_with_lines(path)?
        .into_iter()
        .map(|(r, line)| (r, (path.to_path_buf(), line)))
        .unzip())
}

impl CalibrateError {
    /// A mesh error as the CSV error of the first row that names the mesh
    /// (file, line, column 1 `mesh`); other errors unchanged. `origins` is
    /// parallel to `rows`.
    pub fn at_row(self, rows: &[PassRow], origins: &[RowOrigin]) -> CalibrateError {
        match self {
            CalibrateError::Mesh { spec, message } => match rows.iter().zip(origins).find(|(r, _)| r.mesh == spec) {
                Some((_, (path, line))) => CalibrateError::Csv(super::passes::PassCsvError::Row {
                    path: path.clone(),
                    line: *line,
                    column: 1,
                    name: "mesh".into(),
                    message,
                }),
                None => CalibrateError::Mesh { spec, message },
            },
            other => other,
        }
    }
}

/// The vertex work of one draw of a mesh under a cache policy.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct VertexWork {
    /// Vertex-shader invocations.
    pub invocations: u64,
    /// Batches (warps of up to 32 vertices): as the policy cuts them where
    /// it does (`nvidia`, `lookback:`, `batch:`, `meshopt:`), else (FIFO,
    /// LRU, direct-mapped, lavapipe) the invocations packed 32 to a warp.
    pub batches: u64,
    /// Triangles drawn.
    pub triangles: u64,
}

/// Which vertex invocations a row's load uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Invocations {
    /// The row's measured count (fitting).
    Measured,
    /// The cache policy's count (predicting, as `rendersim predict` does).
    Predicted,
}

/// Coverage and vertex work, computed once per mesh (and size).
#[derive(Default)]
pub struct LoadCache {
    coverage: HashMap<(String, u32, u32), Coverage>,
    vertices: HashMap<(String, u32), VertexWork>,
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

    /// Vertex work of one draw of `spec` under `policy`.
    pub fn vertex_work(&mut self, spec: &str, policy: &CachePolicy) -> Result<VertexWork, CalibrateError> {
        self.vertex_work_in(spec, policy, 1)
    }

    /// Vertex work of `spec` drawn in `draws` draw calls under `policy`
    /// ([`vertex_work_in_draws`]).
    pub fn vertex_work_in(
        &mut self,
        spec: &str,
        policy: &CachePolicy,
        draws: u32,
    ) -> Result<VertexWork, CalibrateError> {
        let key = (spec.to_string(), draws);
        if let Some(v) = self.vertices.get(&key) {
            return Ok(*v);
        }
        let v = vertex_work_in_draws(&mesh(spec)?, policy, draws);
        self.vertices.insert(key, v);
        Ok(v)
    }

    /// Computes the coverage and vertex work of every distinct mesh and
    /// size of `rows` at once, in parallel (rayon); later lookups hit the
    /// cache. Coverage counting dominates a calibration's time.
    pub fn prefetch(&mut self, rows: &[PassRow], policy: &CachePolicy) -> Result<(), CalibrateError> {
        use rayon::prelude::*;
        let mut keys: Vec<(String, u32, u32)> = rows
            .iter()
            .filter(|r| !r.geometry_only)
            .map(|r| (r.mesh.clone(), r.size.width, r.size.height))
            .filter(|k| !self.coverage.contains_key(k))
            .collect();
        keys.sort();
        keys.dedup();
        let mut specs: Vec<(&str, u32)> = rows
            .iter()
            .filter(|r| r.draws > 0)
            .map(|r| (r.mesh.as_str(), r.draws))
            .filter(|(m, d)| !self.vertices.contains_key(&(m.to_string(), *d)))
            .collect();
        specs.sort_unstable();
        specs.dedup();
        let covs: Vec<Coverage> = keys
            .par_iter()
            .map(|(spec, w, h)| Ok(coverage(&mesh(spec)?, spec, *w, *h)))
            .collect::<Result<_, CalibrateError>>()?;
        let works: Vec<VertexWork> = specs
            .par_iter()
            .map(|(spec, draws)| Ok(vertex_work_in_draws(&mesh(spec)?, policy, *draws)))
            .collect::<Result<_, CalibrateError>>()?;
        self.coverage.extend(keys.into_iter().zip(covs));
        self.vertices
            .extend(specs.into_iter().map(|(m, d)| (m.to_string(), d)).zip(works));
        Ok(())
    }

    /// Vertex invocations of one draw of `spec` under `policy`.
    pub fn vertices(&mut self, spec: &str, policy: &CachePolicy) -> Result<u64, CalibrateError> {
        Ok(self.vertex_work(spec, policy)?.invocations)
    }
}

/// Vertex work of one draw of `mesh` under `policy` (its triangle list).
pub fn vertex_work(mesh: &crate::scene::mesh::Mesh, policy: &CachePolicy) -> VertexWork {
    vertex_work_in_draws(mesh, policy, 1)
}

/// Vertex work of `mesh` drawn in `draws` draw calls (its triangle list
/// split in order, as `rendersim measure --draws` splits it): each draw
/// starts with an empty vertex cache and its own batches. 0 draws do no
/// work.
pub fn vertex_work_in_draws(mesh: &crate::scene::mesh::Mesh, policy: &CachePolicy, draws: u32) -> VertexWork {
    let list = mesh.to_triangle_list();
    let triangles = list.indices.len() as u64 / 3;
    let mut work = VertexWork::default();
    for k in 0..u64::from(draws) {
        let at = |k: u64| (3 * (k * triangles / u64::from(draws))) as usize;
        let mut cache = VertexCache::new(policy, list.vertex_count as usize);
        let mut invocations = 0u64;
        for t in list.indices[at(k)..at(k + 1)].chunks_exact(3) {
            invocations += u64::from(cache.access_triangle([t[0], t[1], t[2]]));
        }
        // Direct-mapped caches count their flush segments as warps; those
        // are not shader batches.
        let batches = match (policy, cache.warps()) {
            (CachePolicy::Direct { .. } | CachePolicy::Lavapipe, _) | (_, 0) => invocations.div_ceil(32),
            (_, w) => w,
        };
        work.invocations += invocations;
        work.batches += batches;
    }
    work.triangles = if draws > 0 { triangles } else { 0 };
    work
}

fn mesh(spec: &str) -> Result<crate::scene::mesh::Mesh, CalibrateError> {
    mesh_from_spec(spec, Path::new(".")).map_err(|e| CalibrateError::Mesh {
        spec: spec.to_string(),
        message: e.to_string(),
    })
}

/// The load of a row: vertex batches and triangles from `policy`, the
/// vertex invocations measured or predicted. A pass of 0 draws is its
/// target's pixels alone (its mesh and loop counts do no work).
pub fn row_load(
    row: &PassRow,
    cache: &mut LoadCache,
    policy: &CachePolicy,
    invocations: Invocations,
) -> Result<PassLoad, CalibrateError> {
    let pixels = f64::from(row.size.width) * f64::from(row.size.height);
    if row.draws == 0 {
        return Ok(PassLoad {
            pixels,
            ..PassLoad::default()
        });
    }
    let work = cache.vertex_work_in(&row.mesh, policy, row.draws)?;
    let vertices = match invocations {
        Invocations::Measured => row.vs_invocations,
        Invocations::Predicted => work.invocations,
    };
    Ok(PassLoad {
        pixels,
        draws: f64::from(row.draws),
        vertices: vertices as f64,
        vertex_batches: work.batches as f64,
        triangles: work.triangles as f64,
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
    /// The costs these passes cannot determine ([`undetermined_costs`]):
    /// their values are whatever the fit left.
    pub undetermined: Vec<&'static str>,
}

/// The linear costs (keys as in a profile) that `loads` cannot determine:
/// a cost whose column of the design is zero on every pass (nothing
/// measured exercises it), or a combination of the columns before it (it
/// cannot be told apart from them), by Gaussian elimination over the
/// columns scaled to their largest value.
///
/// ```
/// use rendersim_measure::calibrate::undetermined_costs;
///
/// // No passes: nothing is determined.
/// assert_eq!(undetermined_costs(&[]).len(), rendersim_measure::device_profile::COSTS);
/// ```
pub fn undetermined_costs(loads: &[PassLoad]) -> Vec<&'static str> {
    let mut a = plain_design(loads);
    let keys = DeviceCosts::default().entries();
    let mut free = Vec::new();
    let mut next = 0;
    for j in 0..P {
        let scale = a.iter().map(|r| r[j].abs()).fold(0.0, f64::max);
        if scale > 0.0 {
            a.iter_mut().for_each(|r| r[j] /= scale);
        }
        let best = (next..a.len()).max_by(|&x, &y| a[x][j].abs().total_cmp(&a[y][j].abs()));
        match best.filter(|&r| a[r][j].abs() > 1e-9) {
            None => free.push(keys[j].0),
            Some(r) => {
                a.swap(r, next);
                let pivot = a[next];
                for row in a.iter_mut().skip(next + 1) {
                    let f = row[j] / pivot[j];
                    if f != 0.0 {
                        for (x, p) in row.iter_mut().zip(&pivot) {
                            *x -= f * p;
                        }
                    }
                }
                next += 1;
            }
        }
    }
    free
}

/// The design rows of `loads` with both sides of `max(clear, geometry)`
/// and no overlap: every column a pass exercises.
fn plain_design(loads: &[PassLoad]) -> Vec<[f64; Q]> {
    let draws_vary = loads.iter().any(|l| l.draws != loads[0].draws);
    loads.iter().map(|l| design(l, 0, 0.0, draws_vary)).collect()
}

/// Passes among `loads` that differ in what the fit sees of them.
fn distinct_passes(loads: &[PassLoad]) -> usize {
    let mut rows: Vec<Vec<u64>> = plain_design(loads)
        .iter()
        .map(|r| r.iter().map(|x| x.to_bits()).collect())
        .collect();
    rows.sort_unstable();
    rows.dedup();
    rows.len()
}

/// Design row: the load's regressors with the clear term (side 2) or the
/// geometry terms (side 1) zeroed (side 0, the first pass, keeps both),
/// then the overlap's column: minus the row's `Gl R / (Gl + R)` under the
/// previous fit (`shared`). Without `draws_vary` the draws' column is left
/// out (0): with the same draws in every pass, a draw's cost cannot be told
/// from the pass's, and the pass overhead takes it.
fn design(l: &PassLoad, side: u8, shared: f64, draws_vary: bool) -> [f64; Q] {
    let r = l.regressors();
    let mut x: [f64; Q] = std::array::from_fn(|i| if i < P { r[i] } else { -shared });
    if !draws_vary {
        x[DRAWS] = 0.0;
    }
    match side {
        1 => x[2..=6].fill(0.0),
        2 => x[1] = 0.0,
        _ => {}
    }
    x
}

/// The draws' column in [`PassLoad::regressors`].
const DRAWS: usize = 14;

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

/// Non-negative weighted least squares of `1 = x_i . b / y_i` (Lawson and
/// Hanson's active-set method on the normal equations of unit-norm
/// columns); returns the coefficients, their standard errors and the
/// objective (sum of squared relative errors).
pub(crate) fn nnls<const N: usize>(rows: &[[f64; N]], y: &[f64]) -> ([f64; N], [f64; N], f64) {
    let mut scale = [0.0f64; N];
    for (r, yi) in rows.iter().zip(y) {
        for (s, v) in scale.iter_mut().zip(r) {
            *s += (v / yi).powi(2);
        }
    }
    let usable: Vec<bool> = scale.iter().map(|&s| s > 0.0).collect();
    for s in &mut scale {
        *s = if *s > 0.0 { s.sqrt() } else { 1.0 };
    }
    // Gram matrix and right-hand side of the scaled system.
    let (mut g, mut c) = ([[0.0f64; N]; N], [0.0f64; N]);
    for (r, yi) in rows.iter().zip(y) {
        let x: [f64; N] = std::array::from_fn(|j| r[j] / yi / scale[j]);
        for i in 0..N {
            c[i] += x[i];
            for k in 0..N {
                g[i][k] += x[i] * x[k];
            }
        }
    }
    let solve_on = |set: &[usize]| -> Option<Vec<f64>> {
        let n = set.len();
        let a: Vec<f64> = set.iter().flat_map(|&i| set.iter().map(move |&k| g[i][k])).collect();
        solve(a, set.iter().map(|&i| c[i]).collect(), n)
    };
    let mut x = [0.0f64; N];
    let mut passive: Vec<usize> = Vec::new();
    let mut excluded = [false; N];
    for _ in 0..10 * N {
        let w: [f64; N] = std::array::from_fn(|j| c[j] - (0..N).map(|k| g[j][k] * x[k]).sum::<f64>());
        let Some(j) = (0..N)
            .filter(|&j| usable[j] && !excluded[j] && !passive.contains(&j) && w[j] > 1e-10)
            .max_by(|&a, &b| w[a].total_cmp(&w[b]))
        else {
            break;
        };
        passive.push(j);
        loop {
            let Some(sol) = solve_on(&passive) else {
                // Dependent on the columns already in: leave it out.
                passive.retain(|&k| k != j);
                excluded[j] = true;
                break;
            };
            if sol.iter().all(|&v| v > 0.0) {
                for (&k, v) in passive.iter().zip(&sol) {
                    x[k] = *v;
                }
                break;
            }
            let alpha = passive
                .iter()
                .zip(&sol)
                .filter(|(_, s)| **s <= 0.0)
                .map(|(&k, s)| x[k] / (x[k] - s))
                .fold(f64::INFINITY, f64::min);
            for (&k, s) in passive.iter().zip(&sol) {
                x[k] += alpha * (s - x[k]);
            }
            passive.retain(|&k| {
                if x[k] <= 1e-15 {
                    x[k] = 0.0;
                    false
                } else {
                    true
                }
            });
        }
    }
    let beta: [f64; N] = std::array::from_fn(|j| x[j] / scale[j]);
    let obj: f64 = rows
        .iter()
        .zip(y)
        .map(|(r, yi)| {
            let p: f64 = r.iter().zip(&beta).map(|(a, b)| a * b).sum();
            (p / yi - 1.0).powi(2)
        })
        .sum();
    let n = passive.len();
    let s2 = obj / rows.len().saturating_sub(n).max(1) as f64;
    let mut se = [0.0; N];
    let a: Vec<f64> = passive
        .iter()
        .flat_map(|&i| passive.iter().map(move |&k| g[i][k]))
        .collect();
    for (i, &j) in passive.iter().enumerate() {
        let mut e = vec![0.0; n];
        e[i] = 1.0;
        if let Some(col) = solve(a.clone(), e, n) {
            se[j] = (s2 * col[i]).max(0.0).sqrt() / scale[j];
        }
    }
    (beta, se, obj)
}

/// Costs from a fitted vector: the linear costs, then the overlap (held
/// to at most 1, as a profile must).
fn costs_of(b: &[f64; Q]) -> DeviceCosts {
    let mut c = DeviceCosts::from_array(&std::array::from_fn(|i| b[i]));
    c.shared_core_overlap = b[P].min(1.0);
    c
}

/// Sum of squared relative errors of `costs` on the rows (the cost
/// formula itself, overlap included).
fn objective(costs: &DeviceCosts, loads: &[PassLoad], y: &[f64]) -> f64 {
    loads
        .iter()
        .zip(y)
        .map(|(l, t)| (costs.cost(l).pass_ns / t - 1.0).powi(2))
        .sum()
}

/// The linear fit with each row's overlap work fixed (`shared`): which
/// side of `max(clear, geometry)` each row is on is iterated to a fixed
/// point (starting from both terms summed), keeping the best fit visited.
fn fit_sides(loads: &[PassLoad], y: &[f64], shared: &[f64]) -> Option<([f64; Q], [f64; Q])> {
    let draws_vary = loads.iter().any(|l| l.draws != loads[0].draws);
    let mut side = vec![0u8; loads.len()];
    let mut best: Option<([f64; Q], [f64; Q], f64)> = None;
    for _ in 0..12 {
        let rows: Vec<[f64; Q]> = loads
            .iter()
            .zip(&side)
            .zip(shared)
            .map(|((l, s), h)| design(l, *s, *h, draws_vary))
            .collect();
        let (b, se, obj) = nnls(&rows, y);
        let c = costs_of(&b);
        let next: Vec<u8> = loads
            .iter()
            .map(|l| {
                let k = c.cost(l);
                if k.clear_ns > k.geometry_ns { 1 } else { 2 }
            })
            .collect();
        let done = next == side;
        if !side.contains(&0) && best.as_ref().is_none_or(|(_, _, o)| obj < *o) {
            best = Some((b, se, obj));
        }
        side = next;
        if done {
            break;
        }
    }
    best.map(|(b, se, _)| (b, se))
}

/// Rounds of [`fit`]'s outer loop (the overlap's work taken from the
/// previous round's costs); it settles in a few on the H200 rows.
const OVERLAP_ROUNDS: usize = 12;

/// Fits a profile's costs to `loads` measured at `y` ns. The first round
/// fits the linear costs alone (`fit_sides`); each later round gives the
/// overlap term the `Gl R / (Gl + R)` of every row under the previous round's
/// costs and fits again, until the overlap settles. The round with the
/// smallest sum of squared relative errors (the whole formula) is kept, so
/// the overlap is never worse on the fitted rows than leaving it out.
pub fn fit(loads: &[PassLoad], y: &[f64]) -> Result<Fit, CalibrateError> {
    if loads.len() < MIN_ROWS {
        return Err(CalibrateError::TooFewRows(loads.len()));
    }
    let distinct = distinct_passes(loads);
    if distinct < MIN_ROWS {
        return Err(CalibrateError::TooFewDistinct {
            rows: loads.len(),
            distinct,
        });
    }
    if let Some((row, &value)) = y.iter().enumerate().find(|(_, t)| !t.is_finite() || **t <= 0.0) {
        return Err(CalibrateError::BadTime { row, value });
    }
    let mut shared = vec![0.0; loads.len()];
    let mut best: Option<(DeviceCosts, [f64; Q], f64)> = None;
    let mut last_overlap = f64::NAN;
    for _ in 0..OVERLAP_ROUNDS {
        let Some((b, se)) = fit_sides(loads, y, &shared) else {
            break;
        };
        let c = costs_of(&b);
        let obj = objective(&c, loads, y);
        if best.as_ref().is_none_or(|(_, _, o)| obj < *o) {
            best = Some((c, se, obj));
        }
        if (c.shared_core_overlap - last_overlap).abs() <= 1e-6 {
            break;
        }
        last_overlap = c.shared_core_overlap;
        for (h, l) in shared.iter_mut().zip(loads) {
            let k = c.cost(l);
            *h = shared_work(k.vertex_loop_ns, k.fragment_ns);
        }
    }
    let (costs, se, objective) = best.unwrap_or((DeviceCosts::default(), [0.0; Q], f64::INFINITY));
    check_finite(&costs, &se, objective, loads.len())?;
    Ok(Fit {
        costs,
        std_errors: costs
            .entries()
            .iter()
            .zip(se)
            .map(|((k, _), s)| (k.to_string(), s))
            .collect(),
        objective,
        undetermined: undetermined_costs(loads),
    })
}

/// A fit whose numbers are not finite (a load or time beyond what f64
/// sums) is an error, never a profile.
fn check_finite(costs: &DeviceCosts, se: &[f64; Q], objective: f64, rows: usize) -> Result<(), CalibrateError> {
    let not_finite = |what: String, value: f64| CalibrateError::NotFinite { rows, what, value };
    for ((key, v), s) in costs.entries().iter().zip(se) {
        if !v.is_finite() {
            return Err(not_finite(format!("costs.{key}"), *v));
        }
        if !s.is_finite() {
            return Err(not_finite(format!("uncertainty.{key}"), *s));
        }
    }
    if !objective.is_finite() {
        return Err(not_finite("objective".into(), objective));
    }
    Ok(())
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

    fn synthetic() -> (Vec<PassLoad>, Vec<f64>) {
        let loads: Vec<PassLoad> = (1..=20)
            .map(|i| PassLoad {
                pixels: 4096.0 * f64::from(i),
                draws: 1.0,
                vertices: 81.0 * f64::from(i % 5 + 1),
                vertex_batches: 3.0,
                triangles: 128.0,
                vs_loops: f64::from(i % 3),
                fs_loops: f64::from(i % 4),
                coverage: Coverage {
                    fragments: 4096,
                    quads: 1024,
                    warps: 128,
                    triangles: 128,
                    drawn_triangles: 128,
                    ..Coverage::default()
                },
            })
            .collect();
        let y = loads.iter().map(|l| 1000.0 + l.pixels * 0.5 + l.vertices).collect();
        (loads, y)
    }

    #[test]
    fn a_fit_refuses_bad_times_and_never_returns_non_finite_costs() {
        let (loads, y) = synthetic();
        let f = fit(&loads, &y).unwrap();
        assert!(f.costs.to_array().iter().all(|c| c.is_finite()) && f.objective.is_finite());
        for bad in [f64::NAN, f64::INFINITY, -1.0, 0.0] {
            let mut t = y.clone();
            t[3] = bad;
            let e = fit(&loads, &t).unwrap_err();
            assert!(matches!(e, CalibrateError::BadTime { row: 3, .. }), "{bad}: {e}");
        }
        // Loads beyond what f64 sums give an error or finite costs, never
        // a profile of NaN.
        for (i, big) in [f64::INFINITY, f64::MAX, 1e300].into_iter().enumerate() {
            let mut huge = loads.clone();
            huge[i].pixels = big;
            huge[i + 1].vertices = big;
            huge[i + 2].fs_loops = big;
            if let Ok(f) = fit(&huge, &y) {
                assert!(f.costs.to_array().iter().all(|c| c.is_finite()), "{f:?}");
                assert!(f.objective.is_finite(), "{f:?}");
            }
        }
        // The guard itself.
        let ok = DeviceCosts::from_array(&[1.0; P]);
        assert!(check_finite(&ok, &[0.5; Q], 1.0, 20).is_ok());
        let mut b = [1.0; P];
        b[2] = f64::NAN;
        let e = check_finite(&DeviceCosts::from_array(&b), &[0.5; Q], 1.0, 20).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the fit of 20 rows gives costs.vertex_ns = NaN, not a finite number; no profile is written"
        );
        let mut se = [0.5; Q];
        se[13] = f64::INFINITY;
        let e = check_finite(&ok, &se, 1.0, 20).unwrap_err().to_string();
        assert!(e.contains("uncertainty.fragment_loop_latency_ns = inf"), "{e}");
        let mut se = [0.5; Q];
        se[P] = f64::NAN;
        let e = check_finite(&ok, &se, 1.0, 20).unwrap_err().to_string();
        assert!(e.contains("uncertainty.shared_core_overlap = NaN"), "{e}");
        let e = check_finite(&ok, &[0.5; Q], f64::NAN, 20).unwrap_err().to_string();
        assert!(e.contains("objective = NaN"), "{e}");
    }
}
