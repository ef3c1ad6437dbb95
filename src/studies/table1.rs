//! Paper 000 Table 1 ("the myth of the single bottleneck", §4.5.1) as a
//! calibration of a frame-pipeline model: three of the table's four cells
//! (simple or complex vertex shader x simple or complex fragment shader, GPU
//! time per frame of one terrain viewpoint) fix the model's shader costs,
//! the fourth is predicted.
//!
//! On the unified shader pool the frame costs O + G + F and the calibration
//! is arithmetic (experiments/table1-sum-vs-max.toml). On the split
//! architecture the frame lies between O + max(G, F) and O + G + F, and the
//! simple/simple cell does not say how its shader time divides into
//! geometry G and fragments F: that share is a free parameter. For each
//! share this module solves the three cells by root finding on the
//! simulated GPU time, which is monotone in each cost:
//!
//! 1. the simple/simple cell: a total shader time S, divided as `share x S`
//!    of geometry and the rest of fragments (the costs rounded to integer
//!    picoseconds), scaled until the cell matches;
//! 2. the simple-vertex/complex-fragment cell: the complex per-fragment cost;
//! 3. the complex-vertex/simple-fragment cell: the complex vertex cost;
//!
//! then simulates the fourth cell. Each search works on integer picosecond
//! costs (Illinois false position, every third step a bisection) and stops
//! when the cell is within [`TOLERANCE_MS`] of its target or when the
//! bracket is one picosecond wide (then the closer end is kept).

use serde::Serialize;

use crate::config::{ConfigError, ModelSource, apply_set};
use crate::scene::config::SizeOrder;
use crate::systems::frame_pipeline::Fidelity;
use crate::systems::frame_pipeline::run::PipelineRun;
use crate::systems::{SimError, run_model};

/// `models/terrain.toml`: the terrain viewpoint of Table 1 (86,400
/// triangles, areas lognormal with median 8 px and sigma 0.8).
pub const TERRAIN: &str = include_str!("../../models/terrain.toml");
/// The preset terrain's triangle-area median (px) and spread.
const TERRAIN_MEDIAN: f64 = 8.0;
const TERRAIN_SIGMA: f64 = 0.8;

/// [`TERRAIN`] with its preset written out as a group, so that the order of
/// its triangle sizes within the draw (`size_order`) and their spread can
/// change: areas lognormal with spread `sigma` and the preset's mean
/// (8 e^0.32 = 11.0 px, so the same shaded pixels on average).
pub fn terrain_variant(order: SizeOrder, sigma: f64) -> String {
    let order = order_name(order);
    let median = TERRAIN_MEDIAN * ((TERRAIN_SIGMA * TERRAIN_SIGMA - sigma * sigma) / 2.0).exp();
    format!(
        r#"{}
[[workload.groups]]
name = "terrain"
mesh = {{ triangles = 86400, acmr = 0.99 }}
triangle_pixels = {{ kind = "lognormal", median = {median:?}, sigma = {sigma:?} }}
size_order = "{order}"
"#,
        TERRAIN.replace("preset = \"terrain\"\n", "")
    )
}

/// The vertex-shader cost the calibration sets.
pub const VERTEX_KEY: &str = "gpu.geometry.vertex_shader";
/// The per-fragment cost the calibration sets.
pub const FRAGMENT_KEY: &str = "gpu.fragment.per_fragment";
/// The metric the cells are: mean GPU time per frame.
pub const METRIC: &str = "metrics.gpu_time_ms.mean";
/// A search stops once its cell is this close to the target (ms).
pub const TOLERANCE_MS: f64 = 1e-4;

/// The name a model file gives an enum value: its serde form
/// (`"ascending"`, `"draw"`).
fn key_name<T: Serialize>(value: T) -> String {
    serde_json::to_value(value)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// The `size_order` value of `order`.
pub fn order_name(order: SizeOrder) -> String {
    key_name(order)
}

/// The terrain of Table 1 on the split architecture, one frame: the order
/// of its triangle sizes, the triangle FIFO's depth and the sizes' spread
/// ([`terrain_variant`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SplitTerrain {
    /// Order of the sizes within the draw.
    pub order: SizeOrder,
    /// `gpu.fragment.fifo_depth`.
    pub fifo_depth: u32,
    /// Spread (sigma) of the lognormal triangle areas; the preset's is 0.8.
    pub sigma: f64,
}

impl SplitTerrain {
    /// The model text as a source.
    pub fn source(&self) -> ModelSource {
        ModelSource::from_text("terrain-split.toml", &terrain_variant(self.order, self.sigma))
    }

    /// The model table of `src` (from [`SplitTerrain::source`]) at this
    /// fidelity, patched to the split architecture, this FIFO depth and one
    /// frame.
    pub fn table(&self, src: &ModelSource, fidelity: Fidelity) -> Result<toml::Table, ConfigError> {
        let mut t = src.table()?;
        let fidelity = key_name(fidelity);
        for set in [
            "gpu.architecture=\"split\"".to_string(),
            format!("fidelity=\"{fidelity}\""),
            format!("gpu.fragment.fifo_depth={}", self.fifo_depth),
            "run.frames=1".to_string(),
            "run.warmup_frames=0".to_string(),
        ] {
            apply_set(&mut t, &set)?;
        }
        Ok(t)
    }

    /// `order, FIFO depth, sigma` for tables.
    pub fn label(&self) -> String {
        format!(
            "{} sizes, FIFO {}, sigma {}",
            order_name(self.order),
            self.fifo_depth,
            self.sigma
        )
    }
}

/// GPU time per frame (ms) of the four cells; the first word names the
/// vertex shader, the second the fragment shader.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Cells {
    /// Simple vertex shader, simple fragment shader.
    pub simple_simple: f64,
    /// Simple vertex shader, complex fragment shader.
    pub simple_complex: f64,
    /// Complex vertex shader, simple fragment shader.
    pub complex_simple: f64,
    /// Both complex.
    pub complex_complex: f64,
}

/// Paper 000 Table 1 (GeForce3, one terrain viewpoint), ms.
pub const PAPER: Cells = Cells {
    simple_simple: 4.969,
    simple_complex: 9.859,
    complex_simple: 7.35,
    complex_complex: 11.856,
};

impl Cells {
    /// What the complex vertex shader adds under the complex fragment
    /// shader, as a share of what it adds under the simple one (paper:
    /// 1.997 / 2.381 = 0.84; a single bottleneck: 0; the sum: 1).
    pub fn ratio(&self) -> f64 {
        (self.complex_complex - self.simple_complex) / (self.complex_simple - self.simple_simple)
    }

    /// The fourth cell if the frame were O + max(G, F) (a single
    /// bottleneck), from the other three: the larger of the two one-complex
    /// cells.
    pub fn max_prediction(&self) -> f64 {
        self.simple_complex.max(self.complex_simple)
    }

    /// The fourth cell if the frame were O + G + F: both increments add.
    pub fn sum_prediction(&self) -> f64 {
        self.simple_complex + self.complex_simple - self.simple_simple
    }
}

/// Shader costs, picoseconds (vertex: per transformed vertex; fragment: per
/// shaded fragment).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Costs {
    /// Simple vertex shader.
    pub vertex_simple_ps: u64,
    /// Complex vertex shader.
    pub vertex_complex_ps: u64,
    /// Simple fragment shader.
    pub fragment_simple_ps: u64,
    /// Complex fragment shader.
    pub fragment_complex_ps: u64,
}

/// One calibration: the costs found for a geometry share and the four
/// simulated cells (three calibrated, the fourth predicted).
#[derive(Debug, Clone, Serialize)]
pub struct Calibration {
    /// The share of the simple/simple cell's shader time (G + F of the
    /// model's analytic stage totals) that is geometry.
    pub geometry_share: f64,
    /// The costs.
    pub costs: Costs,
    /// Geometry-stage busy time of the simple/simple cell (ms).
    pub geometry_ms: f64,
    /// Fragment-stage busy time of the simple/simple cell (ms).
    pub fragment_ms: f64,
    /// The simulated cells.
    pub cells: Cells,
    /// Model runs the calibration took.
    pub runs: usize,
}

impl Calibration {
    /// The largest distance of a calibrated cell from its target (ms).
    pub fn max_calibration_error(&self, targets: &Cells) -> f64 {
        [
            self.cells.simple_simple - targets.simple_simple,
            self.cells.simple_complex - targets.simple_complex,
            self.cells.complex_simple - targets.complex_simple,
        ]
        .iter()
        .fold(0.0, |m, e| m.max(e.abs()))
    }
}

/// Errors of a calibration.
#[derive(Debug, thiserror::Error)]
pub enum CalibrationError {
    /// A cost could not be set on the model.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A run failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The run's summary lacks a number (or the model is not a frame
    /// pipeline).
    #[error("the run's summary has no number at {0}")]
    Metric(String),
    /// The geometry share is not in [0, 1].
    #[error("the geometry share must be between 0 and 1, got {0}")]
    Share(f64),
    /// A target cannot be reached by raising the cost.
    #[error("{what}: the target {target} ms is out of reach (the model gives {reached} ms)")]
    Unreachable {
        /// Which cell.
        what: &'static str,
        /// Its target (ms).
        target: f64,
        /// The time at the end of the search range (ms).
        reached: f64,
    },
}

/// Probe cost (ps) for the stage rates.
const PROBE: u64 = 1_000_000;

/// What fixes the split of the simple/simple cell's shader time.
#[derive(Debug, Clone, Copy)]
enum FirstCell {
    /// The geometry share of the stage totals.
    Share(f64),
    /// The simple vertex shader's cost (ps).
    Vertex(u64),
}

/// A frame-pipeline model whose two shader costs the calibration sets.
pub struct CellModel<'a> {
    src: &'a ModelSource,
    table: toml::Table,
    runs: usize,
    /// The times at zero costs, and the stage totals' ms per picosecond of
    /// vertex and fragment cost (found once).
    rates: Option<(Times, f64, f64)>,
}

/// The numbers a run gives the calibration (ms).
#[derive(Debug, Clone, Copy)]
struct Times {
    gpu: f64,
    geometry: f64,
    fragment: f64,
}

impl<'a> CellModel<'a> {
    /// The model `table` (already patched) read from `src`.
    pub fn new(src: &'a ModelSource, table: toml::Table) -> CellModel<'a> {
        CellModel {
            src,
            table,
            runs: 0,
            rates: None,
        }
    }

    fn times(&mut self, vertex_ps: u64, fragment_ps: u64) -> Result<Times, CalibrationError> {
        let mut t = self.table.clone();
        apply_set(&mut t, &format!("{VERTEX_KEY}=\"{vertex_ps}ps\""))?;
        apply_set(&mut t, &format!("{FRAGMENT_KEY}=\"{fragment_ps}ps\""))?;
        let run = run_model(self.src, &t, None)?
            .downcast::<PipelineRun>()
            .map_err(|_| CalibrationError::Metric(format!("{METRIC} (the model is not a frame pipeline)")))?;
        self.runs += 1;
        let m = &run.results.metrics;
        Ok(Times {
            gpu: m
                .gpu_time_ms
                .mean
                .ok_or_else(|| CalibrationError::Metric(METRIC.to_string()))?,
            geometry: m.analytic.geometry_ms,
            fragment: m.analytic.fragment_ms,
        })
    }

    /// Mean GPU time per frame (ms) with these costs.
    pub fn gpu_ms(&mut self, vertex_ps: u64, fragment_ps: u64) -> Result<f64, CalibrationError> {
        Ok(self.times(vertex_ps, fragment_ps)?.gpu)
    }

    /// Model runs so far.
    pub fn runs(&self) -> usize {
        self.runs
    }

    /// Calibrates the three cells of `targets` for a geometry `share`, and
    /// predicts the fourth.
    pub fn calibrate(&mut self, share: f64, targets: &Cells) -> Result<Calibration, CalibrationError> {
        if !(0.0..=1.0).contains(&share) {
            return Err(CalibrationError::Share(share));
        }
        self.calibrate_from(FirstCell::Share(share), targets)
    }

    /// Calibrates the three cells of `targets` with the simple vertex
    /// shader's cost given (`vertex_ps` per transformed vertex, from a
    /// measurement outside the table), so that the simple/simple cell fixes
    /// the simple fragment cost; predicts the fourth.
    pub fn calibrate_with_vertex(&mut self, vertex_ps: u64, targets: &Cells) -> Result<Calibration, CalibrationError> {
        self.calibrate_from(FirstCell::Vertex(vertex_ps), targets)
    }

    /// The simple shaders' costs that reproduce the simple/simple cell.
    fn first_cell(
        &mut self,
        first: FirstCell,
        target: f64,
        rates: (Times, f64, f64),
    ) -> Result<(u64, u64), CalibrationError> {
        let (zero, per_vertex_ps, per_fragment_ps) = rates;
        let room = (target - zero.gpu).max(0.0);
        match first {
            FirstCell::Share(share) => {
                // The total shader time S (ps), divided by the share.
                let split = |s: u64| -> (u64, u64) {
                    let ms = s as f64 * 1e-9;
                    let v = if per_vertex_ps > 0.0 {
                        (share * ms / per_vertex_ps).round() as u64
                    } else {
                        0
                    };
                    let f = if per_fragment_ps > 0.0 {
                        ((1.0 - share) * ms / per_fragment_ps).round() as u64
                    } else {
                        0
                    };
                    (v, f)
                };
                // A first guess that brackets the target: the split frame
                // takes at least the fixed time plus the longer stage.
                let guess = (2.0 * room * 1e9).ceil() as u64;
                let (s, _) = self.solve("simple/simple", target, (0, zero.gpu), guess, |m, s| {
                    let (v, f) = split(s);
                    m.gpu_ms(v, f)
                })?;
                Ok(split(s))
            }
            FirstCell::Vertex(v) => {
                let at_zero = self.gpu_ms(v, 0)?;
                let guess = if per_fragment_ps > 0.0 {
                    (room / per_fragment_ps).ceil() as u64
                } else {
                    PROBE
                };
                let (f, _) = self.solve("simple/simple", target, (0, at_zero), guess, |m, f| m.gpu_ms(v, f))?;
                Ok((v, f))
            }
        }
    }

    fn calibrate_from(&mut self, first: FirstCell, targets: &Cells) -> Result<Calibration, CalibrationError> {
        let runs_before = self.runs;
        // The stage totals are affine in the costs: ms per picosecond of
        // cost (transformed vertices and shaded fragments, in effect).
        let rates = match self.rates {
            Some(r) => r,
            None => {
                let zero = self.times(0, 0)?;
                let probe = self.times(PROBE, PROBE)?;
                let r = (
                    zero,
                    (probe.geometry - zero.geometry) / PROBE as f64,
                    (probe.fragment - zero.fragment) / PROBE as f64,
                );
                self.rates = Some(r);
                r
            }
        };
        let (zero, per_vertex_ps, per_fragment_ps) = rates;
        let room = |target: f64| (target - zero.gpu).max(0.0);
        let guess = |ms: f64, per_ps: f64| {
            if per_ps > 0.0 {
                (ms / per_ps).ceil() as u64
            } else {
                PROBE
            }
        };
        // 1. The simple/simple cell.
        let (v0, f0) = self.first_cell(first, targets.simple_simple, rates)?;
        let base = self.times(v0, f0)?;
        // 2. The complex fragment shader.
        let f_guess = guess(room(targets.simple_complex), per_fragment_ps);
        let (f1, simple_complex) = self.solve(
            "simple/complex",
            targets.simple_complex,
            (f0, base.gpu),
            f_guess,
            |m, f| m.gpu_ms(v0, f),
        )?;
        // 3. The complex vertex shader.
        let v_guess = guess(room(targets.complex_simple), per_vertex_ps);
        let (v1, complex_simple) = self.solve(
            "complex/simple",
            targets.complex_simple,
            (v0, base.gpu),
            v_guess,
            |m, v| m.gpu_ms(v, f0),
        )?;
        // 4. The prediction.
        let complex_complex = self.gpu_ms(v1, f1)?;
        Ok(Calibration {
            geometry_share: base.geometry / (base.geometry + base.fragment),
            costs: Costs {
                vertex_simple_ps: v0,
                vertex_complex_ps: v1,
                fragment_simple_ps: f0,
                fragment_complex_ps: f1,
            },
            geometry_ms: base.geometry,
            fragment_ms: base.fragment,
            cells: Cells {
                simple_simple: base.gpu,
                simple_complex,
                complex_simple,
                complex_complex,
            },
            runs: self.runs - runs_before,
        })
    }

    /// The integer `x >= lo` whose time is closest to `target`, for a time
    /// `eval` that does not decrease in `x`; `at_lo` is the time at `lo`,
    /// `guess` a first upper end of the bracket (doubled until it passes the
    /// target).
    fn solve(
        &mut self,
        what: &'static str,
        target: f64,
        (lo, at_lo): (u64, f64),
        guess: u64,
        mut eval: impl FnMut(&mut Self, u64) -> Result<f64, CalibrationError>,
    ) -> Result<(u64, f64), CalibrationError> {
        if (at_lo - target).abs() <= TOLERANCE_MS {
            return Ok((lo, at_lo));
        }
        if at_lo > target {
            return Err(CalibrationError::Unreachable {
                what,
                target,
                reached: at_lo,
            });
        }
        let (mut lo, mut t_lo) = (lo, at_lo);
        let mut hi = guess.max(lo + 1);
        let mut t_hi;
        let mut doublings = 0;
        loop {
            t_hi = eval(self, hi)?;
            if (t_hi - target).abs() <= TOLERANCE_MS {
                return Ok((hi, t_hi));
            }
            if t_hi > target {
                break;
            }
            doublings += 1;
            if doublings > 40 || hi > u64::MAX / 4 {
                return Err(CalibrationError::Unreachable {
                    what,
                    target,
                    reached: t_hi,
                });
            }
            (lo, t_lo) = (hi, t_hi);
            hi *= 2;
        }
        // Illinois false position on the bracket, with a bisection every
        // third step so that flat stretches cannot stall it.
        let (mut w_lo, mut w_hi) = (t_lo - target, t_hi - target);
        let mut last_side = 0i8;
        let mut iteration = 0u32;
        while hi - lo > 1 {
            iteration += 1;
            let x = if iteration.is_multiple_of(3) || w_hi <= w_lo {
                lo + (hi - lo) / 2
            } else {
                let x = lo as f64 + (-w_lo / (w_hi - w_lo)) * (hi - lo) as f64;
                (x.round() as u64).clamp(lo + 1, hi - 1)
            };
            let t = eval(self, x)?;
            if (t - target).abs() <= TOLERANCE_MS {
                return Ok((x, t));
            }
            if t < target {
                (lo, t_lo, w_lo) = (x, t, t - target);
                if last_side == -1 {
                    w_hi /= 2.0;
                }
                last_side = -1;
            } else {
                (hi, t_hi, w_hi) = (x, t, t - target);
                if last_side == 1 {
                    w_lo /= 2.0;
                }
                last_side = 1;
            }
        }
        Ok(if target - t_lo <= t_hi - target {
            (lo, t_lo)
        } else {
            (hi, t_hi)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_terrain_variant_writes_the_preset_out() {
        let t = terrain_variant(SizeOrder::Ascending, 0.8);
        assert!(!t.contains("preset"), "{t}");
        assert!(t.contains("median = 8.0, sigma = 0.8"), "{t}");
        assert!(t.contains("size_order = \"ascending\""), "{t}");
        let wide = terrain_variant(SizeOrder::Random, 2.0);
        assert!(wide.contains("sigma = 2.0"), "{wide}");
    }

    #[test]
    fn the_papers_bounds() {
        // -16.8% and +3.2% of the paper's fourth cell.
        assert!((PAPER.max_prediction() - 9.859).abs() < 1e-12);
        assert!((PAPER.sum_prediction() - 12.240).abs() < 1e-9);
        assert!((PAPER.ratio() - 1.997 / 2.381).abs() < 1e-9);
    }

    const FIXED: &str = r#"
[run]
frames = 1
warmup_frames = 0
[noise]
enabled = false
[display]
vsync = false
[gpu]
architecture = "split"
[workload]
kind = "scene"
depth_order = "back_to_front"
[[workload.groups]]
name = "g"
mesh = { triangles = 1000, acmr = 1.0 }
triangle_pixels = 10.0
"#;

    #[test]
    fn equal_triangles_on_a_deep_fifo_calibrate_to_the_max() {
        // Every triangle alike and a FIFO as long as the draw: the split
        // pipeline is max(G, F) (plus one triangle), so the fourth cell is
        // the max bound (here at a share of 0.2, away from balance).
        let src = ModelSource::from_text("t.toml", FIXED);
        let mut table = src.table().unwrap();
        apply_set(&mut table, "gpu.fragment.fifo_depth=10000").unwrap();
        let targets = Cells {
            simple_simple: 1.0,
            simple_complex: 2.0,
            complex_simple: 1.5,
            complex_complex: f64::NAN,
        };
        let mut m = CellModel::new(&src, table);
        let c = m.calibrate(0.2, &targets).unwrap();
        assert!(c.max_calibration_error(&targets) < 0.002, "{c:?}");
        assert!((c.cells.complex_complex - 2.0).abs() < 0.01, "{c:?}");
        assert!((c.geometry_ms / (c.geometry_ms + c.fragment_ms) - 0.2).abs() < 1e-3);
        let e = m.calibrate(1.5, &targets).unwrap_err();
        assert!(e.to_string().contains("between 0 and 1"), "{e}");
    }
}
