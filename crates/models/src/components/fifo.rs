//! A bounded FIFO between a producer and a consumer, limited in entries or in
//! bytes. It models the CPU->GPU command buffer of paper 000 §4.4 (a full
//! buffer blocks the driver: CPU idle; an empty one starves the GPU) and the
//! small triangle FIFO between the geometry and fragment stages (§4.5.1).
//!
//! Capacity 0 is a rendezvous: an entry may enter only when the FIFO is empty,
//! and the producer stays blocked until the consumer has taken it. An entry
//! larger than the whole capacity enters only when the FIFO is empty, so a
//! big batch can never deadlock.

/// What the capacity counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FifoUnit {
    /// Entries (commands, triangles).
    Entries,
    /// Bytes.
    Bytes,
}

/// A bounded FIFO of `T`, each entry with a weight (1 entry or its bytes).
///
/// A producer checks [`BoundedFifo::can_push`] before each push and blocks
/// while it is false; an entry larger than the capacity still enters an
/// empty FIFO.
///
/// ```
/// use rendersim_models::components::fifo::BoundedFifo;
///
/// // A command buffer of 1000 bytes.
/// let mut fifo = BoundedFifo::new(1000);
/// fifo.push("draw 1", 400);
/// fifo.push("draw 2", 400);
/// assert_eq!(fifo.used(), 800);
/// assert!(!fifo.can_push(400)); // 1200 > 1000: the driver blocks
/// assert_eq!(fifo.pop(), Some("draw 1")); // oldest first
/// assert!(fifo.can_push(400));
/// fifo.push("draw 3", 400);
/// assert_eq!((fifo.len(), fifo.used(), fifo.max_used()), (2, 800, 800));
///
/// // A 5000-byte entry enters only an empty FIFO, and holds its producer.
/// let mut big = BoundedFifo::new(1000);
/// assert!(big.can_push(5000));
/// big.push("texture upload", 5000);
/// assert!(big.over_capacity());
/// ```
#[derive(Debug, Clone)]
pub struct BoundedFifo<T> {
    items: Ring<(T, u64)>,
    capacity: u64,
    used: u64,
    max_used: u64,
}

impl<T> BoundedFifo<T> {
    /// An empty FIFO of the given capacity (in the unit its weights use).
    pub fn new(capacity: u64) -> Self {
        BoundedFifo {
            items: Ring::new(),
            capacity,
            used: 0,
            max_used: 0,
        }
    }

    /// The capacity.
    pub fn capacity(&self) -> u64 {
        self.capacity
    }

    /// Entries held.
    #[inline]
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when empty.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Weight held (entries or bytes).
    #[inline]
    pub fn used(&self) -> u64 {
        self.used
    }

    /// The largest weight ever held.
    pub fn max_used(&self) -> u64 {
        self.max_used
    }

    /// Whether an entry of `weight` may enter now.
    #[inline]
    pub fn can_push(&self, weight: u64) -> bool {
        self.items.is_empty() || self.used.saturating_add(weight) <= self.capacity
    }

    /// Whether the producer of the last entry must stay blocked until the
    /// consumer takes entries (rendezvous or an over-sized entry).
    #[inline]
    pub fn over_capacity(&self) -> bool {
        self.used > self.capacity
    }

    /// Adds an entry; the caller checks [`BoundedFifo::can_push`] first.
    #[inline(always)]
    pub fn push(&mut self, item: T, weight: u64) {
        debug_assert!(self.can_push(weight));
        self.used += weight;
        self.max_used = self.max_used.max(self.used);
        self.items.push_back((item, weight));
    }

    /// Takes the oldest entry.
    #[inline(always)]
    pub fn pop(&mut self) -> Option<T> {
        let (item, w) = self.items.pop_front()?;
        self.used -= w;
        Some(item)
    }

    /// The oldest entry, without taking it.
    #[inline]
    pub fn front(&self) -> Option<&T> {
        self.items.front().map(|(t, _)| t)
    }
}

/// The entries, oldest first, in a ring of power-of-two size that doubles
/// when full. `VecDeque` would do, but its `push_back` is not inlined into
/// the frame pipeline's hottest path (a CPU draw batch entering the command
/// FIFO), which costs about 1.5% of a long run's instructions.
#[derive(Debug, Clone)]
struct Ring<T> {
    slots: Vec<Option<T>>,
    head: usize,
    len: usize,
}

impl<T> Ring<T> {
    fn new() -> Self {
        Ring {
            slots: Vec::new(),
            head: 0,
            len: 0,
        }
    }

    #[inline(always)]
    fn len(&self) -> usize {
        self.len
    }

    #[inline(always)]
    fn is_empty(&self) -> bool {
        self.len == 0
    }

    #[inline(always)]
    fn mask(&self) -> usize {
        self.slots.len().wrapping_sub(1)
    }

    #[inline(always)]
    fn push_back(&mut self, item: T) {
        if self.len == self.slots.len() {
            self.grow();
        }
        let i = (self.head + self.len) & self.mask();
        self.slots[i] = Some(item);
        self.len += 1;
    }

    /// Doubles the ring (at least 4 slots), the oldest entry first.
    #[cold]
    #[inline(never)]
    fn grow(&mut self) {
        let size = (self.slots.len() * 2).max(4);
        let mask = self.mask();
        let mut slots = Vec::with_capacity(size);
        for k in 0..self.len {
            slots.push(self.slots[(self.head + k) & mask].take());
        }
        slots.resize_with(size, || None);
        self.slots = slots;
        self.head = 0;
    }

    #[inline(always)]
    fn pop_front(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        let item = self.slots[self.head].take();
        self.head = (self.head + 1) & self.mask();
        self.len -= 1;
        item
    }

    #[inline]
    fn front(&self) -> Option<&T> {
        if self.len == 0 {
            return None;
        }
        self.slots[self.head].as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ring against `VecDeque` over pushes and pops that wrap around
    /// and grow it while it holds entries.
    #[test]
    fn ring_keeps_fifo_order_through_wraps_and_growth() {
        let mut ring = Ring::new();
        let mut oracle = std::collections::VecDeque::new();
        let mut next = 0u32;
        // A pattern that pushes more than it pops, then drains.
        for step in 0..2000u32 {
            let pushes = 1 + step % 3;
            let pops = step % 4;
            for _ in 0..pushes {
                ring.push_back(next);
                oracle.push_back(next);
                next += 1;
            }
            for _ in 0..pops {
                assert_eq!(ring.pop_front(), oracle.pop_front());
            }
            assert_eq!(ring.len(), oracle.len());
            assert_eq!(ring.front(), oracle.front());
        }
        while let Some(x) = oracle.pop_front() {
            assert_eq!(ring.pop_front(), Some(x));
        }
        assert!(ring.is_empty());
        assert_eq!(ring.pop_front(), None);
        assert_eq!(ring.front(), None);
    }

    #[test]
    fn bounded_by_weight() {
        let mut f = BoundedFifo::new(10);
        assert!(f.can_push(6));
        f.push('a', 6);
        assert!(f.can_push(4));
        assert!(!f.can_push(5));
        f.push('b', 4);
        assert_eq!(f.used(), 10);
        assert_eq!(f.pop(), Some('a'));
        assert_eq!(f.used(), 4);
        assert!(!f.over_capacity());
    }

    #[test]
    fn zero_capacity_is_a_rendezvous() {
        let mut f = BoundedFifo::new(0);
        assert!(f.can_push(1));
        f.push(1, 1);
        assert!(f.over_capacity());
        assert!(!f.can_push(1));
        f.pop();
        assert!(f.can_push(1));
    }

    #[test]
    fn oversized_entry_enters_when_empty() {
        let mut f = BoundedFifo::new(2);
        f.push(1, 5);
        assert!(f.over_capacity());
        assert!(!f.can_push(1));
    }
}
