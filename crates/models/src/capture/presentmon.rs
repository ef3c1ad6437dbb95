//! PresentMon CSV captures, in both of its column sets.
//!
//! - **v2** (PresentMon 2): the frame's CPU start (`CPUStartQPC` with
//!   `TimeInQPC`; or `CPUStartTime`, `CPUStartTimeInMs` or `CPUStartQPCTime`
//!   in milliseconds, or `CPUStartTimeInSeconds`), `MsCPUBusy` (CPU start
//!   to the present call), `MsCPUWait` (in the present call; `NA`, as
//!   rendersim writes for a run's last frame, is none), `MsGPULatency`
//!   (CPU start to the GPU starting the frame), `MsGPUTime` (from there to
//!   the GPU finishing it), `MsGPUBusy`, `MsRenderPresentLatency` (present
//!   to GPU done), `MsUntilDisplayed`, `MsBetweenDisplayChange`,
//!   `DisplayLatency`. rendersim's own `frames.csv` is such a capture.
//! - **v1** (PresentMon 1): `TimeInSeconds` (the present), `MsBetweenPresents`,
//!   `MsInPresentAPI`, `MsUntilRenderComplete`, `MsUntilDisplayed`, `Dropped`.
//!
//! Either set also names the swap chain (`Application`, `ProcessID`,
//! `SwapChainAddress`) and how it presents (`PresentMode`, `SyncInterval`,
//! `AllowsTearing`). `NA` marks a value that does not exist (a frame never
//! shown has `NA` for `MsUntilDisplayed`); a UTF-8 byte-order mark is
//! skipped. QPC time stamps are converted with the tick rate the capture
//! itself implies (`TimeInQPC - CPUStartQPC` over `MsCPUBusy`).

use std::collections::HashMap;
use std::path::Path;

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
    pub application: String,
    /// Process id (as written).
    pub process_id: String,
    /// Swap chain (as written, e.g. `0x224B280A1C0`).
    pub swap_chain: String,
    /// `PresentMode` as written (`Hardware: Legacy Flip`, `Composed: Flip`, ...).
    pub present_mode: String,
    /// `SyncInterval` (absent in some captures).
    pub sync_interval: Option<i64>,
    /// `AllowsTearing`.
    pub allows_tearing: bool,
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
    /// Present to the frame appearing (`None`: never shown).
    pub until_displayed: Option<f64>,
    /// The previous displayed frame's appearance to this one's.
    pub between_display_change: Option<f64>,
    /// Input (or CPU start) to the frame appearing, where given.
    pub display_latency: Option<f64>,
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
    /// Rows of frames the application did not render (`FrameType` other than
    /// `Application`: generated by frame generation, or repeated), skipped.
    pub not_rendered: usize,
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

impl Capture {
    /// Reads a capture from `path`.
    pub fn read(path: &Path) -> Result<Capture, CaptureError> {
        let bytes = std::fs::read(path).map_err(|source| CaptureError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Capture::parse(&path.display().to_string(), &bytes)
    }

    /// Parses a capture's bytes; `file` names it in errors.
    pub fn parse(file: &str, bytes: &[u8]) -> Result<Capture, CaptureError> {
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        let format = |message: String| CaptureError::Format {
            file: file.to_string(),
            message,
        };
        let mut rdr = csv::ReaderBuilder::new().flexible(false).from_reader(bytes);
        let header = rdr
            .headers()
            .map_err(|e| format(format!("not a CSV file: {e}")))?
            .clone();
        let col: HashMap<&str, usize> = header.iter().enumerate().map(|(i, h)| (h.trim(), i)).collect();
        let columns = column_set(file, &col)?;
        let mut raw = Vec::new();
        for rec in rdr.records() {
            let rec = rec.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line());
                CaptureError::Row {
                    file: file.to_string(),
                    line,
                    message: format!("not a CSV row: {e}"),
                }
            })?;
            let line = rec.position().map_or(0, |p| p.line());
            raw.push((line, rec));
        }
        if raw.is_empty() {
            return Err(format("no presents: the capture has a header and no rows".into()));
        }
        let cell = Cells { file, col: &col };
        let qpc_per_ms = if columns == Columns::V2 && col.contains_key("CPUStartQPC") {
            Some(qpc_rate(file, &cell, &raw)?)
        } else {
            None
        };
        let mut presents = Vec::with_capacity(raw.len());
        let mut prev_v1: HashMap<String, (f64, f64)> = HashMap::new();
        let mut not_rendered = 0;
        for (line, rec) in &raw {
            let line = *line;
            let text = |name: &str| cell.text(rec, name).unwrap_or_default().to_string();
            if !is_application_frame(&text("FrameType")) {
                // A frame a driver or runtime generated (frame generation):
                // no CPU or GPU time of the application's to replay.
                not_rendered += 1;
                continue;
            }
            let swap_chain = text("SwapChainAddress");
            let (cpu_start, present, cpu_busy, cpu_wait) = match columns {
                Columns::V2 => {
                    let busy = cell.need(rec, line, "MsCPUBusy")?;
                    // NA: the capture ends in the frame's present call.
                    let wait = cell.opt(rec, line, "MsCPUWait")?.unwrap_or(0.0);
                    let start = match qpc_per_ms {
                        Some(rate) => cell.need(rec, line, "CPUStartQPC")? / rate,
                        None => {
                            let (name, ms_per_unit) = start_column(&col).expect("a v2 header names a CPU start");
                            cell.need(rec, line, name)? * ms_per_unit
                        }
                    };
                    let present = match qpc_per_ms {
                        Some(rate) => cell.need(rec, line, "TimeInQPC")? / rate,
                        None => start + busy,
                    };
                    (start, present, busy, wait)
                }
                Columns::V1 => {
                    let present = cell.need(rec, line, "TimeInSeconds")? * 1e3;
                    let between = cell.need(rec, line, "MsBetweenPresents")?;
                    let in_api = cell.opt(rec, line, "MsInPresentAPI")?.unwrap_or(0.0);
                    // The frame starts when the previous present call returned.
                    let start = match prev_v1.get(&swap_chain) {
                        Some(&(p, w)) => p + w,
                        None => present - between,
                    };
                    prev_v1.insert(swap_chain.clone(), (present, in_api));
                    (start, present, (present - start).max(0.0), in_api)
                }
            };
            for (name, v) in [("MsCPUBusy", cpu_busy), ("MsCPUWait", cpu_wait)] {
                if v < 0.0 {
                    return Err(cell.bad(line, name, format!("{v} is negative")));
                }
            }
            let until_displayed = match columns {
                Columns::V1 if cell.opt(rec, line, "Dropped")? == Some(1.0) => None,
                _ => cell.opt(rec, line, "MsUntilDisplayed")?,
            };
            let render_complete = match cell.opt(rec, line, "MsRenderPresentLatency")? {
                Some(v) => Some(v),
                None => cell.opt(rec, line, "MsUntilRenderComplete")?,
            };
            presents.push(Present {
                line,
                application: text("Application"),
                process_id: text("ProcessID"),
                swap_chain,
                present_mode: text("PresentMode"),
                sync_interval: cell.opt(rec, line, "SyncInterval")?.map(|v| v as i64),
                allows_tearing: cell.opt(rec, line, "AllowsTearing")? == Some(1.0),
                cpu_start,
                present,
                cpu_busy,
                cpu_wait,
                gpu_latency: cell.opt(rec, line, "MsGPULatency")?,
                gpu_busy: cell.opt(rec, line, "MsGPUBusy")?,
                gpu_time: cell.opt(rec, line, "MsGPUTime")?,
                render_complete,
                until_displayed,
                between_display_change: cell.opt(rec, line, "MsBetweenDisplayChange")?,
                display_latency: cell.opt(rec, line, "DisplayLatency")?,
            });
        }
        if presents.is_empty() {
            return Err(format(format!(
                "no presents the application rendered: all {not_rendered} rows have a `FrameType` other than `Application`"
            )));
        }
        Ok(Capture {
            file: file.to_string(),
            columns,
            qpc_per_ms,
            presents,
            not_rendered,
        })
    }

    /// The swap chains (one per process, application and address: runtimes
    /// without an address write 0x0 for every process), most frames first
    /// (ties in file order).
    pub fn swap_chains(&self) -> Vec<SwapChainInfo> {
        let mut order: Vec<SwapChainInfo> = Vec::new();
        let mut modes: Vec<HashMap<&str, usize>> = Vec::new();
        for p in &self.presents {
            let i = match order.iter().position(|s| {
                s.swap_chain == p.swap_chain && s.application == p.application && s.process_id == p.process_id
            }) {
                Some(i) => i,
                None => {
                    order.push(SwapChainInfo {
                        application: p.application.clone(),
                        process_id: p.process_id.clone(),
                        swap_chain: p.swap_chain.clone(),
                        present_mode: String::new(),
                        frames: 0,
                    });
                    modes.push(HashMap::new());
                    order.len() - 1
                }
            };
            order[i].frames += 1;
            *modes[i].entry(p.present_mode.as_str()).or_default() += 1;
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
    /// least two frames, present times that never go back, and at least
    /// two displayed frames. Returns the swap chain (with the present mode
    /// most of its frames use) and its presents.
    pub fn select(
        &self,
        app: Option<&str>,
        swap_chain: Option<&str>,
    ) -> Result<(SwapChainInfo, Vec<&Present>), CaptureError> {
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
        let rows: Vec<&Present> = self
            .presents
            .iter()
            .filter(|p| {
                p.swap_chain == pick.swap_chain && p.application == pick.application && p.process_id == pick.process_id
            })
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
        for w in rows.windows(2) {
            if w[1].present < w[0].present || w[1].cpu_start < w[0].cpu_start {
                return Err(row_err(
                    w[1].line,
                    format!(
                        "times go back: this frame of swap chain {} starts or presents before the one on line {}",
                        pick.swap_chain, w[0].line
                    ),
                ));
            }
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

/// A PresentMon 2 CPU start column in time units (not QPC ticks), with its
/// milliseconds per unit, as the versions of PresentMon 2 name it.
const START_COLUMNS: [(&str, f64); 4] = [
    ("CPUStartTime", 1.0),
    ("CPUStartTimeInMs", 1.0),
    ("CPUStartQPCTime", 1.0),
    ("CPUStartTimeInSeconds", 1e3),
];

/// The header's CPU start column in time units, with its milliseconds per unit.
fn start_column(col: &HashMap<&str, usize>) -> Option<(&'static str, f64)> {
    START_COLUMNS.iter().copied().find(|(name, _)| col.contains_key(name))
}

/// The column set a header uses, checked for the columns a replay needs.
fn column_set(file: &str, col: &HashMap<&str, usize>) -> Result<Columns, CaptureError> {
    let fmt = |message: String| CaptureError::Format {
        file: file.to_string(),
        message,
    };
    let columns = if col.contains_key("CPUStartQPC") || start_column(col).is_some() {
        Columns::V2
    } else if col.contains_key("TimeInSeconds") {
        Columns::V1
    } else {
        return Err(fmt(
            "not a PresentMon capture: the header has neither `CPUStartQPC`/`CPUStartTime` (PresentMon 2) \
                 nor `TimeInSeconds` (PresentMon 1)"
                .into(),
        ));
    };
    let needed: &[&str] = match columns {
        Columns::V2 if col.contains_key("CPUStartQPC") => &[
            "Application",
            "SwapChainAddress",
            "PresentMode",
            "TimeInQPC",
            "MsCPUBusy",
            "MsCPUWait",
            "MsUntilDisplayed",
        ],
        Columns::V2 => &[
            "Application",
            "SwapChainAddress",
            "PresentMode",
            "MsCPUBusy",
            "MsCPUWait",
            "MsUntilDisplayed",
        ],
        Columns::V1 => &[
            "Application",
            "SwapChainAddress",
            "PresentMode",
            "MsBetweenPresents",
            "MsUntilDisplayed",
        ],
    };
    if let Some(missing) = needed.iter().find(|c| !col.contains_key(**c)) {
        let set = if columns == Columns::V2 {
            "PresentMon 2"
        } else {
            "PresentMon 1"
        };
        return Err(fmt(format!(
            "missing column `{missing}` (a {set} capture needs {})",
            needed.join(", ")
        )));
    }
    Ok(columns)
}

/// Whether a `FrameType` cell names a frame the application rendered: PresentMon
/// writes `Application` (empty, `NotSet` or `Unspecified` when it does not
/// know, taken as rendered); anything else (`Intel XeSS-FG`, `AMD AFMF`,
/// `Repeated`, rendersim's `Generated`) is a frame the application did not
/// render.
fn is_application_frame(frame_type: &str) -> bool {
    matches!(frame_type, "" | "Application" | "NotSet" | "Unspecified")
}

/// Reads cells by column name.
struct Cells<'a> {
    file: &'a str,
    col: &'a HashMap<&'a str, usize>,
}

impl Cells<'_> {
    fn text<'r>(&self, rec: &'r csv::StringRecord, name: &str) -> Option<&'r str> {
        self.col.get(name).and_then(|&i| rec.get(i)).map(str::trim)
    }

    fn bad(&self, line: u64, column: &str, message: String) -> CaptureError {
        CaptureError::Cell {
            file: self.file.to_string(),
            line,
            column: column.to_string(),
            message,
        }
    }

    /// A number, `None` for `NA`, an empty cell or a column the file lacks.
    fn opt(&self, rec: &csv::StringRecord, line: u64, name: &str) -> Result<Option<f64>, CaptureError> {
        let Some(t) = self.text(rec, name) else {
            return Ok(None);
        };
        if t.is_empty() || t.eq_ignore_ascii_case("NA") {
            return Ok(None);
        }
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            Ok(_) => Err(self.bad(line, name, format!("{t:?} is not a finite number"))),
            Err(_) => Err(self.bad(line, name, format!("{t:?} is not a number (nor NA)"))),
        }
    }

    /// A number that must be given.
    fn need(&self, rec: &csv::StringRecord, line: u64, name: &str) -> Result<f64, CaptureError> {
        self.opt(rec, line, name)?
            .ok_or_else(|| self.bad(line, name, "is NA or empty, and a replay needs it".into()))
    }
}

/// QPC ticks per millisecond: the median over rows of the ticks from CPU
/// start to present over `MsCPUBusy` (rows busy at least 0.5 ms).
fn qpc_rate(file: &str, cell: &Cells<'_>, raw: &[(u64, csv::StringRecord)]) -> Result<f64, CaptureError> {
    let mut rates = Vec::new();
    for (line, rec) in raw {
        let (Some(start), Some(at), Some(busy)) = (
            cell.opt(rec, *line, "CPUStartQPC")?,
            cell.opt(rec, *line, "TimeInQPC")?,
            cell.opt(rec, *line, "MsCPUBusy")?,
        ) else {
            continue;
        };
        if busy >= 0.5 && at > start {
            rates.push((at - start) / busy);
        }
    }
    if rates.is_empty() {
        return Err(CaptureError::Format {
            file: file.to_string(),
            message: "the QPC tick rate cannot be inferred: no row has MsCPUBusy of 0.5 ms or more with TimeInQPC after CPUStartQPC".into(),
        });
    }
    rates.sort_by(f64::total_cmp);
    Ok(rates[rates.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "Application,ProcessID,SwapChainAddress,PresentMode,SyncInterval,AllowsTearing,TimeInQPC,CPUStartQPC,MsCPUBusy,MsCPUWait,MsGPULatency,MsGPUBusy,MsRenderPresentLatency,MsUntilDisplayed,MsBetweenDisplayChange\n";

    fn row(start: u64, busy: f64, until: &str) -> String {
        let at = start + (busy * 10_000.0) as u64;
        format!("a.exe,1,0x1,Hardware: Legacy Flip,1,0,{at},{start},{busy},0.1,0.5,2.0,0.1,{until},NA\n")
    }

    #[test]
    fn reads_v2_with_qpc_na_and_a_byte_order_mark() {
        let text = format!("\u{feff}{HEAD}{}{}", row(0, 10.0, "5.0"), row(101_000, 10.0, "NA"));
        let c = Capture::parse("t.csv", text.as_bytes()).unwrap();
        assert_eq!(c.columns, Columns::V2);
        assert_eq!(c.qpc_per_ms, Some(10_000.0));
        assert_eq!(c.presents.len(), 2);
        let p = &c.presents[1];
        assert!((p.cpu_start - 10.1).abs() < 1e-9 && (p.present - 20.1).abs() < 1e-9);
        assert_eq!(p.until_displayed, None);
        assert_eq!(c.presents[0].screen_time(), Some(15.0));
        assert_eq!(c.presents[0].line, 2);
    }

    #[test]
    fn reads_each_name_of_the_cpu_start_and_a_missing_wait_as_none() {
        for (name, scale) in [
            ("CPUStartTime", 1.0),
            ("CPUStartTimeInMs", 1.0),
            ("CPUStartQPCTime", 1.0),
            ("CPUStartTimeInSeconds", 1e-3),
        ] {
            let text = format!(
                "Application,ProcessID,SwapChainAddress,PresentMode,{name},MsCPUBusy,MsCPUWait,MsUntilDisplayed\n\
                 a.exe,1,0x1,Hardware: Legacy Flip,{},10,NA,5\n",
                250.0 * scale
            );
            let c = Capture::parse("t.csv", text.as_bytes()).unwrap();
            assert_eq!(c.columns, Columns::V2, "{name}");
            let p = &c.presents[0];
            assert!(
                (p.cpu_start - 250.0).abs() < 1e-9 && (p.present - 260.0).abs() < 1e-9,
                "{name}"
            );
            assert_eq!(p.cpu_wait, 0.0, "{name}: NA is no time in the present call");
        }
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let text = format!("{HEAD}{}", row(0, 10.0, "abc"));
        let e = Capture::parse("t.csv", text.as_bytes()).unwrap_err().to_string();
        assert_eq!(
            e,
            "t.csv:2: column `MsUntilDisplayed`: \"abc\" is not a number (nor NA)"
        );
        let text = format!("{HEAD}{}", row(0, 10.0, "inf"));
        let e = Capture::parse("t.csv", text.as_bytes()).unwrap_err().to_string();
        assert!(
            e.contains("t.csv:2: column `MsUntilDisplayed`: \"inf\" is not a finite number"),
            "{e}"
        );
        let e = Capture::parse("t.csv", b"Application,SwapChainAddress\na,b\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.csv: not a PresentMon capture"), "{e}");
        let head = HEAD.replace("MsCPUWait,", "");
        let body = "a.exe,1,0x1,Hardware: Legacy Flip,1,0,100000,0,10,0.5,2.0,0.1,5,NA\n";
        let e = Capture::parse("t.csv", format!("{head}{body}").as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.csv: missing column `MsCPUWait`"), "{e}");
        let e = Capture::parse("t.csv", HEAD.as_bytes()).unwrap_err().to_string();
        assert!(e.contains("no rows"), "{e}");
        let e = Capture::parse("t.csv", format!("{HEAD}a,b\n").as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.csv:2: not a CSV row"), "{e}");
    }

    #[test]
    fn select_refuses_one_frame_time_going_back_and_nothing_displayed() {
        let one = format!("{HEAD}{}", row(0, 10.0, "5"));
        let c = Capture::parse("t.csv", one.as_bytes()).unwrap();
        assert!(c.select(None, None).unwrap_err().to_string().contains("has one frame"));
        let back = format!("{HEAD}{}{}", row(200_000, 10.0, "5"), row(0, 10.0, "5"));
        let c = Capture::parse("t.csv", back.as_bytes()).unwrap();
        assert!(
            c.select(None, None)
                .unwrap_err()
                .to_string()
                .starts_with("t.csv:3: times go back")
        );
        let none = format!("{HEAD}{}{}", row(0, 10.0, "NA"), row(101_000, 10.0, "NA"));
        let c = Capture::parse("t.csv", none.as_bytes()).unwrap();
        assert!(
            c.select(None, None)
                .unwrap_err()
                .to_string()
                .contains("fewer than two displayed")
        );
        let two = format!("{HEAD}{}{}", row(0, 10.0, "5"), row(101_000, 10.0, "5"));
        let c = Capture::parse("t.csv", two.as_bytes()).unwrap();
        let e = c.select(Some("b.exe"), None).unwrap_err().to_string();
        assert!(
            e.contains("no swap chain of application \"b.exe\"; the capture has: a.exe (process 1) 0x1"),
            "{e}"
        );
        assert_eq!(c.select(Some("A.EXE"), Some("0x1")).unwrap().1.len(), 2);
    }
}
