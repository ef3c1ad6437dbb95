//! The pending-event set, ordered by `(time, sequence)`: a radix heap for
//! monotone integer time by default, a binary heap for comparison.
//!
//! The sequence number is assigned at scheduling, so events due at the same
//! instant run in the order they were scheduled. That makes every run
//! deterministic whatever the heap's internal layout.
//!
//! ```
//! use rendersim_engine::{EventQueue, Time};
//!
//! let mut q = EventQueue::new();
//! q.push(Time(30), "late");
//! q.push(Time(10), "first at 10");
//! q.push(Time(10), "second at 10"); // same time: after the one scheduled before
//! assert_eq!(q.peek_time(), Some(Time(10)));
//! let order: Vec<&str> = std::iter::from_fn(|| q.pop().map(|s| s.event)).collect();
//! assert_eq!(order, ["first at 10", "second at 10", "late"]);
//! ```

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::radix_heap::RadixHeap;
use super::time::Time;

/// One scheduled event.
#[derive(Debug, Clone)]
pub struct Scheduled<E> {
    /// When it is due.
    pub time: Time,
    /// Tie-breaker: scheduling order.
    pub seq: u64,
    /// The system's event.
    pub event: E,
}

impl<E> PartialEq for Scheduled<E> {
    fn eq(&self, other: &Self) -> bool {
        self.time == other.time && self.seq == other.seq
    }
}
impl<E> Eq for Scheduled<E> {}
impl<E> PartialOrd for Scheduled<E> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl<E> Ord for Scheduled<E> {
    /// Reversed, so that `BinaryHeap` (a max-heap) pops the earliest first.
    #[inline]
    fn cmp(&self, other: &Self) -> Ordering {
        other.time.cmp(&self.time).then_with(|| other.seq.cmp(&self.seq))
    }
}

/// Which data structure holds the pending events. Both pop in exactly the
/// same `(time, seq)` order, so results do not depend on the choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum QueueKind {
    /// A radix heap for monotone integer time ([`super::radix_heap`]):
    /// O(1) amortized per event, flat in the number pending (the default).
    #[default]
    Radix,
    /// A binary heap (`std::collections::BinaryHeap`): O(log n), kept for
    /// comparison.
    Binary,
}

// One per scheduler; boxing the radix heap would add a load on every push
// and pop.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
enum Store<E> {
    Radix(RadixHeap<E>),
    Binary(BinaryHeap<Scheduled<E>>),
}

/// Future events, earliest first; ties in scheduling order.
#[derive(Debug)]
pub struct EventQueue<E> {
    store: Store<E>,
    next_seq: u64,
}

impl<E> Default for EventQueue<E> {
    fn default() -> Self {
        Self::new()
    }
}

impl<E> EventQueue<E> {
    /// An empty queue of the default kind ([`QueueKind::Radix`]).
    pub fn new() -> Self {
        Self::of_kind(QueueKind::default())
    }

    /// An empty queue of the given kind.
    pub fn of_kind(kind: QueueKind) -> Self {
        EventQueue {
            store: match kind {
                QueueKind::Radix => Store::Radix(RadixHeap::new()),
                QueueKind::Binary => Store::Binary(BinaryHeap::with_capacity(64)),
            },
            next_seq: 0,
        }
    }

    /// The kind of this queue.
    pub fn kind(&self) -> QueueKind {
        match self.store {
            Store::Radix(_) => QueueKind::Radix,
            Store::Binary(_) => QueueKind::Binary,
        }
    }

    /// Schedules `event` at `time`.
    #[inline]
    pub fn push(&mut self, time: Time, event: E) {
        let seq = self.next_seq;
        self.next_seq += 1;
        // Built in each arm, not once before the match: one value shared by
        // both arms would live on the stack and be copied into the queue
        // with a wide load that cannot be forwarded from the narrow stores
        // that built it (a stall on every push).
        match &mut self.store {
            Store::Radix(r) => r.push(Scheduled { time, seq, event }),
            Store::Binary(h) => h.push(Scheduled { time, seq, event }),
        }
    }

    /// Takes the next sequence number without scheduling an event (see
    /// [`super::sim::Scheduler::reserve`]): events scheduled later still
    /// come after it at the same time.
    #[inline]
    pub fn reserve_seq(&mut self) -> u64 {
        let seq = self.next_seq;
        self.next_seq += 1;
        seq
    }

    /// Puts back an event just popped, keeping its place among events due
    /// at the same time (the run loop uses it when a time limit stops it).
    pub fn restore(&mut self, s: Scheduled<E>) {
        match &mut self.store {
            Store::Radix(r) => r.restore(s),
            Store::Binary(h) => h.push(s),
        }
    }

    /// Removes and returns the earliest event.
    #[inline]
    pub fn pop(&mut self) -> Option<Scheduled<E>> {
        match &mut self.store {
            Store::Radix(r) => r.pop(),
            Store::Binary(h) => h.pop(),
        }
    }

    /// The time of the earliest pending event.
    pub fn peek_time(&self) -> Option<Time> {
        match &self.store {
            Store::Radix(r) => r.peek_time(),
            Store::Binary(h) => h.peek().map(|s| s.time),
        }
    }

    /// Number of pending events.
    pub fn len(&self) -> usize {
        match &self.store {
            Store::Radix(r) => r.len(),
            Store::Binary(h) => h.len(),
        }
    }

    /// True when nothing is pending.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn earliest_first_ties_in_schedule_order() {
        for kind in [QueueKind::Radix, QueueKind::Binary] {
            let mut q = EventQueue::of_kind(kind);
            q.push(Time(5), 'a');
            q.push(Time(1), 'b');
            q.push(Time(5), 'c');
            q.push(Time(1), 'd');
            let order: Vec<char> = std::iter::from_fn(|| q.pop().map(|s| s.event)).collect();
            assert_eq!(order, vec!['b', 'd', 'a', 'c'], "{kind:?}");
        }
    }

    /// Drives both kinds with the same monotone schedule (each pop may push
    /// events at or after its time, many at the same time, some very far)
    /// and requires the same pop sequence, element for element.
    fn same_order(ops: &[(u8, u64)], initial: &[u64]) {
        let mut r = EventQueue::of_kind(QueueKind::Radix);
        let mut b = EventQueue::of_kind(QueueKind::Binary);
        for (i, &t) in initial.iter().enumerate() {
            r.push(Time(t), i);
            b.push(Time(t), i);
        }
        let mut id = initial.len();
        for &(pushes, delay) in ops {
            let (x, y) = (r.pop(), b.pop());
            assert_eq!(x.as_ref().map(|s| (s.time, s.seq)), y.as_ref().map(|s| (s.time, s.seq)));
            assert_eq!(r.len(), b.len());
            let Some(now) = x.map(|s| s.time.0) else {
                break;
            };
            for k in 0..pushes % 4 {
                // Delays: zero (same time), small, and huge (stiff).
                let d = match (delay >> (8 * k)) % 5 {
                    0 => 0,
                    1 => delay % 7,
                    2 => delay % 1_000,
                    3 => delay % 1_000_000_000_000,
                    _ => (delay % 3) << 40,
                };
                let t = now.saturating_add(d);
                r.push(Time(t), id);
                b.push(Time(t), id);
                id += 1;
            }
            assert_eq!(r.peek_time(), b.peek_time());
        }
        loop {
            let (x, y) = (r.pop(), b.pop());
            assert_eq!(
                x.as_ref().map(|s| (s.time, s.seq, s.event)),
                y.as_ref().map(|s| (s.time, s.seq, s.event))
            );
            if x.is_none() {
                break;
            }
        }
    }

    /// The radix queue keeps few events in a small sorted array and files
    /// them into buckets past 32 pending (back under 8): the order holds
    /// across both changes, with many events due at the same time.
    #[test]
    fn the_radix_queue_keeps_its_order_across_its_small_and_bucket_forms() {
        let initial: Vec<u64> = (0..40).map(|i| (i % 4) * 1_000).collect();
        // Three pushes per pop (zero, small and stiff delays) grow it past
        // 32; then pops alone shrink it below 8; then it grows again.
        let mut ops = vec![(3u8, 0x0301_0200u64); 30];
        ops.extend(vec![(0u8, 0u64); 100]);
        ops.extend(vec![(3u8, 0x0403_0201u64); 40]);
        same_order(&ops, &initial);
    }

    /// Many pending (the bucket form throughout), with delays that fill
    /// every kind of bucket: the same instant, within one level-1 bucket's
    /// 256 ps, within a level-2 bucket's 65,536 ps (small ones are sorted,
    /// large ones spread) and far away; pushes often land inside the run
    /// being popped. Same pop order as the binary heap, element for element.
    #[test]
    fn the_radix_queue_keeps_its_order_with_many_pending_and_mixed_delays() {
        use rand::Rng;
        for (seed, population) in [(1u64, 40usize), (2, 300), (3, 3_000), (4, 20_000)] {
            let mut rng = crate::RngStreams::new(seed).stream("queue test");
            let mut r = EventQueue::of_kind(QueueKind::Radix);
            let mut b = EventQueue::of_kind(QueueKind::Binary);
            for i in 0..population {
                let t = rng.random_range(0..100_000u64);
                r.push(Time(t), i);
                b.push(Time(t), i);
            }
            let mut id = population;
            for step in 0..(20 * population) {
                let (x, y) = (r.pop(), b.pop());
                assert_eq!(
                    x.as_ref().map(|s| (s.time, s.seq, s.event)),
                    y.as_ref().map(|s| (s.time, s.seq, s.event)),
                    "seed {seed}, step {step}"
                );
                let now = x.expect("never empty").time.0;
                // One push per pop on average, so the population stays.
                let pushes = [0, 1, 1, 2][rng.random_range(0..4usize)];
                for _ in 0..pushes {
                    let d = match rng.random_range(0..6u32) {
                        0 => 0,
                        1 => rng.random_range(0..256u64),
                        2 => rng.random_range(0..4_000u64),
                        3 => rng.random_range(0..70_000u64),
                        4 => rng.random_range(0..20_000_000u64),
                        _ => 1u64 << rng.random_range(20..44u32),
                    };
                    r.push(Time(now + d), id);
                    b.push(Time(now + d), id);
                    id += 1;
                }
                assert_eq!(r.len(), b.len());
                assert_eq!(r.peek_time(), b.peek_time());
            }
            while let Some(x) = r.pop() {
                let y = b.pop().expect("same length");
                assert_eq!((x.time, x.seq), (y.time, y.seq));
            }
            assert!(b.pop().is_none());
        }
    }

    proptest::proptest! {
        #[test]
        fn radix_and_binary_heaps_pop_in_the_same_order(
            initial in proptest::collection::vec(0u64..1_000_000, 1..50),
            ops in proptest::collection::vec((0u8..8, proptest::prelude::any::<u64>()), 0..400),
        ) {
            same_order(&ops, &initial);
        }
    }

    #[test]
    fn a_restored_event_keeps_its_place_and_a_late_one_comes_first() {
        for kind in [QueueKind::Radix, QueueKind::Binary] {
            let mut q = EventQueue::of_kind(kind);
            q.push(Time(10), "a");
            q.push(Time(10), "b");
            q.push(Time(u64::MAX), "end of time");
            let a = q.pop().unwrap();
            assert_eq!(a.event, "a");
            q.restore(a);
            assert_eq!(q.pop().unwrap().event, "a", "{kind:?}");
            assert_eq!(q.pop().unwrap().event, "b");
            // Scheduled before the last popped time (a model bug): next out,
            // so the run loop reports it.
            q.push(Time(3), "backwards");
            assert_eq!(q.peek_time(), Some(Time(3)));
            assert_eq!(q.pop().unwrap().event, "backwards");
            assert_eq!(q.pop().unwrap().time, Time(u64::MAX));
            assert!(q.pop().is_none() && q.is_empty());
        }
    }
}
