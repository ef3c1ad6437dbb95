//! The estimation study's outputs: the per-device Markdown document
//! (`--markdown`, `docs/measurements/<adapter>-estimation.md`) and one CSV
//! row per object drawn (`--csv`).

use crate::systems::walkthrough::estimators::Score;

use super::analysis::sig;
use super::{EstimationStudy, PassMeasurement, Plan};

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
