//! A replay's summary as text (`rendersim replay`, and the `replay`
//! system's report): the swap chain, the fates' agreement, the errors per
//! measured quantity, and the display figures measured, replayed as
//! captured and under the what-if.

use super::ReplaySummary;

/// The display figures of a replay: measured, replayed as captured, and
/// the what-if's when it has patches.
fn display_figures(s: &ReplaySummary, w: &mut impl std::io::Write) -> std::io::Result<()> {
    use super::display_stats::DisplayStats;
    let mut cols: Vec<(&str, &DisplayStats)> = vec![("measured", &s.measured), ("as captured", &s.as_captured)];
    if !s.whatif.sets.is_empty() {
        writeln!(w, "  what-if: {}", s.whatif.sets.join(", "))?;
        cols.push(("what-if", &s.whatif.stats));
    }
    let f = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2}"));
    type Row<'a> = (&'a str, &'a dyn Fn(&DisplayStats) -> String);
    let rows: [Row; 9] = [
        ("display latency median (ms)", &|d| f(d.display_latency_ms.median)),
        ("display latency p90 (ms)", &|d| f(d.display_latency_ms.p90)),
        ("display latency p99 (ms)", &|d| f(d.display_latency_ms.p99)),
        ("frame rate (fps)", &|d| f(d.fps)),
        ("1% low (fps)", &|d| f(d.low_1pct_fps)),
        ("dropped frames", &|d| d.dropped.to_string()),
        ("repeated refreshes", &|d| d.repeated_refreshes.to_string()),
        ("stutters", &|d| d.stutters.to_string()),
        ("torn frames per second", &|d| f(d.torn_per_second)),
    ];
    // Tearing only where a column has it.
    let rows = rows.into_iter().filter(|(label, _)| {
        *label != "torn frames per second" || cols.iter().any(|(_, d)| d.torn_per_second.is_some())
    });
    write!(w, "  {:<30}", "")?;
    for (name, _) in &cols {
        write!(w, "{name:>13}")?;
    }
    writeln!(w)?;
    for (label, value) in rows {
        write!(w, "  {label:<30}")?;
        for (_, d) in &cols {
            write!(w, "{:>13}", value(d))?;
        }
        writeln!(w)?;
    }
    Ok(())
}

/// A replay's summary as text.
pub fn write_text(s: &ReplaySummary, w: &mut impl std::io::Write) -> std::io::Result<()> {
    let stat = |e: &super::ErrorStats| match (e.median, e.p90, e.max) {
        (Some(m), Some(p), Some(x)) => format!("median {m:.3}  p90 {p:.3}  max {x:.3}  ({} frames)", e.frames),
        _ => "no frame to compare".to_string(),
    };
    writeln!(w, "replay of {} ({:?} columns)", s.capture, s.columns)?;
    writeln!(
        w,
        "  swap chain {} of {}: {} frames, {} (model: {}), refresh {:.3} Hz",
        s.swapchain,
        s.application,
        s.frames,
        s.present_mode,
        s.model_label(),
        s.refresh_hz
    )?;
    writeln!(w, "  display: {}", s.display.describe())?;
    if let Some(i) = &s.images {
        writeln!(
            w,
            "  swap chain: {} images (its GPU finished frames as early as only {} allow; {} left them {:.2} ms late)",
            i.buffers, i.buffers, i.instead_of, i.late_ms_instead
        )?;
    }
    for note in &s.capture_notes {
        writeln!(w, "  read: {note}")?;
    }
    writeln!(
        w,
        "  displayed: measured {}, predicted {}; fates agree on {:.1}% of frames",
        s.measured_displayed,
        s.predicted_displayed,
        100.0 * s.agreement.displayed
    )?;
    writeln!(
        w,
        "  |error| ms, MsUntilDisplayed        {}",
        stat(&s.error_ms.until_displayed)
    )?;
    writeln!(
        w,
        "  |error| ms, MsBetweenDisplayChange  {}",
        stat(&s.error_ms.between_display_change)
    )?;
    writeln!(
        w,
        "  |error| ms, render complete         {}",
        stat(&s.error_ms.render_complete)
    )?;
    writeln!(w, "  |error| ms, present time            {}", stat(&s.error_ms.present))?;
    display_figures(s, w)?;
    let l = &s.measured_input_latency;
    for (name, p) in [
        ("PC latency (MsPCLatency)", &l.pc_latency_ms),
        ("all input to photon", &l.all_input_to_photon_ms),
        ("click to photon", &l.click_to_photon_ms),
    ] {
        if let Some(p) = p
            && let (Some(m), Some(p90)) = (p.median, p.p90)
        {
            writeln!(w, "  measured {name}: median {m:.2} ms, p90 {p90:.2} ms")?;
        }
    }
    if let Some(lead) = &l.input_lead {
        writeln!(
            w,
            "  input sampled {:.2} ms before PresentMon's CPU start (median over {} frames): {:.2} frames of {:.2} ms, which the predicted PC latency keeps",
            lead.ms, lead.measured_over, lead.frames, lead.interval_ms
        )?;
    }
    if let Some(c) = &s.compare {
        compare_table(c, w)?;
    }
    writeln!(
        w,
        "  {:.4} s wall ({:.4} s simulating)",
        s.wall_seconds, s.simulate_seconds
    )
}

/// The `--compare` table: each figure predicted, measured and their ratio.
fn compare_table(c: &super::compare::Comparison, w: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(
        w,
        "  compared with {} ({} {}, {} frames):",
        c.capture, c.application, c.swapchain, c.frames
    )?;
    writeln!(w, "  {:<28} {:>10} {:>10} {:>7}", "", "predicted", "measured", "ratio")?;
    let v = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.2}"));
    for (name, m) in c.rows() {
        writeln!(
            w,
            "  {name:<28} {:>10} {:>10} {:>7}",
            v(m.predicted),
            v(m.measured),
            m.ratio.map_or("-".to_string(), |r| format!("{r:.3}"))
        )?;
    }
    writeln!(w, "  PC latency predicted with {}", c.pc_latency_assumption)
}
