//! Stated limits on sizes read from input.
//!
//! Every count or size a user writes (a model key, a `--set`, an experiment
//! file, a command-line option, a mesh spec) that decides how much memory is
//! allocated is checked against one of these limits before anything is
//! allocated, so bad input ends with an error naming the key, the value and
//! the limit instead of `memory allocation of N bytes failed`.
//! `docs/models.md` ("Limits") lists them for users.
//!
//! Beyond the per-key limits, systems with a `[run]` table estimate the
//! memory a run needs from its inputs before simulating and compare it with
//! `run.max_memory` (default [`DEFAULT_MAX_MEMORY`]).

/// Default of `run.max_memory`: 8 GiB.
pub const DEFAULT_MAX_MEMORY: u64 = 8 << 30;

/// Most indices of a generated mesh (`grid:WxH`, `strip:WxH`,
/// `random:T:V:SEED`): 2^28, a 1 GiB index buffer (a 6689 x 6689 grid).
pub const MAX_MESH_INDICES: u64 = 1 << 28;

/// Most vertices of a mesh (`random:T:V:SEED`'s V, an `.idx` file's
/// largest index + 1, an `.obj` file's vertices): 2^28. Coverage counting
/// and the caches keep a few bytes per vertex, so a file of three indices
/// naming vertex 4,000,000,000 would otherwise ask for 32 GiB.
pub const MAX_MESH_VERTICES: u64 = 1 << 28;

/// Most objects in a frame-pipeline scene (the sum of every group's
/// `count`, a preset's objects times `workload.scale` included): draws are
/// indexed with 32 bits, and each costs about 100 bytes to compile.
pub const MAX_SCENE_OBJECTS: u64 = 1 << 24;

/// Largest `workload.scale` of a preset scene (a thousand times the paper's
/// scene).
pub const MAX_SCENE_SCALE: f64 = 1000.0;

/// Shortest display refresh period (`display.refresh`): 1 us, a 1 MHz
/// display. Every refresh is an event, so a picosecond refresh would make a
/// run of ordinary frames take billions of events.
pub const MIN_REFRESH_PERIOD_PS: u64 = 1_000_000;

/// Most input events (`run.events`) a multi-frame-rate or VR model may follow.
pub const MAX_INPUT_EVENTS: u64 = 100_000_000;

/// Least share of a unit (the CPU thread, or the GPU front end) that the
/// system tasks preempting it (`noise.periodic` and `noise.random`, their
/// mean durations over their mean gaps, added up per target) must leave
/// free: 5%. At a share `s` left, every frame's work on that unit stretches
/// at least `1/s` times (20 times at 5%), and near saturation the waiting
/// tasks' backlog makes it far worse: 34.99 ms every 35 ms beside the
/// default model's 2 Hz background task is more than the whole CPU, and
/// gave 1 frame per 7,148 simulated seconds. No operating system's noise
/// (the paper's is about 0.5 ms every 35 ms, 1.4%) comes near it.
pub const MIN_FREE_SHARE: f64 = 0.05;

/// Most events a run may be estimated to need before it simulates, when it
/// sets no `run.max_events` (and, for the frame pipeline, no `run.until`):
/// 10^11, one to several hours at the kernel's ten to fifty million events
/// a second. The estimate is a lower bound from the inputs (frames, display
/// refreshes and system tasks over the least simulated span the frames
/// take, triangles at `triangle` fidelity; the loops of a latency system
/// over the span until the last input arrives), so a run refused by it
/// could not have finished in a working day. Setting `run.max_events`
/// raises the bound (a latency system's run needs its events to be under
/// it; a frame-pipeline run stops there with the frames it completed).
pub const DEFAULT_MAX_EVENTS: u64 = 100_000_000_000;

/// Most slots of a `direct:SLOTS,SEGMENT` vertex cache (one 4-byte stamp per slot).
pub const MAX_DIRECT_CACHE_SLOTS: u32 = 1 << 20;

/// Most replications per point of an experiment.
pub const MAX_REPLICATIONS: i64 = 100_000;

/// Most runs of an experiment: points (the product of the sweeps' sizes)
/// times replications.
pub const MAX_EXPERIMENT_RUNS: u64 = 1_000_000;

/// Most PixelFlow nodes (`nodes`).
pub const MAX_PIXELFLOW_NODES: u32 = 4096;

/// Most per-(node, region) bins of a PixelFlow layout (`nodes` x regions).
pub const MAX_PIXELFLOW_BINS: u64 = 1 << 26;

/// Most per-region records of a PixelFlow run (`frames` x regions).
pub const MAX_PIXELFLOW_REGION_RECORDS: u64 = 1 << 24;

/// Most slots of a state-sorting buffer (`rendersim sortbuf --buffer`,
/// `--sweep`): one 4-byte entry each.
pub const MAX_SORT_BUFFER: usize = 1 << 24;

/// Largest m of the sorting buffer's `lru-worst:M` sequence (m (m + m² + 1)
/// elements: about 16.8 million at 256).
pub const MAX_LRU_WORST_M: u64 = 256;

/// Most layers of `rendersim predict --layers`: each layer is one more copy
/// of the mesh, simulated triangle by triangle, so a prediction's time grows
/// linearly with them (about a second per thousand layers of a 64x64 grid;
/// u32::MAX was accepted and would take weeks). The studies draw at most 8
/// layers; no screen pass has a depth complexity of a thousand.
pub const MAX_PASS_LAYERS: u32 = 1024;

/// Most triangles a `rendersim predict` pass simulates (the mesh's
/// triangles times `--layers`): 2^27, about 134 million, at least the
/// largest generated mesh ([`MAX_MESH_INDICES`] / 3) drawn once, and about
/// a quarter of a minute at the kernel's speed (two events per triangle).
pub const MAX_PASS_TRIANGLES: u64 = 1 << 27;

/// Formats a byte count for messages: `8 GiB`, `1.5 MiB`, `512 bytes`.
pub fn show_bytes(b: u64) -> String {
    const UNITS: [(&str, u64); 4] = [("TiB", 1 << 40), ("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (name, size) in UNITS {
        if b >= size {
            let v = b as f64 / size as f64;
            return if b.is_multiple_of(size) {
                format!("{} {name}", b / size)
            } else {
                format!("{v:.1} {name}")
            };
        }
    }
    format!("{b} bytes")
}

/// The message of a run whose estimated memory exceeds `run.max_memory`:
/// names the estimate, what it is made of, the limit and how to raise it.
pub fn over_memory_message(estimate: u64, parts: &str, limit: u64) -> String {
    format!(
        "the run would need about {} ({parts}), more than run.max_memory = {}; \
         shorten the run, or raise the limit, e.g. `--set run.max_memory=\"{}\"` \
         (default {})",
        show_bytes(estimate),
        show_bytes(limit),
        suggest(estimate),
        show_bytes(DEFAULT_MAX_MEMORY)
    )
}

fn suggest(estimate: u64) -> String {
    let gib = estimate.div_ceil(1 << 30).max(1);
    let gib = gib.checked_next_power_of_two().unwrap_or(gib);
    format!("{gib}GiB")
}

/// Adds `count` items of `size` bytes to `total`, saturating.
pub fn add_bytes(total: &mut u64, count: u64, size: usize) {
    *total = total.saturating_add(count.saturating_mul(size as u64));
}

/// The message refusing, before simulating, a latency-system run whose input
/// events alone (`run.events` arrivals `input.mean_interval` apart on
/// average, after `run.warmup`, all in picoseconds) reach past the clock's
/// range (`u64` picoseconds, about 213 days); `None` when they fit. The key
/// to blame is `input.mean_interval|run.events|run.warmup`.
pub fn input_span_message(events: u64, warmup_ps: u64, mean_interval_ps: u64) -> Option<String> {
    let total = warmup_ps as f64 + events as f64 * mean_interval_ps as f64;
    (total >= u64::MAX as f64).then(|| {
        format!(
            "run.events = {events} inputs every {} s on average (after run.warmup) need about {:.3e} s of simulated time, \
             more than the clock can count (about 213 days in picoseconds); lower input.mean_interval or run.events",
            mean_interval_ps as f64 / 1e12,
            total / 1e12
        )
    })
}

/// The keys [`input_span_message`] blames.
pub const INPUT_SPAN_KEYS: &str = "input.mean_interval|run.events|run.warmup";

/// The memory estimate of a latency system (multi_rate, vr): `events` input
/// records of `per_event` bytes (`noun` names them, "input events"). Their
/// frames are not kept, so the simulated span does not count. Returns the
/// bytes and a description.
pub fn latency_estimate(events: u64, per_event: usize, noun: &str) -> (u64, String) {
    let mut bytes = 0u64;
    add_bytes(&mut bytes, events, per_event);
    (
        bytes,
        format!(
            "{events} {noun} = {} of records (run.events; frames are folded into the events they show as they end and not kept)",
            show_bytes(bytes)
        ),
    )
}

/// Refuses, before simulating, a run whose expected simulated span reaches
/// past the clock's range (`u64` picoseconds, about 213 days). `terms` are
/// the span's parts, each with the key it comes from and its picoseconds
/// (multiplicities applied): for a latency system the warm-up, the input
/// events, and what follows the last input until every path has shown it (a
/// tracker period and its latency, two frame intervals of each loop, the
/// links and the display). Returns the key of the largest part and the
/// message, or `None` when the span fits. Such a run would otherwise
/// simulate up to the overflow before it failed, which can take minutes.
pub fn span_check(terms: &[(&str, f64)]) -> Option<(String, String)> {
    let total: f64 = terms.iter().map(|t| t.1).sum();
    if total < u64::MAX as f64 {
        return None;
    }
    // One part per key (a key may feed two loops).
    let mut parts: Vec<(&str, f64)> = Vec::new();
    for &(k, ps) in terms.iter().filter(|t| t.1 > 0.0) {
        match parts.iter_mut().find(|p| p.0 == k) {
            Some(p) => p.1 += ps,
            None => parts.push((k, ps)),
        }
    }
    parts.sort_by(|a, b| b.1.total_cmp(&a.1));
    let list = parts
        .iter()
        .take(3)
        .map(|(k, ps)| format!("{k}: {:.3e} s", ps / 1e12))
        .collect::<Vec<_>>()
        .join(", ");
    Some((
        parts[0].0.to_string(),
        format!(
            "the run needs about {:.3e} s of simulated time until every input is shown (largest parts: {list}), \
             more than the clock can count (about 213 days in picoseconds)",
            total / 1e12
        ),
    ))
}

/// One part of a run's event estimate: the key to blame (`a|b` for several),
/// what the events are, and how many (at least).
pub type EventPart = (String, String, f64);

/// Refuses, before simulating, a run whose estimated events (`parts`, each a
/// lower bound) exceed `max_events` (the model's `run.max_events`), or
/// [`DEFAULT_MAX_EVENTS`] without one. Returns the key of the largest part
/// and the message, or `None` when the run fits. `advice` ends the message
/// (what to lower, or how to run anyway).
pub fn events_check(parts: &[EventPart], max_events: Option<u64>, advice: &str) -> Option<(String, String)> {
    let total: f64 = parts.iter().map(|p| p.2).sum();
    let limit = max_events.unwrap_or(DEFAULT_MAX_EVENTS);
    // Written so that a NaN total is refused too.
    if total <= limit as f64 {
        return None;
    }
    let mut sorted: Vec<&EventPart> = parts.iter().filter(|p| p.2 > 0.0 || p.2.is_nan()).collect();
    sorted.sort_by(|a, b| b.2.total_cmp(&a.2));
    let list = sorted
        .iter()
        .take(3)
        .map(|(k, what, n)| format!("{what} ({k}): {n:.3e}"))
        .collect::<Vec<_>>()
        .join(", ");
    let bound = match max_events {
        Some(m) => format!("run.max_events = {m}"),
        None => format!(
            "the limit of {:.0e} events for a run without run.max_events \
             (hours at the kernel's tens of millions of events a second)",
            DEFAULT_MAX_EVENTS as f64
        ),
    };
    let key = sorted.first().map_or("run.max_events", |p| p.0.as_str()).to_string();
    Some((
        key,
        format!("the run needs at least about {total:.3e} events (largest parts: {list}), more than {bound}; {advice}"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_counts_read_well() {
        assert_eq!(show_bytes(DEFAULT_MAX_MEMORY), "8 GiB");
        assert_eq!(show_bytes(1536 << 20), "1.5 GiB");
        assert_eq!(show_bytes(100), "100 bytes");
        let m = over_memory_message(9 << 30, "frames", DEFAULT_MAX_MEMORY);
        assert!(
            m.contains("9 GiB") && m.contains("run.max_memory = 8 GiB") && m.contains("16GiB"),
            "{m}"
        );
    }

    #[test]
    fn an_event_estimate_past_the_bound_blames_its_largest_part() {
        let parts = [
            ("a".to_string(), "frames".to_string(), 10.0),
            ("b|run.frames".to_string(), "refreshes".to_string(), 2e11),
        ];
        assert_eq!(events_check(&parts[..1], None, "x"), None);
        let (key, m) = events_check(&parts, None, "lower b").unwrap();
        assert_eq!(key, "b|run.frames");
        assert!(
            m.contains("2.000e11 events") && m.contains("refreshes (b|run.frames): 2.000e11") && m.ends_with("lower b"),
            "{m}"
        );
        // An explicit run.max_events is the bound, either way.
        assert_eq!(events_check(&parts, Some(300_000_000_000), "x"), None);
        let (_, m) = events_check(&parts[..1], Some(5), "x").unwrap();
        assert!(m.contains("run.max_events = 5"), "{m}");
        assert!(events_check(&[("n".into(), "nan".into(), f64::NAN)], None, "x").is_some());
    }

    #[test]
    fn a_span_past_the_clock_blames_its_largest_part() {
        let day = 86_400e12;
        assert_eq!(span_check(&[("a", 100.0 * day), ("b", 100.0 * day)]), None);
        let (key, m) = span_check(&[("a", 100.0 * day), ("b", 60.0 * day), ("b", 60.0 * day)]).unwrap();
        // b feeds two loops: its parts add up before the largest is chosen.
        assert_eq!(key, "b");
        assert!(m.contains("b: 1.037e7 s") && m.contains("213 days"), "{m}");
    }
}

/// The kinds of input file, each with its own size limit
/// ([`max_input_bytes`]): text a person writes (models, experiment files,
/// device profiles, LOD instance files, shard files), and data a tool or a
/// measurement wrote (captures, measurement CSVs, meshes, state sequences).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// A model, an experiment, a device profile, an instance or shard file.
    Text,
    /// A capture, a measurement CSV, a mesh (`.obj`, `.idx`), a sequence.
    Data,
}

/// Default size limit of a [`InputKind::Text`] input file: 64 MiB.
pub const MAX_TEXT_INPUT_BYTES: u64 = 64 << 20;

/// Default size limit of a [`InputKind::Data`] input file: 4 GiB.
pub const MAX_DATA_INPUT_BYTES: u64 = 4 << 30;

/// The environment variable that sets one size limit, in bytes, for every
/// input file (the command line's `--max-input-bytes` sets it too).
pub const MAX_INPUT_BYTES_VAR: &str = "RENDERSIM_MAX_INPUT_BYTES";

/// The limit the command line's `--max-input-bytes` set (0: none).
static MAX_INPUT_OVERRIDE: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Sets one size limit, in bytes (at least 1), for every input file this
/// process reads (the command line's `--max-input-bytes`); it wins over
/// [`MAX_INPUT_BYTES_VAR`].
pub fn set_max_input_bytes(bytes: u64) {
    MAX_INPUT_OVERRIDE.store(bytes.max(1), std::sync::atomic::Ordering::Relaxed);
}

/// The size limit of an input file of `kind`: the one
/// [`set_max_input_bytes`] set, else [`MAX_INPUT_BYTES_VAR`] when set to a
/// number, else the kind's default.
pub fn max_input_bytes(kind: InputKind) -> u64 {
    let set = MAX_INPUT_OVERRIDE.load(std::sync::atomic::Ordering::Relaxed);
    if set > 0 {
        return set;
    }
    if let Some(n) = std::env::var(MAX_INPUT_BYTES_VAR)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
    {
        return n;
    }
    match kind {
        InputKind::Text => MAX_TEXT_INPUT_BYTES,
        InputKind::Data => MAX_DATA_INPUT_BYTES,
    }
}

fn too_large(size: u64, kind: InputKind) -> std::io::Error {
    let limit = max_input_bytes(kind);
    let what = match kind {
        InputKind::Text => "a model, experiment, profile or instance file",
        InputKind::Data => "a capture, measurement, mesh or sequence file",
    };
    std::io::Error::new(
        std::io::ErrorKind::InvalidData,
        format!(
            "the file is {}, more than the {} {what} may be (set {MAX_INPUT_BYTES_VAR} or --max-input-bytes to raise it)",
            show_bytes(size),
            show_bytes(limit)
        ),
    )
}

/// Opens an input file of `kind` for reading, refusing what is not a
/// regular file (a device such as `/dev/zero`, a FIFO, a socket: they can
/// be endless or block) and a file over its size limit. The reader stops
/// one byte past the limit, so a file that grows while read is caught by
/// [`read_input`]. A folder is left to the caller's own message (opening
/// one fails, or reading it does).
///
/// ```
/// use rendersim_models::limits::{InputKind, read_input};
/// let e = read_input(std::path::Path::new("/dev/zero"), InputKind::Text).unwrap_err();
/// assert!(e.to_string().contains("not a regular file"), "{e}");
/// ```
pub fn open_input(path: &std::path::Path, kind: InputKind) -> std::io::Result<std::io::Take<std::fs::File>> {
    use std::io::Read;
    // Checked before opening: opening a FIFO blocks until a writer comes.
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() && !meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a device, FIFO or socket): input is read from files",
        ));
    }
    let limit = max_input_bytes(kind);
    if meta.is_file() && meta.len() > limit {
        return Err(too_large(meta.len(), kind));
    }
    Ok(std::fs::File::open(path)?.take(limit.saturating_add(1)))
}

/// Reads an input file of `kind` whole ([`open_input`]'s checks, and the
/// size limit again on what was read).
pub fn read_input(path: &std::path::Path, kind: InputKind) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut r = open_input(path, kind)?;
    let mut bytes = Vec::new();
    r.read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_input_bytes(kind) {
        return Err(too_large(bytes.len() as u64, kind));
    }
    Ok(bytes)
}

/// [`read_input`] as UTF-8 text (invalid UTF-8 is an
/// [`std::io::ErrorKind::InvalidData`] error, as `fs::read_to_string` gives).
pub fn read_input_string(path: &std::path::Path, kind: InputKind) -> std::io::Result<String> {
    String::from_utf8(read_input(path, kind)?)
        .map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidData, "stream did not contain valid UTF-8"))
}
