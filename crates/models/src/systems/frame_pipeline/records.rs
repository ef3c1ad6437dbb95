//! Per-frame records and the frames table (`frames.csv`), written as
//! PresentMon 2 writes a capture, so that the tools that read PresentMon
//! read it, and `rendersim replay` reads it back (a rendersim run replays
//! exactly: `tests/it/replay_round_trip.rs`).
//!
//! The PresentMon columns have PresentMon's meaning (its console
//! application's README, "CSV columns"), with rendersim's present being the
//! moment the CPU thread pushes the frame's swap into the command FIFO:
//!
//! - `CPUStartTime`: when the CPU began working on the frame (after any wait
//!   for frames in flight and any pacing), in ms from the run's start;
//! - `MsCPUBusy`: from there to the present (command-FIFO stalls inside the
//!   frame included, as PresentMon cannot tell them apart either);
//!   `MsCPUWait` = `MsInPresentAPI`: from the present to the next frame's
//!   start (the present call, the wait for frames in flight, a pacer's sleep;
//!   `NA` for the last frame, whose call the run ends in); `FrameTime` their
//!   sum;
//! - `MsBetweenPresents`, `MsBetweenSimulationStart` (input sampling to
//!   input sampling), `MsBetweenDisplayChange`: from the frame before (`NA`
//!   for the first);
//! - `MsGPULatency`: CPU start to the GPU beginning the frame (its clear);
//!   `MsGPUTime`: from there to the GPU finishing it (its swap), of which
//!   `MsGPUBusy` with a GPU unit busy and `MsGPUWait` the rest;
//! - `MsRenderPresentLatency`: present to GPU done; `MsUntilDisplayed`:
//!   present to the frame appearing; `DisplayLatency`: CPU start to the frame
//!   appearing; `DisplayedTime`: how long it stayed on screen (to the next
//!   frame shown). A frame never shown has `NA` for all four display columns.
//!
//! The text columns name the swap chain ([`ChainInfo`]): rendersim's own
//! runs write `Application` `rendersim` and the present mode of the
//! model's display (`fifo`: sync interval 1; `mailbox`: 0; `immediate`: 0
//! with tearing allowed; a composed display `Composed: Flip`, else
//! `Hardware: Independent Flip`); a replay writes the capture's.
//!
//! After them come rendersim's own columns: `Frame` (index, first of the
//! numbers), `MsInputLatency` (input sampled to the frame appearing: the
//! summary's `display_latency_ms`), `MsCPUWork` and `MsCPUBlocked` (the CPU's
//! work, system tasks included, and its blocked time as the model accounts
//! them to the frame), `TearLine` (where an `immediate` flip tore the
//! picture, as a fraction of its height from the top; `NA` for a frame
//! flipped in the vertical blank or at one), `Displayed` and `Dropped` (0
//! or 1).
//!
//! Times are written exactly: integer picoseconds as milliseconds with nine
//! decimals.

use crate::components::swap_chain::{DisplayConfig, PresentMode};
use crate::engine::{PS_PER_MS, Time};

/// One frame's timeline.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameRecord {
    /// Frame index.
    pub index: u64,
    /// The frame's slot on the CPU thread: from the end of the previous
    /// frame's swap call (so it includes any wait for frames in flight).
    pub start: Time,
    /// When the CPU began working on the frame: after the wait for frames in
    /// flight, any pacing and a replayed frame's present call (PresentMon's
    /// CPU start).
    pub begun: Time,
    /// Input sampled.
    pub input: Time,
    /// Swap command pushed (end of the CPU frame).
    pub present: Time,
    /// CPU busy picoseconds (work and system tasks).
    pub cpu_busy: u64,
    /// CPU blocked picoseconds.
    pub cpu_wait: u64,
    /// GPU began the frame.
    pub gpu_start: Option<Time>,
    /// GPU finished the frame.
    pub gpu_end: Option<Time>,
    /// GPU busy picoseconds.
    pub gpu_busy: u64,
    /// Shown on screen.
    pub displayed: Option<Time>,
    /// Discarded without being shown.
    pub dropped: bool,
    /// Where its flip tore the picture (fraction of the height from the
    /// top; `immediate` flips during the scan-out only).
    pub tear_line: Option<f64>,
    /// Picoseconds the CPU spent copying the frame's uploads over a shared
    /// bus (0 unless [`super::workload::SceneProgram::bus_shared`]).
    pub copy: u64,
}

impl FrameRecord {
    /// A frame starting at `start`.
    pub fn new(index: u64, start: Time) -> Self {
        FrameRecord {
            index,
            start,
            begun: start,
            input: start,
            present: start,
            cpu_busy: 0,
            cpu_wait: 0,
            gpu_start: None,
            gpu_end: None,
            gpu_busy: 0,
            displayed: None,
            dropped: false,
            tear_line: None,
            copy: 0,
        }
    }
}

/// The per-frame figures the summary's statistics are taken over (columns
/// of [`metric_rows`]; not an output).
pub(super) mod metric {
    /// Slot start to the next slot start (ms).
    pub const FRAME_TIME: usize = 0;
    /// CPU work in the frame (ms).
    pub const CPU_WORK: usize = 1;
    /// GPU start to GPU end (ms).
    pub const GPU_TIME: usize = 2;
    /// GPU busy (ms).
    pub const GPU_BUSY: usize = 3;
    /// Present to display (ms).
    pub const UNTIL_DISPLAYED: usize = 4;
    /// Input sampled to display (ms).
    pub const INPUT_LATENCY: usize = 5;
    /// Display to the previous display (ms).
    pub const DISPLAY_INTERVAL: usize = 6;
    /// Figures per row.
    pub const N: usize = 7;
}

fn ms(ps: u64) -> f64 {
    ps as f64 / PS_PER_MS as f64
}

/// The summary's per-frame figures ([`metric`] names the columns; NaN where
/// a figure does not exist for the frame).
pub(super) fn metric_rows(records: &[FrameRecord]) -> Vec<[f64; metric::N]> {
    let mut rows = Vec::with_capacity(records.len());
    let mut prev_display: Option<Time> = None;
    for (i, r) in records.iter().enumerate() {
        let end = records.get(i + 1).map(|n| n.start).unwrap_or(r.present);
        let gpu_time = match (r.gpu_start, r.gpu_end) {
            (Some(a), Some(b)) => ms(b.since(a).0),
            _ => f64::NAN,
        };
        let (until, latency, between) = match r.displayed {
            Some(d) => {
                let between = prev_display.map(|p| ms(d.since(p).0)).unwrap_or(f64::NAN);
                prev_display = Some(d);
                (ms(d.since(r.present).0), ms(d.since(r.input).0), between)
            }
            None => (f64::NAN, f64::NAN, f64::NAN),
        };
        rows.push([
            ms(end.since(r.start).0),
            ms(r.cpu_busy),
            gpu_time,
            ms(r.gpu_busy),
            until,
            latency,
            between,
        ]);
    }
    rows
}

/// One frame's figures as the summary's statistics take them: what a view
/// of a run draws frame by frame (`rendersim explore`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FrameFigures {
    /// The frame's index.
    pub index: u64,
    /// Its slot start to the next frame's (ms): `metrics.frame_time_ms`.
    pub frame_time_ms: f64,
    /// Its display to the previous frame's display (ms), where both were
    /// shown: `metrics.display_interval_ms`.
    pub display_interval_ms: Option<f64>,
    /// Input sampled to display (ms), where shown: `metrics.display_latency_ms`.
    pub display_latency_ms: Option<f64>,
}

/// [`FrameFigures`] of every record, in order (warm-up frames included:
/// the summary leaves out the first `run.warmup_frames`).
pub fn frame_figures(records: &[FrameRecord]) -> Vec<FrameFigures> {
    let some = |v: f64| (!v.is_nan()).then_some(v);
    records
        .iter()
        .zip(metric_rows(records))
        .map(|(r, row)| FrameFigures {
            index: r.index,
            frame_time_ms: row[metric::FRAME_TIME],
            display_interval_ms: some(row[metric::DISPLAY_INTERVAL]),
            display_latency_ms: some(row[metric::INPUT_LATENCY]),
        })
        .collect()
}

/// The swap chain the frames were presented on, as PresentMon names it
/// (the text columns of `frames.csv`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChainInfo {
    /// `Application`.
    pub application: String,
    /// `ProcessID`.
    pub process_id: String,
    /// `SwapChainAddress`.
    pub swap_chain: String,
    /// `PresentRuntime`.
    pub runtime: String,
    /// `SyncInterval`.
    pub sync_interval: i64,
    /// `AllowsTearing`.
    pub allows_tearing: bool,
    /// `PresentMode`.
    pub present_mode: String,
}

impl ChainInfo {
    /// A rendersim run's swap chain, from the model's display.
    pub fn of_display(d: &DisplayConfig) -> ChainInfo {
        let mode = d.effective_mode();
        ChainInfo {
            application: "rendersim".into(),
            process_id: "0".into(),
            swap_chain: "0x1".into(),
            runtime: "Other".into(),
            sync_interval: i64::from(mode == PresentMode::Fifo),
            allows_tearing: mode == PresentMode::Immediate,
            present_mode: if d.composition.is_independent() {
                "Hardware: Independent Flip"
            } else {
                "Composed: Flip"
            }
            .into(),
        }
    }
}

/// The text columns of `frames.csv`, before [`COLUMNS`].
pub const TEXT_COLUMNS: [&str; 9] = [
    "Application",
    "ProcessID",
    "SwapChainAddress",
    "PresentRuntime",
    "SyncInterval",
    "PresentFlags",
    "AllowsTearing",
    "PresentMode",
    "FrameType",
];

/// The numeric columns of `frames.csv` (the frames table experiments read).
pub const COLUMNS: [&str; 23] = [
    "Frame",
    "CPUStartTime",
    "FrameTime",
    "MsBetweenSimulationStart",
    "MsBetweenPresents",
    "MsBetweenDisplayChange",
    "MsInPresentAPI",
    "MsRenderPresentLatency",
    "MsUntilDisplayed",
    "MsCPUBusy",
    "MsCPUWait",
    "MsGPULatency",
    "MsGPUTime",
    "MsGPUBusy",
    "MsGPUWait",
    "DisplayLatency",
    "DisplayedTime",
    "MsInputLatency",
    "MsCPUWork",
    "MsCPUBlocked",
    "TearLine",
    "Displayed",
    "Dropped",
];

/// Columns of [`COLUMNS`] that are counts or flags, not times.
const COUNT_COLUMNS: [usize; 3] = [0, 21, 22];

/// One cell of the numeric columns: picoseconds (a time on the run's clock
/// or a duration, signed), a count, or `NA`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Cell {
    Ps(i64),
    Count(u64),
    Fraction(f64),
    Na,
}

impl Cell {
    fn ms(self) -> f64 {
        match self {
            Cell::Ps(p) => p as f64 / PS_PER_MS as f64,
            Cell::Count(n) => n as f64,
            Cell::Fraction(x) => x,
            Cell::Na => f64::NAN,
        }
    }

    /// The number [`Cell::text`] writes, as a reader of `frames.csv`
    /// parses it: milliseconds (the nearest `f64` to the exact nine
    /// decimals), a count, a fraction to six decimals, NaN for `NA`.
    fn value(self) -> f64 {
        match self {
            // Through the text: `x * 1e6` rounds ties the binary value
            // does not have (0.1234565 is 0.12345649...).
            Cell::Fraction(_) => self.text().parse().unwrap_or(f64::NAN),
            c => c.ms(),
        }
    }

    /// Exact text: picoseconds as milliseconds with nine decimals.
    fn text(self) -> String {
        match self {
            Cell::Ps(p) => {
                let ms = PS_PER_MS as i64;
                let sign = if p < 0 { "-" } else { "" };
                let a = p.unsigned_abs();
                format!("{sign}{}.{:09}", a / ms as u64, a % ms as u64)
            }
            Cell::Count(n) => n.to_string(),
            Cell::Fraction(x) => format!("{x:.6}"),
            Cell::Na => "NA".into(),
        }
    }
}

/// Signed picoseconds from `a` to `b`.
fn span(a: Time, b: Time) -> Cell {
    Cell::Ps(b.0 as i64 - a.0 as i64)
}

/// A frame generated by interpolation before rendered frame `before`
/// (`[frame_generation]`, [`crate::components::frame_generation`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratedRecord {
    /// The rendered frame it is shown before.
    pub before: u64,
    /// Presented to the swap chain.
    pub present: Time,
    /// Shown on screen.
    pub displayed: Option<Time>,
    /// Discarded without being shown.
    pub dropped: bool,
    /// Where its flip tore the picture (`immediate` only).
    pub tear_line: Option<f64>,
}

/// One row of the frames table: a rendered frame, or one generated before it.
#[derive(Debug, Clone, Copy)]
enum Row<'a> {
    Rendered(usize, &'a FrameRecord),
    Generated(&'a GeneratedRecord),
}

impl Row<'_> {
    fn displayed(&self) -> Option<Time> {
        match self {
            Row::Rendered(_, r) => r.displayed,
            Row::Generated(g) => g.displayed,
        }
    }
}

/// The rows in presentation order: each generated frame before the
/// rendered frame it precedes.
fn rows_of<'a>(records: &'a [FrameRecord], generated: &'a [GeneratedRecord]) -> Vec<Row<'a>> {
    let mut rows = Vec::with_capacity(records.len() + generated.len());
    let mut g = generated.iter().peekable();
    for (i, r) in records.iter().enumerate() {
        while let Some(x) = g.next_if(|x| x.before <= r.index) {
            rows.push(Row::Generated(x));
        }
        rows.push(Row::Rendered(i, r));
    }
    rows.extend(g.map(Row::Generated));
    rows
}

/// The numeric cells of every row (rendered frames, and the generated
/// frames before them), [`COLUMNS`] in order, with whether the row is a
/// generated frame; `offset_ps` is added to `CPUStartTime`. Display
/// changes run over every frame shown, generated ones too.
fn cells(records: &[FrameRecord], generated: &[GeneratedRecord], offset_ps: i64) -> Vec<(bool, [Cell; 23])> {
    let mut out = Vec::with_capacity(records.len() + generated.len());
    each_row(records, generated, offset_ps, |generated_row, row| {
        out.push((generated_row, *row))
    });
    out
}

/// [`cells`]' rows handed to `f` one by one, in order, none kept.
fn each_row(
    records: &[FrameRecord],
    generated: &[GeneratedRecord],
    offset_ps: i64,
    mut f: impl FnMut(bool, &[Cell; 23]),
) {
    let order = rows_of(records, generated);
    let opt = |a: Option<Time>, b: Option<Time>| match (a, b) {
        (Some(a), Some(b)) => span(a, b),
        _ => Cell::Na,
    };
    // The next frame shown after each row (scanning backwards).
    let mut shown_next = vec![None; order.len()];
    let mut later: Option<Time> = None;
    for (k, row) in order.iter().enumerate().rev() {
        shown_next[k] = later.filter(|_| row.displayed().is_some());
        if row.displayed().is_some() {
            later = row.displayed();
        }
    }
    let mut prev_display: Option<Time> = None;
    for (k, row) in order.iter().enumerate() {
        let shown = row.displayed();
        let between = opt(prev_display.filter(|_| shown.is_some()), shown);
        let on_screen = opt(shown, shown_next[k]);
        let cells = match *row {
            Row::Rendered(i, r) => rendered_cells(records, i, r, offset_ps, between, on_screen),
            Row::Generated(g) => {
                let mut c = [Cell::Na; 23];
                c[0] = Cell::Count(g.before);
                c[5] = between;
                c[8] = opt(Some(g.present), g.displayed);
                c[16] = on_screen;
                c[20] = g.tear_line.map_or(Cell::Na, Cell::Fraction);
                c[21] = Cell::Count(u64::from(g.displayed.is_some()));
                c[22] = Cell::Count(u64::from(g.dropped));
                c
            }
        };
        debug_assert!(COUNT_COLUMNS.iter().all(|&c| !matches!(cells[c], Cell::Ps(_))));
        f(matches!(row, Row::Generated(_)), &cells);
        if shown.is_some() {
            prev_display = shown;
        }
    }
}

/// A rendered frame's cells (`between`, `on_screen`: its display change and
/// its time on screen, over every frame shown).
fn rendered_cells(
    records: &[FrameRecord],
    i: usize,
    r: &FrameRecord,
    offset_ps: i64,
    between: Cell,
    on_screen: Cell,
) -> [Cell; 23] {
    let next = records.get(i + 1);
    let prev = i.checked_sub(1).map(|p| &records[p]);
    // The run ends in the last frame's present call: its wait is unknown.
    let wait = next.map_or(Cell::Na, |n| span(r.present, n.begun));
    let frame_time = next.map_or(Cell::Na, |n| span(r.begun, n.begun));
    let opt = |a: Option<Time>, b: Option<Time>| match (a, b) {
        (Some(a), Some(b)) => span(a, b),
        _ => Cell::Na,
    };
    let gpu_time = opt(r.gpu_start, r.gpu_end);
    let gpu_wait = match gpu_time {
        Cell::Ps(t) => Cell::Ps(t - r.gpu_busy as i64),
        _ => Cell::Na,
    };
    [
        Cell::Count(r.index),
        Cell::Ps(r.begun.0 as i64 + offset_ps),
        frame_time,
        prev.map_or(Cell::Na, |p| span(p.input, r.input)),
        prev.map_or(Cell::Na, |p| span(p.present, r.present)),
        between,
        wait,
        opt(Some(r.present), r.gpu_end),
        opt(Some(r.present), r.displayed),
        span(r.begun, r.present),
        wait,
        opt(Some(r.begun), r.gpu_start),
        gpu_time,
        Cell::Ps(r.gpu_busy as i64),
        gpu_wait,
        opt(Some(r.begun), r.displayed),
        on_screen,
        opt(Some(r.input), r.displayed),
        Cell::Ps(r.cpu_busy as i64),
        Cell::Ps(r.cpu_wait as i64),
        r.tear_line.map_or(Cell::Na, Cell::Fraction),
        Cell::Count(u64::from(r.displayed.is_some())),
        Cell::Count(u64::from(r.dropped)),
    ]
}

/// The frames table's numbers: one row per frame (a generated frame's row
/// before the rendered frame it precedes), [`COLUMNS`] in order, in ms (NaN
/// where `frames.csv` has `NA`); `offset_ps` is added to `CPUStartTime`.
pub fn frame_rows(records: &[FrameRecord], generated: &[GeneratedRecord], offset_ps: i64) -> Vec<Vec<f64>> {
    cells(records, generated, offset_ps)
        .into_iter()
        .map(|(_, row)| row.iter().map(|c| c.ms()).collect())
        .collect()
}

/// Writes `frames.csv`: [`TEXT_COLUMNS`] naming `chain` (`FrameType`
/// `Application`, or `Generated` for a generated frame's row), then
/// [`COLUMNS`] (times exact, `NA` for missing); `offset_ps` is added to
/// `CPUStartTime`.
pub fn write_frames_csv<W: std::io::Write>(
    records: &[FrameRecord],
    generated: &[GeneratedRecord],
    chain: &ChainInfo,
    offset_ps: i64,
    w: W,
) -> std::io::Result<()> {
    let text = chain.text();
    let header: Vec<&str> = TEXT_COLUMNS.iter().chain(COLUMNS.iter()).copied().collect();
    let rows = cells(records, generated, offset_ps)
        .into_iter()
        .map(|(generated_row, row)| {
            let kind = if generated_row { "Generated" } else { "Application" };
            text.iter()
                .cloned()
                .chain(std::iter::once(kind.to_string()))
                .chain(row.iter().map(|c| c.text()))
                .collect()
        });
    crate::output::table::write_table(std::io::BufWriter::new(w), &header, rows)
}

impl ChainInfo {
    /// The first eight [`TEXT_COLUMNS`] (all but `FrameType`), as
    /// `frames.csv` writes them on every row.
    pub fn text(&self) -> [String; 8] {
        [
            self.application.clone(),
            self.process_id.clone(),
            self.swap_chain.clone(),
            self.runtime.clone(),
            self.sync_interval.to_string(),
            "0".into(),
            u8::from(self.allows_tearing).to_string(),
            self.present_mode.clone(),
        ]
    }
}

/// The rows of `frames.csv` as numbers, for a caller that wants them typed
/// rather than as text (the Python package's DataFrames): [`COLUMNS`]
/// column by column, each the number a reader of the file parses (NaN for
/// `NA`), handed to `put(k, value)` with `k` its place in the flattened
/// table (column `c`, row `r` of `n` rows: `c * n + r`), so the caller
/// writes them where it wants them (the Python package: straight into the
/// buffer its arrays view). Returns whether each row is a generated frame;
/// the text columns are [`ChainInfo::text`], the same on every row.
pub fn frame_values_with(
    records: &[FrameRecord],
    generated: &[GeneratedRecord],
    offset_ps: i64,
    mut put: impl FnMut(usize, f64),
) -> Vec<bool> {
    let n = records.len() + generated.len();
    let mut kinds = Vec::with_capacity(n);
    each_row(records, generated, offset_ps, |generated_row, row| {
        let r = kinds.len();
        kinds.push(generated_row);
        for (c, cell) in row.iter().enumerate() {
            put(c * n + r, cell.value());
        }
    });
    kinds
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_s_value_is_what_its_text_parses_to() {
        for c in [
            Cell::Ps(16_666_666_667),
            Cell::Ps(-1),
            Cell::Ps(3_600_000_000_000_001),
            Cell::Ps(123_456_789),
            Cell::Count(7),
            Cell::Fraction(0.123_456_5),
            Cell::Fraction(2.0 / 3.0),
        ] {
            assert_eq!(c.value(), c.text().parse::<f64>().unwrap(), "{c:?}");
        }
        assert!(Cell::Na.value().is_nan());
    }

    #[test]
    fn picoseconds_are_written_exactly() {
        assert_eq!(Cell::Ps(16_666_666_667).text(), "16.666666667");
        assert_eq!(Cell::Ps(-1).text(), "-0.000000001");
        assert_eq!(Cell::Ps(0).text(), "0.000000000");
        assert_eq!(Cell::Ps(3_600_000_000_000_001).text(), "3600000.000000001");
        assert_eq!(Cell::Na.text(), "NA");
        assert_eq!(Cell::Count(7).text(), "7");
    }

    #[test]
    fn a_frame_never_shown_has_na_display_columns_and_the_last_frame_no_known_wait() {
        let mut a = FrameRecord::new(0, Time(0));
        a.present = Time(5);
        a.gpu_start = Some(Time(1));
        a.gpu_end = Some(Time(8));
        a.displayed = Some(Time(10));
        let mut b = FrameRecord::new(1, Time(5));
        b.begun = Time(6);
        b.present = Time(9);
        b.dropped = true;
        let rows: Vec<[Cell; 23]> = cells(&[a, b], &[], 100).into_iter().map(|(_, r)| r).collect();
        let col = |name: &str| COLUMNS.iter().position(|c| *c == name).unwrap();
        assert_eq!(rows[0][col("CPUStartTime")], Cell::Ps(100));
        assert_eq!(rows[0][col("MsCPUWait")], Cell::Ps(1));
        assert_eq!(rows[0][col("FrameTime")], Cell::Ps(6));
        assert_eq!(rows[0][col("MsRenderPresentLatency")], Cell::Ps(3));
        assert_eq!(rows[0][col("DisplayLatency")], Cell::Ps(10));
        assert_eq!(rows[0][col("DisplayedTime")], Cell::Na);
        assert_eq!(rows[0][col("MsBetweenPresents")], Cell::Na);
        assert_eq!(rows[1][col("MsBetweenPresents")], Cell::Ps(4));
        assert_eq!(rows[1][col("MsCPUBusy")], Cell::Ps(3));
        assert_eq!(rows[1][col("MsCPUWait")], Cell::Na);
        assert_eq!(rows[1][col("FrameTime")], Cell::Na);
        assert_eq!(rows[1][col("MsUntilDisplayed")], Cell::Na);
        assert_eq!(rows[1][col("MsGPULatency")], Cell::Na);
        assert_eq!(rows[1][col("Dropped")], Cell::Count(1));
    }
}
