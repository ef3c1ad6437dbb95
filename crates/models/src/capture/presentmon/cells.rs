//! Reading a capture's cells by what they hold, and keeping count of what
//! the reader had to undo.

use super::CaptureError;
use super::columns::{Col, Header};

/// The largest magnitude a time of a capture may have, ms (about 115
/// days): PresentMon 1's unsigned underflow writes 1.8e15, which is no
/// time at all.
pub(super) const MAX_MS: f64 = 1e10;

/// What the reader had to undo, counted, and said once at the end.
#[derive(Debug, Default)]
pub(super) struct Notes {
    pub(super) short_rows: usize,
    pub(super) long_rows: usize,
    pub(super) repeated_headers: usize,
    pub(super) trailers: usize,
    pub(super) unknown_fates: usize,
    /// Presents of a mode PresentMon could not tell that it followed no
    /// further than the present call.
    pub(super) untracked: usize,
    /// Values no time can have: the count, and the first one's line, column and text.
    pub(super) impossible: usize,
    pub(super) first_impossible: Option<Impossible>,
    lines: Vec<String>,
}

impl Notes {
    pub(super) fn push(&mut self, line: String) {
        self.lines.push(line);
    }

    /// The notes, one line each.
    pub(super) fn lines(self) -> Vec<String> {
        let mut out = Vec::new();
        if self.short_rows > 0 {
            out.push(format!(
                "{} row(s) have fewer fields than the header (OCAT writes its system columns on the first row only): their missing columns read as absent",
                self.short_rows
            ));
        }
        if self.long_rows > 0 {
            out.push(format!(
                "{} row(s) have more fields than the header: the extra fields are ignored",
                self.long_rows
            ));
        }
        if self.repeated_headers > 0 {
            out.push(format!("{} repeated header row(s) skipped", self.repeated_headers));
        }
        if self.trailers > 0 {
            out.push(format!(
                "{} line(s) that are not rows (a writer's warnings, such as lost events) skipped",
                self.trailers
            ));
        }
        if self.unknown_fates > 0 {
            out.push(format!(
                "{} frame(s) with a `Dropped` of neither 0 nor 1 (FrameView writes `Error`): read as not shown",
                self.unknown_fates
            ));
        }
        if self.untracked > 0 {
            out.push(format!(
                "{} present(s) of a mode PresentMon could not tell (`Other`) that it followed no further than the \
                 present call (no render completion, no display; the trace began after them): fate unknown",
                self.untracked
            ));
        }
        if let Some((line, col, text)) = &self.first_impossible {
            out.push(format!(
                "{} value(s) no time can have (first: line {line}, column `{col}`, {text}; an unsigned underflow of the writer's): read as missing",
                self.impossible
            ));
        }
        out.extend(self.lines);
        out
    }
}

/// A value read as missing: its line, column and text.
type Impossible = (u64, String, String);

/// Reads cells by column.
pub(super) struct Cells<'a> {
    file: &'a str,
    header: &'a Header,
    /// Values no time can have, read as missing: the count and the first.
    impossible: std::cell::RefCell<(usize, Option<Impossible>)>,
    /// The text cells read so far (names, addresses, modes), each kept once.
    strings: std::cell::RefCell<std::collections::HashSet<std::sync::Arc<str>>>,
    /// Subtracted from every QPC stamp read (the earliest, where stamps
    /// are too large for milliseconds as `f64`; else 0).
    qpc_base: std::cell::Cell<i64>,
}

impl<'a> Cells<'a> {
    pub(super) fn new(file: &'a str, header: &'a Header) -> Cells<'a> {
        Cells {
            file,
            header,
            impossible: Default::default(),
            strings: Default::default(),
            qpc_base: std::cell::Cell::new(0),
        }
    }

    /// Counts QPC stamps from the earliest one (exact in `f64` however
    /// far from boot the capture was taken, and a replay of the same
    /// frames the same wherever its clock stood); a negative stamp is an
    /// error.
    pub(super) fn set_qpc_base(&self, raw: &[(u64, csv::StringRecord)]) -> Result<(), CaptureError> {
        let mut least: Option<i64> = None;
        for (line, rec) in raw {
            for col in [Col::TimeInQpc, Col::CpuStartQpc] {
                if let Some(v) = self.text(rec, col).and_then(|t| t.parse::<i64>().ok()) {
                    if v < 0 {
                        return Err(self.bad(*line, col, format!("{v} is negative: a QPC stamp counts ticks")));
                    }
                    least = Some(least.map_or(v, |l| l.min(v)));
                }
            }
        }
        self.qpc_base.set(least.unwrap_or(0));
        Ok(())
    }

    /// A text cell, shared with every equal one read before (a capture
    /// repeats its few names and modes on every row).
    pub(super) fn intern(&self, text: &str) -> std::sync::Arc<str> {
        let mut strings = self.strings.borrow_mut();
        if let Some(s) = strings.get(text) {
            return s.clone();
        }
        let s: std::sync::Arc<str> = text.into();
        strings.insert(s.clone());
        s
    }

    /// Adds the values read as missing to `notes`.
    pub(super) fn report(&self, notes: &mut Notes) {
        let (n, first) = self.impossible.take();
        notes.impossible += n;
        if notes.first_impossible.is_none() {
            notes.first_impossible = first;
        }
    }

    /// A cell's text, `None` where the header has no such column or the row
    /// ends before it.
    pub(super) fn text<'r>(&self, rec: &'r csv::StringRecord, col: Col) -> Option<&'r str> {
        self.header.get(col).and_then(|i| rec.get(i)).map(str::trim)
    }

    pub(super) fn bad(&self, line: u64, col: Col, message: String) -> CaptureError {
        CaptureError::Cell {
            file: self.file.to_string(),
            line,
            column: self.header.name(col).to_string(),
            message,
        }
    }

    /// A number, `None` for `NA`, an empty cell, a column the file or the
    /// row lacks, or a value no time can have (counted in `notes`).
    pub(super) fn opt(&self, rec: &csv::StringRecord, line: u64, col: Col) -> Result<Option<f64>, CaptureError> {
        let Some(t) = self.text(rec, col) else {
            return Ok(None);
        };
        if t.is_empty() || t.eq_ignore_ascii_case("NA") {
            return Ok(None);
        }
        if matches!(col, Col::TimeInQpc | Col::CpuStartQpc) {
            // Ticks, exactly (an `f64` holds whole numbers only to 2^53);
            // negative ones were refused by `set_qpc_base`.
            if let Ok(v) = t.parse::<i64>() {
                return Ok(Some((v - self.qpc_base.get()) as f64));
            }
        }
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() && v.abs() <= MAX_MS => Ok(Some(v)),
            Ok(v) if v.is_finite() && !matches!(col, Col::TimeInQpc | Col::CpuStartQpc) => {
                let mut imp = self.impossible.borrow_mut();
                imp.0 += 1;
                if imp.1.is_none() {
                    imp.1 = Some((line, self.header.name(col).to_string(), t.to_string()));
                }
                Ok(None)
            }
            Ok(v) if v.is_finite() => Ok(Some(v)),
            Ok(_) => Err(self.bad(line, col, format!("{t:?} is not a finite number"))),
            Err(_) => Err(self.bad(line, col, format!("{t:?} is not a number (nor NA)"))),
        }
    }

    /// A number that must be given.
    pub(super) fn need(&self, rec: &csv::StringRecord, line: u64, col: Col) -> Result<f64, CaptureError> {
        if self.header.get(col).is_some_and(|i| i >= rec.len()) {
            return Err(self.bad(
                line,
                col,
                format!(
                    "the row ends after {} field(s), before this column (the header has {})",
                    rec.len(),
                    self.header.names.len()
                ),
            ));
        }
        self.opt(rec, line, col)?
            .ok_or_else(|| self.bad(line, col, "is NA or empty, and a replay needs it".into()))
    }
}
