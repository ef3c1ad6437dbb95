//! A trace kept in memory as merged spans, for pictures.
//!
//! A [`SpanCollector`] is the other target of a
//! [`super::trace::TraceWriter`] (made with
//! [`TraceWriter::collecting`](super::trace::TraceWriter::collecting)): the
//! systems trace as they always do, and instead of Trace Event Format JSON
//! the collector keeps, per track, the spans merged: a span that starts
//! within `merge_gap_us` of the end of the last one of the same track, name
//! and argument extends it. A frame's thousands of per-triangle spans
//! become a few bars, which is what a picture a thousand pixels wide can
//! show. Counters named when the collector is made are kept as steps
//! (repeated values dropped); the others are skipped. Nothing is formatted
//! or parsed, so a picture costs little more than the run itself.
//!
//! Times are microseconds, the trace format's unit, computed as the JSON
//! writer computes them, so a collector reads exactly what a reader of the
//! written trace would.
//!
//! ```
//! use rendersim_engine::Time;
//! use rendersim_report::output::trace::TraceWriter;
//! use rendersim_report::output::span_collector::SpanCollector;
//!
//! let c = SpanCollector::new(1.0, &["queue"]);
//! let mut t = TraceWriter::collecting(c.clone());
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
use std::sync::{Arc, Mutex};

/// One merged span (times in microseconds, the trace format's unit).
#[derive(Debug, Clone, PartialEq)]
pub struct ReadSpan {
    /// Track (`tid`).
    pub tid: u32,
    /// The span's name.
    pub name: String,
    /// Its numeric argument, if it had one: of several, the one whose name
    /// sorts first (`[("frame", 3), ("draw", 12)]` gives 12).
    pub arg: Option<u64>,
    /// Start (us).
    pub start_us: f64,
    /// End (us).
    pub end_us: f64,
}

/// What a collector kept.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadTrace {
    /// Merged spans, in the order their first piece was traced.
    pub spans: Vec<ReadSpan>,
    /// Kept counters by name: `(time us, value)` steps.
    pub counters: BTreeMap<String, Vec<(f64, f64)>>,
    /// Instants: `(track, name, time us)`.
    pub instants: Vec<(u32, String, f64)>,
}

#[derive(Debug, Default)]
struct State {
    finished: bool,
    merge_gap_us: f64,
    keep_counters: Vec<String>,
    out: ReadTrace,
    /// The last span index per (track, argument), then name: the name is
    /// looked up as a `&str`, so a span that merges allocates nothing.
    last: HashMap<(u32, Option<u64>), HashMap<String, usize>>,
}

/// A trace kept as merged spans (see the module documentation). Clones
/// share what was kept.
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

    /// A span on track `tid` from `ts` lasting `dur` (us).
    pub(crate) fn span(&self, tid: u32, name: &str, ts: f64, dur: f64, arg: Option<u64>) {
        let mut s = self.state();
        let s = &mut *s;
        let end = ts + dur;
        let names = s.last.entry((tid, arg)).or_default();
        if let Some(&i) = names.get(name) {
            let span = &mut s.out.spans[i];
            if ts - span.end_us <= s.merge_gap_us && ts >= span.start_us {
                span.end_us = span.end_us.max(end);
                return;
            }
            names.insert(name.to_string(), s.out.spans.len());
        } else {
            names.insert(name.to_string(), s.out.spans.len());
        }
        s.out.spans.push(ReadSpan {
            tid,
            name: name.to_string(),
            arg,
            start_us: ts,
            end_us: end,
        });
    }

    /// Counter `name` taking `value` from `ts` (us) on.
    pub(crate) fn counter(&self, name: &str, ts: f64, value: f64) {
        let mut s = self.state();
        if !s.keep_counters.iter().any(|k| k == name) {
            return;
        }
        let steps = match s.out.counters.get_mut(name) {
            Some(steps) => steps,
            None => s.out.counters.entry(name.to_string()).or_default(),
        };
        if steps.last().is_none_or(|l| l.1 != value) {
            steps.push((ts, value));
        }
    }

    /// An instant on track `tid` at `ts` (us).
    pub(crate) fn instant(&self, tid: u32, name: &str, ts: f64) {
        self.state().out.instants.push((tid, name.to_string(), ts));
    }

    /// Marks the trace finished ([`super::trace::TraceWriter::finish`]).
    pub(crate) fn finish(&self) {
        self.state().finished = true;
    }

    /// What was kept, once the trace was finished.
    pub fn take(&self) -> Result<ReadTrace, TraceReadError> {
        let mut s = self.state();
        if !s.finished {
            return Err(TraceReadError::Unfinished);
        }
        Ok(std::mem::take(&mut s.out))
    }
}

/// Why a collected trace could not be taken.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TraceReadError {
    /// The trace was never finished (its writer dropped unfinished).
    #[error("collecting the trace: the trace was not finished")]
    Unfinished,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Time;
    use crate::output::trace::TraceWriter;

    /// What a reader of the written JSON would keep: the oracle the
    /// collector must match.
    fn from_json(text: &[u8], gap: f64, keep: &str) -> ReadTrace {
        let v: serde_json::Value = serde_json::from_slice(text).unwrap();
        let mut out = ReadTrace::default();
        let mut last: HashMap<(u32, String, Option<u64>), usize> = HashMap::new();
        for e in v["traceEvents"].as_array().unwrap() {
            let first = e["args"].as_object().and_then(|m| m.values().next()?.as_f64());
            let tid = e["tid"].as_u64().map(|t| t as u32);
            let ts = e["ts"].as_f64();
            match e["ph"].as_str().unwrap() {
                "X" => {
                    let (tid, ts) = (tid.unwrap(), ts.unwrap());
                    let end = ts + e["dur"].as_f64().unwrap();
                    let key = (tid, e["name"].as_str().unwrap().to_string(), first.map(|a| a as u64));
                    if let Some(&i) = last.get(&key) {
                        let s: &mut ReadSpan = &mut out.spans[i];
                        if ts - s.end_us <= gap && ts >= s.start_us {
                            s.end_us = s.end_us.max(end);
                            continue;
                        }
                    }
                    out.spans.push(ReadSpan {
                        tid,
                        name: key.1.clone(),
                        arg: key.2,
                        start_us: ts,
                        end_us: end,
                    });
                    last.insert(key, out.spans.len() - 1);
                }
                "C" if e["name"] == keep => {
                    let steps = out.counters.entry(keep.to_string()).or_default();
                    let v = first.unwrap();
                    if steps.last().is_none_or(|l| l.1 != v) {
                        steps.push((ts.unwrap(), v));
                    }
                }
                "i" => out
                    .instants
                    .push((tid.unwrap(), e["name"].as_str().unwrap().to_string(), ts.unwrap())),
                _ => {}
            }
        }
        out
    }

    /// A `Write` whose bytes can be read after the writer is consumed.
    #[derive(Clone, Default)]
    struct Shared(Arc<Mutex<Vec<u8>>>);
    impl std::io::Write for Shared {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    /// The same events into a JSON writer and a collector.
    fn both(events: impl Fn(&mut TraceWriter), gap: f64, keep: &str) -> (ReadTrace, ReadTrace) {
        let buf = Shared::default();
        let mut json = TraceWriter::new(Box::new(buf.clone()));
        let c = SpanCollector::new(gap, &[keep]);
        let mut kept = TraceWriter::collecting(c.clone());
        events(&mut json);
        events(&mut kept);
        json.finish().unwrap();
        kept.finish().unwrap();
        let text = buf.0.lock().unwrap().clone();
        (c.take().unwrap(), from_json(&text, gap, keep))
    }

    #[test]
    fn the_collector_keeps_what_a_reader_of_the_json_would() {
        let (kept, read) = both(
            |t| {
                // 20,000 spans of 1 us, every other 0.25 us apart (merged in
                // pairs), at times whose microseconds are not exact in binary.
                let mut at = 0u64;
                for i in 0..20_000u64 {
                    let start = at;
                    at += 1_000_003;
                    t.span(1, 3, "busy \"q\"", Time(start), Time(at), None);
                    t.span_args(
                        1,
                        4,
                        "draw",
                        Time(start),
                        Time(at),
                        &[("frame", i / 7), ("draw", i % 3)],
                    );
                    at += if i % 2 == 0 { 250_007 } else { 2_000_001 };
                    t.counter(1, "fifo", "used", Time(start), i % 3);
                    t.counter(1, "other", "used", Time(start), i);
                }
                t.span(1, 1, "frame 1", Time(0), Time(5), Some(("frame", 1)));
                t.instant(1, 1, "input", Time(7_000_000));
            },
            0.5,
            "fifo",
        );
        assert_eq!(kept, read);
        let busy: Vec<_> = kept.spans.iter().filter(|s| s.tid == 3).collect();
        assert_eq!(busy.len(), 10_000);
        assert_eq!(busy[0].name, "busy \"q\"");
        assert!((busy[0].end_us - 2.250013).abs() < 1e-9, "{:?}", busy[0]);
        assert_eq!(kept.spans.last().unwrap().arg, Some(1));
        // Of two arguments, the one whose name sorts first.
        assert!(kept.spans.iter().filter(|s| s.tid == 4).all(|s| s.arg.unwrap() < 3));
        assert_eq!(kept.counters["fifo"].len(), 20_000);
        assert!(!kept.counters.contains_key("other"));
        assert_eq!(kept.instants, vec![(1, "input".to_string(), 7.0)]);
    }

    #[test]
    fn an_unfinished_trace_is_an_error() {
        let c = SpanCollector::new(0.0, &[]);
        let mut t = TraceWriter::collecting(c.clone());
        t.span(1, 1, "x", Time(0), Time(1), None);
        assert_eq!(c.take().unwrap_err(), TraceReadError::Unfinished);
        assert!(c.take().unwrap_err().to_string().contains("not finished"));
        t.finish().unwrap();
        assert_eq!(c.take().unwrap().spans.len(), 1);
    }
}
