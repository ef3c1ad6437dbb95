//! Frame captures in PresentMon's CSV form, as every tool that writes it
//! writes it: PresentMon 1 and 2 (all three of 2's column sets), OCAT,
//! NVIDIA FrameView and CapFrameX ([`columns`] lists the names read).
//!
//! - **v2** (PresentMon 2): the frame's CPU start (`CPUStartQPC` with
//!   `TimeInQPC`; or `CPUStartTime`, `CPUStartTimeInMs` or
//!   `CPUStartQPCTime` in milliseconds, or `CPUStartTimeInSeconds`; or
//!   `CPUStartQPC` alone, at QPC's 10 MHz), `MsCPUBusy` (CPU start to the
//!   present call), `MsCPUWait` (in the present call; `NA`, as rendersim
//!   writes for a run's last frame, is none), `MsGPULatency` (CPU start to
//!   the GPU starting the frame), `MsGPUTime` (from there to the GPU
//!   finishing it), `MsGPUBusy`, `MsRenderPresentLatency` (present to GPU
//!   done), `MsUntilDisplayed`, `MsBetweenDisplayChange`, and, where the
//!   capture has no `MsUntilDisplayed`, `DisplayLatency` (CPU start to the
//!   screen). rendersim's own `frames.csv` is such a capture.
//! - **v1** (PresentMon 1, OCAT, FrameView, CapFrameX): `TimeInSeconds`
//!   (the present; or `TimeInMs`, or `QPCTime` ticks), `MsBetweenPresents`,
//!   `MsInPresentAPI`, `MsUntilRenderComplete`, `MsUntilDisplayed`,
//!   `Dropped`.
//!
//! Either set also names the swap chain (`Application`, `ProcessID`,
//! `SwapChainAddress`) and how it presents (`PresentMode`, `SyncInterval`,
//! `AllowsTearing`), and may carry latency measurements (`MsPCLatency`,
//! `MsAllInputToPhotonLatency`, `MsClickToPhotonLatency`, FrameView's
//! `Render Queue Depth`).
//!
//! What the writers do that a reader must undo, each handled as the
//! writer meant it:
//!
//! - `NA` marks a value that does not exist (a frame never shown has `NA`
//!   for `MsUntilDisplayed`); a UTF-8 byte-order mark is skipped;
//! - CapFrameX writes `//key=value` lines before the header: kept as the
//!   capture's [`Capture::metadata`];
//! - OCAT writes a description of the system (motherboard, OS, processor,
//!   GPU, driver, comment) in extra columns of its first row only, so its
//!   other rows have fewer fields than the header; FrameView writes GPU,
//!   CPU and resolution on every row: kept as metadata too. A row with
//!   fewer fields than the header lacks the values of the missing columns;
//!   a row with more has its extra fields ignored (both counted in
//!   [`Capture::notes`]);
//! - a repeated header row (a log appended to) is skipped;
//! - `FrameType` other than `Application` (`Repeated`, `Intel XeSS-FG`,
//!   `AMD AFMF`, rendersim's `Generated`): a frame the application did not
//!   render, kept apart ([`Capture::generated`]) as a frame of the display;
//! - `Dropped` other than 0 or 1 (FrameView writes `Error`): the frame's
//!   fate is unknown, read as not shown;
//! - a value no time can have (PresentMon 1's unsigned underflow writes
//!   1844674407370955 ms): read as missing;
//! - rows written as frames complete, not in time order across swap
//!   chains or within one: each swap chain's frames are ordered by their
//!   present;
//! - a clock that restarts mid-capture (one swap chain's present going
//!   back more than [`RESTART_MS`]): the capture holds several recordings,
//!   and the one with most rows is read.
//!
//! QPC time stamps are converted with the tick rate the capture itself
//! implies (`TimeInQPC - CPUStartQPC` over `MsCPUBusy`).

mod cells;
pub mod columns;
mod order;
mod qpc;

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use self::cells::{Cells, Notes};
use self::columns::{Col, Header, SYSTEM_COLUMNS};
use self::order::{in_time_order, one_recording};
use self::qpc::{qpc_rate, qpc_rate_from_starts, qpc_rate_v1};

/// A swap chain's present going back more than this (ms) is the capture's
/// clock restarting: a new recording.
pub const RESTART_MS: f64 = 1000.0;

/// QPC ticks per millisecond where the capture gives no way to infer it:
/// Windows' query-performance counter runs at 10 MHz.
pub const DEFAULT_QPC_PER_MS: f64 = 10_000.0;

/// A capture that cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum CaptureError {
    /// The file could not be read.
    #[error("cannot read capture {path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The file is not a PresentMon CSV, or a column it needs is missing.
    #[error("{file}: {message}")]
    Format {
        /// File name.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A cell holds a value that cannot be used.
    #[error("{file}:{line}: column `{column}`: {message}")]
    Cell {
        /// File name.
        file: String,
        /// Line (1-based, the header is line 1).
        line: u64,
        /// Column name.
        column: String,
        /// What is wrong.
        message: String,
    },
    /// The rows cannot be replayed as one swap chain's frames.
    #[error("{file}:{line}: {message}")]
    Row {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// What is wrong.
        message: String,
    },
}

/// Which column set the capture uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Columns {
    /// PresentMon 2 (CPU start, busy and wait times).
    V2,
    /// PresentMon 1 (present times only).
    V1,
}

/// One present of a capture, times in milliseconds on the capture's clock.
#[derive(Debug, Clone)]
pub struct Present {
    /// Line in the file.
    pub line: u64,
    /// Process name.
    pub application: Arc<str>,
    /// Process id (as written).
    pub process_id: Arc<str>,
    /// Swap chain (as written, e.g. `0x224B280A1C0`).
    pub swap_chain: Arc<str>,
    /// `PresentMode` as written (`Hardware: Legacy Flip`, `Composed: Flip`, ...).
    pub present_mode: Arc<str>,
    /// `SyncInterval` (absent in some captures).
    pub sync_interval: Option<i64>,
    /// `AllowsTearing`.
    pub allows_tearing: bool,
    /// `FrameType` as written (empty where the capture has none).
    pub frame_type: Arc<str>,
    /// When the CPU started the frame.
    pub cpu_start: f64,
    /// When the present call started.
    pub present: f64,
    /// CPU start to the present call.
    pub cpu_busy: f64,
    /// Time in the present call.
    pub cpu_wait: f64,
    /// CPU start to the GPU starting the frame (v2).
    pub gpu_latency: Option<f64>,
    /// GPU busy time (v2).
    pub gpu_busy: Option<f64>,
    /// GPU start to GPU end (v2, `MsGPUTime`).
    pub gpu_time: Option<f64>,
    /// Present to the GPU finishing the frame.
    pub render_complete: Option<f64>,
    /// Present to the frame appearing (`None`: never shown, or unknown).
    pub until_displayed: Option<f64>,
    /// Whether the capture says whether the frame was shown (`false` where
    /// `Dropped` holds neither 0 nor 1, and for a present of a mode
    /// PresentMon could not tell that it followed no further than the
    /// present call).
    pub fate_known: bool,
    /// The previous displayed frame's appearance to this one's.
    pub between_display_change: Option<f64>,
    /// Input (or CPU start) to the frame appearing, where given.
    pub display_latency: Option<f64>,
    /// NVIDIA Reflex's PC latency (`MsPCLatency`), where given.
    pub pc_latency: Option<f64>,
    /// Any input to the frame appearing (`MsAllInputToPhotonLatency`).
    pub all_input_to_photon: Option<f64>,
    /// A click to the frame appearing (`MsClickToPhotonLatency`).
    pub click_to_photon: Option<f64>,
    /// FrameView's `Render Queue Depth`.
    pub render_queue_depth: Option<f64>,
}

impl Present {
    /// Whether the frame was shown.
    pub fn displayed(&self) -> bool {
        self.until_displayed.is_some()
    }

    /// When the frame appeared, on the capture's clock.
    pub fn screen_time(&self) -> Option<f64> {
        self.until_displayed.map(|u| self.present + u)
    }

    /// Whether the application rendered the frame (its `FrameType` is
    /// `Application` or unknown), as opposed to a frame generated between
    /// rendered ones or repeated.
    pub fn rendered(&self) -> bool {
        is_application_frame(&self.frame_type)
    }

    /// The swap chain's identity: process name, id and address.
    pub fn chain(&self) -> (&str, &str, &str) {
        (&self.application, &self.process_id, &self.swap_chain)
    }
}

/// A whole capture: every present of every swap chain, in file order.
#[derive(Debug, Clone)]
pub struct Capture {
    /// File name as given.
    pub file: String,
    /// Column set.
    pub columns: Columns,
    /// QPC ticks per millisecond, when the capture uses QPC time stamps.
    pub qpc_per_ms: Option<f64>,
    /// The presents the application rendered.
    pub presents: Vec<Present>,
    /// Rows of frames the application did not render (`FrameType` other
    /// than `Application`: generated by frame generation, or repeated):
    /// frames of the display, not of the CPU.
    pub generated: Vec<Present>,
    /// What the capture says of itself: CapFrameX's `//key=value` lines,
    /// OCAT's and FrameView's system columns (first value of each).
    pub metadata: Vec<(String, String)>,
    /// What the reader had to undo (see the module docs), one line each.
    pub notes: Vec<String>,
}

/// A swap chain of a capture and its frame count.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SwapChainInfo {
    /// Process name.
    pub application: String,
    /// Process id.
    pub process_id: String,
    /// Swap chain address.
    pub swap_chain: String,
    /// The present mode its frames use most.
    pub present_mode: String,
    /// Presents.
    pub frames: usize,
}

/// One row read, before each swap chain's frames are put in order.
struct Row {
    present: Present,
    /// PresentMon 1: `MsBetweenPresents` (the first frame's start).
    between: f64,
}

impl Capture {
    /// Reads a capture from `path`.
    pub fn read(path: &Path) -> Result<Capture, CaptureError> {
        let bytes =
            crate::limits::read_input(path, crate::limits::InputKind::Data).map_err(|source| CaptureError::Io {
                path: path.display().to_string(),
                source,
            })?;
        Capture::parse(&path.display().to_string(), &bytes)
    }

    /// Parses a capture's bytes; `file` names it in errors.
    pub fn parse(file: &str, bytes: &[u8]) -> Result<Capture, CaptureError> {
        let format = |message: String| CaptureError::Format {
            file: file.to_string(),
            message,
        };
        let mut notes = Notes::default();
        let decoded = from_utf16(bytes).map_err(format)?;
        if decoded.is_some() {
            notes.push("read as UTF-16 text (converted; PresentMon and FrameView write UTF-8)".into());
        }
        let bytes = decoded.as_deref().unwrap_or(bytes);
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        let (metadata, skipped, body) = leading_comments(bytes);
        let mut rdr = csv::ReaderBuilder::new()
            .flexible(true)
            .has_headers(false)
            .from_reader(body);
        let mut records = rdr.records();
        let header_rec = match records.next() {
            Some(Ok(h)) => h,
            Some(Err(e)) => return Err(format(format!("not a CSV file: {e}"))),
            None => return Err(format("empty: no header".into())),
        };
        let header = Header::new(&header_rec);
        if let Some((name, a, b)) = header.repeated() {
            return Err(format(format!(
                "the header names `{name}` twice (fields {a} and {b}): which one holds the values is not known; \
                 remove or rename one"
            )));
        }
        let columns = column_set(file, &header)?;
        let mut meta = metadata;
        let mut raw = Vec::new();
        for rec in records {
            let rec = rec.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line()) + skipped;
                CaptureError::Row {
                    file: file.to_string(),
                    line,
                    message: format!("not a CSV row: {e}"),
                }
            })?;
            let line = rec.position().map_or(0, |p| p.line()) + skipped;
            if rec.len() == 1 && header.names.len() > 1 {
                // A blank line, or a writer's closing warning ("warning:
                // N events were lost"), not a row.
                if !rec[0].trim().is_empty() {
                    notes.trailers += 1;
                }
                continue;
            }
            if rec.iter().map(str::trim).eq(header.names.iter().map(String::as_str)) {
                notes.repeated_headers += 1;
                continue;
            }
            match rec.len().cmp(&header.names.len()) {
                std::cmp::Ordering::Less => notes.short_rows += 1,
                std::cmp::Ordering::Greater => notes.long_rows += 1,
                std::cmp::Ordering::Equal => {}
            }
            raw.push((line, rec));
        }
        if raw.is_empty() {
            return Err(format("no presents: the capture has a header and no rows".into()));
        }
        repeated_rows(file, &raw)?;
        system_metadata(&header, &raw, &mut meta);
        let cell = Cells::new(file, &header);
        cell.set_qpc_base(&raw)?;
        let qpc_per_ms = match (columns, header.has(Col::TimeInQpc), header.has(Col::CpuStartQpc)) {
            (Columns::V2, true, true) => match qpc_rate(&cell, &raw)? {
                Some(r) => Some(r),
                None => Some(qpc_rate_from_starts(&cell, &raw, &mut notes)?),
            },
            (Columns::V2, false, true) if !header.has(Col::CpuStartMs) && !header.has(Col::CpuStartS) => {
                Some(qpc_rate_from_starts(&cell, &raw, &mut notes)?)
            }
            (Columns::V1, true, _) if !header.has(Col::TimeInSeconds) && !header.has(Col::TimeInMs) => {
                Some(qpc_rate_v1(file, &cell, &raw)?)
            }
            _ => None,
        };
        if columns == Columns::V2 && !header.has(Col::CpuWait) {
            notes.push("no `MsCPUWait`: each present call read as taking no time".into());
        }
        let mut rows = Vec::with_capacity(raw.len());
        for (line, rec) in &raw {
            rows.push(read_row(&cell, columns, qpc_per_ms, &header, *line, rec, &mut notes)?);
        }
        cell.report(&mut notes);
        let rows = one_recording(rows, &mut notes);
        let presents = in_time_order(rows, columns, &mut notes);
        let (generated, presents): (Vec<Present>, Vec<Present>) = presents.into_iter().partition(|p| !p.rendered());
        if presents.is_empty() {
            return Err(format(format!(
                "no presents the application rendered: all {} rows have a `FrameType` other than `Application`",
                generated.len()
            )));
        }
        Ok(Capture {
            file: file.to_string(),
            columns,
            qpc_per_ms,
            presents,
            generated,
            metadata: meta,
            notes: notes.lines(),
        })
    }

    /// Rows of frames the application did not render (generated or repeated).
    pub fn not_rendered(&self) -> usize {
        self.generated.len()
    }

    /// The swap chains (one per process, application and address: runtimes
    /// without an address write 0x0 for every process), most frames first
    /// (ties in file order).
    pub fn swap_chains(&self) -> Vec<SwapChainInfo> {
        let mut order: Vec<SwapChainInfo> = Vec::new();
        let mut modes: Vec<HashMap<&str, usize>> = Vec::new();
        let mut index: HashMap<(&str, &str, &str), usize> = HashMap::new();
        for p in &self.presents {
            let i = *index.entry(p.chain()).or_insert_with(|| {
                order.push(SwapChainInfo {
                    application: p.application.to_string(),
                    process_id: p.process_id.to_string(),
                    swap_chain: p.swap_chain.to_string(),
                    present_mode: String::new(),
                    frames: 0,
                });
                modes.push(HashMap::new());
                order.len() - 1
            });
            order[i].frames += 1;
            *modes[i].entry(&p.present_mode).or_default() += 1;
        }
        for (s, m) in order.iter_mut().zip(&modes) {
            let mut m: Vec<(&&str, &usize)> = m.iter().collect();
            m.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
            s.present_mode = m.first().map(|(k, _)| k.to_string()).unwrap_or_default();
        }
        order.sort_by_key(|s| std::cmp::Reverse(s.frames));
        order
    }

    /// The presents of one swap chain, chosen by `swap_chain` (its address),
    /// else by `app` (that process's swap chain with most frames), else the
    /// swap chain with most frames. Checks what a replay needs of them: at
    /// least two frames and at least two displayed frames. Returns the swap
    /// chain (with the present mode most of its frames use) and its
    /// presents in time order; a CPU start before the previous frame's
    /// (frames whose CPU work overlapped) is moved to the previous one's,
    /// as the replay's CPU does one frame at a time.
    pub fn select(
        &self,
        app: Option<&str>,
        swap_chain: Option<&str>,
    ) -> Result<(SwapChainInfo, Vec<Present>), CaptureError> {
        let chains = self.swap_chains();
        let listing = || {
            chains
                .iter()
                .map(|s| {
                    format!(
                        "{} (process {}) {} ({}, {} frames)",
                        s.application, s.process_id, s.swap_chain, s.present_mode, s.frames
                    )
                })
                .collect::<Vec<_>>()
                .join("; ")
        };
        let pick = chains.iter().find(|s| {
            swap_chain.is_none_or(|a| s.swap_chain.eq_ignore_ascii_case(a))
                && app.is_none_or(|n| s.application.eq_ignore_ascii_case(n))
        });
        let Some(pick) = pick else {
            let what = match (app, swap_chain) {
                (Some(a), Some(s)) => format!("no swap chain {s} of application {a:?}"),
                (Some(a), None) => format!("no swap chain of application {a:?}"),
                (None, Some(s)) => format!("no swap chain {s}"),
                (None, None) => "no swap chain".into(),
            };
            return Err(CaptureError::Format {
                file: self.file.clone(),
                message: format!("{what}; the capture has: {}", listing()),
            });
        };
        let mut rows: Vec<Present> = self
            .presents
            .iter()
            .filter(|p| p.chain() == (&*pick.application, &*pick.process_id, &*pick.swap_chain))
            .cloned()
            .collect();
        let row_err = |line: u64, message: String| CaptureError::Row {
            file: self.file.clone(),
            line,
            message,
        };
        if rows.len() < 2 {
            return Err(row_err(
                rows[0].line,
                format!(
                    "swap chain {} has one frame: a replay needs at least two",
                    pick.swap_chain
                ),
            ));
        }
        for i in 1..rows.len() {
            let before = rows[i - 1].cpu_start;
            let r = &mut rows[i];
            if r.cpu_start < before {
                r.cpu_start = before;
                r.cpu_busy = (r.present - before).max(0.0);
            }
        }
        if rows.iter().all(|p| p.present == rows[0].present) {
            return Err(row_err(
                rows[0].line,
                format!(
                    "all {} presents of swap chain {} are at one instant ({} ms): a replay needs time between frames",
                    rows.len(),
                    pick.swap_chain,
                    rows[0].present
                ),
            ));
        }
        if rows.iter().filter(|p| p.displayed()).count() < 2 {
            return Err(row_err(
                rows[0].line,
                format!(
                    "swap chain {} has fewer than two displayed frames (MsUntilDisplayed is NA): the refresh cannot be inferred",
                    pick.swap_chain
                ),
            ));
        }
        Ok((pick.clone(), rows))
    }
}

/// CapFrameX's `//key=value` lines (and blank lines) before the header:
/// the pairs, the lines skipped, and the rest of the bytes.
fn leading_comments(bytes: &[u8]) -> (Vec<(String, String)>, u64, &[u8]) {
    let mut meta = Vec::new();
    let mut rest = bytes;
    let mut skipped = 0;
    loop {
        let end = rest.iter().position(|&b| b == b'\n').map_or(rest.len(), |i| i + 1);
        let line = String::from_utf8_lossy(&rest[..end]);
        let t = line.trim();
        if let Some(kv) = t.strip_prefix("//") {
            if let Some((k, v)) = kv.split_once('=') {
                meta.push((k.trim().to_string(), v.trim().to_string()));
            }
        } else if !(t.is_empty() && end > 0) {
            break;
        }
        rest = &rest[end..];
        skipped += 1;
        if rest.is_empty() {
            break;
        }
    }
    (meta, skipped, rest)
}

/// The system columns' first values (OCAT's first row, FrameView's every row).
fn system_metadata(header: &Header, raw: &[(u64, csv::StringRecord)], meta: &mut Vec<(String, String)>) {
    for name in SYSTEM_COLUMNS {
        let Some(i) = header.position(name) else { continue };
        if meta.iter().any(|(k, _)| k.eq_ignore_ascii_case(name)) {
            continue;
        }
        if let Some(v) = raw
            .iter()
            .find_map(|(_, r)| r.get(i).map(str::trim).filter(|v| !v.is_empty() && *v != "NA"))
        {
            meta.push((header.names[i].clone(), v.to_string()));
        }
    }
}

/// Reads one row into a present (its CPU start, for PresentMon 1, is
/// filled in once its swap chain's frames are in order).
fn read_row(
    cell: &Cells<'_>,
    columns: Columns,
    qpc_per_ms: Option<f64>,
    header: &Header,
    line: u64,
    rec: &csv::StringRecord,
    notes: &mut Notes,
) -> Result<Row, CaptureError> {
    let opt = |col: Col| cell.opt(rec, line, col);
    // A frame the application did not render has no CPU times of its own
    // (rendersim writes `NA`): its times are read where they are given.
    let rendered = is_application_frame(cell.text(rec, Col::FrameType).unwrap_or_default());
    let need = |col: Col| -> Result<f64, CaptureError> {
        if rendered {
            cell.need(rec, line, col)
        } else {
            Ok(cell.opt(rec, line, col)?.unwrap_or(f64::NAN))
        }
    };
    let (cpu_start, present, cpu_busy, cpu_wait, between) = match columns {
        Columns::V2 => {
            let busy = need(Col::CpuBusy)?;
            // NA: the capture ends in the frame's present call.
            let wait = opt(Col::CpuWait)?.unwrap_or(0.0);
            let start = if let Some(rate) = qpc_per_ms {
                need(Col::CpuStartQpc)? / rate
            } else if header.has(Col::CpuStartMs) {
                need(Col::CpuStartMs)?
            } else {
                need(Col::CpuStartS)? * 1e3
            };
            let present = match qpc_per_ms {
                Some(rate) if header.has(Col::TimeInQpc) => need(Col::TimeInQpc)? / rate,
                _ => start + busy,
            };
            (start, present, busy, wait, 0.0)
        }
        Columns::V1 => {
            let present = if header.has(Col::TimeInSeconds) {
                need(Col::TimeInSeconds)? * 1e3
            } else if header.has(Col::TimeInMs) {
                need(Col::TimeInMs)?
            } else {
                need(Col::TimeInQpc)? / qpc_per_ms.expect("a QPC rate for QPCTime")
            };
            let between = need(Col::BetweenPresents)?;
            let in_api = opt(Col::InPresentApi)?.unwrap_or(0.0);
            (f64::NAN, present, 0.0, in_api, between)
        }
    };
    for (col, v) in [(Col::CpuBusy, cpu_busy), (Col::CpuWait, cpu_wait)] {
        if v < 0.0 {
            return Err(cell.bad(line, col, format!("{v} is negative")));
        }
    }
    // Shown or not: `Dropped` where the capture has it (anything but 0 or
    // 1 is unknown), else whether the time until displayed exists.
    let dropped = cell.text(rec, Col::Dropped);
    let fate_known = dropped.is_none_or(|d| d == "0" || d == "1" || d.is_empty());
    let until_displayed = if dropped == Some("1") || !fate_known {
        None
    } else if header.has(Col::UntilDisplayed) {
        opt(Col::UntilDisplayed)?
    } else {
        // PresentMon 2.x's own names: CPU start to the screen.
        opt(Col::DisplayLatency)?.map(|l| l - cpu_busy)
    };
    let render_complete = match (opt(Col::RenderPresentLatency)?, opt(Col::UntilRenderComplete)?) {
        (Some(v), _) | (None, Some(v)) => Some(v),
        // PresentMon 2's own names: CPU start to the GPU's start and its time.
        (None, None) => match (opt(Col::GpuLatency)?, opt(Col::GpuTime)?) {
            (Some(l), Some(t)) if columns == Columns::V2 => Some(l + t - cpu_busy),
            _ => None,
        },
    };
    let text = |col: Col| cell.intern(cell.text(rec, col).unwrap_or_default());
    let mut present = Present {
        line,
        application: text(Col::Application),
        process_id: text(Col::ProcessId),
        swap_chain: text(Col::SwapChain),
        present_mode: text(Col::PresentMode),
        sync_interval: opt(Col::SyncInterval)?.map(|v| v as i64),
        allows_tearing: opt(Col::AllowsTearing)? == Some(1.0),
        frame_type: text(Col::FrameType),
        cpu_start,
        present,
        cpu_busy,
        cpu_wait,
        gpu_latency: opt(Col::GpuLatency)?,
        gpu_busy: opt(Col::GpuBusy)?,
        gpu_time: opt(Col::GpuTime)?,
        render_complete,
        until_displayed,
        fate_known,
        between_display_change: opt(Col::BetweenDisplayChange)?,
        display_latency: opt(Col::DisplayLatency)?,
        pc_latency: opt(Col::PcLatency)?,
        all_input_to_photon: opt(Col::AllInputToPhoton)?,
        click_to_photon: opt(Col::ClickToPhoton)?,
        render_queue_depth: opt(Col::RenderQueueDepth)?,
    };
    if !fate_known {
        notes.unknown_fates += 1;
    }
    // A present of a mode PresentMon could not tell (`Other`), marked
    // dropped with neither a render completion nor a display: PresentMon
    // followed it no further than the present call (PresentMon's test
    // capture of TrivFlip opens with 40 of dwm.exe's: the trace began
    // after their flips were set up), so its `Dropped` is no fate.
    let mode: &str = &present.present_mode;
    if fate_known
        && dropped == Some("1")
        && (mode == "Other" || mode == "Unknown")
        && present.render_complete.is_none_or(|r| r == 0.0)
    {
        present.fate_known = false;
        notes.untracked += 1;
    }
    Ok(Row { present, between })
}

/// The column set a header uses, checked for the columns a replay needs.
/// A capture's bytes as UTF-8 when they are UTF-16 (a byte-order mark
/// `FF FE` or `FE FF`, or, without one, a first line whose every other
/// byte is zero); `None` for anything else (read as UTF-8).
fn from_utf16(bytes: &[u8]) -> Result<Option<Vec<u8>>, String> {
    let (little, body) = match bytes {
        [0xFF, 0xFE, rest @ ..] => (true, rest),
        [0xFE, 0xFF, rest @ ..] => (false, rest),
        [a, 0, b, 0, ..] if *a != 0 && *b != 0 => (true, bytes),
        [0, a, 0, b, ..] if *a != 0 && *b != 0 => (false, bytes),
        _ => return Ok(None),
    };
    let units: Vec<u16> = body
        .chunks(2)
        .map(|c| match (c, little) {
            ([lo, hi], true) => u16::from_le_bytes([*lo, *hi]),
            ([hi, lo], false) => u16::from_be_bytes([*hi, *lo]),
            _ => 0xFFFD,
        })
        .collect();
    String::from_utf16(&units)
        .map(|t| Some(t.into_bytes()))
        .map_err(|_| "the file looks like UTF-16 text (by its first bytes) but is not valid UTF-16".to_string())
}

/// Refuses a capture that holds a row twice, field for field (a file
/// written twice into one, which would count every frame twice).
fn repeated_rows(file: &str, raw: &[(u64, csv::StringRecord)]) -> Result<(), CaptureError> {
    let mut seen: HashMap<Vec<&str>, u64> = HashMap::with_capacity(raw.len());
    for (line, rec) in raw {
        if let Some(first) = seen.insert(rec.iter().collect(), *line) {
            return Err(CaptureError::Row {
                file: file.to_string(),
                line: *line,
                message: format!(
                    "repeats line {first} field for field: the capture holds rows twice (written twice into one \
                     file?), which would count its frames twice; remove the copies"
                ),
            });
        }
    }
    Ok(())
}

fn column_set(file: &str, header: &Header) -> Result<Columns, CaptureError> {
    let fmt = |message: String| CaptureError::Format {
        file: file.to_string(),
        message,
    };
    let v2_start = header.has(Col::CpuStartQpc) || header.has(Col::CpuStartMs) || header.has(Col::CpuStartS);
    let v1_time = header.has(Col::TimeInSeconds) || header.has(Col::TimeInMs) || header.has(Col::TimeInQpc);
    let columns = if v2_start && header.has(Col::CpuBusy) {
        Columns::V2
    } else if v1_time && header.has(Col::BetweenPresents) {
        Columns::V1
    } else if v2_start {
        Columns::V2
    } else if v1_time {
        Columns::V1
    } else {
        return Err(fmt(
            "not a PresentMon capture: the header has neither `CPUStartQPC`/`CPUStartTime` (PresentMon 2) \
                 nor `TimeInSeconds` (PresentMon 1)"
                .into(),
        ));
    };
    let needed: &[Col] = match columns {
        Columns::V2 => &[Col::Application, Col::SwapChain, Col::PresentMode, Col::CpuBusy],
        Columns::V1 => &[Col::Application, Col::SwapChain, Col::PresentMode, Col::BetweenPresents],
    };
    let shown_ok = header.has(Col::UntilDisplayed) || (columns == Columns::V2 && header.has(Col::DisplayLatency));
    let missing = needed
        .iter()
        .find(|c| !header.has(**c))
        .map(|c| header.name(*c).to_string())
        .or_else(|| (!shown_ok).then(|| "MsUntilDisplayed".to_string()));
    if let Some(missing) = missing {
        let (set, list) = match columns {
            Columns::V2 => (
                "PresentMon 2",
                "Application, SwapChainAddress, PresentMode, a CPU start, MsCPUBusy, and MsUntilDisplayed or DisplayLatency",
            ),
            Columns::V1 => (
                "PresentMon 1",
                "Application, SwapChainAddress, PresentMode, TimeInSeconds, MsBetweenPresents, MsUntilDisplayed",
            ),
        };
        return Err(fmt(format!(
            "missing column `{missing}` (a {set} capture needs {list})"
        )));
    }
    Ok(columns)
}

/// Whether a `FrameType` cell names a frame the application rendered: PresentMon
/// writes `Application` (also for a repeat of a rendered frame; empty,
/// `NotSet`, `Unspecified` or `Unknown` when it does not know, taken as
/// rendered); anything else (`Intel XeSS-FG`, `AMD AFMF`,
/// `Repeated`, rendersim's `Generated`) is a frame the application did not
/// render.
fn is_application_frame(frame_type: &str) -> bool {
    matches!(frame_type, "" | "Application" | "NotSet" | "Unspecified" | "Unknown")
}

#[cfg(test)]
mod tests;
