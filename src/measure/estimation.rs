//! Rendering-time estimation checked on a device (issue 11 item 8; paper 000
//! §5 and §6.1-6.2): the heuristics h1-h4 and per-object sampling (pos) of
//! the walkthrough system, fitted to and scored on passes measured with
//! timestamp queries instead of simulated frames.
//!
//! - **Objects.** A handful of prototypes, each a mesh from the generators
//!   (`grid:`, `grid:..:shuffled:`, `grid:..:optimized`, `strip:`,
//!   `random:`) with its own vertex and fragment shader loads (ALU loop
//!   counts: a material), drawn as a square on the render target whose side
//!   and centre vary (so pixel counts vary; an object may hang over the
//!   edge, at least a quarter of it stays on the target).
//! - **Heuristic inputs** (paper 000 §5.1): triangles; transformed vertices
//!   = the vertex-shader invocations of a pipeline-statistics query (of the
//!   pass itself for a single-object pass; of the prototype's table passes
//!   for each object of a multi-object pass, whose counter is checked to be
//!   their sum); distinct vertices; **pixels = the projected bounding
//!   square clipped to the target** (known before drawing, as the paper's
//!   projected bounding volume; not the covered pixels, which only the draw
//!   knows, and not lavapipe's fragment counter, which counts 4x4 blocks).
//! - **Pass overhead.** Every pass clears the target; the median time of
//!   empty passes is subtracted from every single-object time before
//!   fitting and tabulating, and added once to every estimate of a pass,
//!   for all estimators alike (the paper's constants have no intercept).
//! - **Fit** (paper 000 §5.1): the walkthrough's least squares
//!   ([`crate::systems::walkthrough::estimators::fit`]) on the single-object
//!   passes at random sizes, positions and prototypes.
//! - **pos** (paper 000 §5.2), this reading: a table per prototype over its
//!   projected size, the analogue of α (a flat object drawn face-on has no
//!   γ or φ; its material is part of the prototype as a shader is part of
//!   an object), sampled in a preprocess by drawing the prototype alone,
//!   centred, at `pos_sizes` sides log-spaced from `min_side` to the
//!   target; a lookup interpolates linearly in the clipped pixel count
//!   (exact for a cost linear in pixels), extrapolates the first segment
//!   below the smallest sample (not below zero) and holds the last value
//!   above the largest. No pruning (one axis).
//! - **Scores** (paper 000 Table 6): on multi-object passes (several objects
//!   drawn in one render pass, each object's estimate summed), the
//!   walkthrough's [`Score`]: squared error (ms²), mean error, share
//!   underestimated, and the estimator's own run time per pass beside the
//!   wall time of measuring a pass (error against run time).
//!
//! Everything here is plain code compiled in every build and tested on
//! synthetic passes; `estimation_device.rs` measures the plan on a device.

use std::collections::BTreeMap;
use std::time::Instant;

use rand::Rng;
use rand::seq::SliceRandom;
use serde::Serialize;

use crate::engine::RngStreams;
use crate::scene::generators::mesh_from_spec;
use crate::scene::mesh::Mesh;
use crate::systems::walkthrough::estimators::{Constants, ESTIMATORS, Features, Score, fit};

use super::fit::median;

/// Errors of the estimation study's setup and analysis.
#[derive(Debug, thiserror::Error)]
pub enum EstimationError {
    /// A setup value out of range.
    #[error("{0}")]
    Setup(String),
    /// A prototype's mesh could not be built.
    #[error("estimation mesh {spec}: {message}")]
    Mesh {
        /// The spec.
        spec: String,
        /// Why.
        message: String,
    },
    /// The measurements do not match the plan.
    #[error("{0}")]
    Measurements(String),
}

/// What the study draws and how often.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EstimationSetup {
    /// Master seed of the pass generator (streams `estimation.prototypes`,
    /// `estimation.single`, `estimation.multi`, `estimation.order`).
    pub seed: u64,
    /// Single-object passes (the fit).
    pub single: usize,
    /// Multi-object passes (the scores).
    pub multi: usize,
    /// Object prototypes (mesh and shader loads).
    pub prototypes: usize,
    /// Objects per multi-object pass, least and most.
    pub objects_per_pass: [usize; 2],
    /// Table entries per prototype (pos).
    pub pos_sizes: usize,
    /// Empty passes (the pass overhead).
    pub overhead_passes: usize,
    /// Smallest side of a drawn object, pixels.
    pub min_side: f64,
    /// Render target width and height, pixels.
    pub target: [u32; 2],
    /// Recorded rounds of every pass (interleaved; the median is used).
    pub repeats: u32,
    /// Multiplies every prototype's loop counts (a GPU needs more shader work
    /// than lavapipe for the same times).
    pub load_scale: f64,
    /// Most vertex-shader loop iterations of a prototype, before scaling.
    pub max_vs_loops: u32,
    /// Most fragment-shader loop iterations of a prototype, before scaling.
    pub max_fs_loops: u32,
}

impl Default for EstimationSetup {
    fn default() -> Self {
        EstimationSetup {
            seed: 1,
            single: 1000,
            multi: 300,
            prototypes: 16,
            objects_per_pass: [2, 8],
            pos_sizes: 6,
            overhead_passes: 16,
            min_side: 8.0,
            target: [256, 256],
            repeats: 5,
            load_scale: 1.0,
            max_vs_loops: 300,
            max_fs_loops: 30,
        }
    }
}

impl EstimationSetup {
    /// Checks every value; the error names the option.
    pub fn validate(&self) -> Result<(), EstimationError> {
        let bad = |m: String| Err(EstimationError::Setup(m));
        if self.single == 0 {
            return bad("--single must be at least 1 (single-object passes to fit the constants to)".into());
        }
        if self.multi == 0 {
            return bad("--multi must be at least 1 (multi-object passes to score the estimators on)".into());
        }
        if self.repeats == 0 {
            return bad("--repeats must be at least 1".into());
        }
        if !(self.load_scale.is_finite() && self.load_scale > 0.0) {
            return bad(format!(
                "--load-scale must be a positive number, not {}",
                self.load_scale
            ));
        }
        if self.prototypes == 0 || self.pos_sizes < 2 || self.overhead_passes == 0 {
            return bad("prototypes and overhead passes must be at least 1, pos sizes at least 2".into());
        }
        let [lo, hi] = self.objects_per_pass;
        if lo == 0 || lo > hi {
            return bad(format!("objects per pass {lo}..{hi}: need 1 <= least <= most"));
        }
        let [w, h] = self.target;
        if w == 0 || h == 0 || w > 8192 || h > 8192 {
            return bad(format!("render target {w}x{h}: each side 1..8192"));
        }
        if !(self.min_side >= 1.0 && self.min_side <= f64::from(w.min(h))) {
            return bad(format!(
                "smallest object side {} outside 1..{}",
                self.min_side,
                w.min(h)
            ));
        }
        let most = |l: u32| f64::from(l) * self.load_scale;
        if most(self.max_vs_loops) > f64::from(super::loops::MAX_LOOPS)
            || most(self.max_fs_loops) > f64::from(super::loops::MAX_LOOPS)
        {
            return bad(format!(
                "--load-scale {} makes loop counts above {}",
                self.load_scale,
                super::loops::MAX_LOOPS
            ));
        }
        Ok(())
    }

    /// The largest object side: the target's shorter side.
    pub fn max_side(&self) -> f64 {
        f64::from(self.target[0].min(self.target[1]))
    }

    /// The table's sides: `pos_sizes` log-spaced from `min_side` to the
    /// largest side.
    pub fn pos_sides(&self) -> Vec<f64> {
        let (lo, hi) = (self.min_side.ln(), self.max_side().ln());
        let n = self.pos_sizes.max(2);
        (0..n)
            .map(|k| (lo + (hi - lo) * k as f64 / (n - 1) as f64).exp())
            .collect()
    }
}

/// An object prototype: a mesh and its shader loads.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Prototype {
    /// `p00`, `p01`, ...
    pub name: String,
    /// Generator spec of the mesh.
    pub mesh: String,
    /// Vertex-shader loop iterations.
    pub vs_loops: u32,
    /// Fragment-shader loop iterations.
    pub fs_loops: u32,
    /// Triangles (h1, h3's polygons).
    pub triangles: u64,
    /// Distinct vertices (h3's vertices).
    pub vertices: u64,
}

/// One object drawn: a prototype as a square on the target.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ObjectDraw {
    /// Index into the prototypes.
    pub prototype: usize,
    /// Centre, pixels from the target's top left corner.
    pub x: f64,
    /// Centre, pixels.
    pub y: f64,
    /// Side of the square, pixels.
    pub side: f64,
}

impl ObjectDraw {
    /// The square's pixels on a `target` (its area clipped to the target).
    pub fn pixels(&self, target: [u32; 2]) -> f64 {
        let h = self.side / 2.0;
        let span = |c: f64, size: u32| ((c + h).min(f64::from(size)) - (c - h).max(0.0)).max(0.0);
        span(self.x, target[0]) * span(self.y, target[1])
    }
}

/// What a pass is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PassKind {
    /// No object: the pass overhead (clearing the target).
    Overhead,
    /// A prototype alone, centred, at a table size (pos's preprocess).
    Pos,
    /// One object at a random size and place (the fit).
    Single,
    /// Several objects (the scores).
    Multi,
}

impl PassKind {
    /// The name used in CSV and reports.
    pub fn name(self) -> &'static str {
        match self {
            PassKind::Overhead => "overhead",
            PassKind::Pos => "pos",
            PassKind::Single => "single",
            PassKind::Multi => "multi",
        }
    }
}

/// A pass to measure.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedPass {
    /// What it is for.
    pub kind: PassKind,
    /// Objects in draw order.
    pub objects: Vec<ObjectDraw>,
}

/// Everything the study draws, generated from the setup's seed.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The setup.
    pub setup: EstimationSetup,
    /// The prototypes.
    pub prototypes: Vec<Prototype>,
    /// Their meshes (same order).
    pub meshes: Vec<Mesh>,
    /// Every pass: overhead, pos, single, multi, in that order.
    pub passes: Vec<PlannedPass>,
    /// The order in which they are measured (a seeded shuffle, so that a
    /// slow spell of the machine touches every kind alike).
    pub order: Vec<usize>,
}

/// A log-uniform draw in `[lo, hi]`.
fn log_uniform(rng: &mut impl Rng, lo: f64, hi: f64) -> f64 {
    (lo.ln() + (hi.ln() - lo.ln()) * rng.random::<f64>()).exp()
}

/// A loop count: zero with probability 1/4, else log-uniform in 1..=most.
fn loops(rng: &mut impl Rng, most: u32, scale: f64) -> u32 {
    if most == 0 || rng.random::<f64>() < 0.25 {
        return 0;
    }
    (log_uniform(rng, 1.0, f64::from(most)) * scale).round() as u32
}

/// The mesh spec of prototype `i`: the kinds in turn (grid, shuffled grid,
/// optimized grid, strip, random), sizes drawn.
fn mesh_spec(i: usize, rng: &mut impl Rng) -> String {
    let mut side = || rng.random_range(2u32..=48);
    let (w, h) = (side(), side());
    match i % 5 {
        0 => format!("grid:{w}x{h}"),
        1 => format!("grid:{w}x{h}:shuffled:{}", rng.random_range(1u64..1000)),
        2 => format!("grid:{w}x{h}:optimized"),
        3 => format!("strip:{w}x{h}"),
        _ => {
            // Vertices scattered over the square: each triangle covers a
            // fair part of it, so few triangles (overdraw about 0.08 x T).
            let t = rng.random_range(8u64..=96);
            let v = rng.random_range((t / 2).max(3)..=t + 2);
            format!("random:{t}:{v}:{}", rng.random_range(1u64..1000))
        }
    }
}

/// A random object of `prototypes` on the target: side log-uniform, centre
/// uniform on the target.
fn random_object(rng: &mut impl Rng, setup: &EstimationSetup) -> ObjectDraw {
    ObjectDraw {
        prototype: rng.random_range(0..setup.prototypes),
        side: log_uniform(rng, setup.min_side, setup.max_side()),
        x: rng.random::<f64>() * f64::from(setup.target[0]),
        y: rng.random::<f64>() * f64::from(setup.target[1]),
    }
}

impl Plan {
    /// Generates the prototypes and passes of `setup` (validated here).
    pub fn new(setup: &EstimationSetup) -> Result<Plan, EstimationError> {
        setup.validate()?;
        let streams = RngStreams::new(setup.seed);
        let mut rng = streams.stream("estimation.prototypes");
        let mut prototypes = Vec::new();
        let mut meshes = Vec::new();
        for i in 0..setup.prototypes {
            let spec = mesh_spec(i, &mut rng);
            let mesh = mesh_from_spec(&spec, std::path::Path::new(".")).map_err(|e| EstimationError::Mesh {
                spec: spec.clone(),
                message: e.to_string(),
            })?;
            prototypes.push(Prototype {
                name: format!("p{i:02}"),
                mesh: spec,
                vs_loops: loops(&mut rng, setup.max_vs_loops, setup.load_scale),
                fs_loops: loops(&mut rng, setup.max_fs_loops, setup.load_scale),
                triangles: mesh.triangles(),
                vertices: mesh.unique_vertices(),
            });
            meshes.push(mesh);
        }
        let mut passes: Vec<PlannedPass> = (0..setup.overhead_passes)
            .map(|_| PlannedPass {
                kind: PassKind::Overhead,
                objects: Vec::new(),
            })
            .collect();
        let [cx, cy] = setup.target.map(|s| f64::from(s) / 2.0);
        for p in 0..setup.prototypes {
            for side in setup.pos_sides() {
                passes.push(PlannedPass {
                    kind: PassKind::Pos,
                    objects: vec![ObjectDraw {
                        prototype: p,
                        x: cx,
                        y: cy,
                        side,
                    }],
                });
            }
        }
        let mut rng = streams.stream("estimation.single");
        for _ in 0..setup.single {
            passes.push(PlannedPass {
                kind: PassKind::Single,
                objects: vec![random_object(&mut rng, setup)],
            });
        }
        let mut rng = streams.stream("estimation.multi");
        let [lo, hi] = setup.objects_per_pass;
        for _ in 0..setup.multi {
            let n = rng.random_range(lo..=hi);
            passes.push(PlannedPass {
                kind: PassKind::Multi,
                objects: (0..n).map(|_| random_object(&mut rng, setup)).collect(),
            });
        }
        let mut order: Vec<usize> = (0..passes.len()).collect();
        order.shuffle(&mut streams.stream("estimation.order"));
        Ok(Plan {
            setup: setup.clone(),
            prototypes,
            meshes,
            passes,
            order,
        })
    }

    /// Objects drawn over all passes.
    pub fn objects(&self) -> usize {
        self.passes.iter().map(|p| p.objects.len()).sum()
    }
}

/// One pass as measured: the median of its rounds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassMeasurement {
    /// Median pass time (timestamp queries around the render pass), ns.
    pub time_ns: f64,
    /// Every round's pass time, ns, in round order.
    pub times_ns: Vec<f64>,
    /// Vertex-shader invocations of the pass.
    pub vs_invocations: u64,
    /// Fragment-shader invocations of the pass.
    pub fs_invocations: u64,
    /// Whether the counters agreed over the rounds.
    pub stable: bool,
    /// Wall time spent measuring the pass (its submissions' wall time,
    /// shared among their passes in proportion to their GPU times), s.
    pub wall_s: f64,
}

/// One entry of a pos table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PosEntry {
    /// Pixels of the sample (the square's area).
    pub pixels: f64,
    /// The object's time: the pass time less the overhead, ms.
    pub ms: f64,
}

/// Looks `pixels` up in a table sorted by pixels: linear between entries,
/// the first segment extended below (not below zero), the last value held
/// above; table reads in `reads`.
pub fn pos_lookup(table: &[PosEntry], pixels: f64, reads: &mut u64) -> f64 {
    match table {
        [] => 0.0,
        [only] => {
            *reads += 1;
            only.ms
        }
        _ => {
            *reads += 2;
            let last = table[table.len() - 1];
            if pixels >= last.pixels {
                return last.ms;
            }
            let k = table[1..]
                .iter()
                .position(|e| pixels < e.pixels)
                .unwrap_or(table.len() - 2);
            let (a, b) = (table[k], table[k + 1]);
            let t = (pixels - a.pixels) / (b.pixels - a.pixels);
            (a.ms + (b.ms - a.ms) * t).max(0.0)
        }
    }
}

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
fn sig(x: f64) -> String {
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
    let target = setup.target;
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
    // Tables and transformed vertices per prototype.
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
    for (p, m) in of_kind(PassKind::Pos) {
        let o = &p.objects[0];
        let r = &mut prototypes[o.prototype];
        if !seen[o.prototype] {
            seen[o.prototype] = true;
            r.transformed = m.vs_invocations;
        } else if r.transformed != m.vs_invocations {
            checks.transformed_table_mismatches += 1;
        }
        r.pos_table.push(PosEntry {
            pixels: o.pixels(target),
            ms: (m.time_ns - overhead_ns) / 1e6,
        });
    }
    for r in &mut prototypes {
        r.pos_table.sort_by(|a, b| a.pixels.total_cmp(&b.pixels));
    }
    // The fit on the single-object passes (picoseconds).
    let single = of_kind(PassKind::Single);
    let samples: Vec<(Features, f64)> = single
        .iter()
        .map(|(p, m)| {
            let o = &p.objects[0];
            let proto = &plan.prototypes[o.prototype];
            let f = Features {
                triangles: proto.triangles as f64,
                transformed: m.vs_invocations as f64,
                vertices: proto.vertices as f64,
                pixels: o.pixels(target),
            };
            (f, (m.time_ns - overhead_ns) * 1e3)
        })
        .collect();
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
    for (name, set) in [("single", &single), ("multi", &multi)] {
        let passes: Vec<&PlannedPass> = set.iter().map(|(p, _)| *p).collect();
        let actual: Vec<f64> = set.iter().map(|(_, m)| m.time_ns / 1e6).collect();
        let estimates: Vec<[f64; 5]> = passes.iter().map(|p| study.pass_ms(plan, p)).collect();
        let mut scores = BTreeMap::new();
        for (k, est_name) in ESTIMATORS.iter().enumerate() {
            let est: Vec<f64> = estimates.iter().map(|e| e[k]).collect();
            let (secs, ops) = time_estimator(&study, plan, &passes, k);
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

/// The CSV header of [`csv_rows`].
pub const CSV_HEADER: [&str; 24] = [
    "pass",
    "kind",
    "objects",
    "pass_time_ns",
    "vs_invocations",
    "fs_invocations",
    "object",
    "prototype",
    "mesh",
    "vs_loops",
    "fs_loops",
    "x",
    "y",
    "side",
    "pixels",
    "triangles",
    "vertices",
    "transformed",
    "h1_ms",
    "h2_ms",
    "h3_ms",
    "h4_ms",
    "pos_ms",
    "pass_estimates_ms",
];

/// One row per object drawn (one row with empty object columns for an
/// empty pass): the pass's measurement, the object, each estimator's
/// estimate of the object (overhead excluded) and, in the last column, the
/// pass's estimates (overhead included) as `h1;h2;h3;h4;pos`.
pub fn csv_rows(plan: &Plan, measured: &[PassMeasurement], study: &EstimationStudy) -> Vec<Vec<String>> {
    use crate::output::table::number;
    let mut rows = Vec::new();
    for (i, (p, m)) in plan.passes.iter().zip(measured).enumerate() {
        let head = vec![
            i.to_string(),
            p.kind.name().to_string(),
            p.objects.len().to_string(),
            number(m.time_ns),
            m.vs_invocations.to_string(),
            m.fs_invocations.to_string(),
        ];
        let pass_est = study
            .pass_ms(plan, p)
            .iter()
            .map(|x| number(*x))
            .collect::<Vec<_>>()
            .join(";");
        if p.objects.is_empty() {
            let mut r = head.clone();
            r.extend(std::iter::repeat_n(String::new(), CSV_HEADER.len() - head.len() - 1));
            r.push(pass_est);
            rows.push(r);
            continue;
        }
        for (j, (o, est)) in p.objects.iter().zip(study.objects_ms(plan, p)).enumerate() {
            let proto = &study.prototypes[o.prototype];
            let mut r = head.clone();
            r.extend([
                j.to_string(),
                proto.prototype.name.clone(),
                proto.prototype.mesh.clone(),
                proto.prototype.vs_loops.to_string(),
                proto.prototype.fs_loops.to_string(),
                number(o.x),
                number(o.y),
                number(o.side),
                number(o.pixels(plan.setup.target)),
                proto.prototype.triangles.to_string(),
                proto.prototype.vertices.to_string(),
                proto.transformed.to_string(),
            ]);
            r.extend(est.iter().map(|x| number(*x)));
            r.push(pass_est.clone());
            rows.push(r);
        }
    }
    rows
}

impl EstimationStudy {
    /// The per-device Markdown document.
    pub fn markdown(&self) -> String {
        let s = &self.setup;
        let mut d = format!(
            "# Rendering-time estimation measured: {}\n\nProduced by `{}` (rendersim {}).\n\n",
            self.adapter,
            self.command,
            env!("CARGO_PKG_VERSION")
        );
        if !self.notes.is_empty() {
            d += self.notes.trim_end();
            d += "\n\n";
        }
        d += &format!(
            "**Verdict.** {}.\n\n\
             What was measured (paper 000 §5; issue 11 item 8): {} prototypes (a generator mesh with its own \
             vertex- and fragment-shader loop counts, loads scaled by {}) drawn as squares on a {}x{} target; \
             {} empty passes (overhead {:.3} ms, added once to every estimate); {} table passes (pos: {} sides \
             per prototype); {} single-object passes (the fit); {} multi-object passes of {}-{} objects ({} objects, \
             the scores). Every pass is timed by timestamp queries around its render pass, {} rounds \
             interleaved in a seeded order (seed {}), median used. Pixels: {}. pos: {}.\n\n",
            self.verdict(),
            s.prototypes,
            s.load_scale,
            s.target[0],
            s.target[1],
            self.passes.overhead,
            self.overhead_ms,
            self.passes.pos,
            s.pos_sizes,
            self.passes.single,
            self.passes.multi,
            s.objects_per_pass[0],
            s.objects_per_pass[1],
            self.passes.multi_objects,
            s.repeats,
            s.seed,
            self.pixels,
            self.pos_reading,
        );
        d += "## Multi-object passes (the paper's Table 6 columns)\n\n\
              | estimator | squared error ms² | mean error ms | mean abs error ms | underestimated | cost µs per pass |\n\
              |---|---|---|---|---|---|\n";
        let row = |name: &str, x: &Score| {
            format!(
                "| {name} | {} | {:+.4} | {:.4} | {:.1}% | {:.3} |\n",
                sig(x.mse_ms2.unwrap_or(f64::NAN)),
                x.mean_error_ms.unwrap_or(f64::NAN),
                x.mean_abs_error_ms.unwrap_or(f64::NAN),
                100.0 * x.underestimated_fraction.unwrap_or(f64::NAN),
                x.cost_us_per_frame
            )
        };
        for (n, x) in &self.scores {
            d += &row(n, x);
        }
        let t = &self.timing;
        d += &format!(
            "| measuring once | {} | | | | {:.1} |\n\n\
             Error against run time: estimating a pass takes microseconds; measuring it once takes {:.3} ms of wall \
             time ({:.3} ms of it on the GPU timer, mean) and has a squared error of {} ms² against the median of its \
             {} rounds. Mean measured pass time {:.3} ms.\n\n",
            sig(t.measure_once_mse_ms2),
            t.multi_measure_ms_per_pass * 1e3,
            t.multi_measure_ms_per_pass,
            t.multi_gpu_ms_mean,
            sig(t.measure_once_mse_ms2),
            s.repeats,
            t.multi_gpu_ms_mean
        );
        d += "## Single-object passes (h1-h4 in-sample: fitted to these)\n\n\
              | estimator | squared error ms² | mean error ms | mean abs error ms | underestimated | cost µs per pass |\n\
              |---|---|---|---|---|---|\n";
        for (n, x) in &self.fit {
            d += &row(n, x);
        }
        let c = &self.constants;
        d += &format!(
            "\n## Fitted constants (least squares without intercept, non-negative)\n\n\
             | estimator | formula | constants |\n|---|---|---|\n\
             | h1 | c1·triangles | c1 = {} ns |\n\
             | h2 | c1·transformed vertices | c1 = {} ns |\n\
             | h3 | max(c1·triangles + c2·vertices, c3·pixels) | c1 = {} ns, c2 = {} ns, c3 = {} ns |\n\
             | h4 | c1·transformed vertices + c2·pixels | c1 = {} ns, c2 = {} ns |\n\n",
            sig(c.h1_per_triangle_ps / 1e3),
            sig(c.h2_per_transformed_vertex_ps / 1e3),
            sig(c.h3_ps[0] / 1e3),
            sig(c.h3_ps[1] / 1e3),
            sig(c.h3_ps[2] / 1e3),
            sig(c.h4_ps[0] / 1e3),
            sig(c.h4_ps[1] / 1e3),
        );
        d += "## Prototypes and their pos tables (object ms by side in pixels)\n\n| prototype | mesh | vs loops | fs loops | triangles | vertices | transformed |";
        let sides = s.pos_sides();
        for side in &sides {
            d += &format!(" {side:.0} px |");
        }
        d += "\n|---|---|---|---|---|---|---|";
        d += &"---|".repeat(sides.len());
        d += "\n";
        for p in &self.prototypes {
            d += &format!(
                "| {} | `{}` | {} | {} | {} | {} | {} |",
                p.prototype.name,
                p.prototype.mesh,
                p.prototype.vs_loops,
                p.prototype.fs_loops,
                p.prototype.triangles,
                p.prototype.vertices,
                p.transformed
            );
            for e in &p.pos_table {
                d += &format!(" {:.4} |", e.ms);
            }
            d += "\n";
        }
        let k = &self.checks;
        let walls: Vec<String> = t.wall_s_by_kind.iter().map(|(n, w)| format!("{n} {w:.2} s")).collect();
        d += &format!(
            "\n## Checks and wall times\n\n\
             - Counters differing between rounds: {} passes. Multi-object passes whose vertex-shader invocations \
               differ from the sum of their objects' prototype counts: {}. Table passes whose count differs from \
               their prototype's: {}.\n\
             - Measuring: {:.2} s in all ({}); the fit took {:.3} ms.\n",
            k.unstable_counters,
            k.transformed_sum_mismatches,
            k.transformed_table_mismatches,
            t.measure_wall_s,
            walls.join(", "),
            t.fit_wall_ms
        );
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> EstimationSetup {
        EstimationSetup {
            single: 20,
            multi: 5,
            prototypes: 5,
            ..EstimationSetup::default()
        }
    }

    #[test]
    fn pixels_are_the_square_clipped_to_the_target() {
        let o = |x, y, side| ObjectDraw {
            prototype: 0,
            x,
            y,
            side,
        };
        assert_eq!(o(128.0, 128.0, 10.0).pixels([256, 256]), 100.0);
        // Hanging over the left edge by half: 5 x 10.
        assert_eq!(o(0.0, 128.0, 10.0).pixels([256, 256]), 50.0);
        // Over a corner: a quarter.
        assert_eq!(o(256.0, 256.0, 10.0).pixels([256, 256]), 25.0);
        assert_eq!(o(128.0, 128.0, 1000.0).pixels([256, 128]), 256.0 * 128.0);
    }

    #[test]
    fn the_plan_is_deterministic_and_has_every_pass() {
        let a = Plan::new(&small()).unwrap();
        let b = Plan::new(&small()).unwrap();
        assert_eq!(a.passes, b.passes);
        assert_eq!(a.prototypes, b.prototypes);
        assert_eq!(a.order, b.order);
        let s = small();
        assert_eq!(
            a.passes.len(),
            s.overhead_passes + s.prototypes * s.pos_sizes + s.single + s.multi
        );
        let mut o = a.order.clone();
        o.sort_unstable();
        assert_eq!(o, (0..a.passes.len()).collect::<Vec<_>>());
        let c = Plan::new(&EstimationSetup { seed: 2, ..small() }).unwrap();
        assert_ne!(a.passes, c.passes);
        // More multi passes leave the single ones as they were (separate streams).
        let d = Plan::new(&EstimationSetup { multi: 9, ..small() }).unwrap();
        let singles = |p: &Plan| -> Vec<PlannedPass> {
            p.passes
                .iter()
                .filter(|x| x.kind == PassKind::Single)
                .cloned()
                .collect()
        };
        assert_eq!(singles(&a), singles(&d));
        for p in &a.passes {
            for o in &p.objects {
                assert!(o.pixels(s.target) > 0.0 && o.side >= s.min_side - 1e-9 && o.side <= s.max_side() + 1e-9);
            }
        }
    }

    #[test]
    fn lookup_interpolates_in_pixels() {
        let t = [
            PosEntry { pixels: 100.0, ms: 1.0 },
            PosEntry { pixels: 300.0, ms: 2.0 },
            PosEntry { pixels: 700.0, ms: 4.0 },
        ];
        let mut r = 0;
        assert_eq!(pos_lookup(&t, 200.0, &mut r), 1.5);
        assert_eq!(pos_lookup(&t, 500.0, &mut r), 3.0);
        assert_eq!(pos_lookup(&t, 900.0, &mut r), 4.0);
        // The first segment extended below, not below zero.
        assert_eq!(pos_lookup(&t, 0.0, &mut r), 0.5);
        assert_eq!(
            pos_lookup(
                &[PosEntry { pixels: 100.0, ms: 1.0 }, PosEntry { pixels: 200.0, ms: 3.0 }],
                0.0,
                &mut r
            ),
            0.0
        );
        assert_eq!(r, 10);
    }

    #[test]
    fn bad_setups_name_the_option() {
        let e = |s: EstimationSetup| Plan::new(&s).unwrap_err().to_string();
        assert!(e(EstimationSetup { single: 0, ..small() }).contains("--single must be at least 1"));
        assert!(e(EstimationSetup { multi: 0, ..small() }).contains("--multi must be at least 1"));
        assert!(
            e(EstimationSetup {
                load_scale: 0.0,
                ..small()
            })
            .contains("--load-scale")
        );
        assert!(
            e(EstimationSetup {
                load_scale: 1e9,
                ..small()
            })
            .contains("--load-scale")
        );
        assert!(
            e(EstimationSetup {
                objects_per_pass: [3, 2],
                ..small()
            })
            .contains("objects per pass")
        );
    }
}
