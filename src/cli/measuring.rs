//! The commands that measure on this machine's GPU (feature `wgpu`):
//! `rendersim measure` (one pass, its row appended to a pass CSV) and
//! `rendersim study` (the hypothesis studies H1-H4 and the estimation
//! study, their passes appended as rows, the machine's load recorded
//! beside them). Without the feature each says how to build with it.

use anyhow::{Result, bail};

use super::args::{MeasureArgs, StudyArgs};

#[cfg(feature = "wgpu")]
use {
    super::print,
    super::progress::{esay, say},
    anyhow::Context,
    rendersim::output::files::check_distinct,
    serde_json::json,
    std::path::Path,
};

/// `rendersim measure`.
#[cfg(feature = "wgpu")]
pub fn measure(args: MeasureArgs) -> Result<()> {
    use rendersim::measure::passes::{PassRow, append_passes, check_appendable};
    let mesh = &args.mesh;
    if let Some(path) = &args.csv {
        if args.layers != 1 || args.depth_test {
            bail!(
                "--csv: a pass CSV row has no column for layers or the depth test; measure one layer without --depth-test"
            );
        }
        // A file with another header is refused before any device time is spent.
        check_appendable(path, args.draws)?;
    }
    let m = rendersim::scene::generators::mesh_from_spec(mesh, Path::new("."))?;
    let r = rendersim::measure::measure(&m, mesh, &(&args).into())?;
    if let Some(path) = &args.csv {
        let row = PassRow::from_measurement(mesh, &r)
            .with_context(|| format!("--csv: {mesh:?} is not a mesh spec a pass CSV can name"))?;
        append_passes(path, &[row])?;
    }
    let mut v = serde_json::to_value(&r)?;
    v["mesh"] = json!({"spec": mesh, "triangles": m.triangles(), "indices": m.index_count(), "unique_vertices": m.unique_vertices()});
    if args.json {
        say!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        say!("{}", print::measurement(mesh, &r));
    }
    Ok(())
}

/// `rendersim measure` without the `wgpu` feature.
#[cfg(not(feature = "wgpu"))]
pub fn measure(_args: MeasureArgs) -> Result<()> {
    bail!(
        "this rendersim was built without the `wgpu` feature; rebuild with `cargo build --release --features wgpu` (and, without a GPU, install Debian's mesa-vulkan-drivers for lavapipe)"
    )
}

/// `rendersim study`.
#[cfg(feature = "wgpu")]
pub fn study(args: StudyArgs) -> Result<()> {
    use rendersim::measure::passes::{append_passes, check_appendable};
    use rendersim::measure::{Gpu, studies};
    if let (Some(m), Some(c)) = (&args.markdown, &args.csv) {
        check_distinct(&[("--markdown", m), ("--csv", c)])?;
    }
    if args.name == super::args::Study::Estimation {
        return study_estimation(args);
    }
    if args.single.is_some() || args.multi.is_some() || args.seed.is_some() || args.load_scale.is_some() {
        bail!("--single, --multi, --seed and --load-scale belong to `rendersim study estimation`");
    }
    let (name, json) = (args.name.name(), args.json);
    let names = studies::study_names(&name)?;
    let repeats = args.repeats.unwrap_or_else(|| studies::default_rounds(&names));
    if repeats == 0 {
        bail!("--repeats must be at least 1");
    }
    if let Some(path) = &args.csv {
        check_appendable(path, 1)?;
    }
    let gpu = Gpu::open()?;
    let load_start = rendersim::measure::machine_load::load_average();
    let command = format!("rendersim study {name} --repeats {repeats}");
    let result = studies::run_studies(&gpu, &names, repeats, &command, |s| {
        if !json {
            say!("{}: {}", s.name, s.verdict);
        }
    });
    // The passes measured are kept even when a study failed part-way.
    if let Some(path) = &args.csv {
        let passes = gpu.measured_passes();
        let written = append_passes(path, &passes.rows);
        match (&written, &result) {
            (Ok(()), _) => esay!(
                "{} passes appended to {} ({} measurements of H1's probes or of layered or depth-tested passes \
                 left out: the pass CSV has no column for them)",
                passes.rows.len(),
                path.display(),
                passes.left_out
            ),
            (Err(e), Err(_)) => esay!("error: {e}"),
            (Err(_), Ok(_)) => {}
        }
        if written.is_ok() {
            record_load(path, &command, passes.rows.len(), load_start);
        }
        if result.is_ok() {
            written?;
        }
    }
    let r = result?;
    if let Some(path) = args.markdown {
        rendersim::output::files::write_output(&path, |w| w.write_all(r.document.as_bytes()))?;
    }
    if json {
        say!("{}", serde_json::to_string_pretty(&r.json)?);
    } else {
        say!("\n{}", r.document);
    }
    if let Some(finding) = r.h1_inexact {
        if args.require_exact {
            bail!("{} (--require-exact)", finding.describe());
        }
        // A finding on this device, not a failure.
        if json {
            esay!("finding: {}", finding.describe());
        } else {
            say!("finding: {}", finding.describe());
        }
    }
    Ok(())
}

/// `rendersim study estimation`: h1-h4 fitted on measured single-object
/// passes, pos tables from table passes, both scored on multi-object passes.
#[cfg(feature = "wgpu")]
fn study_estimation(args: StudyArgs) -> Result<()> {
    use rendersim::measure::Gpu;
    use rendersim::measure::estimation::{CSV_HEADER, EstimationSetup, Plan, csv_rows};
    use rendersim::measure::estimation_device::run_estimation;
    use rendersim::output::files::write_output;
    if args.require_exact {
        bail!("--require-exact belongs to study H1 (`study h1` or `study all`), not to `study estimation`");
    }
    let d = EstimationSetup::default();
    let setup = EstimationSetup {
        seed: args.seed.unwrap_or(d.seed),
        single: args.single.unwrap_or(d.single),
        multi: args.multi.unwrap_or(d.multi),
        repeats: args.repeats.unwrap_or(d.repeats),
        load_scale: args.load_scale.unwrap_or(d.load_scale),
        ..d
    };
    // Validated (and every pass generated) before the adapter is opened.
    let plan = Plan::new(&setup)?;
    let gpu = Gpu::open()?;
    let command = format!(
        "rendersim study estimation --single {} --multi {} --repeats {} --seed {} --load-scale {}",
        setup.single, setup.multi, setup.repeats, setup.seed, setup.load_scale
    );
    if !args.json {
        esay!(
            "measuring {} passes ({} objects) x {} rounds on {}",
            plan.passes.len(),
            plan.objects(),
            setup.repeats,
            gpu.describe()
        );
    }
    let load_start = rendersim::measure::machine_load::load_average();
    let run = run_estimation(&gpu, plan, &command)?;
    if let Some(path) = &args.csv {
        let rows = csv_rows(&run.plan, &run.measured, &run.study);
        let n = rows.len();
        write_output(path, |w| rendersim::output::table::write_table(w, &CSV_HEADER, rows))?;
        record_load(path, &command, n, load_start);
    }
    let document = run.study.markdown();
    if let Some(path) = &args.markdown {
        write_output(path, |w| w.write_all(document.as_bytes()))?;
    }
    if args.json {
        say!("{}", serde_json::to_string_pretty(&run.study)?);
    } else {
        say!("{document}");
    }
    Ok(())
}

/// Appends the machine's load while measuring to `FILE.load.csv` beside the
/// pass CSV `csv` (`rendersim::measure::machine_load`); a failure to write
/// it is a warning, the measurements being kept.
#[cfg(feature = "wgpu")]
fn record_load(csv: &std::path::Path, command: &str, rows: usize, start: Option<[f64; 3]>) {
    use rendersim::measure::machine_load::{LoadRecord, append_load, load_average};
    let r = LoadRecord {
        date_utc: rendersim::provenance(Vec::new()).date,
        command: command.to_string(),
        rows,
        cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
        start,
        end: load_average(),
    };
    match append_load(csv, &r) {
        Ok(p) => esay!("machine load while measuring recorded in {}", p.display()),
        Err(e) => esay!(
            "warning: the machine's load could not be recorded beside {}: {e}",
            csv.display()
        ),
    }
}

/// `rendersim study` without the `wgpu` feature.
#[cfg(not(feature = "wgpu"))]
pub fn study(_args: StudyArgs) -> Result<()> {
    bail!("this rendersim was built without the `wgpu` feature; rebuild with `cargo build --release --features wgpu`")
}
