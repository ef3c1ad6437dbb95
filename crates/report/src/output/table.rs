//! Per-row tables as CSV, through the `csv` crate: every system's per-row
//! table (`frames.csv`) and the experiment tables are written here, so a
//! cell holding a comma, a quote or a line break is quoted, never splitting
//! a row.
//!
//! ```
//! use rendersim_report::output::table::{number, write_table};
//!
//! let mut out = Vec::new();
//! let rows = vec![
//!     vec!["grid, 8x8".to_string(), number(1.5)],
//!     vec!["say \"hi\"".to_string(), number(f64::NAN)],
//! ];
//! write_table(&mut out, &["name", "value"], rows).unwrap();
//! assert_eq!(String::from_utf8(out).unwrap(), "name,value\n\"grid, 8x8\",1.5\n\"say \"\"hi\"\"\",\n");
//! ```

use std::io::Write;

/// A number as a table cell: Rust's shortest exact form, empty for NaN
/// (a value that does not exist for that row).
pub fn number(v: f64) -> String {
    if v.is_nan() { String::new() } else { format!("{v}") }
}

/// Writes `header` and `rows` as CSV into `w` (buffered; flushed at the end).
pub fn write_table<W: Write, S: AsRef<str>>(
    w: W,
    header: &[S],
    rows: impl IntoIterator<Item = Vec<String>>,
) -> std::io::Result<()> {
    let mut csv = csv::Writer::from_writer(w);
    csv.write_record(header.iter().map(|h| h.as_ref()))?;
    for row in rows {
        csv.write_record(&row)?;
    }
    csv.flush()
}

/// Writes a table of numbers (cells through [`number`]): the per-row
/// tables of the systems whose rows are all numeric.
pub fn write_number_table<W: Write, S: AsRef<str>>(w: W, header: &[S], rows: &[Vec<f64>]) -> std::io::Result<()> {
    write_table(w, header, rows.iter().map(|r| r.iter().map(|&v| number(v)).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_with_commas_quotes_and_newlines_round_trip() {
        let names = ["plain", "a, b", "say \"x\"", "two\nlines", ""];
        let mut out = Vec::new();
        write_table(
            &mut out,
            &["name", "v"],
            names
                .iter()
                .enumerate()
                .map(|(i, n)| vec![n.to_string(), number(i as f64)]),
        )
        .unwrap();
        let mut r = csv::Reader::from_reader(out.as_slice());
        let back: Vec<(String, String)> = r
            .records()
            .map(|x| {
                let x = x.unwrap();
                (x[0].to_string(), x[1].to_string())
            })
            .collect();
        assert_eq!(back.len(), names.len());
        for (i, (n, v)) in back.iter().enumerate() {
            assert_eq!(n, names[i]);
            assert_eq!(v, &i.to_string());
        }
    }
}
