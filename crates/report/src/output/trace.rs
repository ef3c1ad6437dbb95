//! Chrome / Perfetto trace JSON (the "Trace Event Format"), written as the
//! simulation makes it: memory stays flat however many frames are traced.
//!
//! A [`TraceWriter`] knows nothing of the systems: they name their own
//! processes and tracks and hand it spans (complete `"X"` events), instants
//! and counters in simulated time. The file opens in ui.perfetto.dev or
//! chrome://tracing, which sort events by time themselves, so events may be
//! written in any order.
//!
//! Write errors are kept, not raised on the hot path: the first one stops
//! further writing and is returned by [`TraceWriter::finish`].
//!
//! A writer carries the [`TraceDetail`] asked for; systems read it and
//! leave out what is finer. Flow events ([`TraceWriter::flow`]) draw arrows
//! between the slices of one frame on different tracks.
//!
//! A writer made with [`TraceWriter::collecting`] formats nothing: it hands
//! the same events to a [`SpanCollector`], which keeps them as merged spans
//! for a picture (the timeline).
//!
//! ```
//! use rendersim_engine::Time;
//! use rendersim_report::output::trace::TraceWriter;
//!
//! let mut t = TraceWriter::new(Box::new(Vec::new()));
//! t.process(1, "example");
//! t.thread(1, 1, "CPU");
//! t.span(1, 1, "work", Time(0), Time(2_000_000), None);
//! t.counter(1, "queue", "used", Time(1_000_000), 3);
//! assert_eq!(t.finish().unwrap(), 4); // two names, a span and a counter
//! ```

use std::io::Write;

use serde::Serialize;

use crate::engine::Time;
use crate::output::span_collector::SpanCollector;

/// Microseconds (the format's unit) from picoseconds.
fn us(t: Time) -> f64 {
    t.0 as f64 / 1e6
}

/// One event of the Trace Event Format (only the fields rendersim uses;
/// those an event does not have stay at their default, left out).
#[derive(Debug, Default, Serialize)]
struct Event<'a> {
    /// Phase: `M` metadata, `X` complete span, `i` instant, `C` counter.
    ph: &'static str,
    pid: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    tid: Option<u32>,
    name: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    ts: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    dur: Option<f64>,
    /// Instant scope (`t`: the thread).
    #[serde(skip_serializing_if = "Option::is_none")]
    s: Option<&'static str>,
    /// Flow events: their category, id and binding point (`e`: the
    /// enclosing slice).
    #[serde(skip_serializing_if = "Option::is_none")]
    cat: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    id: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    bp: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    args: Option<Args<'a>>,
}

/// An event's `args`.
#[derive(Debug, Serialize)]
#[serde(untagged)]
enum Args<'a> {
    Name { name: &'a str },
    SortIndex { sort_index: u32 },
    One(std::collections::BTreeMap<&'a str, u64>),
}

/// How much a trace shows (`--trace-detail`), coarsest first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum TraceDetail {
    /// One slice a frame per track (CPU, GPU, display) and the flows
    /// between them: a few hundred bytes a frame.
    Frame,
    /// Also every unit's states, with the geometry and fragment stages'
    /// work merged into one slice a draw.
    #[default]
    Draw,
    /// Every state change of every unit: a slice a triangle a stage (about
    /// 7 MB a frame of the default model).
    Triangle,
}

impl TraceDetail {
    /// The names `--trace-detail` takes.
    pub const NAMES: [&'static str; 3] = ["frame", "draw", "triangle"];

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

impl std::str::FromStr for TraceDetail {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "frame" => Ok(TraceDetail::Frame),
            "draw" => Ok(TraceDetail::Draw),
            "triangle" => Ok(TraceDetail::Triangle),
            other => Err(format!(
                "unknown trace detail {other:?} (expected frame, draw or triangle)"
            )),
        }
    }
}

/// Where a flow event sits in its chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlowStep {
    /// The first slice.
    Start,
    /// A slice between.
    Step,
    /// The last slice.
    End,
}

/// Where a trace goes.
enum Target {
    /// Trace Event Format JSON.
    Json(Box<dyn Write + Send>),
    /// Merged spans kept in memory, for pictures.
    Spans(SpanCollector),
}

/// A trace being written (see the module documentation).
pub struct TraceWriter {
    out: Target,
    events: u64,
    bytes: u64,
    detail: TraceDetail,
    error: Option<std::io::Error>,
}

impl std::fmt::Debug for TraceWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TraceWriter").field("events", &self.events).finish()
    }
}

impl TraceWriter {
    /// Starts a trace on `out` (buffer it: events are written one by one).
    pub fn new(mut out: Box<dyn Write + Send>) -> Self {
        let head = b"{\"displayTimeUnit\":\"ms\",\"traceEvents\":[";
        let r = out.write_all(head);
        let mut t = TraceWriter {
            out: Target::Json(out),
            events: 0,
            bytes: head.len() as u64,
            detail: TraceDetail::default(),
            error: None,
        };
        t.keep(r);
        t
    }

    /// A trace kept in `collector` as merged spans instead of written
    /// ([`SpanCollector`]): what a picture of a run needs, without
    /// formatting JSON and reading it back. [`Self::bytes`] stays 0.
    pub fn collecting(collector: SpanCollector) -> Self {
        TraceWriter {
            out: Target::Spans(collector),
            events: 0,
            bytes: 0,
            detail: TraceDetail::default(),
            error: None,
        }
    }

    /// The writer at detail `d`.
    pub fn with_detail(mut self, d: TraceDetail) -> Self {
        self.detail = d;
        self
    }

    /// The detail asked for.
    pub fn detail(&self) -> TraceDetail {
        self.detail
    }

    /// Bytes written so far.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    fn keep(&mut self, r: std::io::Result<()>) {
        if let Err(e) = r
            && self.error.is_none()
        {
            self.error = Some(e);
        }
    }

    fn event(&mut self, e: &Event<'_>) {
        if self.error.is_some() {
            return;
        }
        let out = match &mut self.out {
            Target::Json(out) => out,
            Target::Spans(c) => {
                self.events += 1;
                return collect(c, e);
            }
        };
        let mut counted = Counted { out, bytes: 0 };
        let r = (|| {
            if self.events > 0 {
                counted.write_all(b",")?;
            }
            serde_json::to_writer(&mut counted, e).map_err(std::io::Error::from)
        })();
        self.bytes += counted.bytes;
        self.events += 1;
        self.keep(r);
    }

    /// Names process `pid` (a group of tracks) and sorts it by its number.
    pub fn process(&mut self, pid: u32, name: &str) {
        self.event(&Event {
            ph: "M",
            pid,
            name: "process_name",
            args: Some(Args::Name { name }),
            ..Default::default()
        });
    }

    /// Sorts process `pid` by `index` among the processes.
    pub fn process_order(&mut self, pid: u32, index: u32) {
        self.event(&Event {
            ph: "M",
            pid,
            name: "process_sort_index",
            args: Some(Args::SortIndex { sort_index: index }),
            ..Default::default()
        });
    }

    /// Names track `tid` of process `pid`.
    pub fn thread(&mut self, pid: u32, tid: u32, name: &str) {
        self.event(&Event {
            ph: "M",
            pid,
            tid: Some(tid),
            name: "thread_name",
            args: Some(Args::Name { name }),
            ..Default::default()
        });
    }

    /// Names track `tid` and sorts it by its number.
    pub fn track(&mut self, pid: u32, tid: u32, name: &str) {
        self.thread(pid, tid, name);
        self.event(&Event {
            ph: "M",
            pid,
            tid: Some(tid),
            name: "thread_sort_index",
            args: Some(Args::SortIndex { sort_index: tid }),
            ..Default::default()
        });
    }

    /// A span from `start` to `end` on a track, with an optional numeric
    /// argument (`("index", 3)`).
    pub fn span(&mut self, pid: u32, tid: u32, name: &str, start: Time, end: Time, arg: Option<(&str, u64)>) {
        self.span_args(pid, tid, name, start, end, arg.as_slice());
    }

    /// A span with several numeric arguments (`[("frame", 3), ("draw", 12)]`).
    pub fn span_args(&mut self, pid: u32, tid: u32, name: &str, start: Time, end: Time, args: &[(&str, u64)]) {
        self.event(&Event {
            ph: "X",
            pid,
            tid: Some(tid),
            name,
            ts: Some(us(start)),
            dur: Some(us(end) - us(start)),
            args: (!args.is_empty()).then(|| Args::One(args.iter().copied().collect())),
            ..Default::default()
        });
    }

    /// One point of flow `id` (an arrow from slice to slice, drawn by
    /// Perfetto): it binds to the slice enclosing `at` on track `tid`, so
    /// `at` should fall inside one. `name` groups the flows.
    pub fn flow(&mut self, pid: u32, tid: u32, name: &str, id: u64, at: Time, step: FlowStep) {
        let ph = match step {
            FlowStep::Start => "s",
            FlowStep::Step => "t",
            FlowStep::End => "f",
        };
        self.event(&Event {
            ph,
            pid,
            tid: Some(tid),
            name,
            ts: Some(us(at)),
            cat: Some("frame"),
            id: Some(id),
            bp: (step == FlowStep::End).then_some("e"),
            ..Default::default()
        });
    }

    /// A point in time on a track.
    pub fn instant(&mut self, pid: u32, tid: u32, name: &str, at: Time) {
        self.event(&Event {
            ph: "i",
            pid,
            tid: Some(tid),
            name,
            ts: Some(us(at)),
            s: Some("t"),
            ..Default::default()
        });
    }

    /// A counter track `name` taking `value` (shown as `series`) from `at` on.
    pub fn counter(&mut self, pid: u32, name: &str, series: &str, at: Time, value: u64) {
        self.event(&Event {
            ph: "C",
            pid,
            name,
            ts: Some(us(at)),
            args: Some(Args::One([(series, value)].into_iter().collect())),
            ..Default::default()
        });
    }

    /// Events written so far.
    pub fn events(&self) -> u64 {
        self.events
    }

    /// Closes the trace and flushes it; returns the number of events, or the
    /// first write error.
    pub fn finish(mut self) -> std::io::Result<u64> {
        let r = match &mut self.out {
            Target::Json(out) => out.write_all(b"]}").and_then(|()| out.flush()),
            Target::Spans(c) => {
                c.finish();
                Ok(())
            }
        };
        self.keep(r);
        match self.error.take() {
            Some(e) => Err(e),
            None => Ok(self.events),
        }
    }
}

/// Hands one event to a collector: spans, kept counters and instants;
/// names and flows draw nothing.
fn collect(c: &SpanCollector, e: &Event<'_>) {
    // The first argument in name order, as a reader of the JSON sees it.
    let first = || match &e.args {
        Some(Args::One(m)) => m.values().next().copied(),
        _ => None,
    };
    match (e.ph, e.tid, e.ts) {
        ("X", Some(tid), Some(ts)) => c.span(tid, e.name, ts, e.dur.unwrap_or(0.0), first()),
        ("C", _, Some(ts)) => {
            if let Some(v) = first() {
                c.counter(e.name, ts, v as f64)
            }
        }
        ("i", Some(tid), Some(ts)) => c.instant(tid, e.name, ts),
        _ => {}
    }
}

/// A `Write` that counts what passes through.
struct Counted<'a> {
    out: &'a mut Box<dyn Write + Send>,
    bytes: u64,
}

impl Write for Counted<'_> {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        let n = self.out.write(b)?;
        self.bytes += n as u64;
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Arc, Mutex};

    /// A `Write` whose bytes can be read after the writer is consumed.
    #[derive(Clone, Default)]
    struct Shared(Arc<Mutex<Vec<u8>>>);
    impl Write for Shared {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn events_form_one_valid_document() {
        let buf = Shared::default();
        let mut t = TraceWriter::new(Box::new(buf.clone()));
        t.process(1, "p \"quoted\", with comma");
        t.track(1, 2, "GPU");
        t.span(1, 2, "draw", Time(1_000_000), Time(3_500_000), Some(("index", 7)));
        t.instant(1, 2, "input", Time(0));
        t.counter(1, "FIFO", "used", Time(2_000_000), 4);
        assert_eq!(t.finish().unwrap(), 6);
        let v: serde_json::Value = serde_json::from_slice(&buf.0.lock().unwrap()).unwrap();
        let ev = v["traceEvents"].as_array().unwrap();
        assert_eq!(ev.len(), 6);
        assert_eq!(ev[0]["args"]["name"], "p \"quoted\", with comma");
        assert_eq!(ev[3]["ts"], 1.0);
        assert_eq!(ev[3]["dur"], 2.5);
        assert_eq!(ev[3]["args"]["index"], 7);
        assert_eq!(ev[4]["s"], "t");
        assert_eq!(ev[5]["args"]["used"], 4);
        assert_eq!(v["displayTimeUnit"], "ms");
    }

    #[test]
    fn flows_spans_with_arguments_and_the_byte_count() {
        let buf = Shared::default();
        let mut t = TraceWriter::new(Box::new(buf.clone())).with_detail(TraceDetail::Frame);
        assert_eq!(t.detail(), TraceDetail::Frame);
        t.span_args(1, 2, "draw 3", Time(0), Time(2_000_000), &[("frame", 4), ("draw", 3)]);
        t.flow(1, 2, "frame 4", 5, Time(1_000_000), FlowStep::Start);
        t.flow(1, 3, "frame 4", 5, Time(3_000_000), FlowStep::Step);
        t.flow(1, 4, "frame 4", 5, Time(5_000_000), FlowStep::End);
        let bytes = t.bytes();
        t.finish().unwrap();
        let text = buf.0.lock().unwrap().clone();
        assert_eq!(bytes + 2, text.len() as u64, "all but the closing ]}}");
        let v: serde_json::Value = serde_json::from_slice(&text).unwrap();
        let ev = v["traceEvents"].as_array().unwrap();
        assert_eq!(ev[0]["args"]["frame"], 4);
        assert_eq!(ev[0]["args"]["draw"], 3);
        let phases: Vec<&str> = ev[1..].iter().map(|e| e["ph"].as_str().unwrap()).collect();
        assert_eq!(phases, ["s", "t", "f"]);
        assert!(ev[1..].iter().all(|e| e["id"] == 5 && e["cat"] == "frame"));
        assert_eq!(ev[3]["bp"], "e");
        assert!(ev[1].get("bp").is_none());
        for name in TraceDetail::NAMES {
            assert_eq!(name.parse::<TraceDetail>().unwrap().name(), name);
        }
        assert!(
            "pixel"
                .parse::<TraceDetail>()
                .unwrap_err()
                .contains("frame, draw or triangle")
        );
        assert_eq!(TraceDetail::default(), TraceDetail::Draw);
    }

    #[test]
    fn an_empty_trace_is_valid_and_the_first_error_is_kept() {
        let buf = Shared::default();
        assert_eq!(TraceWriter::new(Box::new(buf.clone())).finish().unwrap(), 0);
        let v: serde_json::Value = serde_json::from_slice(&buf.0.lock().unwrap()).unwrap();
        assert_eq!(v["traceEvents"].as_array().unwrap().len(), 0);

        struct Full;
        impl Write for Full {
            fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
                Err(std::io::Error::new(std::io::ErrorKind::StorageFull, "disk full"))
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        let mut t = TraceWriter::new(Box::new(Full));
        t.span(1, 1, "x", Time(0), Time(1), None);
        let e = t.finish().unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::StorageFull);
    }
}
