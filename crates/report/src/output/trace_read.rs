//! Reading a trace back while it is written, for pictures.
//!
//! A [`SpanCollector`] is a `Write` sink for a [`super::trace::TraceWriter`]:
//! it parses the Trace Event Format events as they arrive (in chunks, so the
//! whole document is never held in memory) and keeps, per track, the spans
//! merged: a span that starts within `merge_gap_us` of the end of the last
//! one of the same track, name and argument extends it. A frame's thousands
//! of per-triangle spans become a few bars, which is what a picture a
//! thousand pixels wide can show. Counters named when the collector is made
//! are kept as steps (repeated values dropped); the others are skipped.
//!
//! ```
//! use rendersim_engine::Time;
//! use rendersim_report::output::trace::TraceWriter;
//! use rendersim_report::output::trace_read::SpanCollector;
//!
//! let c = SpanCollector::new(1.0, &["queue"]);
//! let mut t = TraceWriter::new(Box::new(c.clone()));
//! t.span(1, 2, "busy", Time(0), Time(1_000_000), None);
//! t.span(1, 2, "busy", Time(1_500_000), Time(3_000_000), None); // 0.5 us gap: merged
//! t.counter(1, "queue", "used", Time(0), 3);
//! t.finish().unwrap();
//! let r = c.take().unwrap();
//! assert_eq!(r.spans.len(), 1);
//! assert_eq!((r.spans[0].start_us, r.spans[0].end_us), (0.0, 3.0));
//! assert_eq!(r.counters["queue"], vec![(0.0, 3.0)]);
//! ```

use std::collections::{BTreeMap, HashMap};
use std::io::Write;
use std::sync::{Arc, Mutex};

use serde::Deserialize;

/// Bytes gathered before the parser runs over them.
const CHUNK: usize = 1 << 16;

/// One span read back (times in microseconds, the format's unit).
#[derive(Debug, Clone, PartialEq)]
pub struct ReadSpan {
    /// Track (`tid`).
    pub tid: u32,
    /// The span's name.
    pub name: String,
    /// Its numeric argument, if it had one (`("frame", 3)` gives 3).
    pub arg: Option<u64>,
    /// Start (us).
    pub start_us: f64,
    /// End (us).
    pub end_us: f64,
}

/// What a collector read.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadTrace {
    /// Merged spans, in the order their first piece was written.
    pub spans: Vec<ReadSpan>,
    /// Kept counters by name: `(time us, value)` steps.
    pub counters: BTreeMap<String, Vec<(f64, f64)>>,
    /// Instants: `(track, name, time us)`.
    pub instants: Vec<(u32, String, f64)>,
}

/// A trace event as far as pictures need it.
#[derive(Debug, Deserialize)]
struct RawEvent {
    ph: String,
    #[serde(default)]
    tid: Option<u32>,
    name: String,
    #[serde(default)]
    ts: Option<f64>,
    #[serde(default)]
    dur: Option<f64>,
    #[serde(default)]
    args: Option<serde_json::Map<String, serde_json::Value>>,
}

#[derive(Debug, Default)]
struct State {
    buf: Vec<u8>,
    /// Past the document's opening `{"...":...,"traceEvents":[`.
    in_array: bool,
    done: bool,
    error: Option<String>,
    merge_gap_us: f64,
    keep_counters: Vec<String>,
    out: ReadTrace,
    /// The last span index per (track, name, argument).
    last: HashMap<(u32, String, Option<u64>), usize>,
}

impl State {
    fn add(&mut self, e: RawEvent) {
        let first_number = |a: &Option<serde_json::Map<String, serde_json::Value>>| {
            a.as_ref().and_then(|m| m.values().next().and_then(|v| v.as_f64()))
        };
        match e.ph.as_str() {
            "X" => {
                let (Some(tid), Some(ts)) = (e.tid, e.ts) else { return };
                let end = ts + e.dur.unwrap_or(0.0);
                let arg = first_number(&e.args).map(|v| v as u64);
                let key = (tid, e.name, arg);
                if let Some(&i) = self.last.get(&key) {
                    let s = &mut self.out.spans[i];
                    if ts - s.end_us <= self.merge_gap_us && ts >= s.start_us {
                        s.end_us = s.end_us.max(end);
                        return;
                    }
                }
                self.out.spans.push(ReadSpan {
                    tid,
                    name: key.1.clone(),
                    arg,
                    start_us: ts,
                    end_us: end,
                });
                self.last.insert(key, self.out.spans.len() - 1);
            }
            "C" if self.keep_counters.contains(&e.name) => {
                let (Some(ts), Some(v)) = (e.ts, first_number(&e.args)) else {
                    return;
                };
                let steps = self.out.counters.entry(e.name).or_default();
                if steps.last().is_none_or(|l| l.1 != v) {
                    steps.push((ts, v));
                }
            }
            "i" => {
                if let (Some(tid), Some(ts)) = (e.tid, e.ts) {
                    self.out.instants.push((tid, e.name, ts));
                }
            }
            _ => {}
        }
    }

    /// Parses every complete event in the buffer.
    fn parse(&mut self) {
        if self.done || self.error.is_some() {
            return;
        }
        let mut pos = 0;
        if !self.in_array {
            // The header is `{"displayTimeUnit":"ms","traceEvents":[`.
            match self.buf.iter().position(|&b| b == b'[') {
                Some(i) => {
                    pos = i + 1;
                    self.in_array = true;
                }
                None => return,
            }
        }
        let buf = std::mem::take(&mut self.buf);
        loop {
            while pos < buf.len() && (buf[pos] == b',' || buf[pos].is_ascii_whitespace()) {
                pos += 1;
            }
            if pos >= buf.len() {
                break;
            }
            if buf[pos] == b']' {
                self.done = true;
                pos = buf.len();
                break;
            }
            let mut it = serde_json::Deserializer::from_slice(&buf[pos..]).into_iter::<RawEvent>();
            match it.next() {
                Some(Ok(ev)) => {
                    pos += it.byte_offset();
                    self.add(ev);
                }
                Some(Err(e)) if e.is_eof() => break,
                Some(Err(e)) => {
                    self.error = Some(e.to_string());
                    break;
                }
                None => break,
            }
        }
        self.buf = buf[pos..].to_vec();
    }
}

/// A `Write` sink that reads a trace as it is written (see the module
/// documentation). Clones share what was read.
#[derive(Debug, Clone)]
pub struct SpanCollector(Arc<Mutex<State>>);

impl SpanCollector {
    /// A collector merging spans closer than `merge_gap_us` microseconds
    /// and keeping the counters named in `counters`.
    pub fn new(merge_gap_us: f64, counters: &[&str]) -> Self {
        SpanCollector(Arc::new(Mutex::new(State {
            merge_gap_us,
            keep_counters: counters.iter().map(|s| s.to_string()).collect(),
            ..State::default()
        })))
    }

    fn state(&self) -> std::sync::MutexGuard<'_, State> {
        self.0.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// What was read, once the trace was finished (its closing `]` seen);
    /// an error names what could not be parsed.
    pub fn take(&self) -> Result<ReadTrace, TraceReadError> {
        let mut s = self.state();
        s.parse();
        if let Some(e) = &s.error {
            return Err(TraceReadError::Parse(e.clone()));
        }
        if !s.done {
            return Err(TraceReadError::Unfinished);
        }
        Ok(std::mem::take(&mut s.out))
    }
}

/// Why a trace could not be read back.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TraceReadError {
    /// Part of the trace did not parse (what the parser said).
    #[error("reading the trace back: {0}")]
    Parse(String),
    /// The trace's closing `]` never came.
    #[error("reading the trace back: the trace was not finished")]
    Unfinished,
}

impl Write for SpanCollector {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        let mut s = self.state();
        s.buf.extend_from_slice(b);
        if s.buf.len() >= CHUNK {
            s.parse();
        }
        Ok(b.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.state().parse();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Time;
    use crate::output::trace::TraceWriter;

    #[test]
    fn many_events_across_chunks_are_read_and_merged() {
        let c = SpanCollector::new(0.5, &["fifo"]);
        let mut t = TraceWriter::new(Box::new(c.clone()));
        // 20,000 spans of 1 us, every other 0.25 us apart (merged in pairs),
        // with a name that needs escaping.
        let mut at = 0u64;
        for i in 0..20_000u64 {
            let start = at;
            at += 1_000_000;
            t.span(1, 3, "busy \"q\"", Time(start), Time(at), None);
            at += if i % 2 == 0 { 250_000 } else { 2_000_000 };
            t.counter(1, "fifo", "used", Time(start), i % 3);
            t.counter(1, "other", "used", Time(start), i);
        }
        t.span(1, 1, "frame 1", Time(0), Time(5), Some(("frame", 1)));
        t.instant(1, 1, "input", Time(7_000_000));
        t.finish().unwrap();
        let r = c.take().unwrap();
        let busy: Vec<_> = r.spans.iter().filter(|s| s.tid == 3).collect();
        assert_eq!(busy.len(), 10_000);
        assert_eq!(busy[0].name, "busy \"q\"");
        assert!((busy[0].end_us - 2.25).abs() < 1e-9, "{:?}", busy[0]);
        assert_eq!(r.spans.last().unwrap().arg, Some(1));
        assert_eq!(r.counters["fifo"].len(), 20_000);
        assert!(!r.counters.contains_key("other"));
        assert_eq!(r.instants, vec![(1, "input".to_string(), 7.0)]);
    }

    #[test]
    fn an_unfinished_or_broken_trace_is_an_error() {
        let mut c = SpanCollector::new(0.0, &[]);
        c.write_all(b"{\"traceEvents\":[{\"ph\":\"X\"").unwrap();
        assert_eq!(c.take().unwrap_err(), TraceReadError::Unfinished);
        assert!(c.take().unwrap_err().to_string().contains("not finished"));
        let mut c = SpanCollector::new(0.0, &[]);
        c.write_all(b"{\"traceEvents\":[{\"ph\":3}]}").unwrap();
        let e = c.take().unwrap_err();
        assert!(matches!(e, TraceReadError::Parse(_)), "{e:?}");
        assert!(e.to_string().contains("reading the trace back"));
    }
}
