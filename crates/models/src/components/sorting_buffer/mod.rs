//! State sorting with a small buffer between the application and the
//! graphics card (paper 001, slides "State Sorting" to "Round-Robin": the
//! lecture follows Räcke, Sohler & Westermann, "Online Scheduling for
//! Sorting Buffers", ESA 2002).
//!
//! One attribute is looked at (the lecture's "colour"; here a state id).
//! Elements arrive in sequence; a state change happens whenever the element
//! sent to the card has another state than the one before. The model,
//! exactly:
//!
//! - the buffer has `K` slots; every arriving element is written into the
//!   free slot with the lowest index;
//! - when the buffer is full (`K` elements), the strategy chooses a state
//!   and all buffered elements of that state are sent to the card, in one
//!   run ("lazy": elements leave only on overflow, which the lecture shows
//!   costs nothing against non-lazy strategies);
//! - after the last element the buffer is flushed: the current state first
//!   (if buffered, at no cost), then the others;
//! - `state_changes` counts the runs of equal states sent to the card: the
//!   first state set counts as a change (so a sequence of D distinct
//!   states never costs less than D, as the lecture's offline cost 2m for
//!   2m colours counts).
//!
//! With `K = 1` nothing is reordered: the changes are the runs of the input.
//! Passing an element straight to the card (the lecture's first operation)
//! is an element written into the buffer and sent at once: a lecture buffer
//! of `k` slots plus the direct path is this model's `K = k + 1`.
//!
//! Strategies (what is sent on overflow):
//! - [`Strategy::Lru`]: one time stamp per state, set whenever an element of
//!   that state is written; the state with the oldest stamp is sent;
//! - [`Strategy::BoundedWaste`]: a waste counter W(c) per state; on every
//!   overflow W(c) grows by the elements of state c in the buffer, the state
//!   with the largest W is sent and its W reset to 0 (ties: more elements,
//!   then older stamp);
//! - [`Strategy::Random`]: a slot chosen uniformly at random (a named RNG
//!   stream, `sortbuf.random`), its state sent; frequent states are chosen
//!   more often, which over time approximates W(c);
//! - [`Strategy::RoundRobin`]: like random, but the slot is the one a
//!   pointer shows, and the pointer moves on by one slot each time.
//!
//! Cost: LRU, random and round robin take O(log K) per element; bounded
//! waste O(sqrt(K) + log K) per overflow (its counters kept as lines in the
//! overflow count, grouped by slope: see `Waste`), where the direct form
//! looks at every buffered state, O(distinct states in the buffer): 27 s
//! for K = 65,536 on 200,000 ids.
//!
//! [`lower_bound`] bounds the offline optimum from below; [`offline_optimum`]
//! finds it exactly for tiny sequences; [`sequence`] reads sequences and
//! builds the lecture's worst case for LRU.

mod bound;
pub mod sequence;

use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap, HashMap};

use rand::Rng;
use serde::Serialize;

use crate::engine::RngStreams;

pub use bound::{MAX_OFFLINE_LEN, lower_bound, offline_optimum};

/// A state id (the lecture's colour).
pub type StateId = u64;

/// Most buffer slots ([`crate::limits::MAX_SORT_BUFFER`]).
pub const MAX_BUFFER: usize = crate::limits::MAX_SORT_BUFFER;

/// What a strategy sends on overflow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    /// Least recently written state.
    Lru,
    /// Largest waste counter.
    BoundedWaste,
    /// The state of a uniformly random slot.
    Random,
    /// The state of the slot a round-robin pointer shows.
    RoundRobin,
}

impl Strategy {
    /// All strategies, in the lecture's order.
    pub const ALL: [Strategy; 4] = [
        Strategy::Lru,
        Strategy::BoundedWaste,
        Strategy::Random,
        Strategy::RoundRobin,
    ];

    /// The name as written on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Lru => "lru",
            Strategy::BoundedWaste => "bounded-waste",
            Strategy::Random => "random",
            Strategy::RoundRobin => "round-robin",
        }
    }
}

/// Errors of the sorting buffer and its sequences.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SortBufferError {
    /// A buffer of no slots.
    #[error("the buffer must have at least 1 slot (got 0)")]
    ZeroBuffer,
    /// A buffer above the limit.
    #[error("a buffer of {got} slots is more than the limit of {limit}")]
    BufferTooLarge {
        /// Slots asked for.
        got: usize,
        /// The limit.
        limit: usize,
    },
    /// A sequence with no state ids.
    #[error("{source_name}: the sequence has no state ids")]
    Empty {
        /// Where the sequence came from.
        source_name: String,
    },
    /// A token that is not a state id.
    #[error("{source_name}:{line}:{column}: {token:?} is not a state id (a non-negative integer)")]
    BadToken {
        /// Where the sequence came from.
        source_name: String,
        /// Line (1-based).
        line: usize,
        /// Column (1-based, in characters).
        column: usize,
        /// The token.
        token: String,
    },
    /// A sequence spec or file that cannot be used.
    #[error("{0}")]
    Source(String),
    /// The exact offline search was asked for a sequence too long for it.
    #[error("the exact offline optimum is searched only for sequences of at most {limit} elements (got {got})")]
    TooLongForExact {
        /// Elements.
        got: usize,
        /// The limit.
        limit: usize,
    },
}

/// Checks a buffer size.
pub fn check_buffer(k: usize) -> Result<(), SortBufferError> {
    if k == 0 {
        return Err(SortBufferError::ZeroBuffer);
    }
    if k > MAX_BUFFER {
        return Err(SortBufferError::BufferTooLarge {
            got: k,
            limit: MAX_BUFFER,
        });
    }
    Ok(())
}

/// The result of one run of a strategy.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BufferRun {
    /// Runs of equal states sent to the card.
    pub state_changes: u64,
    /// Overflows (choices the strategy made).
    pub overflows: u64,
    /// The runs sent, in order, as (state, elements), when asked for.
    pub output: Option<Vec<(StateId, u64)>>,
}

const FREE: u32 = u32::MAX;

/// The buffer's state while a strategy runs (states mapped to dense ids).
struct Buffer {
    slots: Vec<u32>,
    free: BinaryHeap<Reverse<usize>>,
    slots_of: Vec<Vec<usize>>,
    /// Buffered states, and each one's position in `present`.
    present: Vec<u32>,
    pos: Vec<usize>,
    stamp: Vec<u64>,
    /// Buffered states by stamp, oldest first (LRU in O(log K)).
    by_stamp: BTreeMap<u64, u32>,
    waste: Vec<u64>,
    last: Option<u32>,
    changes: u64,
    output: Option<Vec<(u32, u64)>>,
}

impl Buffer {
    fn insert(&mut self, c: u32, now: u64) {
        let Reverse(s) = self.free.pop().expect("insert into a buffer that is not full");
        self.slots[s] = c;
        if self.slots_of[c as usize].is_empty() {
            self.pos[c as usize] = self.present.len();
            self.present.push(c);
        } else {
            self.by_stamp.remove(&self.stamp[c as usize]);
        }
        self.slots_of[c as usize].push(s);
        self.stamp[c as usize] = now;
        self.by_stamp.insert(now, c);
    }

    fn send(&mut self, c: u32) {
        let list = std::mem::take(&mut self.slots_of[c as usize]);
        let n = list.len() as u64;
        for &s in &list {
            self.slots[s] = FREE;
            self.free.push(Reverse(s));
        }
        let mut list = list;
        list.clear();
        self.slots_of[c as usize] = list;
        self.by_stamp.remove(&self.stamp[c as usize]);
        let p = self.pos[c as usize];
        self.present.swap_remove(p);
        if let Some(&moved) = self.present.get(p) {
            self.pos[moved as usize] = p;
        }
        if self.last != Some(c) {
            self.changes += 1;
            self.last = Some(c);
            if let Some(o) = &mut self.output {
                o.push((c, n));
            }
        } else if let Some(o) = &mut self.output
            && let Some(l) = o.last_mut()
        {
            l.1 += n;
        }
    }

    fn oldest(&self) -> u32 {
        *self.by_stamp.first_key_value().expect("a full buffer holds a state").1
    }
}

/// Bounded waste's counters without touching every buffered state on each
/// overflow. W(c) grows by n(c), the elements of state c in the buffer, on
/// every overflow, and n(c) changes only when an element of c is written or
/// c is sent; so after the `T`-th overflow
/// `W(c) = acc(c) + n(c) (T - t(c))`, with `acc(c)` (in `Buffer::waste`) the
/// counter at overflow `t(c)`, when n(c) last changed: a line in T with slope
/// n(c) and intercept `b(c) = acc(c) - n(c) t(c)`. States with the same n(c)
/// keep their order by intercept (then by older stamp, the tie-break) while
/// T grows, so each group of equal n keeps its states in an ordered set and
/// only the best of each group is compared on an overflow. The buffered
/// elements add up to at most K, so there are at most sqrt(2K) groups: an
/// overflow costs O(sqrt(K) + log K) instead of O(distinct states in the
/// buffer), and the choice is the same state (every W is the same integer;
/// stamps are unique, so there are no full ties).
struct Waste {
    /// n -> the states with n elements buffered, ordered by (intercept,
    /// `Reverse(stamp)`): the best (largest W, then the older stamp) last.
    groups: BTreeMap<usize, std::collections::BTreeSet<(i128, Reverse<u64>, u32)>>,
    /// Each state's overflow count `t(c)` at its last change.
    since: Vec<u64>,
}

impl Waste {
    fn new(states: usize) -> Self {
        Waste {
            groups: BTreeMap::new(),
            since: vec![0; states],
        }
    }

    fn key(b: &Buffer, c: u32, since: u64) -> (usize, (i128, Reverse<u64>, u32)) {
        let n = b.slots_of[c as usize].len();
        let acc = b.waste[c as usize] as i128;
        (n, (acc - n as i128 * since as i128, Reverse(b.stamp[c as usize]), c))
    }

    /// Takes state `c` out of its group before its count changes, bringing
    /// its counter up to overflow `now` (the overflows so far).
    fn leave(&mut self, b: &mut Buffer, c: u32, now: u64) {
        let n = b.slots_of[c as usize].len();
        if n == 0 {
            // Not buffered: its counter is 0 (reset when it was sent).
            self.since[c as usize] = now;
            return;
        }
        let since = self.since[c as usize];
        let (_, key) = Self::key(b, c, since);
        if let Some(g) = self.groups.get_mut(&n) {
            g.remove(&key);
            if g.is_empty() {
                self.groups.remove(&n);
            }
        }
        b.waste[c as usize] += n as u64 * (now - since);
        self.since[c as usize] = now;
    }

    /// Puts state `c` (just written) into the group of its new count.
    fn join(&mut self, b: &Buffer, c: u32) {
        let (n, key) = Self::key(b, c, self.since[c as usize]);
        self.groups.entry(n).or_default().insert(key);
    }

    /// The state to send on overflow number `t` (1-based): the largest
    /// W(c) after this overflow's growth, then more elements, then the
    /// older stamp.
    fn choose(&self, t: u64) -> u32 {
        self.groups
            .iter()
            .filter_map(|(&n, g)| {
                g.last()
                    .map(|&(icpt, stamp, c)| (icpt + n as i128 * t as i128, n, stamp, c))
            })
            .max()
            .expect("a full buffer holds a state")
            .3
    }
}

/// Runs `strategy` over `seq` with a buffer of `k` slots. `seed` is the
/// master seed of the random strategy's stream; `record` keeps the runs
/// sent.
///
/// Alternating states `0 1 0 1 0 1`: one slot reorders nothing (6 changes,
/// the input's runs); six slots hold the whole sequence, and the one
/// overflow when they are full sends the three 0s (LRU: the older stamp),
/// the final flush the three 1s: 2 changes, the number of distinct states,
/// which no buffer beats.
///
/// ```
/// use rendersim_models::components::sorting_buffer::{input_runs, lower_bound, simulate, Strategy};
///
/// let seq = [0, 1, 0, 1, 0, 1];
/// assert_eq!(input_runs(&seq), 6);
/// assert_eq!(simulate(&seq, 1, Strategy::Lru, 1, false).unwrap().state_changes, 6);
/// let all = simulate(&seq, 6, Strategy::Lru, 1, true).unwrap();
/// assert_eq!((all.state_changes, all.overflows), (2, 1));
/// assert_eq!(all.output.unwrap(), [(0, 3), (1, 3)]);
/// assert!(lower_bound(&seq, 6) <= 2);
/// ```
pub fn simulate(
    seq: &[StateId],
    k: usize,
    strategy: Strategy,
    seed: u64,
    record: bool,
) -> Result<BufferRun, SortBufferError> {
    check_buffer(k)?;
    // Dense ids in order of first appearance.
    let mut ids: HashMap<StateId, u32> = HashMap::new();
    let mut names: Vec<StateId> = Vec::new();
    let dense: Vec<u32> = seq
        .iter()
        .map(|&s| {
            *ids.entry(s).or_insert_with(|| {
                names.push(s);
                (names.len() - 1) as u32
            })
        })
        .collect();
    let d = names.len();
    let mut b = Buffer {
        slots: vec![FREE; k],
        free: (0..k).map(Reverse).collect(),
        slots_of: vec![Vec::new(); d],
        present: Vec::new(),
        pos: vec![0; d],
        stamp: vec![0; d],
        by_stamp: BTreeMap::new(),
        waste: vec![0; d],
        last: None,
        changes: 0,
        output: record.then(Vec::new),
    };
    let mut rng = RngStreams::new(seed).stream("sortbuf.random");
    let mut pointer = 0usize;
    let mut overflows = 0u64;
    let mut filled = 0usize;
    let bounded_waste = strategy == Strategy::BoundedWaste;
    let mut waste = Waste::new(if bounded_waste { d } else { 0 });
    for (t, &c) in dense.iter().enumerate() {
        if bounded_waste {
            waste.leave(&mut b, c, overflows);
        }
        b.insert(c, t as u64);
        if bounded_waste {
            waste.join(&b, c);
        }
        filled += 1;
        if filled < k {
            continue;
        }
        overflows += 1;
        let chosen = match strategy {
            Strategy::Lru => b.oldest(),
            Strategy::BoundedWaste => waste.choose(overflows),
            Strategy::Random => b.slots[rng.random_range(0..k)],
            Strategy::RoundRobin => {
                let c = b.slots[pointer];
                pointer = (pointer + 1) % k;
                c
            }
        };
        filled -= b.slots_of[chosen as usize].len();
        if bounded_waste {
            waste.leave(&mut b, chosen, overflows);
            b.waste[chosen as usize] = 0;
        }
        b.send(chosen);
    }
    // Flush: the current state first (free), then oldest first.
    if let Some(l) = b.last
        && !b.slots_of[l as usize].is_empty()
    {
        b.send(l);
    }
    while !b.present.is_empty() {
        let c = b.oldest();
        b.send(c);
    }
    Ok(BufferRun {
        state_changes: b.changes,
        overflows,
        output: b
            .output
            .map(|o| o.into_iter().map(|(c, n)| (names[c as usize], n)).collect()),
    })
}

/// Runs of equal states in `seq` (the changes without a buffer, `K = 1`).
pub fn input_runs(seq: &[StateId]) -> u64 {
    seq.iter()
        .enumerate()
        .filter(|&(i, s)| i == 0 || seq[i - 1] != *s)
        .count() as u64
}

/// Distinct states in `seq`.
pub fn distinct_states(seq: &[StateId]) -> usize {
    let mut v = seq.to_vec();
    v.sort_unstable();
    v.dedup();
    v.len()
}

/// One `rendersim sortbuf` result.
#[derive(Debug, Clone, Serialize)]
pub struct SortbufSummary {
    /// Where the sequence came from (a file, or a spec like `lru-worst:4`).
    pub sequence: String,
    /// Elements in the sequence.
    pub sequence_length: usize,
    /// Distinct state ids.
    pub distinct_states: usize,
    /// State changes without a buffer (runs of the input).
    pub input_runs: u64,
    /// The strategy.
    pub strategy: Strategy,
    /// Buffer slots K.
    pub buffer: usize,
    /// The random strategy's master seed (absent for the others).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// State changes sent to the card (runs of equal states; the first counts).
    pub state_changes: u64,
    /// A lower bound of the offline optimum ([`lower_bound`]).
    pub lower_bound: u64,
    /// The exact offline optimum, for sequences of at most
    /// [`MAX_OFFLINE_LEN`] elements.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offline_optimum: Option<u64>,
    /// Overflows (choices the strategy made).
    pub overflows: u64,
}

impl SortbufSummary {
    /// Runs `strategy` with `k` slots over `seq` and summarizes it.
    pub fn run(name: &str, seq: &[StateId], k: usize, strategy: Strategy, seed: u64) -> Result<Self, SortBufferError> {
        let r = simulate(seq, k, strategy, seed, false)?;
        let offline_optimum = if seq.len() <= MAX_OFFLINE_LEN {
            Some(offline_optimum(seq, k)?)
        } else {
            None
        };
        Ok(SortbufSummary {
            sequence: name.to_string(),
            sequence_length: seq.len(),
            distinct_states: distinct_states(seq),
            input_runs: input_runs(seq),
            strategy,
            buffer: k,
            seed: (strategy == Strategy::Random).then_some(seed),
            state_changes: r.state_changes,
            lower_bound: lower_bound(seq, k),
            offline_optimum,
            overflows: r.overflows,
        })
    }
}

/// One buffer size of a sweep: the bound and every strategy's changes.
#[derive(Debug, Clone, Serialize)]
pub struct SweepRow {
    /// Buffer slots K.
    pub buffer: usize,
    /// The lower bound of the offline optimum at this K.
    pub lower_bound: u64,
    /// The exact offline optimum (tiny sequences only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offline_optimum: Option<u64>,
    /// State changes per strategy, by strategy name.
    pub state_changes: std::collections::BTreeMap<&'static str, u64>,
}

/// `rendersim sortbuf --sweep`: strategies over buffer sizes.
#[derive(Debug, Clone, Serialize)]
pub struct SortbufSweep {
    /// Where the sequence came from.
    pub sequence: String,
    /// Elements in the sequence.
    pub sequence_length: usize,
    /// Distinct state ids.
    pub distinct_states: usize,
    /// State changes without a buffer.
    pub input_runs: u64,
    /// The random strategy's master seed.
    pub seed: u64,
    /// The strategies run.
    pub strategies: Vec<Strategy>,
    /// One row per buffer size, in the order given.
    pub rows: Vec<SweepRow>,
}

impl SortbufSweep {
    /// Runs every strategy at every buffer size.
    pub fn run(
        name: &str,
        seq: &[StateId],
        buffers: &[usize],
        strategies: &[Strategy],
        seed: u64,
    ) -> Result<Self, SortBufferError> {
        for &k in buffers {
            check_buffer(k)?;
        }
        let mut rows = Vec::with_capacity(buffers.len());
        for &k in buffers {
            let mut state_changes = std::collections::BTreeMap::new();
            for &s in strategies {
                state_changes.insert(s.name(), simulate(seq, k, s, seed, false)?.state_changes);
            }
            rows.push(SweepRow {
                buffer: k,
                lower_bound: lower_bound(seq, k),
                offline_optimum: if seq.len() <= MAX_OFFLINE_LEN {
                    Some(offline_optimum(seq, k)?)
                } else {
                    None
                },
                state_changes,
            });
        }
        Ok(SortbufSweep {
            sequence: name.to_string(),
            sequence_length: seq.len(),
            distinct_states: distinct_states(seq),
            input_runs: input_runs(seq),
            seed,
            strategies: strategies.to_vec(),
            rows,
        })
    }
}

#[cfg(test)]
mod tests;
