//! Running the hypothesis studies on a device: the passes each study needs,
//! measured on one opened [`Gpu`], handed to the study's analysis; and
//! [`run_studies`], which runs a list of them (H1 first: H2-H4 price vertices
//! with the reuse policy it finds) and composes the per-device document.

use std::path::Path;
use std::time::Instant;

use crate::scene::generators::mesh_from_spec;
use crate::scene::mesh::Mesh;

use super::device::{Gpu, MeasureError, MeasureOptions, Measurement};
use super::geometry::DepthOrder;
use super::h1;
use super::h2::{self, H2, H2Measured, H2Setup};
use super::h3::{self, H3, H3Measured, H3Pass, H3Setup};
use super::h4::{self, H4, H4Row, H4Setup};
use super::loops::search_loops;
use super::predict::PredictError;
use super::report::{StudySection, device_document};

/// Errors of a study.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A measurement failed.
    #[error(transparent)]
    Measure(#[from] MeasureError),
    /// The simulator's prediction failed.
    #[error(transparent)]
    Predict(#[from] PredictError),
    /// A study mesh could not be built.
    #[error("study mesh: {0}")]
    Mesh(String),
}

/// A study's mesh from its spec.
fn study_mesh(spec: &str) -> Result<Mesh, StudyError> {
    mesh_from_spec(spec, Path::new(".")).map_err(|e| StudyError::Mesh(e.to_string()))
}

/// One pass to measure: mesh spec, mesh, options.
type Condition<'a> = (&'a str, &'a Mesh, MeasureOptions);

/// Measures every condition `rounds` times, interleaved (round 1 of every
/// condition, then round 2, ...), so that a slow spell of the machine
/// touches all conditions alike rather than one; each condition's pass is
/// built once and warmed up by one unrecorded pass ([`Gpu::measure_interleaved`]).
/// Returns one measurement per condition whose `pass_times_ns` holds every
/// round and whose `pass_time_ns` is their median.
fn interleaved(gpu: &Gpu, conds: &[Condition], rounds: u32) -> Result<Vec<Measurement>, StudyError> {
    let conds: Vec<Condition> = conds
        .iter()
        .map(|(spec, mesh, opts)| {
            (
                *spec,
                *mesh,
                MeasureOptions {
                    warmup: 1,
                    ..opts.clone()
                },
            )
        })
        .collect();
    Ok(gpu.measure_interleaved(&conds, rounds)?)
}

/// A short measurement (a warm-up, then the median of three passes), ns.
fn quick(gpu: &Gpu, spec: &str, m: &Mesh, opts: MeasureOptions) -> Result<f64, StudyError> {
    Ok(interleaved(gpu, &[(spec, m, opts)], 3)?[0].pass_time_ns)
}

/// Measures and analyses H2 (sum vs max).
pub fn run_h2(gpu: &Gpu, mut setup: H2Setup, rounds: u32) -> Result<H2, StudyError> {
    let t = Instant::now();
    let grid = study_mesh(&setup.mesh)?;
    let tiny = study_mesh("grid:1x1")?;
    let base = MeasureOptions {
        size: setup.size,
        ..MeasureOptions::default()
    };
    let geometry_only = |vs_loops| MeasureOptions {
        vs_loops,
        geometry_only: true,
        ..base.clone()
    };
    let full = |vs_loops, fs_loops| MeasureOptions {
        vs_loops,
        fs_loops,
        ..base.clone()
    };
    if let Some(target) = setup.auto_target_ms {
        let spec = setup.mesh.clone();
        let [vs, _] = setup.vs_loops;
        let [fs, _] = setup.fs_loops;
        let geo_simple = quick(gpu, &spec, &grid, geometry_only(vs))?;
        let vc = search_loops(setup.vs_loops[1], target * 1e6, |l| {
            Ok::<_, StudyError>(quick(gpu, &spec, &grid, geometry_only(l))? - geo_simple)
        })?;
        // F(complex) aims at G(complex) as measured in the search.
        let frag_simple = quick(gpu, &spec, &grid, full(vs, fs))?;
        let fc = search_loops(setup.fs_loops[1], vc.reached_ms * 1e6, |l| {
            Ok::<_, StudyError>(quick(gpu, &spec, &grid, full(vs, l))? - frag_simple)
        })?;
        setup.vs_loops[1] = vc.loops;
        setup.fs_loops[1] = fc.loops;
        setup.vs_search = Some(vc);
        setup.fs_search = Some(fc);
    }
    let [vs, vc] = setup.vs_loops;
    let [fs, fc] = setup.fs_loops;
    let m = interleaved(
        gpu,
        &[
            ("grid:1x1", &tiny, geometry_only(0)),
            (&setup.mesh, &grid, geometry_only(vs)),
            (&setup.mesh, &grid, geometry_only(vc)),
            (&setup.mesh, &grid, full(vs, fs)),
            (&setup.mesh, &grid, full(vs, fc)),
            (&setup.mesh, &grid, full(vc, fs)),
            (&setup.mesh, &grid, full(vc, fc)),
        ],
        rounds,
    )?;
    let measured = H2Measured {
        overhead_ns: m[0].pass_time_ns,
        geometry_ns: [m[1].pass_time_ns, m[2].pass_time_ns],
        cells_ns: [
            [m[3].pass_time_ns, m[4].pass_time_ns],
            [m[5].pass_time_ns, m[6].pass_time_ns],
        ],
        vs_invocations: m[6].vs_invocations,
        fs_invocations: m[6].fs_invocations,
        fs_invocations_geometry_only: m[2].fs_invocations,
        triangles: grid.triangles(),
    };
    Ok(h2::analyze(setup, measured, t.elapsed().as_secs_f64())?)
}

/// Measures and analyses H3 (draw order).
pub fn run_h3(gpu: &Gpu, mut setup: H3Setup, rounds: u32) -> Result<H3, StudyError> {
    let t = Instant::now();
    let m = study_mesh(&setup.mesh)?;
    if let Some(target) = setup.auto_target_ms {
        let one = |fs_loops| MeasureOptions {
            size: setup.size,
            fs_loops,
            ..MeasureOptions::default()
        };
        let plain = quick(gpu, &setup.mesh, &m, one(0))?;
        let found = search_loops(setup.fs_loops, target * 1e6, |l| {
            Ok::<_, StudyError>(quick(gpu, &setup.mesh, &m, one(l))? - plain)
        })?;
        setup.fs_loops = found.loops;
        setup.fs_search = Some(found);
    }
    let base = MeasureOptions {
        size: setup.size,
        fs_loops: setup.fs_loops,
        ..MeasureOptions::default()
    };
    let layered = |depth_test, order| MeasureOptions {
        layers: setup.layers,
        depth_test,
        order,
        ..base.clone()
    };
    let r = interleaved(
        gpu,
        &[
            (&setup.mesh, &m, base.clone()),
            (&setup.mesh, &m, layered(false, DepthOrder::FrontToBack)),
            (&setup.mesh, &m, layered(true, DepthOrder::FrontToBack)),
            (&setup.mesh, &m, layered(true, DepthOrder::BackToFront)),
            (&setup.mesh, &m, layered(true, DepthOrder::Random)),
        ],
        rounds,
    )?;
    let pass = |r: &Measurement| H3Pass {
        time_ns: r.pass_time_ns,
        fs_invocations: r.fs_invocations,
    };
    let measured = H3Measured {
        one_layer: pass(&r[0]),
        all_layers: pass(&r[1]),
        ordered: [pass(&r[2]), pass(&r[3]), pass(&r[4])],
        triangles: m.triangles(),
    };
    Ok(h3::analyze(setup, measured, t.elapsed().as_secs_f64())?)
}

/// Measures and analyses H4 (cost per transformed vertex).
pub fn run_h4(gpu: &Gpu, mut setup: H4Setup, rounds: u32) -> Result<H4, StudyError> {
    let policy: crate::components::vertex_cache::CachePolicy = setup
        .cache
        .parse()
        .map_err(|e| StudyError::Mesh(format!("cache policy: {e}")))?;
    let specs = setup.orders();
    let meshes: Vec<Mesh> = specs.iter().map(|s| study_mesh(s)).collect::<Result<_, _>>()?;
    let t = Instant::now();
    if let Some(target) = setup.auto_target_ms {
        // The cache-optimized order's geometry-only pass, as a whole.
        let geometry = |vs_loops| MeasureOptions {
            size: setup.size,
            vs_loops,
            geometry_only: true,
            ..MeasureOptions::default()
        };
        let found = search_loops(setup.vs_loops, target * 1e6, |l| {
            quick(gpu, &specs[0], &meshes[0], geometry(l))
        })?;
        setup.vs_loops = found.loops;
        setup.vs_search = Some(found);
    }
    let opts = |geometry_only| MeasureOptions {
        size: setup.size,
        vs_loops: setup.vs_loops,
        geometry_only,
        ..MeasureOptions::default()
    };
    let mut conds: Vec<Condition> = Vec::new();
    for (spec, m) in specs.iter().zip(&meshes) {
        conds.push((spec, m, opts(true)));
        conds.push((spec, m, opts(false)));
    }
    let r = interleaved(gpu, &conds, rounds)?;
    let measure_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut rows = Vec::new();
    for (i, (spec, m)) in specs.iter().zip(&meshes).enumerate() {
        let (geo, full) = (&r[2 * i], &r[2 * i + 1]);
        rows.push(H4Row {
            mesh: spec.clone(),
            measured_vs: full.vs_invocations,
            simulated_vs: m.cache_stats(&policy).transformed,
            fs_invocations: full.fs_invocations,
            geometry_ms: geo.pass_time_ns / 1e6,
            measured_ms: full.pass_time_ns / 1e6,
            predicted_geometry_ms: None,
            predicted_ms: None,
        });
    }
    Ok(h4::analyze(setup, rows, measure_seconds, t.elapsed().as_secs_f64()))
}

/// Timed rounds per measurement unless told otherwise: 5, and the profile
/// study's own ([`super::profile_passes::DEFAULT_ROUNDS`]) when it is the
/// only study named.
pub fn default_rounds(names: &[&str]) -> u32 {
    if names == ["profile"] {
        super::profile_passes::DEFAULT_ROUNDS
    } else {
        5
    }
}

/// A study name that is not one.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown study {0:?} (available: h1, h2, h3, h4, all, estimation, profile)")]
pub struct UnknownStudy(pub String);

/// The studies `name` stands for: `h1` .. `h4`, or `all`.
pub fn study_names(name: &str) -> Result<Vec<&'static str>, UnknownStudy> {
    match name {
        "all" => Ok(vec!["h1", "h2", "h3", "h4"]),
        "profile" => Ok(vec!["profile"]),
        "h1" => Ok(vec!["h1"]),
        "h2" => Ok(vec!["h2"]),
        "h3" => Ok(vec!["h3"]),
        "h4" => Ok(vec!["h4"]),
        _ => Err(UnknownStudy(name.to_string())),
    }
}

/// What [`run_studies`] produced.
#[derive(Debug)]
pub struct StudiesRun {
    /// Verdict, section and wall time per study, in order.
    pub sections: Vec<StudySection>,
    /// Every study's full result (and the adapter), for `--json`.
    pub json: serde_json::Map<String, serde_json::Value>,
    /// The per-device Markdown document.
    pub document: String,
    /// H1's chosen policy and its residuals when it ran and did not predict
    /// every validation mesh exactly (a finding; `--require-exact` makes the
    /// command fail on it).
    pub h1_inexact: Option<H1Inexact>,
}

/// H1's fitted policy did not predict every validation mesh exactly.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct H1Inexact {
    /// The chosen policy.
    pub chosen: String,
    /// Per validation mesh: spec, measured and predicted vertex-shader
    /// invocations.
    pub validation: Vec<(String, u64, u64)>,
}

impl H1Inexact {
    /// The finding's lines: the policy, then one line per validation mesh
    /// with its residual (predicted - measured).
    pub fn describe(&self) -> String {
        let width = self.validation.iter().map(|(m, _, _)| m.len()).max().unwrap_or(0);
        let mut s = format!(
            "H1: the fitted policy `{}` does not predict every validation mesh exactly; \
             residuals (predicted - measured vertex-shader invocations):",
            self.chosen
        );
        for (mesh, measured, predicted) in &self.validation {
            s += &format!(
                "\n  {mesh:<width$}  {:+7}  ({measured} measured, {predicted} predicted)",
                *predicted as i64 - *measured as i64
            );
        }
        s
    }
}

fn to_json<T: serde::Serialize>(v: &T) -> serde_json::Value {
    serde_json::to_value(v).unwrap_or(serde_json::Value::Null)
}

/// Runs the named studies on `gpu` (`rounds` timed passes each, medians),
/// calling `progress` after each; `command` is quoted in the document.
pub fn run_studies(
    gpu: &Gpu,
    names: &[&str],
    rounds: u32,
    command: &str,
    mut progress: impl FnMut(&StudySection),
) -> Result<StudiesRun, StudyError> {
    let mut sections = Vec::new();
    let mut json = serde_json::Map::new();
    let mut h1_inexact = None;
    // H2-H4 price vertices with the reuse policy H1 identifies on this
    // device: run H1 first (it only reads counters, one pass per mesh).
    let mut fitted: Option<(h1::H1, f64)> = None;
    if names.iter().any(|n| !matches!(*n, "h1" | "profile")) {
        let t = Instant::now();
        fitted = Some((h1::h1(gpu, 1)?, t.elapsed().as_secs_f64()));
    }
    let cache = fitted
        .as_ref()
        .map_or_else(|| "lavapipe".to_string(), |(r, _)| r.chosen.clone());
    for &n in names {
        let t = Instant::now();
        let mut earlier = 0.0;
        let (verdict, markdown, value) = match n {
            "h1" => {
                let r = match fitted.take() {
                    Some((r, secs)) => {
                        earlier = secs;
                        r
                    }
                    None => h1::h1(gpu, 1)?,
                };
                if !r.exact {
                    h1_inexact = Some(H1Inexact {
                        chosen: r.chosen.clone(),
                        validation: r
                            .validation
                            .iter()
                            .map(|v| (v.mesh.clone(), v.measured, v.predicted))
                            .collect(),
                    });
                }
                (r.verdict(), r.markdown(), to_json(&r))
            }
            "h2" => {
                let setup = H2Setup {
                    cache: cache.clone(),
                    ..H2Setup::default()
                };
                let r = run_h2(gpu, setup, rounds)?;
                (r.verdict(), r.markdown(), to_json(&r))
            }
            "h3" => {
                let setup = H3Setup {
                    cache: cache.clone(),
                    ..H3Setup::default()
                };
                let r = run_h3(gpu, setup, rounds)?;
                (r.verdict(), r.markdown(), to_json(&r))
            }
            "h4" => {
                let setup = H4Setup {
                    cache: cache.clone(),
                    ..H4Setup::default()
                };
                let r = run_h4(gpu, setup, rounds)?;
                (r.verdict(), r.markdown(), to_json(&r))
            }
            "profile" => {
                let r = super::profile_passes::run_profile(gpu, rounds)?;
                (r.verdict(), r.markdown(), to_json(&r))
            }
            other => return Err(StudyError::Mesh(format!("unknown study {other:?}"))),
        };
        json.insert(n.to_string(), value);
        let section = StudySection {
            name: n.to_uppercase(),
            verdict,
            markdown,
            seconds: earlier + t.elapsed().as_secs_f64(),
        };
        progress(&section);
        sections.push(section);
    }
    json.insert("adapter".into(), to_json(&gpu.adapter));
    let notes = if gpu.adapter.device_type == "Cpu" {
        "The adapter is a software rasterizer on this machine's CPU: pass times include \
         the CPU time it spends and vary with the machine's load."
    } else {
        ""
    };
    let document = device_document(&gpu.describe(), command, notes, &sections);
    Ok(StudiesRun {
        sections,
        json,
        document,
        h1_inexact,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_inexact_h1_lists_every_validation_mesh_with_its_residual() {
        let f = H1Inexact {
            chosen: "meshopt:32,32,32".into(),
            validation: vec![
                ("grid:16x16".into(), 576, 576),
                ("grid:48x48:optimized".into(), 3883, 3873),
            ],
        };
        let text = f.describe();
        assert!(
            text.starts_with("H1: the fitted policy `meshopt:32,32,32` does not predict"),
            "{text}"
        );
        let lines: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split_whitespace().collect()).collect();
        assert_eq!(lines.len(), 2, "{text}");
        assert_eq!(lines[0][..3], ["grid:16x16", "+0", "(576"], "{text}");
        assert_eq!(lines[1][..3], ["grid:48x48:optimized", "-10", "(3883"], "{text}");
    }
}
