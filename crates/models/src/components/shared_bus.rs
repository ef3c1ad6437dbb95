//! A bus that two streams of data share (paper 000 §4.5.3, Table 4): the
//! CPU copying geometry into GPU-visible memory, and the GPU fetching
//! vertices from AGP memory while it renders. Either alone runs at its own
//! rate, up to the bus's bandwidth; together they split the bandwidth
//! max-min fairly: a stream that asks for less than half keeps what it
//! asks, and the other gets the rest.
//!
//! The paper measures the effect (Table 4) but gives no model of it; the
//! fair split is the reading chosen here (`docs/models.md`, "AGP memory
//! and copies"). Geometry in video memory is fetched without the bus, so a
//! copy beside it runs at its own rate (Table 4, Test 1).
//!
//! Rates are bytes per picosecond (`f64`); [`SharedBus`] holds what each
//! stream asks for now, and answers what each gets.

/// Max-min fair shares of `capacity` between two streams asking for
/// `a` and `b` (each at least 0): both get what they ask when it fits;
/// otherwise one that asks for at most half keeps its ask and the other
/// gets the rest, else each gets half. Returns `(rate of a, rate of b)`.
///
/// ```
/// use rendersim_models::components::shared_bus::max_min_fair;
/// // Both fit.
/// assert_eq!(max_min_fair(10.0, 3.0, 4.0), (3.0, 4.0));
/// // The small ask is kept, the large one gets the rest.
/// assert_eq!(max_min_fair(10.0, 3.0, 9.0), (3.0, 7.0));
/// // Both ask for more than half: half each.
/// assert_eq!(max_min_fair(10.0, 8.0, 9.0), (5.0, 5.0));
/// ```
pub fn max_min_fair(capacity: f64, a: f64, b: f64) -> (f64, f64) {
    let (a, b) = (a.max(0.0), b.max(0.0));
    if a + b <= capacity {
        return (a, b);
    }
    let half = capacity / 2.0;
    if a <= half {
        (a, capacity - a)
    } else if b <= half {
        (capacity - b, b)
    } else {
        (half, half)
    }
}

/// The two streams on the bus: what each asks for now (0: not running).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SharedBus {
    capacity: f64,
    fetch: f64,
    copy: f64,
}

impl SharedBus {
    /// An idle bus of `capacity` bytes per picosecond.
    pub fn new(capacity: f64) -> Self {
        SharedBus {
            capacity,
            fetch: 0.0,
            copy: 0.0,
        }
    }

    /// The bus's bandwidth, bytes per picosecond.
    pub fn capacity(&self) -> f64 {
        self.capacity
    }

    /// The GPU's vertex fetch from AGP memory asks for `rate` (0: none).
    /// Returns whether the ask changed.
    pub fn set_fetch(&mut self, rate: f64) -> bool {
        let changed = self.fetch != rate;
        self.fetch = rate;
        changed
    }

    /// A copy asks for `rate` (its own limit; 0: none running).
    pub fn set_copy(&mut self, rate: f64) {
        self.copy = rate;
    }

    /// The rate the copy gets now.
    pub fn copy_rate(&self) -> f64 {
        max_min_fair(self.capacity, self.fetch, self.copy).1
    }

    /// The rate the vertex fetch can have now: what the running copy
    /// leaves of the bandwidth (all of it without a copy).
    pub fn fetch_rate(&self) -> f64 {
        self.capacity - self.copy_rate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_never_exceed_the_capacity_or_an_ask() {
        for (c, a, b) in [
            (1.0, 0.0, 0.0),
            (1.0, 0.3, 0.9),
            (2.0, 5.0, 0.1),
            (2.0, 5.0, 7.0),
            (3.0, 1.5, 1.5),
        ] {
            let (x, y) = max_min_fair(c, a, b);
            assert!(x <= a + 1e-12 && y <= b + 1e-12, "{c} {a} {b}");
            assert!(x + y <= c + 1e-12, "{c} {a} {b}");
            // Work-conserving: the bus is full whenever the asks exceed it.
            if a + b >= c {
                assert!((x + y - c).abs() < 1e-12, "{c} {a} {b}");
            }
        }
    }

    #[test]
    fn table_4s_agp_streams_split_the_bus_in_half() {
        // 952 MB/s; the fetch of non-interleaved vertices asks 55 B x
        // 19.73 M/s = 1085 MB/s, the copy 952 MB/s: 476 each.
        let mut bus = SharedBus::new(952e6 / 1e12);
        bus.set_fetch(55.0 * 19.73e6 / 1e12);
        assert_eq!(bus.fetch_rate(), bus.capacity());
        bus.set_copy(952e6 / 1e12);
        assert!((bus.copy_rate() * 1e12 - 476e6).abs() < 1.0);
        assert!((bus.fetch_rate() * 1e12 - 476e6).abs() < 1.0);
        // A copy slower than half the bus leaves the fetch the rest.
        bus.set_copy(300e6 / 1e12);
        assert!((bus.copy_rate() * 1e12 - 300e6).abs() < 1.0);
        assert!((bus.fetch_rate() * 1e12 - 652e6).abs() < 1.0);
        // No fetch: the copy runs at its own rate.
        bus.set_fetch(0.0);
        assert!((bus.copy_rate() * 1e12 - 300e6).abs() < 1.0);
    }
}
