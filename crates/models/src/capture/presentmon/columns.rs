//! The columns a capture's header may name, under every name its writers
//! have given them: PresentMon 1 (`MsBetweenPresents`, and the lower-case
//! `msBetweenPresents` of its first versions), PresentMon 2's three column
//! sets (the `Ms...` names of `--v1_metrics` and of 2.0's default, the
//! bare names of 2.x's default, `CPUStartQPC` or `CPUStartTime` for the
//! frame's start), OCAT (PresentMon 1's plus a system description on its
//! first row), FrameView (PresentMon 1's plus `Render Queue Depth`,
//! `MsPCLatency` and telemetry) and CapFrameX (PresentMon's, after its
//! `//key=value` lines). Names match without regard to case or spaces at
//! either end.

/// A column the reader uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Col {
    Application,
    ProcessId,
    SwapChain,
    PresentMode,
    SyncInterval,
    AllowsTearing,
    FrameType,
    /// The present, s (PresentMon 1).
    TimeInSeconds,
    /// The present, ms.
    TimeInMs,
    /// The present, QPC ticks.
    TimeInQpc,
    /// The frame's CPU start, QPC ticks.
    CpuStartQpc,
    /// The frame's CPU start, ms.
    CpuStartMs,
    /// The frame's CPU start, s.
    CpuStartS,
    BetweenPresents,
    InPresentApi,
    UntilRenderComplete,
    RenderPresentLatency,
    UntilDisplayed,
    BetweenDisplayChange,
    Dropped,
    CpuBusy,
    CpuWait,
    GpuLatency,
    GpuTime,
    GpuBusy,
    DisplayLatency,
    DisplayedTime,
    PcLatency,
    AllInputToPhoton,
    ClickToPhoton,
    RenderQueueDepth,
}

/// How many [`Col`]s there are.
const COLS: usize = Col::RenderQueueDepth as usize + 1;

/// Each column's names, the preferred first.
const NAMES: &[(Col, &[&str])] = &[
    (Col::Application, &["Application"]),
    (Col::ProcessId, &["ProcessID"]),
    (Col::SwapChain, &["SwapChainAddress"]),
    (Col::PresentMode, &["PresentMode"]),
    (Col::SyncInterval, &["SyncInterval"]),
    (Col::AllowsTearing, &["AllowsTearing"]),
    (Col::FrameType, &["FrameType"]),
    (Col::TimeInSeconds, &["TimeInSeconds", "TimeInS"]),
    (Col::TimeInMs, &["TimeInMs", "TimeInMilliseconds"]),
    (Col::TimeInQpc, &["TimeInQPC", "QPCTime"]),
    (Col::CpuStartQpc, &["CPUStartQPC"]),
    (
        Col::CpuStartMs,
        &[
            "CPUStartTime",
            "CPUStartTimeInMs",
            "CPUStartQPCTime",
            "CPUStartQPCTimeInMs",
        ],
    ),
    (Col::CpuStartS, &["CPUStartTimeInSeconds", "CPUStartQPCTimeInSeconds"]),
    (Col::BetweenPresents, &["MsBetweenPresents"]),
    (Col::InPresentApi, &["MsInPresentAPI"]),
    (Col::UntilRenderComplete, &["MsUntilRenderComplete"]),
    (Col::RenderPresentLatency, &["MsRenderPresentLatency"]),
    (Col::UntilDisplayed, &["MsUntilDisplayed"]),
    (Col::BetweenDisplayChange, &["MsBetweenDisplayChange"]),
    (Col::Dropped, &["Dropped"]),
    (Col::CpuBusy, &["MsCPUBusy", "CPUBusy"]),
    (Col::CpuWait, &["MsCPUWait", "CPUWait"]),
    (Col::GpuLatency, &["MsGPULatency", "GPULatency"]),
    (Col::GpuTime, &["MsGPUTime", "GPUTime"]),
    (Col::GpuBusy, &["MsGPUBusy", "GPUBusy"]),
    (Col::DisplayLatency, &["DisplayLatency", "MsDisplayLatency"]),
    (Col::DisplayedTime, &["DisplayedTime", "MsDisplayedTime"]),
    (Col::PcLatency, &["MsPCLatency", "PCLatency"]),
    (
        Col::AllInputToPhoton,
        &["MsAllInputToPhotonLatency", "AllInputToPhotonLatency"],
    ),
    (Col::ClickToPhoton, &["MsClickToPhotonLatency", "ClickToPhotonLatency"]),
    (Col::RenderQueueDepth, &["Render Queue Depth", "RenderQueueDepth"]),
];

/// Columns that describe the system, not a frame: OCAT writes them on its
/// first row only, FrameView on every row; kept as the capture's metadata.
pub(super) const SYSTEM_COLUMNS: &[&str] = &[
    "Motherboard",
    "OS",
    "Processor",
    "System RAM",
    "Base Driver Version",
    "Driver Package",
    "GPU #",
    "GPU",
    "GPU Core Clock (MHz)",
    "GPU Memory Clock (MHz)",
    "GPU Memory (MB)",
    "Comment",
    "CPU",
    "Resolution",
    "Runtime",
    "PresentRuntime",
];

/// Names a CSV header cell might differ by: case, and spaces at the ends.
fn fold(name: &str) -> String {
    name.trim().to_ascii_lowercase()
}

/// The header's columns by what they hold.
pub(super) struct Header {
    /// Where each column is, by [`Col`]'s discriminant (a lookup per cell).
    index: [Option<usize>; COLS],
    /// The header as written.
    pub(super) names: Vec<String>,
}

impl Header {
    /// Maps a header row (each column taken at its first occurrence).
    pub(super) fn new(cells: &csv::StringRecord) -> Header {
        let folded: Vec<String> = cells.iter().map(fold).collect();
        let mut index = [None; COLS];
        for (col, names) in NAMES {
            index[*col as usize] = names.iter().find_map(|n| folded.iter().position(|h| *h == fold(n)));
        }
        Header {
            index,
            names: cells.iter().map(|s| s.trim().to_string()).collect(),
        }
    }

    /// A column the header names twice (by one name or two of its names):
    /// the name as written and the two fields (1-based).
    pub(super) fn repeated(&self) -> Option<(String, usize, usize)> {
        let folded: Vec<String> = self.names.iter().map(|n| fold(n)).collect();
        for (_, names) in NAMES {
            let mut at = folded
                .iter()
                .enumerate()
                .filter(|(_, h)| names.iter().any(|n| **h == fold(n)))
                .map(|(i, _)| i);
            if let (Some(a), Some(b)) = (at.next(), at.next()) {
                return Some((self.names[b].clone(), a + 1, b + 1));
            }
        }
        None
    }

    /// Where a column is.
    pub(super) fn get(&self, col: Col) -> Option<usize> {
        self.index[col as usize]
    }

    /// Whether the header has a column.
    pub(super) fn has(&self, col: Col) -> bool {
        self.get(col).is_some()
    }

    /// The column's name as the header writes it (else its preferred name).
    pub(super) fn name(&self, col: Col) -> &str {
        match self.get(col) {
            Some(i) => &self.names[i],
            None => NAMES.iter().find(|(c, _)| *c == col).map_or("?", |(_, n)| n[0]),
        }
    }

    /// Where a system column is.
    pub(super) fn position(&self, name: &str) -> Option<usize> {
        let f = fold(name);
        self.names.iter().position(|h| fold(h) == f)
    }
}
