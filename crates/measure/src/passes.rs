//! Measured passes as CSV rows, one format for every writer and reader:
//! `rendersim measure --csv`, `rendersim study --csv` and the shared
//! measurement files (`docs/measurements/nvidia-h200/load-grid.csv`,
//! `load-sweep.csv`). The header is [`PASS_HEADER`]:
//!
//! ```text
//! mesh,size,vs_loops,fs_loops,geometry_only,vs_invocations,fs_invocations,pass_time_ns,draws
//! grid:96x96:optimized,384x384,0,500,false,15570,147456,1512832.0,1
//! ```
//!
//! A row describes a pass of one layer without the depth test (the format
//! has no column for either); `draws` is how many draw calls the mesh's
//! triangles were split into (0: a pass that only clears and stores its
//! target); `pass_time_ns` is the median of the recorded passes. Files
//! written before the `draws` column ([`LEGACY_PASS_HEADER`], the shared
//! H200 files) read as one draw a pass, and rows of one draw are appended
//! to them in their own format. Files are appended to: the header is
//! written only into a new or empty file, and a file whose first line is
//! another header is refused untouched. [`read_passes`] reads the format
//! back, naming file, line and column of anything that does not parse.

use std::fmt;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::fit::median;

/// The first line of every pass CSV written.
pub const PASS_HEADER: &str =
    "mesh,size,vs_loops,fs_loops,geometry_only,vs_invocations,fs_invocations,pass_time_ns,draws";

/// The header of pass CSVs written before the `draws` column (every pass
/// one draw): read, and appended to with rows of one draw.
pub const LEGACY_PASS_HEADER: &str =
    "mesh,size,vs_loops,fs_loops,geometry_only,vs_invocations,fs_invocations,pass_time_ns";

/// The column names of [`PASS_HEADER`], in order.
const COLUMNS: [&str; 9] = [
    "mesh",
    "size",
    "vs_loops",
    "fs_loops",
    "geometry_only",
    "vs_invocations",
    "fs_invocations",
    "pass_time_ns",
    "draws",
];

/// Most draw calls one pass may split its mesh into (`rendersim measure
/// --draws`, a CSV row).
pub const MAX_DRAWS: u32 = 4096;

/// A render target size, written `WxH` (`384x384`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TargetSize {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
}

impl From<(u32, u32)> for TargetSize {
    fn from((width, height): (u32, u32)) -> Self {
        TargetSize { width, height }
    }
}

impl fmt::Display for TargetSize {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

/// A size that is not `WxH` with whole numbers.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("size {0:?}: expected WxH, e.g. 384x384")]
pub struct BadSize(pub String);

impl FromStr for TargetSize {
    type Err = BadSize;

    fn from_str(s: &str) -> Result<Self, BadSize> {
        s.split_once('x')
            .and_then(|(w, h)| {
                Some(TargetSize {
                    width: w.parse().ok()?,
                    height: h.parse().ok()?,
                })
            })
            .ok_or_else(|| BadSize(s.to_string()))
    }
}

impl Serialize for TargetSize {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for TargetSize {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = <std::borrow::Cow<'de, str>>::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// One measured pass: what was drawn, the counters, the median time.
/// Serialized in the order of [`PASS_HEADER`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PassRow {
    /// Mesh spec (`grid:96x96:optimized`, `random:30000:5000:7`, a `.idx` file).
    pub mesh: String,
    /// Render target.
    pub size: TargetSize,
    /// Extra vertex-shader ALU loop iterations.
    pub vs_loops: u32,
    /// Extra fragment-shader ALU loop iterations.
    pub fs_loops: u32,
    /// Every vertex at one point: the geometry stage alone.
    pub geometry_only: bool,
    /// Vertex-shader invocations of one pass.
    pub vs_invocations: u64,
    /// Fragment-shader invocations of one pass.
    pub fs_invocations: u64,
    /// Median pass time, nanoseconds.
    pub pass_time_ns: f64,
    /// Draw calls the mesh's triangles were split into (0: none, a pass
    /// that only clears and stores its target).
    pub draws: u32,
}

/// A row in the format of [`LEGACY_PASS_HEADER`] (no `draws` column).
#[derive(Serialize)]
struct LegacyRow<'a> {
    mesh: &'a str,
    size: TargetSize,
    vs_loops: u32,
    fs_loops: u32,
    geometry_only: bool,
    vs_invocations: u64,
    fs_invocations: u64,
    pass_time_ns: f64,
}

/// What identifies a pass: everything but its results.
type PassKey = (String, TargetSize, u32, u32, bool, u32);

impl PassRow {
    fn key(&self) -> PassKey {
        (
            self.mesh.clone(),
            self.size,
            self.vs_loops,
            self.fs_loops,
            self.geometry_only,
            self.draws,
        )
    }
}

#[cfg(feature = "wgpu")]
impl PassRow {
    /// The row of a measurement of the mesh `spec`; `None` for a pass the
    /// format cannot describe: more than one layer, the depth test on, or a
    /// mesh that no spec rebuilds (H1's built-in probes).
    pub fn from_measurement(spec: &str, m: &super::Measurement) -> Option<PassRow> {
        let o = &m.options;
        if o.layers != 1 || o.depth_test || !is_mesh_spec(spec) {
            return None;
        }
        Some(PassRow {
            mesh: spec.to_string(),
            size: o.size.into(),
            vs_loops: o.vs_loops,
            fs_loops: o.fs_loops,
            geometry_only: o.geometry_only,
            vs_invocations: m.vs_invocations,
            fs_invocations: m.fs_invocations,
            pass_time_ns: m.pass_time_ns,
            draws: o.draws,
        })
    }
}

/// Whether `spec` names a mesh that can be built again: a generator spec
/// (`grid:`, `strip:`, `random:`) or an `.obj` / `.idx` file.
pub fn is_mesh_spec(spec: &str) -> bool {
    let lower = spec.trim().to_ascii_lowercase();
    crate::scene::generators::spec_index_count(spec).is_some() || lower.ends_with(".obj") || lower.ends_with(".idx")
}

/// Errors of reading or appending a pass CSV.
#[derive(Debug, thiserror::Error)]
pub enum PassCsvError {
    /// The operating system refused a read or write.
    #[error("{action} {path}: {source}")]
    Io {
        /// What was being done ("reading", "appending to").
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The file's first line is not [`PASS_HEADER`] (nor
    /// [`LEGACY_PASS_HEADER`]).
    #[error(
        "{path} has the header {found:?}, not the pass CSV header {PASS_HEADER:?}; \
         give a new file or one with that header ({path} is left as it was)"
    )]
    Header {
        /// The file.
        path: PathBuf,
        /// Its first line.
        found: String,
    },
    /// A pass of other than one draw for a file of [`LEGACY_PASS_HEADER`].
    #[error(
        "{path} has the header written before the `draws` column, so every pass in it is one draw; \
         a pass of {draws} draws needs a file with the header {PASS_HEADER:?}: give a new file \
         ({path} is left as it was)"
    )]
    LegacyDraws {
        /// The file.
        path: PathBuf,
        /// The draws of the pass refused.
        draws: u32,
    },
    /// A file read as pass rows does not start with [`PASS_HEADER`] (nor
    /// [`LEGACY_PASS_HEADER`]).
    #[error("{path}: line 1 is the header {found:?}, not the pass CSV header {PASS_HEADER:?}")]
    NotPasses {
        /// The file.
        path: PathBuf,
        /// Its first line.
        found: String,
    },
    /// A row that does not parse.
    #[error("{path}: line {line}, column {column} ({name}): {message}")]
    Row {
        /// The file.
        path: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// 1-based column of the bad field (0 when the whole row is wrong).
        column: u64,
        /// The column's name (or "row").
        name: String,
        /// What is wrong.
        message: String,
    },
}

fn io(action: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> PassCsvError {
    let path = path.to_path_buf();
    move |source| PassCsvError::Io { action, path, source }
}

/// The first line of `path` without its line ending; `None` when the file
/// does not exist or is empty.
fn first_line(path: &Path) -> Result<Option<String>, PassCsvError> {
    let file = match std::fs::File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(io("reading", path)(e)),
    };
    let mut line = String::new();
    std::io::BufReader::new(file)
        .read_line(&mut line)
        .map_err(io("reading", path))?;
    if line.is_empty() {
        return Ok(None);
    }
    Ok(Some(line.trim_end_matches(['\n', '\r']).to_string()))
}

/// The format rows are appended to a file in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AppendTo {
    /// A new or empty file: the header [`PASS_HEADER`] first.
    New,
    /// A file with [`PASS_HEADER`].
    Current,
    /// A file with [`LEGACY_PASS_HEADER`]: only passes of one draw.
    Legacy,
}

/// Checks that passes of `draws` draws can be appended to `path`: it is
/// new, empty, or starts with [`PASS_HEADER`], or with
/// [`LEGACY_PASS_HEADER`] when `draws` is 1. Returns the format to write.
/// Commands call it before measuring, so a wrong file costs no device time.
pub fn check_appendable(path: &Path, draws: u32) -> Result<AppendTo, PassCsvError> {
    match first_line(path)? {
        None => Ok(AppendTo::New),
        Some(line) if line == PASS_HEADER => Ok(AppendTo::Current),
        Some(line) if line == LEGACY_PASS_HEADER && draws == 1 => Ok(AppendTo::Legacy),
        Some(line) if line == LEGACY_PASS_HEADER => Err(PassCsvError::LegacyDraws {
            path: path.to_path_buf(),
            draws,
        }),
        Some(found) => Err(PassCsvError::Header {
            path: path.to_path_buf(),
            found,
        }),
    }
}

/// Appends `rows` to `path` (created when missing), with the header first
/// when the file is new or empty. A file with another header, or with the
/// header before the `draws` column when a row is not of one draw, is
/// refused and left untouched.
pub fn append_passes(path: &Path, rows: &[PassRow]) -> Result<(), PassCsvError> {
    let draws = rows.iter().map(|r| r.draws).find(|d| *d != 1).unwrap_or(1);
    let to = check_appendable(path, draws)?;
    let needs_header = to == AppendTo::New;
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(io("appending to", path))?;
    // A last row without its line ending is ended first.
    let len = file.metadata().map_err(io("appending to", path))?.len();
    if len > 0 && !ends_with_newline(path)? {
        file.write_all(b"\n").map_err(io("appending to", path))?;
    }
    let mut w = csv::WriterBuilder::new()
        .has_headers(needs_header)
        .from_writer(std::io::BufWriter::new(file));
    for row in rows {
        let written = if to == AppendTo::Legacy {
            w.serialize(LegacyRow {
                mesh: &row.mesh,
                size: row.size,
                vs_loops: row.vs_loops,
                fs_loops: row.fs_loops,
                geometry_only: row.geometry_only,
                vs_invocations: row.vs_invocations,
                fs_invocations: row.fs_invocations,
                pass_time_ns: row.pass_time_ns,
            })
        } else {
            w.serialize(row)
        };
        written.map_err(|e| csv_io(e, "appending to", path))?;
    }
    w.flush().map_err(io("appending to", path))
}

fn ends_with_newline(path: &Path) -> Result<bool, PassCsvError> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = std::fs::File::open(path).map_err(io("reading", path))?;
    f.seek(SeekFrom::End(-1)).map_err(io("reading", path))?;
    let mut last = [0u8];
    f.read_exact(&mut last).map_err(io("reading", path))?;
    Ok(last[0] == b'\n')
}

fn csv_io(e: csv::Error, action: &'static str, path: &Path) -> PassCsvError {
    let source = match e.into_kind() {
        csv::ErrorKind::Io(e) => e,
        other => std::io::Error::other(format!("{other:?}")),
    };
    PassCsvError::Io {
        action,
        path: path.to_path_buf(),
        source,
    }
}

/// Largest target side a row may give (as `rendersim predict --size`).
pub const MAX_TARGET_SIDE: u32 = 16384;

/// Longest pass time a row may give: one hour, in nanoseconds (a render
/// pass of a measurement takes milliseconds; drivers end one that runs for
/// seconds).
pub const MAX_PASS_TIME_NS: f64 = 3.6e12;

/// Reads every row of a pass CSV. The header must be [`PASS_HEADER`] (or
/// [`LEGACY_PASS_HEADER`], every row one draw); a
/// field that does not parse, or a value no measurement gives (a time that
/// is not a finite number of nanoseconds above 0, a zero target side, a
/// mesh no spec rebuilds, no vertex-shader invocations), is reported with
/// its file, line and column.
pub fn read_passes(path: &Path) -> Result<Vec<PassRow>, PassCsvError> {
    Ok(read_passes_with_lines(path)?.into_iter().map(|(r, _)| r).collect())
}

/// [`read_passes`], each row with its 1-based line in the file (for errors
/// found later, such as a mesh file that cannot be built).
pub fn read_passes_with_lines(path: &Path) -> Result<Vec<(PassRow, u64)>, PassCsvError> {
    let file = crate::limits::open_input(path, crate::limits::InputKind::Data).map_err(io("reading", path))?;
    read_passes_lines_from(file, path)
}

/// [`read_passes`] from any reader; `path` names it in errors.
pub fn read_passes_from(reader: impl std::io::Read, path: &Path) -> Result<Vec<PassRow>, PassCsvError> {
    Ok(read_passes_lines_from(reader, path)?
        .into_iter()
        .map(|(r, _)| r)
        .collect())
}

/// Checks the values of a row that parsed: `(column, message)` of the first
/// value no measurement gives.
fn check_row(row: &PassRow) -> Result<(), (usize, String)> {
    let mesh = row.mesh.trim();
    if mesh.is_empty() {
        return Err((
            1,
            "is empty; give the mesh spec the pass drew (grid:96x96, a .idx file, ...)".into(),
        ));
    }
    if mesh.chars().any(char::is_control) {
        return Err((1, format!("{mesh:?} holds a control character")));
    }
    if !is_mesh_spec(mesh) {
        return Err((
            1,
            format!("{mesh:?} is no mesh spec (grid:WxH, strip:WxH, random:T:V:SEED, or a .obj or .idx file)"),
        ));
    }
    let TargetSize { width, height } = row.size;
    if width == 0 || height == 0 || width > MAX_TARGET_SIDE || height > MAX_TARGET_SIDE {
        return Err((
            2,
            format!("{width}x{height}: width and height must be 1..{MAX_TARGET_SIDE}"),
        ));
    }
    if row.draws > MAX_DRAWS {
        return Err((9, format!("{}: more than {MAX_DRAWS} draws in one pass", row.draws)));
    }
    if row.vs_invocations == 0 && row.draws > 0 {
        return Err((
            6,
            "0: a pass that draws a triangle runs the vertex shader at least once".into(),
        ));
    }
    if row.draws == 0 && (row.vs_invocations > 0 || row.fs_invocations > 0) {
        return Err((
            if row.vs_invocations > 0 { 6 } else { 7 },
            format!(
                "{}: a pass of 0 draws runs no shader",
                row.vs_invocations.max(row.fs_invocations)
            ),
        ));
    }
    let t = row.pass_time_ns;
    if !t.is_finite() || t <= 0.0 {
        return Err((8, format!("{t}: must be a finite number of nanoseconds above 0")));
    }
    if t > MAX_PASS_TIME_NS {
        return Err((
            8,
            format!("{t}: more than {MAX_PASS_TIME_NS:e} ns (one hour); no render pass takes that long"),
        ));
    }
    Ok(())
}

fn read_passes_lines_from(mut reader: impl std::io::Read, path: &Path) -> Result<Vec<(PassRow, u64)>, PassCsvError> {
    // Lines are counted here from the bytes: the csv reader counts a CRLF
    // file's lines one short after its first record (the shared H200 files
    // are CRLF).
    let mut bytes = Vec::new();
    reader.read_to_end(&mut bytes).map_err(io("reading", path))?;
    let newlines: Vec<u64> = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .map(|(i, _)| i as u64)
        .collect();
    // A record's position may point at the line ending before it (after a
    // CRLF) or at blank lines the reader skips: its line is that of its
    // first byte that ends no line.
    let line_at = |p: Option<&csv::Position>| {
        p.map_or(0, |p| {
            let start = bytes
                .iter()
                .skip(p.byte() as usize)
                .position(|b| *b != b'\r' && *b != b'\n')
                .map_or(bytes.len() as u64, |i| p.byte() + i as u64);
            newlines.partition_point(|&n| n < start) as u64 + 1
        })
    };
    let row_error = |e: csv::Error| {
        let line = line_at(e.position());
        row_error(e, path, line)
    };
    let mut r = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(bytes.as_slice());
    let header = r.headers().map_err(row_error)?.clone();
    if header.iter().ne(COLUMNS) && header.iter().ne(COLUMNS[..8].iter().copied()) {
        return Err(PassCsvError::NotPasses {
            path: path.to_path_buf(),
            found: header.iter().collect::<Vec<_>>().join(","),
        });
    }
    let mut rows = Vec::new();
    for record in r.records() {
        let record = record.map_err(row_error)?;
        let line = line_at(record.position());
        let raw: RawRow = record.deserialize(Some(&header)).map_err(|e| {
            // A deserialize error carries no position: the record's.
            let l = e.position().map_or(line, |p| line_at(Some(p)));
            self::row_error(e, path, l)
        })?;
        let row = raw.row(path, line)?;
        check_row(&row).map_err(|(column, message)| PassCsvError::Row {
            path: path.to_path_buf(),
            line,
            column: column as u64,
            name: COLUMNS[column - 1].to_string(),
            message,
        })?;
        rows.push((row, line));
    }
    Ok(rows)
}

/// A row as read, before its size is parsed (so that a bad size is
/// reported with its line and column like any other field).
#[derive(Deserialize)]
struct RawRow {
    mesh: String,
    size: String,
    vs_loops: u32,
    fs_loops: u32,
    geometry_only: bool,
    vs_invocations: u64,
    fs_invocations: u64,
    pass_time_ns: f64,
    /// Absent from files of [`LEGACY_PASS_HEADER`]: one draw.
    #[serde(default = "one_draw")]
    draws: u32,
}

fn one_draw() -> u32 {
    1
}

impl RawRow {
    fn row(self, path: &Path, line: u64) -> Result<PassRow, PassCsvError> {
        let size = self.size.parse().map_err(|e: BadSize| PassCsvError::Row {
            path: path.to_path_buf(),
            line,
            column: 2,
            name: "size".into(),
            message: e.to_string(),
        })?;
        Ok(PassRow {
            mesh: self.mesh,
            size,
            vs_loops: self.vs_loops,
            fs_loops: self.fs_loops,
            geometry_only: self.geometry_only,
            vs_invocations: self.vs_invocations,
            fs_invocations: self.fs_invocations,
            pass_time_ns: self.pass_time_ns,
            draws: self.draws,
        })
    }
}

/// A csv error as a [`PassCsvError`] naming `line` and the column.
fn row_error(e: csv::Error, path: &Path, line: u64) -> PassCsvError {
    let path = path.to_path_buf();
    match e.into_kind() {
        csv::ErrorKind::Io(source) => PassCsvError::Io {
            action: "reading",
            path,
            source,
        },
        csv::ErrorKind::Deserialize { err, .. } => {
            let column = err.field().map_or(0, |f| f + 1);
            let name = usize::try_from(column)
                .ok()
                .and_then(|c| c.checked_sub(1))
                .and_then(|i| COLUMNS.get(i))
                .map_or("row", |n| n)
                .to_string();
            PassCsvError::Row {
                path,
                line,
                column,
                name,
                message: err.kind().to_string(),
            }
        }
        csv::ErrorKind::UnequalLengths { expected_len, len, .. } => PassCsvError::Row {
            path,
            line,
            column: 0,
            name: "row".into(),
            message: format!("{len} fields, expected {expected_len}"),
        },
        csv::ErrorKind::Utf8 { err, .. } => PassCsvError::Row {
            path,
            line,
            column: err.field() as u64 + 1,
            name: COLUMNS.get(err.field()).map_or("row", |n| n).to_string(),
            message: "not UTF-8".into(),
        },
        other => PassCsvError::Row {
            path,
            line,
            column: 0,
            name: "row".into(),
            message: format!("{other:?}"),
        },
    }
}

/// Pools repeated measurements of the same pass (same mesh, size, loop
/// counts, geometry-only flag and draws) into one row each, in the order each
/// pass was first measured: the recorded pass times of every measurement
/// are pooled and their median is the row's time; the counters are the
/// last measurement's.
pub fn pool(passes: impl IntoIterator<Item = (PassRow, Vec<f64>)>) -> Vec<PassRow> {
    let mut order: Vec<(PassRow, Vec<f64>)> = Vec::new();
    let mut index: std::collections::HashMap<PassKey, usize> = std::collections::HashMap::new();
    for (row, times) in passes {
        match index.get(&row.key()) {
            Some(&i) => {
                let (kept, pooled) = &mut order[i];
                pooled.extend(times);
                kept.vs_invocations = row.vs_invocations;
                kept.fs_invocations = row.fs_invocations;
            }
            None => {
                index.insert(row.key(), order.len());
                order.push((row, times));
            }
        }
    }
    order
        .into_iter()
        .map(|(mut row, times)| {
            if let Some(m) = median(&times) {
                row.pass_time_ns = m;
            }
            row
        })
        .collect()
}

#[cfg(test)]
mod tests;
