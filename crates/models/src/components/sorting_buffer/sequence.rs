//! Sequences of state ids for the sorting buffer: read from a file, or
//! built (the lecture's worst case for LRU; independent random states).
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

//!
//! **Random states** (`random:N:D:S:SEED`): N ids drawn independently,
//! state i of D with probability proportional to 1 / (i + 1)^S (Zipf's law;
//! S = 0 is uniform), from the named RNG stream `sortbuf.sequence` of
//! SEED. The average case the lecture's verdict on round robin speaks of
//! ("worst cases say little about practical performance").

use std::path::Path;

use rand::Rng;

use super::{SortBufferError, StateId};
use crate::engine::RngStreams;

/// Largest N and D of [`random_states`].
pub const MAX_RANDOM_STATES: u64 = 1 << 24;

/// `n` ids drawn independently from `d` states with Zipf exponent `s` (0:
/// uniform) from the stream `sortbuf.sequence` of `seed` (see the module).
pub fn random_states(n: u64, d: u64, s: f64, seed: u64) -> Result<Vec<StateId>, SortBufferError> {
    if !(1..=MAX_RANDOM_STATES).contains(&n) || !(1..=MAX_RANDOM_STATES).contains(&d) {
        return Err(SortBufferError::Source(format!(
            "random:{n}:{d}:...: the length N and the states D must be between 1 and {MAX_RANDOM_STATES}"
        )));
    }
    if !(s.is_finite() && (0.0..=10.0).contains(&s)) {
        return Err(SortBufferError::Source(format!(
            "random:{n}:{d}:{s}:...: the Zipf exponent S must be a number from 0 to 10"
        )));
    }
    // Cumulative weights, drawn by binary search.
    let mut cumulative = Vec::with_capacity(d as usize);
    let mut total = 0.0;
    for i in 0..d {
        total += ((i + 1) as f64).powf(-s);
        cumulative.push(total);
    }
    let mut rng = RngStreams::new(seed).stream("sortbuf.sequence");
    Ok((0..n)
        .map(|_| {
            let u = rng.random::<f64>() * total;
            cumulative.partition_point(|&c| c <= u).min(d as usize - 1) as StateId
        })
        .collect())
}

/// `random:N:D:S:SEED` parsed, or the error naming what is wrong.
fn random_spec(spec: &str, rest: &str) -> Result<Vec<StateId>, SortBufferError> {
    let bad = || {
        SortBufferError::Source(format!(
            "{spec:?}: expected random:N:D:S:SEED (N ids, D states, Zipf exponent S >= 0, 0 = uniform; SEED an integer)"
        ))
    };
    let parts: Vec<&str> = rest.split(':').collect();
    let [n, d, s, seed] = parts.as_slice() else {
        return Err(bad());
    };
    let (n, d, s, seed) = (
        n.parse::<u64>().map_err(|_| bad())?,
        d.parse::<u64>().map_err(|_| bad())?,
        s.parse::<f64>().map_err(|_| bad())?,
        seed.parse::<u64>().map_err(|_| bad())?,
    );
    random_states(n, d, s, seed)
}

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

/// Whether `spec` is built rather than read from a file.
pub fn is_generated(spec: &str) -> bool {
    spec.starts_with("lru-worst:") || spec.starts_with("random:")
}

/// A sequence from a spec: `lru-worst:M`, `random:N:D:S:SEED`, or a file
/// path (relative paths from `base`). Returns the sequence and the name to
/// report.
pub fn sequence_from_spec(spec: &str, base: &Path) -> Result<Vec<StateId>, SortBufferError> {
    if let Some(rest) = spec.strip_prefix("random:") {
        return random_spec(spec, rest);
    }
    if let Some(m) = spec.strip_prefix("lru-worst:") {
        let m: u64 = m.parse().map_err(|_| {
            SortBufferError::Source(format!("{spec:?}: expected lru-worst:M with M a positive integer"))
        })?;
        return lru_worst(m);
    }
    if spec.trim().is_empty() {
        return Err(SortBufferError::Source(
            "the sequence is empty: give a file of state ids, lru-worst:M or random:N:D:S:SEED".into(),
        ));
    }
    let path = base.join(spec);
    let meta =
        std::fs::metadata(&path).map_err(|e| SortBufferError::Source(format!("reading sequence file {spec}: {e}")))?;
    if meta.is_dir() {
        return Err(SortBufferError::Source(format!(
            "{spec} is a folder; give a file of state ids, lru-worst:M or random:N:D:S:SEED"
        )));
    }
    let bytes = crate::limits::read_input(&path, crate::limits::InputKind::Data)
        .map_err(|e| SortBufferError::Source(format!("reading sequence file {spec}: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        SortBufferError::Source(format!(
            "{spec}: not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ))
    })?;
    parse_sequence(&text, spec)
}
