//! A replay's validation report (issue 54, item 4): every swap chain of a
//! capture replayed as captured, its accuracy against the targets, the
//! display inferred for it, and each frame where measured and replayed
//! disagree with the reason: a fate the two do not share (the replay
//! dropped a frame the capture showed, or showed one the compositor or
//! the queue dropped), a whole number of refreshes early or late (a missed
//! refresh, or one the compositor took), a time off the refresh grid (a
//! variable refresh or a tear that came earlier or later), or a fate the
//! capture itself does not know.
//!
//! [`validate`] makes the report; [`ValidationReport::write`] writes it as
//! `report.md`, `chains.csv`, and per swap chain `chain-N.csv` (the frames
//! that disagree) and `chain-N-screen.{png,svg}` (measured and replayed
//! time until displayed, frame by frame).

use std::path::Path;

use serde::Serialize;

use super::results::json_name;
use super::{Replay, ReplayError, ReplayOptions, replay_capture};
use crate::capture::presentmon::{Capture, SwapChainInfo};

/// The accuracy targets a swap chain is held to (issue 26): fates agree on
/// at least this share of frames...
pub const TARGET_AGREEMENT: f64 = 0.95;
/// ... `MsUntilDisplayed`'s median |error| at most this, ms ...
pub const TARGET_UNTIL_MEDIAN_MS: f64 = 0.5;
/// ... and its p90 at most this, ms ...
pub const TARGET_UNTIL_P90_MS: f64 = 2.0;
/// ... and render completion's median |error| at most this, ms.
pub const TARGET_RENDER_MEDIAN_MS: f64 = 0.5;

/// An error of the time until displayed this small (ms) is agreement.
const AGREE_MS: f64 = 0.5;

/// Why a frame's measured and replayed fates or times differ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Reason {
    /// The capture showed the frame; the replay dropped it.
    ReplayDropped,
    /// The capture's compositor dropped the frame (a composed swap
    /// chain); the replay showed it.
    CompositorDropped,
    /// The frame was replaced in the queue before its refresh (an
    /// independent flip); the replay showed it.
    QueueDropped,
    /// The capture does not say whether the frame was shown (`Dropped`
    /// neither 0 nor 1).
    FateUnknown,
    /// Shown a whole number of refreshes later (positive) or earlier than
    /// measured: a refresh missed, or one more the compositor took.
    Refreshes(i64),
    /// Shown off the refresh grid by this much, ms (a variable refresh's or
    /// a tear's timing).
    OffGrid(f64),
}

impl Reason {
    /// The reason in words.
    pub fn describe(&self) -> String {
        match self {
            Reason::ReplayDropped => "the capture showed it, the replay dropped it".into(),
            Reason::CompositorDropped => "the compositor dropped it, the replay showed it".into(),
            Reason::QueueDropped => "replaced in the queue before its refresh, the replay showed it".into(),
            Reason::FateUnknown => "the capture does not say whether it was shown".into(),
            Reason::Refreshes(k) if *k > 0 => format!("{k} refresh(es) later than measured"),
            Reason::Refreshes(k) => format!("{} refresh(es) earlier than measured", -k),
            Reason::OffGrid(d) => format!("{d:+.3} ms off the refresh grid"),
        }
    }

    /// A short label for counting.
    fn kind(&self) -> String {
        match self {
            Reason::Refreshes(k) if *k > 0 => format!("{k} refresh(es) late"),
            Reason::Refreshes(k) => format!("{} refresh(es) early", -k),
            Reason::OffGrid(_) => "off the refresh grid".into(),
            r => r.describe(),
        }
    }
}

/// A frame that disagrees.
#[derive(Debug, Clone, Serialize)]
pub struct Disagreement {
    /// The frame's line in the capture.
    pub line: u64,
    /// Its present, ms on the capture's clock.
    pub present_ms: f64,
    /// Time until displayed, measured and replayed, ms.
    pub until_measured_ms: Option<f64>,
    /// Replayed.
    pub until_replayed_ms: Option<f64>,
    /// Why.
    pub reason: Reason,
}

/// One swap chain's part of the report.
#[derive(Debug)]
pub struct ChainReport {
    /// The swap chain.
    pub chain: SwapChainInfo,
    /// Its replay, or why it cannot be replayed.
    pub replay: Result<Replay, String>,
    /// The frames that disagree.
    pub disagreements: Vec<Disagreement>,
}

impl ChainReport {
    /// Measured, from the GPU finishing each shown frame (present plus
    /// `MsRenderPresentLatency` or `MsUntilRenderComplete`) to the frame on
    /// screen, in refreshes: the 10th percentile, the median and the 90th
    /// (`None` without such frames). On a composed swap chain this is the
    /// compositor's delay as the capture shows it.
    pub fn gpu_done_to_screen_refreshes(&self) -> Option<[f64; 3]> {
        let r = self.replay.as_ref().ok()?;
        let period = 1000.0 / r.summary.refresh_hz;
        let mut lag: Vec<f64> = r
            .frames
            .iter()
            .filter_map(|f| Some((f.until_displayed.0? - f.render_complete.0?) / period))
            .collect();
        if lag.is_empty() {
            return None;
        }
        lag.sort_by(f64::total_cmp);
        let q = |x: f64| crate::stats::quantile::quantile(&lag, x);
        Some([q(0.1), q(0.5), q(0.9)])
    }

    /// Whether the swap chain meets the accuracy targets.
    pub fn meets_targets(&self) -> bool {
        let Ok(r) = &self.replay else { return false };
        let (s, e) = (&r.summary, &r.summary.error_ms);
        s.agreement.displayed >= TARGET_AGREEMENT
            && e.until_displayed.median.is_some_and(|m| m <= TARGET_UNTIL_MEDIAN_MS)
            && e.until_displayed.p90.is_some_and(|m| m <= TARGET_UNTIL_P90_MS)
            && e.render_complete.median.is_none_or(|m| m <= TARGET_RENDER_MEDIAN_MS)
    }
}

/// The whole report.
#[derive(Debug)]
pub struct ValidationReport {
    /// The capture as read.
    pub capture: Capture,
    /// Every swap chain, most frames first.
    pub chains: Vec<ChainReport>,
}

/// Replays every swap chain of the capture at `path` as captured (with
/// `opts.assume`; `opts.app`, `opts.swap_chain` and `opts.sets` are not
/// used) and finds the frames where measured and replayed disagree.
pub fn validate(path: &Path, opts: &ReplayOptions) -> Result<ValidationReport, ReplayError> {
    let capture = Capture::read(path)?;
    let mut chains = Vec::new();
    for chain in capture.swap_chains() {
        let o = ReplayOptions {
            app: Some(chain.application.clone()),
            swap_chain: Some(chain.swap_chain.clone()),
            sets: Vec::new(),
            assume: opts.assume.clone(),
            from_tables: opts.from_tables,
        };
        let replay = replay_capture(&capture, &o, std::time::Instant::now());
        let disagreements = replay.as_ref().map(disagreements).unwrap_or_default();
        chains.push(ChainReport {
            chain,
            replay: replay.map_err(|e| e.to_string()),
            disagreements,
        });
    }
    Ok(ValidationReport { capture, chains })
}

/// The frames of a replay where measured and replayed disagree.
pub fn disagreements(r: &Replay) -> Vec<Disagreement> {
    let period = 1000.0 / r.summary.refresh_hz;
    let composed = !r.summary.model_composition.is_independent();
    let mut out = Vec::new();
    let fate_unknown: std::collections::HashSet<u64> = r.unknown_fates.iter().copied().collect();
    for f in &r.frames {
        let (m, p) = f.until_displayed;
        let reason = if fate_unknown.contains(&f.line) {
            (!f.predicted_displayed || f.displayed).then_some(Reason::FateUnknown)
        } else {
            match (f.displayed, f.predicted_displayed, m, p) {
                (true, false, ..) => Some(Reason::ReplayDropped),
                (false, true, ..) if composed => Some(Reason::CompositorDropped),
                (false, true, ..) => Some(Reason::QueueDropped),
                (true, true, Some(m), Some(p)) if (p - m).abs() > AGREE_MS => {
                    let k = ((p - m) / period).round();
                    if k != 0.0 && (p - m - k * period).abs() <= AGREE_MS {
                        Some(Reason::Refreshes(k as i64))
                    } else {
                        Some(Reason::OffGrid(p - m - k * period))
                    }
                }
                _ => None,
            }
        };
        if let Some(reason) = reason {
            out.push(Disagreement {
                line: f.line,
                present_ms: f.present,
                until_measured_ms: m,
                until_replayed_ms: p,
                reason,
            });
        }
    }
    out
}

/// The columns of `chains.csv`.
pub const CHAIN_COLUMNS: [&str; 18] = [
    "chain",
    "application",
    "process_id",
    "swap_chain",
    "present_mode",
    "frames",
    "model_present_mode",
    "refresh_hz",
    "refresh_from",
    "flips",
    "agreement",
    "until_displayed_median_ms",
    "until_displayed_p90_ms",
    "render_complete_median_ms",
    "gpu_done_to_screen_refreshes_median",
    "compositor_wake_ms",
    "compositor_refreshes",
    "meets_targets",
];

impl ValidationReport {
    /// Writes the report into `dir` (which exists): `report.md`,
    /// `chains.csv`, and per swap chain `chain-N.csv` and
    /// `chain-N-screen.{png,svg}`.
    pub fn write(&self, dir: &Path) -> Result<(), std::io::Error> {
        std::fs::write(dir.join("report.md"), self.markdown())?;
        let mut csv = CHAIN_COLUMNS.join(",") + "\n";
        for (i, c) in self.chains.iter().enumerate() {
            csv += &self.chain_row(i, c);
            if c.replay.is_ok() {
                std::fs::write(dir.join(format!("chain-{i}.csv")), disagreement_csv(&c.disagreements))?;
                self.plot(dir, i, c)?;
            }
        }
        std::fs::write(dir.join("chains.csv"), csv)
    }

    fn chain_row(&self, i: usize, c: &ChainReport) -> String {
        let q = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
        let ch = &c.chain;
        let head = format!(
            "{i},{},{},{},{},{}",
            q(&ch.application),
            q(&ch.process_id),
            q(&ch.swap_chain),
            q(&ch.present_mode),
            ch.frames
        );
        let opt = |x: Option<f64>| x.map_or(String::new(), |v| v.to_string());
        match &c.replay {
            Err(_) => format!("{head},,,,,,,,,,,,false\n"),
            Ok(r) => {
                let s = &r.summary;
                format!(
                    "{head},{},{},{},{},{},{},{},{},{},{},{},{}\n",
                    s.model_present_mode,
                    s.refresh_hz,
                    json_name(s.refresh_from),
                    json_name(s.display.flips),
                    s.agreement.displayed,
                    opt(s.error_ms.until_displayed.median),
                    opt(s.error_ms.until_displayed.p90),
                    opt(s.error_ms.render_complete.median),
                    opt(c.gpu_done_to_screen_refreshes().map(|q| q[1])),
                    opt(s.display.compositor.as_ref().map(|k| k.wake_ms)),
                    opt(s.display.compositor.as_ref().map(|k| f64::from(k.refreshes))),
                    c.meets_targets()
                )
            }
        }
    }

    fn plot(&self, dir: &Path, i: usize, c: &ChainReport) -> Result<(), std::io::Error> {
        use crate::plot::{LinePlot, Series, line_plot};
        let Ok(r) = &c.replay else { return Ok(()) };
        let t0 = r.frames.first().map_or(0.0, |f| f.present);
        let series = |name: &str, pick: &dyn Fn(&super::ReplayFrame) -> Option<f64>| Series {
            name: name.into(),
            points: r
                .frames
                .iter()
                .filter_map(|f| pick(f).map(|u| ((f.present - t0) / 1e3, u)))
                .collect(),
            ..Series::default()
        };
        let plot = LinePlot {
            title: format!("{} {}: present to screen", c.chain.application, c.chain.swap_chain),
            x_label: "present, s from the swap chain's first".into(),
            y_label: "until displayed, ms".into(),
            series: vec![
                series("measured", &|f| f.until_displayed.0),
                series("replayed", &|f| f.until_displayed.1),
            ],
            ..LinePlot::default()
        };
        line_plot(&dir.join(format!("chain-{i}-screen")), &plot).map_err(std::io::Error::other)
    }

    /// The report as Markdown.
    pub fn markdown(&self) -> String {
        let c = &self.capture;
        let mut md = format!("# Replay validation: {}\n\n", c.file);
        md += &format!(
            "{:?} columns, {} presents the application rendered, {} frames it did not (generated or repeated).\n\n",
            c.columns,
            c.presents.len(),
            c.generated.len()
        );
        if !c.metadata.is_empty() {
            md += "What the capture says of itself:\n\n";
            for (k, v) in &c.metadata {
                md += &format!("- {k}: {v}\n");
            }
            md += "\n";
        }
        if !c.notes.is_empty() {
            md += "What the reader undid:\n\n";
            for n in &c.notes {
                md += &format!("- {n}\n");
            }
            md += "\n";
        }
        let met = self.chains.iter().filter(|c| c.meets_targets()).count();
        md += &format!(
            "## Swap chains\n\n{met} of {} meet the accuracy targets (fates agree on {:.0}% of frames, time until displayed within {TARGET_UNTIL_MEDIAN_MS} ms at the median and {TARGET_UNTIL_P90_MS} ms at p90, render completion within {TARGET_RENDER_MEDIAN_MS} ms at the median; `chains.csv`).\n\n",
            self.chains.len(),
            100.0 * TARGET_AGREEMENT
        );
        md += "| # | swap chain | frames | present mode | model | refresh | flips | fates agree | until displayed median / p90, ms | render complete median, ms | meets |\n";
        md += "| ---: | --- | ---: | --- | --- | --- | --- | ---: | --- | ---: | --- |\n";
        for (i, ch) in self.chains.iter().enumerate() {
            md += &chain_line(i, ch);
        }
        for (i, ch) in self.chains.iter().enumerate() {
            md += &chain_section(i, ch);
        }
        md
    }
}

fn chain_line(i: usize, ch: &ChainReport) -> String {
    let name = format!("{} {}", ch.chain.application, ch.chain.swap_chain);
    match &ch.replay {
        Err(e) => format!(
            "| {i} | {name} | {} | {} | not replayed: {} | | | | | | no |\n",
            ch.chain.frames,
            ch.chain.present_mode,
            e.replace('|', "/")
        ),
        Ok(r) => {
            let s = &r.summary;
            let e = &s.error_ms;
            let f = |x: Option<f64>| x.map_or("-".into(), |v| format!("{v:.3}"));
            format!(
                "| {i} | {name} | {} | {} | {} | {:.2} Hz ({}) | {} | {:.1}% | {} / {} | {} | {} |\n",
                s.frames,
                s.present_mode,
                s.model_label(),
                s.refresh_hz,
                json_name(s.refresh_from),
                json_name(s.display.flips),
                100.0 * s.agreement.displayed,
                f(e.until_displayed.median),
                f(e.until_displayed.p90),
                f(e.render_complete.median),
                if ch.meets_targets() { "yes" } else { "no" }
            )
        }
    }
}

fn chain_section(i: usize, ch: &ChainReport) -> String {
    let Ok(r) = &ch.replay else { return String::new() };
    let mut md = format!(
        "\n## {i}: {} {} ({})\n\nDisplay: {}.\n\n",
        ch.chain.application,
        ch.chain.swap_chain,
        ch.chain.present_mode,
        r.summary.display.describe()
    );
    if let Some([lo, mid, hi]) = ch.gpu_done_to_screen_refreshes() {
        md += &format!(
            "Measured, from the GPU finishing a shown frame to the frame on screen: {mid:.2} refreshes at the median ({lo:.2}-{hi:.2}, 10th-90th percentile){}.\n\n",
            match (&r.summary.display.compositor, r.summary.model_composition.is_independent()) {
                (_, true) => String::new(),
                (Some(c), false) => format!(
                    "; the replay's compositor, inferred from these frames, takes the newest ready frame {:.2} ms after each vertical blank and shows it {} blank(s) after the one before",
                    c.wake_ms, c.refreshes
                ),
                (None, false) => "; the replay's compositor takes each frame at the vertical blank and shows it one refresh later (too few frames to infer its timing)".to_string(),
            }
        );
    }
    md += &format!("![measured and replayed time until displayed](chain-{i}-screen.png)\n\n");
    if ch.disagreements.is_empty() {
        md += "Every frame agrees (fate, and time until displayed within 0.5 ms).\n";
        return md;
    }
    let mut counts: Vec<(String, usize)> = Vec::new();
    for d in &ch.disagreements {
        let k = d.reason.kind();
        match counts.iter_mut().find(|(x, _)| *x == k) {
            Some((_, n)) => *n += 1,
            None => counts.push((k, 1)),
        }
    }
    counts.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    md += &format!(
        "{} of {} frames disagree (`chain-{i}.csv` lists each):\n\n",
        ch.disagreements.len(),
        r.frames.len()
    );
    for (k, n) in &counts {
        md += &format!("- {n}: {k}\n");
    }
    md += "\nThe first of them:\n\n| line | present, ms | until displayed measured / replayed, ms | why |\n| ---: | ---: | --- | --- |\n";
    let f = |x: Option<f64>| x.map_or("not shown".into(), |v| format!("{v:.3}"));
    for d in ch.disagreements.iter().take(10) {
        md += &format!(
            "| {} | {:.3} | {} / {} | {} |\n",
            d.line,
            d.present_ms,
            f(d.until_measured_ms),
            f(d.until_replayed_ms),
            d.reason.describe()
        );
    }
    md
}

/// The frames that disagree, as CSV.
fn disagreement_csv(ds: &[Disagreement]) -> String {
    let mut s = String::from("Line,PresentTime,MsUntilDisplayed,ReplayedMsUntilDisplayed,Reason\n");
    let f = |x: Option<f64>| x.map_or("NA".into(), |v| v.to_string());
    for d in ds {
        s += &format!(
            "{},{},{},{},\"{}\"\n",
            d.line,
            d.present_ms,
            f(d.until_measured_ms),
            f(d.until_replayed_ms),
            d.reason.describe()
        );
    }
    s
}
