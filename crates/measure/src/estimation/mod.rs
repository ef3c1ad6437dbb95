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
//!   walkthrough's [`Score`](crate::systems::walkthrough::estimators::Score): squared error (ms²), mean error, share
//!   underestimated, and the estimator's own run time per pass beside the
//!   wall time of measuring a pass (error against run time).
//!
//! Everything here is plain code compiled in every build and tested on
//! synthetic passes: the plan (this file), the fit and scores
//! (`analysis.rs`), the document and CSV (`document.rs`);
//! `../estimation_device.rs` measures the plan on a device.

use rand::Rng;
use rand::seq::SliceRandom;
use serde::Serialize;

use crate::engine::RngStreams;
use crate::scene::generators::mesh_from_spec;
use crate::scene::mesh::Mesh;

mod analysis;
mod document;

pub use analysis::{EstimationChecks, EstimationStudy, EstimationTiming, PassCounts, PrototypeResult, analyze};
pub use document::{CSV_HEADER, csv_rows};

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
        if most(self.max_vs_loops) > f64::from(crate::loops::MAX_LOOPS)
            || most(self.max_fs_loops) > f64::from(crate::loops::MAX_LOOPS)
        {
            return bad(format!(
                "--load-scale {} makes loop counts above {}",
                self.load_scale,
                crate::loops::MAX_LOOPS
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
