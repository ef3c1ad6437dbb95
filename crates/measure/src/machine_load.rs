//! The measuring machine's load, recorded beside a pass CSV.
//!
//! On lavapipe a pass's time stamps are host time: other work on the
//! machine lengthens them. So each `rendersim study --csv FILE` also
//! appends one line to `FILE.load.csv`: when, which command, how many rows
//! it appended, the processors, and the 1-, 5- and 15-minute load averages
//! (`/proc/loadavg`) as measuring began and as it ended. A reader can then
//! set a batch measured on a busy machine aside, or compare batches.

use std::path::{Path, PathBuf};

/// The load file's header.
pub const LOAD_HEADER: &str =
    "date_utc,command,rows,cpus,load1_start,load5_start,load15_start,load1_end,load5_end,load15_end";

/// The 1-, 5- and 15-minute load averages, where the system gives them
/// (Linux's `/proc/loadavg`); `None` elsewhere.
pub fn load_average() -> Option<[f64; 3]> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    parse_loadavg(&text)
}

/// The three averages at the head of a `/proc/loadavg` line.
pub fn parse_loadavg(text: &str) -> Option<[f64; 3]> {
    let mut it = text.split_whitespace().map(|w| w.parse::<f64>().ok());
    Some([it.next()??, it.next()??, it.next()??])
}

/// The load file beside `csv`: `FILE.load.csv`.
pub fn load_path(csv: &Path) -> PathBuf {
    let mut s = csv.as_os_str().to_owned();
    s.push(".load.csv");
    PathBuf::from(s)
}

/// One batch of measurements: what [`append_load`] writes.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadRecord {
    /// When, UTC (RFC 3339).
    pub date_utc: String,
    /// The command that measured.
    pub command: String,
    /// Rows it appended to the pass CSV.
    pub rows: usize,
    /// Processors the machine offers.
    pub cpus: usize,
    /// Load averages as measuring began.
    pub start: Option<[f64; 3]>,
    /// And as it ended.
    pub end: Option<[f64; 3]>,
}

/// Appends `r` to the load file beside `csv` ([`load_path`]), with the
/// header first when the file is new.
pub fn append_load(csv: &Path, r: &LoadRecord) -> std::io::Result<PathBuf> {
    let path = load_path(csv);
    let new = std::fs::metadata(&path).map_or(true, |m| m.len() == 0);
    let file = std::fs::OpenOptions::new().create(true).append(true).open(&path)?;
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(std::io::BufWriter::new(file));
    if new {
        w.write_record(LOAD_HEADER.split(','))?;
    }
    let avg = |a: Option<[f64; 3]>| {
        a.map_or([String::new(), String::new(), String::new()], |v| {
            v.map(|x| x.to_string())
        })
    };
    let mut row = vec![
        r.date_utc.clone(),
        r.command.clone(),
        r.rows.to_string(),
        r.cpus.to_string(),
    ];
    row.extend(avg(r.start));
    row.extend(avg(r.end));
    w.write_record(&row)?;
    w.flush()?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_load_file_sits_beside_the_csv_and_grows_by_a_line_a_batch() {
        assert_eq!(parse_loadavg("0.52 1.07 1.38 2/411 99\n"), Some([0.52, 1.07, 1.38]));
        assert_eq!(parse_loadavg("0.5 x"), None);
        let d = tempfile::tempdir().unwrap();
        let csv = d.path().join("passes.csv");
        let mut r = LoadRecord {
            date_utc: "2026-12-04T19:00:00Z".into(),
            command: "rendersim study all --csv \"p\"".into(),
            rows: 40,
            cpus: 2,
            start: Some([0.5, 1.0, 1.5]),
            end: None,
        };
        let p = append_load(&csv, &r).unwrap();
        assert_eq!(p, d.path().join("passes.csv.load.csv"));
        r.rows = 3;
        append_load(&csv, &r).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3, "{text}");
        assert_eq!(lines[0], LOAD_HEADER);
        assert_eq!(
            lines[1],
            "2026-12-04T19:00:00Z,\"rendersim study all --csv \"\"p\"\"\",40,2,0.5,1,1.5,,,"
        );
        // Every line has the header's columns (a CSV reader takes it).
        let mut rd = csv::Reader::from_path(&p).unwrap();
        assert_eq!(rd.headers().unwrap().len(), 10);
        assert!(rd.records().all(|r| r.unwrap().len() == 10));
    }
}
