//! Sequences of state ids for the sorting buffer: read from a file, or
//! built (the lecture's worst case for LRU).
//!
//! **File format.** State ids are non-negative integers separated by
//! whitespace (spaces, tabs, newlines, in any mix); `#` starts a comment
//! that runs to the end of the line. Anything else is an error naming the
//! line and column. A file without ids is an error.
//!
//! **The worst case for LRU** (paper 001, slide "Beispiel: LRU"). The
//! slide's formulas were lost when the lecture was turned into text; what
//! survives is "m even without loss of generality", an input, LRU's cost
//! and the offline cost "2m colour changes". [`lru_worst`] rebuilds an
//! input of that shape, after the Ω(√k) lower bound for LRU of Räcke,
//! Sohler & Westermann that the slide presents: m thin states a_1..a_m and
//! m fat states b_1..b_m; the input is m blocks, block i being
//! `a_1 a_2 .. a_m` followed by `b_i` repeated m² + 1 times. With a buffer of
//! K = m² + 1 slots the offline strategy keeps every a (m² elements) and
//! sends each b run as it comes: 2m changes, which equals the lower bound
//! (2m distinct states), so it is optimal. LRU sees the b run's stamp as
//! the newest and sends the a states one by one, each a few elements at a
//! time, in every block: m(m + 1) changes, a ratio of (m + 1) / 2 ≈ √K / 2
//! (measured in `tests/it/sortbuf.rs` and `docs/lod-and-state-sorting.md`).

use std::path::Path;

use super::{SortBufferError, StateId};

/// Largest m of [`lru_worst`] ([`crate::limits::MAX_LRU_WORST_M`]).
pub const MAX_LRU_WORST_M: u64 = crate::limits::MAX_LRU_WORST_M;

/// Parses a sequence file's text; `source` names it in errors.
pub fn parse_sequence(text: &str, source: &str) -> Result<Vec<StateId>, SortBufferError> {
    let mut seq = Vec::new();
    for (li, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        let mut col = 0usize;
        for piece in line.split_inclusive(char::is_whitespace) {
            let token = piece.trim_end();
            if !token.is_empty() {
                let id = token.parse::<StateId>().map_err(|_| SortBufferError::BadToken {
                    source_name: source.to_string(),
                    line: li + 1,
                    column: line[..col].chars().count() + 1,
                    token: token.to_string(),
                })?;
                seq.push(id);
            }
            col += piece.len();
        }
    }
    if seq.is_empty() {
        return Err(SortBufferError::Empty {
            source_name: source.to_string(),
        });
    }
    Ok(seq)
}

/// The lecture's worst case for LRU with parameter `m` (see the module):
/// thin states are 0..m, fat state b_i is m + i. Its intended buffer is
/// `m² + 1` slots.
pub fn lru_worst(m: u64) -> Result<Vec<StateId>, SortBufferError> {
    if m == 0 || m > MAX_LRU_WORST_M {
        return Err(SortBufferError::Source(format!(
            "lru-worst:{m}: m must be between 1 and {MAX_LRU_WORST_M}"
        )));
    }
    let run = m * m + 1;
    let mut seq = Vec::with_capacity((m * (m + run)) as usize);
    for i in 0..m {
        seq.extend(0..m);
        seq.extend(std::iter::repeat_n(m + i, run as usize));
    }
    Ok(seq)
}

/// A sequence from a spec: `lru-worst:M`, or a file path (relative paths
/// from `base`). Returns the sequence and the name to report.
pub fn sequence_from_spec(spec: &str, base: &Path) -> Result<Vec<StateId>, SortBufferError> {
    if let Some(m) = spec.strip_prefix("lru-worst:") {
        let m: u64 = m.parse().map_err(|_| {
            SortBufferError::Source(format!("{spec:?}: expected lru-worst:M with M a positive integer"))
        })?;
        return lru_worst(m);
    }
    let path = base.join(spec);
    let meta =
        std::fs::metadata(&path).map_err(|e| SortBufferError::Source(format!("reading sequence file {spec}: {e}")))?;
    if meta.is_dir() {
        return Err(SortBufferError::Source(format!(
            "{spec} is a folder; give a file of state ids or lru-worst:M"
        )));
    }
    let bytes =
        std::fs::read(&path).map_err(|e| SortBufferError::Source(format!("reading sequence file {spec}: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        SortBufferError::Source(format!(
            "{spec}: not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ))
    })?;
    parse_sequence(&text, spec)
}
