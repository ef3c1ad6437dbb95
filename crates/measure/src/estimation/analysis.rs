//! The estimation study's analysis (paper 000 §5.1-5.2, Table 6): the
//! walkthrough's least squares on the single-object passes, a pos table per
//! prototype from its table passes, every estimator scored on the
//! multi-object passes with its own run time beside measuring's.

use std::collections::BTreeMap;
use std::time::Instant;

use serde::Serialize;

use crate::fit::median;
use crate::systems::walkthrough::estimators::{Constants, Features, PER_OBJECT_ESTIMATORS, Score, fit};

use super::{
    EstimationError, EstimationSetup, ObjectDraw, PassKind, PassMeasurement, Plan, PlannedPass, PosEntry, Prototype,
    pos_lookup,
};

/// A prototype with what was measured of it.
#[derive(Debug, Clone, Serialize)]
pub struct PrototypeResult {
    /// The prototype.
    #[serde(flatten)]
    pub prototype: Prototype,
    /// Vertex-shader invocations of one draw (its table passes).
    pub transformed: u64,
    /// Its pos table, by pixels.
    pub pos_table: Vec<PosEntry>,
}

/// Passes measured, by kind.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct PassCounts {
    /// Empty passes.
    pub overhead: usize,
    /// Table passes.
    pub pos: usize,
    /// Single-object passes.
    pub single: usize,
    /// Multi-object passes.
    pub multi: usize,
    /// Objects drawn in the multi-object passes.
    pub multi_objects: usize,
}

/// Wall times, error against run time.
#[derive(Debug, Clone, Serialize)]
pub struct EstimationTiming {
    /// Wall time of all measuring (device set-up excluded), s.
    pub measure_wall_s: f64,
    /// Of which, per kind of pass, s (`overhead`, `pos`, `single`, `multi`).
    pub wall_s_by_kind: BTreeMap<String, f64>,
    /// Mean GPU time of a multi-object pass (timestamps), ms.
    pub multi_gpu_ms_mean: f64,
    /// Wall time of measuring one multi-object pass once (one round), ms.
    pub multi_measure_ms_per_pass: f64,
    /// Squared error of one round's time against the pass's median over
    /// the multi-object passes, ms² (what measuring once costs in error).
    pub measure_once_mse_ms2: f64,
    /// Wall time of the least-squares fit, ms.
    pub fit_wall_ms: f64,
}

/// Consistency checks of the counters.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct EstimationChecks {
    /// Passes whose counters differed between rounds.
    pub unstable_counters: usize,
    /// Multi-object passes whose vertex-shader invocations differ from the
    /// sum of their objects' prototype counts.
    pub transformed_sum_mismatches: usize,
    /// Table passes whose vertex-shader invocations differ from their
    /// prototype's first table pass.
    pub transformed_table_mismatches: usize,
}

/// The study's result (`rendersim study estimation --json`).
#[derive(Debug, Clone, Serialize)]
pub struct EstimationStudy {
    /// The adapter.
    pub adapter: String,
    /// The command that produced it.
    pub command: String,
    /// The setup.
    pub setup: EstimationSetup,
    /// The heuristics' pixel input.
    pub pixels: String,
    /// How pos is read here.
    pub pos_reading: String,
    /// Passes measured.
    pub passes: PassCounts,
    /// Median time of an empty pass, ms (added once to every estimate).
    pub overhead_ms: f64,
    /// The fitted constants, picoseconds per unit (the walkthrough's).
    pub constants: Constants,
    /// Each estimator on the single-object passes (in-sample for h1-h4).
    pub fit: BTreeMap<String, Score>,
    /// Each estimator on the multi-object passes (Table 6's columns).
    pub scores: BTreeMap<String, Score>,
    /// The estimator with the least squared error on the multi-object passes.
    pub best: String,
    /// Wall times.
    pub timing: EstimationTiming,
    /// Counter checks.
    pub checks: EstimationChecks,
    /// The prototypes with their counts and tables.
    pub prototypes: Vec<PrototypeResult>,
    /// Notes on the adapter (a software rasterizer's times vary with load).
    pub notes: String,
}

const PIXELS: &str =
    "projected bounding square clipped to the render target (known before drawing; not covered pixels)";
const POS_READING: &str = "a table per prototype (mesh + shader loads) over its projected size, sampled centred at \
                           pos_sizes sides log-spaced from min_side to the target, interpolated linearly in pixels";

/// The estimates of one object by each estimator (h1, h2, h3, h4, pos), ms
/// without the pass overhead; `reads` counts pos table reads.
fn object_ms(c: &Constants, protos: &[PrototypeResult], o: &ObjectDraw, target: [u32; 2], reads: &mut u64) -> [f64; 5] {
    let p = &protos[o.prototype];
    let f = Features {
        triangles: p.prototype.triangles as f64,
        transformed: p.transformed as f64,
        vertices: p.prototype.vertices as f64,
        pixels: o.pixels(target),
    };
    let h = |k| c.object(k, &f) / 1e9;
    [h(0), h(1), h(2), h(3), pos_lookup(&p.pos_table, f.pixels, reads)]
}

impl EstimationStudy {
    /// Every estimator's estimate of a whole pass (overhead included), ms.
    pub fn pass_ms(&self, plan: &Plan, pass: &PlannedPass) -> [f64; 5] {
        let mut out = [self.overhead_ms; 5];
        let mut reads = 0;
        for o in &pass.objects {
            for (x, e) in out.iter_mut().zip(object_ms(
                &self.constants,
                &self.prototypes,
                o,
                plan.setup.target,
                &mut reads,
            )) {
                *x += e;
            }
        }
        out
    }

    /// Each estimator's estimate of each object of a pass (overhead
    /// excluded), ms.
    pub fn objects_ms(&self, plan: &Plan, pass: &PlannedPass) -> Vec<[f64; 5]> {
        let mut reads = 0;
        pass.objects
            .iter()
            .map(|o| object_ms(&self.constants, &self.prototypes, o, plan.setup.target, &mut reads))
            .collect()
    }

    /// One line: the best estimator and its error, the measuring cost.
    pub fn verdict(&self) -> String {
        let s = &self.scores[&self.best];
        format!(
            "{} estimates {} multi-object passes best: squared error {} ms², mean error {:+.3} ms, {:.0}% underestimated, \
             {:.2} µs per pass to estimate against {:.2} ms to measure",
            self.best,
            self.passes.multi,
            sig(s.mse_ms2.unwrap_or(f64::NAN)),
            s.mean_error_ms.unwrap_or(f64::NAN),
            100.0 * s.underestimated_fraction.unwrap_or(f64::NAN),
            s.cost_us_per_frame,
            self.timing.multi_measure_ms_per_pass
        )
    }
}

/// Four significant digits.
pub(super) fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = (3 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.digits$}")
}

/// Times computing every pass's estimates with estimator `which`: seconds
/// for one sweep over `passes` (repeated until at least 2 ms elapsed) and
/// the operations of one sweep (objects evaluated; pos: table reads).
fn time_estimator(study: &EstimationStudy, plan: &Plan, passes: &[&PlannedPass], which: usize) -> (f64, u64) {
    let target = plan.setup.target;
    let sweep = |reads: &mut u64| -> f64 {
        let mut total = 0.0;
        for p in passes {
            let mut t = study.overhead_ms;
            for o in &p.objects {
                let obj = &study.prototypes[o.prototype];
                t += if which == 4 {
                    pos_lookup(&obj.pos_table, o.pixels(target), reads)
                } else {
                    *reads += 1;
                    let f = Features {
                        triangles: obj.prototype.triangles as f64,
                        transformed: obj.transformed as f64,
                        vertices: obj.prototype.vertices as f64,
                        pixels: o.pixels(target),
                    };
                    study.constants.object(which, &f) / 1e9
                };
            }
            total += std::hint::black_box(t);
        }
        total
    };
    let mut ops = 0;
    std::hint::black_box(sweep(&mut ops));
    let start = Instant::now();
    let mut sweeps = 0u32;
    while sweeps == 0 || (start.elapsed().as_secs_f64() < 2e-3 && sweeps < 100_000) {
        let mut r = 0;
        std::hint::black_box(sweep(&mut r));
        sweeps += 1;
    }
    (start.elapsed().as_secs_f64() / f64::from(sweeps), ops)
}

/// Fits and scores the estimators on measured passes: `measured[i]` is
/// `plan.passes[i]`; `measure_wall_s` the wall time of all measuring.
pub fn analyze(
    plan: &Plan,
    measured: &[PassMeasurement],
    adapter: &str,
    command: &str,
    measure_wall_s: f64,
) -> Result<EstimationStudy, EstimationError> {
    if measured.len() != plan.passes.len() {
        return Err(EstimationError::Measurements(format!(
            "{} measurements for {} planned passes",
            measured.len(),
            plan.passes.len()
        )));
    }
    let setup = &plan.setup;
    let of_kind = |k: PassKind| -> Vec<(&PlannedPass, &PassMeasurement)> {
        plan.passes.iter().zip(measured).filter(|(p, _)| p.kind == k).collect()
    };
    let overhead: Vec<f64> = of_kind(PassKind::Overhead).iter().map(|(_, m)| m.time_ns).collect();
    let overhead_ns = median(&overhead)
        .ok_or_else(|| EstimationError::Measurements("no empty pass was measured (or a time is NaN)".into()))?;
    let mut checks = EstimationChecks {
        unstable_counters: measured.iter().filter(|m| !m.stable).count(),
        ..EstimationChecks::default()
    };
    let prototypes = prototype_tables(plan, &of_kind(PassKind::Pos), overhead_ns, &mut checks);
    // The fit on the single-object passes (picoseconds).
    let single = of_kind(PassKind::Single);
    let samples = fit_samples(plan, &single, overhead_ns);
    let t = Instant::now();
    let constants = fit(&samples);
    let fit_wall_ms = t.elapsed().as_secs_f64() * 1e3;
    let multi = of_kind(PassKind::Multi);
    for (p, m) in &multi {
        let sum: u64 = p.objects.iter().map(|o| prototypes[o.prototype].transformed).sum();
        if sum != m.vs_invocations {
            checks.transformed_sum_mismatches += 1;
        }
    }
    let mut study = EstimationStudy {
        adapter: adapter.to_string(),
        command: command.to_string(),
        setup: setup.clone(),
        pixels: PIXELS.into(),
        pos_reading: POS_READING.into(),
        passes: PassCounts {
            overhead: overhead.len(),
            pos: of_kind(PassKind::Pos).len(),
            single: single.len(),
            multi: multi.len(),
            multi_objects: multi.iter().map(|(p, _)| p.objects.len()).sum(),
        },
        overhead_ms: overhead_ns / 1e6,
        constants,
        fit: BTreeMap::new(),
        scores: BTreeMap::new(),
        best: String::new(),
        timing: EstimationTiming {
            measure_wall_s,
            wall_s_by_kind: BTreeMap::new(),
            multi_gpu_ms_mean: 0.0,
            multi_measure_ms_per_pass: 0.0,
            measure_once_mse_ms2: 0.0,
            fit_wall_ms,
        },
        checks,
        prototypes,
        notes: String::new(),
    };
    score_estimators(&mut study, plan, &single, &multi);
    for kind in [PassKind::Overhead, PassKind::Pos, PassKind::Single, PassKind::Multi] {
        let wall = of_kind(kind).iter().map(|(_, m)| m.wall_s).sum();
        study.timing.wall_s_by_kind.insert(kind.name().to_string(), wall);
    }
    let n = multi.len().max(1) as f64;
    let rounds = f64::from(setup.repeats.max(1));
    study.timing.multi_gpu_ms_mean = multi.iter().map(|(_, m)| m.time_ns / 1e6).sum::<f64>() / n;
    study.timing.multi_measure_ms_per_pass = study.timing.wall_s_by_kind["multi"] * 1e3 / n / rounds;
    let (mut se, mut count) = (0.0, 0usize);
    for (_, m) in &multi {
        for t in &m.times_ns {
            se += ((t - m.time_ns) / 1e6).powi(2);
            count += 1;
        }
    }
    study.timing.measure_once_mse_ms2 = se / count.max(1) as f64;
    Ok(study)
}

/// Measured passes with what was planned for each.
type Measured<'a> = [(&'a PlannedPass, &'a PassMeasurement)];

/// Each prototype's pos table (milliseconds beyond the empty pass's
/// `overhead_ns`, by pixels) and transformed vertices, from its `pos`
/// passes; counts in `checks` the passes whose transformed vertices differ
/// from the prototype's first.
fn prototype_tables(
    plan: &Plan,
    pos: &Measured,
    overhead_ns: f64,
    checks: &mut EstimationChecks,
) -> Vec<PrototypeResult> {
    let mut prototypes: Vec<PrototypeResult> = plan
        .prototypes
        .iter()
        .map(|p| PrototypeResult {
            prototype: p.clone(),
            transformed: 0,
            pos_table: Vec::new(),
        })
        .collect();
    let mut seen = vec![false; prototypes.len()];
    for &(p, m) in pos {
        let o = &p.objects[0];
        let r = &mut prototypes[o.prototype];
        if !seen[o.prototype] {
            seen[o.prototype] = true;
            r.transformed = m.vs_invocations;
        } else if r.transformed != m.vs_invocations {
            checks.transformed_table_mismatches += 1;
        }
        r.pos_table.push(PosEntry {
            pixels: o.pixels(plan.setup.target),
            ms: (m.time_ns - overhead_ns) / 1e6,
        });
    }
    for r in &mut prototypes {
        r.pos_table.sort_by(|a, b| a.pixels.total_cmp(&b.pixels));
    }
    prototypes
}

/// The fit's samples from the `single`-object passes: each object's
/// features and its time (picoseconds) beyond the empty pass's `overhead_ns`.
fn fit_samples(plan: &Plan, single: &Measured, overhead_ns: f64) -> Vec<(Features, f64)> {
    single
        .iter()
        .map(|(p, m)| {
            let o = &p.objects[0];
            let proto = &plan.prototypes[o.prototype];
            let f = Features {
                triangles: proto.triangles as f64,
                transformed: m.vs_invocations as f64,
                vertices: proto.vertices as f64,
                pixels: o.pixels(plan.setup.target),
            };
            (f, (m.time_ns - overhead_ns) * 1e3)
        })
        .collect()
}

/// Scores every per-object estimator on the `single` passes (the fit, in
/// `study.fit`) and the `multi` passes (`study.scores`), and names the
/// best on the latter (least mse).
fn score_estimators(study: &mut EstimationStudy, plan: &Plan, single: &Measured, multi: &Measured) {
    for (name, set) in [("single", single), ("multi", multi)] {
        let passes: Vec<&PlannedPass> = set.iter().map(|(p, _)| *p).collect();
        let actual: Vec<f64> = set.iter().map(|(_, m)| m.time_ns / 1e6).collect();
        let estimates: Vec<[f64; 5]> = passes.iter().map(|p| study.pass_ms(plan, p)).collect();
        let mut scores = BTreeMap::new();
        for (k, est_name) in PER_OBJECT_ESTIMATORS.iter().enumerate() {
            let est: Vec<f64> = estimates.iter().map(|e| e[k]).collect();
            let (secs, ops) = time_estimator(study, plan, &passes, k);
            scores.insert(est_name.to_string(), Score::of(&est, &actual, secs, ops));
        }
        if name == "single" {
            study.fit = scores;
        } else {
            study.scores = scores;
        }
    }
    study.best = study
        .scores
        .iter()
        .filter_map(|(n, s)| Some((n, s.mse_ms2?)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(n, _)| n.clone())
        .unwrap_or_default();
}
