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
    fn a_span_past_the_clock_blames_its_largest_part() {
        let day = 86_400e12;
        assert_eq!(span_check(&[("a", 100.0 * day), ("b", 100.0 * day)]), None);
        let (key, m) = span_check(&[("a", 100.0 * day), ("b", 60.0 * day), ("b", 60.0 * day)]).unwrap();
        // b feeds two loops: its parts add up before the largest is chosen.
        assert_eq!(key, "b");
        assert!(m.contains("b: 1.037e7 s") && m.contains("213 days"), "{m}");
    }
}
